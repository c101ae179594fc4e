"""ST[04] parameter statistics reporting: minimum, maximum, mean and standard deviation.

Each statistics definition samples one numeric parameter of the pool every ``sampling
interval`` cycles of the application process (ECSS-E-ST-70-41C 6.4). A report (on request,
TC[4,1], or periodic every ``reporting interval`` cycles once enabled) gives, for the
interval since the last reset, the number of samples, the maximum and minimum with the time
each was seen, the mean and the standard deviation. Periodic reports reset the statistics;
a requested one does when its reset flag is set. Minimum and maximum travel in the
parameter's own type, mean and standard deviation as 64-bit reals. Definitions and the
periodic reporting state persist in the context store.
"""

import math

from obsw.pus.fields import field
from obsw.pus.messages import (
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
    SERVICE_PARAMETER_STATISTICS,
    TC_STATS_ADD_DEFINITIONS,
    TC_STATS_DELETE_DEFINITIONS,
    TC_STATS_DISABLE_PERIODIC,
    TC_STATS_ENABLE_PERIODIC,
    TC_STATS_REPORT,
    TC_STATS_REPORT_DEFINITIONS,
    TC_STATS_RESET,
    TM_STATS_DEFINITIONS_REPORT,
    TM_STATS_REPORT,
)
from obsw.pus.services.base import BOOL8, PARAMETER_ID, U16, U32, Service, ServiceUser
from obsw.pus.services.s01_verification import PusFailure
from obsw.pus.structure import Repeated, Structure

TIME_TAG = field(9, 17)  # absolute time, CUC 4+2 octets like the TM time field
REAL64 = field(5, 2)
INTERVAL = U16  # in cycles of the application process
COUNT = U16
_NUMERIC = (2, 3, 4, 5)  # PTCs with an order and a mean

EMPTY = Structure([])
REPORT_REQUEST = Structure([("reset", BOOL8)])
PERIODIC = Structure([("interval", INTERVAL)])
DEFINITIONS = Structure(
    [("items", Repeated(COUNT, [("id", PARAMETER_ID), ("interval", INTERVAL)]))]
)
IDS = Structure([("ids", Repeated(COUNT, PARAMETER_ID))])
DEFINITIONS_REPORT = Structure(
    [
        ("interval", INTERVAL),
        ("items", Repeated(COUNT, [("id", PARAMETER_ID), ("interval", INTERVAL)])),
    ]
)


def report_layout(types):
    """TM[4,2]: start and end time, then per parameter its samples and statistics."""
    value = lambda: field(11, 0, key="id", lookup=types)  # noqa: E731
    return Structure(
        [
            ("start", TIME_TAG),
            ("end", TIME_TAG),
            (
                "items",
                Repeated(
                    COUNT,
                    [
                        ("id", PARAMETER_ID),
                        ("samples", U32),
                        ("max", value()),
                        ("max_time", TIME_TAG),
                        ("min", value()),
                        ("min_time", TIME_TAG),
                        ("mean", REAL64),
                        ("stddev", REAL64),
                    ],
                ),
            ),
        ]
    )


class Statistic:
    """The running statistics of one parameter."""

    __slots__ = ("pid", "interval", "countdown", "n", "min", "min_t", "max", "max_t", "s", "ss")

    def __init__(self, pid, interval):
        self.pid = pid
        self.interval = interval
        self.countdown = interval
        self.reset()

    def reset(self):
        self.n = 0
        self.min = self.max = None
        self.min_t = self.max_t = 0.0
        self.s = 0.0
        self.ss = 0.0

    def add(self, v, t):
        self.n += 1
        if self.min is None or v < self.min:
            self.min, self.min_t = v, t
        if self.max is None or v > self.max:
            self.max, self.max_t = v, t
        self.s += v
        self.ss += v * v

    def mean(self):
        return self.s / self.n if self.n else 0.0

    def stddev(self):
        if self.n < 2:
            return 0.0
        m = self.s / self.n
        var = self.ss / self.n - m * m
        return math.sqrt(var) if var > 0 else 0.0


