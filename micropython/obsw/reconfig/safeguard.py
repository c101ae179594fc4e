"""Safeguard memory: records kept on two M24512 EEPROMs at once, safe against resets and noise.

Layout: record k owns two slots on every device (A/B alternation); a slot is ``slot_pages``
whole pages. A slot holds, before coding, ``magic u8, record u8, length u16, sequence u32,
payload, CRC-32`` padded to 8-byte blocks, then SECDED Hamming(72,64) per block
(`obsw.reconfig.ecc`): single bit errors on the I2C transfer (the M24512's own ECC guards only
the cells) are corrected, double ones detected, and the CRC catches the rest.

A write goes to the slot of each device that does not hold that device's newest valid copy,
device after device, and is read back and compared (rewritten on mismatch). A reset at any
instant therefore damages at most the slot being written, and a read - the valid copy with the
highest sequence on any device - returns the old record or the new one. Reads retry transfers
that fail their checks, and repair: a device lacking the newest copy gets it in its other slot.
"""

import struct

from obsw.compat import const
from obsw.crc import crc32
from obsw.reconfig import ecc
from obsw.reconfig.eeprom import PAGE, SIZE

_MAGIC = const(0x5A)
_HEADER = const(8)
_TRAILER = const(4)


class RecordError(ValueError):
    """A record id outside the layout or a payload larger than a slot holds."""

    def __init__(self, msg, record=None):
        super().__init__(msg)
        self.record = record


class _Copy:
    def __init__(self, device, slot, seq, payload, fixed):
        self.device = device
        self.slot = slot
        self.seq = seq
        self.payload = payload
        self.fixed = fixed


