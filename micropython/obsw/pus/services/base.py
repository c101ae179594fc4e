"""What every PUS service provider and service user shares, and the mission's field sizes.

A provider subclasses ``Service``, names its service type, lists its handlers as
``(message type, method name)`` pairs and the TM types it emits as ``REPORTS``; a handler is
a small method taking a ``Request`` (``obsw.pus.app``), plain or ``async``. A user subclasses
``ServiceUser`` and lists the TM it decodes the same way; each decoder returns a dict of
named values.

The field types below are the packet layout choices ECSS-E-ST-70-41C leaves to the mission,
named once. The defaults follow puslib's default policy so either side can talk to it.
"""

from obsw.pus.fields import field
from obsw.pus.packets import ACK_ALL

U8 = field(3, 4)
U16 = field(3, 12)
U32 = field(3, 14)
E8 = field(2, 8)
E16 = field(2, 16)
BOOL8 = field(1, 8)

FAILURE_CODE = E8  # service 1 failure code
STEP_ID = U8  # service 1 step identifier
PARAMETER_ID = U16  # on-board parameter identifier
PARAMETER_COUNT = U8  # N of a service 20 request or report
STRUCTURE_ID = U16  # housekeeping parameter report structure identifier
HK_COUNT = U16  # N of a service 3 request or report
COLLECTION_INTERVAL = U16  # in minimum sampling intervals (application process cycles)
GENERATION_STATUS = U8  # periodic generation action status
EVENT_ID = E16  # event definition identifier
EVENT_COUNT = U8  # N of a service 5 request or report
APID_FIELD = U16  # application process identifier in service 17


class Service:
    """Base of service providers: a service type, handlers by subtype, optional state."""

    SERVICE = 0
    NAME = None  # key in the context store; None keeps no state
    HANDLERS = ()  # ((service, subtype), "method name") pairs
    REPORTS = ()  # the (service, subtype) TM types this provider emits (obsw pus coverage)

    def __init__(self):
        self.app = None
        self._handlers = {}
        self._cycle_task = None

    def attach(self, app):
        """Called by ApplicationProcess.register: bind the handlers, restore saved state."""
        self.app = app
        for (svc, sub), name in self.HANDLERS:
            if svc != self.SERVICE:
                raise ValueError("%s lists TC[%d,%d]" % (type(self).__name__, svc, sub))
            self._handlers[sub] = getattr(self, name)
        if self.NAME is not None and app.store is not None:
            ctx = app.store.load(self.NAME)
            if ctx is not None:
                try:
                    self.restore(ctx)
                except (ValueError, TypeError, KeyError, IndexError, AttributeError):
                    app.count("context_rejected")
                    set_aside = getattr(app.store, "set_aside", None)
                    if set_aside is not None:
                        set_aside(self.NAME)

    def handler(self, subtype):
        return self._handlers.get(subtype)

    def subtypes(self):
        return sorted(self._handlers)

    cyclic = None  # a method ``cyclic(now)`` (plain or async) when there is periodic work

    def context(self):
        """What to persist (JSON-able), or None."""
        return None

    def restore(self, ctx):
        """Take back what ``context`` returned after a restart."""

    def persist(self):
        """Save ``context()`` in the application process's context store, if it has one."""
        store = self.app.store if self.app is not None else None
        if self.NAME is not None and store is not None:
            store.save(self.NAME, self.context())

    def send(self, message_type, data=b"", destination=0):
        """Send a TM of this service (``message_type`` is a (service, subtype) pair)."""
        return self.app.send_tm(message_type[0], message_type[1], data, destination)


class ServiceUser:
    """Base of service users: build TCs of one service type and decode its TM."""

    SERVICE = 0
    DECODERS = ()  # ((service, subtype), "method name") pairs

    def __init__(self):
        self.proc = None
        self._decoders = {}

    def attach(self, proc):
        self.proc = proc
        for (svc, sub), name in self.DECODERS:
            if svc != self.SERVICE:
                raise ValueError("%s lists TM[%d,%d]" % (type(self).__name__, svc, sub))
            self._decoders[sub] = getattr(self, name)

    def decoder(self, subtype):
        return self._decoders.get(subtype)

    def request(self, apid, message_type, data=b"", expect=None, ack=ACK_ALL):
        """Send a TC of this service; returns the ground process's Transaction."""
        return self.proc.send(apid, message_type[0], message_type[1], data, expect, ack)
