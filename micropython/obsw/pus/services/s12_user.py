"""The ST[12] on-board monitoring user: definitions sent, reports decoded.

``limit_check``, ``expected_value_check`` and ``delta_check`` build definitions; checks and
statuses are the numbers of ``obsw.pus.services.s12_layouts``. Functional monitoring is
``obsw.pus.services.s12_functional_user``.
"""

from obsw.pus.messages import (
    SERVICE_ON_BOARD_MONITORING,
    TC_MON_ADD_PARAMETER_MONITORING,
    TC_MON_CHANGE_TRANSITION_DELAY,
    TC_MON_DELETE_ALL_PARAMETER_MONITORING,
    TC_MON_DELETE_PARAMETER_MONITORING,
    TC_MON_DISABLE_PARAMETER_MONITORING,
    TC_MON_DISABLE_PARAMETER_MONITORING_FUNCTION,
    TC_MON_ENABLE_PARAMETER_MONITORING,
    TC_MON_ENABLE_PARAMETER_MONITORING_FUNCTION,
    TC_MON_MODIFY_PARAMETER_MONITORING,
    TC_MON_REPORT_OUT_OF_LIMITS,
    TC_MON_REPORT_PARAMETER_MONITORING,
    TC_MON_REPORT_PARAMETER_MONITORING_STATUS,
    TM_MON_CHECK_TRANSITION_REPORT,
    TM_MON_OUT_OF_LIMITS_REPORT,
    TM_MON_PARAMETER_MONITORING_REPORT,
    TM_MON_PARAMETER_MONITORING_STATUS_REPORT,
)
from obsw.pus.services.base import ServiceUser
from obsw.pus.services.s12_layouts import (
    CHECK_DELTA,
    CHECK_EXPECTED_VALUE,
    CHECK_LIMIT,
    DELAY_LAYOUT,
    IDS,
    STATUS_REPORT,
    Layouts,
)


class OnBoardMonitoringUser(ServiceUser):
    """The service 12 user; ``types(pid)`` gives parameter field types and ``ids(name)``
    parameter IDs (both the database's).

    A definition is a dict as in ``obsw.pus.services.s12_layouts`` (keys ``pmon``,
    ``parameter``, ``check``, ...); ``limit_check`` and friends build the common ones.
    """

    SERVICE = SERVICE_ON_BOARD_MONITORING
    DECODERS = (
        (TM_MON_PARAMETER_MONITORING_REPORT, "decode_definitions"),
        (TM_MON_OUT_OF_LIMITS_REPORT, "decode_transitions"),
        (TM_MON_CHECK_TRANSITION_REPORT, "decode_transitions"),
        (TM_MON_PARAMETER_MONITORING_STATUS_REPORT, "decode_status"),
    )

    def __init__(self, types, ids=None):
        super().__init__()
        self.layouts = Layouts(types)
        self.ids = ids  # qualified name -> parameter ID

    def _complete(self, d):
        d = _complete(d)
        for key in ("parameter", "validity"):
            if not isinstance(d[key], int) and self.ids is not None:
                d[key] = self.ids(d[key])
        return d

    def add(self, apid, definitions):
        items = [self._complete(d) for d in definitions]
        return self.request(
            apid, TC_MON_ADD_PARAMETER_MONITORING, self.layouts.add.pack({"items": items})
        )

    def modify(self, apid, definitions):
        items = [self._complete(d) for d in definitions]
        data = self.layouts.modify.pack({"items": items})
        return self.request(apid, TC_MON_MODIFY_PARAMETER_MONITORING, data)

    def _ids(self, message_type, apid, ids, expect=None):
        return self.request(apid, message_type, IDS.pack({"ids": list(ids)}), expect)

    def delete(self, apid, ids):
        return self._ids(TC_MON_DELETE_PARAMETER_MONITORING, apid, ids)

    def delete_all(self, apid):
        return self.request(apid, TC_MON_DELETE_ALL_PARAMETER_MONITORING)

    def enable(self, apid, ids):
        return self._ids(TC_MON_ENABLE_PARAMETER_MONITORING, apid, ids)

    def disable(self, apid, ids):
        return self._ids(TC_MON_DISABLE_PARAMETER_MONITORING, apid, ids)

    def change_delay(self, apid, delay):
        data = DELAY_LAYOUT.pack({"delay": delay})
        return self.request(apid, TC_MON_CHANGE_TRANSITION_DELAY, data)

    def enable_function(self, apid):
        return self.request(apid, TC_MON_ENABLE_PARAMETER_MONITORING_FUNCTION)

    def disable_function(self, apid):
        return self.request(apid, TC_MON_DISABLE_PARAMETER_MONITORING_FUNCTION)

    def report_definitions(self, apid, ids=()):
        return self._ids(
            TC_MON_REPORT_PARAMETER_MONITORING, apid, ids, TM_MON_PARAMETER_MONITORING_REPORT
        )

    def report_out_of_limits(self, apid):
        return self.request(apid, TC_MON_REPORT_OUT_OF_LIMITS, b"", TM_MON_OUT_OF_LIMITS_REPORT)

    def report_status(self, apid):
        return self.request(
            apid,
            TC_MON_REPORT_PARAMETER_MONITORING_STATUS,
            b"",
            TM_MON_PARAMETER_MONITORING_STATUS_REPORT,
        )

    def decode_definitions(self, tm):
        out = self.layouts.report.unpack(tm.data)
        for d in out["items"]:
            d["enabled"] = bool(d["enabled"])
        return out

    def decode_transitions(self, tm):
        items = self.layouts.transitions.unpack(tm.data)["items"]
        for i in items:
            c, f = i["time"]
            i["time"] = c + f / 65536
        return {"items": items}

    def decode_status(self, tm):
        items = STATUS_REPORT.unpack(tm.data)["items"]
        for i in items:
            i["enabled"] = bool(i["enabled"])
        return {"items": items}


def _complete(d):
    """A definition with the optional fields filled in (no validity check, no events)."""
    out = {
        "validity": 0,
        "validity_mask": 0,
        "validity_value": 0,
        "interval": 1,
        "repetitions": 1,
    }
    if d["check"] == CHECK_EXPECTED_VALUE:
        out["event"] = 0
    else:
        out["low_event"] = 0
        out["high_event"] = 0
    out.update(d)
    return out


def limit_check(pmon, parameter, low, high, low_event=0, high_event=0, **options):
    """A limit-check definition (``options``: interval, repetitions, validity...)."""
    d = {"pmon": pmon, "parameter": parameter, "check": CHECK_LIMIT, "low": low, "high": high}
    d.update(low_event=low_event, high_event=high_event, **options)
    return d


def expected_value_check(pmon, parameter, expected, mask=0xFFFFFFFF, event=0, **options):
    d = {"pmon": pmon, "parameter": parameter, "check": CHECK_EXPECTED_VALUE}
    d.update(mask=mask, expected=expected, event=event, **options)
    return d


def delta_check(pmon, parameter, low, high, consecutive=1, low_event=0, high_event=0, **options):
    d = {"pmon": pmon, "parameter": parameter, "check": CHECK_DELTA, "low": low, "high": high}
    d.update(consecutive=consecutive, low_event=low_event, high_event=high_event, **options)
    return d
