"""Debian's libfec (Phil Karn's FEC library, package libfec0) through ctypes: the channel-coding
oracle of the interop tests, the coding benchmark and the coding-gain script; never the product.

``load()`` returns a ``LibFec`` or None with ``reason`` saying why (the library is missing).
"""

import ctypes
import ctypes.util

reason = None
_NAMES = ("libfec.so.0", "libfec.so")


def load():
    """The library wrapped, or None (``reason`` then says why)."""
    global reason
    names = list(_NAMES)
    found = ctypes.util.find_library("fec")
    if found:
        names.insert(0, found)
    for name in names:
        try:
            return LibFec(ctypes.CDLL(name))
        except OSError as e:
            reason = "libfec not loadable (apt-get install libfec0): %s" % e
    return None


class LibFec:
    """RS(255,223) CCSDS (dual basis), RS(255,239) from the general codec, Viterbi K=7 r=1/2."""

    def __init__(self, lib):
        self.lib = lib
        lib.encode_rs_ccsds.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_int]
        lib.decode_rs_ccsds.argtypes = [
            ctypes.c_char_p,
            ctypes.POINTER(ctypes.c_int),
            ctypes.c_int,
            ctypes.c_int,
        ]
        lib.init_rs_char.restype = ctypes.c_void_p
        lib.init_rs_char.argtypes = [ctypes.c_int] * 6
        lib.encode_rs_char.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_char_p]
        lib.decode_rs_char.argtypes = [
            ctypes.c_void_p,
            ctypes.c_char_p,
            ctypes.POINTER(ctypes.c_int),
            ctypes.c_int,
        ]
        lib.create_viterbi27.restype = ctypes.c_void_p
        lib.create_viterbi27.argtypes = [ctypes.c_int]
        lib.init_viterbi27.argtypes = [ctypes.c_void_p, ctypes.c_int]
        lib.update_viterbi27_blk.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int]
        lib.chainback_viterbi27.argtypes = [
            ctypes.c_void_p,
            ctypes.c_char_p,
            ctypes.c_uint,
            ctypes.c_uint,
        ]
        lib.delete_viterbi27.argtypes = [ctypes.c_void_p]
        # CCSDS: G1 = 171, G2 = 133 octal, G2 inverted; libfec writes the taps current bit
        # first (0x4F, 0x6D) and takes a negative polynomial for an inverted symbol. Its SIMD
        # decoders have no branch table until this is called.
        lib.set_viterbi27_polynomial((ctypes.c_int * 2)(0x4F, -0x6D))
        taltab = (ctypes.c_ubyte * 256).in_dll(lib, "Taltab")
        self.taltab = bytes(taltab)  # conventional -> dual basis
        inv = bytearray(256)
        for i, v in enumerate(self.taltab):
            inv[v] = i
        self.tal1tab = bytes(inv)
        self._rs8 = {}

    def _rs_e8(self, pad):
        # (255,239) E=8: the general codec with the CCSDS field, first root 120, root step 11
        rs = self._rs8.get(pad)
        if rs is None:
            rs = self._rs8[pad] = self.lib.init_rs_char(8, 0x187, 120, 11, 16, pad)
        return rs

    def rs_encode(self, data, e=16):
        """Check symbols (dual basis) of one codeword's data, shortened by 255-2E-len(data)."""
        pad = 255 - 2 * e - len(data)
        parity = ctypes.create_string_buffer(2 * e)
        if e == 16:
            self.lib.encode_rs_ccsds(bytes(data), parity, pad)
            return parity.raw
        conv = bytes(data).translate(self.tal1tab)
        self.lib.encode_rs_char(self._rs_e8(pad), conv, parity)
        return parity.raw.translate(self.taltab)

    def rs_decode(self, word, erasures=(), e=16):
        """``(corrected word, count)`` of one (shortened) codeword; count -1: uncorrectable."""
        pad = 255 - len(word)
        buf = ctypes.create_string_buffer(bytes(word), len(word))
        eras = (ctypes.c_int * 32)(*erasures)
        if e == 16:
            n = self.lib.decode_rs_ccsds(buf, eras, len(erasures), pad)
            return buf.raw, n
        conv = ctypes.create_string_buffer(bytes(word).translate(self.tal1tab), len(word))
        n = self.lib.decode_rs_char(self._rs_e8(pad), conv, eras, len(erasures))
        return conv.raw.translate(self.taltab), n

    def viterbi27(self, symbols, nbits):
        """Decode ``nbits`` bits (the last 6 of them the zero tail) from 2 * nbits soft
        symbols (0 = strong zero, 255 = strong one) as CCSDS sends them, G2 inverted."""
        vp = self.lib.create_viterbi27(nbits)
        try:
            self.lib.init_viterbi27(vp, 0)
            self.lib.update_viterbi27_blk(vp, bytes(symbols), nbits)
            out = ctypes.create_string_buffer((nbits + 7) // 8)
            self.lib.chainback_viterbi27(vp, out, nbits - 6, 0)
            return out.raw[: (nbits - 6) // 8]
        finally:
            self.lib.delete_viterbi27(vp)
