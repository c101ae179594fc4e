"""Every shell and Python example of README.md and of the documentation (docs/**/*.md) runs as
written, in order, page by page, against the sample spacecraft, from a copy of examples/ (the
samples the examples use are shipped there).

Each shell block is one terminal: a line ending in ``&`` starts a server, which must print its
ready line (bound) before the next line runs, and stays up for the Python blocks that follow
until the next shell block. A shell block whose first line is ``# from the top folder`` runs
there (the copy of examples/ sits next to links to the rest of the tree). A line's expected
exit status is 0 unless its comment says ``exit N``. Lines that need hardware or root, or that
are whole suites run elsewhere, are listed in SKIP with the reason. Ports move with
OBSW_PORT_BASE (PUS) and a substitution (CFDP).

A block may state what it prints: a ```text block right after it (nothing but blank lines
between) holds the output of its lines in order, as a terminal shows it (standard output and
error; a server's output, lines skipped here and ``export`` lines print nothing). The test
compares it line by line, trailing spaces aside. What varies from run to run (times, process
ids, ports, paths) is written ``...``: within a line it stands for any text, and a line that
is only ``...`` for any number of lines, none included. An output block that reads
``(prints nothing)`` says the block prints nothing at all.
"""

import json
import os
import pathlib
import re
import shlex
import shutil
import signal
import subprocess
import sys
import threading

import mission_ports
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
BOUND = 60  # seconds any line may take
SKIP = {  # a piece of the line -> why it does not run here
    "tools/demo": "the demo is tests/host/test_demo.py",
    "tools/test": "this is the test suite",
    "tools/bench/": "benchmarks run on demand",
    "socketcan": "needs CAN hardware (the Raspberry Pi's can0, can1)",
    "/dev/ttyS": "needs serial ports",
    "/dev/ttyACM0": "needs a Pyboard on USB",
    "obsw board flash": "needs a Pyboard in DFU mode",
    "obsw board build": "the firmware stage of tools/test builds every image",
    "obsw board": "the cortex-m stage of tools/test runs the board tools against the QEMU board",
    "obsw yamcs run": "runs Yamcs until Ctrl-C (the yamcs stage runs it)",
    "tools/bootstrap": "the tests run in the .venv it made",
    "sudo ": "needs root on the machine it sets up (a Raspberry Pi, a Pyboard's host)",
    "dfu-util": "needs a Pyboard in DFU mode",
    "can0": "needs CAN hardware (the Raspberry Pi's can0, can1)",
    "tests/fuzz/run.py --inputs 1000000": "the long fuzz run takes hours",
    "mkdocs serve": "serves the site until Ctrl-C (tools/test builds it)",
    "tools/mutation.py": "the mutation stage of tools/test draws its sample of mutants",
}
EXPORT = re.compile(r"^export ([A-Z_][A-Z0-9_]*)=(\S+)$")  # a variable the terminal keeps
# lines a SKIP piece names that run in seconds and change nothing: they run
RUN_ANYWAY = ("tools/bench/report.py check", "tools/bootstrap")
TOP_FOLDER = "# from the top folder"  # a shell block that starts so runs from the top folder
RAN_AT_LEAST = 100  # examples run over all pages
# every skip names where it is covered or what it needs; most are the hardware guides' lines
# (docs/pyboard.md, docs/raspberry-pi.md: root, a Pyboard, CAN interfaces), and the mutation
# sample of docs/testing.md (its own stage)
SKIPPED_AT_MOST = 61


def pages():
    """README.md, then every page of the documentation, as paths relative to the top."""
    docs = sorted(p.relative_to(ROOT) for p in (ROOT / "docs").rglob("*.md"))
    return [pathlib.Path("README.md")] + docs


BLOCK = re.compile(r"```(sh|python)\n(.*?)```(?:\n\s*```text\n(.*?)```)?", re.S)


def blocks(page):
    return [(kind, body) for kind, body, _ in stated(page)]


def stated(page):
    """(kind, body, the output the page states for it or None) of every runnable block."""
    text = (ROOT / page).read_text()
    return [(m.group(1), m.group(2), m.group(3)) for m in BLOCK.finditer(text)]


def _line_pattern(line):
    return re.compile(".*".join(re.escape(part) for part in line.split("...")) + r"\Z")


NOTHING = "(prints nothing)"  # an output block that says so: the block prints nothing


