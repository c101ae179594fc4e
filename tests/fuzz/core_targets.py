"""Fuzz targets for the core decoders and entry points (MicroPython subset, both interpreters).

Each target names the errors its decoder declares; an entry point documented never to raise
(``CfdpEntity.receive``, ``ApplicationProcess.receive``, the frame and CAN receivers, the
stream parsers) declares none.
"""

from fuzzcore import Target
from obsw import cbor, spp, store
from obsw.bits import BitsTooShortError, Decoder
from obsw.cfdp.defs import CfdpError
from obsw.cfdp.pdu import decode_pdu
from obsw.cfdp.tlv import unpack_tlvs
from obsw.frames import cltu, farm
from obsw.frames.clcw import Clcw
from obsw.frames.errors import FrameError
from obsw.frames.tc import TcFrame, parse_control_command, set_vr_command
from obsw.frames.tm import TmFrame
from obsw.pluto.lexer import PlutoError, tokenize
from obsw.pluto.parser import parse
from obsw.pus.any_packet import unpack_packet
from obsw.pus.fields import FieldValueError, field
from obsw.pus.packets import PusError
from obsw.pus.sdb import SdbError
from obsw.pus.sdb import loads as sdb_loads
from obsw.pus.structure import Repeated, Structure
from obsw.pus.tc import PusTc
from obsw.pus.tm import PusTm
from obsw.spacecan import packets as can_packets
from obsw.spacecan.fragment import Reassembler, split
from obsw.spacecan.nodedef import NodeDefinition
from obsw.spacecan.responder import Responder
from obsw.spacecan.timeframes import CanFrameLengthError, ScetTime, UtcTime
from obsw.timecode import TimeCodeError

# -- seeds ----------------------------------------------------------------------------------


def _pus_seeds():
    out = [
        PusTc(10, 17, 1, b"", 5, source_id=1).pack(),
        PusTc(10, 3, 27, b"\x00\x02\x00\x01\x00\x02", 6).pack(),
        PusTc(10, 20, 1, b"\x01\x00\x02", 7).pack(),
        PusTc(10, 11, 4, b"\x00\x01" + b"\x00" * 6 + PusTc(10, 17, 1).pack(), 8).pack(),
        PusTm(10, 1, 1, b"\x18\x0a\xc0\x05", 3).pack(),
        PusTm(10, 3, 25, b"\x00\x01\x12\x34\x56", 4).pack(),
    ]
    return out


PUS_SEEDS = _pus_seeds()


def _cfdp_pdus():
    """Every PDU of a class 2 transfer with a lost segment, from two simulated entities."""
    from cfdp_sim import Link, make_pair, payload

    a, b = make_pair(files_a={"a.bin": payload(300)})
    a.put(2, "a.bin", "b.bin", mode=0, now=0)
    seen = []
    n = [0]

    def drop(side, pdu):
        seen.append(pdu)
        n[0] += 1
        return n[0] == 3  # one file data PDU lost: NAKs and retransmission

    Link(a, b, drop=drop).run()
    return seen


def _field_catalogue():
    out = [field(1, 8), field(2, 12), field(3, 14), field(4, 16), field(5, 1), field(5, 2)]
    out += [field(5, 3), field(5, 4), field(6, 13), field(7, 4), field(8, 0), field(7, 0)]
    out += [field(9, 0), field(9, 1), field(9, 2), field(9, 17), field(10, 17)]
    out += [field(12, 0), field(12, 1), field(6, 0, length_bits=8, max_length=200)]
    return out


FIELDS = _field_catalogue()
_PARAMS = {0: field(3, 4), 1: field(4, 12), 2: field(5, 1), 3: field(8, 0, length_bits=8)}
MESSAGE = Structure(
    [
        ("sid", field(3, 12)),
        ("flag", field(1, 0)),
        ("ids", Repeated(field(3, 4), field(3, 12))),
        (
            "params",
            Repeated(
                field(3, 4),
                [("id", field(3, 4)), ("value", field(11, 0, key="id", lookup=_PARAMS))],
            ),
        ),
        ("time", field(9, 17)),
    ]
)
FIELD_ERRORS = (BitsTooShortError, FieldValueError, TimeCodeError)


