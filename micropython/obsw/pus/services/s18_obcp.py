"""ST[18] on-board operations procedures: OBCPs loaded, run and controlled from the ground.

The provider stands on the OBCP engine (``obsw.pluto.engine.ObcpEngine``) and calls it
directly: each request is one call of an engine operation of the same name (``load``,
``unload``, ``activate``, ``stop``, ``suspend``, ``resume``, ``abort``, ``answer``,
``status``), so an interaction layer proxy of ``ENGINE`` (an engine in another process)
serves as well, with ``drive=False`` and the engine's events bridged by the caller through
``engine_event``. A request the engine refuses fails its start: an unknown OBCP with
FAILURE_UNKNOWN_ID (the OBCP ID in the data), a procedure text that does not load with
FAILURE_OBCP_REJECTED (kind, line, column and message), a request the OBCP's state forbids
with FAILURE_REFUSED (the reason and the OBCP ID).

Requests: load directly (TC[18,1], the procedure text in the TC) or by reference (TC[18,13],
a file of the on-board filestore), both with the procedure's arguments and their default
values (``s18_layouts``), unload (2), activate with arguments and an observability
level (3), stop at the end of the current step (4), suspend (5), resume (6), communicate
parameters (7: the answer to the question an OBCP waits on), report the status of each OBCP
(8, answered by TM[18,9]), abort (12), set observability levels (16), abort all and report
(17, answered by TM[18,18] with the OBCPs aborted), load by reference and activate (19), stop
and unload (20), start and stop the engine (21, 22; stopping aborts every active OBCP, and
nothing is activated or resumed until it starts again), and execution one step at a time:
activate and execute one OBCP step (14: activate with arguments and an observability level
as TC[18,3]; the OBCP suspends once its first step has ended) and resume and execute one
OBCP step (15: a suspended OBCP runs its next step, or finishes the step it was suspended
in, then suspends again). A step is an outermost PLUTO step; TC[18,6] resume leaves step by
step mode (``obsw.pluto.engine``).

The engine's events become service 5 events with the IDs and auxiliary data of the
spacecraft database entries ``obcp.<event>`` (``sdb_events``), filtered by the OBCP's
observability level (``LEVEL_*``). ``cyclic`` steps the engine once per cycle of the
application process, on the procedure clock ``clock()`` (seconds since the Unix epoch).
"""

from obsw.il.errors import ComponentError, InteractionError
from obsw.pluto.obcp import ENGINE, INACTIVE, UNKNOWN_OBCP, wire_arguments
from obsw.pus.messages import (
    FAILURE_FILESTORE,
    FAILURE_PATH,
    SERVICE_OBCP,
    TC_OBCP_ABORT,
    TC_OBCP_ABORT_ALL,
    TC_OBCP_ACTIVATE,
    TC_OBCP_ACTIVATE_AND_STEP,
    TC_OBCP_COMMUNICATE_PARAMETERS,
    TC_OBCP_LOAD_AND_ACTIVATE,
    TC_OBCP_LOAD_BY_REFERENCE,
    TC_OBCP_LOAD_DIRECT,
    TC_OBCP_REPORT_STATUS,
    TC_OBCP_RESUME,
    TC_OBCP_RESUME_AND_STEP,
    TC_OBCP_SET_OBSERVABILITY,
    TC_OBCP_START_ENGINE,
    TC_OBCP_STOP,
    TC_OBCP_STOP_AND_UNLOAD,
    TC_OBCP_STOP_ENGINE,
    TC_OBCP_SUSPEND,
    TC_OBCP_UNLOAD,
    TM_OBCP_ABORTED_REPORT,
    TM_OBCP_STATUS_REPORT,
)
from obsw.pus.services import s18_layouts as lay
from obsw.pus.services.base import Service
from obsw.pus.services.s01_verification import PusFailure, app_data_error
from obsw.pus.services.s18_user import ObcpUser  # noqa: F401  (the user, importable here too)
from obsw.pus.structure import Structure

