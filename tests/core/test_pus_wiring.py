"""The application process's declared wiring: services registered in every order give the
same TM, byte for byte (TM pipeline: storage and forwarding; events: reporting and action)."""

import unittest

from obsw.cfdp.filestore import MemoryFilestore
from obsw.il.interface import LOW
from obsw.pus.services.s05_events import EventReporting
from obsw.pus.services.s14_forwarding import ForwardingControl, ForwardingUser
from obsw.pus.services.s15_storage import Storage
from obsw.pus.services.s15_user import StorageUser
from obsw.pus.services.s17_test import ServiceTest, ServiceTestUser
from obsw.pus.services.s19_event_action import EventAction, EventActionUser
from pus_loop import APID, Loop, sdb

PROVIDERS = ("s05", "s14", "s15", "s17", "s19")


def orders(items):
    """Every permutation of ``items`` (a tuple), as tuples."""
    if len(items) <= 1:
        return [items]
    out = []
    for i in range(len(items)):
        for rest in orders(items[:i] + items[i + 1 :]):
            out.append((items[i],) + rest)
    return out


def provider(name, db):
    if name == "s05":
        return EventReporting(known=db.events)
    if name == "s14":
        return ForwardingControl()
    if name == "s15":
        return Storage((), MemoryFilestore(), rate=16)
    if name == "s17":
        return ServiceTest()
    return EventAction(known=db.events)


def scenario(order):
    """Run one fixed script with the providers registered in ``order``; all TM bytes out."""
    db = sdb()
    loop = Loop()
    played = []
    app = loop.app
    app.playback = lambda raw, vc: played.append((vc, raw))
    for name in order:
        app.register(provider(name, db))
    ground = loop.ground
    test = ground.register(ServiceTestUser())
    store = ground.register(StorageUser())
    fwd = ground.register(ForwardingUser())
    action = ground.register(EventActionUser())
    loop.run(store.create(APID, [{"store": 1, "size": 4000, "kind": 0, "vc": 1}]))
    loop.run(store.add_types(APID, 1, {APID: {17: [2], 5: []}}))
    loop.run(store.enable(APID, [1]))
    raw, _ = action.embed(APID, 17, 1)
    loop.run(action.add(APID, [(APID, 3, raw)]))
    loop.run(action.enable(APID, [(APID, 3)]))
    loop.run(fwd.delete_types(APID, {APID: {17: [2]}}))  # pings answered but stored only
    for _ in range(3):
        loop.clock.advance(1.0)
        loop.run(test.ping(APID))
    app.event(3, LOW, b"")  # reported, stored, and its action (a ping) runs
    loop.pump()
    loop.run(store.retrieve_time(APID, 1, 0, 10**6))
    app.tick()
    loop.pump()
    return loop.raw, played


class WiringTest(unittest.TestCase):
    def test_registration_order_carries_no_meaning(self):
        first = None
        for order in orders(PROVIDERS):
            tm, played = scenario(order)
            if first is None:
                first = (tm, played)
                self.assertTrue(len(played) >= 4)  # pings and the event came back stored
                continue
            self.assertEqual(first[0], tm)
            self.assertEqual(first[1], played)

    def test_no_event_reporter_counts_the_event_as_lost(self):
        loop = Loop()
        self.assertFalse(loop.app.event(3, LOW, b""))
        self.assertEqual(loop.app.events_lost, 1)

    def test_a_failing_listener_does_not_stop_the_others(self):
        loop = Loop()
        heard = []

        def broken(event_id, severity, aux):
            raise ValueError("listener defect")

        loop.app.event_listeners.append(broken)
        loop.app.event_listeners.append(lambda i, s, a: heard.append(i))
        loop.app.event(4, LOW, b"")
        self.assertEqual(heard, [4])
        self.assertEqual(loop.app.counters["listener_errors"], 1)


if __name__ == "__main__":
    unittest.main()
