"""ST[06] packet field layouts, shared by the provider and the user.

Raw memory is addressed by memory ID and absolute address, object memory by memory ID,
object ID (the standard's "base") and offset in the object. Checksums are CRC-16/CCITT-FALSE,
the packet error control's (ECSS-E-ST-70-41C 6.6 lets the mission choose). Files are named
by repository and file name, as in ST[23].
"""

from obsw.pus.fields import field
from obsw.pus.services.base import U8, U16, U32
from obsw.pus.services.s23_layouts import PATH
from obsw.pus.structure import Repeated, Structure

MEMORY_ID = U16
OBJECT_ID = U16
ADDRESS = U32
OFFSET = U32
LENGTH = U32
CHECKSUM = U16
DATA = field(7, 0)  # octet string, 16-bit length
ITEM_COUNT = U8


def _head(objects):
    return [("memory", MEMORY_ID), ("object", OBJECT_ID)] if objects else [("memory", MEMORY_ID)]


def _layout(objects, item):
    return Structure(_head(objects) + [("items", Repeated(ITEM_COUNT, item))])


_AT = ("address", ADDRESS)
_OFF = ("offset", OFFSET)

# TC[6,2] and TM[6,6]; TC[6,1] and TM[6,4]
LOAD = _layout(False, [_AT, ("data", DATA), ("checksum", CHECKSUM)])
OBJECT_LOAD = _layout(True, [_OFF, ("data", DATA), ("checksum", CHECKSUM)])
DUMP_REPORT = LOAD
OBJECT_DUMP_REPORT = OBJECT_LOAD
# TC[6,5] and TC[6,9]; TC[6,3] and TC[6,7]
RANGES = _layout(False, [_AT, ("length", LENGTH)])
OBJECT_RANGES = _layout(True, [_OFF, ("length", LENGTH)])
# TM[6,10]; TM[6,8]
CHECK_REPORT = _layout(False, [_AT, ("length", LENGTH), ("checksum", CHECKSUM)])
OBJECT_CHECK_REPORT = _layout(True, [_OFF, ("length", LENGTH), ("checksum", CHECKSUM)])
# TC[6,11]: one area, loaded whole or not at all
ATOMIC_LOAD = Structure([("memory", MEMORY_ID), _AT, ("data", DATA), ("checksum", CHECKSUM)])
# TC[6,13] .. TC[6,16]
ONE_MEMORY = Structure([("memory", MEMORY_ID)])
# TC[6,17] and TM[6,18]
ONE_OBJECT = Structure([("memory", MEMORY_ID), ("object", OBJECT_ID)])
OBJECT_WHOLE_REPORT = Structure(
    [("memory", MEMORY_ID), ("object", OBJECT_ID), ("length", LENGTH), ("checksum", CHECKSUM)]
)
# TC[6,19], TC[6,21]: the data come from files; TC[6,20], TC[6,22]: they go to files
_FILE = [("repository", PATH), ("file", PATH)]
LOAD_BY_REFERENCE = _layout(False, [_AT] + _FILE + [("checksum", CHECKSUM)])
OBJECT_LOAD_BY_REFERENCE = _layout(True, [_OFF] + _FILE + [("checksum", CHECKSUM)])
DUMP_TO_FILE = _layout(False, [_AT, ("length", LENGTH)] + _FILE)
OBJECT_DUMP_TO_FILE = _layout(True, [_OFF, ("length", LENGTH)] + _FILE)
# failure data
WHERE = Structure([("memory", MEMORY_ID), ("address", ADDRESS)])
OBJECT_WHERE = Structure([("memory", MEMORY_ID), ("object", OBJECT_ID), ("offset", OFFSET)])
