"""`obsw frames`: the frame processor on two UARTs, CLTU and TM frame tools, TC security keys
and signing (SDLS). The spacecraft id, virtual channels, MAP IDs and ports come from the
mission (``--mission DIR``) unless an option gives them."""

import binascii
import json

from obsw_host.errors import UserError, user_message
from obsw_host.mission import ids as mission_ids
from obsw_host.net import DEFAULT_HOST


def add_parser(sub):
    p = sub.add_parser(
        "frames", help="CCSDS TC/TM frames, CLTUs, frame processor", description=__doc__
    )
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True

    proc = s.add_parser("processor", help="run the frame processor on two serial ports")
    proc.add_argument("--uart-a", required=True, help="first link (serial device)")
    proc.add_argument("--uart-b", required=True, help="second, hot-redundant link")
    mission_ids.add_arguments(proc)
    proc.add_argument("--scid", type=_int, help="spacecraft id (default: the mission's)")
    proc.add_argument("--baudrate", type=int, default=115200)
    proc.add_argument(
        "--host", default=DEFAULT_HOST, help="where the application processes are (%(default)s)"
    )
    proc.add_argument("--port-base", type=int, help="TC packets go to base+APID (the mission's)")
    proc.add_argument("--tm-port", type=int, help="UDP port receiving TM packets (the mission's)")
    proc.add_argument(
        "--playback-port", type=int, default=None,
        help="UDP port whose packets go on the playback VC (default: the mission's)",
    )  # fmt: skip
    for role in ("realtime", "playback", "essential"):
        proc.add_argument(
            "--%s-vc" % role, type=int, help="TM VC of %s TM (default: the mission's)" % role
        )
    proc.add_argument("--frame-length", type=int, help="TM frame length (the mission's)")
    proc.add_argument("--essential-map", type=int, default=None, help="MAP ID of HPCs")
    proc.add_argument("--duration", type=float, default=None, help="stop after N seconds")
    proc.add_argument("--keys", help="SDLS key file: authenticate every TC frame")
    proc.add_argument("--key-state", help="sequence number state file (default KEYS.state)")
    proc.set_defaults(func=processor)

    st = s.add_parser(
        "station", help="a ground station on radio interfaces (KISS, GNU Radio UDP, serial)",
        description="Decodes the TM the links give (the mission's frames.tm_coding) and hands "
        "its packets to the ground tools on UDP (--port; they find the station by sending a "
        "TC), whose TCs go up through FOP-1 as CLTUs; with --yamcs, hands the decoded frames "
        "to Yamcs' TM frame link instead and sends up the CLTUs Yamcs sends to --port.",
    )  # fmt: skip
    st.add_argument("--link", action="append", required=True, metavar="SPEC",
                    help="kiss-serial:DEV[@BAUD], kiss-tcp:HOST:PORT, kiss-listen:HOST:PORT, "
                    "udp:PORT[:octets|bits|int8|float32][@HOST:PORT] or a serial device path "
                    "(repeat for the second link)")  # fmt: skip
    mission_ids.add_arguments(st)
    st.add_argument("--host", default=DEFAULT_HOST, help="address of --port (%(default)s)")
    st.add_argument("--port", type=int, default=0, help="UDP port of the ground tools (0: free)")
    st.add_argument("--yamcs", type=int, metavar="PORT", help="Yamcs' TM frame link UDP port")
    st.add_argument("--report", type=float, default=10.0, help="seconds between counter lines")
    st.add_argument("--duration", type=float, default=None, help="stop after N seconds")
    st.set_defaults(func=station)

    kg = s.add_parser("keygen", help="write a new SDLS key file (outside any repository)")
    kg.add_argument("file")
    kg.add_argument("--vcid", type=int, action="append", help="VC with an SA (repeat; 0)")
    kg.add_argument("--essential-map", type=int, default=63, help="MAP of the HPC SA (63)")
    kg.add_argument("--no-essential", action="store_true", help="no SA for essential TCs")
    kg.add_argument("--mac-length", type=int, default=16, help="MAC octets, 8..32 (16)")
    kg.add_argument("--window", type=int, default=64, help="anti-replay window (64)")
    kg.add_argument("--ahead", type=int, help="refuse numbers this far above the last (none)")
    kg.set_defaults(func=keygen)

    sign = s.add_parser("sign", help="a signed TC frame (hex, or a CLTU) carrying a packet")
    sign.add_argument("hex", help="the TC packet")
    sign.add_argument("--keys", required=True, help="SDLS key file")
    sign.add_argument("--key-state", help="sequence number state file (default KEYS.state)")
    mission_ids.add_arguments(sign)
    sign.add_argument("--scid", type=_int, help="spacecraft id (default: the mission's)")
    sign.add_argument("--vcid", type=int, help="TC VC (default: the mission's)")
    sign.add_argument("--map", type=int, help="MAP ID (default: the mission's packets MAP)")
    sign.add_argument("--ad", action="store_true", help="Type-AD frame (default BD)")
    sign.add_argument("--seq", type=int, default=0, help="frame sequence number N(S)")
    sign.add_argument("--cltu", action="store_true", help="print the CLTU instead")
    sign.set_defaults(func=sign_frame)

    ver = s.add_parser("verify", help="check a signed TC frame or CLTU (hex) against a key file")
    ver.add_argument("hex")
    ver.add_argument("--keys", required=True, help="SDLS key file")
    ver.set_defaults(func=verify_frame)

    cltu = s.add_parser("cltu", help="encode or decode a CLTU")
    cs = cltu.add_subparsers(dest="cltu_action", metavar="ACTION")
    cs.required = True
    enc = cs.add_parser("encode", help="CLTU of a TC frame (hex)")
    enc.add_argument("hex")
    enc.add_argument("--randomize", action="store_true", help="apply the TC randomizer")
    enc.set_defaults(func=cltu_encode)
    dec = cs.add_parser("decode", help="TC frame (JSON) from a CLTU (hex)")
    dec.add_argument("hex")
    dec.add_argument("--randomize", action="store_true", help="remove the TC randomizer")
    dec.set_defaults(func=cltu_decode)

    tm = s.add_parser("tm", help="encode or decode TM frames (CCSDS 131.0-B channel coding)")
    ts = tm.add_subparsers(dest="tm_action", metavar="ACTION")
    ts.required = True
    tenc = ts.add_parser("encode", help="TM frames to a coded channel stream (ASM, RS, conv)")
    tenc.add_argument("hex", nargs="?", help="one TM frame in hex (or --in FILE)")
    _coding_arguments(tenc)
    tenc.set_defaults(func=tm_encode)
    tdec = ts.add_parser("decode", help="TM frame (hex, ASM and randomization optional), or a "
                         "coded stream with --coding")  # fmt: skip
    tdec.add_argument("hex", nargs="?", help="one TM frame or CADU in hex (or --in FILE)")
    tdec.add_argument("--randomized", action="store_true", help="frame is TM-randomized")
    _coding_arguments(tdec)
    tdec.add_argument(
        "--soft", action="store_true", help="--in holds int8 soft symbols (positive: 1)"
    )
    tdec.add_argument("--no-fecf", action="store_true", help="frames carry no FECF")
    tdec.set_defaults(func=tm_decode)


