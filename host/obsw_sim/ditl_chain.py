"""A day in the life of the whole chain: the OBC's processes, both reconfiguration
controllers, TM frames and CLTUs between the OBC's UARTs and the station, the ground, flying
the mission's orbit under time acceleration (``obsw_sim.faketime``: one clock, faster, in
every process).

``ChainDay(work, predictor, seconds)`` runs in a process started under libfaketime (the
tool ``tools/ditl.py`` starts itself so). It brings the chain up with contact awareness on
(``contact.stores``: store 1 for the high-priority housekeeping and the verification of the
planned commands, store 2 for the routine housekeeping and the OBC's store backlog), then:

- the pass table (``obsw_host.ops.pass_table``: the day's passes over the mission's first
  station) goes up with TC[8,1] ``Passes.load``, and the plan (``obsw_host.ops.plan``: a
  command ``lead`` s before AOS and one ``lag`` s after LOS, here ``SolarPanel.set_angle``
  standing in for the transmitter) as TC[11,4];
- the station's links carry nothing out of a pass (``FdLink.carrier``, set from the same
  prediction): the OBC knows its passes from the table only; nothing is sent to it out of
  contact;
- in a pass the ground archives what comes down by the PUS message type counter of each
  stored type (housekeeping TM[3,25], verification TM[1,3], [1,7], [1,8]: each counter
  counts every report of its type, so a number missing between two that came is a report
  lost), and every ``ack_every`` s and just before LOS, when no number is missing,
  acknowledges (``Passes.acknowledge``) through the last storage sequence number the
  ``passes.dumped`` events had named one round before (a report lost since would show as a
  missing number by now), else asks again for everything after its last acknowledgement
  (``Passes.resend``);
- files go through the frames (``Chain.cfdp_frames``): the ground's CFDP entity (class 2,
  its own ``PassHold`` driven by the prediction, its file data at most ``up_rate`` octets/s)
  puts ``up_size`` octets up and asks the OBC by proxy put for ``down_size`` octets; the
  OBC's entity sends its PDUs into the frame processor's TM input with the dump's part of
  the downlink when the stores have nothing waiting (``Passes.spare``: ``share``, here 95 %,
  of ``contact.downlink_bps``) and holds them across passes with the OBC's own ``Passes``.

``run()`` returns the figures (a dict) and keeps the series for the plots.
"""

import os
import random
import select
import time

from obsw.cfdp import msgs
from obsw.cfdp.contact import PassHold
from obsw.cfdp.defs import ACKNOWLEDGED
from obsw.spp import TYPE_TC
from obsw_host.cfdp.filestore import RootedFilestore
from obsw_host.cfdp.link import UdpEntity, make_entity
from obsw_host.obc.passes import pack_table
from obsw_host.ops.pass_table import windows
from obsw_host.ops.plan import plan
from obsw_host.pus.storage_ground import StorageGround
from obsw_host.pus.tai import TAI_MINUS_UNIX

from obsw_sim.chain import Chain

HIGH, ROUTINE = 1, 2  # the stores, by priority
HK_HIGH, HK_ROUTINE = 1, 30  # SolarPanel housekeeping; the backlog and the OBC's load
PLAN_ON = "function SolarPanel.set_angle angle=30"
PLAN_OFF = "function SolarPanel.set_angle angle=0"


def chain_settings(chain, speed):
    """The chain's timers for a run at ``speed``: heartbeats and deadlines in onboard seconds
    that leave a loaded machine room (a deadline of 2 s is 20 ms here at 100 times)."""
    slack = max(1.0, speed / 2.0)
    chain.platform.update(heartbeat=1.0, deadline=6.0 * slack, start_timeout=60.0 * slack,
                          context_period=5.0, module_timeout=1.0 * slack)  # fmt: skip
    chain.sections["spacecan"] = {"heartbeat_period": 1.0, "timeout": 1.0 * slack}
    chain.sections["frames"] = {"clcw_period": 1.0}
    chain.sections["obcp"] = {"step_period": 0.5}
    chain.sections["pus"] = {"period": 0.25}
    chain.sections["cfdp"] = {"poll": 0.1}
    chain.recovery.update(deadline=8.0 * slack, boot_grace=60.0 * slack)
    chain.sim_options.update(watchdog_timeout_ms=int(3000 * slack), watchdog_open_ms=0,
                             boot_limit=30.0 * slack)  # fmt: skip


