"""Ordinary mistakes on the `obsw` command line: each prints one line naming what was wrong
and what was expected, and exits with status 2 (never a traceback; --debug shows one)."""

import os
import socket
import subprocess
import sys

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
ENV = dict(
    os.environ,
    PYTHONPATH=os.pathsep.join([os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]),
)

# (name, arguments, a piece of the one line); {d} is a scratch folder, {port} a busy UDP port
MISTAKES = [
    ("missing sdb", "ground --sdb {d}/missing.json ping", "missing.json: no such file"),
    ("directory for sdb", "ground --sdb {d} ping", "is a directory; expected a file"),
    ("bad JSON sdb", "ground --sdb {d}/bad.json ping", "not valid JSON"),
    ("unknown host", "ground --host no-such-host.invalid ping", "unknown host"),
    ("unknown action", "ground pingg", "invalid choice: 'pingg'"),
    ("unknown parameter", "ground params set Foo=1", "no parameter 'Foo'"),
    ("assignment", "ground params set SolarPanel.speed", "expected NAME=VALUE"),
    ("unknown function", "ground function No.fn", "no function 'No.fn'"),
    ("unknown event", "ground events enable NoSuchEvent", "no event 'NoSuchEvent'"),
    ("bad UTC time", "ground schedule insert --at soon ping", "not a UTC time"),
    ("bad activity id", "ground schedule delete 1:2", "expected SOURCE:APID:SEQ"),
    ("bad request", "ground action add monitoring.speed_high jump", "expected ping | function"),
    ("missing session log", "ground replay {d}/none.log", "none.log: no such file"),
    ("bad session log", "ground replay {d}/bad.json", "expected a session log record"),
    ("missing mission", "obc serve {d}/none.json", "none.json"),
    ("port in use, cfdp", "cfdp serve --port {port} --root {d}/fs", "address already in use"),
    ("bad --peer", "cfdp put a.bin --peer 2=localhost --root {d}/fs", "expected ID=HOST:PORT"),
    ("bad peer id", "cfdp put a.bin --peer x=1.2.3.4:5 --root {d}/fs", "expected ID=HOST:PORT"),
    ("no file to put", "cfdp put none.bin --root {d}/fs --peer 2=127.0.0.1:9", "none.bin"),
    ("bad transaction", "cfdp status 1:x --root {d}/fs --peer 2=127.0.0.1:9", "SOURCE:SEQ"),
    ("bad hex", "frames cltu decode zz", "not hexadecimal"),
    ("odd hex", "frames tm decode 123", "even number of hex digits"),
    ("packet hex", "packet decode 18zz", "hex"),
    ("serial device", "frames processor --uart-a {d}/ttyNONE --uart-b {d}/ttyNONE2", "ttyNONE"),
    ("CAN interface", "spacecan ping --interface nosuch --node-id 5", "nosuch"),
    ("node definition", "spacecan monitor --interface virtual --node-def {d}/n.json", "n.json"),
    ("missing procedure", "pluto check {d}/none.pluto", "none.pluto: no such file"),
    ("directory procedure", "pluto check {d}", "is a directory"),
    ("bad system JSON", "pluto run {d}/p.pluto --system {d}/bad.json", "bad JSON at line 1"),
    ("missing OBCP file", "obcp load turn {d}/none.plt", "none.plt: no such file"),
    ("unknown option", "ground ping --frobnicate", "unrecognized arguments: --frobnicate"),
]


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """Every mistake run at once (each its own `obsw` process), then their outputs."""
    d = tmp_path_factory.mktemp("mistakes")
    (d / "bad.json").write_text("{bad")
    (d / "p.pluto").write_text("procedure log 1; end procedure\n")
    busy = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    busy.bind(("127.0.0.1", 0))
    port = busy.getsockname()[1]
    procs = {}
    try:
        for name, args, _ in MISTAKES:
            words = args.format(d=d, port=port).split()
            procs[name] = subprocess.Popen(
                [sys.executable, "-m", "obsw_host.cli"] + words,
                env=ENV,
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                text=True,
            )
        out = {}
        for name, proc in procs.items():
            stdout, stderr = proc.communicate(timeout=120)
            out[name] = (proc.returncode, stdout, stderr)
        return out
    finally:
        for proc in procs.values():
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        busy.close()


@pytest.mark.parametrize("name, args, expected", MISTAKES, ids=[m[0] for m in MISTAKES])
def test_one_line_and_status_2(results, name, args, expected):
    status, stdout, stderr = results[name]
    lines = stderr.strip().splitlines()
    assert status == 2, (stdout, stderr)
    assert len(lines) == 1 and "Traceback" not in stderr, stderr
    assert lines[0].startswith("obsw") and expected in lines[0], lines[0]
    assert "serving" not in stdout + stderr


def test_debug_shows_the_traceback(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "obsw_host.cli", "ground", "--sdb", str(tmp_path / "x.json")]
        + ["ping", "--debug"],
        env=ENV,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode != 0
    assert "Traceback" in result.stderr and "FileNotFoundError" in result.stderr