def printed_as_stated(expected, actual):
    """True if ``actual`` (what ran printed) is ``expected`` (a page's output block), where
    ``...`` stands for any text within a line and a line of only ``...`` for any lines."""
    if expected.strip() == NOTHING:
        return actual.strip() == ""
    want = expected.strip("\n").splitlines()
    got = [x.rstrip() for x in actual.strip("\n").splitlines()]
    pats = [None if w.strip() == "..." else _line_pattern(w.rstrip()) for w in want]
    ok = {0}  # lines of ``got`` matched so far by some way through the first i patterns
    for pat in pats:
        if pat is None:
            ok = set(range(min(ok), len(got) + 1)) if ok else set()
        else:
            ok = {j + 1 for j in ok if j < len(got) and pat.match(got[j])}
    return len(got) in ok


def shell_lines(body):
    """(command, expected exit status, skip reason or None) of every line of a shell block."""
    out = []
    for line in body.splitlines():
        command, expected = _command(line)
        if command:
            reason = next((why for piece, why in SKIP.items() if piece in command), None)
            if any(piece in command for piece in RUN_ANYWAY):
                reason = None
            out.append((command, expected, reason))
    return out


def lines(page):
    return [line for kind, body in blocks(page) if kind == "sh" for line in shell_lines(body)]


def free_base():
    """A port base B with B+10 (PUS) and B+100, B+101 (CFDP) free."""
    return mission_ports.free_base(mission_ports.SAMPLE)


SHELL = set("|&;<>()$`\\*?[]{}~!")  # a line with any of these is the shell's to run


def plain_obsw(command):
    """The arguments of a line that is only ``obsw`` with words (no shell syntax), or None."""
    if SHELL & set(command):
        return None
    try:
        words = shlex.split(command)
    except ValueError:
        return None
    return words[1:] if words and words[0] == "obsw" else None


class Forks:
    """tests/host/obsw_forks.py for one page: runs its plain ``obsw`` lines in a child forked
    from a process that imported the command line once, instead of an interpreter each."""

    def __init__(self, env, tmp):
        self.env = env
        self.tmp = tmp
        self.proc = None
        self.n = 0

    def run(self, argv, env, cwd):
        """(exit status, what it printed) of ``obsw ARGV`` in ``cwd`` with ``env``."""
        if self.proc is None:
            self.proc = subprocess.Popen(
                [sys.executable, str(ROOT / "tests" / "host" / "obsw_forks.py")],
                env=self.env, cwd=str(self.tmp), stdin=subprocess.PIPE,
                stdout=subprocess.PIPE, text=True, bufsize=1,
            )  # fmt: skip
            assert json.loads(self._reply())["ready"]
        self.n += 1
        out = self.tmp / ("forks-%d.out" % self.n)
        req = {"argv": argv, "cwd": str(cwd), "env": dict(env), "out": str(out),
               "timeout": BOUND}  # fmt: skip
        self.proc.stdin.write(json.dumps(req) + "\n")
        self.proc.stdin.flush()
        status = json.loads(self._reply())["status"]
        return status, out.read_text(errors="replace")

    def _reply(self):
        line = self.proc.stdout.readline()
        assert line, "the obsw fork server ended"
        return line

    def stop(self):
        if self.proc is not None:
            self.proc.stdin.close()
            self.proc.wait(BOUND)
            self.proc.stdout.close()


# a server's ready line (else: its first); `obsw obc serve`: see Server.is_ready
READY = {"obsw spacecan master": "served by pid"}
OBC = "obsw obc serve"
OBC_PROCESSES = re.compile(r", processes (.*?), state in ")  # its first line names them


class Server:
    def __init__(self, line, env, cwd):
        self.line = line
        self.ready_text = next((t for k, t in READY.items() if line.startswith(k)), "")
        self.proc = subprocess.Popen(
            ["bash", "-c", "exec " + line],
            env=env,
            cwd=cwd,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            start_new_session=True,  # its children (the OBC's processes) stop with it
        )
        self.ready = threading.Event()
        self.output = []
        self.waiting = None  # an OBC's processes not up yet (once its first line named them)
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for text in self.proc.stdout:
            self.output.append(text)
            if self.is_ready(text):
                self.ready.set()
        self.ready.set()

    def is_ready(self, text):
        """True once the server is ready. An OBC is when each of its processes is up (the
        platform manager heard its first heartbeat): its PUS process then answers at once;
        the line of the PUS process binding its port comes earlier than that."""
        if not self.line.startswith(OBC):
            return self.ready_text in text
        m = OBC_PROCESSES.search(text)
        if m:
            self.waiting = set(m.group(1).split(", "))
        for name in list(self.waiting or ()):
            if "[platform] %s up (pid" % name in text:
                self.waiting.discard(name)
        return self.waiting == set()

    def stop(self):
        try:
            os.killpg(self.proc.pid, signal.SIGTERM)
        except ProcessLookupError:  # it and its children ended by themselves
            pass
        try:
            self.proc.wait(15)
        except subprocess.TimeoutExpired:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()


