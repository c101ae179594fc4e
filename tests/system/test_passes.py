"""Contact awareness through the real chain (``obsw_sim.chain``: the OBC's processes, the
reconfiguration controllers, the frames on the UARTs, the station, the ground): a pass table
uplinked with TC[8,1] ``Passes.load`` (a bad one refused with its reason), housekeeping kept
in a packet store out of contact and dumped at the table's AOS before any TC, each report
once, the ground's acknowledgement freeing the store, a resend on request. Every wait has a
deadline; nothing asserts on time."""

import os
import time

import pytest
from obsw_host.obc.passes import pack_table
from obsw_host.pus.storage_ground import StorageGround
from obsw_sim.chain import Chain
from obsw_sim.reconfig import micropython_binary

pytestmark = pytest.mark.skipif(
    micropython_binary() is None or not hasattr(os, "openpty"),
    reason="needs the MicroPython unix port and pseudo-terminals",
)

WAIT = 60.0
STORE = 1
HK_SID = 1  # the sample's SolarPanel housekeeping, every second


def loaded_chain(tmp_path):
    """The chain, set for a machine busy with other test lanes: its station thread shares
    this process, so the OBC's UART queues hold a burst while it is late rather than drop the
    oldest frames, and a process paused for seconds is not taken for a hung one (a restart
    between a dump and its event would leave a report the events do not count)."""
    chain = Chain(str(tmp_path), processes=Chain.SAMPLE_PROCESSES)
    chain.sections["frames"] = {"uart_queue": 4096}
    chain.platform.update(deadline=10.0)
    return chain


def refused(tx, *texts):
    """The TC[8,1] failed its completion, the component's reason carrying ``texts``."""
    report = " ".join(tx.verification())
    return not tx.ok and all(t.encode().hex() in report for t in texts)


def tm_seconds(tm):
    coarse, fine = tm.time
    return coarse + fine / 65536.0  # the sample's CUC: 4 coarse, 2 fine octets


class Watch:
    """The ground's view: housekeeping SID 1 and the events, in arrival order."""

    def __init__(self, chain):
        self.chain = chain
        # every unsolicited TM kept: the ground drops the oldest beyond 1000 by default, and
        # this watch reads on from an index into the list
        chain.ground.keep_unsolicited = 1 << 30
        sdb = chain.sdb
        self.ids = {sdb.event(n).id: n for n in ("passes.dumped", "Passes.aos", "Passes.los")}
        self.dumped = sdb.event("passes.dumped")
        self.seen = 0
        self.log = []  # ("hk", time tag) or (event name, values)

    def poll(self):
        g = self.chain.ground
        g.poll(0.02)
        for tm, _ in g.received[self.seen :]:
            if tm.service == 3 and tm.subtype == 25 and tm.data[:2] == bytes((0, HK_SID)):
                self.log.append(("hk", tm_seconds(tm)))
            elif tm.service == 5 and len(tm.data) >= 2:
                eid = tm.data[0] << 8 | tm.data[1]
                name = self.ids.get(eid)
                if name == "passes.dumped":
                    self.log.append((name, self.dumped.unpack(tm.data[2:])))
                elif name is not None:
                    self.log.append((name, tm_seconds(tm)))  # when on board
        self.seen = len(g.received)

    def wait(self, predicate, timeout=WAIT):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            self.poll()
            if predicate():
                return True
        return False

    def count(self, name):
        return sum(1 for k, _ in self.log if k == name)

    def now(self):
        """Onboard time: the newest time tag the ground has seen."""
        self.wait(lambda: self.chain.ground.received)
        return tm_seconds(self.chain.ground.received[-1][0])