_STATUS = {"inactive": 0, "running": 1, "suspended": 2, "stopping": 3}
_OUTCOME = {None: 0, "confirmed": 1, "not confirmed": 2, "aborted": 3}


class _Event:
    def __init__(self, id, severity, names):
        self.id = id
        self.severity = severity
        self.layout = Structure([(n, lay.MESSAGE) for n in names])

    def pack(self, payload):
        return self.layout.pack(payload)


class ObcpManagement(Service):
    """The service 18 provider (see the module text).

    ``engine`` is an ``ObcpEngine`` (or a proxy of ``ENGINE``); ``filestore`` has
    ``read_bytes(path)`` (an ``obsw.cfdp.filestore.Filestore``) for loads by reference;
    ``events(key)`` gives the database's event definition for ``"obcp.<event>"`` (e.g.
    ``Sdb.event``; default: the IDs of ``sdb_events``); ``level`` is the observability level
    of OBCPs activated without one; ``drive`` makes ``cyclic`` step the engine; ``clock()``
    is the procedure clock (default: the application process's clock); ``detail`` adds
    outcome, level, activations, statements, line and executing steps to TM[18,9].
    """

    SERVICE = SERVICE_OBCP
    REPORTS = (TM_OBCP_STATUS_REPORT, TM_OBCP_ABORTED_REPORT)
    HANDLERS = (
        (TC_OBCP_LOAD_DIRECT, "load_direct"),
        (TC_OBCP_UNLOAD, "unload"),
        (TC_OBCP_ACTIVATE, "activate"),
        (TC_OBCP_STOP, "stop"),
        (TC_OBCP_SUSPEND, "suspend"),
        (TC_OBCP_RESUME, "resume"),
        (TC_OBCP_COMMUNICATE_PARAMETERS, "communicate"),
        (TC_OBCP_REPORT_STATUS, "report_status"),
        (TC_OBCP_ABORT, "abort"),
        (TC_OBCP_LOAD_BY_REFERENCE, "load_by_reference"),
        (TC_OBCP_ACTIVATE_AND_STEP, "activate_and_step"),
        (TC_OBCP_RESUME_AND_STEP, "resume_and_step"),
        (TC_OBCP_SET_OBSERVABILITY, "set_observability"),
        (TC_OBCP_ABORT_ALL, "abort_all"),
        (TC_OBCP_LOAD_AND_ACTIVATE, "load_and_activate"),
        (TC_OBCP_STOP_AND_UNLOAD, "stop_and_unload"),
        (TC_OBCP_START_ENGINE, "start_engine"),
        (TC_OBCP_STOP_ENGINE, "stop_engine"),
    )

    def __init__(
        self,
        engine,
        *,
        filestore=None,
        events=None,
        level=lay.LEVEL_STEP,
        drive=True,
        clock=None,
        detail=True,
    ):
        super().__init__()
        self.engine = engine
        self.filestore = filestore
        self.lookup = events
        self.level = level
        self.drive = drive
        self.clock = clock
        self.detail = detail
        self.running = True  # the engine is started (TC[18,21] / TC[18,22])
        self.levels = {}  # OBCP ID -> observability level
        self.unload_after = []  # OBCPs to unload once they have stopped (TC[18,20])
        self.events_sent = 0
        self.events_filtered = 0
        self._defs = {}

    def attach(self, app):
        super().attach(app)
        if self.drive:
            self.engine.on_event = self.engine_event

    # -------------------------------------------------------------------------- engine side

    def cyclic(self, now):
        if self.drive and self.running:
            self.engine.step(self.clock() if self.clock is not None else now)
        if self.unload_after:
            states = self.engine.states
            for name in list(self.unload_after):
                st = states.get(name)
                if st is None or st == INACTIVE:
                    self.unload_after.remove(name)
                    if st is not None:
                        try:
                            self._engine("unload", name)
                        except PusFailure:
                            pass  # unloaded or reloaded meanwhile by another request
                        self.levels.pop(name, None)

    def engine_event(self, name, payload):
        """One event of the engine (``name``, ``payload``): a service 5 event, if the OBCP's
        observability level asks for it."""
        obcp = payload.get("obcp") if isinstance(payload, dict) else None
        need = lay.EVENT_LEVELS.get(name, lay.LEVEL_STATEMENT)
        if need > self.levels.get(obcp, self.level):
            self.events_filtered += 1
            return
        ev = self._event_def(name)
        if ev is None or self.app is None:
            return
        values = {}
        for k, v in payload.items():
            values[k] = "" if v is None else (v if isinstance(v, str) else str(v))
        try:
            aux = ev.pack(values)
        except (ValueError, KeyError, TypeError):
            aux = b""
        self.events_sent += 1
        self.app.event(ev.id, ev.severity, aux)

    def _event_def(self, name):
        ev = self._defs.get(name)
        if ev is None:
            if self.lookup is not None:
                try:
                    ev = self.lookup("obcp." + name)
                except KeyError:
                    ev = None
            if ev is None:
                for e in ENGINE.events:
                    if e.name == name:
                        ev = _Event(lay.EVENT_BASE + e.id, e.severity, e.fields)
            if ev is None:
                return None
            self._defs[name] = ev
        return ev

    def _engine(self, op, name, *args):
        try:
            return getattr(self.engine, op)(name, *args)
        except InteractionError as e:
            raise lay.failure_of(name, e) from None

    def _started(self, name):
        if not self.running:
            raise lay.refusal("ENGINE_STOPPED", name, "the OBCP engine is stopped")

    def _level(self, level):
        if not 0 <= level < len(lay.LEVEL_NAMES):
            raise app_data_error("observability level %d, expected 0 to 3" % level)
        return level

    def _read(self, repository, file):
        path = repository.rstrip("/") + "/" + file if repository else file
        if not file or ".." in path.split("/"):
            raise PusFailure(FAILURE_PATH, "bad procedure path %r" % path, lay.PATH.pack(path))
        if self.filestore is None:
            raise PusFailure(FAILURE_FILESTORE, "no filestore", lay.PATH.pack(path))
        try:
            data = self.filestore.read_bytes(path)
        except OSError as e:
            raise PusFailure(FAILURE_FILESTORE, str(e), lay.PATH.pack(path)) from None
        return self._text(data)

    def _text(self, code):
        try:
            return bytes(code).decode("utf-8")
        except UnicodeError:
            raise lay.rejection("other", 0, 0, "procedure text is not UTF-8") from None

    def _activate(self, name, level, arguments, op="activate"):
        self._started(name)
        level = self._level(level)
        before = self.levels.get(name)
        self.levels[name] = level  # before the call: the started event is filtered by it
        try:
            self._engine(op, name, lay.decode_arguments(arguments) or None)
        except PusFailure:
            if before is None:
                self.levels.pop(name, None)
            else:
                self.levels[name] = before
            raise

    # -------------------------------------------------------------------------- requests

    def _load(self, name, source, args):
        args = lay.decode_arguments(args)
        if args:
            self._engine("load", name, source, args)
        else:  # an IL proxy's load takes (name, source)
            self._engine("load", name, source)

    def load_direct(self, req):
        v = req.decode(lay.LOAD)
        self._load(v["id"], self._text(v["code"]), v["args"])

    def load_by_reference(self, req):
        v = req.decode(lay.LOAD_BY_REFERENCE)
        self._load(v["id"], self._read(v["repository"], v["file"]), v["args"])

    def load_and_activate(self, req):
        v = req.decode(lay.LOAD_AND_ACTIVATE)
        name = v["id"]
        self._started(name)
        self._level(v["level"])
        self._load(name, self._read(v["repository"], v["file"]), v["args"])
        try:
            self._activate(name, v["level"], v["args"])
        except PusFailure:
            self._engine("unload", name)  # all or nothing
            raise

    def unload(self, req):
        name = req.decode(lay.ID)["id"]
        self._engine("unload", name)
        self.levels.pop(name, None)

    def activate(self, req):
        v = req.decode(lay.ACTIVATE)
        self._activate(v["id"], v["level"], v["args"])

    def activate_and_step(self, req):
        v = req.decode(lay.ACTIVATE)
        self._activate(v["id"], v["level"], v["args"], "activate_step")

    def resume_and_step(self, req):
        name = req.decode(lay.ID)["id"]
        self._started(name)
        self._engine("resume_step", name)

    def stop(self, req):
        self._engine("stop", req.decode(lay.ID)["id"])

    def suspend(self, req):
        self._engine("suspend", req.decode(lay.ID)["id"])

    def resume(self, req):
        name = req.decode(lay.ID)["id"]
        self._started(name)
        self._engine("resume", name)

    def abort(self, req):
        self._engine("abort", req.decode(lay.ID)["id"])

    def communicate(self, req):
        v = req.decode(lay.COMMUNICATE)
        args = v["args"]
        if len(args) != 1:
            raise app_data_error("one value (the answer) expected, got %d" % len(args))
        value = lay.decode_arguments(args)
        self._engine("answer", v["id"], wire_arguments(value)[args[0]["name"]])

    def stop_and_unload(self, req):
        name = req.decode(lay.ID)["id"]
        state = self.engine.states.get(name)
        if state is None:
            raise lay.failure_of(name, ComponentError(UNKNOWN_OBCP, "no OBCP %s loaded" % name))
        if state != INACTIVE:
            self._engine("stop", name)
            if self.engine.states.get(name) != INACTIVE:
                self.unload_after.append(name)  # once the current step has ended
                return
        self._engine("unload", name)
        self.levels.pop(name, None)

    def set_observability(self, req):
        items = req.decode(lay.LEVELS)["items"]
        known = self.engine.obcps
        for i in items:
            if i["id"] not in known:
                raise lay.failure_of(i["id"], ComponentError(UNKNOWN_OBCP, "no OBCP %s" % i["id"]))
            self._level(i["level"])
        for i in items:
            self.levels[i["id"]] = i["level"]

    def abort_all(self, req):
        req.decode(lay.EMPTY)
        req.start()
        ids = self._abort_all()
        req.report(TM_OBCP_ABORTED_REPORT, lay.ABORTED.pack({"ids": ids}))

    def _abort_all(self):
        ids = []
        states = self.engine.states
        for name in self.engine.obcps:
            if states.get(name, INACTIVE) != INACTIVE:
                try:
                    self.engine.abort(name)
                except ComponentError:
                    continue  # it ended meanwhile
                ids.append(name)
        return ids

    def report_status(self, req):
        req.decode(lay.EMPTY)
        req.start()
        items = []
        for name in self.engine.obcps:
            try:
                st = self.engine.status(name)
            except ComponentError:
                continue  # unloaded meanwhile
            items.append(self._status_item(st))
        layout = lay.STATUS_DETAIL if self.detail else lay.STATUS
        req.report(TM_OBCP_STATUS_REPORT, layout.pack({"items": items}))

    def _status_item(self, st):
        name = st["name"]
        steps = st.get("steps") or {}
        executing = sorted([s for s, x in steps.items() if x == "executing"])
        return {
            "id": name,
            "status": _STATUS.get(st["state"], 0),
            "outcome": _OUTCOME.get(st.get("outcome"), 0),
            "level": self.levels.get(name, self.level),
            "activations": min(st.get("activations", 0), 0xFFFF),
            "statements": min(st.get("statements", 0), 0xFFFFFFFF),
            "line": min(st.get("line", 0), 0xFFFF),
            "step": ",".join(executing)[:255],
        }

    def start_engine(self, req):
        req.decode(lay.EMPTY)
        self.running = True

    def stop_engine(self, req):
        req.decode(lay.EMPTY)
        req.start()
        self.running = False
        self._abort_all()
