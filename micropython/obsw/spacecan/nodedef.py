"""SpaceCAN node definition: parameters, housekeeping reports and functions (spacecan's JSON)."""

import json

from obsw.spacecan import encoding as enc


class NodeDefinitionError(ValueError):
    """A node definition that is missing a list, repeats an id, or refers to an unknown one."""

    def __init__(self, msg, key=None):
        super().__init__(msg)
        self.key = key


def _byte_id(what, value):
    if not isinstance(value, int) or isinstance(value, bool) or value < 0 or value > 255:
        raise NodeDefinitionError("%s must be an integer 0..255, got %r" % (what, value), what)
    return value


def _entry(what, obj):
    if not isinstance(obj, dict):
        raise NodeDefinitionError("%s entry must be an object, got %r" % (what, obj), what)
    return obj


def _need(obj, key, what):
    if key not in obj:
        raise NodeDefinitionError("%s entry lacks %r: %r" % (what, key, obj), key)
    return obj[key]


class Parameter:
    """A parameter: id, name, encoding and current value (the default in the file)."""

    def __init__(self, parameter_id, name, encoding, value=0):
        self.parameter_id = _byte_id("parameter_id", parameter_id)
        self.name = name
        try:
            self.encoding = enc.check(encoding)
        except enc.EncodingError as e:
            msg = "parameter %d: %s" % (parameter_id, e)
            raise NodeDefinitionError(msg, "encoding")  # noqa: B904
        self.size = enc.size(encoding)
        try:
            enc.encode(encoding, value)
        except enc.EncodingError as e:
            msg = "parameter %d default: %s" % (parameter_id, e)
            raise NodeDefinitionError(msg, "value")  # noqa: B904
        self.value = value

    def encode(self, value=None):
        return enc.encode(self.encoding, self.value if value is None else value)

    def decode(self, buf, offset=0):
        return enc.decode(self.encoding, buf, offset)

    def to_dict(self):
        return {
            "parameter_id": self.parameter_id,
            "parameter_name": self.name,
            "encoding": self.encoding,
            "value": self.value,
        }


class HousekeepingReport:
    """A housekeeping report: id, interval in seconds, enabled flag and parameter ids in order."""

    def __init__(self, report_id, interval, enabled, parameter_ids):
        self.report_id = _byte_id("report_id", report_id)
        if not isinstance(interval, (int, float)) or isinstance(interval, bool):
            raise NodeDefinitionError(
                "report %d: interval must be a number of seconds, got %r" % (report_id, interval),
                "interval",
            )
        self.interval = interval
        self.enabled = bool(enabled)
        self.parameter_ids = [_byte_id("parameter_ids entry", p) for p in parameter_ids]

    def to_dict(self):
        return {
            "report_id": self.report_id,
            "interval": self.interval,
            "enabled": self.enabled,
            "parameter_ids": list(self.parameter_ids),
        }


class Argument:
    """A function argument: id, name and encoding."""

    def __init__(self, argument_id, name, encoding):
        self.argument_id = _byte_id("argument_id", argument_id)
        self.name = name
        try:
            self.encoding = enc.check(encoding)
        except enc.EncodingError as e:
            msg = "argument %d: %s" % (argument_id, e)
            raise NodeDefinitionError(msg, "encoding")  # noqa: B904
        self.size = enc.size(encoding)

    def to_dict(self):
        return {
            "argument_id": self.argument_id,
            "argument_name": self.name,
            "encoding": self.encoding,
        }


class Function:
    """A function (service 8): id, name and its arguments keyed by id."""

    def __init__(self, function_id, name, arguments=()):
        self.function_id = _byte_id("function_id", function_id)
        self.name = name
        self.arguments = {}
        for a in arguments:
            if a.argument_id in self.arguments:
                raise NodeDefinitionError(
                    "function %d repeats argument id %d" % (function_id, a.argument_id),
                    "argument_id",
                )
            self.arguments[a.argument_id] = a

    def to_dict(self):
        d = {"function_id": self.function_id, "function_name": self.name}
        if self.arguments:
            d["arguments"] = [self.arguments[k].to_dict() for k in sorted(self.arguments)]
        return d