def _command(line):
    """The line without its comment, and the exit status the comment expects."""
    if line.lstrip().startswith("#"):
        return "", 0
    parts = re.split(r"\s#\s", line + " ", maxsplit=1)
    comment = parts[1] if len(parts) > 1 else ""
    m = re.search(r"exit (\d+)", comment)
    return parts[0].strip(), int(m.group(1)) if m else 0


@pytest.mark.parametrize("page", [p for p in pages() if blocks(p)], ids=str)
def test_every_example_runs(page, tmp_path):
    work = tmp_path / "examples"
    shutil.copytree(ROOT / "examples", work, ignore=shutil.ignore_patterns("__pycache__"))
    for entry in ROOT.iterdir():  # the rest of the tree, for blocks run from the top folder
        if entry.name not in ("examples", ".git", "build"):
            (tmp_path / entry.name).symlink_to(entry)
    base = free_base()
    venv_bin = os.path.dirname(sys.executable)
    env = dict(
        os.environ,
        PATH=venv_bin + os.pathsep + os.environ.get("PATH", ""),
        OBSW_PORT_BASE=str(base),
        OBSW_IL_DIR=str(tmp_path / "il"),
        TMPDIR=str(tmp_path),
        HOME=str(tmp_path / "home"),  # what the examples write under ~ stays here
        OBSW_STATE=str(tmp_path / "state"),  # the page's OBCs keep their state to themselves
        PYTHONPATH=os.pathsep.join([str(work), str(ROOT / "micropython"), str(ROOT / "host")]),
    )
    env.pop("OBSW_MISSION", None)  # a page names its mission as a reader would type it
    session_log = tmp_path / "session.log"
    if page == GUIDE:
        env["OBSW_SESSION_LOG"] = str(session_log)
    os.makedirs(env["OBSW_IL_DIR"])
    os.makedirs(env["HOME"])
    ports = {"5100": str(base + 100), "5101": str(base + 101)}
    servers, ran, skipped = [], 0, []
    forks = Forks(env, tmp_path)
    try:
        for kind, body, expected in stated(page):
            printed = []  # what the block's lines print, in order
            if kind == "python":
                res = subprocess.run(
                    [sys.executable, "-c", body],
                    env=env,
                    cwd=work,
                    stdout=subprocess.PIPE,
                    stderr=subprocess.STDOUT,
                    text=True,
                    timeout=BOUND,
                )
                assert res.returncode == 0, "%s: python block failed:\n%s\n%s" % (
                    page,
                    body,
                    res.stdout,
                )
                ran += 1
                _check_stated(page, body, expected, res.stdout)
                continue
            for server in servers:
                server.stop()
            servers = []
            cwd = tmp_path if body.startswith(TOP_FOLDER) else work
            for command, status, reason in shell_lines(body):
                if reason:
                    skipped.append((command, reason))
                    continue
                for old, new in ports.items():
                    command = command.replace(old, new)
                exported = EXPORT.match(command)
                if exported:  # the terminal keeps it for the lines that follow
                    name, value = exported.groups()
                    echo = ["bash", "-c", 'printf %%s "%s"' % value]
                    env[name] = subprocess.run(echo, env=env, cwd=cwd, capture_output=True,
                                               text=True).stdout  # fmt: skip
                    ran += 1
                    continue
                if command.endswith("&"):
                    server = Server(command[:-1].strip(), env, cwd)
                    servers.append(server)
                    assert server.ready.wait(BOUND), "no ready line from %r" % command
                    assert server.proc.poll() is None, "%r ended: %s" % (command, server.output)
                    ran += 1
                    continue
                argv = plain_obsw(command)
                if argv is not None:
                    code, output = forks.run(argv, env, cwd)
                else:
                    res = subprocess.run(
                        ["bash", "-c", command],
                        env=env,
                        cwd=cwd,
                        stdout=subprocess.PIPE,
                        stderr=subprocess.STDOUT,
                        text=True,
                        timeout=BOUND,
                    )
                    code, output = res.returncode, res.stdout
                assert code == status, "%s: %r: exit %d\n%s" % (
                    page,
                    command,
                    code,
                    output[-4000:],
                )
                printed.append(output)
                ran += 1
            _check_stated(page, body, expected, "".join(printed))
    finally:
        for server in servers:
            server.stop()
        forks.stop()
    print("%s: %d examples ran, %d skipped: %s" % (page, ran, len(skipped), skipped))
    if page == GUIDE:
        missing = served_services(work / "sample") - accepted_services(session_log)
        assert not missing, "the operator's guide reaches no TC of services %s" % sorted(missing)


