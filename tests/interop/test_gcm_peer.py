"""AES-GCM both ways with an independent implementation (PyPI's `cryptography`, OpenSSL): what
the core's own GCM (counter mode and GHASH in Python, the path the boards run) encrypts the peer
decrypts, what the peer encrypts the core decrypts, and a tampered frame is refused by both.
Keys of 128, 192 and 256 bits, 96-bit and other IV lengths, AAD and data of any length."""

import pytest
from cryptography.exceptions import InvalidTag
from cryptography.hazmat.primitives.ciphers.aead import AESGCM
from hypothesis import given, settings
from hypothesis import strategies as st
from obsw.frames.gcm import AesGcm, GcmAuthError

keys = st.sampled_from([16, 24, 32]).flatmap(lambda n: st.binary(min_size=n, max_size=n))
ivs = st.one_of(st.binary(min_size=12, max_size=12), st.binary(min_size=8, max_size=16))
blobs = st.binary(max_size=300)


def ours(key):
    """The core's GCM on its own (no accelerator): the flight path."""
    g = AesGcm(key)
    g._fast = None
    return g


@settings(max_examples=150, deadline=None)
@given(key=keys, iv=ivs, data=blobs, aad=blobs)
def test_ours_encrypts_the_peer_decrypts(key, iv, data, aad):
    ciphertext, tag = ours(key).encrypt(iv, data, aad)
    assert AESGCM(key).decrypt(iv, ciphertext + tag, aad) == data


@settings(max_examples=150, deadline=None)
@given(key=keys, iv=ivs, data=blobs, aad=blobs)
def test_the_peer_encrypts_ours_decrypts(key, iv, data, aad):
    sealed = AESGCM(key).encrypt(iv, data, aad)
    assert ours(key).decrypt(iv, sealed[:-16], sealed[-16:], aad) == data


@settings(max_examples=100, deadline=None)
@given(key=keys, iv=ivs, data=st.binary(min_size=1, max_size=200), aad=blobs,
       where=st.integers(min_value=0), bit=st.integers(min_value=0, max_value=7))  # fmt: skip
def test_a_flipped_bit_is_refused_by_both(key, iv, data, aad, where, bit):
    ciphertext, tag = ours(key).encrypt(iv, data, aad)
    sealed = bytearray(ciphertext + tag)
    sealed[where % len(sealed)] ^= 1 << bit
    with pytest.raises(InvalidTag):
        AESGCM(key).decrypt(iv, bytes(sealed), aad)
    with pytest.raises(GcmAuthError):
        ours(key).decrypt(iv, bytes(sealed[:-16]), bytes(sealed[-16:]), aad)
