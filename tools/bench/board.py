"""CPU budget of the reconfiguration module: Cortex-M instructions per operation of the frozen
core, counted exactly on the QEMU board, and what they mean on a 168 MHz Cortex-M4 at full
SpaceCAN load.

The QEMU Cortex-M image (tools/firmware.py: mps2-an385, the core frozen, `cryptolib` on mbed
TLS's AES, the Pyboard's heap and 32 KiB more for the bench's own rig: a SpaceCAN controller
playing the OBC and the modelled EEPROMs and DS3231, which the application alone does not
carry; the `heap` stage checks the application in the Pyboard's heap) runs under
`-icount shift=7`: every guest instruction advances the virtual clock by 2**7 ns,
whatever the host does. The operations of tools/bench/board_ops.py read the board's CMSDK APB
timer (25 MHz, 40 ns a tick) around each operation with the SysTick interrupt masked; 128 ns
per instruction is 3.2 ticks, so a tick difference t fixes the instruction count I exactly
(3.2 I - 1 < t < 3.2 I + 1 holds one integer). (`shift=0`, 1 ns an instruction, would give
40 instructions a tick; QEMU 7.2 as Debian ships it has no TCG plugins to count with, and the
M3's DWT cycle counter reads 0.) Each operation starts on a freshly collected heap (not
counted), so its figure holds its own allocation but no collection; "with gc" adds a whole
collection of the case's heap, counted on the board (to 10,000 instructions: the collector's
conservative stack scan reads a few words the REPL left at the host's pace), each time its
allocations add up to the heap the application leaves free on a Pyboard (the low-water mark of
the `heap` stage's session, which the benchmark runs itself on a freshly booted board and
reports in its first row). The empty operation (the timer reads and a call) is subtracted.
Each case runs on a freshly booted board (after a soft reset the heap was found a few bytes
apart from one run to the next, and the counts with it), so no figure depends on which cases
ran before; `--check` measures every case twice and compares every count.

The counts are Thumb-2 instructions of the Cortex-M3 build; a Pyboard's Cortex-M4 runs the same
interpreter code (its build adds the FPU, which the core's few float operations use). The CPU
shares assume an IPC of 0.7 at 168 MHz (flash wait states behind the ART accelerator, the
bytecode loop's branches and loads): 117.6 million instructions per second.

Usage: python tools/bench/board.py [--quick] [--json] [--check] [--cases NAME,..]
"""

import argparse
import contextlib
import json
import os
import subprocess
import sys
import tempfile

from obsw_host import firmware

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))

import firmware_stages  # noqa: E402 (the heap stage's session)

OPS_SCRIPT = os.path.join(ROOT, "tools", "bench", "board_ops.py")
SHIFT = 7  # -icount shift: 2**SHIFT ns of virtual time per guest instruction
TICK_NS = 40  # the CMSDK APB timer at the MPS2 board's 25 MHz
CPU_HZ = 168e6
IPC = 0.7
CAPACITY = CPU_HZ * IPC  # instructions per second
BUS_FRAMES = 8000  # SpaceCAN at 1 Mbit/s: about 8,000 frames per second
BATCH = 16  # frames per poll in the batch cases (board_ops.BATCH)
FRAMES_PER_PASS = 64  # the application's bound: 32 frames a bus per loop pass
RESPONDER_SHARE = 0.5  # the responder's budget at full bus load
# What the reconfiguration application leaves free on a Pyboard's heap, the heap stage's
# low-water mark, measured by its own session in each run (firmware_stages.free_heap): a
# collection comes every so many bytes allocated. (The free heap of a case itself is not used:
# a stale word in the C stack can keep a garbage block alive in one boot.)
QUICK_HEAP_PASSES = 2000  # the heap stage's session runs HEAP_PASSES; --quick this many
WATCHDOG_TARGET_MS = 330  # obsw.reconfig.watchdog: kick aimed at 330 ms after the last one
WATCHDOG_TIMEOUT_MS = 1000  # the TPS3813 resets after 1000 ms without a kick
WATCHDOG_MARGIN_MS = 10

