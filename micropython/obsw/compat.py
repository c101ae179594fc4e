"""The one module that knows which interpreter runs: const, clocks and optional accelerators."""

import struct
import sys
import time

try:
    from micropython import const
except ImportError:

    def const(x):
        return x


MICROPYTHON = sys.implementation.name == "micropython"
# bytes a CFDP sender reads from its file at once and cuts its file data PDUs from (one
# filestore read per 64 KiB instead of one per PDU); none on a board, whose heap is ~100 KiB
CFDP_READ_AHEAD = 0 if MICROPYTHON else 65536

if MICROPYTHON:
    import micropython  # the hot paths say @micropython.native: compiled to machine code
else:

    def _as_is(f):
        return f

    class micropython:  # noqa: N801 - stands in for the module of that name
        """MicroPython's code emitter decorators, as no-ops where there is no such compiler.

        A core module imports this name (``from obsw.compat import micropython``) and marks a
        hot function ``@micropython.native``: MicroPython's compiler (mpy-cross with
        ``-march``, as every image and deploy of this project gives it) emits machine code;
        CPython runs the function as it is. Only functions that behave the same either way
        carry it (no generators, no ``super()`` without arguments)."""

        native = staticmethod(_as_is)
        viper = staticmethod(_as_is)


_TICKS_PERIOD = const(1 << 30)
_TICKS_MAX = const((1 << 30) - 1)
_TICKS_HALF = const(1 << 29)

if hasattr(time, "ticks_ms"):
    ticks_ms = time.ticks_ms
    ticks_add = time.ticks_add
    ticks_diff = time.ticks_diff
else:

    def ticks_ms():
        """Milliseconds from an arbitrary point, wrapping like MicroPython's ticks_ms."""
        return int(time.monotonic() * 1000) & _TICKS_MAX

    def ticks_add(ticks, delta):
        return (ticks + delta) & _TICKS_MAX

    def ticks_diff(end, start):
        return ((end - start + _TICKS_HALF) & _TICKS_MAX) - _TICKS_HALF


# The wrap period of ticks_ms: 2**30 on boards and here, 2**62 on the 64-bit unix port.
TICKS_PERIOD = ticks_add(0, -1) + 1

if hasattr(time, "monotonic"):
    monotonic = time.monotonic
else:
    _mono = [0, None]  # accumulated milliseconds, last ticks reading

    def monotonic():
        """Seconds from an arbitrary point; never wraps (extends ticks_ms across its period)."""
        now = time.ticks_ms()
        last = _mono[1]
        if last is not None:
            _mono[0] += time.ticks_diff(now, last)
        _mono[1] = now
        return _mono[0] / 1000


if hasattr(struct, "Struct"):
    Struct = struct.Struct  # the C implementation, faster where it exists
else:

    class Struct:
        """``struct.Struct`` for interpreters that lack it (MicroPython)."""

        def __init__(self, fmt):
            self.format = fmt
            self.size = struct.calcsize(fmt)

        def pack(self, *values):
            return struct.pack(self.format, *values)

        def pack_into(self, buf, offset, *values):
            struct.pack_into(self.format, buf, offset, *values)

        def unpack(self, buf):
            return struct.unpack(self.format, buf)

        def unpack_from(self, buf, offset=0):
            return struct.unpack_from(self.format, buf, offset)


def _struct_checks_ranges():
    for fmt, value in ((">B", 256), (">B", -1), (">H", 1 << 16), (">I", 1 << 32), (">I", -1)):
        try:
            struct.pack(fmt, value)
        except Exception:
            continue
        return False
    return True


# True where struct.pack rejects a value its format code cannot hold (CPython raises
# struct.error) instead of truncating it (MicroPython): codecs can then leave those range
# checks to struct and only check the fields narrower than a format code themselves.
STRUCT_CHECKS_RANGES = _struct_checks_ranges()


def sleep(seconds):
    """Sleep for a (possibly fractional) number of seconds on either interpreter."""
    if hasattr(time, "sleep_ms"):
        time.sleep_ms(int(seconds * 1000))
    else:
        time.sleep(seconds)


