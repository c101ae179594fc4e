"""The reconfiguration application on the in-memory hardware layer: SpaceCAN functions, time
sync, essential commands and telemetry, reset counters in the safeguard memory, health."""

import unittest

from obsw.frames import cltu, tc
from obsw.frames.asm import CaduDecoder
from obsw.frames.tm_demux import TmDemultiplexer
from obsw.reconfig import essential as E
from obsw.reconfig.app import H_LOOP, ReconfigApp
from obsw.reconfig.hal import REDUNDANT, RESET_WATCHDOG
from obsw.reconfig.models import ModelHal
from obsw.reconfig.node import NODE_NOMINAL, definition
from obsw.spacecan.controller import COMPLETED, FAILED, Controller
from obsw.utc import days_from_civil

SCID = 0x42


def hpc_cltu(hpc, seq=0):
    frame = tc.TcFrame(SCID, 0, tc.Segment(63, hpc.packet()).pack(), seq, bypass=True)
    return cltu.encode(frame.pack())


class Rig:
    def __init__(self, role=0, hal=None, security=None):
        self.hal = hal or ModelHal(role, rtc_seconds=days_from_civil(2025, 1, 1) * 86400)
        self.app = ReconfigApp(self.hal, essential_security=security)
        self.ctrl = Controller(heartbeat_period=0.5)
        self.ctrl.add_node(NODE_NOMINAL, definition(NODE_NOMINAL))
        self.ctrl.start(0.0)

    def now(self):
        return self.hal.now / 1000000

    def step(self, n=1):
        for _ in range(n):
            for bus, can_id, data in self.ctrl.take_frames():
                self.hal.can_rx[bus].append((can_id, data))
            ms = self.app.step()
            self.at = self.now()  # the time of the last pass (the idle after it moves on)
            self.hal.idle(ms)
            for bus, can_id, data in self.hal.can_tx:
                self.ctrl.receive(bus, can_id, data, self.now())
            self.hal.can_tx = []
            self.ctrl.poll(self.now())

    def until(self, predicate, limit=3000):
        for _ in range(limit):
            if predicate():
                return True
            self.step()
        return predicate()


class TestSpaceCan(unittest.TestCase):
    def test_set_state_bits_and_friends(self):
        r = Rig()
        r.step(5)
        req = r.ctrl.call_function(NODE_NOMINAL, 1, now=r.now(), args={1: 0x0F0})
        self.assertTrue(r.until(lambda: req.done))
        self.assertEqual(req.status, COMPLETED)
        self.assertEqual(r.hal.q, 0x0F0)
        req = r.ctrl.call_function(NODE_NOMINAL, 2, now=r.now(), args={1: 0x001})
        r.until(lambda: req.done)
        req = r.ctrl.call_function(NODE_NOMINAL, 3, now=r.now(), args={1: 0x010})
        r.until(lambda: req.done)
        self.assertEqual(r.hal.q, 0x0E1)
        r.step(150)  # status refresh
        req = r.ctrl.request_parameters(NODE_NOMINAL, [1, 7], r.now())
        r.until(lambda: req.done)
        self.assertEqual(req.result[1], 0x0E1)
        self.assertTrue(req.result[7] & H_LOOP)

    def test_store_context_survives_reset(self):
        r = Rig()
        r.step(3)
        req = r.ctrl.call_function(NODE_NOMINAL, 6, now=r.now(), args={1: 123456})
        r.until(lambda: req.done)
        self.assertEqual(req.status, COMPLETED)
        r.hal.cause = RESET_WATCHDOG
        r2 = Rig(hal=r.hal)
        r2.step(1)
        self.assertEqual(r2.app.context, 123456)
        self.assertEqual(r2.app.boots, 2)
        self.assertEqual(r2.app.resets, [1, 1, 0, 0])

    def test_failed_cpdu_access_reports_failure(self):
        r = Rig()
        r.step(3)
        r.hal.other = 1  # the other controller never lets go
        req = r.ctrl.call_function(NODE_NOMINAL, 1, now=r.now(), args={1: 1})
        r.until(lambda: req.done)
        self.assertEqual(req.status, FAILED)

    def test_utc_frame_syncs_the_rtc(self):
        r = Rig()
        r.step(3)
        day = days_from_civil(2025, 6, 1)
        r.ctrl.send_utc(day, 43200250, now=r.now())
        r.until(lambda: r.app.sync.counters["sets"] == 1)
        self.assertEqual(r.app.rtc.day_ms()[0], day)
        self.assertTrue(abs(r.app.rtc.day_ms()[1] - 43201000) <= 1000)


