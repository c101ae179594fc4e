"""The Python Ed25519 verifier against ``cryptography``'s, both ways: keys and signatures made
by ``cryptography`` verify alike in both; spoiled ones fail alike (``obsw.update.signature``
takes the fast one on CPython)."""

import os
import random

from cryptography.hazmat.primitives import serialization
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey
from obsw.update import ed25519, signature


def raw(public):
    return public.public_bytes(serialization.Encoding.Raw, serialization.PublicFormat.Raw)


def test_both_verifiers_agree_on_random_keys_messages_and_spoils():
    rng = random.Random(8032)
    for n in range(40):
        key = Ed25519PrivateKey.generate()
        message = os.urandom(rng.randrange(0, 400))
        sig = key.sign(message)
        public = raw(key.public_key())
        cases = [(public, sig, message, True)]
        spoilt = bytearray(sig)
        spoilt[rng.randrange(64)] ^= 1 << rng.randrange(8)
        cases.append((public, bytes(spoilt), message, False))
        cases.append((public, sig, message + b"!", False))
        cases.append((raw(Ed25519PrivateKey.generate().public_key()), sig, message, False))
        for pk, s, m, expected in cases:
            assert ed25519.verify(pk, s, m) is expected, n
            assert signature.verify(pk, s, m) is expected, n
    assert signature._fast is not None  # the C one on CPython
