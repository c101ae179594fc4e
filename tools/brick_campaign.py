#!/usr/bin/env python3
"""The brick campaign: every way the ground was found to brick the OBC, replayed against a
live `obsw obc serve`, with power cuts (kill -9 of the OBC's process group) in the middle of
parameter sets, context store writes and CFDP receptions. Bounded; prints one line per check
and ``N passed, N failed`` last; exits 1 if any failed.

    python tools/brick_campaign.py            # the full run: 20 cuts of each kind (60)
    python tools/brick_campaign.py --quick    # 2 of each: about two minutes
    python tools/brick_campaign.py --cuts 5 --seed 3

Checks, each counted:

- **start from persisted state**: a state file written into the filestore by CFDP, and every
  state file of the OBC spoiled (empty object, bad JSON, deep nesting): the OBC starts each
  time (0 start failures);
- **silent task deaths**: a download and a delete of the same file (four PDUs): the transfer
  ends with a fault the ground hears of, the CFDP entity still serves (0 silent deaths; a task
  restarted with its event is reported, not silent);
- **files deleted**: `Software.stage` pointed at files outside the update folder: refused,
  every file still there;
- **power cuts**: during parameter sets (service 20), the value set last is there after the
  restart (or the one in flight); during context store writes (service 5 disable and enable of
  an event), the state confirmed last is there; during a CFDP upload, the file is delivered
  whole once the OBC is back (0 lost).
"""

import argparse
import os
import random
import shutil
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from obsw_sim.brick import LiveObc, make_mission, wait_for  # noqa: E402

EVENT = "monitoring.obc_high"  # the event disabled and enabled (a context store write)


