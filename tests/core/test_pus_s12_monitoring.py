"""ST[12]: parameter monitoring definitions, checks, repetitions, transitions and events."""

import unittest

from obsw.pus.parameters import ParameterPool
from obsw.pus.services.s01_verification import (
    FAILURE_ILLEGAL_APP_DATA,
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
)
from obsw.pus.services.s05_events import EventReporting, EventUser
from obsw.pus.services.s12_layouts import (
    ABOVE_HIGH,
    BELOW_LOW,
    CHECK_DELTA,
    CHECK_EXPECTED_VALUE,
    CHECK_LIMIT,
    INVALID,
    UNCHECKED,
    WITHIN,
)
from obsw.pus.services.s12_monitoring import OnBoardMonitoring
from obsw.pus.services.s12_user import (
    OnBoardMonitoringUser,
    delta_check,
    expected_value_check,
    limit_check,
)
from obsw.store import Store
from pus_loop import APID, Loop, sdb
from store_sim import SimFs


def make(store=None):
    db = sdb()
    loop = Loop(store=store)
    pool = ParameterPool(db)
    pool.values.update({1: 20.0, 2: 3.0, 3: 2, 4: True, 100: 0})
    loop.app.register(EventReporting(known=db.events))
    mon = loop.app.register(OnBoardMonitoring(pool, db.events))
    loop.ground.register(EventUser(db.event))
    user = loop.ground.register(
        OnBoardMonitoringUser(lambda pid: db.parameter(pid).type, lambda k: db.parameter(k).id)
    )
    return loop, mon, user, pool


def cycle(loop, n=1):
    for _ in range(n):
        loop.clock.advance(1.0)
        loop.app.tick()
    loop.pump()


def transitions(loop):
    out = []
    for d in loop.unsolicited(12, 12):
        out.extend((i["pmon"], i["previous"], i["current"]) for i in d["items"])
    return out


def failure(tx):
    return (tx.failure["stage"], tx.failure["code"], tx.failure["data"]) if tx.failure else None


