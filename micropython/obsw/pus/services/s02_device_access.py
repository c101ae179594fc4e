"""ST[02] device access: raw commands to on-board equipment and the data they return.

The provider talks to the equipment through the ``DeviceAccess`` interaction-layer
component (``obsw.spacecan.device_access``, SpaceCAN in front of the controller):

- TC[2,7] distribute physical device commands: (device ID, octets) items, sent raw;
- TC[2,8] acquire data from physical devices: the same, each answered by a device's reply
  frame, all in one TM[2,9] physical device data report;
- TC[2,10] distribute logical device commands: (device ID, service, subtype, octets) items,
  SpaceCAN service requests the nodes verify;
- TC[2,11] acquire data from logical devices: the same, the nodes' report packets in one
  TM[2,12] logical device data report.

Items run in order; the first that fails fails the request's completion with its device ID
in the failure data (``FAILURE_TIMEOUT`` when the device did not answer,
``FAILURE_UNAVAILABLE`` when the component is not reachable, ``FAILURE_COMPONENT``
otherwise). ``devices`` (device ID -> anything) limits the IDs accepted (others fail the start).
"""

from obsw.il.errors import CallTimeoutError, ComponentError, InteractionError, UnavailableError
from obsw.pus.fields import field
from obsw.pus.messages import (
    FAILURE_COMPONENT,
    FAILURE_TIMEOUT,
    FAILURE_UNAVAILABLE,
    FAILURE_UNKNOWN_ID,
    SERVICE_DEVICE_ACCESS,
    TC_DEVICE_LOGICAL_ACQUIRE,
    TC_DEVICE_LOGICAL_COMMAND,
    TC_DEVICE_PHYSICAL_ACQUIRE,
    TC_DEVICE_PHYSICAL_COMMAND,
    TM_DEVICE_LOGICAL_DATA_REPORT,
    TM_DEVICE_PHYSICAL_DATA_REPORT,
)
from obsw.pus.services.base import U8, U16, Service, ServiceUser
from obsw.pus.services.s01_verification import PusFailure
from obsw.pus.structure import Repeated, Structure

DEVICE_ID = U16
OCTETS = field(7, 0)
PHYSICAL = Structure([("items", Repeated(U8, [("device", DEVICE_ID), ("data", OCTETS)]))])
LOGICAL = Structure(
    [
        (
            "items",
            Repeated(
                U8,
                [("device", DEVICE_ID), ("service", U8), ("subtype", U8), ("data", OCTETS)],
            ),
        )
    ]
)
TIMEOUT_REASON = "TIMEOUT"


def _failure(error, device):
    data = DEVICE_ID.pack(device)
    if isinstance(error, CallTimeoutError):
        return PusFailure(FAILURE_TIMEOUT, error.message, data)
    if isinstance(error, ComponentError) and error.code == TIMEOUT_REASON:
        return PusFailure(FAILURE_TIMEOUT, error.message, data)
    if isinstance(error, UnavailableError):
        return PusFailure(FAILURE_UNAVAILABLE, error.message, data)
    return PusFailure(FAILURE_COMPONENT, str(error), data)


class DeviceAccess(Service):
    """The service 2 provider, calling ``component`` on the interaction-layer ``node``."""

    SERVICE = SERVICE_DEVICE_ACCESS
    REPORTS = (TM_DEVICE_PHYSICAL_DATA_REPORT, TM_DEVICE_LOGICAL_DATA_REPORT)
    HANDLERS = (
        (TC_DEVICE_PHYSICAL_COMMAND, "physical_command"),
        (TC_DEVICE_PHYSICAL_ACQUIRE, "physical_acquire"),
        (TC_DEVICE_LOGICAL_COMMAND, "logical_command"),
        (TC_DEVICE_LOGICAL_ACQUIRE, "logical_acquire"),
    )

    def __init__(self, node, devices=None, timeout=5.0, component="DeviceAccess"):
        super().__init__()
        self.node = node
        self.devices = devices
        self.timeout = timeout
        self.component = component

    def _decode(self, req, layout):
        items = req.decode(layout)["items"]
        if self.devices is not None:
            for i in items:
                if i["device"] not in self.devices:
                    raise PusFailure(
                        FAILURE_UNKNOWN_ID,
                        "no device %d" % i["device"],
                        DEVICE_ID.pack(i["device"]),
                    )
        req.start()
        return items

    async def _call(self, operation, args, device):
        try:
            pending = self.node.start(self.component + "." + operation, args, timeout=self.timeout)
            return await pending.wait(self.timeout)
        except (InteractionError, ValueError) as e:
            raise _failure(e, device) from None

    async def physical_command(self, req):
        for i in self._decode(req, PHYSICAL):
            await self._call("command", (i["device"], i["data"]), i["device"])

    async def physical_acquire(self, req):
        out = []
        for i in self._decode(req, PHYSICAL):
            data = await self._call("acquire", (i["device"], i["data"]), i["device"])
            out.append({"device": i["device"], "data": bytes(data)})
        req.report(TM_DEVICE_PHYSICAL_DATA_REPORT, PHYSICAL.pack({"items": out}))

    async def _logical(self, req):
        out = []
        for i in self._decode(req, LOGICAL):
            args = (i["device"], i["service"], i["subtype"], i["data"])
            packets = await self._call("request", args, i["device"])
            for service, subtype, data in packets or ():
                out.append(
                    {"device": i["device"], "service": service, "subtype": subtype, "data": data}
                )
        return out

    async def logical_command(self, req):
        await self._logical(req)

    async def logical_acquire(self, req):
        out = await self._logical(req)
        req.report(TM_DEVICE_LOGICAL_DATA_REPORT, LOGICAL.pack({"items": out}))


class DeviceUser(ServiceUser):
    """The service 2 user."""

    SERVICE = SERVICE_DEVICE_ACCESS
    DECODERS = (
        (TM_DEVICE_PHYSICAL_DATA_REPORT, "decode_physical"),
        (TM_DEVICE_LOGICAL_DATA_REPORT, "decode_logical"),
    )

    def _physical(self, items):
        return PHYSICAL.pack({"items": [{"device": d, "data": bytes(b)} for d, b in items]})

    def command(self, apid, items):
        """``items``: (device ID, octets) pairs, sent raw."""
        return self.request(apid, TC_DEVICE_PHYSICAL_COMMAND, self._physical(items))

    def acquire(self, apid, items):
        return self.request(
            apid,
            TC_DEVICE_PHYSICAL_ACQUIRE,
            self._physical(items),
            TM_DEVICE_PHYSICAL_DATA_REPORT,
        )

    def _logical(self, items):
        return LOGICAL.pack(
            {
                "items": [
                    {"device": d, "service": s, "subtype": t, "data": bytes(b)}
                    for d, s, t, b in items
                ]
            }
        )

    def logical_command(self, apid, items):
        """``items``: (device ID, service, subtype, octets), as SpaceCAN service requests."""
        return self.request(apid, TC_DEVICE_LOGICAL_COMMAND, self._logical(items))

    def logical_acquire(self, apid, items):
        return self.request(
            apid, TC_DEVICE_LOGICAL_ACQUIRE, self._logical(items), TM_DEVICE_LOGICAL_DATA_REPORT
        )

    def decode_physical(self, tm):
        return {"items": [(i["device"], i["data"]) for i in PHYSICAL.unpack(tm.data)["items"]]}

    def decode_logical(self, tm):
        items = LOGICAL.unpack(tm.data)["items"]
        return {"items": [(i["device"], i["service"], i["subtype"], i["data"]) for i in items]}