class Campaign:
    def __init__(self, work, seed, out=print):
        self.work = work
        self.rng = random.Random(seed)
        self.out = out
        self.passed = 0
        self.failed = 0
        mission = make_mission(os.path.join(work, "sat"))
        self.obc = LiveObc(mission, os.path.join(work, "state"))
        self.ground = None

    # ------------------------------------------------------------------------ bookkeeping

    def check(self, ok, what):
        if ok:
            self.passed += 1
        else:
            self.failed += 1
        self.out("%s  %s" % ("ok  " if ok else "FAIL", what))
        return ok

    def _ground(self):
        from obsw_host.mission.ids import MissionIds
        from obsw_host.pus.ground import Ground

        if self.ground is None:
            ids = MissionIds.locate(self.obc.mission)
            port = self.obc.base + ids.pus_apid
            self.ground = Ground(ids.sdb, target=("127.0.0.1", port), timeout=2.0,
                                 source_id=ids.source_id, config=ids.pus_config)  # fmt: skip
        return self.ground

    def start(self, what):
        """(Re)start the OBC; a start that does not answer is a start failure."""
        self.obc.lines.clear()
        self.obc.start(wait=False)
        up = bool(self.obc.wait_up()) and wait_for(self.obc.ping, 30)
        self.check(up, "starts: %s" % what)
        return up

    def traceback_free(self, what):
        self.check(not self.obc.said("Traceback"), "no traceback: %s" % what)

    # ------------------------------------------------------------------------ reproductions

    def state_reproductions(self):
        obc = self.obc
        ground_root = os.path.join(self.work, "ground")
        os.makedirs(ground_root, exist_ok=True)
        with open(os.path.join(ground_root, "empty.json"), "w") as f:
            f.write("{}")
        r = obc.obsw("cfdp", "put", "empty.json", ".cfdp/R-1-77.json", "--root", ground_root,
                     "--timeout", "30")  # fmt: skip
        self.check(r.returncode == 0, "a state file put into the filestore by CFDP")
        obc.stop()
        self.start("after a state file was put into the filestore")
        self._ground().set_parameters({"nav.distance": 1})
        obc.stop()
        for content in (b"{}", b"[", b"[" * 50000, b"\xff\xfe"):
            for path in _state_files(obc.state):
                with open(path, "wb") as f:
                    f.write(content)
            self.start("every state file holding %r" % content[:8])
            self.traceback_free("spoiled state files")
            obc.stop()
        self.start("after the spoiled state files were set aside")

    def task_reproductions(self):
        from obsw.cfdp import msgs
        from obsw.cfdp.defs import FS_DELETE_FILE
        from obsw.cfdp.tlv import FilestoreRequest

        obc = self.obc
        files = obc.files
        with open(os.path.join(files, "big.bin"), "wb") as f:
            f.write(os.urandom(300_000))
        with open(os.path.join(files, "other.bin"), "wb") as f:
            f.write(b"other\n" * 1000)
        root = os.path.join(self.work, "ground-dl")
        os.makedirs(root, exist_ok=True)
        sat, ground, udp = _ground_entity(obc, root)
        heard = []
        try:
            ent = udp.entity
            ent.seq = 60000 + self.rng.randrange(1000)
            now = time.monotonic()
            ent.put(sat, messages=[msgs.proxy_put_request(ground, "big.bin", "big.bin")], now=now)
            ent.put(sat, filestore_requests=[FilestoreRequest(FS_DELETE_FILE, "big.bin")],
                    now=now)  # fmt: skip
            end = time.monotonic() + 60
            while time.monotonic() < end and not heard:
                heard += [i for i in udp.step(0.05) if i.kind == "finished" and i.tid[0] == sat]
        finally:
            udp.close()
        self.check(bool(heard), "a download then a delete of the file: the ground hears the end")
        r = obc.obsw("cfdp", "get", "other.bin", "--root", root, "--timeout", "30")
        self.check(r.returncode == 0, "the CFDP entity still serves after it (no silent death)")
        self.traceback_free("download then delete")
        obc.stop()
        self.start("after a download then a delete")

    def file_reproductions(self):
        obc = self.obc
        g = self._ground()
        keep = {"memory/image.bin": None, "data.txt": b"keep me\n"}
        with open(os.path.join(obc.files, "data.txt"), "wb") as f:
            f.write(keep["data.txt"])
        path = os.path.join(obc.files, "memory", "image.bin")
        if os.path.exists(path):
            with open(path, "rb") as f:
                keep["memory/image.bin"] = f.read()
        for name in keep:
            tx = g.perform("Software.stage", file=name)
            self.check(not tx.ok, "Software.stage(%r) refused" % name)
        for name, data in keep.items():
            p = os.path.join(obc.files, *name.split("/"))
            there = os.path.exists(p) and (data is None or open(p, "rb").read() == data)
            self.check(there, "%s still there" % name)

    # ------------------------------------------------------------------------ power cuts

    def _cut_during(self, step):
        """Run ``step(k)`` for k = 1, 2, .. in a thread; cut the power at a random moment after
        the first step completed (a loaded machine may take long for it); returns the last k
        whose step completed."""
        done = [0]
        stop = threading.Event()
        first = threading.Event()

        def run():
            k = 0
            while not stop.is_set():
                k += 1
                try:
                    ok = step(k)
                except Exception:
                    return
                if not ok:
                    return
                done[0] = k
                first.set()

        t = threading.Thread(target=run, daemon=True)
        t.start()
        first.wait(30.0)
        time.sleep(self.rng.uniform(0.0, 1.2))  # the moment of the cut is the experiment
        self.obc.power_cut()
        stop.set()
        t.join(10)
        return done[0]

    def cut_parameter_sets(self, n):
        g = self._ground()
        for c in range(n):

            def step(k, c=c):
                return g.set_parameters({"nav.distance": 1000 * c + k}, timeout=2.0).ok

            last = self._cut_during(step)
            if not self.start("after a cut during parameter sets"):
                continue
            tx = g.get_parameters("nav.distance")
            got = tx.reply["values"]["nav.distance"] if tx.ok else None
            want = (1000 * c + last, 1000 * c + last + 1)
            self.check(last > 0 and got in want, "parameter set %s kept (read %s)" % (
                want[0], got))  # fmt: skip

    def cut_store_writes(self, n):
        g = self._ground()
        eid = g.sdb.event(EVENT).id

        def step(k):  # odd: disable, even: enable
            if k % 2:
                return g.disable_events([EVENT], timeout=2.0).ok
            return g.enable_events([EVENT], timeout=2.0).ok

        for _ in range(n):
            last = self._cut_during(step)
            if not self.start("after a cut during context store writes"):
                continue
            tx = g.disabled_events()
            disabled = eid in tx.reply["ids"] if tx.ok else None
            want = {bool(last % 2), bool((last + 1) % 2)} if last else {False, True}
            # the confirmed state, or the one in flight when the power went
            what = "event state after %d confirmed writes (disabled: %s)" % (last, disabled)
            self.check(last > 0 and disabled in want and tx.ok, what)
            if disabled:
                g.enable_events([EVENT])

    def cut_cfdp_receive(self, n):
        from obsw_host.cfdp.client import CfdpClient
        from obsw_host.mission.ids import MissionIds

        ids = MissionIds.locate(self.obc.mission)
        sat, ground = ids.cfdp_entities
        root = os.path.join(self.work, "ground-up")
        os.makedirs(root, exist_ok=True)
        for c in range(n):
            name = "up-%d.bin" % c
            data = os.urandom(self.rng.randrange(1, 3) << 20)
            with open(os.path.join(root, name), "wb") as f:
                f.write(data)
            result = []
            client = CfdpClient(ground, {sat: ("127.0.0.1", self.obc.base + ids.apid("cfdp"))},
                                root, apid=ids.apid("cfdp"), cls=2,
                                port=self.obc.base + ids.apid("cfdp") + 1, timeout=120,
                                answer_timeout=30,
                                state=os.path.join(self.work, "seq"))  # fmt: skip
            client.udp.rate = 2e6  # the cut lands in the middle of the transfer

            def put(client=client, name=name, result=result):
                try:
                    result.append(client.put(name, name))
                except Exception as e:
                    result.append(e)

            t = threading.Thread(target=put, daemon=True)
            t.start()
            time.sleep(self.rng.uniform(0.2, 0.8))
            self.obc.power_cut()
            up = self.start("after a cut during a CFDP reception")
            t.join(150)
            client.close()
            got = os.path.join(self.obc.files, name)
            whole = os.path.exists(got) and open(got, "rb").read() == data
            delivered = bool(result) and getattr(result[0], "delivered", False)
            self.check(up and delivered and whole, "%s (%d B) delivered whole across the cut" % (
                name, len(data)))  # fmt: skip

    # ------------------------------------------------------------------------ the run

    def run(self, cuts):
        if not self.start("a fresh OBC"):
            return
        try:
            self.state_reproductions()
            self.task_reproductions()
            self.file_reproductions()
            self.cut_parameter_sets(cuts)
            self.cut_store_writes(cuts)
            self.cut_cfdp_receive(cuts)
            tasks = sum(1 for x in self.obc.lines if " stopped (" in x and "task " in x)
            self.out("tasks restarted with an event: %d" % tasks)
        finally:
            if self.ground is not None:
                self.ground.close()
            self.obc.stop()


