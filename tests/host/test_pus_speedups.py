"""The C packet codec (obsw_speedups) against the pure-Python one: same bytes, same objects,
same exceptions carrying the same data, for every layout it takes; and the pure path alone
(OBSW_PURE=1) still passes the core packet tests."""

import os
import subprocess
import sys

import pytest
from hypothesis import event, given, settings
from hypothesis import strategies as st
from obsw.compat import pus_accelerator
from obsw.crc import CRC16_CCITT_FALSE, crc16_ccitt
from obsw.pus.config import PusConfig
from obsw.pus.tc import PusTc
from obsw.pus.tm import PusTm
from obsw.timecode import Cds, Cuc

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
C = pus_accelerator()
needs_c = pytest.mark.skipif(
    C is None, reason="obsw_speedups not built (no C compiler?) or OBSW_PURE set"
)
SETTINGS = settings(max_examples=200, deadline=None)


def twins(**kw):
    """The same layout twice: ``fast`` may use the C codec, ``slow`` never does."""
    fast = PusConfig(**kw)
    slow = PusConfig(**kw)
    slow.tc_fast = slow.tm_fast = 0
    return fast, slow


@st.composite
def layouts(draw):
    # half of them layouts the C codec takes (whole-octet struct fields), half anything
    struct_size = st.sampled_from([1, 2, 4])
    if draw(st.booleans()):
        return dict(
            source_id_size=draw(struct_size),
            destination_id_size=draw(struct_size),
            message_counter_size=draw(st.sampled_from([1, 2])),
            time=Cuc(draw(struct_size), draw(struct_size)),
            pec=draw(st.booleans()),
            tc_spare=draw(st.integers(0, 3)),
            tm_spare=draw(st.integers(0, 3)),
            max_packet_size=draw(st.sampled_from([65542, 65542, 70000, 1024, 60])),
        )
    time = st.one_of(
        st.builds(Cuc, st.integers(1, 7), st.integers(0, 3), st.none(), st.booleans()),
        st.builds(Cds, st.sampled_from([2, 3]), st.sampled_from([0, 2])),
        st.none(),
    )
    return dict(
        source_id_size=draw(st.integers(0, 4)),
        destination_id_size=draw(st.integers(0, 4)),
        message_counter_size=draw(st.integers(0, 2)),
        time=draw(time),
        pec=draw(st.booleans()),
        tc_spare=draw(st.integers(0, 3)),
        tm_spare=draw(st.integers(0, 3)),
        max_packet_size=draw(st.sampled_from([65542, 1024, 40, 20, 0, -1, 1.5e9])),
    )


WRONG = st.sampled_from(
    [-1, 1 << 16, 1 << 32, 1 << 64, -(1 << 70), True, False, None, 1.0, "1", b"\x01", (1, 2)]
)


def spoiled(draw, valid):
    """Valid field values, and in half the draws one replaced by a wrong one (or its upper edge
    plus one); ``valid`` is a list of (name, strategy or maximum)."""
    values = {}
    for name, what in valid:
        values[name] = draw(st.integers(0, what) if isinstance(what, int) else what)
    names = [name for name, _ in valid]
    victim = draw(st.sampled_from([None] * len(names) + names))
    if victim is not None:
        what = dict(valid)[victim]
        edge = [what + 1] if isinstance(what, int) else []
        values[victim] = draw(st.one_of(WRONG, st.sampled_from(edge or [None])))
    return values


payloads = st.one_of(
    st.binary(max_size=100),
    st.binary(max_size=30).map(bytearray),
    st.binary(max_size=30).map(memoryview),
    st.sampled_from(["text", 5]),
)
times = st.one_of(
    st.none(),
    st.tuples(st.integers(0, (1 << 32) - 1), st.integers(0, (1 << 32) - 1)),
    st.tuples(st.integers(0, 255), st.integers(0, 255)).map(list),
    st.sampled_from([(1,), (1, 2, 3), 7, (-1, 0), (0, -1), (1 << 32, 0), (0, True)]),
)


def tc_fields(c):
    return [
        ("apid", 0x7FF),
        ("service", 255),
        ("subtype", 255),
        ("data", st.binary(max_size=100)),
        ("seq_count", 0x3FFF),
        ("ack", 15),
        ("source_id", c.source_id_max),
        ("seq_flags", 3),
    ]


