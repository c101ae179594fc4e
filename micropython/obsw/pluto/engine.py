"""The OBCP engine: loaded PLUTO procedures, several running at once, as an IL component.

Each loaded OBCP has a name, its source text and the checked program; activating it starts a
``Procedure`` against a system of its own (a fork of the engine's ``IlSystem``). The engine
never blocks: ``step(now)`` runs every procedure that is due for at most ``budget``
statements and returns ``next_deadline()``; a host runs it from a loop or an asyncio task
(``serve``), a board from its main loop. ``now`` is the procedure clock (seconds since the
Unix epoch: ``wait until`` takes absolute times).

States (as in PUS ST[18]): ``inactive`` (loaded), ``running``, ``suspended`` and ``stopping``
(running to the end of the step it is in). Requests take effect between statements:
``suspend`` at the next statement boundary, ``stop`` at the first boundary outside the steps
executing when it was asked, ``abort`` at once (activities waited for are abandoned).

Step by step (PUS TC[18,14] and TC[18,15]): ``activate_step`` starts an OBCP and
``resume_step`` continues a suspended one, each for one step: the OBCP runs until a step
(an outermost PLUTO ``step``: the one executing when resumed, else the next to begin) has
ended, then suspends at the next statement boundary. Statements outside steps run with the
step that follows them; with no step left the OBCP runs to its end. ``resume`` leaves step
by step mode and runs on.

The IL interface ``ENGINE``, the states, the refusal codes and ``Obcp`` (one loaded
procedure) live in ``obsw.pluto.obcp``; they are imported here too.
"""

from obsw.pluto.interp import Procedure
from obsw.pluto.interp import load as load_program
from obsw.pluto.lexer import PlutoError
from obsw.pluto.obcp import (
    ALREADY_LOADED,
    BAD_NAME,
    ENGINE,
    INACTIVE,
    LOAD_FAILED,
    NO_QUESTION,
    NO_ROOM,
    NOT_ACTIVE,
    NOT_INACTIVE,
    NOT_RUNNING,
    NOT_SUSPENDED,
    RUNNING,
    STOPPING,
    SUSPENDED,
    UNKNOWN_OBCP,
    Obcp,
    ObcpError,
    Steps,
    rejected,
    wire_arguments,
)
from obsw.pluto.statements import ABORTED, Wait

_OUTPUT_EVENTS = {"log": "log", "inform": "message", "ask": "question"}


