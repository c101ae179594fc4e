"""The ground station's radio interfaces: KISS over a serial port (a pseudo-terminal pair), over
TCP (`obsw frames station` as a KISS server), and UDP octets, bits or soft symbols from a GNU
Radio flowgraph; TM decoded with the mission's coding, TCs up as CLTUs."""

import array
import json
import os
import shutil
import socket
import threading
import time

import pytest
from obsw.frames import kiss
from obsw.frames.processor import FrameProcessor
from obsw.frames.tm_coding import TmDecoder, TmEncoder
from obsw_host import sample
from obsw_host.cli import main
from obsw_host.errors import UserError
from obsw_host.frames.coding import LinkSettings
from obsw_host.frames.ground import Ground
from obsw_host.frames.links import open_pty_pair
from obsw_host.frames.radio import KissSerial, UdpLink, open_link
from obsw_host.mission.ids import MissionIds

SCID = 0x2A
LENGTH = 128


def tm_packet(apid, seq, payload):
    n = len(payload)
    return bytes((0x08 | apid >> 8, apid & 0xFF, 0xC0, seq, 0, n - 1)) + payload


def coded_tm(encoder, packets, scid=SCID):
    """Channel octets of the frames carrying ``packets``, one chunk per frame, and a few idle
    frames after them (the synchronizer's flywheel)."""
    fp = FrameProcessor(scid, lambda a, p: None, tm_frame_length=encoder.frame_length,
                        tm_coding=encoder)  # fmt: skip
    for p in packets:
        fp.send_packet(p)
    out = fp.tm_output(0.0)
    for i in range(4):
        out += fp.tm_output(10.0 * (i + 1))
    return out


def pump(ground, until, limit=20.0):
    end = time.monotonic() + limit
    while time.monotonic() < end:
        ground.poll(0.0, 0.02)
        if until():
            return True
    return False


def test_kiss_serial_both_ways_over_a_pty_pair():
    enc = TmEncoder(LENGTH, "rs", 16, 1)
    ctrl, path = open_pty_pair()
    link = KissSerial(path, 9600)
    ground = Ground([link], SCID, tm_frame_length=LENGTH,
                    tm_decoder=lambda: TmDecoder(LENGTH, "rs", 16, 1))  # fmt: skip
    try:
        packets = [tm_packet(0x21, i, b"serial %d" % i) for i in range(3)]
        for chunk in coded_tm(enc, packets):
            os.write(ctrl, kiss.encode(chunk))
        assert pump(ground, lambda: len(ground.packets) == 3)
        assert list(ground.packets) == packets
        ground.initiate(0.0)
        cltu = ground.sent_frames[-1].pack()
        got = kiss.KissDecoder()
        frames = []
        end = time.monotonic() + 10
        while not frames and time.monotonic() < end:
            try:
                frames += got.feed(os.read(ctrl, 4096))
            except BlockingIOError:
                time.sleep(0)
        assert frames and frames[0][:2] == b"\xeb\x90" and len(frames[0]) > len(cltu)
    finally:
        link.close()
        os.close(ctrl)


@pytest.mark.parametrize("fmt", ["octets", "bits", "int8", "float32"])
def test_udp_from_a_flowgraph(fmt):
    enc = TmEncoder(LENGTH, "concatenated", 16, 1)
    peer = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    peer.bind(("127.0.0.1", 0))
    link = UdpLink(0, fmt, peer=peer.getsockname())
    ground = Ground([link], SCID, tm_frame_length=LENGTH,
                    tm_decoder=lambda: TmDecoder(LENGTH, "concatenated", 16, 1))  # fmt: skip
    try:
        packets = [tm_packet(0x22, 1, b"flowgraph " + fmt.encode())]
        for chunk in coded_tm(enc, packets):
            bits = [(b >> (7 - k)) & 1 for b in chunk for k in range(8)]
            if fmt == "octets":
                data = chunk
            elif fmt == "bits":
                data = bytes(bits)
            elif fmt == "int8":
                data = array.array("b", [90 if b else -90 for b in bits]).tobytes()
            else:
                data = array.array("f", [0.8 if b else -0.8 for b in bits]).tobytes()
            for i in range(0, len(data), 4096):
                peer.sendto(data[i : i + 4096], link.address)
        assert pump(ground, lambda: list(ground.packets) == packets)
        ground.initiate(0.0)  # the uplink: a CLTU to the flowgraph's input, as octets
        peer.settimeout(10)
        assert peer.recv(4096)[:2] == b"\xeb\x90"
    finally:
        link.close()
        peer.close()


def test_open_link_names_what_it_expects():
    with pytest.raises(UserError) as e:
        open_link("radio:1")
    assert "expected kiss-serial:DEV[@BAUD]" in str(e.value)
    with pytest.raises(UserError) as e:
        open_link("udp:0:float64")
    assert "float32" in str(e.value)


def _free_port(kind=socket.SOCK_STREAM):
    s = socket.socket(socket.AF_INET, kind)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def test_obsw_frames_station_as_a_kiss_server(tmp_path, capsys):
    folder = str(tmp_path / "m")
    shutil.copytree(sample.MISSION_DIR, folder)
    path = os.path.join(folder, "mission.json")
    with open(path) as f:
        doc = json.load(f)
    doc["frames"]["tm_coding"] = {"scheme": "rs", "interleave": 2}
    with open(path, "w") as f:
        json.dump(doc, f)
    ids = MissionIds.locate(path)
    link = LinkSettings.of(ids.config)
    kiss_port, tools_port = _free_port(), _free_port(socket.SOCK_DGRAM)
    args = ["frames", "station", "--mission", folder, "--link",
            "kiss-listen:127.0.0.1:%d" % kiss_port, "--port", str(tools_port),
            "--duration", "10", "--report", "1"]  # fmt: skip
    result = []
    runner = threading.Thread(target=lambda: result.append(main(args)), daemon=True)
    runner.start()
    tnc = None
    end = time.monotonic() + 10
    while tnc is None and time.monotonic() < end:
        try:
            tnc = socket.create_connection(("127.0.0.1", kiss_port), 1)
        except OSError:
            time.sleep(0.05)  # the station is not listening yet
    assert tnc is not None
    tools = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    tools.bind(("127.0.0.1", 0))
    tools.settimeout(0.5)
    try:
        apid = ids.apid("pus")
        sent = []
        got = None
        end = time.monotonic() + 15
        while got is None and time.monotonic() < end:
            # the station learns where the ground tools are from their TC (it may not listen
            # yet: again with a new TM packet until one comes back)
            tools.sendto(bytes((0x18, apid, 0xC0, 0, 0, 0)) + b"x", ("127.0.0.1", tools_port))
            packet = tm_packet(apid, len(sent), b"to the ground tools")
            sent.append(packet)
            for chunk in coded_tm(link.encoder(), [packet], ids.scid):
                tnc.sendall(kiss.encode(chunk))
            try:
                got = tools.recv(4096)
            except socket.timeout:
                pass
        assert got in sent
        decoder = kiss.KissDecoder()
        tnc.settimeout(15)
        frames = []
        while not frames:
            frames = decoder.feed(tnc.recv(4096))
        assert frames[0][:2] == b"\xeb\x90"  # FOP-1's first CLTU went out through the TNC
    finally:
        tnc.close()
        tools.close()
        runner.join(30)
    assert result == [0]
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("station: kiss-listen:127.0.0.1:%d; TM rs RS(255,223) I=2"
                               % kiss_port)  # fmt: skip
    counters = json.loads(lines[-1].split(": ", 1)[1])
    assert counters["frames"] >= 1 and counters["uncorrectable"] == 0
