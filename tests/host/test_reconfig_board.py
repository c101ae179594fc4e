"""`obsw board build|deploy|flash|repl|test` with fake make, mpremote, mpy-cross and dfu-util
that record their arguments (no board is touched)."""

import os
import stat
import subprocess
import sys
import tempfile

import pytest
from obsw_host import board
from obsw_host.commands import board as cmd

FAKE = """#!/bin/sh
echo "$(basename "$0") $*" >> "{log}"
echo "2 passed, 0 failed"
exit 0
"""


@pytest.fixture
def fakes(tmp_path, monkeypatch):
    log = tmp_path / "calls.log"
    bindir = tmp_path / "bin"
    bindir.mkdir()
    for name in ("make", "mpremote", "dfu-util", "arm-none-eabi-gcc"):
        p = bindir / name
        p.write_text(FAKE.format(log=log))
        p.chmod(p.stat().st_mode | stat.S_IEXEC)
    monkeypatch.setenv("PATH", str(bindir) + os.pathsep + os.environ["PATH"])
    for var in ("MAKE", "MPREMOTE", "DFU_UTIL", "ARM_GCC"):
        monkeypatch.delenv(var, raising=False)

    def calls():
        return log.read_text().splitlines() if log.exists() else []

    return tmp_path, calls


def run(argv):
    import argparse

    p = argparse.ArgumentParser()
    sub = p.add_subparsers()
    cmd.add_parser(sub)
    args = p.parse_args(argv)
    return args.func(args)


def test_build_says_where_to_get_the_pinned_source(fakes, capsys, monkeypatch):
    tmp, calls = fakes
    monkeypatch.setenv("OBSW_MICROPYTHON_SRC", str(tmp / "nothing"))
    assert run(["board", "build", "--image", "unix"]) == 2
    assert "no MicroPython 1.28.0 source" in capsys.readouterr().out
    assert run(["board", "build", "--micropython", str(tmp / "nothing")]) == 2
    assert calls() == []
    fw = board.firmware_tools()
    monkeypatch.delenv("OBSW_MICROPYTHON_SRC")
    monkeypatch.setattr(fw, "_candidates", lambda explicit: iter([tmp / "none"]))
    with pytest.raises(fw.FirmwareError) as e:
        fw.source()
    assert "git clone --branch v1.28.0" in str(e.value)


def test_the_pyboard_image_freezes_the_reconfiguration_manifest():
    with open(os.path.join(board.board_dir(), "mpconfigboard.mk")) as f:
        assert "manifests/reconfig.py" in f.read()


def test_deploy_compiles_for_the_pyboard_and_copies(fakes, tmp_path, monkeypatch):
    tmp, calls = fakes
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    assert run(["board", "deploy", "--port", "/dev/ttyACM0", "--march", "armv7emsp"]) == 0
    assert os.listdir(scratch) == []  # the compiled files' folder is gone again
    c = [line for line in calls() if not line.endswith(" exec pass")]  # the board answers
    assert len(c) == 1 and c[0].startswith("mpremote connect /dev/ttyACM0")
    assert " cp -r " in c[0] and c[0].endswith("soft-reset")
    assert ":main.py" in c[0] and ":boot.py" in c[0]
    names = [n for _, n in board.frozen_modules()]
    assert "obsw/reconfig/app.py" in names and "hal_pyb.py" in names
    assert not [n for n in names if n.startswith(("obsw/cfdp", "obsw/pluto", "obsw/il"))]


