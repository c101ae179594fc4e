"""SDLS with AES-256-GCM (CCSDS 355.0-B-2, baseline of 352.0): TC and TM frames, as Yamcs has it.

Security header: SPI (2) | IV (12), no sequence number field and no pad length: the IV is the
anti-replay sequence number (a 96-bit counter, ARSN = IV). Security trailer: the GCM tag
(``mac_length``, 16 by default). Authenticated encryption ("aes-gcm") encrypts the frame data
field between them; authentication only ("aes-gmac") leaves it clear and authenticates it with
the headers. The additional authenticated data is the frame up to the frame data under the
authentication mask of ``org.yamcs.security.sdls.StandardAuthMask``: TC: VC ID, segment header
and SPI; TM: VC ID and SPI (every other header bit zeroed, the IV too, as GCM takes it itself).

IV policy: an SA sends IVs from a counter that only goes up and that it reserves in blocks of
``reserve_block``: before the first IV of a new block is used, the end of the block is saved
(``on_reserve`` of the TcSecurity or TmSecurity, e.g. ``StateFile.save``), and after a restart
counting resumes above the saved mark. An IV is thus never used twice under one key, whenever
the power goes; at worst a block's unused numbers are skipped. At 2**96 the SA refuses to send:
re-key it.
"""

from obsw.compat import const
from obsw.frames.gcm import AesGcm, GcmAuthError
from obsw.frames.sdls import (
    BAD_MAC,
    BAD_SPI,
    NOT_OPERATIONAL,
    OK,
    OUTCOME_NAMES,
    REPLAY,
    SA_KEYED,
    SA_OPERATIONAL,
    SA_STATE_NAMES,
    SA_UNKEYED,
    TOO_SHORT,
    SdlsError,
    SecurityAssociation,
)

GCM = "aes-gcm"
GMAC = "aes-gmac"
IV_LENGTH = const(12)
KEY_LENGTH = const(32)
RESERVE_BLOCK = const(64)


def _be(value, n):
    return value.to_bytes(n, "big")


class GcmSecurityAssociation(SecurityAssociation):
    """An AES-256-GCM SA (``algorithm`` GCM: authenticated encryption, or GMAC:
    authentication only) on a TC VC (optionally one MAP) or a TM VC."""

    def __init__(
        self,
        spi,
        vcid,
        key=None,
        map_id=None,
        mac_length=16,
        window=64,
        state=None,
        ahead=None,
        algorithm=GCM,
        reserve_block=RESERVE_BLOCK,
    ):
        if algorithm not in (GCM, GMAC):
            raise SdlsError("SA %d: algorithm %r, expected %s or %s" % (spi, algorithm, GCM, GMAC))
        if not 8 <= mac_length <= 16:
            raise SdlsError("SA %d: GCM tag length %d outside 8..16" % (spi, mac_length))
        if reserve_block < 1:
            raise SdlsError("SA %d: IV reserve block %d below 1" % (spi, reserve_block))
        self.algorithm = algorithm
        self._gcm = None
        SecurityAssociation.__init__(
            self, spi, vcid, key, map_id, mac_length, 8, window, state, ahead
        )
        self.sn_length = IV_LENGTH
        self.sn_max = (1 << (8 * IV_LENGTH)) - 1
        self.reserve_block = reserve_block
        self.window._seen = 0  # the first IV may be 0 (Yamcs starts its counter there)

    def set_key(self, key):
        key = bytes(key)
        if len(key) != KEY_LENGTH:
            raise SdlsError("SA %d: AES-256 key of %d octets, needs 32" % (self.spi, len(key)))
        if self.state not in (SA_UNKEYED, SA_KEYED):
            raise SdlsError("SA %d is %s" % (self.spi, SA_STATE_NAMES[self.state]))
        self.key = key
        self._gcm = AesGcm(key)
        self.state = SA_KEYED

    def expire(self):
        SecurityAssociation.expire(self)
        self._gcm = None

    def mac(self, *parts):
        raise SdlsError("SA %d is GCM: no HMAC" % self.spi)

    def _protect(self, iv, aad, body):
        if self.algorithm == GMAC:
            return body + self._gcm.gmac(iv, aad + body, self.mac_length)
        ct, tag = self._gcm.encrypt(iv, body, aad, self.mac_length)
        return ct + tag

    def _unprotect(self, iv, aad, body, tag):
        """The clear ``body``, or None when the tag fails."""
        try:
            if self.algorithm == GMAC:
                self._gcm.decrypt(iv, b"", tag, aad + body)
                return body
            return self._gcm.decrypt(iv, body, tag, aad)
        except GcmAuthError:
            return None

    def _spi_iv_aad(self):
        return _be(self.spi, 2) + bytes(IV_LENGTH)

    # -- TC frames (called by TcSecurity) ---------------------------------------------------

    def seal(self, security, header, head, body):
        iv = _be(self.next_sn(security), IV_LENGTH)
        aad = bytes((0, 0, header[2] & 0xFC, 0, 0)) + head + self._spi_iv_aad()
        return _be(self.spi, 2) + iv + self._protect(iv, aad, body)

    def open(self, raw, n, lead):
        start = 5 + lead
        body = start + 2 + IV_LENGTH
        trailer = n - 2 - self.mac_length
        if trailer < body:
            return False
        view = memoryview(raw)
        iv = bytes(view[start + 2 : body])
        aad = bytes((0, 0, raw[2] & 0xFC, 0, 0)) + bytes(view[5:start]) + self._spi_iv_aad()
        clear = self._unprotect(iv, aad, bytes(view[body:trailer]), bytes(view[trailer : n - 2]))
        if clear is None:
            return None
        return int.from_bytes(iv, "big"), clear

    # -- TM frames (called by TmSecurity) ---------------------------------------------------

    def tm_aad(self, vcid, secondary_header_length):
        return (
            bytes((0, (vcid << 1) & 0x0E, 0, 0, 0, 0))
            + bytes(secondary_header_length)
            + (self._spi_iv_aad())
        )


