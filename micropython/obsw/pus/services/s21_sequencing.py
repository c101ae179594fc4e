"""ST[21] request sequencing: named sequences of TCs released one after another.

A sequence is loaded directly (TC[21,1]) as N (request, delay) pairs: a whole TC packet and
the relative time to wait after its release before the next one (after the last, before
the sequence ends). Activation releases the first request on the next cycle of the
application process; each request goes in through ``receive`` and is verified like a
ground TC, its reports going to its own source ID. An active sequence cannot be loaded
again, unloaded or activated twice; aborting an inactive one is refused. Loaded sequences
persist in the context store; after a restart every sequence is inactive. Loading by
reference (TC[21,2]; TC[21,8] loads and activates) takes the (request, delay) pairs from a
file of the onboard filestore, named by repository and file as in ST[23]: the file holds
them in the layout of TC[21,1] without the sequence ID (``SEQUENCE_FILE``;
``RequestSequencingUser.sequence_file`` writes one). A file that is missing or locked fails
with ``FAILURE_FILESTORE``, one that does not hold a sequence with ``FAILURE_REFUSED``. The
checksum is the CRC-16/CCITT of the sequence's content as TC[21,12] reports it.
"""

from binascii import hexlify, unhexlify

from obsw.crc import crc16_ccitt
from obsw.pus.fields import field
from obsw.pus.messages import (
    SERVICE_REQUEST_SEQUENCING,
    TC_SEQUENCE_ABORT,
    TC_SEQUENCE_ABORT_ALL,
    TC_SEQUENCE_ACTIVATE,
    TC_SEQUENCE_CHECKSUM,
    TC_SEQUENCE_LOAD_AND_ACTIVATE,
    TC_SEQUENCE_LOAD_BY_REFERENCE,
    TC_SEQUENCE_LOAD_DIRECT,
    TC_SEQUENCE_REPORT_CONTENT,
    TC_SEQUENCE_REPORT_STATUS,
    TC_SEQUENCE_UNLOAD,
    TM_SEQUENCE_ABORTED_REPORT,
    TM_SEQUENCE_CHECKSUM_REPORT,
    TM_SEQUENCE_CONTENT_REPORT,
    TM_SEQUENCE_STATUS_REPORT,
)
from obsw.pus.packets import PusError
from obsw.pus.ptc_time import cuc_pfc
from obsw.pus.services.base import E8, U16, Service, ServiceUser
from obsw.pus.services.file_refs import read_file, split_path
from obsw.pus.services.s01_verification import (
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
    PusFailure,
    app_data_error,
)
from obsw.pus.services.s11_scheduling import ticks
from obsw.pus.services.s23_layouts import PATH
from obsw.pus.services.schedule_user import describe_request, embed, request_bytes
from obsw.pus.structure import Repeated, Structure
from obsw.pus.tc import PusTc

SEQUENCE_ID = field(8, 0, length_bits=8, max_length=32)
REQUEST_COUNT = U16
SEQUENCE_COUNT = U16
STATUS = E8  # 1 active, 0 inactive
REQUEST = field(12, 0)
DELAY = field(10, cuc_pfc(4, 2))

EMPTY = Structure([])
ID = Structure([("id", SEQUENCE_ID)])
ITEMS = Repeated(REQUEST_COUNT, [("request", REQUEST), ("delay", DELAY)])
CONTENT = Structure([("id", SEQUENCE_ID), ("items", ITEMS)])
SEQUENCE_FILE = Structure([("items", ITEMS)])  # the content of a file TC[21,2] loads
BY_REFERENCE = Structure([("id", SEQUENCE_ID), ("repository", PATH), ("file", PATH)])
STATUS_REPORT = Structure(
    [("items", Repeated(SEQUENCE_COUNT, [("id", SEQUENCE_ID), ("active", STATUS)]))]
)
CHECKSUM_REPORT = Structure([("id", SEQUENCE_ID), ("checksum", U16)])
ABORTED_REPORT = Structure([("ids", Repeated(SEQUENCE_COUNT, SEQUENCE_ID))])

