"""ST[12] functional monitoring (TC[12,17] to TM[12,28]): FMONs over PMONs, their statuses,
protection, events and failure codes."""

import gc
import unittest

from obsw.pus.parameters import ParameterPool
from obsw.pus.services.s01_verification import FAILURE_REFUSED, FAILURE_UNKNOWN_ID
from obsw.pus.services.s05_events import EventReporting
from obsw.pus.services.s12_functional import FunctionalOnBoardMonitoring
from obsw.pus.services.s12_functional_user import FunctionalMonitoringUser, functional_check
from obsw.pus.services.s12_layouts import FMON_FAILED, FMON_UNCHECKED
from obsw.pus.services.s12_user import limit_check
from obsw.store import Store
from pus_loop import APID, Loop, sdb
from store_sim import SimFs


def make(store=None):
    db = sdb()
    loop = Loop(store=store)
    pool = ParameterPool(db)
    pool.values.update({1: 20.0, 2: 3.0, 3: 2, 4: True, 100: 0})
    loop.app.register(EventReporting(known=db.events))
    mon = loop.app.register(FunctionalOnBoardMonitoring(pool, db.events))
    user = loop.ground.register(
        FunctionalMonitoringUser(lambda pid: db.parameter(pid).type, lambda k: db.parameter(k).id)
    )
    return loop, mon, user, pool


def cycle(loop, n=1):
    for _ in range(n):
        loop.clock.advance(1.0)
        loop.app.tick()
    loop.pump()


def failure(tx):
    return (tx.failure["stage"], tx.failure["code"], tx.failure["data"]) if tx.failure else None


def setup(store=None):
    """Two enabled limit checks (angle, speed) and FMON 7 over both, failing on one."""
    loop, mon, user, pool = make(store)
    pmons = [limit_check(1, "Panel.angle", -10.0, 45.0), limit_check(2, "Panel.speed", 0.0, 5.0)]
    assert loop.run(user.add(APID, pmons)).ok
    assert loop.run(user.enable(APID, [1, 2])).ok
    fmon = functional_check(7, [1, 2], failing=1, event=4)
    assert loop.run(user.add_functional(APID, [fmon])).ok
    return loop, mon, user, pool


def statuses(loop, user):
    tx = loop.run(user.report_functional_status(APID))
    return [
        (d["fmon"], d["enabled"], d["protected"], d["checking"]) for d in tx.reply["functional"]
    ]


def events(loop):
    return [e.data for e in loop.tm if (e.service, e.subtype) == (5, 3)]


