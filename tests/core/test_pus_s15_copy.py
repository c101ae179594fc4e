"""ST[15] copy of a packet store's time window into another (TC[15,24]) and the diagnostic
parameter report storage-control configuration (TC[15,31], [15,32], [15,37], TM[15,38])."""

import unittest

from obsw.cfdp.filestore import MemoryFilestore
from obsw.pus.messages import FAILURE_REFUSED, FAILURE_UNKNOWN_ID
from obsw.pus.services.packet_store import BOUNDED, CIRCULAR
from obsw.pus.services.s15_layouts import COPY_WINDOW
from obsw.pus.services.s15_storage import Storage
from obsw.pus.services.s15_user import StorageUser
from obsw.pus.services.s17_test import ServiceTest, ServiceTestUser
from obsw.store import Store
from pus_loop import APID, Loop
from store_sim import SimFs


class Harness:
    def __init__(self, store=None):
        self.loop = Loop(store=store)
        self.fs = MemoryFilestore()
        self.loop.app.register(ServiceTest())
        self.storage = self.loop.app.register(Storage((), self.fs))
        self.user = self.loop.ground.register(StorageUser())
        self.test = self.loop.ground.register(ServiceTestUser())

    def run(self, tx):
        self.loop.pump()
        return tx

    def create(self, store, size=4000, kind=CIRCULAR):
        tx = self.run(
            self.user.create(APID, [{"store": store, "size": size, "kind": kind, "vc": 0}])
        )
        assert tx.ok

    def pings(self, times):
        """One TM[17,2] stored at each of ``times`` (the clock starts at 1000 s)."""
        for t in times:
            self.loop.clock.advance(t - self.loop.clock.now())
            self.run(self.test.ping(APID))

    def times(self, store):
        return [p[1] for p in self.storage.stores[store].packets]


def filled():
    h = Harness()
    h.create(1)
    assert h.run(h.user.add_types(APID, 1, {APID: {17: [2]}})).ok
    assert h.run(h.user.enable(APID, [1])).ok
    h.pings([1010.0, 1020.0, 1030.0, 1040.0])
    assert h.run(h.user.disable(APID, [1])).ok
    h.create(2)
    return h


class TestCopyByTimeWindow(unittest.TestCase):
    def test_from_to_after_before(self):
        h = filled()
        self.assertEqual(h.times(1), [1010.0, 1020.0, 1030.0, 1040.0])
        self.assertTrue(h.run(h.user.copy_window(APID, 1, 2, 1015.0, 1030.0)).ok)
        self.assertEqual(h.times(2), [1020.0, 1030.0])
        src = [p[2] for p in h.storage.stores[1].packets]
        self.assertEqual([p[2] for p in h.storage.stores[2].packets], src[1:3])  # unchanged
        self.assertEqual(h.times(1), [1010.0, 1020.0, 1030.0, 1040.0])  # the source stays
        h.create(3)
        self.assertTrue(h.run(h.user.copy_window(APID, 1, 3, start=1030.0)).ok)
        self.assertEqual(h.times(3), [1030.0, 1040.0])
        h.create(4)
        self.assertTrue(h.run(h.user.copy_window(APID, 1, 4, end=1010.0)).ok)
        self.assertEqual(h.times(4), [1010.0])
        self.assertEqual(h.storage.copied, 5)
        # the copy is a store like any other: retrieved, summarised by its storage times
        tx = h.run(h.user.report_summary(APID, [2]))
        self.assertEqual(
            (tx.reply["stores"][0]["oldest"], tx.reply["stores"][0]["newest"]), (1020.0, 1030.0)
        )

    def test_bounds_at_the_time_tags_resolution(self):
        h = Harness()
        h.create(1)
        h.run(h.user.add_types(APID, 1, {APID: {17: [2]}}))
        h.run(h.user.enable(APID, [1]))
        h.pings([1010.3, 1020.7])  # not whole 1/65536 s: the tags round them
        h.create(2)
        self.assertTrue(h.run(h.user.copy_window(APID, 1, 2, 1010.3, 1020.7)).ok)
        self.assertEqual(len(h.storage.stores[2].packets), 2)

    def test_an_empty_window_copies_nothing(self):
        h = filled()
        self.assertTrue(h.run(h.user.copy_window(APID, 1, 2, 2000.0, 3000.0)).ok)
        self.assertEqual(h.times(2), [])

    def test_refusals(self):
        h = filled()
        for tx, code in (
            (h.user.copy_window(APID, 1, 9, 0.0, 5000.0), FAILURE_UNKNOWN_ID),
            (h.user.copy_window(APID, 9, 2, 0.0, 5000.0), FAILURE_UNKNOWN_ID),
            (h.user.copy_window(APID, 1, 1, 0.0, 5000.0), FAILURE_REFUSED),
            (h.user.copy_window(APID, 1, 2, 1030.0, 1020.0), FAILURE_REFUSED),
        ):
            h.run(tx)
            self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, code))
        data = COPY_WINDOW.pack({"window": 7, "tag1": 0, "tag2": 0, "source": 1, "target": 2})
        tx = h.run(h.user.request(APID, (15, 24), data))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # no such window type
        self.assertTrue(h.run(h.user.copy_window(APID, 1, 2, 1000.0, 1015.0)).ok)
        tx = h.run(h.user.copy_window(APID, 1, 2, 1000.0, 1015.0))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # the target is not empty
        one = len(h.storage.stores[1].packets[0][2])
        h.create(5, size=one, kind=BOUNDED)
        tx = h.run(h.user.copy_window(APID, 1, 5, 1000.0, 1025.0))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # two packets, room for one
        self.assertEqual(h.times(5), [])
        h.create(6, size=one, kind=CIRCULAR)
        self.assertTrue(h.run(h.user.copy_window(APID, 1, 6, 1000.0, 1025.0)).ok)
        self.assertEqual(h.times(6), [1020.0])  # circular: the newest stay


