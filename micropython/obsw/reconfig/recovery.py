"""Autonomous recovery of the OBC: heartbeat deadline, power cycle, switch-over to the other OBC.

Sans-I/O policy, one per controller. Heartbeats come from SpaceCAN and from the UART link
(either keeps the OBC alive). When both have been silent past ``deadline`` seconds the policy
decides to power-cycle the active OBC's CPDU line; when ``max_failures`` recoveries already
happened within ``window`` seconds it decides to switch to the other OBC instead. After a
decision the OBC gets ``off_ms`` plus ``boot_grace`` seconds to send its first heartbeat.

The OBC is "active" on the line that is on in the latched CPDU state; with no OBC line on the
ground has switched the OBC off on purpose and the policy waits. A line change the policy did
not make (the other controller's recovery, a ground command) restarts the wait for a
heartbeat and counts in the window (a power cycle) or empties it (a switch-over), so two
controllers watching one OBC do not act twice in a row and agree on when to switch over; two
decisions at the
same instant are kept apart by the CPDU's Dekker arbitration with a compare step
(`Cpdu.write(..., expect=...)`): the second finds the line already changed and stands down.
"""

import struct

from obsw.compat import const

POWER_CYCLE = const(1)
SWITCH_OVER = const(2)
STOOD_DOWN = const(3)  # the other controller made the same change first
FAILED = const(4)  # the CPDU could not be written
KIND_NAMES = ("", "power_cycle", "switch_over", "stood_down", "failed")

SOURCE_CAN = const(0)
SOURCE_UART = const(1)

DEFAULTS = {
    "enabled": True,
    "deadline": 10.0,  # s of silence on CAN and UART before the OBC counts as hung or dead
    "boot_grace": 30.0,  # s an OBC may take from power on to its first heartbeat
    "off_ms": 1000,  # ms a power cycle keeps the line off
    "max_failures": 3,  # recoveries within the window before switching to the other OBC
    "window": 900.0,  # s
    "lines": (0, 1),  # CPDU lines of the nominal and the redundant OBC
}


class Decision:
    """One decision: what, on which line, why (silence in ms, recoveries in the window)."""

    _FMT = ">BBBBHII"
    SIZE = const(14)

    def __init__(self, kind, line, obc, failures, count, silence_ms, at_s):
        self.kind = kind
        self.line = line
        self.obc = obc  # the OBC (0 nominal, 1 redundant) active after the decision
        self.failures = failures
        self.count = count  # decisions made by this controller so far (modulo 2**16)
        self.silence_ms = silence_ms
        self.at_s = at_s  # controller uptime in seconds

    def pack(self):
        return struct.pack(
            self._FMT,
            self.kind,
            self.line,
            self.obc,
            self.failures & 0xFF,
            self.count & 0xFFFF,
            self.silence_ms & 0xFFFFFFFF,
            self.at_s & 0xFFFFFFFF,
        )

    @classmethod
    def unpack(cls, buf):
        if len(buf) < cls.SIZE:
            raise ValueError("decision record too short: %d bytes, needs %d" % (len(buf), 14))
        return cls(*struct.unpack(cls._FMT, buf[: cls.SIZE]))

    def __repr__(self):
        return "Decision(%s line %d, obc %d, %d in window, silent %d ms)" % (
            KIND_NAMES[self.kind],
            self.line,
            self.obc,
            self.failures,
            self.silence_ms,
        )


