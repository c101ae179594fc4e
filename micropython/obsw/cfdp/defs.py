"""CFDP (CCSDS 727.0-B-5) numbers: PDU fields, condition codes, TLV types and decode errors."""

from obsw.compat import const
from obsw.errors import too_short

VERSION = const(1)  # '001' = CFDP version 2 (727.0-B-4 and later)

# PDU type, direction, transmission mode (fixed header, 5.1)
FILE_DIRECTIVE = const(0)
FILE_DATA = const(1)
TOWARD_RECEIVER = const(0)
TOWARD_SENDER = const(1)
ACKNOWLEDGED = const(0)
UNACKNOWLEDGED = const(1)
CLASS_1 = UNACKNOWLEDGED
CLASS_2 = ACKNOWLEDGED

# File directive codes (table 5-4)
DIR_EOF = const(0x04)
DIR_FINISHED = const(0x05)
DIR_ACK = const(0x06)
DIR_METADATA = const(0x07)
DIR_NAK = const(0x08)
DIR_PROMPT = const(0x09)
DIR_KEEP_ALIVE = const(0x0C)

# Condition codes (table 5-5)
NO_ERROR = const(0)
POSITIVE_ACK_LIMIT_REACHED = const(1)
KEEP_ALIVE_LIMIT_REACHED = const(2)
INVALID_TRANSMISSION_MODE = const(3)
FILESTORE_REJECTION = const(4)
FILE_CHECKSUM_FAILURE = const(5)
FILE_SIZE_ERROR = const(6)
NAK_LIMIT_REACHED = const(7)
INACTIVITY_DETECTED = const(8)
INVALID_FILE_STRUCTURE = const(9)
CHECK_LIMIT_REACHED = const(10)
UNSUPPORTED_CHECKSUM_TYPE = const(11)
SUSPEND_REQUEST_RECEIVED = const(14)
CANCEL_REQUEST_RECEIVED = const(15)

CONDITION_NAMES = {
    0: "no error",
    1: "positive ACK limit reached",
    2: "keep alive limit reached",
    3: "invalid transmission mode",
    4: "filestore rejection",
    5: "file checksum failure",
    6: "file size error",
    7: "NAK limit reached",
    8: "inactivity detected",
    9: "invalid file structure",
    10: "check limit reached",
    11: "unsupported checksum type",
    14: "suspend request received",
    15: "cancel request received",
}

# Fault handler codes (table 5-19)
HANDLER_CANCEL = const(1)
HANDLER_SUSPEND = const(2)
HANDLER_IGNORE = const(3)
HANDLER_ABANDON = const(4)

# Finished PDU delivery code and file status (5.2.3)
DATA_COMPLETE = const(0)
DATA_INCOMPLETE = const(1)
FILE_DISCARDED = const(0)
FILE_DISCARDED_FILESTORE = const(1)
FILE_RETAINED = const(2)
FILE_STATUS_UNREPORTED = const(3)

# ACK PDU transaction status (5.2.4)
STATUS_UNDEFINED = const(0)
STATUS_ACTIVE = const(1)
STATUS_TERMINATED = const(2)
STATUS_UNRECOGNIZED = const(3)

# Prompt PDU response required (5.2.7)
PROMPT_NAK = const(0)
PROMPT_KEEP_ALIVE = const(1)

# File data record continuation state (5.3)
RCS_NONE = const(0)
RCS_START = const(1)
RCS_END = const(2)
RCS_START_END = const(3)

# TLV types (table 5-8)
TLV_FILESTORE_REQUEST = const(0x00)
TLV_FILESTORE_RESPONSE = const(0x01)
TLV_MESSAGE_TO_USER = const(0x02)
TLV_FAULT_HANDLER = const(0x04)
TLV_FLOW_LABEL = const(0x05)
TLV_ENTITY_ID = const(0x06)

# Filestore action codes (table 5-16)
FS_CREATE_FILE = const(0)
FS_DELETE_FILE = const(1)
FS_RENAME_FILE = const(2)
FS_APPEND_FILE = const(3)
FS_REPLACE_FILE = const(4)
FS_CREATE_DIRECTORY = const(5)
FS_REMOVE_DIRECTORY = const(6)
FS_DENY_FILE = const(7)
FS_DENY_DIRECTORY = const(8)
# actions that carry a second file name
FS_TWO_NAMES = (FS_RENAME_FILE, FS_APPEND_FILE, FS_REPLACE_FILE)

# Filestore response status codes (table 5-18); 0 success, 15 not performed for every action
FS_SUCCESS = const(0)
FS_NOT_PERFORMED = const(15)


class CfdpError(ValueError):
    """Base of CFDP decode errors."""


class PduTooShortError(CfdpError):
    """Fewer bytes than a PDU or field needs (``obsw.errors``: the too-short kind)."""

    def __init__(self, what, needed, got):
        super().__init__(too_short(what, needed, got))
        self.what = what
        self.needed = needed
        self.got = got


class PduFormatError(CfdpError):
    """A field holds a value the standard does not allow."""

    def __init__(self, msg):
        super().__init__(msg)


class PduCrcError(CfdpError):
    """The PDU's CRC-16 does not match its contents."""

    def __init__(self, expected, got):
        super().__init__("PDU CRC mismatch: computed 0x%04X, PDU holds 0x%04X" % (expected, got))
        self.expected = expected
        self.got = got
