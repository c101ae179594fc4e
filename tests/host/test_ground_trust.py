"""The ground trusts only its OBC (issue 34): TM is taken from the configured on-board address
only, so forged reports from another port cannot make `obsw ground ping` succeed; strings from
the spacecraft are printed with their control characters escaped (monitor, replay, watch)."""

import json
import socket
import threading

from obsw.pus.config import from_sdb
from obsw.pus.packets import RequestId
from obsw.pus.services.s05_events import EVENT_ID
from obsw.pus.tc import PusTc
from obsw.pus.tm import PusTm
from obsw_host.pus.ground import Ground
from obsw_host.pus.text import escape
from obsw_host.sample import SDB_PATH, load_sdb
from test_mission_examples import obsw

SDB = load_sdb()
EVIL = "\x1b[2J\x1b]0;pwned\x07\rforged line\n\u202egnp.exe"


class Forger:
    """Binds the OBC's port (it sees the ground's TCs) and answers every TC with forged
    acceptance, ping reply and completion, sent from another port."""

    def __init__(self):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.port = self.sock.getsockname()[1]
        self.other = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.other.bind(("127.0.0.1", 0))
        self.config = from_sdb(SDB)
        self.forged = 0
        threading.Thread(target=self._run, daemon=True).start()

    def _run(self):
        while True:
            try:
                data, ground = self.sock.recvfrom(65536)
            except OSError:
                return
            if len(data) < 7:
                continue  # a subscription
            tc = PusTc.unpack(data, self.config)
            rid = RequestId(tc.apid, tc.seq_count).pack()
            for service, subtype, body in ((1, 1, rid), (17, 2, b""), (1, 7, rid)):
                tm = PusTm(tc.apid, service, subtype, body, config=self.config).pack()
                self.other.sendto(tm, ground)
                self.forged += 1

    def close(self):
        self.sock.close()
        self.other.close()


def test_forged_reports_from_another_port_are_dropped():
    forger = Forger()
    try:
        with Ground(SDB, target=("127.0.0.1", forger.port), timeout=1.0) as g:
            tx = g.wait(g.test.ping(g.apid), 1.0, raise_on_timeout=False)
            assert not tx.ok and not tx.verification()
            assert g.foreign >= 3 and forger.forged >= 3
    finally:
        forger.close()


def test_obsw_ground_ping_fails_on_forged_reports():
    forger = Forger()
    try:
        r = obsw("ground", "--sdb", SDB_PATH, "--port", forger.port, "--timeout", "1", "ping")
        assert r.returncode != 0, r.stdout + r.stderr
        assert forger.forged >= 3
    finally:
        forger.close()


def test_escape():
    assert escape("plain text, ünïcode") == "plain text, ünïcode"
    out = escape(EVIL)
    assert not any(ord(c) < 0x20 or 0x7F <= ord(c) < 0xA0 for c in out)
    assert "\u202e" not in out and "\\x1b[2J" in out and "\\x0a" in out
    assert escape("a\\x1b") == "a\\\\x1b"  # a backslash is escaped: no fake escape either


def event_tm(config):
    e = SDB.event("obcp.log")
    data = EVENT_ID.pack(e.id) + e.pack({"obcp": "proc" + EVIL, "text": EVIL})
    return PusTm(10, 5, 1, data, seq_count=3, config=config).pack()


def test_replay_and_monitor_escape_spacecraft_strings(tmp_path):
    log = tmp_path / "session.log"
    raw = event_tm(from_sdb(SDB))
    log.write_text(json.dumps({"utc": "2026-01-01T00:00:00Z", "dir": "TM", "raw": raw.hex()})
                   + "\n")  # fmt: skip
    r = obsw("ground", "--sdb", SDB_PATH, "replay", str(log))
    assert r.returncode == 0, r.stderr
    assert "obcp.log" in r.stdout and "pwned" in r.stdout
    assert "\x1b" not in r.stdout and "\x07" not in r.stdout and "\r" not in r.stdout
    assert "\u202e" not in r.stdout
    assert r.stdout.count("\n") == 1  # one record, one line: no forged line