class Recovery:
    """The policy; times in seconds. ``poll(now, bits)`` returns a planned action or None:
    ``(kind, mask, value, expect_mask, expect_value, line)`` for the CPDU, then ``done()``."""

    def __init__(self, settings=None):
        s = dict(DEFAULTS)
        if settings:
            s.update(settings)
        self.enabled = bool(s["enabled"])
        self.deadline = float(s["deadline"])
        self.boot_grace = float(s["boot_grace"])
        self.off_ms = int(s["off_ms"])
        self.max_failures = int(s["max_failures"])
        self.window = float(s["window"])
        self.lines = tuple(s["lines"])
        self.last_seen = [None, None]  # per source
        self.failures = []  # times of recent recoveries
        self.count = 0
        self.active = 0
        self._due = None  # when silence becomes a fault
        self._bits = None  # the OBC lines as last seen
        self._pending = None
        self._since = 0  # the last start or change of the OBC lines

    def start(self, now):
        """At the controller's boot: the OBC may be booting too."""
        self._due = now + self.boot_grace
        self._since = now

    def heartbeat(self, source, now):
        """A heartbeat sent at ``now``: the boot grace, if any, is over. One older than the
        last start or line change (a bus's stale record) moves nothing."""
        if self.last_seen[source] is None or now > self.last_seen[source]:
            self.last_seen[source] = now
        if now >= self._since:
            self._due = now + self.deadline

    def silence(self, now):
        """Seconds since the last heartbeat from any source (None: never heard)."""
        best = None
        for t in self.last_seen:
            if t is not None and (best is None or t > best):
                best = t
        return None if best is None else now - best

    def _obc_bits(self, bits):
        m = 0
        for i in (0, 1):
            if bits >> self.lines[i] & 1:
                m |= 1 << i
        return m

    def observe(self, bits, now):
        """The latched CPDU state; a change of the OBC lines restarts the wait."""
        if bits is None:
            return
        obc = self._obc_bits(bits)
        was = self._bits
        if was is not None and obc != was:
            self._due = now + self.off_ms / 1000 + self.boot_grace
            self._since = now
            if self._pending is None:  # not our own action: the other controller's, the ground's
                if was and obc and not obc & was:
                    self.failures = []  # a switch-over
                elif was >> self.active & 1 and not obc >> self.active & 1:
                    self.failures.append(now)  # the active OBC's line off: a power cycle
        self._bits = obc
        if obc == 1 or obc == 3:
            self.active = 0
        elif obc == 2:
            self.active = 1

    def next_deadline(self):
        """When ``poll`` may next act (None: not before something else happens)."""
        if not self.enabled or self._pending is not None:
            return None
        return self._due

    def poll(self, now, bits):
        """The action due now, or None. ``bits``: the latched CPDU state (None: unknown)."""
        self.observe(bits, now)
        if not self.enabled or self._pending is not None or self._due is None:
            return None
        if now < self._due:
            return None
        if self._bits == 0:  # the OBC is off: the ground's choice
            self._due = now + self.deadline
            return None
        self.failures = [t for t in self.failures if now - t < self.window]
        line = self.lines[self.active]
        bit = 1 << line
        if len(self.failures) >= self.max_failures:
            other = 1 << self.lines[1 - self.active]
            act = (SWITCH_OVER, bit | other, other, bit | other, bit & ~other, line)
        else:
            act = (POWER_CYCLE, bit, 0, bit, bit, line)
        self._pending = (act, now)
        return act

    def done(self, now, result, uptime_s=0):
        """The CPDU result of the pending action: True latched, None stood down, False failed.
        Returns the Decision to report."""
        act, t = self._pending
        self._pending = None
        kind, line = act[0], act[5]
        silence = self.silence(now)
        silence_ms = int((silence if silence is not None else now - t) * 1000)
        if result is None:
            kind = STOOD_DOWN
        elif not result:
            kind = FAILED
        if result is not False:
            if act[0] == SWITCH_OVER:  # made here or by the other controller: a new window
                self.failures = []
                self.active = 1 - self.lines.index(line)
            else:
                self.failures.append(now)
        wait = self.deadline if kind == FAILED else self.off_ms / 1000 + self.boot_grace
        self._due = now + wait
        self.count += 1
        return Decision(
            kind,
            line,
            self.active,
            len(self.failures),
            self.count,
            silence_ms,
            int(uptime_s),
        )


def log_pack(entries):
    """The safeguard log record: the newest decisions, oldest first."""
    return b"".join(d.pack() for d in entries)


def log_unpack(rec):
    out = []
    for i in range(0, len(rec) - Decision.SIZE + 1, Decision.SIZE):
        out.append(Decision.unpack(rec[i : i + Decision.SIZE]))
    return out
