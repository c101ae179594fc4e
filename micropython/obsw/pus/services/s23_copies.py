"""ST[23] copy operations: copies and moves, inside the onboard filestore or to and from the
ground through the remote file copy component; their suspension, resumption, abortion and
status reports. ``CopyOperations`` is the half of ``FileManagement`` that does this
(``obsw.pus.services.s23_files`` has the module text).
"""

from obsw.cfdp.remote_copy import (
    ACTIVE,
    CANCELLED,
    COMPLETED,
    FAILED,
    REQUESTED,
    SUSPENDED,
)
from obsw.il.errors import TIMEOUT, UNAVAILABLE, InteractionError
from obsw.il.interface import INFO, LOW
from obsw.pus.messages import (
    FAILURE_COMPONENT,
    FAILURE_FILESTORE,
    FAILURE_PATH,
    FAILURE_REFUSED,
    FAILURE_TIMEOUT,
    FAILURE_UNAVAILABLE,
    FAILURE_UNKNOWN_ID,
    TM_FILE_COPY_STATUS_REPORT,
)
from obsw.pus.services.base import Service
from obsw.pus.services.s01_verification import PusFailure
from obsw.pus.services.s23_layouts import (
    COPY,
    COPY_ABORTED,
    COPY_COMPLETED,
    COPY_FAILED,
    COPY_IN_PROGRESS,
    COPY_PENDING,
    COPY_STATUS,
    COPY_SUSPENDED,
    EMPTY,
    INTERVAL,
    OPERATION_ID,
    OPERATIONS,
    REPOSITORY,
)

_STATUS = {
    REQUESTED: COPY_PENDING,
    ACTIVE: COPY_IN_PROGRESS,
    SUSPENDED: COPY_SUSPENDED,
    COMPLETED: COPY_COMPLETED,
    FAILED: COPY_FAILED,
    CANCELLED: COPY_ABORTED,
}
_OVER = (COPY_COMPLETED, COPY_FAILED, COPY_ABORTED)


def _path_error(path, why):
    return PusFailure(FAILURE_PATH, "path %r: %s" % (path, why))


def _fs_error(msg):
    return PusFailure(FAILURE_FILESTORE, msg)


