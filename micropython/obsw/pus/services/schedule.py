"""The schedule shared by ST[11] time-based and ST[22] position-based scheduling.

An activity is a request (a whole TC packet) with a tag (a release time, or a position),
a sub-schedule ID and a group ID; it is named by its request ID (source ID, APID, sequence
count). Both services have the same 27 subtypes; a subclass names its message types, the
field types of a tag and of a shift, and what "now" is. Tags are held as integers (time in
1/65536 s, position in the position parameter's unit).

When an activity's tag is reached it leaves the schedule; it is released into the
application process (through ``receive``, so it is verified like a ground TC, its reports
going to its own source ID) if the schedule, its sub-schedule and its group are enabled,
otherwise it is counted as skipped. Group 0 means "no group" and is always enabled; new
groups start enabled; sub-schedules 0 .. n-1 exist from the start. A reset removes every
activity and group and disables the schedule. The schedule persists in the context store
after every change and before every release, so a restart loses nothing and releases
nothing twice; activities that came due while the process was down go out on its first
cycle. A request that names several activities or groups is checked as a whole first: one
bad item fails the start of execution (its ID in the failure data) and nothing changes.
"""

from binascii import hexlify, unhexlify

from obsw.pus.packets import PusError
from obsw.pus.services.base import U8, Service
from obsw.pus.services.s01_verification import (
    FAILURE_REFUSED,
    FAILURE_UNKNOWN_ID,
    PusFailure,
    app_data_error,
)
from obsw.pus.services.schedule_layouts import (
    EMPTY,
    GROUPS,
    REQUEST_ID,
    STATUS_REPORT,
    SUBSCHEDULES,
    Layouts,
)
from obsw.pus.structure import Structure
from obsw.pus.tc import PusTc

_RID = Structure(REQUEST_ID)
_ID = Structure([("id", U8)])

_DECODE_ERRORS = (ValueError, KeyError, IndexError, TypeError)


class Activity:
    __slots__ = ("tag", "subschedule", "group", "request", "rid")

    def __init__(self, tag, subschedule, group, request, rid):
        self.tag = tag
        self.subschedule = subschedule
        self.group = group
        self.request = request
        self.rid = rid  # (source ID, APID, sequence count)


def _rid_data(rid):
    return _RID.pack({"source": rid[0], "apid": rid[1], "seq_count": rid[2]})


def _id_failure(code, what, ident):
    return PusFailure(code, what, _ID.pack({"id": ident}))