class Safeguard:
    """Records 0..records-1 on ``devices`` (M24512 objects, written in order)."""

    def __init__(self, devices, records=8, slot_pages=1, base_page=0, retries=3):
        self.devices = list(devices)
        self.records = records
        self.slot_pages = slot_pages
        self.base_page = base_page
        self.retries = retries
        self.blocks = (slot_pages * PAGE) // ecc.CODED
        self.capacity = self.blocks * ecc.BLOCK - _HEADER - _TRAILER
        if (base_page + 2 * records * slot_pages) * PAGE > SIZE:
            raise RecordError(
                "%d records of %d pages do not fit the EEPROM" % (records, slot_pages)
            )
        self.counters = {
            "reads": 0,
            "writes": 0,
            "corrected": 0,
            "bad_reads": 0,
            "retries": 0,
            "rewrites": 0,
            "repairs": 0,
            "device_errors": 0,
        }
        self._seq = {}  # record -> newest sequence seen
        self._slots = {}  # (record, device) -> [seq of slot 0, seq of slot 1] (-1: invalid)

    def _address(self, record, slot):
        return (self.base_page + (2 * record + slot) * self.slot_pages) * PAGE

    def _check_record(self, record):
        if not 0 <= record < self.records:
            raise RecordError("record %r outside 0..%d" % (record, self.records - 1), record)

    # -- coding -------------------------------------------------------------------------------

    def encode(self, record, seq, payload):
        plain = bytearray(self.blocks * ecc.BLOCK)
        n = len(payload)
        struct.pack_into(">BBHI", plain, 0, _MAGIC, record, n, seq)
        plain[_HEADER : _HEADER + n] = payload
        struct.pack_into(">I", plain, _HEADER + n, crc32(memoryview(plain)[: _HEADER + n]))
        return bytes(ecc.encode(plain))

    def decode(self, record, raw):
        """(seq, payload, corrected bits) of a slot's bytes, or None if it holds no valid copy;
        RecordError for bytes that are not a slot's length (a read of the wrong size)."""
        want = self.blocks * ecc.CODED
        if len(raw) != want:
            raise RecordError("slot of %d octets, expected %d" % (len(raw), want), record)
        try:
            plain, fixed = ecc.decode(raw, self.blocks)
        except ecc.EccError:
            return None
        magic, rid, n, seq = struct.unpack_from(">BBHI", plain, 0)
        if magic != _MAGIC or rid != record or n > self.capacity:
            return None
        (crc,) = struct.unpack_from(">I", plain, _HEADER + n)
        if crc != crc32(memoryview(plain)[: _HEADER + n]):
            return None
        return seq, bytes(plain[_HEADER : _HEADER + n]), fixed

    # -- reading ------------------------------------------------------------------------------

    def _read_slot(self, d, record, slot):
        """The slot's copy, retrying transfers that do not decode; None if it holds none."""
        dev = self.devices[d]
        addr = self._address(record, slot)
        n = self.blocks * ecc.CODED
        for attempt in range(self.retries):
            if attempt:
                self.counters["retries"] += 1
            try:
                got = self.decode(record, dev.read(addr, n))
            except (OSError, RecordError):  # a failed or short transfer: try again
                self.counters["device_errors"] += 1
                continue
            if got is not None:
                self.counters["corrected"] += got[2]
                return _Copy(d, slot, got[0], got[1], got[2])
        self.counters["bad_reads"] += 1
        return None

    def _scan(self, record):
        copies = []
        for d in range(len(self.devices)):
            seqs = [-1, -1]
            for slot in (0, 1):
                c = self._read_slot(d, record, slot)
                if c is not None:
                    copies.append(c)
                    seqs[slot] = c.seq
            self._slots[(record, d)] = seqs
        return copies

    def read(self, record, repair=True):
        """The newest complete payload of ``record`` (None if never written); repairs copies."""
        self._check_record(record)
        self.counters["reads"] += 1
        copies = self._scan(record)
        best = None
        for c in copies:
            if best is None or c.seq > best.seq:
                best = c
        if best is None:
            self._seq[record] = -1
            return None
        self._seq[record] = best.seq
        if repair:
            for d in range(len(self.devices)):
                seqs = self._slots[(record, d)]
                fixed = False
                for c in copies:
                    if c.device == d and c.seq == best.seq and c.fixed:
                        fixed = True
                if best.seq not in seqs or (fixed and seqs[0] != seqs[1]):
                    self.counters["repairs"] += 1
                    self._put(d, record, best.seq, best.payload)
        return best.payload

    # -- writing ------------------------------------------------------------------------------

    def _target(self, record, d):
        seqs = self._slots[(record, d)]
        newest = 0 if seqs[0] >= seqs[1] else 1
        return 1 - newest if seqs[newest] >= 0 else 0

    def _put(self, d, record, seq, payload):
        """Write one copy into device d's older slot and verify it; True when it reads back."""
        slot = self._target(record, d)
        raw = self.encode(record, seq, payload)
        addr = self._address(record, slot)
        dev = self.devices[d]
        seqs = self._slots[(record, d)]
        seqs[slot] = -1  # from now on the slot is in doubt until verified
        for attempt in range(self.retries):
            if attempt:
                self.counters["rewrites"] += 1
            try:
                dev.write(addr, raw)
                for _ in range(self.retries):
                    if dev.read(addr, len(raw)) == raw:
                        seqs[slot] = seq
                        return True
            except OSError:
                self.counters["device_errors"] += 1
        # not verified byte for byte: accept what decodes to the same record
        got = None
        try:
            got = self.decode(record, dev.read(addr, len(raw)))
        except (OSError, RecordError):
            self.counters["device_errors"] += 1
        if got is not None and got[0] == seq and got[1] == payload:
            seqs[slot] = seq
            return True
        return False

    def write(self, record, payload):
        """Store ``payload`` as the new content of ``record``; returns how many devices hold it."""
        self._check_record(record)
        if len(payload) > self.capacity:
            raise RecordError(
                "payload of %d bytes exceeds the slot's %d" % (len(payload), self.capacity), record
            )
        if record not in self._seq:
            self.read(record, repair=False)
        seq = (self._seq[record] + 1) & 0xFFFFFFFF
        self.counters["writes"] += 1
        ok = 0
        for d in range(len(self.devices)):
            if self._put(d, record, seq, bytes(payload)):
                ok += 1
        self._seq[record] = seq
        return ok
