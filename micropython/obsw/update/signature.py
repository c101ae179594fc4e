"""Ed25519 verification with the fastest implementation at hand.

    from obsw.update.signature import verify
    verify(public_key, signature, message)   # True or False

``cryptography``'s (OpenSSL's C, ``obsw.compat.ed25519_accelerator``) where it is importable and
the core may use accelerators; the pure-Python ``obsw.update.ed25519`` everywhere else (the
boards). Both refuse the same signatures: S not below L, a public key or an R that is no
canonical encoding of a curve point.
"""

from obsw.compat import ed25519_accelerator
from obsw.update import ed25519


def _strict(accelerated):
    def verify(public_key, signature, message):
        ed25519.check_lengths(public_key, signature)
        if not ed25519.canonical_encoding(public_key):
            return False  # OpenSSL takes these keys; RFC 8032 and obsw.update.ed25519 do not
        return accelerated(bytes(public_key), bytes(signature), bytes(message))

    return verify


_accelerated = ed25519_accelerator()
verify = _strict(_accelerated) if _accelerated else ed25519.verify
