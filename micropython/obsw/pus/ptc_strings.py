"""PTC 6 bit-string, 7 octet-string, 8 character-string and 12 packet field types."""

from obsw.bits import BitsTooShortError
from obsw.pus.fields import (
    PTC_BIT_STRING,
    PTC_CHARACTER_STRING,
    PTC_OCTET_STRING,
    PTC_PACKET,
    FieldType,
    FieldTypeError,
)

PACKET_TC = 0  # PTC 12 PFC 0: a whole telecommand packet
PACKET_TM = 1  # PTC 12 PFC 1: a whole telemetry packet

_DEFAULT_LENGTH_BITS = 16


def _length_params(ptc, pfc, mission):
    length_bits = mission.pop("length_bits", _DEFAULT_LENGTH_BITS)
    max_length = mission.pop("max_length", None)
    if not isinstance(length_bits, int) or not 1 <= length_bits <= 32:
        raise FieldTypeError(ptc, pfc, "length_bits must be 1..32, got %r" % (length_bits,))
    limit = (1 << length_bits) - 1
    if max_length is None:
        max_length = limit
    if not 0 <= max_length <= limit:
        raise FieldTypeError(ptc, pfc, "max_length %r does not fit the prefix" % (max_length,))
    return length_bits, max_length


def make(ptc, pfc, mission):
    mission = dict(mission)
    if ptc == PTC_PACKET:
        codec = mission.pop("codec", None)
        if mission:
            raise FieldTypeError(ptc, pfc, "unknown parameters %s" % sorted(mission))
        if pfc in (PACKET_TC, PACKET_TM):
            return Packet(pfc, codec)
        raise FieldTypeError(ptc, pfc)
    if not isinstance(pfc, int) or pfc < 0:
        raise FieldTypeError(ptc, pfc, "PFC is 0 (variable) or a length")
    if pfc == 0:
        length_bits, max_length = _length_params(ptc, pfc, mission)
    else:
        length_bits, max_length = 0, pfc
    if mission:
        raise FieldTypeError(ptc, pfc, "unknown parameters %s" % sorted(mission))
    if ptc == PTC_BIT_STRING:
        return BitString(pfc, length_bits, max_length)
    if ptc == PTC_OCTET_STRING:
        return OctetString(pfc, length_bits, max_length)
    return CharacterString(pfc, length_bits, max_length)


class BitString(FieldType):
    """PTC 6: PFC > 0 is a fixed string of PFC bits, its value an int of that many bits;
    PFC 0 is a ``length_bits`` count of bits followed by the bits, its value ``(nbits, int)``.
    """

    ptc = PTC_BIT_STRING
    name = "bit-string"

    def __init__(self, pfc, length_bits, max_length):
        self.pfc = pfc
        self.length_bits = length_bits
        self.max_length = max_length
        self.bits = pfc or None

    def check(self, value):
        if self.pfc:
            n, v = self.pfc, value
        else:
            try:
                n, v = value
            except (TypeError, ValueError):
                self.fail(value, "(number of bits, value)")
            if not isinstance(n, int) or not 0 <= n <= self.max_length:
                self.fail(value, "a bit count in 0..%d" % self.max_length)
        if not isinstance(v, int) or isinstance(v, bool) or v < 0 or v >> n:
            self.fail(value, "an unsigned value of %d bits" % n)
        return n, v

    def write(self, enc, value):
        n, v = self.check(value)
        if not self.pfc:
            enc.write(n, self.length_bits)
        enc.write(v, n)

    def read(self, dec):
        if self.pfc:
            return dec.read(self.pfc)
        n = dec.read(self.length_bits)
        if n > self.max_length:
            self.fail(n, "a bit count up to %d" % self.max_length)
        return n, dec.read(n)


class OctetString(FieldType):
    """PTC 7: PFC > 0 is exactly PFC octets; PFC 0 a ``length_bits`` octet count, then octets."""

    ptc = PTC_OCTET_STRING
    name = "octet-string"

    def __init__(self, pfc, length_bits, max_length):
        self.pfc = pfc
        self.length_bits = length_bits
        self.max_length = max_length
        self.bits = pfc * 8 or None

    def _octets(self, value):
        if not isinstance(value, (bytes, bytearray, memoryview)):
            self.fail(value, "bytes")
        return value

    def check(self, value):
        data = self._octets(value)
        n = len(data)
        if self.pfc:
            if n != self.pfc:
                self.fail(value, "exactly %d octets" % self.pfc)
        elif n > self.max_length:
            self.fail(value, "at most %d octets" % self.max_length)
        return data

    def write(self, enc, value):
        data = self.check(value)
        if not self.pfc:
            enc.write(len(data), self.length_bits)
        enc.write_bytes(data)

    def _read_octets(self, dec):
        if self.pfc:
            return dec.read_bytes(self.pfc)
        n = dec.read(self.length_bits)
        if n > self.max_length:
            self.fail(n, "a length up to %d" % self.max_length)
        return dec.read_bytes(n)

    def read(self, dec):
        return self._read_octets(dec)


class CharacterString(OctetString):
    """PTC 8: like the octet string, with the octets read and written as UTF-8 text.

    Lengths count octets. A ``bytes`` value is written unchanged (for other encodings).
    """

    ptc = PTC_CHARACTER_STRING
    name = "character-string"

    def _octets(self, value):
        if isinstance(value, str):
            return value.encode("utf-8")
        if isinstance(value, (bytes, bytearray)):
            return value
        self.fail(value, "a string")

    def read(self, dec):
        data = self._read_octets(dec)
        try:
            return data.decode("utf-8")
        except UnicodeError:
            self.fail(data, "UTF-8 text")


class Packet(FieldType):
    """PTC 12: a whole space packet (TC for PFC 0, TM for PFC 1) as a field.

    The length comes from the packet's own primary header. The value is its bytes, or with a
    ``codec`` (a class with ``pack()`` on instances and ``unpack(buf)``) a decoded packet.
    """

    ptc = PTC_PACKET
    bits = None

    def __init__(self, pfc, codec=None):
        self.pfc = pfc
        self.codec = codec
        self.name = "TC packet" if pfc == PACKET_TC else "TM packet"

    def check(self, value):
        data = value
        if not isinstance(data, (bytes, bytearray, memoryview)):
            try:
                data = value.pack()
            except AttributeError:
                self.fail(value, "packet bytes or an object with pack()")
        self._check_header(data, value)
        return data

    def _check_header(self, data, value):
        if len(data) < 7:
            self.fail(value, "a space packet (at least 7 octets)")
        if len(data) != ((data[4] << 8) | data[5]) + 7:
            self.fail(value, "a space packet whose length field matches its size")
        is_tc = (data[0] >> 4) & 1
        if is_tc != (self.pfc == PACKET_TC):
            self.fail(value, "a %s (packet type bit %d)" % (self.name, self.pfc == PACKET_TC))

    def write(self, enc, value):
        enc.write_bytes(self.check(value))

    def read(self, dec):
        start = dec.bit_position
        header = dec.read_bytes(6)
        size = ((header[4] << 8) | header[5]) + 1
        if dec.bits_left < size * 8:
            left = dec.bits_left
            dec.pos = start
            raise BitsTooShortError("buffer", size * 8, left)
        data = header + dec.read_bytes(size)
        self._check_header(data, data)
        if self.codec is not None:
            return self.codec.unpack(data)
        return data