class TestDiagnosticStorageControl(unittest.TestCase):
    def test_diagnostic_reports_are_selected_by_structure(self):
        h = Harness()
        h.create(1)
        self.assertTrue(h.run(h.user.add_types(APID, 1, {APID: {3: [25, 26]}})).ok)
        self.assertTrue(h.run(h.user.enable(APID, [1])).ok)
        tx = h.run(h.user.report_diag(APID, 1))
        self.assertEqual(tx.reply, {"store": 1, "diag": {APID: []}})  # initially every one
        self.assertEqual(h.loop.types()[-2:], [(15, 38), (1, 7)])
        self.assertTrue(h.run(h.user.delete_diag(APID, 1, {APID: []})).ok)
        self.assertTrue(h.run(h.user.add_diag(APID, 1, {APID: [5, 6]})).ok)
        self.assertEqual(h.run(h.user.report_diag(APID, 1)).reply["diag"], {APID: [5, 6]})
        for sid in (5, 7, 6):
            h.loop.app.send_tm(3, 26, bytes((0, sid, 1, 2)))
        stored = [p[2] for p in h.storage.stores[1].packets]
        self.assertEqual([raw[h.loop.app.config.tm_data_offset + 1] for raw in stored], [5, 6])
        self.assertTrue(h.run(h.user.delete_diag(APID, 1, {APID: [5]})).ok)
        self.assertEqual(h.run(h.user.report_diag(APID, 1)).reply["diag"], {APID: [6]})

    def test_refusals(self):
        h = Harness()
        h.create(1)
        tx = h.run(h.user.delete_diag(APID, 1, {APID: [9]}))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # every ID is selected
        tx = h.run(h.user.delete_diag(APID, 1, {99: [1]}))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)
        tx = h.run(h.user.add_diag(APID, 8, {APID: [1]}))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)
        tx = h.run(h.user.report_diag(APID, 8))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)

    def test_the_configuration_survives_a_restart(self):
        store = Store("ctx", SimFs())
        h = Harness(store)
        h.create(1)
        h.run(h.user.delete_diag(APID, 1, {APID: []}))
        h.run(h.user.add_diag(APID, 1, {APID: [3]}))
        h2 = Harness(store)
        self.assertEqual(h2.run(h2.user.report_diag(APID, 1)).reply["diag"], {APID: [3]})


if __name__ == "__main__":
    unittest.main()
