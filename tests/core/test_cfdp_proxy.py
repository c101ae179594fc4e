"""CFDP filestore requests, messages to user and proxy operations (remote get, directory
listing, remote status report, remote suspend and resume, proxy put cancel)."""

import unittest

from cfdp_sim import Link, make_pair, payload
from obsw.cfdp import msgs
from obsw.cfdp.defs import (
    ACKNOWLEDGED,
    FILE_RETAINED,
    FILESTORE_REJECTION,
    FS_NOT_PERFORMED,
    FS_SUCCESS,
    NO_ERROR,
    STATUS_ACTIVE,
    UNACKNOWLEDGED,
)
from obsw.cfdp.tlv import FilestoreRequest, MessageToUser

DATA = payload(3000)


def responses(link, side, kind):
    return [i for i in link.kinds(side, "proxy_response") if i.info["message"] == kind]


class TestFilestoreRequestsAndMessages(unittest.TestCase):
    def test_requests_executed_at_receiver_and_reported(self):
        ground, obc = make_pair(files_a={"f": DATA}, files_b={"old": b"x"})
        reqs = [
            FilestoreRequest(5, "dir"),
            FilestoreRequest(2, "incoming", "dir/final"),
            FilestoreRequest(1, "old"),
            FilestoreRequest(1, "old"),  # fails: already deleted
            FilestoreRequest(0, "never"),
        ]
        ground.put(2, "f", "incoming", filestore_requests=reqs)
        link = Link(ground, obc, seed=2, loss=0.1)
        link.run()
        self.assertEqual(bytes(obc.fs.files["dir/final"]), DATA)
        fin = link.finished(0)[0].info
        self.assertEqual(fin["condition"], NO_ERROR)
        self.assertEqual(
            [r.status for r in fin["responses"]],
            [FS_SUCCESS, FS_SUCCESS, FS_SUCCESS, 1, FS_NOT_PERFORMED],
        )
        self.assertFalse("never" in obc.fs.files)

    def test_metadata_only_with_messages_class1(self):
        ground, obc = make_pair()
        ground.put(
            2, messages=[MessageToUser(b"hello"), MessageToUser(b"world")], mode=UNACKNOWLEDGED
        )
        link = Link(ground, obc)
        link.run()
        meta = link.kinds(1, "metadata")[0].info
        self.assertEqual([m.value for m in meta["messages"]], [b"hello", b"world"])
        self.assertEqual(link.finished(1)[0].info["condition"], NO_ERROR)


class TestProxy(unittest.TestCase):
    def test_get_by_proxy_put(self):
        ground, obc = make_pair(files_b={"obc.bin": DATA})
        req = ground.put(2, messages=[msgs.proxy_put_request(1, "obc.bin", "ground.bin")])
        link = Link(ground, obc, seed=4, loss=0.1)
        link.run()
        self.assertEqual(bytes(ground.fs.files["ground.bin"]), DATA)
        incoming = [i for i in link.finished(0) if i.info["role"] == "R"]
        self.assertEqual(incoming[0].info["origin"], req)
        resp = responses(link, 0, msgs.PROXY_PUT_RESPONSE)
        self.assertEqual(resp[0].info["origin"], req)
        f = resp[0].info["fields"]
        self.assertEqual((f["condition"], f["file_status"]), (NO_ERROR, FILE_RETAINED))

    def test_proxy_options_are_forwarded(self):
        ground, obc = make_pair(files_b={"obc.bin": DATA})
        ground.put(
            2,
            messages=[
                msgs.proxy_put_request(1, "obc.bin", "g.bin"),
                msgs.proxy_transmission_mode(UNACKNOWLEDGED),
                msgs.proxy_closure_request(True),
                msgs.proxy_message_to_user(b"note"),
                msgs.proxy_filestore_request(FilestoreRequest(2, "g.bin", "h.bin")),
            ],
        )
        link = Link(ground, obc)
        link.run()
        self.assertEqual(bytes(ground.fs.files["h.bin"]), DATA)
        metas = link.kinds(0, "metadata")
        self.assertIn(b"note", [m.value for m in metas[0].info["messages"]])
        resp = responses(link, 0, msgs.PROXY_FILESTORE_RESPONSE)
        self.assertEqual(resp[0].info["fields"]["response"].status, FS_SUCCESS)

    def test_proxy_put_of_missing_file(self):
        ground, obc = make_pair()
        ground.put(2, messages=[msgs.proxy_put_request(1, "nope", "x")])
        link = Link(ground, obc)
        link.run()
        resp = responses(link, 0, msgs.PROXY_PUT_RESPONSE)
        self.assertEqual(resp[0].info["fields"]["condition"], FILESTORE_REJECTION)

    def test_proxy_put_cancel(self):
        ground, obc = make_pair(files_b={"obc.bin": DATA})
        req = ground.put(2, messages=[msgs.proxy_put_request(1, "obc.bin", "g.bin")])
        link = Link(ground, obc, drop=lambda side, pdu: side == 1 and bool(pdu[0] & 0x10))
        link.run(until=lambda: any(t.role == "S" for t in obc.tx.values()))
        ground.put(2, messages=[msgs.proxy_put_cancel(), msgs.originating_transaction_id(req)])
        link.drop = None
        link.run()
        resp = responses(link, 0, msgs.PROXY_PUT_RESPONSE)
        self.assertEqual(resp[0].info["fields"]["condition"], 15)
        self.assertFalse("g.bin" in ground.fs.files)

    def test_directory_listing(self):
        ground, obc = make_pair(files_b={"logs/a.txt": b"12", "logs/b.txt": b"345"})
        obc.fs.dirs.add("logs")
        ground.put(2, messages=[msgs.directory_listing_request("logs", "listing.txt")])
        link = Link(ground, obc)
        link.run()
        self.assertEqual(bytes(ground.fs.files["listing.txt"]), b"a.txt 2\nb.txt 3\n")
        resp = responses(link, 0, msgs.DIRECTORY_LISTING_RESPONSE)
        self.assertTrue(resp[0].info["fields"]["ok"])

    def test_remote_suspend_resume_and_status(self):
        ground, obc = make_pair(files_b={"obc.bin": DATA}, mode=ACKNOWLEDGED)
        tid = obc.put(1, "obc.bin", "down.bin")
        link = Link(ground, obc)
        link.step()
        ground.put(2, messages=[msgs.remote_suspend_request(tid)])
        link.run(until=lambda: bool(responses(link, 0, msgs.REMOTE_SUSPEND_RESPONSE)))
        self.assertTrue(obc.find(tid).suspended)
        f = responses(link, 0, msgs.REMOTE_SUSPEND_RESPONSE)[0].info["fields"]
        self.assertEqual((f["suspended"], f["status"], f["tid"]), (True, STATUS_ACTIVE, tid))
        ground.put(2, messages=[msgs.remote_status_report_request(tid, "r")])
        link.run(until=lambda: bool(responses(link, 0, msgs.REMOTE_STATUS_REPORT_RESPONSE)))
        f = responses(link, 0, msgs.REMOTE_STATUS_REPORT_RESPONSE)[0].info["fields"]
        self.assertEqual(f["status"], STATUS_ACTIVE)
        ground.put(2, messages=[msgs.remote_resume_request(tid)])
        link.run()
        f = responses(link, 0, msgs.REMOTE_RESUME_RESPONSE)[0].info["fields"]
        self.assertFalse(f["suspended"])
        self.assertEqual(bytes(ground.fs.files["down.bin"]), DATA)


if __name__ == "__main__":
    unittest.main()
