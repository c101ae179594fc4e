"""Defects of the command line, each through the real `obsw` command: Ctrl-C during `cfdp put`
cancels the transaction (the receiver keeps no partial file), `obsw obcp` sends fresh sequence
counts and writes a session log, durations must be positive, missing key files and folders and
a machine without socketcan give one line (exit status 2), and nothing is left in the temp
folder by these commands."""

import json
import os
import signal
import socket
import subprocess
import time

import pytest
from test_cli_ground import BOUND, ENV, OBSW, ROOT, Lines, obc, obsw  # noqa: F401

SAMPLE = dict(ENV, OBSW_MISSION=os.path.join(ROOT, "examples", "sample"))  # the sample mission


def sample(*args):
    return subprocess.run(
        OBSW + [str(a) for a in args], env=SAMPLE, capture_output=True, text=True, timeout=BOUND
    )


def udp_port():
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def udp_queued(port):
    """Octets waiting in the receive queue of the UDP socket bound to ``port`` on 127.0.0.1."""
    with open("/proc/net/udp") as f:
        for line in f.readlines()[1:]:
            fields = line.split()
            if fields[1] == "0100007F:%04X" % port:
                return int(fields[4].split(":")[1], 16)
    return 0


def test_ctrl_c_during_cfdp_put_cancels_and_the_receiver_keeps_nothing(tmp_path):
    ground, onboard = tmp_path / "ground", tmp_path / "onboard"
    ground.mkdir()
    onboard.mkdir()
    (ground / "big.bin").write_bytes(os.urandom(1 << 16) * 128)  # 8 MB in 64 B: seconds
    port, back = udp_port(), udp_port()
    serve = subprocess.Popen(
        OBSW
        + ["cfdp", "serve", "--port", str(port), "--root", str(onboard)]
        + ["--peer", "1=127.0.0.1:%d" % back],
        env=SAMPLE,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )
    served = Lines(serve.stdout)
    try:
        served.until(lambda line: line.startswith("cfdp entity 2 on udp"))
        # the receiver held still: class 2 cannot finish without its Finished PDU, so the
        # Ctrl-C comes during the transfer however fast or loaded the machine is
        os.kill(serve.pid, signal.SIGSTOP)
        put = subprocess.Popen(
            OBSW + ["cfdp", "put", "big.bin", "--root", str(ground), "--segment", "64"]
            + ["--port", str(back), "--peer", "2=127.0.0.1:%d" % port],
            env=SAMPLE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            # Ctrl-C as a terminal gives it, whatever this process inherited (a shell's
            # background job ignores SIGINT, and so would the put)
            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        )  # fmt: skip
        end = time.monotonic() + BOUND
        while not udp_queued(port) and time.monotonic() < end:  # the transfer is under way
            time.sleep(0.05)
        put.send_signal(signal.SIGINT)
        os.kill(serve.pid, signal.SIGCONT)
        out, err = put.communicate(timeout=BOUND)
        assert put.returncode == 130, out + err
        assert "Traceback" not in err
        line = served.until(lambda line: line.startswith("finished "))
        # condition code 15, cancel request received; file status 0, discarded deliberately
        assert " condition=15 " in line and " file_status=0 " in line, line
        kept = [os.path.join(d, n) for d, _, names in os.walk(onboard) for n in names]
        partial = [p for p in kept if os.path.getsize(p) > 4096]  # (small state files may stay)
        assert partial == [], kept
    finally:
        os.killpg(serve.pid, signal.SIGTERM)
        serve.wait(BOUND)


def test_obcp_sends_fresh_sequence_counts_and_logs_the_session(obc, tmp_path):  # noqa: F811
    port, _ = obc
    log = tmp_path / "obcp.log"
    for _ in range(2):
        obsw("obcp", "--port", port, "--log", log, "status")  # no OBCP engine here: refused
    obsw("ground", "--port", port, "--log", log, "obcp", "status")
    tcs = [r for r in map(json.loads, log.read_text().splitlines()) if r["dir"] == "TC"]
    assert len(tcs) == 3 and all("TC[18,8]" in r["text"] for r in tcs)
    counts = [int(r["text"].split(" seq ")[1].split()[0]) for r in tcs]
    assert len(set(counts)) == 3 and counts != [0, 0, 0], counts


@pytest.mark.parametrize(
    "args",
    [
        ("ground", "monitor", "--seconds", "-1"),
        ("ground", "monitor", "--count", "0"),
        ("ground", "events", "listen", "--seconds", "0"),
        ("ground", "watch", "--every", "-2"),
    ],
)
def test_durations_and_counts_must_be_positive(args):
    r = obsw(*args)
    assert r.returncode == 2 and "expected" in r.stderr and "Traceback" not in r.stderr


