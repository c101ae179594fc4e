"""Essential telecommand and telemetry: high priority commands (HPCs) from the COM module on their
own MAP ID act on the CPDU lines without the OBC; a compact report goes back on its own TM
virtual channel (HPTM).

TC: CLTUs from the COM UART go through the frames core (CLTU, TC frame, FARM, segments); the
MAP service data units of ``essential_map`` are HPCs, the rest belongs to the OBC and is only
counted. Send HPCs as Type-BD frames: this module's FARM does not follow the OBC's sequence.
An HPC is a TC space packet (or the bare bytes) whose data are ``code u8, target u8, args``.
With ``security`` (an ``obsw.frames.sdls.TcSecurity``, e.g. from ``security_from_file``) every
frame must be authenticated (SDLS), HPCs by the SA of the essential MAP; rejected frames are
counted in ``frames.counters["tc_rejected"]`` and by outcome in ``security.counters``.
"""

import struct

from obsw.compat import const
from obsw.frames.asm import cadu
from obsw.frames.processor import FrameProcessor
from obsw.frames.tm_mux import TmMultiplexer, TmVirtualChannel
from obsw.reconfig.hal import CPDU_MASK, NOMINAL
from obsw.spp import SequenceCounter, SpacePacket

HPC_LINES = const(1)  # mask u16, value u16: set lines
HPC_POWER_CYCLE = const(2)  # line u8, off_ms u16: off now, on again after off_ms
HPC_SELECT_OBC = const(3)  # which u8: 0 nominal, 1 redundant (the other is switched off)
HPC_REPORT = const(4)  # send an HPTM report now
HPC_CLEAR = const(5)  # clear the HPC counters
HPC_NAMES = ("", "lines", "power_cycle", "select_obc", "report", "clear")

TARGET_IN_CHARGE = const(0)  # whichever controller is in charge (the nominal while alive)
TARGET_NOMINAL = const(1)
TARGET_REDUNDANT = const(2)
TARGET_BOTH = const(3)

STATUS_NONE = const(0)
STATUS_DONE = const(1)
STATUS_REJECTED = const(2)  # malformed or unknown
STATUS_NOT_MINE = const(3)  # meant for the other controller
STATUS_FAILED = const(4)  # CPDU access failed

ESSENTIAL_MAP = const(63)
HPTM_VCID = const(6)
HPTM_APID = const(0x07E)
DECISION_APID = const(0x07D)  # HPTM: the recovery decisions (obsw.reconfig.recovery.Decision)
HPC_PRIORITY = const(3)  # CPDU battle priority of an HPC (above SpaceCAN's 0)

_ARGS = {
    HPC_LINES: ">HH",
    HPC_POWER_CYCLE: ">BH",
    HPC_SELECT_OBC: ">B",
    HPC_REPORT: "",
    HPC_CLEAR: "",
}


class HpcError(ValueError):
    """An HPC with an unknown code, wrong argument length or a value out of range."""

    def __init__(self, msg, code=None):
        super().__init__(msg)
        self.code = code


class Hpc:
    """A high priority command: code, target and its arguments (a tuple)."""

    def __init__(self, code, args=(), target=TARGET_IN_CHARGE):
        self.code = code
        self.args = tuple(args)
        self.target = target

    def pack(self):
        fmt = _ARGS.get(self.code)
        if fmt is None:
            raise HpcError("unknown HPC code %r" % (self.code,), self.code)
        return bytes((self.code, self.target)) + (struct.pack(fmt, *self.args) if fmt else b"")

    @classmethod
    def unpack(cls, buf):
        if len(buf) < 2:
            raise HpcError("HPC too short: %d bytes, needs 2" % len(buf))
        code = buf[0]
        fmt = _ARGS.get(code)
        if fmt is None:
            raise HpcError("unknown HPC code %d" % code, code)
        n = struct.calcsize(fmt) if fmt else 0
        if len(buf) != 2 + n:
            raise HpcError("HPC %d needs %d bytes, got %d" % (code, 2 + n, len(buf)), code)
        if buf[1] > TARGET_BOTH:
            raise HpcError("HPC target %d outside 0..3" % buf[1], code)
        args = struct.unpack(fmt, buf[2:]) if fmt else ()
        return cls(code, args, buf[1])

    def packet(self, apid=0x7F, seq_count=0):
        """The HPC in a TC space packet, as the ground sends it on the essential MAP."""
        return SpacePacket(1, apid, self.pack(), False, 3, seq_count).pack()

    def __eq__(self, other):
        return isinstance(other, Hpc) and self.pack() == other.pack()

    def __repr__(self):
        name = HPC_NAMES[self.code] if self.code < len(HPC_NAMES) else str(self.code)
        return "Hpc(%s%r target=%d)" % (name, self.args, self.target)


