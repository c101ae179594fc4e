"""Persisted state of a receiving transaction (written atomically through the filestore)."""

from binascii import hexlify, unhexlify

from obsw.cfdp.defs import ACKNOWLEDGED, FILE_DATA, TLV_MESSAGE_TO_USER
from obsw.cfdp.pdu.header import PduHeader
from obsw.cfdp.tlv import pack_tlvs, unpack_tlvs

WAIT_FIN_ACK = "wait_finished_ack"

_NONE = type(None)
_BOOL = (bool, int)
_COMMON = (
    ("role", str),
    ("tid", list),
    ("mode", int),
    ("suspended", _BOOL),
    ("condition", int),
    ("overrides", list),
    ("timers", list),
)
_SENDER = (
    ("dest_id", int),
    ("source_name", (str, _NONE)),
    ("dest_name", (str, _NONE)),
    ("closure", _BOOL),
    ("checksum", int),
    ("seg_ctrl", _BOOL),
    ("large", _BOOL),
    ("options", str),
    ("progress", int),
    ("resend", list),
    ("state", str),
    ("cancelling", _BOOL),
    ("eof", (str, _NONE)),
)
_RECEIVER = (
    ("hdr", list),
    ("meta", (dict, _NONE)),
    ("progress", int),
    ("gaps", list),
    ("eof", (list, _NONE)),
    ("state", (str, _NONE)),
    ("finished", (str, _NONE)),
)


class StateError(ValueError):
    """A persisted transaction that cannot be used: ``field`` names what is wrong."""

    def __init__(self, msg, field=None):
        super().__init__(msg)
        self.field = field


def _ints(name, v, n):
    if not isinstance(v, list) or (n is not None and len(v) != n):
        raise StateError("%s: expected a list of %s integers, got %r" % (name, n, v), name)
    for x in v:  # flags are booleans (not ints on MicroPython)
        if not isinstance(x, _BOOL) or x < 0:
            raise StateError("%s: expected integers >= 0, got %r" % (name, v), name)


def check_state(st):
    """Raise ``StateError`` unless ``st`` has every field of a persisted transaction with the
    right type (the whole check happens before anything is rebuilt from it)."""
    if not isinstance(st, dict):
        raise StateError("expected an object, got %s" % type(st).__name__)
    role = st.get("role")
    if role not in ("S", "R"):
        raise StateError("role: expected 'S' or 'R', got %r" % (role,), "role")
    for name, kinds in _COMMON + (_SENDER if role == "S" else _RECEIVER):
        if name not in st:
            raise StateError("%s: missing" % name, name)
        if not isinstance(st[name], kinds):
            raise StateError("%s: wrong type %s" % (name, type(st[name]).__name__), name)
    _ints("tid", st["tid"], 2)
    for t in st["timers"]:
        if not isinstance(t, list) or len(t) != 2 or not isinstance(t[0], int):
            raise StateError("timers: expected [count, running] pairs, got %r" % (t,), "timers")
    for o in st["overrides"]:
        _ints("overrides", o, 2)
    if role == "S":
        for r in st["resend"]:
            _ints("resend", r, 2)
    else:
        _ints("hdr", st["hdr"], 6)
        for g in st["gaps"]:
            _ints("gaps", g, 2)
        if st["eof"] is not None and not isinstance(st["eof"], list):
            raise StateError("eof: expected a list", "eof")
    if st["progress"] < 0:
        raise StateError("progress: expected >= 0, got %d" % st["progress"], "progress")


def receiver_state(self):
    """The receiver's persisted state as a JSON-friendly dict."""
    m = self.meta
    if m is not None:
        m = dict(m)
        m["options"] = hexlify(pack_tlvs(m["options"])).decode()
    h = self.header
    return {
        "hdr": [h.crc, h.large, h.seg_ctrl, h.eid_len, h.seq_len, h.dest],
        "meta": m,
        "progress": self.progress,
        "gaps": [[g[0], g[1]] for g in self.gaps],
        "eof": list(self.eof) if self.eof else None,
        "state": self.state_,
        "finished": hexlify(self.finished).decode() if self.finished else None,
    }


def restore_receiver(cls, entity, st, remote, now):
    """A Receiver rebuilt from ``receiver_state`` after a restart."""
    crc, large, seg, el, sl, dest = st["hdr"]
    src, seq = st["tid"]
    hdr = PduHeader(
        src,
        dest,
        seq,
        pdu_type=FILE_DATA,
        mode=st["mode"],
        crc=crc,
        large=large,
        seg_ctrl=seg,
        eid_len=el,
        seq_len=sl,
    )
    tx = cls(entity, (src, seq), remote, hdr, now)
    m = st["meta"]
    if m is not None:
        m["options"] = unpack_tlvs(unhexlify(m["options"]))
        tx.meta = m
        tx.set_overrides(m["options"])
        tx.messages = [t for t in m["options"] if t.tlv_type == TLV_MESSAGE_TO_USER]
        # the running checksum is rebuilt from the file at the end
    tx.restore_common(st, now)
    tx.progress = st["progress"]
    tx.gaps = [[g[0], g[1], None] for g in st["gaps"]]
    tx.eof = tuple(st["eof"]) if st["eof"] else None
    tx.state_ = st["state"]
    if st["finished"]:
        tx.finished = unhexlify(st["finished"])
    if tx.state_ == WAIT_FIN_ACK:
        tx.inactivity.stop()
        tx.keep_alive.stop()
        if not tx.suspended:
            tx.emit(tx.finished)
            tx.ack.start(now)
    elif tx.eof is not None and not tx.suspended and not tx._check_done(now):
        if tx.mode == ACKNOWLEDGED:
            tx._nak_all(now)
            tx.nak.start(now)
        else:
            tx.check.start(now)
    return tx
