"""Ed25519 verification in Python (RFC 8032 section 7.1 vectors, the strict checks a verifier
must make) and SHA-512 (FIPS 180-4 examples), on the unix port, CPython and the board."""

import unittest

from obsw.update import ed25519
from obsw.update.sha512 import pure, sha512

_P = 2**255 - 19
_L = 2**252 + 27742317777372353535851937790883648493

_TEST_1024 = (
    "08b8b2b733424243760fe426a4b54908632110a66c2f6591eabd3345e3e4eb98fa6e264bf09efe12ee50f8f5"
    "4e9f77b1e355f6c50544e23fb1433ddf73be84d879de7c0046dc4996d9e773f4bc9efe5738829adb26c81b37"
    "c93a1b270b20329d658675fc6ea534e0810a4432826bf58c941efb65d57a338bbd2e26640f89ffbc1a858efc"
    "b8550ee3a5e1998bd177e93a7363c344fe6b199ee5d02e82d522c4feba15452f80288a821a579116ec6dad2b"
    "3b310da903401aa62100ab5d1a36553e06203b33890cc9b832f79ef80560ccb9a39ce767967ed628c6ad573c"
    "b116dbefefd75499da96bd68a8a97b928a8bbc103b6621fcde2beca1231d206be6cd9ec7aff6f6c94fcd7204"
    "ed3455c68c83f4a41da4af2b74ef5c53f1d8ac70bdcb7ed185ce81bd84359d44254d95629e9855a94a7c1958"
    "d1f8ada5d0532ed8a5aa3fb2d17ba70eb6248e594e1a2297acbbb39d502f1a8c6eb6f1ce22b3de1a1f40cc24"
    "554119a831a9aad6079cad88425de6bde1a9187ebb6092cf67bf2b13fd65f27088d78b7e883c8759d2c4f5c6"
    "5adb7553878ad575f9fad878e80a0c9ba63bcbcc2732e69485bbc9c90bfbd62481d9089beccf80cfe2df16a2"
    "cf65bd92dd597b0707e0917af48bbb75fed413d238f5555a7a569d80c3414a8d0859dc65a46128bab27af87a"
    "71314f318c782b23ebfe808b82b0ce26401d2e22f04d83d1255dc51addd3b75a2b1ae0784504df543af8969b"
    "e3ea7082ff7fc9888c144da2af58429ec96031dbcad3dad9af0dcbaaaf268cb8fcffead94f3c7ca495e056a9"
    "b47acdb751fb73e666c6c655ade8297297d07ad1ba5e43f1bca32301651339e22904cc8c42f58c30c04aafdb"
    "038dda0847dd988dcda6f3bfd15c4b4c4525004aa06eeff8ca61783aacec57fb3d1f92b0fe2fd1a85f672451"
    "7b65e614ad6808d6f6ee34dff7310fdc82aebfd904b01e1dc54b2927094b2db68d6f903b68401adebf5a7e08"
    "d78ff4ef5d63653a65040cf9bfd4aca7984a74d37145986780fc0b16ac451649de6188a7dbdf191f64b5fc5e"
    "2ab47b57f7f7276cd419c17a3ca8e1b939ae49e488acba6b965610b5480109c8b17b80e1b7b750dfc7598d5d"
    "5011fd2dcc5600a32ef5b52a1ecc820e308aa342721aac0943bf6686b64b2579376504ccc493d97e6aed3fb0"
    "f9cd71a43dd497f01f17c0e2cb3797aa2a2f256656168e6c496afc5fb93246f6b1116398a346f1a641f3b041"
    "e989f7914f90cc2c7fff357876e506b50d334ba77c225bc307ba537152f3f1610e4eafe595f6d9d90d11faa9"
    "33a15ef1369546868a7f3a45a96768d40fd9d03412c091c6315cf4fde7cb68606937380db2eaaa707b4c4185"
    "c32eddcdd306705e4dc1ffc872eeee475a64dfac86aba41c0618983f8741c5ef68d3a101e8a3b8cac60c905c"
    "15fc910840b94c00a0b9d0"
)