def _fields_call(data):
    if not data:
        return
    ft = FIELDS[data[0] % len(FIELDS)]
    ft.read(Decoder(data[1:], 0))


def _structure_call(data):
    MESSAGE.unpack(data, exact=False)


NODE = {
    "parameters": [
        {"parameter_id": 1, "parameter_name": "mode", "encoding": "u8", "value": 3},
        {"parameter_id": 2, "parameter_name": "volt", "encoding": "f32", "value": 7.5},
        {"parameter_id": 3, "parameter_name": "count", "encoding": "u32", "value": 5},
        {"parameter_id": 4, "parameter_name": "temp", "encoding": "i16", "value": -20},
    ],
    "housekeeping_reports": [
        {"report_id": 1, "interval": 1, "enabled": False, "parameter_ids": [1, 4]},
    ],
    "functions": [
        {
            "function_id": 1,
            "function_name": "set_line",
            "arguments": [{"argument_id": 1, "argument_name": "line", "encoding": "u8"}],
        },
        {"function_id": 2, "function_name": "reset"},
    ],
}
NODEDEF = NodeDefinition.from_dict(NODE)
_CAN_IDS = (0x281, 0x281, 0x281, 0x700, 0x080, 0x180, 0x200, 0x301, 0x7FF)


def _can_seeds():
    out = []
    for payload in (b"\x11\x01", b"\x03\x01\x00\x01", b"\x14\x01\x00\x01\x01\x07", b"\x11\x01"):
        frames = split(payload)
        out.append(b"".join(bytes([0, len(f)]) + f for f in frames))
    out.append(bytes([3, 0]))
    out.append(bytes([5, 7]) + ScetTime(10, 5).pack())
    out.append(bytes([6, 8]) + UtcTime(3, 1000, 5).pack())
    return out


class _CanState:
    def __init__(self):
        self.reset()

    def reset(self):
        self.responder = Responder(1, NODEDEF)
        self.reasm = Reassembler()
        self.now = 0.0

    def frames(self, data):
        """Input: (selector, length, data...)* -> CAN frames (can_id, bus, data)."""
        pos = 0
        while pos + 2 <= len(data):
            sel = data[pos]
            n = data[pos + 1] & 0x0F
            body = data[pos + 2 : pos + 2 + n]
            pos += 2 + n
            yield _CAN_IDS[sel % len(_CAN_IDS)], (sel >> 7) & 1, body

    def responder_call(self, data):
        r = self.responder
        for can_id, bus, body in self.frames(data):
            self.now += 0.01
            r.receive(bus, can_id, body, self.now)
        r.poll(self.now + 0.5)
        r.take_frames()
        r.take_events()

    def fragment_call(self, data):
        for can_id, bus, body in self.frames(data):
            self.now += 0.01
            self.reasm.push(can_id | (bus << 11), body, self.now)
        self.reasm.expire(self.now + 5)


def _can_payload_call(data):
    if not data:
        return
    fn = (
        can_packets.unpack_ids,
        lambda b: can_packets.unpack_values(NODEDEF, b),
        lambda b: can_packets.unpack_hk(NODEDEF, b),
        lambda b: can_packets.unpack_function(NODEDEF, b),
        ScetTime.unpack,
        UtcTime.unpack,
    )[data[0] % 6]
    fn(data[1:])


# -- frames ---------------------------------------------------------------------------------


def _tc_frames():
    return [
        TcFrame(5, 0, PusTc(10, 17, 1).pack(), 3).pack(),
        TcFrame(5, 1, b"\x00" + PusTc(10, 17, 1).pack(), 0, True).pack(),
        TcFrame(5, 0, set_vr_command(7), 0, True, True).pack(),
    ]


def _tm_frames():
    return [
        TmFrame(5, 0, PusTm(10, 17, 2, b"", 1).pack() + b"\x07\xff" * 20).pack(),
        TmFrame(5, 2, b"\x00" * 40, 3, 4, 0x7FE, ocf=b"\x01\x00\x00\x00").pack(),
    ]


