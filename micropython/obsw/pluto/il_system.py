"""The PLUTO system interface on the interaction layer: procedures act on IL components.

A PLUTO object reference names a member of a component, innermost first:
``"angle of SolarPanel"`` is attribute ``SolarPanel.angle`` (read with a synchronous get,
bounded by ``timeout``), ``"set_state_bits of CpduN"`` is operation ``CpduN.set_state_bits``
(started without waiting; its ``Pending`` becomes the activity's confirmation), and
``"angle_reached of SolarPanel"`` is event ``SolarPanel.angle_reached`` (counted through a
subscription). Names match whatever their spelling: ``"set state bits of Cpdu N"`` finds
``CpduN.set_state_bits``; a reference with one name only (``"Switch on Star Tracker1"``)
finds the member whose name and component's name, run together, spell it.

Names resolve through ``obsw.pluto.names`` (``Catalog``, ``target_of``, ``plain``).

Load-time facts (``describe``) come from the spacecraft database (an ``obsw.pus.sdb.Sdb`` or its
JSON document, which may also list operations with their arguments) and from component
``Interface`` declarations: those given, and those of the node's own providers.

Outcomes: an operation that returns is confirmed; one whose provider raises
``ComponentError`` (refuses or fails on purpose) is not confirmed; anything else (no
provider, a crash, a broken link, no outcome within ``activity_timeout``, abandoned by the
procedure) is aborted.
"""

from obsw.il.errors import COMPONENT_ERROR, OK, InteractionError, error_from_reply
from obsw.pluto.names import (
    CODE,
    COMPONENT,
    KIND,
    PARAMS,
    SIGNATURE,
    UNIT,
    Catalog,
    ParameterError,
    norm,
    plain,
    target_of,
)
from obsw.pluto.statements import ABORTED, CONFIRMED, NOT_CONFIRMED
from obsw.pluto.system import System
from obsw.pluto.units import Quantity, isdigits


class ActivityArgumentError(ValueError):
    """Activity arguments that do not fit the operation's parameters."""

    def __init__(self, msg, path=None):
        super().__init__(msg)
        self.path = path


class Activity:
    """An initiated operation: the handle ``initiate`` returns."""

    def __init__(self, path, target, deadline):
        self.path = path
        self.target = target
        self.deadline = deadline
        self.pending = None
        self.result = None  # confirmed, not confirmed, aborted
        self.value = None  # the operation's return value once confirmed
        self.error = None  # why it was not confirmed or aborted
        self.system = None

    def __repr__(self):
        return "Activity(%s, %s)" % (self.target, self.result or "executing")

    def _on_status(self, pending, state, value):
        if pending.done and self.system is not None:
            self.system._wake()


class _Counter:
    """Stands in for a subscription's queue: counts the publications of one event."""

    def __init__(self, system):
        self.system = system
        self.count = 0
        self.last = None
        self.dropped = 0
        self.sub = None
        self.retry_at = None

    def put(self, pub):
        self.count += 1
        self.last = pub.value
        self.system._wake()
        return True


