"""ST[11]: every request, provider against user; exact release times; restart mid-schedule."""

import unittest

from obsw.pus.services.s01_verification import (
    FAILURE_ILLEGAL_APP_DATA,
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
)
from obsw.pus.services.s11_scheduling import TimeScheduling, TimeSchedulingUser
from obsw.pus.services.s17_test import ServiceTest, ServiceTestUser
from obsw.store import Store
from pus_loop import APID, Loop
from store_sim import SimFs

T0 = 1000.0  # the loop's clock starts here


def make(store=None, **options):
    loop = Loop(store=store)
    sched = loop.app.register(TimeScheduling(**options))
    loop.app.register(ServiceTest())
    loop.ground.register(ServiceTestUser())
    user = loop.ground.register(TimeSchedulingUser())
    return loop, sched, user


def ping(user):
    """A TC[17,1] to schedule, and its transaction."""
    return user.embed(APID, 17, 1)[1]


def advance_to(loop, t):
    loop.clock.advance(t - loop.clock.now())
    loop.app.tick()
    loop.pump()


def start_failure(tx):
    return (tx.failure["stage"], tx.failure["code"]) if tx.failure else None


class TestRelease(unittest.TestCase):
    def test_release_at_the_exact_time_with_verification(self):
        loop, sched, user = make()
        a, b = ping(user), ping(user)
        tx = loop.run(user.insert(APID, [(T0 + 10.0, a), (T0 + 5.5, b)]))
        self.assertTrue(tx.ok)
        self.assertEqual([x.tag for x in sched.activities], [(1005 << 16) | 32768, 1010 << 16])
        advance_to(loop, T0 + 5.4999)
        self.assertFalse(b.done)
        advance_to(loop, T0 + 5.5)
        self.assertTrue(b.ok)
        self.assertEqual(loop.types()[-4:], [(1, 1), (1, 3), (17, 2), (1, 7)])
        self.assertEqual(
            b.verification(), ["acceptance success", "start success", "completion success"]
        )
        advance_to(loop, T0 + 9.99)
        self.assertFalse(a.done)
        advance_to(loop, T0 + 10.0)
        self.assertTrue(a.ok)
        self.assertEqual((sched.released, sched.activities), (2, []))

    def test_release_order_and_several_in_one_cycle(self):
        loop, sched, user = make()
        txs = [ping(user) for _ in range(3)]
        loop.run(user.insert(APID, [(T0 + 3, txs[2]), (T0 + 1, txs[0]), (T0 + 2, txs[1])]))
        advance_to(loop, T0 + 5)
        pings = [tm for tm in loop.tm if (tm.service, tm.subtype) == (17, 2)]
        self.assertEqual(len(pings), 3)
        self.assertTrue(all(t.ok for t in txs))
        seqs = [
            r["request_id"].seq_count
            for tm, r, tx in loop.results
            if tm.subtype == 7 and tx in txs
        ]
        self.assertEqual(seqs, [t.tc.seq_count for t in txs])

    def test_disabled_schedule_skips_and_enable_resumes(self):
        loop, sched, user = make()
        a, b = ping(user), ping(user)
        loop.run(user.insert(APID, [(T0 + 1, a), (T0 + 3, b)]))
        self.assertTrue(loop.run(user.disable(APID)).ok)
        advance_to(loop, T0 + 2)
        self.assertEqual((a.done, sched.skipped, len(sched.activities)), (False, 1, 1))
        self.assertTrue(loop.run(user.enable(APID)).ok)
        advance_to(loop, T0 + 3)
        self.assertTrue(b.ok)

    def test_reset(self):
        loop, sched, user = make()
        loop.run(user.create_groups(APID, [4]))
        loop.run(user.insert(APID, [(T0 + 1, ping(user), 0, 4)]))
        self.assertTrue(loop.run(user.reset(APID)).ok)
        self.assertEqual((sched.activities, sched.groups, sched.enabled), ([], {}, False))


