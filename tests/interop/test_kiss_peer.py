"""KISS against kiss3 (PyPI, the TNC library of APRS tools): its TCP client on the station's
KISS server, both directions: its frames carry coded TM to our decoder, ours carry CLTUs to
its decoder; and the framing alone, byte for byte, both ways."""

import asyncio
import threading
import time

import kiss as kiss
import kiss.util as kiss_util
from obsw.frames import kiss as ours
from obsw.frames.cltu import encode as cltu_encode
from obsw.frames.tm_coding import TmDecoder, TmEncoder
from obsw_host.frames.ground import Ground
from obsw_host.frames.radio import KissTcpServer

SCID = 0x2A
LENGTH = 128


def test_framing_byte_for_byte_both_ways():
    # kiss3's decoder strips a leading 0x00 and trailing white space (it expects AX.25), so
    # the payloads here start and end with other octets; CLTUs (EB 90 ... 79) do too
    payloads = [b"\x01\xc0\xdb\xc0\xdb\x02", bytes(range(1, 200)) + b"\x7f", b"\xeb\x90\xc0\x79"]
    for p in payloads:
        theirs = b"".join([b"\xc0\x00", kiss_util.escape_special_codes(p), b"\xc0"])
        assert ours.encode(p) == theirs
        decoder = kiss.KISSDecode()
        assert list(decoder.update(ours.encode(p))) == [p]
        assert ours.KissDecoder().feed(theirs) == [p]


def _tm_stream():
    """Coded TM frames of a frame processor (one packet) as channel octets, one per frame."""
    from obsw.frames.processor import FrameProcessor

    enc = TmEncoder(LENGTH, "rs", 16, 1)
    fp = FrameProcessor(SCID, lambda a, p: None, tm_frame_length=LENGTH, tm_coding=enc)
    packet = bytes((0x08, 0x21, 0xC0, 0x01, 0x00, 0x04)) + b"kiss!"
    fp.send_packet(packet)
    frames = fp.tm_output(0.0)
    frames += [enc.encode(bytes(LENGTH))] * 3  # anything after it: the synchronizer's flywheel
    return packet, frames


def test_kiss3_tcp_client_on_the_station_server():
    packet, tm_frames = _tm_stream()
    server = KissTcpServer()
    decoder = lambda: TmDecoder(LENGTH, "rs", 16, 1)  # noqa: E731
    ground = Ground([server], SCID, tm_frame_length=LENGTH, tm_decoder=decoder)
    got_by_peer = []
    done = threading.Event()

    async def peer():
        transport, protocol = await kiss.create_tcp_connection(
            *server.address[:2], protocol_kwargs={"decoder": kiss.KISSDecode()}
        )
        for f in tm_frames:
            protocol.write(f)
        end = time.monotonic() + 20
        while not done.is_set() and time.monotonic() < end:
            while not protocol.frames.empty():
                got_by_peer.append(protocol.frames.get_nowait())
            await asyncio.sleep(0.01)
        transport.close()

    thread = threading.Thread(target=lambda: asyncio.run(peer()), daemon=True)
    thread.start()
    try:
        end = time.monotonic() + 20
        while time.monotonic() < end and packet not in ground.packets:
            ground.poll(0.0, 0.02)
        assert packet in ground.packets
        assert ground.coding()["uncorrectable"] == 0
        ground.initiate(0.0)  # FOP-1's first BC frame: a CLTU through KISS to the peer
        sent = cltu_encode(ground.sent_frames[-1].pack())
        while time.monotonic() < end and sent not in got_by_peer:
            ground.poll(0.0, 0.02)
        assert sent in got_by_peer
    finally:
        done.set()
        thread.join(5)
        server.close()
