"""AES-GCM and GMAC: NIST vectors, the pure path against the accelerated one, tag failures."""

import binascii
import unittest

from obsw import compat
from obsw.frames.aes import Aes
from obsw.frames.gcm import AesGcm, GcmAuthError, GcmError


def _octets(n, seed):
    """``n`` pseudo-random octets from ``seed`` (deterministic, on every interpreter)."""
    out = bytearray(n)
    for i in range(n):
        seed = (seed * 1103515245 + 12345) & 0x7FFFFFFF
        out[i] = seed >> 16 & 0xFF
    return bytes(out)


_h = binascii.unhexlify
_P = (
    "d9313225f88406e5a55909c5aff5269a86a7a9531534f7da2e4c303d8a318a72"
    "1c3c0c95956809532fcf0e2449a6b525b16aedf5aa0de657ba637b391aafd255"
)
_C15 = (
    "522dc1f099567d07f47f37a32a84427d643a8cdcbfe5c0c97598a2bd2555d1aa"
    "8cb08e48590dbb3da7b08b1056828838c5f61e6393ba7a0abcc9f662898015ad"
)
_K = "feffe9928665731c6d6a8f9467308308" * 2
_A = "feedfacedeadbeeffeedfacedeadbeefabaddad2"

# (key, IV, plaintext, AAD, ciphertext, tag): NIST CAVP gcmEncryptExtIV256.rsp (Keylen 256,
# IVlen 96, Taglen 128: PTlen 0 and 128, Count 0) and the AES-256 test cases 13-18 of the GCM
# specification (McGrew and Viega), IVs of 96, 64 and 480 bits
VECTORS = (
    (
        "b52c505a37d78eda5dd34f20c22540ea1b58963cf8e5bf8ffa85f9f2492505b4",
        "516c33929df5a3284ff463d7",
        "",
        "",
        "",
        "bdc1ac884d332457a1d2664f168c76f0",
    ),
    (
        "31bdadd96698c204aa9ce1448ea94ae1fb4a9a0b3c9d773b51bb1822666b8f22",
        "0d18e06c7c725ac9e362e1ce",
        "2db5168e932556f8089a0622981d017d",
        "",
        "fa4362189661d163fcd6a56d8bf0405a",
        "d636ac1bbedd5cc3ee727dc2ab4a9489",
    ),
    ("00" * 32, "00" * 12, "", "", "", "530f8afbc74536b9a963b4f1c4cb738b"),
    (
        "00" * 32,
        "00" * 12,
        "00" * 16,
        "",
        "cea7403d4d606b6e074ec5d3baf39d18",
        "d0d1c8a799996bf0265b98b5d48ab919",
    ),
    (_K, "cafebabefacedbaddecaf888", _P, "", _C15, "b094dac5d93471bdec1a502270e3cc6c"),
    (
        _K,
        "cafebabefacedbaddecaf888",
        _P[:120],
        _A,
        _C15[:120],
        "76fc6ece0f4e1768cddf8853bb2d551b",
    ),
    (
        _K,
        "cafebabefacedbad",
        _P[:120],
        _A,
        "c3762df1ca787d32ae47c13bf19844cbaf1ae14d0b976afac52ff7d79bba9de0"
        "feb582d33934a4f0954cc2363bc73f7862ac430e64abe499f47c9b1f",
        "3a337dbf46a792c45e454913fe2ea8f2",
    ),
    (
        _K,
        "9313225df88406e555909c5aff5269aa6a7a9538534f7da1e4c303d2a318a728"
        "c3c0c95156809539fcf0e2429a6b525416aedbf5a0de6a57a637b39b",
        _P[:120],
        _A,
        "5a8def2f0c9e53f1f75d7853659e2a20eeb2b22aafde6419a058ab4f6f746bf4"
        "0fc0c3b780f244452da3ebf1c5d82cdea2418997200ef82e44ae7e3f",
        "a44a8266ee1c8eb0c8b5d4cf5ae9f19a",
    ),
)


def _pure(key):
    """An AesGcm that runs this module's counter mode and GHASH (no AESGCM accelerator)."""
    g = AesGcm(key)
    g._fast = None
    return g


