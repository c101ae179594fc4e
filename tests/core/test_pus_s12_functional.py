"""ST[12] functional monitoring (TC[12,17] to TM[12,28]): FMONs over PMONs, their statuses,
protection, events and failure codes."""

import unittest

from obsw.pus.services.s01_verification import FAILURE_REFUSED, FAILURE_UNKNOWN_ID
from obsw.pus.services.s12_user import functional_check, limit_check
from obsw.store import Store
from store_sim import SimFs
from test_pus_s12_monitoring import APID, cycle, failure, make


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
        self.assertEqual(sorted(mon.functional.fmons), [7])
        for call in (user.enable_functional, user.protect_functional, user.report_functional):
            self.assertEqual(
                failure(loop.run(call(APID, [3]))), (2, FAILURE_UNKNOWN_ID, b"\x00\x03")
            )

    def test_the_function_depends_on_parameter_monitoring(self):
        loop, mon, user, pool = setup()
        loop.run(user.enable_functional(APID, [7]))
        pool.values[2] = 9.0
        self.assertTrue(loop.run(user.disable_functional_function(APID)).ok)
        cycle(loop, 2)
        self.assertEqual(statuses(loop, user)[0][3], "unchecked")
        self.assertEqual(events(loop), [])
        loop.run(user.disable_function(APID))
        tx = loop.run(user.enable_functional_function(APID))
        self.assertEqual(failure(tx)[:2], (2, FAILURE_REFUSED))
        loop.run(user.enable_function(APID))
        self.assertFalse(mon.functional.function)  # disabled with parameter monitoring
        self.assertTrue(loop.run(user.enable_functional_function(APID)).ok)
        cycle(loop, 2)
        self.assertEqual(statuses(loop, user)[0][3], "failed")
        loop.run(user.disable_function(APID))
        self.assertEqual(statuses(loop, user)[0][3], "unchecked")

    def test_definitions_survive_a_restart(self):
        fs = SimFs()
        loop, mon, user, pool = setup(Store("/ctx", fs))
        loop.run(user.enable_functional(APID, [7]))
        loop.run(user.protect_functional(APID, [7]))
        loop2, mon2, user2, pool2 = make(Store("/ctx", fs))
        self.assertEqual(statuses(loop2, user2), [(7, True, True, "unchecked")])
        pool2.values[1] = 90.0
        cycle(loop2, 2)
        self.assertEqual(events(loop2), [b"\x00\x04\x00\x07"])


if __name__ == "__main__":
    unittest.main()
