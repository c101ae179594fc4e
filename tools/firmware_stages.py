"""The tools/test stages on real MicroPython images (each closes with 'N passed, N failed').

firmware_stages.py firmware     the Pyboard image builds; flash and frozen-bytecode table
firmware_stages.py upy-frozen   core tests on the unix port with the core frozen
firmware_stages.py cortex-m     core tests on the QEMU Cortex-M board through mpremote
firmware_stages.py heap         reconfiguration session and a PLUTO procedure on the QEMU board
                                with the Pyboard's heap: heap figures
firmware_stages.py board        obsw board deploy / test against the QEMU board's pty
"""

import os
import pathlib
import re
import shutil
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
import firmware  # noqa: E402

CORE_TESTS = sorted((ROOT / "tests" / "core").glob("test_*.py"))
# Core tests that cannot run on a board with the Pyboard's heap, and why (counted as skipped).
CORTEX_M_SKIPS = {}
MIN_FREE = 0.30  # the least share of the Pyboard heap free at the low-water mark
HEAP_PASSES = 10000
COUNTS = re.compile(r"(\d+) passed, (\d+) failed(?:, (\d+) skipped)?")


def _close(label, t0, passed, failed, skipped=0):
    print("%s stage time %.1f s" % (label, time.monotonic() - t0))
    line = "%s: %d passed, %d failed" % (label, passed, failed)
    print(line + (", %d skipped" % skipped if skipped else ""))
    return 1 if failed else 0


def _counts(text):
    found = COUNTS.findall(text)
    if not found:
        return None
    p, f, k = found[-1]
    return int(p), int(f), int(k or 0)


def stage_upy_frozen():
    t0 = time.monotonic()
    try:
        exe = firmware.build_unix()
    except firmware.FirmwareError as e:
        print(e)
        return _close("upy-frozen", t0, 0, 1)
    env = dict(os.environ, MICROPYPATH="%s:.frozen" % (ROOT / "tools" / "upy"))
    # the entry point of the reconfiguration image, from the frozen modules alone
    probe = "import obsw.reconfig.app as a; print('entry point', a.__name__, 'imported frozen')"
    r = subprocess.run([str(exe), "-c", probe], env=env, capture_output=True, text=True)
    print(r.stdout.strip() or r.stderr.strip())
    entry_ok = r.returncode == 0
    cmd = [str(exe), "-X", "heapsize=64M", str(ROOT / "tools" / "upy" / "run.py")]
    cmd += [str(p.relative_to(ROOT)) for p in CORE_TESTS]
    r = subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True)
    out = r.stdout + r.stderr
    print("\n".join(out.splitlines()[-30:]))
    c = _counts(out) or (0, 1, 0)
    return _close("upy-frozen", t0, c[0] + entry_ok, c[1] + (not entry_ok), c[2])


def _stage_dir(name):
    d = firmware.BUILD / name
    if d.exists():
        shutil.rmtree(d)
    d.mkdir(parents=True)
    return d


def stage_cortex_m():
    t0 = time.monotonic()
    try:
        elf = firmware.build_qemu()
    except firmware.FirmwareError as e:
        print(e)
        return _close("cortex-m", t0, 0, 1)
    from_source = firmware.stage_board_tests()  # tests that cannot be frozen: copied, compiled
    passed = failed = skipped = 0
    q = firmware.Qemu(elf)
    try:
        for path in CORE_TESTS:
            name = path.name
            code = "import obsw_run_tests as r; r.main([%r], %r)" % (name, CORTEX_M_SKIPS)
            t1 = time.monotonic()
            pre = ["cp", str(path), ":" + name, "+"] if name in from_source else []
            rc, out = firmware.mpremote(q.pty, *pre, "exec", code, timeout=90)
            c = _counts(out)
            if c is None:
                failed += 1
                print("FAIL %s (no result, status %d):\n%s" % (name, rc, out[-1500:]))
                q.close()
                q = firmware.Qemu(elf)
                continue
            passed, failed, skipped = passed + c[0], failed + c[1], skipped + c[2]
            for line in out.splitlines():
                if (
                    line.startswith(("FAIL", "skip", "Traceback", "MemoryError"))
                    or "Error" in line
                ):
                    print("  " + line)
            print(
                "%-40s %3d passed %3d failed %3d skipped %5.1f s"
                % (name, *c, time.monotonic() - t1)
            )
    finally:
        q.close()
    return _close("cortex-m", t0, passed, failed, skipped)


def _figures(out, prefix):
    return [line for line in out.splitlines() if line.startswith(prefix)]


def stage_heap():
    t0 = time.monotonic()
    try:
        elf = firmware.build_qemu()
        heap = firmware.pyboard_heap()
    except firmware.FirmwareError as e:
        print(e)
        return _close("heap", t0, 0, 1)
    passed = failed = 0
    print(
        "QEMU Cortex-M3 board, MICROPY_HEAP_SIZE %d (the Pyboard's _heap_end - _heap_start)" % heap
    )
    with firmware.Qemu(elf) as q:
        code = (
            "import obsw_heap; ok, low, total = obsw_heap.reconfig(%d); "
            "print('reconfig', 'ok' if ok and low >= %r * total else 'FAILED')"
            % (HEAP_PASSES, MIN_FREE)
        )
        t1 = time.monotonic()
        rc, out = firmware.mpremote(q.pty, "exec", code, timeout=300)
        print("\n".join(_figures(out, ("heap", "passes", "reconfig", "Traceback", "MemoryError"))))
        print("reconfiguration session %.1f s" % (time.monotonic() - t1))
        if rc == 0 and "reconfig ok" in out:
            passed += 1
        else:
            failed += 1
            print(out[-2000:])
        data = ROOT / "tests" / "data" / "pluto"
        code = (
            "import obsw_heap; ok, free, total = obsw_heap.pluto('p.pluto', 'p.json'); "
            "print('pluto', 'ok' if ok else 'FAILED')"
        )
        t1 = time.monotonic()
        rc, out = firmware.mpremote(
            q.pty,
            "cp", str(data / "commissioning.pluto"), ":p.pluto", "+",
            "cp", str(data / "commissioning.system.json"), ":p.json", "+",
            "exec", code,
            timeout=180,
        )  # fmt: skip
        lines = sum(1 for _ in open(data / "commissioning.pluto"))
        print("PLUTO procedure tests/data/pluto/commissioning.pluto (%d lines)" % lines)
        print("\n".join(_figures(out, ("pluto", "Traceback", "MemoryError"))))
        print("PLUTO run %.1f s" % (time.monotonic() - t1))
        if rc == 0 and "pluto ok" in out:
            passed += 1
        else:
            failed += 1
            print(out[-2000:])
    return _close("heap", t0, passed, failed)


def main(argv):
    stages = {
        "firmware": firmware.stage_sizes,
        "upy-frozen": stage_upy_frozen,
        "cortex-m": stage_cortex_m,
        "heap": stage_heap,
    }
    if len(argv) != 1 or argv[0] not in stages:
        print(__doc__)
        return 2
    return stages[argv[0]]()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