class NodeDefinition:
    """What a node offers: parameters, housekeeping reports and functions, each keyed by id.

    Reads and writes the JSON of spacecan's services file (all three lists are required, extra
    keys are ignored). Controller and responder load the same definition.
    """

    def __init__(self, parameters=(), housekeeping_reports=(), functions=(), node_id=None):
        self.node_id = node_id
        self.parameters = {}
        self.reports = {}
        self.functions = {}
        self._by_name = {}
        for p in parameters:
            if p.parameter_id in self.parameters:
                raise NodeDefinitionError(
                    "repeated parameter_id %d" % p.parameter_id, "parameter_id"
                )
            self.parameters[p.parameter_id] = p
            self._by_name[p.name] = p
        for r in housekeeping_reports:
            if r.report_id in self.reports:
                raise NodeDefinitionError("repeated report_id %d" % r.report_id, "report_id")
            for pid in r.parameter_ids:
                if pid not in self.parameters:
                    raise NodeDefinitionError(
                        "report %d refers to unknown parameter %d" % (r.report_id, pid),
                        "parameter_ids",
                    )
            self.reports[r.report_id] = r
        for f in functions:
            if f.function_id in self.functions:
                raise NodeDefinitionError("repeated function_id %d" % f.function_id, "function_id")
            self.functions[f.function_id] = f

    @classmethod
    def from_dict(cls, d, node_id=None):
        if not isinstance(d, dict):
            raise NodeDefinitionError("node definition must be an object, got %r" % (d,))
        for key in ("parameters", "housekeeping_reports", "functions"):
            if key not in d or not isinstance(d[key], list):
                raise NodeDefinitionError("node definition needs a list %r" % key, key)
        params = []
        for e in d["parameters"]:
            _entry("parameters", e)
            params.append(
                Parameter(
                    _need(e, "parameter_id", "parameters"),
                    e.get("parameter_name", ""),
                    _need(e, "encoding", "parameters"),
                    e.get("value", 0),
                )
            )
        reports = []
        for e in d["housekeeping_reports"]:
            _entry("housekeeping_reports", e)
            reports.append(
                HousekeepingReport(
                    _need(e, "report_id", "housekeeping_reports"),
                    _need(e, "interval", "housekeeping_reports"),
                    e.get("enabled", False),
                    _need(e, "parameter_ids", "housekeeping_reports"),
                )
            )
        funcs = []
        for e in d["functions"]:
            _entry("functions", e)
            args = []
            for a in e.get("arguments") or ():
                _entry("arguments", a)
                args.append(
                    Argument(
                        _need(a, "argument_id", "arguments"),
                        a.get("argument_name", ""),
                        _need(a, "encoding", "arguments"),
                    )
                )
            funcs.append(
                Function(_need(e, "function_id", "functions"), e.get("function_name", ""), args)
            )
        if node_id is None:
            node_id = d.get("node_id")
        return cls(params, reports, funcs, node_id)

    @classmethod
    def from_json(cls, text, node_id=None):
        return cls.from_dict(json.loads(text), node_id)

    @classmethod
    def load(cls, path, node_id=None):
        with open(path) as f:
            return cls.from_dict(json.load(f), node_id)

    def to_dict(self):
        d = {}
        if self.node_id is not None:
            d["node_id"] = self.node_id
        d["parameters"] = [self.parameters[k].to_dict() for k in sorted(self.parameters)]
        d["housekeeping_reports"] = [self.reports[k].to_dict() for k in sorted(self.reports)]
        d["functions"] = [self.functions[k].to_dict() for k in sorted(self.functions)]
        return d

    def to_json(self):
        return json.dumps(self.to_dict())

    def parameter(self, key):
        """A parameter by id or by name (None if unknown)."""
        if isinstance(key, str):
            return self._by_name.get(key)
        return self.parameters.get(key)

    def function_by_name(self, name):
        for f in self.functions.values():
            if f.name == name:
                return f
        return None
