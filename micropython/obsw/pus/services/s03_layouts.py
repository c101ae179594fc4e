"""ST[03] housekeeping: the application data layouts of its requests and reports.

Housekeeping and diagnostic requests share their layouts (ECSS-E-ST-70-41C 6.3: the diagnostic
subtypes mirror the housekeeping ones). A parameter functional reporting definition lists
parameter report definitions: N1 housekeeping then N2 diagnostic (SID, periodic generation
action status, collection interval) entries.
"""

from obsw.pus.services.base import (
    COLLECTION_INTERVAL,
    GENERATION_STATUS,
    HK_COUNT,
    PARAMETER_ID,
    STRUCTURE_ID,
    U16,
)
from obsw.pus.structure import Repeated, Structure

FUNCTIONAL_ID = U16  # parameter functional reporting definition identifier
FUNCTIONAL_COUNT = U16

PARAMETERS = Repeated(HK_COUNT, PARAMETER_ID)
SUPER_COMMUTATED = Repeated(HK_COUNT, [("repetitions", U16), ("parameters", PARAMETERS)])
CREATE = Structure(
    [
        ("sid", STRUCTURE_ID),
        ("interval", COLLECTION_INTERVAL),
        ("parameters", PARAMETERS),
        ("groups", SUPER_COMMUTATED),
    ]
)
APPEND = Structure(
    [("sid", STRUCTURE_ID), ("parameters", PARAMETERS), ("groups", SUPER_COMMUTATED)]
)
SIDS = Structure([("sids", Repeated(HK_COUNT, STRUCTURE_ID))])
INTERVALS = Structure(
    [("items", Repeated(HK_COUNT, [("sid", STRUCTURE_ID), ("interval", COLLECTION_INTERVAL)]))]
)
STRUCTURE_REPORT = Structure(
    [
        ("sid", STRUCTURE_ID),
        ("enabled", GENERATION_STATUS),
        ("interval", COLLECTION_INTERVAL),
        ("parameters", PARAMETERS),
        ("groups", SUPER_COMMUTATED),
    ]
)
PROPERTY = [
    ("sid", STRUCTURE_ID),
    ("enabled", GENERATION_STATUS),
    ("interval", COLLECTION_INTERVAL),
]
PROPERTIES_REPORT = Structure([("items", Repeated(HK_COUNT, PROPERTY))])
SID_ONLY = Structure([("sid", STRUCTURE_ID)])

# functional reporting (TC[3,37] to TM[3,41], TC[3,42] to TC[3,44])
REPORT_DEFINITIONS = [("hk", Repeated(HK_COUNT, PROPERTY)), ("diag", Repeated(HK_COUNT, PROPERTY))]
FUNCTIONAL = Structure([("id", FUNCTIONAL_ID)] + REPORT_DEFINITIONS)
FUNCTIONAL_IDS = Structure([("ids", Repeated(FUNCTIONAL_COUNT, FUNCTIONAL_ID))])
FUNCTIONAL_REMOVE = Structure(
    [
        ("id", FUNCTIONAL_ID),
        ("hk", Repeated(HK_COUNT, STRUCTURE_ID)),
        ("diag", Repeated(HK_COUNT, STRUCTURE_ID)),
    ]
)
FUNCTIONAL_REPORT = Structure(
    [("items", Repeated(FUNCTIONAL_COUNT, [("id", FUNCTIONAL_ID)] + REPORT_DEFINITIONS))]
)
