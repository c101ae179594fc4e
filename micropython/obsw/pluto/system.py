"""The system a PLUTO procedure acts on: parameters, activities, events and the user.

``System`` is the interface the interpreter calls; ``SimulatedSystem`` plays a system from a
JSON-like description on a virtual clock (dry runs and tests); ``run_virtual`` drives a
procedure to its end against it, advancing the clock straight to each deadline.
"""

from obsw.pluto.units import TIME, Quantity, UnitError, dims, parse_iso
from obsw.pluto.units import parse as parse_unit


class System:
    """Interface between a running procedure and the spacecraft (or a simulation of it).

    Paths are PLUTO object references as written, without a leading "value of":
    ``"angle of SolarPanel"``, ``"set_state_bits of CpduN"``, ``"Switch on Star Tracker1"``.
    """

    def get(self, path):
        """Current value of a parameter: bool, int, float, str or Quantity."""
        raise NotImplementedError

    def request(self, path, args):
        """A property read with arguments (an object property request's 'with ... end
        with'); none of this system's properties takes any."""
        raise ValueError("%s takes no arguments" % path)

    def initiate(self, path, args, confirm=False):
        """Start an activity with a dict of evaluated arguments; returns a handle."""
        raise NotImplementedError

    def status(self, handle):
        """None while executing, then "confirmed", "not confirmed" or "aborted"."""
        raise NotImplementedError

    def abort_activity(self, handle):
        """Stop an activity the procedure no longer waits for (in parallel until one)."""

    def raise_event(self, name, data=None):
        """Report an event raised by the procedure (service 5 on board)."""

    def event_count(self, path):
        """How many times system event ``path`` occurred so far (waits compare counts)."""
        return 0

    def log(self, text):
        """Record a log statement's text."""

    def inform_user(self, text):
        """Show a message to the operator."""

    def ask_user(self, question):
        """Ask the operator; return the answer now, or None to wait for Procedure.answer()."""
        return None

    def describe(self, path):
        """Load-time facts about a reference: ("parameter", type code, unit),
        ("activity", None, None), ("event", None, None), or None when unknown."""
        return None

    def signature(self, path):
        """The arguments activity ``path`` declares, [(name, type code, unit)] (type codes
        as ``describe`` gives, "u" unsigned, "rt" relative time), or None: any arguments."""
        return None


def norm(name):
    """A name's spelling-free form: lower case, without spaces and underscores (how member
    and argument names are matched)."""
    return name.replace(" ", "").replace("_", "").lower()


# PLUTO's predefined types as an argument declaration may name them, and packet field types
# by PTC; tuples of constants (frozen in flash on a board, where a dict would take heap)
_PLUTO_TYPES = (
    ("boolean", "b"),
    ("signed integer", "i"),
    ("integer", "i"),
    ("unsigned integer", "u"),
    ("real", "r"),
    ("string", "s"),
    ("absolute time", "a"),
    ("relative time", "rt"),
)
_DB_PREFIXES = (("uint", "u"), ("int", "i"), ("float", "r"), ("bool", "b"), ("str", "s"))
_PTC_CODES = ("?", "b", "?", "u", "i", "r", "?", "?", "s")


def argument_code(t):
    """Checker type code of a declared activity argument: a PLUTO predefined type name
    ("unsigned integer", "relative time"...) or a database type ("uint8", "float32", [3, 4]);
    unsigned integers give "u", types PLUTO cannot check "?"."""
    if isinstance(t, (list, tuple)) and len(t) == 2:
        ptc = t[0]
        return _PTC_CODES[ptc] if type(ptc) is int and 0 <= ptc < len(_PTC_CODES) else "?"
    name = str(t or "").lower()
    for whole, code in _PLUTO_TYPES:
        if name == whole:
            return code
    for prefix, code in _DB_PREFIXES:
        if name.startswith(prefix):
            return code
    return "?"


class SystemSpecError(ValueError):
    """A simulated system description that cannot be played; the message names the entry."""

    def __init__(self, msg):
        super().__init__(msg)


def _code(v):
    if type(v) is bool:
        return "b"
    if isinstance(v, int):
        return "i"
    if isinstance(v, float):
        return "r"
    if isinstance(v, str):
        return "s"
    if isinstance(v, Quantity):
        return "i" if isinstance(v.value, int) else "r"
    return "?"


def _is_number(v):
    return type(v) is not bool and isinstance(v, (int, float))


def value_of(v, where, unit=None):
    """A PLUTO value from a system file value: plain JSON, or ``{"value": v, "unit": u}`` (a
    value with units); numbers and quantities come out in ``unit`` when it is given."""
    if isinstance(v, dict):
        if "value" not in v or [k for k in v if k not in ("value", "unit")]:
            raise SystemSpecError(
                '%s: a value with units is {"value": v, "unit": u}, got %r' % (where, v)
            )
        u = v.get("unit")
        v = value_of(v["value"], where)
        if u:
            v = _quantity(v, u, where)
    if unit:
        if isinstance(v, Quantity):
            try:
                return v.to(unit)
            except UnitError:
                raise SystemSpecError("%s: %s is not in units of %s" % (where, v, unit)) from None
        return _quantity(v, unit, where)
    return v