_DECODE_ERRORS = (ValueError, KeyError, IndexError, TypeError)


class Sequence:
    __slots__ = ("id", "items", "active", "index", "due")

    def __init__(self, id, items):
        self.id = id
        self.items = items  # [(request bytes, delay in 1/65536 s)]
        self.active = False
        self.index = 0
        self.due = 0

    def content(self):
        return {
            "id": self.id,
            "items": [{"request": r, "delay": (d >> 16, d & 0xFFFF)} for r, d in self.items],
        }


def _id_failure(code, msg, sid):
    return PusFailure(code, msg, ID.pack({"id": sid}))


class RequestSequencing(Service):
    """The service 21 provider; ``capacity`` sequences of at most ``max_requests`` each.
    ``route(raw)`` takes requests for APIDs this process does not serve."""

    SERVICE = SERVICE_REQUEST_SEQUENCING
    REPORTS = (
        TM_SEQUENCE_STATUS_REPORT,
        TM_SEQUENCE_CHECKSUM_REPORT,
        TM_SEQUENCE_CONTENT_REPORT,
        TM_SEQUENCE_ABORTED_REPORT,
    )
    NAME = "s21"
    HANDLERS = (
        (TC_SEQUENCE_LOAD_DIRECT, "load"),
        (TC_SEQUENCE_LOAD_BY_REFERENCE, "load_by_reference"),
        (TC_SEQUENCE_LOAD_AND_ACTIVATE, "load_and_activate"),
        (TC_SEQUENCE_UNLOAD, "unload"),
        (TC_SEQUENCE_ACTIVATE, "activate"),
        (TC_SEQUENCE_ABORT, "abort"),
        (TC_SEQUENCE_REPORT_STATUS, "report_status"),
        (TC_SEQUENCE_CHECKSUM, "checksum"),
        (TC_SEQUENCE_REPORT_CONTENT, "report_content"),
        (TC_SEQUENCE_ABORT_ALL, "abort_all"),
    )

    def __init__(self, capacity=8, max_requests=32, route=None):
        super().__init__()
        self.capacity = capacity
        self.max_requests = max_requests
        self.route = route
        self.sequences = {}  # ID -> Sequence
        self.released = 0
        self.completed = 0

    def context(self):
        return [
            [s.id, [[hexlify(r).decode(), d] for r, d in s.items]] for s in self.sequences.values()
        ]

    def restore(self, ctx):
        seqs = {}
        for sid, items in ctx:
            seq = []
            for text, d in items:
                raw = unhexlify(text)
                PusTc.unpack(raw)  # a damaged request rejects the whole context
                seq.append((raw, int(d)))
            seqs[sid] = Sequence(sid, seq)
        self.sequences = seqs

    def _known(self, req):
        sid = req.decode(ID)["id"]
        s = self.sequences.get(sid)
        if s is None:
            raise _id_failure(FAILURE_UNKNOWN_ID, "no sequence %r" % sid, sid)
        return s

    def _requests(self, items):
        return [PusTc.unpack(i["request"], self.app.config) for i in items]

    def load(self, req):
        try:
            tc = CONTENT.unpack(req.data)
            tcs = self._requests(tc["items"])
        except PusError as e:
            raise app_data_error("request: %s" % e) from None
        except _DECODE_ERRORS as e:
            raise app_data_error(e) from None
        req.accept()
        self._load(req, tc["id"], tc["items"], tcs)

    def _from_file(self, req):
        tc = req.decode(BY_REFERENCE)
        sid = tc["id"]
        data = read_file(self.app, tc["repository"], tc["file"])
        try:
            items = SEQUENCE_FILE.unpack(data)["items"]
            tcs = self._requests(items)
        except (PusError,) + _DECODE_ERRORS as e:
            raise _id_failure(FAILURE_REFUSED, "not a request sequence: %s" % e, sid) from None
        return sid, items, tcs

    def load_by_reference(self, req):
        sid, items, tcs = self._from_file(req)
        self._load(req, sid, items, tcs)

    def load_and_activate(self, req):
        sid, items, tcs = self._from_file(req)
        self._load(req, sid, items, tcs)
        self._activate(self.sequences[sid])

    def _load(self, req, sid, entries, tcs):
        refused = None
        old = self.sequences.get(sid)
        if old is not None and old.active:
            refused = "sequence %r is active" % sid
        elif old is None and len(self.sequences) >= self.capacity:
            refused = "%d sequences already" % len(self.sequences)
        elif not 0 < len(tcs) <= self.max_requests:
            refused = "%d requests, expected 1..%d" % (len(tcs), self.max_requests)
        if refused:
            raise _id_failure(FAILURE_REFUSED, refused, sid)
        items = []
        for i, t in zip(entries, tcs):
            if t.apid not in self.app.apids and self.route is None:
                raise _id_failure(FAILURE_UNKNOWN_ID, "no process %d" % t.apid, sid)
            c, f = i["delay"]
            if c < 0:
                raise _id_failure(FAILURE_REFUSED, "negative delay", sid)
            items.append((bytes(i["request"]), (c << 16) | f))
        req.start()
        self.sequences[sid] = Sequence(sid, items)
        self.persist()

    def unload(self, req):
        s = self._known(req)
        if s.active:
            raise _id_failure(FAILURE_REFUSED, "sequence %r is active" % s.id, s.id)
        req.start()
        del self.sequences[s.id]
        self.persist()

    def activate(self, req):
        s = self._known(req)
        if s.active:
            raise _id_failure(FAILURE_REFUSED, "sequence %r is active" % s.id, s.id)
        req.start()
        self._activate(s)

    def _activate(self, s):
        s.active = True
        s.index = 0
        s.due = ticks(self.app.time())

    def abort(self, req):
        s = self._known(req)
        if not s.active:
            raise _id_failure(FAILURE_REFUSED, "sequence %r is not active" % s.id, s.id)
        req.start()
        s.active = False

    def abort_all(self, req):
        req.decode(EMPTY)
        req.start()
        ids = []
        for sid, s in sorted(self.sequences.items()):
            if s.active:
                s.active = False
                ids.append(sid)
        req.report(TM_SEQUENCE_ABORTED_REPORT, ABORTED_REPORT.pack({"ids": ids}))

    def report_status(self, req):
        req.decode(EMPTY)
        items = [
            {"id": sid, "active": 1 if s.active else 0}
            for sid, s in sorted(self.sequences.items())
        ]
        req.report(TM_SEQUENCE_STATUS_REPORT, STATUS_REPORT.pack({"items": items}))

    def checksum(self, req):
        s = self._known(req)
        crc = crc16_ccitt(CONTENT.pack(s.content()))
        req.report(
            TM_SEQUENCE_CHECKSUM_REPORT, CHECKSUM_REPORT.pack({"id": s.id, "checksum": crc})
        )

    def report_content(self, req):
        s = self._known(req)
        req.report(TM_SEQUENCE_CONTENT_REPORT, CONTENT.pack(s.content()))

    def cyclic(self, now):
        t = None
        for s in list(self.sequences.values()):
            if not s.active:
                continue
            if t is None:
                t = ticks(self.app.time())
            while s.active and t >= s.due:
                if s.index >= len(s.items):
                    s.active = False
                    self.completed += 1
                    break
                raw, delay = s.items[s.index]
                s.index += 1
                s.due += delay
                self.released += 1
                dest = ((raw[0] & 7) << 8) | raw[1]
                if dest in self.app.apids or self.route is None:
                    self.app.receive(raw)
                else:
                    self.route(raw)