class ObcpEngine:
    """Loads, runs and controls OBCPs (see the module text).

    ``system`` is an ``IlSystem`` (or any ``System``; one with ``fork`` gives each procedure
    its own outputs); it also answers the load-time checks unless ``check`` is False.
    ``capacity`` bounds the loaded OBCPs, ``budget`` the statements one procedure runs per
    ``step``, ``poll`` how often a waiting condition is re-evaluated (seconds), and
    ``max_source`` the characters of one procedure text.
    ``on_event(name, payload)`` sees every event (a PUS service 5 bridge), besides the
    interaction layer's subscribers once the engine is provided on a node.
    """

    def __init__(self, system, *, capacity=8, budget=100, poll=1.0, check=True, max_source=65536):
        self.system = system
        self.max_source = max_source
        self.capacity = capacity
        self.budget = budget
        self.poll = poll
        self.check = check
        self.on_event = None
        self.on_wake = None
        self.il = None
        self.now = 0
        self._obcps = {}
        self._order = []  # names in load order (dicts keep no order on MicroPython)
        if getattr(system, "on_wake", 0) is None:
            system.on_wake = self._wake

    def il_bind(self, provider):
        self.il = provider

    # -------------------------------------------------------------------------- attributes

    @property
    def obcps(self):
        """Names of the loaded OBCPs, in load order."""
        return list(self._order)

    @property
    def states(self):
        return {n: self._obcps[n].state for n in self._order}

    def list(self):
        """Status of every loaded OBCP."""
        return [self._obcps[n].status() for n in self._order]

    def status(self, name):
        return self._get(name).status()

    # -------------------------------------------------------------------------- requests

    def load(self, name, source, arguments=None):
        """Check ``source`` and keep it as OBCP ``name``, inactive. ``arguments`` are
        default procedure arguments (their names and types are checked with the text)."""
        if not isinstance(name, str) or not name or len(name) > 64:
            raise ObcpError(BAD_NAME, "OBCP name must be a text of 1 to 64 characters", name)
        if name in self._obcps:
            raise ObcpError(ALREADY_LOADED, "OBCP %s is already loaded" % name, name)
        if len(self._obcps) >= self.capacity:
            raise ObcpError(
                NO_ROOM, "%d OBCPs loaded, the engine holds %d" % (self.capacity, self.capacity)
            )
        if isinstance(source, (bytes, bytearray)):
            try:
                source = bytes(source).decode()
            except UnicodeError:
                raise rejected(name, PlutoError("procedure text is not UTF-8", 1, 1)) from None
        if not isinstance(source, str):
            raise rejected(name, PlutoError("procedure text must be text", 1, 1))
        if len(source) > self.max_source:
            raise rejected(
                name,
                PlutoError(
                    "procedure text of %d characters, at most %d" % (len(source), self.max_source),
                    1,
                    1,
                ),
            )
        arguments = wire_arguments(arguments)
        ob = Obcp(name, source, self._compile(name, source, arguments), arguments)
        self._obcps[name] = ob
        self._order.append(name)
        self._changed(ob, INACTIVE, True)

    def load_file(self, name, path, arguments=None):
        """``load`` from a procedure file on the file system."""
        try:
            with open(path) as f:
                source = f.read()
        except OSError as e:
            raise ObcpError(LOAD_FAILED, "cannot read %s: %s" % (path, e), path) from None
        self.load(name, source, arguments)

    def unload(self, name):
        ob = self._get(name)
        if ob.state != INACTIVE:
            raise ObcpError(NOT_INACTIVE, "OBCP %s is %s; stop it first" % (name, ob.state))
        del self._obcps[name]
        self._order.remove(name)
        self._changed(ob, "unloaded", True)

    def activate(self, name, arguments=None):
        """Start OBCP ``name``; it runs from the next ``step``."""
        ob = self._get(name)
        if ob.state != INACTIVE:
            raise ObcpError(NOT_INACTIVE, "OBCP %s is %s" % (name, ob.state))
        args = wire_arguments(arguments)
        program = ob.program
        if args:
            program = self._compile(name, ob.source, args)
        else:
            args = ob.arguments
        fork = getattr(self.system, "fork", None)
        if fork is not None:
            system = fork(lambda kind, text: self._output(ob, kind, text))
            system.on_wake = lambda: self._wake(ob)
        else:
            system = self.system
        proc = Procedure(program, system, args, poll=self.poll)
        proc.step_status = Steps(self, ob)
        proc.start(self.now)
        ob.proc = proc
        ob.activations += 1
        ob.outcome = ob.error = ob.requested = ob.stop_steps = None
        ob.stepping = ob.step_done = False
        ob.ready = True
        self._changed(ob, RUNNING)
        self._emit("started", {"obcp": name})
        self._wake(ob)

    def activate_step(self, name, arguments=None):
        """Start OBCP ``name`` step by step: it suspends once its first step has ended."""
        self.activate(name, arguments)
        self._obcps[name].stepping = True

    def resume_step(self, name):
        """Continue suspended OBCP ``name`` for one step, then suspend it again."""
        ob = self._get(name)
        if ob.state != SUSPENDED and ob.requested != "suspend":
            raise ObcpError(NOT_SUSPENDED, "OBCP %s is %s" % (name, ob.state))
        self.resume(name)
        ob.stepping = True
        ob.step_done = False

    def suspend(self, name):
        """Hold OBCP ``name`` at its next statement boundary."""
        ob = self._get(name)
        if ob.state != RUNNING:
            raise ObcpError(NOT_RUNNING, "OBCP %s is %s" % (name, ob.state))
        ob.proc.suspend()
        ob.requested = "suspend"
        self._wake(ob)

    def resume(self, name):
        ob = self._get(name)
        if ob.state != SUSPENDED and ob.requested != "suspend":
            raise ObcpError(NOT_SUSPENDED, "OBCP %s is %s" % (name, ob.state))
        ob.proc.resume()
        ob.requested = None
        ob.stepping = False
        if ob.state == SUSPENDED:
            self._changed(ob, RUNNING)
        self._wake(ob)

    def stop(self, name):
        """End OBCP ``name`` once the steps it executes now have ended (at once if none)."""
        ob = self._active(name)
        steps = [s for s, st in ob.proc.step_status.items() if st == "executing"]
        ob.requested = "stop"
        if not steps or ob.state == SUSPENDED:
            self._end(ob, "stopped by request")
            return
        ob.stop_steps = steps
        self._changed(ob, STOPPING)
        self._wake(ob)

    def abort(self, name, reason="aborted by request"):
        """End OBCP ``name`` now with status aborted."""
        ob = self._active(name)
        ob.requested = "abort"
        self._end(ob, reason)

    def abort_all(self, reason="aborted by request"):
        for ob in self._in_order():
            if ob.proc is not None:
                ob.requested = "abort"
                self._end(ob, reason)

    def answer(self, name, value):
        """Deliver the operator's answer to the question OBCP ``name`` waits on."""
        ob = self._active(name)
        if ob.proc.question is None:
            raise ObcpError(NO_QUESTION, "OBCP %s asks nothing" % name)
        ob.proc.answer(value)
        self._wake(ob)

    # -------------------------------------------------------------------------- running

    def step(self, now):
        """Run every OBCP that is due at ``now``; return ``next_deadline()``."""
        self.now = now
        for ob in self._in_order():
            if ob.proc is None or (ob.state != RUNNING and ob.state != STOPPING):
                continue
            if ob.ready or (ob.due is not None and ob.due <= now):
                self._run(ob, now)
        return self.next_deadline()

    def next_deadline(self):
        """When ``step`` has work next (a time not after the last ``now`` means at once), or
        None while every active OBCP waits for an answer, a wake-up or is suspended."""
        best = None
        for ob in self._obcps.values():
            if ob.proc is None or (ob.state != RUNNING and ob.state != STOPPING):
                continue
            d = self.now if ob.ready else ob.due
            if d is not None and (best is None or d < best):
                best = d
        return best

    def active(self):
        """Number of OBCPs running, stopping or suspended."""
        return len([1 for ob in self._obcps.values() if ob.proc is not None])

    async def serve(self, clock, idle=1.0):
        """Run from an asyncio task: ``clock()`` gives the procedure time; wakes on activity
        (an activation, an operation's outcome, an event) or at the next deadline."""
        import asyncio  # only here: boards without asyncio still import this module

        ev = asyncio.Event()
        self.on_wake = ev.set
        try:
            while True:
                ev.clear()
                d = self.step(clock())
                delay = idle if d is None else min(idle, d - clock())
                if delay > 0:
                    try:
                        await asyncio.wait_for(ev.wait(), delay)
                    except asyncio.TimeoutError:
                        pass
                else:
                    await asyncio.sleep(0)
        finally:
            self.on_wake = None

    def _run(self, ob, now):
        ob.ready = False
        proc = ob.proc
        try:
            if ob.stop_steps is not None:
                w = self._run_to_step_end(ob, now)
            elif ob.stepping:
                w = self._run_one_step(ob, now)
            else:
                w = proc.run(now, self.budget)
        except Exception as e:  # a fault in a system adapter ends this OBCP, not the engine
            proc.abort("internal error: %s: %s" % (type(e).__name__, e))
            w = None
        if ob.proc is not proc:
            return
        if proc.state == "finished":
            self._finished(ob)
        elif proc.state == "suspended":
            ob.due = None
            ob.requested = None
            self._changed(ob, SUSPENDED)
        else:
            ob.due = w.deadline if w is not None else now

    def _run_to_step_end(self, ob, now):
        proc = ob.proc
        status = proc.step_status
        for _ in range(self.budget):
            if not [s for s in ob.stop_steps if status.get(s) == "executing"]:
                proc.abort("stopped by request at the end of step %s" % ", ".join(ob.stop_steps))
                return None
            w = proc.run(now, 1)
            if proc.state != "running" or w is None:
                return w
            if w.activities or w.prompt or w.deadline is None or w.deadline > now:
                return w  # a real wait, not the end of the one-statement budget
        return Wait(now)

    def _run_one_step(self, ob, now):
        proc = ob.proc
        for _ in range(self.budget):
            w = proc.run(now, 1)
            if proc.state != "running" or w is None:
                return w
            if ob.step_done and proc.at_boundary():
                ob.step_done = False
                proc.hold()
                return None
            if w.activities or w.prompt or w.deadline is None or w.deadline > now:
                return w  # a real wait, not the end of the one-statement budget
        return Wait(now)

    def _end(self, ob, reason):
        ob.proc.abort(reason)
        if ob.proc.state == "finished":
            self._finished(ob)

    def _finished(self, ob):
        proc = ob.proc
        ob.proc = None
        ob.outcome = proc.outcome
        ob.error = proc.error
        ob.steps = proc.step_status.copy()
        ob.statements = proc.statements
        ob.due = None
        ob.ready = False
        ob.stop_steps = None
        by_request = ob.requested in ("stop", "abort")
        ob.requested = None
        self._emit("finished", {"obcp": ob.name, "outcome": ob.outcome, "error": ob.error})
        if ob.outcome == ABORTED and not by_request:
            self._emit("failed", {"obcp": ob.name, "error": ob.error or "aborted"})
        self._changed(ob, INACTIVE)

    # -------------------------------------------------------------------------- helpers

    def _compile(self, name, source, arguments):
        try:
            return load_program(source, self.system if self.check else None, arguments)
        except PlutoError as e:
            raise rejected(name, e) from None
        except Exception as e:  # a checker defect refuses this text, it never stops the engine
            raise rejected(name, PlutoError("%s: %s" % (type(e).__name__, e), 0, 0)) from None

    def _in_order(self):
        return [self._obcps[n] for n in self._order]

    def _get(self, name):
        ob = self._obcps.get(name)
        if ob is None:
            raise ObcpError(UNKNOWN_OBCP, "no OBCP %s loaded" % (name,), name)
        return ob

    def _active(self, name):
        ob = self._get(name)
        if ob.proc is None:
            raise ObcpError(NOT_ACTIVE, "OBCP %s is %s" % (name, ob.state))
        return ob

    def _changed(self, ob, state, listing=False):
        ob.state = state
        self._emit("state_changed", {"obcp": ob.name, "state": state})
        il = self.il
        if il is not None:
            if listing:
                il.node.publish(il.name, "obcps", self.obcps)
            il.node.publish(il.name, "states", self.states)

    def _output(self, ob, kind, text):
        if kind == "raise":
            self._emit("raised", {"obcp": ob.name, "event": text})
        else:
            self._emit(_OUTPUT_EVENTS.get(kind, "log"), {"obcp": ob.name, "text": text})

    def _emit(self, event, payload):
        if self.il is not None:
            self.il.emit(event, payload)
        if self.on_event is not None:
            self.on_event(event, payload)

    def _wake(self, ob=None):
        if ob is None:
            for x in self._obcps.values():
                if x.proc is not None:
                    x.ready = True
        elif ob.proc is not None:
            ob.ready = True
        if self.on_wake is not None:
            self.on_wake()


def provide(node, sdb=None, interfaces=(), *, timeout=1.0, activity_timeout=30.0, **options):
    """An engine on ``node`` with an ``IlSystem``, provided as component ``ENGINE``;
    returns the engine (``options`` go to ``ObcpEngine``)."""
    from obsw.pluto.il_system import IlSystem

    system = IlSystem(
        node,
        sdb,
        interfaces,
        timeout=timeout,
        activity_timeout=activity_timeout,
        user=ENGINE.name,
    )
    engine = ObcpEngine(system, **options)
    node.provide(ENGINE, engine)
    return engine
