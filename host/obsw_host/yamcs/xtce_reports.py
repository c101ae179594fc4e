"""XTCE containers for whole PUS reports, written from the layouts the OBC packs them with.

``ReportWriter(generator).write(msg_type, name, layout)`` turns a ``Structure`` (or service 12
``Items``) into a container under ``/MISSION/TM/<name>`` that decodes every field of the report:

- a numeric, boolean or enumerated field is a parameter of its PTC/PFC; a field that names an
  event, a parameter or a state is an enumeration with their labels;
- a character string with its leading length, an octet string after a length parameter, an
  absolute time (CUC: a time since 1958-01-01 TAI), a relative time (seconds);
- a repeated group is its count, then a container of one item repeated that many times
  (XTCE ``RepeatEntry``); each repetition gives the item's parameters one more value;
- a field whose type another field gives (PTC 11, deduced) is an ``IndirectParameterRefEntry``:
  the selector's value picks the parameter by alias. A parameter value report (TM[20,2])
  fills the database's own parameters (alias name space ``pus-parameter``); other reports
  fill parameters of their own, one per database parameter (``max_SolarPanel_speed``);
- an embedded telecommand (PTC 12: schedules, sequences, event-actions) is its packet header,
  PUS header, application data and error control;
- service 12's items are a head, then the fields its check type selects, each variant a
  container included when the check type matches (XTCE ``IncludeCondition``).
"""

import xml.etree.ElementTree as ET

from obsw.pus.fields import Boolean, Real, Signed, Unsigned
from obsw.pus.ptc_strings import BitString, CharacterString, OctetString, Packet
from obsw.pus.ptc_time import AbsoluteTime, RelativeTime
from obsw.pus.services import s18_layouts as s18
from obsw.pus.services.s12_layouts import FMON_STATUS_NAMES, PMON_COUNT, STATUS_NAMES, Items
from obsw.pus.services.s20_parameters import DEFINITION_NAMES
from obsw.pus.structure import Deduced, Repeated, Structure
from obsw.timecode import Cuc

from obsw_host.yamcs.xtce_types import XtceTypeError, octets_type, parameter_type

PID = "pus-parameter"  # alias name space: a database parameter by its ID
# service 12 transitions fill the monitored parameter's own parameters (name spaces by
# parameter ID): its value, the limit it crossed, its previous and current check states
TRANSITION = {
    "value": PID,
    "limit": "pus-limit-crossed",
    "previous": "pus-previous-check",
    "current": "pus-check-state",
}
CHECK_ALARMS = {"below_low": "critical", "above_high": "critical", "invalid": "warning"}
_TRANSITION_REPORTS = ("check_transition", "out_of_limits")
_PID_KEYS = ("id", "parameter")  # the selectors of deduced fields that are parameter IDs
# reports whose "id" fields are parameter IDs (elsewhere an ID of what the service manages)
_PID_REPORTS = (
    "parameter_values",
    "parameter_definitions",
    "statistics",
    "statistics_definitions",
)
_CANDIDATES = {s18.arg_type: s18.ARG_TYPES}  # other selectors: the values they may take


def _sub(parent, tag, **attrs):
    return ET.SubElement(parent, tag, {k: str(v) for k, v in attrs.items()})


def _label(text):
    return "".join(c if c.isalnum() or c in "_-" else "_" for c in str(text))


def _string_type(ft):
    """A character string: PFC octets, or as many as its leading length field says."""
    t = ET.Element("StringParameterType")
    _sub(t, "UnitSet")
    enc = _sub(t, "StringDataEncoding", encoding="UTF-8")
    if ft.pfc:
        fixed = _sub(_sub(enc, "SizeInBits"), "Fixed")
        ET.SubElement(fixed, "FixedValue").text = str(8 * ft.pfc)
    else:
        var = _sub(enc, "Variable", maxSizeInBits=8 * ((1 << ft.length_bits) - 1))
        _sub(var, "LeadingSize", sizeInBitsOfSizeTag=ft.length_bits)
    return t


