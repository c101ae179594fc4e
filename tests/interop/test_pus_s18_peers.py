"""ST[18] against spacepackets: every TM of service 18 (and the OBCP events and failure
reports it causes) decodes with spacepackets' PusTm field for field, the application data
read by hand; our TCs decode with spacepackets' PusTc; spacepackets' TCs are served by us."""

import struct
import sys
from pathlib import Path

from spacepackets.ecss.pus_1_verification import ManagedParamsVerification, Service1Tm
from spacepackets.ecss.tc import PusTc as SpTc
from spacepackets.ecss.tm import ManagedParams
from spacepackets.ecss.tm import PusTm as SpTm

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))

from obsw.cfdp.filestore import MemoryFilestore  # noqa: E402
from obsw.pus.messages import FAILURE_OBCP_REJECTED  # noqa: E402
from obsw.pus.services import s18_layouts as lay  # noqa: E402
from obsw.pus.services.s18_obcp import ObcpManagement  # noqa: E402
from obsw.pus.services.s18_user import ObcpUser  # noqa: E402
from pus_loop import APID  # noqa: E402
from test_pus_s18_obcp import HOLD, TURN, Rig  # noqa: E402


def _scenario():
    r = Rig(MemoryFilestore({"obcp/turn.plt": TURN.encode()}))
    u = r.user
    r.run(u.load(APID, "turn", TURN))
    r.run(u.load(APID, "hold", HOLD, {"limit": {"value": 2.5, "unit": "deg"}, "n": 3}))
    r.run(u.load_by_reference(APID, "ref", "obcp", "turn.plt"))
    r.run(u.report_status(APID))  # all inactive, never run
    r.run(u.activate(APID, "turn", level=lay.LEVEL_STATEMENT))
    r.run(u.activate(APID, "hold", {"limit": 1.0, "n": -4}))
    r.drive(1.0)
    r.run(u.report_status(APID))  # one running, one finished
    r.run(u.load(APID, "bad", "procedure\n main\n  log 1\n end main\nend"))  # rejected
    r.run(u.abort_all(APID))
    r.run(u.abort_all(APID))  # nothing left to abort: N = 0
    r.run(u.report_status(APID))
    return r


RIG = None


def rig():
    global RIG
    if RIG is None:
        RIG = _scenario()
    return RIG


def _tm(service, subtype=None):
    r = rig()
    return [
        (raw, t)
        for raw, t in zip(r.loop.raw, r.loop.tm)
        if t.service == service and (subtype is None or t.subtype == subtype)
    ]


def _sp(raw, ours):
    sp = SpTm.unpack(raw, timestamp_len=6)
    assert (sp.apid, sp.seq_count, sp.service, sp.message_subtype) == (
        ours.apid,
        ours.seq_count,
        ours.service,
        ours.subtype,
    )
    assert sp.pus_tm_sec_header.message_counter == ours.message_counter
    assert sp.pus_tm_sec_header.dest_id == ours.destination_id
    assert sp.source_data == ours.data
    return sp.source_data


class Reader:
    """Reads the fields of application data by hand (struct), the test's own decoder."""

    def __init__(self, data):
        self.data = bytes(data)
        self.pos = 0

    def take(self, fmt):
        n = struct.calcsize(fmt)
        v = struct.unpack_from(fmt, self.data, self.pos)
        self.pos += n
        return v[0] if len(v) == 1 else v

    def text(self, length_fmt=">B"):
        n = self.take(length_fmt)
        v = self.data[self.pos : self.pos + n]
        self.pos += n
        return v.decode()

    def done(self):
        return self.pos == len(self.data)


def _status_items(data):
    rd = Reader(data)
    items = []
    for _ in range(rd.take(">B")):
        items.append(
            {
                "id": rd.text(),
                "status": rd.take(">B"),
                "outcome": rd.take(">B"),
                "level": rd.take(">B"),
                "activations": rd.take(">H"),
                "statements": rd.take(">I"),
                "line": rd.take(">H"),
                "step": rd.text(),
            }
        )
    assert rd.done()
    return items


