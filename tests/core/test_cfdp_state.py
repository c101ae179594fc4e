"""No persisted state can stop the CFDP entity: its state lives in a store of its own (not the
filestore the ground writes to), every state file is checked on load and a bad one is set aside
with a ``state_rejected`` indication; a file that goes away under a transaction ends that
transaction with the standard's filestore rejection, never the entity."""

import json
import unittest

from cfdp_sim import Link, payload
from obsw.cfdp.defs import CANCEL_REQUEST_RECEIVED, FILESTORE_REJECTION, NO_ERROR
from obsw.cfdp.entity import CfdpEntity
from obsw.cfdp.filestore import MemoryFilestore
from obsw.cfdp.mib import Mib, RemoteEntity
from obsw.cfdp.persist import StateError, check_state

DATA = payload(6000)
RECEIVER = {"role": "R", "tid": [1, 5], "mode": 0, "suspended": False, "condition": 0,
            "overrides": [], "timers": [], "hdr": [0, 0, 0, 1, 1, 2], "meta": None,
            "progress": 0, "gaps": [], "eof": None, "state": None, "finished": None}  # fmt: skip
KW = {"ack_interval": 2.0, "nak_interval": 2.0, "inactivity": 30.0, "max_segment": 64}


def entity(eid, peer, files=None, state=None):
    mib = Mib(eid, [RemoteEntity(peer, **KW)])
    fs = files if files is not None else MemoryFilestore()
    st = state if state is not None else MemoryFilestore()
    return CfdpEntity(mib, fs, persist=True, state=st)


def rejected(ent):
    return [i for i in ent.pop_indications() if i.kind == "state_rejected"]


class TestStateStore(unittest.TestCase):
    def test_state_is_kept_outside_the_filestore(self):
        a = entity(1, 2, MemoryFilestore({"src.bin": DATA}))
        b = entity(2, 1)
        tid = a.put(2, "src.bin", "dst.bin")
        link = Link(a, b)
        link.run(until=lambda: b.find(tid) is not None and b.find(tid).received > 1000)
        self.assertIn("cfdp/S-1-%d.json" % tid[1], a.state_fs.files)
        self.assertIn("cfdp/seq", a.state_fs.files)
        self.assertEqual([n for n in a.fs.files if n.endswith(".json")], [])
        self.assertEqual([n for n in b.fs.files if n.endswith(".json")], [])
        self.assertTrue(link.run())
        self.assertEqual(bytes(b.fs.files["dst.bin"]), DATA)

    def test_a_state_file_written_into_the_filestore_is_only_a_file(self):
        files = MemoryFilestore()
        files.mkdir(".cfdp")
        files.write_bytes(".cfdp/R-1-77.json", b"{}")
        ent = entity(2, 1, files)
        self.assertEqual(ent.restore(0.0), 0)
        self.assertEqual(ent.tx, {})
        self.assertEqual(bytes(files.files[".cfdp/R-1-77.json"]), b"{}")


