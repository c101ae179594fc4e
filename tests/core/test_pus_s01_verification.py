"""ST[01]: every report the provider builds, decoded by the user, matched to its request."""

import unittest

from obsw.pus.packets import ACK_ALL, ACK_PROGRESS, RequestId
from obsw.pus.services.base import Service
from obsw.pus.services.s01_verification import (
    ACCEPTANCE,
    COMPLETION,
    FAILURE_REFUSED,
    PROGRESS,
    ROUTING,
    START,
    PusFailure,
    VerificationUser,
    describe,
)
from obsw.pus.tm import PusTm
from pus_loop import APID, Loop


class Stages(Service):
    """Fails at the stage the first data octet names (0: succeed with two progress steps)."""

    SERVICE = 200
    HANDLERS = (((200, 1), "run"),)

    def run(self, req):
        where = req.data[0] if req.data else 0
        if where == 1:
            raise PusFailure(5, data=b"\xaa")
        req.accept()
        if where == 2:
            raise PusFailure(FAILURE_REFUSED, data=b"\xbb")
        req.start()
        req.progress(1)
        if where == 3:
            raise PusFailure(FAILURE_REFUSED, data=b"\xcc", step=2)
        req.progress(2)
        if where == 4:
            raise PusFailure(FAILURE_REFUSED, data=b"\xdd")


def send(where):
    loop = Loop()
    loop.app.register(Stages())
    tx = loop.ground.send(APID, 200, 1, bytes((where,)), None, ACK_ALL | ACK_PROGRESS)
    loop.pump()
    return loop, tx


class TestVerification(unittest.TestCase):
    def test_all_successes(self):
        loop, tx = send(0)
        self.assertEqual(loop.types(), [(1, 1), (1, 3), (1, 5), (1, 5), (1, 7)])
        self.assertEqual(
            [r["stage"] for r in tx.reports], [ACCEPTANCE, START, PROGRESS, PROGRESS, COMPLETION]
        )
        self.assertEqual([r.get("step") for r in tx.reports], [None, None, 1, 2, None])
        self.assertTrue(tx.ok)
        self.assertTrue(tx.accepted)
        self.assertTrue(tx.started)
        self.assertTrue(tx.completed)
        for r in tx.reports:
            self.assertEqual(r["request_id"], RequestId(APID, tx.tc.seq_count))

    def test_failures_at_each_stage(self):
        for where, subtype, stage, data in (
            (1, 2, ACCEPTANCE, b"\xaa"),
            (2, 4, START, b"\xbb"),
            (3, 6, PROGRESS, b"\xcc"),
            (4, 8, COMPLETION, b"\xdd"),
        ):
            loop, tx = send(where)
            self.assertEqual(loop.types()[-1], (1, subtype))
            self.assertTrue(tx.done)
            self.assertFalse(tx.ok)
            self.assertEqual(tx.failure["stage"], stage)
            self.assertEqual(tx.failure["data"], data)
            self.assertEqual(tx.stage(stage), False)
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)

    def test_progress_failure_names_the_step(self):
        loop, tx = send(3)
        self.assertEqual(tx.failure["step"], 2)
        self.assertEqual(
            describe(tx.failure), "progress failure step 2: refused (code 10) data cc"
        )

    def test_routing_failure_decodes(self):
        user = VerificationUser()
        user.attach(None)
        rid = RequestId(33, 7)
        tm = PusTm(APID, 1, 10, rid.pack() + b"\x00\x01\x02")
        report = user.decoder(10)(tm)
        self.assertEqual(report["stage"], ROUTING)
        self.assertEqual(report["request_id"], rid)
        self.assertEqual((report["code"], report["data"]), (0, b"\x01\x02"))

    def test_truncated_report_is_undecodable(self):
        loop = Loop()
        for data in (b"", b"\x18\x0a\xc0", RequestId(APID, 0).pack()):
            loop.ground.receive(PusTm(APID, 1, 2, data).pack())
        loop.ground.receive(PusTm(APID, 1, 1, RequestId(APID, 0).pack() + b"x").pack())
        self.assertEqual(loop.ground.counters["undecodable"], 4)

    def test_unmatched_report_is_counted(self):
        loop = Loop()
        loop.ground.receive(PusTm(APID, 1, 1, RequestId(APID, 99).pack()).pack())
        self.assertEqual(loop.ground.counters["unmatched_reports"], 1)


if __name__ == "__main__":
    unittest.main()
