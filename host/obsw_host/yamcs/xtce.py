"""XTCE (Yamcs mission database) generated from the spacecraft database, nothing hand-written.

``generate(spacecraft)`` returns the XML text of one SpaceSystem named after the mission:
- the packet headers (``ccsds`` root, ``pus_tm`` with the PUS-C secondary header of
  ``obsw.pus.config.PusConfig``), every report the OBC sends: service 1 verification reports,
  3 housekeeping structures (one container per SID, the database's parameters in order),
  5 event reports (one container per event with its auxiliary data), 12 check transitions
  (with an alarm on the monitored parameter's checking state), 17 and 20 reports;
- the parameters in one sub-system per component (``/MISSION/SolarPanel/angle``) with their
  types, units, calibrations and alarm limits where the database gives them;
- the telecommands: an abstract ``pus_tc`` whose verifiers follow the service 1 reports
  (acceptance, start, completion, by APID and sequence count); the standard services'
  commands, each walked from the layout the OBC decodes it with (``command_layouts``); from
  the database, services 8 (one command per function with its typed arguments), 12 (a limit
  check for each parameter with limits) and 20 (one set command per writable parameter, its
  range checked);
- the mission's own services (types 128..255): a command per request, a container per report.
"""

import xml.etree.ElementTree as ET

from obsw.pus import messages as M
from obsw.pus.calibration import CalibrationError, Values
from obsw.pus.config import PusConfig
from obsw.pus.fields import PTC_UNSIGNED, field
from obsw.pus.packets import ACK_ALL
from obsw.pus.ptc_strings import OctetString
from obsw.pus.ptc_time import AbsoluteTime
from obsw.pus.services.s01_verification import FAILURE_NAMES
from obsw.pus.services.s12_layouts import STATUS_NAMES
from obsw.pus.structure import Repeated, Structure

from obsw_host.yamcs.command_layouts import APID, COMMANDS, Arg, Fixed
from obsw_host.yamcs.report_layouts import report_layouts
from obsw_host.yamcs.xtce_reports import CHECK_ALARMS, PID, TRANSITION, ReportWriter
from obsw_host.yamcs.xtce_types import (
    argument_type,
    linear,
    octets_argument_type,
    octets_type,
    parameter_type,
    text_argument_type,
)

XTCE_NS = "http://www.omg.org/spec/XTCE/20180204"
U8, U16, U32, E8, E16 = (3, 4), (3, 12), (3, 14), (2, 8), (2, 16)
SEVERITY_LEVELS = {1: "watch", 2: "warning", 3: "distress", 4: "critical"}
_UNSIGNED_PFC = {8: 4, 16: 12, 24: 13, 32: 14}  # PTC 3: PFC by width in bits


class XtceNameError(ValueError):
    """Two things of the database would get one name in the mission database."""


def _sub(parent, tag, **attrs):
    return ET.SubElement(parent, tag, {k: str(v) for k, v in attrs.items()})


def _label(text):
    return "".join(c if c.isalnum() or c in "_-" else "_" for c in text)


class SpaceSystem:
    """One XTCE SpaceSystem being built: its types, parameters, containers and commands."""

    def __init__(self, name, path):
        self.name = name
        self.path = path  # absolute, '/MISSION/SolarPanel'
        self.children = {}
        self.ptypes = []
        self.params = []
        self.containers = []
        self.atypes = []
        self.commands = []

    def child(self, name):
        s = self.children.get(name)
        if s is None:
            s = self.children[name] = SpaceSystem(name, self.path + "/" + name)
        return s

    def parameter(self, name, ptype, description=None, aliases=None):
        """Add a parameter of type element ``ptype`` (``aliases`` {name space: alias});
        returns its absolute reference."""
        if any(p.get("name") == name for p in self.params):
            raise ValueError("%s: two parameters named %s (an attribute, and an event's field "
                             "or a generated one): rename one" % (self.path, name))  # fmt: skip
        ptype.set("name", name + "_t")
        self.ptypes.append(ptype)
        p = ET.Element("Parameter", name=name, parameterTypeRef=name + "_t")
        if description:
            p.set("shortDescription", description)
        if aliases:
            alias_set = _sub(p, "AliasSet")
            for space, alias in sorted(aliases.items()):
                _sub(alias_set, "Alias", nameSpace=space, alias=alias)
        self.params.append(p)
        return self.path + "/" + name

    def element(self):
        ss = ET.Element("SpaceSystem", name=self.name)
        if self.params or self.containers:
            tm = _sub(ss, "TelemetryMetaData")
            _sub(tm, "ParameterTypeSet").extend(self.ptypes)
            _sub(tm, "ParameterSet").extend(self.params)
            if self.containers:
                _sub(tm, "ContainerSet").extend(self.containers)
        if self.commands:
            cm = _sub(ss, "CommandMetaData")
            if self.atypes:
                _sub(cm, "ArgumentTypeSet").extend(self.atypes)
            _sub(cm, "MetaCommandSet").extend(self.commands)
        for c in self.children.values():
            ss.append(c.element())
        return ss


