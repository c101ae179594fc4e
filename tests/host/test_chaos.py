"""The chaos campaign's verdict (``obsw_sim.chaos``) on made-up runs: what counts as lost, as
declared, as a gap; the page it writes. The campaign itself is the `chaos` stage."""

import types

from obsw_sim.chaos import Campaign, markdown, print_result


class Tx:
    def __init__(self, seq, stages):
        self.tc = types.SimpleNamespace(seq_count=seq)
        self.stages = stages

    def verification(self):
        return self.stages


def campaign(faults, sent, hk, transfers=()):
    c = Campaign.__new__(Campaign)
    c.t0 = 0.0
    c.faults = faults
    c.sent = sent
    c.hk_counts = [(t, 0) for t in hk]
    c.transfers = list(transfers)
    return c


def rss(controllers, obc, ground=30000):
    return {"controllers": controllers, "OBC": obc, "ground": ground}


FLAT = rss(28000, 130000)
DONE = ["acceptance success", "start success", "completion success"]
OPEN = ["acceptance success", "start success"]
FAILED = ["acceptance success", "start success", "completion failure: refused (code 10)"]


def test_a_tc_left_open_is_lost_unless_the_obc_died_meanwhile():
    faults = [{"kind": "obc_kill", "at": 50.0, "until": 58.0, "took": 8.0, "recovered": True,
               "kills": True}]  # fmt: skip
    sent = [(Tx(1, DONE), 10.0), (Tx(2, OPEN), 49.0), (Tx(3, FAILED), 70.0), (Tx(4, OPEN), 90.0)]
    hk = [float(t) for t in range(0, 48)] + [float(t) for t in range(60, 100)]
    r = campaign(faults, sent, hk).report(FLAT, FLAT)
    assert len(r["tcs_declared"]) == 1 and len(r["tcs_lost"]) == 1  # seq 2, seq 4
    assert (r["hk_declared_gaps"], r["hk_gaps"]) == (1, 0)
    assert r["checks"]["no accepted TC lost without a declared cause"] is False
    assert r["recovery"]["obc_kill"] == {"n": 1, "recovered": 1, "p50": 8.0, "p99": 8.0}


def test_a_silent_stretch_without_a_fault_is_a_gap_and_a_transfer_must_say():
    transfers = [{"name": "a", "ok": True, "reported": False},
                 {"name": "b", "ok": False, "reported": True},
                 {"name": "c", "ok": False, "reported": False}]  # fmt: skip
    r = campaign([], [(Tx(1, DONE), 1.0)], [0.0, 1.0, 9.0, 10.0], transfers).report(FLAT, FLAT)
    assert r["hk_gaps"] == 1 and r["transfers"]["lost"] == ["c"]
    lines = []
    assert print_result(r, lines.append) is False
    assert lines[-1] == "3 passed, 2 failed"
    page = markdown(r, 3, 30)
    assert "--minutes 30 --seed 3" in page and "| CFDP transfers lost | 1 |" in page


def test_the_spacecraft_memory_must_stay_flat_the_grounds_may_grow():
    grown = campaign([], [], []).report(FLAT, rss(28000, 130000, ground=90000))
    assert grown["checks"]["the spacecraft's memory flat (controllers, OBC)"] is True
    leak = campaign([], [], []).report(FLAT, rss(28000, 180000))
    assert leak["checks"]["the spacecraft's memory flat (controllers, OBC)"] is False
    assert "| RSS of the OBC, start and end (kB) | 130000, 180000 |" in markdown(leak, 1, 1)