class RequestSequencingUser(ServiceUser):
    """The service 21 user; delays are seconds, requests TC bytes, PusTcs or transactions
    of ``embed``."""

    SERVICE = SERVICE_REQUEST_SEQUENCING
    DECODERS = (
        (TM_SEQUENCE_STATUS_REPORT, "decode_status"),
        (TM_SEQUENCE_CHECKSUM_REPORT, "decode_checksum"),
        (TM_SEQUENCE_CONTENT_REPORT, "decode_content"),
        (TM_SEQUENCE_ABORTED_REPORT, "decode_aborted"),
    )

    def embed(self, apid, service, subtype, data=b"", expect=None):
        """A TC for a sequence (see ``obsw.pus.services.schedule_user.embed``)."""
        return embed(self.proc, apid, service, subtype, data, expect=expect)

    def _id(self, message_type, apid, sid, expect=None):
        return self.request(apid, message_type, ID.pack({"id": sid}), expect)

    def load(self, apid, sid, items):
        """``items``: (request, delay in seconds) pairs."""
        values = {
            "id": sid,
            "items": [{"request": request_bytes(r), "delay": d} for r, d in items],
        }
        return self.request(apid, TC_SEQUENCE_LOAD_DIRECT, CONTENT.pack(values))

    def _by_reference(self, message_type, apid, sid, path):
        repo, name = split_path(path)
        data = BY_REFERENCE.pack({"id": sid, "repository": repo, "file": name})
        return self.request(apid, message_type, data)

    def load_by_reference(self, apid, sid, path):
        """TC[21,2]: load sequence ``sid`` from a file (``SAT:/seq/warmup.seq``)."""
        return self._by_reference(TC_SEQUENCE_LOAD_BY_REFERENCE, apid, sid, path)

    def load_and_activate(self, apid, sid, path):
        """TC[21,8]: load sequence ``sid`` from a file and activate it."""
        return self._by_reference(TC_SEQUENCE_LOAD_AND_ACTIVATE, apid, sid, path)

    @staticmethod
    def sequence_file(items):
        """The bytes of a file that TC[21,2] loads: ``items`` as for ``load``."""
        values = [{"request": request_bytes(r), "delay": d} for r, d in items]
        return SEQUENCE_FILE.pack({"items": values})

    def unload(self, apid, sid):
        return self._id(TC_SEQUENCE_UNLOAD, apid, sid)

    def activate(self, apid, sid):
        return self._id(TC_SEQUENCE_ACTIVATE, apid, sid)

    def abort(self, apid, sid):
        return self._id(TC_SEQUENCE_ABORT, apid, sid)

    def abort_all(self, apid):
        return self.request(apid, TC_SEQUENCE_ABORT_ALL, b"", TM_SEQUENCE_ABORTED_REPORT)

    def report_status(self, apid):
        return self.request(apid, TC_SEQUENCE_REPORT_STATUS, b"", TM_SEQUENCE_STATUS_REPORT)

    def checksum(self, apid, sid):
        return self._id(TC_SEQUENCE_CHECKSUM, apid, sid, TM_SEQUENCE_CHECKSUM_REPORT)

    def report_content(self, apid, sid):
        return self._id(TC_SEQUENCE_REPORT_CONTENT, apid, sid, TM_SEQUENCE_CONTENT_REPORT)

    def decode_status(self, tm):
        items = STATUS_REPORT.unpack(tm.data)["items"]
        for i in items:
            i["active"] = bool(i["active"])
        return {"items": items}

    def decode_checksum(self, tm):
        return CHECKSUM_REPORT.unpack(tm.data)

    def decode_content(self, tm):
        out = CONTENT.unpack(tm.data)
        items = []
        for i in out["items"]:
            d = describe_request(i["request"], self.proc.config if self.proc else None)
            c, f = i["delay"]
            d["delay"] = c + f / 65536
            items.append(d)
        return {"id": out["id"], "items": items}

    def decode_aborted(self, tm):
        return ABORTED_REPORT.unpack(tm.data)