def hpc_of_unit(unit):
    """The HPC in a MAP service data unit: a TC space packet's data field, or the bare bytes."""
    if len(unit) >= 7 and not unit[0] & 0xE0 and ((unit[4] << 8) | unit[5]) + 7 == len(unit):
        return Hpc.unpack(unit[6:])
    return Hpc.unpack(unit)


class Report:
    """The essential telemetry report (HPTM data), big-endian: 31 bytes in version 2, which
    adds ``tc_rejected`` (TC frames refused by TC security, modulo 2**16) to the 29 of
    version 1; a version 1 report still decodes (``tc_rejected`` 0)."""

    _FMT = ">BBHBBBBHHHIBBBBBhIH"
    _FMT_V1 = ">BBHBBBBHHHIBBBBBhI"
    FIELDS = (
        "version",
        "role",
        "cpdu",
        "resets_power",
        "resets_watchdog",
        "resets_stuck",
        "resets_soft",
        "boots",
        "hpcs",
        "utc_day",
        "utc_ms",
        "last_hpc",
        "last_status",
        "health",
        "sgm_devices",
        "can_bus",
        "temperature_q",
        "uptime",
        "tc_rejected",
    )

    def __init__(self, **fields):
        for k in self.FIELDS:
            setattr(self, k, fields.get(k, 0))
        self.version = fields.get("version", 2)

    def pack(self):
        return struct.pack(self._FMT, *[getattr(self, k) for k in self.FIELDS])

    @classmethod
    def unpack(cls, buf):
        fmt = cls._FMT_V1 if buf[:1] == b"\x01" else cls._FMT
        n = struct.calcsize(fmt)
        if len(buf) < n:
            raise ValueError("HPTM report too short: %d bytes, needs %d" % (len(buf), n))
        values = struct.unpack(fmt, buf[:n])
        d = {}
        for i in range(len(values)):
            d[cls.FIELDS[i]] = values[i]
        return cls(**d)

    def to_dict(self):
        d = {}
        for k in self.FIELDS:
            d[k] = getattr(self, k)
        return d


def security_from_file(path, insecure=None, log=print):
    """The TcSecurity of the SDLS key file at ``path``. Secure by default: without a key file,
    or with one that cannot be read as one, a TcSecurity with no SA (every TC frame rejected,
    while the module keeps running: a boot that raised would reset it forever). Only when the
    file ``insecure`` exists (the mission's explicit choice, put there by ``obsw board
    deploy``) and there is no key file: None, TC frames unauthenticated. ``log`` gets one line
    at every boot that is not the normal, keyed one."""
    from obsw.frames.sdls import SdlsError, TcSecurity

    try:
        f = open(path)
    except OSError:
        if insecure is not None:
            try:
                open(insecure).close()
            except OSError:
                pass
            else:
                log("SDLS OFF (%s): essential TCs accepted without authentication" % insecure)
                return None
        log("SDLS: no key file %s: every essential TC is refused" % path)
        return TcSecurity(())
    from obsw.frames.sdls_keys import load_security

    try:
        with f:
            return load_security(f.read())
    except (SdlsError, OSError, ValueError):
        log("SDLS: %s is not a usable key file: every essential TC is refused" % path)
        return TcSecurity(())


