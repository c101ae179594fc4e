"""The context store under sequences of power cuts: after every cut at every operation (and
every partial write) of a save, and of the save after it, ``load`` gives the last state it
could give before, or the new one; never nothing. With and without an atomic rename."""

import unittest

from obsw.jsonsafe import JsonDepthError
from obsw.store import Store, decode, encode
from store_sim import PowerCut, SimFs

V = [{"v": 0}, {"v": 1, "text": "x" * 30}, {"v": 2, "list": [1, 2, 3]}, {"v": 3}]


def load(files, replacing):
    return Store("/ctx", SimFs(files, replacing=replacing)).load("s", "none")


def save(files, replacing, value, cut=None, partial=0):
    """Save with the power cut at operation ``cut`` (None: no cut); True if it finished."""
    fs = SimFs(files, replacing=replacing, cut_at=cut, partial=partial)
    try:
        Store("/ctx", fs).save("s", value)
        return True
    except PowerCut:
        return False


def cuts(value):
    """(operation, partial octets) pairs to try: every operation of a save, and for each one
    that is a write a few lengths of what still lands (none, one, half, all but one)."""
    n = len(encode(value))
    out = []
    for op in range(1, 9):
        for partial in sorted(set((0, 1, n // 2, n - 1))):
            out.append((op, partial))
    return out


class TestCuts(unittest.TestCase):
    def pairs(self, replacing):
        seen = 0
        for c1, p1 in cuts(V[1]):
            files = {}
            save(files, replacing, V[0])
            save(files, replacing, V[1], c1, p1)
            first = load(files, replacing)
            self.assertIn(first, (V[0], V[1]))
            for c2, p2 in cuts(V[2]):
                f2 = dict(files)
                save(f2, replacing, V[2], c2, p2)
                second = load(f2, replacing)
                self.assertIn(second, (first, V[2]))
                self.assertTrue(save(f2, replacing, V[3]))  # and the store goes on working
                self.assertEqual(load(f2, replacing), V[3])
                seen += 1
        return seen

    def test_pairs_of_cuts_posix_rename(self):
        self.assertTrue(self.pairs(True) > 500)

    def test_pairs_of_cuts_fat_rename(self):
        self.assertTrue(self.pairs(False) > 500)

    def test_sequences_of_cuts(self):
        # a deterministic walk: each save cut somewhere (or not), up to eight in a row
        x = 12345
        for replacing in (True, False):
            for _ in range(150):
                files = {}
                save(files, replacing, V[0])
                last = V[0]
                for k in range(8):
                    x = (x * 1103515245 + 12345) & 0x7FFFFFFF
                    value = {"v": k + 10, "pad": "p" * (x % 40)}
                    cut = x % 9 or None  # 0: no cut
                    partial = (x >> 8) % len(encode(value))
                    done = save(files, replacing, value, cut, partial)
                    got = load(files, replacing)
                    self.assertIn(got, (last, value))
                    if done:
                        self.assertEqual(got, value)
                    last = got

    def test_deep_json_is_a_damaged_file(self):
        body = b"[" * 5000 + b"]" * 5000
        from obsw.crc import crc32

        data = b"OBSWCTX1 %08x %d\n" % (crc32(body), len(body)) + body
        self.assertRaises(JsonDepthError, decode, data)
        store = Store("/ctx", SimFs({"/ctx/s": data}))
        self.assertEqual(store.load("s", "none"), "none")
        self.assertEqual(store.damaged, 1)


if __name__ == "__main__":
    unittest.main()
