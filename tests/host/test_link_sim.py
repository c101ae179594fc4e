"""The slow, noisy link (obsw_sim.radio, obsw_sim.link_sim) on a simulated clock: at 9,600
bit/s real-time housekeeping keeps its period while a playback dump and a CFDP downlink share
the rest, the link is used while data waits, nothing is lost, TCs go up through COP-1."""

from obsw_sim import link_sim
from obsw_sim.radio import RadioChannel


def test_9600_bits_per_second_with_ber_1e3_loses_nothing():
    f = link_sim.run(bps=9600, ber=1e-3, coding="concatenated", interleave=2, hk_period=1.0)
    frame_time = 648 * 8 / 9600  # 256-octet frames, RS I=2 and rate 1/2: 648 octets on the air
    assert f["link_use"] >= 95.0, f.summary()
    assert f["lost"] == 0 and f["dropped"] == 0 and f["duplicates"] == 0, f.summary()
    assert f["spilled"] > 0  # the dump went faster than the link: it waited, it was not lost
    assert f["flipped"] > 1000 and f["uncorrectable"] == 0  # errors on the air, all corrected
    assert abs(f["hk_mean"] - 1.0) < 0.02, f.summary()
    assert f["hk_max"] <= 1.0 + 2 * frame_time and f["hk_min"] >= 1.0 - 2 * frame_time
    assert f["hk_received"] >= f["seconds"] - 2  # one a second from start to end
    assert f["tcs_acknowledged"] == f["tcs"] == f["tcs_delivered"] and f["tcs_in_order"]


def test_uplink_at_1200_bits_per_second_with_errors_keeps_cop1_working():
    f = link_sim.run(uplink_bps=1200, uplink_ber=1e-4, tcs=12, playback=20, cfdp=10, seed=4)
    assert f["tcs_acknowledged"] == 12 and f["tcs_delivered"] == 12 and f["tcs_in_order"]
    assert f["lost"] == 0


def test_awgn_soft_symbols_at_3_db_are_corrected():
    f = link_sim.run(ebn0_db=3.0, ber=0.0, playback=20, cfdp=10)
    assert f["corrected"] > 0, f.summary()
    assert f["uncorrectable"] <= 1 and f["lost"] <= 1, f.summary()


def test_error_bursts_are_corrected_by_interleaved_reed_solomon():
    f = link_sim.run(coding="rs", interleave=4, ber=0.0, burst_rate=2e-4, frame_length=512,
                     playback=20, cfdp=10)  # fmt: skip
    assert f["corrected"] > 0 and f["uncorrectable"] == 0 and f["lost"] == 0, f.summary()


def test_bit_slips_cost_the_frame_they_hit_and_never_the_lock():
    f = link_sim.run(coding="rs", interleave=2, ber=0.0, slip_rate=1e-5, playback=20, cfdp=10)
    assert f["locks"] == 1 and f["losses"] == 0, f.summary()
    assert 0 < f["uncorrectable"] and f["lost"] > 0  # the frames a slip hit, nothing more


def test_channel_rate_and_arrival_time():
    ch = RadioChannel(1000)
    ch.send(b"\x01" * 125, 0.0)  # one second on the air
    ch.send(b"\x02" * 125, 0.5)  # queued behind it
    assert ch.receive(0.999) == b""
    assert ch.receive(1.0) == b"\x01" * 125
    assert ch.receive(1.999) == b""
    assert ch.receive(2.0) == b"\x02" * 125
    assert ch.busy == 2.0 and ch.idle_at() == 2.0


def test_ber_is_what_was_asked():
    ch = RadioChannel(1e6, ber=1e-2, seed=7)
    ch.send(bytes(50000), 0.0)
    ones = sum(bin(b).count("1") for b in ch.receive(1.0))
    assert ones == ch.flipped and 3600 <= ones <= 4400  # 400,000 bits at 1e-2, 6 sigma


def test_slips_keep_the_stream_octet_aligned_across_sends():
    ch = RadioChannel(1e6, slip_rate=1e-3, seed=2)
    total = 0
    for _ in range(20):
        ch.send(bytes(100), 0.0)
        total += 800
    got = ch.receive(1.0)
    assert ch.slips > 0 and abs(len(got) * 8 - total) <= ch.slips + 8