def _container(name, base, conditions, entries=(), archive=False):
    """A SequenceContainer: ``conditions`` [(parameter ref, value)], ``entries`` parameter refs
    or (ref, absolute bit offset) pairs."""
    c = ET.Element("SequenceContainer", name=name)
    if archive:
        anc = _sub(c, "AncillaryDataSet")
        _sub(
            anc, "AncillaryData", name="Yamcs", mimeType="text/plain"
        ).text = "UseAsArchivingPartition"
    lst = _sub(c, "EntryList")
    for e in entries:
        if isinstance(e, ET.Element):  # an entry made by the caller (xtce_reports)
            lst.append(e)
            continue
        ref, offset = e if isinstance(e, tuple) else (e, None)
        entry = _sub(lst, "ParameterRefEntry", parameterRef=ref)
        if offset is not None:
            loc = _sub(entry, "LocationInContainerInBits", referenceLocation="containerStart")
            _sub(loc, "FixedValue").text = str(offset)
    if base is not None:
        b = _sub(c, "BaseContainer", containerRef=base)
        if conditions:
            rc = _sub(b, "RestrictionCriteria")
            cl = _sub(rc, "ComparisonList")
            for ref, value in conditions:
                _sub(cl, "Comparison", parameterRef=ref, value=value, comparisonOperator="==")
    return c


