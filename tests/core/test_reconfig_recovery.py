"""Autonomous recovery of the OBC: the UART link's frames, the policy (deadline, power cycle,
switch-over), both controllers deciding at once under the Dekker arbitration, and the whole
thing in the reconfiguration application (decisions in HPTM and in the safeguard log, the OBC's
context and the DS3231's time over the UART)."""

import unittest

from obsw.frames.asm import CaduDecoder
from obsw.frames.tm_demux import TmDemultiplexer
from obsw.reconfig import mission
from obsw.reconfig import obclink as L
from obsw.reconfig import recovery as R
from obsw.reconfig.app import ReconfigApp
from obsw.reconfig.dekker_sim import DekkerSim
from obsw.reconfig.essential import DECISION_APID
from obsw.reconfig.hal import PORT_COM, PORT_OBC, RESET_WATCHDOG
from obsw.reconfig.models import ModelHal
from obsw.utc import days_from_civil

FAST = {"deadline": 1.0, "boot_grace": 2.0, "off_ms": 200, "max_failures": 2, "window": 60.0}


class TestLink(unittest.TestCase):
    def test_round_trip_in_pieces(self):
        frames = L.heartbeat(7) + L.encode(L.T_CONTEXT_WRITE, b"ctx" * 20) + L.time_reply(0, 1, 2)
        d = L.Decoder()
        got = []
        for i in range(len(frames)):
            got += d.feed(frames[i : i + 1])
        self.assertEqual(got[0], (L.T_HEARTBEAT, b"\x00\x07"))
        self.assertEqual(got[1], (L.T_CONTEXT_WRITE, b"ctx" * 20))
        self.assertEqual(L.parse_time(got[2][1]), (0, 1, 2))
        self.assertEqual(d.counters["skipped"], 0)

    def test_noise_and_bad_crc_cost_only_their_frames(self):
        good = L.heartbeat(1)
        bad = bytearray(L.heartbeat(2))
        bad[5] ^= 0x40
        d = L.Decoder()
        got = d.feed(b"\x00\xa5\x13junk" + bytes(bad) + good + b"\xa5")
        self.assertEqual(got, [(L.T_HEARTBEAT, b"\x00\x01")])
        self.assertEqual(d.counters["bad_crc"], 1)
        self.assertTrue(d.counters["skipped"] >= 7)
        self.assertEqual(d.feed(b"\x5a"), [])  # the kept 0xA5 was the start of a sync

    def test_bad_frames_to_build(self):
        self.assertRaises(L.LinkError, L.encode, 0)
        self.assertRaises(L.LinkError, L.encode, L.T_CONTEXT_WRITE, bytes(L.MAX_PAYLOAD + 1))
        self.assertRaises(L.LinkError, L.parse_time, b"\x00")


