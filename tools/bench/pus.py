"""PUS-C packet encode+decode round trips per second: obsw, spacepackets, puslib, plain struct.

Each round trip builds a packet object from field values, packs it, unpacks the bytes and reads
the fields back. The reference is hand-written `struct` code doing the same with the same CRC
function obsw uses (obsw.crc.crc16_ccitt_update, binascii.crc_hqx on CPython, pure Python with
OBSW_PURE=1). "spacepackets, same CRC" is spacepackets with its compiled CRC (fastcrc, Rust)
replaced by that same function too, so that with OBSW_PURE=1 both pay a pure-Python CRC and
without it both a C one. TM[3,25] carries a 16-bit structure ID and 16 uint32 parameters,
encoded once up front and the same bytes for every implementation.

Usage: python tools/bench/pus.py [--quick] [--json]
"""

import argparse
import json
import os
import statistics
import struct
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from measure import batch_size  # noqa: E402
from obsw.crc import crc16_ccitt_update  # noqa: E402
from obsw.pus.tc import PusTc  # noqa: E402
from obsw.pus.tm import PusTm  # noqa: E402

APID = 0x65
APP_DATA_64 = bytes(range(64))
HK_DATA = struct.pack(">H16I", 7, *range(1000, 1016))
TIME = (0x5A5A5A5A, 0x1234)
CASES = (
    ("TC[17,1]", "tc", 17, 1, b""),
    ("TC[20,3] 64 B", "tc", 20, 3, APP_DATA_64),
    ("TM[3,25] 16 x uint32", "tm", 3, 25, HK_DATA),
)


# --- obsw ------------------------------------------------------------------------------------
def obsw_tc(service, subtype, data):
    def run(n):
        for i in range(n):
            raw = PusTc(APID, service, subtype, data, i & 0x3FFF).pack()
            tc = PusTc.unpack(raw)
            if tc.subtype != subtype:
                raise AssertionError

    return run


def obsw_tm(service, subtype, data):
    def run(n):
        for i in range(n):
            raw = PusTm(APID, service, subtype, data, i & 0x3FFF, i & 0xFFFF, 0, TIME).pack()
            tm = PusTm.unpack(raw)
            if tm.subtype != subtype:
                raise AssertionError

    return run


# --- hand-written struct reference -------------------------------------------------------------
_TC_HEAD = struct.Struct(">HHHBBBH")
_TM_HEAD = struct.Struct(">HHHBBBHHIH")
_PEC = struct.Struct(">H")


def reference_tc(service, subtype, data):
    def run(n):
        head_pack = _TC_HEAD.pack
        head_unpack = _TC_HEAD.unpack_from
        pec = _PEC.pack
        for i in range(n):
            body = head_pack(
                0x1800 | APID, 0xC000 | (i & 0x3FFF), len(data) + 6, 0x2F, service, subtype, 0
            ) + bytes(data)
            raw = body + pec(crc16_ccitt_update(body, 0xFFFF))
            pid, psc, dlen, b0, svc, sub, src = head_unpack(raw)
            if dlen + 7 != len(raw) or crc16_ccitt_update(raw, 0xFFFF) != 0 or b0 >> 4 != 2:
                raise ValueError("bad packet")
            app = raw[11:-2]
            if sub != subtype or len(app) != len(data):
                raise AssertionError

    return run


def reference_tm(service, subtype, data):
    def run(n):
        head_pack = _TM_HEAD.pack
        head_unpack = _TM_HEAD.unpack_from
        pec = _PEC.pack
        for i in range(n):
            body = head_pack(
                0x0800 | APID,
                0xC000 | (i & 0x3FFF),
                len(data) + 14,
                0x20,
                service,
                subtype,
                i & 0xFFFF,
                0,
                TIME[0],
                TIME[1],
            ) + bytes(data)
            raw = body + pec(crc16_ccitt_update(body, 0xFFFF))
            pid, psc, dlen, b0, svc, sub, cnt, dest, coarse, fine = head_unpack(raw)
            if dlen + 7 != len(raw) or crc16_ccitt_update(raw, 0xFFFF) != 0 or b0 >> 4 != 2:
                raise ValueError("bad packet")
            src = raw[19:-2]
            if sub != subtype or len(src) != len(data):
                raise AssertionError

    return run


# --- spacepackets ------------------------------------------------------------------------------
def spacepackets_tc(service, subtype, data):
    from spacepackets.ecss.tc import PusTc as SpTc

    def run(n):
        for i in range(n):
            raw = SpTc(
                service=service,
                message_subtype=subtype,
                apid=APID,
                seq_count=i & 0x3FFF,
                app_data=data,
            ).pack()
            tc = SpTc.unpack(raw)
            if tc.message_subtype != subtype:
                raise AssertionError

    return run


