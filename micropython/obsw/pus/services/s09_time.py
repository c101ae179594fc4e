"""ST[09] time management: time reports, CUC or CDS, at a rate the ground sets.

The mission chooses the on-board time format once (``code``): TM[9,2] CUC time reports carry
the report rate exponent, the on-board time as a CUC (4 coarse, 2 fine octets) and the time
reference status; TM[9,3] CDS time reports carry the same with the time as a CDS (16-bit day,
32-bit millisecond of day: PTC 9 PFC 1, CCSDS 301.0-B-4 3.3). Both count from the TM time
code's epoch. TC[9,1] sets the rate: a report goes out every ``2 ** exponent`` seconds of
on-board time (exponent 0 to ``MAX_EXPONENT``; above, the start of execution fails with
``FAILURE_REFUSED`` and the rate is unchanged), the first on the cycle after the rate is set.
Until a rate is set (``exponent`` None) no report goes out. The exponent persists in the
context store.
"""

from obsw.pus.fields import field
from obsw.pus.messages import (
    SERVICE_TIME_MANAGEMENT,
    TC_TIME_SET_REPORT_RATE,
    TM_TIME_CDS_REPORT,
    TM_TIME_CUC_REPORT,
)
from obsw.pus.ptc_time import cuc_pfc
from obsw.pus.services.base import E8, U8, Service, ServiceUser
from obsw.pus.services.s01_verification import FAILURE_REFUSED, PusFailure
from obsw.pus.structure import Structure

MAX_EXPONENT = 16  # once every 18 hours at the slowest
RATE = Structure([("exponent", U8)])
CUC_4_2 = field(9, cuc_pfc(4, 2))
CDS_SHORT = field(9, 1)
TIME_REPORT = Structure([("exponent", U8), ("time", CUC_4_2), ("status", E8)])
CDS_TIME_REPORT = Structure([("exponent", U8), ("time", CDS_SHORT), ("status", E8)])
CODES = {"cuc": (TM_TIME_CUC_REPORT, TIME_REPORT), "cds": (TM_TIME_CDS_REPORT, CDS_TIME_REPORT)}


class TimeManagement(Service):
    """The service 9 provider; ``exponent`` is the initial report rate exponent (None: no
    reports until the ground sets a rate), ``code`` the time format, "cuc" or "cds"."""

    SERVICE = SERVICE_TIME_MANAGEMENT
    REPORTS = (TM_TIME_CUC_REPORT, TM_TIME_CDS_REPORT)
    NAME = "s09"
    HANDLERS = ((TC_TIME_SET_REPORT_RATE, "set_rate"),)

    def __init__(self, exponent=None, code="cuc"):
        super().__init__()
        if code not in CODES:
            raise ValueError("time report code %r; expected one of %s" % (code, sorted(CODES)))
        self.exponent = exponent
        self.code = code
        self._next = None
        self.reports = 0

    def context(self):
        return self.exponent

    def restore(self, ctx):
        if ctx is not None and not 0 <= int(ctx) <= MAX_EXPONENT:
            raise ValueError("time report exponent %r" % ctx)
        self.exponent = ctx

    def set_rate(self, req):
        exponent = req.decode(RATE)["exponent"]
        if exponent > MAX_EXPONENT:
            raise PusFailure(FAILURE_REFUSED, "rate exponent above %d" % MAX_EXPONENT)
        req.start()
        self.exponent = exponent
        self._next = None
        self.persist()

    def time_report(self, destination=0):
        message_type, layout = CODES[self.code]
        data = layout.pack(
            {"exponent": self.exponent or 0, "time": self.app.time(), "status": self.app.time_ref}
        )
        self.reports += 1
        return self.send(message_type, data, destination)

    def cyclic(self, now):
        if self.exponent is None:
            return
        t = self.app.time()
        if self._next is None or t >= self._next:
            period = 1 << self.exponent
            self._next = (t if self._next is None else self._next) + period
            if self._next <= t:  # fell far behind (time was set forward): start afresh
                self._next = t + period
            self.time_report()


class TimeUser(ServiceUser):
    """The service 9 user; decoded times are seconds of the TM time code's epoch."""

    SERVICE = SERVICE_TIME_MANAGEMENT
    DECODERS = ((TM_TIME_CUC_REPORT, "decode_time"), (TM_TIME_CDS_REPORT, "decode_cds_time"))

    def set_rate(self, apid, exponent):
        return self.request(apid, TC_TIME_SET_REPORT_RATE, RATE.pack({"exponent": exponent}))

    def decode_time(self, tm):
        out = TIME_REPORT.unpack(tm.data)
        coarse, fine = out["time"]
        out["time"] = coarse + fine / 65536
        return out

    def decode_cds_time(self, tm):
        out = CDS_TIME_REPORT.unpack(tm.data)
        day, ms = out["time"][:2]
        out["time"] = day * 86400 + ms / 1000
        return out