class CopyOperations(Service):
    """Copy operations of service 23 (needs the path helpers of ``FileManagement``)."""

    def copy(self, req):
        return self._copy(req, False)

    def move(self, req):
        return self._copy(req, True)

    def _copy(self, req, move):
        tc = req.decode(COPY)
        op_id = tc["operation"]
        old = self.ops.get(op_id)
        if old is not None and old["status"] not in _OVER:
            raise PusFailure(
                FAILURE_REFUSED, "operation %d is running" % op_id, OPERATION_ID.pack(op_id)
            )
        sp, src = self._join(tc["source_repository"], tc["source_file"])
        tp, dst = self._join(tc["target_repository"], tc["target_file"])
        src_path = "%s:/%s" % (sp, src)
        dst_path = "%s:/%s" % (tp, dst)
        if sp == self.local:
            self._need_file(src)
            if move:
                self._unlocked(src)
        if tp == self.local:
            if self.fs.exists(dst):
                raise _fs_error("%s exists" % dst)
            folder = dst.rsplit("/", 1)[0] if "/" in dst else ""
            if folder and not self.fs.is_dir(folder):
                raise _fs_error("no directory %s" % folder)
        if sp == self.local and tp == self.local:
            req.start()
            if move:
                self._fs(self.fs.rename, src, dst)
            else:
                self._fs(self.fs.copy_file, dst, src)
            self._remember(op_id, "local", src_path, dst_path, move, None, COPY_COMPLETED)
            return None
        if sp != self.local and tp != self.local:
            raise _path_error(src_path, "a copy needs the onboard filestore at one end")
        if move and sp != self.local:
            raise PusFailure(FAILURE_REFUSED, "a file is moved from the ground by copying it")
        if self.node is None:
            raise PusFailure(FAILURE_UNAVAILABLE, "no interaction layer for remote copies")
        if sp == self.local:
            return self._remote(
                req, op_id, "put", src, dst, self.prefixes[tp], src_path, dst_path, move
            )
        return self._remote(
            req, op_id, "get", src, dst, self.prefixes[sp], src_path, dst_path, move
        )

    def _remember(self, op_id, kind, src, dst, move, transfer, status):
        self.ops[op_id] = {
            "id": op_id,
            "kind": kind,
            "source": src,
            "target": dst,
            "move": move,
            "transfer": transfer,
            "status": status,
            "bytes": 0,
            "size": 0,
        }
        self._trim()
        self.persist()
        return self.ops[op_id]

    def _trim(self):
        done = [o for o in self.ops.values() if o["status"] in _OVER]
        for o in done[: max(0, len(done) - self.keep_done)]:
            del self.ops[o["id"]]

    async def _remote(self, req, op_id, kind, src, dst, entity, src_path, dst_path, move):
        import asyncio  # only here: boards without asyncio still import this module

        operation = "put_to_ground" if kind == "put" else "get_from_ground"
        req.start()
        op = self._remember(op_id, kind, src_path, dst_path, move, None, COPY_PENDING)
        woken = asyncio.Event()

        def on_status(pending, state, value):
            if isinstance(value, dict):
                self._update(op, value)
            elif pending.done:
                try:
                    self._update(op, pending.outcome())
                except InteractionError as e:
                    self._update(op, _failed_record(e.data))
            woken.set()

        try:
            pending = await self.node.acall(
                "%s.%s" % (self.component, operation), (src, dst, entity), timeout=self.timeout
            )
        except InteractionError as e:
            op["status"] = COPY_FAILED
            self.persist()
            raise _component_failure(e, op_id) from None
        pending.on_status = on_status
        if pending.progress is None and not pending.done:
            try:
                await asyncio.wait_for(woken.wait(), self.timeout)
            except asyncio.TimeoutError:
                pass
        if isinstance(pending.progress, dict):
            self._update(op, pending.progress)
        if pending.done:
            try:
                self._update(op, pending.outcome())
            except InteractionError as e:
                self._update(op, _failed_record(getattr(e, "data", None)))
                raise _component_failure(e, op_id) from None
        self.persist()

    def _update(self, op, rec):
        """Take a status record of the remote copy component into operation ``op``."""
        if not isinstance(rec, dict):
            return
        before = op["status"]
        if rec.get("transfer"):
            op["transfer"] = rec["transfer"]
        op["bytes"] = rec.get("bytes", op["bytes"])
        op["size"] = rec.get("size", op["size"])
        status = _STATUS.get(rec.get("state"), op["status"])
        if before in _OVER:
            return
        op["status"] = status
        if status == before:
            return
        self.persist()
        if status == COPY_COMPLETED:
            if op["move"] and op["kind"] == "put":
                name = self.local_path(op["source"])
                try:
                    self.fs.delete(name)
                except OSError:
                    pass
            self._event(0, op)
        elif status in (COPY_FAILED, COPY_ABORTED):
            self._event(1, op)

    def _event(self, which, op):
        if self.app is not None and self.events:
            aux = OPERATION_ID.pack(op["id"]) + bytes((op["status"],))
            self.app.event(self.events[which], INFO if which == 0 else LOW, aux)

    def _select(self, ids):
        out = []
        for op_id in ids:
            op = self.ops.get(op_id)
            if op is None:
                raise PusFailure(
                    FAILURE_UNKNOWN_ID, "no copy operation %d" % op_id, OPERATION_ID.pack(op_id)
                )
            out.append(op)
        return out

    def _in_path(self, path):
        prefix, name = self.split(path)
        out = []
        for op in self.ops.values():
            for p in (op["source"], op["target"]):
                pp, pn = self.split(p)
                if pp == prefix and (not name or pn == name or pn.startswith(name + "/")):
                    out.append(op)
                    break
        return out

    async def _control(self, req, ops, operation):
        req.start()
        for op in ops:
            if op["status"] in _OVER or op["kind"] == "local":
                continue
            if not op["transfer"]:
                raise PusFailure(
                    FAILURE_REFUSED,
                    "operation %d has not started" % op["id"],
                    OPERATION_ID.pack(op["id"]),
                )
            try:
                rec = await self.node.acall(
                    "%s.%s" % (self.component, operation), (op["transfer"],), timeout=self.timeout
                )
            except InteractionError as e:
                raise _component_failure(e, op["id"]) from None
            self._update(op, rec)
        self.persist()

    def suspend(self, req):
        return self._control(req, self._select(req.decode(OPERATIONS)["operations"]), "suspend")

    def resume(self, req):
        return self._control(req, self._select(req.decode(OPERATIONS)["operations"]), "resume")

    def abort(self, req):
        return self._control(req, self._select(req.decode(OPERATIONS)["operations"]), "cancel")

    def suspend_in_path(self, req):
        return self._control(req, self._in_path(req.decode(REPOSITORY)["repository"]), "suspend")

    def resume_in_path(self, req):
        return self._control(req, self._in_path(req.decode(REPOSITORY)["repository"]), "resume")

    def abort_in_path(self, req):
        return self._control(req, self._in_path(req.decode(REPOSITORY)["repository"]), "cancel")

    # -------------------------------------------------------------------------- status reports

    def enable_reports(self, req):
        interval = req.decode(INTERVAL)["interval"]
        if interval == 0:
            raise PusFailure(FAILURE_REFUSED, "reporting interval 0")
        req.start()
        self.report_interval = interval
        self._report_countdown = interval
        self.persist()

    def disable_reports(self, req):
        req.decode(EMPTY)
        req.start()
        self.report_interval = 0
        self.persist()

    def status_report(self, destination=0):
        """Send a TM[23,23] with every operation known now."""
        items = [
            {"operation": o["id"], "status": o["status"], "bytes": o["bytes"], "size": o["size"]}
            for o in self.ops.values()
        ]
        return self.send(
            TM_FILE_COPY_STATUS_REPORT, COPY_STATUS.pack({"operations": items}), destination
        )

    def running(self):
        return [o for o in self.ops.values() if o["status"] not in _OVER and o["kind"] != "local"]

    def cyclic(self, now):
        if self.report_interval:
            self._report_countdown -= 1
            if self._report_countdown <= 0:
                self._report_countdown = self.report_interval
                self.status_report()
        if self.node is None or not self.running():
            return None
        self._poll_countdown -= 1
        if self._poll_countdown > 0:
            return None
        self._poll_countdown = self.poll_every
        return self.refresh()

    async def refresh(self):
        """Ask the remote copy component for the status of every running operation."""
        for op in self.running():
            if not op["transfer"]:
                continue
            try:
                rec = await self.node.acall(
                    "%s.status" % self.component, (op["transfer"],), timeout=self.timeout
                )
            except InteractionError as e:
                if getattr(e, "code", None) == "UNKNOWN_TRANSFER":
                    self._update(op, {"state": FAILED})
                continue
            self._update(op, rec)


def _failed_record(data):
    """The status record a failed remote copy carries, or a plain 'failed' one."""
    return data if isinstance(data, dict) else {"state": FAILED}


def _component_failure(error, op_id):
    if error.status == TIMEOUT:
        code = FAILURE_TIMEOUT
    elif error.status == UNAVAILABLE:
        code = FAILURE_UNAVAILABLE
    else:
        code = FAILURE_COMPONENT
    return PusFailure(code, str(error), OPERATION_ID.pack(op_id))
