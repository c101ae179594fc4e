"""Step-wise PLUTO interpreter: runs a checked procedure between statements, never blocking.

``run(now)`` executes until the procedure waits and returns a ``Wait`` (a deadline, the
activity handles it waits for, a question for the user), or None when it has finished or
is suspended. Time is passed in (seconds since the Unix epoch); nothing reads a clock.
"""

from obsw.pluto.checker import check
from obsw.pluto.evaluate import PlutoRuntimeError, _Ask
from obsw.pluto.parser import parse
from obsw.pluto.statements import (
    _PENDING,
    ABORTED,
    CONFIRMED,
    NOT_CONFIRMED,
    Statements,
    Wait,
    _Abort,
    _Terminate,
    _Timeout,
)
from obsw.pluto.units import AbsTime, UnitError, seconds

_DEFAULT = {CONFIRMED: ("continue", 0), NOT_CONFIRMED: ("abort", 0), ABORTED: ("abort", 0)}
_ACTIONS = ("resume", "abort", "restart", "continue", "terminate")


class Program:
    """A parsed and checked procedure, ready to be activated any number of times."""

    def __init__(self, source, resolver=None, arguments=None):
        self.source = source
        self.ast = parse(source)
        self.var_types, self.def_vars = check(self.ast, resolver, arguments)


def load(source, resolver=None, arguments=None):
    """Parse and check procedure text; raises PlutoSyntaxError, PlutoReferenceError or
    PlutoTypeError with line and column."""
    return Program(source, resolver, arguments)