class Generator:
    """Builds the mission's SpaceSystem from a ``database.Spacecraft``."""

    def __init__(self, sc, config=None):
        self.sc = sc
        ids = sc.ids  # the mission's: layout, source id, APIDs
        self.cfg = config or (ids.pus_config if ids is not None else PusConfig())
        self.root = SpaceSystem(_label(sc.mission), "/" + _label(sc.mission))
        self.refs = {}  # parameter id -> absolute reference
        self.entries = {}  # parameter id -> its container entries (a length before octets)
        self.apid = sc.required_apid("pus")
        self.source_id = ids.source_id if ids is not None else 0
        self.labels = {  # the values of a command argument by their names in the mission
            "sid": {s.sid: "sid_%d" % s.sid for s in sc.structures} or None,
            "event": {e.id: _label(e.qualified) for e in sc.events.values()},
            "parameter": {pid: _label(p.qualified) for pid, p in sc.params.items()},
        }

    # ------------------------------------------------------------------ helpers
    def system_of(self, parts):
        s = self.root
        for p in parts:
            s = s.child(_label(p))
        return s

    def header_param(self, name, bits, labels=None, description=None):
        return self.root.parameter(
            name, parameter_type(name, (0, bits), labels=labels), description
        )

    # ------------------------------------------------------------------ telemetry
    def headers(self):
        r = self.root
        cfg = self.cfg
        h = {}
        for name, bits in (
            ("ccsds_version", 3),
            ("ccsds_type", 1),
            ("ccsds_secondary_header", 1),
            ("apid", 11),
            ("sequence_flags", 2),
            ("sequence_count", 14),
            ("packet_length", 16),
        ):
            h[name] = self.header_param(name, bits)
        r.containers.append(_container("ccsds", None, (), list(h.values())))
        pus = [
            ("pus_version", 4),
            ("time_reference", 4),
            ("service", 8),
            ("subtype", 8),
        ]
        if cfg.message_counter_size:
            pus.append(("message_counter", 8 * cfg.message_counter_size))
        if cfg.destination_id_size:
            pus.append(("destination", 8 * cfg.destination_id_size))
        entries = [self.header_param(n, b) for n, b in pus]
        t = cfg.time
        if t is not None:
            obt = ET.Element("AbsoluteTimeParameterType", name="obt_t")
            enc = _sub(obt, "Encoding", units="seconds", scale=repr(1.0 / (1 << (8 * t.fine))))
            _sub(enc, "IntegerDataEncoding", sizeInBits=8 * (t.coarse + t.fine))
            _sub(_sub(obt, "ReferenceTime"), "Epoch").text = "TAI"
            r.ptypes.append(obt)
            r.params.append(
                ET.Element(
                    "Parameter",
                    name="obt",
                    parameterTypeRef="obt_t",
                    shortDescription="on-board time of the report (CUC, TAI)",
                )
            )
            entries.append(r.path + "/obt")
        self.h = h
        self.service = r.path + "/service"
        self.subtype = r.path + "/subtype"
        r.containers.append(
            _container("pus_tm", "ccsds", [(h["ccsds_secondary_header"], 1)], entries)
        )
        self.data_bits = 8 * (6 + cfg.tm_header_size)

    def report(self, name, msg_type, entries=(), archive=False, base="pus_tm", extra=()):
        conditions = [(self.service, msg_type[0]), (self.subtype, msg_type[1])] + list(extra)
        self.root.containers.append(_container(name, base, conditions, entries, archive))
        return name

    def verification(self):
        r = self.root
        self.v_subtype = self.header_param("verification_subtype", 8)
        self.v_flags = self.header_param("verified_tc_flags", 5)
        self.v_apid = self.header_param("verified_tc_apid", 11)
        self.header_param("verified_tc_sequence_flags", 2)
        self.v_seq = self.header_param("verified_tc_sequence_count", 14)
        self.v_code = r.parameter(
            "failure_code", parameter_type("failure_code", E8, labels=_failure_labels())
        )
        self.v_step = self.header_param("step_id", 8)
        r.containers.append(
            _container(
                "verification",
                "pus_tm",
                [(self.service, 1)],
                [
                    (self.v_subtype, 64),
                    (self.v_flags, self.data_bits),
                    self.v_apid,
                    r.path + "/verified_tc_sequence_flags",
                    self.v_seq,
                ],
            )
        )
        # a failure's data (what failed: a parameter ID, a path...): the rest of the packet
        # after the request ID, the code (and a progress report's step), before the PEC
        data = {}
        for step in (0, 1):
            octets = 1 - self.cfg.tm_header_size - 4 - 1 - step - self.cfg.pec_size
            ptype = ET.Element("BinaryParameterType")
            size = _sub(_sub(ptype, "BinaryDataEncoding"), "SizeInBits")
            dyn = _sub(size, "DynamicValue")
            _sub(dyn, "ParameterInstanceRef", parameterRef=self.h["packet_length"])
            _sub(dyn, "LinearAdjustment", slope="8", intercept=str(8 * octets))
            name = "failure_data" + ("_after_step" if step else "")
            data[step] = r.parameter(name, ptype, "the failure's data, as the OBC sent it")
        self.v_data = data[0]
        for sub, name, entries in (
            (M.TM_VERIFY_ACCEPTANCE_FAILURE, "acceptance_failure", [self.v_code, data[0]]),
            (M.TM_VERIFY_START_FAILURE, "start_failure", [self.v_code, data[0]]),
            (M.TM_VERIFY_PROGRESS_SUCCESS, "progress_success", [self.v_step]),
            (
                M.TM_VERIFY_PROGRESS_FAILURE,
                "progress_failure",
                [self.v_step, self.v_code, data[1]],
            ),
            (M.TM_VERIFY_COMPLETION_FAILURE, "completion_failure", [self.v_code, data[0]]),
            (M.TM_VERIFY_ROUTING_FAILURE, "routing_failure", [self.v_code, data[0]]),
        ):
            r.containers.append(
                _container(name, "verification", [(self.subtype, sub[1])], entries)
            )

    def parameters(self):
        for pid in sorted(self.sc.params):
            p = self.sc.params[pid]
            s = self.system_of(p.path[:-1])
            name = _label(p.path[-1])
            entries = []
            if p.pair[0] == 7:  # octets: a variable string of them goes after its length
                if not p.pair[1]:
                    length = parameter_type("", U16)
                    entries.append(s.parameter(name + "_length", length, "octets of " + name))
                ptype = octets_type("", p.pair, entries[0] if entries else None)
            else:
                ptype = parameter_type(
                    "", p.pair, p.unit, limits=p.limits, calibration=p.calibration, labels=p.labels
                )
            # the alias a value report (TM[20,2]) finds it by; not a variable octet string,
            # which needs its length parameter before it
            aliases = None if entries else {PID: pid}
            self.refs[pid] = s.parameter(name, ptype, p.description, aliases)
            self.entries[pid] = entries + [self.refs[pid]]

    def housekeeping(self):
        r = self.root
        sid = self.header_param("hk_structure_id", 16)
        self.report("hk_report", M.TM_HK_HK_REPORT, [sid])
        for st in self.sc.structures:
            entries = [e for pid in st.parameters for e in self.entries[pid]]
            r.containers.append(
                _container("hk_%d" % st.sid, "hk_report", [(sid, st.sid)], entries, True)
            )

    def events(self):
        r = self.root
        labels = {e.id: _label(e.qualified) for e in self.sc.events.values()}
        self.event_id = r.parameter("event_id", parameter_type("", E16, labels=labels))
        base = self.report("event_report", (5, 0), [self.event_id])
        # the subtype is the severity: match any of 1..4 by leaving it out of the condition
        _drop_condition(r.containers[-1], self.subtype)
        self.templates = []
        for e in sorted(self.sc.events.values(), key=lambda e: e.id):
            s = self.system_of(e.path[:-1])
            refs = []
            for fname, pair, flabels in e.fields:
                pname = "%s_%s" % (_label(e.path[-1]), _label(fname))
                ptype = parameter_type("", pair, labels=flabels)
                refs.append((fname, s.parameter(pname, ptype)))
            r.containers.append(
                _container(
                    "event_" + _label(e.qualified),
                    base,
                    [(self.event_id, labels[e.id])],
                    [ref for _, ref in refs],
                )
            )
            text = e.qualified
            if refs:
                text += ": " + ", ".join("%s={%s}" % (n, ref) for n, ref in refs)
            self.templates.append({"eventId": labels[e.id], "template": text})

    def monitoring(self):
        """Service 12's per-parameter parameters: the limit a numeric parameter crossed and
        its previous and current check states (an alarm when out of limits), which check
        transition reports (TM[12,12], TM[12,11]) fill by alias."""
        states = {k: _label(v) for k, v in STATUS_NAMES.items()}
        for pid in sorted(self.sc.params):
            p = self.sc.params[pid]
            if p.pair[0] not in (2, 3, 4, 5):
                continue
            s = self.system_of(p.path[:-1])
            name = _label(p.path[-1])
            for suffix, ptype, space in (
                ("_limit_crossed", parameter_type("", p.pair, p.unit), TRANSITION["limit"]),
                ("_previous_check", parameter_type("", E8, labels=states), TRANSITION["previous"]),
                (
                    "_check_state",
                    parameter_type("", E8, labels=states, alarms=CHECK_ALARMS),
                    TRANSITION["current"],
                ),
            ):
                s.parameter(name + suffix, ptype, aliases={space: pid})

    def reports(self):
        """Every report of ``report_layouts``, whole (``xtce_reports``)."""
        writer = ReportWriter(self)
        types = lambda pid: field(*self.sc.params[pid].pair)  # noqa: E731
        for msg_type, (name, layout) in sorted(report_layouts(types).items()):
            writer.write(msg_type, name, layout)

    def test_reports(self):
        self.report("are_you_alive_report", M.TM_TEST_ARE_YOU_ALIVE_REPORT)
        apid = self.header_param("connection_test_apid", 16)
        self.report("connection_test_report", M.TM_TEST_ON_BOARD_CONNECTION_REPORT, [apid])

    # ------------------------------------------------------------------ telecommands
    def tc_base(self):
        r = self.root
        cfg = self.cfg
        source_bits = 8 * cfg.source_id_size or 16
        for name, bits in (("apid_t", 11), ("ack_t", 4), ("u8_t", 8), ("source_t", source_bits)):
            r.atypes.append(argument_type(name, (0, bits)))
        cmd = _sub(ET.Element("root"), "MetaCommand", name="pus_tc", abstract="true")
        cmd.set("shortDescription", "PUS-C telecommand: header, then the service's data")
        args = _sub(cmd, "ArgumentList")
        _sub(args, "Argument", name="apid", argumentTypeRef="apid_t", initialValue=self.apid)
        _sub(args, "Argument", name="ack", argumentTypeRef="ack_t", initialValue=ACK_ALL)
        _sub(args, "Argument", name="service", argumentTypeRef="u8_t")
        _sub(args, "Argument", name="subtype", argumentTypeRef="u8_t")
        if cfg.source_id_size:
            _sub(
                args,
                "Argument",
                name="source",
                argumentTypeRef="source_t",
                initialValue=self.source_id,
            )
        cc = _sub(cmd, "CommandContainer", name="pus_tc")
        entries = _sub(cc, "EntryList")
        _fixed(entries, "ccsds_version_type_flag", 0b00011, 5)
        _sub(entries, "ArgumentRefEntry", argumentRef="apid")
        _fixed(entries, "sequence_flags", 3, 2)
        _fixed(entries, "sequence_count", 0, 14)
        _fixed(entries, "packet_length", 0, 16)
        _fixed(entries, "pus_version", 2, 4)
        _sub(entries, "ArgumentRefEntry", argumentRef="ack")
        _sub(entries, "ArgumentRefEntry", argumentRef="service")
        _sub(entries, "ArgumentRefEntry", argumentRef="subtype")
        if cfg.source_id_size:
            _sub(entries, "ArgumentRefEntry", argumentRef="source")
        if cfg.tc_spare:
            _fixed(entries, "spare", 0, 8 * cfg.tc_spare)
        vs = _sub(cmd, "VerifierSet")
        for tag, name, stage, window in (
            ("AcceptedVerifier", "Accepted", 1, "PT10S"),
            ("ExecutionVerifier", "Started", 3, "PT10S"),
            ("CompleteVerifier", "Complete", 7, "PT30S"),
        ):
            v = _sub(vs, tag, name=name)
            alg = _sub(v, "CustomAlgorithm", name="verify_" + name.lower())
            _sub(alg, "AlgorithmText", language="Java").text = (
                'org.yamcs.pus.Pus1Verifier({stage: %d, template: "{code} (data {data})"})' % stage
            )
            inputs = _sub(alg, "InputSet")
            for ref, n in (
                ("/yamcs/cmd/arg/apid", "sentApid"),
                ("/yamcs/cmdHist/ccsds-seqcount", "sentSeq"),
                (self.v_apid, "rcvdApid"),
                (self.v_seq, "rcvdSeq"),
                (self.v_subtype, "reportSubType"),
                (self.v_code, "code"),
                (self.v_data, "data"),
            ):
                _sub(inputs, "InputParameterInstanceRef", parameterRef=ref, inputName=n)
            _sub(
                v,
                "CheckWindow",
                timeToStopChecking=window,
                timeWindowIsRelativeTo="commandRelease",
            )
        r.commands.append(cmd)
        self.tc = r.path + "/pus_tc"

    def command(self, system, name, msg_type, fields=(), description=None):
        """A MetaCommand on ``pus_tc``: ``fields`` are ('fixed', name, value, bits) or
        ('arg', name, argument type element)."""
        if any(c.get("name") == name for c in system.commands):
            raise XtceNameError("two commands named %s/%s" % (system.path, name))
        cmd = ET.Element("MetaCommand", name=name)
        if description:
            cmd.set("shortDescription", description)
        base = _sub(cmd, "BaseMetaCommand", metaCommandRef=self.tc)
        assigns = _sub(base, "ArgumentAssignmentList")
        _sub(assigns, "ArgumentAssignment", argumentName="service", argumentValue=msg_type[0])
        _sub(assigns, "ArgumentAssignment", argumentName="subtype", argumentValue=msg_type[1])
        args = [f for f in fields if f[0] == "arg"]
        if args:
            alist = _sub(cmd, "ArgumentList")
            for _, aname, atype in args:
                tname = "%s_%s_t" % (name, aname)
                atype.set("name", tname)
                system.atypes.append(atype)
                _sub(alist, "Argument", name=aname, argumentTypeRef=tname)
        cc = _sub(cmd, "CommandContainer", name=name)
        entries = _sub(cc, "EntryList")
        for f in fields:
            if f[0] == "fixed":
                _fixed(entries, f[1], f[2], f[3])
            else:
                _sub(entries, "ArgumentRefEntry", argumentRef=f[1])
        _sub(cc, "BaseContainer", containerRef=self.tc)
        system.commands.append(cmd)

    def service_commands(self):
        """The standard services' commands, each walked from the layout the OBC decodes it
        with (``command_layouts``)."""
        pus = self.root.child("PUS")
        for name, msg_type, layout, description, arguments in COMMANDS:
            fields = self.layout_fields(layout.fields, arguments, top=True)
            self.command(pus, name, msg_type, fields, description)

    def layout_fields(self, fields, arguments, top=False):
        """The command entries of a layout's ``fields`` (see ``command_layouts``)."""
        out = []
        for fname, ftype in fields:
            spec = arguments.get(fname, fname)
            if isinstance(spec, str):
                spec = Arg(spec)
            if isinstance(ftype, Repeated):
                count = 0 if isinstance(spec, Fixed) else 1
                first = top and not any(f[1] == "n" for f in out)
                counter = "n" if first else getattr(spec, "name", fname) + "_count"
                out.append(("fixed", counter, count, ftype.counter.bits))
                if count:
                    item = ftype.item
                    item = item.fields if isinstance(item, Structure) else item
                    if isinstance(item, list):
                        out += self.layout_fields(item, arguments)
                    else:
                        out += self.layout_fields([(fname, item)], arguments)
            elif isinstance(spec, Fixed):
                value = self.apid if spec.value == APID else spec.value
                out.append(("fixed", fname, value, ftype.bits))
            elif isinstance(ftype, AbsoluteTime):  # CUC: the seconds, a fraction of 0
                code = ftype.code
                seconds = field(PTC_UNSIGNED, _UNSIGNED_PFC[8 * code.coarse])
                out.append(("arg", spec.name + "_seconds", self.argument(seconds, spec)))
                out.append(("fixed", spec.name + "_fraction", 0, 8 * code.fine))
            else:
                out.append(("arg", spec.name, self.argument(ftype, spec)))
        return out

    def argument(self, ftype, spec):
        """The argument type of a field: its PTC/PFC, the mission's labels, its valid range; a
        variable string of characters or octets is text after its leading length (the
        operator types a path or a procedure; binary loads are the CLI's)."""
        if isinstance(ftype, OctetString) and not ftype.pfc:
            return text_argument_type("", ftype.length_bits)
        labels = spec.labels
        if isinstance(labels, str):
            labels = self.labels[labels]
        return argument_type("", (ftype.ptc, ftype.pfc), valid=spec.valid, labels=labels)

    def parameter_commands(self):
        for pid in sorted(self.sc.params):
            p = self.sc.params[pid]
            if not p.writable:
                continue
            s = self.system_of(p.path[:-1])
            if p.pair == (7, 0):  # variable octets: their length, then them
                value = [
                    ("arg", "length", argument_type("", U16)),
                    ("arg", "value", octets_argument_type("", p.pair, "length")),
                ]
            elif p.pair[0] == 7:
                value = [("arg", "value", octets_argument_type("", p.pair))]
            else:
                value = [("arg", "value", _value_argument(p))]
            self.command(
                s,
                "set_" + _label(p.path[-1]),
                M.TC_PARAM_SET_VALUES,
                [("fixed", "n", 1, 8), ("fixed", "parameter", pid, 16)] + value,
                "TC[20,3] set %s" % p.qualified,
            )

    def monitor_commands(self):
        """TC[12,5] for each parameter with limits: a limit check with the database's critical
        range as default limits (then TC[12,1] enables it)."""
        labels = {e.id: _label(e.qualified) for e in self.sc.events.values()}
        labels[0] = "none"
        for pid in sorted(self.sc.params):
            p = self.sc.params[pid]
            if not p.limits or p.pair[0] not in (2, 3, 4, 5):
                continue
            low, high = p.limits.get("critical") or p.limits.get("warning")
            s = self.system_of(p.path[:-1])
            fields = [("fixed", "n", 1, 16), ("arg", "pmon", argument_type("", U16))]
            fields += [
                ("fixed", "parameter", pid, 16),
                ("fixed", "validity", 0, 16),
                ("fixed", "validity_mask", 0, 32),
                ("fixed", "validity_value", 0, 32),
                ("arg", "interval", argument_type("", U16, valid=(1, 65535))),
                ("arg", "repetitions", argument_type("", U16, valid=(1, 65535))),
                ("fixed", "check", 1, 8),
                ("arg", "low", argument_type("", p.pair, p.unit)),
                ("arg", "low_event", argument_type("", E16, labels=labels)),
                ("arg", "high", argument_type("", p.pair, p.unit)),
                ("arg", "high_event", argument_type("", E16, labels=labels)),
            ]
            name = "monitor_" + _label(p.path[-1])
            self.command(
                s,
                name,
                M.TC_MON_ADD_PARAMETER_MONITORING,
                fields,
                "TC[12,5] limit check of %s" % p.qualified,
            )
            cmd = s.commands[-1]
            defaults = {
                "interval": 1,
                "repetitions": 1,
                "low": low,
                "high": high,
                "low_event": "none",
                "high_event": "none",
            }
            defaults["low"], defaults["high"] = _raw_limits(p, low, high)
            for a in cmd.find("ArgumentList"):
                if defaults.get(a.get("name")) is not None:
                    a.set("initialValue", str(defaults[a.get("name")]))

    def function_commands(self):
        for fid in sorted(self.sc.functions):
            f = self.sc.functions[fid]
            s = self.system_of(f.path[:-1])
            fields = [("fixed", "function", fid, 16), ("fixed", "n", len(f.arguments), 8)]
            for aid, aname, pair, labels in f.arguments:
                fields.append(("fixed", "id_" + _label(aname), aid, 8))
                if pair == (7, 0):  # variable octets: their length, then them
                    length = _label(aname) + "_length"
                    fields.append(("arg", length, argument_type("", U16)))
                    fields.append(("arg", _label(aname), octets_argument_type("", pair, length)))
                    continue
                fields.append(("arg", _label(aname), argument_type("", pair, labels=labels)))
            self.command(
                s, _label(f.path[-1]), M.TC_FUNCTION_PERFORM, fields, "TC[8,1] %s" % f.qualified
            )

    # ------------------------------------------------------------------ ST[12] 17-28, ST[20] 4-7
    def functional_monitoring(self):
        """TC[12,17] to TC[12,27]."""
        ev_labels = {e.id: _label(e.qualified) for e in self.sc.events.values()}
        ev_labels[0] = "none"
        pus = self.root.child("PUS")
        one = ("fixed", "n", 1, 16)

        def fmon_arg():
            return ("arg", "fmon", argument_type("", U16))

        for name, mt in (
            ("fmon_function_enable", M.TC_MON_ENABLE_FUNCTIONAL_MONITORING_FUNCTION),
            ("fmon_function_disable", M.TC_MON_DISABLE_FUNCTIONAL_MONITORING_FUNCTION),
            ("fmon_status_report", M.TC_MON_REPORT_FUNCTIONAL_MONITORING_STATUS),
        ):
            self.command(pus, name, mt)
        for name, mt in (
            ("fmon_enable", M.TC_MON_ENABLE_FUNCTIONAL_MONITORING),
            ("fmon_disable", M.TC_MON_DISABLE_FUNCTIONAL_MONITORING),
            ("fmon_protect", M.TC_MON_PROTECT_FUNCTIONAL_MONITORING),
            ("fmon_unprotect", M.TC_MON_UNPROTECT_FUNCTIONAL_MONITORING),
            ("fmon_delete", M.TC_MON_DELETE_FUNCTIONAL_MONITORING),
            ("fmon_report", M.TC_MON_REPORT_FUNCTIONAL_MONITORING),
        ):
            self.command(pus, name, mt, [one, fmon_arg()])
        for n in (1, 2, 3, 4):  # one command per number of PMONs
            fields = [one, fmon_arg()]
            fields += [
                ("fixed", "validity", 0, 16),
                ("fixed", "validity_mask", 0, 32),
                ("fixed", "validity_value", 0, 32),
                ("arg", "event", argument_type("", E16, labels=ev_labels)),
                ("arg", "failing", argument_type("", U16, valid=(1, n))),
                ("fixed", "n2", n, 16),
            ]
            fields += [("arg", "pmon%d" % i, argument_type("", U16)) for i in range(1, n + 1)]
            self.command(
                pus,
                "fmon_add_%d" % n,
                M.TC_MON_ADD_FUNCTIONAL_MONITORING,
                fields,
                "TC[12,23] an FMON over %d PMON%s" % (n, "s" if n > 1 else ""),
            )

    def parameter_definitions(self):
        """TC[20,4] to TC[20,6]."""
        param_labels = {pid: _label(p.qualified) for pid, p in self.sc.params.items()}
        pus = self.root.child("PUS")
        one = ("fixed", "n", 1, 8)

        def param():
            return ("arg", "parameter", argument_type("", U16, labels=param_labels))

        self.command(
            pus,
            "parameter_definitions_report",
            M.TC_PARAM_REPORT_DEFINITIONS,
            [one, param()],
            "TC[20,6] report where a parameter lives",
        )
        for name, mt, where in (
            ("parameter_define_raw", M.TC_PARAM_CHANGE_RAW_MEMORY_DEFINITIONS, "address"),
            ("parameter_define_object", M.TC_PARAM_CHANGE_OBJECT_MEMORY_DEFINITIONS, "offset"),
        ):
            self.command(
                pus,
                name,
                mt,
                [
                    one,
                    param(),
                    ("arg", "memory", argument_type("", U16)),
                ]
                + ([("arg", "object", argument_type("", U16))] if where == "offset" else [])
                + [("arg", where, argument_type("", U32))],
                "TC[%d,%d] place a parameter in memory (%s)" % (mt[0], mt[1], where),
            )

    def build(self):
        self.headers()
        self.verification()
        self.parameters()
        self.housekeeping()
        self.events()
        self.monitoring()
        self.reports()
        self.test_reports()
        self.tc_base()
        self.service_commands()
        self.parameter_commands()
        self.monitor_commands()
        self.function_commands()
        self.functional_monitoring()
        self.parameter_definitions()
        self.time_reports()
        self.mission_services()
        return self.root.element()

    # ------------------------------------------------------------------ services 128..255
    def mission_services(self):
        """The mission's own services (``services`` of the database): one command per request
        in a sub-system named after the service (``/MISSION/mtq/dipole``), its arguments typed
        with their units and ranges; one container per report (``mtq_dipole_report``)."""
        for stype in sorted(getattr(self.sc, "services", None) or {}):
            svc = self.sc.services[stype]
            system = self.root.child(_label(svc.name))
            for sub in sorted(svc.requests):
                req = svc.requests[sub]
                fields = []
                for f in req.fields:
                    atype = argument_type("", (f.type.ptc, f.type.pfc), f.unit, valid=f.range)
                    fields.append(("arg", _label(f.name), atype))
                what = "TC[%d,%d] %s: %s" % (stype, sub, req.qualified, svc.operation(req))
                self.command(system, _label(req.name), (stype, sub), fields, what)
            for sub in sorted(svc.reports):
                rep = svc.reports[sub]
                refs = []
                for f in rep.fields:
                    pname = "%s_%s" % (_label(rep.name), _label(f.name))
                    refs.append(
                        system.parameter(
                            pname, parameter_type("", (f.type.ptc, f.type.pfc), f.unit)
                        )
                    )
                self.report(_label(rep.qualified), (stype, sub), refs)

    # ------------------------------------------------------------------ services 2, 3, 9, 14
    def time_reports(self):
        """The time reports and the diagnostic report's header (the other reports come from
        their layouts: ``reports``)."""
        exponent = self.header_param("time_rate_exponent", 8)
        status = self.header_param("time_reference_status", 8)
        cuc = [self.header_param("cuc_coarse", 32), self.header_param("cuc_fine", 16)]
        cds = [self.header_param("cds_day", 16), self.header_param("cds_ms_of_day", 32)]
        self.report("cuc_time_report", M.TM_TIME_CUC_REPORT, [exponent] + cuc + [status])
        self.report("cds_time_report", M.TM_TIME_CDS_REPORT, [exponent] + cds + [status])
        diag_sid = self.header_param("diag_structure_id", 16)
        self.report("diag_report", M.TM_HK_DIAG_REPORT, [diag_sid])