def tm_fields(c):
    t = c.time
    if isinstance(t, Cuc) and not t.explicit:
        time = st.one_of(
            st.tuples(
                st.integers(0, (1 << (8 * t.coarse)) - 1), st.integers(0, (1 << (8 * t.fine)) - 1)
            ),
            times,
        )
    else:
        time = times
    return [
        ("apid", 0x7FF),
        ("service", 255),
        ("subtype", 255),
        ("data", st.binary(max_size=100)),
        ("seq_count", 0x3FFF),
        ("message_counter", c.message_counter_max),
        ("destination_id", c.destination_id_max),
        ("time", time),
        ("time_ref", 15),
        ("seq_flags", 3),
    ]


def outcome(fn, *args):
    """What ``fn(*args)`` did: ("ok", result) or ("raised", type, args, attributes)."""
    try:
        return ("ok", fn(*args))
    except Exception as e:  # compared whole, whatever it is
        return ("raised", type(e), e.args, sorted(vars(e).items(), key=lambda kv: kv[0]))


def fields(p):
    if isinstance(p, PusTc):
        names = ("apid", "service", "subtype", "seq_count", "ack", "source_id", "seq_flags")
    else:
        names = PusTm.__slots__[:3] + (
            "seq_count",
            "message_counter",
            "destination_id",
            "time",
            "time_ref",
            "seq_flags",
        )
    values = [(n, getattr(p, n)) for n in names]
    return type(p), values, type(p.data), bytes(p.data)


def decoded(o):
    return o if o[0] != "ok" else ("ok", fields(o[1]))


@needs_c
def test_default_layout_takes_the_c_path():
    fast, slow = twins()
    assert fast.tc_fast and fast.tm_fast
    assert not slow.tc_fast and not slow.tm_fast
    raw = PusTc(0x65, 17, 1, b"", 3).pack()
    assert C.tc_unpack(PusTc, raw, fast.tc_fast, fast) is not None
    assert C.tc_pack(0x65, 3, 3, 15, 17, 1, 0, b"", fast.tc_fast) == raw
    assert C.tc_pack(0x800, 3, 3, 15, 17, 1, 0, b"", fast.tc_fast) is None  # Python raises


@needs_c
def test_other_layouts_stay_pure():
    for kw in (
        {"source_id_size": 3},
        {"source_id_size": 0},
        {"message_counter_size": 0},
        {"time": Cds()},
        {"time": Cuc(4, 2, None, True)},
        {"max_packet_size": 1.5e9},
    ):
        c = PusConfig(**kw)
        assert not c.tc_fast or not c.tm_fast, kw


@needs_c
@SETTINGS
@given(st.binary(max_size=300), st.integers(0, 0xFFFF))
def test_crc_matches_pure(data, register):
    assert C.crc16_ccitt(data, register) == CRC16_CCITT_FALSE(data, register)


@needs_c
@SETTINGS
@given(layouts(), st.sampled_from([None, None, payloads]), st.data())
def test_tc_pack_same_both_ways(kw, other_data, data):
    fast, slow = twins(**kw)
    values = spoiled(data.draw, tc_fields(fast))
    if other_data is not None:
        values["data"] = data.draw(other_data)
    a = outcome(lambda: PusTc(config=fast, **values).pack())
    b = outcome(lambda: PusTc(config=slow, **values).pack())
    assert a == b
    v = values
    took = fast.tc_fast and C.tc_pack(
        v["apid"],
        v["seq_count"],
        v["seq_flags"],
        v["ack"],
        v["service"],
        v["subtype"],
        v["source_id"],
        v["data"],
        fast.tc_fast,
    )
    event("C packed" if took else "Python %s" % a[0])


@needs_c
@SETTINGS
@given(layouts(), st.sampled_from([None, None, payloads]), st.data())
def test_tm_pack_same_both_ways(kw, other_data, data):
    fast, slow = twins(**kw)
    values = spoiled(data.draw, tm_fields(fast))
    if other_data is not None:
        values["data"] = data.draw(other_data)
    a = outcome(lambda: PusTm(config=fast, **values).pack())
    b = outcome(lambda: PusTm(config=slow, **values).pack())
    assert a == b
    v = values
    took = fast.tm_fast and C.tm_pack(
        v["apid"],
        v["seq_count"],
        v["seq_flags"],
        v["time_ref"],
        v["service"],
        v["subtype"],
        v["message_counter"],
        v["destination_id"],
        v["time"],
        v["data"],
        fast.tm_fast,
    )
    event("C packed" if took else "Python %s" % a[0])