def test_status_reports_field_for_field():
    reports = _tm(18, 9)
    assert len(reports) == 3
    seen = [_status_items(_sp(raw, ours)) for raw, ours in reports]
    assert [i["id"] for i in seen[0]] == ["turn", "hold", "ref"]
    assert [(i["status"], i["outcome"], i["activations"]) for i in seen[0]] == [(0, 0, 0)] * 3
    turn, hold, ref = seen[1]
    assert (turn["status"], turn["outcome"], turn["level"], turn["step"]) == (0, 1, 3, "")
    assert turn["statements"] > 0
    assert (hold["status"], hold["outcome"], hold["level"], hold["step"]) == (1, 0, 2, "Hold")
    assert hold["line"] == 5
    assert [(i["status"], i["outcome"]) for i in seen[2]] == [(0, 1), (0, 3), (0, 0)]
    # the user's decoding agrees with the hand-made one
    decoded = [d for tm, d, tx in rig().loop.results if (tm.service, tm.subtype) == (18, 9)]
    assert [[o["id"] for o in d["obcps"]] for d in decoded] == [[i["id"] for i in s] for s in seen]
    assert decoded[1]["obcps"][1]["status"] == "running"


def test_bare_status_report_is_n_pairs():
    r = Rig()
    r.loop.app.services.pop(18)
    r.loop.app.register(ObcpManagement(r.engine, detail=False))
    user = r.loop.ground.register(ObcpUser(detail=False))
    r.run(user.load(APID, "a", TURN))
    tx = r.run(user.report_status(APID))
    raw, ours = _tm_of(r, 18, 9)[0]
    assert _sp(raw, ours) == b"\x01\x01a\x00"
    assert tx.reply == {"obcps": [{"id": "a", "status": "inactive"}]}


def _tm_of(r, service, subtype):
    return [
        (raw, t)
        for raw, t in zip(r.loop.raw, r.loop.tm)
        if (t.service, t.subtype) == (service, subtype)
    ]


def test_aborted_reports_field_for_field():
    reports = _tm(18, 18)
    assert len(reports) == 2
    lists = []
    for raw, ours in reports:
        rd = Reader(_sp(raw, ours))
        lists.append([rd.text() for _ in range(rd.take(">B"))])
        assert rd.done()
    assert lists == [["hold"], []]


def test_obcp_events_field_for_field():
    events = _tm(5)
    assert len(events) > 8
    names = {}
    for raw, ours in events:
        rd = Reader(_sp(raw, ours))
        event_id = rd.take(">H")
        ev = rig().sdb.event(event_id)
        assert ev.severity == ours.subtype
        values = {}
        for name, _ in ev.fields:
            values[name] = rd.text(">H")
        assert rd.done()
        names.setdefault(ev.name, []).append(values)
    assert {"obcp": "hold", "step": "Hold", "status": "executing"} in names["obcp.step_status"]
    assert {"obcp": "turn", "text": "to 30.0 deg"} in names["obcp.log"]
    assert {"obcp": "turn", "outcome": "confirmed", "error": ""} in names["obcp.finished"]


def test_rejection_failure_report_in_spacepackets():
    params = ManagedParams(timestamp_len=6)
    verif = ManagedParamsVerification(bytes_step_id=1, bytes_err_code=1)
    found = 0
    for raw, _ours in _tm(1, 4):
        tm = Service1Tm.unpack(raw, params, verif)
        if tm.error_code.val != FAILURE_OBCP_REJECTED:
            continue
        rd = Reader(tm.failure_notice.data)
        kind, line, column = rd.take(">B"), rd.take(">H"), rd.take(">H")
        message = rd.text(">H")
        assert rd.done()
        assert (lay.KINDS[kind], line, column) == ("syntax_error", 4, 2)
        assert "expected" in message
        found += 1
    assert found == 1


