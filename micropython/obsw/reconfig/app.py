"""The reconfiguration module's main loop: SpaceCAN node, essential TC/TM, CPDU, safeguard
memory, time reference and watchdog, on whatever hardware layer it is given.

`ReconfigApp(hal, **mission.load()).run()` on a board (the mission's SCID, node ids, MAP and VC
from ``obsw.reconfig.mission``); tests and the host simulation call `step()` themselves.
Nothing in a step may raise into the loop: an error is counted, makes the application unhealthy
for a while, and an unhealthy application stops kicking the watchdog.
"""

import struct

from obsw.compat import const, micropython
from obsw.reconfig import obclink
from obsw.reconfig.cpdu import Cpdu
from obsw.reconfig.ds3231 import DS3231, TimeSync
from obsw.reconfig.eeprom import M24512
from obsw.reconfig.essential import (
    DECISION_APID,
    ESSENTIAL_MAP,
    HPC_POWER_CYCLE,
    HPC_PRIORITY,
    HPC_SELECT_OBC,
    HPTM_VCID,
    TARGET_BOTH,
    Essential,
    Hpc,
    Report,
)
from obsw.reconfig.hal import NOMINAL, PORT_COM, PORT_OBC, RESET_NAMES
from obsw.reconfig.node import NODE_NOMINAL, NODE_REDUNDANT, CpduNode
from obsw.reconfig.recovery import (
    KIND_NAMES,
    POWER_CYCLE,
    SOURCE_CAN,
    SOURCE_UART,
    Recovery,
    log_pack,
    log_unpack,
)
from obsw.reconfig.safeguard import RecordError, Safeguard
from obsw.reconfig.watchdog import Watchdog
from obsw.spacecan import events as ev

RECORD_STATE = const(0)  # boots, resets by cause, last commanded CPDU bits
RECORD_CONTEXT = const(1)  # the OBC's context word (store_context)
RECORD_SDLS = const(2)  # per SA of the essential TCs: the highest sequence number accepted
# a second area of the safeguard memory, after the first's 8 pages, with 2-page slots
OBC_AREA_PAGE = const(8)
RECORD_OBC_CONTEXT = const(0)  # the OBC's context (mode, time, counters, OBCPs), opaque here
RECORD_RECOVERY_LOG = const(1)  # the newest recovery decisions
LOG_ENTRIES = const(12)

H_RTC = const(0x01)
H_SGM = const(0x02)
H_CAN = const(0x04)
H_OTHER = const(0x08)
H_LOOP = const(0x10)
H_IN_CHARGE = const(0x20)

_STATE_FMT = ">HBBBBH"
FRAMES_PER_BUS = const(32)  # SpaceCAN frames taken from each bus per loop pass
IDLE_MAX_MS = const(250)  # the longest idle of the main loop between passes


def _sdls_record(security):
    """spi u16, top u32 per SA, in SPI order (RECORD_SDLS)."""
    return b"".join(struct.pack(">HI", e[0], e[2]) for e in security.context())


def _where(e):
    """`` at FILE, line N`` of the innermost frame of ``e`` on MicroPython, else ""."""
    try:
        import io
        import sys

        buf = io.StringIO()
        sys.print_exception(e, buf)
    except (AttributeError, ImportError):
        return ""
    lines = [x.strip() for x in buf.getvalue().splitlines() if x.strip().startswith("File")]
    return " at " + lines[-1] if lines else ""