class Essential:
    """HPCs in (``feed``), CPDU writes out (``take_writes``), HPTM CADUs out (``report``).

    ``in_charge()`` tells whether this controller executes TARGET_IN_CHARGE commands.
    """

    def __init__(
        self,
        scid,
        role=NOMINAL,
        in_charge=None,
        essential_map=ESSENTIAL_MAP,
        tc_vcids=(0,),
        hptm_vcid=HPTM_VCID,
        hptm_apid=HPTM_APID,
        tm_frame_length=64,
        obc_lines=(0, 1),
        tc_randomized=False,
        tm_randomize=True,
        security=None,
    ):
        self.role = role
        self.in_charge = in_charge or (lambda: role == NOMINAL)
        self.obc_lines = obc_lines
        self.hptm_vcid = hptm_vcid
        self.hptm_apid = hptm_apid
        self.tm_randomize = tm_randomize
        self.frames = FrameProcessor(
            scid,
            self._other,
            self._unit,
            essential_map=essential_map,
            tc_vcids=tc_vcids,
            tc_randomized=tc_randomized,
            security=security,
        )
        self.mux = TmMultiplexer(scid, tm_frame_length, [TmVirtualChannel(hptm_vcid, 1)])
        self.seq = SequenceCounter()
        self.counters = {"hpcs": 0, "rejected": 0, "not_mine": 0, "other_packets": 0}
        self.last_code = 0
        self.last_status = STATUS_NONE
        self.last_hpc = None
        self.report_requested = False
        self._writes = []  # [due time, mask, value]
        self._now = 0

    def _other(self, apid, packet):
        self.counters["other_packets"] += 1

    def feed(self, data, now):
        """Bytes from the COM UART."""
        self._now = now
        self.frames.receive(0, data, now)

    def _unit(self, unit):
        now = self._now
        try:
            hpc = hpc_of_unit(unit)
        except ValueError:
            self.counters["rejected"] += 1
            self.last_code = unit[6] if len(unit) > 6 else 0
            self.last_status = STATUS_REJECTED
            return
        self.execute(hpc, now)

    def _mine(self, target):
        if target == TARGET_BOTH:
            return True
        if target == TARGET_IN_CHARGE:
            return bool(self.in_charge())
        return (target == TARGET_NOMINAL) == (self.role == NOMINAL)

    def execute(self, hpc, now):
        """Run one HPC: queue its line changes, or note why not."""
        self.last_code = hpc.code
        self.last_hpc = hpc
        if not self._mine(hpc.target):
            self.counters["not_mine"] += 1
            self.last_status = STATUS_NOT_MINE
            return False
        self.counters["hpcs"] += 1
        self.last_status = STATUS_DONE
        c = hpc.code
        if c == HPC_LINES:
            self._writes.append([now, hpc.args[0] & CPDU_MASK, hpc.args[1]])
        elif c == HPC_POWER_CYCLE:
            line, off_ms = hpc.args
            if line >= 12:
                self.last_status = STATUS_REJECTED
                self.counters["rejected"] += 1
                return False
            bit = 1 << line
            self._writes.append([now, bit, 0])
            self._writes.append([now + off_ms / 1000, bit, bit])
        elif c == HPC_SELECT_OBC:
            which = hpc.args[0]
            if which > 1:
                self.last_status = STATUS_REJECTED
                self.counters["rejected"] += 1
                return False
            on = 1 << self.obc_lines[which]
            off = 1 << self.obc_lines[1 - which]
            self._writes.append([now, on | off, on])
        elif c == HPC_REPORT:
            self.report_requested = True
        elif c == HPC_CLEAR:
            self.counters["hpcs"] = 0
            self.counters["rejected"] = 0
            self.counters["not_mine"] = 0
        self.report_requested = True
        return True

    def next_deadline(self):
        best = None
        for w in self._writes:
            if best is None or w[0] < best:
                best = w[0]
        return best

    def take_writes(self, now):
        """The (mask, value) line changes due now, oldest first."""
        due = [w for w in self._writes if w[0] <= now]
        if due:
            self._writes = [w for w in self._writes if w[0] > now]
        return [(w[1], w[2]) for w in due]

    def failed(self):
        """The app could not get the CPDU for the last write."""
        self.last_status = STATUS_FAILED

    def later(self, due, mask, value):
        """Queue a line change for ``due`` (the second half of a power cycle)."""
        self._writes.append([due, mask & CPDU_MASK, value])

    def report(self, report):
        """CADUs carrying one HPTM packet with ``report`` (a Report) for the COM UART."""
        self.report_requested = False
        return self.packet(self.hptm_apid, report.pack())

    def packet(self, apid, data):
        """CADUs carrying one HPTM packet of ``apid`` with ``data`` on the HPTM channel."""
        pkt = SpacePacket(0, apid, data, False, 3, self.seq.next(apid))
        self.mux.channel(self.hptm_vcid).push(pkt.pack())
        out = []
        while True:
            f = self.mux.frame(True)
            if f is None:
                break
            out.append(cadu(f.pack(), self.tm_randomize))
        return out