class ChainDay:
    """One run of the whole chain (see the module text)."""

    def __init__(self, work, predictor, seconds, speed, out=None, hk_period=10.0,
                 ack_every=60.0, lead=60.0, lag=30.0, down_size=5_000_000,
                 up_size=1_000_000, up_rate=900.0, frame_length=1024,
                 downlink_bps=None):  # fmt: skip
        self.work = work
        self.pred = predictor
        self.station = predictor.stations[0]
        self.seconds = seconds
        self.speed = speed
        self.out = out
        self.hk_period = hk_period
        self.ack_every = ack_every
        self.lead, self.lag = lead, lag
        self.chain = Chain(work, out=out, processes=Chain.SAMPLE_PROCESSES,
                           timeout=10.0 * max(1.0, speed / 2.0))  # fmt: skip
        # the dump and the files take 95 % of the downlink; the rest is real-time TM (events,
        # acceptance reports), a few packets a second
        self.chain.sections["contact"] = {"stores": [HIGH, ROUTINE], "hold": 5.0, "share": 0.95}
        chain_settings(self.chain, speed)
        # files through the frames; the OBC paces its dump and its file data at a share of the
        # downlink rate (``downlink_bps``, default the station's; contact.downlink_bps: the
        # frame processor does not pace, a radio paced in accelerated time needs a wake-up
        # per frame)
        self.chain.cfdp_frames = True
        self.chain.tm_frame_length = frame_length
        # the UARTs' queues hold a burst rather than drop it while the station reads
        self.chain.sections["frames"].update(tm_frame_length=frame_length, uart_queue=4096)
        self.downlink_bps = downlink_bps or self.station.downlink_bps
        self.chain.sections["contact"]["downlink_bps"] = self.downlink_bps
        rng = random.Random(7)
        self.down_data = rng.randbytes(down_size)
        self.up_data = rng.randbytes(up_size)
        self.up_rate = up_rate
        self.onboard_files = os.path.join(self.chain.state, "files")
        self.ground_files = os.path.join(work, "ground-files")
        for folder, name, data in ((self.onboard_files, "payload.bin", self.down_data),
                                   (self.ground_files, "update.bin", self.up_data)):  # fmt: skip
            os.makedirs(folder, exist_ok=True)
            with open(os.path.join(folder, name), "wb") as f:
                f.write(data)
        self.cfdp = None  # the ground's entity (UdpEntity), once the chain is up
        self.hold = None
        self.cfdp_progress = {"down": [], "up": []}  # (time, octets) at each AOS
        self.cfdp_log = []  # (time, kind, info) of the ground entity's main indications
        self.transactions = {"down": set(), "up": set()}  # ids seen per file
        self.archive = {HIGH: {}, ROUTINE: {}}  # store -> {key: arrival (onboard s)}
        self.duplicates = 0
        self.dumped = {HIGH: [], ROUTINE: []}  # (first, last, count) of passes.dumped
        self.acked = {HIGH: 0, ROUTINE: 0}
        self.resends = 0
        self._asked = {}
        self._ready = {}  # store -> the last sequence number dumped, as of the last round
        self._resent = {}  # store -> reports asked again, not yet come twice
        self.backlog = []  # (onboard s, octets) from store 2's reports
        self.executed = {}  # planned step index -> onboard time of its TM[1,7]
        self.started = {}  # planned step index -> onboard time of its TM[1,3]
        self.plan = []
        self.pass_use = []  # (aos, los, packets down, volume octets)
        self.series = {"t": [], "generated": [], "delivered": []}
        self.generated = {HK_HIGH: [], HK_ROUTINE: []}  # time tags seen, to count them
        self.contacts = 0
        self._tx_steps = {}  # request id -> plan step index
        self.seen = {}  # (service, subtype) -> TM packets the ground decoded

    def say(self, text):
        if self.out is not None:
            self.out(text)

    # ---------------------------------------------------------------- the ground's view

    def _tm(self, tm, decoded, tx):
        """Every TM the ground decodes: archive, dump events, plan verification."""
        k = (tm.service, tm.subtype)
        self.seen[k] = self.seen.get(k, 0) + 1
        if tm.service == 3 and tm.subtype == 25 and len(tm.data) >= 2:
            sid = tm.data[0] << 8 | tm.data[1]
            store = HIGH if sid == HK_HIGH else ROUTINE if sid == HK_ROUTINE else None
            if store is None:
                return
            self._archive(store, (3, 25, tm.message_counter))
            if sid == HK_ROUTINE and decoded and "values" in decoded:
                v = decoded["values"].get("Passes.backlog")
                if v is not None:
                    self.backlog.append((_seconds(tm), v))
        elif tm.service == 1 and tm.subtype in (3, 7, 8) and decoded:
            rid = decoded.get("request_id")
            if rid is None:
                return
            # store 1 keeps every start and completion report: each counted, whoever asked
            self._archive(HIGH, (1, tm.subtype, tm.message_counter))
            step = self._tx_steps.get(rid)
            if step is None:
                return
            if tm.subtype == 3:  # the start of its execution: when it was released
                self.started[step] = _seconds(tm)
            elif tm.subtype == 8:
                self.say("planned command %d failed: %r" % (step, decoded))
            else:
                self.executed[step] = _seconds(tm)
        elif tm.service == 5 and len(tm.data) >= 2:
            eid = tm.data[0] << 8 | tm.data[1]
            if eid == self._dumped.id:
                d = self._dumped.unpack(tm.data[2:])
                if d["store"] in self.dumped:
                    self.dumped[d["store"]].append((d["first"], d["last"], d["count"]))

    def _archive(self, store, key):
        """One report into the ground's archive; one already there is a duplicate unless the
        ground asked for it again (``Passes.resend`` of a range: as many reports of the store
        as the range holds may come twice)."""
        if key in self.archive[store]:
            if self._resent.get(store, 0) > 0:
                self._resent[store] -= 1
            else:
                self.duplicates += 1
                if self.duplicates <= 5:  # what they are, for the record
                    self.say("a report came twice: store %d, %r, first %.1f s before" % (
                        store, key, self.onboard() - self.archive[store][key]))  # fmt: skip
        self.archive[store][key] = self.onboard()

    def onboard(self):
        return time.time() + TAI_MINUS_UNIX

    # ---------------------------------------------------------------- set-up

    def _wait_up(self):
        """Ping until one completes, each with a timeout that a loaded machine can meet."""
        slack = max(1.0, self.speed / 2.0)
        end = time.monotonic() + 600.0 * slack
        while time.monotonic() < end:
            try:
                if self.chain.ground.ping(timeout=5.0 * slack).ok:
                    return
            except Exception:
                pass
        raise TimeoutError("no ping completed through the chain")

    def _setup(self):
        chain = self.chain
        g = chain.ground
        g.keep_unsolicited = 100
        self._dumped = chain.sdb.event("passes.dumped")
        g.proc.listeners.append(self._tm)
        sg = StorageGround(g)
        apid = g.apid
        period = float(chain.config.section("pus").get("period", 0.1))
        ticks = lambda s: max(1, int(round(s / period)))  # noqa: E731
        ok = [
            g.perform("SolarPanel.deploy").ok,  # the plan turns the panel: deployed first
            g.create_hk(HK_ROUTINE, ticks(self.hk_period * 6),
                        ["Passes.backlog", "Obc.cpu_load", "Obc.restarts"]).ok,
            g.set_hk_interval(HK_HIGH, ticks(self.hk_period)).ok,
            g.enable_hk([HK_HIGH, HK_ROUTINE]).ok,
        ]  # fmt: skip
        for store, types, sids in ((HIGH, {3: [25], 1: [3, 7, 8]}, [HK_HIGH]),
                                   (ROUTINE, {3: [25]}, [HK_ROUTINE])):  # fmt: skip
            ok.append(sg.create_store(store, 4_000_000, kind=1).ok)
            ok.append(sg.store_types(store, {apid: types}).ok)
            ok.append(sg.store_hk(store, sids).ok)  # these only, each in one store
        ok.append(sg.enable_storage([HIGH, ROUTINE]).ok)
        if not all(ok):
            raise RuntimeError("the day's stores and housekeeping were not set up: %r" % ok)
        self.sg = sg

    def _uplink(self):
        g = self.chain.ground
        table = pack_table(windows(self.passes))
        tx = g.perform("Passes.load", table=table)
        if not tx.ok:
            raise RuntimeError("pass table refused: %s" % tx.verification())
        self.plan = plan(self.passes, lead=self.lead, lag=self.lag, tx_on=PLAN_ON,
                         tx_off=PLAN_OFF)  # fmt: skip
        for i, step in enumerate(self.plan):
            words = step.request.split()
            args = dict(w.split("=", 1) for w in words[2:])
            req = g.function_request(words[1], **{k: float(v) for k, v in args.items()})
            self._tx_steps[req.request_id] = i
            tx = g.schedule_at(step.time + TAI_MINUS_UNIX, req)
            if not tx.ok:
                raise RuntimeError("plan step %d refused: %s" % (i, tx.verification()))

    def _files(self):
        """The ground's CFDP entity on the chain's ground port, behind the station; the two
        transfers asked (they start at the first AOS: the hold keeps them till then). Its
        segments are 900 octets: a PDU in its space packet fits one signed TC frame (1024
        octets at most), which FOP-1's window of five frames then carries best."""
        chain = self.chain
        onboard, ground = chain.ids.cfdp_entities
        entity = make_entity(ground, [onboard], RootedFilestore(self.ground_files),
                             state=os.path.join(self.work, "ground-cfdp"),
                             segment=900, limit=100, inactivity=3600.0, ack_interval=5.0,
                             nak_interval=5.0)  # fmt: skip
        self.cfdp = UdpEntity(entity, ("127.0.0.1", chain.cfdp_ground_port),
                              {onboard: chain.station.address}, apid=chain.ids.apid("cfdp"),
                              packet_type=TYPE_TC, rate=self.up_rate)  # fmt: skip
        self.hold = PassHold(entity)
        now = time.monotonic()
        self.hold.update(False, now)
        entity.put(onboard, "update.bin", "update.bin", mode=ACKNOWLEDGED, now=now)
        entity.put(
            onboard,
            mode=ACKNOWLEDGED,
            now=now,
            messages=[msgs.proxy_put_request(ground, "payload.bin", "payload.bin")],
        )
        self.hold.update(False, now)

    def _cfdp_step(self, in_pass, aos):
        ent = self.cfdp.entity
        now = time.monotonic()
        self.hold.update(in_pass, now)
        for ind in self.cfdp.step(0):
            if ind.kind in ("finished", "fault", "abandoned", "suspended", "resumed"):
                self.cfdp_log.append((time.time(), ind.kind, dict(ind.info)))
            if ind.kind in ("finished", "fault", "abandoned"):
                self.say("file transfer %s: %r" % (ind.kind, dict(ind.info)))
        for t in list(ent.tx.values()):
            meta = getattr(t, "meta", None) or {}
            if t.role == "R" and meta.get("dest_name") == "payload.bin":
                name = "down"
            elif t.role == "S" and getattr(t, "source_name", None) == "update.bin":
                name = "up"
            else:
                continue  # the proxy put request and its response: options only
            self.transactions[name].add(tuple(t.tid))
            if aos:
                self.cfdp_progress[name].append((time.time(), t.progress_of()))

    def _say_files(self):
        st = self.chain.station
        txs = ["%s %s %d%s" % (t.role, getattr(t, "source_name", None) or "-", t.progress_of(),
                               " suspended" if t.suspended else "")
               for t in self.cfdp.entity.tx.values()]  # fmt: skip
        self.say("files at LOS: ground entity sent %d PDUs, received %d; station uplinked %d, "
                 "refused %d; transactions: %s; TM so far %s" % (self.cfdp.sent,
                  self.cfdp.received, st.uplinked, st.refused, ", ".join(txs) or "none",
                  sorted(self.seen.items())))  # fmt: skip

    def file_results(self):
        """(identical, transactions, octets at each AOS) of each file."""
        out = {}
        for name, path, data in (("down", os.path.join(self.ground_files, "payload.bin"),
                                  self.down_data),
                                 ("up", os.path.join(self.onboard_files, "update.bin"),
                                  self.up_data)):  # fmt: skip
            try:
                with open(path, "rb") as f:
                    same = f.read() == data
            except OSError:
                same = False
            out[name] = (same, len(self.transactions[name]),
                         [p for _, p in self.cfdp_progress[name]])  # fmt: skip
        return out

    # ---------------------------------------------------------------- the day

    def in_pass(self, t):
        for p in self.passes:
            if p.aos <= t < p.los:
                return p
        return None

    def _carrier(self, on):
        for link in self.chain.links:
            link.carrier = on

    def run(self, progress=None):
        chain = self.chain
        began = time.monotonic()
        chain.start()
        # the two links' copies of a frame, paired however far apart a busy machine reads them
        chain.station.ground.dedup.window = 5.0 * max(1.0, self.speed / 2.0)
        try:
            self._wait_up()
            self._setup()
            self.start = time.time()
            self.end = self.start + self.seconds
            self.passes = [p for p in self.pred.passes(self.start, self.end, [self.station])
                           if p.aos > self.start + 60.0]  # fmt: skip
            self._uplink()
            self._files()
            self.say("chain up and set in %.0f s here; %d passes to fly" % (
                time.monotonic() - began, len(self.passes)))  # fmt: skip
            self._fly(progress)
        finally:
            chain.stop()
        return self.figures()

    def _fly(self, progress):
        g = self.chain.ground
        current = None
        last_ack = 0.0
        next_sample = self.start
        next_progress = self.start + 3600.0
        while True:
            now = time.time()
            if now >= self.end:
                break
            p = self.in_pass(now)
            self._cfdp_step(p is not None, p is not None and current is None)
            if p is not None and current is None:  # AOS
                self._carrier(True)
                self.contacts += 1
                current = [p.aos, p.los, sum(len(a) for a in self.archive.values()),
                           self.downlink_bps * (p.los - p.aos) / 8]  # fmt: skip
                last_ack = now
            elif p is None and current is not None:  # LOS
                self._carrier(False)
                current[2] = sum(len(a) for a in self.archive.values()) - current[2]
                self.pass_use.append(tuple(current))
                current = None
                self._say_files()
            # once more within 15 s of LOS, whatever the period
            closing = current is not None and now > current[1] - 15.0 > last_ack
            if current is not None and (now - last_ack >= self.ack_every or closing):
                last_ack = now
                self._acknowledge()
            select.select([g.sock, self.cfdp.sock], [], [], 0.05)
            g.poll(0)
            if now >= next_sample:
                next_sample += 60.0
                self.series["t"].append(now)
                self.series["delivered"].append(sum(1 for k in self.archive[HIGH] if k[0] == 3))
                self.series["generated"].append((now - self.start) / self.hk_period)
            if progress is not None and now >= next_progress:
                next_progress += 3600.0
                progress(now - self.start, self)
        self._carrier(False)

    def _missing(self):
        """Reports missing: per stored type, the message type counters between the first and
        the newest that came (16 bits: a day's reports of one type do not wrap)."""
        seen = {}
        for a in self.archive.values():
            for service, subtype, counter in a:
                seen.setdefault((service, subtype), set()).add(counter)
        return {k: max(c) - min(c) + 1 - len(c) for k, c in seen.items()}

    def _acknowledge(self):
        """With no report missing, acknowledge per store through the last sequence number
        dumped as of the last round; else ask again for all after the last acknowledgement."""
        g = self.chain.ground
        missing = sum(self._missing().values())
        for store in (HIGH, ROUTINE):
            dumps = self.dumped[store]
            if not dumps:
                continue
            last = max(d[1] for d in dumps)
            ready, self._ready[store] = self._ready.get(store, 0), last
            try:
                if not missing:
                    if ready > self.acked[store]:
                        tx = g.perform("Passes.acknowledge", store=store, seq=ready, timeout=10.0)
                        if tx.ok:
                            self.acked[store] = ready
                elif not self._asked.get(store):
                    first = self.acked[store] + 1
                    # counted before it goes: a TC whose report is late may still have run
                    self._resent[store] = self._resent.get(store, 0) + last - first + 1
                    self._asked[store] = True
                    g.perform("Passes.resend", store=store, first=first, last=last,
                              timeout=10.0)  # fmt: skip
                    self.resends += 1
                else:
                    self._asked[store] = False  # asked last round: ask again next round
            except Exception as e:  # a TC lost at the pass's edge: the next round asks again
                self.say("acknowledgement of store %d: %s" % (store, e))

    # ---------------------------------------------------------------- figures

    def figures(self):
        # a command's completion report comes down in the first pass after it: those planned
        # before the AOS of the last pass flown are the ones the ground can have seen
        horizon = max((u[0] for u in self.pass_use), default=self.start)
        planned = [(i, s.time + TAI_MINUS_UNIX) for i, s in enumerate(self.plan)
                   if s.time < min(horizon, self.end)]  # fmt: skip
        # executed: completed (TM[1,7]); its time: the start of its execution (TM[1,3])
        lateness = [self.started.get(i, self.executed[i]) - t for i, t in planned
                    if i in self.executed]  # fmt: skip
        # every housekeeping report from the first to the newest delivered came: no message
        # type counter of TM[3,25] missing between them (both stores' structures count)
        hk = sorted(k[2] for a in self.archive.values() for k in a if k[0] == 3)
        missing = self._missing().get((3, 25), 0)
        orbit_s = 86400.0 / self.pred.tle.mean_motion
        return {
            "hours": self.seconds / 3600.0,
            "orbits": self.seconds / orbit_s,
            "passes": len(self.passes),
            "contacts": self.contacts,
            "delivered": {s: len(a) for s, a in self.archive.items()},
            "hk_due": hk[-1] - hk[0] + 1 if hk else 0,
            "missing": missing,
            "duplicates": self.duplicates,
            "resends": self.resends,
            "acked": dict(self.acked),
            "max_backlog": max((v for _, v in self.backlog), default=0),
            "store_size": 4_000_000,
            "planned": len(planned),
            "executed": len(lateness),
            "max_lateness": max((abs(x) for x in lateness), default=float("inf")),
            "lateness": lateness,
            "pass_use": self.pass_use,
            "obc_boots": self.chain.sim.obc_boots if self.chain.sim else None,
            "process_restarts": sum(
                1
                for _, text in self.chain.sim.log_lines()
                if "[platform]" in text and "restarting" in text
            ),
            "controller_resets": sum(len(r) for r in self.chain.sim.resets),
            "files": self.file_results(),
            "down_size": len(self.down_data),
            "up_size": len(self.up_data),
        }


def _seconds(tm):
    coarse, fine = tm.time
    return coarse + fine / 65536.0
