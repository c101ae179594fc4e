"""ST[06] memory management: load, dump and check memory, raw and by object; atomic loads,
loads from and dumps to files, scrubbing and write protection.

Memory areas are those the spacecraft database declares (``memories``, see
``obsw.pus.services.s06_areas``) or any object of that interface. Raw memory is addressed by
memory ID and absolute address (TC[6,2], [6,5], [6,9]); object memory by memory ID, object
ID and offset in the object (TC[6,1], [6,3], [6,7]; object 0 is the whole area). Every item
of a request is checked before anything is done: an unknown memory or object fails the start
of execution with ``FAILURE_UNKNOWN_ID``, a range outside its area or object with
``FAILURE_OUT_OF_BOUNDS`` (memory ID and address, or memory ID, object ID and offset, in the
failure data), a load whose checksum does not match its data or into a read-only area with
``FAILURE_REFUSED``, into a write-protected memory (TC[6,15] .. [6,16]) with
``FAILURE_WRITE_PROTECTED``. Write protection holds for every load: raw, object, atomic and by
reference. Every load is read back from each copy of the area; data that did not stay fail
the completion with ``FAILURE_READBACK``. TC[6,11] loads one area in one non-interruptible
transaction: written whole (a new image renamed over a file-backed one) or, if it does not
read back, put back as it was.

Loads by reference (TC[6,19], [6,21]) take each area's data from a file of the onboard
filestore, named as in ST[23]; dumps to file (TC[6,20], [6,22]) and their abort (TC[6,12])
are ``obsw.pus.services.s06_files``. Dumps in telemetry larger than ``max_dump`` octets are
refused. TC[6,17] checks a whole object (TM[6,18]).

Scrubbing (TC[6,13], [6,14]; ``obsw.pus.services.s06_scrub``) reads ``scrub_blocks`` blocks
of each scrubbed memory per cycle and raises an event for each block it repaired from a
mirror copy and each it could not. Protection and scrubbing references persist in the
context store.
"""

from obsw.compat import const
from obsw.crc import crc16_ccitt
from obsw.il.interface import LOW, MEDIUM
from obsw.pus.messages import (
    FAILURE_OUT_OF_BOUNDS,
    FAILURE_READBACK,
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
    FAILURE_WRITE_PROTECTED,
    SERVICE_MEMORY_MANAGEMENT,
    TC_MEM_ABORT_ALL_DUMPS,
    TC_MEM_CHECK_OBJECT,
    TC_MEM_CHECK_OBJECT_WHOLE,
    TC_MEM_CHECK_RAW,
    TC_MEM_DISABLE_SCRUBBING,
    TC_MEM_DISABLE_WRITE_PROTECTION,
    TC_MEM_DUMP_OBJECT,
    TC_MEM_DUMP_OBJECT_TO_FILE,
    TC_MEM_DUMP_RAW,
    TC_MEM_DUMP_RAW_TO_FILE,
    TC_MEM_ENABLE_SCRUBBING,
    TC_MEM_ENABLE_WRITE_PROTECTION,
    TC_MEM_LOAD_OBJECT,
    TC_MEM_LOAD_OBJECT_BY_REFERENCE,
    TC_MEM_LOAD_RAW,
    TC_MEM_LOAD_RAW_ATOMIC,
    TC_MEM_LOAD_RAW_BY_REFERENCE,
    TM_MEM_CHECK_OBJECT_REPORT,
    TM_MEM_CHECK_OBJECT_WHOLE_REPORT,
    TM_MEM_CHECK_RAW_REPORT,
    TM_MEM_DUMP_OBJECT_REPORT,
    TM_MEM_DUMP_RAW_REPORT,
)
from obsw.pus.services import s06_layouts as lay
from obsw.pus.services.file_refs import read_file
from obsw.pus.services.s01_verification import PusFailure
from obsw.pus.services.s06_areas import (  # noqa: F401 (the module's public names)
    BytesMemory,
    FileMemory,
    MirroredMemory,
    areas_from_sdb,
)
from obsw.pus.services.s06_files import MemoryFiles
from obsw.pus.services.s06_scrub import REPAIRED, Scrub
from obsw.pus.services.s06_user import MemoryUser  # noqa: F401

EVENT_SCRUB_REPAIRED = const(0xFF06)  # aux: memory ID, address of the block
EVENT_SCRUB_UNCORRECTABLE = const(0xFF07)

_SLICE = const(1024)  # octets read at once by checks and dumps


