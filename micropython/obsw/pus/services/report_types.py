"""Report-type selections shared by ST[14] forwarding and ST[15] storage, and the TM header.

A ``ReportTypes`` selection maps APIDs to services to subtypes; an empty list at a level means
"all" (ECSS-E-ST-70-41C 6.14 and 6.15: N2 = 0 selects every service type of the APID, N3 = 0
every subtype of the service). ``IdSelection`` is the same for housekeeping structure IDs and
event IDs per APID. ``TmHeader`` is what the application process's TM pipeline stages see of
each packet.
"""

from obsw.pus.services.base import APID_FIELD, EVENT_ID, STRUCTURE_ID, U8, U16
from obsw.pus.services.s01_verification import FAILURE_REFUSED, FAILURE_UNKNOWN_ID, PusFailure
from obsw.pus.structure import Repeated, Structure

SERVICE_FIELD = U8
SUBTYPE_FIELD = U8

TYPES = Repeated(
    U8,
    [
        ("apid", APID_FIELD),
        (
            "services",
            Repeated(U8, [("service", SERVICE_FIELD), ("subtypes", Repeated(U8, SUBTYPE_FIELD))]),
        ),
    ],
)
HK_ITEMS = Repeated(U8, [("apid", APID_FIELD), ("ids", Repeated(U8, STRUCTURE_ID))])
EVENT_ITEMS = Repeated(U16, [("apid", APID_FIELD), ("id", EVENT_ID)])
REPORT_TYPES = Structure([("apids", TYPES)])
HK_IDS = Structure([("apids", HK_ITEMS)])
EVENT_IDS = Structure([("items", EVENT_ITEMS)])

_SID = (3, 25)


def _refuse(msg, apid):
    return PusFailure(FAILURE_REFUSED, msg, APID_FIELD.pack(apid))


class ReportTypes:
    """APID -> {service -> set of subtypes}; an empty dict or set means all of that level."""

    def __init__(self):
        self.apids = {}

    def selects(self, apid, service, subtype):
        services = self.apids.get(apid)
        if services is None:
            return False
        if not services:
            return True
        subs = services.get(service)
        if subs is None:
            return False
        return not subs or subtype in subs

    def add(self, apids):
        """Add the decoded ``apids`` list of a TC."""
        for a in apids:
            apid = a["apid"]
            services = self.apids.get(apid)
            if not a["services"]:
                self.apids[apid] = {}  # every service of the APID
                continue
            if services is not None and not services:
                continue  # every service is selected already
            if services is None:
                services = self.apids[apid] = {}
            for s in a["services"]:
                subs = services.get(s["service"])
                if not s["subtypes"]:
                    services[s["service"]] = set()
                    continue
                if subs is not None and not subs:
                    continue  # the whole service is selected already
                if subs is None:
                    subs = services[s["service"]] = set()
                for t in s["subtypes"]:
                    subs.add(t)

    def check_delete(self, apids):
        """Raise PusFailure if a deletion names what is not selected or only part of 'all'."""
        for a in apids:
            apid = a["apid"]
            services = self.apids.get(apid)
            if services is None:
                raise PusFailure(
                    FAILURE_UNKNOWN_ID, "APID %d is not selected" % apid, APID_FIELD.pack(apid)
                )
            for s in a["services"]:
                if not services:
                    raise _refuse("APID %d is selected as a whole" % apid, apid)
                subs = services.get(s["service"])
                if subs is None:
                    raise PusFailure(
                        FAILURE_UNKNOWN_ID,
                        "service %d of APID %d is not selected" % (s["service"], apid),
                        APID_FIELD.pack(apid),
                    )
                if s["subtypes"] and not subs:
                    raise _refuse("service %d is selected as a whole" % s["service"], apid)

    def delete(self, apids):
        self.check_delete(apids)
        for a in apids:
            apid = a["apid"]
            if not a["services"]:
                del self.apids[apid]
                continue
            services = self.apids[apid]
            for s in a["services"]:
                subs = services[s["service"]]
                if not s["subtypes"]:
                    del services[s["service"]]
                    continue
                for t in s["subtypes"]:
                    subs.discard(t)
                if not subs:
                    del services[s["service"]]
            if not services:
                del self.apids[apid]

    def clear(self):
        self.apids = {}

    def as_list(self):
        """The selection in the layout of the TCs and reports (sorted)."""
        out = []
        for apid in sorted(self.apids):
            services = self.apids[apid]
            out.append(
                {
                    "apid": apid,
                    "services": [
                        {"service": s, "subtypes": sorted(services[s])} for s in sorted(services)
                    ],
                }
            )
        return out

    def context(self):
        return [
            [apid, [[s, sorted(subs)] for s, subs in svc.items()]]
            for apid, svc in self.apids.items()
        ]

    def restore(self, ctx):
        apids = {}
        for apid, services in ctx:
            apids[int(apid)] = {int(s): set(subs) for s, subs in services}
        self.apids = apids


