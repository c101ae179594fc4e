"""Reserved CFDP messages to user (727.0-B-5 6): proxy operations, directory listing, remote
status report, remote suspend and resume. Build with the functions below, read with ``parse``.
"""

from obsw.cfdp.defs import PduFormatError, PduTooShortError
from obsw.cfdp.pdu.header import int_len, uint_bytes, uint_from
from obsw.cfdp.tlv import FilestoreRequest, FilestoreResponse, MessageToUser, lv_pack, lv_unpack
from obsw.compat import const

PROXY_PUT_REQUEST = const(0x00)
PROXY_MESSAGE_TO_USER = const(0x01)
PROXY_FILESTORE_REQUEST = const(0x02)
PROXY_FAULT_HANDLER_OVERRIDE = const(0x03)
PROXY_TRANSMISSION_MODE = const(0x04)
PROXY_FLOW_LABEL = const(0x05)
PROXY_SEGMENTATION_CONTROL = const(0x06)
PROXY_PUT_RESPONSE = const(0x07)
PROXY_FILESTORE_RESPONSE = const(0x08)
PROXY_PUT_CANCEL = const(0x09)
ORIGINATING_TRANSACTION_ID = const(0x0A)
PROXY_CLOSURE_REQUEST = const(0x0B)
DIRECTORY_LISTING_REQUEST = const(0x10)
DIRECTORY_LISTING_RESPONSE = const(0x11)
REMOTE_STATUS_REPORT_REQUEST = const(0x20)
REMOTE_STATUS_REPORT_RESPONSE = const(0x21)
REMOTE_SUSPEND_REQUEST = const(0x30)
REMOTE_SUSPEND_RESPONSE = const(0x31)
REMOTE_RESUME_REQUEST = const(0x38)
REMOTE_RESUME_RESPONSE = const(0x39)

_MARK = b"cfdp"


def _msg(kind, body=b""):
    return MessageToUser(_MARK + bytes((kind,)) + body)


def _tid_pack(tid):
    src, seq = tid
    e = int_len(src)
    s = int_len(seq)
    return bytes((((e - 1) << 4) | (s - 1),)) + uint_bytes(src, e) + uint_bytes(seq, s)


def _tid_unpack(v, pos):
    if len(v) < pos + 1:
        raise PduTooShortError("transaction id", pos + 1, len(v))
    e = ((v[pos] >> 4) & 7) + 1
    s = (v[pos] & 7) + 1
    end = pos + 1 + e + s
    if len(v) < end:
        raise PduTooShortError("transaction id", end, len(v))
    return (uint_from(v, pos + 1, e), uint_from(v, pos + 1 + e, s)), end


def _name(raw):
    try:
        return raw.decode()
    except Exception:
        raise PduFormatError("name in a reserved message is not UTF-8") from None


def proxy_put_request(dest_id, source_name, dest_name):
    """Ask the receiving entity to put ``source_name`` to entity ``dest_id`` (a remote 'get')."""
    return _msg(
        PROXY_PUT_REQUEST,
        lv_pack(uint_bytes(dest_id, int_len(dest_id)))
        + lv_pack(source_name or "")
        + lv_pack(dest_name or ""),
    )


def proxy_message_to_user(data):
    return _msg(PROXY_MESSAGE_TO_USER, lv_pack(data))


def proxy_filestore_request(request):
    return _msg(PROXY_FILESTORE_REQUEST, request.value_bytes())


def proxy_fault_handler_override(condition, handler):
    return _msg(PROXY_FAULT_HANDLER_OVERRIDE, bytes(((condition << 4) | handler,)))


def proxy_transmission_mode(mode):
    return _msg(PROXY_TRANSMISSION_MODE, bytes((mode & 1,)))


def proxy_flow_label(label):
    return _msg(PROXY_FLOW_LABEL, lv_pack(label))


def proxy_segmentation_control(preserve):
    return _msg(PROXY_SEGMENTATION_CONTROL, bytes((1 if preserve else 0,)))


def proxy_put_response(condition, delivery, file_status):
    return _msg(PROXY_PUT_RESPONSE, bytes(((condition << 4) | (delivery << 2) | file_status,)))


def proxy_filestore_response(response):
    return _msg(PROXY_FILESTORE_RESPONSE, response.value_bytes())


def proxy_put_cancel():
    return _msg(PROXY_PUT_CANCEL)


def originating_transaction_id(tid):
    return _msg(ORIGINATING_TRANSACTION_ID, _tid_pack(tid))


def proxy_closure_request(closure):
    return _msg(PROXY_CLOSURE_REQUEST, bytes((1 if closure else 0,)))


def directory_listing_request(directory, listing_file):
    return _msg(DIRECTORY_LISTING_REQUEST, lv_pack(directory) + lv_pack(listing_file))


def directory_listing_response(ok, directory, listing_file):
    body = bytes((0 if ok else 0x80,)) + lv_pack(directory) + lv_pack(listing_file)
    return _msg(DIRECTORY_LISTING_RESPONSE, body)