FREE_HEAP_CASE = "free heap the application leaves on a Pyboard (heap stage's low-water mark)"
# (name, what, operations)
CASES = (
    ("empty", "the timer reads alone", 8),
    ("gc_collect", "one garbage collection (the case's heap)", 4),
    ("frame_heartbeat", "SpaceCAN frame: heartbeat", 8),
    ("frame_sync", "SpaceCAN frame: sync", 8),
    ("frame_tc_20_1", "SpaceCAN frame: TC[20,1] with its report", 8),
    ("frame_ping_17_1", "SpaceCAN frame: TC[17,1] ping with its three replies", 8),
    ("frame_other", "SpaceCAN frame: another node's request", 8),
    ("batch_heartbeat", "SpaceCAN poll of 16 heartbeats", 4),
    ("batch_sync", "SpaceCAN poll of 16 sync frames", 4),
    ("batch_tc_20_1", "SpaceCAN poll of 16 TC[20,1]", 4),
    ("batch_ping_17_1", "SpaceCAN poll of 16 TC[17,1]", 4),
    ("batch_other", "SpaceCAN poll of 16 requests to another node", 4),
    ("can_idle", "SpaceCAN poll with no frame", 8),
    ("loop_idle", "main loop pass, idle", 8),
    ("loop_busy", "main loop pass, busy (status, report, save, four frames)", 4),
    ("essential_tc", "essential TC: CLTU to CPDU line change", 4),
    ("essential_tc_hmac", "essential TC, SDLS HMAC-SHA-256 verified", 4),
    ("essential_tc_gcm", "essential TC, SDLS AES-256-GCM verified (cryptolib AES)", 4),
    ("sgm_write", "safeguard record write (both EEPROMs, read back)", 4),
    ("sgm_read", "safeguard record read (both EEPROMs, ECC, compare)", 4),
    ("pus_tc_decode", "PUS TC decode (TC[17,1])", 8),
    ("pus_tm_encode", "PUS TM encode (TM[3,25], 16 bytes)", 8),
    ("pluto_statement", "PLUTO statement (`i := i + 1;` in a while loop)", 8),
    ("update_verify", "update package: its manifest's Ed25519 signature (collections in)", 1),
)
# the bench's own rig (a SpaceCAN controller playing the OBC, the modelled EEPROMs and DS3231)
# shares the board's heap with the application: it gets this much on top of the Pyboard's
RIG_HEAP = 32 * 1024
QUICK = ("empty", "gc_collect", "frame_heartbeat", "batch_heartbeat", "can_idle", "loop_busy")
# frame kinds at full load, and the frames each puts on the bus: a request and its replies
# share the bus's 8,000 frames a second (TC[20,1] of one parameter: (1,1), (20,2), (1,7))
KINDS = {"heartbeat": 1, "sync": 1, "other": 1, "tc_20_1": 4, "ping_17_1": 4}


def instructions(ticks):
    """The one instruction count a tick difference allows (3.2 ticks an instruction)."""
    per = (1 << SHIFT) / TICK_NS
    if per <= 2:
        raise ValueError("a tick difference fixes the count only above 2 ticks an instruction")
    # ticks - 1 < per * I < ticks + 1, in integers for per = 2**SHIFT / TICK_NS
    return ((ticks - 1) * TICK_NS) // (1 << SHIFT) + 1


def compile_ops(out):
    cross = firmware.build_mpy_cross()
    subprocess.run([str(cross), "-march=armv7m", "-o", out, OPS_SCRIPT], check=True, cwd=ROOT)


def run_board(elf, mpy, cases):
    """Every case on a fresh board: {case: {"ticks": [...], "alloc", "heap", "gc", "ok"}}."""
    out = {}
    for name, _, n in cases:
        # a fresh board for every case: after a soft reset the heap was found a few bytes apart
        # from one run to the next, and the counts with it
        with firmware.Qemu(elf, ["-icount", "shift=%d" % SHIFT]) as q:
            code = "import board_ops\nboard_ops.run(%r, %d)\n" % (name, n)
            rc, text = firmware.mpremote(q.pty, "cp", mpy, ":board_ops.mpy", "+", "exec", code)
            r = {}
            for line in text.splitlines():
                parts = line.split()
                if len(parts) >= 2 and parts[1] == name:
                    if parts[0] == "ticks":
                        r["ticks"] = [int(t) for t in parts[2:]]
                    elif parts[0] in ("alloc", "heap", "gc"):
                        r[parts[0]] = int(parts[2])
                    elif parts[0] == "ok":
                        r["ok"] = line
            if rc or len(r) != 5:
                raise SystemExit("board op %s failed:\n%s" % (name, text))
            out[name] = r
    return out


