"""ST[23]: file management, provider against user; copies to and from the ground over CFDP
through the remote file copy component, under PDU loss, suspended, aborted, restarted."""

import unittest

from cfdp_sim import payload
from files_loop import FilesLoop
from obsw.pus.messages import (
    FAILURE_FILESTORE,
    FAILURE_PATH,
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
)
from obsw.pus.services.s05_events import EventReporting
from obsw.pus.services.s23_files import EVENT_COPY_COMPLETED, EVENT_COPY_FAILED, match
from obsw.pus.services.s23_layouts import (
    COPY_ABORTED,
    COPY_COMPLETED,
    COPY_IN_PROGRESS,
    COPY_SUSPENDED,
)
from obsw.store import Store
from pus_loop import APID
from store_sim import SimFs

DATA = payload(3000)
BIG = payload(40000, seed=9)


def make(**kw):
    fl = FilesLoop(sat_files={"data/a.bin": DATA, "big.bin": BIG}, **kw)
    fl.sat_ent.fs.dirs.add("data")
    fl.ground_ent.fs.dirs.add("down")
    return fl


def status(fl, op):
    return fl.files.ops[op]["status"]


class TestLocalFiles(unittest.TestCase):
    def run_tx(self, fl, tx):
        fl.loop.pump()
        return tx

    def test_create_attributes_lock_delete(self):
        fl = make()
        u, fs = fl.user, fl.sat_ent.fs
        tx = self.run_tx(fl, u.create(APID, "SAT:/data/new.txt", 500))
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(fs.files["data/new.txt"]), b"")
        tx = self.run_tx(fl, u.create(APID, "SAT:/data/new.txt"))
        self.assertEqual(tx.failure["code"], FAILURE_FILESTORE)
        tx = self.run_tx(fl, u.attributes(APID, "SAT:/data/a.bin"))
        self.assertEqual(
            tx.reply,
            {
                "repository": "SAT:/data",
                "file": "a.bin",
                "size": 3000,
                "max_size": 0,
                "locked": False,
            },
        )
        self.assertTrue(self.run_tx(fl, u.lock(APID, "SAT:/data/a.bin")).ok)
        self.assertTrue(self.run_tx(fl, u.attributes(APID, "SAT:/data/a.bin")).reply["locked"])
        tx = self.run_tx(fl, u.delete(APID, "SAT:/data/a.bin"))
        self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_FILESTORE))
        self.assertTrue(self.run_tx(fl, u.unlock(APID, "SAT:/data/a.bin")).ok)
        self.assertTrue(self.run_tx(fl, u.delete(APID, "SAT:/data/a.bin")).ok)
        self.assertFalse("data/a.bin" in fs.files)
        tx = self.run_tx(fl, u.attributes(APID, "SAT:/data/a.bin"))
        self.assertEqual(tx.failure["code"], FAILURE_FILESTORE)
        self.assertEqual(fl.loop.types()[-1], (1, 4))

    def test_paths_outside_the_root_are_refused(self):
        fl = make()
        u = fl.user
        for tx in (
            u.create(APID, "SAT:/../outside.txt"),
            u.delete(APID, "SAT:/data/../../etc/passwd"),
            u.attributes(APID, "SAT:/../../x"),
            u.lock(APID, "NOWHERE:/x"),
            u.find(APID, "SAT:/..", "*"),
            u.summary(APID, "SAT:/../.."),
            u.create_directory(APID, "SAT:/../d"),
            u.delete(APID, "GROUND:/a.bin"),  # file management works on board only
        ):
            self.run_tx(fl, tx)
            self.assertEqual((tx.failure["stage"], tx.failure["code"]), (2, FAILURE_PATH))
        tx = self.run_tx(fl, u.copy(APID, 1, "SAT:/../../x", "GROUND:/x"))
        self.assertEqual(tx.failure["code"], FAILURE_PATH)
        self.assertEqual(fl.files.ops, {})

    def test_directories_find_and_summary(self):
        fl = make()
        u, fs = fl.user, fl.sat_ent.fs
        self.assertTrue(self.run_tx(fl, u.create_directory(APID, "SAT:/data/raw")).ok)
        fs.files["data/raw/img1.raw"] = bytearray(b"1")
        fs.files["data/raw/img2.raw"] = bytearray(b"22")
        tx = self.run_tx(fl, u.summary(APID, "SAT:/data"))
        self.assertEqual((tx.reply["files"], tx.reply["directories"]), (["a.bin"], ["raw"]))
        tx = self.run_tx(fl, u.find(APID, "SAT:/", "*.raw"))
        self.assertEqual(tx.reply["paths"], ["SAT:/data/raw/img1.raw", "SAT:/data/raw/img2.raw"])
        tx = self.run_tx(fl, u.find(APID, "SAT:/data", "img?.r*"))
        self.assertEqual(len(tx.reply["paths"]), 2)
        tx = self.run_tx(fl, u.delete_directory(APID, "SAT:/data/raw"))
        self.assertEqual(tx.failure["code"], FAILURE_FILESTORE)  # not empty
        tx = self.run_tx(fl, u.rename_directory(APID, "SAT:/data", "raw", "images"))
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(fs.files["data/images/img2.raw"]), b"22")
        self.assertFalse(fs.is_dir("data/raw"))
        fs.delete("data/images/img1.raw")
        fs.delete("data/images/img2.raw")
        self.assertTrue(self.run_tx(fl, u.delete_directory(APID, "SAT:/data/images")).ok)
        tx = self.run_tx(fl, u.delete_directory(APID, "SAT:/data/images"))
        self.assertEqual(tx.failure["code"], FAILURE_FILESTORE)

    def test_local_copy_and_move(self):
        fl = make()
        u, fs = fl.user, fl.sat_ent.fs
        tx = fl.run(lambda: u.copy(APID, 1, "SAT:/data/a.bin", "SAT:/copy.bin"))
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(fs.files["copy.bin"]), DATA)
        self.assertEqual(status(fl, 1), COPY_COMPLETED)
        tx = fl.run(lambda: u.copy(APID, 2, "SAT:/data/a.bin", "SAT:/copy.bin"))
        self.assertEqual(tx.failure["code"], FAILURE_FILESTORE)  # the target exists
        tx = fl.run(lambda: u.move(APID, 3, "SAT:/copy.bin", "SAT:/data/moved.bin"))
        self.assertTrue(tx.ok)
        self.assertFalse("copy.bin" in fs.files)
        self.assertEqual(bytes(fs.files["data/moved.bin"]), DATA)
        fl.run(lambda: u.lock(APID, "SAT:/data/moved.bin"))
        tx = fl.run(lambda: u.move(APID, 4, "SAT:/data/moved.bin", "SAT:/m2.bin"))
        self.assertEqual(tx.failure["code"], FAILURE_FILESTORE)  # locked
        tx = fl.run(lambda: u.copy(APID, 5, "GROUND:/a", "GROUND:/b"))
        self.assertEqual(tx.failure["code"], FAILURE_PATH)

    def test_match(self):
        self.assertTrue(match("*.bin", "a.bin"))
        self.assertTrue(match("a?c*", "abcdef"))
        self.assertFalse(match("*.bin", "a.binx"))
        self.assertTrue(match("*", ""))
        self.assertFalse(match("?", ""))


