"""The PLUTO system interface on the interaction layer: procedures act on IL components.

A PLUTO object reference names a member of a component, innermost first:
``"angle of SolarPanel"`` is attribute ``SolarPanel.angle`` (read with a synchronous get,
bounded by ``timeout``), ``"set_state_bits of CpduN"`` is operation ``CpduN.set_state_bits``
(started without waiting; its ``Pending`` becomes the activity's confirmation), and
``"angle_reached of SolarPanel"`` is event ``SolarPanel.angle_reached`` (counted through a
subscription). Names match whatever their spelling: ``"set state bits of Cpdu N"`` finds
``CpduN.set_state_bits``; a reference with one name only (``"Switch on Star Tracker1"``)
finds the member whose name and component's name, run together, spell it.

Load-time facts (``describe``) come from the spacecraft database (an ``obsw.sdb.Sdb`` or its
JSON document, which may also list operations with their arguments) and from component
``Interface`` declarations: those given, and those of the node's own providers.

Outcomes: an operation that returns is confirmed; one whose provider raises
``ComponentError`` (refuses or fails on purpose) is not confirmed; anything else (no
provider, a crash, a broken link, no outcome within ``activity_timeout``, abandoned by the
procedure) is aborted.
"""

from obsw.il.errors import COMPONENT_ERROR, OK, InteractionError, error_from_reply
from obsw.pluto.statements import ABORTED, CONFIRMED, NOT_CONFIRMED
from obsw.pluto.system import System
from obsw.pluto.units import AbsTime, Quantity, UnitError, isdigits
from obsw.pluto.units import parse as parse_unit


class ParameterError(ValueError):
    """A parameter could not be read through the interaction layer."""

    def __init__(self, path, cause):
        super().__init__("%s: %s" % (path, cause))
        self.path = path
        self.cause = cause


class ActivityArgumentError(ValueError):
    """Activity arguments that do not fit the operation's parameters."""

    def __init__(self, msg, path=None):
        super().__init__(msg)
        self.path = path


def norm(name):
    """A name's spelling-free form: lower case, without spaces and underscores."""
    return name.replace(" ", "").replace("_", "").lower()


def type_code(t):
    """PLUTO checker type code for a database or interface type name ('float32', 'u8'...)."""
    if isinstance(t, (list, tuple)) and len(t) == 2:
        return _PTC.get(t[0], "?")
    t = str(t or "").lower()
    if not t:
        return "?"
    if t.startswith("bool"):
        return "b"
    if t.startswith("f") or t in ("real", "double"):
        return "r"
    if t.startswith("uint") or t.startswith("int") or (t[0] in "ui" and isdigits(t[1:])):
        return "i"
    if t.startswith("str") or t == "text":
        return "s"
    return "?"


_PTC = {1: "b", 3: "i", 4: "i", 5: "r", 8: "s"}


def _unit(u):
    """``u`` if PLUTO (Annex B) knows it, else None (the value then counts as unitless)."""
    if not u:
        return None
    try:
        parse_unit(u)
    except (UnitError, ValueError):
        return None
    return u


def _items(x):
    """Entries of a database section given as a list (of dicts or names) or a dict."""
    if isinstance(x, dict):
        out = []
        for k, v in x.items():
            d = dict(v) if isinstance(v, dict) else {}
            d.setdefault("name", k)
            out.append(d)
        return out
    return [i if isinstance(i, dict) else {"name": i} for i in (x or ())]


# catalog entry fields
_KIND = 0
_COMP = 1
_MEMBER = 2
_CODE = 3
_UNIT = 4
_PARAMS = 5


