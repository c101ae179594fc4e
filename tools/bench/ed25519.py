"""Ed25519 verification of an update package's signature: one verify of a 300-octet message
on the reconfiguration module (QEMU Cortex-M board) and, on CPython, the pure-Python verifier
against cryptography's (OpenSSL's C).

On the board (tools/firmware.py's QEMU image, mps2-an385, the core frozen, the Pyboard's heap)
the frozen obsw.update.ed25519 verifies under `-icount shift=5`: every guest instruction
advances the virtual clock by 2**5 ns, and the CMSDK APB timer (25 MHz, 40 ns a tick, read with
SysTick masked, as tools/bench/board_ops.py does) gives the Thumb-2 instructions of the verify
to within two (1.25 per tick; the timer reads themselves, a few dozen instructions, are left
in). Milliseconds on a Pyboard's 168 MHz Cortex-M4 are given at 1 instruction a cycle and at
board.py's IPC of 0.7. The heap a verify needs is found by search on the board: a ballast
leaves a given heap free, and the verify either completes (collections included) or raises
MemoryError; the figure is the least free heap found to suffice.

Usage: python tools/bench/ed25519.py [--quick] [--json]
"""

import argparse
import contextlib
import json
import pathlib
import statistics
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "micropython")]

from cryptography.hazmat.primitives.asymmetric.ed25519 import (  # noqa: E402
    Ed25519PrivateKey,
    Ed25519PublicKey,
)
from measure import rate  # noqa: E402
from obsw.update import ed25519  # noqa: E402
from obsw_host import firmware  # noqa: E402

SHIFT = 5  # -icount shift: 2**SHIFT ns of virtual time per guest instruction
TICK_NS = 40  # the CMSDK APB timer at the MPS2 board's 25 MHz
CPU_HZ = 168e6
IPC = 0.7  # tools/bench/board.py's assumption for the Pyboard
MESSAGE = bytes(i * 7 & 0xFF for i in range(300))  # a package manifest's size
SEED = bytes(range(32))
HEAP_STEP = 256  # the heap search's resolution in bytes (--quick: 2048)

# Runs on the board through mpremote exec; %r are the key, signature and message.
BOARD_CODE = """
import gc, machine
from obsw.update import ed25519
mem = machine.mem32
TIMER, VALUE, TOP, CSR = 0x40000000, 0x40000004, 0x3FFFFFFF, 0xE000E010
key, sig, msg = %r, %r, %r
bad = bytes([sig[0] ^ 1]) + sig[1:]
ok = ed25519.verify(key, sig, msg) and not ed25519.verify(key, bad, msg)
csr = mem[CSR]
mem[CSR] = csr & ~2
mem[TIMER] = 0
mem[TIMER + 8] = TOP
mem[VALUE] = TOP
mem[TIMER] = 1
ticks = []
for i in range(%d):
    gc.collect()
    a = mem[VALUE]
    ed25519.verify(key, sig, msg)
    b = mem[VALUE]
    ticks.append((a - b) & TOP)
mem[CSR] = csr
gc.collect()
free = gc.mem_free()
lo, hi = 0, free  # a verify fails with lo free, succeeds with hi
while hi - lo > %d:
    want = (lo + hi) // 2
    gc.collect()
    ballast = bytearray(max(0, gc.mem_free() - want - 64))
    have = gc.mem_free()
    try:
        ed25519.verify(key, sig, msg)
        hi = min(hi, have)
    except MemoryError:
        lo = max(lo, have)
    ballast = None
print("result", ok, free, hi, " ".join(str(t) for t in ticks))
"""


def instructions(ticks):
    return ticks * TICK_NS / (1 << SHIFT)


def on_board(key, sig, quick):
    """(verified and refused a forgery, free heap, heap needed, [instructions per verify])."""
    code = BOARD_CODE % (key, sig, MESSAGE, 1 if quick else 3, 2048 if quick else HEAP_STEP)
    with contextlib.redirect_stdout(sys.stderr):  # the build's progress; stdout is the result
        elf = firmware.build_qemu()
    with firmware.Qemu(elf, ["-icount", "shift=%d" % SHIFT]) as q:
        rc, text = firmware.mpremote(q.pty, "exec", code, timeout=900)
    for line in text.splitlines():
        parts = line.split()
        if parts[:1] == ["result"]:
            counts = [instructions(int(t)) for t in parts[4:]]
            return parts[1] == "True", int(parts[2]), int(parts[3]), counts
    raise SystemExit("the board's verify failed (exit %d):\n%s" % (rc, text))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one verify, a coarse heap search")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    args = ap.parse_args(argv)
    private = Ed25519PrivateKey.from_private_bytes(SEED)
    key = private.public_key().public_bytes_raw()
    sig = private.sign(MESSAGE)
    ok, free, needed, counts = on_board(key, sig, args.quick)
    if not ok:
        raise SystemExit("the board's verifier gave a wrong answer")
    count = statistics.median(counts)
    seconds, repeats = (0.3, 3) if args.quick else (1.0, 5)
    peer = Ed25519PublicKey.from_public_bytes(key)
    ours = rate(lambda: ed25519.verify(key, sig, MESSAGE), seconds, repeats)
    theirs = rate(lambda: peer.verify(sig, MESSAGE), seconds, repeats)
    board = "one verify, 300-octet message, QEMU Cortex-M board"
    rows = [
        (board, "obsw", round(count), "instructions", False),
        (board, "obsw", round(count / CPU_HZ * 1000), "ms at 168 MHz, IPC 1", False),
        (board, "obsw", round(count / (CPU_HZ * IPC) * 1000), "ms at 168 MHz, IPC 0.7", False),
        (board, "obsw", needed, "bytes of free heap needed (search step %d)" % HEAP_STEP, False),
        ("one verify, 300-octet message, CPython", "obsw", ours, "verifies/s", True),
        ("one verify, 300-octet message, CPython", "cryptography", theirs, "verifies/s", True),
    ]
    if args.json:
        keys = ("case", "impl", "value", "unit", "higher_is_better")
        out = {
            "bench": "ed25519",
            "rows": [dict(zip(keys, r)) for r in rows],
            "counter": "Thumb-2 instructions, QEMU mps2-an385 (Cortex-M3), -icount "
            "shift=%d, CMSDK APB timer" % SHIFT,
            "board_heap_free": free,
        }
        print(json.dumps(out))
        return 0
    print("on the board (Pyboard heap, %d bytes free after a collection):" % free)
    print(
        "  instructions per verify:   %12.0f  (%s)"
        % (count, ", ".join("%.0f" % c for c in counts))
    )
    print(
        "  at 168 MHz:                %12.0f ms at IPC 1, %.0f ms at IPC 0.7"
        % (count / CPU_HZ * 1000, count / (CPU_HZ * IPC) * 1000)
    )
    print(
        "  free heap a verify needs:  %12d bytes (to %d)"
        % (needed, 2048 if args.quick else HEAP_STEP)
    )
    print("on CPython:")
    print("  %-24s %10.0f verifies/s" % ("obsw.update.ed25519", ours))
    print("  %-24s %10.0f verifies/s" % ("cryptography", theirs))
    print("  ratio (cryptography / obsw): %.0f" % (theirs / ours))
    return 0


if __name__ == "__main__":
    sys.exit(main())
