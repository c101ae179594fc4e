"""Parameter values set through service 20 survive a restart of the PUS process: saved in the
context store, set again on components when they (re)appear, given to local setters."""

import unittest

from obsw.il.node import Node
from obsw.pus.parameters import STORE_NAME, ParameterPool
from obsw.pus.sdb import loads
from obsw.pus.services.s20_parameters import ParameterManagement, ParameterUser
from obsw.store import Store
from pus_loop import APID, SDB, Loop
from store_sim import SimFs
from test_pus_pool import PANEL, Panel

# the test database with two writable parameters of no component: a gain and a key
LOCAL = SDB.replace(
    '"parameters": [{"name": "count", "id": 100, "type": "uint32"}]',
    '"parameters": [{"name": "count", "id": 100, "type": "uint32"},'
    ' {"name": "gain", "id": 101, "type": "int16", "writable": true},'
    ' {"name": "key", "id": 102, "type": "octets", "writable": true}]',
)


class Process:
    """One start of a PUS process: a fresh node, panel and pool on the same context store."""

    def __init__(self, files, panel_up=True):
        self.db = loads(LOCAL)
        self.store = Store("/ctx", SimFs(files))
        self.node = Node("pus")
        self.panel = Panel()
        self.provider = self.node.provide(PANEL, self.panel) if panel_up else None
        self.loop = Loop(store=self.store)
        self.pool = ParameterPool(self.db, self.node)
        self.held = self.pool.persist(self.store)
        self.pool.bind()
        self.loop.app.register(ParameterManagement(self.pool))
        db = self.db
        self.user = self.loop.ground.register(
            ParameterUser(
                lambda pid: db.parameter(pid).type,
                lambda pid: db.parameter(pid).qualified,
                lambda k: db.parameter(k).id,
            )
        )

    def set(self, values):
        tx = self.loop.run_async(lambda: self.user.set(APID, values))
        return tx


class TestPersistedParameters(unittest.TestCase):
    def test_component_values_come_back_after_a_restart(self):
        files = {}
        first = Process(files)
        self.assertEqual(first.held, 0)
        tx = first.set({"Panel.speed": 4.0, "Panel.mode": 3})
        self.assertTrue(tx.ok)
        second = Process(files)  # the panel starts with its defaults again
        self.assertEqual(second.held, 2)
        self.assertEqual((second.panel.speed, second.panel.mode), (4.0, 3))
        self.assertEqual(second.pool.get(2), 4.0)
        self.assertEqual(second.pool.reapplied, 2)

    def test_a_component_that_appears_later_gets_its_values(self):
        files = {}
        Process(files).set({"Panel.mode": 7})
        later = Process(files, panel_up=False)
        self.assertEqual(later.pool.reapplied, 0)
        panel = Panel()
        later.node.provide(PANEL, panel)
        later.pool.refresh()
        self.assertEqual(panel.mode, 7)
        self.assertEqual(later.pool.get(3), 7)

    def test_a_component_that_restarts_gets_its_values_again(self):
        files = {}
        p = Process(files)
        p.set({"Panel.mode": 5})
        fresh = Panel()  # the component comes back (a new provider, its defaults)
        p.node.provide(PANEL, fresh)
        p.pool.refresh()
        self.assertEqual(fresh.mode, 5)

    def test_values_of_no_component_and_local_setters(self):
        files = {}
        first = Process(files)
        self.assertTrue(first.set({"gain": -12, "key": b"\x00\xffk"}).ok)
        second = Process(files)
        self.assertEqual(second.pool.get(101), -12)
        self.assertEqual(second.pool.get(102), b"\x00\xffk")
        got = []
        second.pool.provide("gain", lambda: 0, got.append)
        self.assertEqual(got, [-12])

    def test_last_value_wins(self):
        files = {}
        p = Process(files)
        p.set({"Panel.mode": 1})
        p.set({"Panel.mode": 2})
        self.assertEqual(Process(files).panel.mode, 2)

    def test_a_refused_set_is_not_saved(self):
        files = {}
        p = Process(files)
        self.assertFalse(p.set({"Panel.speed": 50.0}).ok)  # the panel refuses above 10
        self.assertEqual(Process(files).held, 0)

    def test_bad_saved_entries_are_counted_not_raised(self):
        files = {}
        Store("/ctx", SimFs(files)).save(STORE_NAME, {"999": 1, "3": "text", "x": 1, "2": 3.5})
        p = Process(files)
        self.assertEqual(p.pool.rejected, 3)
        self.assertEqual(p.panel.speed, 3.5)


if __name__ == "__main__":
    unittest.main()
