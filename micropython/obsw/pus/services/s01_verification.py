"""ST[01] request verification: acceptance, start, progress and completion reports.

The provider has no TCs of its own: the application process calls it for every request
(``obsw.pus.app.Request``). A report carries the request ID (the TC's first two header
words), a step ID for progress reports, and for failures a failure code and its data.
The user decodes the reports; the ground process matches them to its transactions.
"""

from obsw.compat import const
from obsw.pus.messages import (
    FAILURE_ABORTED,
    FAILURE_BUSY,
    FAILURE_COMPONENT,
    FAILURE_EXECUTION,
    FAILURE_FILESTORE,
    FAILURE_ILLEGAL_APP_DATA,
    FAILURE_OBCP_REJECTED,
    FAILURE_OUT_OF_BOUNDS,
    FAILURE_OUT_OF_RANGE,
    FAILURE_PATH,
    FAILURE_READBACK,
    FAILURE_REFUSED,
    FAILURE_TIMEOUT,
    FAILURE_UNAVAILABLE,
    FAILURE_UNKNOWN_ID,
    FAILURE_WRITE_PROTECTED,
    SERVICE_VERIFICATION,
    TM_VERIFY_ACCEPTANCE_FAILURE,
    TM_VERIFY_ACCEPTANCE_SUCCESS,
    TM_VERIFY_COMPLETION_FAILURE,
    TM_VERIFY_COMPLETION_SUCCESS,
    TM_VERIFY_PROGRESS_FAILURE,
    TM_VERIFY_PROGRESS_SUCCESS,
    TM_VERIFY_ROUTING_FAILURE,
    TM_VERIFY_START_FAILURE,
    TM_VERIFY_START_SUCCESS,
)
from obsw.pus.packets import RequestId
from obsw.pus.services.base import FAILURE_CODE, STEP_ID, Service, ServiceUser

FAILURE_NAMES = {
    0: "illegal APID",
    1: "invalid length",
    2: "incorrect checksum",
    3: "illegal service type",
    4: "illegal subtype",
    5: "illegal application data",
    6: "unsupported header",
    FAILURE_BUSY: "busy",
    FAILURE_EXECUTION: "execution error",
    FAILURE_UNKNOWN_ID: "unknown identifier",
    FAILURE_REFUSED: "refused",
    FAILURE_TIMEOUT: "timeout",
    FAILURE_UNAVAILABLE: "unavailable",
    FAILURE_COMPONENT: "component error",
    FAILURE_PATH: "bad path",
    FAILURE_FILESTORE: "filestore refused",
    FAILURE_OUT_OF_BOUNDS: "out of bounds",
    FAILURE_OBCP_REJECTED: "OBCP rejected",
    FAILURE_ABORTED: "aborted",
    FAILURE_WRITE_PROTECTED: "write-protected",
    FAILURE_READBACK: "read-back mismatch",
    FAILURE_OUT_OF_RANGE: "out of range",
}

# stages of a request, in order
ACCEPTANCE = const(1)
START = const(2)
PROGRESS = const(3)
COMPLETION = const(4)
ROUTING = const(5)

STAGE_NAMES = {
    ACCEPTANCE: "acceptance",
    START: "start",
    PROGRESS: "progress",
    COMPLETION: "completion",
    ROUTING: "routing",
}

# subtype -> (stage, success)
REPORTS = {
    TM_VERIFY_ACCEPTANCE_SUCCESS[1]: (ACCEPTANCE, True),
    TM_VERIFY_ACCEPTANCE_FAILURE[1]: (ACCEPTANCE, False),
    TM_VERIFY_START_SUCCESS[1]: (START, True),
    TM_VERIFY_START_FAILURE[1]: (START, False),
    TM_VERIFY_PROGRESS_SUCCESS[1]: (PROGRESS, True),
    TM_VERIFY_PROGRESS_FAILURE[1]: (PROGRESS, False),
    TM_VERIFY_COMPLETION_SUCCESS[1]: (COMPLETION, True),
    TM_VERIFY_COMPLETION_FAILURE[1]: (COMPLETION, False),
    TM_VERIFY_ROUTING_FAILURE[1]: (ROUTING, False),
}
_SUCCESS = {ACCEPTANCE: 1, START: 3, PROGRESS: 5, COMPLETION: 7}
_FAILURE = {ACCEPTANCE: 2, START: 4, PROGRESS: 6, COMPLETION: 8, ROUTING: 10}


