"""FARM-1, the receiving end of COP-1 (CCSDS 232.1-B-2 section 6), for one virtual channel."""

from collections import deque

from obsw.compat import const
from obsw.frames.clcw import Clcw
from obsw.frames.errors import ControlCommandError
from obsw.frames.tc import CMD_UNLOCK, TYPE_AD, TYPE_BC, TYPE_BD, parse_control_command

OPEN = const(1)  # S1
WAIT = const(2)  # S2
LOCKOUT = const(3)  # S3
STATE_NAMES = ("", "Open", "Wait", "Lockout")

BD_ROOM = const(64)  # buffer places for BD frames beyond the AD frames' buffer_size
ACCEPT = const(1)
DISCARD = const(2)


class Farm1:
    """Frame acceptance and reporting for one virtual channel.

    ``on_frame(frame)`` runs the FARM-1 state table on a valid TC frame and returns ACCEPT or
    DISCARD; accepted frames wait in ``buffer`` until the higher procedures ``take()`` them
    (which is the buffer release signal). ``clcw()`` reports the state. ``last_event`` holds the
    state table event (1..10) of the last input, for tests and telemetry.
    """

    def __init__(self, vcid, window=10, positive=None, negative=None, buffer_size=16, status=0):
        if positive is None:
            if window % 2 or not 2 <= window <= 254:
                raise ValueError("FARM window W must be even and 2..254, got %d" % window)
            positive = negative = window // 2
        elif negative is None or not 1 <= positive <= window or negative < 0:
            raise ValueError("FARM windows need 1 <= PW <= W and NW >= 0")
        self.vcid = vcid
        self.window = window
        self.positive = positive
        self.negative = negative
        self.buffer_size = buffer_size
        self.status = status
        self.no_rf = False
        self.no_bitlock = False
        self._capacity = buffer_size + BD_ROOM
        self.buffer = deque((), self._capacity)
        self._held = 0  # AD frames in the buffer (BD frames do not count towards Wait)
        self.bd_dropped = 0  # BD frames discarded because the buffer was full
        self.reset()

    def reset(self):
        """FARM-1 initialization: V(R) 0, all flags clear, Open state, buffer emptied."""
        self.state = OPEN
        self.vr = 0
        self.lockout = False
        self.wait = False
        self.retransmit = False
        self.farm_b = 0
        self.last_event = 0
        while self.buffer:
            self.buffer.popleft()
        self._held = 0

    def _buffer_available(self):
        return self._held < self.buffer_size

    def on_frame(self, frame):
        """Apply the state table to a frame that passed frame validation."""
        kind = frame.frame_type
        if kind == TYPE_BD:
            return self._event(6, frame)
        if kind == TYPE_BC:
            try:
                cmd, value = parse_control_command(frame.data)
            except ControlCommandError:
                return self._event(9, frame)
            if cmd == CMD_UNLOCK:
                return self._event(7, frame)
            return self._event(8, frame, value)
        if kind != TYPE_AD:
            return self._event(9, frame)
        ns = frame.seq
        if ns == self.vr:
            return self._event(1 if self._buffer_available() else 2, frame)
        ahead = (ns - self.vr) & 0xFF
        behind = (self.vr - ns) & 0xFF
        if ahead < self.positive:
            return self._event(3, frame)
        if behind <= self.negative:
            return self._event(4, frame)
        return self._event(5, frame)

    def _event(self, e, frame=None, value=None):
        self.last_event = e
        s = self.state
        if e == 1:
            if s == OPEN:
                self._accept(frame)
                self.vr = (self.vr + 1) & 0xFF
                self.retransmit = False
                return ACCEPT
            return DISCARD
        if e == 2:
            if s == OPEN:
                self.retransmit = True
                self.wait = True
                self.state = WAIT
            return DISCARD
        if e == 3:
            if s == OPEN:
                self.retransmit = True
            return DISCARD
        if e == 4:
            return DISCARD
        if e == 5:
            if s != LOCKOUT:
                self.lockout = True
                self.state = LOCKOUT
            return DISCARD
        if e == 6:
            # BD frames bypass Wait, but the buffer is finite: a BD frame that finds it full is
            # discarded and counted (never an older frame pushed out, which would lose an
            # accepted AD frame and leave the AD count wrong; MicroPython's deque would raise)
            if len(self.buffer) >= self._capacity:
                self.bd_dropped += 1
                return DISCARD
            self._accept(frame)
            self.farm_b = (self.farm_b + 1) & 0xFF
            return ACCEPT
        if e == 7:
            self.farm_b = (self.farm_b + 1) & 0xFF
            self.retransmit = False
            self.wait = False
            self.lockout = False
            self.state = OPEN
            return ACCEPT
        if e == 8:
            self.farm_b = (self.farm_b + 1) & 0xFF
            if s != LOCKOUT:
                self.retransmit = False
                self.wait = False
                self.vr = value
                self.state = OPEN
            return ACCEPT
        if e == 9:
            return DISCARD
        if e == 10:
            if s == WAIT:
                self.wait = False
                self.state = OPEN
            elif s == LOCKOUT:
                self.wait = False
        return None

    def _accept(self, frame):
        self.buffer.append(frame)
        if frame.frame_type == TYPE_AD:
            self._held += 1

    def take(self):
        """Hand the oldest accepted frame to the higher procedures (or None); releases buffer."""
        if not self.buffer:
            return None
        frame = self.buffer.popleft()
        if frame.frame_type == TYPE_AD:
            self._held -= 1
        if self.wait and self._buffer_available():
            self._event(10)
        return frame

    def clcw(self):
        """The CLCW reporting this FARM's state (only the 2 low bits of FARM-B go in it)."""
        return Clcw(
            vcid=self.vcid,
            report=self.vr,
            lockout=self.lockout,
            wait=self.wait,
            retransmit=self.retransmit,
            farm_b=self.farm_b & 3,
            status=self.status,
            no_rf=self.no_rf,
            no_bitlock=self.no_bitlock,
        )

    def __repr__(self):
        return "Farm1(vc=%d %s V(R)=%d)" % (self.vcid, STATE_NAMES[self.state], self.vr)