class ParameterStatistics(Service):
    """The service 4 provider, sampling a ``ParameterPool``."""

    SERVICE = SERVICE_PARAMETER_STATISTICS
    REPORTS = (TM_STATS_REPORT, TM_STATS_DEFINITIONS_REPORT)
    NAME = "s04"
    HANDLERS = (
        (TC_STATS_REPORT, "report"),
        (TC_STATS_RESET, "reset"),
        (TC_STATS_ENABLE_PERIODIC, "enable_periodic"),
        (TC_STATS_DISABLE_PERIODIC, "disable_periodic"),
        (TC_STATS_ADD_DEFINITIONS, "add_definitions"),
        (TC_STATS_DELETE_DEFINITIONS, "delete_definitions"),
        (TC_STATS_REPORT_DEFINITIONS, "report_definitions"),
    )

    def __init__(self, pool, max_definitions=32, reporting_interval=10):
        super().__init__()
        self.pool = pool
        self.max_definitions = max_definitions
        self.stats = {}  # pid -> Statistic
        self.periodic = False
        self.reporting_interval = reporting_interval
        self.countdown = reporting_interval
        self.start = None  # on-board time of the last reset
        self.layout = report_layout(self._type)

    def _type(self, pid):
        try:
            return self.pool.type_of(pid)
        except KeyError:
            return None

    def attach(self, app):
        super().attach(app)
        self.start = app.time()

    # -------------------------------------------------------------------------- context

    def context(self):
        return [
            self.periodic,
            self.reporting_interval,
            [[s.pid, s.interval] for s in self.stats.values()],
        ]

    def restore(self, ctx):
        periodic, interval, defs = ctx
        stats = {}
        for pid, n in defs:
            if pid not in self.pool:
                raise KeyError(pid)
            stats[pid] = Statistic(pid, n)
        self.periodic, self.reporting_interval, self.stats = bool(periodic), interval, stats
        self.countdown = interval

    # -------------------------------------------------------------------------- sampling

    def sample(self, now=None):
        """Take one sample of every definition due (what ``cyclic`` does each cycle)."""
        t = self.app.time()
        get = self.pool.get
        for s in self.stats.values():
            s.countdown -= 1
            if s.countdown <= 0:
                s.countdown = s.interval or 1
                v = get(s.pid)
                if isinstance(v, (int, float)):
                    s.add(v, t)

    def cyclic(self, now):
        self.sample(now)
        if self.periodic:
            self.countdown -= 1
            if self.countdown <= 0:
                self.countdown = self.reporting_interval
                self.generate()
                self._reset_all()

    def _reset_all(self):
        for s in self.stats.values():
            s.reset()
        self.start = self.app.time()

    def _report_data(self):
        items = []
        for s in self.stats.values():
            zero = 0.0 if self._type(s.pid).ptc == 5 else 0
            items.append(
                {
                    "id": s.pid,
                    "samples": s.n,
                    "max": s.max if s.max is not None else zero,
                    "max_time": s.max_t,
                    "min": s.min if s.min is not None else zero,
                    "min_time": s.min_t,
                    "mean": s.mean(),
                    "stddev": s.stddev(),
                }
            )
        return self.layout.pack({"start": self.start, "end": self.app.time(), "items": items})

    def generate(self, destination=0):
        """Send a TM[4,2] for every definition now."""
        return self.send(TM_STATS_REPORT, self._report_data(), destination)

    # -------------------------------------------------------------------------- handlers

    def report(self, req):
        reset = req.decode(REPORT_REQUEST)["reset"]
        req.report(TM_STATS_REPORT, self._report_data())
        if reset:
            self._reset_all()

    def reset(self, req):
        req.decode(EMPTY)
        req.start()
        self._reset_all()

    def enable_periodic(self, req):
        interval = req.decode(PERIODIC)["interval"]
        if interval == 0:
            raise PusFailure(FAILURE_REFUSED, "reporting interval 0")
        req.start()
        self.periodic = True
        self.reporting_interval = interval
        self.countdown = interval
        self.persist()

    def disable_periodic(self, req):
        req.decode(EMPTY)
        req.start()
        self.periodic = False
        self.persist()

    def add_definitions(self, req):
        items = req.decode(DEFINITIONS)["items"]
        new = 0
        for i in items:
            pid = i["id"]
            if pid not in self.pool:
                raise PusFailure(
                    FAILURE_UNKNOWN_ID, "no parameter %d" % pid, PARAMETER_ID.pack(pid)
                )
            if self.pool.type_of(pid).ptc not in _NUMERIC:
                raise PusFailure(
                    FAILURE_REFUSED, "parameter %d is not numeric" % pid, PARAMETER_ID.pack(pid)
                )
            if pid not in self.stats:
                new += 1
        if len(self.stats) + new > self.max_definitions:
            raise PusFailure(FAILURE_REFUSED, "at most %d definitions" % self.max_definitions)
        req.start()
        for i in items:
            s = self.stats.get(i["id"])
            if s is None:
                self.stats[i["id"]] = Statistic(i["id"], i["interval"])
            else:
                s.interval = s.countdown = i["interval"]
        self.persist()

    def delete_definitions(self, req):
        ids = req.decode(IDS)["ids"]
        for pid in ids:
            if pid not in self.stats:
                raise PusFailure(
                    FAILURE_UNKNOWN_ID,
                    "no statistics of parameter %d" % pid,
                    PARAMETER_ID.pack(pid),
                )
        req.start()
        if not ids:
            self.stats = {}
        for pid in ids:
            del self.stats[pid]
        self.persist()

    def report_definitions(self, req):
        req.decode(EMPTY)
        items = [{"id": s.pid, "interval": s.interval} for s in self.stats.values()]
        data = DEFINITIONS_REPORT.pack(
            {"interval": self.reporting_interval if self.periodic else 0, "items": items}
        )
        req.report(TM_STATS_DEFINITIONS_REPORT, data)


