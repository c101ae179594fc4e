"""A packet store of ST[15]: TM packets with their storage time, circular or bounded, on a log.

Packets are kept in memory and, when a filestore is given (``obsw.cfdp.filestore``), appended
to a log file, one record each: sequence number, storage time, length, the packet, CRC-32.
A restart replays the log; a record cut short by a power loss fails its CRC and ends the
replay, so the store comes back with every packet stored completely. Deleting content and
circular overwriting rewrite the log atomically (write a new copy, rename it over) once the
log has grown to twice the store's size, so a restart never sees a half-rewritten store.
"""

import struct

from obsw.crc import crc32

CIRCULAR = 0
BOUNDED = 1

_HEAD = ">IdH"  # sequence number, storage time (seconds), packet length
_HEAD_SIZE = 14
_CRC_SIZE = 4


def pack_record(seq, t, raw):
    body = struct.pack(_HEAD, seq, t, len(raw)) + bytes(raw)
    return body + struct.pack(">I", crc32(body))


def unpack_records(data):
    """(records, octets of the complete ones); stops at the first incomplete or damaged one."""
    out = []
    pos = 0
    n = len(data)
    mv = memoryview(data)
    while pos + _HEAD_SIZE <= n:
        seq, t, size = struct.unpack(_HEAD, mv[pos : pos + _HEAD_SIZE])
        end = pos + _HEAD_SIZE + size
        if end + _CRC_SIZE > n:
            break
        (crc,) = struct.unpack(">I", mv[end : end + _CRC_SIZE])
        if crc32(mv[pos:end]) != crc:
            break
        out.append((seq, t, bytes(mv[pos + _HEAD_SIZE : end])))
        pos = end + _CRC_SIZE
    return out, pos