class TestReports(unittest.TestCase):
    def setUp(self):
        self.loop, self.sched, self.user = make(subschedules=3)
        self.loop.run(self.user.create_groups(APID, [1, 2]))
        self.txs = [ping(self.user) for _ in range(4)]
        self.loop.run(
            self.user.insert(
                APID,
                [
                    (T0 + 10, self.txs[0], 0, 1),
                    (T0 + 20, self.txs[1], 1, 1),
                    (T0 + 30, self.txs[2], 2, 2),
                    (T0 + 40.25, self.txs[3], 1, 0),
                ],
            )
        )

    def times(self, tx):
        return [a["time"] for a in tx.reply["activities"]]

    def test_detail_reports(self):
        loop, user = self.loop, self.user
        tx = loop.run(user.detail_all(APID))
        self.assertEqual(self.times(tx), [1010.0, 1020.0, 1030.0, 1040.25])
        first = tx.reply["activities"][0]
        self.assertEqual((first["type"], first["subschedule"], first["group"]), ((17, 1), 0, 1))
        self.assertEqual(first["request"], self.txs[0].tc.pack())
        tx = loop.run(user.detail(APID, [self.txs[2], self.txs[0]]))
        self.assertEqual(self.times(tx), [1030.0, 1010.0])
        tx = loop.run(user.detail_filter(APID, T0 + 15, T0 + 35))
        self.assertEqual(self.times(tx), [1020.0, 1030.0])
        tx = loop.run(user.detail_filter(APID, subschedules=[1]))
        self.assertEqual(self.times(tx), [1020.0, 1040.25])
        tx = loop.run(user.detail_filter(APID, end=T0 + 20, groups=[1]))
        self.assertEqual(self.times(tx), [1010.0, 1020.0])
        tx = loop.run(user.detail_filter(APID, start=T0 + 25))
        self.assertEqual(self.times(tx), [1030.0, 1040.25])

    def test_summary_reports(self):
        loop, user = self.loop, self.user
        tx = loop.run(user.summary_all(APID))
        got = tx.reply["activities"][3]
        self.assertEqual(
            got,
            {
                "subschedule": 1,
                "group": 0,
                "source": 7,
                "apid": APID,
                "seq_count": self.txs[3].tc.seq_count,
                "time": 1040.25,
            },
        )
        tx = loop.run(user.summary(APID, [self.txs[1]]))
        self.assertEqual(self.times(tx), [1020.0])
        tx = loop.run(user.summary_filter(APID, groups=[2]))
        self.assertEqual(self.times(tx), [1030.0])

    def test_time_shifts(self):
        loop, user = self.loop, self.user
        self.assertTrue(loop.run(user.shift(APID, 2.5, [self.txs[0]])).ok)
        self.assertTrue(loop.run(user.shift_filter(APID, -5, T0 + 25, T0 + 45)).ok)
        tx = loop.run(user.detail_all(APID))
        self.assertEqual(self.times(tx), [1012.5, 1020.0, 1025.0, 1035.25])
        self.assertTrue(loop.run(user.shift_all(APID, 100)).ok)
        tx = loop.run(user.summary_all(APID))
        self.assertEqual(self.times(tx), [1112.5, 1120.0, 1125.0, 1135.25])
        advance_to(loop, 1112.4)
        self.assertFalse(self.txs[0].done)
        advance_to(loop, 1112.5)
        self.assertTrue(self.txs[0].ok)

    def test_shift_into_the_past_is_refused_and_changes_nothing(self):
        loop, user = self.loop, self.user
        tx = loop.run(user.shift_all(APID, -15))
        self.assertEqual(start_failure(tx), (2, FAILURE_REFUSED))
        rid = self.txs[0].tc
        self.assertEqual(tx.failure["data"], bytes([0, 7, 0, APID, 0, rid.seq_count]))
        tx = loop.run(user.summary_all(APID))
        self.assertEqual(self.times(tx), [1010.0, 1020.0, 1030.0, 1040.25])

    def test_deletes(self):
        loop, user, sched = self.loop, self.user, self.sched
        self.assertTrue(loop.run(user.delete(APID, [self.txs[1]])).ok)
        self.assertTrue(loop.run(user.delete_filter(APID, subschedules=[2])).ok)
        self.assertEqual([a.tag >> 16 for a in sched.activities], [1010, 1040])
        tx = loop.run(user.delete(APID, [self.txs[1]]))
        self.assertEqual(start_failure(tx), (2, FAILURE_UNKNOWN_ID))
        self.assertTrue(loop.run(user.delete_filter(APID)).ok)
        self.assertEqual(sched.activities, [])

    def test_subschedules(self):
        loop, user, sched = self.loop, self.user, self.sched
        self.assertTrue(loop.run(user.disable_subschedules(APID, [1])).ok)
        tx = loop.run(user.subschedule_status(APID))
        self.assertEqual(
            tx.reply["items"],
            [{"id": 0, "enabled": True}, {"id": 1, "enabled": False}, {"id": 2, "enabled": True}],
        )
        advance_to(loop, T0 + 25)
        self.assertEqual((self.txs[0].ok, self.txs[1].done, sched.skipped), (True, False, 1))
        self.assertTrue(loop.run(user.enable_subschedules(APID, [1])).ok)
        tx = loop.run(user.enable_subschedules(APID, [1, 7]))
        self.assertEqual(
            (start_failure(tx), tx.failure["data"]), ((2, FAILURE_UNKNOWN_ID), b"\x07")
        )

    def test_groups(self):
        loop, user, sched = self.loop, self.user, self.sched
        tx = loop.run(user.delete_groups(APID, [1]))  # it has activities
        self.assertEqual((start_failure(tx), tx.failure["data"]), ((2, FAILURE_REFUSED), b"\x01"))
        self.assertTrue(loop.run(user.disable_groups(APID, [2])).ok)
        tx = loop.run(user.group_status(APID))
        self.assertEqual(
            tx.reply["items"], [{"id": 1, "enabled": True}, {"id": 2, "enabled": False}]
        )
        advance_to(loop, T0 + 35)
        self.assertEqual((self.txs[1].ok, self.txs[2].done, sched.skipped), (True, False, 1))
        self.assertTrue(loop.run(user.enable_groups(APID, [2])).ok)
        tx = loop.run(user.create_groups(APID, [2]))
        self.assertEqual((start_failure(tx), tx.failure["data"]), ((2, FAILURE_REFUSED), b"\x02"))
        tx = loop.run(user.create_groups(APID, [0]))
        self.assertEqual(start_failure(tx), (2, FAILURE_REFUSED))
        self.assertTrue(loop.run(user.create_groups(APID, [9])).ok)
        self.assertTrue(loop.run(user.delete_groups(APID, [2, 9])).ok)  # group 2 now empty
        self.assertEqual(sorted(sched.groups), [1])
        tx = loop.run(user.enable_groups(APID, [5]))
        self.assertEqual(
            (start_failure(tx), tx.failure["data"]), ((2, FAILURE_UNKNOWN_ID), b"\x05")
        )