def _frame_call(data):
    if not data:
        return
    k = data[0] % 6
    body = data[1:]
    if k == 0:
        TcFrame.unpack(body)
    elif k == 1:
        TcFrame.unpack(body, trailing=True)
    elif k == 2:
        TmFrame.unpack(body)
    elif k == 3:
        TmFrame.unpack(body, fecf=False)
    elif k == 4:
        Clcw.unpack(body)
    else:
        parse_control_command(body)


class _FarmState:
    def __init__(self):
        self.reset()

    def reset(self):
        self.farm = farm.Farm1(0, window=10, buffer_size=4)

    def call(self, data):
        """A run of TC frames (length-prefixed) through FARM-1; frames it cannot decode are
        what the frame processor refuses before FARM sees them."""
        pos = 0
        f = self.farm
        while pos < len(data):
            n = data[pos]
            raw = data[pos + 1 : pos + 1 + n]
            pos += 1 + n
            try:
                frame = TcFrame.unpack(raw, fecf=False)
            except FrameError:
                continue
            f.on_frame(frame)
            if data[0] & 1:
                f.take()
            f.clcw()


class _ProcessorState:
    """The onboard frame processor: CLTU bytes on either link, frames through FARM-1 and
    segments to the packet routes; it never raises, whatever arrives."""

    def __init__(self):
        self.reset()

    def reset(self):
        from obsw.frames.processor import FrameProcessor

        self.proc = FrameProcessor(5, lambda apid, packet: None, tc_vcids=(0, 1))
        self.now = 0.0

    def call(self, data):
        self.now += 0.1
        link = data[0] & 1 if data else 0
        self.proc.receive(link, data, self.now)
        self.proc.on_frame_data(link, data, self.now)


def _processor_seeds():
    seg = b"\x03" + PusTc(10, 17, 1).pack()
    return [
        cltu.encode(TcFrame(5, 0, seg, 0).pack()),
        cltu.encode(TcFrame(5, 1, seg, 0, True).pack())
        + cltu.encode(TcFrame(5, 0, seg, 1).pack()),
        cltu.encode(TcFrame(5, 0, set_vr_command(0), 0, True, True).pack()),
    ]


def _farm_seeds():
    out = []
    for frames in (
        [TcFrame(1, 0, b"x", n, fecf=False) for n in range(6)],
        [TcFrame(1, 0, b"x", 0, True, True, fecf=False), TcFrame(1, 0, b"y", 200, fecf=False)],
        [TcFrame(1, 0, set_vr_command(9), 0, True, True, fecf=False)],
    ):
        out.append(b"".join(bytes([len(r)]) + r for r in (fr.pack() for fr in frames)))
    return out


# -- PLUTO, the database, the context store ------------------------------------------------

PLUTO_SEEDS = [
    "procedure main log 1 + 2 * 3; end main end procedure",
    "procedure declare variable x of type signed integer end declare main x := -5; "
    'if x < 0 then log "neg", x; else log "pos"; end if; end main end procedure',
    "procedure main wait for 2.5 s; wait until 2025-01-01T00:00:10Z; log 10 s + 1 min; "
    "log 2025-001T00:00:00.5Z; end main end procedure",
    "procedure main initiate and confirm step S declare variable n of type unsigned integer "
    "end declare main n := 0; while n < 3 do n := n + 1; end while; end main end step; "
    "end procedure",
    "procedure main in case 3 is = 1: log 1; or is > 2: log 2; otherwise: log 3; end case; "
    "log (1 + (2 * (3 - 4))) / 5; log 2 ** 8; log not true and (false or true); "
    "log 1.5e3 V; log 16#FF#; end main end procedure",
    "procedure main initiate and confirm a of B with arguments x := 1, y := 2 end with "
    "in case confirmed: continue; not confirmed: restart max times 2; end case; "
    "in parallel until one completes log 1; wait for 1 s; end parallel; end main end procedure",
]