def _coding_arguments(p):
    p.add_argument(
        "--coding",
        choices=("none", "rs", "conv", "concatenated"),
        help="131.0-B channel coding (decode: a stream, not one frame)",
    )
    p.add_argument("--interleave", type=int, default=1, help="RS interleaving depth I (1)")
    p.add_argument(
        "--rs-e", type=int, choices=(16, 8), default=16,
        help="RS correction capability: 16 = (255,223), 8 = (255,239)",
    )  # fmt: skip
    p.add_argument("--frame-length", type=int,
                   help="TM frame length in octets (encode: the frames' own)")  # fmt: skip
    p.add_argument("--no-randomize", action="store_true", help="no pseudo-randomizer")
    p.add_argument("--in", dest="infile", help="input file, hex or binary (- for stdin)")
    p.add_argument("--out", help="output file: binary (.bin) or hex (anything else)")
    p.add_argument("--format", choices=("auto", "hex", "bin"), default="auto",
                   help="how --in is written (auto: hex if it is only hex digits)")  # fmt: skip


def _int(text):
    return int(text, 0)


def _hex(text):
    from obsw_host.errors import hex_bytes

    return hex_bytes(text, "frame")


def processor(args):
    from obsw_host.frames.processor import FrameProcessorHost

    ids = mission_ids.from_args(args)
    ports = ids.ports
    plan = dict(ids.tm_vcs)
    for role in plan:
        given = getattr(args, "%s_vc" % role)
        if given is not None:
            plan[role] = given
    if args.port_base is not None:  # every TC packet to base + APID, names fixed or not
        routes, route_to = {}, "base %d + APID" % args.port_base
        default_route = lambda apid: (args.host, args.port_base + apid)  # noqa: E731
    else:
        routes, default_route = ports.routes(args.host), ports.route(args.host)
        route_to = ", ".join("%d:%d" % (a, p) for a, (_, p) in sorted(routes.items()))
    tm_port = args.tm_port if args.tm_port is not None else ports.tm
    playback = args.playback_port
    if playback is None:
        playback = tm_port + 1 if args.tm_port is not None else ports.playback
    scid = args.scid if args.scid is not None else ids.scid
    from obsw_host.frames.coding import LinkSettings

    section = dict(ids.config.section("frames")) if ids.config is not None else {}
    if args.frame_length is not None:
        section["tm_frame_length"] = args.frame_length
    space = LinkSettings(section)
    problems = space.problems()
    if problems:
        raise UserError("processor: frames.tm_coding", expected=problems[0][1])
    security = {}
    if args.keys:
        from obsw_host.frames.processor import security_options

        try:
            security = security_options(args.keys, ids.sdb, args.key_state)
        except (OSError, ValueError, KeyError) as e:
            raise _mistake("processor", e) from None
    try:
        host = FrameProcessorHost(
            args.uart_a,
            args.uart_b,
            scid,
            host=args.host,
            routes=routes,
            default_route=default_route,
            tm_port=tm_port,
            vc_ports={plan["playback"]: playback},
            tm_frame_length=space.frame_length,
            tm_coding=space.encoder(),
            downlink_bps=space.downlink_bps,
            tm_spill=space.tm_spill,
            essential_map=args.essential_map,
            tm_plan=plan,
            tm_channels=ids.tm_channels() if plan == ids.tm_vcs else None,
            tm_vc_of_apid=ids.tm_vc_of_apid() if plan == ids.tm_vcs else None,
            tc_vcids=(ids.tc_vc,),
            **security,
        )
    except ValueError as e:
        raise _mistake("processor", e) from None
    for link in host.links:
        link.port.baudrate = args.baudrate
    print("frame processor: %s + %s, TC to UDP %s (APID:port %s), TM on UDP %d (VC %d), "
          "playback TM on UDP %d (VC %d)" % (
        args.uart_a, args.uart_b, args.host, route_to, host.tm_port, plan["realtime"],
        host.playback_port, plan["playback"]))  # fmt: skip
    print("space link: %s" % space.describe())
    if args.keys:
        print("TC security: %d SA(s) from %s, events on APID %d" % (
            len(security["security"].sas), args.keys, security["event_apid"]))  # fmt: skip
    else:
        print("TC security: off (no --keys): every well-formed TC frame is accepted")
    try:
        host.run(duration=args.duration)
    finally:
        print(json.dumps(host.core.counters))
        if args.keys:
            print(json.dumps(host.core.security.counters))
        host.close()
    return 0