class TestBadInput(unittest.TestCase):
    def test_malformed_requests_fail_acceptance(self):
        loop, sched, user = make()
        good = ping(user).tc.pack()
        for data in (
            b"\x00",  # N cut short
            b"\x00\x01\x00\x00",  # N=1, no activity
            b"\x00\x01\x00\x00" + bytes(6) + good[:-1],  # request cut short
            b"\x00\x01\x00\x00" + bytes(6) + good[:-2] + b"\x00\x00",  # bad checksum
        ):
            tx = loop.run(loop.ground.send(APID, 11, 4, data))
            self.assertEqual(
                (tx.failure["stage"], tx.failure["code"]), (1, FAILURE_ILLEGAL_APP_DATA)
            )
        for data in (b"\x04", b"\x01" + bytes(6)):  # unknown window type; tags missing
            tx = loop.run(loop.ground.send(APID, 11, 11, data))
            self.assertEqual(tx.failure["code"], FAILURE_ILLEGAL_APP_DATA)
        tx = loop.run(loop.ground.send(APID, 11, 1, b"\x00"))  # trailing data
        self.assertEqual(tx.failure["code"], FAILURE_ILLEGAL_APP_DATA)
        self.assertEqual(sched.activities, [])

    def test_conflicting_or_out_of_range_inserts_are_refused(self):
        loop, sched, user = make(capacity=2, margin=1.0)
        a = ping(user)
        self.assertTrue(loop.run(user.insert(APID, [(T0 + 5, a)])).ok)
        other = user.embed(99, 17, 1)[1]
        for items, code in (
            ([(T0 + 6, a)], FAILURE_REFUSED),  # same request ID
            ([(T0 + 0.5, ping(user))], FAILURE_REFUSED),  # inside the margin
            ([(T0 - 10, ping(user))], FAILURE_REFUSED),  # in the past
            ([(T0 + 6, ping(user)), (T0 + 7, ping(user))], FAILURE_REFUSED),  # full
            ([(T0 + 6, ping(user), 3)], FAILURE_UNKNOWN_ID),  # no sub-schedule 3
            ([(T0 + 6, ping(user), 0, 8)], FAILURE_UNKNOWN_ID),  # no group 8
            ([(T0 + 6, other)], FAILURE_UNKNOWN_ID),  # no process 99
        ):
            tx = loop.run(user.insert(APID, items))
            self.assertEqual(start_failure(tx), (2, code))
        self.assertEqual(len(sched.activities), 1)
        tx = loop.run(user.detail_filter(APID, T0 + 10, T0 + 5))
        self.assertEqual(start_failure(tx), (2, FAILURE_REFUSED))

    def test_other_process_through_route(self):
        routed = []
        loop, sched, user = make(route=routed.append)
        tx = user.embed(11, 17, 1)[1]
        loop.run(user.insert(APID, [(T0 + 1, tx)]))
        advance_to(loop, T0 + 1)
        self.assertEqual(routed, [tx.tc.pack()])


