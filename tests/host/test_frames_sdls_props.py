"""Property tests for TC security (SDLS): sign/verify round trips, every bit authenticated,
random frames never raise, and the replay window against a plain set model."""

from hypothesis import given, settings
from hypothesis import strategies as st
from obsw.frames import sdls, tc

SETTINGS = settings(max_examples=200, deadline=None)
SCID = 0x2A
KEY = bytes(range(32))


def make_security(mac_length=16, sn_length=4):
    return sdls.TcSecurity(
        [
            sdls.SecurityAssociation(1, 0, KEY, None, mac_length, sn_length),
            sdls.SecurityAssociation(2, 0, KEY[::-1], 63, mac_length, sn_length),
        ]
    )


signed_inputs = st.tuples(
    st.sampled_from((1, 7, 63)),
    st.binary(min_size=0, max_size=200),
    st.booleans(),
    st.integers(8, 32),
    st.integers(1, 8),
    st.integers(0, 255),
)


@SETTINGS
@given(signed_inputs)
def test_signed_frames_verify_and_come_back_unchanged(args):
    map_id, payload, bypass, mac_length, sn_length, seq = args
    ground, onboard = make_security(mac_length, sn_length), make_security(mac_length, sn_length)
    seg = tc.Segment(map_id, payload).pack()
    raw = tc.TcFrame(SCID, 0, ground.apply(SCID, 0, seg, bypass), seq, bypass).pack()
    outcome, sa, sn, clear = onboard.process(raw, len(raw))
    assert (outcome, sn, clear) == (sdls.OK, 1, seg)
    assert sa.spi == (2 if map_id == 63 else 1)


@SETTINGS
@given(signed_inputs, st.data())
def test_every_authenticated_bit_counts(args, data):
    map_id, payload, bypass, mac_length, sn_length, seq = args
    ground, onboard = make_security(mac_length, sn_length), make_security(mac_length, sn_length)
    seg = tc.Segment(map_id, payload).pack()
    raw = tc.TcFrame(SCID, 0, ground.apply(SCID, 0, seg, bypass), seq, bypass).pack()
    # any bit but N(S) (octet 4, masked) and the FECF, with the FECF made good again
    bit = data.draw(st.integers(0, (len(raw) - 2) * 8 - 1).filter(lambda b: b // 8 != 4))
    changed = bytearray(raw[:-2])
    changed[bit // 8] ^= 0x80 >> (bit % 8)
    if bit // 8 < 4 and (changed[0] >> 6 or (changed[2] >> 2) != 0):
        return  # version or VC changed: not a frame for this channel any more
    n = tc.frame_length(bytes(changed) + b"\0\0")
    if bit // 8 in (2, 3) and n != len(raw):
        return  # the length field changed: the frame no longer parses as this frame
    outcome, _, _, clear = onboard.process(bytes(changed) + b"\0\0", len(raw))
    assert clear is None
    assert outcome != sdls.OK


@SETTINGS
@given(st.binary(min_size=5, max_size=300))
def test_random_frames_never_raise(raw):
    security = make_security()
    n = min(len(raw), tc.frame_length(raw))
    outcome, _, _, clear = security.process(raw, n)
    assert outcome in range(len(sdls.OUTCOME_NAMES))
    assert (clear is None) == (outcome != sdls.OK)


@SETTINGS
@given(
    st.integers(1, 40), st.none() | st.integers(1, 40), st.lists(st.integers(0, 200), max_size=80)
)
def test_replay_window_matches_a_model(size, ahead, numbers):
    window = sdls.ReplayWindow(size, ahead)
    seen = set()
    top = 0
    for sn in numbers:
        near = top == 0 or ahead is None or sn - top <= ahead
        expected = sn not in seen and sn > top - size and near and sn > 0
        assert window.acceptable(sn) == expected
        if expected:
            window.commit(sn)
            seen.add(sn)
            top = max(top, sn)