def station(args):
    import threading
    import time

    from obsw_host.frames.coding import LinkSettings
    from obsw_host.frames.radio import open_link

    ids = mission_ids.from_args(args)
    link = LinkSettings.of(ids.config)
    links = []
    try:
        for spec in args.link:
            links.append(open_link(spec))
    except OSError as e:
        for opened in links:
            opened.close()
        raise UserError("station: %s" % e, expected="a radio interface that opens") from None
    if args.yamcs is not None:
        from obsw_host.frames.relay import FrameRelay

        node = FrameRelay(links, link.decoder, (args.host, args.yamcs), args.host, args.port)
        where = "frames to Yamcs on UDP %d, its CLTUs on UDP %s:%d" % (
            args.yamcs, args.host, node.cltu_address[1])  # fmt: skip
    else:
        from obsw_host.frames.station import GroundStation

        node = GroundStation.for_mission(ids, links, host=args.host, port=args.port)
        where = "ground tools on UDP %s:%d" % node.address[:2]
    print("station: %s; %s; %s" % (", ".join(x.name for x in links), link.describe(), where),
          flush=True)  # fmt: skip
    stop = threading.Event()
    worker = threading.Thread(target=node.run, args=(stop,), daemon=True)
    worker.start()
    end = None if args.duration is None else time.monotonic() + args.duration
    try:
        while worker.is_alive() and (end is None or time.monotonic() < end):
            wait = args.report if end is None else min(args.report, end - time.monotonic())
            stop.wait(max(0.0, wait))
            print("station: %s" % json.dumps(_station_counters(node)), flush=True)
    except KeyboardInterrupt:
        pass
    finally:
        stop.set()
        worker.join(2)
        node.close()
    return 0


