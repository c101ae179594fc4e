"""SpaceCAN service packets ([service][subtype][data]) and the data layouts of services 1-20."""

from obsw.compat import micropython
from obsw.spacecan import encoding as enc

# Services and subtypes, named once.
SERVICE_VERIFICATION = 1
SERVICE_HOUSEKEEPING = 3
SERVICE_FUNCTION = 8
SERVICE_TEST = 17
SERVICE_PARAMETER = 20

ACCEPT_OK = 1  # (1,1)
ACCEPT_FAIL = 2  # (1,2)
COMPLETE_OK = 7  # (1,7)
COMPLETE_FAIL = 8  # (1,8)

HK_ENABLE = 5  # (3,5)
HK_DISABLE = 6  # (3,6)
HK_REPORT = 25  # (3,25)
HK_ONE_SHOT = 27  # (3,27)
FUNCTION_PERFORM = 1  # (8,1)
PING = 1  # (17,1)
PING_REPORT = 2  # (17,2)
PARAM_REQUEST = 1  # (20,1)
PARAM_REPORT = 2  # (20,2)
PARAM_SET = 3  # (20,3): our extension; spacecan 0.8.1 answers it with (1,2)

VERIFICATION_NAMES = {
    ACCEPT_OK: "accepted",
    ACCEPT_FAIL: "rejected",
    COMPLETE_OK: "completed",
    COMPLETE_FAIL: "failed",
}

# Requests a responder serves, and the data reports each one may bring back.
REQUESTS = (
    (SERVICE_HOUSEKEEPING, HK_ENABLE),
    (SERVICE_HOUSEKEEPING, HK_DISABLE),
    (SERVICE_HOUSEKEEPING, HK_ONE_SHOT),
    (SERVICE_FUNCTION, FUNCTION_PERFORM),
    (SERVICE_TEST, PING),
    (SERVICE_PARAMETER, PARAM_REQUEST),
    (SERVICE_PARAMETER, PARAM_SET),
)


class ServicePacketError(ValueError):
    """A service packet or its data that cannot be decoded."""

    def __init__(self, msg, service=None, subtype=None):
        super().__init__(msg)
        self.service = service
        self.subtype = subtype


class ServicePacket:
    """[service u8][subtype u8][data]: no request id, no sequence count, no CRC on the wire."""

    def __init__(self, service, subtype, data=b""):
        self.service = service
        self.subtype = subtype
        self.data = bytes(data)

    def pack(self):
        if not (0 <= self.service <= 255 and 0 <= self.subtype <= 255):
            raise ServicePacketError(
                "service and subtype must be 0..255, got (%r,%r)" % (self.service, self.subtype)
            )
        return bytes((self.service, self.subtype)) + self.data

    @classmethod
    def unpack(cls, buf):
        if len(buf) < 2:
            raise ServicePacketError("service packet too short: %d bytes, needs 2" % len(buf))
        return cls(buf[0], buf[1], buf[2:])

    def __eq__(self, other):
        return (
            isinstance(other, ServicePacket)
            and other.service == self.service
            and other.subtype == self.subtype
            and other.data == self.data
        )

    def __repr__(self):
        return "ServicePacket(%d, %d, %r)" % (self.service, self.subtype, self.data)


def _u8(what, v):
    if not isinstance(v, int) or isinstance(v, bool) or v < 0 or v > 255:
        raise ServicePacketError("%s must be 0..255, got %r" % (what, v))
    return v


def pack_ids(ids):
    """[N][id x N] (parameter ids for 20,1; report ids for 3,5/3,6/3,27)."""
    ids = [_u8("id", i) for i in ids]
    if len(ids) > 255:
        raise ServicePacketError("at most 255 ids in one request, got %d" % len(ids))
    return bytes([len(ids)] + ids)


@micropython.native
def unpack_ids(data):
    if len(data) < 1:
        raise ServicePacketError("id list needs a count byte, got no data")
    n = data[0]
    if n != len(data) - 1:
        raise ServicePacketError("id list announces %d ids, carries %d" % (n, len(data) - 1))
    return list(data[1:])


def pack_values(nodedef, pairs):
    """[N][(parameter_id, value) x N] for (20,2) and (20,3); pairs is a list or a dict."""
    if isinstance(pairs, dict):
        pairs = list(pairs.items())
    if len(pairs) > 255:
        raise ServicePacketError("at most 255 values in one packet, got %d" % len(pairs))
    out = [bytes((len(pairs),))]
    for pid, value in pairs:
        p = nodedef.parameters.get(pid)
        if p is None:
            raise ServicePacketError("unknown parameter id %r" % (pid,))
        out.append(bytes((pid,)))
        out.append(enc.encode(p.encoding, value))
    return b"".join(out)


