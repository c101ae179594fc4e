"""Benchmark the space data link: CLTU, TC and TM frames, CADUs, COP-1 (ours vs peers).

frames.py [--quick] [--json]
Peers measured in the same run where one exists: spacepackets (TM frame decode) and ccsds-cop
(COP-1 FOP and FARM). CLTU/BCH and the randomizer have no Python peer. SDLS authentication
(HMAC-SHA-256 in obsw, for MicroPython) is set against CPython's C hmac on the same bytes.
"""

import argparse
import json
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "micropython"), str(ROOT / "host")]

from measure import rate  # noqa: E402
from obsw.frames import asm, cltu, farm, sdls, tc, tm, tm_demux, tm_mux  # noqa: E402
from obsw.frames import fop as F  # noqa: E402

TC_LEN = 1024
TM_LEN = 1115


def cases():
    tc_frame = tc.TcFrame(0x2A, 0, bytes(range(256)) * 3 + bytes(TC_LEN - 7 - 768), 5).pack()
    encoded = cltu.encode(tc_frame)
    vc = tm_mux.TmVirtualChannel(0)
    mux = tm_mux.TmMultiplexer(0x2A, TM_LEN, [vc], lambda: b"\x01\x00\x00\x05")
    packet = bytes((0x08, 0x10, 0xC0, 0, 0x01, 0x2B)) + bytes(300)

    def tm_build():
        while vc.pending() < mux.data_length:
            vc.push(packet)
        return asm.cadu(mux.frame().pack())

    cadu = tm_build()
    tm_raw = mux.frame(True).pack()
    demux = tm_demux.TmDemultiplexer(0x2A)

    def tm_parse():
        dec = asm.CaduDecoder(TM_LEN)
        for raw in dec.feed(cadu):
            demux.feed(raw)

    secured = sdls.TcSecurity([sdls.SecurityAssociation(1, 0, bytes(range(32)))])
    plain = tc.Segment(1, bytes(TC_LEN - 7 - 1 - 6 - 16)).pack()
    signed = tc.TcFrame(0x2A, 0, secured.apply(0x2A, 0, plain), 0).pack()

    rows = [
        ("SDLS sign (HMAC-SHA-256), 1024-byte TC frame", "frame/s",
         lambda: secured.apply(0x2A, 0, plain), TC_LEN),
        ("SDLS verify (HMAC-SHA-256), 1024-byte TC frame", "frame/s",
         lambda: secured.process(signed, TC_LEN), TC_LEN),
        ("CLTU encode, 1024-byte TC frame", "frame/s", lambda: cltu.encode(tc_frame), TC_LEN),
        ("CLTU decode, 1024-byte TC frame", "frame/s", lambda: cltu.decode(encoded), TC_LEN),
        ("TC frame pack (FECF)", "frame/s",
         lambda: tc.TcFrame(0x2A, 0, tc_frame[5:-2], 5).pack(), TC_LEN),
        ("TC frame unpack (FECF)", "frame/s", lambda: tc.TcFrame.unpack(tc_frame), TC_LEN),
        ("TM frame build + CADU (randomized)", "frame/s", tm_build, TM_LEN),
        ("TM CADU parse + packets", "frame/s", tm_parse, TM_LEN),
        ("TM frame unpack (FECF)", "frame/s", lambda: tm.TmFrame.unpack(tm_raw), TM_LEN),
    ]  # fmt: skip
    peers = {}
    import hashlib
    import hmac

    key = bytes(range(32))
    peers["SDLS verify (HMAC-SHA-256), 1024-byte TC frame"] = (
        "reference",
        lambda: hmac.compare_digest(
            hmac.new(key, signed[:-18], hashlib.sha256).digest()[:16], signed[-18:-2]
        ),
    )
    try:
        from spacepackets.ccsds.tm_frame import TmTransferFrame

        peers["TM frame unpack (FECF)"] = (
            "spacepackets",
            lambda: TmTransferFrame.unpack(tm_raw, TM_LEN, True),
        )
    except ImportError:
        pass
    return rows, peers


def cop_ours(n=50):
    def run():
        fop = F.Fop1(1, 0, window=10)
        fa = farm.Farm1(0, 10)
        fop.directive(F.INITIATE_AD_NO_CLCW, now=0)
        for _ in range(n):
            fop.send_ad(b"fdu", 0)
            for f in fop.take_frames():
                fa.on_frame(f)
                fa.take()
                fop.on_clcw(fa.clcw(), 0)
            fop.take_notifications()

    return run