class TestChecks(unittest.TestCase):
    def test_limit_check_with_repetitions_events_and_transition_reports(self):
        loop, mon, user, pool = make()
        d = limit_check(1, "Panel.angle", -10.0, 45.0, low_event=3, high_event=4, repetitions=2)
        self.assertTrue(loop.run(user.add(APID, [d])).ok)
        self.assertTrue(loop.run(user.enable(APID, [1])).ok)
        cycle(loop)
        self.assertEqual(transitions(loop), [])  # one result is not confirmed yet
        cycle(loop)
        self.assertEqual(transitions(loop), [(1, UNCHECKED, WITHIN)])
        pool.values[1] = 50.0
        cycle(loop)
        self.assertEqual(len(transitions(loop)), 1)
        cycle(loop)
        self.assertEqual(transitions(loop)[-1], (1, WITHIN, ABOVE_HIGH))
        (report,) = [r for r in loop.unsolicited(12, 12) if r["items"][0]["current"] == ABOVE_HIGH]
        item = report["items"][0]
        self.assertEqual(
            (item["parameter"], item["check"], item["value"], item["limit"]),
            (1, CHECK_LIMIT, 50.0, 45.0),
        )
        self.assertEqual(item["time"], 1004.0)
        (event,) = [t for t in loop.tm if (t.service, t.subtype) == (5, 3)]  # medium_one
        self.assertEqual(event.data, b"\x00\x04" + b"\x00\x01\x00\x01")  # PMON 1, parameter 1
        tx = loop.run(user.report_out_of_limits(APID))
        self.assertEqual([(i["pmon"], i["current"]) for i in tx.reply["items"]], [(1, ABOVE_HIGH)])
        pool.values[1] = -20.0
        cycle(loop, 2)
        self.assertEqual(transitions(loop)[-1], (1, ABOVE_HIGH, BELOW_LOW))
        self.assertEqual(len(loop.unsolicited(5, 2)), 1)  # low_one
        pool.values[1] = 0.0
        cycle(loop, 2)
        self.assertEqual(transitions(loop)[-1], (1, BELOW_LOW, WITHIN))
        tx = loop.run(user.report_out_of_limits(APID))
        self.assertEqual(tx.reply["items"], [])

    def test_expected_value_check_and_validity(self):
        loop, mon, user, pool = make()
        d = expected_value_check(
            2,
            "Panel.mode",
            2,
            mask=0x0F,
            event=4,
            validity="Panel.deployed",
            validity_mask=1,
            validity_value=1,
        )
        loop.run(user.add(APID, [d]))
        loop.run(user.enable(APID, [2]))
        cycle(loop)
        pool.values[3] = 0x13  # low nibble 3: unexpected
        cycle(loop)
        pool.values[4] = False  # the validity parameter says: not valid
        cycle(loop)
        self.assertEqual(
            transitions(loop),
            [(2, UNCHECKED, WITHIN), (2, WITHIN, BELOW_LOW), (2, BELOW_LOW, INVALID)],
        )
        item = loop.unsolicited(12, 12)[1]["items"][0]  # the check's mask, then the value
        self.assertEqual((item["mask"], item["value"], item["limit"]), (0x0F, 0x13, 2))
        self.assertEqual([e["id"] for e in loop.unsolicited(5, 3)], [4])

    def test_delta_check_on_the_mean_of_consecutive_deltas(self):
        loop, mon, user, pool = make()
        d = delta_check(3, "count", -1.0, 5.0, consecutive=2, high_event=4, interval=2)
        loop.run(user.add(APID, [d]))
        loop.run(user.enable(APID, [3]))
        for v in (0, 2, 4, 6, 20, 34):  # deltas 2, 2, 2, 14, 14: mean 2, 2, 8, 14
            pool.values[100] = v
            cycle(loop, 2)  # sampled every second cycle
        self.assertEqual(transitions(loop), [(3, UNCHECKED, WITHIN), (3, WITHIN, ABOVE_HIGH)])
        last = loop.unsolicited(12, 12)[-1]["items"][0]
        self.assertEqual((last["value"], last["limit"]), (8.0, 5.0))

    def test_transition_reporting_delay_gathers_transitions(self):
        loop, mon, user, pool = make()
        loop.run(user.add(APID, [limit_check(1, 1, 0.0, 10.0), limit_check(2, 2, 0.0, 1.0)]))
        loop.run(user.change_delay(APID, 3))
        loop.run(user.enable(APID, [1, 2]))
        cycle(loop, 3)
        self.assertEqual(loop.unsolicited(12, 12), [])
        cycle(loop)
        (report,) = loop.unsolicited(12, 12)
        self.assertEqual(
            [(i["pmon"], i["current"]) for i in report["items"]],
            [(1, ABOVE_HIGH), (2, ABOVE_HIGH)],
        )