class Schedule(Service):
    """The provider core (see the module text); subclasses are services 11 and 22.

    ``capacity`` bounds the activities, ``subschedules`` is how many sub-schedules exist,
    ``max_groups`` how many groups may be created, ``margin`` how far ahead of now (in tag
    units) a tag must be. ``route(raw)`` takes released requests for APIDs this process
    does not serve (other on-board processes); without it such requests are refused.
    """

    TAG = None
    OFFSET = None
    TAG_MAX = 0
    TM_DETAIL = TM_SUMMARY = TM_SUBSCHEDULES = TM_GROUPS = None

    def __init__(self, capacity=64, subschedules=1, max_groups=16, margin=0, route=None):
        super().__init__()
        self.layouts = Layouts(self.TAG, self.OFFSET)
        self.capacity = capacity
        self.max_groups = max_groups
        self.margin = margin
        self.route = route
        self.enabled = True
        self.subschedules = {}
        for i in range(subschedules):
            self.subschedules[i] = True
        self.groups = {}  # group ID -> enabled
        self.activities = []  # by tag, then by insertion
        self.released = 0
        self.skipped = 0

    # -------------------------------------------------------------------------- tags

    def now(self):
        """The current tag (time or position) as an integer, or None if unknown."""
        raise NotImplementedError

    def tag_in(self, value):
        return value

    def tag_out(self, tag):
        return tag

    # -------------------------------------------------------------------------- context

    def context(self):
        return {
            "enabled": self.enabled,
            "subschedules": [[k, v] for k, v in self.subschedules.items()],
            "groups": [[k, v] for k, v in self.groups.items()],
            "activities": [
                [a.tag, a.subschedule, a.group, hexlify(a.request).decode()]
                for a in self.activities
            ],
        }

    def restore(self, ctx):
        acts = []
        for tag, sub, group, text in ctx["activities"]:
            raw = unhexlify(text)
            acts.append(Activity(int(tag), sub, group, raw, self._rid(PusTc.unpack(raw))))
        subs = {}
        for k, v in ctx["subschedules"]:
            subs[int(k)] = bool(v)
        groups = {}
        for k, v in ctx["groups"]:
            groups[int(k)] = bool(v)
        self.enabled = bool(ctx["enabled"])
        self.subschedules = subs
        self.groups = groups
        self.activities = acts

    # -------------------------------------------------------------------------- helpers

    def _rid(self, tc):
        return (tc.source_id, tc.apid, tc.seq_count)

    def _find(self, rid):
        for a in self.activities:
            if a.rid == rid:
                return a
        return None

    def _known_ids(self, items):
        found = []
        for i in items:
            rid = (i["source"], i["apid"], i["seq_count"])
            a = self._find(rid)
            if a is None:
                raise PusFailure(FAILURE_UNKNOWN_ID, "no activity %r" % (rid,), _rid_data(rid))
            found.append(a)
        return found

    def _check_subschedule(self, sub):
        if sub not in self.subschedules:
            raise _id_failure(FAILURE_UNKNOWN_ID, "no sub-schedule %d" % sub, sub)

    def _check_group(self, group):
        if group != 0 and group not in self.groups:
            raise _id_failure(FAILURE_UNKNOWN_ID, "no group %d" % group, group)

    def _add(self, a):
        acts = self.activities
        i = len(acts)
        while i > 0 and acts[i - 1].tag > a.tag:
            i -= 1
        acts.insert(i, a)

    def _earliest(self):
        now = self.now()
        if now is None:
            raise PusFailure(FAILURE_REFUSED, "the schedule's position is unknown")
        return now + self.margin

    def _check_tag(self, tag, rid, earliest):
        if tag < earliest:
            raise PusFailure(FAILURE_REFUSED, "tag %r is in the past" % (tag,), _rid_data(rid))
        if tag > self.TAG_MAX:
            raise PusFailure(FAILURE_REFUSED, "tag %r out of range" % (tag,), _rid_data(rid))

    def _select(self, f):
        lo = self.tag_in(f["from"]) if "from" in f else None
        hi = self.tag_in(f["to"]) if "to" in f else None
        if lo is not None and hi is not None and hi < lo:
            raise PusFailure(FAILURE_REFUSED, "window ends before it starts")
        subs = f["subschedules"]
        groups = f["groups"]
        for s in subs:
            self._check_subschedule(s)
        for g in groups:
            self._check_group(g)
        return [
            a
            for a in self.activities
            if (lo is None or a.tag >= lo)
            and (hi is None or a.tag <= hi)
            and (not subs or a.subschedule in subs)
            and (not groups or a.group in groups)
        ]

    def _filter(self, req, shifted=False):
        try:
            layout = self.layouts.filter(req.data, shifted)
        except ValueError as e:
            raise app_data_error(e) from None
        return req.decode(layout)

    # -------------------------------------------------------------------------- handlers

    def enable(self, req):
        req.decode(EMPTY)
        req.start()
        self.enabled = True
        self.persist()

    def disable(self, req):
        req.decode(EMPTY)
        req.start()
        self.enabled = False
        self.persist()

    def reset(self, req):
        req.decode(EMPTY)
        req.start()
        self.activities = []
        self.groups = {}
        self.enabled = False
        self.persist()

    def insert(self, req):
        try:
            items = self.layouts.activities.unpack(req.data)["items"]
            tcs = [PusTc.unpack(i["request"], self.app.config) for i in items]
        except PusError as e:
            raise app_data_error("request: %s" % e) from None
        except _DECODE_ERRORS as e:
            raise app_data_error(e) from None
        req.accept()
        earliest = self._earliest()
        if len(self.activities) + len(items) > self.capacity:
            raise PusFailure(FAILURE_REFUSED, "schedule full (%d activities)" % self.capacity)
        new = []
        seen = set()
        for i, tc in zip(items, tcs):
            rid = self._rid(tc)
            if rid in seen or self._find(rid) is not None:
                raise PusFailure(FAILURE_REFUSED, "activity %r exists" % (rid,), _rid_data(rid))
            seen.add(rid)
            if tc.apid not in self.app.apids and self.route is None:
                raise PusFailure(FAILURE_UNKNOWN_ID, "no process %d" % tc.apid, _rid_data(rid))
            self._check_subschedule(i["subschedule"])
            self._check_group(i["group"])
            tag = self.tag_in(i["tag"])
            self._check_tag(tag, rid, earliest)
            new.append(Activity(tag, i["subschedule"], i["group"], bytes(i["request"]), rid))
        req.start()
        for a in new:
            self._add(a)
        self.persist()

    def _delete(self, req, acts):
        req.start()
        self.activities = [a for a in self.activities if a not in acts]
        self.persist()

    def delete_ids(self, req):
        self._delete(req, self._known_ids(req.decode(self.layouts.ids)["ids"]))

    def delete_filter(self, req):
        self._delete(req, self._select(self._filter(req)))

    def _shift(self, req, acts, offset):
        delta = self.tag_in(offset)
        earliest = self._earliest()
        for a in acts:
            self._check_tag(a.tag + delta, a.rid, earliest)
        req.start()
        for a in acts:
            self.activities.remove(a)
            a.tag += delta
            self._add(a)
        self.persist()

    def shift_ids(self, req):
        tc = req.decode(self.layouts.shift_ids)
        self._shift(req, self._known_ids(tc["ids"]), tc["offset"])

    def shift_filter(self, req):
        tc = self._filter(req, True)
        self._shift(req, self._select(tc), tc["offset"])

    def shift_all(self, req):
        tc = req.decode(self.layouts.shift_all)
        self._shift(req, list(self.activities), tc["offset"])

    def _detail(self, req, acts):
        items = [
            {
                "subschedule": a.subschedule,
                "group": a.group,
                "tag": self.tag_out(a.tag),
                "request": a.request,
            }
            for a in acts
        ]
        req.report(self.TM_DETAIL, self.layouts.activities.pack({"items": items}))

    def _summary(self, req, acts):
        items = [
            {
                "subschedule": a.subschedule,
                "group": a.group,
                "tag": self.tag_out(a.tag),
                "source": a.rid[0],
                "apid": a.rid[1],
                "seq_count": a.rid[2],
            }
            for a in acts
        ]
        req.report(self.TM_SUMMARY, self.layouts.summary.pack({"items": items}))

    def detail_ids(self, req):
        self._detail(req, self._known_ids(req.decode(self.layouts.ids)["ids"]))

    def detail_filter(self, req):
        self._detail(req, self._select(self._filter(req)))

    def detail_all(self, req):
        req.decode(EMPTY)
        self._detail(req, self.activities)

    def summary_ids(self, req):
        self._summary(req, self._known_ids(req.decode(self.layouts.ids)["ids"]))

    def summary_filter(self, req):
        self._summary(req, self._select(self._filter(req)))

    def summary_all(self, req):
        req.decode(EMPTY)
        self._summary(req, self.activities)

    def _status(self, req, message_type, table):
        items = [{"id": k, "enabled": 1 if v else 0} for k, v in sorted(table.items())]
        req.report(message_type, STATUS_REPORT.pack({"items": items}))

    def report_subschedules(self, req):
        req.decode(EMPTY)
        self._status(req, self.TM_SUBSCHEDULES, self.subschedules)

    def _switch_subschedules(self, req, enabled):
        ids = req.decode(SUBSCHEDULES)["ids"]
        for s in ids:
            self._check_subschedule(s)
        req.start()
        for s in ids:
            self.subschedules[s] = enabled
        self.persist()

    def enable_subschedules(self, req):
        self._switch_subschedules(req, True)

    def disable_subschedules(self, req):
        self._switch_subschedules(req, False)

    def create_groups(self, req):
        ids = req.decode(GROUPS)["ids"]
        if len(self.groups) + len(ids) > self.max_groups:
            raise PusFailure(FAILURE_REFUSED, "at most %d groups" % self.max_groups)
        for i, g in enumerate(ids):
            if g == 0 or g in self.groups or g in ids[:i]:
                raise _id_failure(FAILURE_REFUSED, "group %d exists" % g, g)
        req.start()
        for g in ids:
            self.groups[g] = True
        self.persist()

    def _known_groups(self, req):
        ids = req.decode(GROUPS)["ids"]
        for g in ids:
            if g not in self.groups:
                raise _id_failure(FAILURE_UNKNOWN_ID, "no group %d" % g, g)
        return ids

    def delete_groups(self, req):
        ids = self._known_groups(req)
        for a in self.activities:
            if a.group in ids:
                raise _id_failure(FAILURE_REFUSED, "group %d has activities" % a.group, a.group)
        req.start()
        for g in ids:
            del self.groups[g]
        self.persist()

    def _switch_groups(self, req, enabled):
        ids = self._known_groups(req)
        req.start()
        for g in ids:
            self.groups[g] = enabled
        self.persist()

    def enable_groups(self, req):
        self._switch_groups(req, True)

    def disable_groups(self, req):
        self._switch_groups(req, False)

    def report_groups(self, req):
        req.decode(EMPTY)
        self._status(req, self.TM_GROUPS, self.groups)

    # -------------------------------------------------------------------------- release

    def cyclic(self, now):
        acts = self.activities
        if not acts:
            return
        tag = self.now()
        if tag is None or acts[0].tag > tag:
            return
        due = []
        while acts and acts[0].tag <= tag:
            due.append(acts.pop(0))
        self.persist()  # before the release: a restart in between releases nothing twice
        for a in due:
            if self.enabled and self.subschedules.get(a.subschedule) and self._group_on(a):
                self.release(a)
            else:
                self.skipped += 1

    def _group_on(self, a):
        return a.group == 0 or self.groups.get(a.group, False)

    def release(self, a):
        self.released += 1
        if a.rid[1] in self.app.apids or self.route is None:
            self.app.receive(a.request)
        else:
            self.route(a.request)
