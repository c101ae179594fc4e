"""ST[06] memory management: load, dump and check raw memory by address and length.

Memory areas are those the spacecraft database declares (``memories``: id, start address,
size, writable, and a backing file in the filestore for a file-backed image), or any object
with ``start``, ``size``, ``writable``, ``read(offset, n)`` and ``write(offset, data)``
(``BytesMemory`` for safeguard memory in RAM and tests). Every item of a request is checked
before anything is done: an address range outside its area fails the start of execution
with ``FAILURE_OUT_OF_BOUNDS`` (memory ID and address in the failure data); a load whose
checksum does not match its data, or into a read-only area, is refused. Checksums are
CRC-16/CCITT-FALSE, the packet error control's (ECSS-E-ST-70-41C 6.6 lets the mission
choose). Dumps of more than ``max_dump`` octets in one report are refused.
"""

from obsw.crc import crc16_ccitt
from obsw.pus.fields import field
from obsw.pus.messages import (
    FAILURE_OUT_OF_BOUNDS,
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
    SERVICE_MEMORY_MANAGEMENT,
    TC_MEM_CHECK_RAW,
    TC_MEM_DUMP_RAW,
    TC_MEM_LOAD_RAW,
    TM_MEM_CHECK_RAW_REPORT,
    TM_MEM_DUMP_RAW_REPORT,
)
from obsw.pus.services.base import U8, U16, U32, Service, ServiceUser
from obsw.pus.services.s01_verification import PusFailure
from obsw.pus.structure import Repeated, Structure

MEMORY_ID = U16
ADDRESS = U32
LENGTH = U32
CHECKSUM = U16
DATA = field(7, 0)  # octet string, 16-bit length

LOAD = Structure(
    [
        ("memory", MEMORY_ID),
        ("items", Repeated(U8, [("address", ADDRESS), ("data", DATA), ("checksum", CHECKSUM)])),
    ]
)
RANGES = Structure(
    [("memory", MEMORY_ID), ("items", Repeated(U8, [("address", ADDRESS), ("length", LENGTH)]))]
)
DUMP_REPORT = LOAD
CHECK_REPORT = Structure(
    [
        ("memory", MEMORY_ID),
        (
            "items",
            Repeated(U8, [("address", ADDRESS), ("length", LENGTH), ("checksum", CHECKSUM)]),
        ),
    ]
)
_WHERE = Structure([("memory", MEMORY_ID), ("address", ADDRESS)])


class BytesMemory:
    """A memory area in RAM (a bytearray) at ``start``."""

    def __init__(self, size, start=0, writable=True, data=None):
        self.start = start
        self.size = size
        self.writable = writable
        self.buf = bytearray(size) if data is None else bytearray(data)

    def read(self, offset, n):
        return bytes(self.buf[offset : offset + n])

    def write(self, offset, data):
        self.buf[offset : offset + len(data)] = data


class FileMemory:
    """A memory area backed by a file of a filestore (``obsw.cfdp.filestore``), e.g. an
    image; the file is created, filled with zeros, when missing."""

    def __init__(self, fs, name, size, start=0, writable=True):
        self.fs = fs
        self.name = name
        self.start = start
        self.size = size
        self.writable = writable
        if not fs.exists(name):
            folder = name.rsplit("/", 1)[0] if "/" in name else ""
            if folder and not fs.is_dir(folder):
                fs.mkdir(folder)
            fs.write_bytes(name, bytes(size))

    def read(self, offset, n):
        return self.fs.read_bytes(self.name, offset, n)

    def write(self, offset, data):
        h = self.fs.open_write(self.name, False)
        try:
            h.write(offset, data)
        finally:
            h.close()


def areas_from_sdb(sdb, filestore=None):
    """The memory areas the spacecraft database declares (file-backed ones need a filestore)."""
    out = {}
    for mid, m in sdb.memories.items():
        if m["file"] and filestore is not None:
            out[mid] = FileMemory(filestore, m["file"], m["size"], m["start"], m["writable"])
        else:
            out[mid] = BytesMemory(m["size"], m["start"], m["writable"])
    return out


