"""A report of every layout of ``obsw_host.yamcs.report_layouts``, with known values.

``sample(layout, pid)`` gives values for a layout that its ``pack`` takes: every repeated
group twice, every service 12 check type once, ``pid`` wherever a parameter ID selects a
value's type, and an embedded TC (a ping) wherever a packet goes.
"""

from obsw.pus.fields import Boolean, Real, Signed, Unsigned
from obsw.pus.ptc_strings import BitString, CharacterString, OctetString, Packet
from obsw.pus.ptc_time import AbsoluteTime, RelativeTime
from obsw.pus.services import s18_layouts as s18
from obsw.pus.services.s12_layouts import Items
from obsw.pus.structure import Deduced, Repeated, Structure
from obsw.pus.tc import PusTc

PID_KEYS = ("id", "parameter")


class Sampler:
    def __init__(self, pid, config, apid):
        self.pid = pid
        self.ping = PusTc(apid, 17, 1, config=config).pack()

    def layout(self, layout):
        if isinstance(layout, Items):
            out = self.structure(layout.prefix) if layout.prefix is not None else {}
            items = []
            for check, variant in sorted(layout.variants.items()):
                item = self.structure(layout.head)
                item["check"] = check
                item.update(self.structure(variant, item))
                items.append(item)
            out["items"] = items
            return out
        return self.structure(layout)

    def structure(self, st, outer=None):
        out = {}
        for name, ft in st.fields:
            if isinstance(ft, Deduced):  # its selector, set before: one that has a type
                out[ft.key] = self.pid if ft.key in PID_KEYS else s18.ARG_INT
            scope = dict(outer or {}, **out)
            out[name] = self.value(name, ft, scope)
        return out

    def value(self, name, ft, scope):
        if isinstance(ft, Repeated):
            return [self.value(name, ft.item, scope) for _ in range(2)]
        if isinstance(ft, Structure):
            return self.structure(ft, scope)
        if isinstance(ft, Deduced):
            return self.value(name, ft.resolve(scope[ft.key]), scope)
        if name in PID_KEYS and isinstance(ft, Unsigned):
            return self.pid
        if isinstance(ft, Packet):
            return self.ping
        if isinstance(ft, CharacterString):
            return "x" * ft.pfc if ft.pfc else "abc"
        if isinstance(ft, OctetString):
            return b"\x5a" * ft.pfc if ft.pfc else b"\x01\x02\x03"
        if isinstance(ft, AbsoluteTime):
            return 1000.5
        if isinstance(ft, RelativeTime):
            return 2.5
        if isinstance(ft, BitString):
            return 1
        if isinstance(ft, Boolean):
            return True
        if isinstance(ft, Real):
            return 1.5
        if isinstance(ft, Signed):
            return -3
        if isinstance(ft, Unsigned):
            return 3
        raise TypeError("no sample for %s %r" % (name, ft))


def pack(layout, values):
    """The report's data: Items and Structures both have ``pack``."""
    return layout.pack(values)
