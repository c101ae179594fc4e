"""Ed25519 verification in Python (RFC 8032 section 7.1 test vectors, and the checks a
verifier must make) and SHA-512 (FIPS 180-4 vectors), on the unix port, CPython and the board."""

import unittest

from obsw.update import ed25519, sha512

# RFC 8032 7.1: TEST 1, 2, 3 (public key, message, signature)
RFC8032 = (
    (
        "d75a980182b10ab7d54bfed3c964073a0ee172f3daa62325af021a68f707511a",
        "",
        "e5564300c360ac729086e2cc806e828a84877f1eb8e5d974d873e065224901555fb8821590a33bacc61e39701cf9b46bd25bf5f0595bbe24655141438e7a100b",
    ),
    (
        "3d4017c3e843895a92b70aa74d1b7ebc9c982ccf2ec4968cc0cd55f12af4660c",
        "72",
        "92a009a9f0d4cab8720e820b5f642540a2b27b5416503f8fb3762223ebdb69da085ac1e43e15996e458f3613d0f11d8c387b2eaeb4302aeeb00d291612bb0c00",
    ),
    (
        "fc51cd8e6218a1a38da47ed00230f0580816ed13ba3303ac5deb911548908025",
        "af82",
        "6291d657deec24024827e69c3abe01a30ce548a284743a445e3680d7db5ac3ac18ff9b538d16f290ae67f760984dc6594a7c15e9716ed28dc027beceea1ec40a",
    ),
)  # fmt: skip
SHA512 = (
    (
        b"",
        "cf83e1357eefb8bdf1542850d66d8007d620e4050b5715dc83f4a921d36ce9ce47d0d13c5d85f2b0ff8318d2877eec2f63b931bd47417a81a538327af927da3e",
    ),
    (
        b"abc",
        "ddaf35a193617abacc417349ae20413112e6fa4e89a97ea20a9eeee64b55d39a2192992a274fc1a836ba3c23a3feebbd454d4423643ce80e2a9ac94fa54ca49f",
    ),
    (
        b"abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmnhijklmnoijklmnopjklmnopqklmnopqrlmnopqrsmnopqrstnopqrstu",
        "8e959b75dae313da8cf4f72814fc143f8f7779c6eb9f7fa17299aeadb6889018501d289e4900f7e4331b99dec4b5433ac7d329eeb6dd26545e96e55b874be909",
    ),
    (
        b"a" * 1000,
        "67ba5535a46e3f86dbfbed8cbbaf0125c76ed549ff8b0b9e03e0c88cf90fa634fa7b12b47d77b694de488ace8d9a65967dc96df599727d3292a8d9d447709c97",
    ),
)  # fmt: skip


def unhex(s):
    return bytes(int(s[i : i + 2], 16) for i in range(0, len(s), 2))


def tohex(b):
    return "".join("%02x" % x for x in b)


class TestSha512(unittest.TestCase):
    def test_fips_vectors(self):
        for message, digest in SHA512:
            self.assertEqual(tohex(sha512.pure(message)), digest)
            self.assertEqual(tohex(sha512.sha512(message)), digest)

    def test_every_length_around_a_block(self):
        for n in (111, 112, 113, 127, 128, 129, 239, 240):
            self.assertEqual(sha512.pure(b"x" * n), sha512.sha512(b"x" * n))


class TestVerify(unittest.TestCase):
    def test_rfc8032_vectors(self):
        for key, message, signature in RFC8032:
            self.assertTrue(ed25519.verify(unhex(key), unhex(signature), unhex(message)))

    def test_a_changed_message_signature_or_key(self):
        key, message, signature = (unhex(x) for x in RFC8032[2])
        self.assertFalse(ed25519.verify(key, signature, message + b"\x00"))
        bad = bytearray(signature)
        bad[5] ^= 1
        self.assertFalse(ed25519.verify(key, bytes(bad), message))
        bad = bytearray(signature)
        bad[40] ^= 1
        self.assertFalse(ed25519.verify(key, bytes(bad), message))
        self.assertFalse(ed25519.verify(unhex(RFC8032[0][0]), signature, message))

    def test_s_not_below_l_is_refused(self):
        key, message, signature = (unhex(x) for x in RFC8032[0])
        s = int.from_bytes(signature[32:], "little") + ed25519.L  # the same point, S >= L
        self.assertFalse(ed25519.verify(key, signature[:32] + s.to_bytes(32, "little"), message))

    def test_points_off_the_curve_are_refused(self):
        key, message, signature = (unhex(x) for x in RFC8032[0])
        off = (2).to_bytes(32, "little")  # y = 2 gives no x on the curve
        self.assertIsNone(ed25519.decode(off))
        self.assertFalse(ed25519.verify(off, signature, message))
        self.assertFalse(ed25519.verify(key, off + signature[32:], message))
        big = (ed25519.P + 1).to_bytes(32, "little")  # y >= p: not canonical
        self.assertFalse(ed25519.verify(big, signature, message))

    def test_the_base_point_round_trips(self):
        self.assertEqual(ed25519.decode(ed25519.encode(ed25519.BASE)), ed25519.BASE)

    def test_wrong_lengths_raise(self):
        with self.assertRaises(ValueError):
            ed25519.verify(b"\x00" * 31, b"\x00" * 64, b"")
        with self.assertRaises(ValueError):
            ed25519.verify(b"\x00" * 32, b"\x00" * 63, b"")


if __name__ == "__main__":
    unittest.main()
