"""ST[03] parameter functional reporting: named sets of periodic generation properties.

A parameter functional reporting definition (ECSS-E-ST-70-41C 6.3.4) has an ID and lists
parameter report definitions: housekeeping and diagnostic structure IDs, each with the periodic
generation action status and the collection interval it should have. Applying definitions
(TC[3,37]) sets those properties on the structures at once, e.g. the reporting of an
operational mode; structures a definition does not list keep theirs. ``FunctionalReporting``
is mixed into the service 3 provider, which has ``sets`` ({"hk": ..., "diag": ...}: SID ->
``ReportStructure``). Every request is checked as a whole before anything changes: an unknown
definition or structure ID fails the start of execution with ``FAILURE_UNKNOWN_ID`` and the ID
in the failure data; an ID in use, a duplicate, a zero interval or a full table with
``FAILURE_REFUSED``.
"""

from obsw.pus.messages import (
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
    TM_HK_FUNCTIONAL_REPORTING_REPORT,
)
from obsw.pus.services.s01_verification import PusFailure
from obsw.pus.services.s03_layouts import (
    FUNCTIONAL,
    FUNCTIONAL_ID,
    FUNCTIONAL_IDS,
    FUNCTIONAL_REMOVE,
    FUNCTIONAL_REPORT,
    SID_ONLY,
)

KINDS = ("hk", "diag")


def _refused(text, data=b""):
    return PusFailure(FAILURE_REFUSED, text, data)


def _unknown_definition(fid):
    return PusFailure(FAILURE_UNKNOWN_ID, "no functional reporting definition %d" % fid,
                      FUNCTIONAL_ID.pack(fid))  # fmt: skip


class FunctionalReporting:
    """The functional reporting half of the service 3 provider (see the module text)."""

    max_functional = 16

    def _functional_init(self):
        self.functional = {}  # id -> {"hk": [[sid, enabled, interval]], "diag": [...]}

    # -------------------------------------------------------------------------- checks

    def _definition(self, fid):
        d = self.functional.get(fid)
        if d is None:
            raise _unknown_definition(fid)
        return d

    def _check_entries(self, tc, existing=None):
        """Entries of ``tc`` (decoded FUNCTIONAL): structures known, no duplicates, interval
        above 0; with ``existing``, none already listed there."""
        for kind in KINDS:
            seen = set(e[0] for e in existing[kind]) if existing is not None else set()
            for e in tc[kind]:
                sid = e["sid"]
                if sid not in self.sets[kind]:
                    raise PusFailure(FAILURE_UNKNOWN_ID, "no %s structure %d" % (kind, sid),
                                     SID_ONLY.pack({"sid": sid}))  # fmt: skip
                if sid in seen:
                    raise _refused("%s structure %d listed twice" % (kind, sid),
                                   SID_ONLY.pack({"sid": sid}))  # fmt: skip
                if e["interval"] == 0:
                    raise _refused("collection interval 0", SID_ONLY.pack({"sid": sid}))
                seen.add(sid)

    # -------------------------------------------------------------------------- handlers

    def apply_functional(self, req):
        ids = req.decode(FUNCTIONAL_IDS)["ids"]
        for fid in ids:
            d = self._definition(fid)
            for kind in KINDS:
                for sid, _enabled, _interval in d[kind]:
                    if sid not in self.sets[kind]:
                        raise PusFailure(
                            FAILURE_UNKNOWN_ID,
                            "definition %d names %s structure %d, deleted since"
                            % (fid, kind, sid),
                            SID_ONLY.pack({"sid": sid}),
                        )
        req.start()
        for fid in ids:
            d = self.functional[fid]
            for kind in KINDS:
                for sid, enabled, interval in d[kind]:
                    self._set_properties(self.sets[kind][sid], enabled, interval)
        self.persist()

    def create_functional(self, req):
        tc = req.decode(FUNCTIONAL)
        fid = tc["id"]
        if fid in self.functional:
            raise _refused("functional reporting definition %d exists" % fid,
                           FUNCTIONAL_ID.pack(fid))  # fmt: skip
        if len(self.functional) >= self.max_functional:
            raise _refused("%d functional reporting definitions already" % len(self.functional))
        self._check_entries(tc)
        req.start()
        self.functional[fid] = {k: [_entry(e) for e in tc[k]] for k in KINDS}
        self.persist()

    def delete_functional(self, req):
        ids = req.decode(FUNCTIONAL_IDS)["ids"]
        for fid in ids:
            self._definition(fid)
        req.start()
        if not ids:  # N = 0: every definition
            self.functional = {}
        for fid in ids:
            self.functional.pop(fid, None)
        self.persist()

    def report_functional(self, req):
        ids = req.decode(FUNCTIONAL_IDS)["ids"] or sorted(self.functional)
        for fid in ids:
            self._definition(fid)
        items = []
        for fid in ids:
            d = self.functional[fid]
            item = {"id": fid}
            for kind in KINDS:
                item[kind] = [
                    {"sid": s, "enabled": 1 if en else 0, "interval": i} for s, en, i in d[kind]
                ]
            items.append(item)
        req.report(TM_HK_FUNCTIONAL_REPORTING_REPORT, FUNCTIONAL_REPORT.pack({"items": items}))

    def add_to_functional(self, req):
        tc = req.decode(FUNCTIONAL)
        d = self._definition(tc["id"])
        self._check_entries(tc, d)
        req.start()
        for kind in KINDS:
            d[kind] += [_entry(e) for e in tc[kind]]
        self.persist()

    def remove_from_functional(self, req):
        tc = req.decode(FUNCTIONAL_REMOVE)
        d = self._definition(tc["id"])
        for kind in KINDS:
            listed = [e[0] for e in d[kind]]
            for sid in tc[kind]:
                if sid not in listed:
                    raise PusFailure(
                        FAILURE_UNKNOWN_ID,
                        "definition %d lists no %s structure %d" % (tc["id"], kind, sid),
                        SID_ONLY.pack({"sid": sid}),
                    )
        req.start()
        for kind in KINDS:
            d[kind] = [e for e in d[kind] if e[0] not in tc[kind]]
        self.persist()

    def modify_functional(self, req):
        tc = req.decode(FUNCTIONAL)
        d = self._definition(tc["id"])
        for kind in KINDS:
            listed = [e[0] for e in d[kind]]
            for e in tc[kind]:
                if e["sid"] not in listed:
                    raise PusFailure(
                        FAILURE_UNKNOWN_ID,
                        "definition %d lists no %s structure %d" % (tc["id"], kind, e["sid"]),
                        SID_ONLY.pack({"sid": e["sid"]}),
                    )
                if e["interval"] == 0:
                    raise _refused("collection interval 0", SID_ONLY.pack({"sid": e["sid"]}))
        req.start()
        for kind in KINDS:
            for e in tc[kind]:
                for entry in d[kind]:
                    if entry[0] == e["sid"]:
                        entry[1] = bool(e["enabled"])
                        entry[2] = e["interval"]
        self.persist()

    # -------------------------------------------------------------------------- context

    def functional_context(self):
        return [[fid, d["hk"], d["diag"]] for fid, d in self.functional.items()]

    def restore_functional(self, ctx):
        out = {}
        for fid, hk, diag in ctx:
            out[int(fid)] = {
                "hk": [[int(s), bool(en), int(i)] for s, en, i in hk],
                "diag": [[int(s), bool(en), int(i)] for s, en, i in diag],
            }
        self.functional = out


def _entry(e):
    return [e["sid"], bool(e["enabled"]), e["interval"]]
