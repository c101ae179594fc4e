"""The slow, noisy link simulated on one clock: a frame processor paced to the radio, a
playback dump and a CFDP downlink sharing the link with real-time housekeeping, TCs going up
through COP-1, and the ground decoding what the radio model lets through.

``run(...)`` returns the figures: the link's use while data waits, the housekeeping period
seen on the ground, packets lost per kind, the decoder's corrections, the TCs acknowledged.
Time is simulated (``dt`` steps): a run is as fast as the machine, never depends on it, and
repeats (the noise has a seed).
"""

from obsw.frames import fop as F
from obsw.frames.cltu import encode as cltu_encode
from obsw.frames.processor import FrameProcessor
from obsw.frames.tc import Segment
from obsw.frames.tm import TmFrame
from obsw.frames.tm_coding import TmDecoder, TmEncoder
from obsw.frames.tm_demux import TmDemultiplexer
from obsw.frames.tm_mux import TmVirtualChannel
from obsw.frames.tm_plan import plan_channels, tm_plan

from obsw_sim.radio import RadioChannel

SCID = 0x2A
HK_APID, PLAYBACK_APID, CFDP_APID, TC_APID = 0x10, 0x11, 0x12, 0x20
CFDP_VC = 2


def _packet(apid, seq, size):
    n = size - 6
    body = bytes((seq >> 8 & 0xFF, seq & 0xFF)) + bytes((seq + k) & 0xFF for k in range(n - 2))
    return bytes((0x08 | apid >> 8, apid & 0xFF, 0xC0 | seq >> 8 & 0x3F, seq & 0xFF,
                  (n - 1) >> 8, (n - 1) & 0xFF)) + body  # fmt: skip


class Figures(dict):
    """The figures of a run (a dict, with a one-line summary)."""

    def summary(self):
        return (
            "%(bps)d bit/s %(coding)s BER %(ber)g: link %(link_use).1f %% used while data "
            "waited (packets fill %(octet_use).1f %% of their data fields), HK period "
            "%(hk_mean).3f s "
            "(%(hk_min).2f-%(hk_max).2f s, set %(hk_period)g s), lost %(lost)d of %(sent)d "
            "packets, %(corrected)d RS symbols corrected, %(uncorrectable)d uncorrectable, "
            "%(tcs_acknowledged)d/%(tcs)d TCs acknowledged at %(uplink_bps)d bit/s" % self
        )