class PacketStore:
    """One packet store: its configuration, content and retrieval state."""

    def __init__(self, sid, size, kind=CIRCULAR, vc=0, fs=None, folder="stores"):
        self.id = sid
        self.size = size  # octets of packets it may hold
        self.kind = kind
        self.vc = vc  # virtual channel of its retrievals
        self.enabled = False  # the storage function
        self.packets = []  # [seq, time, raw], oldest first
        self.used = 0
        self.next_seq = 1
        self.rejected = 0  # packets a full bounded store could not take
        self.overwritten = 0  # packets a circular store dropped for newer ones
        # open retrieval: from a start time tag onwards, in storage order, as packets come
        self.open_active = False
        self.open_start = 0.0
        self.open_next = 1  # the storage sequence number to send next
        # by-time-range (or by-sequence) retrieval: a list of packets to send
        self.range_queue = None
        self.fs = fs
        self.folder = folder
        self._log_size = 0

    # -------------------------------------------------------------------------- content

    @property
    def name(self):
        return "%s/store-%d.log" % (self.folder, self.id)

    def append(self, t, raw):
        """Store one packet at time ``t``; False if a full bounded store refused it."""
        n = len(raw)
        if n > self.size:
            self.rejected += 1
            return False
        if self.used + n > self.size:
            if self.kind == BOUNDED:
                self.rejected += 1
                return False
            while self.packets and self.used + n > self.size:
                self.used -= len(self.packets.pop(0)[2])
                self.overwritten += 1
        seq = self.next_seq
        self.next_seq = seq + 1
        self.packets.append([seq, t, raw])
        self.used += n
        if self.fs is not None:
            rec = pack_record(seq, t, raw)
            if self._log_size > 2 * self.size + 64:
                self.rewrite()
            else:
                h = self.fs.open_write(self.name, False)
                try:
                    h.write(self._log_size, rec)
                finally:
                    h.close()
                self._log_size += len(rec)
        return True

    def delete_up_to(self, t):
        """Drop every packet stored at or before time ``t``; returns how many."""
        keep = [p for p in self.packets if p[1] > t]
        n = len(self.packets) - len(keep)
        if n:
            self.packets = keep
            self.used = sum(len(p[2]) for p in keep)
            self.rewrite()
        return n

    def delete_through(self, seq):
        """Drop every packet up to storage sequence number ``seq`` (the ground has them)."""
        keep = [p for p in self.packets if p[0] > seq]
        n = len(self.packets) - len(keep)
        if n:
            self.packets = keep
            self.used = sum(len(p[2]) for p in keep)
            self.rewrite()
        return n

    def clear(self):
        self.packets = []
        self.used = 0
        self.rewrite()

    def shrink_to(self, size):
        self.size = size
        dropped = False
        while self.packets and self.used > size:
            self.used -= len(self.packets.pop(0)[2])
            dropped = True
        if dropped:
            self.rewrite()

    def oldest(self):
        return self.packets[0][1] if self.packets else 0.0

    def newest(self):
        return self.packets[-1][1] if self.packets else 0.0

    def fill(self):
        """Percentage of the store in use (0..100)."""
        return (self.used * 100) // self.size if self.size else 0

    def fill_from_open(self):
        """Percentage of the store taken by packets the open retrieval has still to send."""
        n = 0
        for seq, t, raw in self.packets:
            if seq >= self.open_next and t >= self.open_start:
                n += len(raw)
        return (n * 100) // self.size if self.size else 0

    # -------------------------------------------------------------------------- retrieval

    def select_time(self, start, end):
        return [p[2] for p in self.packets if start <= p[1] <= end]

    def select_sequence(self, first, last):
        return [p[2] for p in self.packets if first <= p[0] <= last]

    def next_open(self):
        """The next packet of the open retrieval (advancing it), or None."""
        for seq, t, raw in self.packets:
            if seq >= self.open_next and t >= self.open_start:
                self.open_next = seq + 1
                return raw
        if self.packets and self.packets[-1][0] >= self.open_next:
            self.open_next = self.packets[-1][0] + 1
        return None

    # -------------------------------------------------------------------------- persistence

    def rewrite(self):
        """Write the log anew from memory, atomically."""
        if self.fs is None:
            return
        parts = [pack_record(seq, t, raw) for seq, t, raw in self.packets]
        data = b"".join(parts)
        self._ready()
        self.fs.write_atomic(self.name, data)
        self._log_size = len(data)

    def _ready(self):
        if not self.fs.is_dir(self.folder):
            self.fs.mkdir(self.folder)

    def create_log(self):
        if self.fs is not None:
            self._ready()
            self.rewrite()

    def remove_log(self):
        if self.fs is not None and self.fs.exists(self.name):
            self.fs.delete(self.name)

    def load(self):
        """Replay the log after a restart; returns the number of packets found."""
        fs = self.fs
        if fs is None or not fs.exists(self.name):
            self.create_log() if fs is not None else None
            return 0
        data = fs.read_bytes(self.name)
        records, good = unpack_records(data)
        self.packets = []
        self.used = 0
        for seq, t, raw in records:
            self.packets.append([seq, t, raw])
            self.used += len(raw)
            if seq >= self.next_seq:
                self.next_seq = seq + 1
        self._log_size = good
        over = self.used > self.size
        while self.packets and self.used > self.size:
            self.used -= len(self.packets.pop(0)[2])
        if good != len(data) or over:
            self.rewrite()  # drop the torn tail (or what a smaller size no longer holds)
        return len(self.packets)

    def config(self):
        return [
            self.id,
            self.size,
            self.kind,
            self.vc,
            self.enabled,
            self.open_active,
            self.open_start,
            self.open_next,
            self.next_seq,
        ]

    @classmethod
    def from_config(cls, c, fs, folder):
        s = cls(c[0], c[1], c[2], c[3], fs, folder)
        s.enabled, s.open_active, s.open_start, s.open_next = c[4], c[5], c[6], c[7]
        s.next_seq = c[8]
        return s