class IdSelection:
    """APID -> set of IDs (housekeeping SIDs, event IDs); an empty set means every ID."""

    def __init__(self):
        self.apids = {}

    def has(self, apid, ident):
        ids = self.apids.get(apid)
        return ids is not None and (not ids or ident in ids)

    def listed(self, apid, ident):
        """True when ``ident`` is named explicitly (event blocking lists are never 'all')."""
        ids = self.apids.get(apid)
        return ids is not None and ident in ids

    def add(self, apid, ids):
        cur = self.apids.get(apid)
        if cur is not None and not cur and ids:
            return
        if cur is None or not ids:
            cur = self.apids[apid] = set()
            if not ids:
                return
        for i in ids:
            cur.add(i)

    def check_delete(self, apid, ids):
        cur = self.apids.get(apid)
        if cur is None:
            raise PusFailure(
                FAILURE_UNKNOWN_ID, "APID %d is not selected" % apid, APID_FIELD.pack(apid)
            )
        if ids and not cur:
            raise _refuse("APID %d is selected with every ID" % apid, apid)
        for i in ids:
            if i not in cur:
                raise PusFailure(
                    FAILURE_UNKNOWN_ID, "ID %d of APID %d is not selected" % (i, apid), U16.pack(i)
                )

    def delete(self, apid, ids):
        if not ids:
            self.apids.pop(apid, None)
            return
        cur = self.apids[apid]
        for i in ids:
            cur.discard(i)
        if not cur:
            del self.apids[apid]

    def as_list(self):
        return [{"apid": a, "ids": sorted(self.apids[a])} for a in sorted(self.apids)]

    def pairs(self):
        out = []
        for a in sorted(self.apids):
            for i in sorted(self.apids[a]):
                out.append({"apid": a, "id": i})
        return out

    def context(self):
        return [[a, sorted(ids)] for a, ids in self.apids.items()]

    def restore(self, ctx):
        self.apids = {int(a): set(ids) for a, ids in ctx}


class TmHeader:
    """What the TM pipeline needs from a packed TM, read without decoding the whole packet."""

    __slots__ = ("apid", "service", "subtype", "data")

    def __init__(self, raw, config):
        if len(raw) < config.tm_min_size:
            raise ValueError(
                "TM too short: %d bytes, header needs %d" % (len(raw), config.tm_min_size)
            )
        self.apid = ((raw[0] << 8) | raw[1]) & 0x7FF
        self.service = raw[7]
        self.subtype = raw[8]
        self.data = raw[config.tm_data_offset : len(raw) - config.pec_size]

    def sid(self):
        """The structure ID of a housekeeping report, the event ID of an event report."""
        d = self.data
        return (d[0] << 8) | d[1] if len(d) >= 2 else None


def hk_or_event_id(h):
    """(kind, id) for a housekeeping or event report, else None."""
    if h.service == _SID[0] and h.subtype == _SID[1]:
        return "hk", h.sid()
    if h.service == 5 and 1 <= h.subtype <= 4:
        return "event", h.sid()
    return None