# RFC 8032 section 7.1: (name, SECRET KEY, PUBLIC KEY, MESSAGE, SIGNATURE)
VECTORS = (
    (
        "TEST 1",
        "9d61b19deffd5a60ba844af492ec2cc44449c5697b326919703bac031cae7f60",
        "d75a980182b10ab7d54bfed3c964073a0ee172f3daa62325af021a68f707511a",
        "",
        "e5564300c360ac729086e2cc806e828a84877f1eb8e5d974d873e065224901555fb8821590a33bac"
        "c61e39701cf9b46bd25bf5f0595bbe24655141438e7a100b",
    ),
    (
        "TEST 2",
        "4ccd089b28ff96da9db6c346ec114e0f5b8a319f35aba624da8cf6ed4fb8a6fb",
        "3d4017c3e843895a92b70aa74d1b7ebc9c982ccf2ec4968cc0cd55f12af4660c",
        "72",
        "92a009a9f0d4cab8720e820b5f642540a2b27b5416503f8fb3762223ebdb69da085ac1e43e15996e"
        "458f3613d0f11d8c387b2eaeb4302aeeb00d291612bb0c00",
    ),
    (
        "TEST 3",
        "c5aa8df43f9f837bedb7442f31dcb7b166d38535076f094b85ce3a2e0b4458f7",
        "fc51cd8e6218a1a38da47ed00230f0580816ed13ba3303ac5deb911548908025",
        "af82",
        "6291d657deec24024827e69c3abe01a30ce548a284743a445e3680d7db5ac3ac18ff9b538d16f290"
        "ae67f760984dc6594a7c15e9716ed28dc027beceea1ec40a",
    ),
    (
        "TEST 1024",
        "f5e5767cf153319517630f226876b86c8160cc583bc013744c6bf255f5cc0ee5",
        "278117fc144c72340f67d0f2316e8386ceffbf2b2428c9c51fef7c597f1d426e",
        _TEST_1024,
        "0aab4c900501b3e24d7cdf4663326a3a87df5e4843b2cbdb67cbf6e460fec350aa5371b1508f9f45"
        "28ecea23c436d94b5e8fcd4f681e30a6ac00a9704a188a03",
    ),
    (
        "TEST SHA(abc)",
        "833fe62409237b9d62ec77587520911e9a759cec1d19755b7da901b96dca3d42",
        "ec172b93ad5e563bf4932c70e1245034c35467ef2efd4d64ebf819683467e2bf",
        "ddaf35a193617abacc417349ae20413112e6fa4e89a97ea20a9eeee64b55d39a2192992a274fc1a8"
        "36ba3c23a3feebbd454d4423643ce80e2a9ac94fa54ca49f",
        "dc2a4459e7369633a52b1bf277839a00201009a3efbf3ecb69bea2186c26b58909351fc9ac90b3ec"
        "fdfbc7c66431e0303dca179c138ac17ad9bef1177331a704",
    ),
)


def _vector(i):
    _, secret, public, message, signature = VECTORS[i]
    return (
        bytes.fromhex(secret),
        bytes.fromhex(public),
        bytes.fromhex(message),
        bytes.fromhex(signature),
    )


def _flip(octets, index, bit=1):
    out = bytearray(octets)
    out[index] ^= bit
    return bytes(out)


def _secret_scalar(secret):
    # RFC 8032 section 5.1.5: the clamped low half of SHA-512(secret)
    a = int.from_bytes(sha512(secret)[:32], "little")
    return (a & ((1 << 254) - 8)) | (1 << 254)


def _signed_with_identity_r(secret, public, message, r_octets):
    # A signature whose R is the neutral point (r = 0): S = k * a. Valid when R is its canonical
    # encoding; a verifier that decodes R leniently would take a non-canonical one as well.
    k = int.from_bytes(sha512(r_octets + public + message), "little") % _L
    s = k * _secret_scalar(secret) % _L
    return r_octets + s.to_bytes(32, "little")


class TestRfc8032Vectors(unittest.TestCase):
    def test_every_vector_verifies(self):
        for i in range(len(VECTORS)):
            _, public, message, signature = _vector(i)
            self.assertTrue(ed25519.verify(public, signature, message), VECTORS[i][0])

    def test_bytearray_and_memoryview_inputs(self):
        _, public, message, signature = _vector(2)
        self.assertTrue(
            ed25519.verify(bytearray(public), memoryview(signature), bytearray(message))
        )


