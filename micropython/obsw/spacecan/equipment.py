"""Equipment components: one interaction-layer interface per SpaceCAN node, from its definition.

The interface is generated at run time from the node definition (spacecan's JSON):

- an attribute (read-only, ``DATA``) per parameter, named as the parameter, fed by the
  node's housekeeping reports and parameter replies (None until the first value came);
- an asynchronous operation per service 8 function, named as the function, whose parameters
  are the function's arguments (by argument id), checked against their encodings;
- the generic operations ``request_parameters``, ``set_parameters``,
  ``request_housekeeping``, ``enable_housekeeping``, ``disable_housekeeping`` and ``ping``;
- the events ``housekeeping`` (a report came), ``command_failed`` (a (1,2) or (1,8) for
  this node) and ``unresponsive`` (a request to this node timed out).

A node named ``CpduN`` with parameter ``state_bits`` and function ``set_state_bits`` gives
``CpduN.state_bits`` and ``CpduN.set_state_bits``. Operations call the SpaceCAN master through
the interaction layer, so the master may run in this process or another one.

Ids are derived from the definition: interface ``0x100 + node id``, attribute
``0x100 + parameter id``, function operation ``0x200 + function id``, generic operations
from ``0x300``, events from ``0x380``. A generic member whose name a parameter or function
already uses is left out (the node's own member wins).
"""

from obsw.compat import const
from obsw.il.errors import ComponentError
from obsw.il.interface import (  # noqa: F401 (check_unique_ids: re-exported for the OBC)
    DATA,
    EVENT,
    INFO,
    LOW,
    MEDIUM,
    Attribute,
    Event,
    Interface,
    Operation,
    check_unique_ids,
)
from obsw.il.message import RUNNING
from obsw.spacecan import encoding as enc
from obsw.spacecan.ids import check_node_id
from obsw.spacecan.master import BAD_REQUEST, MASTER_NAME
from obsw.spacecan.nodedef import NodeDefinition

INTERFACE_BASE = const(0x100)
PARAMETER_BASE = const(0x100)
FUNCTION_BASE = const(0x200)
SERVICE_BASE = const(0x300)
EVENT_BASE = const(0x380)

# generic operations: (name, parameters, description), ids SERVICE_BASE + index
GENERIC = (
    ("request_parameters", ("names",), "(20,1) of the named parameters (None: all)"),
    ("set_parameters", ("values",), "(20,3) with {name: value}"),
    ("request_housekeeping", ("report_ids",), "(3,27) one-shot reports"),
    ("enable_housekeeping", ("report_ids",), "(3,5) periodic reports on"),
    ("disable_housekeeping", ("report_ids",), "(3,6) periodic reports off"),
    ("ping", (), "(17,1) connection test"),
)
# events: (name, severity, fields), ids EVENT_BASE + index
EVENTS = (
    ("housekeeping", INFO, ("report_id", "values")),
    ("command_failed", LOW, ("service", "subtype", "report")),
    ("unresponsive", MEDIUM, ("service", "subtype", "attempts", "error")),
)


class EquipmentError(ValueError):
    """A node definition that cannot become an interface (two members with one name)."""

    def __init__(self, msg, name=None):
        super().__init__(msg)
        self.name = name


def member_name(name, fallback):
    """``name`` with every character other than letters, digits and '_' made '_'."""
    if not name:
        return fallback
    out = []
    for ch in name:
        out.append(ch if ch.isalpha() or ch.isdigit() or ch == "_" else "_")
    return "".join(out)


def _claim(used, name, what):
    if name in used:
        raise EquipmentError("%s and %s are both called %r" % (used[name], what, name), name)
    used[name] = what


def _arguments(f):
    """[(argument id, encoding, parameter name)] of function ``f``, by argument id."""
    out = []
    seen = {}
    for aid in sorted(f.arguments):
        a = f.arguments[aid]
        _claim(seen, member_name(a.name, "arg_%d" % aid), "argument %d" % aid)
        out.append((aid, a.encoding, member_name(a.name, "arg_%d" % aid)))
    return out