def cop_theirs(n=50):
    try:
        from ccsds_cop.cop_1 import ControlWord, Gvcid
        from ccsds_cop.cop_1 import farm as tf
        from ccsds_cop.cop_1 import fop as tp
        from spacepackets.uslp import (
            BypassSequenceControlFlag,
            PrimaryHeader,
            ProtocolCommandFlag,
            SourceOrDestField,
            TfdzConstructionRules,
            TransferFrame,
            TransferFrameDataField,
            UslpProtocolIdentifier,
        )
    except ImportError:
        return None
    g = Gvcid(12, 1, 0)

    def run():
        fop = tp.Fop1(g, k=10, timer_initial_value=10000)
        fa = tf.Farm1(10)
        fop.on_receive_response_from_lower_layer(tp.Response(g, tp.ResponseType.AD_ACCEPTED))
        fop.on_receive_directive(tp.DirectiveRequest(g, 0, tp.DirectiveType.INITIATE_AD_NO_CLCW))
        for i in range(n):
            fop.on_receive_request_to_transfer_fdu(
                tp.RequestToTransferFdu(g, i, b"fdu", tp.ServiceType.AD)
            )
            q = fop.interface.to_lower
            while q:
                req = q.pop()
                if not isinstance(req, tp.TransmitRequestForFrame):
                    continue
                h = PrimaryHeader(
                    1, SourceOrDestField.SOURCE, 0, 0, 0, BypassSequenceControlFlag(0),
                    ProtocolCommandFlag(0), vcf_count_len=1, vcf_count=req.v_s,
                )  # fmt: skip
                d = TransferFrameDataField(
                    TfdzConstructionRules.VpNoSegmentation,
                    UslpProtocolIdentifier.SPACE_PACKETS_ENCAPSULATION_PACKETS,
                    req.tfdf,
                )
                fa.lower_interface.buffer.append(TransferFrame(h, d))
                fa.lower_interface.signal.append(tf.ValidFrameArrivedIndication(g))
                fa.tick()
                fa.higher_interface.buffer.clear()
                fa.higher_interface.signal.clear()
                fop.on_receive_response_from_lower_layer(
                    tp.Response(g, tp.ResponseType.AD_ACCEPTED)
                )
                fop.on_clcw_arrived(ControlWord(report_value=fa.v_r))
            fop.interface.to_higher.clear()
        fop.cancel_timer()

    return run


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="short runs (smoke check)")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    args = ap.parse_args(argv)
    seconds, repeats = (0.15, 3) if args.quick else (0.6, 5)
    out = []
    rows, peers = cases()
    for name, unit, fn, size in rows:
        ours = rate(fn, seconds, repeats)
        out.append((name, "obsw", ours, unit))
        if name in peers:
            peer, pfn = peers[name]
            out.append((name, peer, rate(pfn, seconds, repeats), unit))
        out.append((name + ": line rate", "obsw", ours * size * 8, "bit/s"))
    ours = rate(cop_ours(), seconds, repeats) * 50
    out.append(("COP-1 AD frame, FOP -> FARM -> CLCW -> FOP", "obsw", ours, "frame/s"))
    theirs = cop_theirs()
    if theirs is not None:
        out.append(
            (
                "COP-1 AD frame, FOP -> FARM -> CLCW -> FOP",
                "ccsds-cop",
                rate(theirs, seconds, repeats) * 50,
                "frame/s",
            )
        )
    if args.json:
        print(
            json.dumps(
                {
                    "bench": "frames",
                    "rows": [
                        {"case": c, "impl": i, "value": v, "unit": u, "higher_is_better": True}
                        for c, i, v, u in out
                    ],
                }
            )
        )
        return 0
    print("%-48s %-13s %14s %-8s %8s" % ("case", "impl", "median", "unit", "ratio"))
    ours_by_case = {}
    for c, i, v, u in out:
        if i == "obsw":
            ours_by_case[c] = v
        ratio = "" if i == "obsw" else "%.2fx" % (ours_by_case[c] / v)
        print("%-48s %-13s %14.0f %-8s %8s" % (c, i, v, u, ratio))
    print("ratio = obsw / peer (higher is better for obsw)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
