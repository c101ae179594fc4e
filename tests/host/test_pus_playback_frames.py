"""Service 15 playback over the space link: the on-board PUS process, the frame processor on
two pseudo-UARTs and a ground station decoding TM frames; stored housekeeping retrieved with
service 15 comes down unchanged on the playback VC, live telemetry on the real-time VC."""

from obsw.frames.tm_plan import PLAYBACK_VCID, REALTIME_VCID
from obsw_host.pus.onboard import tai_now
from storage_demo import Segment

STORE = 3


def _kind(raw):
    return raw[7], raw[8]  # PUS-C TM: service and subtype after the 6-byte header and 1 octet


def _hk(ground):
    return [d for tm, d in ground.received if (tm.service, tm.subtype) == (3, 25)]


def _since(station, mark):
    return list(station.downlinked)[mark:]


def test_stored_hk_retrieved_with_service_15_arrives_on_the_playback_vc(tmp_path):
    with Segment(str(tmp_path), frames=True) as seg:
        sg, ground, station = seg.sg, seg.ground, seg.station
        apid = ground.apid
        assert sg.create_store(STORE, 65536).ok  # the playback VC by default
        assert sg.store_types(STORE, {apid: {3: [25]}}).ok
        assert sg.enable_storage([STORE]).ok
        assert sg.issue(ground.hk.modify_interval(apid, {1: 2})).ok
        assert sg.wait_until(lambda: any(_kind(p) == (3, 25) for _, p in station.downlinked), 3.0)
        live = [vc for vc, p in station.downlinked if _kind(p) == (3, 25)]
        assert set(live) == {REALTIME_VCID}
        assert sg.withhold_hk().ok
        t0 = tai_now()
        sg.wait_until(lambda: False, 0.8)  # out of contact: stored, not forwarded
        t1 = tai_now()
        stored = seg.onboard.call(lambda: seg.storage.stores[STORE].select_time(t0, t1))
        assert len(stored) >= 3
        mark = len(station.downlinked)
        hk_mark = len(_hk(ground))
        tx = sg.retrieve_time(STORE, t0, t1)
        assert tx.ok, tx.verification()
        assert sg.wait_until(lambda: len(_hk(ground)) - hk_mark >= len(stored), 5.0)
        got = _since(station, mark)
        played = [(vc, p) for vc, p in got if _kind(p) == (3, 25)]
        assert [p for _, p in played] == stored  # unchanged, in storage order
        assert {vc for vc, _ in played} == {PLAYBACK_VCID}
        reports = [vc for vc, p in got if _kind(p)[0] == 1]  # verification of TC[15,9]
        assert reports and set(reports) == {REALTIME_VCID}
        hk = _hk(ground)  # decoded by the ground's service 3 user
        assert "SolarPanel.angle" in hk[-1]["values"]
        counters = seg.fp.core.counters
        assert counters["tm_unknown_vc"] == 0 and counters["tm_dropped"] == 0
        assert seg.onboard.app.counters.get("playback_sent", 0) >= len(stored)
        assert seg.station.ground.bad_frames == 0


def test_a_store_on_the_realtime_vc_plays_back_in_real_time(tmp_path):
    with Segment(str(tmp_path), frames=True) as seg:
        sg, ground, station = seg.sg, seg.ground, seg.station
        apid = ground.apid
        assert sg.create_store(STORE, 65536, vc=REALTIME_VCID).ok
        assert sg.store_types(STORE, {apid: {17: []}}).ok
        assert sg.enable_storage([STORE]).ok
        assert ground.ping().ok  # TM[17,2] stored (and forwarded)
        mark = len(station.downlinked)
        assert sg.retrieve_sequence(STORE, 0, 0xFFFFFFFF).ok
        assert sg.wait_until(
            lambda: any(_kind(p) == (17, 2) for _, p in _since(station, mark)), 5.0
        )
        vcs = {vc for vc, p in _since(station, mark) if _kind(p) == (17, 2)}
        assert vcs == {REALTIME_VCID}


def test_a_store_keeps_the_housekeeping_structures_named_only(tmp_path):
    # a new store keeps every structure of its APID; structures added to "every" would change
    # nothing, so StorageGround.store_hk deletes that selection first
    with Segment(str(tmp_path)) as seg:
        sg, apid = seg.sg, seg.ground.apid
        assert sg.create_store(STORE, 65536).ok
        report = lambda: sg.issue(sg.storage.report_hk(apid, STORE)).reply  # noqa: E731
        assert report() == {"store": STORE, "hk": {apid: []}}
        assert sg.store_hk(STORE, [1]).ok
        assert report() == {"store": STORE, "hk": {apid: [1]}}
        assert sg.store_hk(STORE, [2, 3]).ok  # again: these replace the last ones
        assert report() == {"store": STORE, "hk": {apid: [2, 3]}}
        assert sg.store_hk(STORE, []).ok  # none named: every structure again
        assert report() == {"store": STORE, "hk": {apid: []}}
        assert not sg.store_hk(STORE + 1, [1]).ok  # no such store: refused
