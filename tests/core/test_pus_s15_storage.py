"""ST[15]: packet stores, storage control, retrieval by time, by sequence and open retrieval,
provider against user; stores survive a restart (and a cut in the middle of a write)."""

import unittest

from obsw.cfdp.filestore import MemoryFilestore
from obsw.pus.messages import FAILURE_REFUSED, FAILURE_UNKNOWN_ID
from obsw.pus.services.packet_store import BOUNDED, CIRCULAR, pack_record, unpack_records
from obsw.pus.services.s05_events import EventReporting
from obsw.pus.services.s14_forwarding import ForwardingControl, ForwardingUser
from obsw.pus.services.s15_storage import Storage
from obsw.pus.services.s15_user import StorageUser
from obsw.pus.services.s17_test import ServiceTest, ServiceTestUser
from obsw.store import Store
from pus_loop import APID, Loop
from store_sim import SimFs


class Harness:
    def __init__(self, store=None, fs=None, initial=(), rate=16):
        self.loop = Loop(store=store)
        self.played = []  # (raw, vc) sent on the playback channel
        self.fs = fs if fs is not None else MemoryFilestore()
        app = self.loop.app
        app.register(ServiceTest())
        app.register(EventReporting())
        self.storage = app.register(Storage(initial, self.fs, rate=rate))
        self.fwd = app.register(ForwardingControl())
        app.playback = self.playback
        self.user = self.loop.ground.register(StorageUser())
        self.fwd_user = self.loop.ground.register(ForwardingUser())
        self.test = self.loop.ground.register(ServiceTestUser())

    def playback(self, raw, vc):
        self.played.append((raw, vc))
        self.loop.down.append(raw)

    def run(self, tx):
        self.loop.pump()
        return tx

    def pings(self, n, step=10.0):
        for _ in range(n):
            self.loop.clock.advance(step)
            self.run(self.test.ping(APID))

    def cycle(self, n=1):
        for _ in range(n):
            self.loop.app.tick()
        self.loop.pump()

    def played_types(self):
        return [(r[7], r[8]) for r, vc in self.played]


def with_store(h, size=4000, kind=CIRCULAR, vc=2, types=None):
    u = h.user
    assert h.run(u.create(APID, [{"store": 1, "size": size, "kind": kind, "vc": vc}])).ok
    assert h.run(u.add_types(APID, 1, types or {APID: {17: [2]}})).ok
    assert h.run(u.enable(APID, [1])).ok
    return h.storage.stores[1]


