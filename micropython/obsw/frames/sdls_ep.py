"""SDLS extended procedures (CCSDS 355.1-B-1): key management and SA management over the link.

PDUs are TLVs: tag (1: bit 7 reply, bit 6 user flag, bits 5-4 service group, bits 3-0
procedure), length (2, of the value in bits), value. The subset here, with the standard's
procedure identifiers:

key management (group 0): OTAR 0x01 (master key ID (2) | IV (12) | AES-256-GCM under the
master key of [key ID (2) | key (32)]... | MAC (16)), activation 0x02, deactivation 0x03 and
destruction 0x06 (key IDs, 2 each), verification 0x04 ([key ID | challenge (16)]...; reply
[key ID | IV (12) | challenge encrypted under the key (16) | MAC (16)]...), inventory 0x07
(first, last key ID; reply count (2) | [key ID | state (1)]...).

SA management (group 1): rekey 0x16 (SPI | key ID; unkeyed -> keyed, sequence numbers
restart with the new key), start 0x1B, stop 0x1E, expire 0x19 (keyed -> unkeyed, the key
erased), status 0x1F (reply SPI | state (1)), read ARSN 0x10 (reply SPI | ARSN).

Key IDs below MASTER_LIMIT are master (key-encrypting) keys: they only unwrap OTAR uploads and
are never given to an SA; session keys arrive by OTAR in the pre-activation state and must be
activated before a rekey can use them. Every command gets a reply PDU: the command's tag with
bit 7 set, a status octet (STATUS_NAMES; 0 done) and the reply data; bytes that do not split
into PDUs get one reply of tag 0xFF, bad_pdu. The engine never raises on bad input.
"""

import binascii
import json

from obsw.compat import const
from obsw.frames.gcm import AesGcm, GcmAuthError
from obsw.frames.sdls import SA_KEYED, SA_OPERATIONAL, SA_STATE_NAMES, SA_UNKEYED, SdlsError

OTAR = const(0x01)
KEY_ACTIVATE = const(0x02)
KEY_DEACTIVATE = const(0x03)
KEY_VERIFY = const(0x04)
KEY_DESTROY = const(0x06)
KEY_INVENTORY = const(0x07)
SA_READ_ARSN = const(0x10)
SA_REKEY = const(0x16)
SA_EXPIRE = const(0x19)
SA_START = const(0x1B)
SA_STOP = const(0x1E)
SA_STATUS = const(0x1F)
REPLY = const(0x80)
PROCEDURE_NAMES = {
    OTAR: "otar",
    KEY_ACTIVATE: "activate",
    KEY_DEACTIVATE: "deactivate",
    KEY_VERIFY: "verify",
    KEY_DESTROY: "destroy",
    KEY_INVENTORY: "inventory",
    SA_READ_ARSN: "read-arsn",
    SA_REKEY: "rekey",
    SA_EXPIRE: "expire",
    SA_START: "start",
    SA_STOP: "stop",
    SA_STATUS: "status",
}

# key states (355.1 3.3.2)
PRE_ACTIVE = const(0)
ACTIVE = const(1)
DEACTIVATED = const(2)
DESTROYED = const(3)
KEY_STATE_NAMES = ("pre-active", "active", "deactivated", "destroyed")

# reply status octet: 0 done, else why not
DONE = const(0)
BAD_PDU = const(1)
UNKNOWN_KEY = const(2)
KEY_STATE = const(3)
BAD_MAC = const(4)
UNKNOWN_SA = const(5)
SA_STATE = const(6)
UNKNOWN_PROCEDURE = const(7)
STATUS_NAMES = (
    "done",
    "bad_pdu",
    "unknown_key",
    "wrong_key_state",
    "bad_mac",
    "unknown_sa",
    "wrong_sa_state",
    "unknown_procedure",
)
MASTER_LIMIT = const(128)
KEY_LENGTH = const(32)


class EpError(ValueError):
    """A PDU that cannot be decoded (the engine answers it with BAD_PDU instead of raising)."""


def pdu(tag, value):
    """One TLV: tag, length of ``value`` in bits, value."""
    n = 8 * len(value)
    return bytes((tag, n >> 8, n & 0xFF)) + bytes(value)