def run(bps=9600, ber=1e-3, ebn0_db=None, coding="concatenated", interleave=2,
        frame_length=256, hk_period=1.0, hk_size=60, playback=120, playback_size=200,
        playback_rate=64, cfdp=60, cfdp_size=220, cfdp_rate=200, start=2.0, tcs=5,
        uplink_bps=2400, uplink_ber=1e-5, burst_rate=0.0, slip_rate=0.0, seed=1, dt=0.01,
        limit=600.0):  # fmt: skip
    """Simulate until every packet is on the ground (or ``limit`` seconds); the Figures."""
    enc = TmEncoder(frame_length, coding, 16, interleave)
    plan = tm_plan()
    channels = plan_channels(plan, 4096) + [TmVirtualChannel(CFDP_VC, 0, 8192, "cfdp")]
    fp = FrameProcessor(
        SCID, lambda apid, p: received_tcs.append(p), tm_frame_length=frame_length,
        tm_channels=channels, tm_plan=plan, tm_vc_of_apid={CFDP_APID: CFDP_VC},
        tm_coding=enc, downlink_bps=bps, tm_spill=1 << 20, clcw_period=1.0,
    )  # fmt: skip
    rate = frame_length / enc.channel_length
    down = RadioChannel(bps, ber, ebn0_db, rate, burst_rate, 8, slip_rate, seed)
    up = RadioChannel(uplink_bps, uplink_ber, seed=seed + 1, soft=False)
    dec = TmDecoder(frame_length, coding, 16, interleave)
    demux = TmDemultiplexer(SCID)
    # K = 5, the FARM's positive window (W = 10): more, and frames behind a lost CLTU lock it out
    fop = F.Fop1(SCID, 0, 5, 4 * enc.channel_length * 8 / bps + 2.0, 10)
    received_tcs = []
    notes = []
    sent = {"hk": [], "playback": [], "cfdp": []}
    got = {"hk": [], "playback": [], "cfdp": []}
    kinds = {HK_APID: "hk", PLAYBACK_APID: "playback", CFDP_APID: "cfdp"}
    hk_times = []
    tc_packets = [_packet(TC_APID, i, 20) for i in range(tcs)]
    tc_queue = list(tc_packets)
    # link use: frame slots handed while data waited, and how many of them carried data
    slots_waiting = 0
    slots_used = 0
    data_octets = 0  # packet octets in the frames received while the dump and file lasted
    frames_while = 0
    t = 0.0
    next_hk = 0.0
    played = 0
    cfdp_sent = 0
    initiated = False
    done = None
    settle = 3.0 * hk_period + 4 * enc.channel_length * 8 / bps  # HK still in flight then
    while t < limit:
        if t >= next_hk:
            p = _packet(HK_APID, len(sent["hk"]), hk_size)
            sent["hk"].append(p)
            fp.send_packet(p)
            next_hk += hk_period
        if t >= start:
            while played < playback and played < (t - start) * playback_rate:
                p = _packet(PLAYBACK_APID, played, playback_size)
                sent["playback"].append(p)
                fp.send_playback(p)
                played += 1
            while cfdp_sent < cfdp and cfdp_sent < (t - start) * cfdp_rate:
                p = _packet(CFDP_APID, cfdp_sent, cfdp_size)
                sent["cfdp"].append(p)
                fp.send_packet(p)
                cfdp_sent += 1
            if not initiated:
                fop.directive(F.INITIATE_AD_WITH_UNLOCK, None, t)
                initiated = True
        waiting = fp.mux.pending() + (fp.spill.octets if fp.spill else 0)
        idle_before = fp.counters["tm_idle_frames"]
        out = fp.tm_output(t)
        if out:
            used = len(out) - (fp.counters["tm_idle_frames"] - idle_before)
            if waiting and t >= start and (played < playback or cfdp_sent < cfdp or waiting):
                slots_waiting += len(out)
                slots_used += used
            down.send(b"".join(out), t)
        for frame in dec.feed_octets(down.receive(t)) if not down.soft else dec.feed_soft(
                down.receive(t)):  # fmt: skip
            if frame.data is None:
                continue
            tm = TmFrame.unpack(frame.data)
            packets = demux.on_frame(tm)
            if start <= t and done is None and tm.vcid != 7:  # while the dump and file last
                frames_while += 1
                data_octets += sum(len(p) for p in packets)
            for p in packets:
                kind = kinds.get(((p[0] & 7) << 8) | p[1])
                if kind is not None:
                    got[kind].append(p)
                    if kind == "hk":
                        hk_times.append(t)
            if tm.ocf is not None and demux.clcw is not None:
                fop.on_clcw(demux.clcw, t)
        # the uplink: TCs through FOP-1 as CLTUs on the slow radio
        while tc_queue and fop.ready and initiated and fop.state == F.ACTIVE:
            fop.send_ad(Segment(1, tc_queue.pop(0)).pack(), t)
        for frame in fop.take_frames():
            up.send(cltu_encode(frame.pack()), t)
        fp.receive(0, up.receive(t), t)
        fop.tick(t)
        for note in fop.take_notifications():
            notes.append((round(t, 2),) + tuple(note) if isinstance(note, tuple) else note)
        if done is None and played == playback and cfdp_sent == cfdp and not tc_queue and (
                fop.outstanding == 0 and len(got["playback"]) + len(got["cfdp"]) >= playback
                + cfdp):  # fmt: skip
            done = t  # every packet of the dump and the file is down: HK a while longer
        if done is not None and t >= done + settle:
            break
        t += dt
    intervals = [b - a for a, b in zip(hk_times, hk_times[1:])]
    in_flight = [p for p in sent["hk"][-4:] if p not in got["hk"]]  # sent as the run ended
    sent["hk"] = sent["hk"][: len(sent["hk"]) - len(in_flight)]
    total = sum(len(v) for v in sent.values())
    lost = sum(len(set(sent[k]) - set(got[k])) for k in sent)
    frames_down = fp.counters["tm_frames"]
    return Figures(  # fmt: skip
        bps=bps, coding=coding, ber=ber if ebn0_db is None else 0.0, ebn0_db=ebn0_db,
        seconds=t, link_use=100.0 * slots_used / slots_waiting if slots_waiting else 0.0,
        octet_use=100.0 * data_octets / max(1, frames_while * fp.mux.data_length),
        hk_period=hk_period, hk_mean=sum(intervals) / len(intervals) if intervals else 0.0,
        hk_min=min(intervals) if intervals else 0.0, hk_max=max(intervals) if intervals else 0.0,
        hk_received=len(got["hk"]), sent=total, lost=lost,
        lost_by_kind={k: len(set(sent[k]) - set(got[k])) for k in sent},
        duplicates=sum(len(got[k]) - len(set(got[k])) for k in got),
        dropped=fp.counters["tm_dropped"], spilled=fp.counters["tm_spilled"],
        corrected=dec.corrected, uncorrectable=dec.uncorrectable, frames=frames_down,
        idle_frames=fp.counters["tm_idle_frames"], locks=dec.sync.locks,
        losses=dec.sync.losses, tcs=tcs, tcs_acknowledged=tcs - len(tc_queue)
        - fop.outstanding, tcs_delivered=len(received_tcs), tcs_in_order=received_tcs ==
        tc_packets, uplink_bps=uplink_bps, flipped=down.flipped, fop_state=fop.state,
        notes=notes, tc_counters={k: fp.counters[k] for k in ("cltus", "corrected_bits",
        "cltus_aborted", "bad_fecf", "accepted", "discarded", "duplicates")},
    )  # fmt: skip
