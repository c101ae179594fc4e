"""Every shell example of the documentation's PUS, OBCP and OBC pages, run as written against one
`obsw obc serve` with the sample spacecraft (on 127.0.0.1, on ports of this run's own). An
example ending in a comment `# exit N` must exit with N, one saying `exit 1 if none came` (a
listener) with 0 or 1, every other one with 0. Bounded: each command has
a timeout, the whole run prints its time."""

import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time

import mission_ports
import pytest
from obsw_host.sample import MISSION_DIR

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PAGES = ("docs/pus.md", "docs/obcp.md", "docs/obc.md")  # the pages whose examples need the OBC
SERVER = "obsw obc serve"  # the OBC itself: started once, here (no other server is started)
COMMAND_TIMEOUT = 30.0


def examples(text):
    """(command, expected exit status) of every `obsw ...` example in ``text``, in order:
    lines of ```sh blocks and inline `obsw ground ...` / `obsw obcp ...` spans."""
    found = []
    for block in re.findall(r"```sh\n(.*?)```", text, re.S):
        for line in block.splitlines():
            if line.startswith("obsw "):
                found.append(line)
    prose = re.sub(r"```.*?```", "", text, flags=re.S)
    found += re.findall(r"`(obsw (?:ground|obcp|obc) [^`]+)`", prose)
    out = []
    for line in found:
        if line.split()[1] not in ("ground", "obcp", "obc"):
            continue  # other tools' examples (pluto, spacecan, ...) have their own tests
        command, _, comment = line.partition("#")
        m = re.search(r"exit (\d+)", comment)
        expected = (int(m.group(1)),) if m else (0,)
        if "exit 1 if none came" in comment:
            expected = (0, 1)
        out.append((command.strip().rstrip("&").strip(), expected))
    return out


def obsw():
    exe = shutil.which("obsw", path=os.path.dirname(sys.executable))
    return [exe] if exe else [sys.executable, "-m", "obsw_host.cli"]


# the reader's session names its mission once, as the docs say (`export OBSW_MISSION=...`);
# its ports are this run's own (an OBC may already serve the sample on the default ports)
ENV = dict(os.environ, OBSW_MISSION=MISSION_DIR)


def run(argv, cwd, timeout=COMMAND_TIMEOUT):
    return subprocess.run(argv, cwd=cwd, capture_output=True, text=True, timeout=timeout, env=ENV)


def test_every_obc_example_of_the_docs(tmp_path, capsys):
    cases = []
    for page in PAGES:
        with open(os.path.join(ROOT, page)) as f:
            cases += examples(f.read())
    assert any(c.startswith(SERVER) for c, _ in cases), "no `obsw obc serve` example"
    commands = [(c, e) for c, e in cases if " serve" not in c]
    assert len(commands) >= 20
    from obcp_engine_demo import DEMO_PROCEDURE

    for name in ("turn.plt",):
        (tmp_path / name).write_text(DEMO_PROCEDURE)
    os.symlink(MISSION_DIR, tmp_path / "sample")  # the pages run from examples/: `sample` there
    state = tmp_path / "state"
    t0 = time.monotonic()
    ENV["OBSW_PORT_BASE"] = str(mission_ports.free_base())
    server = subprocess.Popen(
        obsw() + ["obc", "serve", "--state", str(state)],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        start_new_session=True,
        env=ENV,
    )
    try:
        end = time.monotonic() + 60.0
        while time.monotonic() < end:  # up once a ping completes
            if run(obsw() + ["ground", "--timeout", "0.5", "ping"], tmp_path).returncode == 0:
                break
            assert server.poll() is None, server.stdout.read().decode()
        else:
            pytest.fail("obsw obc serve did not answer a ping within 60 s")
        failures = []
        for command, expected in commands:
            r = run(obsw() + shlex.split(command)[1:], tmp_path)
            if r.returncode not in expected:
                failures.append(
                    "%s -> exit %d (expected %s)\n%s%s"
                    % (command, r.returncode, expected, r.stdout[-800:], r.stderr[-800:])
                )
        assert not failures, "\n\n".join(failures)
    finally:
        os.killpg(server.pid, signal.SIGTERM)
        try:
            server.wait(15.0)
        except subprocess.TimeoutExpired:
            os.killpg(server.pid, signal.SIGKILL)
            server.wait(5.0)
    with capsys.disabled():
        print(
            "\n  docs OBC examples: %d commands against obsw obc serve in %.1f s"
            % (len(commands), time.monotonic() - t0)
        )
