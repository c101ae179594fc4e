"""Benchmark SDLS AES-256-GCM per TC and TM frame: obsw's protect/verify against cryptography.

sdls.py [--quick] [--json]
The peer is cryptography's AESGCM alone on the same key, IV, AAD and data (the cipher with no
frame handling): the ratio is what our SA, header, mask, anti-replay and copies add on top.
The "pure Python GCM" cases run the core's own counter mode and GHASH over AES-ECB, the path
the boards take (there over cryptolib), against the same peer.
"""

import argparse
import json
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "micropython"), str(ROOT / "host")]

from cryptography.hazmat.primitives.ciphers.aead import AESGCM  # noqa: E402
from measure import rate  # noqa: E402
from obsw.frames import sdls, tc  # noqa: E402
from obsw.frames.sdls_gcm import GcmSecurityAssociation, TmSecurity  # noqa: E402

KEY = bytes(range(32))
SCID = 0x2A
TM_FIELD = 1115 - 6 - 4 - 2  # data field of the TM frame the frames benchmark uses


def _pure(sa):
    sa._gcm._fast = None
    return sa


def cases(pure):
    """(case, obsw fn, peer fn) for one TC of 64 octets and one full TM frame."""

    def tc_pair():
        sender = GcmSecurityAssociation(1, 0, KEY, reserve_block=1 << 40)
        receiver = GcmSecurityAssociation(1, 0, KEY)
        if pure:
            _pure(sender), _pure(receiver)
        tx = sdls.TcSecurity([sender], segment_header=True)
        rx = sdls.TcSecurity([receiver], segment_header=True)
        return tx, rx, receiver

    tx, rx, receiver = tc_pair()
    segment = tc.Segment(63, bytes(64)).pack()
    frame = tc.TcFrame(SCID, 0, tx.apply(SCID, 0, segment), 0).pack()
    receiver.window.ahead = None

    def tc_protect():
        return tc.TcFrame(SCID, 0, tx.apply(SCID, 0, segment), 0).pack()

    def tc_verify():
        receiver.window.top = 0
        receiver.window._seen = 0
        return rx.process(frame, len(frame))

    tm_tx = TmSecurity([GcmSecurityAssociation(9, 0, KEY, reserve_block=1 << 40)])
    tm_rx = TmSecurity([GcmSecurityAssociation(9, 0, KEY)])
    if pure:
        _pure(tm_tx.by_vc[0]), _pure(tm_rx.by_vc[0])
    data = bytes(TM_FIELD - tm_tx.overhead(0))
    field = tm_tx.seal(0, data)
    rx_sa = tm_rx.by_vc[0]

    def tm_protect():
        return tm_tx.seal(0, data)

    def tm_verify():
        rx_sa.window.top = 0
        rx_sa.window._seen = 0
        return tm_rx.open(0, field)

    peer = AESGCM(KEY)
    iv = bytes(12)
    aad = bytes(20)
    ct_tc = peer.encrypt(iv, bytes(64), aad)
    ct_tm = peer.encrypt(iv, data, aad)
    return [
        ("TC frame (64 B) protect", tc_protect, lambda: peer.encrypt(iv, bytes(64), aad)),
        ("TC frame (64 B) verify", tc_verify, lambda: peer.decrypt(iv, ct_tc, aad)),
        ("TM frame (1115 B) protect", tm_protect, lambda: peer.encrypt(iv, data, aad)),
        ("TM frame (1115 B) verify", tm_verify, lambda: peer.decrypt(iv, ct_tm, aad)),
    ]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="short runs (smoke check)")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    args = ap.parse_args(argv)
    seconds, repeats = (0.15, 3) if args.quick else (0.6, 5)
    rows = []
    table = []
    for pure in (False, True):
        for case, ours, theirs in cases(pure):
            a = rate(ours, seconds, repeats)
            b = rate(theirs, seconds, repeats)
            if pure:
                case += ", pure Python GCM"
            for impl, value in (("obsw", a), ("cryptography", b)):
                rows.append({"case": case, "impl": impl, "value": value, "unit": "frames/s",
                             "higher_is_better": True})  # fmt: skip
            table.append((case, a, b))
    if args.json:
        print(json.dumps({"bench": "sdls", "rows": rows}))
        return 0
    print(
        "%-28s %-12s %14s %16s %7s" % ("case", "impl", "obsw frames/s", "cryptography/s", "ratio")
    )
    for case, impl, a, b in table:
        print("%-28s %-12s %14.0f %16.0f %7.2f" % (case, impl, a, b, b / a))
    return 0


if __name__ == "__main__":
    sys.exit(main())