def _value_argument(p):
    """The value argument of a set command: a label of an enumeration; an engineering value
    (range checked by Yamcs) when the calibration is linear; else the raw value."""
    if p.labels:
        return argument_type("", p.pair, p.unit, labels=p.labels)
    valid = tuple(p.range) if p.range else None
    if p.calibration:
        if linear(p.calibration):
            return argument_type("", p.pair, p.unit, valid=valid, calibration=p.calibration)
        return argument_type("", p.pair)  # raw: the range is in engineering units
    return argument_type("", p.pair, p.unit, valid=valid)


def _raw_limits(p, low, high):
    """Default raw limits of a limit check from engineering ones (None: not expressible)."""
    if low is None or high is None:
        return None, None
    try:
        values = Values(field(*p.pair), {"calibration": p.calibration})
        raw_low, raw_high, _ = values.raw_limits(low, high)
    except CalibrationError:
        return None, None
    return raw_low, raw_high


def _drop_condition(container, ref):
    for cl in container.iter("ComparisonList"):
        for c in list(cl):
            if c.get("parameterRef") == ref:
                cl.remove(c)


def _fixed(entries, name, value, bits):
    digits = max(1, (bits + 3) // 4)
    if digits % 2:
        digits += 1
    _sub(
        entries,
        "FixedValueEntry",
        name=name,
        binaryValue="%0*x" % (digits, value),
        sizeInBits=bits,
    )


def _failure_labels():
    return {code: _label(text) for code, text in FAILURE_NAMES.items()}


def generate(spacecraft, config=None):
    """The XTCE document (text) of ``spacecraft`` (a ``database.Spacecraft``)."""
    g = Generator(spacecraft, config)
    root = g.build()
    root.set("xmlns", XTCE_NS)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, "unicode") + "\n"


def event_templates(spacecraft, config=None):
    """The PusEventDecoder templates of every event: [{"eventId": label, "template": text}]."""
    g = Generator(spacecraft, config)
    g.build()
    return g.templates
