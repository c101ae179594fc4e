"""ST[23] packet field layouts and copy status codes, shared by the provider and the user."""

from obsw.compat import const
from obsw.pus.fields import field
from obsw.pus.services.base import BOOL8, E8, U8, U16, U32
from obsw.pus.structure import Repeated, Structure

PATH = field(8, 0)  # character string with a 16-bit length
OPERATION_ID = U16
OBJECT_FILE = const(0)
OBJECT_DIRECTORY = const(1)

# copy operation status in TM[23,23] (mission-defined values)
COPY_PENDING = const(0)  # asked for, no data moved yet
COPY_IN_PROGRESS = const(1)
COPY_SUSPENDED = const(2)
COPY_COMPLETED = const(3)
COPY_FAILED = const(4)
COPY_ABORTED = const(5)
COPY_STATUS_NAMES = {
    COPY_PENDING: "pending",
    COPY_IN_PROGRESS: "in progress",
    COPY_SUSPENDED: "suspended",
    COPY_COMPLETED: "completed",
    COPY_FAILED: "failed",
    COPY_ABORTED: "aborted",
}

EMPTY = Structure([])
CREATE = Structure([("repository", PATH), ("file", PATH), ("max_size", U32)])
FILE = Structure([("repository", PATH), ("file", PATH)])
ATTRIBUTES = Structure(
    [
        ("repository", PATH),
        ("file", PATH),
        ("size", U32),
        ("max_size", U32),
        ("locked", BOOL8),
    ]
)
FIND = Structure([("repository", PATH), ("pattern", PATH)])
FOUND = Structure([("repository", PATH), ("pattern", PATH), ("paths", Repeated(U16, PATH))])
DIRECTORY = Structure([("repository", PATH), ("directory", PATH)])
RENAME_DIRECTORY = Structure([("repository", PATH), ("old", PATH), ("new", PATH)])
REPOSITORY = Structure([("repository", PATH)])
SUMMARY = Structure(
    [("repository", PATH), ("objects", Repeated(U16, [("type", E8), ("name", PATH)]))]
)
COPY = Structure(
    [
        ("operation", OPERATION_ID),
        ("source_repository", PATH),
        ("source_file", PATH),
        ("target_repository", PATH),
        ("target_file", PATH),
    ]
)
OPERATIONS = Structure([("operations", Repeated(U8, OPERATION_ID))])
INTERVAL = Structure([("interval", U16)])
COPY_STATUS = Structure(
    [
        (
            "operations",
            Repeated(
                U8,
                [
                    ("operation", OPERATION_ID),
                    ("status", E8),
                    # project additions: octets moved so far and the file's size
                    ("bytes", U32),
                    ("size", U32),
                ],
            ),
        )
    ]
)
