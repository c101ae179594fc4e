"""`obsw packet`: decode and encode space packets and PUS-C packets."""

import binascii
import json
import sys

from obsw import spp
from obsw.pus import messages
from obsw.pus.config import PusConfig
from obsw.pus.packets import ACK_ACCEPTANCE, ACK_ALL, ACK_COMPLETION, ACK_PROGRESS, ACK_START
from obsw.pus.tc import PusTc
from obsw.pus.tm import PusTm

_ACK_NAMES = (
    ("acceptance", ACK_ACCEPTANCE),
    ("start", ACK_START),
    ("progress", ACK_PROGRESS),
    ("completion", ACK_COMPLETION),
)
_SEQ_FLAGS = ("continuation", "first", "last", "unsegmented")


def _int(text):
    return int(text, 0)


def _ack(text):
    """'all', 'none', a comma list of step names, or a number 0..15."""
    t = text.strip().lower()
    if t == "all":
        return ACK_ALL
    if t == "none":
        return 0
    try:
        return int(t, 0)
    except ValueError:
        pass
    value = 0
    names = dict(_ACK_NAMES)
    for part in t.split(","):
        if part.strip() not in names:
            raise ValueError(
                "unknown acknowledgement %r (use all, none, a number or %s)"
                % (part, ",".join(names))
            )
        value |= names[part.strip()]
    return value


def _hex_bytes(text, what):
    digits = "".join(text.split())
    if digits[:2].lower() == "0x":
        digits = digits[2:]
    if len(digits) % 2:
        raise ValueError("%s has an odd number of hex digits (%d)" % (what, len(digits)))
    try:
        return binascii.unhexlify(digits)
    except (binascii.Error, ValueError):
        raise ValueError("%s is not hexadecimal: %r" % (what, text)) from None


def _message_names():
    names = {}
    for name in dir(messages):
        if name[:3] in ("TC_", "TM_"):
            names[(name[:2],) + getattr(messages, name)] = name
    return names


def add_parser(sub):
    p = sub.add_parser("packet", help="decode or encode space packets", description=__doc__)
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    d = s.add_parser(
        "decode",
        help="print a packet as JSON",
        description="Decode a space packet and its PUS-C header (TC or TM by the type bit) "
        "and print them as JSON. Exit status 1 on a malformed packet.",
    )
    d.add_argument("hex", nargs="+", help="the packet as hexadecimal (spaces allowed)")
    _config_args(d)
    d.set_defaults(func=decode)
    e = s.add_parser(
        "encode",
        help="build a PUS-C telecommand and print it as hex",
        description="Build a PUS-C TC from its fields and print it as hexadecimal.",
    )
    e.add_argument("--apid", type=_int, required=True, help="application process ID (0..2047)")
    e.add_argument("--service", type=_int, required=True, help="service type ID (0..255)")
    e.add_argument("--subtype", type=_int, required=True, help="message subtype ID (0..255)")
    e.add_argument(
        "--ack",
        default="all",
        help="acknowledgement flags: all (default), none, a number, or a comma list of "
        "acceptance,start,progress,completion",
    )
    e.add_argument("--source-id", type=_int, default=0, help="source ID (default 0)")
    e.add_argument("--seq", type=_int, default=0, help="sequence count (0..16383, default 0)")
    e.add_argument("--data", default="", help="application data as hexadecimal")
    _config_args(e)
    e.set_defaults(func=encode)


def _config_args(p):
    p.add_argument("--no-pec", action="store_true", help="packets carry no packet error control")
    p.add_argument(
        "--source-id-size", type=int, default=2, help="octets of TC source ID (default 2)"
    )


def _config(args):
    return PusConfig(source_id_size=args.source_id_size, pec=not args.no_pec)


def _fail(action, message, status=1):
    sys.stderr.write("obsw packet %s: %s\n" % (action, message))
    return status


def describe(raw, config):
    """The JSON-ready description of one packet (raises spp.SppError when malformed)."""
    header = spp.PrimaryHeader.unpack(raw)
    if header.version != spp.PACKET_VERSION:
        raise spp.PacketVersionError(header.version)
    if len(raw) < header.packet_length:
        raise spp.BytesTooShortError("space packet", header.packet_length, len(raw))
    if len(raw) > header.packet_length:
        raise spp.SppError(
            "packet is %d bytes, packet data length field says %d"
            % (len(raw), header.packet_length)
        )
    out = {
        "space_packet": {
            "version": header.version,
            "type": "TC" if header.packet_type else "TM",
            "sec_header_flag": header.sec_header_flag,
            "apid": header.apid,
            "idle": header.apid == spp.APID_IDLE,
            "seq_flags": _SEQ_FLAGS[header.seq_flags],
            "seq_count": header.seq_count,
            "data_length": header.data_length,
            "packet_length": header.packet_length,
        }
    }
    if not header.sec_header_flag or header.apid == spp.APID_IDLE:
        out["data"] = raw[6:].hex()
        return out
    names = _message_names()
    if header.packet_type == spp.TYPE_TC:
        tc = PusTc.unpack(raw, config)
        kind = "TC"
        pus = {
            "ack": tc.ack,
            "ack_flags": [n for n, bit in _ACK_NAMES if tc.ack & bit],
            "source_id": tc.source_id,
        }
        pkt = tc
    else:
        tm = PusTm.unpack(raw, config)
        kind = "TM"
        pus = {
            "time_ref_status": tm.time_ref,
            "message_counter": tm.message_counter,
            "destination_id": tm.destination_id,
            "time": list(tm.time) if tm.time is not None else None,
        }
        if tm.time is not None and config.time is not None:
            pus["time_seconds"] = config.time.to_seconds(*tm.time)
        pkt = tm
    pus.update(
        {
            "pus_version": 2,
            "service": pkt.service,
            "subtype": pkt.subtype,
            "message": names.get((kind, pkt.service, pkt.subtype)),
        }
    )
    if config.pec:
        pus["pec"] = "0x" + raw[-2:].hex()
    out["pus"] = pus
    out["data"] = bytes(pkt.data).hex()
    return out


def decode(args):
    """Exit status 0, 1 when the packet is malformed, 2 when the hex or options are wrong."""
    raw = _user_input(lambda: _hex_bytes(" ".join(args.hex), "packet"), "decode")
    if not isinstance(raw, bytes):
        return raw
    try:
        config = _config(args)
        print(json.dumps(describe(raw, config), indent=2, sort_keys=True))
    except ValueError as e:
        return _fail("decode", e)
    return 0


def encode(args):
    try:
        config = _config(args)
        tc = PusTc(
            args.apid,
            args.service,
            args.subtype,
            _hex_bytes(args.data, "--data"),
            args.seq,
            _ack(args.ack),
            args.source_id,
            config=config,
        )
        print(tc.pack().hex())
    except ValueError as e:
        return _fail("encode", e, 2)  # the arguments were wrong
    return 0


def _user_input(fn, action):
    try:
        return fn()
    except ValueError as e:
        return _fail(action, e, 2)
