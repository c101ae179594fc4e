"""The mission's initial service 12 monitoring: limit checks installed at the OBC's first start.

The mission file's ``pus.monitoring`` lists limit checks by parameter and event name::

    {"pmon": 43, "parameter": "Obc.temperature", "low": -40, "high": 80,
     "low_event": "monitoring.obc_low", "high_event": "monitoring.obc_high",
     "interval": 10, "repetitions": 3, "enabled": true}

``low`` and ``high`` are engineering values, as in the database (its ``calibration``, its unit):
they become the raw limits a limit check compares the raw value with, exactly as the ground's
``obsw ground monitor add`` converts them (``Parameter.raw_limits``); a falling calibration
swaps the two limits and so the two events.

They are installed, enabled, when service 12 has no saved state (a fresh state folder); after
that the operators own the definitions (TC[12,5], [12,6], ...) and the context store keeps
theirs across restarts, so a deleted or changed definition stays deleted or changed.
"""

from obsw.pus.services.s12_monitoring import Pmon
from obsw.pus.services.s12_user import limit_check

from obsw_host.mission.config import ConfigError


class MonitoringError(ConfigError):
    """An entry of ``pus.monitoring`` that cannot be monitored: its index and why (a mistake
    in the mission: the process refuses to start, exit status 2)."""

    def __init__(self, index, why):
        super().__init__("pus.monitoring[%d]" % index, why)
        self.index = index


def definition(sdb, index, entry):
    """The complete limit-check definition of one ``pus.monitoring`` entry."""
    try:
        p = sdb.parameter(entry["parameter"])
        low_event = sdb.event(entry["low_event"]).id if entry.get("low_event") else 0
        high_event = sdb.event(entry["high_event"]).id if entry.get("high_event") else 0
        low, high, swapped = p.raw_limits(entry["low"], entry["high"])
        if swapped:  # a falling calibration: the low raw limit is the high engineering one
            low_event, high_event = high_event, low_event
        d = limit_check(int(entry["pmon"]), p.id, low, high, low_event, high_event)
    except KeyError as e:
        raise MonitoringError(index, "unknown or missing %s" % e) from None
    except (TypeError, ValueError) as e:  # CalibrationError is a ValueError
        raise MonitoringError(index, str(e)) from None
    pid = p.id
    d.update(
        validity=pid,
        validity_mask=0,
        validity_value=0,
        interval=int(entry.get("interval", 1)),
        repetitions=int(entry.get("repetitions", 1)),
    )
    return d


def install(app, sdb, entries):
    """Install ``entries`` on ``app``'s service 12 if it has no saved state; returns how many.
    Raises ``MonitoringError`` naming the first entry that cannot be monitored."""
    s12 = app.services.get(12)
    if s12 is None or not entries:
        return 0
    if app.store is not None and app.store.load(s12.NAME) is not None:
        return 0  # the operators' definitions, kept across restarts
    pmons = {}
    for i, entry in enumerate(entries):
        d = definition(sdb, i, entry)
        if d["pmon"] in pmons:
            raise MonitoringError(i, "PMON %d twice" % d["pmon"])
        try:
            s12.check_definition(d)
        except Exception as e:  # PusFailure: what a TC[12,5] would be refused for
            raise MonitoringError(i, str(e)) from None
        pmons[d["pmon"]] = Pmon(d, bool(entry.get("enabled", True)))
    s12.pmons.update(pmons)
    s12.persist()
    return len(pmons)
