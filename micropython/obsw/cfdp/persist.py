"""Persisted state of a receiving transaction (written atomically through the filestore)."""

from binascii import hexlify, unhexlify

from obsw.cfdp.defs import ACKNOWLEDGED, FILE_DATA, TLV_MESSAGE_TO_USER
from obsw.cfdp.pdu.header import PduHeader
from obsw.cfdp.tlv import pack_tlvs, unpack_tlvs

WAIT_FIN_ACK = "wait_finished_ack"


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
