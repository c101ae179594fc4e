"""Storage and file demo: housekeeping kept on board while out of contact and downlinked at the
pass (services 14 and 15); a science file copied SAT: -> GROUND: with service 23 over CFDP.

``Segment`` wires the pieces on loopback: the on-board PUS process (``Onboard``) with
services 4, 6, 13, 14, 15 and 23 added, an on-board and a ground CFDP entity on UDP (PDUs
optionally dropped), the remote file copy component of the on-board entity on the on-board
interaction-layer node, and the ground process with ``StorageGround``. ``run(out=print)`` is
the demo section; the host tests use ``Segment`` too.
"""

import asyncio
import os
import shutil
import tempfile
import time

from obsw.cfdp.remote_copy import REMOTE_COPY, RemoteCopy
from obsw.pus.services.s04_statistics import ParameterStatistics
from obsw.pus.services.s06_memory import MemoryManagement, areas_from_sdb
from obsw.pus.services.s13_large_packets import LargePacketTransfer
from obsw.pus.services.s14_forwarding import ForwardingControl
from obsw.pus.services.s15_storage import Storage
from obsw.pus.services.s23_files import FileManagement
from obsw.spp import TYPE_TC, TYPE_TM
from obsw.store import Store

from obsw_host.cfdp.filestore import RootedFilestore
from obsw_host.cfdp.link import UdpEntity, make_entity

HK_STORE = 1


class Segment:
    """On-board and ground, PUS and CFDP, on loopback (see the module text)."""

    def __init__(self, work, sdb=None, loss=0.0, seed=1, log=None, segment=512, timeout=5.0):
        from obsw_host.pus.demo import load_sdb
        from obsw_host.pus.onboard import Onboard

        self.sdb = sdb = sdb or load_sdb()
        self.work = work
        self.log = log
        self.timeout = timeout
        self.sat_fs = RootedFilestore(os.path.join(work, "sat"))
        self.ground_fs = RootedFilestore(os.path.join(work, "ground"))
        sat_id = sdb.filestore_entity(sdb.local_filestore)
        ground_id = [e for p, e in sdb.filestores.items() if p != sdb.local_filestore][0]
        timers = {"ack_interval": 0.2, "nak_interval": 0.2, "limit": 50, "inactivity": 20.0}
        self.sat_entity = make_entity(sat_id, [ground_id], self.sat_fs, segment=segment, **timers)
        self.ground_entity = make_entity(
            ground_id, [sat_id], self.ground_fs, segment=segment, persist=False, **timers
        )
        local = ("127.0.0.1", 0)
        self.sat_udp = UdpEntity(
            self.sat_entity, local, {}, packet_type=TYPE_TM, loss=loss, seed=seed
        )
        self.ground_udp = UdpEntity(
            self.ground_entity, local, {}, packet_type=TYPE_TC, loss=loss, seed=seed + 1
        )
        self.sat_udp.peers[ground_id] = self.ground_udp.address
        self.ground_udp.peers[sat_id] = self.sat_udp.address
        from obsw_host.solar_panel import SOLAR_PANEL, SolarPanel

        self.onboard = Onboard(
            sdb,
            port=0,
            period=0.05,
            store=Store(os.path.join(work, "context")),
            components=[(SOLAR_PANEL, SolarPanel())],  # its parameters bind at once
        )
        app = self.onboard.app
        self.copy = RemoteCopy(self.sat_entity)
        self.onboard.node.provide(REMOTE_COPY, self.copy)
        self.sat_udp.on_indication = self.copy.indication
        self.storage = app.register(Storage(filestore=self.sat_fs, rate=64))
        self.forwarding = app.register(ForwardingControl())
        self.files = app.register(
            FileManagement(
                self.sat_fs, sdb.filestores, sdb.local_filestore, self.onboard.node, poll_every=4
            )
        )
        app.register(LargePacketTransfer())
        app.register(ParameterStatistics(self.onboard.pool))
        app.register(MemoryManagement(areas_from_sdb(sdb, self.sat_fs)))
        self.ground = None
        self.sg = None
        self._running = False

    def start(self):
        from obsw_host.pus.ground import Ground
        from obsw_host.pus.storage_ground import StorageGround

        self.onboard.start()
        self._running = True
        self.onboard.call(lambda: asyncio.ensure_future(self._cfdp_task()))
        host, port = self.onboard.address[:2]
        self.ground = Ground(self.sdb, target=(host, port), log=self.log, timeout=self.timeout)
        self.sg = StorageGround(self.ground, cfdp=self.ground_udp)
        return self

    async def _cfdp_task(self):
        """The on-board CFDP entity, stepped on the on-board process's loop (where the remote
        copy component and service 23 live)."""
        while self._running:
            try:
                self.sat_udp.step(0)
                self.copy.poll(time.monotonic())
            except OSError:
                return
            await asyncio.sleep(0.002)

    def stop(self):
        self._running = False
        self.onboard.stop()
        if self.ground is not None:
            self.ground.close()
        self.sat_udp.close()
        self.ground_udp.close()

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()


