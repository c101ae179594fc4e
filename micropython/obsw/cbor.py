"""CBOR (RFC 8949) in pure Python: deterministic encoder and strict decoder for board and host.

Encoding is deterministic (RFC 8949 4.2): definite lengths, shortest integers and lengths,
floats in the shortest of half/single/double that keeps the value (NaN as 0xf97e00), bignums
(tags 2/3) beyond 64 bits, map keys sorted length-first (RFC 8949 4.2.3, the RFC 7049 order),
so the bytes equal ``cbor2.dumps(value, canonical=True)``.

Values: int, bool, None, float, str, bytes/bytearray/memoryview, list/tuple, dict (any
hashable key), ``UNDEFINED``, ``Tag``, ``Simple``. Decoding gives lists (tuples as map keys)
and bytes, accepts indefinite lengths, and raises ``CborDecodeError`` on malformed input.
"""

import struct
from math import frexp, ldexp

from obsw.compat import const

MAX_DEPTH = const(32)  # nesting limit: keeps the C stack safe on a Pyboard

_UINT = const(0x00)
_NINT = const(0x20)
_BYTES = const(0x40)
_TEXT = const(0x60)
_ARRAY = const(0x80)
_MAP = const(0xA0)
_TAG = const(0xC0)
_FALSE = const(0xF4)
_TRUE = const(0xF5)
_NULL = const(0xF6)
_UNDEF = const(0xF7)
_BREAK = const(0xFF)
_TAG_POSBIG = const(2)
_TAG_NEGBIG = const(3)
_U64_LIMIT = 1 << 64


class CborDecodeError(ValueError):
    """Malformed or unsupported CBOR input; ``offset`` is where decoding stopped."""

    def __init__(self, msg, offset=None):
        super().__init__(msg)
        self.offset = offset


class CborEncodeError(TypeError):
    """A value that CBOR cannot carry here (unsupported type, nesting too deep)."""

    def __init__(self, msg):
        super().__init__(msg)


class _Undefined:
    def __repr__(self):
        return "UNDEFINED"

    def __bool__(self):
        return False


UNDEFINED = _Undefined()


class Tag:
    """A tagged data item (major type 6) that the codec does not interpret itself."""

    def __init__(self, tag, value):
        if not isinstance(tag, int) or tag < 0 or tag >= _U64_LIMIT:
            raise ValueError("CBOR tag must be an unsigned 64-bit int, got %r" % (tag,))
        self.tag = tag
        self.value = value

    def __eq__(self, other):
        return isinstance(other, Tag) and self.tag == other.tag and self.value == other.value

    def __ne__(self, other):
        return not self.__eq__(other)

    def __hash__(self):
        return hash((self.tag, _freeze(self.value)))

    def __repr__(self):
        return "Tag(%d, %r)" % (self.tag, self.value)


class Simple:
    """A simple value (major type 7) other than false, true, null and undefined."""

    def __init__(self, value):
        if not isinstance(value, int) or not (0 <= value < 20 or 32 <= value < 256):
            raise ValueError("CBOR simple value must be 0..19 or 32..255, got %r" % (value,))
        self.value = value

    def __eq__(self, other):
        return isinstance(other, Simple) and self.value == other.value

    def __ne__(self, other):
        return not self.__eq__(other)

    def __hash__(self):
        return hash(("simple", self.value))

    def __repr__(self):
        return "Simple(%d)" % self.value


# ---------------------------------------------------------------------------------------- encode


def dumps(value, max_depth=MAX_DEPTH):
    """Encode ``value`` deterministically and return the bytes."""
    out = bytearray()
    _encode(out, value, max_depth)
    return bytes(out)


def _head(out, major, n):
    if n < 24:
        out.append(major | n)
    elif n < 0x100:
        out.append(major | 24)
        out.append(n)
    elif n < 0x10000:
        out += struct.pack(">BH", major | 25, n)
    elif n < 0x100000000:
        out += struct.pack(">BI", major | 26, n)
    else:
        out += struct.pack(">BQ", major | 27, n)