class TestStores(unittest.TestCase):
    def test_create_configure_report_delete(self):
        h = Harness()
        u = h.user
        st = with_store(h)
        tx = h.run(u.report_configuration(APID))
        self.assertEqual(tx.reply, {"stores": [{"store": 1, "size": 4000, "kind": 0, "vc": 2}]})
        tx = h.run(u.create(APID, [{"store": 1, "size": 10, "kind": 0, "vc": 0}]))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)
        tx = h.run(u.create(APID, [{"store": 2, "size": 10, "kind": 7, "vc": 0}]))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)
        self.assertEqual(
            h.run(u.report_types(APID, 1)).reply, {"store": 1, "types": {APID: {17: [2]}}}
        )
        tx = h.run(u.delete(APID, [1]))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # storage still enabled
        for tx in (u.report_types(APID, 9), u.enable(APID, [9]), u.report_summary(APID, [9])):
            h.run(tx)
            self.assertEqual(
                (tx.failure["code"], tx.failure["data"]), (FAILURE_UNKNOWN_ID, b"\x00\x09")
            )
        self.assertTrue(h.run(u.disable(APID)).ok)
        self.assertFalse(st.enabled)
        self.assertTrue(h.run(u.resize(APID, {1: 100})).ok)
        self.assertTrue(h.run(u.make_bounded(APID, [1])).ok)
        self.assertTrue(h.run(u.change_vc(APID, 1, 5)).ok)
        tx = h.run(u.report_configuration(APID))
        self.assertEqual(tx.reply["stores"], [{"store": 1, "size": 100, "kind": BOUNDED, "vc": 5}])
        self.assertTrue(h.run(u.make_circular(APID, [1])).ok)
        self.assertTrue(h.run(u.delete(APID, [1])).ok)
        self.assertEqual(h.storage.stores, {})
        self.assertFalse(h.fs.exists("stores/store-1.log"))

    def test_storage_control_selects_packets(self):
        h = Harness()
        st = with_store(h)
        h.pings(3)
        self.assertEqual(len(st.packets), 3)  # only the TM[17,2]
        self.assertTrue(all(p[2][7:9] == b"\x11\x02" for p in st.packets))
        self.assertTrue(h.run(h.user.add_types(APID, 1, {APID: {1: [1, 7]}})).ok)
        h.pings(1)
        self.assertEqual(len(st.packets), 3 + 2 + 2)  # the add's completion, then 3 of the ping
        tx = h.run(h.user.delete_types(APID, 1, {APID: {1: []}}))
        self.assertTrue(tx.ok)
        tx = h.run(h.user.delete_types(APID, 1, {APID: {3: []}}))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)
        self.assertEqual(h.run(h.user.report_types(APID, 1)).reply["types"], {APID: {17: [2]}})
        tx = h.run(h.user.delete_types(APID, 1, {}))
        self.assertTrue(tx.ok)
        n = len(st.packets)
        h.pings(2)
        self.assertEqual(len(st.packets), n)

    def test_housekeeping_and_event_control(self):
        h = Harness()
        u = h.user
        st = with_store(h, types={APID: {3: [25], 5: []}})
        self.assertEqual(h.run(u.report_hk(APID, 1)).reply, {"store": 1, "hk": {APID: []}})
        self.assertTrue(h.run(u.delete_hk(APID, 1, {APID: []})).ok)
        self.assertTrue(h.run(u.add_hk(APID, 1, {APID: [4]})).ok)
        self.assertEqual(h.run(u.report_hk(APID, 1)).reply, {"store": 1, "hk": {APID: [4]}})
        h.loop.app.send_tm(3, 25, b"\x00\x04\x01")
        h.loop.app.send_tm(3, 25, b"\x00\x05\x01")
        self.assertEqual([p[2][19:21] for p in st.packets], [b"\x00\x04"])
        tx = h.run(u.delete_hk(APID, 1, {APID: [5]}))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)
        self.assertTrue(h.run(u.add_blocked(APID, 1, {APID: [7]})).ok)
        self.assertEqual(
            h.run(u.report_blocked(APID, 1)).reply, {"store": 1, "blocked": {APID: [7]}}
        )
        h.loop.app.event(7, 2)
        h.loop.app.event(8, 2)
        self.assertEqual(len(st.packets), 2)
        self.assertTrue(h.run(u.delete_blocked(APID, 1, {APID: [7]})).ok)
        self.assertTrue(h.run(u.delete_hk(APID, 1, {APID: [4]})).ok)
        h.loop.app.event(7, 2)
        h.loop.app.send_tm(3, 25, b"\x00\x04\x01")
        self.assertEqual(len(st.packets), 3)

    def test_circular_and_bounded(self):
        h = Harness()
        st = with_store(h, size=100)
        h.pings(6)  # a TM[17,2] is 21 octets
        self.assertEqual(len(st.packets), 4)
        self.assertEqual(st.overwritten, 2)
        self.assertEqual(st.packets[0][0], 3)
        self.assertTrue(h.run(h.user.disable(APID)).ok)
        self.assertTrue(h.run(h.user.make_bounded(APID, [1])).ok)
        self.assertTrue(h.run(h.user.enable(APID)).ok)
        h.pings(2)
        self.assertEqual(len(st.packets), 4)
        self.assertEqual(st.rejected, 2)
        self.assertEqual(h.loop.app.counters["store_full"], 2)
        tx = h.run(h.user.report_summary(APID))
        s = tx.reply["stores"][0]
        self.assertEqual((s["fill"], s["count"], s["first_seq"], s["last_seq"]), (84, 4, 3, 6))
        self.assertTrue(h.run(h.user.disable(APID)).ok)
        tx = h.run(h.user.resize(APID, {1: 50}))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # bounded, holds more