def spacepackets_tm(service, subtype, data):
    from spacepackets.ecss.tm import PusTm as SpTm

    stamp = struct.pack(">IH", *TIME)

    def run(n):
        for i in range(n):
            raw = SpTm(
                service=service,
                message_subtype=subtype,
                timestamp=stamp,
                source_data=data,
                apid=APID,
                seq_count=i & 0x3FFF,
                message_counter=i & 0xFFFF,
            ).pack()
            tm = SpTm.unpack(raw, timestamp_len=6)
            if tm.message_subtype != subtype:
                raise AssertionError

    return run


class _SameCrc16:
    """Stands in for fastcrc's ``crc16`` module in spacepackets: its ibm_3740 (that is
    CRC-16/CCITT-FALSE) computed by the function obsw uses, so that both pay the same CRC."""

    @staticmethod
    def ibm_3740(data, initial=None):
        return crc16_ccitt_update(data, 0xFFFF if initial is None else initial)


def _same_crc(make):
    def factory(service, subtype, data):
        import spacepackets.ecss.tc as sp_tc
        import spacepackets.ecss.tm as sp_tm

        inner = make(service, subtype, data)

        def run(n):
            saved = sp_tc.crc16, sp_tm.crc16
            sp_tc.crc16 = sp_tm.crc16 = _SameCrc16
            try:
                inner(n)
            finally:
                sp_tc.crc16, sp_tm.crc16 = saved

        return run

    return factory


# --- puslib ------------------------------------------------------------------------------------
def puslib_tc(service, subtype, data):
    from puslib.packet import AckFlag, PusTcPacket

    ack = AckFlag(15)

    def run(n):
        for i in range(n):
            raw = PusTcPacket.create(
                apid=APID,
                name=i & 0x3FFF,
                pus_version=2,
                ack_flags=ack,
                service_type=service,
                service_subtype=subtype,
                source=0,
                data=data,
            ).serialize()
            tc = PusTcPacket.deserialize(raw)
            if tc.subservice != subtype:
                raise AssertionError

    return run


def puslib_tm(service, subtype, data):
    from puslib.packet import PusTmPacket
    from puslib.time import CucTime

    def run(n):
        for i in range(n):
            raw = PusTmPacket.create(
                apid=APID,
                seq_count=i & 0x3FFF,
                pus_version=2,
                service_type=service,
                service_subtype=subtype,
                msg_type_counter=i & 0xFFFF,
                destination=0,
                time=CucTime(TIME[0], TIME[1], 4, 2, has_preamble=False),
                data=data,
            ).serialize()
            template = CucTime(0, 0, 4, 2, has_preamble=False)
            tm = PusTmPacket.deserialize(raw, cuc_time=template)
            if tm.subservice != subtype:
                raise AssertionError

    return run


IMPLS = (
    ("obsw", obsw_tc, obsw_tm),
    ("reference", reference_tc, reference_tm),
    ("spacepackets", spacepackets_tc, spacepackets_tm),
    ("spacepackets, same CRC", _same_crc(spacepackets_tc), _same_crc(spacepackets_tm)),
    ("puslib", puslib_tc, puslib_tm),
)


def measure(runs, seconds, repeats):
    """Median round trips per second of each run, the timed batches interleaved.

    On a shared machine the load drifts; timing one batch of every implementation per repeat
    gives each the same conditions, so the ratios stay honest even when the absolute figures
    move."""
    sizes = [batch_size(run, seconds, start=100) for run in runs]
    rates = [[] for _ in runs]
    for _ in range(repeats):
        for run, n, out in zip(runs, sizes, rates):
            t0 = time.perf_counter()
            run(n)
            out.append(n / (time.perf_counter() - t0))
    return [statistics.median(r) for r in rates]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="short runs (a few seconds in all)")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    args = ap.parse_args(argv)
    seconds, repeats = (0.1, 3) if args.quick else (0.5, 7)
    rows = []
    for case, kind, service, subtype, data in CASES:
        impls, runs = [], []
        for impl, make_tc, make_tm in IMPLS:
            try:
                runs.append((make_tc if kind == "tc" else make_tm)(service, subtype, data))
            except ImportError:
                continue  # peer not installed
            impls.append(impl)
        for impl, value in zip(impls, measure(runs, seconds, repeats)):
            rows.append(
                {
                    "case": case,
                    "impl": impl,
                    "value": round(value, 1),
                    "unit": "round trips/s",
                    "higher_is_better": True,
                }
            )
    if args.json:
        print(json.dumps({"bench": "pus", "rows": rows}))
        return 0
    print("%-22s %-23s %14s %12s" % ("case", "impl", "round trips/s", "obsw ratio"))
    for case, *_ in CASES:
        mine = [r for r in rows if r["case"] == case]
        ours = next(r["value"] for r in mine if r["impl"] == "obsw")
        for r in mine:
            ratio = "" if r["impl"] == "obsw" else "%.2fx" % (ours / r["value"])
            print("%-22s %-23s %14.0f %12s" % (case, r["impl"], r["value"], ratio))
    return 0


if __name__ == "__main__":
    sys.exit(main())