def _quantity(v, unit, where):
    if not _is_number(v):
        raise SystemSpecError("%s: only numbers take units, got %r with %s" % (where, v, unit))
    try:
        parse_unit(unit)
    except UnitError as e:
        raise SystemSpecError("%s: %s" % (where, e)) from None
    return Quantity(v, unit)


def seconds_of(v, where):
    """Seconds from a system file time: a number of seconds or a relative time with units."""
    v = value_of(v, where)
    if isinstance(v, Quantity):
        if dims(v.unit) != TIME:
            raise SystemSpecError("%s: %s is not a relative time" % (where, v))
        return v.to("s").value
    if not _is_number(v):
        raise SystemSpecError("%s: expected seconds or a relative time, got %r" % (where, v))
    return v


def _parameter(path, p):
    """(type code, unit, timeline of (seconds, value)) of a parameter's description."""
    where = "parameter %s" % path
    if not isinstance(p, dict) or ("value" not in p and "timeline" not in p):
        v = value_of(p, where)
        return _code(v), v.unit if isinstance(v, Quantity) else None, [(0, v)]
    extra = [k for k in p if k not in ("value", "timeline", "unit", "type")]
    if extra:
        raise SystemSpecError("%s: unknown key %s (value, timeline, unit, type)"
                              % (where, ", ".join(extra)))  # fmt: skip
    unit = p.get("unit")
    if unit:
        _quantity(0, unit, where)
    if "timeline" in p:
        line = p["timeline"]
        if not isinstance(line, list) or not line:
            raise SystemSpecError("%s: a timeline is a list of [time, value] pairs" % where)
        raw = []
        for k, entry in enumerate(line):
            if not isinstance(entry, (list, tuple)) or len(entry) != 2:
                raise SystemSpecError("%s: timeline entry %d is not [time, value]" % (where, k))
            raw.append((seconds_of(entry[0], "%s, timeline time %d" % (where, k)), entry[1]))
    else:
        raw = [(0, p["value"])]
    if not unit:  # the first value with units sets the unit of the others
        for _, v in raw:
            v = value_of(v, where)
            if isinstance(v, Quantity):
                unit = v.unit
                break
    line = [(t, value_of(v, "%s at %s s" % (where, t), unit)) for t, v in raw]
    return p.get("type") or _code(line[0][1]), unit, line


def _signature(path, a):
    """An activity's declared arguments: [(name, type code, unit)], or None."""
    args = a.get("arguments")
    if args is None:
        return None
    if not isinstance(args, list):
        raise SystemSpecError("activity %s: arguments is a list, got %r" % (path, args))
    out = []
    for x in args:
        if not isinstance(x, dict) or "name" not in x:
            raise SystemSpecError(
                'activity %s: an argument is {"name": n, "type": t, "unit": u}, got %r' % (path, x)
            )
        u = x.get("unit")
        if u:
            _quantity(0, u, "activity %s, argument %s" % (path, x["name"]))
        out.append((x["name"], argument_code(x.get("type")), u))
    return out