def _ok(out, tx, what):
    out("  => %s: %s" % (what, "ok" if tx.ok else "FAILED " + "; ".join(tx.verification())))
    return tx.ok


def _hk_received(ground, since):
    return [d for tm, d in ground.received[since:] if (tm.service, tm.subtype) == (3, 25)]


def run(out=print, loss=0.05, seed=3, size=48000):
    """The demo section; returns True when every step went as expected."""
    from obsw_host.pus.onboard import tai_now

    work = tempfile.mkdtemp(prefix="obsw-storage-demo-")
    ok = True
    try:
        with Segment(work, loss=loss, seed=seed) as seg:
            sg, ground = seg.sg, seg.ground
            apid = ground.apid
            out(
                "Storage and files: on-board PUS process APID %d with services 14, 15 and 23; "
                "CFDP entities on loopback UDP, %d%% of PDUs dropped" % (apid, int(loss * 100))
            )
            out("1. a packet store for housekeeping (service 15): circular, 64 KiB")
            ok &= _ok(out, sg.create_store(HK_STORE, 65536), "store %d created" % HK_STORE)
            ok &= _ok(out, sg.store_types(HK_STORE, {apid: {3: [25]}}), "keeps TM[3,25]")
            ok &= _ok(out, sg.enable_storage([HK_STORE]), "storage enabled")
            tx = sg.issue(ground.hk.modify_interval(apid, {1: 2}))
            ok &= _ok(out, tx, "HK structure 1 every 0.1 s")
            out("2. loss of signal: housekeeping no longer forwarded in real time (service 14)")
            ok &= _ok(out, sg.withhold_hk(), "real-time HK withheld")
            mark = len(ground.received)
            t0 = tai_now()
            sg.wait_until(lambda: False, 1.2)
            t1 = tai_now()
            live = len(_hk_received(ground, mark))
            out("  => %d HK reports reached the ground while out of contact" % live)
            ok &= live == 0
            tx = sg.summary([HK_STORE])
            st = (tx.reply or {"stores": [{}]})["stores"][0]
            out(
                "  => store %d holds %d packets (sequence %d..%d), %d%% full"
                % (
                    HK_STORE,
                    st.get("count", 0),
                    st.get("first_seq", 0),
                    st.get("last_seq", 0),
                    st.get("fill", 0),
                )
            )
            ok &= st.get("count", 0) > 0
            out("3. the pass: downlink what was stored while out of contact, by time window")
            mark = len(ground.received)
            ok &= _ok(out, sg.retrieve_time(HK_STORE, t0, t1), "retrieval started")
            sg.wait_until(lambda: len(_hk_received(ground, mark)) >= 5, 3.0)
            sg.wait_until(lambda: False, 0.3)
            got = _hk_received(ground, mark)
            out("  => %d stored HK reports decoded on the ground" % len(got))
            if got:
                out("     first: %s" % (got[0] or {}).get("values"))
            ok &= len(got) >= 5
            ok &= _ok(out, sg.forward_hk([]), "real-time HK forwarded again")
            ok &= _ok(out, sg.disable_storage([HK_STORE]), "storage disabled")
            out("4. a science file copied SAT: -> GROUND: with service 23, carried by CFDP")
            data = bytes((i * 7 + (i >> 8)) & 0xFF for i in range(size))
            seg.sat_fs.mkdir("science")
            seg.sat_fs.write_bytes("science/obs-001.dat", data)
            seg.ground_fs.mkdir("downlink")
            ok &= _ok(out, sg.copy_reports(4), "copy status reports every 0.2 s")
            op, tx = sg.copy("SAT:/science/obs-001.dat", "GROUND:/downlink/obs-001.dat")
            ok &= _ok(out, tx, "copy operation %d started" % op)
            st = sg.wait_copy(op, 15.0)
            same = (
                seg.ground_fs.exists("downlink/obs-001.dat")
                and seg.ground_fs.read_bytes("downlink/obs-001.dat") == data
            )
            out(
                "  => operation %d %s: %d octets, %s; %d PDUs dropped by the link, %d file data "
                "PDUs sent again"
                % (
                    op,
                    (st or {}).get("status_name", "not finished"),
                    (st or {}).get("bytes", 0),
                    "byte-identical on the ground" if same else "NOT delivered intact",
                    seg.sat_udp.dropped + seg.ground_udp.dropped,
                    seg.sat_entity.stats["retransmitted_pdus"],
                )
            )
            ok &= same
            out("5. a path outside the on-board filestore is refused")
            tx = sg.attributes("SAT:/../../etc/passwd")
            out("  => %s" % "; ".join(tx.verification()))
            ok &= tx.failure is not None and tx.failure["code"] == 14
    finally:
        shutil.rmtree(work, ignore_errors=True)
    out("storage and files demo %s" % ("done" if ok else "FAILED"))
    return ok