class TestRemoteCopies(unittest.TestCase):
    def test_copy_to_ground_and_back_under_loss(self):
        fl = make(loss=0.1, seed=4)
        events = fl.loop.app.register(EventReporting())
        u = fl.user
        tx = fl.run(
            lambda: u.copy(APID, 7, "SAT:/data/a.bin", "GROUND:/down/a.bin"),
            until=lambda: status(fl, 7) == COPY_COMPLETED,
        )
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(fl.ground_ent.fs.files["down/a.bin"]), DATA)
        tx = fl.run(
            lambda: u.copy(APID, 8, "GROUND:/down/a.bin", "SAT:/data/back.bin"),
            until=lambda: status(fl, 8) == COPY_COMPLETED,
        )
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(fl.sat_ent.fs.files["data/back.bin"]), DATA)
        op = fl.files.ops[8]
        self.assertEqual((op["bytes"], op["size"]), (3000, 3000))
        self.assertEqual(fl.event_ids(1), [EVENT_COPY_COMPLETED, EVENT_COPY_COMPLETED])
        self.assertEqual(events.reported, 2)
        self.assertTrue(fl.link.dropped[0] + fl.link.dropped[1] > 0)

    def test_missing_ground_file_fails_the_operation(self):
        fl = make()
        fl.loop.app.register(EventReporting())
        tx = fl.run(
            lambda: fl.user.copy(APID, 3, "GROUND:/nothing.bin", "SAT:/n.bin"),
            until=lambda: fl.files.ops.get(3, {}).get("status") not in (None, 0, 1),
            rounds=400,
        )
        self.assertTrue(tx.ok)  # the request was carried out; the ground refused the file
        self.assertEqual(status(fl, 3), 4)
        self.assertFalse("n.bin" in fl.sat_ent.fs.files)
        self.assertEqual(fl.event_ids(2), [EVENT_COPY_FAILED])

    def test_suspend_resume_and_status_reports(self):
        fl = make(max_segment=64)
        u = fl.user
        fl.run(lambda: u.enable_reports(APID, 3))
        fl.run(
            lambda: u.copy(APID, 1, "SAT:/big.bin", "GROUND:/big.bin"),
            until=lambda: 0 < fl.files.ops.get(1, {}).get("bytes", 0) < len(BIG),
        )
        tx = fl.run(lambda: u.suspend(APID, [1]))
        self.assertTrue(tx.ok)
        self.assertEqual(status(fl, 1), COPY_SUSPENDED)
        before = fl.files.ops[1]["bytes"]
        for _ in range(30):
            fl.step()
        self.assertEqual(fl.files.ops[1]["bytes"], before)
        self.assertFalse("big.bin" in fl.ground_ent.fs.files)
        tx = fl.run(lambda: u.suspend(APID, [1]))
        self.assertEqual(tx.failure["code"], 13)  # the component: not active
        tx = fl.run(lambda: u.resume(APID, [1]), until=lambda: status(fl, 1) == COPY_COMPLETED)
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(fl.ground_ent.fs.files["big.bin"]), BIG)
        seen = [o["status"] for d in fl.loop.unsolicited(23, 23) for o in d["operations"]]
        self.assertIn(COPY_IN_PROGRESS, seen)
        self.assertIn(COPY_SUSPENDED, seen)
        fl.run(lambda: u.disable_reports(APID))
        n = len(fl.loop.unsolicited(23, 23))
        for _ in range(10):
            fl.step()
        self.assertEqual(len(fl.loop.unsolicited(23, 23)), n)
        tx = fl.run(lambda: u.suspend(APID, [99]))
        self.assertEqual(tx.failure["code"], FAILURE_UNKNOWN_ID)

    def test_abort_in_path_and_move(self):
        fl = make(max_segment=64)
        u = fl.user
        fl.run(
            lambda: u.copy(APID, 1, "SAT:/big.bin", "GROUND:/big.bin"),
            until=lambda: 0 < fl.files.ops.get(1, {}).get("bytes", 0),
        )
        tx = fl.run(lambda: u.abort_in_path(APID, "GROUND:/"))
        self.assertTrue(tx.ok)
        self.assertEqual(status(fl, 1), COPY_ABORTED)
        self.assertFalse("big.bin" in fl.ground_ent.fs.files)
        tx = fl.run(
            lambda: u.move(APID, 2, "SAT:/data/a.bin", "GROUND:/a.bin"),
            until=lambda: status(fl, 2) == COPY_COMPLETED,
        )
        self.assertTrue(tx.ok)
        self.assertEqual(bytes(fl.ground_ent.fs.files["a.bin"]), DATA)
        self.assertFalse("data/a.bin" in fl.sat_ent.fs.files)
        tx = fl.run(lambda: u.move(APID, 3, "GROUND:/a.bin", "SAT:/a.bin"))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)
        tx = fl.run(lambda: u.copy(APID, 4, "SAT:/big.bin", "GROUND:/x"))
        self.assertTrue(tx.ok)
        tx = fl.run(lambda: u.copy(APID, 4, "SAT:/big.bin", "GROUND:/y"))
        self.assertEqual(tx.failure["code"], FAILURE_REFUSED)  # operation 4 is running


