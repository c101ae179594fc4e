"""The operator's live view and console through the real `obsw` command against a running
`obsw obc serve`: `ground watch` frames (values with units and limit state, events, commands and
their verification), `ground console` driven through a pseudo-terminal and through a pipe, its
completion from the database and its history file in the mission's state folder."""

import fcntl
import json
import os
import pty
import re
import select
import struct
import subprocess
import termios
import time

import pytest
from obsw_host.cli import build_parser
from obsw_host.commands.ground_tui import GroundCompleter, _subcommands
from obsw_host.sample import load_sdb
from prompt_toolkit.document import Document
from test_cli_ground import BOUND, ENV, OBSW, obc, obsw, start, stop  # noqa: F401, F811


def test_watch_once_shows_values_units_and_limit_states(obc):  # noqa: F811 (the fixture)
    port, _ = obc
    assert obsw("ground", "--port", port, "params", "set", "SolarPanel.speed=12").returncode == 0
    r = obsw("ground", "--port", port, "watch", "--once", "--json")
    assert r.returncode == 0, r.stderr
    frame = json.loads(r.stdout)
    values = {v["name"]: v for v in frame["values"]}
    speed = values["SolarPanel.speed"]
    assert (speed["value"], speed["unit"], speed["limit"]) == (12, "deg/s", "warning")
    assert speed["time"].startswith("20") and speed["time"].endswith("Z")  # UTC ISO
    assert values["SolarPanel.angle"]["limit"] == ""  # the database gives it no limits
    asked = [c for c in frame["commands"] if c["request"].startswith("TC[3,27]")]
    assert asked and asked[0]["stages"][-1] == "completed", frame["commands"]
    obsw("ground", "--port", port, "params", "set", "SolarPanel.speed=16")
    table = subprocess.run(
        OBSW + ["ground", "--port", str(port), "watch", "--once"],
        env=dict(ENV, COLUMNS="160"),
        capture_output=True,
        text=True,
        timeout=BOUND,
    )
    assert table.returncode == 0, table.stderr
    row = [x for x in table.stdout.splitlines() if "SolarPanel.speed" in x][0]
    assert "16" in row and "deg/s" in row and "critical" in row
    assert "current values" in table.stdout and "latest events" in table.stdout


def test_watch_frames_show_events_and_verification_of_other_clients(obc):  # noqa: F811 (the fixture)
    port, _ = obc
    # frames until the test has seen what it waits for (stopped then), however slow the machine
    watch, out, err = start("ground", "--port", port, "watch", "--count", 40, "--every", 1.5)
    try:
        out.until(lambda line: "commands" in line)  # the first frame is out
        assert obsw("ground", "--port", port, "function", "SolarPanel.deploy").returncode == 0
        seen = []
        out.until(lambda line: seen.append(line) or "SolarPanel.deployed" in line)
        assert any("hinges=3" in x for x in seen + [out.until(lambda line: "hinges" in line)])
    finally:
        stop(watch)
    frames = obsw("ground", "--port", port, "--json", "watch", "--count", 2, "--every", 0.2)
    assert frames.returncode == 0
    assert len(frames.stdout.splitlines()) == 2


@pytest.mark.parametrize("bad", ["-1", "0", "x"])
def test_watch_refuses_times_that_are_not_positive(bad):
    r = obsw("ground", "watch", "--seconds", bad)
    assert r.returncode == 2 and "--seconds" in r.stderr and "Traceback" not in r.stderr


_ANSI = re.compile(rb"\x1b\[[0-9;?]*[A-Za-z]")