class TestEssential(unittest.TestCase):
    def test_hpc_round_trip_and_errors(self):
        h = E.Hpc(E.HPC_POWER_CYCLE, (3, 500), E.TARGET_BOTH)
        self.assertEqual(E.Hpc.unpack(h.pack()), h)
        self.assertEqual(E.hpc_of_unit(h.packet()), h)
        for bad in (b"", b"\x09\x00", b"\x02\x00\x01", b"\x04\x07"):
            with self.assertRaises(E.HpcError):
                E.Hpc.unpack(bad)

    def test_power_cycle_and_hptm(self):
        r = Rig()
        r.step(3)
        r.app.lines(0xFFF, 0x003)
        r.hal.uart_rx[0].extend(hpc_cltu(E.Hpc(E.HPC_POWER_CYCLE, (0, 300))))
        r.until(lambda: r.hal.q == 0x002)
        t_off = r.at  # the pass that switched the line off
        r.until(lambda: r.hal.q == 0x003)
        self.assertTrue(r.at - t_off >= 0.3)
        self.assertEqual(r.app.essential.counters["hpcs"], 1)
        r.step(10)
        dec = CaduDecoder(64)
        demux = TmDemultiplexer(SCID)
        reports = []
        for f in dec.feed(r.hal.uart_tx[0]):
            for p in demux.feed(f):
                reports.append(E.Report.unpack(p[6:]))
        self.assertTrue(len(reports) >= 2)
        last = reports[-1]
        self.assertEqual(last.cpdu, 0x003)
        self.assertEqual(last.last_hpc, E.HPC_POWER_CYCLE)
        self.assertEqual(last.last_status, E.STATUS_DONE)
        self.assertEqual(last.boots, 1)
        self.assertEqual(E.Report.unpack(last.pack()).to_dict(), last.to_dict())

    def test_select_obc_and_bad_hpc(self):
        r = Rig()
        r.step(2)
        r.hal.uart_rx[0].extend(hpc_cltu(E.Hpc(E.HPC_SELECT_OBC, (1,))))
        r.until(lambda: r.hal.q == 0x002)
        self.assertEqual(r.hal.q, 0x002)
        r.hal.uart_rx[0].extend(hpc_cltu(E.Hpc(E.HPC_POWER_CYCLE, (20, 10)), 1))
        r.step(5)
        self.assertEqual(r.app.essential.last_status, E.STATUS_REJECTED)

    def test_redundant_takes_over_when_nominal_stops(self):
        r = Rig(role=REDUNDANT)
        r.hal.alive_other = 0
        r.hal.other_alive = lambda: r.hal.alive_other
        for _ in range(20):
            r.hal.alive_other ^= 1
            r.step()
        r.hal.uart_rx[0].extend(hpc_cltu(E.Hpc(E.HPC_LINES, (0x00F, 0x005))))
        r.step(5)
        self.assertEqual(r.app.essential.last_status, E.STATUS_NOT_MINE)
        self.assertEqual(r.hal.q, 0)
        r.until(lambda: r.app.in_charge())  # the nominal's alive line stands still
        r.hal.uart_rx[0].extend(hpc_cltu(E.Hpc(E.HPC_LINES, (0x00F, 0x005)), 1))
        r.until(lambda: r.hal.q == 0x005)
        self.assertEqual(r.hal.q, 0x005)


def essential_sa():
    from obsw.frames.sdls import SecurityAssociation, TcSecurity

    return TcSecurity([SecurityAssociation(2, 0, bytes(range(32)), map_id=63)])


