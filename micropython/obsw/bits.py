"""Progressive bit-level encoder and decoder: fields of any width at any bit offset, MSB first."""

import struct

from obsw.errors import too_short


class BitsTooShortError(ValueError):
    """A read past the end of the buffer, ``needed`` and ``got`` in bits (``obsw.errors``: the
    too-short kind)."""

    def __init__(self, what, needed, got):
        super().__init__(too_short(what, needed, got, "bits"))
        self.what = what
        self.needed = needed
        self.got = got


class BitsValueError(ValueError):
    """A value that does not fit the number of bits it is written with."""

    def __init__(self, value, nbits):
        super().__init__("value %r does not fit %d unsigned bits" % (value, nbits))
        self.value = value
        self.nbits = nbits


class Encoder:
    """Appends unsigned fields of any width; whole octets go straight into a bytearray.

    ``buf`` holds the complete octets written so far; up to 7 trailing bits wait in an
    accumulator until the next write completes their octet (or ``pad_to_byte`` does).
    """

    def __init__(self):
        self.buf = bytearray()
        self._acc = 0  # pending bits, right-aligned
        self._nacc = 0  # number of pending bits, 0..7

    @property
    def bit_length(self):
        return len(self.buf) * 8 + self._nacc

    @property
    def aligned(self):
        """True when the next write starts on an octet boundary."""
        return self._nacc == 0

    def write(self, value, nbits):
        """Append ``value`` as an ``nbits`` wide unsigned integer, most significant bit first."""
        if value < 0 or value >> nbits:
            raise BitsValueError(value, nbits)
        n = self._nacc
        if not n and not nbits & 7:
            if nbits:
                self.buf += value.to_bytes(nbits >> 3, "big")
            return
        acc = (self._acc << nbits) | value
        n += nbits
        if n >= 8:
            rem = n & 7
            self.buf += (acc >> rem).to_bytes(n >> 3, "big")
            acc &= (1 << rem) - 1
            n = rem
        self._acc = acc
        self._nacc = n

    def write_bytes(self, data):
        """Append octets (at the current bit offset, which need not be octet aligned)."""
        if not self._nacc:
            self.buf += data
        elif len(data):
            self.write(int.from_bytes(bytes(data), "big"), len(data) * 8)

    def write_struct(self, fmt, *values):
        """Append ``struct.pack(fmt, *values)``; ``fmt`` must be big-endian (``>``)."""
        if not self._nacc:
            self.buf += struct.pack(fmt, *values)
        else:
            self.write_bytes(struct.pack(fmt, *values))

    def pad_to_byte(self):
        """Fill the current octet with zero bits; returns how many were added."""
        n = self._nacc
        if not n:
            return 0
        self.buf.append((self._acc << (8 - n)) & 0xFF)
        self._acc = 0
        self._nacc = 0
        return 8 - n

    def getvalue(self):
        """The bytes written so far, the last partial octet padded with zero bits."""
        if self._nacc:
            return bytes(self.buf) + bytes(((self._acc << (8 - self._nacc)) & 0xFF,))
        return bytes(self.buf)


class Decoder:
    """Reads fields of any width from a buffer, starting ``bit_offset`` bits in."""

    def __init__(self, buf, bit_offset=0):
        self.buf = buf
        self.pos = bit_offset  # in bits
        self.end = len(buf) * 8
        if bit_offset < 0 or bit_offset > self.end:
            raise BitsTooShortError("buffer", bit_offset, self.end)

    @property
    def bit_position(self):
        return self.pos

    @property
    def bits_left(self):
        return self.end - self.pos

    @property
    def aligned(self):
        return not self.pos & 7

    def _need(self, nbits):
        if nbits < 0:
            raise ValueError("negative bit count %d" % nbits)
        if self.pos + nbits > self.end:
            raise BitsTooShortError("buffer", nbits, self.end - self.pos)

    def read(self, nbits):
        """Read an ``nbits`` wide unsigned integer."""
        pos = self.pos
        if pos + nbits > self.end or nbits < 0:
            self._need(nbits)
        start = pos >> 3
        if not pos & 7 and not nbits & 7:
            self.pos = pos + nbits
            return int.from_bytes(self.buf[start : start + (nbits >> 3)], "big")
        stop = (pos + nbits + 7) >> 3
        chunk = int.from_bytes(self.buf[start:stop], "big")
        self.pos = pos + nbits
        return (chunk >> ((stop << 3) - pos - nbits)) & ((1 << nbits) - 1)

    def read_bytes(self, n):
        """Read ``n`` octets (from the current bit offset) as bytes."""
        pos = self.pos
        self._need(n * 8)
        if not pos & 7:
            start = pos >> 3
            self.pos = pos + n * 8
            return bytes(self.buf[start : start + n])
        return self.read(n * 8).to_bytes(n, "big")

    def read_struct(self, fmt, size):
        """``struct.unpack(fmt, ...)`` over the next ``size`` octets (``fmt`` big-endian)."""
        pos = self.pos
        if pos + size * 8 > self.end:
            raise BitsTooShortError("buffer", size * 8, self.end - pos)
        if not pos & 7:
            self.pos = pos + size * 8
            return struct.unpack_from(fmt, self.buf, pos >> 3)
        return struct.unpack(fmt, self.read_bytes(size))

    def skip(self, nbits):
        self._need(nbits)
        self.pos += nbits

    def align(self):
        """Skip to the next octet boundary; returns the number of bits skipped."""
        n = -self.pos & 7
        self._need(n)
        self.pos += n
        return n

    def rest(self):
        """All remaining octets (the decoder must be octet aligned)."""
        return self.read_bytes(self.bits_left >> 3)