def split(buf):
    """The (tag, value) of each TLV in ``buf``; EpError when a length runs past the end."""
    out = []
    i = 0
    while i < len(buf):
        if i + 3 > len(buf):
            raise EpError("EP PDU header cut: %d octets left, needs 3" % (len(buf) - i))
        bits = (buf[i + 1] << 8) | buf[i + 2]
        if bits % 8:
            raise EpError("EP PDU length of %d bits is not whole octets" % bits)
        end = i + 3 + bits // 8
        if end > len(buf):
            raise EpError("EP PDU of %d octets, %d left" % (bits // 8, len(buf) - i - 3))
        out.append((buf[i], bytes(buf[i + 3 : end])))
        i = end
    return out


def _u16(b, i):
    return (b[i] << 8) | b[i + 1]


def _b16(v):
    return bytes((v >> 8, v & 0xFF))


def otar_pdu(master_id, master_key, keys, iv):
    """An OTAR command uploading ``keys`` ({key ID: 32-octet key}) wrapped under master key
    ``master_id`` with ``iv`` (12 octets, never twice under one master key)."""
    clear = b"".join(_b16(k) + bytes(keys[k]) for k in sorted(keys))
    ct, tag = AesGcm(master_key).encrypt(iv, clear, _b16(master_id))
    return pdu(OTAR, _b16(master_id) + bytes(iv) + ct + tag)


def verify_reply_ok(key, reply_value, challenges):
    """True when a key verification reply proves knowledge of ``key`` for ``challenges``
    ({key ID: 16-octet challenge}); the ground side of KEY_VERIFY."""
    got = {}
    for i in range(0, len(reply_value), 46):
        kid = _u16(reply_value, i)
        iv = reply_value[i + 2 : i + 14]
        try:
            got[kid] = AesGcm(key[kid]).decrypt(
                iv, reply_value[i + 14 : i + 30], reply_value[i + 30 : i + 46], _b16(kid)
            )
        except (GcmAuthError, KeyError):
            return False
    return got == challenges


class KeyStore:
    """Keys by ID with their 355.1 states; ``dump``/``load`` as JSON for atomic saving."""

    def __init__(self):
        self.keys = {}  # ID -> [state, key bytes or None]

    def add(self, kid, key, state=PRE_ACTIVE):
        self.keys[kid] = [state, bytes(key)]

    def dump(self):
        return json.dumps(
            {
                "format": "obsw-sdls-keystore",
                "keys": [
                    [k, v[0], "" if v[1] is None else binascii.hexlify(v[1]).decode()]
                    for k, v in sorted(self.keys.items())
                ],
            }
        )

    @classmethod
    def load(cls, text):
        doc = json.loads(text)
        if not isinstance(doc, dict) or doc.get("format") != "obsw-sdls-keystore":
            raise EpError("not an obsw-sdls-keystore")
        store = cls()
        for kid, state, key in doc["keys"]:
            store.keys[int(kid)] = [int(state), binascii.unhexlify(key) if key else None]
        return store


class ExtendedProcedures:
    """The receiving end of EP PDUs for one TcSecurity (and its TmSecurity, if any).
    ``handle(buf)`` runs every PDU of ``buf`` and returns the reply PDUs; ``on_change`` is
    called after anything that must be saved (keys, SA states) changed."""

    def __init__(self, store, security, tm=None, iv_source=None):
        self.store = store
        self.security = security
        self.tm = tm
        self.on_change = None
        self.counters = {"done": 0, "refused": 0}
        self._iv = iv_source  # callable -> 12 fresh octets (the verification replies)
        self._iv_count = 0

    def _sa(self, spi):
        sa = self.security.sas.get(spi)
        if sa is None and self.tm is not None:
            sa = self.tm.sas.get(spi)
        return sa

    def _next_iv(self):
        if self._iv is not None:
            return self._iv()
        self._iv_count += 1
        return self._iv_count.to_bytes(12, "big")

    def handle(self, buf):
        try:
            items = split(buf)
        except EpError:
            self.counters["refused"] += 1
            return pdu(0xFF, bytes((BAD_PDU,)))
        out = b""
        for tag, value in items:
            try:
                status, data = self._run(tag, value)
            except (IndexError, ValueError, SdlsError):
                status, data = BAD_PDU, b""
            self.counters["done" if status == DONE else "refused"] += 1
            out += pdu(tag | REPLY, bytes((status,)) + data)
        return out

    def _changed(self):
        if self.on_change is not None:
            self.on_change()

    def _run(self, tag, v):
        if tag not in PROCEDURE_NAMES:
            return UNKNOWN_PROCEDURE, b""
        keys = self.store.keys
        if tag == OTAR:
            mid = _u16(v, 0)
            master = keys.get(mid)
            if mid >= MASTER_LIMIT or master is None:
                return UNKNOWN_KEY, b""
            if master[0] != ACTIVE:
                return KEY_STATE, b""
            if len(v) < 2 + 12 + 16 or (len(v) - 30) % (2 + KEY_LENGTH):
                return BAD_PDU, b""
            try:
                clear = AesGcm(master[1]).decrypt(v[2:14], v[14:-16], v[-16:], v[0:2])
            except GcmAuthError:
                return BAD_MAC, b""
            for i in range(0, len(clear), 2 + KEY_LENGTH):
                kid = _u16(clear, i)
                if kid < MASTER_LIMIT or (kid in keys and keys[kid][0] != DESTROYED):
                    return KEY_STATE, _b16(kid)
            for i in range(0, len(clear), 2 + KEY_LENGTH):
                self.store.add(_u16(clear, i), clear[i + 2 : i + 2 + KEY_LENGTH])
            self._changed()
            return DONE, b""
        if tag in (KEY_ACTIVATE, KEY_DEACTIVATE, KEY_DESTROY):
            ids = [_u16(v, i) for i in range(0, len(v), 2)]
            want = {KEY_ACTIVATE: (PRE_ACTIVE,), KEY_DEACTIVATE: (ACTIVE,)}.get(
                tag, (PRE_ACTIVE, ACTIVE, DEACTIVATED)
            )
            for kid in ids:
                if kid not in keys or kid < MASTER_LIMIT and tag != KEY_ACTIVATE:
                    return UNKNOWN_KEY, _b16(kid)
                if keys[kid][0] not in want:
                    return KEY_STATE, _b16(kid)
                if tag == KEY_DESTROY and self._in_use(keys[kid][1]):
                    return KEY_STATE, _b16(kid)
            new = {KEY_ACTIVATE: ACTIVE, KEY_DEACTIVATE: DEACTIVATED}.get(tag, DESTROYED)
            for kid in ids:
                keys[kid][0] = new
                if new == DESTROYED:
                    keys[kid][1] = None
            self._changed()
            return DONE, b""
        if tag == KEY_VERIFY:
            out = b""
            for i in range(0, len(v), 18):
                kid = _u16(v, i)
                entry = keys.get(kid)
                if entry is None or entry[1] is None:
                    return UNKNOWN_KEY, _b16(kid)
                iv = self._next_iv()
                ct, mac = AesGcm(entry[1]).encrypt(iv, v[i + 2 : i + 18], _b16(kid))
                out += _b16(kid) + iv + ct + mac
            return DONE, out
        if tag == KEY_INVENTORY:
            first, last = _u16(v, 0), _u16(v, 2)
            found = [k for k in sorted(keys) if first <= k <= last]
            return DONE, _b16(len(found)) + b"".join(_b16(k) + bytes((keys[k][0],)) for k in found)
        sa = self._sa(_u16(v, 0))
        if sa is None:
            return UNKNOWN_SA, v[0:2]
        if tag == SA_STATUS:
            return DONE, v[0:2] + bytes((sa.state,))
        if tag == SA_READ_ARSN:
            return DONE, v[0:2] + max(sa.sn_sent, sa.window.top).to_bytes(sa.sn_length, "big")
        if tag == SA_START:
            if sa.state != SA_KEYED:
                return SA_STATE, v[0:2]
            sa.start()
        elif tag == SA_STOP:
            if sa.state != SA_OPERATIONAL:
                return SA_STATE, v[0:2]
            sa.stop()
        elif tag == SA_EXPIRE:
            if sa.state != SA_KEYED:
                return SA_STATE, v[0:2]
            sa.expire()
            sa.state = SA_UNKEYED  # 355.0 figure 4-1: expire goes back to unkeyed
        elif tag == SA_REKEY:
            entry = keys.get(_u16(v, 2))
            if entry is None or _u16(v, 2) < MASTER_LIMIT:
                return UNKNOWN_KEY, v[0:4]
            if entry[0] != ACTIVE:
                return KEY_STATE, v[0:4]
            if sa.state != SA_UNKEYED:
                return SA_STATE, v[0:2]
            sa.set_key(entry[1])
            sa.sn_sent = sa.sn_reserved = 0  # a new key: its IVs and ARSNs start afresh
            sa.window.top = 0
            sa.window._seen = 0
        else:
            return UNKNOWN_PROCEDURE, b""
        self._changed()
        return DONE, v[0:2]

    def _in_use(self, key):
        for sas in (self.security.sas, self.tm.sas if self.tm is not None else {}):
            for sa in sas.values():
                if sa.key == key:
                    return True
        return False


def describe(reply):
    """Readable lines for the reply PDUs of ``reply`` (the ground's view)."""
    lines = []
    for tag, value in split(reply):
        name = PROCEDURE_NAMES.get(tag & 0x7F, "0x%02x" % tag)
        status = STATUS_NAMES[value[0]] if value and value[0] < len(STATUS_NAMES) else "?"
        line = "%s: %s" % (name, status)
        data = value[1:]
        if status == "done" and tag & 0x7F == SA_STATUS and len(data) == 3:
            line += " SPI %d %s" % (_u16(data, 0), SA_STATE_NAMES[data[2]])
        elif status == "done" and tag & 0x7F == SA_READ_ARSN:
            line += " SPI %d ARSN %d" % (_u16(data, 0), int.from_bytes(data[2:], "big"))
        elif status == "done" and tag & 0x7F == KEY_INVENTORY:
            for i in range(2, len(data), 3):
                line += " %d:%s" % (_u16(data, i), KEY_STATE_NAMES[data[i + 2]])
        elif data:
            line += " " + binascii.hexlify(data).decode()
        lines.append(line)
    return lines