class TestPolicy(unittest.TestCase):
    def test_deadline_power_cycle_then_switch_over(self):
        p = R.Recovery(FAST)
        p.start(0.0)
        self.assertIsNone(p.poll(1.9, 0x001))  # boot grace
        p.heartbeat(R.SOURCE_UART, 1.9)
        self.assertIsNone(p.poll(2.8, 0x001))
        p.heartbeat(R.SOURCE_CAN, 2.8)  # either source keeps the OBC alive
        self.assertIsNone(p.poll(3.7, 0x001))
        act = p.poll(3.9, 0x001)
        self.assertEqual(act, (R.POWER_CYCLE, 1, 0, 1, 1, 0))
        self.assertIsNone(p.poll(3.95, 0x001))  # one action at a time
        d = p.done(4.0, True)
        self.assertEqual((d.kind, d.line, d.obc, d.failures), (R.POWER_CYCLE, 0, 0, 1))
        self.assertEqual(d.silence_ms, 1200)
        self.assertIsNone(p.poll(6.1, 0x001))  # off_ms + boot grace
        self.assertEqual(p.poll(6.3, 0x001)[0], R.POWER_CYCLE)
        p.done(6.3, True)
        act = p.poll(8.6, 0x001)  # the second failure in the window: the other OBC
        self.assertEqual(act, (R.SWITCH_OVER, 3, 2, 3, 1, 0))
        d = p.done(8.6, True)
        self.assertEqual((d.kind, d.obc, d.failures), (R.SWITCH_OVER, 1, 0))
        self.assertIsNone(p.poll(8.7, 0x002))  # the lines as switched
        self.assertIsNone(p.poll(10.7, 0x002))
        act = p.poll(10.9, 0x002)
        self.assertEqual((act[0], act[1], act[5]), (R.POWER_CYCLE, 2, 1))  # the redundant's

    def test_window_forgets_old_failures(self):
        p = R.Recovery(FAST)
        p.start(0.0)
        p.poll(2.0, 0x001)
        p.done(2.0, True)
        act = p.poll(100.0, 0x001)
        self.assertEqual(act[0], R.POWER_CYCLE)

    def test_obc_switched_off_by_the_ground_is_left_off(self):
        p = R.Recovery(FAST)
        p.start(0.0)
        self.assertIsNone(p.poll(5.0, 0x000))
        self.assertIsNone(p.poll(50.0, 0x0F0))

    def test_a_line_change_by_someone_else_restarts_the_wait(self):
        p = R.Recovery(FAST)
        p.start(0.0)
        p.poll(1.0, 0x001)
        self.assertIsNone(p.poll(2.0, 0x000))  # the other controller's power cycle
        self.assertIsNone(p.poll(2.2, 0x001))
        self.assertIsNone(p.poll(4.3, 0x001))
        self.assertEqual(p.poll(4.5, 0x001)[0], R.POWER_CYCLE)

    def test_the_other_controllers_recoveries_count(self):
        p = R.Recovery(FAST)
        p.start(0.0)
        p.poll(1.0, 0x001)
        p.poll(1.1, 0x000)  # a power cycle by the other controller
        p.poll(1.3, 0x001)
        self.assertEqual(len(p.failures), 1)
        self.assertEqual(p.poll(3.6, 0x001)[0], R.POWER_CYCLE)
        d = p.done(3.6, None)  # the other controller power-cycled first
        self.assertEqual((d.kind, d.failures), (R.STOOD_DOWN, 2))
        self.assertEqual(p.poll(5.9, 0x001)[0], R.SWITCH_OVER)  # the third: switch over
        d = p.done(5.9, None)  # the other controller switched first
        self.assertEqual((d.kind, d.obc, p.active, p.failures), (R.STOOD_DOWN, 1, 1, []))
        p2 = R.Recovery(FAST)
        p2.start(0.0)
        p2.poll(1.0, 0x001)
        p2.poll(1.1, 0x000)
        p2.poll(1.3, 0x001)
        self.assertEqual(len(p2.failures), 1)
        p2.poll(1.5, 0x002)  # switched over by the other controller
        self.assertEqual((p2.failures, p2.active), ([], 1))

    def test_disabled(self):
        p = R.Recovery({"enabled": False})
        p.start(0.0)
        self.assertIsNone(p.poll(1000.0, 0x001))

    def test_decision_record_and_log(self):
        d = R.Decision(R.SWITCH_OVER, 1, 1, 3, 9, 12345, 678)
        e = R.Decision.unpack(d.pack())
        self.assertEqual((e.kind, e.line, e.obc, e.failures, e.count), (2, 1, 1, 3, 9))
        self.assertEqual((e.silence_ms, e.at_s), (12345, 678))
        log = R.log_unpack(R.log_pack([d, e]))
        self.assertEqual(len(log), 2)
        self.assertRaises(ValueError, R.Decision.unpack, b"\x01")


class TestMissionFile(unittest.TestCase):
    DOC = {"scid": 66, "nodes": [10, 11], "essential_map": 63, "hptm_vc": 6}

    def test_thresholds_delivered_with_the_ids(self):
        doc = dict(self.DOC, recovery={"deadline": 20.0, "max_failures": 2, "lines": [0, 1]})
        opts = mission.parse(doc)
        self.assertEqual(opts["recovery"]["deadline"], 20.0)
        self.assertEqual(R.Recovery(opts["recovery"]).max_failures, 2)
        self.assertTrue("recovery" not in mission.parse(dict(self.DOC)))

    def test_bad_thresholds_named(self):
        for bad in ({"deadline": 0}, {"lines": [3, 3]}, {"enabled": 1}, {"dead_line": 5}):
            with self.assertRaises(mission.MissionFileError) as cm:
                mission.parse(dict(self.DOC, recovery=bad))
            self.assertEqual(cm.exception.key, "recovery." + list(bad)[0])
        self.assertRaises(mission.MissionFileError, mission.parse, dict(self.DOC, recovery=[]))


def both_at_once(seed, mask, value, expect):
    """Both controllers start the same compare-and-set write at the same instant."""
    sim = DekkerSim(seed=seed)
    sim.q = 0x0F1
    for c in sim.ctrl:
        c.bits = sim.q
        c.write(mask, value, 3, expect)
    done = [False, False]
    while not (done[0] and done[1]):
        sim.now += sim.rng.below(sim.max_dt + 1)
        i = sim.rng.next() & 1
        if not done[i] and sim.ctrl[i].step(sim.now):
            done[i] = True
        if sim.ctrl[0].inside and sim.ctrl[1].inside:
            sim.counters["both_inside"] += 1
    return sim


class TestBothControllersDecide(unittest.TestCase):
    def test_power_cycle_acted_on_once(self):
        winners = [0, 0]
        for seed in range(1, 201):
            sim = both_at_once(seed, 0x001, 0x000, (0x001, 0x001))
            self.assertEqual(sim.q, 0x0F0)
            self.assertEqual(sim.counters["latches"], 1)
            self.assertEqual(sim.counters["both_inside"], 0)
            skipped = [c.skipped for c in sim.ctrl]
            self.assertEqual(skipped.count(True), 1)
            winners[skipped.index(False)] += 1
        self.assertTrue(winners[0] > 0)  # either can be first; the other always stands down

    def test_switch_over_acted_on_once(self):
        for seed in range(1, 101):
            sim = both_at_once(seed, 0x003, 0x002, (0x003, 0x001))
            self.assertEqual(sim.q, 0x0F2)
            self.assertEqual(sim.counters["latches"], 1)


