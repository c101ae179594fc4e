"""The tools/test stages on real MicroPython images (each closes with 'N passed, N failed').

firmware_stages.py firmware     the Pyboard image builds; flash and frozen-bytecode table
firmware_stages.py upy-frozen   core tests on the unix port with the core frozen
firmware_stages.py cortex-m     core tests on the QEMU Cortex-M board through mpremote
firmware_stages.py heap         reconfiguration session and a PLUTO procedure on the QEMU board
                                with the Pyboard's heap: heap figures
firmware_stages.py board        obsw board deploy / test / update against the QEMU board's pty
"""

import os
import pathlib
import re
import shutil
import subprocess
import sys
import time

from obsw_host import firmware

ROOT = pathlib.Path(__file__).resolve().parent.parent

CORE_TESTS = sorted((ROOT / "tests" / "core").glob("test_*.py"))
# Core tests that cannot run on a board with the Pyboard's heap, and why (counted as
# skipped, with the reason, by the board-side runner). A file name skips the whole file.
EEPROM = "host model of two 64 KiB M24512 EEPROMs: more than the Pyboard's whole heap"
BIG = "a 64 KiB packet: more than the Pyboard's heap can hold in one block"
HEAP = "a host-scale scenario (many transfers, stores or procedures at once) beyond a 103 KiB heap"
FILES = "reads the host's files (tests/data, temporary folders)"
TWO_ENDS = (
    "the spacecraft and the ground in one heap (the PUS application with its services, the "
    "ground's user process, CFDP entities at both ends): beyond a 103 KiB heap"
)
FILE19K = "a 19 KB file held four times (the data, both RAM filestores, the expected copy)"
CUTS20K = (
    "a 20 KB file through eight power cuts in RAM filestores (the data, the partial file, its "
    "state, the expected copy, both entities): beyond a 103 KiB heap"
)
TOKENS = "a 12 KB procedure text of 6,000 tokens (48 KB of token columns) in a 103 KiB heap"
MEMORY = (
    "memory areas with their copies as files in a RAM filestore (10 KiB chunks), the PUS "
    "application and its services: beyond a 103 KiB heap"
)
PASSES = (
    "files of 30 KB in RAM filestores at both ends of a transfer across passes (the data, "
    "the partial file, the expected copy): beyond a 103 KiB heap"
)
RESTART = (
    "the PUS application before and after a restart, both with their services, in one heap "
    "beside the ground's user process: beyond a 103 KiB heap"
)
MIB = "a manifest of 1 MiB and one of 1 MiB + 1 octet: ten times the Pyboard's heap"
VITERBI = (
    "the ground's soft-decision Viterbi decoder over a four-frame stream (64 path metrics, the "
    "traceback window) beyond a 103 KiB heap: the board only encodes"
)
CORTEX_M_SKIPS = {
    "test_frames_sync.py::TestChains::test_every_coding_round_trips": VITERBI,
    "test_frames_sync.py::TestChains::test_concatenated_inverted_and_noisy": VITERBI,
    "test_frames_downlink.py::DownlinkTest::test_coded_frames_take_the_coded_length": VITERBI,
    "test_cfdp_durability.py::TestReceiverCuts::test_cuts_through_a_transfer": CUTS20K,
    "test_pus_random_requests.py": TWO_ENDS,
    "test_pus_mission_services.py::TestProvider::"
    "test_random_application_data_gets_a_verdict_never_an_exception": TWO_ENDS,
    "test_pus_s06_files.py": MEMORY,
    "test_pus_s12_functional.py": TWO_ENDS,
    "test_pus_s15_copy.py::TestCopyByTimeWindow::test_from_to_after_before": HEAP,
    "test_pus_s15_copy.py::TestCopyByTimeWindow::test_refusals": HEAP,
    "test_pus_s15_storage.py::TestRetrieval::test_by_time_range_on_the_playback_channel": HEAP,
    "test_pus_s15_storage.py::TestRetrieval::test_by_sequence_and_abort": HEAP,
    "test_pus_app.py::TestRouting::test_a_tm_too_long_leaves_no_gap_in_the_counts": BIG,
    "test_pus_s21_by_reference.py": MEMORY,
    "test_pus_s06_objects.py::TestWriteProtection::test_every_load_honours_it": MEMORY,
    "test_pus_s15_storage.py::TestStores::test_housekeeping_and_event_control": HEAP,
    "test_pus_s15_storage.py::TestPersistence::test_stores_survive_a_restart": HEAP,
    "test_reconfig_recovery.py::TestInTheApplication::test_context_kept_and_given_back": EEPROM,
    "test_reconfig_recovery.py::TestInTheApplication::test_heartbeats_keep_the_obc_on": EEPROM,
    "test_reconfig_recovery.py::TestInTheApplication::"
    "test_silence_power_cycles_then_switches_over": EEPROM,
    "test_reconfig_recovery.py::TestInTheApplication::test_time_from_the_ds3231": EEPROM,
    "test_cfdp_class2.py::TestClass2::test_retransmissions_close_to_losses": FILE19K,
    "test_cfdp_filestore.py": FILES,
    "test_pluto_engine.py::TestLoading::test_load_file_and_bytes": FILES,
    "test_pluto_checker.py::TestRejections::test_long_operator_chain_is_a_syntax_error_with_line": TOKENS,  # noqa: E501
    "test_pluto_grammar.py::TestWrittenFromTheGrammar::test_every_production_loads_and_runs": FILES,  # noqa: E501
    "test_cfdp_passes.py": PASSES,
    "test_pluto_interp.py::TestParallelAndControl::test_thesis_cpdu_example": FILES,
    "test_pus_s03_housekeeping.py::TestUnsent::test_a_packet_too_long_is_heard_and_leaves_no_gap": BIG,  # noqa: E501
    "test_pus_s15_storage.py::TestPersistence::test_log_is_compacted_atomically": HEAP,
    "test_pus_s15_storage.py::TestRetrieval::test_open_retrieval_follows_the_store": HEAP,
    "test_pus_s15_storage.py::TestStores::test_circular_and_bounded": HEAP,
    "test_pus_s15_storage.py::TestStores::test_create_configure_report_delete": HEAP,
    "test_pus_s15_storage.py::TestStores::test_storage_control_selects_packets": HEAP,
    "test_pus_s18_obcp.py": HEAP,
    "test_pus_s23_files.py": TWO_ENDS,
    "test_pus_wiring.py::WiringTest::test_registration_order_carries_no_meaning": TWO_ENDS,
    "test_reconfig_app.py": EEPROM,
    "test_reconfig_cpdu.py": EEPROM,
    "test_reconfig_safeguard.py": EEPROM,
    "test_reconfig_time.py::TestWatchdog::test_early_kick_is_a_reset_in_the_model": EEPROM,
    "test_reconfig_time.py::TestWatchdog::test_unhealthy_is_reset_by_timeout": EEPROM,
    "test_reconfig_time.py::TestWatchdog::test_window_respected_with_jittery_loop": EEPROM,
    "test_spp.py::TestSpacePacket::test_largest_packet": BIG,
    "test_pus_s22_position_scheduling.py::TestPositionScheduling::"
    "test_restart_keeps_the_schedule": RESTART,
    "test_update_boundaries.py::TestManifestLength::test_a_manifest_of_one_mib_at_most": MIB,
}
# the board's test runner collects after every 8 KiB allocated (gc.threshold), as a small-heap
# application does: collecting only when the heap is exhausted scatters the live objects of a
# scenario over the whole heap and a 1-4 KB block then finds no room with half the heap free
GC_THRESHOLD = 8192
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
    # one interpreter per test file, as a board boots afresh for each
    totals = [0, 0, 0]
    for path in CORE_TESTS:
        cmd = [str(exe), "-X", "heapsize=64M", str(ROOT / "tools" / "upy" / "run.py")]
        r = subprocess.run(
            cmd + [str(path.relative_to(ROOT))], env=env, cwd=ROOT, capture_output=True, text=True
        )
        out = r.stdout + r.stderr
        got = _counts(out) or (0, 1, 0)
        if got[1] or r.returncode:
            print("\n".join(out.splitlines()[-30:]))
        for i in range(3):
            totals[i] += got[i]
    c = totals
    return _close("upy-frozen", t0, c[0] + entry_ok, c[1] + (not entry_ok), c[2])


