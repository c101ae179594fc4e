"""ST[18] service user: OBCP requests from the ground, the status and aborted-OBCP reports
decoded, and the data of service 18 failure reports explained."""

from obsw.pus.messages import (
    FAILURE_FILESTORE,
    FAILURE_OBCP_REJECTED,
    FAILURE_PATH,
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
    SERVICE_OBCP,
    TC_OBCP_ABORT,
    TC_OBCP_ABORT_ALL,
    TC_OBCP_ACTIVATE,
    TC_OBCP_ACTIVATE_AND_STEP,
    TC_OBCP_COMMUNICATE_PARAMETERS,
    TC_OBCP_LOAD_AND_ACTIVATE,
    TC_OBCP_LOAD_BY_REFERENCE,
    TC_OBCP_LOAD_DIRECT,
    TC_OBCP_REPORT_STATUS,
    TC_OBCP_RESUME,
    TC_OBCP_RESUME_AND_STEP,
    TC_OBCP_SET_OBSERVABILITY,
    TC_OBCP_START_ENGINE,
    TC_OBCP_STOP,
    TC_OBCP_STOP_AND_UNLOAD,
    TC_OBCP_STOP_ENGINE,
    TC_OBCP_SUSPEND,
    TC_OBCP_UNLOAD,
    TM_OBCP_ABORTED_REPORT,
    TM_OBCP_STATUS_REPORT,
)
from obsw.pus.services import s18_layouts as lay
from obsw.pus.services.base import ServiceUser


def _name(names, i):
    return names[i] if 0 <= i < len(names) else "code %d" % i