@st.composite
def damaged(draw, make):
    """A packet of a random layout (from ``make(config, draw)``), maybe damaged."""
    kw = draw(layouts())
    fast, slow = twins(**kw)
    try:
        raw = bytearray(make(slow, draw))
    except Exception:
        raw = bytearray(draw(st.binary(max_size=40)))
    how = draw(st.sampled_from(["intact", "flip", "reseal", "cut", "extend", "random"]))
    if how in ("flip", "reseal") and raw:
        i = draw(st.integers(0, min(len(raw), 12) - 1 if how == "reseal" else len(raw) - 1))
        raw[i] ^= 1 << draw(st.integers(0, 7))
        if how == "reseal" and slow.pec and len(raw) > 2:
            # a header field changed under a valid PEC: only the field checks can catch it
            raw[-2:] = crc16_ccitt(bytes(raw[:-2])).to_bytes(2, "big")
    elif how == "cut":
        del raw[draw(st.integers(0, len(raw))) :]
    elif how == "extend":
        raw += draw(st.binary(min_size=1, max_size=4))
    elif how == "random":
        raw = bytearray(draw(st.binary(max_size=60)))
    kind = draw(st.sampled_from([bytes, bytes, bytearray, memoryview]))
    return fast, slow, kind(bytes(raw))


def some_tc(c, draw):
    return PusTc(
        draw(st.integers(0, 0x7FF)),
        draw(st.integers(0, 255)),
        draw(st.integers(0, 255)),
        draw(st.binary(max_size=40)),
        draw(st.integers(0, 0x3FFF)),
        draw(st.integers(0, 15)),
        draw(st.integers(0, (1 << (8 * c.source_id_size)) - 1)),
        draw(st.integers(0, 3)),
        config=c,
    ).pack()


def some_tm(c, draw):
    time = None
    if isinstance(c.time, Cuc) and not c.time.explicit:
        coarse = draw(st.integers(0, (1 << (8 * c.time.coarse)) - 1))
        time = (coarse, draw(st.integers(0, (1 << (8 * c.time.fine)) - 1)))
    return PusTm(
        draw(st.integers(0, 0x7FF)),
        draw(st.integers(0, 255)),
        draw(st.integers(0, 255)),
        draw(st.binary(max_size=40)),
        draw(st.integers(0, 0x3FFF)),
        draw(st.integers(0, c.message_counter_max)),
        draw(st.integers(0, c.destination_id_max)),
        time,
        draw(st.integers(0, 15)),
        draw(st.integers(0, 3)),
        config=c,
    ).pack()


@needs_c
@SETTINGS
@given(damaged(some_tc))
def test_tc_unpack_same_both_ways(case):
    fast, slow, buf = case
    a = decoded(outcome(lambda: PusTc.unpack(buf, fast)))
    b = decoded(outcome(lambda: PusTc.unpack(buf, slow)))
    assert a == b
    c_took = fast.tc_fast and C.tc_unpack(PusTc, buf, fast.tc_fast, fast)
    event("C decoded" if c_took else "Python %s" % a[0])


@needs_c
@SETTINGS
@given(damaged(some_tm))
def test_tm_unpack_same_both_ways(case):
    fast, slow, buf = case
    a = decoded(outcome(lambda: PusTm.unpack(buf, fast)))
    b = decoded(outcome(lambda: PusTm.unpack(buf, slow)))
    assert a == b
    c_took = fast.tm_fast and C.tm_unpack(PusTm, buf, fast.tm_fast, fast)
    event("C decoded" if c_took else "Python %s" % a[0])


@needs_c
@pytest.mark.parametrize("kind", [PusTc, PusTm])
@pytest.mark.parametrize(
    "kw",
    [{}, {"pec": False}, {"source_id_size": 1, "tc_spare": 2, "destination_id_size": 4}],
)
def test_every_header_bit_flipped_under_a_valid_pec(kind, kw):
    fast, slow = twins(**kw)
    raw = kind(0x65, 3, 25, b"abc", 7, config=slow).pack()
    header = slow.tc_data_offset if kind is PusTc else slow.tm_data_offset
    for i in range(header):
        for bit in range(8):
            buf = bytearray(raw)
            buf[i] ^= 1 << bit
            if slow.pec:
                buf[-2:] = crc16_ccitt(bytes(buf[:-2])).to_bytes(2, "big")
            a = decoded(outcome(kind.unpack, bytes(buf), fast))
            b = decoded(outcome(kind.unpack, bytes(buf), slow))
            assert a == b, (i, bit)