def unpack_values(nodedef, data):
    """Decode [N][(id, value) x N] with the sizes of nodedef; returns a list of (id, value)."""
    if len(data) < 1:
        raise ServicePacketError("parameter values need a count byte, got no data")
    n = data[0]
    out = []
    off = 1
    while off < len(data):
        pid = data[off]
        p = nodedef.parameters.get(pid)
        if p is None:
            raise ServicePacketError("unknown parameter id %d in values at byte %d" % (pid, off))
        try:
            value, off = enc.decode(p.encoding, data, off + 1)
        except enc.ValueTooShortError as e:
            raise ServicePacketError("parameter %d: %s" % (pid, e))  # noqa: B904
        out.append((pid, value))
    if n != len(out):
        raise ServicePacketError("parameter values announce %d, carry %d" % (n, len(out)))
    return out


def pack_hk(nodedef, report_id, values=None):
    """(3,25) data: [report_id][values in report order]; values default to the current ones."""
    r = nodedef.reports.get(report_id)
    if r is None:
        raise ServicePacketError("unknown report id %r" % (report_id,))
    out = [bytes((report_id,))]
    for i, pid in enumerate(r.parameter_ids):
        p = nodedef.parameters[pid]
        out.append(enc.encode(p.encoding, p.value if values is None else values[i]))
    return b"".join(out)


def unpack_hk(nodedef, data):
    """Decode (3,25) data; returns (report_id, [(parameter_id, value), ...])."""
    if len(data) < 1:
        raise ServicePacketError("housekeeping report needs a report id, got no data")
    r = nodedef.reports.get(data[0])
    if r is None:
        raise ServicePacketError("unknown report id %d" % data[0])
    off = 1
    out = []
    for pid in r.parameter_ids:
        try:
            value, off = enc.decode(nodedef.parameters[pid].encoding, data, off)
        except enc.ValueTooShortError as e:
            msg = "report %d parameter %d: %s" % (r.report_id, pid, e)
            raise ServicePacketError(msg)  # noqa: B904
        out.append((pid, value))
    if off != len(data):
        raise ServicePacketError(
            "report %d is %d bytes, expected %d" % (r.report_id, len(data), off)
        )
    return r.report_id, out


def pack_function(nodedef, function_id, args=None):
    """(8,1) data: [fid], or [fid][N][(arg_id, value) x N] sorted by arg_id."""
    f = nodedef.functions.get(function_id) if nodedef is not None else None
    out = [bytes((_u8("function id", function_id),))]
    if args:
        if f is None:
            raise ServicePacketError("unknown function id %r" % (function_id,))
        out.append(bytes((len(args),)))
        for aid in sorted(args):
            a = f.arguments.get(aid)
            if a is None:
                raise ServicePacketError("function %d has no argument %r" % (function_id, aid))
            out.append(bytes((aid,)))
            out.append(enc.encode(a.encoding, args[aid]))
    return b"".join(out)


def unpack_function(nodedef, data):
    """Decode (8,1) data against nodedef; returns (function_id, {arg_id: value})."""
    if len(data) < 1:
        raise ServicePacketError("function call needs a function id, got no data")
    fid = data[0]
    f = nodedef.functions.get(fid)
    if f is None:
        raise ServicePacketError("unknown function id %d" % fid)
    args = {}
    if len(data) == 1:
        n = 0
    else:
        n = data[1]
        off = 2
        while off < len(data):
            a = f.arguments.get(data[off])
            if a is None:
                raise ServicePacketError("function %d has no argument %d" % (fid, data[off]))
            if a.argument_id in args:
                raise ServicePacketError("function %d argument %d repeated" % (fid, data[off]))
            try:
                args[a.argument_id], off = enc.decode(a.encoding, data, off + 1)
            except enc.ValueTooShortError as e:
                msg = "function %d argument %d: %s" % (fid, a.argument_id, e)
                raise ServicePacketError(msg)  # noqa: B904
    if n != len(args):
        raise ServicePacketError(
            "function %d call announces %d arguments, carries %d" % (fid, n, len(args))
        )
    for aid in f.arguments:
        if aid not in args:
            raise ServicePacketError("function %d call lacks argument %d" % (fid, aid))
    return fid, args
