"""PUS-C mission parameters: which optional packet fields exist and their sizes."""

from obsw.compat import Struct, pus_accelerator
from obsw.timecode import Cuc

_INT_FMT = {1: "B", 2: "H", 4: "I"}
_CUC_4_2 = Cuc(4, 2)

# packet primary header, then the octet holding the PUS version, service type, subtype
_COMMON = ">HHHBBB"


def _size(name, value, allowed):
    if value not in allowed:
        raise ValueError("%s must be one of %r, got %r" % (name, allowed, value))
    return value


class PusConfig:
    """The packet layout choices ECSS-E-ST-70-41C leaves to a mission.

    Sizes are in octets; 0 leaves a field out. Defaults are the PUS-C layout:
    source ID 16 bits in TCs; message type counter 16 bits and destination ID 16 bits in TMs;
    no spare; TM time a 4+2 octet CUC with implicit P-field; packet error control present.
    ``time`` is any time code with ``size``, ``pack(*fields)`` and ``unpack(buf, offset)``
    (``obsw.timecode.Cuc`` or ``Cds``), or None for no time field. ``tc_spare`` and
    ``tm_spare`` are zero octets that close the secondary header (word alignment).
    """

    def __init__(
        self,
        source_id_size=2,
        destination_id_size=2,
        message_counter_size=2,
        time=_CUC_4_2,
        pec=True,
        tc_spare=0,
        tm_spare=0,
        max_packet_size=65542,
    ):
        self.source_id_size = _size("source ID size", source_id_size, (0, 1, 2, 3, 4))
        self.destination_id_size = _size(
            "destination ID size", destination_id_size, (0, 1, 2, 3, 4)
        )
        self.message_counter_size = _size(
            "message type counter size", message_counter_size, (0, 1, 2)
        )
        self.time = time
        self.pec = bool(pec)
        self.tc_spare = _size("TC spare octets", tc_spare, (0, 1, 2, 3))
        self.tm_spare = _size("TM spare octets", tm_spare, (0, 1, 2, 3))
        self.max_packet_size = max_packet_size
        self.pec_size = 2 if self.pec else 0
        time_size = self.time.size if self.time is not None else 0
        # secondary header sizes, and the smallest whole packet of each kind
        self.tc_header_size = 3 + self.source_id_size + self.tc_spare
        self.tm_header_size = (
            3 + self.message_counter_size + self.destination_id_size + time_size + self.tm_spare
        )
        self.tc_min_size = 6 + self.tc_header_size + self.pec_size
        self.tm_min_size = 6 + self.tm_header_size + self.pec_size
        self.tc_data_offset = 6 + self.tc_header_size
        self.tm_data_offset = 6 + self.tm_header_size
        self.source_id_max = (1 << (8 * self.source_id_size)) - 1
        self.destination_id_max = (1 << (8 * self.destination_id_size)) - 1
        self.message_counter_max = (1 << (8 * self.message_counter_size)) - 1
        # widths in bits: ``value >> bits`` is non-zero exactly when a value (negative ones
        # included) does not fit, one cheap test per field on the encode path
        self.source_id_bits = 8 * self.source_id_size
        self.destination_id_bits = 8 * self.destination_id_size
        self.message_counter_bits = 8 * self.message_counter_size
        self._build_fast_paths()

    def _build_fast_paths(self):
        # One precompiled struct covers the whole header when every field has a struct code;
        # other layouts take the field-by-field path in the packet classes.
        pad = "%dx" % self.tc_spare if self.tc_spare else ""
        sfmt = _INT_FMT.get(self.source_id_size)
        self.tc_struct = Struct(_COMMON + sfmt + pad) if sfmt else None
        self.tc_common = Struct(_COMMON)
        self.time_fields = None  # (coarse bits, fine bits) when the time goes in the struct
        t = self.time
        if isinstance(t, Cuc) and not t.explicit and t.coarse in _INT_FMT and t.fine in _INT_FMT:
            self.time_fields = (8 * t.coarse, 8 * t.fine)
        cfmt = _INT_FMT.get(self.message_counter_size)
        dfmt = _INT_FMT.get(self.destination_id_size)
        pad = "%dx" % self.tm_spare if self.tm_spare else ""
        if cfmt and dfmt and self.time_fields:
            tfmt = _INT_FMT[t.coarse] + _INT_FMT[t.fine]
            self.tm_struct = Struct(_COMMON + cfmt + dfmt + tfmt + pad)
        else:
            self.tm_struct = None
        self._build_accelerated()

    def _build_accelerated(self):
        # The C codec (obsw.compat.pus_accelerator) takes the layouts the structs above cover,
        # described by one int each; 0 means no C path (MicroPython, OBSW_PURE, other layouts).
        self.tc_fast = 0
        self.tm_fast = 0
        m = self.max_packet_size
        if not isinstance(m, int) or pus_accelerator() is None:
            return
        m = min(max(m, 0), 65542) << 16  # no packet is longer: the length field has 16 bits
        pec = 1 if self.pec else 0
        if self.tc_struct is not None:
            self.tc_fast = m | pec << 5 | self.tc_spare << 3 | self.source_id_size
        if self.tm_struct is not None:
            t = self.time
            self.tm_fast = (
                m
                | pec << 13
                | self.tm_spare << 11
                | t.fine << 8
                | t.coarse << 5
                | self.destination_id_size << 2
                | self.message_counter_size
            )

    def __eq__(self, other):
        return isinstance(other, PusConfig) and _key(self) == _key(other)

    def __repr__(self):
        return (
            "PusConfig(source_id_size=%d, destination_id_size=%d, message_counter_size=%d, "
            "time=%r, pec=%r, tc_spare=%d, tm_spare=%d)" % _key(self)
        )