class ReconfigApp:
    """One controller's application. Times: seconds (float) and the hal's microseconds."""

    def __init__(
        self,
        hal,
        scid=0x42,
        node_id=None,
        node_ids=(NODE_NOMINAL, NODE_REDUNDANT),
        essential_map=ESSENTIAL_MAP,
        hptm_vc=HPTM_VCID,
        heartbeat_period=0.5,
        watchdog_open_ms=100,
        watchdog_timeout_ms=1000,
        report_period=1.0,
        status_period=1.0,
        save_period=2.0,
        takeover_ms=500,
        obc_lines=(0, 1),
        cpdu_budget_us=20000,
        tm_frame_length=64,
        cpdu_options=None,
        essential_security=None,
        recovery=None,
    ):
        self.hal = hal
        self.role = hal.role
        self.cpdu = Cpdu(hal, self.role, **(cpdu_options or {}))
        self.cpdu_budget_us = cpdu_budget_us
        devices = [M24512(hal.i2c, a) for a in hal.eeprom_addresses]
        self.sgm = Safeguard(devices, records=4)
        self.obc_sgm = Safeguard(devices, records=2, slot_pages=2, base_page=OBC_AREA_PAGE)
        self.recovery = Recovery(recovery)
        self.decisions = []  # the newest recovery decisions, oldest first (also in the log)
        self.link = obclink.Decoder()
        self.link_counters = {"heartbeats": 0, "context_writes": 0, "context_reads": 0}
        self.link_counters["time_reads"] = 0
        self.rtc = DS3231(hal.i2c, hal.rtc_address)
        self.sync = TimeSync(self.rtc)
        self.watchdog = Watchdog(hal, watchdog_open_ms, watchdog_timeout_ms)
        if node_id is None:  # the mission's node of this controller (obsw.reconfig.mission)
            node_id = node_ids[0] if self.role == NOMINAL else node_ids[1]
        self.node = CpduNode(self, node_id, heartbeat_period)
        # the events _can acts on; the others (SYNC above all, a frame kind a loaded bus may
        # carry thousands of times a second) are not built
        self.node.responder.event_kinds = (ev.UTC, ev.SCET, ev.FUNCTION_CALL)
        self.essential = Essential(
            scid,
            self.role,
            self.in_charge,
            essential_map=essential_map,
            hptm_vcid=hptm_vc,
            obc_lines=obc_lines,
            tm_frame_length=tm_frame_length,
            security=essential_security,
        )
        self.report_period = report_period
        self.status_period = status_period
        self.save_period = save_period
        self.takeover_ms = takeover_ms
        self.boots = 0
        self.resets = [0, 0, 0, 0]
        self.cause = 0
        self.bits = 0
        self.context = 0
        self.health = 0
        self.utc = (0, 0)
        self.temperature = 0.0
        self.counters = {"steps": 0, "loop_errors": 0, "can_tx_errors": 0, "saves": 0}
        self.last_error = None
        self.log = None  # optional callable(text) for notable events
        self._started = None
        # called once when the application has run healthy for healthy_after seconds: the
        # board's boot selector keeps an updated application then (obsw.reconfig.appslot)
        self.on_healthy = None
        self.healthy_after = 30.0
        self._alive = 0
        self._other_level = None
        self._other_seen = 0
        self._bad_until = 0
        self._last_heartbeat = None
        self._can_heartbeat = None
        self._next_status = 0
        self._next_report = 0
        self._next_save = 0
        self._dirty = False
        self._sgm_ok = 0
        self._sdls_saved = None  # the anti-replay tops as last written to the safeguard memory

    # -- life cycle ---------------------------------------------------------------------------

    def _note(self, text):
        if self.log is not None:
            self.log(text)

    def boot(self):
        """After a reset: count it in the safeguard memory, restore the context, start timers."""
        now_us = self.hal.now_us()
        now = now_us / 1000000
        self._started = now
        self.cause = self.hal.reset_cause()
        try:
            rec = self.sgm.read(RECORD_STATE)
            if rec is not None and len(rec) >= struct.calcsize(_STATE_FMT):
                v = struct.unpack(_STATE_FMT, rec)
                self.boots = v[0]
                self.resets = [v[1], v[2], v[3], v[4]]
                self.bits = v[5]
            ctx = self.sgm.read(RECORD_CONTEXT)
            if ctx is not None and len(ctx) == 4:
                self.context = struct.unpack(">I", ctx)[0]
            self._restore_sdls()
            log = self.obc_sgm.read(RECORD_RECOVERY_LOG)
            if log is not None:
                self.decisions = log_unpack(log)
        except (OSError, ValueError) as e:
            self._error(e, now)
        self.recovery.start(now)
        if self.decisions:
            self.recovery.count = self.decisions[-1].count
        self.boots = (self.boots + 1) & 0xFFFF
        if 0 <= self.cause < 4:
            self.resets[self.cause] = (self.resets[self.cause] + 1) & 0xFF
        latched = self.hal.cpdu_readback()
        if latched is not None:
            self.bits = latched
        self.cpdu.bits = self.bits
        self._save_state(now)
        self.watchdog.start(now_us // 1000)
        self.node.responder.start(now)
        self._other_seen = now_us
        self._note(
            "boot %d (%s reset), cpdu 0x%03X, context %d"
            % (self.boots, RESET_NAMES[self.cause], self.bits, self.context)
        )

    def _save_state(self, now):
        rec = struct.pack(_STATE_FMT, self.boots, *(self.resets + [self.bits]))
        try:
            self._sgm_ok = self.sgm.write(RECORD_STATE, rec)
            self.counters["saves"] += 1
        except (OSError, ValueError) as e:
            self._sgm_ok = 0
            self._error(e, now)
        self._dirty = False
        self._next_save = now + self.save_period

    def _restore_sdls(self):
        security = self.essential.frames.security
        if security is None:
            return
        rec = self.sgm.read(RECORD_SDLS)
        if rec is not None and len(rec) % 6 == 0:
            tops = [struct.unpack_from(">HI", rec, i) for i in range(0, len(rec), 6)]
            security.restore([[spi, 0, top] for spi, top in tops])
        self._sdls_saved = _sdls_record(security)

    def _save_sdls(self):
        """Before an authenticated HPC acts, the sequence number that carried it is in the
        safeguard memory: no reset, however timed, lets that frame be accepted again."""
        rec = _sdls_record(self.essential.frames.security)
        if rec != self._sdls_saved:
            self.sgm.write(RECORD_SDLS, rec)
            self._sdls_saved = rec

    def _error(self, e, now):
        self.counters["loop_errors"] += 1
        if repr(e) != self.last_error:  # said once while it repeats, with where it happened
            self._note("loop error: %r%s" % (e, _where(e)))
        self.last_error = repr(e)
        self._bad_until = now + 2.0

    # -- what the SpaceCAN functions and HPCs do ----------------------------------------------

    def lines(self, mask, value, priority=0):
        ok = self.cpdu.run(
            mask, value, self.hal.now_us, budget_us=self.cpdu_budget_us, priority=priority
        )
        if ok:
            self.bits = self.cpdu.bits
            self._dirty = True
            self._note("cpdu 0x%03X (mask 0x%03X)" % (self.bits, mask))
        return ok

    def power_cycle(self, line, off_ms):
        now = self.hal.now_us() / 1000000
        return self.essential.execute(Hpc(HPC_POWER_CYCLE, (line, off_ms), TARGET_BOTH), now)

    def select_obc(self, which):
        now = self.hal.now_us() / 1000000
        return self.essential.execute(Hpc(HPC_SELECT_OBC, (which,), TARGET_BOTH), now)

    def store_context(self, value):
        try:
            ok = self.sgm.write(RECORD_CONTEXT, struct.pack(">I", value)) > 0
        except (OSError, ValueError):
            return False
        if ok:
            self.context = value
        return ok

    def in_charge(self):
        """The nominal always; the redundant while the nominal's alive line stands still."""
        if self.role == NOMINAL:
            return True
        return self.hal.now_us() - self._other_seen > self.takeover_ms * 1000

    # -- the loop -----------------------------------------------------------------------------

    def step(self):
        """One pass of the main loop; returns the milliseconds it may idle."""
        hal = self.hal
        now_us = hal.now_us()
        now = now_us / 1000000
        if self._started is None:
            self.boot()
        self.counters["steps"] += 1
        try:
            self._can(now)
            data = hal.uart_read(PORT_COM)
            if data:
                self.essential.feed(data, now)
                if self.essential.frames.security is not None:
                    self._save_sdls()
            data = hal.uart_read(PORT_OBC)
            if data:
                for frame_type, payload in self.link.feed(data):
                    self._obc_frame(frame_type, payload, now)
            self._recover(now)
            for mask, value in self.essential.take_writes(now):
                if not self.lines(mask, value, HPC_PRIORITY):
                    self.essential.failed()
                self.essential.report_requested = True
            self.sync.poll(now)
            if now >= self._next_status:
                self._status(now)
            if self.essential.report_requested or now >= self._next_report:
                self._next_report = now + self.report_period
                for c in self.essential.report(self.report()):
                    hal.uart_write(PORT_COM, c)
            if self._dirty and now >= self._next_save:
                self._save_state(now)
        except Exception as e:  # the loop outlives any one failure; the watchdog judges
            self._error(e, now)
        self._alive ^= 1
        hal.alive(self._alive)
        level = hal.other_alive()
        if level is not None and level != self._other_level:
            self._other_level = level
            self._other_seen = now_us
        self.watchdog.poll(now_us // 1000, self.healthy(now))
        if self.on_healthy is not None and now - self._started >= self.healthy_after:
            if self.healthy(now):  # once, after running healthy that long (appslot.confirm)
                fn, self.on_healthy = self.on_healthy, None
                fn()
        return self._idle_ms(now)

    @micropython.native
    def _can(self, now):
        """One SpaceCAN pass: at most FRAMES_PER_BUS frames from each bus, then the node's
        deadlines, the replies and the events. The bound keeps a pass short whatever the bus
        carries (a flood waits in the controller's receive FIFO, which drops what overflows),
        so a flood of frames cannot starve the rest of the loop and the watchdog kick."""
        hal = self.hal
        r = self.node.responder
        for bus in (0, 1):
            n = FRAMES_PER_BUS
            while n:
                f = hal.can_recv(bus)
                if f is None:
                    break
                r.receive(bus, f[0], f[1], now)
                n -= 1
        r.poll(now)
        frames = r.take_frames()
        while frames:
            for bus, can_id, data in frames:
                if not hal.can_send(bus, can_id, data):
                    self.counters["can_tx_errors"] += 1
                    r.tx_error(bus, now)
            frames = r.take_frames()
        for e in r.take_events():
            k = e.kind
            if k == ev.UTC:
                self._last_heartbeat = now
                if self.sync.on_utc(e.value, now):
                    self._note(
                        "time: RTC set from the OBC's UTC at the next second (%d s off)"
                        % (self.sync.last_error_ms // 1000)
                    )
            elif k == ev.SCET:
                self.sync.on_scet(e.value, now)
            elif k == ev.FUNCTION_CALL:
                self._note("function %d %r -> %s" % (e.function_id, e.args, e.ok))
        last = r.health[r.monitor.active].last_heartbeat
        if last is not None:
            self._last_heartbeat = last
        for h in r.health:  # the OBC's heartbeat on either bus keeps it alive
            t = h.last_heartbeat
            if t is not None and (self._can_heartbeat is None or t > self._can_heartbeat):
                self._can_heartbeat = t
                self.recovery.heartbeat(SOURCE_CAN, t)

    # -- the OBC: UART link and autonomous recovery -------------------------------------------

    def _obc_frame(self, frame_type, payload, now):
        """One frame from the OBC's UART: heartbeat, context kept or given back, the time."""
        out = None
        if frame_type == obclink.T_HEARTBEAT:
            self.link_counters["heartbeats"] += 1
            self.recovery.heartbeat(SOURCE_UART, now)
        elif frame_type == obclink.T_CONTEXT_WRITE:
            self.link_counters["context_writes"] += 1
            try:
                ok = self.obc_sgm.write(RECORD_OBC_CONTEXT, payload) > 0
            except (OSError, RecordError):
                ok = False
            status = obclink.OK if ok else obclink.FAILED
            out = obclink.encode(obclink.T_ACK, bytes((frame_type, status)))
        elif frame_type == obclink.T_CONTEXT_READ:
            self.link_counters["context_reads"] += 1
            try:
                rec = self.obc_sgm.read(RECORD_OBC_CONTEXT)
                status = obclink.NONE if rec is None else obclink.OK
            except OSError:
                rec, status = None, obclink.FAILED
            out = obclink.encode(obclink.T_CONTEXT, bytes((status,)) + (rec or b""))
        elif frame_type == obclink.T_TIME_READ:
            self.link_counters["time_reads"] += 1
            try:
                if self.rtc.oscillator_stopped():
                    out = obclink.time_reply(obclink.NONE)
                else:
                    day, ms = self.rtc.day_ms()
                    out = obclink.time_reply(obclink.OK, day, ms)
            except (OSError, ValueError):
                out = obclink.time_reply(obclink.FAILED)
        if out is not None:
            self.hal.uart_write(PORT_OBC, out)

    def _recover(self, now):
        """The recovery policy's decision, carried out on the CPDU and reported."""
        latched = self.hal.cpdu_readback()
        if latched is None and not self.in_charge():
            # no read-back to compare with: only the controller in charge acts
            self.recovery.observe(self.bits, now)
            return
        act = self.recovery.poll(now, self.bits if latched is None else latched)
        if act is None:
            return
        kind, mask, value, emask, evalue, line = act
        expect = (emask, evalue) if latched is not None else None
        ok = self.cpdu.run(
            mask,
            value,
            self.hal.now_us,
            budget_us=self.cpdu_budget_us,
            priority=HPC_PRIORITY,
            expect=expect,
        )
        result = ok
        if ok and self.cpdu.skipped:
            result = None
        elif ok:
            self.bits = self.cpdu.bits
            self._dirty = True
            if kind == POWER_CYCLE:
                self.essential.later(now + self.recovery.off_ms / 1000, mask, mask)
        self.recovery.observe(self.bits if latched is None else self.cpdu.bits, now)
        d = self.recovery.done(now, result, now - (self._started or now))
        self.decisions.append(d)
        if len(self.decisions) > LOG_ENTRIES:
            self.decisions.pop(0)
        try:
            self.obc_sgm.write(RECORD_RECOVERY_LOG, log_pack(self.decisions))
        except (OSError, ValueError) as e:
            self._error(e, now)
        for c in self.essential.packet(DECISION_APID, d.pack()):
            self.hal.uart_write(PORT_COM, c)
        self._note(
            "recovery: %s line %d (OBC silent %d ms, %d in window), OBC %d active"
            % (KIND_NAMES[d.kind], d.line, d.silence_ms, d.failures, d.obc)
        )

    def _status(self, now):
        self._next_status = now + self.status_period
        h = 0
        try:
            if not self.rtc.oscillator_stopped():
                h |= H_RTC
            self.utc = self.rtc.day_ms()
            self.temperature = self.rtc.temperature()
        except (OSError, ValueError):
            pass
        if self._sgm_ok == len(self.sgm.devices):
            h |= H_SGM
        if self._last_heartbeat is not None and now - self._last_heartbeat < 3.0:
            h |= H_CAN
        if self.hal.now_us() - self._other_seen <= self.takeover_ms * 1000:
            h |= H_OTHER
        if now >= self._bad_until:
            h |= H_LOOP
        if self.in_charge():
            h |= H_IN_CHARGE
        self.health = h
        c = self.cpdu.counters
        self.node.update(
            {
                "state_bits": self.bits,
                "role": self.role,
                "boot_count": self.boots,
                "reset_cause": self.cause,
                "hpc_count": self.essential.counters["hpcs"] & 0xFFFF,
                "last_hpc": self.essential.last_code,
                "health": h,
                "utc_day": self.utc[0] & 0xFFFF,
                "utc_ms": self.utc[1],
                "temperature": self.temperature,
                "cpdu_writes": c["writes"] & 0xFFFFFFFF,
                "battles_lost": c["battles_lost"] & 0xFFFF,
                "sgm_devices": self._sgm_ok,
                "context": self.context,
                "in_charge": bool(h & H_IN_CHARGE),
            }
        )

    def healthy(self, now):
        return now >= self._bad_until

    def report(self):
        """The essential telemetry report of this controller now."""
        e = self.essential
        now = self.hal.now_us() / 1000000
        return Report(
            role=self.role,
            cpdu=self.bits,
            resets_power=self.resets[0],
            resets_watchdog=self.resets[1],
            resets_stuck=self.resets[2],
            resets_soft=self.resets[3],
            boots=self.boots,
            hpcs=e.counters["hpcs"] & 0xFFFF,
            utc_day=self.utc[0] & 0xFFFF,
            utc_ms=self.utc[1],
            last_hpc=e.last_code,
            last_status=e.last_status,
            health=self.health,
            sgm_devices=self._sgm_ok,
            can_bus=self.node.responder.active,
            temperature_q=int(self.temperature * 4),
            uptime=int(now - (self._started or now)),
            tc_rejected=e.frames.counters["tc_rejected"] & 0xFFFF,
        )

    def _idle_ms(self, now):
        """Milliseconds until the loop has something to do that no input announces: the next
        deadline of the essential writes, the time sync, the SpaceCAN node, the recovery, the
        status, the report, the save and the watchdog kick, and at most IDLE_MAX_MS and a
        quarter of ``takeover_ms`` (the alive line the other controller watches toggles once a
        pass). A HAL's ``idle`` returns early when input comes (a board sleeps till then)."""
        best = IDLE_MAX_MS
        if self.takeover_ms // 4 < best:
            best = self.takeover_ms // 4
        ts = [
            self.essential.next_deadline(),
            self.sync.next_deadline(),
            self.node.responder.next_deadline(),
            self.recovery.next_deadline(),
            self._next_status,
            self._next_report,
        ]
        if self._dirty:
            ts.append(self._next_save)
        kick = self.watchdog.next_deadline()
        if kick is not None:
            ts.append(kick / 1000)
        for t in ts:
            if t is not None:
                ms = int((t - now) * 1000) + 1 if t > now else 0
                if ms < best:
                    best = ms
        return best

    def run(self, steps=None):
        """The main loop (forever unless ``steps`` is given)."""
        n = 0
        while steps is None or n < steps:
            self.hal.idle(self.step())
            n += 1