class MemoryManagement(Service):
    """The service 6 provider over ``areas`` (memory ID -> area)."""

    SERVICE = SERVICE_MEMORY_MANAGEMENT
    REPORTS = (TM_MEM_DUMP_RAW_REPORT, TM_MEM_CHECK_RAW_REPORT)
    HANDLERS = (
        (TC_MEM_LOAD_RAW, "load"),
        (TC_MEM_DUMP_RAW, "dump"),
        (TC_MEM_CHECK_RAW, "check"),
    )

    def __init__(self, areas, max_dump=1024):
        super().__init__()
        self.areas = dict(areas)
        self.max_dump = max_dump

    def _area(self, mid):
        a = self.areas.get(mid)
        if a is None:
            raise PusFailure(FAILURE_UNKNOWN_ID, "no memory %d" % mid, MEMORY_ID.pack(mid))
        return a

    def _bounds(self, mid, area, address, length):
        if address < area.start or address + length > area.start + area.size:
            raise PusFailure(
                FAILURE_OUT_OF_BOUNDS,
                "memory %d: 0x%x + %d outside 0x%x + %d"
                % (mid, address, length, area.start, area.size),
                _WHERE.pack({"memory": mid, "address": address}),
            )
        return address - area.start

    def load(self, req):
        tc = req.decode(LOAD)
        mid = tc["memory"]
        area = self._area(mid)
        if not area.writable:
            raise PusFailure(FAILURE_REFUSED, "memory %d is read-only" % mid, MEMORY_ID.pack(mid))
        for i in tc["items"]:
            self._bounds(mid, area, i["address"], len(i["data"]))
            if crc16_ccitt(i["data"]) != i["checksum"]:
                raise PusFailure(
                    FAILURE_REFUSED,
                    "checksum of the data for 0x%x does not match" % i["address"],
                    _WHERE.pack({"memory": mid, "address": i["address"]}),
                )
        req.start()
        for i in tc["items"]:
            area.write(i["address"] - area.start, i["data"])

    def _ranges(self, req):
        tc = req.decode(RANGES)
        mid = tc["memory"]
        area = self._area(mid)
        for i in tc["items"]:
            self._bounds(mid, area, i["address"], i["length"])
        return mid, area, tc["items"]

    def dump(self, req):
        mid, area, items = self._ranges(req)
        total = 0
        for i in items:
            total += i["length"]
        if total > self.max_dump:
            raise PusFailure(
                FAILURE_REFUSED, "dump of %d octets, at most %d" % (total, self.max_dump)
            )
        out = []
        for i in items:
            data = area.read(i["address"] - area.start, i["length"])
            out.append({"address": i["address"], "data": data, "checksum": crc16_ccitt(data)})
        req.report(TM_MEM_DUMP_RAW_REPORT, DUMP_REPORT.pack({"memory": mid, "items": out}))

    def check(self, req):
        mid, area, items = self._ranges(req)
        out = []
        for i in items:
            crc = None
            off = i["address"] - area.start
            left = i["length"]
            while left > 0:  # in slices, so a large area is never read whole
                n = left if left < 1024 else 1024
                crc = crc16_ccitt(area.read(off, n), crc)
                off += n
                left -= n
            if crc is None:
                crc = crc16_ccitt(b"")
            out.append({"address": i["address"], "length": i["length"], "checksum": crc})
        req.report(TM_MEM_CHECK_RAW_REPORT, CHECK_REPORT.pack({"memory": mid, "items": out}))


class MemoryUser(ServiceUser):
    """The service 6 user; decoded dumps verify their checksums (``ok`` per item)."""

    SERVICE = SERVICE_MEMORY_MANAGEMENT
    DECODERS = (
        (TM_MEM_DUMP_RAW_REPORT, "decode_dump"),
        (TM_MEM_CHECK_RAW_REPORT, "decode_check"),
    )

    def load(self, apid, memory, address, data, checksum=None):
        """Load ``data`` at ``address``; ``checksum`` defaults to the right one."""
        items = [
            {
                "address": address,
                "data": bytes(data),
                "checksum": crc16_ccitt(data) if checksum is None else checksum,
            }
        ]
        return self.request(apid, TC_MEM_LOAD_RAW, LOAD.pack({"memory": memory, "items": items}))

    def _ranges(self, memory, ranges):
        items = [{"address": a, "length": n} for a, n in ranges]
        return RANGES.pack({"memory": memory, "items": items})

    def dump(self, apid, memory, ranges):
        """``ranges`` is a list of (address, length)."""
        return self.request(
            apid, TC_MEM_DUMP_RAW, self._ranges(memory, ranges), TM_MEM_DUMP_RAW_REPORT
        )

    def check(self, apid, memory, ranges):
        return self.request(
            apid, TC_MEM_CHECK_RAW, self._ranges(memory, ranges), TM_MEM_CHECK_RAW_REPORT
        )

    def decode_dump(self, tm):
        out = DUMP_REPORT.unpack(tm.data)
        for i in out["items"]:
            i["ok"] = crc16_ccitt(i["data"]) == i["checksum"]
        return out

    def decode_check(self, tm):
        return CHECK_REPORT.unpack(tm.data)