class TestRetrieval(unittest.TestCase):
    def test_by_time_range_on_the_playback_channel(self):
        h = Harness(rate=2)
        st = with_store(h)
        h.pings(5)  # stored at 1010, 1020 .. 1050
        u = h.user
        tx = h.run(u.retrieve_time(APID, 1, 1015, 1045))
        self.assertTrue(tx.ok)
        h.cycle()
        self.assertEqual(len(h.played), 2)  # two per cycle
        self.assertEqual(h.run(u.report_status(APID)).reply["stores"][0]["range_retrieval"], True)
        tx = h.run(u.retrieve_time(APID, 1, 0, 2000))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # one at a time
        h.cycle(2)
        self.assertEqual([r for r, vc in h.played], [p[2] for p in st.packets[1:4]])
        self.assertEqual({vc for r, vc in h.played}, {2})
        self.assertEqual(h.storage.stores[1].range_queue, None)
        tx = h.run(u.retrieve_time(APID, 1, 1050, 1010))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)

    def test_by_sequence_and_abort(self):
        h = Harness(rate=1)
        st = with_store(h)
        h.pings(5)
        u = h.user
        self.assertTrue(h.run(u.retrieve_sequence(APID, 1, 2, 4)).ok)
        h.cycle()
        self.assertEqual(h.played[0][0], st.packets[1][2])
        self.assertTrue(h.run(u.abort_retrieval(APID, [1])).ok)
        h.cycle(3)
        self.assertEqual(len(h.played), 1)
        self.assertTrue(h.run(u.retrieve_sequence(APID, 1, 5, 99)).ok)
        h.cycle(3)
        self.assertEqual(h.played[-1][0], st.packets[4][2])

    def test_open_retrieval_follows_the_store(self):
        h = Harness(rate=3)
        st = with_store(h)
        u = h.user
        h.pings(4)  # 1010 .. 1040
        self.assertTrue(h.run(u.change_open_start(APID, 1025, [1])).ok)
        self.assertTrue(h.run(u.resume_open(APID, [1])).ok)
        tx = h.run(u.change_open_start(APID, 0, [1]))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # running
        h.cycle()
        self.assertEqual([r for r, vc in h.played], [p[2] for p in st.packets[2:4]])
        h.pings(1)
        h.cycle()
        self.assertEqual(h.played[-1][0], st.packets[4][2])
        s = h.run(u.report_summary(APID, [1])).reply["stores"][0]
        self.assertEqual((s["open_start"], s["fill_open"]), (1025.0, 0))
        tx = h.run(u.delete_content(APID, 2000, [1]))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # being retrieved
        self.assertTrue(h.run(u.suspend_open(APID, [1])).ok)
        h.pings(1)
        h.cycle()
        self.assertEqual(len(h.played), 3)
        status = h.run(u.report_status(APID)).reply["stores"][0]
        self.assertEqual(
            status,
            {"store": 1, "storage": True, "open_retrieval": False, "range_retrieval": False},
        )
        self.assertTrue(h.run(u.delete_content(APID, 1035, [1])).ok)
        self.assertEqual([p[0] for p in st.packets], [4, 5, 6])


class TestPersistence(unittest.TestCase):
    def test_stores_survive_a_restart(self):
        ctx = SimFs()
        fs = MemoryFilestore()
        h = Harness(Store("/ctx", ctx), fs)
        st = with_store(h)
        h.pings(4)
        h.run(h.user.change_open_start(APID, 1025, [1]))
        saved = [list(p) for p in st.packets]
        h2 = Harness(Store("/ctx", ctx), fs)
        st2 = h2.storage.stores[1]
        self.assertEqual([list(p) for p in st2.packets], saved)
        self.assertEqual((st2.enabled, st2.vc, st2.open_start), (True, 2, 1025.0))
        self.assertEqual(
            h2.storage.controls[1].types.as_list(),
            [{"apid": APID, "services": [{"service": 17, "subtypes": [2]}]}],
        )
        h2.loop.clock = h.loop.clock
        h2.pings(1)
        self.assertEqual(st2.packets[-1][0], 5)  # the sequence goes on

    def test_a_write_cut_short_loses_only_that_packet(self):
        fs = MemoryFilestore()
        ctx = SimFs()
        h = Harness(Store("/ctx", ctx), fs)
        st = with_store(h)
        h.pings(3)
        fs.files["stores/store-1.log"].extend(pack_record(9, 1.0, b"x" * 40)[:30])
        h2 = Harness(Store("/ctx", ctx), fs)
        self.assertEqual([p[0] for p in h2.storage.stores[1].packets], [1, 2, 3])
        records, good = unpack_records(bytes(fs.files["stores/store-1.log"]))
        self.assertEqual(len(records), 3)
        self.assertEqual(good, len(fs.files["stores/store-1.log"]))  # the torn tail is gone
        self.assertEqual(st.next_seq, 4)

    def test_log_is_compacted_atomically(self):
        fs = MemoryFilestore()
        h = Harness(None, fs)
        st = with_store(h, size=100)
        h.pings(30)
        size = len(fs.files["stores/store-1.log"])
        self.assertTrue(size <= 2 * 100 + 64 + 40)
        records, good = unpack_records(bytes(fs.files["stores/store-1.log"]))
        self.assertEqual(records[-1][0], st.packets[-1][0])

    def test_initial_stores(self):
        h = Harness(
            initial=[
                {"id": 3, "size": 500, "kind": BOUNDED, "enabled": True, "types": {APID: {17: []}}}
            ]
        )
        h.pings(2)
        self.assertEqual(len(h.storage.stores[3].packets), 2)


if __name__ == "__main__":
    unittest.main()
