"""Storage and file demo: housekeeping kept on board while out of contact and downlinked at the
pass (services 14 and 15); a science file copied SAT: -> GROUND: with service 23 over CFDP.

``Segment`` wires the pieces on loopback: the on-board PUS process (``Onboard``) with
services 4, 6, 13, 14, 15 and 23 added, an on-board and a ground CFDP entity on UDP (PDUs
optionally dropped), the remote file copy component of the on-board entity on the on-board
interaction-layer node, and the ground process with ``StorageGround``. With ``frames=True``
the PUS packets travel the space link instead of plain UDP: a ground station (FOP-1, CLTUs)
and the frame processor on two pseudo-UARTs; real-time TM comes down on the real-time VC and
what service 15 retrieves on the playback VC (``obsw.frames.tm_plan``; the database's
``frames.tm_vcs`` may renumber them). ``run(out=print)`` is the demo section; the host tests
use ``Segment`` too.
"""

import asyncio
import os
import shutil
import sys
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
from obsw_host.mission.ids import MissionIds

HK_STORE = 1
SCID = MissionIds.sample().scid  # the sample spacecraft's


class Segment:
    """On-board and ground, PUS and CFDP, on loopback (see the module text)."""

    def __init__(
        self,
        work,
        sdb=None,
        loss=0.0,
        seed=1,
        log=None,
        segment=512,
        timeout=5.0,
        frames=False,
        tm_frame_length=256,
    ):
        from obsw_host.pus.onboard import Onboard
        from obsw_host.sample import SDB_PATH, load_sdb

        self.sdb = sdb = sdb or load_sdb(SDB_PATH)
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
        apid = sdb.apid("cfdp")
        self.sat_udp = UdpEntity(
            self.sat_entity, local, {}, apid=apid, packet_type=TYPE_TM, loss=loss, seed=seed
        )
        self.ground_udp = UdpEntity(
            self.ground_entity, local, {}, apid=apid, packet_type=TYPE_TC, loss=loss, seed=seed + 1
        )
        self.sat_udp.peers[ground_id] = self.ground_udp.address
        self.ground_udp.peers[sat_id] = self.sat_udp.address
        from obsw_host.solar_panel import SOLAR_PANEL, SolarPanel

        self.fp = self.station = None
        self._threads = []
        self._stop = None
        playback_to = None
        if frames:
            self._open_link(sdb, tm_frame_length)
            playback_to = {vc: ("127.0.0.1", p) for vc, p in self.fp.vc_ports.items()}
        self.onboard = Onboard(
            sdb,
            port=0,
            period=0.05,
            store=Store(os.path.join(work, "context")),
            components=[(SOLAR_PANEL, SolarPanel())],  # its parameters bind at once
            playback_to=playback_to,
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

    def _open_link(self, sdb, frame_length):
        """The frame processor and a ground station on two pseudo-UART pairs; TC frames are
        signed (SDLS) with keys made for the run in the work folder."""
        from obsw_host.frames import keys
        from obsw_host.frames.links import FdLink, SerialLink, open_pty_pair
        from obsw_host.frames.processor import FrameProcessorHost, security_options
        from obsw_host.frames.station import GroundStation

        key_file = os.path.join(self.work, "tc.keys")
        if not os.path.exists(key_file):
            keys.generate(key_file)
        onboard_keys = security_options(key_file, sdb, key_file + ".onboard")
        ground_keys, ground_state = keys.load(key_file, key_file + ".ground")

        plan = sdb.tm_vcs
        ctrl_a, dev_a = open_pty_pair()
        ctrl_b, dev_b = open_pty_pair()
        self.fp = FrameProcessorHost(
            SerialLink(dev_a), SerialLink(dev_b), SCID, tm_port=0,
            tm_frame_length=frame_length, tm_plan=plan, clcw_period=0.5, **onboard_keys,
        )  # fmt: skip
        self.station = GroundStation(
            [FdLink(ctrl_a, "A"), FdLink(ctrl_b, "B")], SCID, tm_frame_length=frame_length,
            security=ground_keys, state=ground_state,
        )  # fmt: skip

    def start(self):
        import threading

        from obsw_host.pus.ground import Ground
        from obsw_host.pus.storage_ground import StorageGround

        self.onboard.start()
        self._running = True
        self.onboard.call(lambda: asyncio.ensure_future(self._cfdp_task()))
        host, port = self.onboard.address[:2]
        if self.fp is not None:
            self.fp.routes[self.onboard.apid] = (host, port)  # TC packets to the process
            self._stop = threading.Event()
            for name, target in (("frames", self.fp.run), ("station", self.station.run)):
                t = threading.Thread(target=target, args=(self._stop,), name=name, daemon=True)
                t.start()
                self._threads.append(t)
            host, port = self.station.address[:2]
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
        if self._stop is not None:
            self._stop.set()
            for t in self._threads:
                t.join(2)
            self._threads = []
        if self.fp is not None:
            self.fp.close()
            self.station.close()
            self.fp = self.station = None
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


def _vc_names(seg, packets):
    """ "VC 1 (playback)" for each VC the (VC ID, packet) pairs came on."""
    roles = {v: k for k, v in (seg.fp.core.tm_plan or {}).items()}
    vcs = sorted({vc for vc, _ in packets})
    return ", ".join("VC %d (%s)" % (vc, roles.get(vc, "?")) for vc in vcs) or "no VC"


def _hk_on_link(seg, mark):
    return [(vc, p) for vc, p in list(seg.station.downlinked)[mark:] if p[7:9] == b"\x03\x19"]


def run(out=print, loss=0.05, seed=3, size=48000, frames=True):
    """The demo section; returns True when every step went as expected. With ``frames`` the
    PUS packets go over the space link (frame processor, two pseudo-UARTs, ground station)."""
    from obsw_host.pus.onboard import tai_now

    work = tempfile.mkdtemp(prefix="obsw-storage-demo-")
    ok = True
    try:
        with Segment(work, loss=loss, seed=seed, frames=frames) as seg:
            sg, ground = seg.sg, seg.ground
            apid = ground.apid
            out(
                "Storage and files: on-board PUS process APID %d with services 14, 15 and 23; "
                "CFDP entities on loopback UDP, %d%% of PDUs dropped" % (apid, int(loss * 100))
            )
            if frames:
                out(
                    "  PUS packets over the space link: ground station <-> 2 pseudo-UARTs <-> "
                    "frame processor (TM VCs %s)"
                    % ", ".join("%s %d" % (k, v) for k, v in seg.fp.core.tm_plan.items())
                )
            out(
                "1. a packet store for housekeeping (service 15): circular, 64 KiB, "
                "downlinked on the playback VC"
            )
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
            link_mark = len(seg.station.downlinked) if frames else 0
            ok &= _ok(out, sg.retrieve_time(HK_STORE, t0, t1), "retrieval started")
            sg.wait_until(lambda: len(_hk_received(ground, mark)) >= 5, 3.0)
            sg.wait_until(lambda: False, 0.3)
            got = _hk_received(ground, mark)
            out("  => %d stored HK reports decoded on the ground" % len(got))
            if got:
                out("     first: %s" % (got[0] or {}).get("values"))
            ok &= len(got) >= 5
            if frames:
                on_link = _hk_on_link(seg, link_mark)
                out("  => they came down on %s" % _vc_names(seg, on_link))
                ok &= {vc for vc, _ in on_link} == {seg.fp.core.playback_vcid}
            link_mark = len(seg.station.downlinked) if frames else 0
            ok &= _ok(out, sg.forward_hk([]), "real-time HK forwarded again")
            if frames:
                sg.wait_until(lambda: _hk_on_link(seg, link_mark), 2.0)
                out("  => live HK on %s" % _vc_names(seg, _hk_on_link(seg, link_mark)))
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


if __name__ == "__main__":
    sys.exit(run())