def _time_type(ft):
    code = ft.code
    if not isinstance(code, Cuc) or code.epoch is not None:
        return parameter_type("", (0, ft.bits))  # the raw T-field
    t = ET.Element("AbsoluteTimeParameterType")
    enc = _sub(t, "Encoding", units="seconds", scale=repr(2.0 ** (-8 * code.fine)), offset="0")
    _sub(enc, "IntegerDataEncoding", sizeInBits=ft.bits, encoding="unsigned")
    ET.SubElement(_sub(t, "ReferenceTime"), "Epoch").text = "TAI"
    return t


def _duration_type(ft):
    t = ET.Element("FloatParameterType", sizeInBits="64")
    ET.SubElement(_sub(t, "UnitSet"), "Unit").text = "s"
    enc = _sub(t, "IntegerDataEncoding", sizeInBits=ft.bits, encoding="twosComplement")
    poly = _sub(_sub(enc, "DefaultCalibrator"), "PolynomialCalibrator")
    _sub(poly, "Term", coefficient="0.0", exponent=0)
    _sub(poly, "Term", coefficient=repr(2.0 ** (-8 * ft.code.fine)), exponent=1)
    return t


def _entry(ref, repeat=None, include=None, container=False):
    if container:
        e = ET.Element("ContainerRefEntry", containerRef=ref)
    else:
        e = ET.Element("ParameterRefEntry", parameterRef=ref)
    if repeat is not None:
        dyn = _sub(_sub(_sub(e, "RepeatEntry"), "Count"), "DynamicValue")
        _sub(dyn, "ParameterInstanceRef", parameterRef=repeat)
    if include is not None:
        ref, value = include
        _sub(_sub(e, "IncludeCondition"), "Comparison", parameterRef=ref, value=value)
    return e


def _indirect(selector, namespace):
    e = ET.Element("IndirectParameterRefEntry", aliasNameSpace=namespace)
    _sub(e, "ParameterInstance", parameterRef=selector, useCalibratedValue="false")
    return e


