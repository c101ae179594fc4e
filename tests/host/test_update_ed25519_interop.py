"""The Python Ed25519 verifier (obsw.update.ed25519) against cryptography's (OpenSSL's), and the
verifier obsw.update.signature picks on CPython: keys and signatures made by cryptography verify
alike in both; spoiled ones and the encodings RFC 8032 refuses fail alike."""

import os
import random

import pytest
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey
from obsw.update import ed25519, signature

P = 2**255 - 19
L = 2**252 + 27742317777372353535851937790883648493


def _cases(rng, n):
    """(public key, signature, message, valid) for n random keys, each with tampered copies."""
    for _ in range(n):
        key = Ed25519PrivateKey.from_private_bytes(rng.randbytes(32))
        public = key.public_key().public_bytes_raw()
        message = rng.randbytes(rng.choice((0, 1, 31, 111, 112, 300, 1000)))
        sig = key.sign(message)
        yield public, sig, message, True
        bit = 1 << rng.randrange(8)
        i = rng.randrange(64)
        yield public, sig[:i] + bytes([sig[i] ^ bit]) + sig[i + 1 :], message, False
        if message:
            i = rng.randrange(len(message))
            tampered = message[:i] + bytes([message[i] ^ bit]) + message[i + 1 :]
            yield public, sig, tampered, False
        i = rng.randrange(32)
        yield public[:i] + bytes([public[i] ^ bit]) + public[i + 1 :], sig, message, False
        s = int.from_bytes(sig[32:], "little") + L
        yield public, sig[:32] + s.to_bytes(32, "little"), message, False
        yield rng.randbytes(32), sig, message, False


def _openssl(public, sig, message):
    from cryptography.exceptions import InvalidSignature
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PublicKey

    try:
        Ed25519PublicKey.from_public_bytes(public).verify(sig, message)
    except (InvalidSignature, ValueError):
        return False
    return True


def test_python_verifier_agrees_with_cryptography():
    rng = random.Random(int.from_bytes(os.urandom(4), "big"))
    n = 0
    for public, sig, message, valid in _cases(rng, 40):
        expected = _openssl(public, sig, message)
        if valid:
            assert expected
        assert ed25519.verify(public, sig, message) == expected, (public.hex(), sig.hex())
        n += 1
    assert n >= 200


def test_picked_verifier_agrees_with_python_one():
    rng = random.Random(int.from_bytes(os.urandom(4), "big"))
    for public, sig, message, _ in _cases(rng, 20):
        assert signature.verify(public, sig, message) == ed25519.verify(public, sig, message)


def test_picked_verifier_is_cryptography_unless_pure(monkeypatch):
    import importlib

    monkeypatch.setenv("OBSW_PURE", "1")
    assert importlib.reload(signature)._fast is None
    monkeypatch.delenv("OBSW_PURE")
    assert importlib.reload(signature)._fast is not None  # the C one on CPython
    monkeypatch.undo()
    importlib.reload(signature)  # as the environment of the run has it


@pytest.mark.parametrize("verify", [ed25519.verify, signature.verify], ids=["python", "picked"])
def test_non_canonical_public_keys_refused(verify):
    # the neutral point's encodings that are not canonical: y = p + 1, and x = 0 with the sign
    # bit set. With A neutral, [S]B = R holds for R = B, S = 1; OpenSSL takes both keys.
    base = bytes.fromhex("58" + "66" * 31)
    sig = base + (1).to_bytes(32, "little")
    assert verify((1).to_bytes(32, "little"), sig, b"m")  # the canonical one: valid
    for y in (P + 1, 1 | 1 << 255, (P - 1) | 1 << 255):
        assert not verify(y.to_bytes(32, "little"), sig, b"m")


@pytest.mark.parametrize("verify", [ed25519.verify, signature.verify], ids=["python", "picked"])
def test_wrong_lengths_raise(verify):
    with pytest.raises(ValueError):
        verify(bytes(31), bytes(64), b"")
    with pytest.raises(ValueError):
        verify(bytes(32), bytes(65), b"")