def remote_status_report_request(tid, report_file):
    return _msg(REMOTE_STATUS_REPORT_REQUEST, _tid_pack(tid) + lv_pack(report_file))


def remote_status_report_response(tid, status, ok):
    body = bytes(((status << 6) | (0 if ok else 1),)) + _tid_pack(tid)
    return _msg(REMOTE_STATUS_REPORT_RESPONSE, body)


def remote_suspend_request(tid):
    return _msg(REMOTE_SUSPEND_REQUEST, _tid_pack(tid))


def remote_suspend_response(tid, suspended, status):
    body = bytes(((0x80 if suspended else 0) | (status << 5),)) + _tid_pack(tid)
    return _msg(REMOTE_SUSPEND_RESPONSE, body)


def remote_resume_request(tid):
    return _msg(REMOTE_RESUME_REQUEST, _tid_pack(tid))


def remote_resume_response(tid, suspended, status):
    body = bytes(((0x80 if suspended else 0) | (status << 5),)) + _tid_pack(tid)
    return _msg(REMOTE_RESUME_RESPONSE, body)


def is_reserved(msg):
    v = msg.value
    return len(v) >= 5 and v[:4] == _MARK


def _byte(v):
    if len(v) < 6:
        raise PduTooShortError("reserved message", 6, len(v))
    return v[5]


def parse(msg):
    """(message type, dict of fields) of a reserved CFDP message, or None for a user's own."""
    if not is_reserved(msg):
        return None
    v = msg.value
    kind = v[4]
    f = {}
    if kind == PROXY_PUT_REQUEST:
        raw, pos = lv_unpack(v, 5, "proxy put destination id")
        if not 1 <= len(raw) <= 8:
            raise PduFormatError("proxy put destination id of %d octets" % len(raw))
        f["dest_id"] = int.from_bytes(raw, "big")
        raw, pos = lv_unpack(v, pos, "proxy put source file name")
        f["source_name"] = _name(raw) or None
        raw, pos = lv_unpack(v, pos, "proxy put destination file name")
        f["dest_name"] = _name(raw) or None
    elif kind in (PROXY_MESSAGE_TO_USER, PROXY_FLOW_LABEL):
        f["data"], _ = lv_unpack(v, 5)
    elif kind == PROXY_FILESTORE_REQUEST:
        f["request"] = FilestoreRequest.from_value(v[5:])
    elif kind == PROXY_FILESTORE_RESPONSE:
        f["response"] = FilestoreResponse.from_value(v[5:])
    elif kind == PROXY_FAULT_HANDLER_OVERRIDE:
        b = _byte(v)
        f["condition"] = b >> 4
        f["handler"] = b & 15
    elif kind == PROXY_TRANSMISSION_MODE:
        f["mode"] = _byte(v) & 1
    elif kind == PROXY_SEGMENTATION_CONTROL:
        f["preserve"] = bool(_byte(v) & 1)
    elif kind == PROXY_CLOSURE_REQUEST:
        f["closure"] = bool(_byte(v) & 1)
    elif kind == PROXY_PUT_RESPONSE:
        b = _byte(v)
        f["condition"] = b >> 4
        f["delivery"] = (b >> 2) & 1
        f["file_status"] = b & 3
    elif kind == ORIGINATING_TRANSACTION_ID:
        f["tid"], _ = _tid_unpack(v, 5)
    elif kind in (DIRECTORY_LISTING_REQUEST, DIRECTORY_LISTING_RESPONSE):
        pos = 5
        if kind == DIRECTORY_LISTING_RESPONSE:
            f["ok"] = not (_byte(v) & 0x80)
            pos = 6
        raw, pos = lv_unpack(v, pos, "directory name")
        f["directory"] = _name(raw)
        raw, pos = lv_unpack(v, pos, "directory listing file name")
        f["listing_file"] = _name(raw)
    elif kind == REMOTE_STATUS_REPORT_REQUEST:
        f["tid"], pos = _tid_unpack(v, 5)
        raw, pos = lv_unpack(v, pos, "report file name")
        f["report_file"] = _name(raw)
    elif kind == REMOTE_STATUS_REPORT_RESPONSE:
        b = _byte(v)
        f["status"] = b >> 6
        f["ok"] = not (b & 1)
        f["tid"], _ = _tid_unpack(v, 6)
    elif kind in (REMOTE_SUSPEND_REQUEST, REMOTE_RESUME_REQUEST):
        f["tid"], _ = _tid_unpack(v, 5)
    elif kind in (REMOTE_SUSPEND_RESPONSE, REMOTE_RESUME_RESPONSE):
        b = _byte(v)
        f["suspended"] = bool(b & 0x80)
        f["status"] = (b >> 5) & 3
        f["tid"], _ = _tid_unpack(v, 6)
    return kind, f
