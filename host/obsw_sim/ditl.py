"""A day in the life: the mission's orbit flown on one injected clock, passes over its station,
store-and-forward, files across passes and planned commands, with the figures of the day.

Time acceleration is one injected clock (``obsw.il.clock.SimClock``) behind every timer: the
rig advances it (1 s steps around passes and planned commands, 10 s steps between), and every
part reads it: onboard time (the application process's ``time``), the service 11 schedule's
releases, CFDP's timers on both sides, the contact state and the pass table. Nothing sleeps, so
a day runs in as long as the machine needs to compute it, and a run repeats (the link's losses
come from a seeded generator).

On board: a PUS application process with service 8 (the radio's transmitter on and off), 11
(the plan, uplinked as time-tagged TC[8,1]) and 15 (two packet stores: the high-priority
structure and routine housekeeping), ``Contact`` with the uplinked pass table, ``StoreForward``
dumping the stores by priority within each pass's volume, and a CFDP entity holding its
transactions across passes (``PassHold``). On the ground: the same pass prediction, a CFDP
entity with its own hold, and an archive that asks again for gaps in the storage sequence
numbers and acknowledges what it has at the end of each pass. The downlink and uplink carry
what the station's rates allow; ``loss`` drops that share of packets and PDUs each way.
"""

import random

from obsw.cfdp.contact import PassHold
from obsw.cfdp.defs import ACKNOWLEDGED, NO_ERROR
from obsw.cfdp.entity import CfdpEntity
from obsw.cfdp.filestore import MemoryFilestore
from obsw.cfdp.mib import Mib, RemoteEntity
from obsw.frames.contact import AOS, LOS, Contact
from obsw.frames.downlink import StoreForward
from obsw.il.clock import SimClock
from obsw.pus.app import ApplicationProcess
from obsw.pus.services.s08_functions import Function, FunctionManagement, FunctionUser
from obsw.pus.services.s11_scheduling import TimeScheduling, TimeSchedulingUser
from obsw.pus.services.s15_storage import Storage
from obsw.pus.tm import PusTm
from obsw.pus.user import UserProcess
from obsw_host.ops.plan import TX_OFF, TX_ON, plan

APID = 10
HIGH, ROUTINE = 1, 2  # the stores, by priority; also the structure ids they keep
HK = {HIGH: (60.0, 40), ROUTINE: (10.0, 120)}  # sid: (period s, packet data octets)
SPACE, GROUND = 1, 2  # CFDP entity ids
FUNCTIONS = {1: Function(1, TX_ON.split()[1]), 2: Function(2, TX_OFF.split()[1])}