class TestFunctionalMonitoring(unittest.TestCase):
    def test_new_definitions_are_disabled_unprotected_and_reported(self):
        loop, mon, user, pool = setup()
        self.assertEqual(statuses(loop, user), [(7, False, False, "unchecked")])
        tx = loop.run(user.report_functional(APID, [7]))
        (d,) = tx.reply["functional"]
        self.assertEqual(
            (d["fmon"], d["event"], d["failing"], d["pmons"], d["enabled"]),
            (7, 4, 1, [1, 2], False),
        )
        self.assertEqual(loop.types()[-2:], [(12, 26), (1, 7)])
        self.assertEqual(loop.run(user.report_functional(APID)).reply, tx.reply)  # all

    def test_fails_once_when_enough_pmons_are_out_of_limits(self):
        loop, mon, user, pool = setup()
        self.assertTrue(loop.run(user.enable_functional(APID, [7])).ok)
        cycle(loop)
        self.assertEqual(statuses(loop, user)[0][3], "running")
        pool.values[2] = 9.0  # speed above 5
        cycle(loop)
        self.assertEqual(statuses(loop, user)[0][3], "failed")
        self.assertEqual(events(loop), [b"\x00\x04\x00\x07"])  # event 4, FMON 7
        cycle(loop, 3)
        self.assertEqual(len(events(loop)), 1)  # raised on the transition only
        pool.values[2] = 1.0
        cycle(loop)
        self.assertEqual(statuses(loop, user)[0][3], "running")
        pool.values[1] = 90.0
        cycle(loop)
        self.assertEqual(len(events(loop)), 2)

    def test_minimum_failing_number(self):
        loop, mon, user, pool = make()
        pmons = [limit_check(1, 1, -10.0, 45.0), limit_check(2, 2, 0.0, 5.0)]
        loop.run(user.add(APID, pmons))
        loop.run(user.enable(APID, [1, 2]))
        loop.run(user.add_functional(APID, [functional_check(3, [1, 2], failing=2)]))
        loop.run(user.enable_functional(APID, [3]))
        pool.values[2] = 9.0
        cycle(loop)
        self.assertEqual(statuses(loop, user)[0][3], "running")
        pool.values[1] = 90.0
        cycle(loop)
        self.assertEqual(statuses(loop, user)[0][3], "failed")
        self.assertEqual(events(loop), [])  # event 0: none

    def test_validity_condition(self):
        loop, mon, user, pool = make()
        loop.run(user.add(APID, [limit_check(1, 1, -10.0, 45.0)]))
        loop.run(user.enable(APID, [1]))
        fmon = functional_check(5, [1], validity="Panel.deployed", mask=1, expected=1)
        loop.run(user.add_functional(APID, [fmon]))
        loop.run(user.enable_functional(APID, [5]))
        pool.values[4] = False
        cycle(loop)
        self.assertEqual(statuses(loop, user)[0][3], "invalid")
        pool.values[4] = True
        cycle(loop)
        self.assertEqual(statuses(loop, user)[0][3], "running")

    def test_protected_cannot_be_disabled_enabled_cannot_be_deleted(self):
        loop, mon, user, pool = setup()
        loop.run(user.enable_functional(APID, [7]))
        self.assertTrue(loop.run(user.protect_functional(APID, [7])).ok)
        tx = loop.run(user.disable_functional(APID, [7]))
        self.assertEqual(failure(tx), (2, FAILURE_REFUSED, b"\x00\x07"))
        tx = loop.run(user.delete_functional(APID, [7]))
        self.assertEqual(failure(tx), (2, FAILURE_REFUSED, b"\x00\x07"))
        self.assertEqual(statuses(loop, user), [(7, True, True, "unchecked")])
        loop.run(user.unprotect_functional(APID, [7]))
        self.assertTrue(loop.run(user.disable_functional(APID, [7])).ok)
        self.assertTrue(loop.run(user.delete_functional(APID, [7])).ok)
        self.assertEqual(statuses(loop, user), [])

    def test_a_pmon_in_use_cannot_be_deleted(self):
        loop, mon, user, pool = setup()
        loop.run(user.disable(APID, [1]))
        tx = loop.run(user.delete(APID, [1]))
        self.assertEqual(failure(tx), (2, FAILURE_REFUSED, b"\x00\x01"))
        loop.run(user.disable_function(APID))
        tx = loop.run(user.delete_all(APID))
        self.assertEqual(failure(tx)[:2], (2, FAILURE_REFUSED))
        self.assertEqual(sorted(mon.pmons), [1, 2])

    def test_bad_definitions_fail_the_start_and_add_nothing(self):
        loop, mon, user, pool = setup()
        cases = (
            (functional_check(7, [1]), FAILURE_REFUSED, b"\x00\x07"),  # exists
            (functional_check(8, [1, 9]), FAILURE_UNKNOWN_ID, b"\x00\x08"),  # no PMON 9
            (functional_check(8, [1], failing=2), FAILURE_REFUSED, b"\x00\x08"),
            (functional_check(8, [1], failing=0), FAILURE_REFUSED, b"\x00\x08"),
            (functional_check(8, [1, 1]), FAILURE_REFUSED, b"\x00\x08"),
            (functional_check(8, []), FAILURE_REFUSED, b"\x00\x08"),
            (functional_check(8, [1], event=99), FAILURE_UNKNOWN_ID, b"\x00\x08"),
            (functional_check(8, [1], validity=999, mask=1), FAILURE_UNKNOWN_ID, b"\x03\xe7"),
        )
        for d, code, data in cases:
            tx = loop.run(user.add_functional(APID, [functional_check(9, [2]), d]))
            self.assertEqual(failure(tx), (2, code, data))
        self.assertEqual(sorted(mon.fmons), [7])
        for call in (user.enable_functional, user.protect_functional, user.report_functional):
            self.assertEqual(
                failure(loop.run(call(APID, [3]))), (2, FAILURE_UNKNOWN_ID, b"\x00\x03")
            )

    def test_disabling_the_function_stops_every_fmon(self):
        loop, mon, user, pool = setup()
        loop.run(user.enable_functional(APID, [7]))
        pool.values[2] = 9.0
        self.assertTrue(loop.run(user.disable_functional_function(APID)).ok)
        cycle(loop, 2)
        self.assertEqual(statuses(loop, user)[0][3], "unchecked")
        self.assertEqual(events(loop), [])
        self.assertTrue(loop.run(user.enable_functional_function(APID)).ok)
        cycle(loop)
        self.assertEqual(statuses(loop, user)[0][3], "failed")

    def test_the_function_depends_on_parameter_monitoring(self):
        loop, mon, user, pool = setup()
        loop.run(user.enable_functional(APID, [7]))
        loop.run(user.disable_function(APID))
        self.assertFalse(mon.fmon_function)  # disabled with parameter monitoring
        tx = loop.run(user.enable_functional_function(APID))
        self.assertEqual(failure(tx)[:2], (2, FAILURE_REFUSED))
        loop.run(user.enable_function(APID))
        self.assertFalse(mon.fmon_function)  # not enabled again by it
        self.assertTrue(loop.run(user.enable_functional_function(APID)).ok)
        pool.values[2] = 9.0
        cycle(loop, 2)
        self.assertEqual(mon.fmons[7].status, FMON_FAILED)
        loop.run(user.disable_function(APID))
        self.assertEqual(mon.fmons[7].status, FMON_UNCHECKED)

    def test_definitions_survive_a_restart(self):
        fs = SimFs()
        loop, mon, user, pool = setup(Store("/ctx", fs))
        loop.run(user.enable_functional(APID, [7]))
        loop.run(user.protect_functional(APID, [7]))
        del loop, mon, user, pool  # one spacecraft at a time: a board's heap holds one
        gc.collect()
        loop, mon, user, pool = make(Store("/ctx", fs))
        self.assertEqual(statuses(loop, user), [(7, True, True, "unchecked")])
        pool.values[1] = 90.0
        cycle(loop, 2)
        self.assertEqual(events(loop), [b"\x00\x04\x00\x07"])


if __name__ == "__main__":
    unittest.main()