class ReportWriter:
    """Writes report containers into a ``xtce.Generator`` (see the module text)."""

    def __init__(self, gen):
        self.gen = gen
        self.tm = gen.root.child("TM")
        sc = gen.sc
        self.pids = {pid: _label(p.qualified) for pid, p in sc.params.items()}
        events = {e.id: _label(e.qualified) for e in sc.events.values()}
        events[0] = "none"
        yes_no = {0: "disabled", 1: "enabled"}
        # fields named so carry these labels, in every report
        self.labels = {
            "event": events,
            "low_event": events,
            "high_event": events,
            "parameter": self.pids,
            "validity": self.pids,
            "enabled": yes_no,
            "previous": {k: _label(v) for k, v in STATUS_NAMES.items()},
            "current": {k: _label(v) for k, v in STATUS_NAMES.items()},
            "checking": {k: _label(v) for k, v in FMON_STATUS_NAMES.items()},
            "kind": {k: _label(v) for k, v in DEFINITION_NAMES.items()},
        }
        self.alarms = {"checking": {"failed": "critical"}, "current": CHECK_ALARMS}
        self._embedded = None
        self._per_pid = {}  # name space -> True once its parameters exist

    # ------------------------------------------------------------------ reports
    def write(self, msg_type, name, layout):
        system = self.tm.child(name)
        self.name = name
        entries = self._layout(system, [], layout, {})
        self.gen.report(name, msg_type, entries)

    def _layout(self, system, path, layout, scope):
        if isinstance(layout, Items):
            return self._items(system, path, layout, scope)
        entries = []
        for fname, ft in layout.fields:
            where = path + [str(fname)]
            if isinstance(ft, Repeated):
                entries += self._repeated(system, where, ft, scope)
            elif isinstance(ft, Structure):
                entries += self._layout(system, where, ft, scope)
            elif isinstance(ft, Deduced):
                entries.append(self._deduced(system, where, ft, scope))
            else:
                entries += self._field(system, where, ft, scope)
        return entries

    def _repeated(self, system, path, rep, scope):
        count = self._param(system, ["number_of"] + path, parameter_type("", _pair(rep.counter)))
        item = rep.item
        inner = dict(scope)
        if isinstance(item, Structure):
            entries = self._layout(system, path, item, inner)
        elif isinstance(item, Deduced):
            entries = [self._deduced(system, path, item, inner)]
        else:
            entries = self._field(system, path, item, inner)
        ref = self._item_container(system, path, entries)
        return [_entry(count), _entry(ref, repeat=count, container=True)]

    def _items(self, system, path, items, scope):
        """Service 12's Items: prefix, N, then N heads each with its check type's fields."""
        entries = []
        if items.prefix is not None:
            entries += self._layout(system, path, items.prefix, scope)
        where = path + ["items"]
        count = self._param(system, ["number_of"] + where, parameter_type("", _pair(PMON_COUNT)))
        inner = dict(scope)
        item = self._layout(system, where, items.head, inner)
        check = inner["check"]
        for value, variant in sorted(items.variants.items()):
            sub = dict(inner)
            fields = self._layout(system, where + ["check%d" % value], variant, sub)
            ref = self._item_container(system, where + ["check%d" % value], fields)
            item.append(_entry(ref, include=(check, value), container=True))
        ref = self._item_container(system, where, item)
        return entries + [_entry(count), _entry(ref, repeat=count, container=True)]

    def _item_container(self, system, path, entries):
        name = "_".join([self.name] + path + ["item"])
        c = ET.Element("SequenceContainer", name=_label(name), abstract="true")
        lst = _sub(c, "EntryList")
        lst.extend(entries)
        system.containers.append(c)
        return system.path + "/" + _label(name)

    # ------------------------------------------------------------------ fields
    def _param(self, system, path, ptype, description=None):
        return system.parameter(_label("_".join(path)), ptype, description)

    def _field(self, system, path, ft, scope):
        """The entries of one fixed-type field (most often one); records it in ``scope``."""
        last = path[-1]
        if self.name in _TRANSITION_REPORTS and last in ("previous", "current"):
            return [_indirect(scope["parameter"], TRANSITION[last])]
        if isinstance(ft, Packet):
            return [_entry(self._embedded_tc(), container=True)]
        if isinstance(ft, CharacterString):
            ref = self._param(system, path, _string_type(ft))
        elif isinstance(ft, OctetString):
            if ft.pfc:
                return [_entry(self._param(system, path, octets_type("", (7, ft.pfc))))]
            size = parameter_type("", (0, ft.length_bits))
            length = self._param(system, path + ["length"], size)
            data = self._param(system, path, octets_type("", (7, 0), length))
            return [_entry(length), _entry(data)]
        elif isinstance(ft, AbsoluteTime):
            ref = self._param(system, path, _time_type(ft))
        elif isinstance(ft, RelativeTime):
            ref = self._param(system, path, _duration_type(ft))
        elif isinstance(ft, BitString) and ft.pfc:
            ref = self._param(system, path, parameter_type("", (0, ft.pfc)))
        elif isinstance(ft, (Boolean, Unsigned, Signed, Real)):
            labels = self.labels.get(last)
            if last == "id" and self.name in _PID_REPORTS:
                labels = self.pids
            pair = _pair(ft)
            labels = labels if pair[0] in (2, 3) else None
            alarms = self.alarms.get(last) if labels is not None else None
            ptype = parameter_type("", pair, labels=labels, alarms=alarms)
            ref = self._param(system, path, ptype)
        else:
            raise XtceTypeError("%s: no XTCE form for %s" % (".".join(path), ft.name))
        scope[last] = ref
        return [_entry(ref)]

    def _deduced(self, system, path, ft, scope):
        selector = scope.get(ft.key)
        if selector is None:
            raise XtceTypeError("%s: its selector %s comes after it" % (".".join(path), ft.key))
        if self.name in _TRANSITION_REPORTS and path[-1] in TRANSITION:
            return _indirect(selector, TRANSITION[path[-1]])  # the monitored parameter's own
        if ft.key in _PID_KEYS:
            if self.name == "parameter_values":
                return _indirect(selector, PID)  # the database's own parameters
            namespace = "pus-" + _label("_".join([self.name] + path))
            if namespace not in self._per_pid:
                self._per_pid[namespace] = True
                for pid, p in sorted(self.gen.sc.params.items()):
                    if p.pair[0] in (7, 8):
                        continue  # statistics and limits are of numbers only
                    ptype = parameter_type("", p.pair, p.unit)
                    name = _label("_".join(path + [self.pids[pid]]))
                    system.parameter(name, ptype, aliases={namespace: pid})
            return _indirect(selector, namespace)
        candidates = _CANDIDATES.get(ft.lookup)
        if candidates is None:
            raise XtceTypeError("%s: the values of selector %s are not known" % (path, ft.key))
        namespace = "pus-" + _label("_".join([self.name] + path))
        if namespace not in self._per_pid:
            self._per_pid[namespace] = True
            for value in candidates:
                vt = ft.resolve(value)
                name = _label("_".join(path + [str(value)]))
                if isinstance(vt, CharacterString):
                    ptype = _string_type(vt)
                elif isinstance(vt, OctetString):
                    # no leading size for binary data in Yamcs: as a string of its octets
                    ptype = _string_type(vt)
                    ptype.find("StringDataEncoding").set("encoding", "ISO-8859-1")
                else:
                    ptype = parameter_type("", _pair(vt))
                system.parameter(name, ptype, aliases={namespace: value})
        return _indirect(selector, namespace)

    def _embedded_tc(self):
        """The container of a TC packet carried in a report (made once)."""
        if self._embedded is not None:
            return self._embedded
        system = self.tm.child("embedded_tc")
        cfg = self.gen.cfg
        fields = [
            ("version", 3),
            ("type", 1),
            ("secondary_header_flag", 1),
            ("apid", 11),
            ("sequence_flags", 2),
            ("sequence_count", 14),
            ("data_length", 16),
            ("pus_version", 4),
            ("ack_flags", 4),
            ("service", 8),
            ("subtype", 8),
        ]
        if cfg.source_id_size:
            fields.append(("source_id", 8 * cfg.source_id_size))
        if cfg.tc_spare:
            fields.append(("spare", 8 * cfg.tc_spare))
        refs = {}
        entries = []
        for name, bits in fields:
            refs[name] = system.parameter("tc_" + name, parameter_type("", (0, bits)))
            entries.append(_entry(refs[name]))
        # application data: the packet's length field + 1, less the PUS header and the PEC
        data = ET.Element("BinaryParameterType")
        size = _sub(_sub(data, "BinaryDataEncoding"), "SizeInBits")
        dyn = _sub(size, "DynamicValue")
        _sub(dyn, "ParameterInstanceRef", parameterRef=refs["data_length"])
        intercept = 8 * (1 - cfg.tc_header_size - cfg.pec_size)
        _sub(dyn, "LinearAdjustment", slope="8", intercept=str(intercept))
        entries.append(_entry(system.parameter("tc_application_data", data)))
        if cfg.pec:
            entries.append(_entry(system.parameter("tc_pec", parameter_type("", (0, 16)))))
        c = ET.Element("SequenceContainer", name="embedded_tc", abstract="true")
        _sub(c, "EntryList").extend(entries)
        system.containers.append(c)
        self._embedded = system.path + "/embedded_tc"
        return self._embedded


def _pair(ft):
    return (ft.ptc, ft.pfc)
