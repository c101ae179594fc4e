"""ST[03] diagnostic parameter report structures (2, 4, 7, 8, 11, 12, 26, 28, 30, 32, 34, 36)
and appending parameters (29, 30), provider against user."""

import unittest

from obsw.pus.parameters import ParameterPool
from obsw.pus.services.s01_verification import FAILURE_REFUSED, FAILURE_UNKNOWN_ID
from obsw.pus.services.s03_housekeeping import Housekeeping, HousekeepingUser
from obsw.store import Store
from pus_loop import APID, Loop, sdb
from store_sim import SimFs

DIAG = [{"sid": 1, "interval": 1, "parameters": [1], "enabled": False}]


def make(store=None):
    db = sdb()
    loop = Loop(store=store)
    pool = ParameterPool(db)
    pool.values.update({1: 12.5, 2: 3.0, 3: 2, 4: True, 5: "panel"})
    hk = loop.app.register(Housekeeping(pool, db.housekeeping, diagnostic=DIAG))
    user = loop.ground.register(
        HousekeepingUser(
            lambda pid: db.parameter(pid).type,
            lambda pid: db.parameter(pid).qualified,
            db.housekeeping,
            DIAG,
        )
    )
    return loop, hk, user, pool


def ticks(loop, n):
    for _ in range(n):
        loop.app.tick()
    loop.pump()


class TestDiagnostics(unittest.TestCase):
    def test_the_two_sets_are_apart(self):
        loop, hk, user, pool = make()
        # SID 1 names a housekeeping and a diagnostic structure, each with its own parameters
        tx = loop.run(user.one_shot(APID, [1], "diag"))
        self.assertEqual(tx.reply, {"sid": 1, "values": {"Panel.angle": 12.5}})
        self.assertEqual(loop.types()[-2:], [(3, 26), (1, 7)])
        tx = loop.run(user.one_shot(APID, [1]))
        self.assertEqual(len(tx.reply["values"]), 3)
        tx = loop.run(user.create(APID, 9, 2, [2, 3], "diag"))
        self.assertTrue(tx.ok)
        self.assertEqual(sorted(hk.diagnostics), [1, 9])
        self.assertEqual(sorted(hk.structures), [1])
        tx = loop.run(user.one_shot(APID, [9]))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)  # not a housekeeping SID

    def test_structure_and_properties_reports(self):
        loop, hk, user, pool = make()
        loop.run(user.create(APID, 9, 2, [2, 3], "diag"))
        tx = loop.run(user.report_structures(APID, [9, 1], "diag"))
        self.assertEqual(loop.types().count((3, 12)), 2)
        self.assertEqual(
            tx.replies[0],
            {"sid": 9, "enabled": False, "interval": 2, "parameters": [2, 3], "groups": []},
        )
        self.assertEqual(tx.replies[1]["parameters"], [1])
        self.assertTrue(loop.run(user.enable(APID, [9], "diag")).ok)
        self.assertTrue(loop.run(user.modify_interval(APID, {9: 3}, "diag")).ok)
        tx = loop.run(user.report_properties(APID, [9, 1], "diag"))
        self.assertEqual(loop.types()[-2], (3, 36))
        self.assertEqual(
            tx.reply,
            {
                "items": [
                    {"sid": 9, "enabled": True, "interval": 3},
                    {"sid": 1, "enabled": False, "interval": 1},
                ]
            },
        )

    def test_periodic_diagnostic_reports(self):
        loop, hk, user, pool = make()
        self.assertTrue(loop.run(user.enable(APID, [1], "diag")).ok)
        ticks(loop, 4)
        reports = loop.unsolicited(3, 26)
        self.assertEqual(len(reports), 4)  # every cycle
        self.assertEqual(loop.unsolicited(3, 25), [])
        self.assertTrue(loop.run(user.disable(APID, [1], "diag")).ok)
        ticks(loop, 4)
        self.assertEqual(len(loop.unsolicited(3, 26)), 4)

    def test_refusals_and_unknown_ids(self):
        loop, hk, user, pool = make()
        loop.run(user.enable(APID, [1], "diag"))
        cases = (
            (lambda: user.create(APID, 1, 1, [1], "diag"), FAILURE_REFUSED),  # in use
            (lambda: user.create(APID, 2, 0, [1], "diag"), FAILURE_REFUSED),  # interval 0
            (lambda: user.create(APID, 2, 1, [1, 1], "diag"), FAILURE_REFUSED),  # twice
            (lambda: user.create(APID, 2, 1, [999], "diag"), FAILURE_UNKNOWN_ID),
            (lambda: user.delete(APID, [1], "diag"), FAILURE_REFUSED),  # enabled
            (lambda: user.delete(APID, [5], "diag"), FAILURE_UNKNOWN_ID),
            (lambda: user.enable(APID, [5], "diag"), FAILURE_UNKNOWN_ID),
            (lambda: user.modify_interval(APID, {1: 0}, "diag"), FAILURE_REFUSED),
            (lambda: user.report_properties(APID, [5], "diag"), FAILURE_UNKNOWN_ID),
            (lambda: user.one_shot(APID, [5], "diag"), FAILURE_UNKNOWN_ID),
        )
        for make_tx, code in cases:
            tx = loop.run(make_tx())
            self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, code))
        self.assertEqual(sorted(hk.diagnostics), [1])

    def test_append_parameters(self):
        loop, hk, user, pool = make()
        for kind, report in (("hk", (3, 25)), ("diag", (3, 26))):
            tx = loop.run(user.append(APID, 1, [4, 5], kind))
            self.assertTrue(tx.ok)
            tx = loop.run(user.one_shot(APID, [1], kind))
            self.assertEqual(loop.types()[-2], report)
            self.assertEqual(tx.reply["values"]["Panel.deployed"], True)
            self.assertEqual(tx.reply["values"]["Panel.label"], "panel")
        self.assertEqual(hk.structures[1].parameters, [1, 2, 3, 4, 5])
        self.assertEqual(hk.diagnostics[1].parameters, [1, 4, 5])

    def test_append_refusals(self):
        loop, hk, user, pool = make()
        for sid, pids, code in (
            (7, [1], FAILURE_UNKNOWN_ID),  # no structure 7
            (1, [999], FAILURE_UNKNOWN_ID),
            (1, [2], FAILURE_REFUSED),  # already in the structure
            (1, [4, 4], FAILURE_REFUSED),
        ):
            tx = loop.run(user.append(APID, sid, pids))
            self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, code))
        loop.run(user.enable(APID, [1]))
        tx = loop.run(user.append(APID, 1, [4]))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # periodic generation enabled
        self.assertEqual(hk.structures[1].parameters, [1, 2, 3])

    def test_diagnostics_persist_and_old_contexts_load(self):
        fs = SimFs()
        loop, hk, user, pool = make(Store("/ctx", fs))
        loop.run(user.create(APID, 9, 2, [2, 3], "diag"))
        loop.run(user.append(APID, 1, [4]))
        loop2, hk2, _, _ = make(Store("/ctx", fs))
        self.assertEqual(hk2.diagnostics[9].parameters, [2, 3])
        self.assertEqual(hk2.structures[1].parameters, [1, 2, 3, 4])
        hk2.restore([[4, 2, [1], True]])  # a context saved before diagnostics
        self.assertEqual(sorted(hk2.structures), [4])
        self.assertEqual(hk2.diagnostics, {})


if __name__ == "__main__":
    unittest.main()