class PusFailure(Exception):
    """Raised by a handler: the request failed with ``code``; ``data`` goes in the report.

    ``step`` names the progress step that failed (a progress failure report) or is None.
    """

    def __init__(self, code, message="", data=b"", step=None):
        super().__init__(message or FAILURE_NAMES.get(code, "failure code %d" % code))
        self.code = code
        self.data = data
        self.step = step


def app_data_error(error):
    """The PusFailure for application data that does not decode."""
    return PusFailure(FAILURE_ILLEGAL_APP_DATA, "application data: %s" % error)


class Verification(Service):
    """The service 1 provider: builds and sends the reports the application process asks."""

    SERVICE = SERVICE_VERIFICATION
    REPORTS = (
        TM_VERIFY_ACCEPTANCE_SUCCESS,
        TM_VERIFY_ACCEPTANCE_FAILURE,
        TM_VERIFY_START_SUCCESS,
        TM_VERIFY_START_FAILURE,
        TM_VERIFY_PROGRESS_SUCCESS,
        TM_VERIFY_PROGRESS_FAILURE,
        TM_VERIFY_COMPLETION_SUCCESS,
        TM_VERIFY_COMPLETION_FAILURE,
        TM_VERIFY_ROUTING_FAILURE,
    )

    def success(self, request_id, stage, destination=0, step=None):
        return self.succeeded(request_id.pack(), stage, destination, step)

    def succeeded(self, rid, stage, destination=0, step=None):
        """``success`` of the request whose ID ``rid`` is packed already (4 octets: a
        request's reports of every stage carry the same, packed once)."""
        if step is not None:
            rid += STEP_ID.pack(step)
        return self.app.send_tm(1, _SUCCESS[stage], rid, destination)

    def failure(self, request_id, stage, code, data=b"", destination=0, step=None):
        return self.failed(request_id.pack(), stage, code, data, destination, step)

    def failed(self, rid, stage, code, data=b"", destination=0, step=None):
        """``failure`` of the request whose ID ``rid`` is packed already."""
        out = rid
        if stage == PROGRESS:
            out += STEP_ID.pack(step or 0)
        out += FAILURE_CODE.pack(code) + bytes(data)
        return self.app.send_tm(1, _FAILURE[stage], out, destination)


class VerificationUser(ServiceUser):
    """The service 1 user: decodes every report into a dict."""

    SERVICE = SERVICE_VERIFICATION
    DECODERS = tuple(
        (mt, "decode_report")
        for mt in (
            TM_VERIFY_ACCEPTANCE_SUCCESS,
            TM_VERIFY_ACCEPTANCE_FAILURE,
            TM_VERIFY_START_SUCCESS,
            TM_VERIFY_START_FAILURE,
            TM_VERIFY_PROGRESS_SUCCESS,
            TM_VERIFY_PROGRESS_FAILURE,
            TM_VERIFY_COMPLETION_SUCCESS,
            TM_VERIFY_COMPLETION_FAILURE,
            TM_VERIFY_ROUTING_FAILURE,
        )
    )

    def decode_report(self, tm):
        stage, ok = REPORTS[tm.subtype]
        data = tm.data
        out = {"request_id": RequestId.unpack(data), "stage": stage, "success": ok}
        pos = 4
        if stage == PROGRESS:
            _need(data, pos + 1)
            out["step"] = STEP_ID.unpack(data[pos:])
            pos += 1
        if not ok:
            _need(data, pos + 1)
            out["code"] = FAILURE_CODE.unpack(data[pos:])
            out["data"] = bytes(data[pos + 1 :])
        elif len(data) != pos:
            raise ValueError("TM[1,%d]: %d trailing bytes" % (tm.subtype, len(data) - pos))
        return out


def _need(data, n):
    if len(data) < n:
        raise ValueError("verification report too short: %d bytes, needs %d" % (len(data), n))


def describe(report):
    """One line for a decoded report: 'completion success' or 'start failure: refused'."""
    text = "%s %s" % (STAGE_NAMES[report["stage"]], "success" if report["success"] else "failure")
    if "step" in report:
        text += " step %d" % report["step"]
    if not report["success"]:
        code = report["code"]
        text += ": %s (code %d)" % (FAILURE_NAMES.get(code, "mission code"), code)
        if report["data"]:
            text += " data %s" % _hex(report["data"])
    return text


def _hex(b):
    return "".join("%02x" % x for x in b)
