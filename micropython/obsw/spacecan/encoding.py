"""SpaceCAN value encodings (bool, i8..u64, f32, f64; big-endian), as named in node definitions."""

import struct

from obsw.compat import micropython
from obsw.errors import too_short

# name -> (struct code, size, signed); bool is handled by hand (MicroPython's struct has no '?')
_TABLE = {
    "bool": (None, 1, False),
    "i8": ("b", 1, True),
    "u8": ("B", 1, False),
    "i16": ("h", 2, True),
    "u16": ("H", 2, False),
    "i32": ("i", 4, True),
    "u32": ("I", 4, False),
    "i64": ("q", 8, True),
    "u64": ("Q", 8, False),
    "f32": ("f", 4, False),
    "f64": ("d", 8, False),
}

NAMES = tuple(_TABLE)

# name -> (">" + code, lowest, highest), made once: encoding a value builds no format string
# (for f32 and f64 the range is of no use: a caller packing an int in range packs it as struct
# would; bool has no entry)
PACK = {}
for _name in _TABLE:
    _code, _width, _signed = _TABLE[_name]
    if _code is not None:
        _bits = _width * 8
        if _signed:
            PACK[_name] = (">" + _code, -(1 << (_bits - 1)), (1 << (_bits - 1)) - 1)
        else:
            PACK[_name] = (">" + _code, 0, (1 << _bits) - 1)
del _name, _code, _width, _signed, _bits
_PARTS = {}  # encoding -> its names, for the encodings met (bounded: _PARTS_MAX)
_PARTS_MAX = 64


class EncodingError(ValueError):
    """An unknown encoding name, or a value that does not fit it."""

    def __init__(self, msg, encoding=None, value=None):
        super().__init__(msg)
        self.encoding = encoding
        self.value = value


class ValueTooShortError(ValueError):
    """Too few bytes to decode a value (``obsw.errors``: the too-short kind)."""

    def __init__(self, what, needed, got):
        super().__init__(too_short(what, needed, got))
        self.what = what
        self.needed = needed
        self.got = got


def parts(encoding):
    """Split a (possibly comma separated) encoding into its known names (a list of the
    caller's; see ``_names`` for the shared one)."""
    return list(_names(encoding))


@micropython.native
def _names(encoding):
    # the names of an encoding, split once per encoding met (a tuple shared by the callers)
    got = _PARTS.get(encoding)
    if got is not None:
        return got
    out = []
    for name in encoding.split(","):
        name = name.strip()
        if name not in _TABLE:
            raise EncodingError(
                "unknown encoding %r, expected one of %s" % (name, ", ".join(NAMES)), name
            )
        out.append(name)
    out = tuple(out)
    if len(_PARTS) < _PARTS_MAX:
        _PARTS[encoding] = out
    return out


def check(encoding):
    """Return encoding if every part is known, else raise EncodingError."""
    if not isinstance(encoding, str):
        raise EncodingError("encoding must be a string, got %r" % (encoding,), encoding)
    _names(encoding)
    return encoding


def size(encoding):
    """Encoded size in bytes."""
    n = 0
    for name in _names(encoding):
        n += _TABLE[name][1]
    return n


@micropython.native
def _encode_one(name, value):
    packing = PACK.get(name)
    if packing is None:
        if value is True or value is False or value in (0, 1):
            return b"\x01" if value else b"\x00"
        raise EncodingError("bool value must be True/False/0/1, got %r" % (value,), name, value)
    fmt, lo, hi = packing
    if name == "f32" or name == "f64":
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            raise EncodingError("%s value must be a number, got %r" % (name, value), name, value)
        return struct.pack(fmt, value)
    if not isinstance(value, int) or isinstance(value, bool):
        raise EncodingError("%s value must be an integer, got %r" % (name, value), name, value)
    if value < lo or value > hi:
        raise EncodingError(
            "%s value out of range %d..%d: %d" % (name, lo, hi, value), name, value
        )
    return struct.pack(fmt, value)


@micropython.native
def encode(encoding, value):
    """Encode value; for a comma separated encoding value is a list or tuple of the same length."""
    names = _names(encoding)
    if len(names) == 1:
        return _encode_one(names[0], value)
    if not isinstance(value, (list, tuple)) or len(value) != len(names):
        raise EncodingError(
            "%s needs %d values, got %r" % (encoding, len(names), value), encoding, value
        )
    return b"".join(_encode_one(n, v) for n, v in zip(names, value))


def _decode_one(name, buf, offset):
    width = _TABLE[name][1]
    if len(buf) - offset < width:
        raise ValueTooShortError("%s value" % name, width, len(buf) - offset)
    packing = PACK.get(name)
    if packing is None:
        return buf[offset] != 0, offset + 1
    return struct.unpack_from(packing[0], buf, offset)[0], offset + width


def decode(encoding, buf, offset=0):
    """Decode one value at offset; return (value, next offset). Lists give a tuple value."""
    names = _names(encoding)
    if len(names) == 1:
        return _decode_one(names[0], buf, offset)
    values = []
    for n in names:
        v, offset = _decode_one(n, buf, offset)
        values.append(v)
    return tuple(values), offset
