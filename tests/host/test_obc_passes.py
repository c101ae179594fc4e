"""The OBC's ``Passes`` component (``obsw_host.obc.passes``) on one clock: the pass table's
layout and its refusals, real-time TM withheld for the dumped stores, the dump by priority
within the pass, acknowledgement and resend, CFDP held across the pass."""

import pytest
from obsw.il.clock import SimClock
from obsw.il.errors import ComponentError
from obsw.pus.app import ApplicationProcess
from obsw.pus.services.s15_storage import Storage
from obsw_host.obc.passes import Passes, pack_table, unpack_table


class Header:
    def __init__(self, apid, service, subtype, sid=None):
        self.apid, self.service, self.subtype = apid, service, subtype
        self._sid = sid
        self.data = bytes((0, sid)) if sid is not None else b""

    def sid(self):
        return self._sid


class Clock:
    def __init__(self, t=1000.0):
        self.t = t

    def __call__(self):
        return self.t


def make(stores=(1, 2), entity=None):
    storage = Storage(
        [
            {
                "id": sid,
                "size": 10_000,
                "kind": 1,
                "enabled": True,
                "types": {10: {3: [25]}},
                "hk": {10: [sid]},
            }
            for sid in (1, 2)
        ]  # fmt: skip
    )
    ApplicationProcess(10, lambda raw: None, SimClock(0.0)).register(storage)
    sent, events = [], []
    clock = Clock()
    p = Passes(storage, lambda raw, vc: sent.append(raw), clock,
               lambda name, values: events.append((name, values)), stores=stores, hold=5.0,
               bps=8000.0, share=1.0, entity=entity, clock=clock)  # fmt: skip
    return p, storage, clock, sent, events


def test_table_layout_and_refusals():
    table = pack_table([(100, 200.5), (300, 400)])
    assert len(table) == 16
    assert unpack_table(table) == [(100, 200), (300, 400)]  # inside the pass
    p, *_ = make()
    p.load(table)
    assert p.passes == 2
    for bad, why in (
        (bytes(7), "expected 8 octets a pass"),
        (pack_table([(300, 400), (100, 200)]), "before pass 0 ends"),
        (bytes(8), "not before LOS"),
        (pack_table([(i * 10, i * 10 + 5) for i in range(65)]), "at most 64"),
    ):
        with pytest.raises(ComponentError) as e:
            p.load(bad)
        assert e.value.code == "BAD_TABLE" and why in str(e.value), str(e.value)
    assert p.passes == 2  # the table in force stays
    p.load(b"")
    assert p.passes == 0


def test_withheld_stored_and_dumped_by_priority_once():
    p, storage, clock, sent, events = make()
    assert not p.realtime(Header(10, 3, 25, 1)) and not p.realtime(Header(10, 3, 25, 2))
    assert p.realtime(Header(10, 3, 25, 7)) and p.realtime(Header(10, 1, 1))
    for i in range(5):
        storage.stores[2].append(clock.t, b"R%05d" % i)
        storage.stores[1].append(clock.t, b"H%05d" % i)
    p.step()
    assert sent == [] and not p.in_contact  # out of contact nothing leaves
    p.load(pack_table([(1010, 1020)]))
    clock.t = 1010.0
    p.step()
    clock.t = 1011.0
    p.step()
    assert p.in_contact
    assert sent[:5] == [b"H%05d" % i for i in range(5)]  # the high-priority store first
    assert sent[5:] == [b"R%05d" % i for i in range(5)]
    assert [e[1]["store"] for e in events if e[0] == "passes.dumped"] == [1, 2]
    clock.t = 1012.0
    p.step()
    assert len(sent) == 10  # nothing twice
    p.resend(1, 3, 4)  # storage sequence numbers count from 1
    clock.t = 1013.0
    p.step()
    assert sent[10:] == [b"H00002", b"H00003"]
    p.acknowledge(1, 5)
    assert storage.stores[1].packets == []
    with pytest.raises(ComponentError):
        p.acknowledge(9, 1)
    clock.t = 1021.0
    p.step()
    assert not p.in_contact


def test_the_pass_volume_bounds_the_dump():
    p, storage, clock, sent, _ = make()
    for _i in range(100):
        storage.stores[1].append(clock.t, bytes(100))
    p.load(pack_table([(1000, 1002)]))  # 2 s at 8000 bit/s: 2000 octets
    for t in (1000.0, 1000.5, 1001.0, 1001.5, 1001.9, 1002.5):
        clock.t = t
        p.step()
    assert 0 < sum(len(r) for r in sent) <= 2000
    assert p.backlog == sum(100 for _ in range(100)) - sum(len(r) for r in sent)


def test_files_have_the_radio_when_the_stores_have_nothing_waiting():
    p, storage, clock, sent, _ = make()
    assert p.spare == p.cycle_octets == 1000.0  # 8000 bit/s, all of it the dump's
    for _i in range(30):
        storage.stores[1].append(clock.t, bytes(100))
    p.load(pack_table([(1000, 1100)]))
    clock.t = 1000.0
    p.step()
    assert p.backlog > 0 and p.spare == 0.0  # the stores first: no file data meanwhile
    while p.backlog:
        clock.t += 0.5
        p.step()
    assert len(sent) == 30 and p.spare == 1000.0  # caught up: the files have it again


def test_cfdp_held_out_of_contact():
    class Tx:
        def __init__(self):
            self.done = False
            self.suspended = False

        def suspend(self, now):
            self.suspended = True
            return True

        def resume(self, now):
            self.suspended = False
            return True

    class Entity:
        tx = {("t", "S"): Tx()}

    entity = Entity()
    p, _storage, clock, _sent, _ = make(entity=entity)
    p.load(pack_table([(1010, 1020)]))
    p.step()
    assert entity.tx[("t", "S")].suspended
    clock.t = 1010.0
    p.step()
    assert not entity.tx[("t", "S")].suspended
    clock.t = 1020.0
    p.step()
    assert entity.tx[("t", "S")].suspended


def test_off_without_stores():
    p, *_ = make(stores=())
    assert not p.enabled and p.realtime(Header(10, 3, 25, 1))


def test_a_restart_goes_on_after_the_last_packet_sent(tmp_path):
    path = str(tmp_path / "passes.json")
    p, storage, clock, sent, _ = make()
    p.path = path
    for i in range(4):
        storage.stores[1].append(clock.t, b"H%05d" % i)
    p.load(pack_table([(1000, 1100)]))
    p.step()
    clock.t = 1001.0
    p.step()
    assert len(sent) == 4
    storage.stores[1].append(clock.t, b"H00004")
    # the process restarts: the same stores (restored from their files), a new component
    again = Passes(storage, lambda raw, vc: sent.append(raw), clock, lambda n, v: None,
                   stores=(1, 2), bps=8000.0, share=1.0, clock=clock, path=path)  # fmt: skip
    again.load(pack_table([(1000, 1100)]))
    again.step()
    clock.t = 1002.0
    again.step()
    assert sent[4:] == [b"H00004"]  # nothing twice


def test_a_restart_keeps_the_pass_table(tmp_path):
    path = str(tmp_path / "passes.json")
    p, storage, clock, sent, _ = make()
    p.path = path
    p.load(pack_table([(1000, 1100), (2000, 2100)]))
    again = Passes(storage, lambda raw, vc: sent.append(raw), clock, lambda n, v: None,
                   stores=(1, 2), bps=8000.0, share=1.0, clock=clock, path=path)  # fmt: skip
    assert again.passes == 2
    clock.t = 1050.0
    again.step()
    assert again.contact.in_contact
