"""FOP-1, the sending end of COP-1 (CCSDS 232.1-B-2 section 5), for one virtual channel.

Sans-I/O: every input carries ``now`` (seconds, any epoch); outputs are collected and taken by
the caller: ``take_frames()`` (TC frames to send, in order), ``take_notifications()`` (responses,
confirms, alerts, suspends) and ``deadline`` (when to call ``tick``). The state machine is the
standard's state table, in ``obsw.frames.fop_table``.
"""

from obsw.compat import const
from obsw.frames.fop_table import TABLE
from obsw.frames.tc import UNLOCK, TcFrame, set_vr_command

ACTIVE = const(1)  # S1
RETRANSMIT_NO_WAIT = const(2)  # S2
RETRANSMIT_WITH_WAIT = const(3)  # S3
INITIALIZING_NO_BC = const(4)  # S4
INITIALIZING_WITH_BC = const(5)  # S5
INITIAL = const(6)  # S6
STATE_NAMES = (
    "",
    "Active",
    "Retransmit without Wait",
    "Retransmit with Wait",
    "Initializing without BC Frame",
    "Initializing with BC Frame",
    "Initial",
)

# Alert reason codes (table 4-4)
ALERT_LIMIT = const(1)
ALERT_T1 = const(2)
ALERT_LOCKOUT = const(3)
ALERT_SYNCH = const(4)
ALERT_NNR = const(5)
ALERT_CLCW = const(6)
ALERT_LLIF = const(7)
ALERT_TERM = const(8)
ALERT_NAMES = ("", "LIMIT", "T1", "LOCKOUT", "SYNCH", "NN(R)", "CLCW", "LLIF", "TERM")

# Notifications: (kind, request id, detail)
ACCEPT = const(1)  # request accepted (FDU or directive)
REJECT = const(2)
POSITIVE_CONFIRM = const(3)
NEGATIVE_CONFIRM = const(4)
ALERT = const(5)  # detail: alert code
SUSPEND = const(6)  # detail: suspend state
ABORT = const(7)  # lower procedures asked to drop frames queued but not yet sent
NOTIFICATION_NAMES = ("", "accept", "reject", "confirm", "negative", "alert", "suspend", "abort")

# Directives (table 4-1)
INITIATE_AD_NO_CLCW = const(1)
INITIATE_AD_WITH_CLCW = const(2)
INITIATE_AD_WITH_UNLOCK = const(3)
INITIATE_AD_WITH_SET_VR = const(4)
TERMINATE_AD = const(5)
RESUME_AD = const(6)
SET_VS = const(7)
SET_WINDOW = const(8)
SET_T1 = const(9)
SET_TRANSMISSION_LIMIT = const(10)
SET_TIMEOUT_TYPE = const(11)

_AD = const(0)
_BC = const(1)
_BD = const(2)


class _Sent:
    __slots__ = ("frame", "request", "retransmit")

    def __init__(self, frame, request):
        self.frame = frame
        self.request = request
        self.retransmit = False