def test_pass_table_store_and_forward(tmp_path):
    chain = loaded_chain(tmp_path)
    chain.sections["contact"] = {"stores": [STORE], "hold": 1.0}
    with chain:
        chain.wait_up(2 * WAIT)
        g = chain.ground
        sg = StorageGround(g)
        apid = g.apid
        assert sg.create_store(STORE, 200_000, kind=1).ok
        assert sg.store_types(STORE, {apid: {3: [25]}}).ok
        assert sg.store_hk(STORE, [HK_SID]).ok
        assert sg.enable_storage([STORE]).ok
        watch = Watch(chain)

        # a bad table: refused with its reason, nothing loaded
        bad = g.perform("Passes.load", table=bytes(12))
        assert refused(bad, "BAD_TABLE", "expected 8 octets a pass"), bad.verification()
        overlapping = pack_table([(1000, 2000), (1500, 2500)])
        bad = g.perform("Passes.load", table=overlapping)
        assert refused(bad, "BAD_TABLE", "before pass 0 ends"), bad.verification()

        # a pass 8 s from now, 6 s long; then silence from the ground
        now = watch.now()
        aos, los = int(now) + 8, int(now) + 14
        assert g.perform("Passes.load", table=pack_table([(aos, los)])).ok
        assert watch.wait(lambda: watch.count("Passes.los") >= 1), watch.log
        assert watch.wait(lambda: watch.count("Passes.aos") >= 1), watch.log
        assert watch.wait(lambda: watch.count("Passes.los") >= 2), watch.log

        # the dump events travel on the real-time channel, the reports on the store's: the
        # last events may come after the last reports
        def counted():
            hk = sum(1 for k, _ in watch.log if k == "hk")
            return hk == sum(v["count"] for k, v in watch.log if k == "passes.dumped")

        assert watch.wait(counted), watch.log
        kinds = [k for k, _ in watch.log]
        first_los = kinds.index("Passes.los")
        aos_at = kinds.index("Passes.aos")
        # out of contact nothing went down in real time: the reports waited in the store
        # (a report dumped before LOS, on the store's channel, may come after the LOS event)
        los_time = watch.log[first_los][1]
        late = [t for k, t in watch.log[first_los:aos_at] if k == "hk" and t > los_time]
        assert not late, (los_time, watch.log)
        hk = [t for k, t in watch.log if k == "hk"]
        dumps = [v for k, v in watch.log if k == "passes.dumped"]
        assert hk and dumps, watch.log
        # each report once, in order, and as many as the dump events say were sent
        assert hk == sorted(hk) and len(set(hk)) == len(hk), hk
        assert sum(d["count"] for d in dumps) == len(hk), (dumps, len(hk))
        seqs = [(d["first"], d["last"]) for d in dumps]
        for (_a, b), (c, _) in zip(seqs, seqs[1:]):
            assert c == b + 1, seqs  # contiguous: nothing skipped, nothing twice
        # the reports generated out of contact came down in the pass
        in_pass = [t for k, t in watch.log[aos_at:] if k == "hk"]
        assert any(t < aos for t in in_pass), (aos, in_pass)
        print("%d reports in %d dumps, %d generated out of contact" % (
            len(hk), len(dumps), sum(1 for t in in_pass if t < aos)))  # fmt: skip

        # the ground acknowledges what it has: the store's content shrinks
        last = seqs[-1][1]
        before = sg.summary([STORE]).reply
        assert g.perform("Passes.acknowledge", store=STORE, seq=last).ok
        after = sg.summary([STORE]).reply
        assert after != before, (before, after)
        # an unknown store is refused
        nope = g.perform("Passes.acknowledge", store=77, seq=1)
        assert refused(nope, "UNKNOWN_STORE"), nope.verification()


def test_a_file_up_across_two_passes(tmp_path):
    """A class 2 upload larger than a pass: suspended at LOS on both ends (the OBC from its
    pass table, the ground from the same windows), out of contact longer than the OBC's
    inactivity limit (60 s: it would have cancelled the transaction), resumed at AOS where
    it stopped, byte-identical, never restarted."""
    import random

    from obsw.cfdp.contact import PassHold
    from obsw.cfdp.defs import ACKNOWLEDGED, NO_ERROR
    from obsw.cfdp.filestore import MemoryFilestore
    from obsw.spp import TYPE_TC
    from obsw_host.cfdp.link import UdpEntity, make_entity
    from obsw_host.pus.tai import tai_now

    chain = loaded_chain(tmp_path)
    chain.sections["contact"] = {"stores": [STORE], "hold": 1.0}
    data = random.Random(7).randbytes(240_000)
    with chain:
        chain.wait_up(2 * WAIT)
        g = chain.ground
        sat, ground = chain.ids.cfdp_entities
        files = MemoryFilestore({"up.bin": data})
        entity = make_entity(ground, [sat], files, persist=False)
        windows = []

        def in_contact():
            t = tai_now()
            return any(a <= t < b for a, b in windows)

        link = UdpEntity(entity, ("127.0.0.1", chain.cfdp_ground_port),
                         {sat: ("127.0.0.1", chain.cfdp_port)}, apid=chain.ids.apid("cfdp"),
                         packet_type=TYPE_TC, rate=12_000, pace=False,
                         drop=lambda pdu: not in_contact())  # fmt: skip
        hold = PassHold(entity)
        try:
            now = int(tai_now())
            # a pass of 8 s now, then 70 s out of contact, then a pass of 60 s
            windows[:] = [(now, now + 8), (now + 78, now + 138)]
            assert g.perform("Passes.load", table=pack_table(windows)).ok
            entity.put(sat, "up.bin", "up.bin", mode=ACKNOWLEDGED)
            at_los = None
            finished = []
            progress = []  # the sender's progress, each step: it never goes back to zero
            end = time.monotonic() + 5 * WAIT
            while time.monotonic() < end and not finished:
                hold.update(in_contact(), time.monotonic())
                for ind in link.step(0.02):
                    if ind.kind == "finished":
                        finished.append(ind.info)
                progress.extend(tx.progress_of() for tx in entity.tx.values())
                t = tai_now()
                if at_los is None and t >= windows[0][1]:
                    at_los = [tx.progress_of() for tx in entity.tx.values()]
            assert finished, [(tx.progress_of(), tx.suspended) for tx in entity.tx.values()]
            assert finished[0].get("condition", NO_ERROR) == NO_ERROR, finished
            assert at_los and 0 < at_los[0] < len(data), at_los  # it spanned the two passes
            assert hold.suspends >= 1 and hold.resumes >= 1
            assert progress == sorted(progress), "the transfer went back"
            assert len(finished) == 1 and not entity.tx  # one transaction, done
            path = os.path.join(chain.state, "files", "up.bin")
            assert wait_file(path, data), "the OBC's copy differs"
            print("up: %d octets, %d at LOS, finished in the second pass" % (
                len(data), at_los[0]))  # fmt: skip
        finally:
            link.close()


def wait_file(path, data, timeout=WAIT):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            with open(path, "rb") as f:
                if f.read() == data:
                    return True
        except OSError:
            pass
        time.sleep(0.1)
    return False
