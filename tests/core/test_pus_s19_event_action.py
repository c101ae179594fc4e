"""ST[19]: event-action definitions, provider against user; actions verified like ground TCs."""

import unittest

from obsw.pus.events import EventManager
from obsw.pus.services.s01_verification import (
    FAILURE_ILLEGAL_APP_DATA,
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
)
from obsw.pus.services.s05_events import EventReporting, EventUser
from obsw.pus.services.s17_test import ServiceTest
from obsw.pus.services.s19_event_action import EventAction, EventActionUser
from obsw.store import Store
from pus_loop import APID, Loop, sdb
from store_sim import SimFs


def make(store=None, **options):
    db = sdb()
    loop = Loop(store=store)
    loop.app.register(EventReporting(known=db.events))
    ea = loop.app.register(EventAction(known=db.events, **options))
    loop.app.register(ServiceTest())
    events = EventManager(db)
    events.connect(loop.app)
    loop.ground.register(EventUser(db.event))
    user = loop.ground.register(EventActionUser())
    return loop, ea, user, events


def failure(tx):
    return (tx.failure["stage"], tx.failure["code"], tx.failure["data"]) if tx.failure else None


class TestEventAction(unittest.TestCase):
    def test_event_fires_the_action_through_the_application_process(self):
        loop, ea, user, events = make()
        raw, action = user.embed(APID, 17, 1)
        self.assertTrue(loop.run(user.add(APID, [(APID, 3, raw)])).ok)
        events.raise_event("low_one")
        loop.pump()
        self.assertFalse(action.done)  # new definitions are disabled
        self.assertTrue(loop.run(user.enable(APID, [(APID, 3)])).ok)
        events.raise_event("low_one")
        loop.pump()
        self.assertTrue(action.ok)
        self.assertEqual(
            action.verification(), ["acceptance success", "start success", "completion success"]
        )
        self.assertEqual(loop.types()[-5:], [(5, 2), (1, 1), (1, 3), (17, 2), (1, 7)])
        self.assertEqual((ea.fired, loop.app.counters["actions"]), (1, 1))
        events.raise_event("medium_one")  # no definition
        self.assertEqual(ea.fired, 1)

    def test_action_runs_even_with_the_report_disabled(self):
        loop, ea, user, events = make()
        raw, action = user.embed(APID, 17, 1)
        loop.run(user.add(APID, [(APID, 4, raw)]))
        loop.run(user.enable(APID, [(APID, 4)]))
        loop.app.services[5].disabled.add(4)
        events.raise_event("medium_one")
        loop.pump()
        self.assertTrue(action.ok)
        self.assertEqual(loop.unsolicited(5, 3), [])

    def test_failed_action_is_reported_to_its_source(self):
        loop, ea, user, events = make()
        raw, action = user.embed(APID, 17, 3, b"\x00\x63")  # connection test to process 99
        loop.run(user.add(APID, [(APID, 3, raw)]))
        loop.run(user.enable(APID, [(APID, 3)]))
        events.raise_event("low_one")
        loop.pump()
        self.assertEqual(failure(action), (2, FAILURE_UNKNOWN_ID, b"\x00\x63"))

    def test_function_switch_and_reports(self):
        loop, ea, user, events = make()
        r3, a3 = user.embed(APID, 17, 1)
        r4, a4 = user.embed(APID, 17, 1)
        loop.run(user.add(APID, [(APID, 3, r3), (APID, 4, r4)]))
        loop.run(user.enable(APID, [(APID, 4)]))
        tx = loop.run(user.report_status(APID))
        self.assertEqual(
            tx.reply["items"],
            [
                {"apid": APID, "event": 3, "enabled": False},
                {"apid": APID, "event": 4, "enabled": True},
            ],
        )
        tx = loop.run(user.report_definitions(APID, [(APID, 4)]))
        (d,) = tx.reply["items"]
        self.assertEqual(
            (d["event"], d["enabled"], d["type"], d["request"]), (4, True, (17, 1), r4)
        )
        tx = loop.run(user.report_definitions(APID))
        self.assertEqual([i["event"] for i in tx.reply["items"]], [3, 4])
        self.assertTrue(loop.run(user.disable_function(APID)).ok)
        events.raise_event("medium_one")
        loop.pump()
        self.assertFalse(a4.done)
        self.assertTrue(loop.run(user.enable_function(APID)).ok)
        events.raise_event("medium_one")
        loop.pump()
        self.assertTrue(a4.ok)
        self.assertTrue(loop.run(user.disable(APID, [(APID, 4)])).ok)
        self.assertTrue(loop.run(user.delete(APID, [(APID, 4)])).ok)
        self.assertTrue(loop.run(user.delete_all(APID)).ok)
        self.assertEqual(ea.definitions, {})

    def test_bad_and_conflicting_requests(self):
        loop, ea, user, events = make(capacity=2)
        raw, _ = user.embed(APID, 17, 1)
        loop.run(user.add(APID, [(APID, 3, raw)]))
        loop.run(user.enable(APID, [(APID, 3)]))
        key = bytes([0, APID, 0, 3])
        other = user.embed(99, 17, 1)[0]
        for tx, expected in (
            (user.add(APID, [(APID, 3, raw)]), (2, FAILURE_REFUSED, key)),  # exists
            (user.add(APID, [(APID, 77, raw)]), (2, FAILURE_UNKNOWN_ID, bytes([0, APID, 0, 77]))),
            (user.add(APID, [(APID, 1, other)]), (2, FAILURE_UNKNOWN_ID, bytes([0, APID, 0, 1]))),
            (user.add(APID, [(APID, 1, raw), (APID, 2, raw)]), (2, FAILURE_REFUSED, b"")),
            (user.delete(APID, [(APID, 3)]), (2, FAILURE_REFUSED, key)),  # enabled
            (user.enable(APID, [(APID, 9)]), (2, FAILURE_UNKNOWN_ID, bytes([0, APID, 0, 9]))),
        ):
            loop.run(tx)
            self.assertEqual(failure(tx), expected)
        for data in (
            b"\x01\x00",
            b"\x01\x00\x0a\x00\x01" + raw[:-1],
            b"\x01\x00\x0a\x00\x01" + b"\x00" * 12,
        ):
            tx = loop.run(loop.ground.send(APID, 19, 1, data))
            self.assertEqual(failure(tx)[:2], (1, FAILURE_ILLEGAL_APP_DATA))
        self.assertEqual(list(ea.definitions), [(APID, 3)])

    def test_an_action_raising_its_own_event_stops(self):
        loop, ea, user, events = make(max_depth=3)
        calls = []

        def probe(apid):
            calls.append(apid)
            events.raise_event("low_one")  # the action raises the event that fired it
            return True

        loop.app.services[17].peers[11] = probe
        raw, _ = user.embed(APID, 17, 3, b"\x00\x0b")
        loop.run(user.add(APID, [(APID, 3, raw)]))
        loop.run(user.enable(APID, [(APID, 3)]))
        events.raise_event("low_one")
        loop.pump()
        self.assertEqual(len(calls), 3)
        self.assertEqual(loop.app.counters["actions_nested"], 1)

    def test_definitions_survive_a_restart(self):
        fs = SimFs()
        loop, ea, user, events = make(Store("/ctx", fs))
        raw, action = user.embed(APID, 17, 1)
        loop.run(user.add(APID, [(APID, 3, raw)]))
        loop.run(user.enable(APID, [(APID, 3)]))
        loop.run(user.disable_function(APID))
        loop2, ea2, _, events2 = make(Store("/ctx", fs))
        self.assertEqual((ea2.definitions, ea2.function), ({(APID, 3): [True, raw]}, False))


if __name__ == "__main__":
    unittest.main()