def _int_bytes(n):
    size = 0
    m = n
    while m:
        m >>= 8
        size += 1
    return n.to_bytes(size, "big")


def _encode(out, v, depth):
    t = type(v)
    if t is int:
        if v >= 0:
            if v < _U64_LIMIT:
                _head(out, _UINT, v)
            else:
                _head(out, _TAG, _TAG_POSBIG)
                b = _int_bytes(v)
                _head(out, _BYTES, len(b))
                out += b
        else:
            n = -1 - v
            if n < _U64_LIMIT:
                _head(out, _NINT, n)
            else:
                _head(out, _TAG, _TAG_NEGBIG)
                b = _int_bytes(n)
                _head(out, _BYTES, len(b))
                out += b
    elif t is str:
        b = v.encode()
        _head(out, _TEXT, len(b))
        out += b
    elif t is bytes or t is bytearray or t is memoryview:
        _head(out, _BYTES, len(v))
        out += v
    elif t is list or t is tuple:
        if depth <= 0:
            raise CborEncodeError("CBOR nesting deeper than the limit")
        _head(out, _ARRAY, len(v))
        for x in v:
            _encode(out, x, depth - 1)
    elif t is dict:
        if depth <= 0:
            raise CborEncodeError("CBOR nesting deeper than the limit")
        _head(out, _MAP, len(v))
        pairs = []
        for k in v:
            kb = bytearray()
            _encode(kb, k, depth - 1)
            pairs.append((len(kb), bytes(kb), k))
        pairs.sort(key=_pair_key)
        for _, kb, k in pairs:
            out += kb
            _encode(out, v[k], depth - 1)
    elif t is bool:
        out.append(_TRUE if v else _FALSE)
    elif v is None:
        out.append(_NULL)
    elif t is float:
        _encode_float(out, v)
    elif v is UNDEFINED:
        out.append(_UNDEF)
    elif t is Tag:
        if depth <= 0:
            raise CborEncodeError("CBOR nesting deeper than the limit")
        _head(out, _TAG, v.tag)
        _encode(out, v.value, depth - 1)
    elif t is Simple:
        if v.value < 24:
            out.append(0xE0 | v.value)
        else:
            out.append(0xF8)
            out.append(v.value)
    elif isinstance(v, int):  # int subclasses other than bool
        _encode(out, int(v), depth)
    else:
        raise CborEncodeError("cannot encode %s as CBOR" % type(v).__name__)


def _pair_key(p):
    return (p[0], p[1])


def _half_bits(x):
    """Return the IEEE 754 half-precision bits of ``x`` if it is exactly representable."""
    sign = 0x8000 if struct.pack(">d", x)[0] & 0x80 else 0
    a = -x if sign else x
    if a == 0:
        return sign
    if a == float("inf"):
        return sign | 0x7C00
    m, e = frexp(a)  # a = m * 2**e, 0.5 <= m < 1
    if e > 16:
        return None
    if e >= -13:  # normal: a = (1 + f/1024) * 2**(e-1)
        mant = m * 2048
        if mant != int(mant):
            return None
        return sign | ((e + 14) << 10) | (int(mant) - 1024)
    frac = ldexp(a, 24)  # subnormal: a = frac * 2**-24
    if frac != int(frac) or frac >= 1024:
        return None
    return sign | int(frac)


def _encode_float(out, x):
    if x != x:
        out += b"\xf9\x7e\x00"
        return
    h = _half_bits(x)
    if h is not None:
        out += struct.pack(">BH", 0xF9, h)
        return
    try:
        s = struct.pack(">f", x)
        single = struct.unpack(">f", s)[0] == x
    except (OverflowError, ValueError):
        single = False
    if single:
        out.append(0xFA)
        out += s
    else:
        out.append(0xFB)
        out += struct.pack(">d", x)


# ---------------------------------------------------------------------------------------- decode