def pure():
    """True where the core must not use C accelerators: always on MicroPython, and on CPython
    when the environment variable OBSW_PURE is set to anything but "" or "0" (tests then
    exercise the pure-Python paths the accelerated ones must agree with)."""
    if MICROPYTHON:
        return True
    import os

    return os.environ.get("OBSW_PURE", "0") not in ("", "0")


def crc_accelerator(width, poly, init, reflect, xorout):
    """Return a C-accelerated CRC function ``f(data, previous_crc)`` or None.

    ``poly`` is given without its top bit; ``init`` is the register value before the first byte.
    The function returned continues a running CRC the same way the core's pure functions do.
    """
    if pure():
        return None
    if (width, poly, reflect, xorout) == (16, 0x1021, False, 0):
        import binascii  # CPython's crc_hqx is this CRC family, C-fast and always present

        return binascii.crc_hqx
    if (width, poly, init, reflect, xorout) == (32, 0x04C11DB7, 0xFFFFFFFF, True, 0xFFFFFFFF):
        try:
            import zlib  # CRC-32 (IEEE, the CFDP file checksum 3): several times crcmod's
        except ImportError:
            pass
        else:
            return zlib.crc32
    try:
        import crcmod
    except ImportError:
        return None
    # crcmod applies xorOut to initCrc itself, so hand it the value it will un-xor.
    return crcmod.mkCrcFun((1 << width) | poly, initCrc=init ^ xorout, rev=reflect, xorOut=xorout)


_PUS_API = const(2)  # the obsw_speedups interface this core speaks


def speedups():
    """The C hot paths ``obsw_speedups`` (built with the host package on CPython) or None:
    the PUS packet codec and the interaction layer's CBOR framing.

    It only ever takes the inputs it can handle without doubt and declines the rest, so the
    Python code stays the definition and raises the errors.
    """
    if pure():
        return None
    try:
        import obsw_speedups
    except ImportError:
        return None
    if getattr(obsw_speedups, "API", None) != _PUS_API:
        return None  # a stale build from other sources
    return obsw_speedups


pus_accelerator = speedups  # the PUS codec's name for it


def aes_ecb(key):
    """AES encryption in ECB mode under ``key`` (16, 24 or 32 octets): a function that takes a
    multiple of 16 octets and returns as many. MicroPython: ``cryptolib.aes``; CPython:
    ``cryptography``; where neither is (an image built without cryptolib), AES in Python
    (``obsw.frames.aes``), the same octets much slower."""
    try:
        if MICROPYTHON:
            import cryptolib

            return cryptolib.aes(bytes(key), 1).encrypt
        from cryptography.hazmat.primitives.ciphers import Cipher, algorithms, modes

        return Cipher(algorithms.AES(bytes(key)), modes.ECB()).encryptor().update
    except ImportError:
        from obsw.frames.aes import Aes

        return Aes(key).encrypt


def gcm_accelerator(key):
    """``cryptography``'s AESGCM under ``key`` (the whole GCM in C) or None: on MicroPython,
    under OBSW_PURE, or without the package. ``obsw.frames.gcm`` stays the definition."""
    if pure():
        return None
    try:
        from cryptography.hazmat.primitives.ciphers.aead import AESGCM
    except ImportError:
        return None
    return AESGCM(bytes(key))


def ed25519_accelerator():
    """``cryptography``'s Ed25519 verification as ``verify(public_key, signature, message) ->
    bool``, or None: on MicroPython, under OBSW_PURE, or without the package.
    ``obsw.update.ed25519`` stays the definition."""
    if pure():
        return None
    try:
        from cryptography.exceptions import InvalidSignature
        from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PublicKey
    except ImportError:
        return None

    def verify(public_key, signature, message):
        try:
            key = Ed25519PublicKey.from_public_bytes(bytes(public_key))
            key.verify(bytes(signature), bytes(message))
        except (InvalidSignature, ValueError):
            return False
        return True

    return verify


def bytes_ops():
    """True where the channel codecs may use CPython's C byte operations (``bytes.translate``
    and slices with a step, which MicroPython lacks), i.e. on CPython without OBSW_PURE; the
    codecs' loops in Python stay the definition and a test shows both give the same octets."""
    return not pure() and hasattr(bytes, "translate")