class Day:
    """One run; ``run()`` returns the figures (a dict) and keeps the series for the plots."""

    def __init__(self, predictor, start, seconds, *, down_file=5_000_000, up_file=1_000_000,
                 loss=1e-3, seed=1, store_size=4_000_000):  # fmt: skip
        self.pred = predictor
        self.station = predictor.stations[0]
        self.start = start
        self.end = start + seconds
        self.rng = random.Random(seed)
        self.loss = loss
        self.clock = SimClock(start)
        self.passes = predictor.passes(start, self.end, [self.station])
        # on board
        self.tm_out = []
        self.app = ApplicationProcess(APID, self.tm_out.append, self.clock)
        self.executed = []  # (onboard time, function name)
        local = {1: lambda: self._tx(True), 2: lambda: self._tx(False)}
        self.app.register(FunctionManagement(FUNCTIONS, local=local))
        self.app.register(TimeScheduling())
        stores = [
            {"id": sid, "size": store_size, "kind": 1, "enabled": True,
             "types": {APID: {3: [25]}}, "hk": {APID: [sid]}}
            for sid in (HIGH, ROUTINE)
        ]  # fmt: skip
        self.storage = Storage(stores)
        self.app.register(self.storage)
        # housekeeping goes out through the stores only: real time is the dump caught up
        self.app.tm_filters.append(lambda h: not (h.service == 3 and h.subtype == 25))
        self.contact = Contact(hold=5.0)
        self.contact.load([(p.aos, p.los) for p in self.passes][:64])
        order = [self.storage.stores[HIGH], self.storage.stores[ROUTINE]]
        self.forward = StoreForward(order, self.contact, self.station.downlink_bps)
        self.transmitter = False
        # CFDP both ends, each holding its transactions across passes
        # a slow uplink answers a NAK late (behind the file data already queued): the NAK
        # timer gives it 30 s, ten times, inside a pass; out of contact every timer is frozen
        kw = {"max_segment": 1000, "ack_interval": 10.0, "nak_interval": 30.0, "nak_limit": 10,
              "inactivity": 120.0, "keep_alive_interval": None}  # fmt: skip
        self.down_data = self.rng.randbytes(down_file)
        self.up_data = self.rng.randbytes(up_file)
        self.space_fs = MemoryFilestore({"payload.bin": self.down_data})
        self.ground_fs = MemoryFilestore({"update.bin": self.up_data})
        self.space = CfdpEntity(Mib(SPACE, [RemoteEntity(GROUND, **kw)]), self.space_fs)
        self.ground = CfdpEntity(Mib(GROUND, [RemoteEntity(SPACE, **kw)]), self.ground_fs)
        self.holds = (PassHold(self.space), PassHold(self.ground))
        self.ground_contact = Contact(hold=0.0)  # the ground knows its passes by prediction
        self.ground_contact.load([(p.aos, p.los) for p in self.passes][:64])
        self.cfdp_progress = {"down": [], "up": []}  # (time, octets received) at each AOS
        self.credit = [0.0, 0.0]  # octets each way a step may still send (down, up)
        self.cfdp_log = []  # (time, side, kind, info) of the transactions' main indications
        # the ground: a PUS user and the archive
        self.tc_out = []
        self.user = UserProcess(self.tc_out.append, self.clock, source_id=1)
        self.sched = TimeSchedulingUser()
        self.funcs = FunctionUser(FUNCTIONS)
        self.user.register(self.sched)
        self.user.register(self.funcs)
        self.archive = {HIGH: {}, ROUTINE: {}}  # sid -> {counter: count received}
        self.generated = {HIGH: 0, ROUTINE: 0}
        self.counter = {HIGH: 0, ROUTINE: 0}
        self.duplicates = 0
        self.resend_requests = 0
        self.plan = []
        self.series = {"t": [], "fill": [], "generated": [], "delivered": []}
        self.pass_use = []  # per pass: (aos, los, octets down, volume)
        self.max_fill = 0.0
        self.born = {HIGH: [], ROUTINE: []}  # generation times, by counter - 1
        self.last_sync = start
        self.received_seq = {}  # sid -> storage sequence numbers received, not acknowledged
        self.acked = {}  # sid -> acknowledged through

    # ------------------------------------------------------------------ on board

    def _tx(self, on):
        self.transmitter = on
        self.executed.append((self.app.time(), TX_ON if on else TX_OFF))

    def _housekeeping(self, now):
        for sid, (period, size) in HK.items():
            if now >= self.next_hk[sid]:
                self.next_hk[sid] += period
                self.counter[sid] += 1
                c = self.counter[sid]
                data = bytes((sid >> 8, sid & 0xFF)) + c.to_bytes(4, "big") + bytes(size - 6)
                self.app.send_tm(3, 25, data)
                self.generated[sid] += 1
                self.born[sid].append(now)

    # ------------------------------------------------------------------ the run

    def uplink_plan(self):
        """The day's plan (``obsw ops plan``) as TC[11,4] of TC[8,1], uplinked before it."""
        self.plan = plan(self.passes, lead=60.0, lag=30.0)
        acts = []
        for s in self.plan:
            fname = s.request.split()[1]
            raw, _tx = self.sched.embed(APID, 8, 1, self.funcs.pack(fname))
            acts.append((s.time, raw))
        for i in range(0, len(acts), 8):
            self.sched.insert(APID, acts[i : i + 8])
        while self.tc_out:
            self.app.receive(self.tc_out.pop(0))

    def run(self, progress=None):
        self.uplink_plan()
        self.space.put(GROUND, "payload.bin", "payload.bin", mode=ACKNOWLEDGED)
        self.ground.put(SPACE, "update.bin", "update.bin", mode=ACKNOWLEDGED)
        self.next_hk = {sid: self.start for sid in HK}
        now = self.start
        current = None  # [aos, los, octets, volume] of the pass in progress
        releases = sorted(s.time for s in self.plan)
        while now < self.end:
            self.clock.advance(now - self.clock.now())  # the one clock every part reads
            self._housekeeping(now)
            self.app.tick()
            self.tm_out.clear()  # real-time TM other than housekeeping: verification reports
            edge = self.contact.update(now)
            self.ground_contact.update(now)
            self.holds[0].update(self.contact.in_contact, now)
            self.holds[1].update(self.ground_contact.in_contact, now)
            if edge == AOS:  # where each file stands as the pass begins: its receiver's octets
                for name, ent in (("down", self.ground), ("up", self.space)):
                    for t in ent.tx.values():
                        if t.role == "R":
                            self.cfdp_progress[name].append((now, t.progress_of()))
            if edge == AOS:
                self.credit = [0.0, 0.0]
                w = self.contact.window(now) or (now, now)
                volume = self.station.downlink_bps * (w[1] - w[0]) / 8
                current = [now, w[1], 0, volume]
            in_pass = self.contact.in_contact and self.ground_contact.in_contact
            dt = 1.0 if in_pass or self._near(now, releases) else 10.0
            if in_pass and current is not None:
                current[2] += self._pass_second(now, dt)
                if int(now - current[0]) % 30 == 29:
                    self._ground_sync(now)
            if edge == LOS and current is not None:
                self._ground_sync(now)
                self.pass_use.append(tuple(current))
                current = None
            self.space.poll(now)
            self.ground.poll(now)
            for side, ent in ((0, self.space), (1, self.ground)):
                for ind in ent.pop_indications():
                    if ind.kind in ("finished", "fault", "abandoned", "suspended", "resumed"):
                        self.cfdp_log.append((now, side, ind.kind, ind.info))
            fill = max(st.fill() for st in self.storage.stores.values())
            self.max_fill = max(self.max_fill, fill)
            if int(now) % 60 == 0:
                self.series["t"].append(now)
                self.series["fill"].append(fill)
                self.series["generated"].append(sum(self.generated.values()))
                self.series["delivered"].append(sum(len(a) for a in self.archive.values()))
            if progress is not None and int(now) % 3600 == 0:
                progress(now)
            step = now + dt
            while releases and releases[0] <= now:
                releases.pop(0)
            if releases and now < releases[0] < step:
                step = releases[0]  # a planned command is released at its time, not after
            now = step
        return self.figures()

    def _near(self, now, releases):
        for t in releases:
            if -5.0 <= t - now <= 15.0:
                return True
        return False

    def _pass_second(self, now, dt):
        """One step of a pass: the stores' dump and CFDP down, CFDP up; octets sent down."""
        budget = self.station.downlink_bps * dt / 8
        sent = 0
        left_in_pass = self.forward.budget(now)
        while True:
            got = self.forward.next(now, budget=min(budget - sent, left_in_pass - sent))
            if got is None:
                break
            st, seq, raw = got
            sent += len(raw)
            if self.rng.random() >= self.loss:
                self._archive(st.id, seq, raw)
        # CFDP file data and directives fill what is left of this step, one PDU at a time
        room = min(budget, left_in_pass) - sent
        sent += self._carry(0, self.space, self.ground, room, now)
        self._carry(1, self.ground, self.space, self.station.uplink_bps * dt / 8, now)
        return sent

    def _carry(self, way, src, dst, room, now):
        """PDUs from ``src`` to ``dst`` within ``room`` octets of this step (a PDU that ran
        over is paid back from the next step's room); octets sent."""
        credit = self.credit[way] + room
        n = 0
        while credit > 0:
            out = src.transmit(now, 1)
            if not out:
                credit = min(credit, 0.0)  # an idle link saves no credit
                break
            for _dest, pdu in out:
                n += len(pdu)
                credit -= len(pdu)
                if self.rng.random() >= self.loss:
                    dst.receive(pdu, now)
        self.credit[way] = credit
        return n

    def _archive(self, sid, seq, raw):
        tm = PusTm.unpack(raw)
        counter = int.from_bytes(tm.data[2:6], "big")
        got = self.archive[sid]
        if counter in got:
            self.duplicates += 1
        got[counter] = seq
        self.received_seq.setdefault(sid, set()).add(seq)

    def _ground_sync(self, now):
        """The ground asks for the gaps in the storage sequence numbers, up to the store's
        next number (its status report, TM[15,x]), and acknowledges everything before the
        first gap; every 30 s of a pass and at LOS, as TCs handed to the forwarder at once."""
        self.last_sync = now
        for st in self.forward.stores:
            have = self.received_seq.setdefault(st.id, set())
            acked = self.acked.get(st.id, 0)
            top = self.forward.next_seq[st.id]
            missing = [s for s in range(acked + 1, top) if s not in have]
            for s in missing:
                self.forward.resend(st.id, s, s)
                self.resend_requests += 1
            complete = missing[0] - 1 if missing else top - 1
            if complete > acked:
                self.forward.acknowledge(st.id, complete)
                self.acked[st.id] = complete
                have.difference_update(range(acked + 1, complete + 1))

    def figures(self):
        delivered = {sid: len(self.archive[sid]) for sid in HK}
        # every report generated before the ground's last look at the stores has arrived
        due = {sid: sum(1 for t in self.born[sid] if t < self.last_sync - 1) for sid in HK}
        missing = sum(
            1 for sid in HK for c in range(1, due[sid] + 1) if c not in self.archive[sid]
        )
        planned = sorted((s.time, s.request) for s in self.plan if s.time < self.end)
        done = sorted(self.executed)
        lateness = []
        for (t, req), (te, reqe) in zip(planned, done):
            lateness.append(te - t if req == reqe else float("inf"))
        down_ok = self.ground_fs.files.get("payload.bin")
        up_ok = self.space_fs.files.get("update.bin")
        orbit_s = 86400.0 / self.pred.tle.mean_motion
        return {
            "hours": (self.end - self.start) / 3600,
            "orbits": (self.end - self.start) / orbit_s,
            "passes": len(self.passes),
            "generated": dict(self.generated),
            "delivered": delivered,
            "due": due,
            "missing": missing,
            "duplicates": self.duplicates,
            "resend_requests": self.resend_requests,
            "max_store_fill": self.max_fill,
            "overflow": sum(st.rejected + st.overwritten for st in self.storage.stores.values()),
            "planned": len(planned),
            "executed": len(done),
            "max_lateness": max(lateness) if lateness else 0.0,
            "down_file": bytes(down_ok) == self.down_data if down_ok is not None else False,
            "up_file": bytes(up_ok) == self.up_data if up_ok is not None else False,
            "down_resumes": self.cfdp_progress["down"],
            "up_resumes": self.cfdp_progress["up"],
            "pass_use": self.pass_use,
            "cfdp_conditions": NO_ERROR,
        }
