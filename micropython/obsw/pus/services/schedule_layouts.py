"""Message layouts of ST[11] and ST[22] scheduling, for a service's tag and shift types.

A filter selects activities by a window of tags (all, from-to, from, to: the window type
decides which tags follow it), by sub-schedules and by groups (an empty list: any).
"""

from obsw.compat import const
from obsw.pus.fields import field
from obsw.pus.services.base import E8, U8, U16
from obsw.pus.structure import Repeated, Structure

# mission field sizes of services 11 and 22
SUBSCHEDULE_ID = U8
GROUP_ID = U8
ACTIVITY_COUNT = U16  # N of activities in a request or report
ID_COUNT = U8  # N of sub-schedule or group IDs
STATUS = E8  # 1 enabled, 0 disabled
WINDOW = E8  # type of a filter's window, below
REQUEST = field(12, 0)  # a whole TC packet
REQUEST_ID = [("source", U16), ("apid", U16), ("seq_count", U16)]

WINDOW_ALL = const(0)
WINDOW_FROM_TO = const(1)
WINDOW_FROM = const(2)
WINDOW_TO = const(3)

EMPTY = Structure([])
SUBSCHEDULES = Structure([("ids", Repeated(ID_COUNT, SUBSCHEDULE_ID))])
GROUPS = Structure([("ids", Repeated(ID_COUNT, GROUP_ID))])
STATUS_REPORT = Structure([("items", Repeated(ID_COUNT, [("id", U8), ("enabled", STATUS)]))])


class Layouts:
    """The message layouts of one scheduling service, for its tag and offset field types."""

    def __init__(self, tag, offset):
        self.tag = tag
        self.offset = offset
        ids = Repeated(ACTIVITY_COUNT, REQUEST_ID)
        self.ids = Structure([("ids", ids)])
        self.shift_ids = Structure([("offset", offset), ("ids", ids)])
        self.shift_all = Structure([("offset", offset)])
        self.activities = Structure(
            [
                (
                    "items",
                    Repeated(
                        ACTIVITY_COUNT,
                        [
                            ("subschedule", SUBSCHEDULE_ID),
                            ("group", GROUP_ID),
                            ("tag", tag),
                            ("request", REQUEST),
                        ],
                    ),
                )
            ]
        )
        self.summary = Structure(
            [
                (
                    "items",
                    Repeated(
                        ACTIVITY_COUNT,
                        [("subschedule", SUBSCHEDULE_ID), ("group", GROUP_ID), ("tag", tag)]
                        + REQUEST_ID,
                    ),
                )
            ]
        )
        self.filters = {}
        self.shift_filters = {}
        for w in (WINDOW_ALL, WINDOW_FROM_TO, WINDOW_FROM, WINDOW_TO):
            f = [("window", WINDOW)]
            if w in (WINDOW_FROM_TO, WINDOW_FROM):
                f.append(("from", tag))
            if w in (WINDOW_FROM_TO, WINDOW_TO):
                f.append(("to", tag))
            f.append(("subschedules", Repeated(ID_COUNT, SUBSCHEDULE_ID)))
            f.append(("groups", Repeated(ID_COUNT, GROUP_ID)))
            self.filters[w] = Structure(f)
            self.shift_filters[w] = Structure([("offset", offset)] + f)
        self._window_at = offset.bits >> 3

    def filter(self, data, shifted=False):
        """The filter layout for ``data`` (its window type decides which tags follow)."""
        at = self._window_at if shifted else 0
        if len(data) <= at:
            raise ValueError("filter too short: %d bytes, window type at %d" % (len(data), at))
        table = self.shift_filters if shifted else self.filters
        layout = table.get(data[at])
        if layout is None:
            raise ValueError("window type %d, expected 0..3" % data[at])
        return layout
