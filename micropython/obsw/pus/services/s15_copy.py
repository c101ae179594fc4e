"""ST[15] copy by time window (TC[15,24]) and the diagnostic parameter report
storage-control configuration (TC[15,31], [15,32], [15,37], TM[15,38]): a part of
``Storage`` (``obsw.pus.services.s15_storage`` has the module text).

TC[15,24] copies the packets of the source packet store whose storage time (at the time tags'
resolution) lies in the window (from time tag 1 to time tag 2, after time tag 1, or before
time tag 2, bounds included) into the target packet store, in storage order and with their
storage times, so the copy can be retrieved, summarised or deleted by time like the original.
The target must be another store, exist, be empty and not be retrieved; a bounded target
must hold the whole selection (a circular one keeps the newest packets, as when storing). The
diagnostic configuration selects TM[3,26] by structure ID per APID, as the housekeeping one
selects TM[3,25].
"""

from obsw.pus.messages import (
    FAILURE_REFUSED,
    TM_STORE_DIAG_STRUCTURES_REPORT,
)
from obsw.pus.services.base import Service
from obsw.pus.services.packet_store import BOUNDED
from obsw.pus.services.s01_verification import PusFailure
from obsw.pus.services.s15_layouts import (
    COPY_WINDOW,
    ONE_STORE,
    STORE_DIAG,
    STORE_ID,
    TIME_TAG,
    WINDOW_AFTER,
    WINDOW_BEFORE,
    WINDOW_FROM_TO,
)


def _refuse(msg, sid):
    return PusFailure(FAILURE_REFUSED, msg, STORE_ID.pack(sid))


def _at_tag_resolution(t):
    """A storage time as a time tag carries it (the times reports give, and TCs name)."""
    code = TIME_TAG.code
    return code.to_seconds(*code.from_seconds(t))


def window_bounds(window, tag1, tag2):
    """(first, last) storage time of a time window, in seconds; None for an unknown type."""
    t1 = TIME_TAG.seconds(tag1)
    t2 = TIME_TAG.seconds(tag2)
    if window == WINDOW_FROM_TO:
        return t1, t2
    if window == WINDOW_AFTER:
        return t1, None
    if window == WINDOW_BEFORE:
        return None, t2
    return None


class CopyAndDiagnostics(Service):
    """TC[15,24] and the diagnostic storage control (see the module text)."""

    copied = 0  # packets copied by TC[15,24]

    def copy_window(self, req):
        tc = req.decode(COPY_WINDOW)
        src = self.store(tc["source"])
        dst = self.store(tc["target"])
        bounds = window_bounds(tc["window"], tc["tag1"], tc["tag2"])
        if bounds is None:
            raise _refuse("time window type %d" % tc["window"], src.id)
        first, last = bounds
        if first is not None and last is not None and last < first:
            raise _refuse("time window ends before it starts", src.id)
        if src is dst:
            raise _refuse("store %d copied into itself" % src.id, src.id)
        if dst.packets:
            raise _refuse("target store %d is not empty" % dst.id, dst.id)
        if dst.range_queue is not None or dst.open_active:
            raise _refuse("target store %d is being retrieved" % dst.id, dst.id)
        chosen = []
        for p in src.packets:
            t = _at_tag_resolution(p[1])
            if (first is None or t >= first) and (last is None or t <= last):
                chosen.append(p)
        size = 0
        for p in chosen:
            size += len(p[2])
        if dst.kind == BOUNDED and size > dst.size:
            raise _refuse(
                "%d octets for bounded store %d of %d" % (size, dst.id, dst.size), dst.id
            )
        req.start()
        for p in chosen:
            if dst.append(p[1], p[2]):
                self.copied += 1
        self.persist()

    def add_diag(self, req):
        tc = req.decode(STORE_DIAG)
        c = self.controls[self.store(tc["store"]).id]
        req.start()
        for i in tc["apids"]:
            c.diag.add(i["apid"], i["ids"])
        self.persist()

    def delete_diag(self, req):
        tc = req.decode(STORE_DIAG)
        c = self.controls[self.store(tc["store"]).id]
        for i in tc["apids"]:
            c.diag.check_delete(i["apid"], i["ids"])
        req.start()
        if not tc["apids"]:
            c.diag.apids = {}
        for i in tc["apids"]:
            c.diag.delete(i["apid"], i["ids"])
        self.persist()

    def report_diag(self, req):
        sid = self.store(req.decode(ONE_STORE)["store"]).id
        data = STORE_DIAG.pack({"store": sid, "apids": self.controls[sid].diag.as_list()})
        req.report(TM_STORE_DIAG_STRUCTURES_REPORT, data)
