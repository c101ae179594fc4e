"""OBCPs from the ground: PUS service 18 requests through a ``Ground`` and their results.

    from obsw_host.pus.ground import Ground
    from obsw_host.pus.obcp_ground import ObcpGround
    with Ground(sdb, target=(host, port)) as ground:
        obcp = ObcpGround(ground)
        obcp.load("turn", open("turn.plt").read())      # TC[18,1]; a Transaction
        obcp.activate("turn", level=3)                 # TC[18,3]
        obcp.activate_and_step("turn")                 # TC[18,14] (when inactive): one step
        obcp.resume_and_step("turn")                   # TC[18,15]: the next step
        obcp.status()                                  # {'turn': {'status': 'running', ..}}
        for e in obcp.events(timeout=5.0): ...         # the OBCP's service 5 events

Each request waits (driving the ground socket) for its completion or failure report;
``explain(tx)`` says why a request failed (``obsw.pus.services.s18_user.failure_info``).
"""

from obsw.il.clock import REAL_CLOCK
from obsw.pus.messages import FAILURE_OBCP_REJECTED
from obsw.pus.services.s01_verification import describe
from obsw.pus.services.s18_layouts import LEVEL_STEP
from obsw.pus.services.s18_user import ObcpUser, failure_info


class ObcpGround:
    """Service 18 calls on a ``Ground`` (its user process gets an ``ObcpUser``)."""

    def __init__(self, ground, detail=True):
        self.ground = ground
        user = ground.proc.users.get(18)
        if not isinstance(user, ObcpUser):
            user = ground.proc.register(ObcpUser(detail))
        self.user = user
        self._seen = len(ground.received)

    def _apid(self, apid):
        return self.ground.apid if apid is None else apid

    def issue(self, tx, timeout=None):
        g = self.ground
        if g.log is not None:
            g.log("TC[%d,%d] seq %d" % (tx.tc.service, tx.tc.subtype, tx.tc.seq_count))
        return g.wait(tx, timeout)

    # -------------------------------------------------------------------------- requests

    def load(self, name, source, arguments=None, apid=None, timeout=None):
        """TC[18,1]: upload procedure text ``source`` as OBCP ``name``."""
        return self.issue(self.user.load(self._apid(apid), name, source, arguments), timeout)

    def load_file(self, name, path, arguments=None, apid=None, timeout=None):
        """TC[18,1] with the text of the local file ``path``."""
        with open(path) as f:
            return self.load(name, f.read(), arguments, apid, timeout)

    def load_by_reference(self, name, repository, file, arguments=None, apid=None, timeout=None):
        """TC[18,13]: load ``repository/file`` of the on-board filestore."""
        tx = self.user.load_by_reference(self._apid(apid), name, repository, file, arguments)
        return self.issue(tx, timeout)

    def load_and_activate(
        self, name, repository, file, arguments=None, level=LEVEL_STEP, apid=None, timeout=None
    ):
        """TC[18,19]: load by reference and activate."""
        tx = self.user.load_and_activate(
            self._apid(apid), name, repository, file, arguments, level
        )
        return self.issue(tx, timeout)

    def activate(self, name, arguments=None, level=LEVEL_STEP, apid=None, timeout=None):
        """TC[18,3]; ``arguments`` maps names to values or ``{"value": v, "unit": u}``."""
        tx = self.user.activate(self._apid(apid), name, arguments, level)
        return self.issue(tx, timeout)

    def activate_and_step(self, name, arguments=None, level=LEVEL_STEP, apid=None, timeout=None):
        """TC[18,14]: activate; the OBCP suspends once its first step has ended."""
        tx = self.user.activate_and_step(self._apid(apid), name, arguments, level)
        return self.issue(tx, timeout)

    def resume_and_step(self, name, apid=None, timeout=None):
        """TC[18,15]: a suspended OBCP runs its next step, then suspends again."""
        return self.issue(self.user.resume_and_step(self._apid(apid), name), timeout)

    def unload(self, name, apid=None, timeout=None):
        return self.issue(self.user.unload(self._apid(apid), name), timeout)

    def stop(self, name, apid=None, timeout=None):
        return self.issue(self.user.stop(self._apid(apid), name), timeout)

    def suspend(self, name, apid=None, timeout=None):
        return self.issue(self.user.suspend(self._apid(apid), name), timeout)

    def resume(self, name, apid=None, timeout=None):
        return self.issue(self.user.resume(self._apid(apid), name), timeout)

    def abort(self, name, apid=None, timeout=None):
        return self.issue(self.user.abort(self._apid(apid), name), timeout)

    def stop_and_unload(self, name, apid=None, timeout=None):
        return self.issue(self.user.stop_and_unload(self._apid(apid), name), timeout)

    def answer(self, name, value, apid=None, timeout=None):
        """TC[18,7]: the answer to the question OBCP ``name`` asks."""
        return self.issue(self.user.answer(self._apid(apid), name, value), timeout)

    def set_observability(self, levels, apid=None, timeout=None):
        return self.issue(self.user.set_observability(self._apid(apid), levels), timeout)

    def abort_all(self, apid=None, timeout=None):
        """TC[18,17]; ``tx.reply["ids"]`` names the OBCPs aborted."""
        return self.issue(self.user.abort_all(self._apid(apid)), timeout)

    def start_engine(self, apid=None, timeout=None):
        return self.issue(self.user.start_engine(self._apid(apid)), timeout)

    def stop_engine(self, apid=None, timeout=None):
        return self.issue(self.user.stop_engine(self._apid(apid)), timeout)

    def report_status(self, apid=None, timeout=None):
        """TC[18,8]; ``tx.reply["obcps"]`` is the decoded TM[18,9]."""
        return self.issue(self.user.report_status(self._apid(apid)), timeout)

    def status(self, apid=None, timeout=None):
        """The loaded OBCPs and their status by name (TC[18,8] and TM[18,9])."""
        tx = self.report_status(apid, timeout)
        if not tx.ok or tx.reply is None:
            raise RuntimeError("no OBCP status report: %s" % "; ".join(explain(tx)))
        return {o["id"]: o for o in tx.reply["obcps"]}

    def held(self, name, apid=None, timeout=10.0, period=0.1):
        """Wait until OBCP ``name`` holds (suspended) or has ended (inactive), as after a step
        request: the request's completion report comes as soon as the step starts. Its status
        (TM[18,9]), or None if it still runs after ``timeout`` seconds."""
        end = REAL_CLOCK.now() + timeout
        while True:
            o = self.status(apid).get(name)
            if o is None or o["status"] in ("suspended", "inactive"):
                return o
            if REAL_CLOCK.now() > end:
                return None
            REAL_CLOCK.sleep(period)

    # -------------------------------------------------------------------------- events

    def events(self, timeout=0.0, until=None):
        """OBCP events (decoded service 5 reports named ``obcp.*``) that came since the last
        call, as ``(name, data)``; waits up to ``timeout`` seconds for the first, or, with
        ``until(name, data)``, until it returns True (the events up to that one)."""
        g = self.ground
        deadline = REAL_CLOCK.now() + timeout
        out = []
        while True:
            while self._seen < len(g.received):
                tm, decoded = g.received[self._seen]
                self._seen += 1
                if tm.service != 5 or not decoded or "event" not in decoded:
                    continue
                name = decoded["event"]
                if not name.startswith("obcp."):
                    continue
                out.append((name[5:], decoded["data"]))
                if until is not None and until(name[5:], decoded["data"]):
                    return out
            left = deadline - REAL_CLOCK.now()
            if left <= 0 or (out and until is None):
                return out
            g.poll(min(left, 0.05))


def explain(tx):
    """The verification reports of ``tx`` as text, a failure's data explained."""
    lines = []
    for r in tx.reports:
        line = describe(r)
        if not r["success"]:
            info = failure_info(r)
            if info is not None:
                line = "%s: %s" % (line.split(" data ")[0], _info(info))
                if r["code"] == FAILURE_OBCP_REJECTED:  # a code s01's names do not list
                    line = line.replace("mission code", "OBCP rejected")
        lines.append(line)
    if not tx.done:
        lines.append("no completion report")
    return lines


def _info(info):
    if "line" in info:
        return "%s at line %d, column %d: %s" % (
            info["kind"].replace("_", " "),
            info["line"],
            info["column"],
            info["message"],
        )
    return ", ".join("%s %s" % (k, v) for k, v in info.items())
