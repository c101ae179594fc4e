"""Ed25519 verification with the fastest implementation at hand.

    from obsw.update.signature import verify
    verify(public_key, signature, message)   # True or False

``cryptography``'s (OpenSSL's C) where it is importable and the core may use accelerators
(``obsw.compat.pure``); the pure-Python ``obsw.update.ed25519`` everywhere else (the boards).
Both refuse the same signatures: S not below L, a public key that is no canonical encoding of a
curve point, an R that is none.
"""

from obsw.compat import pure
from obsw.update import ed25519


def _accelerated():
    if pure():
        return None
    try:
        from cryptography.exceptions import InvalidSignature
        from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PublicKey
    except ImportError:
        return None

    def verify(public_key, signature, message):
        ed25519.check_lengths(public_key, signature)
        if not ed25519.canonical_encoding(public_key):
            return False  # OpenSSL takes these keys; RFC 8032 and obsw.update.ed25519 do not
        try:
            key = Ed25519PublicKey.from_public_bytes(bytes(public_key))
            key.verify(bytes(signature), bytes(message))
        except (InvalidSignature, ValueError):
            return False
        return True

    return verify


verify = _accelerated() or ed25519.verify