def test_missing_key_files_and_folders_in_one_line(tmp_path):
    keygen = sample("frames", "keygen", tmp_path / "no" / "such" / "keys.json")
    sign = sample("frames", "sign", "--keys", tmp_path / "absent.json", "00")
    for r in (keygen, sign):
        assert r.returncode == 2, r.stderr
        said = r.stderr.lower()
        assert ("no such file" in said or "does not exist" in said) and "[errno" not in said
        assert len(r.stderr.strip().splitlines()) == 1


def test_spacecan_without_socketcan_in_one_line():
    r = sample(
        "spacecan", "monitor", "--interface", "socketcan", "--channel-a", "obswnone0",
        "--channel-b", "obswnone1", "--duration", "0.5",
    )  # fmt: skip
    assert r.returncode == 2, r.stdout + r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr


def test_nothing_left_in_the_temp_folder(obc, tmp_path):  # noqa: F811
    port, _ = obc
    temp = tmp_path / "temp"
    temp.mkdir()
    env = dict(ENV, TMPDIR=str(temp), OBSW_STATE=str(tmp_path / "state"))

    def run(*args, **kw):
        return subprocess.run(
            OBSW + [str(a) for a in args],
            env=env,
            capture_output=True,
            text=True,
            timeout=BOUND,
            **kw,
        )

    assert run("ground", "--port", port, "watch", "--once", "--json").returncode == 0
    assert run("ground", "--port", port, "console", input="ping\n").returncode == 0
    run("obcp", "--port", port, "status")
    run("frames", "keygen", tmp_path / "keys.json")
    run("ground", "--port", port, "monitor", "--seconds", "0.5")
    assert os.listdir(temp) == []


def test_sigterm_ends_the_qemu_board_with_it(tmp_path):
    """`obsw board qemu` under a service manager: SIGTERM to it ends QEMU too."""
    if subprocess.run(["which", "qemu-system-arm", "arm-none-eabi-gcc"]).returncode:
        pytest.skip("qemu-system-arm and arm-none-eabi-gcc are needed (tools/bootstrap)")
    board = subprocess.Popen(
        OBSW + ["board", "qemu"], env=ENV, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
        text=True,
    )  # fmt: skip
    try:
        Lines(board.stdout).until(lambda x: x.startswith("QEMU board on "))
        qemu = _children(board.pid)
        assert qemu, "no qemu-system-arm process under `obsw board qemu`"
        board.send_signal(signal.SIGTERM)
        board.wait(BOUND)
        assert [pid for pid in qemu if _alive(pid)] == []
    finally:
        if board.poll() is None:
            board.kill()
            board.wait()


def _children(parent):
    """The qemu-system-arm processes whose parent is ``parent`` (from /proc)."""
    out = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open("/proc/%s/stat" % pid) as f:
                ppid = int(f.read().rsplit(") ", 1)[1].split()[1])
            with open("/proc/%s/cmdline" % pid, "rb") as f:
                cmd = f.read().split(b"\0")
        except (OSError, IndexError, ValueError):
            continue
        if ppid == parent and cmd[0].endswith(b"qemu-system-arm"):
            out.append(int(pid))
    return out


def _alive(pid):
    try:
        with open("/proc/%d/stat" % pid) as f:
            return f.read().split(") ")[1][0] != "Z"
    except OSError:
        return False


def test_no_answer_names_the_port_the_ground_used(tmp_path):
    env = dict(SAMPLE, OBSW_PORT_BASE="17000")
    r = subprocess.run(
        OBSW + ["ground", "--timeout", "0.3", "ping"],
        env=env,
        capture_output=True,
        text=True,
        timeout=BOUND,
    )
    assert r.returncode == 1
    assert "no report from 127.0.0.1:17010 within 0.3s" in r.stdout + r.stderr


def tcp_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def test_yamcs_run_leaves_nothing_in_the_temp_folder_when_terminated(tmp_path):
    from obsw_host.yamcs import server

    if server.missing():
        pytest.skip(server.missing())
    temp = tmp_path / "temp"
    temp.mkdir()
    env = dict(SAMPLE, TMPDIR=str(temp), OBSW_PORT_BASE=str(udp_port() - 10))
    ports = ["--http-port", tcp_port(), "--pus-port", tcp_port(), "--cfdp-port", udp_port()]
    ports += ["--cltu-port", udp_port(), "--tm-frames-port", udp_port()]
    run = subprocess.Popen(
        OBSW + ["yamcs", "run"] + [str(p) for p in ports],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
    )
    try:
        out = Lines(run.stdout)
        assert "starting Yamcs" in out.until(lambda line: "Yamcs" in line)  # said at once
        out.until(lambda line: "(Ctrl-C stops)" in line)
        assert os.listdir(temp)  # its instance lives there while it runs
        run.send_signal(signal.SIGTERM)  # as a service manager stops it
        assert run.wait(120) == 0  # a clean stop, as by Ctrl-C
    finally:
        if run.poll() is None:
            os.killpg(run.pid, signal.SIGKILL)
            run.wait()
    assert os.listdir(temp) == []