def _check_stated(page, body, expected, actual):
    if expected is not None:
        assert printed_as_stated(expected, actual), (
            "%s: the block\n%s\nprinted\n%s\nnot what the page says:\n%s"
            % (page, body, actual, expected)
        )


GUIDE = pathlib.Path("docs/operators-guide.md")


def served_services(mission):
    """The services the mission's OBC takes TCs of, from the service tables it registers."""
    from obsw_host.pus.coverage import obc_services

    return {s for s, provider in obc_services(str(mission)).items() if provider.HANDLERS}


def accepted_services(path):
    """The services of the TCs of a session log whose acceptance succeeded (TM[1,1])."""
    import json

    from obsw.pus.tc import PusTc

    sent, accepted = {}, set()
    for line in path.read_text().splitlines():
        record = json.loads(line)
        if record["dir"] == "TC":
            tc = PusTc.unpack(bytes.fromhex(record["raw"]))
            sent[(tc.apid, tc.seq_count)] = tc.service
            continue
        decoded = record.get("decoded") or {}
        request = decoded.get("request_id") if isinstance(decoded, dict) else None
        if request and decoded.get("stage") == 1 and decoded.get("success"):
            key = (request["apid"], request["seq_count"])
            if key in sent:
                accepted.add(sent[key])
    return accepted


def test_stated_output_matching():
    assert printed_as_stated("alive\n", "alive\n")
    assert not printed_as_stated("alive\n", "dead\n")
    assert printed_as_stated("took ... s\n", "took 0.25 s\n")
    assert not printed_as_stated("took ... s\n", "took 0.25 ms\n")
    assert printed_as_stated("...\nalive\n", "a\nb\nalive\n")
    assert printed_as_stated("...\nalive\n...\n", "alive\n")
    assert printed_as_stated("a\n...\nz\n", "a\nz\n")
    assert not printed_as_stated("a\n...\nz\n", "a\nb\n")
    assert not printed_as_stated("a\n", "a\nb\n")  # no line left over unstated
    assert printed_as_stated("x [1.5]  \n", "x [1.5]\n")  # trailing spaces aside; [ literal
    assert printed_as_stated("", "")
    assert printed_as_stated("(prints nothing)\n", "")
    assert printed_as_stated("(prints nothing)\n", "\n")
    assert not printed_as_stated("(prints nothing)\n", "saved\n")


def test_examples_are_many_and_every_skip_has_a_reason():
    found = [(page, line) for page in pages() for line in lines(page)]
    skipped = [(page, command, why) for page, (command, _, why) in found if why]
    python = sum(kind == "python" for page in pages() for kind, _ in blocks(page))
    assert len(found) - len(skipped) + python >= RAN_AT_LEAST
    assert len(skipped) <= SKIPPED_AT_MOST, skipped


# pages with an example that runs here without stating its output, and why
UNSTATED = {"docs/benchmarks.md": "its report block's other lines run benchmarks (skipped here)"}


def runs(kind, body):
    """True if the block runs here: Python, or a shell block with a line not skipped."""
    return kind == "python" or any(not why for _, _, why in shell_lines(body))


def test_every_example_that_runs_states_what_it_prints():
    unstated = [(str(page), body.splitlines()[0]) for page in pages()
                for kind, body, printed in stated(page)
                if printed is None and runs(kind, body) and str(page) not in UNSTATED]  # fmt: skip
    assert unstated == []


@pytest.mark.parametrize("name", ["node.json", "proc.pluto", "system.json", "turn.plt"])
def test_sample_files_are_shipped(name):
    assert (ROOT / "examples" / name).is_file()
    assert any(name in (ROOT / page).read_text() for page in pages())