class TestPersistence(unittest.TestCase):
    def test_restart_mid_schedule_loses_nothing(self):
        fs = SimFs()
        loop, sched, user = make(Store("/ctx", fs), subschedules=2)
        a, b, c = ping(user), ping(user), ping(user)
        loop.run(user.create_groups(APID, [3]))
        loop.run(user.disable_subschedules(APID, [1]))
        loop.run(user.insert(APID, [(T0 + 1, a), (T0 + 7.75, b, 0, 3), (T0 + 9, c, 1)]))
        advance_to(loop, T0 + 2)
        self.assertTrue(a.ok)
        # the process restarts: a new application process on the same store
        loop2, sched2, user2 = make(Store("/ctx", fs), subschedules=2)
        loop2.clock.advance(2)
        self.assertEqual([x.tag for x in sched2.activities], [(1007 << 16) | 49152, 1009 << 16])
        self.assertEqual((sched2.groups, sched2.subschedules), ({3: True}, {0: True, 1: False}))
        loop2.ground = loop.ground  # the same ground, with b's transaction open
        advance_to(loop2, T0 + 7.7)
        self.assertFalse(b.done)
        advance_to(loop2, T0 + 7.75)
        self.assertTrue(b.ok)
        advance_to(loop2, T0 + 9)
        self.assertEqual((c.done, sched2.skipped, sched2.released), (False, 1, 1))
        pings = [t for t in loop.tm + loop2.tm if (t.service, t.subtype) == (17, 2)]
        self.assertEqual(len(pings), 2)  # nothing released twice

    def test_activities_due_while_down_go_out_on_the_first_cycle(self):
        fs = SimFs()
        loop, sched, user = make(Store("/ctx", fs))
        a = ping(user)
        loop.run(user.insert(APID, [(T0 + 1, a)]))
        loop2, sched2, _ = make(Store("/ctx", fs))
        loop2.ground = loop.ground
        advance_to(loop2, T0 + 60)
        self.assertTrue(a.ok)

    def test_broken_context_is_ignored(self):
        fs = SimFs()
        Store("/ctx", fs).save("s11", {"enabled": True, "activities": [[1, 0, 0, "zz"]]})
        loop, sched, user = make(Store("/ctx", fs))
        self.assertEqual((sched.activities, loop.app.counters["context_rejected"]), ([], 1))


if __name__ == "__main__":
    unittest.main()