def _state_files(state):
    out = []
    for folder, _, names in os.walk(state):
        if os.path.relpath(folder, state).split(os.sep)[0] == "files":
            continue
        out += [os.path.join(folder, n) for n in names
                if not n.endswith((".lock", ".bad")) and not n.startswith("bad-")]  # fmt: skip
    return out


def _ground_entity(obc, root):
    from obsw_host.cfdp.filestore import RootedFilestore
    from obsw_host.cfdp.link import UdpEntity, make_entity, packet_type_for
    from obsw_host.mission.ids import MissionIds

    ids = MissionIds.locate(obc.mission)
    sat, ground = ids.cfdp_entities
    port = obc.base + ids.apid("cfdp")
    peers = {sat: ("127.0.0.1", port)}
    ent = make_entity(ground, list(peers), RootedFilestore(root), persist=False)
    udp = UdpEntity(ent, ("127.0.0.1", port + 1), peers, apid=ids.apid("cfdp"),
                    packet_type=packet_type_for(False))  # fmt: skip
    return sat, ground, udp


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="2 cuts of each kind (default 20)")
    ap.add_argument("--cuts", type=int, help="power cuts of each kind")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    cuts = args.cuts if args.cuts is not None else (2 if args.quick else 20)
    work = tempfile.mkdtemp(prefix="obsw-brick-")
    t0 = time.monotonic()
    campaign = Campaign(work, args.seed)
    try:
        campaign.run(cuts)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print("%d power cuts, %.0f s" % (3 * cuts, time.monotonic() - t0))
    print("%d passed, %d failed" % (campaign.passed, campaign.failed))
    return 1 if campaign.failed else 0


if __name__ == "__main__":
    sys.exit(main())
