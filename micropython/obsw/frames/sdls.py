"""TC frame security after CCSDS SDLS (355.0-B-2), authentication service, HMAC-SHA-256.

A secured TC frame: primary header (5) | segment header (1, if the VC has them) | security
header: SPI (2), IV (none), sequence number (``sn_length``), pad length (none) | frame data |
security trailer: MAC (``mac_length``, HMAC-SHA-256 truncated) | FECF (2). The frame length
field covers them all and the FECF is computed over the whole frame. The MAC covers the
primary header (authentication mask: the frame sequence number N(S) is zeroed, because FOP-1
sets it after ApplySecurity, TC SDLP 4.3.3), the segment header, the security header and the
frame data. Control command (Type-BC) frames carry no security header and trailer (232.0-B
6.3.1).

Security associations (SAs) belong to a virtual channel, or to one MAP of it: a MAP-specific SA
is the only one valid for its MAP. ``TcSecurity.apply`` builds the secured data field on the
sending end; ``process`` verifies a received frame before FARM-1 and returns the standard's
outcome (bad SPI, SA not operational, invalid MAC, anti-replay sequence number failure, or a
frame too short for its SA); ``commit`` records the sequence number once FARM-1 accepted the
frame, so that a frame FARM-1 discarded can come again by FOP-1 retransmission while a frame
it accepted can never be replayed.
"""

from obsw.compat import const
from obsw.frames.errors import FrameError
from obsw.frames.sdls_mac import DIGEST_LENGTH, HmacSha256, equal

# SA states (355.0-B-2 figure 4-1, with an end state once the key is erased)
SA_UNKEYED = const(0)
SA_KEYED = const(1)
SA_OPERATIONAL = const(2)
SA_EXPIRED = const(3)
SA_STATE_NAMES = ("unkeyed", "keyed", "operational", "expired")

# Frame verification outcomes (ProcessSecurity); 0 is success
OK = const(0)
BAD_SPI = const(1)
NOT_OPERATIONAL = const(2)
BAD_MAC = const(3)
REPLAY = const(4)
TOO_SHORT = const(5)
OUTCOME_NAMES = ("ok", "bad_spi", "sa_not_operational", "bad_mac", "replay", "too_short")

# The PUS event ID raised for each rejection (the spacecraft database names them frames.tc_*)
EVENT_IDS = (0, 0xFF31, 0xFF32, 0xFF33, 0xFF34, 0xFF35)

SPI_MIN = const(1)  # SPI 0 and 0xFFFF are reserved (355.0-B-2 4.1.1.2)
SPI_MAX = const(0xFFFE)
MAC_MIN = const(8)
MAX_WINDOW = const(1024)


class SdlsError(FrameError):
    """An SA or security configuration the standard or this implementation rules out, or a
    sending request no operational SA can serve."""


class ReplayWindow:
    """Anti-replay sequence numbers of one SA: the highest accepted (``top``) and which of the
    ``size`` numbers below it were seen. A number is acceptable when it was not seen, is above
    ``top - size`` and, with ``ahead``, at most ``ahead`` above ``top`` (the SDLS sequence
    number window: set it to refuse jumps; without it, any authentic number above ``top`` is
    taken, so frames lost on the way, however many, never lock the channel out).

    Before anything was accepted or restored (``top`` 0) any number from 1 is: a receiver that
    restarts without its saved state takes up the sender's numbers instead of locking the
    channel out, at the price of accepting, once, frames sent before the restart. Keeping the
    state (``TcSecurity.context``) closes that gap."""

    __slots__ = ("size", "ahead", "top", "_seen")

    def __init__(self, size=64, ahead=None, top=0):
        if not 1 <= size <= MAX_WINDOW:
            raise SdlsError("anti-replay window %d outside 1..%d" % (size, MAX_WINDOW))
        if ahead is not None and ahead < 1:
            raise SdlsError("sequence number window ahead %d below 1" % ahead)
        self.size = size
        self.ahead = ahead
        self.top = top
        self._seen = 1  # bit i: top - i was accepted (top itself counts as seen)

    def acceptable(self, sn):
        top = self.top
        if sn > top:
            return top == 0 or self.ahead is None or sn - top <= self.ahead
        back = top - sn
        return back < self.size and not (self._seen >> back) & 1

    def commit(self, sn):
        """Record ``sn`` as accepted (call only after ``acceptable(sn)``)."""
        top = self.top
        if sn > top:
            shift = sn - top
            if shift >= self.size:
                self._seen = 1
            else:
                self._seen = ((self._seen << shift) | 1) & ((1 << self.size) - 1)
            self.top = sn
        else:
            self._seen |= 1 << (top - sn)