def _collection(ticks):
    # A collection scans the C stack conservatively, and a few words there are left by code
    # that ran at the host's pace (the REPL polling the UART for the code to run): its count
    # moves by a few instructions from one boot to the next, so it is kept to 10,000.
    return round(instructions(ticks), -4)


def _counts(r):
    """What must repeat exactly from one boot to the next."""
    return (
        [instructions(t) for t in r["ticks"]],
        r["alloc"],
        _collection(r["gc"]),
        r["ok"],
    )


def measure(elf, mpy, cases, check, free_heap):
    first = run_board(elf, mpy, cases)
    same = None
    if check:
        second = run_board(elf, mpy, cases)
        differ = [k for k in first if _counts(first[k]) != _counts(second[k])]
        for k in differ:
            print("board: %s counted differently:" % k, file=sys.stderr)
            print("  %r\n  %r" % (_counts(first[k]), _counts(second[k])), file=sys.stderr)
        same = not differ
    empty = [instructions(t) for t in first["empty"]["ticks"]]
    base = min(empty)
    res = {}
    for name, what, _ in cases:
        r = first[name]
        counts = [instructions(t) - base for t in r["ticks"]]
        res[name] = {
            "what": what,
            "instructions": sum(counts) / len(counts),
            "min": min(counts),
            "max": max(counts),
            "alloc": r["alloc"],
            "heap": r["heap"],
            "collect": _collection(r["gc"]),
            "ok": r["ok"],
        }
    gc_case = res.get("gc_collect")
    if gc_case is not None:  # a collection's count, kept to 10,000 like the others
        for key in ("instructions", "min", "max"):
            gc_case[key] = round(gc_case[key], -4)
    for r in res.values():
        # the collections its garbage costs: one of its heap for every free_heap bytes
        r["with_gc"] = r["instructions"] + r["alloc"] * r["collect"] / free_heap
    for kind in KINDS:
        b = res.get("batch_" + kind)
        if b is not None and "can_idle" in res:
            # one frame more in a poll at full load: (poll of BATCH - idle poll) / BATCH
            idle = res["can_idle"]
            for key in ("instructions", "with_gc"):
                b["per_frame_" + key] = (b[key] - idle[key]) / BATCH
    return res, same


def budget(res):
    """Shares of the CPU at full bus load and the main loop's worst-case period."""
    share = {}
    per_bus_frame = {}
    for kind, on_bus in KINDS.items():
        b = res.get("batch_" + kind)
        if b is not None and "per_frame_with_gc" in b:
            # a bus full of this kind carries BUS_FRAMES / on_bus of them a second
            per_bus_frame[kind] = b["per_frame_with_gc"] / on_bus
            share[kind] = BUS_FRAMES * per_bus_frame[kind] / CAPACITY
    out = {"share": share}
    if "loop_busy" in res and share:
        # the costliest frame kind at the full bus rate, the loop doing its busiest pass: the
        # frames that arrive during a pass are handled in the next, so the period is
        # T = busy / (capacity - rate * per_frame) while that leaves CPU, and at most
        # (busy + 64 frames) / capacity, since a pass takes at most 64 frames (the rest stay in
        # the controller's receive FIFO, where the hardware drops what overflows)
        worst = max(per_bus_frame.values())  # instructions per frame on the bus
        busy = res["loop_busy"]["with_gc"]
        left = CAPACITY - BUS_FRAMES * worst
        dearest = max(res["batch_" + k]["per_frame_with_gc"] for k in share)  # a received one
        bounded = (busy + FRAMES_PER_PASS * dearest) / CAPACITY
        fed = bounded if left <= 0 else min(busy / left, bounded)
        out["loop_worst_ms"] = fed * 1000
        out["loop_busy_alone_ms"] = busy / CAPACITY * 1000
        out["watchdog_room_ms"] = WATCHDOG_TIMEOUT_MS - WATCHDOG_MARGIN_MS - WATCHDOG_TARGET_MS
        out["frame_budget"] = RESPONDER_SHARE * CAPACITY / BUS_FRAMES
    return out


