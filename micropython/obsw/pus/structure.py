"""PUS message structures: named fields, repeated groups (N then N entries), deduced fields.

Consecutive whole-octet numeric fields are packed with one ``struct`` call, so a structure of
sixteen uint32 costs about what a hand-written ``struct.pack(">16I", ...)`` costs.
"""

import struct

from obsw.bits import BitsTooShortError, Decoder, Encoder
from obsw.compat import MICROPYTHON
from obsw.pus.fields import (
    PTC_DEDUCED,
    FieldType,
    FieldTypeError,
    FieldValueError,
    Real,
    Signed,
    Unsigned,
    field,
)

# CPython's struct range-checks integers itself; MicroPython's truncates silently.
_STRUCT_CHECKS = not MICROPYTHON
_PACK_ERRORS = (getattr(struct, "error", ValueError), OverflowError, TypeError, ValueError)


def _renamed(e, name):
    return FieldValueError("%s %s" % (name, e.field), e.value, e.expected)


class Deduced(FieldType):
    """PTC 11: a field whose type is given by the value of another field (``key``).

    ``lookup`` maps that value to a field type: a dict or a callable, returning a FieldType or
    a ``(ptc, pfc)`` pair. Inside a Structure the key is looked up among the fields already
    read (the innermost group first). Standalone, values are ``(selector, value)`` pairs.
    """

    ptc = PTC_DEDUCED
    pfc = 0
    bits = None
    name = "deduced"

    def __init__(self, key, lookup):
        self.key = key
        self.lookup = lookup

    def resolve(self, selector):
        try:
            ft = self.lookup(selector) if callable(self.lookup) else self.lookup[selector]
        except (KeyError, IndexError, TypeError):
            ft = None
        if isinstance(ft, tuple):
            ft = field(*ft)
        if not isinstance(ft, FieldType):
            self.fail(selector, "a %s value with a known type" % (self.key or "selector"))
        return ft

    def check(self, value):
        try:
            selector, v = value
        except (TypeError, ValueError):
            self.fail(value, "(selector, value)")
        return self.resolve(selector).check(v)

    def write(self, enc, value):
        try:
            selector, v = value
        except (TypeError, ValueError):
            self.fail(value, "(selector, value)")
        self.resolve(selector).write(enc, v)

    def read_for(self, dec, selector):
        return self.resolve(selector).read(dec)

    def read(self, dec):
        raise FieldTypeError(PTC_DEDUCED, 0, "reading needs the selector: use read_for()")


def make_deduced(pfc, mission):
    mission = dict(mission)
    key = mission.pop("key", None)
    lookup = mission.pop("lookup", None)
    if pfc != 0 or mission or lookup is None:
        raise FieldTypeError(PTC_DEDUCED, pfc, "PFC 0 with a lookup (and a key) only")
    return Deduced(key, lookup)


def _min_bits(item):
    if isinstance(item, FieldType):
        return item.bits or 1
    return max(item.min_bits, 1)


class Repeated:
    """A group repeated N times, N first as ``counter`` (a field type, e.g. uint8/uint16).

    ``item`` is a field type (the value is a list of values) or a Structure or a list of
    (name, type) pairs (the value is a list of dicts).
    """

    def __init__(self, counter, item):
        if isinstance(item, list):
            item = Structure(item)
        self.counter = counter
        self.item = item
        self.min_bits = counter.bits or 1
        self._fmt = item.fmt if type(item) in (Unsigned, Signed, Real) else None
        self._item_octets = (item.bits >> 3) if self._fmt else 0

    def write(self, enc, values, scopes=None):
        try:
            n = len(values)
        except TypeError:
            raise FieldValueError("group", values, "a list") from None
        self.counter.write(enc, n)
        item = self.item
        if self._fmt is not None and n:
            if _STRUCT_CHECKS:
                try:
                    enc.write_struct(">%d%s" % (n, self._fmt), *values)
                    return
                except _PACK_ERRORS:
                    pass  # fall through to the per-item path, which names the culprit
            else:
                for i, v in enumerate(values):
                    try:
                        item.check(v)
                    except FieldValueError as e:
                        raise _renamed(e, "[%d]" % i) from None
                enc.write_struct(">%d%s" % (n, self._fmt), *values)
                return
        if isinstance(item, FieldType):
            for i, v in enumerate(values):
                try:
                    item.write(enc, v)
                except FieldValueError as e:
                    raise _renamed(e, "[%d]" % i) from None
        else:
            for i, v in enumerate(values):
                try:
                    item.write(enc, v, scopes)
                except FieldValueError as e:
                    raise _renamed(e, "[%d]" % i) from None

    def read(self, dec, scopes=None):
        n = self.counter.read(dec)
        item = self.item
        need = n * _min_bits(item)
        if need > dec.bits_left:
            raise BitsTooShortError("buffer", need, dec.bits_left)
        if self._fmt is not None and n:
            return list(dec.read_struct(">%d%s" % (n, self._fmt), n * self._item_octets))
        if isinstance(item, FieldType):
            return [item.read(dec) for _ in range(n)]
        return [item.read(dec, scopes) for _ in range(n)]


