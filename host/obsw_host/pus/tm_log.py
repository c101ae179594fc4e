"""The on-board process's log, from the TM it sends: one line per TC accepted or failed and
per event (standard ``logging``, logger ``obsw.onboard``; level set by ``obsw --log-level``).

Activities that services 11, 21, 22 and 19 release are TCs like any other: their acceptance,
failure and completion appear here, so a failed scheduled TC is visible on board too.
"""

import logging

from obsw.pus.services.s01_verification import VerificationUser, describe
from obsw.pus.services.s05_events import EventUser
from obsw.pus.tm import PusTm

LOG = logging.getLogger("obsw.onboard")
_EVENT_LEVELS = {1: logging.INFO, 2: logging.WARNING, 3: logging.WARNING, 4: logging.ERROR}


class TmLog:
    """Logs verification reports and events of the TM passed to ``tm(raw)``."""

    def __init__(self, sdb=None, logger=LOG):
        self.logger = logger
        self.verification = VerificationUser()
        self.events = EventUser(sdb.event if sdb is not None else None)

    def tm(self, raw):
        log = self.logger
        if not log.isEnabledFor(logging.INFO):
            return
        try:
            tm = PusTm.unpack(raw)
            if tm.service == 1:
                self._verification(tm)
            elif tm.service == 5 and tm.subtype in _EVENT_LEVELS:
                self._event(tm)
            else:
                log.debug("TM[%d,%d] %d bytes", tm.service, tm.subtype, len(tm.data))
        except (ValueError, KeyError, IndexError) as e:
            log.warning("TM not logged: %s", e)

    def _verification(self, tm):
        report = self.verification.decode_report(tm)
        rid = report["request_id"]
        what = "TC apid %d seq %d" % (rid.apid, rid.seq_count)
        if not report["success"]:
            self.logger.warning("%s: %s", what, describe(report))
        elif report["stage"] == 1:
            self.logger.info("%s accepted", what)
        else:
            self.logger.debug("%s: %s", what, describe(report))

    def _event(self, tm):
        ev = self.events.decode_event(tm)
        name = ev.get("event", "event %d" % ev["id"])
        data = ev.get("labelled", ev["data"])
        if isinstance(data, dict):
            data = ", ".join("%s=%s" % kv for kv in data.items())
        elif isinstance(data, (bytes, bytearray)):
            data = bytes(data).hex()
        self.logger.log(
            _EVENT_LEVELS[tm.subtype],
            "event %s (%s)%s",
            name,
            ev["severity"],
            data and ": " + data,
        )