class Terminal:
    """The master side of a pseudo-terminal: what it shows, read up to each needle in turn."""

    def __init__(self, fd):
        self.fd = fd
        self.pending = b""

    def until(self, needle, seconds=BOUND):
        """What the terminal shows up to and including ``needle`` (AssertionError after
        ``seconds``); what came after it stays for the next call."""
        end = time.monotonic() + seconds
        want = needle.encode()
        # what it shows, without the control sequences that redraws put between characters
        while want not in _ANSI.sub(b"", self.pending):
            left = end - time.monotonic()
            assert left > 0, "%r not seen in %r" % (needle, self.pending[-600:])
            r, _, _ = select.select([self.fd], [], [], left)
            if r:
                try:
                    chunk = os.read(self.fd, 4096)
                except OSError:
                    chunk = b""
                assert chunk, "%r not seen before the end: %r" % (needle, self.pending[-600:])
                self.pending += chunk
        text = _ANSI.sub(b"", self.pending)
        cut = text.index(want) + len(want)
        shown, self.pending = text[:cut], text[cut:]
        return shown.decode(errors="replace")


def test_console_in_a_terminal_pings_reads_a_parameter_and_keeps_history(obc, tmp_path):  # noqa: F811 (the fixture)
    port, _ = obc
    state = tmp_path / "state"
    env = dict(ENV, OBSW_STATE=str(state), PROMPT_TOOLKIT_NO_CPR="1", TERM="xterm")
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 40, 160, 0, 0))
    proc = subprocess.Popen(
        OBSW + ["ground", "--port", str(port), "console"],
        stdin=slave,
        stdout=slave,
        stderr=slave,
        env=env,
        start_new_session=True,
    )
    os.close(slave)
    term = Terminal(master)
    try:
        term.until("obsw-demo>")
        os.write(master, b"ping\r")
        assert "alive" in term.until("alive")
        term.until("obsw-demo>")
        os.write(master, b"params get SolarPanel.sp\t")  # Tab completes the name
        term.until("speed")
        os.write(master, b"\r")
        shown = term.until("deg/s")
        assert "SolarPanel.speed = " in shown
        term.until("obsw-demo>")  # (typed ahead, Ctrl-D would be the tty's EOF)
        os.write(master, b"\x04")  # Ctrl-D leaves
        assert proc.wait(BOUND) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        os.close(master)
    history = (tmp_path / "state" / "ground-history").read_text()  # the mission's state
    assert "+ping" in history and "+params get SolarPanel.speed" in history


def test_console_reads_commands_from_a_pipe_and_reports_mistakes_in_one_line(obc):  # noqa: F811 (the fixture)
    port, _ = obc
    r = subprocess.run(
        OBSW + ["ground", "--port", str(port), "console"],
        input="ping\nparams get SolarPanel.speed --json\nparams get Nope.x\nbogus\nexit\nping\n",
        env=ENV,
        capture_output=True,
        text=True,
        timeout=BOUND,
    )
    lines = r.stdout.splitlines()
    assert lines.count("alive") == 1  # nothing after exit ran
    assert any(x.startswith("{") and '"SolarPanel.speed"' in x for x in lines)
    assert "no parameter" in r.stderr and "invalid choice: 'bogus'" in r.stderr
    assert "Traceback" not in r.stderr
    assert r.returncode == 2


def test_completion_of_commands_and_database_names():
    ground = _subcommands(build_parser("ground"))["ground"]
    completer = GroundCompleter(ground, load_sdb(None))

    def complete(text):
        return [c.text for c in completer.get_completions(Document(text), None)]

    assert "ping" in complete("pi") and "watch" in complete("wa")
    assert complete("params g") == ["get"]
    assert "SolarPanel.speed" in complete("params get SolarPanel.")
    assert "SolarPanel.speed=" in complete("params set Sol")
    assert complete("function SolarPanel.set_angle ") == ["angle="]
    assert "SolarPanel.deployed" in complete("events disable Sol")


def test_a_labelled_argument_completes_with_its_labels():
    from obsw.pus.sdb import load

    aurora = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "aurora", "sdb.json")
    ground = _subcommands(build_parser("ground"))["ground"]
    completer = GroundCompleter(ground, load(aurora))
    texts = [c.text for c in completer.get_completions(
        Document("function Attitude.select_mode mode=D"), None)]  # fmt: skip
    assert texts == ["mode=DETUMBLE"]