class TestBadState(unittest.TestCase):
    def restart_with(self, name, content):
        state = MemoryFilestore()
        state.mkdir("cfdp")
        state.write_bytes("cfdp/" + name, content)
        ent = entity(2, 1, state=state)
        n = ent.restore(0.0)
        return ent, state, n

    def check_set_aside(self, name, content):
        ent, state, n = self.restart_with(name, content)
        self.assertEqual(n, 0)
        self.assertEqual(ent.tx, {})
        self.assertEqual([i.info["name"] for i in rejected(ent)], [name])
        self.assertIn("cfdp/bad-" + name, state.files)
        self.assertTrue("cfdp/" + name not in state.files)
        self.assertEqual(ent.stats["state_rejected"], 1)
        # the entity starts clean and works
        self.assertEqual(ent.restore(0.0), 0)
        self.assertEqual(rejected(ent), [])
        return ent

    def test_empty_object(self):
        self.check_set_aside("R-1-77.json", b"{}")

    def test_not_json(self):
        self.check_set_aside("S-2-3.json", b"\xff\xfe{")

    def test_wrong_types(self):
        st = dict(RECEIVER, progress="lots")
        self.check_set_aside("R-1-5.json", json.dumps(st).encode())

    def test_name_and_content_disagree(self):
        st = dict(RECEIVER, tid=[1, 6])
        self.check_set_aside("R-1-5.json", json.dumps(st).encode())

    def test_sender_whose_file_is_gone(self):
        a = entity(1, 2, MemoryFilestore({"src.bin": DATA}))
        tid = a.put(2, "src.bin", "dst.bin")
        name = "S-1-%d.json" % tid[1]
        content = bytes(a.state_fs.files["cfdp/" + name])
        self.check_set_aside(name, content.replace(b"src.bin", b"gone.bin"))

    def test_bad_sequence_number(self):
        for text in (b"x", b"-4", b"99999999999"):
            ent = self.check_set_aside("seq", text)
            self.assertEqual(ent.seq, 1)

    def test_bad_remote_copy_records(self):
        from obsw.cfdp.remote_copy import RemoteCopy

        for content in (b"{}", b"[1]", b'[{"transfer": 3}]', b"\x00"):
            state = MemoryFilestore()
            state.mkdir("cfdp")
            state.write_bytes("cfdp/remote-copy.json", content)
            ent = entity(2, 1, state=state)
            copy = RemoteCopy(ent)
            self.assertEqual(copy.records, {})
            self.assertEqual([i.info["name"] for i in rejected(ent)], ["remote-copy.json"])

    def test_check_state_boundaries(self):
        self.assertRaises(StateError, check_state, [])
        self.assertRaises(StateError, check_state, {"role": "X"})
        a = entity(1, 2, MemoryFilestore({"src.bin": DATA}))
        tid = a.put(2, "src.bin", "dst.bin")
        st = json.loads(bytes(a.state_fs.files["cfdp/S-1-%d.json" % tid[1]]).decode())
        check_state(st)  # a real one passes
        for field in ("tid", "progress", "resend", "timers"):
            bad = dict(st)
            del bad[field]
            self.assertRaises(StateError, check_state, bad)
        bad = dict(st, tid=[1])
        self.assertRaises(StateError, check_state, bad)
        bad = dict(st, progress=-1)
        self.assertRaises(StateError, check_state, bad)


class TestFileGone(unittest.TestCase):
    def test_file_deleted_while_it_is_sent(self):
        """The ground asks for a file, then deletes it: that transaction ends with the
        filestore rejection fault (the receiver is told), the entity goes on."""
        files = MemoryFilestore({"src.bin": DATA, "other.bin": DATA})
        a = entity(1, 2, files)
        b = entity(2, 1)
        tid = a.put(2, "src.bin", "dst.bin")
        link = Link(a, b)
        link.step()
        del files.files["src.bin"]  # deleted under the transfer: what was not read yet is gone
        tx = a.find(tid)
        tx._fh = None
        tx._ra = None  # nor read ahead
        self.assertTrue(link.run())
        conds = [i.info["condition"] for i in link.finished(0)]
        self.assertEqual(len(conds), 1)
        self.assertIn(conds[0], (FILESTORE_REJECTION, CANCEL_REQUEST_RECEIVED))
        self.assertEqual(a.stats["internal_errors"], 0)  # a fault, not a defect
        self.assertEqual(a.tx, {})
        self.assertEqual(b.tx, {})
        # nothing of it is left to restore, and the entity still sends files
        a2 = entity(1, 2, files, a.state_fs)
        self.assertEqual(a2.restore(link.now), 0)
        tid2 = a2.put(2, "other.bin", "o.bin")
        link.ents[0] = a2
        self.assertTrue(link.run())
        self.assertEqual(bytes(b.fs.files["o.bin"]), DATA)
        self.assertEqual([i.info["condition"] for i in link.finished(0)][-1:], [NO_ERROR])
        self.assertTrue(tid2[1] > tid[1])


class TestNulInNames(unittest.TestCase):
    def test_a_nul_in_a_file_name_is_a_filestore_rejection_the_sender_is_told(self):
        a = entity(1, 2, MemoryFilestore({"src.bin": DATA}))
        b = entity(2, 1)
        tid = a.put(2, "src.bin", "bad\0name.bin")
        link = Link(a, b)
        self.assertTrue(link.run())
        self.assertEqual([i.info["condition"] for i in link.finished(0)], [FILESTORE_REJECTION])
        self.assertEqual([i.info["condition"] for i in link.finished(1)], [FILESTORE_REJECTION])
        self.assertEqual(b.tx, {})
        self.assertEqual([n for n in b.fs.files if "bad" in n], [])
        self.assertTrue(tid[1] >= 1)
        with self.assertRaises(OSError):
            MemoryFilestore().open_write("a\0b")


if __name__ == "__main__":
    unittest.main()
