"""CPU budget of the reconfiguration module: instructions per operation of the core as the board
runs it, and what they mean on a 168 MHz Cortex-M4 at full SpaceCAN load.

Each operation of tools/bench/board_ops.py runs in the MicroPython unix port, on the core
compiled to bytecode by mpy-cross (as frozen modules run it), under valgrind's callgrind, which
counts executed instructions exactly: the same input gives the same count, run after run
(`--check` proves it by running every case twice). One operation's instructions are the count
difference between a run with N1 and one with N2 operations, divided by N2 - N1, less the same
figure of the harness loop. Each operation starts on a freshly collected heap; that collection
is counted apart and subtracted, so an operation's figure includes sweeping its own garbage but
not marking the live heap. "with gc" adds one whole collection (counted on the unix port's
heap, which also holds the imported bytecode a board keeps in flash: an upper bound) for every
64 KiB the operation allocates, what a board's heap leaves free. Address-space randomisation
is turned off (setarch -R) and the unix port's CPython host gets a fixed hash seed, so nothing
varies.

These are x86-64 instructions of the unix port, the nearest deterministic figure until the
Cortex-M image runs under QEMU with -icount. The CPU shares assume one Thumb-2 instruction per
x86-64 instruction of the same interpreter code and an IPC of 0.7 on the Cortex-M4 (flash wait
states behind the ART accelerator, the bytecode loop's branches and loads): 117.6 million
instructions per second at 168 MHz.

Usage: python tools/bench/board.py [--quick] [--json] [--check]
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OPS_SCRIPT = os.path.join(ROOT, "tools", "bench", "board_ops.py")
CPU_HZ = 168e6
IPC = 0.7
CAPACITY = CPU_HZ * IPC  # instructions per second
BUS_FRAMES = 8000  # SpaceCAN at 1 Mbit/s: about 8,000 frames per second
HEAP = "2M"  # room for the bytecode the unix port keeps on the heap and a few operations
FREE_HEAP = 64 * 1024  # what the board's heap leaves free for garbage between collections
WATCHDOG_TARGET_MS = 330  # obsw.reconfig.watchdog: kick aimed at 330 ms after the last one
WATCHDOG_TIMEOUT_MS = 1000  # the TPS3813 resets after 1000 ms without a kick
WATCHDOG_MARGIN_MS = 10

# (name, what, N1, N2)
CASES = (
    ("empty", "the harness loop alone", 20, 220),
    ("gc_collect", "one garbage collection (unix port heap)", 2, 6),
    ("frame_heartbeat", "SpaceCAN frame: heartbeat", 4, 20),
    ("frame_sync", "SpaceCAN frame: sync", 4, 20),
    ("frame_tc_20_1", "SpaceCAN frame: TC[20,1] with its reply", 4, 12),
    ("frame_ping_17_1", "SpaceCAN frame: TC[17,1] ping with its reply", 4, 12),
    ("can_idle", "SpaceCAN poll with no frame", 4, 20),
    ("loop_idle", "main loop pass, idle", 4, 20),
    ("loop_busy", "main loop pass, busy", 2, 6),
    ("essential_tc", "essential TC: CLTU to CPDU line change", 2, 6),
    ("sgm_write", "safeguard record write", 2, 6),
    ("sgm_read", "safeguard record read", 2, 6),
    ("pus_tc_decode", "PUS TC decode", 4, 20),
    ("pus_tm_encode", "PUS TM encode", 4, 20),
    ("pluto_statement", "PLUTO statement", 4, 20),
)
QUICK = ("empty", "gc_collect", "frame_heartbeat", "frame_ping_17_1", "loop_idle", "loop_busy")


def build_mpy(out):
    subprocess.run(
        [sys.executable, os.path.join(ROOT, "tools", "mpy.py"), "build", out, "--march", "x64"],
        check=True,
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
    )


def micropython():
    exe = os.path.join(ROOT, ".venv", "bin", "micropython")
    return exe if os.path.exists(exe) else shutil.which("micropython")


def count(mpy, name, n):
    """(instructions, allocated bytes per operation, check line) of one run."""
    cmd = [
        "setarch",
        "-R",
        "valgrind",
        "--tool=callgrind",
        "--callgrind-out-file=/dev/null",
        micropython(),
        "-X",
        "heapsize=" + HEAP,
        OPS_SCRIPT,
        name,
        str(n),
    ]
    env = {"PATH": os.environ.get("PATH", ""), "PYTHONHASHSEED": "0", "MICROPYPATH": mpy}
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=ROOT)
    m = re.search(r"Collected : (\d+)", r.stderr)
    ok = [line for line in r.stdout.splitlines() if line.startswith("ok ")]
    alloc = [line for line in r.stdout.splitlines() if line.startswith("alloc ")]
    if r.returncode or m is None or not ok or not alloc:
        raise SystemExit("board op %s failed:\n%s\n%s" % (name, r.stdout, r.stderr[-2000:]))
    return int(m.group(1)), int(alloc[0].split()[1]), ok[0]


def measure(mpy, cases, check):
    out = {}
    for name, what, n1, n2 in cases:
        a, alloc, _ = count(mpy, name, n1)
        b, _, line = count(mpy, name, n2)
        same = None
        if check:
            same = count(mpy, name, n1)[0] == a and count(mpy, name, n2)[0] == b
        out[name] = {"what": what, "raw": (b - a) / (n2 - n1), "alloc": alloc, "same": same}
        out[name]["line"] = line
    base = out["gc_collect"]["raw"]  # the harness loop and a collection of a clean heap
    collect = base - out["empty"]["raw"]
    out["gc_collect"]["raw"] = collect
    for name, r in out.items():
        r["instructions"] = r["raw"] - base if name not in ("empty", "gc_collect") else r["raw"]
        # the collections its garbage costs, one per FREE_HEAP bytes allocated
        r["with_gc"] = r["instructions"] + r["alloc"] * collect / FREE_HEAP
    return out


def budget(res):
    """Shares of the CPU at full bus load and the main loop's worst-case period."""
    share = {}
    for name, r in res.items():
        if name.startswith("frame_"):
            share[name] = BUS_FRAMES * r["with_gc"] / CAPACITY
    out = {"share": share}
    if "loop_busy" in res and share:
        # the worst frame kind arriving at the full bus rate while the loop does its busiest
        # pass: T = busy / (capacity - rate * per_frame), if the frames leave any CPU at all
        worst = max(res[k]["with_gc"] for k in share)
        left = CAPACITY - BUS_FRAMES * worst
        busy = res["loop_busy"]["with_gc"]
        out["loop_worst_ms"] = None if left <= 0 else busy / left * 1000
        out["loop_busy_alone_ms"] = busy / CAPACITY * 1000
        out["watchdog_room_ms"] = WATCHDOG_TIMEOUT_MS - WATCHDOG_MARGIN_MS - WATCHDOG_TARGET_MS
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a few operations only")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--check", action="store_true", help="run each case twice, compare counts")
    args = ap.parse_args(argv)
    if shutil.which("valgrind") is None or shutil.which("setarch") is None:
        raise SystemExit("board.py needs valgrind and setarch (apt-get install valgrind)")
    cases = [c for c in CASES if not args.quick or c[0] in QUICK]
    tmp = tempfile.mkdtemp(prefix="obsw-board-")
    try:
        mpy = os.path.join(tmp, "mpy")
        build_mpy(mpy)
        res = measure(mpy, cases, args.check)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    b = budget(res)
    rows = []
    for name, what, *_ in cases:
        r = res[name]
        rows.append(
            {
                "case": what,
                "impl": "obsw",
                "value": round(r["instructions"]),
                "unit": "instructions",
                "higher_is_better": False,
            }
        )
        rows.append(
            {
                "case": what,
                "impl": "obsw",
                "value": r["alloc"],
                "unit": "bytes allocated",
                "higher_is_better": False,
            }
        )
        if name in b["share"]:
            rows.append(
                {
                    "case": what + " at %d frames/s" % BUS_FRAMES,
                    "impl": "obsw",
                    "value": round(100 * b["share"][name], 1),
                    "unit": "% of a 168 MHz Cortex-M4",
                    "higher_is_better": False,
                }
            )
    if "loop_worst_ms" in b:
        rows.append(
            {
                "case": "main loop worst-case period at full bus load",
                "impl": "obsw",
                "value": None if b["loop_worst_ms"] is None else round(b["loop_worst_ms"], 2),
                "unit": "ms (room before the watchdog: %d ms)" % b["watchdog_room_ms"],
                "higher_is_better": False,
            }
        )
    deterministic = None
    if args.check:
        deterministic = all(r["same"] for r in res.values())
    if args.json:
        print(
            json.dumps(
                {
                    "bench": "board",
                    "rows": rows,
                    "counter": "x86-64 instructions, MicroPython unix port, callgrind",
                    "cpu": {"hz": CPU_HZ, "ipc": IPC, "bus_frames_per_s": BUS_FRAMES},
                    "deterministic": deterministic,
                }
            )
        )
        return 0
    print(
        "%-44s %12s %9s %12s %9s"
        % ("operation", "instructions", "alloc B", "with gc", "CPU @8k/s")
    )
    for name, what, *_ in cases:
        r = res[name]
        s = b["share"].get(name)
        print(
            "%-44s %12.0f %9d %12.0f %9s"
            % (
                what,
                r["instructions"],
                r["alloc"],
                r["with_gc"],
                "" if s is None else "%.1f%%" % (100 * s),
            )
        )
    if "loop_worst_ms" in b:
        w = b["loop_worst_ms"]
        print(
            "main loop, busy pass alone: %.2f ms; worst case under full bus load: %s "
            "(the watchdog leaves %d ms after its aim)"
            % (
                b["loop_busy_alone_ms"],
                "never ends" if w is None else "%.2f ms" % w,
                b["watchdog_room_ms"],
            )  # fmt: skip
        )
    print(
        "x86-64 instructions of the unix port (callgrind); shares assume 1 Thumb-2 instruction "
        "each and IPC %.1f at 168 MHz%s"
        % (IPC, "" if deterministic is None else "; counts repeat: %s" % deterministic)
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