class Rig:
    def __init__(self, hal=None, settings=FAST):
        self.hal = hal or ModelHal(0, rtc_seconds=days_from_civil(2026, 11, 24) * 86400)
        if hal is None:
            self.hal.q = 0x001  # the nominal OBC powered
        self.app = ReconfigApp(self.hal, recovery=settings)
        self.beats = 0
        self.rx = L.Decoder()
        self.got = []
        self.cadus = CaduDecoder(64)
        self.demux = TmDemultiplexer(0x42)
        self.decisions = []

    def now(self):
        return self.hal.now / 1000000

    def run(self, seconds, beat=None):
        end = self.now() + seconds
        next_beat = self.now()
        while self.now() < end:
            if beat is not None and self.now() >= next_beat:
                self.send(L.heartbeat(self.beats))
                self.beats += 1
                next_beat = self.now() + beat
            self.hal.idle(self.app.step())
            self.take()

    def send(self, data):
        self.hal.uart_rx[PORT_OBC].extend(data)

    def take(self):
        tx = self.hal.uart_tx
        if tx[PORT_OBC]:
            self.got += self.rx.feed(bytes(tx[PORT_OBC]))
            tx[PORT_OBC] = bytearray()
        if tx[PORT_COM]:
            for f in self.cadus.feed(bytes(tx[PORT_COM])):
                for p in self.demux.feed(f):
                    if ((p[0] & 7) << 8 | p[1]) == DECISION_APID:
                        self.decisions.append(R.Decision.unpack(p[6:]))
            tx[PORT_COM] = bytearray()

    def ask(self, frame):
        n = len(self.got)
        self.send(frame)
        for _ in range(100):
            self.hal.idle(self.app.step())
            self.take()
            if len(self.got) > n:
                return self.got[n]
        return None


class TestInTheApplication(unittest.TestCase):
    def test_heartbeats_keep_the_obc_on(self):
        r = Rig()
        r.run(6.0, beat=0.3)
        self.assertEqual(r.hal.q, 0x001)
        self.assertEqual(r.app.decisions, [])
        self.assertTrue(r.app.link_counters["heartbeats"] >= 19)

    def test_silence_power_cycles_then_switches_over(self):
        r = Rig()
        r.run(1.0, beat=0.3)
        seen = set()
        t = r.now()
        while r.now() < t + 12.0:
            r.run(0.01)
            seen.add(r.hal.q)
        self.assertIn(0x000, seen)  # the power cycle's off phase
        kinds = [d.kind for d in r.decisions]
        self.assertEqual(kinds[:3], [R.POWER_CYCLE, R.POWER_CYCLE, R.SWITCH_OVER])
        self.assertEqual(r.hal.q & 0x003, 0x002)  # the redundant OBC powered, the nominal off
        self.assertEqual([d.kind for d in r.app.decisions], kinds)
        # the log survives a reset of the controller
        r.hal.cause = RESET_WATCHDOG
        r2 = Rig(hal=r.hal)
        r2.app.step()
        self.assertEqual([d.kind for d in r2.app.decisions], kinds)
        r2.run(0.5, beat=0.1)  # the redundant OBC's heartbeats
        self.assertEqual(r2.hal.q & 0x003, 0x002)

    def test_context_kept_and_given_back(self):
        r = Rig()
        r.run(0.1)
        self.assertEqual(r.ask(L.encode(L.T_CONTEXT_READ)), (L.T_CONTEXT, b"\x01"))
        ctx = bytes(range(200))
        self.assertEqual(r.ask(L.encode(L.T_CONTEXT_WRITE, ctx)), (L.T_ACK, b"\x02\x00"))
        too_long = bytes(L.MAX_PAYLOAD)
        self.assertEqual(r.ask(L.encode(L.T_CONTEXT_WRITE, too_long)), (L.T_ACK, b"\x02\x02"))
        r2 = Rig(hal=r.hal)  # a controller reset in between
        r2.run(0.1)
        self.assertEqual(r2.ask(L.encode(L.T_CONTEXT_READ)), (L.T_CONTEXT, b"\x00" + ctx))

    def test_time_from_the_ds3231(self):
        r = Rig()
        r.run(0.1)
        got = r.ask(L.encode(L.T_TIME_READ))  # never set: its oscillator-stop flag is up
        self.assertEqual(got, (L.T_TIME, L.time_reply(L.NONE)[4:-2]))
        r.app.rtc.set_day_ms(days_from_civil(2026, 11, 24), 0)
        got = r.ask(L.encode(L.T_TIME_READ))
        self.assertEqual(got[0], L.T_TIME)
        status, day, ms = L.parse_time(got[1])
        self.assertEqual(status, L.OK)
        self.assertEqual(day, days_from_civil(2026, 11, 24))
        self.assertTrue(0 <= ms < 2000)


if __name__ == "__main__":
    unittest.main()