class IlSystem(System):
    """``System`` on an IL ``Node`` (see the module text).

    ``timeout`` bounds each parameter read and each subscription; ``activity_timeout`` the
    wait for an operation's outcome. ``user`` names the calling component (cycle detection).
    ``on_output(kind, text)`` receives "log", "inform", "raise" (an event name) and "ask"
    (a question; the answer comes through ``Procedure.answer``). ``on_wake()`` is called when
    an activity's outcome or a subscribed event arrives, so a runner can step at once.
    """

    def __init__(
        self,
        node,
        sdb=None,
        interfaces=(),
        *,
        timeout=1.0,
        activity_timeout=30.0,
        user=None,
        on_output=None,
        catalog=None,
    ):
        self.node = node
        self.catalog = catalog if catalog is not None else Catalog(sdb, interfaces)
        self.timeout = timeout
        self.activity_timeout = activity_timeout
        self.user = user
        self.on_output = on_output
        self.on_wake = None
        self.retry_interval = 5.0  # between attempts to subscribe to an unreachable event
        self.reads = 0
        self.initiated = 0
        self._events = {}  # "Component.event" -> _Counter, shared with forks
        self._root = self

    def fork(self, on_output=None):
        """A system for one more procedure: same node, catalog and event counters, its own
        output and wake-up callbacks."""
        s = IlSystem(
            self.node,
            timeout=self.timeout,
            activity_timeout=self.activity_timeout,
            user=self.user,
            on_output=on_output,
            catalog=self.catalog,
        )
        s.retry_interval = self.retry_interval
        s._events = self._events
        s._root = self._root
        return s

    def _wake(self):
        if self.on_wake is not None:
            self.on_wake()

    def _output(self, kind, text):
        if self.on_output is not None:
            self.on_output(kind, text)

    def target(self, path):
        """``"Component.member"`` for a PLUTO path."""
        comp, member = target_of(path, self._find(path))
        return comp + "." + member

    def _find(self, path):
        e = self.catalog.find(path)
        if e is None:
            added = False
            for p in self.node.providers():  # the node's own components describe themselves
                if p.name not in self.catalog.interfaces:
                    self.catalog.add_interface(p.interface)
                    added = True
            if added:
                e = self.catalog.find(path)
        return e

    # -------------------------------------------------------------------------- System

    def describe(self, path):
        e = self._find(path)
        if e is None:
            return None
        if e[KIND] == "parameter":
            return ("parameter", e[CODE] or "?", e[UNIT])
        return (e[KIND], None, None)

    def signature(self, path):
        """The arguments the database declares for activity ``path``: [(name, type code,
        unit)], or None (the load-time checker then takes any arguments)."""
        e = self._find(path)
        return e[SIGNATURE] if e is not None and e[KIND] == "activity" else None

    def get(self, path):
        target = self.target(path)
        try:
            v = self.node.get(target, timeout=self.timeout, user=self.user)
        except InteractionError as e:
            raise ParameterError(path, e) from None
        self.reads += 1
        if isinstance(v, dict) and "value" in v and "unit" in v:
            return Quantity(v["value"], v["unit"])
        p = self.catalog.calibrated.get(target)
        if p is not None:  # the engineering value of a raw one, with its unit
            try:
                v = p.engineering(v)
            except ValueError as e:
                raise ParameterError(path, e) from None
            return Quantity(v, p.unit) if p.unit and not isinstance(v, str) else v
        return v

    def arguments(self, path, args):
        """The positional arguments of the operation ``path`` names, from PLUTO arguments
        (named, or ``arg1``, ``arg2`` ... in order); quantities in the parameters' units."""
        e = self._find(path)
        given = [(k, v) for k, v in args.items() if k != "directives"]
        params = e[PARAMS] if e is not None else None
        if params is None:  # positional order; named ones (unordered on MicroPython) by name
            given.sort(key=_position)
            return tuple([plain(v) for _, v in given])
        by_name = {}
        for k, v in given:
            by_name[norm(k)] = (k, v)
        out = []
        for i, (name, unit) in enumerate(params):
            hit = by_name.pop(norm(name), None) or by_name.pop("arg%d" % (i + 1), None)
            if hit is None:
                raise ActivityArgumentError(
                    "%s needs argument %s (takes: %s)" % (path, name, _names(params)), path
                )
            out.append(plain(hit[1], unit or self.catalog.unit_of(e[COMPONENT], name)))
        if by_name:
            extra = ", ".join([k for k, _ in by_name.values()])
            raise ActivityArgumentError(
                "%s has no argument %s (takes: %s)" % (path, extra, _names(params)), path
            )
        return tuple(out)

    def initiate(self, path, args, confirm=False):
        target = self.target(path)
        values = self.arguments(path, args)
        act = Activity(path, target, self.node.clock.now() + self.activity_timeout)
        act.system = self
        self.initiated += 1
        try:
            act.pending = self.node.start(
                target, values, timeout=self.timeout, user=self.user, on_status=act._on_status
            )
        except InteractionError as e:
            self._end(act, ABORTED, e)
        return act

    def status(self, act):
        if act.result is None:
            p = act.pending
            if p is not None and p.done:
                if p.status == OK:
                    act.value = p.value
                    act.result = CONFIRMED
                else:
                    err = error_from_reply(p.status, p.value, p.target)
                    self._end(act, NOT_CONFIRMED if p.status == COMPONENT_ERROR else ABORTED, err)
            elif self.node.clock.now() >= act.deadline:
                self._end(act, ABORTED, "no outcome within %ss" % self.activity_timeout)
        return act.result

    def _end(self, act, result, error):
        act.result = result
        act.error = error
        if act.pending is not None:
            act.pending.on_status = None
        if isinstance(error, InteractionError):
            code = getattr(error, "code", None)
            error = "%s%s: %s" % (
                type(error).__name__,
                "" if code is None else " " + str(code),
                error.message,
            )
            act.error = error
        self._output("log", "%s %s: %s" % (act.path, result, error))

    def abort_activity(self, act):
        if act.result is None:
            act.result = ABORTED
            act.error = "abandoned by the procedure"
            if act.pending is not None:
                act.pending.on_status = None

    def event_count(self, path):
        target = self.target(path)
        c = self._events.get(target)
        if c is None:
            c = self._events[target] = _Counter(self._root)
        if c.sub is None:
            now = self.node.clock.now()
            if c.retry_at is None or now >= c.retry_at:
                try:
                    c.sub = self.node.subscribe(target, None, c, timeout=self.timeout)
                except (InteractionError, ValueError):
                    c.retry_at = now + self.retry_interval
        return c.count

    def raise_event(self, name, data=None):
        self._output("raise", name)

    def log(self, text):
        self._output("log", text)

    def inform_user(self, text):
        self._output("inform", text)

    def ask_user(self, question):
        self._output("ask", question)
        return None

    def close(self):
        """Cancel the event subscriptions (shared with every fork)."""
        for c in self._events.values():
            if c.sub is not None:
                c.sub.cancel()
                c.sub = None
        self._events.clear()


def _position(item):
    k = item[0]
    if k.startswith("arg") and isdigits(k[3:]):
        return (0, int(k[3:]), "")
    return (1, 0, k)


def _names(params):
    return ", ".join([p[0] for p in params]) or "none"