class Catalog:
    """What is known about component members, by spelling-free (component, member) names.

    An entry is ``[kind, component, member, type code, unit, params]``; ``kind`` is
    "parameter", "activity" or "event"; ``params`` lists an operation's ``(name, unit)``.
    """

    def __init__(self, sdb=None, interfaces=()):
        self.entries = {}
        self.interfaces = {}  # names of interfaces added
        self._paths = {}  # path -> entry or None, filled as paths are looked up
        if sdb is not None:
            self.add_sdb(sdb)
        for itf in interfaces or ():
            self.add_interface(itf)

    def add(self, kind, comp, member, code=None, unit=None, params=None):
        key = (norm(comp), norm(member))
        e = self.entries.get(key)
        if e is None:
            self.entries[key] = [kind, comp, member, code, _unit(unit), params]
        else:  # a second source fills in what the first left open
            if e[_CODE] in (None, "?") and code:
                e[_CODE] = code
            if not e[_UNIT]:
                e[_UNIT] = _unit(unit)
            if e[_PARAMS] is None and params is not None:
                e[_PARAMS] = params
        self._paths = {}

    def add_interface(self, itf):
        """Attributes, operations and events of an ``obsw.il.interface.Interface``."""
        self.interfaces[itf.name] = itf
        for a in itf.attributes:
            self.add("parameter", itf.name, a.name, type_code(a.type), a.unit)
        for op in itf.operations:
            self.add("activity", itf.name, op.name, None, None, [(p, None) for p in op.params])
        for ev in itf.events:
            self.add("event", itf.name, ev.name)

    def add_sdb(self, sdb):
        """A spacecraft database: an ``obsw.sdb.Sdb`` or its JSON document (a dict)."""
        if not isinstance(sdb, dict):
            for p in sdb.parameters.values():
                if p.component:
                    self.add("parameter", p.component, p.name, type_code(p.type_spec), p.unit)
            for e in sdb.events.values():
                if e.component:
                    self.add("event", e.component, e.name)
            return
        comps = sdb.get("components", ())
        for comp in _items(comps):
            c = comp["name"]
            for a in _items(comp.get("attributes")) + _items(comp.get("parameters")):
                self.add("parameter", c, a["name"], type_code(a.get("type")), a.get("unit"))
            for op in _items(comp.get("operations")) + _items(comp.get("activities")):
                args = op.get("arguments", op.get("params"))
                params = None
                if args is not None:
                    params = [(x["name"], x.get("unit")) for x in _items(args)]
                self.add("activity", c, op["name"], None, None, params)
            for e in _items(comp.get("events")):
                self.add("event", c, e["name"])

    def find(self, path):
        """The entry a PLUTO path names, or None."""
        if path in self._paths:
            return self._paths[path]
        names = path.split(" of ")
        if len(names) > 2 and names[0] == "value":
            names = names[1:]
        e = None
        if len(names) > 1:
            e = self.entries.get(("".join([norm(n) for n in names[:0:-1]]), norm(names[0])))
        else:
            n = norm(names[0])
            for (c, m), x in self.entries.items():
                if m + c == n or c + m == n:
                    e = x
                    break
        self._paths[path] = e
        return e

    def unit_of(self, comp, name):
        """Unit of ``comp``'s attribute called ``name`` (an argument's default unit)."""
        e = self.entries.get((norm(comp), norm(name)))
        return e[_UNIT] if e is not None and e[_KIND] == "parameter" else None


def target_of(path, entry=None):
    """``(component, member)`` of a PLUTO path (from its catalog entry when there is one)."""
    if entry is not None:
        return entry[_COMP], entry[_MEMBER]
    names = path.split(" of ")
    if len(names) > 2 and names[0] == "value":
        names = names[1:]
    if len(names) < 2:
        raise ParameterError(path, "names no member of a component ('<member> of <component>')")
    comp = "".join(names[:0:-1]).replace(" ", "")
    return comp, names[0].strip().replace(" ", "_")


def plain(v, unit=None):
    """A procedure value as the interaction layer carries it: numbers in ``unit``."""
    if isinstance(v, Quantity):
        return v.to(unit).value if unit else v.value
    if isinstance(v, AbsTime):
        return v.seconds
    if isinstance(v, dict):
        return {k: plain(x) for k, x in v.items()}
    if isinstance(v, list):
        return [plain(x) for x in v]
    return v


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
        if e[_KIND] == "parameter":
            return ("parameter", e[_CODE] or "?", e[_UNIT])
        return (e[_KIND], None, None)

    def get(self, path):
        target = self.target(path)
        try:
            v = self.node.get(target, timeout=self.timeout, user=self.user)
        except InteractionError as e:
            raise ParameterError(path, e) from None
        self.reads += 1
        if isinstance(v, dict) and "value" in v and "unit" in v:
            return Quantity(v["value"], v["unit"])
        return v

    def arguments(self, path, args):
        """The positional arguments of the operation ``path`` names, from PLUTO arguments
        (named, or ``arg1``, ``arg2`` ... in order); quantities in the parameters' units."""
        e = self._find(path)
        given = [(k, v) for k, v in args.items() if k != "directives"]
        params = e[_PARAMS] if e is not None else None
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
            out.append(plain(hit[1], unit or self.catalog.unit_of(e[_COMP], name)))
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