class SecurityAssociation:
    """One SA: SPI, the channel it secures (VC, optionally one MAP), key, lengths, state, and
    the sequence numbers of both ends (``sn_sent`` sending, ``window`` receiving; ``window`` and
    ``ahead`` as in ReplayWindow)."""

    algorithm = "hmac-sha256"
    link = "tc"  # or "tm" (GCM SAs of TM virtual channels)

    def __init__(
        self,
        spi,
        vcid,
        key=None,
        map_id=None,
        mac_length=16,
        sn_length=4,
        window=64,
        state=None,
        ahead=None,
    ):
        if not SPI_MIN <= spi <= SPI_MAX:
            raise SdlsError("SPI %r outside %d..%d" % (spi, SPI_MIN, SPI_MAX))
        if not 0 <= vcid < 64 or (map_id is not None and not 0 <= map_id < 64):
            raise SdlsError("SA %d: VC ID or MAP ID outside 0..63" % spi)
        if not MAC_MIN <= mac_length <= DIGEST_LENGTH:
            raise SdlsError(
                "SA %d: MAC length %d outside %d..%d" % (spi, mac_length, MAC_MIN, DIGEST_LENGTH)
            )
        if not 1 <= sn_length <= 8:
            raise SdlsError("SA %d: sequence number length %d outside 1..8" % (spi, sn_length))
        self.spi = spi
        self.vcid = vcid
        self.map_id = map_id
        self.mac_length = mac_length
        self.sn_length = sn_length
        self.sn_max = (1 << (8 * sn_length)) - 1
        self.window = ReplayWindow(window, ahead)
        self.sn_sent = 0
        self.sn_reserved = 0
        self.reserve_block = 0  # 0: numbers are saved by the caller, not reserved in blocks
        self._mac = None
        self.key = None
        self.state = SA_UNKEYED
        if key is not None:
            self.set_key(key)
            self.state = SA_OPERATIONAL if state is None else state
        elif state not in (None, SA_UNKEYED, SA_EXPIRED):
            raise SdlsError("SA %d: state %s needs a key" % (spi, SA_STATE_NAMES[state]))
        elif state is not None:
            self.state = state

    @property
    def header_length(self):
        return 2 + self.sn_length

    def set_key(self, key):
        """Key the SA (unkeyed or keyed -> keyed)."""
        key = bytes(key)
        if len(key) < 16:
            raise SdlsError("SA %d: key of %d octets, needs at least 16" % (self.spi, len(key)))
        if self.state not in (SA_UNKEYED, SA_KEYED):
            raise SdlsError("SA %d is %s" % (self.spi, SA_STATE_NAMES[self.state]))
        self.key = key
        self._mac = HmacSha256(key)
        self.state = SA_KEYED

    def start(self):
        """Keyed -> operational."""
        if self.state != SA_KEYED:
            raise SdlsError("SA %d is %s, not keyed" % (self.spi, SA_STATE_NAMES[self.state]))
        self.state = SA_OPERATIONAL

    def stop(self):
        """Operational -> keyed."""
        if self.state == SA_OPERATIONAL:
            self.state = SA_KEYED

    def expire(self):
        """Erase the key for good: no frame can be sent or accepted with this SA again."""
        self.key = None
        self._mac = None
        self.state = SA_EXPIRED

    def mac(self, *parts):
        return self._mac.digest(*parts)[: self.mac_length]

    @property
    def trailer_length(self):
        return self.mac_length

    def next_sn(self, security):
        """The sequence number of the next frame this SA sends (reserving a block first when
        the SA keeps its numbers in blocks)."""
        if self.sn_sent >= self.sn_max:
            raise SdlsError("SA %d: sequence numbers exhausted, re-key it" % self.spi)
        if self.reserve_block and self.sn_sent + 1 > self.sn_reserved:
            security.reserve(self)
        self.sn_sent += 1
        return self.sn_sent

    def seal(self, security, header, head, body):
        """Security header, frame data and trailer of a TC frame with primary header
        ``header`` (N(S) zero) and segment header ``head`` (b"" without)."""
        sec_header = _be(self.spi, 2) + _be(self.next_sn(security), self.sn_length)
        return sec_header + body + self.mac(header, head, sec_header, body)

    def open(self, raw, n, lead):
        """(sequence number, clear frame data) of the received TC frame ``raw[:n]`` (FECF
        included) that names this SA; None when its MAC fails, False when it is too short."""
        start = 5 + lead + 2
        body = start + self.sn_length
        trailer = n - 2 - self.mac_length
        if trailer < body:
            return False
        view = memoryview(raw)
        header = bytes(view[0:4]) + b"\x00"
        if not equal(self.mac(header, view[5:trailer]), view[trailer : n - 2]):
            return None
        return _int(view[start:body]), bytes(view[body:trailer])

    def __repr__(self):
        return "SecurityAssociation(spi=%d vc=%d map=%s %s)" % (
            self.spi,
            self.vcid,
            "any" if self.map_id is None else self.map_id,
            SA_STATE_NAMES[self.state],
        )