class Structure:
    """An ordered list of ``(name, type)``; type is a FieldType, Repeated or Structure.

    ``pack(dict) -> bytes`` and ``unpack(buf) -> dict``; ``write``/``read`` work on an
    Encoder/Decoder so structures can be embedded at any bit offset.
    """

    def __init__(self, fields):
        self.fields = list(fields)
        self._plan = []
        self.min_bits = 0
        run = []
        for name, ft in self.fields:
            if type(ft) in (Unsigned, Signed, Real) and ft.fmt is not None:
                run.append((name, ft))
                continue
            self._flush(run)
            run = []
            if isinstance(ft, Deduced):
                self._plan.append((3, name, ft))
            elif isinstance(ft, FieldType):
                self._plan.append((1, name, ft))
                self.min_bits += ft.bits or 0
            elif isinstance(ft, (Repeated, Structure)):
                self._plan.append((2, name, ft))
                self.min_bits += ft.min_bits
            else:
                raise FieldTypeError(None, None, "field %r: %r is not a field type" % (name, ft))
        self._flush(run)
        # One struct run and nothing else: pack() and unpack() skip the bit encoder entirely.
        self._single = self._plan[0] if len(self._plan) == 1 and self._plan[0][0] == 0 else None

    def _flush(self, run):
        if not run:
            return
        names = tuple(n for n, _ in run)
        fmt = ">" + "".join(ft.fmt for _, ft in run)
        size = sum(ft.bits for _, ft in run) >> 3
        self._plan.append((0, names, (fmt, size, tuple(ft for _, ft in run))))
        self.min_bits += size * 8

    @staticmethod
    def _selector(name, key, values, scopes):
        if key in values:
            return values[key]
        for scope in reversed(scopes or ()):
            if key in scope:
                return scope[key]
        raise FieldValueError(name, None, "field %r to deduce the type from" % (key,))

    def _run_error(self, names, types, values):
        for n, ft in zip(names, types):
            try:
                ft.check(values[n])
            except FieldValueError as e:
                raise _renamed(e, n) from None
        raise FieldValueError(", ".join(names), None, "values struct can pack")

    def write(self, enc, values, scopes=None):
        try:
            for kind, name, ft in self._plan:
                if kind == 0:
                    fmt, _, types = ft
                    vals = [values[n] for n in name]
                    if _STRUCT_CHECKS:
                        try:
                            enc.write_struct(fmt, *vals)
                        except _PACK_ERRORS:
                            self._run_error(name, types, values)
                    else:
                        for n, t in zip(name, types):
                            try:
                                t.check(values[n])
                            except FieldValueError as e:
                                raise _renamed(e, n) from None
                        enc.write_struct(fmt, *vals)
                    continue
                try:
                    if kind == 1:
                        ft.write(enc, values[name])
                    elif kind == 2:
                        ft.write(enc, values[name], (scopes or []) + [values])
                    else:
                        sel = self._selector(name, ft.key, values, scopes)
                        ft.resolve(sel).write(enc, values[name])
                except FieldValueError as e:
                    raise _renamed(e, name) from None
        except KeyError as e:
            raise FieldValueError("structure", values, "a value for %s" % e.args[0]) from None
        except TypeError:
            raise FieldValueError("structure", values, "a dict of field values") from None

    def read(self, dec, scopes=None):
        out = {}
        for kind, name, ft in self._plan:
            if kind == 0:
                vals = dec.read_struct(ft[0], ft[1])
                for i, n in enumerate(name):
                    out[n] = vals[i]
            elif kind == 1:
                out[name] = ft.read(dec)
            elif kind == 2:
                out[name] = ft.read(dec, (scopes or []) + [out])
            else:
                try:
                    out[name] = ft.resolve(self._selector(name, ft.key, out, scopes)).read(dec)
                except FieldValueError as e:
                    raise _renamed(e, name) from None
        return out

    def pack(self, values):
        single = self._single
        if single is not None and _STRUCT_CHECKS:
            names = single[1]
            try:
                return struct.pack(single[2][0], *[values[n] for n in names])
            except _PACK_ERRORS:
                pass  # the general path names the culprit
            except KeyError:
                pass
        enc = Encoder()
        self.write(enc, values)
        return enc.getvalue()

    def unpack(self, buf, exact=True):
        """The dict at the start of ``buf``; with ``exact`` only pad bits may follow."""
        single = self._single
        if single is not None and len(buf) == single[2][1]:
            return dict(zip(single[1], struct.unpack(single[2][0], buf)))
        dec = Decoder(buf)
        out = self.read(dec)
        if exact and dec.bits_left >= 8:
            raise FieldValueError(
                "structure", dec.bits_left >> 3, "no trailing octets after the last field"
            )
        return out
