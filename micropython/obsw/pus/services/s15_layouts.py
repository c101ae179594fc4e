"""ST[15] packet field layouts, shared by the provider and the user."""

from obsw.pus.fields import field
from obsw.pus.services.base import E8, U8, U16, U32
from obsw.pus.services.packet_store import BOUNDED, CIRCULAR
from obsw.pus.services.report_types import EVENT_ITEMS, HK_ITEMS, TYPES
from obsw.pus.structure import Repeated, Structure

STORE_ID = U16
TIME_TAG = field(9, 17)  # absolute time, CUC 4+2 octets like the TM time field
PERCENT = U8
STORE_COUNT = U8

EMPTY = Structure([])
STORES = Structure([("stores", Repeated(STORE_COUNT, STORE_ID))])
STORE_TYPES = Structure([("store", STORE_ID), ("apids", TYPES)])
STORE_HK = Structure([("store", STORE_ID), ("apids", HK_ITEMS)])
STORE_EVENTS = Structure([("store", STORE_ID), ("items", EVENT_ITEMS)])
ONE_STORE = Structure([("store", STORE_ID)])
TIME_RANGE = Structure([("store", STORE_ID), ("start", TIME_TAG), ("end", TIME_TAG)])
SEQUENCE_RANGE = Structure([("store", STORE_ID), ("first", U32), ("last", U32)])
TIME_AND_STORES = Structure([("time", TIME_TAG), ("stores", Repeated(STORE_COUNT, STORE_ID))])
SUMMARY_REPORT = Structure(
    [
        (
            "stores",
            Repeated(
                STORE_COUNT,
                [
                    ("store", STORE_ID),
                    ("oldest", TIME_TAG),
                    ("newest", TIME_TAG),
                    ("open_start", TIME_TAG),
                    ("fill", PERCENT),
                    ("fill_open", PERCENT),
                    # project additions: how many packets and their storage sequence numbers
                    ("count", U32),
                    ("first_seq", U32),
                    ("last_seq", U32),
                ],
            ),
        )
    ]
)
STATUS_REPORT = Structure(
    [
        (
            "stores",
            Repeated(
                STORE_COUNT,
                [
                    ("store", STORE_ID),
                    ("storage", U8),
                    ("open_retrieval", U8),
                    ("range_retrieval", U8),
                ],
            ),
        )
    ]
)
CONFIGURATION = Structure(
    [
        (
            "stores",
            Repeated(STORE_COUNT, [("store", STORE_ID), ("size", U32), ("kind", E8), ("vc", U8)]),
        )
    ]
)
RESIZE = Structure([("stores", Repeated(STORE_COUNT, [("store", STORE_ID), ("size", U32)]))])
CHANGE_VC = Structure([("store", STORE_ID), ("vc", U8)])

KIND_NAMES = {CIRCULAR: "circular", BOUNDED: "bounded"}

# TC[15,24]: the packets of a time window of one store copied into another
WINDOW_FROM_TO = 0  # time tag 1 <= storage time <= time tag 2
WINDOW_AFTER = 1  # storage time >= time tag 1
WINDOW_BEFORE = 2  # storage time <= time tag 2
WINDOW_NAMES = {WINDOW_FROM_TO: "from-to", WINDOW_AFTER: "after", WINDOW_BEFORE: "before"}
COPY_WINDOW = Structure(
    [
        ("window", E8),
        ("tag1", TIME_TAG),
        ("tag2", TIME_TAG),
        ("source", STORE_ID),
        ("target", STORE_ID),
    ]
)
# TC[15,31], [15,32] and TM[15,38]: diagnostic structure IDs per APID, as for housekeeping
STORE_DIAG = STORE_HK