class ObcpUser(ServiceUser):
    """The service 18 user. Each request returns the ground process's Transaction; the
    status report decodes to ``{"obcps": [{"id", "status", ...}]}`` (status, outcome and
    level by name), the aborted-OBCP report to ``{"ids": [...]}``. ``detail`` must match the
    provider's."""

    SERVICE = SERVICE_OBCP
    DECODERS = (
        (TM_OBCP_STATUS_REPORT, "decode_status"),
        (TM_OBCP_ABORTED_REPORT, "decode_aborted"),
    )

    def __init__(self, detail=True):
        super().__init__()
        self.detail = detail

    def _id(self, apid, message_type, name, expect=None):
        return self.request(apid, message_type, lay.ID.pack({"id": name}), expect)

    def load(self, apid, name, source, arguments=None):
        """TC[18,1]: ``source`` (text or bytes) becomes OBCP ``name``; ``arguments`` declare
        the procedure's arguments with their default values."""
        code = source.encode("utf-8") if isinstance(source, str) else bytes(source)
        args = lay.encode_arguments(arguments)
        data = lay.LOAD.pack({"id": name, "code": code, "args": args})
        return self.request(apid, TC_OBCP_LOAD_DIRECT, data)

    def load_by_reference(self, apid, name, repository, file, arguments=None):
        """TC[18,13]: load the procedure file ``repository``/``file`` of the filestore."""
        data = lay.LOAD_BY_REFERENCE.pack(
            {
                "id": name,
                "repository": repository,
                "file": file,
                "args": lay.encode_arguments(arguments),
            }
        )
        return self.request(apid, TC_OBCP_LOAD_BY_REFERENCE, data)

    def unload(self, apid, name):
        return self._id(apid, TC_OBCP_UNLOAD, name)

    def activate(self, apid, name, arguments=None, level=lay.LEVEL_STEP):
        """TC[18,3]; ``arguments`` maps names to values or ``{"value": v, "unit": u}``."""
        data = lay.ACTIVATE.pack(
            {"id": name, "level": level, "args": lay.encode_arguments(arguments)}
        )
        return self.request(apid, TC_OBCP_ACTIVATE, data)

    def activate_and_step(self, apid, name, arguments=None, level=lay.LEVEL_STEP):
        """TC[18,14]: activate as TC[18,3]; the OBCP suspends once its first step ended."""
        data = lay.ACTIVATE.pack(
            {"id": name, "level": level, "args": lay.encode_arguments(arguments)}
        )
        return self.request(apid, TC_OBCP_ACTIVATE_AND_STEP, data)

    def resume_and_step(self, apid, name):
        """TC[18,15]: a suspended OBCP runs one more step, then suspends again."""
        return self._id(apid, TC_OBCP_RESUME_AND_STEP, name)

    def load_and_activate(
        self, apid, name, repository, file, arguments=None, level=lay.LEVEL_STEP
    ):
        """TC[18,19]: load by reference and activate in one request."""
        data = lay.LOAD_AND_ACTIVATE.pack(
            {
                "id": name,
                "repository": repository,
                "file": file,
                "level": level,
                "args": lay.encode_arguments(arguments),
            }
        )
        return self.request(apid, TC_OBCP_LOAD_AND_ACTIVATE, data)

    def stop(self, apid, name):
        return self._id(apid, TC_OBCP_STOP, name)

    def suspend(self, apid, name):
        return self._id(apid, TC_OBCP_SUSPEND, name)

    def resume(self, apid, name):
        return self._id(apid, TC_OBCP_RESUME, name)

    def abort(self, apid, name):
        return self._id(apid, TC_OBCP_ABORT, name)

    def stop_and_unload(self, apid, name):
        return self._id(apid, TC_OBCP_STOP_AND_UNLOAD, name)

    def answer(self, apid, name, value, argument="answer"):
        """TC[18,7]: ``value`` to OBCP ``name`` (the answer to its question)."""
        args = lay.encode_arguments({argument: value})
        data = lay.COMMUNICATE.pack({"id": name, "args": args})
        return self.request(apid, TC_OBCP_COMMUNICATE_PARAMETERS, data)

    def set_observability(self, apid, levels):
        """TC[18,16]: ``levels`` maps OBCP IDs to observability levels (``LEVEL_*``)."""
        items = [{"id": k, "level": v} for k, v in levels.items()]
        return self.request(apid, TC_OBCP_SET_OBSERVABILITY, lay.LEVELS.pack({"items": items}))

    def report_status(self, apid):
        """TC[18,8]; ``tx.reply`` is the decoded TM[18,9]."""
        return self.request(apid, TC_OBCP_REPORT_STATUS, b"", TM_OBCP_STATUS_REPORT)

    def abort_all(self, apid):
        """TC[18,17]; ``tx.reply["ids"]`` lists the OBCPs aborted (TM[18,18])."""
        return self.request(apid, TC_OBCP_ABORT_ALL, b"", TM_OBCP_ABORTED_REPORT)

    def start_engine(self, apid):
        return self.request(apid, TC_OBCP_START_ENGINE)

    def stop_engine(self, apid):
        return self.request(apid, TC_OBCP_STOP_ENGINE)

    # -------------------------------------------------------------------------- decoding

    def decode_status(self, tm):
        layout = lay.STATUS_DETAIL if self.detail else lay.STATUS
        out = []
        for i in layout.unpack(tm.data)["items"]:
            i["status"] = _name(lay.STATUS_NAMES, i["status"])
            if "outcome" in i:
                i["outcome"] = _name(lay.OUTCOME_NAMES, i["outcome"])
                i["level"] = _name(lay.LEVEL_NAMES, i["level"])
            out.append(i)
        return {"obcps": out}

    def decode_aborted(self, tm):
        return lay.ABORTED.unpack(tm.data)


def failure_info(report):
    """The data of a decoded service 1 failure report of a service 18 request, explained:
    ``{"obcp"}`` for an unknown OBCP, ``{"reason", "obcp"}`` for a refusal, ``{"kind",
    "line", "column", "message"}`` for a procedure that did not load, ``{"path"}`` for a
    filestore failure; None for other codes or data that does not decode."""
    code = report.get("code")
    data = report.get("data") or b""
    try:
        if code == FAILURE_UNKNOWN_ID:
            return {"obcp": lay.ID.unpack(data)["id"]}
        if code == FAILURE_REFUSED:
            v = lay.REFUSAL.unpack(data)
            return {"reason": _name(lay.REASONS, v["reason"]), "obcp": v["id"]}
        if code == FAILURE_OBCP_REJECTED:
            v = lay.REJECTION.unpack(data)
            v["kind"] = _name(lay.KINDS, v["kind"])
            return v
        if code == FAILURE_PATH or code == FAILURE_FILESTORE:
            return {"path": lay.PATH.unpack(data)}
    except (ValueError, KeyError, IndexError, TypeError):
        return None
    return None