def _be(value, n):
    out = bytearray(n)
    for i in range(n - 1, -1, -1):
        out[i] = value & 0xFF
        value >>= 8
    return bytes(out)


def _int(buf):
    v = 0
    for b in buf:
        v = (v << 8) | b
    return v


class TcSecurity:
    """The SA database of a TC receiver or sender, and SDLS Apply/ProcessSecurity on TC frames.

    ``counters`` counts the verification outcomes by name. Every frame but a control command is
    secured: sending on a channel (VC, MAP) with no operational SA is refused, and a received
    frame no SA can verify is rejected as a bad SPI.
    """

    def __init__(self, sas=(), segment_header=True):
        self.segment_header = segment_header
        self.on_reserve = None  # called when an SA reserves a block of sequence numbers
        self.sas = {}  # SPI -> SA
        self.counters = {}
        for name in OUTCOME_NAMES:
            self.counters[name] = 0
        for sa in sas:
            self.add(sa)

    def add(self, sa):
        if sa.spi in self.sas:
            raise SdlsError("SPI %d given twice" % sa.spi)
        self.sas[sa.spi] = sa
        return sa

    def _valid_for(self, sa, vcid, map_id):
        """True when ``sa`` may secure frames of (vcid, map_id): a MAP-specific SA of that MAP,
        or a VC-wide one when the MAP has none of its own."""
        if sa.vcid != vcid:
            return False
        if sa.map_id is not None:
            return sa.map_id == map_id
        for other in self.sas.values():
            if other.vcid == vcid and other.map_id is not None and other.map_id == map_id:
                return False
        return True

    def sa_for(self, vcid, map_id=None):
        """The operational SA that secures (vcid, map_id) when sending (the lowest SPI);
        SdlsError when there is none."""
        for spi in sorted(self.sas):
            sa = self.sas[spi]
            if self._valid_for(sa, vcid, map_id) and sa.state == SA_OPERATIONAL:
                return sa
        raise SdlsError("no operational SA for VC %d MAP %s" % (vcid, map_id))

    # -- sending end --------------------------------------------------------------------------

    def apply(self, scid, vcid, data, bypass=False, sa=None):
        """ApplySecurity: the frame data field ``data`` (segment header first, when the VC has
        them) with the security header and trailer of the channel's SA (or of ``sa``). The
        frame is then made with ``TcFrame(scid, vcid, result, N(S), bypass)``, with FECF."""
        map_id = None
        if self.segment_header:
            if len(data) < 1:
                raise SdlsError("TC frame data without a segment header")
            map_id = data[0] & 0x3F
        if sa is None:
            sa = self.sa_for(vcid, map_id)
        elif sa.state != SA_OPERATIONAL or not self._valid_for(sa, vcid, map_id):
            raise SdlsError("SA %d cannot secure VC %d MAP %s" % (sa.spi, vcid, map_id))
        lead = 1 if self.segment_header else 0
        n = 5 + len(data) + sa.header_length + sa.trailer_length + 2
        if n > 1024:
            raise SdlsError("secured TC frame of %d octets, above 1024" % n)
        header = bytes(
            (
                (0x20 if bypass else 0) | (scid >> 8),
                scid & 0xFF,
                (vcid << 2) | ((n - 1) >> 8),
                (n - 1) & 0xFF,
                0,
            )
        )
        head = bytes(data[:lead])
        return head + sa.seal(self, header, head, bytes(data[lead:]))

    def reserve(self, sa):
        """Called before ``sa`` sends with a number at or above what was reserved: reserve the
        next block (``sa.reserve_block`` numbers) and save the state first (``on_reserve``),
        so that no number is ever sent twice, whenever the power goes."""
        sa.sn_reserved = sa.sn_sent + sa.reserve_block
        if self.on_reserve is not None:
            self.on_reserve()

    # -- receiving end ------------------------------------------------------------------------

    def _reject(self, outcome):
        self.counters[OUTCOME_NAMES[outcome]] += 1
        return outcome

    def process(self, raw, n):
        """ProcessSecurity on a received frame of ``n`` octets at ``raw[0]`` (FECF included and
        already checked). Returns (outcome, SA or None, sequence number, data field without the
        security header and trailer, or None)."""
        lead = 1 if self.segment_header else 0
        vcid = raw[2] >> 2
        fixed = 5 + lead + 2 + 2  # header, segment header, SPI, FECF
        if n < fixed:
            return self._reject(TOO_SHORT), None, 0, None
        map_id = raw[5] & 0x3F if lead else None
        spi = (raw[5 + lead] << 8) | raw[6 + lead]
        sa = self.sas.get(spi)
        if sa is None or not self._valid_for(sa, vcid, map_id):
            return self._reject(BAD_SPI), None, 0, None
        if sa.state != SA_OPERATIONAL:
            return self._reject(NOT_OPERATIONAL), sa, 0, None
        got = sa.open(raw, n, lead)
        if got is None:
            return self._reject(BAD_MAC), sa, 0, None
        if got is False:
            return self._reject(TOO_SHORT), sa, 0, None
        sn, clear = got
        if not sa.window.acceptable(sn):
            return self._reject(REPLAY), sa, sn, None
        self.counters["ok"] += 1
        return OK, sa, sn, bytes(raw[5 : 5 + lead]) + clear

    def commit(self, sa, sn):
        """The frame secured by ``sa`` with ``sn`` was accepted (by FARM-1): never again."""
        if sa.window.acceptable(sn):
            sa.window.commit(sn)

    # -- state across restarts ----------------------------------------------------------------

    def context(self):
        """What must survive a restart: per SPI, the last sequence number sent and the highest
        one accepted (a list of [spi, sent, top])."""
        out = []
        for spi in sorted(self.sas):
            sa = self.sas[spi]
            out.append([spi, max(sa.sn_sent, sa.sn_reserved), sa.window.top])
        return out

    def restore(self, ctx):
        """Take back what ``context`` gave; numbers never go down. Accepting resumes above the
        highest number accepted before (the window's history is not kept)."""
        for entry in ctx:
            sa = self.sas.get(entry[0])
            if sa is None:
                continue
            sa.sn_sent = max(sa.sn_sent, int(entry[1]))
            sa.sn_reserved = sa.sn_sent  # the next frame reserves a new block first
            top = int(entry[2])
            if top > sa.window.top:
                sa.window.top = top
                sa.window._seen = (1 << sa.window.size) - 1  # nothing at or below top again