def _key(c):
    return (
        c.source_id_size,
        c.destination_id_size,
        c.message_counter_size,
        c.time,
        c.pec,
        c.tc_spare,
        c.tm_spare,
    )


# the PUS-C default layout, shared
DEFAULT = PusConfig()


# ---------------------------------------------------------------------------- from the database

LAYOUT_KEYS = (
    "source_id",
    "source_id_size",
    "destination_id_size",
    "message_counter_size",
    "time",
    "pec",
    "tc_spare",
    "tm_spare",
)


class PusLayoutError(ValueError):
    """The spacecraft database's ``pus`` section names a layout PUS-C does not allow."""

    def __init__(self, key, message):
        super().__init__("pus.%s: %s" % (key, message))
        self.key = key


def from_sdb(sdb):
    """The packet layout the database's ``pus`` section declares (``Sdb.pus``), for example
    ``{"source_id_size": 1, "time": {"coarse": 4, "fine": 3}, "pec": true}``; absent keys keep
    the PUS-C defaults, ``"time": null`` leaves the TM time out. ``DEFAULT`` when the section
    says nothing about the layout."""
    doc = sdb.pus if sdb is not None else None
    if not doc:
        return DEFAULT
    if not isinstance(doc, dict):
        raise PusLayoutError("", "expected an object, got %r" % (doc,))
    for key in doc:
        if key not in LAYOUT_KEYS:
            raise PusLayoutError(key, "unknown key (one of %s)" % ", ".join(LAYOUT_KEYS))
    kw = {}
    for key in ("source_id_size", "destination_id_size", "message_counter_size"):
        if key in doc:
            kw[key] = doc[key]
    for key in ("tc_spare", "tm_spare"):
        if key in doc:
            kw[key] = doc[key]
    if "pec" in doc:
        if not isinstance(doc["pec"], bool):
            raise PusLayoutError("pec", "expected true or false, got %r" % (doc["pec"],))
        kw["pec"] = doc["pec"]
    if "time" in doc:
        kw["time"] = _time(doc["time"])
    if not kw:
        return DEFAULT
    try:
        return PusConfig(**kw)
    except ValueError as e:
        raise PusLayoutError("", str(e)) from None


def _time(spec):
    if spec is None:
        return None
    if not isinstance(spec, dict):
        raise PusLayoutError("time", "expected {'coarse': 1-4, 'fine': 0-3} or null")
    coarse = spec.get("coarse", 4)
    fine = spec.get("fine", 2)
    for key in spec:
        if key not in ("coarse", "fine"):
            raise PusLayoutError("time.%s" % key, "unknown key (coarse, fine)")
    if coarse not in (1, 2, 3, 4) or fine not in (0, 1, 2, 3):
        raise PusLayoutError("time", "CUC octets coarse 1-4, fine 0-3, got %r" % (spec,))
    return Cuc(coarse, fine)