class TestAuthenticatedHpcs(unittest.TestCase):
    """The anti-replay window of the essential TCs lives in the safeguard memory: a frame
    accepted before a reset is refused after it."""

    def signed_cltu(self, ground, hpc):
        data = ground.apply(SCID, 0, tc.Segment(63, hpc.packet()).pack(), True)
        return cltu.encode(tc.TcFrame(SCID, 0, data, 0, True).pack())

    def test_replay_after_reset_refused(self):
        ground = essential_sa()
        r = Rig(security=essential_sa())
        r.step(3)
        first = self.signed_cltu(ground, E.Hpc(E.HPC_LINES, (0x00F, 0x003)))
        r.hal.uart_rx[0].extend(first)
        self.assertTrue(r.until(lambda: r.hal.q == 0x003))
        r.hal.cause = RESET_WATCHDOG
        r2 = Rig(hal=r.hal, security=essential_sa())  # a fresh window, as after any reset
        r2.step(3)
        r2.hal.uart_rx[0].extend(first)
        r2.step(5)
        counters = r2.app.essential.frames.security.counters
        self.assertEqual((counters["ok"], counters["replay"]), (0, 1))
        self.assertEqual(r2.app.essential.counters["hpcs"], 0)
        r2.hal.uart_rx[0].extend(self.signed_cltu(ground, E.Hpc(E.HPC_LINES, (0x00F, 0x00C))))
        self.assertTrue(r2.until(lambda: r2.hal.q == 0x00C))
        self.assertEqual(r2.app.essential.frames.security.sas[2].window.top, 2)

    def test_saved_before_the_lines_change(self):
        ground = essential_sa()
        r = Rig(security=essential_sa())
        r.step(3)
        writes = r.app.sgm.counters["writes"]
        r.hal.uart_rx[0].extend(self.signed_cltu(ground, E.Hpc(E.HPC_LINES, (0x00F, 0x003))))
        while r.hal.q != 0x003:
            r.step()
            if r.app.sgm.counters["writes"] == writes:
                self.assertEqual(r.hal.q, 0)  # no line changed before the window was saved
        self.assertEqual(r.app.sgm.read(2), b"\x00\x02\x00\x00\x00\x01")

    def test_rejected_frames_in_the_report(self):
        r = Rig(security=essential_sa())
        r.step(3)
        signed = self.signed_cltu(essential_sa(), E.Hpc(E.HPC_LINES, (0x00F, 0x003)))
        unsigned = hpc_cltu(E.Hpc(E.HPC_LINES, (0x00F, 0x003)))
        r.hal.uart_rx[0].extend(signed)
        r.step(3)
        r.hal.uart_rx[0].extend(signed)  # a replay now
        r.hal.uart_rx[0].extend(unsigned)
        r.step(5)
        rep = E.Report.unpack(r.app.report().pack())
        self.assertEqual((rep.version, rep.tc_rejected, rep.hpcs), (2, 2, 1))

    def test_version_1_report_decodes(self):
        v2 = E.Report(boots=7, uptime=99, tc_rejected=3).pack()
        self.assertEqual(len(v2), 31)
        v1 = b"\x01" + v2[1:29]
        rep = E.Report.unpack(v1)
        self.assertEqual((rep.version, rep.boots, rep.uptime, rep.tc_rejected), (1, 7, 99, 0))
        with self.assertRaises(ValueError):
            E.Report.unpack(v2[:30])

    def test_without_security_nothing_is_written(self):
        r = Rig()
        r.step(3)
        self.assertIsNone(r.app.sgm.read(2))


class TestHealth(unittest.TestCase):
    def test_loop_error_stops_the_watchdog_kicks(self):
        r = Rig()
        r.step(200)
        self.assertTrue(r.hal.kick_count > 3)

        def broken(port):
            raise OSError(5)

        r.hal.uart_read = broken
        n = r.hal.kick_count
        r.step(100)
        self.assertTrue(r.app.counters["loop_errors"] > 0)
        self.assertEqual(r.hal.kick_count, n)
        self.assertFalse(r.app.healthy(r.now()))


class TestIdle(unittest.TestCase):
    def test_the_loop_idles_until_its_next_deadline(self):
        r = Rig()
        r.step(5)
        ms = r.app.step()
        now_ms = r.hal.now // 1000
        kick = r.app.watchdog.next_deadline()
        self.assertTrue(0 <= ms <= max(0, kick - now_ms) + 1)
        self.assertTrue(ms <= r.app.takeover_ms // 4)
        # ten seconds of a quiet bus: far fewer passes than a 10 ms poll, no kick late
        steps = r.app.counters["steps"]
        end = r.hal.now + 10_000_000
        while r.hal.now < end:
            r.step()
        passes = r.app.counters["steps"] - steps
        self.assertTrue(passes < 500, passes)
        self.assertEqual(r.app.watchdog.late, 0)
        self.assertTrue(r.app.watchdog.kicks >= 10_000 // r.app.watchdog.target_ms - 1)