def loads(data, max_depth=MAX_DEPTH):
    """Decode exactly one CBOR item from ``data``; trailing bytes are an error."""
    buf = bytes(data)
    value, end = _item(buf, 0, max_depth)
    if value is _BREAK_MARK:
        raise CborDecodeError("unexpected break code at offset 0", 0)
    if end != len(buf):
        raise CborDecodeError(
            "trailing data: item ends at offset %d, input has %d bytes" % (end, len(buf)), end
        )
    return value


def decode_from(data, offset=0, max_depth=MAX_DEPTH):
    """Decode one item starting at ``offset``; return ``(value, end_offset)``."""
    buf = bytes(data)
    value, end = _item(buf, offset, max_depth)
    if value is _BREAK_MARK:
        raise CborDecodeError("unexpected break code at offset %d" % offset, offset)
    return value, end


_BREAK_MARK = object()


def _truncated(what, pos, need, n):
    return CborDecodeError(
        "CBOR truncated: %s at offset %d needs %d bytes, %d left" % (what, pos, need, n - pos), pos
    )


def _argument(buf, pos, ai, n):
    """Read the argument that follows an initial byte; return (arg, new_pos)."""
    if ai < 24:
        return ai, pos
    if ai < 28:
        size = 1 << (ai - 24)
        if pos + size > n:
            raise _truncated("argument", pos, size, n)
        return int.from_bytes(buf[pos : pos + size], "big"), pos + size
    raise CborDecodeError(
        "CBOR additional info %d is reserved (offset %d)" % (ai, pos - 1), pos - 1
    )


def _item(buf, pos, depth):
    n = len(buf)
    if pos >= n:
        raise _truncated("data item", pos, 1, n)
    ib = buf[pos]
    start = pos
    pos += 1
    major = ib & 0xE0
    ai = ib & 0x1F
    if major == 0xE0:
        return _special(buf, pos, ai, n, start)
    if ai == 31:
        if major == _BYTES or major == _TEXT:
            return _indefinite_string(buf, pos, major, depth, start)
        if major == _ARRAY or major == _MAP:
            return _indefinite_container(buf, pos, major, depth, start)
        raise CborDecodeError(
            "CBOR additional info 31 is invalid for major type %d (offset %d)"
            % (major >> 5, start),
            start,
        )
    arg, pos = _argument(buf, pos, ai, n)
    if major == _UINT:
        return arg, pos
    if major == _NINT:
        return -1 - arg, pos
    if major == _BYTES or major == _TEXT:
        if arg > n - pos:
            raise _truncated("string body", pos, arg, n)
        chunk = buf[pos : pos + arg]
        if major == _TEXT:
            chunk = _text(chunk, pos)
        return chunk, pos + arg
    if depth <= 0:
        raise CborDecodeError("CBOR nesting deeper than the limit at offset %d" % start, start)
    if major == _ARRAY:
        if arg > n - pos:
            raise _truncated("array of %d items" % arg, pos, arg, n)
        items = []
        for _ in range(arg):
            v, pos = _item(buf, pos, depth - 1)
            if v is _BREAK_MARK:
                raise CborDecodeError("unexpected break code at offset %d" % (pos - 1), pos - 1)
            items.append(v)
        return items, pos
    if major == _MAP:
        if arg > (n - pos) // 2:
            raise _truncated("map of %d pairs" % arg, pos, 2 * arg, n)
        d = {}
        for _ in range(arg):
            pos = _pair(buf, pos, depth - 1, d)
        return d, pos
    # tag
    v, pos = _item(buf, pos, depth - 1)
    if v is _BREAK_MARK:
        raise CborDecodeError("unexpected break code at offset %d" % (pos - 1), pos - 1)
    if arg == _TAG_POSBIG or arg == _TAG_NEGBIG:
        if type(v) is not bytes:
            raise CborDecodeError(
                "CBOR bignum tag %d needs a byte string, got %s (offset %d)"
                % (arg, type(v).__name__, start),
                start,
            )
        m = int.from_bytes(v, "big") if v else 0
        return (m if arg == _TAG_POSBIG else -1 - m), pos
    return Tag(arg, v), pos