class TmSecurity:
    """The SAs of TM virtual channels (at most one per VC) and SDLS Apply/ProcessSecurity on
    the data field of TM frames. ``counters`` counts received frames' outcomes by name."""

    def __init__(self, sas=()):
        self.sas = {}
        self.by_vc = {}
        self.on_reserve = None
        self.counters = {}
        for name in OUTCOME_NAMES:
            self.counters[name] = 0
        for sa in sas:
            self.add(sa)

    def add(self, sa):
        if sa.spi in self.sas:
            raise SdlsError("SPI %d given twice" % sa.spi)
        if sa.vcid in self.by_vc:
            raise SdlsError("TM VC %d has two SAs" % sa.vcid)
        if not 0 <= sa.vcid < 8 or sa.map_id is not None:
            raise SdlsError("TM SA %d: VC ID %d outside 0..7, or a MAP" % (sa.spi, sa.vcid))
        self.sas[sa.spi] = sa
        self.by_vc[sa.vcid] = sa
        return sa

    def overhead(self, vcid):
        """Octets of security header and trailer in the data field of VC ``vcid``'s frames."""
        sa = self.by_vc.get(vcid)
        return 0 if sa is None else sa.header_length + sa.trailer_length

    def reserve(self, sa):
        sa.sn_reserved = sa.sn_sent + sa.reserve_block
        if self.on_reserve is not None:
            self.on_reserve()

    def seal(self, vcid, data, secondary_header_length=0):
        """The data field of a frame of VC ``vcid`` carrying ``data``: unchanged when the VC
        has no SA, else security header, protected data and trailer."""
        sa = self.by_vc.get(vcid)
        if sa is None:
            return data
        if sa.state != SA_OPERATIONAL:
            raise SdlsError("TM SA %d is %s" % (sa.spi, SA_STATE_NAMES[sa.state]))
        iv = _be(sa.next_sn(self), IV_LENGTH)
        aad = sa.tm_aad(vcid, secondary_header_length)
        return _be(sa.spi, 2) + iv + sa._protect(iv, aad, bytes(data))

    def _reject(self, outcome):
        self.counters[OUTCOME_NAMES[outcome]] += 1
        return outcome, None

    def open(self, vcid, field, secondary_header_length=0):
        """ProcessSecurity on the data field ``field`` of a received frame of VC ``vcid``:
        (outcome, clear data or None). Accepted numbers are committed at once."""
        sa = self.by_vc.get(vcid)
        if sa is None:
            return OK, field
        if len(field) < sa.header_length + sa.trailer_length:
            return self._reject(TOO_SHORT)
        spi = (field[0] << 8) | field[1]
        if spi != sa.spi:
            return self._reject(BAD_SPI)
        if sa.state != SA_OPERATIONAL:
            return self._reject(NOT_OPERATIONAL)
        iv = bytes(field[2 : 2 + IV_LENGTH])
        end = len(field) - sa.trailer_length
        aad = sa.tm_aad(vcid, secondary_header_length)
        clear = sa._unprotect(iv, aad, bytes(field[2 + IV_LENGTH : end]), bytes(field[end:]))
        if clear is None:
            return self._reject(BAD_MAC)
        sn = int.from_bytes(iv, "big")
        if not sa.window.acceptable(sn):
            return self._reject(REPLAY)
        sa.window.commit(sn)
        self.counters["ok"] += 1
        return OK, clear

    def context(self):
        return [[s, max(a.sn_sent, a.sn_reserved), a.window.top] for s, a in self.sas.items()]

    def restore(self, ctx):
        for entry in ctx:
            sa = self.sas.get(entry[0])
            if sa is not None:
                sa.sn_sent = max(sa.sn_sent, int(entry[1]))
                sa.sn_reserved = sa.sn_sent
                if int(entry[2]) > sa.window.top:
                    sa.window.top = int(entry[2])
                    sa.window._seen = (1 << sa.window.size) - 1