def test_deploy_installs_the_keys_or_says_it_did_not(fakes, tmp_path, capsys):
    from obsw_host.frames import keys

    tmp, calls = fakes
    argv = ["board", "deploy", "--port", "/dev/ttyACM0", "--march", "armv7emsp"]
    assert run(argv) == 0
    assert "SDLS keys NOT installed" in capsys.readouterr().out
    assert ":tc.keys" not in calls()[-1]
    key_file = str(tmp_path / "board.keys")
    keys.generate(key_file, algorithm="aes-gcm")
    assert run(argv + ["--keys", key_file]) == 0
    assert "installed on the board as tc.keys" in capsys.readouterr().out
    assert "cp %s :tc.keys" % key_file in calls()[-1]
    assert run(argv + ["--insecure"]) == 0
    assert "SDLS OFF" in capsys.readouterr().out and "tc.insecure" in calls()[-1]
    n = len(calls())
    os.chmod(key_file, 0o644)  # others could read it: refused before anything is copied
    assert run(argv + ["--keys", key_file]) == 2
    assert "chmod 600" in capsys.readouterr().out and len(calls()) == n


BOARD_SAYS = """#!/bin/sh
echo "$(basename "$0") $*" >> "{log}"
case "$*" in *_mpy*) echo {mpy} ;; esac
exit 0
"""


@pytest.mark.parametrize(
    "mpy, march", [(6 | 5 << 10, "armv7m"), (6 | 7 << 10, "armv7emsp"), (6, "armv7emsp")]
)
def test_deploy_compiles_for_the_boards_own_architecture(fakes, mpy, march):
    tmp, calls = fakes
    log = tmp / "calls.log"
    for name in ("mpremote", "mpy-cross"):
        p = tmp / "bin" / name
        p.write_text(BOARD_SAYS.format(log=log, mpy=mpy))
        p.chmod(p.stat().st_mode | stat.S_IEXEC)
    os.environ["MPY_CROSS"] = str(tmp / "bin" / "mpy-cross")
    try:
        assert run(["board", "deploy", "--port", "/dev/pts/7"]) == 0
    finally:
        del os.environ["MPY_CROSS"]
    c = [line for line in calls() if not line.endswith(" exec pass")]  # the board answers
    assert c[0].startswith("mpremote connect /dev/pts/7 exec") and "_mpy" in c[0]
    compiled = [line for line in c if line.startswith("mpy-cross")]
    assert compiled and all(line.split()[1] == "-march=" + march for line in compiled)


def test_arch_codes():
    assert board.arch_of(6 | 2 << 10) == "x64"
    assert board.arch_of(6 | 4 << 10) == "armv6m"
    assert board.arch_of(6) is None and board.arch_of(6 | 63 << 10) is None


def test_flash_repl_and_test(fakes, tmp_path):
    tmp, calls = fakes
    fw = tmp / "firmware.dfu"
    fw.write_bytes(b"DfuSe")
    assert run(["board", "flash", str(fw)]) == 0
    assert run(["board", "repl"]) == 0
    assert run(["board", "test", "--port", "u0"]) == 0
    c = [line for line in calls() if not line.endswith(" exec pass")]  # the board answers
    assert c[0] == "mpremote bootloader"
    assert c[1] == "dfu-util -a 0 -d 0483:df11 -D %s -s :leave" % fw  # starts the firmware
    assert c[2].startswith("mpremote cp") and c[2].endswith(":main.py")
    assert c[3] == "mpremote repl"
    tests = c[4:]
    assert len(tests) == len(board.BOARD_TESTS)
    assert all(t.startswith("mpremote connect u0 cp") and " exec " in t for t in tests)
    assert run(["board", "flash", str(tmp / "missing.dfu")]) == 2