def _text(chunk, pos):
    try:
        return str(chunk, "utf-8")
    except (UnicodeError, ValueError):
        raise CborDecodeError(
            "CBOR text string at offset %d is not valid UTF-8" % pos, pos
        ) from None


def _pair(buf, pos, depth, d):
    k, pos = _item(buf, pos, depth)
    if k is _BREAK_MARK:
        raise CborDecodeError("unexpected break code at offset %d" % (pos - 1), pos - 1)
    v, pos = _item(buf, pos, depth)
    if v is _BREAK_MARK:
        raise CborDecodeError(
            "break code in place of a map value at offset %d" % (pos - 1), pos - 1
        )
    try:
        d[_freeze(k)] = v
    except TypeError:
        raise CborDecodeError(
            "CBOR map key of type %s is not supported" % type(k).__name__, pos
        ) from None
    return pos


def _freeze(k):
    if type(k) is list:
        return tuple(_freeze(x) for x in k)
    if type(k) is dict:
        raise TypeError("map as map key")
    return k


def _special(buf, pos, ai, n, start):
    if ai < 20:
        return Simple(ai), pos
    if ai == 20:
        return False, pos
    if ai == 21:
        return True, pos
    if ai == 22:
        return None, pos
    if ai == 23:
        return UNDEFINED, pos
    if ai == 24:
        if pos >= n:
            raise _truncated("simple value", pos, 1, n)
        sv = buf[pos]
        if sv < 32:
            raise CborDecodeError(
                "CBOR simple value %d must use the one-byte form (offset %d)" % (sv, start), start
            )
        return Simple(sv), pos + 1
    if ai == 25:
        if pos + 2 > n:
            raise _truncated("half float", pos, 2, n)
        return _half(buf[pos] << 8 | buf[pos + 1]), pos + 2
    if ai == 26:
        if pos + 4 > n:
            raise _truncated("single float", pos, 4, n)
        return struct.unpack(">f", buf[pos : pos + 4])[0], pos + 4
    if ai == 27:
        if pos + 8 > n:
            raise _truncated("double float", pos, 8, n)
        return struct.unpack(">d", buf[pos : pos + 8])[0], pos + 8
    if ai == 31:
        return _BREAK_MARK, pos
    raise CborDecodeError("CBOR additional info %d is reserved (offset %d)" % (ai, start), start)


def _half(h):
    exp = (h >> 10) & 0x1F
    frac = h & 0x3FF
    if exp == 0:
        v = ldexp(frac, -24)
    elif exp == 31:
        v = float("inf") if frac == 0 else float("nan")
    else:
        v = ldexp(frac + 1024, exp - 25)
    return -v if h & 0x8000 else v


def _indefinite_string(buf, pos, major, depth, start):
    chunks = []
    n = len(buf)
    while True:
        if pos >= n:
            raise _truncated("indefinite string chunk", pos, 1, n)
        ib = buf[pos]
        if ib == _BREAK:
            pos += 1
            break
        if ib & 0xE0 != major or ib & 0x1F == 31:
            raise CborDecodeError(
                "CBOR indefinite string chunk at offset %d has the wrong type" % pos, pos
            )
        chunk, pos = _item(buf, pos, depth)
        chunks.append(chunk)
    if major == _TEXT:
        return "".join(chunks), pos
    return b"".join(chunks), pos


def _indefinite_container(buf, pos, major, depth, start):
    if depth <= 0:
        raise CborDecodeError("CBOR nesting deeper than the limit at offset %d" % start, start)
    n = len(buf)
    if major == _ARRAY:
        items = []
        while True:
            if pos >= n:
                raise _truncated("indefinite array item", pos, 1, n)
            v, pos = _item(buf, pos, depth - 1)
            if v is _BREAK_MARK:
                return items, pos
            items.append(v)
    d = {}
    while True:
        if pos >= n:
            raise _truncated("indefinite map key", pos, 1, n)
        if buf[pos] == _BREAK:
            return d, pos + 1
        pos = _pair(buf, pos, depth - 1, d)
