"""Properties of the 131.0-B channel codecs: round trips within the code's power, and random
input never raises anything but the declared errors."""

from hypothesis import given
from hypothesis import strategies as st
from obsw.frames import rs, sync, tm_coding
from obsw.frames.errors import RsUncorrectableError


@st.composite
def rs_case(draw):
    e = draw(st.sampled_from([16, 8]))
    depth = draw(st.sampled_from(rs.DEPTHS))
    per_word = draw(st.integers(1, 255 - 2 * e))
    data = draw(st.binary(min_size=per_word * depth, max_size=per_word * depth))
    n = per_word + 2 * e
    # per codeword: errors and erasures with 2 * errors + erasures <= 2E
    errors, erasures = [], []
    for w in range(depth):
        nerr = draw(st.integers(0, e))
        ners = draw(st.integers(0, 2 * e - 2 * nerr))
        pos = draw(st.lists(st.integers(0, n - 1), min_size=min(n, nerr + ners),
                            max_size=min(n, nerr + ners), unique=True))  # fmt: skip
        errors += [(p * depth + w, draw(st.integers(1, 255))) for p in pos[:nerr]]
        erasures += [p * depth + w for p in pos[nerr:]]
    return e, depth, data, errors, erasures


@given(rs_case())
def test_rs_corrects_within_2e(case):
    e, depth, data, errors, erasures = case
    code = rs.ReedSolomon(e, depth, len(data))
    bad = bytearray(code.encode(data))
    for p, v in errors:
        bad[p] ^= v
    for p in erasures:
        bad[p] ^= 0x5A  # an erased symbol may be anything
    frame, corrected = code.decode(bytes(bad), erasures)
    assert frame == data
    assert sum(corrected) <= len(errors) + len(erasures)


@given(st.sampled_from([16, 8]), st.sampled_from(rs.DEPTHS), st.data())
def test_rs_random_blocks_decode_or_say_uncorrectable(e, depth, data):
    code = rs.ReedSolomon(e, depth, depth * 20)
    block = data.draw(st.binary(min_size=code.block_length, max_size=code.block_length))
    try:
        frame, corrected = code.decode(block)
    except RsUncorrectableError as err:
        assert err.codewords and len(err.data) == code.length
    else:
        assert len(frame) == code.length and all(0 <= c <= e for c in corrected)


@given(st.binary(max_size=600), st.sampled_from(tm_coding.CODINGS))
def test_random_streams_never_raise(data, coding):
    dec = tm_coding.TmDecoder(40, coding, 8, 2)
    for frame in dec.feed_octets(data) + dec.flush():
        assert frame.data is None or len(frame.data) == 40


@given(st.binary(max_size=300))
def test_bit_packing_round_trip(data):
    assert sync.pack_bits(sync.unpack_bits(data)) == data