def test_our_tcs_decode_in_spacepackets():
    r = rig()
    ours = [raw for raw in r.loop.tc if raw[7] == 18]
    assert len(ours) >= 10
    for raw in ours:
        tc = SpTc.unpack(raw)
        assert (tc.apid, tc.service) == (APID, 18)
    load = SpTc.unpack(ours[1])
    rd = Reader(load.app_data)
    assert (load.message_subtype, rd.text()) == (1, "hold")
    assert rd.text(">H") == HOLD
    args = {}
    for _ in range(rd.take(">B")):
        name, code, unit = rd.text(), rd.take(">H"), rd.text()
        value = rd.take(">d") if code == lay.ARG_REAL else rd.take(">q")
        args[name] = (code, unit, value)
    assert rd.done()
    assert args == {"limit": (lay.ARG_REAL, "deg", 2.5), "n": (lay.ARG_INT, "", 3)}


def test_spacepackets_tcs_are_served():
    r = Rig()
    data = bytes([4]) + b"ping" + struct.pack(">H", len(TURN)) + TURN.encode() + b"\x00"
    r.loop.app.receive(SpTc(apid=APID, service=18, message_subtype=1, app_data=data).pack())
    act = bytes([4]) + b"ping" + bytes([3, 0])
    r.loop.app.receive(
        SpTc(apid=APID, service=18, message_subtype=3, app_data=act, seq_count=1).pack()
    )
    r.loop.pump()
    r.drive()
    assert r.panel.angle == 30.0
    assert r.engine.status("ping")["outcome"] == "confirmed"
    assert r.loop.app.counters["completed"] == 2


def test_spacepackets_step_by_step_tcs_are_served():
    """TC[18,14] and TC[18,15] built by spacepackets; the status report in between (TM[18,9])
    decodes field for field: suspended after the step, inactive and confirmed at the end."""
    r = Rig()
    r.run(r.user.load(APID, "hold", HOLD))
    seq = 10
    act = bytes([4]) + b"hold" + bytes([3, 0])  # ID, level 3 (statement), N = 0 arguments
    r.loop.app.receive(
        SpTc(apid=APID, service=18, message_subtype=14, app_data=act, seq_count=seq).pack()
    )
    r.loop.pump()
    r.drive(12.0)
    r.run(r.user.report_status(APID))
    raw, ours = _tm_of(r, 18, 9)[-1]
    item = _status_items(_sp(raw, ours))[0]
    assert (item["id"], lay.STATUS_NAMES[item["status"]], item["step"]) == (
        "hold",
        "suspended",
        "",
    )
    step = bytes([4]) + b"hold"
    r.loop.app.receive(
        SpTc(apid=APID, service=18, message_subtype=15, app_data=step, seq_count=seq + 1).pack()
    )
    r.loop.pump()
    r.drive(2.0)
    r.run(r.user.report_status(APID))
    raw, ours = _tm_of(r, 18, 9)[-1]
    item = _status_items(_sp(raw, ours))[0]
    assert (lay.STATUS_NAMES[item["status"]], lay.OUTCOME_NAMES[item["outcome"]]) == (
        "inactive",
        "confirmed",
    )
    params = ManagedParams(timestamp_len=6)
    verif = ManagedParamsVerification(bytes_step_id=1, bytes_err_code=1)
    completed = [
        Service1Tm.unpack(raw, params, verif).tc_req_id.tc_psc.seq_count
        for raw, t in zip(r.loop.raw, r.loop.tm)
        if (t.service, t.subtype) == (1, 7)
    ]
    assert seq in completed and seq + 1 in completed  # both requests completed
    events = [d for tm, d, _tx in r.loop.results if tm.service == 5 and d]
    logs = [d["data"]["text"] for d in events if d.get("event") == "obcp.log"]
    assert logs == ["held", "done"]


def _tm_of(r, service, subtype):
    pairs = zip(r.loop.raw, r.loop.tm)
    return [(raw, t) for raw, t in pairs if (t.service, t.subtype) == (service, subtype)]
