"""Durability order of a CFDP receiver (issue 34): the partial file's data is on the medium
before the saved progress claims it, so a power cut at any point of a transfer loses only what
the sender sends again, never a delivered file (a cut loses every write not yet synced)."""

import unittest

from cfdp_sim import Link, payload
from obsw.cfdp.defs import NO_ERROR
from obsw.cfdp.entity import CfdpEntity
from obsw.cfdp.filestore import MemoryFilestore
from obsw.cfdp.mib import Mib, RemoteEntity

DATA = payload(20000)
KW = {"ack_interval": 2.0, "nak_interval": 2.0, "inactivity": 60.0, "max_segment": 200}


class _Handle:
    def __init__(self, fs, name, inner):
        self.fs = fs
        self.name = name
        self.inner = inner

    def read(self, offset, n):
        return self.inner.read(offset, n)

    def write(self, offset, data):
        self.inner.write(offset, data)

    def sync(self):
        n = self.fs._n(self.name)
        self.fs.durable[n] = bytes(self.fs.files[n])

    def close(self):
        self.inner.close()


class CutFilestore(MemoryFilestore):
    """A filestore whose power can be cut: each file goes back to what was last synced (a
    handle's ``sync``, an atomic write, a rename), the rest is lost."""

    def __init__(self, files=None):
        super().__init__(files)
        self.durable = {}
        for k in self.files:
            self.durable[k] = bytes(self.files[k])

    def open_write(self, name, truncate=True):
        return _Handle(self, name, super().open_write(name, truncate))

    def write_atomic(self, name, data):
        super().write_atomic(name, data)
        self.durable[self._n(name)] = bytes(data)

    def rename(self, old, new):
        super().rename(old, new)
        o, n = self._n(old), self._n(new)
        self.durable[n] = bytes(self.files[n]) if o not in self.durable else self.durable.pop(o)

    def delete(self, name):
        super().delete(name)
        self.durable.pop(self._n(name), None)

    def cut(self):
        for k in list(self.files):
            self.files[k] = bytearray(self.durable.get(k, b""))


def pair(checkpoint):
    a = CfdpEntity(Mib(1, [RemoteEntity(2, **KW)]), MemoryFilestore({"src.bin": DATA}))
    files, state = CutFilestore(), CutFilestore()
    b = CfdpEntity(Mib(2, [RemoteEntity(1, **KW)]), files, persist=True, state=state)
    a.checkpoint_bytes = b.checkpoint_bytes = checkpoint
    return a, b


class TestReceiverCuts(unittest.TestCase):
    def cut_at(self, received, seed):
        a, b = pair(1000)
        tid = a.put(2, "src.bin", "dst.bin")
        link = Link(a, b, seed=seed, loss=0.05)
        link.run(until=lambda: b.find(tid) is not None and b.find(tid).received >= received)
        b.fs.cut()
        b.state_fs.cut()
        b2 = CfdpEntity(b.mib, b.fs, persist=True, state=b.state_fs)
        b2.checkpoint_bytes = 1000
        b2.restore(link.now)
        link.ents[1] = b2
        self.assertTrue(link.run())
        conds = [i.info["condition"] for i in link.finished(0)]
        self.assertEqual(conds, [NO_ERROR])
        self.assertEqual(bytes(b2.fs.files["dst.bin"]), DATA)

    def test_cuts_through_a_transfer(self):
        for k, received in enumerate((1, 999, 1000, 1001, 2500, 7000, 15000, 19999)):
            self.cut_at(received, seed=k + 1)

    def test_the_data_is_synced_before_each_save(self):
        a, b = pair(1000)
        order = []
        real_atomic = b.state_fs.write_atomic

        def atomic(name, data):
            order.append(("state", name))
            real_atomic(name, data)

        b.state_fs.write_atomic = atomic
        real_open = b.fs.open_write

        def open_write(name, truncate=True):
            h = real_open(name, truncate)
            real_sync = h.sync
            h.sync = lambda: (order.append(("sync", name)), real_sync())[1]
            return h

        b.fs.open_write = open_write
        tid = a.put(2, "src.bin", "dst.bin")
        link = Link(a, b)
        link.run(until=lambda: b.find(tid) is not None and b.find(tid).received >= 5000)
        saves = [i for i, o in enumerate(order) if o[0] == "state" and "R-" in o[1]]
        self.assertTrue(len(saves) >= 3)
        for i in saves[1:]:  # after the first save (metadata) every save follows a sync
            self.assertEqual(order[i - 1][0], "sync")


if __name__ == "__main__":
    unittest.main()