def _station_counters(node):
    out = node.coding()
    if hasattr(node, "ground"):
        out.update(uplinked=node.uplinked, downlinked=len(node.downlinked))
    else:
        out.update(frames_to_yamcs=node.frames, cltus=node.cltus)
    return out


def keygen(args):
    from obsw_host.frames import keys

    try:
        sas = keys.generate(
            args.file,
            tuple(args.vcid or (0,)),
            None if args.no_essential else args.essential_map,
            args.mac_length,
            args.window,
            args.ahead,
        )
    except (OSError, ValueError) as e:
        raise _mistake("keygen", e) from None
    for sa in sas:
        print("SA %d: VC %d MAP %s, HMAC-SHA-256 MAC %d octets, window %d" % (
            sa.spi, sa.vcid, "any" if sa.map_id is None else sa.map_id, sa.mac_length,
            sa.window.size))  # fmt: skip
    print("wrote %s (mode 600): keep it out of repositories" % args.file)
    return 0


def sign_frame(args):
    from obsw.frames.cltu import encode

    from obsw_host.frames import keys

    ids = mission_ids.from_args(args)
    scid = args.scid if args.scid is not None else ids.scid
    vcid = args.vcid if args.vcid is not None else ids.tc_vc
    map_id = args.map if args.map is not None else ids.maps["packets"]
    try:
        security, state = keys.load(args.keys, args.key_state)
        frame = keys.signed_frame(
            security, scid, vcid, _hex(args.hex), map_id, args.seq, not args.ad
        )
        state.save()
    except (OSError, ValueError) as e:
        raise _mistake("sign", e) from None
    print(binascii.hexlify(encode(frame) if args.cltu else frame).decode())
    return 0


def cltu_encode(args):
    from obsw.frames.cltu import encode

    print(binascii.hexlify(encode(_hex(args.hex), args.randomize)).decode())
    return 0


def _frame_json(frame):
    return {
        "type": frame.type_name,
        "scid": frame.scid,
        "vcid": frame.vcid,
        "seq": frame.seq,
        "data": binascii.hexlify(frame.data).decode(),
    }


def cltu_decode(args):
    from obsw.frames.cltu import decode
    from obsw.frames.errors import FrameError
    from obsw.frames.tc import TcFrame

    try:
        data, fixed = decode(_hex(args.hex), args.randomize)
        frame = TcFrame.unpack(data, trailing=True)
    except FrameError as e:
        raise _mistake("cltu decode", e) from None
    out = _frame_json(frame)
    out["corrected_bits"] = fixed
    print(json.dumps(out))
    return 0


def _read_input(args):
    import sys

    if args.infile is None:
        if args.hex is None:
            raise UserError("no input", expected="a frame in hex or --in FILE")
        return _hex(args.hex)
    try:
        if args.infile == "-":
            raw = sys.stdin.buffer.read()
        else:
            with open(args.infile, "rb") as f:
                raw = f.read()
    except OSError as e:
        raise _mistake("tm", e) from None
    if args.format == "hex" or (
        args.format == "auto" and raw and not raw.strip(b"0123456789abcdefABCDEF \t\r\n")
    ):
        return _hex(raw.decode())
    return raw


def _write_output(args, data):
    if args.out is None:
        print(binascii.hexlify(data).decode())
        return
    try:
        with open(args.out, "wb") as f:
            f.write(data if args.out.endswith(".bin") else binascii.hexlify(data) + b"\n")
    except OSError as e:
        raise _mistake("tm", e) from None


def _frames_of(raw, length):
    if length is None:
        return [raw]
    if length <= 0 or len(raw) % length:
        raise UserError(
            "input of %d octets is not a whole number of %s-octet frames" % (len(raw), length),
            expected="a multiple of --frame-length",
        )
    return [raw[i : i + length] for i in range(0, len(raw), length)]


