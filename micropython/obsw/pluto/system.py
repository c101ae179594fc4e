"""The system a PLUTO procedure acts on: parameters, activities, events and the user.

``System`` is the interface the interpreter calls; ``SimulatedSystem`` plays a system from a
JSON-like description on a virtual clock (dry runs and tests); ``run_virtual`` drives a
procedure to its end against it, advancing the clock straight to each deadline.
"""

from obsw.pluto.units import Quantity, parse_iso


class System:
    """Interface between a running procedure and the spacecraft (or a simulation of it).

    Paths are PLUTO object references as written, without a leading "value of":
    ``"angle of SolarPanel"``, ``"set_state_bits of CpduN"``, ``"Switch on Star Tracker1"``.
    """

    def get(self, path):
        """Current value of a parameter: bool, int, float, str or Quantity."""
        raise NotImplementedError

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


def _code(v):
    if type(v) is bool:
        return "b"
    if isinstance(v, int):
        return "i"
    if isinstance(v, float):
        return "r"
    if isinstance(v, str):
        return "s"
    return "?"


class SimulatedSystem(System):
    """A system played from a description (the format of ``obsw pluto run --system``)::

        {"clock_start": "2025-01-01T00:00:00Z",
         "parameters": {"angle of SolarPanel": 12.5 | {"value": 3.3, "unit": "V"}
                        | {"timeline": [[t_s, value], ...], "unit": "degC"}},
         "activities": {"set_state_bits of CpduN": {"confirmation": "confirmed"}
                        | {"confirmations": ["not confirmed", "confirmed"], "duration_s": 2}},
         "events": ["Overheat of Thermal" | {"name": ..., "at_s": [t_s, ...]}],
         "user_responses": ["yes", ...]}

    Times ``t_s`` count from the clock start. Calls are recorded for the run trace.
    """

    def __init__(self, spec=None):
        spec = spec or {}
        cs = spec.get("clock_start")
        self.start = parse_iso(cs) if cs else 0
        self.now = self.start
        self.parameters = spec.get("parameters", {})
        self.activities = spec.get("activities", {})
        self.events = {}
        for e in spec.get("events", ()):
            if isinstance(e, str):
                self.events[e] = ()
            else:
                self.events[e["name"]] = tuple(e.get("at_s", ()))
        self.responses = list(spec.get("user_responses", ()))
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
        p = self.parameters[path]
        if not isinstance(p, dict):
            return p
        if "timeline" in p:
            v = None
            t = self.elapsed()
            for ts, val in p["timeline"]:
                if ts <= t:
                    v = val
            if v is None:
                v = p["timeline"][0][1]
        else:
            v = p["value"]
        return Quantity(v, p["unit"]) if p.get("unit") else v

    def initiate(self, path, args, confirm=False):
        self.activity_calls.append(
            {
                "activity": path,
                "mode": "initiate and confirm" if confirm else "initiate",
                "arguments": _plain(args),
                "at_s": self.elapsed(),
            }
        )
        a = self.activities.get(path, {})
        n = self._counts.get(path, 0)
        self._counts[path] = n + 1
        if "confirmations" in a:
            seq = a["confirmations"]
            conf = seq[min(n, len(seq) - 1)] if seq else "confirmed"
        else:
            conf = a.get("confirmation", "confirmed")
        self._handles.append((self.now + a.get("duration_s", 0), conf))
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
        if path in self.parameters:
            p = self.parameters[path]
            if isinstance(p, dict):
                v = p["timeline"][0][1] if "timeline" in p else p.get("value")
                return ("parameter", p.get("type") or _code(v), p.get("unit"))
            return ("parameter", _code(p), None)
        if path in self.activities:
            return ("activity", None, None)
        if path in self.events:
            return ("event", None, None)
        return None

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