def equipment_interface(name, node_id, nodedef, interface_id=None):
    """The ``Interface`` of node ``node_id`` described by ``nodedef`` (see the module text)."""
    check_node_id(node_id)
    members = []
    used = {}
    for pid in sorted(nodedef.parameters):
        p = nodedef.parameters[pid]
        n = member_name(p.name, "parameter_%d" % pid)
        _claim(used, n, "parameter %d" % pid)
        members.append(
            Attribute(
                n, PARAMETER_BASE + pid, DATA, type=p.encoding, description="parameter %d" % pid
            )
        )
    for fid in sorted(nodedef.functions):
        f = nodedef.functions[fid]
        n = member_name(f.name, "function_%d" % fid)
        _claim(used, n, "function %d" % fid)
        params = [a[2] for a in _arguments(f)]
        members.append(
            Operation(
                n,
                FUNCTION_BASE + fid,
                params,
                asynchronous=True,
                description="(8,1) function %d" % fid,
            )
        )
    for i, (n, params, doc) in enumerate(GENERIC):
        if n not in used:
            used[n] = "generic"
            members.append(
                Operation(n, SERVICE_BASE + i, params, asynchronous=True, description=doc)
            )
    for i, (n, severity, fields) in enumerate(EVENTS):
        if n not in used:
            used[n] = "event"
            members.append(Event(n, EVENT_BASE + i, severity, fields=fields))
    if interface_id is None:
        interface_id = INTERFACE_BASE + node_id
    return Interface(name, interface_id, members, description="SpaceCAN node %d" % node_id)


class _Members:
    """The provider's implementation object: only the interface's members live here."""