def _stage_dir(name):
    d = firmware.BUILD / name
    if d.exists():
        shutil.rmtree(d)
    d.mkdir(parents=True)
    return d


BATCH = 12  # test files per mpremote session (each after a soft reset): a session costs ~1 s
MARK = "== obsw test file "


def _board_code(name):
    skips = {k: v for k, v in CORTEX_M_SKIPS.items() if k.split("::")[0] == name}
    return (
        "import time; print(%r); t = time.ticks_ms(); import obsw_run_tests as r; "
        "r.main([%r], %r, %d); print('board time', time.ticks_diff(time.ticks_ms(), t))"
        % (MARK + name, name, skips, GC_THRESHOLD)
    )


def _run_batch(q, paths, from_source):
    """One mpremote session: per file a soft reset (a fresh heap), the file copied when it is
    not frozen, and the board's runner. Returns {name: output}."""
    args = []
    for path in paths:
        args += ["soft-reset", "+"]
        if path.name in from_source:
            args += ["cp", str(path), ":" + path.name, "+"]
        args += ["exec", _board_code(path.name), "+"]
    rc, out = firmware.mpremote(q.pty, *args[:-1], timeout=60 + 90 * len(paths))
    found = {}
    name = None
    for line in out.splitlines():
        if line.startswith(MARK):
            name = line[len(MARK) :].strip()
            found[name] = []
        elif name is not None:
            found[name].append(line)
    return rc, {k: "\n".join(v) for k, v in found.items()}, out


