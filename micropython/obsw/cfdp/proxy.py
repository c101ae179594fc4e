"""Proxy operations and the other reserved messages (727.0-B-5 6), acted on when the
transaction that carried them has been received."""

from obsw.cfdp import msgs
from obsw.cfdp.defs import (
    DATA_INCOMPLETE,
    FILE_DISCARDED_FILESTORE,
    FILESTORE_REJECTION,
    NO_ERROR,
)
from obsw.cfdp.tlv import FaultHandlerOverride, FlowLabel, MessageToUser

_RESPONSES = (
    msgs.PROXY_PUT_RESPONSE,
    msgs.PROXY_FILESTORE_RESPONSE,
    msgs.DIRECTORY_LISTING_RESPONSE,
    msgs.REMOTE_STATUS_REPORT_RESPONSE,
    msgs.REMOTE_SUSPEND_RESPONSE,
    msgs.REMOTE_RESUME_RESPONSE,
)


def _parsed(tx):
    out = []
    for m in tx.messages:
        try:
            p = msgs.parse(m)
        except ValueError:
            p = None
        if p is not None:
            out.append(p)
    return out


def note_origin(tx):
    """Remember the Originating Transaction ID message of an incoming transaction."""
    for kind, f in _parsed(tx):
        if kind == msgs.ORIGINATING_TRANSACTION_ID:
            tx.origin = f["tid"]


def _reply(ent, tx, messages, now, source=None, dest=None):
    """Send response messages back to the entity that started ``tx``."""
    messages = list(messages) + [msgs.originating_transaction_id(tx.tid)]
    try:
        return ent.put(tx.tid[0], source, dest, mode=tx.mode, messages=messages, now=now)
    except ValueError:
        return None


def _proxy_put(ent, tx, req, parsed, now):
    kw = {"mode": tx.mode}
    messages = [msgs.originating_transaction_id(tx.tid)]
    fsreqs = []
    overrides = []
    for kind, f in parsed:
        if kind == msgs.PROXY_MESSAGE_TO_USER:
            messages.append(MessageToUser(f["data"]))
        elif kind == msgs.PROXY_FILESTORE_REQUEST:
            fsreqs.append(f["request"])
        elif kind == msgs.PROXY_FAULT_HANDLER_OVERRIDE:
            overrides.append(FaultHandlerOverride(f["condition"], f["handler"]))
        elif kind == msgs.PROXY_TRANSMISSION_MODE:
            kw["mode"] = f["mode"]
        elif kind == msgs.PROXY_CLOSURE_REQUEST:
            kw["closure"] = f["closure"]
        elif kind == msgs.PROXY_SEGMENTATION_CONTROL:
            kw["seg_ctrl"] = f["preserve"]
        elif kind == msgs.PROXY_FLOW_LABEL:
            kw["flow_label"] = FlowLabel(f["data"])
    try:
        tid = ent.put(
            req["dest_id"],
            req["source_name"],
            req["dest_name"],
            messages=messages,
            filestore_requests=fsreqs,
            fault_overrides=overrides,
            now=now,
            origin=tx.tid,
            **kw,
        )
    except (ValueError, OSError):
        ent.indicate("proxy_rejected", tx.tid, request=req)
        resp = msgs.proxy_put_response(
            FILESTORE_REJECTION, DATA_INCOMPLETE, FILE_DISCARDED_FILESTORE
        )
        _reply(ent, tx, [resp], now)
        return
    ent.find(tid).proxy_put = True


def on_receiver_finished(ent, tx, condition, now):
    """Carry out the reserved messages of a received transaction."""
    if condition != NO_ERROR or not tx.messages:
        return
    parsed = _parsed(tx)
    for kind, f in parsed:
        if kind == msgs.PROXY_PUT_REQUEST:
            _proxy_put(ent, tx, f, parsed, now)
        elif kind == msgs.PROXY_PUT_CANCEL and tx.origin is not None:
            for t in list(ent.tx.values()):
                if t.role == "S" and t.origin == tx.origin:
                    ent.cancel(t.tid, now)
        elif kind == msgs.DIRECTORY_LISTING_REQUEST:
            _listing(ent, tx, f, now)
        elif kind == msgs.REMOTE_STATUS_REPORT_REQUEST:
            rep = ent.report(f["tid"])
            status = rep["status"]
            _reply(ent, tx, [msgs.remote_status_report_response(f["tid"], status, True)], now)
        elif kind in (msgs.REMOTE_SUSPEND_REQUEST, msgs.REMOTE_RESUME_REQUEST):
            target = ent.find(f["tid"])
            if kind == msgs.REMOTE_SUSPEND_REQUEST:
                ent.suspend(f["tid"], now)
                build = msgs.remote_suspend_response
            else:
                ent.resume(f["tid"], now)
                build = msgs.remote_resume_response
            status = ent.report(f["tid"])["status"]
            suspended = bool(target is not None and target.suspended)
            _reply(ent, tx, [build(f["tid"], suspended, status)], now)
        elif kind in _RESPONSES:
            ent.indicate("proxy_response", tx.tid, message=kind, fields=f, origin=tx.origin)


def _listing(ent, tx, f, now):
    name = ent.work_name("listing-%d-%d.txt" % tx.tid)
    try:
        lines = []
        d = f["directory"]
        for n in ent.fs.listdir(d):
            full = (d.rstrip("/") + "/" + n) if d.strip("/") else n
            if ent.fs.is_dir(full):
                lines.append(n + "/")
            else:
                lines.append("%s %d" % (n, ent.fs.size(full)))
        ent.fs.write_bytes(name, ("\n".join(lines) + "\n").encode())
        ok = True
    except OSError:
        ok = False
    resp = msgs.directory_listing_response(ok, f["directory"], f["listing_file"])
    if ok:
        _reply(ent, tx, [resp], now, name, f["listing_file"])
    else:
        _reply(ent, tx, [resp], now)


def on_sender_finished(ent, tx, condition, delivery, file_status, responses, now):
    """After a proxy put ends, tell the entity that asked for it how it went."""
    if not getattr(tx, "proxy_put", False) or tx.origin is None:
        return
    out = [msgs.proxy_put_response(condition, delivery, file_status)]
    for r in responses:
        out.append(msgs.proxy_filestore_response(r))
    out.append(msgs.originating_transaction_id(tx.origin))
    try:
        ent.put(tx.origin[0], mode=tx.mode, messages=out, now=now)
    except ValueError:
        pass
