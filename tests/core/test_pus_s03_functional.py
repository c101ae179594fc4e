"""ST[03] parameter functional reporting (37 to 44): definitions created, reported, changed
and applied, provider against user."""

import unittest

from obsw.pus.parameters import ParameterPool
from obsw.pus.services.s01_verification import FAILURE_REFUSED, FAILURE_UNKNOWN_ID
from obsw.pus.services.s03_housekeeping import Housekeeping, HousekeepingUser
from obsw.store import Store
from pus_loop import APID, Loop, sdb
from store_sim import SimFs

HK = [
    {"sid": 1, "interval": 2, "parameters": [1, 2, 3], "enabled": False},
    {"sid": 2, "interval": 5, "parameters": [4], "enabled": True},
]
DIAG = [{"sid": 1, "interval": 1, "parameters": [1], "enabled": False}]


def make(store=None):
    db = sdb()
    loop = Loop(store=store)
    pool = ParameterPool(db)
    hk = loop.app.register(Housekeeping(pool, HK, diagnostic=DIAG))
    user = loop.ground.register(
        HousekeepingUser(lambda pid: db.parameter(pid).type, None, HK, DIAG)
    )
    return loop, hk, user


def props(structure):
    return structure.enabled, structure.interval


class TestFunctionalReporting(unittest.TestCase):
    def test_create_report_and_apply(self):
        loop, hk, user = make()
        science = {1: (True, 1), 2: (False, 5)}
        tx = loop.run(user.create_functional(APID, 7, hk=science, diag={1: (True, 4)}))
        self.assertTrue(tx.ok)
        loop.run(user.create_functional(APID, 8, hk={2: (True, 10)}))
        tx = loop.run(user.report_functional(APID, [7]))
        self.assertEqual(loop.types()[-2], (3, 41))
        self.assertEqual(tx.reply, {"definitions": {7: {"hk": science, "diag": {1: (True, 4)}}}})
        tx = loop.run(user.report_functional(APID))  # N = 0: all of them
        self.assertEqual(sorted(tx.reply["definitions"]), [7, 8])
        self.assertEqual(
            (props(hk.structures[1]), props(hk.structures[2])), ((False, 2), (True, 5))
        )
        self.assertTrue(loop.run(user.apply_functional(APID, [7])).ok)
        self.assertEqual(props(hk.structures[1]), (True, 1))
        self.assertEqual(props(hk.structures[2]), (False, 5))
        self.assertEqual(props(hk.diagnostics[1]), (True, 4))
        for _ in range(4):
            loop.app.tick()
        loop.pump()
        self.assertEqual(len(loop.unsolicited(3, 25)), 4)  # SID 1 every cycle, SID 2 off
        self.assertEqual(len(loop.unsolicited(3, 26)), 1)  # diagnostic SID 1 every 4
        self.assertTrue(loop.run(user.apply_functional(APID, [8])).ok)
        self.assertEqual(props(hk.structures[2]), (True, 10))
        self.assertEqual(props(hk.structures[1]), (True, 1))  # not in 8: unchanged

    def test_add_remove_modify(self):
        loop, hk, user = make()
        loop.run(user.create_functional(APID, 7, hk={1: (True, 1)}))
        self.assertTrue(loop.run(user.add_to_functional(APID, 7, hk={2: (True, 3)})).ok)
        self.assertTrue(loop.run(user.add_to_functional(APID, 7, diag={1: (False, 2)})).ok)
        self.assertTrue(loop.run(user.modify_functional(APID, 7, hk={1: (False, 6)})).ok)
        self.assertTrue(loop.run(user.remove_from_functional(APID, 7, hk=[2])).ok)
        tx = loop.run(user.report_functional(APID, [7]))
        self.assertEqual(
            tx.reply["definitions"][7], {"hk": {1: (False, 6)}, "diag": {1: (False, 2)}}
        )

    def test_refusals_change_nothing(self):
        loop, hk, user = make()
        loop.run(user.create_functional(APID, 7, hk={1: (True, 1)}))
        cases = (
            (lambda: user.create_functional(APID, 7), FAILURE_REFUSED),  # in use
            (lambda: user.create_functional(APID, 8, hk={9: (True, 1)}), FAILURE_UNKNOWN_ID),
            (lambda: user.create_functional(APID, 8, diag={2: (True, 1)}), FAILURE_UNKNOWN_ID),
            (lambda: user.create_functional(APID, 8, hk={1: (True, 0)}), FAILURE_REFUSED),
            (lambda: user.add_to_functional(APID, 7, hk={1: (True, 2)}), FAILURE_REFUSED),
            (lambda: user.add_to_functional(APID, 9, hk={1: (True, 2)}), FAILURE_UNKNOWN_ID),
            (lambda: user.remove_from_functional(APID, 7, hk=[2]), FAILURE_UNKNOWN_ID),
            (lambda: user.modify_functional(APID, 7, hk={2: (True, 2)}), FAILURE_UNKNOWN_ID),
            (lambda: user.modify_functional(APID, 7, hk={1: (True, 0)}), FAILURE_REFUSED),
            (lambda: user.apply_functional(APID, [7, 9]), FAILURE_UNKNOWN_ID),
            (lambda: user.delete_functional(APID, [9]), FAILURE_UNKNOWN_ID),
            (lambda: user.report_functional(APID, [9]), FAILURE_UNKNOWN_ID),
        )
        for make_tx, code in cases:
            tx = loop.run(make_tx())
            self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, code))
        self.assertEqual(sorted(hk.functional), [7])
        self.assertEqual(hk.functional[7]["hk"], [[1, True, 1]])
        self.assertEqual(props(hk.structures[1]), (False, 2))  # apply [7, 9] changed nothing

    def test_a_deleted_structure_fails_the_apply(self):
        loop, hk, user = make()
        loop.run(user.create_functional(APID, 7, hk={1: (True, 1)}, diag={1: (True, 1)}))
        self.assertTrue(loop.run(user.delete(APID, [1], "diag")).ok)
        tx = loop.run(user.apply_functional(APID, [7]))
        self.assertEqual(
            (tx.failure["code"], tx.failure["data"]), (FAILURE_UNKNOWN_ID, b"\x00\x01")
        )
        self.assertEqual(props(hk.structures[1]), (False, 2))

    def test_delete_and_persist(self):
        fs = SimFs()
        loop, hk, user = make(Store("/ctx", fs))
        loop.run(user.create_functional(APID, 7, hk={1: (True, 1)}))
        loop.run(user.create_functional(APID, 8, diag={1: (False, 3)}))
        loop2, hk2, _ = make(Store("/ctx", fs))
        self.assertEqual(hk2.functional, hk.functional)
        self.assertTrue(loop.run(user.delete_functional(APID, [7])).ok)
        self.assertEqual(sorted(hk.functional), [8])
        self.assertTrue(loop.run(user.delete_functional(APID, [])).ok)  # N = 0: all
        self.assertEqual(hk.functional, {})

    def test_the_table_is_bounded(self):
        loop, hk, user = make()
        hk.max_functional = 2
        for fid in (1, 2):
            self.assertTrue(loop.run(user.create_functional(APID, fid)).ok)
        tx = loop.run(user.create_functional(APID, 3))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)


if __name__ == "__main__":
    unittest.main()