class StatisticsUser(ServiceUser):
    """The service 4 user; ``types(pid)`` and ``names(pid)`` come from the database."""

    SERVICE = SERVICE_PARAMETER_STATISTICS
    DECODERS = (
        (TM_STATS_REPORT, "decode_report"),
        (TM_STATS_DEFINITIONS_REPORT, "decode_definitions"),
    )

    def __init__(self, types, names=None, ids=None):
        super().__init__()
        self.names = names
        self.ids = ids
        self.layout = report_layout(types)

    def _id(self, key):
        return key if isinstance(key, int) or self.ids is None else self.ids(key)

    def report(self, apid, reset=False):
        data = REPORT_REQUEST.pack({"reset": bool(reset)})
        return self.request(apid, TC_STATS_REPORT, data, TM_STATS_REPORT)

    def reset(self, apid):
        return self.request(apid, TC_STATS_RESET)

    def enable_periodic(self, apid, interval):
        return self.request(apid, TC_STATS_ENABLE_PERIODIC, PERIODIC.pack({"interval": interval}))

    def disable_periodic(self, apid):
        return self.request(apid, TC_STATS_DISABLE_PERIODIC)

    def add_definitions(self, apid, definitions):
        """``definitions`` maps parameter IDs or names to sampling intervals (cycles)."""
        items = [{"id": self._id(k), "interval": v} for k, v in definitions.items()]
        return self.request(apid, TC_STATS_ADD_DEFINITIONS, DEFINITIONS.pack({"items": items}))

    def delete_definitions(self, apid, keys=()):
        data = IDS.pack({"ids": [self._id(k) for k in keys]})
        return self.request(apid, TC_STATS_DELETE_DEFINITIONS, data)

    def report_definitions(self, apid):
        return self.request(apid, TC_STATS_REPORT_DEFINITIONS, b"", TM_STATS_DEFINITIONS_REPORT)

    def decode_report(self, tm):
        out = self.layout.unpack(tm.data)
        out["start"] = TIME_TAG.seconds(out["start"])
        out["end"] = TIME_TAG.seconds(out["end"])
        stats = {}
        for i in out.pop("items"):
            i["max_time"] = TIME_TAG.seconds(i["max_time"])
            i["min_time"] = TIME_TAG.seconds(i["min_time"])
            pid = i.pop("id")
            stats[self.names(pid) if self.names else pid] = i
        out["statistics"] = stats
        return out

    def decode_definitions(self, tm):
        out = DEFINITIONS_REPORT.unpack(tm.data)
        out["items"] = {
            (self.names(i["id"]) if self.names else i["id"]): i["interval"] for i in out["items"]
        }
        return out