def stage_cortex_m():
    t0 = time.monotonic()
    try:
        elf = firmware.build_qemu()
    except firmware.FirmwareError as e:
        print(e)
        return _close("cortex-m", t0, 0, 1)
    from_source = firmware.stage_board_tests()  # tests that cannot be frozen: copied, compiled
    passed = failed = skipped = 0
    reasons = {}  # skip reason -> tests skipped for it
    q = firmware.Qemu(elf)
    try:
        for i in range(0, len(CORE_TESTS), BATCH):
            batch = CORE_TESTS[i : i + BATCH]
            rc, outs, raw = _run_batch(q, batch, from_source)
            for path in batch:
                name = path.name
                out = outs.get(name, "")
                c = _counts(out)
                if c is None or not out.rstrip().splitlines()[-1].startswith("board time"):
                    # no result (a crash, a hang): alone on a fresh board, once
                    q.close()
                    q = firmware.Qemu(elf)
                    rc, again, raw = _run_batch(q, [path], from_source)
                    out = again.get(name, "")
                    c = _counts(out)
                    if c is None:
                        failed += 1
                        print("FAIL %s (no result, status %d):\n%s" % (name, rc, raw[-1500:]))
                        q.close()
                        q = firmware.Qemu(elf)
                        continue
                passed, failed, skipped = passed + c[0], failed + c[1], skipped + c[2]
                ms = 0
                for line in out.splitlines():
                    if line.startswith("board time"):
                        ms = int(line.split()[-1])
                    elif line.startswith("skip "):
                        reason = line.split(": ", 1)[-1]
                        reasons[reason] = reasons.get(reason, 0) + 1
                    elif line.startswith(("FAIL", "Traceback", "MemoryError")) or "Error" in line:
                        print("  " + line)
                print("%-40s %3d passed %3d failed %3d skipped %5.1f s" % (name, *c, ms / 1000))
        print("skipped on the board (a file counts once):")
        for reason, n in sorted(reasons.items(), key=lambda kv: -kv[1]):
            print("  %3d  %s" % (n, reason))
        q.close()  # the board tools start on a board as flashed: only the frozen modules
        q = firmware.Qemu(elf)
        p, f = board_tools(q.pty)
        passed, failed = passed + p, failed + f
        p, f = board_update(q.pty)
        passed, failed = passed + p, failed + f
    finally:
        q.close()
    return _close("cortex-m", t0, passed, failed, skipped)


def board_tools(pty):
    """`obsw board test` against the QEMU board's pty as flashed (the frozen modules), then
    `obsw board deploy` and `obsw board test` again, as against a Pyboard: the deployed modules
    shadow the frozen ones; the results are read back."""
    obsw = shutil.which("obsw") or str(ROOT / ".venv" / "bin" / "obsw")

    def board_test(what):
        t1 = time.monotonic()
        r = subprocess.run([obsw, "board", "test", "--port", pty], capture_output=True, text=True)
        c = _counts(r.stdout) or (0, 1, 0)
        print("obsw board test --port %s (%s): %d passed, %d failed (%.1f s)"
              % (pty, what, c[0], c[1], time.monotonic() - t1))  # fmt: skip
        if r.returncode or c[1]:
            print(r.stdout[-2000:] + r.stderr[-1000:])
        return c

    frozen = board_test("frozen modules, as flashed")
    r = subprocess.run([obsw, "board", "deploy", "--port", pty], capture_output=True, text=True)
    deployed = r.returncode == 0 and "modules deployed" in r.stdout
    print("obsw board deploy --port %s: %s" % (pty, r.stdout.strip().splitlines()[-1:]))
    if not deployed:
        print(r.stdout[-1500:] + r.stderr[-1500:])
    c = board_test("deployed modules")
    return frozen[0] + c[0] + deployed, frozen[1] + c[1] + (not deployed)