def _pluto_files():
    out = []
    for name in ("cpdu_state_bits.pluto", "deploy_and_track.pluto", "annex_a.pluto"):
        try:
            with open("tests/data/pluto/" + name) as f:
                out.append(f.read())
        except OSError:
            pass
    return out


_PLUTO_WORDS = (
    "procedure",
    "end procedure",
    "main",
    "end main",
    "initiate and confirm step S main",
    "end step;",
    "if",
    "then",
    "end if;",
    "while",
    "do",
    "end while;",
    "log",
    "(",
    ")",
    "-",
    "+",
    "*",
    "**",
    ";",
    "1",
    "99999999999999999999999999999999999",
    "1.5e308",
    "1e999",
    "2025-13-45T25:61:61Z",
    "2025-001T00:00:00Z",
    "9999999999-01-01T00:00:00Z",
    "16#FFFFFFFFFFFFFFFFFFFF#",
    "10 s",
    "1e400 min",
    "x :=",
    '"text"',
    "of",
    "wait for",
    "wait until",
    "to string(",
    "day of year(",
    "to integer(",
    "save context refer to a of B by v",
    ", refer to",
    "confirmation status of",
    "1 V",
    "2 m",
)


def _pluto_generate(rng):
    """Token soup, and the deep nestings an attacker would try first."""
    k = rng.below(4)
    depth = 1 + rng.below(60 if rng.chance(90) else 400)
    if k == 0:
        return (
            "procedure main log " + "(" * depth + "1" + ")" * depth + "; end main end procedure"
        ).encode()
    if k == 1:
        body = "if true then " * depth + "log 1;" + " end if;" * depth
        return ("procedure main " + body + " end main end procedure").encode()
    if k == 2:
        steps = (
            "initiate and confirm step S main " * depth + "log 1;" + " end main end step;" * depth
        )
        return ("procedure main " + steps + " end main end procedure").encode()
    words = [rng.pick(_PLUTO_WORDS) for _ in range(rng.below(40))]
    return (" ".join(words)).encode()


def _pluto_load(text):
    from obsw.pluto.interp import load

    load(text)


def _pluto_run(text):
    """Load, then run on a simulated system for a bounded number of statements: a program
    that loads may end (finished or aborted) but ``run`` itself never raises."""
    from obsw.pluto.interp import Procedure, load
    from obsw.pluto.system import SimulatedSystem

    try:
        program = load(text)
    except PlutoError:
        return
    proc = Procedure(program, SimulatedSystem({"parameters": {"a of B": 3}}))
    now = 0
    proc.start(now)
    for _ in range(20):
        w = proc.run(now, 50)
        if w is None:
            break
        now = max(now, w.deadline or now) + 1


SDB_SEED = None


def _sdb_seed():
    from pus_loop import SDB

    return SDB


def _json_deep(rng):
    depth = 1 + rng.below(200 if rng.chance(95) else 20000)
    open_, close = rng.pick((("[", "]"), ('{"a":', "}")))
    return (open_ * depth + "1" + close * depth).encode()


def _store_seeds():
    return [store.encode({"enabled": [1, 2], "rate": 3}), store.encode([[1, 10, [1, 2], True]])]


def _store_generate(rng):
    body = _json_deep(rng)
    return store.encode(1)[:0] + b"OBSWCTX1 %08x %d\n" % (_crc(body), len(body)) + body


def _crc(body):
    from obsw.crc import crc32

    return crc32(body)


def _store_call(data):
    store.decode(data)


def _cbor_seeds():
    return [
        cbor.dumps({1: [1, 2, b"\x00"], "k": {"x": -7, "y": 1.5}, 3: None}),
        cbor.dumps([True, False, 1 << 40, -(1 << 40), "text", 2.5, [[], {}]]),
        cbor.dumps(cbor.Tag(1, 1700000000)),
    ]


def _cbor_generate(rng):
    depth = 1 + rng.below(200 if rng.chance(95) else 5000)
    return bytes([0x81]) * depth + b"\x01"


def _spp_stream_call(data):
    s = spp.PacketStream(max_length=512)
    half = len(data) // 2
    s.feed(data[:half])
    s.feed(data[half:])
    s.flush()


