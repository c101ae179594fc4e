"""A PLUTO dry run: check a procedure and run it against a simulated system on a virtual clock.

``dry_run(source, spec, arguments, on_statement)`` returns a trace (dict): whether it loaded,
the activity calls, parameter reads, events, log lines, step status and the outcome. It is
what `obsw pluto run` prints, and a script can call it the same way.
"""

from obsw.pluto.interp import Procedure, load
from obsw.pluto.lexer import PlutoError, line_col
from obsw.pluto.system import SimulatedSystem, run_virtual

_KEYWORDS = {
    "set": "assignment",
    "if": "if",
    "case": "in case",
    "while": "while",
    "repeat": "repeat",
    "for": "for",
    "wait": "wait",
    "par": "in parallel",
    "log": "log",
    "inform": "inform user",
    "ctx": "in the context of",
    "save": "save context",
}


def describe(s):
    """One line naming a statement, for the statement-by-statement printout."""
    k = s[0]
    if k in ("conf", "init"):
        return ("initiate and confirm " if k == "conf" else "initiate ") + s[2][0][5]
    if k == "op":
        return "operation " + s[2][5]
    if k == "step":
        return "initiate and confirm step " + s[2]
    if k == "set":
        return "%s := ..." % s[2][2][-1]
    return _KEYWORDS.get(k, k)


def dry_run(source, spec=None, arguments=None, on_statement=None):
    """Check and run a procedure against a simulated system; returns the trace dict."""
    sim = SimulatedSystem(spec or {})
    trace = {
        "accept": False,
        "error": None,
        "activity_calls": [],
        "parameter_reads": [],
        "events_raised": [],
        "log": [],
        "user_messages": [],
        "user_prompts": [],
        "step_status": {},
        "status": None,
        "end_time_s": 0,
    }
    try:
        prog = load(source, sim if spec else None, arguments)
    except PlutoError as e:
        trace["error"] = {"kind": e.kind, "line": e.line, "message": e.msg}
        return trace
    trace["accept"] = True

    def show(s):
        if on_statement:
            on_statement(sim.elapsed(), line_col(s[1])[0], describe(s))

    proc = Procedure(prog, sim, arguments, trace=show)
    proc.start(sim.now)
    end = run_virtual(proc, sim)
    trace.update(
        activity_calls=sim.activity_calls,
        parameter_reads=sim.parameter_reads,
        events_raised=sim.events_raised,
        log=sim.logs,
        user_messages=sim.user_messages,
        user_prompts=sim.user_prompts,
        step_status=proc.step_status,
        status=proc.outcome,
        end_time_s=end - sim.start,
    )
    if proc.error:
        trace["runtime_error"] = proc.error
    return trace