# on the board: the boot selector, with an application start that says which application
# module it got and does not run it (the QEMU board has no reconfiguration hardware)
_BOOT = (
    "from obsw.reconfig import appslot\n"
    "def start():\n"
    "    import obsw.reconfig.app as a\n"
    "    print('app', getattr(a, 'UPDATE', 'frozen'))\n"
    "appslot.boot('', start)\n"
    "print('record', appslot.running(''))\n"
)
# what `obsw board deploy` put on the board's filesystem: an updated board runs frozen modules
_UNDEPLOY = (
    "import os\n"
    "from obsw.reconfig import appslot\n"
    "for n in os.listdir():\n"
    "    if n == 'obsw' or n.endswith('.mpy') or n in ('app', 'app.json'):\n"
    "        appslot.remove_tree(n)\n"
)


def board_update(pty):
    """The reconfiguration module's application update on the QEMU board, as on a Pyboard:
    `obsw update build --target reconfig` and `obsw board update` stage a signed package of
    the changed application module, which the boot selector loads on trial and keeps once
    confirmed; a package with one changed byte and one signed with another key are refused
    and change nothing; a module that raises at import gives way to the frozen one; one that
    never confirms (hung, reset by the watchdog) is left after its starts.
    Returns (passed, failed)."""
    import json
    import tempfile

    obsw = shutil.which("obsw") or str(ROOT / ".venv" / "bin" / "obsw")
    sys.path[:0] = [str(ROOT / "host"), str(ROOT / "micropython")]
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey
    from obsw_host import board
    from obsw_host.mission.ids import MissionIds
    from obsw_host.reconfig import board_file
    from obsw_host.update import build as b

    checks = []

    def check(what, ok, detail=""):
        checks.append(ok)
        print("%s %s%s" % ("ok  " if ok else "FAIL", what, "" if ok else ": " + detail[-800:]))

    def on_board(code):  # a fresh start of the board, then code
        return firmware.mpremote(pty, "soft-reset", "+", "exec", code, timeout=120)[1]

    t0 = time.monotonic()
    march = board.board_arch(pty) or "armv7m"
    with tempfile.TemporaryDirectory(prefix="obsw-board-update-") as tmp:
        mission = os.path.join(tmp, "sat")
        shutil.copytree(ROOT / "examples" / "sample", mission)
        key_file = os.path.join(tmp, "update.key")
        b.keygen(key_file, allow_git=True)
        shutil.copy(key_file + ".pub", os.path.join(mission, "update.pub"))
        path = os.path.join(mission, "mission.json")
        with open(path) as f:
            doc = json.load(f)
        doc["update"] = {"public_key": "update.pub"}
        with open(path, "w") as f:
            json.dump(doc, f)
        ids = MissionIds.locate(mission)
        on_board(_UNDEPLOY)
        firmware.mpremote(pty, "cp", board_file(ids, tmp), ":mission.json", "+",
                          "cp", key_file + ".pub", ":update.pub")  # fmt: skip
        key = b.load_private(key_file)
        app_source = (ROOT / "micropython" / "obsw" / "reconfig" / "app.py").read_text()

        def package(version, text=None, signer=key):
            """The application module of ``version``: the image's with a mark, or ``text``."""
            src = os.path.join(tmp, "app-%s.py" % version)
            with open(src, "w") as f:
                f.write(text or app_source + "\nUPDATE = %r\n" % version)
            files = board._compile(os.path.join(tmp, version), march, src,
                                   "obsw/reconfig/app.py", subprocess.call)  # fmt: skip
            out = os.path.join(tmp, "v%s.obsw" % version)
            b.build(out, files, mission=ids.config.name, version=version, key=signer,
                    target="reconfig")  # fmt: skip
            return out

        def update(path):
            r = subprocess.run([obsw, "board", "update", path, "--port", pty],
                               capture_output=True, text=True, timeout=900)  # fmt: skip
            return r.returncode, (r.stdout + r.stderr).strip()

        good = package("1.1")
        t = time.monotonic()
        rc, said = update(good)
        check("obsw board update stages 1.1 (%d bytes, %.1f s)" % (
            os.path.getsize(good), time.monotonic() - t),
            rc == 0 and said.endswith("staged 1.1"), said)  # fmt: skip
        out = on_board(_BOOT)
        check("the boot selector loads 1.1's module, on trial",
              "app 1.1" in out and "record ('1.1', 'trial')" in out, out)  # fmt: skip
        out = on_board("from obsw.reconfig import appslot; print(appslot.confirm(''))")
        check("confirmed once healthy", out.strip().endswith("True"), out)
        spoilt = os.path.join(tmp, "spoilt.obsw")
        data = bytearray(open(package("1.2"), "rb").read())
        data[-5] ^= 1
        with open(spoilt, "wb") as f:
            f.write(data)
        forged = package("1.3", signer=Ed25519PrivateKey.generate())
        for name, path, code in (("one changed byte", spoilt, "hash_mismatch"),
                                 ("another key", forged, "bad_signature")):  # fmt: skip
            rc, said = update(path)
            out = on_board(_BOOT)
            check("%s: refused (%s), 1.1 keeps running" % (name, code),
                  rc == 1 and ("refused %s" % code) in said and "app 1.1" in out
                  and "record ('1.1', 'good')" in out, said + out)  # fmt: skip
        rc, said = update(package("1.4", text="raise RuntimeError('1.4 is broken')\n"))
        out = on_board(_BOOT)
        check("a module that raises at import: the frozen application runs",
              said.endswith("staged 1.4") and "the frozen one starts" in out
              and "app frozen" in out and "'failed'" in out, said + out)  # fmt: skip
        rc, said = update(package("1.5"))
        outs = [on_board(_BOOT) for _ in range(3)]  # never confirmed: the watchdog resets it
        check("an application that never confirms is left after 2 starts",
              "app 1.5" in outs[0] and "app 1.5" in outs[1] and "app frozen" in outs[2]
              and "did not confirm in 2 starts" in on_board(
                  "from obsw.reconfig import appslot; print(appslot.read(''))"),
              "\n".join(outs))  # fmt: skip
        on_board(_UNDEPLOY)
    passed = sum(checks)
    print("board update: %d passed, %d failed (%.1f s)" % (
        passed, len(checks) - passed, time.monotonic() - t0))  # fmt: skip
    return passed, len(checks) - passed