def _crc(area, off, n):
    crc = None
    while n > 0:  # in slices, so a large area is never read whole
        k = n if n < _SLICE else _SLICE
        crc = crc16_ccitt(area.read(off, k), crc)
        off += k
        n -= k
    return crc16_ccitt(b"") if crc is None else crc


class MemoryManagement(MemoryFiles):
    """The service 6 provider over ``areas`` (memory ID -> area); see the module text."""

    SERVICE = SERVICE_MEMORY_MANAGEMENT
    REPORTS = (
        TM_MEM_DUMP_OBJECT_REPORT,
        TM_MEM_DUMP_RAW_REPORT,
        TM_MEM_CHECK_OBJECT_REPORT,
        TM_MEM_CHECK_RAW_REPORT,
        TM_MEM_CHECK_OBJECT_WHOLE_REPORT,
    )
    NAME = "s06"
    HANDLERS = (
        (TC_MEM_LOAD_OBJECT, "load_object"),
        (TC_MEM_LOAD_RAW, "load"),
        (TC_MEM_DUMP_OBJECT, "dump_object"),
        (TC_MEM_DUMP_RAW, "dump"),
        (TC_MEM_CHECK_OBJECT, "check_object"),
        (TC_MEM_CHECK_RAW, "check"),
        (TC_MEM_LOAD_RAW_ATOMIC, "load_atomic"),
        (TC_MEM_ABORT_ALL_DUMPS, "abort_dumps"),
        (TC_MEM_ENABLE_SCRUBBING, "enable_scrubbing"),
        (TC_MEM_DISABLE_SCRUBBING, "disable_scrubbing"),
        (TC_MEM_ENABLE_WRITE_PROTECTION, "protect"),
        (TC_MEM_DISABLE_WRITE_PROTECTION, "unprotect"),
        (TC_MEM_CHECK_OBJECT_WHOLE, "check_whole_object"),
        (TC_MEM_LOAD_RAW_BY_REFERENCE, "load_by_reference"),
        (TC_MEM_DUMP_RAW_TO_FILE, "dump_to_file"),
        (TC_MEM_LOAD_OBJECT_BY_REFERENCE, "load_object_by_reference"),
        (TC_MEM_DUMP_OBJECT_TO_FILE, "dump_object_to_file"),
    )

    def __init__(
        self,
        areas,
        max_dump=1024,
        chunk=4096,
        scrub_block=256,
        scrub_blocks=4,
        events=(EVENT_SCRUB_REPAIRED, EVENT_SCRUB_UNCORRECTABLE),
    ):
        super().__init__(chunk)
        self.areas = dict(areas)
        self.max_dump = max_dump
        self.scrub_block = scrub_block
        self.scrub_blocks = scrub_blocks
        self.events = events
        self.protected = set()  # memory IDs whose write protection is on
        self.scrubs = {}  # memory ID -> Scrub

    # -------------------------------------------------------------------------- context

    def context(self):
        return {
            "protected": sorted(self.protected),
            "scrub": [[mid, self.scrubs[mid].refs] for mid in sorted(self.scrubs)],
        }

    def restore(self, ctx):
        protected = set(int(m) for m in ctx["protected"])
        scrubs = {}
        for mid, refs in ctx["scrub"]:
            area = self.areas.get(mid)
            if area is not None:
                scrubs[mid] = Scrub(area, self.scrub_block, refs)
        self.protected, self.scrubs = protected, scrubs

    # -------------------------------------------------------------------------- addressing

    def _area(self, mid):
        a = self.areas.get(mid)
        if a is None:
            raise PusFailure(FAILURE_UNKNOWN_ID, "no memory %d" % mid, lay.MEMORY_ID.pack(mid))
        return a

    def _raw(self, mid, area, address, length):
        """The offset in ``area`` of a raw range, checked."""
        if address < area.start or address + length > area.start + area.size:
            raise PusFailure(
                FAILURE_OUT_OF_BOUNDS,
                "memory %d: 0x%x + %d outside 0x%x + %d"
                % (mid, address, length, area.start, area.size),
                lay.WHERE.pack({"memory": mid, "address": address}),
            )
        return address - area.start

    def _object(self, mid, area, oid):
        """(offset in the area, size) of object ``oid``."""
        if oid == 0:
            return 0, area.size
        o = area.objects.get(oid)
        if o is None:
            raise PusFailure(
                FAILURE_UNKNOWN_ID,
                "memory %d has no object %d" % (mid, oid),
                lay.ONE_OBJECT.pack({"memory": mid, "object": oid}),
            )
        return o[1], o[2]

    def _in_object(self, mid, oid, span, offset, length):
        base, size = span
        if offset + length > size:
            raise PusFailure(
                FAILURE_OUT_OF_BOUNDS,
                "object %d of memory %d: %d + %d outside its %d octets"
                % (oid, mid, offset, length, size),
                lay.OBJECT_WHERE.pack({"memory": mid, "object": oid, "offset": offset}),
            )
        return base + offset

    def _writable(self, mid, area):
        if not area.writable:
            raise PusFailure(
                FAILURE_REFUSED, "memory %d is read-only" % mid, lay.MEMORY_ID.pack(mid)
            )
        if mid in self.protected:
            raise PusFailure(
                FAILURE_WRITE_PROTECTED,
                "memory %d is write-protected" % mid,
                lay.MEMORY_ID.pack(mid),
            )

    def _checksum(self, data, checksum, where):
        if crc16_ccitt(data) != checksum:
            raise PusFailure(FAILURE_REFUSED, "checksum of the data does not match", where)

    # -------------------------------------------------------------------------- loads

    def _write(self, mid, area, writes, atomic=False):
        """Write checked ``writes`` [(offset, data)], read them back, update scrubbing."""
        bad = None
        for off, data in writes:
            old = area.read(off, len(data)) if atomic else None
            if atomic:
                area.write_atomic(off, data)
            else:
                area.write(off, data)
            for copy in area.copies():
                if copy.read(off, len(data)) != data and bad is None:
                    bad = off
            if atomic and bad is not None:
                area.write_atomic(off, old)  # all or nothing
        scrub = self.scrubs.get(mid)
        if scrub is not None:
            for off, data in writes:
                scrub.loaded(off, len(data))
            self.persist()
        if bad is not None:
            raise PusFailure(
                FAILURE_READBACK,
                "memory %d: data at 0x%x did not read back" % (mid, area.start + bad),
                lay.WHERE.pack({"memory": mid, "address": area.start + bad}),
            )

    def _raw_writes(self, mid, area, items, data_of):
        writes = []
        for i in items:
            data = data_of(i)
            off = self._raw(mid, area, i["address"], len(data))
            where = lay.WHERE.pack({"memory": mid, "address": i["address"]})
            self._checksum(data, i["checksum"], where)
            writes.append((off, data))
        return writes

    def _object_writes(self, mid, oid, area, items, data_of):
        span = self._object(mid, area, oid)
        writes = []
        for i in items:
            data = data_of(i)
            off = self._in_object(mid, oid, span, i["offset"], len(data))
            where = lay.OBJECT_WHERE.pack({"memory": mid, "object": oid, "offset": i["offset"]})
            self._checksum(data, i["checksum"], where)
            writes.append((off, data))
        return writes

    def _file_data(self, item):
        return read_file(self.app, item["repository"], item["file"])

    def load(self, req):
        tc = req.decode(lay.LOAD)
        mid = tc["memory"]
        area = self._area(mid)
        self._writable(mid, area)
        writes = self._raw_writes(mid, area, tc["items"], lambda i: i["data"])
        req.start()
        self._write(mid, area, writes)

    def load_object(self, req):
        tc = req.decode(lay.OBJECT_LOAD)
        mid = tc["memory"]
        area = self._area(mid)
        self._writable(mid, area)
        writes = self._object_writes(mid, tc["object"], area, tc["items"], lambda i: i["data"])
        req.start()
        self._write(mid, area, writes)

    def load_atomic(self, req):
        tc = req.decode(lay.ATOMIC_LOAD)
        mid = tc["memory"]
        area = self._area(mid)
        self._writable(mid, area)
        writes = self._raw_writes(mid, area, [tc], lambda i: i["data"])
        req.start()
        self._write(mid, area, writes, atomic=True)

    def load_by_reference(self, req):
        tc = req.decode(lay.LOAD_BY_REFERENCE)
        mid = tc["memory"]
        area = self._area(mid)
        self._writable(mid, area)
        writes = self._raw_writes(mid, area, tc["items"], self._file_data)
        req.start()
        self._write(mid, area, writes)

    def load_object_by_reference(self, req):
        tc = req.decode(lay.OBJECT_LOAD_BY_REFERENCE)
        mid = tc["memory"]
        area = self._area(mid)
        self._writable(mid, area)
        writes = self._object_writes(mid, tc["object"], area, tc["items"], self._file_data)
        req.start()
        self._write(mid, area, writes)

    # -------------------------------------------------------------------------- dumps, checks

    def _limit(self, items):
        total = 0
        for i in items:
            total += i["length"]
        if total > self.max_dump:
            raise PusFailure(
                FAILURE_REFUSED, "dump of %d octets, at most %d" % (total, self.max_dump)
            )

    def _raw_ranges(self, req, layout):
        tc = req.decode(layout)
        mid = tc["memory"]
        area = self._area(mid)
        spans = [self._raw(mid, area, i["address"], i["length"]) for i in tc["items"]]
        return tc, area, spans

    def _object_ranges(self, req, layout):
        tc = req.decode(layout)
        mid = tc["memory"]
        area = self._area(mid)
        span = self._object(mid, area, tc["object"])
        spans = [
            self._in_object(mid, tc["object"], span, i["offset"], i["length"]) for i in tc["items"]
        ]
        return tc, area, spans

    def dump(self, req):
        tc, area, spans = self._raw_ranges(req, lay.RANGES)
        self._limit(tc["items"])
        out = []
        for i, off in zip(tc["items"], spans):
            data = area.read(off, i["length"])
            out.append({"address": i["address"], "data": data, "checksum": crc16_ccitt(data)})
        req.report(
            TM_MEM_DUMP_RAW_REPORT, lay.DUMP_REPORT.pack({"memory": tc["memory"], "items": out})
        )

    def dump_object(self, req):
        tc, area, spans = self._object_ranges(req, lay.OBJECT_RANGES)
        self._limit(tc["items"])
        out = []
        for i, off in zip(tc["items"], spans):
            data = area.read(off, i["length"])
            out.append({"offset": i["offset"], "data": data, "checksum": crc16_ccitt(data)})
        tc["items"] = out
        req.report(TM_MEM_DUMP_OBJECT_REPORT, lay.OBJECT_DUMP_REPORT.pack(tc))

    def check(self, req):
        tc, area, spans = self._raw_ranges(req, lay.RANGES)
        for i, off in zip(tc["items"], spans):
            i["checksum"] = _crc(area, off, i["length"])
        req.report(TM_MEM_CHECK_RAW_REPORT, lay.CHECK_REPORT.pack(tc))

    def check_object(self, req):
        tc, area, spans = self._object_ranges(req, lay.OBJECT_RANGES)
        for i, off in zip(tc["items"], spans):
            i["checksum"] = _crc(area, off, i["length"])
        req.report(TM_MEM_CHECK_OBJECT_REPORT, lay.OBJECT_CHECK_REPORT.pack(tc))

    def check_whole_object(self, req):
        tc = req.decode(lay.ONE_OBJECT)
        area = self._area(tc["memory"])
        off, n = self._object(tc["memory"], area, tc["object"])
        tc["length"] = n
        tc["checksum"] = _crc(area, off, n)
        req.report(TM_MEM_CHECK_OBJECT_WHOLE_REPORT, lay.OBJECT_WHOLE_REPORT.pack(tc))

    # -------------------------------------------------------------------------- protection

    def _one(self, req):
        mid = req.decode(lay.ONE_MEMORY)["memory"]
        return mid, self._area(mid)

    def protect(self, req):
        mid, area = self._one(req)
        req.start()
        self.protected.add(mid)
        self.persist()

    def unprotect(self, req):
        mid, area = self._one(req)
        req.start()
        self.protected.discard(mid)
        self.persist()

    # -------------------------------------------------------------------------- scrubbing

    def enable_scrubbing(self, req):
        mid, area = self._one(req)
        req.start()
        if mid not in self.scrubs:  # enabled already: its reference stays
            self.scrubs[mid] = Scrub(area, self.scrub_block)
            self.persist()

    def disable_scrubbing(self, req):
        mid, area = self._one(req)
        req.start()
        if self.scrubs.pop(mid, None) is not None:
            self.persist()

    def cyclic(self, now):
        self._wake()
        for mid in sorted(self.scrubs):
            scrub = self.scrubs[mid]
            for kind, off in scrub.step(self.scrub_blocks):
                where = lay.WHERE.pack({"memory": mid, "address": scrub.area.start + off})
                if kind == REPAIRED:
                    self.app.event(self.events[0], LOW, where)
                else:
                    self.app.event(self.events[1], MEDIUM, where)