def _cltu_call(data):
    if not data:
        return
    if data[0] & 1:
        cltu.decode(data[1:], bool(data[0] & 2))
    else:
        cltu.CltuDecoder().feed(data[1:])


def _cltu_seeds():
    return [b"\x00" + cltu.encode(f) for f in _tc_frames()] + [
        b"\x03" + cltu.encode(_tc_frames()[0], True)
    ]


class _CfdpState:
    def __init__(self):
        self.entities = None

    def reset(self):
        from cfdp_sim import make_pair, payload

        a, b = make_pair(files_a={"a.bin": payload(300)}, max_file_size=1 << 20)
        self.entities = (a, b)
        self.now = 0.0

    def call(self, data):
        if self.entities is None:
            self.reset()
        self.now += 0.5
        for ent in self.entities:
            ent.receive(data, self.now)
            if ent.stats["internal_errors"]:
                raise AssertionError("CfdpEntity.receive caught a defect of its own")
            ent.poll(self.now)
            ent.transmit(self.now, 8)
            ent.pop_indications()


def targets():
    """Every core target, built fresh (stateful ones start from their initial state)."""
    pus = PUS_SEEDS
    pdus = _cfdp_pdus()
    can = _CanState()
    can2 = _CanState()
    fr = _FarmState()
    cf = _CfdpState()
    fp = _ProcessorState()
    pluto = PLUTO_SEEDS + _pluto_files()
    return [
        Target("spp", spp.SpacePacket.unpack, pus, (spp.SppError,)),
        Target("spp-stream", _spp_stream_call, [b"".join(pus)], ()),
        Target("pus-tc-tm", unpack_packet, pus, (PusError,)),
        Target(
            "pus-fields", _fields_call, [bytes([i]) + bytes(16) for i in range(20)], FIELD_ERRORS
        ),
        Target(
            "pus-structure",
            _structure_call,
            [
                MESSAGE.pack(
                    {
                        "sid": 1,
                        "flag": True,
                        "ids": [1, 2],
                        "params": [{"id": 0, "value": 3}, {"id": 3, "value": "ab"}],
                        "time": (5, 0),
                    }
                )
            ],
            FIELD_ERRORS,
        ),
        Target("cbor", cbor.loads, _cbor_seeds(), (cbor.CborDecodeError,), _cbor_generate),
        Target("cfdp-pdu", decode_pdu, pdus, (CfdpError,)),
        Target("cfdp-tlv", unpack_tlvs, [p[-20:] for p in pdus], (CfdpError,)),
        Target("cfdp-entity", cf.call, pdus, (), reset=cf.reset),
        Target(
            "frames",
            _frame_call,
            [b"\x00" + f for f in _tc_frames()] + [b"\x02" + f for f in _tm_frames()],
            (FrameError,),
        ),
        Target("cltu", _cltu_call, _cltu_seeds(), (FrameError,)),
        Target("farm", fr.call, _farm_seeds(), (), reset=fr.reset),
        Target("frame-processor", fp.call, _processor_seeds(), (), reset=fp.reset),
        Target(
            "spacecan-payload",
            _can_payload_call,
            [b"\x00\x02\x01\x02", b"\x01\x01\x00\x01"],
            (can_packets.ServicePacketError, CanFrameLengthError),
        ),
        Target("spacecan-fragment", can.fragment_call, _can_seeds(), (), reset=can.reset),
        Target("spacecan-responder", can2.responder_call, _can_seeds(), (), reset=can2.reset),
        Target("pluto-lexer", tokenize, pluto, (PlutoError,), _pluto_generate, text=True),
        Target("pluto-parser", parse, pluto, (PlutoError,), _pluto_generate, text=True),
        Target("pluto-load", _pluto_load, pluto, (PlutoError,), _pluto_generate, text=True),
        Target("pluto-run", _pluto_run, pluto, (), _pluto_generate, text=True),
        Target("sdb", sdb_loads, [_sdb_seed()], (SdbError,), _json_deep, text=True),
        Target("context-store", _store_call, _store_seeds(), (ValueError,), _store_generate),
    ]
