"""ST[05]: event reports of four severities, enable, disable, the disabled list."""

import unittest

from obsw.pus.events import EventManager
from obsw.pus.services.s01_verification import FAILURE_UNKNOWN_ID
from obsw.pus.services.s05_events import EventReporting, EventUser
from obsw.store import Store
from pus_loop import APID, Loop, sdb
from store_sim import SimFs


def make(store=None):
    db = sdb()
    loop = Loop(store=store)
    s5 = loop.app.register(EventReporting(known=db.events))
    events = EventManager(db)
    events.connect(loop.app)
    user = loop.ground.register(EventUser(db.event))
    return loop, s5, events, user


class TestEvents(unittest.TestCase):
    def test_four_severities(self):
        loop, s5, events, user = make()
        events.raise_event("Panel.moved", {"angle": 1.5})
        events.raise_event("low_one")
        events.raise_event("medium_one")
        events.raise_event("Panel.stuck", [7])
        loop.pump()
        self.assertEqual(loop.types(), [(5, 1), (5, 2), (5, 3), (5, 4)])
        got = [d for _, d, _ in loop.results]
        self.assertEqual(
            got[0], {"id": 1, "severity": "info", "event": "Panel.moved", "data": {"angle": 1.5}}
        )
        self.assertEqual(got[1], {"id": 3, "severity": "low", "event": "low_one", "data": {}})
        self.assertEqual(got[2]["severity"], "medium")
        self.assertEqual(got[3]["data"], {"code": 7})
        self.assertEqual(loop.tm[3].data, b"\x00\x02\x00\x07")

    def test_disable_enable_and_report(self):
        loop, s5, events, user = make()
        self.assertTrue(loop.run(user.disable(APID, [1, 4])).ok)
        events.raise_event(1, 2.0)
        events.raise_event(4)
        events.raise_event(3)
        loop.pump()
        self.assertEqual(loop.unsolicited(5, 3), [])
        self.assertEqual(len(loop.unsolicited(5, 2)), 1)
        self.assertEqual(s5.suppressed, 2)
        tx = loop.run(user.report_disabled(APID))
        self.assertEqual(tx.reply, {"ids": [1, 4]})
        self.assertTrue(loop.run(user.enable(APID, [4])).ok)
        tx = loop.run(user.report_disabled(APID))
        self.assertEqual(tx.reply, {"ids": [1]})
        events.raise_event(4)
        loop.pump()
        self.assertEqual(len(loop.unsolicited(5, 3)), 1)

    def test_unknown_event_ids(self):
        loop, s5, events, user = make()
        tx = loop.run(user.disable(APID, [1, 77]))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_UNKNOWN_ID))
        self.assertEqual(tx.failure["data"], b"\x00\x4d")
        self.assertEqual(s5.disabled, set())

    def test_unknown_event_on_ground_stays_raw(self):
        loop, s5, events, user = make()
        loop.app.event(500, 2, b"\x01\x02")
        loop.pump()
        self.assertEqual(loop.results[0][1], {"id": 500, "severity": "low", "data": b"\x01\x02"})

    def test_payload_that_does_not_fit_goes_empty(self):
        loop, s5, events, user = make()
        events.raise_event("Panel.stuck", {"code": "not a number"})
        loop.pump()
        self.assertEqual(events.bad_payloads, 1)
        self.assertEqual(loop.tm[0].data, b"\x00\x02")

    def test_disabled_list_persists(self):
        fs = SimFs()
        loop, s5, events, user = make(Store("/ctx", fs))
        loop.run(user.disable(APID, [2, 3]))
        loop2, s5b, _, _ = make(Store("/ctx", fs))
        self.assertEqual(s5b.disabled, {2, 3})

    def test_no_event_service_counts_lost_events(self):
        loop = Loop()
        self.assertFalse(loop.app.event(1, 1))
        self.assertEqual(loop.app.events_lost, 1)


if __name__ == "__main__":
    unittest.main()