class TestRefused(unittest.TestCase):
    def test_tampered_signature(self):
        _, public, message, signature = _vector(2)
        for index in (0, 17, 31, 32, 50, 63):
            self.assertFalse(ed25519.verify(public, _flip(signature, index), message), index)

    def test_tampered_message(self):
        _, public, message, signature = _vector(3)
        self.assertFalse(ed25519.verify(public, signature, _flip(message, 500)))
        self.assertFalse(ed25519.verify(public, signature, message[:-1]))
        self.assertFalse(ed25519.verify(public, signature, message + b"\x00"))

    def test_wrong_key(self):
        _, public, message, signature = _vector(1)
        other = _vector(0)[1]
        self.assertFalse(ed25519.verify(other, signature, message))
        self.assertFalse(ed25519.verify(_flip(public, 5), signature, message))

    def test_s_not_below_l(self):
        # S + L satisfies the group equation as S does: only the range check refuses it
        for i in (0, 2):
            _, public, message, signature = _vector(i)
            s = int.from_bytes(signature[32:], "little")
            for big in (s + _L, _L, (1 << 256) - 1):
                forged = signature[:32] + big.to_bytes(32, "little")
                self.assertFalse(ed25519.verify(public, forged, message), (i, big))

    def test_non_canonical_r(self):
        secret, public, message, _ = _vector(0)
        canonical = (1).to_bytes(32, "little")  # the neutral point (0, 1)
        lenient = (_P + 1).to_bytes(32, "little")  # y = p + 1, the same point if reduced
        negative_zero = (1 | 1 << 255).to_bytes(32, "little")  # x = 0 with the sign bit
        good = _signed_with_identity_r(secret, public, message, canonical)
        self.assertTrue(ed25519.verify(public, good, message))
        for r in (lenient, negative_zero):
            forged = _signed_with_identity_r(secret, public, message, r)
            self.assertFalse(ed25519.verify(public, forged, message))

    def test_r_not_on_curve(self):
        _, public, message, signature = _vector(0)
        forged = (2).to_bytes(32, "little") + signature[32:]  # y = 2 has no x
        self.assertFalse(ed25519.verify(public, forged, message))

    def test_public_key_not_canonical_or_not_on_curve(self):
        _, _, message, signature = _vector(0)
        for y in (_P, _P + 1, (1 << 255) - 1, 2, 1 | 1 << 255):
            self.assertFalse(ed25519.verify(y.to_bytes(32, "little"), signature, message), y)

    def test_any_octets_give_false(self):
        _, _, message, signature = _vector(0)
        for key in (bytes(32), b"\xff" * 32, bytes(range(32))):
            for sig in (bytes(64), b"\xff" * 64, signature):
                self.assertFalse(ed25519.verify(key, sig, message))

    def test_wrong_lengths_raise(self):
        _, public, message, signature = _vector(0)
        for key, sig in ((public[:31], signature), (public + b"\x00", signature)):
            with self.assertRaises(ValueError):
                ed25519.verify(key, sig, message)
        for sig in (signature[:63], signature + b"\x00", b""):
            with self.assertRaises(ValueError):
                ed25519.verify(public, sig, message)


class TestSha512(unittest.TestCase):
    def test_fips_180_4_examples(self):
        cases = (
            (
                b"abc",
                "ddaf35a193617abacc417349ae20413112e6fa4e89a97ea20a9eeee64b55d39a"
                "2192992a274fc1a836ba3c23a3feebbd454d4423643ce80e2a9ac94fa54ca49f",
            ),
            (
                b"",
                "cf83e1357eefb8bdf1542850d66d8007d620e4050b5715dc83f4a921d36ce9ce"
                "47d0d13c5d85f2b0ff8318d2877eec2f63b931bd47417a81a538327af927da3e",
            ),
            (
                b"abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq",  # 448 bits
                "204a8fc6dda82f0a0ced7beb8e08a41657c16ef468b228a8279be331a703c335"
                "96fd15c13b1b07f9aa1d3bea57789ca031ad85c7a71dd70354ec631238ca3445",
            ),
            (
                b"abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmn"
                b"hijklmnoijklmnopjklmnopqklmnopqrlmnopqrsmnopqrstnopqrstu",  # 896 bits
                "8e959b75dae313da8cf4f72814fc143f8f7779c6eb9f7fa17299aeadb6889018"
                "501d289e4900f7e4331b99dec4b5433ac7d329eeb6dd26545e96e55b874be909",
            ),
            (
                b"a" * 1000,  # eight blocks
                "67ba5535a46e3f86dbfbed8cbbaf0125c76ed549ff8b0b9e03e0c88cf90fa634"
                "fa7b12b47d77b694de488ace8d9a65967dc96df599727d3292a8d9d447709c97",
            ),
        )
        for message, expected in cases:
            self.assertEqual(pure(message), bytes.fromhex(expected), message[:8])
            self.assertEqual(sha512(message), bytes.fromhex(expected), message[:8])

    def test_every_length_around_a_block(self):
        # 111 octets leave room for the length in the last block, 112 do not
        for n in (111, 112, 113, 127, 128, 129, 239, 240):
            self.assertEqual(pure(b"x" * n), sha512(b"x" * n), n)


if __name__ == "__main__":
    unittest.main()
