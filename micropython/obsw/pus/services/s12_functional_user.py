"""The ST[12] functional monitoring user: FMON requests sent, their reports decoded.

``FunctionalMonitoringUser`` is ``OnBoardMonitoringUser`` (parameter monitoring) with every
functional monitoring request (TC[12,17] to TC[12,27]) and the decoders of TM[12,26] and
TM[12,28]; ``functional_check`` builds a definition.
"""

from obsw.pus.messages import (
    TC_MON_ADD_FUNCTIONAL_MONITORING,
    TC_MON_DELETE_FUNCTIONAL_MONITORING,
    TC_MON_DISABLE_FUNCTIONAL_MONITORING,
    TC_MON_DISABLE_FUNCTIONAL_MONITORING_FUNCTION,
    TC_MON_ENABLE_FUNCTIONAL_MONITORING,
    TC_MON_ENABLE_FUNCTIONAL_MONITORING_FUNCTION,
    TC_MON_PROTECT_FUNCTIONAL_MONITORING,
    TC_MON_REPORT_FUNCTIONAL_MONITORING,
    TC_MON_REPORT_FUNCTIONAL_MONITORING_STATUS,
    TC_MON_UNPROTECT_FUNCTIONAL_MONITORING,
    TM_MON_FUNCTIONAL_MONITORING_REPORT,
    TM_MON_FUNCTIONAL_MONITORING_STATUS_REPORT,
)
from obsw.pus.services.s12_layouts import FMON_STATUS_NAMES, fmon_layouts
from obsw.pus.services.s12_user import OnBoardMonitoringUser


class FunctionalMonitoringUser(OnBoardMonitoringUser):
    """The service 12 user with functional monitoring (see the module text)."""

    DECODERS = OnBoardMonitoringUser.DECODERS + (
        (TM_MON_FUNCTIONAL_MONITORING_REPORT, "decode_functional"),
        (TM_MON_FUNCTIONAL_MONITORING_STATUS_REPORT, "decode_functional_status"),
    )

    def enable_functional_function(self, apid):
        return self.request(apid, TC_MON_ENABLE_FUNCTIONAL_MONITORING_FUNCTION)

    def disable_functional_function(self, apid):
        return self.request(apid, TC_MON_DISABLE_FUNCTIONAL_MONITORING_FUNCTION)

    def _fmons(self, message_type, apid, ids, expect=None):
        return self.request(
            apid, message_type, fmon_layouts().ids.pack({"ids": list(ids)}), expect
        )

    def enable_functional(self, apid, ids):
        return self._fmons(TC_MON_ENABLE_FUNCTIONAL_MONITORING, apid, ids)

    def disable_functional(self, apid, ids):
        return self._fmons(TC_MON_DISABLE_FUNCTIONAL_MONITORING, apid, ids)

    def protect_functional(self, apid, ids):
        return self._fmons(TC_MON_PROTECT_FUNCTIONAL_MONITORING, apid, ids)

    def unprotect_functional(self, apid, ids):
        return self._fmons(TC_MON_UNPROTECT_FUNCTIONAL_MONITORING, apid, ids)

    def add_functional(self, apid, definitions):
        """TC[12,23] for definitions built with ``functional_check``."""
        items = []
        for d in definitions:
            d = dict(d)
            if not isinstance(d["validity"], int) and self.ids is not None:
                d["validity"] = self.ids(d["validity"])
            items.append(d)
        data = fmon_layouts().add.pack({"items": items})
        return self.request(apid, TC_MON_ADD_FUNCTIONAL_MONITORING, data)

    def delete_functional(self, apid, ids):
        return self._fmons(TC_MON_DELETE_FUNCTIONAL_MONITORING, apid, ids)

    def report_functional(self, apid, ids=()):
        return self._fmons(
            TC_MON_REPORT_FUNCTIONAL_MONITORING, apid, ids, TM_MON_FUNCTIONAL_MONITORING_REPORT
        )

    def report_functional_status(self, apid):
        return self.request(
            apid,
            TC_MON_REPORT_FUNCTIONAL_MONITORING_STATUS,
            b"",
            TM_MON_FUNCTIONAL_MONITORING_STATUS_REPORT,
        )

    def decode_functional(self, tm):
        items = fmon_layouts().report.unpack(tm.data)["items"]
        for d in items:
            d["enabled"] = bool(d["enabled"])
            d["protected"] = bool(d["protected"])
        return {"functional": items}

    def decode_functional_status(self, tm):
        items = fmon_layouts().status.unpack(tm.data)["items"]
        for d in items:
            d["enabled"] = bool(d["enabled"])
            d["protected"] = bool(d["protected"])
            d["checking"] = FMON_STATUS_NAMES.get(d["checking"], d["checking"])
        return {"functional": items}


def functional_check(fmon, pmons, failing=1, event=0, validity=0, mask=0, expected=0):
    """A functional monitoring definition: it fails when ``failing`` of ``pmons`` are out of
    limits (while ``validity`` masked with ``mask`` equals ``expected``; mask 0: always)."""
    return {
        "fmon": fmon,
        "validity": validity,
        "validity_mask": mask,
        "validity_value": expected,
        "event": event,
        "failing": failing,
        "pmons": list(pmons),
    }
