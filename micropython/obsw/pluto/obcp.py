"""OBCPs as the engine keeps them: states, refusal codes, the engine's IL interface.

``ENGINE`` declares the OBCP engine component (``obsw.pluto.engine.ObcpEngine``): the
operations (load, unload, activate, stop, suspend, resume, abort, answer, status, and
activate_step and resume_step for execution one step at a time), the attributes ``obcps``
and ``states`` and the events (progress, outcome, failures, log lines and user messages,
each with the OBCP's name). Operations refuse with ``ObcpError`` (a
``ComponentError`` whose ``code`` is one of the reason names below). ``Obcp`` is one loaded
procedure with its state; its ``status()`` is the plain data of a PUS ST[18] status report.
"""

from obsw.il.errors import ComponentError
from obsw.il.interface import DATA, INFO, LOW, MEDIUM, Attribute, Event, Interface, Operation
from obsw.pluto.lexer import line_col
from obsw.pluto.units import Quantity

INACTIVE = "inactive"
RUNNING = "running"
SUSPENDED = "suspended"
STOPPING = "stopping"

# why a request was refused (ObcpError.code)
UNKNOWN_OBCP = "UNKNOWN_OBCP"
ALREADY_LOADED = "ALREADY_LOADED"
LOAD_FAILED = "LOAD_FAILED"
BAD_NAME = "BAD_NAME"
NO_ROOM = "NO_ROOM"
NOT_INACTIVE = "NOT_INACTIVE"
NOT_ACTIVE = "NOT_ACTIVE"
NOT_RUNNING = "NOT_RUNNING"
NOT_SUSPENDED = "NOT_SUSPENDED"
NO_QUESTION = "NO_QUESTION"

ENGINE = Interface(
    "ObcpEngine",
    0x18,
    [
        Attribute("obcps", 1, DATA, type="list", description="names of the loaded OBCPs"),
        Attribute("states", 2, DATA, type="map", description="state of each loaded OBCP"),
        Operation("load", 3, ("name", "source"), description="check and keep a procedure"),
        Operation("unload", 4, ("name",), description="forget an inactive OBCP"),
        Operation("activate", 5, ("name", "arguments"), description="start an OBCP"),
        Operation("stop", 6, ("name",), description="end at the end of the current step"),
        Operation("suspend", 7, ("name",), description="hold at the next statement"),
        Operation("resume", 8, ("name",), description="continue a suspended OBCP"),
        Operation("abort", 9, ("name",), description="end now, status aborted"),
        Operation("answer", 10, ("name", "value"), description="answer an ask user"),
        Operation("status", 11, ("name",), returns="map", description="one OBCP's status"),
        Operation("activate_step", 12, ("name", "arguments"), description="start, one step"),
        Operation("resume_step", 13, ("name",), description="continue for one step"),
        Event("state_changed", 16, INFO, fields=("obcp", "state")),
        Event("started", 17, INFO, fields=("obcp",)),
        Event("step_status", 18, INFO, fields=("obcp", "step", "status")),
        Event("finished", 19, INFO, fields=("obcp", "outcome", "error")),
        Event("failed", 20, MEDIUM, fields=("obcp", "error")),
        Event("log", 21, INFO, fields=("obcp", "text")),
        Event("message", 22, INFO, fields=("obcp", "text")),
        Event("raised", 23, LOW, fields=("obcp", "event")),
        Event("question", 24, INFO, fields=("obcp", "text")),
    ],
    description="runs PLUTO on-board control procedures",
)


class ObcpError(ComponentError):
    """A request the engine refuses; ``code`` is one of the module's reason names."""

    def __init__(self, code, message, data=None):
        super().__init__(code, message, data, ENGINE.name)


class Steps:
    """A procedure's step statuses that report every change (the engine's progress events)."""

    def __init__(self, engine, ob):
        self._d = {}
        self._engine = engine
        self._ob = ob

    def __setitem__(self, step, status):
        d = self._d
        d[step] = status
        ob = self._ob
        if ob.stepping and status != "executing":
            for x in d.values():
                if x == "executing":
                    break
            else:
                ob.step_done = True  # an outermost step has ended: hold at the next boundary
        self._engine._emit("step_status", {"obcp": self._ob.name, "step": step, "status": status})

    def __getitem__(self, step):
        return self._d[step]

    def __contains__(self, step):
        return step in self._d

    def __len__(self):
        return len(self._d)

    def get(self, step, default=None):
        return self._d.get(step, default)

    def items(self):
        return self._d.items()

    def copy(self):
        return dict(self._d)


class Obcp:
    """One loaded procedure and, while active, its running ``Procedure``."""

    def __init__(self, name, source, program, arguments):
        self.name = name
        self.source = source
        self.program = program
        self.arguments = arguments
        self.state = INACTIVE
        self.proc = None
        self.outcome = None  # of the last activation
        self.error = None
        self.steps = {}
        self.statements = 0
        self.activations = 0
        self.requested = None  # "suspend", "stop" or "abort" while it takes effect
        self.stop_steps = None
        self.stepping = False  # step by step: hold once the step being run has ended
        self.step_done = False
        self.ready = False
        self.due = None

    def status(self):
        """The OBCP's status as plain data (the PUS ST[18] status report's content)."""
        proc = self.proc
        line = 0
        question = None
        steps = self.steps
        statements = self.statements
        if proc is not None:
            cur = getattr(proc, "cur", None)
            line = line_col(cur[1])[0] if cur else 0
            question = proc.question
            steps = proc.step_status.copy()
            statements = proc.statements
        return {
            "name": self.name,
            "state": self.state,
            "outcome": self.outcome,
            "error": self.error,
            "steps": steps,
            "statements": statements,
            "line": line,
            "question": question,
            "activations": self.activations,
            "requested": self.requested,
            "stepping": self.stepping,
        }


def wire_arguments(arguments):
    """Procedure arguments from the wire: ``{"value": v, "unit": u}`` becomes a Quantity."""
    if not arguments:
        return None
    if not isinstance(arguments, dict):
        raise ObcpError(LOAD_FAILED, "arguments must be a map of name to value", arguments)
    out = {}
    for k, v in arguments.items():
        if isinstance(v, dict) and "value" in v and "unit" in v:
            v = Quantity(v["value"], v["unit"])
        out[k] = v
    return out


def rejected(name, error):
    """The ObcpError for procedure text ``name`` that did not load (a ``PlutoError``): its
    data gives the kind, line, column and message of the first error and lists them all."""
    errors = getattr(error, "errors", None) or [error]
    return ObcpError(
        LOAD_FAILED,
        "OBCP %s rejected: line %d, column %d: %s" % (name, error.line, error.col, error.msg),
        {
            "kind": error.kind,
            "line": error.line,
            "column": error.col,
            "message": error.msg,
            "errors": [[x.kind, x.line, x.col, x.msg] for x in errors],
        },
    )