class Fop1:
    """FOP-1 for the virtual channel ``vcid`` of spacecraft ``scid``.

    ``auto_accept`` models lower procedures that take every frame at once (the usual case: the
    CLTU goes straight to a serial port); with it off, call ``lower_response`` yourself.
    """

    def __init__(
        self,
        scid,
        vcid,
        window=10,
        t1=2.0,
        transmission_limit=3,
        timeout_type=0,
        auto_accept=True,
    ):
        self.scid = scid
        self.vcid = vcid
        self.window = window  # K
        self.t1 = t1
        self.transmission_limit = transmission_limit
        self.timeout_type = timeout_type
        self.auto_accept = auto_accept
        self.state = INITIAL
        self.vs = 0
        self.nnr = 0
        self.transmission_count = 0
        self.suspend_state = 0
        self.ad_out = True
        self.bc_out = True
        self.bd_out = True
        self.deadline = None
        self.now = 0
        self.last_event = 0
        self._sent = []  # AD frames N(S) = NN(R)... in order, or the one BC frame
        self._wait = None  # (request id, data)
        self._frames = []
        self._notes = []
        self._lower = []  # frame kinds handed to auto-accepting lower procedures
        self._next_id = 1
        self._request = None  # request id of the input being handled
        self._data = None
        self._qualifier = None
        self._pending_init = None  # id of an Initiate AD directive awaiting its confirm
        self._nr = 0

    # -- outputs --------------------------------------------------------------------------

    def take_frames(self):
        out = self._frames
        self._frames = []
        return out

    def take_notifications(self):
        out = self._notes
        self._notes = []
        return out

    @property
    def ready(self):
        """True when a Type-AD request would be queued rather than rejected (Wait_Queue empty)."""
        return self._wait is None and self.state in (
            ACTIVE,
            RETRANSMIT_NO_WAIT,
            RETRANSMIT_WITH_WAIT,
        )

    @property
    def outstanding(self):
        """Number of AD frames sent but not yet acknowledged."""
        return (self.vs - self.nnr) & 0xFF

    # -- inputs ---------------------------------------------------------------------------

    def _new_id(self):
        i = self._next_id
        self._next_id += 1
        return i

    def _time(self, now):
        if now is not None:
            self.now = now

    def send_ad(self, data, now=None):
        """Request to transfer an FDU with the AD service; returns the request id."""
        self._time(now)
        rid = self._new_id()
        self._request = rid
        self._data = bytes(data)
        self._run(19 if self._wait is None else 20)
        return rid

    def send_bd(self, data, now=None):
        """Request to transfer an FDU with the BD service (bypass); returns the request id."""
        self._time(now)
        rid = self._new_id()
        self._request = rid
        self._data = bytes(data)
        self._run(21 if self.bd_out else 22)
        return rid

    def directive(self, kind, qualifier=None, now=None):
        """Directive from the higher procedures (INITIATE_AD_*, TERMINATE_AD, SET_*...)."""
        self._time(now)
        rid = self._new_id()
        self._request = rid
        self._qualifier = qualifier
        if kind == INITIATE_AD_NO_CLCW:
            e = 23
        elif kind == INITIATE_AD_WITH_CLCW:
            e = 24
        elif kind == INITIATE_AD_WITH_UNLOCK:
            e = 25 if self.bc_out else 26
        elif kind == INITIATE_AD_WITH_SET_VR:
            e = 27 if self.bc_out and qualifier is not None and 0 <= qualifier < 256 else 28
        elif kind == TERMINATE_AD:
            e = 29
        elif kind == RESUME_AD:
            e = (30, 31, 32, 33, 34)[self.suspend_state]
        elif kind == SET_VS:
            ok = qualifier is not None and 0 <= qualifier < 256 and self.suspend_state == 0
            e = 35 if ok else 40
        elif kind == SET_WINDOW:
            e = 36 if qualifier is not None and 1 <= qualifier < 256 else 40
        elif kind == SET_T1:
            e = 37 if qualifier is not None and qualifier > 0 else 40
        elif kind == SET_TRANSMISSION_LIMIT:
            e = 38 if qualifier is not None and qualifier >= 1 else 40
        elif kind == SET_TIMEOUT_TYPE:
            e = 39 if qualifier in (0, 1) else 40
        else:
            e = 40
        self._run(e)
        return rid

    def on_clcw(self, clcw, now=None):
        """A CLCW arrived for this virtual channel (CLCWs of other channels are ignored)."""
        self._time(now)
        if clcw.vcid != self.vcid:
            return
        self._request = None
        if clcw.cop != 1 or clcw.version != 0:
            self._run(15)
            return
        nr = clcw.report
        self._nr = nr
        vs = self.vs
        nnr = self.nnr
        if clcw.lockout:
            e = 14
        elif nr == vs:
            if clcw.retransmit:
                e = 4
            elif clcw.wait:
                e = 3
            else:
                e = 1 if nr == nnr else 2
        elif (nr - nnr) & 0xFF < (vs - nnr) & 0xFF:
            if not clcw.retransmit:
                if clcw.wait:
                    e = 7
                else:
                    e = 5 if nr == nnr else 6
            elif self.transmission_limit == 1:
                e = 102 if nr == nnr else 101
            elif nr != nnr:
                e = 9 if clcw.wait else 8
            elif self.transmission_count < self.transmission_limit:
                e = 11 if clcw.wait else 10
            else:
                e = 103 if clcw.wait else 12
        else:
            e = 13
        self._run(e)

    def tick(self, now):
        """Advance time; fires the timer (events E16-E18, E104) once its deadline is passed."""
        self.now = now
        if self.deadline is None or now < self.deadline:
            return
        self.deadline = None
        self._request = None
        if self.transmission_count < self.transmission_limit:
            self._run(16 if self.timeout_type == 0 else 104)
        else:
            self._run(17 if self.timeout_type == 0 else 18)

    def lower_response(self, kind, accepted, now=None):
        """Lower procedures accepted or rejected a frame of ``kind`` (0 AD, 1 BC, 2 BD)."""
        self._time(now)
        self._request = None
        self._run((41, 43, 45)[kind] if accepted else (42, 44, 46)[kind])

    # -- the state machine ----------------------------------------------------------------

    def _run(self, event):
        self.last_event = event
        self._step(event)
        while self._lower:
            self._request = None
            self._step((41, 43, 45)[self._lower.pop(0)])

    def _step(self, event):
        row = TABLE[event]
        next_state, actions = row[self.state - 1]
        for action in actions:
            getattr(self, "_a_" + action)()
        if next_state:
            self.state = next_state

    def _note(self, kind, request, detail=None):
        self._notes.append((kind, request, detail))

    def _lower_send(self, kind, frame):
        self._frames.append(frame)
        if self.auto_accept:
            self._lower.append(kind)

    # -- actions (232.1-B-2 5.2) ----------------------------------------------------------

    def _a_accept(self):
        self._note(ACCEPT, self._request)

    def _a_reject(self):
        self._note(REJECT, self._request)

    def _a_confirm(self):
        # Confirms either the directive at hand or the Initiate AD waiting for its CLCW.
        rid = self._request if self._request is not None else self._pending_init
        if rid == self._pending_init:
            self._pending_init = None
        self._note(POSITIVE_CONFIRM, rid)

    def _a_pend(self):
        self._pending_init = self._request

    def _a_start_timer(self):
        self.deadline = self.now + self.t1

    def _a_cancel_timer(self):
        self.deadline = None

    def _purge_sent(self):
        for entry in self._sent:
            if entry.request is not None:
                self._note(NEGATIVE_CONFIRM, entry.request)
        self._sent = []

    def _purge_wait(self):
        if self._wait is not None:
            self._note(REJECT, self._wait[0])
            self._wait = None

    def _a_initialize(self):
        self._purge_sent()
        self._purge_wait()
        self.transmission_count = 1
        self.suspend_state = 0

    def _alert(self, code):
        self.deadline = None
        self._purge_sent()
        self._purge_wait()
        if self._pending_init is not None:
            self._note(NEGATIVE_CONFIRM, self._pending_init)
            self._pending_init = None
        self._note(ALERT, None, code)

    def _a_alert_limit(self):
        self._alert(ALERT_LIMIT)

    def _a_alert_t1(self):
        self._alert(ALERT_T1)

    def _a_alert_lockout(self):
        self._alert(ALERT_LOCKOUT)

    def _a_alert_synch(self):
        self._alert(ALERT_SYNCH)

    def _a_alert_nnr(self):
        self._alert(ALERT_NNR)

    def _a_alert_clcw(self):
        self._alert(ALERT_CLCW)

    def _a_alert_llif(self):
        self._alert(ALERT_LLIF)

    def _a_alert_term(self):
        self._alert(ALERT_TERM)

    def _a_suspend(self):
        self.suspend_state = self.state
        self._note(SUSPEND, None, self.state)

    def _a_resume(self):
        self._a_start_timer()
        self.suspend_state = 0

    def _a_remove_acked(self):
        n = (self._nr - self.nnr) & 0xFF
        for entry in self._sent[:n]:
            self._note(POSITIVE_CONFIRM, entry.request)
        self._sent = self._sent[n:]
        self.nnr = self._nr
        self.transmission_count = 1

    def _a_retransmit_ad(self):
        self._note(ABORT, None)
        self.transmission_count += 1
        self._a_start_timer()
        for entry in self._sent:
            entry.retransmit = True

    def _a_retransmit_bc(self):
        self.transmission_count += 1
        self._a_start_timer()
        for entry in self._sent:
            entry.retransmit = True

    def _a_look_for_directive(self):
        if self.bc_out and self._sent and self._sent[0].retransmit:
            entry = self._sent[0]
            entry.retransmit = False
            self.bc_out = False
            self._lower_send(_BC, entry.frame)

    def _a_look_for_fdu(self):
        if not self.ad_out:
            return
        for entry in self._sent:
            if entry.retransmit:
                entry.retransmit = False
                self.ad_out = False
                self._lower_send(_AD, entry.frame)
                return
        if self._wait is not None and (self.vs - self.nnr) & 0xFF < self.window:
            rid, data = self._wait
            self._wait = None
            self._note(ACCEPT, rid)
            frame = TcFrame(self.scid, self.vcid, data, self.vs)
            self.vs = (self.vs + 1) & 0xFF
            if not self._sent:
                self.transmission_count = 1
            self._sent.append(_Sent(frame, rid))
            self._a_start_timer()
            self.ad_out = False
            self._lower_send(_AD, frame)

    def _a_add_to_wait(self):
        self._wait = (self._request, self._data)

    def _a_accept_bd(self):
        self._note(ACCEPT, self._request)
        self.bd_out = False
        self._lower_send(_BD, TcFrame(self.scid, self.vcid, self._data, 0, True))

    def _transmit_bc(self, data):
        frame = TcFrame(self.scid, self.vcid, data, 0, True, True)
        self._sent = [_Sent(frame, None)]
        self.transmission_count = 1
        self._a_start_timer()
        self.bc_out = False
        self._lower_send(_BC, frame)

    def _a_transmit_unlock(self):
        self._transmit_bc(UNLOCK)

    def _a_transmit_set_vr(self):
        self._transmit_bc(set_vr_command(self._qualifier))

    def _a_release_bc(self):
        self._sent = []

    def _a_set_vs(self):
        self.vs = self.nnr = self._qualifier

    def _a_set_window(self):
        self.window = self._qualifier

    def _a_set_t1(self):
        self.t1 = self._qualifier

    def _a_set_limit(self):
        self.transmission_limit = self._qualifier

    def _a_set_timeout_type(self):
        self.timeout_type = self._qualifier

    def _a_ad_ready(self):
        self.ad_out = True

    def _a_bc_ready(self):
        self.bc_out = True

    def _a_bd_ready(self):
        self.bd_out = True

    def __repr__(self):
        return "Fop1(vc=%d %s V(S)=%d NN(R)=%d)" % (
            self.vcid,
            STATE_NAMES[self.state],
            self.vs,
            self.nnr,
        )