class TestVectors(unittest.TestCase):
    def test_encrypt_gives_nist_ciphertext_and_tag(self):
        for key, iv, p, a, c, t in VECTORS:
            for g in (AesGcm(_h(key)), _pure(_h(key))):
                ct, tag = g.encrypt(_h(iv), _h(p), _h(a))
                self.assertEqual(binascii.hexlify(ct).decode(), c)
                self.assertEqual(binascii.hexlify(tag).decode(), t)

    def test_decrypt_gives_plaintext(self):
        for key, iv, p, a, c, t in VECTORS:
            for g in (AesGcm(_h(key)), _pure(_h(key))):
                self.assertEqual(g.decrypt(_h(iv), _h(c), _h(t), _h(a)), _h(p))

    def test_truncated_tag_is_the_prefix(self):
        key, iv, p, a, c, t = VECTORS[5]
        g = AesGcm(_h(key))
        ct, tag = g.encrypt(_h(iv), _h(p), _h(a), 12)
        self.assertEqual(tag, _h(t)[:12])
        self.assertEqual(g.decrypt(_h(iv), ct, tag, _h(a)), _h(p))

    def test_gmac_is_the_tag_of_the_aad_alone(self):
        key, iv = VECTORS[5][0], VECTORS[5][1]
        g = AesGcm(_h(key))
        aad = _h(VECTORS[5][2])
        self.assertEqual(g.gmac(_h(iv), aad), g.encrypt(_h(iv), b"", aad)[1])
        self.assertEqual(g.decrypt(_h(iv), b"", g.gmac(_h(iv), aad), aad), b"")


class TestFailures(unittest.TestCase):
    def test_any_flipped_bit_fails(self):
        key, iv, p, a, c, t = VECTORS[5]
        for g in (AesGcm(_h(key)), _pure(_h(key))):
            for field in range(4):
                parts = [bytearray(_h(x)) for x in (iv, c, t, a)]
                parts[field][len(parts[field]) // 2] ^= 0x10
                with self.assertRaises(GcmAuthError):
                    g.decrypt(bytes(parts[0]), bytes(parts[1]), bytes(parts[2]), bytes(parts[3]))

    def test_lengths_outside_the_standard(self):
        with self.assertRaises(GcmError):
            AesGcm(bytes(20))
        g = AesGcm(bytes(32))
        with self.assertRaises(GcmError):
            g.encrypt(bytes(12), b"x", b"", 3)
        with self.assertRaises(GcmError):
            g.encrypt(b"", b"x")
        with self.assertRaises(GcmError):
            g.decrypt(bytes(12), b"x", bytes(17))


class TestPaths(unittest.TestCase):
    def test_pure_and_accelerated_paths_agree(self):
        # On CPython the accelerated path is cryptography's AESGCM and the block function its
        # AES-ECB; on MicroPython both are this module over cryptolib's AES-ECB.
        for n in (0, 1, 15, 16, 17, 33, 100, 250):
            key = _octets(32, n)
            iv = _octets(12, n + 1)
            data = _octets(n, n + 2)
            aad = _octets(n % 23, n + 3)
            self.assertEqual(AesGcm(key).encrypt(iv, data, aad), _pure(key).encrypt(iv, data, aad))

    def test_python_aes_gives_fips197_vectors_and_agrees(self):
        # FIPS 197 appendix C.1-C.3: AES-128/192/256 of 00112233...eeff under 000102...
        block = _h("00112233445566778899aabbccddeeff")
        for n, want in (
            (16, "69c4e0d86a7b0430d8cdb78070b4c55a"),
            (24, "dda97ca4864cdfe06eaf70a0ec0d7191"),
            (32, "8ea2b7ca516745bfeafc49904b496089"),
        ):
            key = bytes(range(n))
            self.assertEqual(Aes(key).encrypt(block + block), _h(want) * 2)
            if n != 24:  # cryptolib (axTLS) has no AES-192
                self.assertEqual(Aes(key).encrypt(block), compat.aes_ecb(key)(block))

    def test_block_function_is_aes(self):
        # FIPS 197 appendix C.3: AES-256 of 00112233...eeff
        ecb = compat.aes_ecb(bytes(range(32)))
        self.assertEqual(
            ecb(_h("00112233445566778899aabbccddeeff")), _h("8ea2b7ca516745bfeafc49904b496089")
        )


if __name__ == "__main__":
    unittest.main()