class Procedure(Statements):
    """One activation of a Program against a System, with its own state."""

    def __init__(self, program, system, arguments=None, poll=1.0, trace=None):
        super().__init__(system, program.var_types, arguments)
        self.program = program
        self.poll = poll
        self.trace = trace  # called with each statement node before it runs
        self.state = "loaded"  # loaded, running, suspended, finished
        self.outcome = None  # confirmed, not confirmed, aborted
        self.error = None
        self.step_status = {}
        self.statements = 0
        self.evcounts = {}
        self.question = None
        self._answer = None
        self._gen = None
        self._pending = False
        self._suspend = False
        self._abort = None
        self._busy = False
        self.ts = [[], None]  # per-branch state: active timeouts, current step token

    def start(self, now):
        self.now = now
        self._gen = self._procedure()
        self.state = "running"

    def suspend(self):
        """Stop at the next statement boundary."""
        if self.state == "running":
            self._suspend = True

    def at_boundary(self):
        """True when running and held between two statements (``run`` ran out of budget),
        not inside a statement that waits."""
        return self.state == "running" and self._pending

    def hold(self):
        """Suspend now, at the statement boundary ``run`` stopped at (see ``at_boundary``)."""
        if self.at_boundary():
            self.state = "suspended"

    def resume(self):
        if self.state == "suspended":
            self.state = "running"
        self._suspend = False

    def abort(self, reason="aborted by request"):
        """End the procedure now (between statements), status aborted."""
        if self.state == "finished":
            return
        if self._busy:
            self._abort = reason
            return
        if self._gen is not None:
            self._gen.close()
        self._finish(ABORTED, reason)

    def answer(self, value):
        """Deliver the operator's answer to the pending question."""
        self._answer = value

    def step(self, now):
        """Execute at most one statement (and any wait that is already over)."""
        return self.run(now, 1)

    def run(self, now, budget=None):
        """Run until the procedure waits, ends, is suspended, or ``budget`` statements ran."""
        if self.state != "running":
            return None
        self.now = now
        n = 0
        gen = self._gen
        self._busy = True
        try:
            if self._pending:
                self._pending = False
                n = 1
                self._count()
            while True:
                w = gen.send(None)
                if w is not None:
                    return w
                if self._abort:
                    raise _Abort(self._abort)
                if self._suspend or (budget is not None and n >= budget):
                    self._pending = True
                    if self._suspend:
                        self._suspend = False
                        self.state = "suspended"
                        return None
                    return Wait(now)
                n += 1
                self._count()
        except StopIteration as e:
            self._finish(e.value)
        except _Abort as e:
            gen.close()
            self._finish(ABORTED, str(e))
        except (PlutoRuntimeError, UnitError, TypeError, ValueError, ArithmeticError, _Ask) as e:
            gen.close()
            self._finish(ABORTED, "runtime error at line %d: %s" % (self._line(), e))
        finally:
            self._busy = False
        return None

    def _count(self):
        self.statements += 1
        if self.trace:
            self.trace(self.cur)

    def _line(self):
        return self.cur[1] >> 12 if getattr(self, "cur", None) else 0

    def _finish(self, outcome, error=None):
        self.state = "finished"
        self.outcome = outcome
        self.error = error
        self.question = None  # outcome and error are the status; the log holds only what
        # log statements wrote

    def _procedure(self):
        d = self.program.ast
        self._declare(d)
        if not (yield from self._conditions(d[3])):
            raise _Abort("preconditions not met")
        ended = yield from self._main(d)
        if d[6]:
            ok = yield from self._conditions(d[6])
        else:
            ok = not ended
        return CONFIRMED if ok else NOT_CONFIRMED

    def _declare(self, d):
        for x in d[2]:
            if x[0] == "event":
                self.evcounts.setdefault(x[2], 0)
        for k in self.program.def_vars.get(id(d), ()):
            self.vars.pop(k, None)

    def _main(self, d):
        """Run a main body under its watchdog; True when a timeout ended it."""
        me = object()
        ts = self.ts
        outer = ts[1]
        ts[1] = me
        try:
            yield from self._guarded(d[4], d[5])
        except _Terminate:
            pass
        except _Timeout as t:
            if t.entry[2] is not me:
                raise
            return True
        finally:
            ts[1] = outer
        return False

    def _conditions(self, conds):
        for c in conds or ():
            if c[0] == "if":
                v = self._val(c[2])
                if v is _PENDING:
                    v = yield from self._ev(c[2])
                if not v:
                    return False
            else:
                try:
                    yield from self._wait(c, True)
                except _Timeout as t:
                    if t.entry[3] is not c:
                        raise
                    return False
        return True

    def _guarded(self, main, wd):
        g = self._block(main)
        if not wd:
            yield from g
            return
        arms = [[True, self.now, {}] for _ in wd]
        for i, w in enumerate(wd):
            self._rearm(w, arms[i])
        try:
            while True:
                for i, w in enumerate(wd):
                    if self._triggered(w, arms[i]):
                        yield from self._confirm(lambda w=w: self._step_body(w, True), w[4], w)
                try:
                    x = next(g)
                except StopIteration:
                    return
                if x is not None:
                    x.merge(Wait(self.now + self.poll))
                yield x
        finally:
            g.close()

    def _rearm(self, w, arm):
        arm[1] = self.now
        for c in w[3][3] or ():
            if c[0] == "wait" and c[2] == "event":
                arm[2][c[3][5]] = self._evcount(c[3][5])

    def _triggered(self, w, arm):
        ok = True
        for c in w[3][3] or ():
            if c[0] == "if":
                ok = self.eval(c[2])
            elif c[2] == "event":
                ok = self._evcount(c[3][5]) > arm[2].get(c[3][5], 0)
            elif c[2] == "for":
                ok = self.now >= arm[1] + seconds(self.eval(c[3]))
            else:
                v = self.eval(c[3])
                ok = self.now >= v.seconds if isinstance(v, AbsTime) else v
            if not ok:
                break
        if not ok:
            arm[0] = True
            return False
        if not arm[0]:
            return False
        arm[0] = False
        self._rearm(w, arm)
        return True

    def _step_body(self, s, watchdog=False):
        name, d = s[2], s[3]
        self.step_status[name] = "executing"
        st = ABORTED
        try:
            self._declare(d)
            if watchdog or (yield from self._conditions(d[3])):
                ended = yield from self._main(d)
                ok = (yield from self._conditions(d[6])) if d[6] else not ended
                st = CONFIRMED if ok else NOT_CONFIRMED
        finally:
            self.step_status[name] = st
        return st

    def _confirm(self, runner, cont, s):
        """Run an activity or step (``runner`` returns its status) under its continuation test."""
        tries = 0
        t0 = self.now
        while True:
            st = yield from runner()
            a = (cont or {}).get(st) or _DEFAULT[st]
            k = a[0]
            if k == "ask user":
                what = s[2] if s[0] == "step" else s[2][0][5]
                ans = yield from self._ask("%s %s: %s?" % (what, st, ", ".join(_ACTIONS)))
                k = str(ans).strip().lower()
                a = (k, a[1], None, None, None)
                if k not in _ACTIONS:
                    raise _Abort("%s %s, answer %r" % (what, st, ans))
            if k == "resume" or k == "continue":
                return st
            if k == "abort":
                raise _Abort("%s at line %d" % (st, s[1] >> 12))
            if k == "terminate":
                raise _Terminate()
            if k == "raise":
                self.raise_event(a[2])
                return st
            tries += 1  # restart
            ev = None
            over = False
            if a[2] is not None:
                over = self.now - t0 >= seconds(self.eval(a[2][0]))
                ev = a[2][1]
            if a[3] is not None:
                over = tries > self.eval(a[3])
                ev = a[4]
            if over:
                if ev is None:
                    raise _Abort("%s at line %d after %d restarts" % (st, s[1] >> 12, tries - 1))
                self.raise_event(ev)
                return st


def run_procedure(source, system, now=0, arguments=None, resolver=None):
    """Load, start and run a procedure once (a convenience for tests and the CLI)."""
    p = Procedure(load(source, resolver, arguments), system, arguments)
    p.start(now)
    return p, p.run(now)