class SimulatedSystem(System):
    """A system played from a description (the format of ``obsw pluto run --system``)::

        {"clock_start": "2025-01-01T00:00:00Z",
         "parameters": {"angle of SolarPanel": 12.5 | {"value": 3.3, "unit": "V"}
                        | {"timeline": [[t, value], ...], "unit": "degC"}},
         "activities": {"set_state_bits of CpduN": {"confirmation": "confirmed"}
                        | {"confirmations": ["not confirmed", "confirmed"], "duration_s": 2,
                           "arguments": [{"name": "state", "type": "uint8"}, ...]}},
         "events": ["Overheat of Thermal" | {"name": ..., "at_s": [t, ...]}],
         "user_responses": ["yes", ...]}

    Wherever a value goes, a value with units may stand: ``{"value": 6.5, "unit": "V"}``;
    times (``t``, ``at_s``, ``duration_s``) are seconds from the clock start or relative times
    such as ``{"value": 2, "unit": "min"}``. Quantities of one parameter are converted to its
    unit (``unit``, else the first value's). A description that cannot be played raises
    ``SystemSpecError`` here, not while a procedure runs. Calls are recorded for the trace.
    """

    def __init__(self, spec=None):
        spec = {} if spec is None else spec
        if not isinstance(spec, dict):
            raise SystemSpecError("a system description is a JSON object, got %r" % (spec,))
        cs = spec.get("clock_start")
        try:
            self.start = parse_iso(cs) if cs else 0
        except UnitError as e:
            raise SystemSpecError("clock_start: %s" % e) from None
        self.now = self.start
        self.parameters = {}
        for path, p in (spec.get("parameters") or {}).items():
            self.parameters[path] = _parameter(path, p)
        self.activities = {}
        self.signatures = {}
        for path, a in (spec.get("activities") or {}).items():
            a = a or {}
            if not isinstance(a, dict):
                raise SystemSpecError("activity %s: expected an object, got %r" % (path, a))
            d = a.get("duration_s", 0)
            self.activities[path] = (a, seconds_of(d, "activity %s, duration_s" % path))
            self.signatures[path] = _signature(path, a)
        self.events = {}
        for e in spec.get("events", ()):
            if isinstance(e, str):
                self.events[e] = ()
            elif isinstance(e, dict) and "name" in e:
                where = "event %s, at_s" % e["name"]
                self.events[e["name"]] = tuple([seconds_of(t, where) for t in e.get("at_s", ())])
            else:
                raise SystemSpecError('an event is a name or {"name": n, "at_s": [...]}: %r' % e)
        self.responses = [value_of(r, "user_responses") for r in spec.get("user_responses", ())]
        self.activity_calls = []
        self.parameter_reads = []
        self.events_raised = []
        self.logs = []
        self.user_messages = []
        self.user_prompts = []
        self._handles = []  # (finish time, confirmation)
        self._counts = {}

    def elapsed(self):
        return self.now - self.start

    def get(self, path):
        if path not in self.parameter_reads:
            self.parameter_reads.append(path)
        line = self.parameters[path][2]
        v = line[0][1]
        t = self.elapsed()
        for ts, val in line:
            if ts <= t:
                v = val
        return v

    def initiate(self, path, args, confirm=False):
        self.activity_calls.append(
            {
                "activity": path,
                "mode": "initiate and confirm" if confirm else "initiate",
                "arguments": _plain(args),
                "at_s": self.elapsed(),
            }
        )
        a, duration = self.activities.get(path, ({}, 0))
        n = self._counts.get(path, 0)
        self._counts[path] = n + 1
        if "confirmations" in a:
            seq = a["confirmations"]
            conf = seq[min(n, len(seq) - 1)] if seq else "confirmed"
        else:
            conf = a.get("confirmation", "confirmed")
        self._handles.append((self.now + duration, conf))
        return len(self._handles) - 1

    def status(self, handle):
        t, conf = self._handles[handle]
        return conf if self.now >= t else None

    def abort_activity(self, handle):
        t, conf = self._handles[handle]
        if self.now < t:
            self._handles[handle] = (self.now, "aborted")

    def raise_event(self, name, data=None):
        self.events_raised.append({"event": name, "at_s": self.elapsed()})

    def event_count(self, path):
        t = self.elapsed()
        return len([x for x in self.events.get(path, ()) if x <= t])

    def log(self, text):
        self.logs.append(text)

    def inform_user(self, text):
        self.user_messages.append(text)

    def ask_user(self, question):
        self.user_prompts.append(question)
        return self.responses.pop(0) if self.responses else None

    def describe(self, path):
        p = self.parameters.get(path)
        if p is not None:
            return ("parameter", p[0], p[1])
        if path in self.activities:
            return ("activity", None, None)
        if path in self.events:
            return ("event", None, None)
        return None

    def signature(self, path):
        """The arguments activity ``path`` declares, [(name, type code, unit)], or None."""
        return self.signatures.get(path)

    def next_event_time(self, after):
        """Earliest scheduled system event or activity completion later than ``after``."""
        best = None
        for ts in self.events.values():
            for t in ts:
                t += self.start
                if t > after and (best is None or t < best):
                    best = t
        for t, _ in self._handles:
            if t > after and (best is None or t < best):
                best = t
        return best


def _plain(v):
    if isinstance(v, Quantity):
        return {"value": v.value, "unit": v.unit}
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_plain(x) for x in v]
    if hasattr(v, "seconds"):
        return str(v)
    return v


def run_virtual(proc, sim, limit_s=864000):
    """Run a started procedure against ``sim`` on a virtual clock until it ends.

    Waits advance the clock instantly to their deadline (or the next scheduled event).
    Stops early when the procedure waits for a user answer that will never come, or
    after ``limit_s`` simulated seconds. Returns the final clock value.
    """
    now = sim.now
    while proc.state != "finished":
        sim.now = now
        w = proc.run(now)
        if proc.state != "running" or w is None:
            break
        nxt = w.deadline
        ev = sim.next_event_time(now)
        if ev is not None and (nxt is None or ev < nxt):
            nxt = ev
        if nxt is None or nxt - sim.start > limit_s:
            break
        if nxt > now:
            now = nxt
    sim.now = now
    return now