@needs_c
def test_unpack_keeps_config_and_subclass():
    class Mine(PusTc):
        __slots__ = ("extra",)

    fast, _ = twins()
    tc = Mine.unpack(PusTc(1, 17, 1).pack(), fast)
    assert type(tc) is Mine and tc.config is fast
    assert not hasattr(tc, "extra")
    tm = PusTm.unpack(PusTm(1, 17, 2, b"x", time=(5, 6)).pack(), fast)
    assert tm.time == (5, 6) and tm.data == b"x" and tm.config is fast


@needs_c
def test_pack_reads_slots_only_of_classes_it_can_vouch_for():
    fast, slow = twins()

    class Plain(PusTc):
        __slots__ = ("extra",)

    class Computed(PusTc):
        # a field turned into a property: the slot is not where the value lives any more
        @property
        def apid(self):
            return 0x42

        @apid.setter
        def apid(self, value):
            pass

    raw = PusTc(0x42, 17, 1, b"ab", 3).pack()
    assert C.tc_pack_slots(Plain(0x42, 17, 1, b"ab", 3), fast.tc_fast) == raw
    assert C.tc_pack_slots(Computed(7, 17, 1, b"ab", 3), fast.tc_fast) is None
    assert Computed(7, 17, 1, b"ab", 3, config=fast).pack() == raw
    tc = Computed.unpack(raw, fast)
    assert type(tc) is Computed and tc.apid == 0x42 and tc.data == b"ab"
    unset = PusTc.__new__(PusTc)
    assert C.tc_pack_slots(unset, fast.tc_fast) is None
    with pytest.raises(AttributeError):
        unset.pack()
    tm = PusTm(5, 3, 25, b"xyz", 9, 4, 0, (1, 2), config=fast)
    assert (
        C.tm_pack_slots(tm, fast.tm_fast)
        == PusTm(5, 3, 25, b"xyz", 9, 4, 0, (1, 2), config=slow).pack()
    )
    PusTc.apid = PusTc.apid  # any change to the class invalidates the cached offsets
    assert C.tc_pack_slots(Plain(0x42, 17, 1, b"ab", 3), fast.tc_fast) == raw


@needs_c
def test_odd_buffers_go_the_python_way():
    fast, slow = twins()
    raw = PusTc(1, 17, 1).pack()
    # a memoryview of 16-bit items has a length in items, not octets: Python decides
    words = memoryview(bytearray(raw + b"\x00")).cast("H")
    assert C.tc_unpack(PusTc, words, fast.tc_fast, fast) is None
    assert decoded(outcome(lambda: PusTc.unpack(words, fast))) == decoded(
        outcome(lambda: PusTc.unpack(words, slow))
    )
    assert C.tc_unpack(PusTc, "text", fast.tc_fast, fast) is None
    assert C.tc_unpack(PusTc, raw[::-1], fast.tc_fast, fast) is None


def _pure_env():
    env = dict(os.environ, OBSW_PURE="1")
    paths = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]
    env["PYTHONPATH"] = os.pathsep.join(paths + [env.get("PYTHONPATH", "")])
    return env


def test_obsw_pure_turns_accelerators_off():
    code = (
        "from obsw.compat import pus_accelerator, crc_accelerator\n"
        "from obsw.crc import crc16_ccitt_update\n"
        "from obsw.pus.config import DEFAULT\n"
        "print(pus_accelerator() is None, crc_accelerator(16, 0x1021, 0xFFFF, False, 0)"
        " is None, crc16_ccitt_update.__module__ == 'obsw.crc', DEFAULT.tc_fast, DEFAULT.tm_fast)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], env=_pure_env(), capture_output=True, text=True, cwd=ROOT
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "True", "True", "0", "0"]


def test_core_packet_tests_pass_pure():
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "-q",
            "-o",
            "addopts=-p no:cacheprovider",
            os.path.join("tests", "core", "test_pus_packets.py"),
            os.path.join("tests", "core", "test_crc.py"),
        ],
        env=_pure_env(),
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert out.returncode == 0, out.stdout + out.stderr
    assert " passed" in out.stdout and "failed" not in out.stdout, out.stdout
