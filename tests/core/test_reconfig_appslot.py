"""The reconfiguration module's application slot: a verified package becomes the slot on trial,
a trial is confirmed or left after its starts, and a slot whose application raises gives way
to the frozen one. Runs on the unix port, on CPython and on the QEMU board's littlefs."""

import hashlib
import io
import os
import sys
import unittest

from obsw.reconfig import appslot
from obsw.update.package import BadSignature, HashMismatch, WrongTarget, canonical, header

KEY = b"k" * 32


def sign(key, message):
    digest = hashlib.sha256(key + message).digest()
    return digest + digest


def verify(key, signature, message):
    return signature == sign(key, message)


def _hex(data):
    return "".join("%02x" % b for b in hashlib.sha256(data).digest())


MODULE = "APP_VERSION = %r\n"


def package(version, files=None, target="reconfig", key=KEY):
    files = files or [("appslot_probe.py", (MODULE % version).encode())]
    tree = {}
    for p, d in files:
        tree[p] = _hex(d)
    m = {
        "format": 1,
        "mission": "sat-1",
        "target": target,
        "version": version,
        "base": None,
        "created": "2026-11-25T00:00:00Z",
        "files": [{"path": p, "size": len(d), "sha256": _hex(d)} for p, d in files],
        "tree": tree,
    }
    body = canonical(m)
    return header(body, sign(key, body)) + b"".join(d for _, d in files)


def _temp():
    base = (os.getenv("TMPDIR") if hasattr(os, "getenv") else None) or "/tmp"
    try:
        os.stat(base)
    except OSError:
        base = ""  # a board: its filesystem's top
    pid = os.getpid() if hasattr(os, "getpid") else 0
    path = (base.rstrip("/") + "/" if base else "") + "obsw-appslot-%d" % pid
    appslot.remove_tree(path)
    os.mkdir(path)
    return path


class TestSlot(unittest.TestCase):
    def setUp(self):
        self.root = _temp()
        self.modules = dict(sys.modules)  # boot() drops the obsw modules: the suite's come back
        self.path = list(sys.path)
        sys.modules.pop("appslot_probe", None)

    def tearDown(self):
        appslot.remove_tree(self.root)
        sys.modules.clear()
        sys.modules.update(self.modules)
        sys.path[:] = self.path

    def stage(self, data, **kw):
        return appslot.stage(self.root, io.BytesIO(data), verify, KEY, kw.get("mission", "sat-1"))

    def start(self):
        try:
            import appslot_probe
        except ImportError:
            return "frozen"
        return appslot_probe.APP_VERSION

    def test_staged_runs_on_trial_then_is_confirmed(self):
        m = self.stage(package("1.1"))
        self.assertEqual(m["version"], "1.1")
        self.assertEqual(appslot.running(self.root), ("1.1", "trial"))
        self.assertEqual(appslot.boot(self.root, self.start, out=lambda t: None), "1.1")
        self.assertEqual(appslot.read(self.root)["starts"], 1)
        self.assertTrue(appslot.confirm(self.root))
        self.assertFalse(appslot.confirm(self.root))
        self.assertEqual(appslot.choose(self.root, 2), self.root + "/" + appslot.SLOT)
        self.assertEqual(appslot.running(self.root), ("1.1", "good"))

    def test_a_module_of_a_package_takes_the_place_of_the_image_one(self):
        import obsw
        import obsw.bits

        frozen = obsw.bits
        files = [("obsw/bits.py", b"from obsw.compat import const\nSLOT_MARK = 'from the slot'\n")]
        self.stage(package("1.1", files))

        def start():
            from obsw import bits

            return getattr(bits, "SLOT_MARK", "frozen")

        try:
            self.assertEqual(appslot.boot(self.root, start, out=lambda t: None), "from the slot")
            self.assertFalse(hasattr(frozen, "SLOT_MARK"))
        finally:
            obsw.bits = frozen  # the suite's module again

    def test_a_trial_that_never_confirms_is_left(self):
        self.stage(package("1.1"))
        for _ in range(2):
            self.assertEqual(appslot.choose(self.root, 2), self.root + "/" + appslot.SLOT)
        self.assertIsNone(appslot.choose(self.root, 2))  # a third start: the watchdog reset it
        record = appslot.read(self.root)
        self.assertEqual(record["state"], "failed")
        self.assertEqual(record["reason"], "did not confirm in 2 starts")

    def test_an_application_that_raises_gives_way_to_the_frozen_one(self):
        self.stage(package("1.2", [("appslot_probe.py", b"raise RuntimeError('broken')\n")]))
        said = []
        self.assertEqual(appslot.boot(self.root, self.start, out=said.append), "frozen")
        self.assertEqual(appslot.read(self.root)["state"], "failed")
        self.assertIn("RuntimeError: broken", appslot.read(self.root)["reason"])
        self.assertIn("the frozen one starts", said[-1])
        self.assertIsNone(appslot.choose(self.root, 2))

    def test_bad_packages_are_refused_and_change_nothing(self):
        self.stage(package("1.1"))
        data = bytearray(package("1.2"))
        data[-3] ^= 1
        cases = (
            (HashMismatch, bytes(data)),
            (BadSignature, package("1.2", key=b"x" * 32)),
            (WrongTarget, package("1.2", target="obc")),
        )
        for cls, bad in cases:
            with self.assertRaises(cls):
                self.stage(bad)
            self.assertEqual(appslot.running(self.root), ("1.1", "trial"))  # as it was
            self.assertEqual(sorted(os.listdir(self.root)), [appslot.SLOT, appslot.RECORD])

    def test_no_record_no_slot(self):
        self.assertIsNone(appslot.choose(self.root, 2))
        self.assertEqual(appslot.boot(self.root, self.start, out=lambda t: None), "frozen")


if __name__ == "__main__":
    unittest.main()
