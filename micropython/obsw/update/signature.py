"""The Ed25519 verifier of update packages: ``cryptography``'s through ``compat`` where it is
installed (the OBC, the ground), else the Python one (``obsw.update.ed25519``, the boards).
Both answer alike (``tests/host/test_update_ed25519_interop.py``): OpenSSL takes a public key
that is a non-canonical encoding, which RFC 8032 and the Python verifier refuse, so such a key
is refused here before OpenSSL sees it."""

from obsw.compat import ed25519_accelerator
from obsw.update import ed25519

_fast = ed25519_accelerator()


def verify(public_key, signature, message):
    """True if ``signature`` is ``public_key``'s Ed25519 signature of ``message``; wrong
    lengths raise ValueError."""
    if _fast is None:
        return ed25519.verify(public_key, signature, message)
    ed25519.check_lengths(public_key, signature)
    if not ed25519.canonical_encoding(public_key):
        return False
    return _fast(public_key, signature, message)