def test_flash_without_dfu_util_leaves_the_board_running(tmp_path):
    """Through the real command: no dfu-util on the PATH is one line and exit 2, before
    mpremote is asked to put the board into DFU mode."""
    log = tmp_path / "calls.log"
    bindir = tmp_path / "bin"
    bindir.mkdir()
    fake = bindir / "mpremote"
    fake.write_text('#!/bin/sh\necho "mpremote $*" >> "%s"\n' % log)
    fake.chmod(fake.stat().st_mode | stat.S_IEXEC)
    fw = tmp_path / "firmware.dfu"
    fw.write_bytes(b"DfuSe")
    env = {k: v for k, v in os.environ.items() if k not in ("MPREMOTE", "DFU_UTIL")}
    env["PATH"] = str(bindir)  # nothing else: no dfu-util wherever the machine keeps one
    obsw = os.path.join(os.path.dirname(sys.executable), "obsw")
    r = subprocess.run(
        [obsw, "board", "flash", str(fw)], env=env, capture_output=True, text=True, timeout=60
    )
    assert r.returncode == 2, r.stdout + r.stderr
    assert r.stdout.strip().splitlines() == [
        "obsw board: dfu-util not found: apt install dfu-util (the board was left running)"
    ]
    assert not log.exists()  # mpremote never ran: the board did not enter DFU mode


def test_a_long_build_says_how_far_it_is(tmp_path, capsys, monkeypatch):
    """make's output goes to a log; while it runs, a line every PROGRESS_EVERY seconds says how
    many steps are done against the last clean build's count (or the pinned source's)."""
    fw = board.firmware_tools()
    monkeypatch.setattr(fw, "PROGRESS_EVERY", 0.2)
    out = tmp_path / "build"
    out.mkdir()
    log = tmp_path / "build.log"
    steps = "for i in 1 2 3 4 5 6 7 8; do echo CC file$i.c; sleep 0.1; done"
    with open(log, "w") as f:
        assert fw._run_with_progress(["sh", "-c", steps], f, log, out, "firmware.elf") == 0
    lines = [s for s in capsys.readouterr().out.splitlines() if "building" in s]
    assert lines, "no progress line"
    assert "of about %d steps" % fw._STEPS["firmware.elf"] in lines[0]
    fw._record_steps(out / ".obsw-steps", 8)
    fw._record_steps(out / ".obsw-steps", 3)  # an incremental build does not lower it
    assert (out / ".obsw-steps").read_text() == "8"
    with open(log, "w") as f:
        fw._run_with_progress(["sh", "-c", steps], f, log, out, "firmware.elf")
    lines = [s for s in capsys.readouterr().out.splitlines() if "building" in s]
    assert "of about 8 steps" in lines[-1], lines


def test_deploy_installs_the_missions_ids_or_says_it_did_not(fakes, tmp_path, capsys, monkeypatch):
    tmp, calls = fakes
    argv = ["board", "deploy", "--port", "/dev/ttyACM0", "--march", "armv7emsp"]
    assert run(argv) == 0  # the sample, named by $OBSW_MISSION
    assert "mission.json of sample-spacecraft installed" in capsys.readouterr().out
    assert ":mission.json" in calls()[-1]
    monkeypatch.delenv("OBSW_MISSION")
    monkeypatch.chdir(tmp_path)  # no mission.json here or above
    assert run(argv) == 0
    assert "mission.json NOT installed" in capsys.readouterr().out
    assert ":mission.json" not in calls()[-1]


NO_BOARD = """#!/bin/sh
echo "$(basename "$0") $*" >> "{log}"
echo "mpremote: failed to access $2 (it may be in use by another program)" >&2
exit 1
"""


@pytest.mark.parametrize("action", ["deploy", "repl", "test"])
@pytest.mark.parametrize("port", [None, "/dev/obsw-no-such-board", "busy"])
def test_no_board_is_one_line_before_any_work(fakes, capsys, action, port):
    tmp, calls = fakes
    p = tmp / "bin" / "mpremote"
    p.write_text(NO_BOARD.format(log=tmp / "calls.log"))
    argv = ["board", action] + (["--port", port] if port else [])
    assert run(argv) == 2
    out = capsys.readouterr().out.strip().splitlines()
    assert len(out) == 1, out
    expected = {None: "no board found on USB", "busy": "the board on busy does not answer"}
    assert out[0].startswith("obsw board: " + expected.get(port, "no board on " + str(port)))
    assert len(calls()) == 1  # one question to the board, nothing compiled or copied