class TestRestarts(unittest.TestCase):
    def test_cfdp_entity_restarts_during_a_copy(self):
        fl = make(max_segment=64, loss=0.05, seed=2)
        u = fl.user
        fl.run(
            lambda: u.copy(APID, 1, "SAT:/big.bin", "GROUND:/big.bin"),
            until=lambda: fl.files.ops.get(1, {}).get("bytes", 0) > 8000,
        )
        fl.restart_cfdp()
        self.assertEqual(fl.copy.status("2:1")["state"], "active")
        fl.run(until=lambda: status(fl, 1) == COPY_COMPLETED)
        self.assertEqual(bytes(fl.ground_ent.fs.files["big.bin"]), BIG)

    def test_pus_process_restarts_during_a_get(self):
        fs = SimFs()
        fl = make(max_segment=64, store=Store("/ctx", fs))
        fl.ground_ent.fs.files["up.bin"] = bytearray(BIG)
        u = fl.user
        fl.run(
            lambda: u.copy(APID, 5, "GROUND:/up.bin", "SAT:/up.bin"),
            until=lambda: fl.files.ops.get(5, {}).get("bytes", 0) > 4000,
        )
        fl.restart_pus(Store("/ctx", fs))
        op = fl.files.ops[5]
        self.assertEqual((op["kind"], op["transfer"]), ("get", "2:1"))
        fl.run(until=lambda: status(fl, 5) == COPY_COMPLETED)
        self.assertEqual(bytes(fl.sat_ent.fs.files["up.bin"]), BIG)
        self.assertEqual(fl.files.ops[5]["bytes"], len(BIG))


if __name__ == "__main__":
    unittest.main()