class TestManagement(unittest.TestCase):
    def test_reports_modify_disable_and_delete(self):
        loop, mon, user, pool = make()
        loop.run(
            user.add(
                APID, [limit_check(1, 1, 0.0, 10.0, repetitions=3), expected_value_check(2, 3, 1)]
            )
        )
        loop.run(user.enable(APID, [2]))
        tx = loop.run(user.report_status(APID))
        self.assertEqual(
            tx.reply["items"], [{"pmon": 1, "enabled": False}, {"pmon": 2, "enabled": True}]
        )
        tx = loop.run(user.report_definitions(APID, [1]))
        (d,) = tx.reply["items"]
        self.assertEqual(
            (
                d["pmon"],
                d["parameter"],
                d["check"],
                d["low"],
                d["high"],
                d["repetitions"],
                d["enabled"],
            ),
            (1, 1, CHECK_LIMIT, 0.0, 10.0, 3, False),
        )
        self.assertEqual(tx.reply["delay"], 0)
        tx = loop.run(
            user.modify(
                APID,
                [
                    {
                        "pmon": 1,
                        "parameter": 1,
                        "repetitions": 1,
                        "check": CHECK_DELTA,
                        "low": -1.0,
                        "high": 1.0,
                        "consecutive": 1,
                    }
                ],
            )
        )
        self.assertTrue(tx.ok)
        tx = loop.run(user.report_definitions(APID))
        self.assertEqual(
            [(i["pmon"], i["check"]) for i in tx.reply["items"]],
            [(1, CHECK_DELTA), (2, CHECK_EXPECTED_VALUE)],
        )
        tx = loop.run(user.delete(APID, [2]))
        self.assertEqual(failure(tx), (2, FAILURE_REFUSED, b"\x00\x02"))  # enabled
        tx = loop.run(user.delete_all(APID))
        self.assertEqual(failure(tx)[:2], (2, FAILURE_REFUSED))  # the function is enabled
        self.assertTrue(loop.run(user.disable(APID, [2])).ok)
        self.assertEqual(mon.pmons[2].status, UNCHECKED)
        self.assertTrue(loop.run(user.delete(APID, [2])).ok)
        self.assertTrue(loop.run(user.disable_function(APID)).ok)
        self.assertTrue(loop.run(user.delete_all(APID)).ok)
        self.assertEqual(mon.pmons, {})

    def test_disabled_function_checks_nothing(self):
        loop, mon, user, pool = make()
        loop.run(user.add(APID, [limit_check(1, 1, 0.0, 10.0)]))
        loop.run(user.enable(APID, [1]))
        loop.run(user.disable_function(APID))
        cycle(loop, 3)
        self.assertEqual(loop.unsolicited(12, 12), [])
        loop.run(user.enable_function(APID))
        cycle(loop)
        self.assertEqual(transitions(loop), [(1, UNCHECKED, ABOVE_HIGH)])

    def test_bad_and_conflicting_requests(self):
        loop, mon, user, pool = make()
        loop.run(user.add(APID, [limit_check(1, 1, 0.0, 10.0)]))
        for d, expected in (
            (limit_check(1, 2, 0.0, 1.0), (2, FAILURE_REFUSED, b"\x00\x01")),  # PMON exists
            (limit_check(5, 2, 3.0, 1.0), (2, FAILURE_REFUSED, b"\x00\x05")),  # low above high
            (limit_check(5, 2, 0.0, 1.0, high_event=99), (2, FAILURE_UNKNOWN_ID, b"\x00\x05")),
            (limit_check(5, 2, 0.0, 1.0, repetitions=0), (2, FAILURE_REFUSED, b"\x00\x05")),
            (expected_value_check(5, 1, 1), (2, FAILURE_REFUSED, b"\x00\x05")),  # a float
            (delta_check(5, 2, 0.0, 1.0, consecutive=0), (2, FAILURE_REFUSED, b"\x00\x05")),
            (
                limit_check(5, 2, 0.0, 1.0, validity=77, validity_mask=1),
                (2, FAILURE_UNKNOWN_ID, b"\x00\x4d"),
            ),
        ):
            tx = loop.run(user.add(APID, [d]))
            self.assertEqual(failure(tx), expected)
        for tx, expected in (
            (user.enable(APID, [9]), (2, FAILURE_UNKNOWN_ID, b"\x00\x09")),
            (user.modify(APID, [limit_check(1, 2, 0.0, 1.0)]), (2, FAILURE_REFUSED, b"\x00\x01")),
            (user.report_definitions(APID, [9]), (2, FAILURE_UNKNOWN_ID, b"\x00\x09")),
        ):
            loop.run(tx)
            self.assertEqual(failure(tx), expected)
        for data in (
            b"\x00\x01\x00\x05\x03\xe7" + bytes(16) + b"\x01",  # unknown parameter 999
            b"\x00\x01\x00\x05\x00\x01" + bytes(16) + b"\x07",  # unknown check type
            b"\x00\x01\x00\x05",  # cut short
        ):
            tx = loop.run(loop.ground.send(APID, 12, 5, data))
            self.assertEqual(failure(tx)[:2], (1, FAILURE_ILLEGAL_APP_DATA))
        self.assertEqual(list(mon.pmons), [1])

    def test_definitions_survive_a_restart(self):
        fs = SimFs()
        loop, mon, user, pool = make(Store("/ctx", fs))
        loop.run(
            user.add(
                APID, [limit_check(1, 1, 0.0, 10.0, high_event=4), delta_check(3, 100, 0.0, 1.0)]
            )
        )
        loop.run(user.enable(APID, [1]))
        loop.run(user.change_delay(APID, 4))
        loop2, mon2, user2, pool2 = make(Store("/ctx", fs))
        self.assertEqual(sorted(mon2.pmons), [1, 3])
        self.assertEqual(
            (mon2.pmons[1].enabled, mon2.pmons[1].d["high"], mon2.delay), (True, 10.0, 4)
        )
        cycle(loop2, 5)
        self.assertEqual([e["id"] for e in loop2.unsolicited(5, 3)], [4])


if __name__ == "__main__":
    unittest.main()