class Equipment:
    """An equipment component: ``interface`` provided by ``provide(node)`` (module text).

    ``master`` names the SpaceCAN master component; ``timeout`` bounds finding it.
    """

    def __init__(
        self, name, node_id, nodedef, *, master=MASTER_NAME, interface_id=None, timeout=5.0
    ):
        self.name = name
        self.node_id = node_id
        self.nodedef = nodedef
        self.interface = equipment_interface(name, node_id, nodedef, interface_id)
        self.master = master
        self.timeout = timeout
        self.node = None
        self.provider = None
        self.subscription = None
        self.names = {}  # parameter id -> attribute name
        self.ids = {}  # attribute name -> parameter id
        self.reports = 0
        self.values = impl = _Members()
        self._outstanding = []  # [pending, job, on_result] of calls to the master
        itf = self.interface
        for pid in sorted(nodedef.parameters):
            m = itf.by_id[PARAMETER_BASE + pid]
            self.names[pid] = m.name
            self.ids[m.name] = pid
            setattr(impl, m.name, None)
        for fid in sorted(nodedef.functions):
            m = itf.by_id[FUNCTION_BASE + fid]
            setattr(impl, m.name, self._function(fid, _arguments(nodedef.functions[fid])))
        generic = {
            "request_parameters": self._request_parameters,
            "set_parameters": self._set_parameters,
            "request_housekeeping": self._reports("request_housekeeping"),
            "enable_housekeeping": self._reports("enable_housekeeping"),
            "disable_housekeeping": self._reports("disable_housekeeping"),
            "ping": self._ping,
        }
        for i in range(len(GENERIC)):
            m = itf.by_id.get(SERVICE_BASE + i)
            if m is not None:
                setattr(impl, m.name, generic[m.name])

    @classmethod
    def from_json(cls, name, node_id, text, **kw):
        """From the node definition JSON text (spacecan's services file)."""
        return cls(name, node_id, NodeDefinition.from_json(text, node_id), **kw)

    def __repr__(self):
        return "Equipment(%s, node %d)" % (self.name, self.node_id)

    def provide(self, node, inbox=8):
        """Provide the interface on IL ``node`` and subscribe to the master; the provider."""
        self.node = node
        self.provider = node.provide(self.interface, self.values, inbox)
        self.subscription = node.subscribe(
            self.master + ".*", self._on_master, timeout=self.timeout, length=32
        )
        return self.provider

    # -- operations ----------------------------------------------------------------------------

    def _function(self, fid, specs):
        def perform(job, *args):
            values = {}
            for i in range(len(specs)):
                aid, encoding, pname = specs[i]
                try:
                    enc.encode(encoding, args[i])
                except enc.EncodingError as e:
                    raise ComponentError(  # noqa: B904
                        BAD_REQUEST,
                        "%s.%s argument %s: %s" % (self.name, job.operation.name, pname, e),
                        {"argument": pname, "value": args[i]},
                    )
                values[aid] = args[i]
            self._forward(
                job, "call_function", (self.node_id, fid, values or None), then=self._read_back
            )

        return perform

    def _read_back(self, job, value):
        """A function's effect readable as soon as its job ends: the node's parameters are read
        back first; the function succeeded, so a failed read-back still ends the job with
        ``value`` (the housekeeping reports bring the values later)."""
        ids = sorted(self.nodedef.parameters)
        if not ids:
            job.succeed(value)
            return

        def keep(rec):
            self._parameter_result(rec)
            return value

        self._forward(job, "request_parameters", (self.node_id, ids), keep, fallback=(value,))

    def _parameter_ids(self, names):
        if names is None or names == []:
            return sorted(self.nodedef.parameters)
        if isinstance(names, str):
            names = [names]
        out = []
        for n in names:
            pid = self.ids.get(n)
            if pid is None:
                raise ComponentError(
                    BAD_REQUEST, "%s has no parameter %r" % (self.name, n), {"parameter": n}
                )
            out.append(pid)
        return out

    def _request_parameters(self, job, names):
        ids = self._parameter_ids(names)
        self._forward(job, "request_parameters", (self.node_id, ids), self._parameter_result)

    def _parameter_result(self, rec):
        out = {}
        values = rec.get("result") or {}
        for pid in values:
            name = self.names.get(pid)
            if name is not None:
                # readable at once; the parameter_report publication follows from the master
                setattr(self.values, name, values[pid])
                out[name] = values[pid]
        return out

    def _set_parameters(self, job, values):
        if not isinstance(values, dict) or not values:
            raise ComponentError(BAD_REQUEST, "values must be a non-empty {name: value} dict")
        by_id = {}
        for name in values:
            pid = self._parameter_ids([name])[0]
            try:
                enc.encode(self.nodedef.parameters[pid].encoding, values[name])
            except enc.EncodingError as e:
                raise ComponentError(BAD_REQUEST, "%s: %s" % (name, e), {"parameter": name})  # noqa: B904
            by_id[pid] = values[name]

        def written(rec):
            for pid in by_id:
                self.provider.update(self.names[pid], by_id[pid])
            return rec

        self._forward(job, "set_parameters", (self.node_id, by_id), written)

    def _reports(self, member):
        def reports(job, report_ids):
            if isinstance(report_ids, int):
                report_ids = [report_ids]
            self._forward(job, member, (self.node_id, list(report_ids or ())))

        return reports

    def _ping(self, job):
        self._forward(job, "ping", (self.node_id,))

    def _forward(self, job, member, args, on_result=None, then=None, fallback=None):
        """Call the master's ``member``; its outcome (through ``on_result``) ends ``job``, or
        goes to ``then(job, value)``; with ``fallback`` ``(value,)`` a failure ends it so."""
        entry = [None, job, on_result, then, fallback]

        def status(pending, state, value):
            if state == RUNNING:
                if value is not None:
                    job.update(value)
            else:
                self._finish(entry)

        entry[0] = p = self.node.start(
            self.master + "." + member, args, timeout=self.timeout, on_status=status
        )
        self._outstanding.append(entry)
        if p.done:  # the link to a remote master was down
            self._finish(entry)

    def _finish(self, entry):
        if entry in self._outstanding:
            self._outstanding.remove(entry)
        p, job, on_result, then, fallback = entry
        if job.done:
            return
        try:
            value = p.outcome()
            if on_result is not None:
                value = on_result(value)
        except Exception as e:  # a malformed record must fail the job, not the caller's loop
            if fallback is not None:
                job.succeed(fallback[0])
            else:
                job.fail(e)
            return
        if then is not None:
            then(job, value)
            return
        job.succeed(value)

    def check(self):
        """Finish jobs whose call to the master ended without a status (its link went down)."""
        for entry in list(self._outstanding):
            if entry[0].done:
                self._finish(entry)
        return len(self._outstanding)

    # -- what the master publishes ---------------------------------------------------------------

    def _emit(self, name, payload):
        m = self.interface.members.get(name)
        if m is not None and m.member == EVENT:
            self.provider.emit(name, payload)

    def _feed(self, values):
        named = {}
        if isinstance(values, dict):
            for pid in values:
                name = self.names.get(pid)
                if name is not None:
                    self.provider.update(name, values[pid])
                    named[name] = values[pid]
        return named

    def _on_master(self, pub):
        v = pub.value
        if not isinstance(v, dict) or v.get("node") != self.node_id:
            return
        member = pub.member
        if member == "housekeeping_report":
            self.reports += 1
            named = self._feed(v.get("values"))
            self._emit("housekeeping", {"report_id": v.get("report_id"), "values": named})
        elif member == "parameter_report":
            self._feed(v.get("values"))
        elif member == "verification_failure":
            self._emit(
                "command_failed",
                {
                    "service": v.get("service"),
                    "subtype": v.get("subtype"),
                    "report": v.get("report"),
                },
            )
        elif member == "request_timeout":
            self._emit(
                "unresponsive",
                {
                    "service": v.get("service"),
                    "subtype": v.get("subtype"),
                    "attempts": v.get("attempts"),
                    "error": v.get("error"),
                },
            )
