"""ST[06] memory scrubbing: read a memory back block by block, repair or report what changed.

When scrubbing of a memory is enabled (TC[6,13]) its content is taken as the reference: a
CRC-16 per block of ``block`` octets. Every cycle a few blocks of each scrubbed memory are
read from each of its copies and compared with the reference. A mirrored memory
(``s06_areas.MirroredMemory``) has a block that one copy still holds repaired from it, read
back and reported (``REPAIRED``); a block that no copy holds any more is reported once
(``UNCORRECTABLE``) until it is loaded again. Loads through service 6 update the reference
of the blocks they write, so scrubbing guards against every change that did not come
through a load.
"""

from obsw.compat import const
from obsw.crc import crc16_ccitt

REPAIRED = const(1)
UNCORRECTABLE = const(2)


class Scrub:
    """The scrubbing state of one memory area (see the module text)."""

    def __init__(self, area, block=256, refs=None):
        self.area = area
        self.block = block
        self.count = (area.size + block - 1) // block
        self.refs = list(refs) if refs is not None else self.baseline()
        if len(self.refs) != self.count:
            raise ValueError("%d block checksums for %d blocks" % (len(self.refs), self.count))
        self.next = 0
        self.bad = set()  # blocks reported uncorrectable, until loaded again
        self.repaired = 0
        self.uncorrectable = 0
        self.passes = 0

    def _span(self, i):
        off = i * self.block
        n = self.block if off + self.block <= self.area.size else self.area.size - off
        return off, n

    def baseline(self):
        first = self.area.copies()[0]
        out = []
        for i in range(self.count):
            off, n = self._span(i)
            out.append(crc16_ccitt(first.read(off, n)))
        return out

    def loaded(self, offset, n):
        """Take what a load wrote at ``offset`` (``n`` octets) as the new reference."""
        if n <= 0:
            return
        first = self.area.copies()[0]
        for i in range(offset // self.block, (offset + n - 1) // self.block + 1):
            off, k = self._span(i)
            self.refs[i] = crc16_ccitt(first.read(off, k))
            self.bad.discard(i)

    def step(self, blocks):
        """Scrub the next ``blocks`` blocks; returns [(REPAIRED or UNCORRECTABLE, offset)]."""
        out = []
        copies = self.area.copies()
        for _ in range(min(blocks, self.count)):
            i = self.next
            self.next = i + 1
            if self.next >= self.count:
                self.next = 0
                self.passes += 1
            off, n = self._span(i)
            ref = self.refs[i]
            datas = [c.read(off, n) for c in copies]
            good = None
            for d in datas:
                if crc16_ccitt(d) == ref:
                    good = d
                    break
            if good is None:
                if i not in self.bad:
                    self.bad.add(i)
                    self.uncorrectable += 1
                    out.append((UNCORRECTABLE, off))
                continue
            fixed = broken = False
            for c, d in zip(copies, datas):
                if d != good:
                    c.write(off, good)
                    if c.read(off, n) == good:
                        fixed = True
                    else:
                        broken = True  # the copy does not keep what is written to it
            if fixed:
                self.repaired += 1
                out.append((REPAIRED, off))
            if not broken:
                self.bad.discard(i)
            elif i not in self.bad:
                self.bad.add(i)
                self.uncorrectable += 1
                out.append((UNCORRECTABLE, off))
        return out