def _figures(out, prefix):
    return [line for line in out.splitlines() if line.startswith(prefix)]


HEAP_FIGURES = re.compile(r"heap low-water free (\d+)")


def reconfig_heap(pty, passes=HEAP_PASSES):
    """The reconfiguration application's session on the board at ``pty`` (the Pyboard's heap):
    (ok, low-water free heap in bytes or None, the board's output)."""
    code = (
        "import obsw_heap; ok, low, total = obsw_heap.reconfig(%d); "
        "print('reconfig', 'ok' if ok and low >= %r * total else 'FAILED')" % (passes, MIN_FREE)
    )
    rc, out = firmware.mpremote(pty, "exec", code, timeout=300)
    m = HEAP_FIGURES.search(out)
    return rc == 0 and "reconfig ok" in out, int(m.group(1)) if m else None, out


def free_heap(passes=HEAP_PASSES):
    """What the reconfiguration application leaves free on a Pyboard's heap (the low-water
    mark of the heap stage's session): measured on a freshly booted board (FirmwareError when
    the session fails)."""
    with firmware.Qemu(firmware.build_qemu()) as q:
        ok, low, out = reconfig_heap(q.pty, passes)
    if not ok or low is None:
        raise firmware.FirmwareError("the heap stage's session failed:\n" + out[-2000:])
    return low


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
        t1 = time.monotonic()
        ok, _, out = reconfig_heap(q.pty)
        print("\n".join(_figures(out, ("heap", "passes", "reconfig", "Traceback", "MemoryError"))))
        print("reconfiguration session %.1f s" % (time.monotonic() - t1))
        if ok:
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


def stage_board():
    t0 = time.monotonic()
    with firmware.Qemu(firmware.build_qemu()) as q:
        passed, failed = board_tools(q.pty)
        p, f = board_update(q.pty)
    return _close("board", t0, passed + p, failed + f)


def main(argv):
    stages = {
        "board": stage_board,
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
