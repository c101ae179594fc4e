"""ST[18] packet layouts: OBCP IDs, procedure arguments, reports, events, and failures.

The field sizes ECSS-E-ST-70-41C leaves to the mission are named here once: an OBCP ID is a
character string of 1 to 64 octets after an 8-bit length, the OBCP code an octet string
after a 16-bit length, a repository path or file name a character string after an 8-bit
length. A procedure argument carries its own type: name, a 16-bit type code (PTC << 8 |
PFC: boolean, signed or unsigned 64-bit integer, double, character or octet string), a unit
(Annex B of ECSS-E-ST-70-32C, empty for none) and the value, so a procedure's arguments need
no database entry. A load request ends with the procedure's arguments and their default
values (N = 0 for none; a mission extension of TC[18,1] and TC[18,13]): the names and
types the procedure text is checked with, since PLUTO text does not declare them.
"""

from obsw.compat import const
from obsw.il.errors import CallTimeoutError, ComponentError, UnavailableError
from obsw.pluto.obcp import LOAD_FAILED, UNKNOWN_OBCP
from obsw.pus.fields import field
from obsw.pus.messages import FAILURE_OBCP_REJECTED
from obsw.pus.services.base import E8, U8, U16, U32
from obsw.pus.services.s01_verification import (
    FAILURE_COMPONENT,
    FAILURE_REFUSED,
    FAILURE_TIMEOUT,
    FAILURE_UNAVAILABLE,
    FAILURE_UNKNOWN_ID,
    PusFailure,
)
from obsw.pus.structure import Deduced, Repeated, Structure

OBCP_ID = field(8, 0, length_bits=8, max_length=64)
OBCP_CODE = field(7, 0)
PATH = field(8, 0, length_bits=8)
TEXT = field(8, 0, length_bits=8)
MESSAGE = field(8, 0)
LEVEL = E8
COUNT = U8

# observability levels: which engine events go to ground as service 5 events
LEVEL_NONE = const(0)  # failures only
LEVEL_PROCEDURE = const(1)  # + activation, outcome, state changes, raised events, questions
LEVEL_STEP = const(2)  # + the status of every step
LEVEL_STATEMENT = const(3)  # + log lines and user messages
LEVEL_NAMES = ("none", "procedure", "step", "statement")
EVENT_LEVELS = {
    "failed": LEVEL_NONE,
    "started": LEVEL_PROCEDURE,
    "finished": LEVEL_PROCEDURE,
    "state_changed": LEVEL_PROCEDURE,
    "raised": LEVEL_PROCEDURE,
    "question": LEVEL_PROCEDURE,
    "step_status": LEVEL_STEP,
    "log": LEVEL_STATEMENT,
    "message": LEVEL_STATEMENT,
}

# TM[18,9] OBCP status and last outcome
STATUS_NAMES = ("inactive", "running", "suspended", "stopping")
OUTCOME_NAMES = ("none", "confirmed", "not confirmed", "aborted")

# the reason in the data of a FAILURE_REFUSED report (the engine's ObcpError codes)
REASONS = (
    "OTHER",
    "ALREADY_LOADED",
    "BAD_NAME",
    "NO_ROOM",
    "NOT_INACTIVE",
    "NOT_ACTIVE",
    "NOT_RUNNING",
    "NOT_SUSPENDED",
    "NO_QUESTION",
    "ENGINE_STOPPED",
)
# the kind in the data of a FAILURE_OBCP_REJECTED report
KINDS = ("other", "syntax_error", "unknown_reference", "type_error")

# PUS event IDs of the engine's events: this base plus the event's id in ``ENGINE``
EVENT_BASE = const(0x1800)

ARG_BOOL = const(0x0108)
ARG_INT = const(0x0410)
ARG_UINT = const(0x0310)
ARG_REAL = const(0x0502)
ARG_TEXT = const(0x0800)
ARG_OCTETS = const(0x0700)
ARG_TYPES = (ARG_BOOL, ARG_INT, ARG_UINT, ARG_REAL, ARG_TEXT, ARG_OCTETS)


def arg_type(code):
    """The field type of argument type code ``code`` (None: an unknown code)."""
    if code not in ARG_TYPES:
        return None  # the deduced field then reports an unknown type code
    return field(code >> 8, code & 0xFF)


ARGS = Repeated(
    COUNT,
    [
        ("name", TEXT),
        ("type", U16),
        ("unit", TEXT),
        ("value", Deduced("type", arg_type)),
    ],
)

