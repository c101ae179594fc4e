"""ST[06] service user: memory requests and the decoding of their reports.

Raw ranges are (address, length) pairs, object ranges (offset, length); files are full paths
(``SAT:/dumps/image.bin``). Checksums default to the right one (CRC-16/CCITT-FALSE of the
data); decoded dumps verify theirs (``ok`` per item).
"""

from obsw.crc import crc16_ccitt
from obsw.pus.messages import (
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
from obsw.pus.services.base import ServiceUser
from obsw.pus.services.file_refs import split_path


def _sum(data, checksum):
    return crc16_ccitt(data) if checksum is None else checksum


def _verified(out):
    for i in out["items"]:
        i["ok"] = crc16_ccitt(i["data"]) == i["checksum"]
    return out


class MemoryUser(ServiceUser):
    """The service 6 user (see the module text)."""

    SERVICE = SERVICE_MEMORY_MANAGEMENT
    DECODERS = (
        (TM_MEM_DUMP_OBJECT_REPORT, "decode_object_dump"),
        (TM_MEM_DUMP_RAW_REPORT, "decode_dump"),
        (TM_MEM_CHECK_OBJECT_REPORT, "decode_object_check"),
        (TM_MEM_CHECK_RAW_REPORT, "decode_check"),
        (TM_MEM_CHECK_OBJECT_WHOLE_REPORT, "decode_whole_object"),
    )

    # -------------------------------------------------------------------------- raw memory

    def load(self, apid, memory, address, data, checksum=None):
        """TC[6,2]: load ``data`` at ``address``."""
        items = [{"address": address, "data": bytes(data), "checksum": _sum(data, checksum)}]
        return self.request(
            apid, TC_MEM_LOAD_RAW, lay.LOAD.pack({"memory": memory, "items": items})
        )

    def load_atomic(self, apid, memory, address, data, checksum=None):
        """TC[6,11]: load one area whole or not at all."""
        values = {
            "memory": memory,
            "address": address,
            "data": bytes(data),
            "checksum": _sum(data, checksum),
        }
        return self.request(apid, TC_MEM_LOAD_RAW_ATOMIC, lay.ATOMIC_LOAD.pack(values))

    def _ranges(self, memory, ranges):
        items = [{"address": a, "length": n} for a, n in ranges]
        return lay.RANGES.pack({"memory": memory, "items": items})

    def dump(self, apid, memory, ranges):
        """TC[6,5]; ``ranges`` is a list of (address, length)."""
        return self.request(
            apid, TC_MEM_DUMP_RAW, self._ranges(memory, ranges), TM_MEM_DUMP_RAW_REPORT
        )

    def check(self, apid, memory, ranges):
        """TC[6,9]."""
        return self.request(
            apid, TC_MEM_CHECK_RAW, self._ranges(memory, ranges), TM_MEM_CHECK_RAW_REPORT
        )

    def load_by_reference(self, apid, memory, items):
        """TC[6,19]; ``items``: (address, path of the file, checksum of its content)."""
        out = []
        for address, path, checksum in items:
            repo, name = split_path(path)
            out.append(
                {"address": address, "repository": repo, "file": name, "checksum": checksum}
            )
        data = lay.LOAD_BY_REFERENCE.pack({"memory": memory, "items": out})
        return self.request(apid, TC_MEM_LOAD_RAW_BY_REFERENCE, data)

    def dump_to_file(self, apid, memory, items):
        """TC[6,20]; ``items``: (address, length, path of the file to write)."""
        out = []
        for address, length, path in items:
            repo, name = split_path(path)
            out.append({"address": address, "length": length, "repository": repo, "file": name})
        data = lay.DUMP_TO_FILE.pack({"memory": memory, "items": out})
        return self.request(apid, TC_MEM_DUMP_RAW_TO_FILE, data)

    # -------------------------------------------------------------------------- object memory

    def load_object(self, apid, memory, obj, offset, data, checksum=None):
        """TC[6,1]: load ``data`` at ``offset`` in object ``obj`` (0: the whole memory)."""
        items = [{"offset": offset, "data": bytes(data), "checksum": _sum(data, checksum)}]
        values = {"memory": memory, "object": obj, "items": items}
        return self.request(apid, TC_MEM_LOAD_OBJECT, lay.OBJECT_LOAD.pack(values))

    def _object_ranges(self, memory, obj, ranges):
        items = [{"offset": o, "length": n} for o, n in ranges]
        return lay.OBJECT_RANGES.pack({"memory": memory, "object": obj, "items": items})

    def dump_object(self, apid, memory, obj, ranges):
        """TC[6,3]; ``ranges`` is a list of (offset, length)."""
        data = self._object_ranges(memory, obj, ranges)
        return self.request(apid, TC_MEM_DUMP_OBJECT, data, TM_MEM_DUMP_OBJECT_REPORT)

    def check_object(self, apid, memory, obj, ranges):
        """TC[6,7]."""
        data = self._object_ranges(memory, obj, ranges)
        return self.request(apid, TC_MEM_CHECK_OBJECT, data, TM_MEM_CHECK_OBJECT_REPORT)

    def check_whole_object(self, apid, memory, obj):
        """TC[6,17]: the checksum of a whole object (TM[6,18])."""
        data = lay.ONE_OBJECT.pack({"memory": memory, "object": obj})
        return self.request(
            apid, TC_MEM_CHECK_OBJECT_WHOLE, data, TM_MEM_CHECK_OBJECT_WHOLE_REPORT
        )

    def load_object_by_reference(self, apid, memory, obj, items):
        """TC[6,21]; ``items``: (offset, path of the file, checksum of its content)."""
        out = []
        for offset, path, checksum in items:
            repo, name = split_path(path)
            out.append({"offset": offset, "repository": repo, "file": name, "checksum": checksum})
        values = {"memory": memory, "object": obj, "items": out}
        data = lay.OBJECT_LOAD_BY_REFERENCE.pack(values)
        return self.request(apid, TC_MEM_LOAD_OBJECT_BY_REFERENCE, data)

    def dump_object_to_file(self, apid, memory, obj, items):
        """TC[6,22]; ``items``: (offset, length, path of the file to write)."""
        out = []
        for offset, length, path in items:
            repo, name = split_path(path)
            out.append({"offset": offset, "length": length, "repository": repo, "file": name})
        values = {"memory": memory, "object": obj, "items": out}
        data = lay.OBJECT_DUMP_TO_FILE.pack(values)
        return self.request(apid, TC_MEM_DUMP_OBJECT_TO_FILE, data)

    # -------------------------------------------------------------------------- control

    def abort_dumps(self, apid):
        """TC[6,12]: abort every dump to file in progress."""
        return self.request(apid, TC_MEM_ABORT_ALL_DUMPS)

    def _memory(self, apid, message_type, memory):
        return self.request(apid, message_type, lay.ONE_MEMORY.pack({"memory": memory}))

    def enable_scrubbing(self, apid, memory):
        """TC[6,13]."""
        return self._memory(apid, TC_MEM_ENABLE_SCRUBBING, memory)

    def disable_scrubbing(self, apid, memory):
        """TC[6,14]."""
        return self._memory(apid, TC_MEM_DISABLE_SCRUBBING, memory)

    def protect(self, apid, memory):
        """TC[6,15]: enable the write protection of ``memory``."""
        return self._memory(apid, TC_MEM_ENABLE_WRITE_PROTECTION, memory)

    def unprotect(self, apid, memory):
        """TC[6,16]."""
        return self._memory(apid, TC_MEM_DISABLE_WRITE_PROTECTION, memory)

    # -------------------------------------------------------------------------- reports

    def decode_dump(self, tm):
        return _verified(lay.DUMP_REPORT.unpack(tm.data))

    def decode_object_dump(self, tm):
        return _verified(lay.OBJECT_DUMP_REPORT.unpack(tm.data))

    def decode_check(self, tm):
        return lay.CHECK_REPORT.unpack(tm.data)

    def decode_object_check(self, tm):
        return lay.OBJECT_CHECK_REPORT.unpack(tm.data)

    def decode_whole_object(self, tm):
        return lay.OBJECT_WHOLE_REPORT.unpack(tm.data)
