"""CBOR for the wire: cbor2's C encoder where it gives the core encoder's bytes, and framing.

The core encoder (``obsw.cbor``) is deterministic with length-first map key order, which is
what ``cbor2.dumps(canonical=True)`` produces, so the host encodes with cbor2 and the bytes are
the same (tests/host/test_cbor_properties.py checks it). Set ``OBSW_IL_CODEC=core`` to use the
pure-Python codec instead. Decoding with cbor2 gives the same Python values for everything the
interaction layer sends; CBOR ``undefined`` decodes to ``cbor2.undefined`` and tags cbor2 knows
(dates, decimals, ...) to its own types. One difference: cbor2 encodes a ``memoryview`` as an
array of ints, so values that cross processes carry ``bytes``, never memoryviews (the core
encoder takes both; asking cbor2 to special-case it would double its encoding time).

A frame is a 4-byte big-endian length followed by one CBOR item. With the cbor2 codec, the
C hot path of ``obsw_speedups`` frames and decodes the plain values that make up nearly every
message (ints, floats, strings, bytes, lists, dicts, None, bools) and declines the rest, which
cbor2 then handles; tests/host/test_cbor_properties.py proves both give the same bytes and
values. ``OBSW_PURE=1`` turns it off.
"""

import os
import struct

from obsw import cbor as core
from obsw.cbor import CborDecodeError, CborEncodeError
from obsw.compat import speedups

MAX_FRAME = 64 * 1024 * 1024
_LEN = struct.Struct(">I")

try:
    import cbor2
except ImportError:  # pragma: no cover - cbor2 is a dependency, but the core codec suffices
    cbor2 = None


def _default(encoder, value):
    if value is core.UNDEFINED:
        encoder.encode(cbor2.undefined)
    elif isinstance(value, core.Tag):
        encoder.encode(cbor2.CBORTag(value.tag, value.value))
    elif isinstance(value, core.Simple):
        encoder.encode(cbor2.CBORSimpleValue(value.value))
    else:
        raise CborEncodeError("cannot encode %s as CBOR" % type(value).__name__)


def _tag_hook(*args):
    # cbor2 5 calls hook(decoder, tag), cbor2 6 hook(tag, immutable): take the tag either way
    tag = args[1] if isinstance(args[1], cbor2.CBORTag) else args[0]
    return core.Tag(tag.tag, tag.value)


def _cbor2_dumps(value):
    try:
        return cbor2.dumps(value, canonical=True, default=_default)
    except CborEncodeError:
        raise
    except (cbor2.CBOREncodeError, TypeError, ValueError) as e:
        raise CborEncodeError(str(e)) from e


def _cbor2_loads(data):
    try:
        return cbor2.loads(data, tag_hook=_tag_hook, max_depth=core.MAX_DEPTH)
    except (cbor2.CBORDecodeError, ValueError, TypeError, OverflowError, RecursionError) as e:
        raise CborDecodeError("CBOR: %s" % e) from e


def codec_name():
    return CODEC


CODEC = "cbor2" if cbor2 is not None and os.environ.get("OBSW_IL_CODEC") != "core" else "core"
_C = speedups() if CODEC == "cbor2" else None
_c_frame = _C.cbor_frame if _C is not None else None
_c_loads = _C.cbor_loads if _C is not None else None
# a reader's usual case in one C call: one whole frame, decoded (older builds lack it)
_c_frame_loads = getattr(_C, "cbor_frame_loads", None)
_DECLINED = object()


def _fast_loads(data):
    v = _c_loads(data, _DECLINED)
    if v is _DECLINED:
        return _cbor2_loads(data)
    return v


if CODEC == "cbor2":
    dumps = _cbor2_dumps
    loads = _fast_loads if _C is not None else _cbor2_loads
else:
    dumps = core.dumps
    loads = core.loads


class FrameError(ValueError):
    """A frame whose declared length is beyond ``MAX_FRAME``."""

    def __init__(self, length):
        super().__init__("frame of %d bytes announced, limit is %d" % (length, MAX_FRAME))
        self.length = length


def frame(msg):
    """One length-prefixed CBOR frame for ``msg``."""
    if _c_frame is not None:
        data = _c_frame(msg)
        if data is not None:
            return data
    body = dumps(msg)
    return _LEN.pack(len(body)) + body


class FrameReader:
    """Collects bytes from a stream and gives back the decoded messages of whole frames."""

    def __init__(self):
        self._buf = bytearray()

    def feed(self, data):
        """Add ``data``; return the list of messages completed by it."""
        buf = self._buf
        if not buf and _c_frame_loads is not None:
            v = _c_frame_loads(data, _DECLINED, MAX_FRAME)
            if v is not _DECLINED:
                return [v]
        if not buf and len(data) >= 4:
            # the usual case: one read holds exactly one frame, decoded without buffering
            (length,) = _LEN.unpack_from(data, 0)
            if length + 4 == len(data) and length <= MAX_FRAME:
                return [loads(data[4:])]
        buf += data
        out = []
        pos = 0
        n = len(buf)
        while n - pos >= 4:
            (length,) = _LEN.unpack_from(buf, pos)
            if length > MAX_FRAME:
                raise FrameError(length)
            end = pos + 4 + length
            if end > n:
                break
            out.append(loads(bytes(buf[pos + 4 : end])))
            pos = end
        if pos:
            del buf[:pos]
        return out

    def pending(self):
        """Bytes held for an incomplete frame."""
        return len(self._buf)
