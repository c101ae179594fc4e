"""The context store: round trips, and a power cut at every step leaves old or new state."""

import os
import unittest

from obsw.store import Store, decode, encode
from store_sim import PowerCut, SimFs

OLD = {"enabled": [1, 2], "rate": 3}
NEW = {"enabled": [1, 2, 5], "rate": 4, "name": "x" * 40}


def cut_everywhere(replacing, first):
    """Save NEW over OLD (or over nothing) with the power cut at each operation and octet."""
    outcomes = set()
    cut = 1
    while True:
        partial = 0
        while True:
            files = {}
            fs = SimFs(files, replacing=replacing)
            if not first:
                Store("/ctx", fs).save("s05", OLD)
            fs.cut_at = fs.ops + cut
            fs.partial = partial
            try:
                Store("/ctx", fs).save("s05", NEW)
                finished = True
            except PowerCut:
                finished = False
            got = Store("/ctx", SimFs(files, replacing=replacing)).load("s05", "default")
            outcomes.add("new" if got == NEW else "old" if got == OLD else repr(got))
            if finished:
                return outcomes, cut
            if fs.ops != fs.cut_at or partial >= len(encode(NEW)):
                break
            partial += 1  # the cut came during a write: try every length that may land
        cut += 1


class TestStore(unittest.TestCase):
    def test_round_trip(self):
        fs = SimFs()
        store = Store("/ctx", fs)
        self.assertIsNone(store.load("s03"))
        self.assertEqual(store.load("s03", []), [])
        store.save("s03", [[1, 10, [1, 2], True]])
        store.save("s09", 4)
        self.assertEqual(Store("/ctx", fs).load("s03"), [[1, 10, [1, 2], True]])
        self.assertEqual(Store("/ctx", fs).load("s09"), 4)
        self.assertEqual(sorted(fs.files), ["/ctx/s03", "/ctx/s09"])
        store.delete("s09")
        self.assertIsNone(store.load("s09"))

    def test_power_cut_at_every_step_posix_rename(self):
        outcomes, steps = cut_everywhere(True, first=False)
        self.assertEqual(outcomes, {"old", "new"})
        self.assertTrue(steps >= 3)

    def test_power_cut_at_every_step_fat_rename(self):
        outcomes, steps = cut_everywhere(False, first=False)
        self.assertEqual(outcomes, {"old", "new"})
        self.assertTrue(steps >= 4)  # create, write, remove, rename

    def test_power_cut_on_first_save(self):
        outcomes, _ = cut_everywhere(True, first=True)
        self.assertEqual(outcomes, {"'default'", "new"})

    def test_damaged_files_are_ignored(self):
        for data in (b"", b"OBSWCTX1", encode(OLD)[:-1], encode(OLD)[:-1] + b"?", b"junk\n{}"):
            self.assertRaises(ValueError, decode, data)
            fs = SimFs({"/ctx/a": data})
            store = Store("/ctx", fs)
            self.assertEqual(store.load("a", "none"), "none")
            self.assertEqual(store.damaged, 1)

    def test_a_damaged_file_with_no_new_copy_is_set_aside(self):
        fs = SimFs({"/ctx/a": b"junk\n{}", "/ctx/b": encode(OLD)})
        store = Store("/ctx", fs)
        self.assertEqual(store.load("a", "none"), "none")
        self.assertEqual(store.rejected, ["a"])
        self.assertEqual(fs.files["/ctx/a.bad"], b"junk\n{}")
        self.assertTrue("/ctx/a" not in fs.files)
        self.assertEqual(store.load("a", "none"), "none")  # starts clean: nothing to reject
        self.assertEqual((store.damaged, store.rejected), (1, ["a"]))
        self.assertEqual(store.load("b"), OLD)
        store.set_aside("b")  # what a service refuses goes the same way
        self.assertEqual(store.rejected, ["a", "b"])
        self.assertIsNone(store.load("b"))

    def test_bad_names(self):
        store = Store("/ctx", SimFs())
        for name in ("", "a/b", ".new"):
            self.assertRaises(ValueError, store.save, name, 1)

    def test_real_file_system(self):
        import random

        root = "/tmp/obsw-store-test-%08x" % random.getrandbits(32)
        store = Store(root + "/deeper")
        store.save("ctx", NEW)
        self.assertEqual(Store(root + "/deeper").load("ctx"), NEW)
        store.save("ctx", OLD)
        self.assertEqual(Store(root + "/deeper").load("ctx"), OLD)
        store.delete("ctx")
        os.rmdir(root + "/deeper")
        os.rmdir(root)


if __name__ == "__main__":
    unittest.main()