ID = Structure([("id", OBCP_ID)])
EMPTY = Structure([])
LOAD = Structure([("id", OBCP_ID), ("code", OBCP_CODE), ("args", ARGS)])
LOAD_BY_REFERENCE = Structure(
    [("id", OBCP_ID), ("repository", PATH), ("file", PATH), ("args", ARGS)]
)
ACTIVATE = Structure([("id", OBCP_ID), ("level", LEVEL), ("args", ARGS)])
LOAD_AND_ACTIVATE = Structure(
    [("id", OBCP_ID), ("repository", PATH), ("file", PATH), ("level", LEVEL), ("args", ARGS)]
)
COMMUNICATE = Structure([("id", OBCP_ID), ("args", ARGS)])
LEVELS = Structure([("items", Repeated(COUNT, [("id", OBCP_ID), ("level", LEVEL)]))])
ABORTED = Structure([("ids", Repeated(COUNT, OBCP_ID))])
STATUS = Structure([("items", Repeated(COUNT, [("id", OBCP_ID), ("status", E8)]))])
STATUS_DETAIL = Structure(
    [
        (
            "items",
            Repeated(
                COUNT,
                [
                    ("id", OBCP_ID),
                    ("status", E8),
                    ("outcome", E8),
                    ("level", LEVEL),
                    ("activations", U16),
                    ("statements", U32),
                    ("line", U16),
                    ("step", TEXT),
                ],
            ),
        )
    ]
)

# service 1 failure data
REFUSAL = Structure([("reason", E8), ("id", OBCP_ID)])
REJECTION = Structure([("kind", E8), ("line", U16), ("column", U16), ("message", MESSAGE)])


def encode_arguments(arguments):
    """Procedure arguments (a dict of name to value or ``{"value": v, "unit": u}``) as the
    entries of ``ARGS``."""
    out = []
    for name, v in (arguments or {}).items():
        unit = ""
        if isinstance(v, dict):
            unit = v.get("unit") or ""
            v = v["value"]
        if isinstance(v, bool):
            code = ARG_BOOL
        elif isinstance(v, int):
            code = ARG_INT if v < (1 << 63) else ARG_UINT
        elif isinstance(v, float):
            code = ARG_REAL
        elif isinstance(v, str):
            code = ARG_TEXT
        elif isinstance(v, (bytes, bytearray)):
            code = ARG_OCTETS
        else:
            raise ValueError("argument %s: %r is no boolean, number, text or octets" % (name, v))
        out.append({"name": name, "type": code, "unit": unit, "value": v})
    return out


def decode_arguments(entries):
    """The ``ARGS`` entries as a dict of name to value (``{"value", "unit"}`` with a unit)."""
    out = {}
    for e in entries:
        v = e["value"]
        if e["type"] == ARG_OCTETS:
            v = bytes(v)
        out[e["name"]] = {"value": v, "unit": e["unit"]} if e["unit"] else v
    return out


def event_table(interface):
    """``{event name: (PUS event ID, severity, field names)}`` for the engine's events."""
    return {e.name: (EVENT_BASE + e.id, e.severity, e.fields) for e in interface.events}


def sdb_events(interface, prefix="obcp."):
    """The spacecraft database entries of the engine's events (every field a string)."""
    names = {1: "info", 2: "low", 3: "medium", 4: "high"}
    return [
        {
            "name": prefix + e.name,
            "id": EVENT_BASE + e.id,
            "severity": names[e.severity],
            "data": [{"name": f, "type": "string"} for f in e.fields],
        }
        for e in interface.events
    ]


def refusal(reason, name, message):
    data = REFUSAL.pack({"reason": REASONS.index(reason), "id": name})
    return PusFailure(FAILURE_REFUSED, message, data)


def rejection(kind, line, column, message):
    kind = KINDS.index(kind) if kind in KINDS else 0
    data = REJECTION.pack({"kind": kind, "line": line, "column": column, "message": message[:200]})
    return PusFailure(FAILURE_OBCP_REJECTED, message, data)


def failure_of(name, error):
    """The PusFailure for an engine's refusal (a ComponentError) or an IL call that failed."""
    if isinstance(error, ComponentError):
        code = error.code
        if code == UNKNOWN_OBCP:
            return PusFailure(FAILURE_UNKNOWN_ID, error.message, OBCP_ID.pack(name))
        if code == LOAD_FAILED:
            d = error.data if isinstance(error.data, dict) else {}
            if "line" in d:
                return rejection(d.get("kind"), d["line"], d.get("column", 0), d["message"])
            return rejection("other", 0, 0, error.message)
        reason = code if code in REASONS else "OTHER"
        return refusal(reason, name, error.message)
    if isinstance(error, CallTimeoutError):
        return PusFailure(FAILURE_TIMEOUT, error.message)
    if isinstance(error, UnavailableError):
        return PusFailure(FAILURE_UNAVAILABLE, error.message)
    return PusFailure(FAILURE_COMPONENT, str(error))