def tm_encode(args):
    from obsw.frames.tm_coding import TmEncoder

    raw = _read_input(args)
    frames = _frames_of(raw, args.frame_length)
    try:
        enc = TmEncoder(len(frames[0]), args.coding or "none", args.rs_e, args.interleave,
                        not args.no_randomize)  # fmt: skip
        out = b"".join(enc.encode(f) for f in frames)
    except ValueError as e:
        raise _mistake("tm encode", e) from None
    _write_output(args, out)
    return 0


def _tm_json(frame, fecf=True):
    from obsw.frames.tm_demux import PacketExtractor

    return {
        "scid": frame.scid,
        "vcid": frame.vcid,
        "mc_count": frame.mc_count,
        "vc_count": frame.vc_count,
        "first_header_pointer": frame.fhp,
        "ocf": None if frame.ocf is None else binascii.hexlify(frame.ocf).decode(),
        "packets": [binascii.hexlify(p).decode() for p in PacketExtractor().feed(frame)],
    }


def tm_decode(args):
    from obsw.frames.asm import ASM
    from obsw.frames.errors import FrameError
    from obsw.frames.randomizer import randomize_tm
    from obsw.frames.tm import TmFrame

    if args.coding is not None or args.soft:
        return _tm_decode_stream(args)
    raw = _read_input(args)
    if raw[:4] == ASM:
        raw = raw[4:]
    if args.randomized:
        raw = randomize_tm(raw)
    try:
        frame = TmFrame.unpack(raw, not args.no_fecf)
    except FrameError as e:
        raise _mistake("tm decode", e) from None
    print(json.dumps(_tm_json(frame)))
    return 0


def _tm_decode_stream(args):
    from obsw.frames.errors import FrameError
    from obsw.frames.sync import STATE_NAMES
    from obsw.frames.tm import TmFrame
    from obsw.frames.tm_coding import TmDecoder

    if args.frame_length is None:
        raise UserError("a coded stream needs --frame-length", expected="the TM frame length")
    raw = _read_input(args)
    try:
        dec = TmDecoder(args.frame_length, args.coding or "none", args.rs_e, args.interleave,
                        not args.no_randomize)  # fmt: skip
    except ValueError as e:
        raise _mistake("tm decode", e) from None
    if args.soft:
        from array import array

        got = dec.feed_soft(array("b", raw)) + dec.flush()
    else:
        got = dec.feed_octets(raw) + dec.flush()
    frames = []
    for d in got:
        out = {
            "position": d.position,
            "sync": STATE_NAMES[d.state],
            "asm_errors": d.asm_errors,
            "inverted": bool(d.inverted),
            "rs_corrected": d.corrected,
        }
        if d.data is None:
            out["error"] = str(d.error)
        else:
            frames.append(d.data)
            try:
                out.update(_tm_json(TmFrame.unpack(d.data, not args.no_fecf)))
            except FrameError as e:
                out["error"] = str(e)
        print(json.dumps(out))
    s = dec.sync
    print(json.dumps({"frames": dec.frames, "rs_corrected": dec.corrected,
                      "uncorrectable": dec.uncorrectable, "locks": s.locks,
                      "losses": s.losses, "slips": s.slips}))  # fmt: skip
    if args.out is not None:
        _write_output(args, b"".join(frames))
    return 0 if dec.frames and not dec.uncorrectable else 1


def verify_frame(args):
    from obsw.frames.cltu import decode
    from obsw.frames.errors import FrameError
    from obsw.frames.sdls import OUTCOME_NAMES
    from obsw.frames.tc import TcFrame

    from obsw_host.frames import keys

    raw = _hex(args.hex)
    try:
        security, _ = keys.load(args.keys, False)  # no state: any fresh number is taken
        if raw[:2] == b"\xeb\x90":
            raw, _ = decode(raw)
        frame = TcFrame.unpack(raw, trailing=True)
    except (OSError, FrameError) as e:
        raise _mistake("verify", e) from None
    outcome, sa, sn, clear = security.process(raw, len(frame))
    out = _frame_json(frame)
    out.update(outcome=OUTCOME_NAMES[outcome], spi=None if sa is None else sa.spi, sn=sn)
    out["data"] = None if clear is None else binascii.hexlify(clear).decode()
    print(json.dumps(out))
    return 0 if clear is not None else 1


def _mistake(action, e):
    """A bad key file, path or input of ``action`` as one line (exit status 2), the errno
    spelled out as every command spells it (``obsw_host.errors.user_message``)."""
    return UserError("%s: %s" % (action, user_message(e) or e))