def rows_of(cases, res, b, free_heap):
    rows = []

    def row(case, value, unit, higher_is_better=False):
        rows.append(
            {
                "case": case,
                "impl": "obsw",
                "value": value,
                "unit": unit,
                "higher_is_better": higher_is_better,
            }
        )

    row(FREE_HEAP_CASE, free_heap, "bytes", True)

    for name, what, _ in cases:
        r = res[name]
        row(what, round(r["instructions"]), "instructions")
        row(what, round(r["with_gc"]), "instructions with gc")
        row(what, r["alloc"], "bytes allocated")
        if "per_frame_instructions" in r:
            kind = name[len("batch_") :]
            row(
                what + ", per frame received",
                round(r["per_frame_with_gc"]),
                "instructions with gc",
            )
            row(
                what + ", a bus of them at %d frames/s" % BUS_FRAMES,
                round(100 * b["share"][kind], 1),
                "% of a 168 MHz Cortex-M4",
            )
    if "loop_worst_ms" in b:
        row(
            "main loop worst-case period at full bus load",
            round(b["loop_worst_ms"], 2),
            "ms (room before the watchdog: %d ms)" % b["watchdog_room_ms"],
        )
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a few operations only")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--check", action="store_true", help="boot twice, compare every count")
    ap.add_argument("--heap", type=int, help="the board's heap (default: Pyboard + RIG_HEAP)")
    ap.add_argument("--cases", help="only these operations (names, comma-separated)")
    args = ap.parse_args(argv)
    cases = [c for c in CASES if not args.quick or c[0] in QUICK]
    if args.cases:
        wanted = args.cases.split(",")
        unknown = sorted(set(wanted) - {c[0] for c in CASES})
        if unknown:
            ap.error("no operation %s; expected some of %s" % (unknown, [c[0] for c in CASES]))
        cases = [c for c in CASES if c[0] in wanted]
    with contextlib.redirect_stdout(sys.stderr):  # the build's progress; stdout is the result
        elf = firmware.build_qemu(heap=args.heap or firmware.pyboard_heap() + RIG_HEAP)
        with tempfile.TemporaryDirectory(prefix="obsw-board-") as tmp:
            mpy = os.path.join(tmp, "board_ops.mpy")
            compile_ops(mpy)
            passes = QUICK_HEAP_PASSES if args.quick else firmware_stages.HEAP_PASSES
            free_heap = firmware_stages.free_heap(passes)
            res, same = measure(str(elf), mpy, cases, args.check, free_heap)
    b = budget(res)
    if args.json:
        print(
            json.dumps(
                {
                    "bench": "board",
                    "rows": rows_of(cases, res, b, free_heap),
                    "counter": "Thumb-2 instructions, QEMU mps2-an385 (Cortex-M3), -icount "
                    "shift=%d, CMSDK APB timer" % SHIFT,
                    "cpu": {"hz": CPU_HZ, "ipc": IPC, "bus_frames_per_s": BUS_FRAMES},
                    "deterministic": same,
                }
            )
        )
        return 0
    print(
        "%-58s %11s %11s %8s %11s %8s"
        % ("operation", "instr.", "with gc", "alloc B", "per frame", "@8k/s")
    )
    for name, what, _ in cases:
        r = res[name]
        kind = name[len("batch_") :] if name.startswith("batch_") else None
        print(
            "%-58s %11.0f %11.0f %8d %11s %8s"
            % (
                what,
                r["instructions"],
                r["with_gc"],
                r["alloc"],
                "%.0f" % r["per_frame_with_gc"] if "per_frame_with_gc" in r else "",
                "%.1f%%" % (100 * b["share"][kind]) if kind in b["share"] else "",
            )
        )
    if "loop_worst_ms" in b:
        print(
            "per-frame budget (half the CPU at %d frames/s): %.0f instructions; main loop, busy "
            "pass alone: %.2f ms; worst case at full bus load: %.2f ms (the watchdog leaves %d ms "
            "after its aim)"
            % (
                BUS_FRAMES,
                b["frame_budget"],
                b["loop_busy_alone_ms"],
                b["loop_worst_ms"],
                b["watchdog_room_ms"],
            )  # fmt: skip
        )
    print("free heap (the heap stage's low-water mark, %d passes): %d bytes" % (passes, free_heap))
    print(
        "Thumb-2 instructions (QEMU -icount, exact); shares at IPC %.1f and 168 MHz%s"
        % (IPC, "" if same is None else "; two boots count the same: %s" % same)
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
