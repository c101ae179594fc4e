"""Our SDLS AES-256-GCM frames against Yamcs' own (org.yamcs.security.sdls, the jar we ship),
both ways, TC and TM: what one end protects the other verifies and decrypts; forged and
replayed frames are refused by both. Yamcs runs in one JVM (tests/host/sdls_oracle) for the
module. Without Java or the Yamcs jars every test here is skipped with the reason."""

import os
import shutil
import subprocess

import pytest
from obsw.crc import crc16_ccitt
from obsw.frames import sdls, tc
from obsw.frames.sdls_gcm import GMAC, GcmSecurityAssociation, TmSecurity
from obsw.frames.tm import TmFrame
from obsw_host.yamcs import server

MISSING = server.missing() or (None if shutil.which("javac") else "javac is not installed")
pytestmark = pytest.mark.skipif(MISSING is not None, reason=str(MISSING))
SOURCE = os.path.join(os.path.dirname(__file__), "sdls_oracle", "SdlsOracle.java")
KEY = bytes(range(0x40, 0x60))
SCID = 0x2A


class Yamcs:
    def __init__(self, folder):
        jar = os.path.join(server.lib_dir(), "yamcs-core-5.12.8.jar")
        cp = os.pathsep.join([jar, os.path.join(server.lib_dir(), "*")])
        javac = os.path.join(os.path.dirname(server.java()), "javac")
        javac = javac if os.path.exists(javac) else shutil.which("javac")
        subprocess.run([javac, "-cp", cp, "-d", folder, SOURCE], check=True)
        self.proc = subprocess.Popen(
            [server.java(), "-cp", os.pathsep.join([folder, cp]), "SdlsOracle"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )

    def ask(self, *words):
        self.proc.stdin.write(" ".join(str(w) for w in words) + "\n")
        self.proc.stdin.flush()
        answer = self.proc.stdout.readline().strip()
        assert not answer.startswith("error"), answer
        return answer

    def new(self, name, spi, window=10, verify=True, key=KEY):
        self.ask("new", name, key.hex(), spi, window, str(verify).lower())

    def apply(self, name, kind, arg, frame, start, end):
        return bytes.fromhex(
            self.ask("apply", name, kind, str(arg).lower(), frame.hex(), start, end)
        )

    def process(self, name, kind, arg, frame, start, end):
        status, out = self.ask(
            "process", name, kind, str(arg).lower(), frame.hex(), start, end
        ).split()
        return status, bytes.fromhex(out)


@pytest.fixture(scope="module")
def yamcs(tmp_path_factory):
    y = Yamcs(str(tmp_path_factory.mktemp("sdls_oracle")))
    yield y
    y.proc.stdin.close()
    y.proc.wait(10)


def with_fecf(raw):
    return bytes(raw) + crc16_ccitt(bytes(raw)).to_bytes(2, "big")


def tc_security(spi=5, algorithm="aes-gcm"):
    sa = GcmSecurityAssociation(spi, 0, KEY, algorithm=algorithm)
    return sdls.TcSecurity([sa], segment_header=True), sa


def yamcs_tc_frame(yamcs, name, packet, map_id=1, vcid=0, spi=5, seq=0):
    """A TC frame Yamcs protected: header, segment header, room for the security header
    (2 + 12) and trailer (16), FECF recomputed after."""
    data = bytes([0xC0 | map_id]) + bytes(14) + packet + bytes(16)
    raw = bytearray(tc.TcFrame(SCID, vcid, data, seq, False).pack())
    n = len(raw)
    out = bytearray(yamcs.apply(name, "tc", True, bytes(raw[:-2]), 6, n - 2))
    return with_fecf(out)


def test_yamcs_tc_frames_are_accepted_and_decrypted(yamcs):
    yamcs.new("tc_up", 5)
    security, sa = tc_security()
    for i in range(3):
        packet = bytes([0x18, 0x01, 0xC0, i, 0, 5]) + bytes([i] * 6)
        frame = yamcs_tc_frame(yamcs, "tc_up", packet)
        assert packet not in frame  # encrypted on the way
        outcome, got_sa, sn, clear = security.process(frame, len(frame))
        assert (outcome, got_sa, sn) == (sdls.OK, sa, i)  # Yamcs counts its IVs from 0
        assert clear == bytes([0xC1]) + packet
        security.commit(sa, sn)
        # the same frame again is a replay
        assert security.process(frame, len(frame))[0] == sdls.REPLAY
    forged = bytearray(yamcs_tc_frame(yamcs, "tc_up", b"\x18\x01\xc0\x09\x00\x00\x01"))
    forged[22] ^= 1
    forged = with_fecf(forged[:-2])
    assert security.process(forged, len(forged))[0] == sdls.BAD_MAC
    assert security.counters["replay"] == 3 and security.counters["bad_mac"] == 1


def test_our_tc_frames_are_verified_by_yamcs(yamcs):
    yamcs.new("tc_down", 6, window=5, verify=True)
    security, sa = tc_security(6)
    frames = []
    for i in range(3):
        packet = bytes([0x18, 0x01, 0xC0, i, 0, 3, 1, 2, 3, i])
        data = security.apply(SCID, 0, tc.Segment(1, packet).pack())
        raw = tc.TcFrame(SCID, 0, data, i, False).pack()
        frames.append(raw)
        status, out = yamcs.process("tc_down", "tc", True, raw[:-2], 6, len(raw) - 2)
        assert status == "NoFailure"
        assert out[6 + 14 : 6 + 14 + len(packet)] == packet
    status, _ = yamcs.process("tc_down", "tc", True, frames[1][:-2], 6, len(frames[1]) - 2)
    assert status == "AntiReplaySequenceNumberFailure"
    forged = bytearray(frames[2][:-2])
    forged[-3] ^= 0x80
    status, _ = yamcs.process("tc_down", "tc", True, bytes(forged), 6, len(forged))
    assert status == "MacVerificationFailure"


def tm_frame(field, vcid=1, length=64):
    body = field + bytes(length - 6 - 4 - 2 - len(field))
    return TmFrame(SCID, vcid, body, 3, 7, 0, b"\x01\x02\x03\x04").pack()


def test_our_tm_frames_are_verified_by_yamcs(yamcs):
    yamcs.new("tm_down", 9, window=100, verify=True)
    tm = TmSecurity([GcmSecurityAssociation(9, 1, KEY)])
    packet = bytes([0x08, 0x65, 0xC0, 0, 0, 9]) + bytes(range(10))
    room = 64 - 6 - 4 - 2 - tm.overhead(1)
    frames = []
    for _ in range(2):
        raw = TmFrame(SCID, 1, tm.seal(1, packet + bytes(room - len(packet))), 0, 0, 0, b"\0" * 4)
        raw = raw.pack()
        frames.append(raw)
        assert packet not in raw
        status, out = yamcs.process("tm_down", "tm", 0, raw, 6, len(raw) - 6)
        assert status == "NoFailure"
        assert out[20 : 20 + len(packet)] == packet
    status, _ = yamcs.process("tm_down", "tm", 0, frames[0], 6, len(frames[0]) - 6)
    assert status == "AntiReplaySequenceNumberFailure"
    forged = bytearray(frames[1])
    forged[30] ^= 4
    status, _ = yamcs.process("tm_down", "tm", 0, bytes(forged), 6, len(forged) - 6)
    assert status == "MacVerificationFailure"


def test_yamcs_tm_frames_are_verified_by_us(yamcs):
    yamcs.new("tm_up", 9)
    tm = TmSecurity([GcmSecurityAssociation(9, 1, KEY)])
    packet = bytes([0x08, 0x65, 0xC0, 0, 0, 3, 9, 8, 7, 6])
    field = bytes(14) + packet + bytes(64 - 12 - 30 - len(packet)) + bytes(16)
    raw = with_fecf(yamcs.apply("tm_up", "tm", 0, tm_frame(field), 6, 64 - 6)[:-2])
    got = TmFrame.unpack(raw)
    outcome, clear = tm.open(1, got.data)
    assert outcome == sdls.OK and clear.startswith(packet)
    assert tm.open(1, got.data)[0] == sdls.REPLAY
    bad = bytearray(got.data)
    bad[-1] ^= 1
    assert tm.open(1, bytes(bad))[0] == sdls.BAD_MAC
    assert tm.counters == {
        "ok": 1,
        "bad_spi": 0,
        "sa_not_operational": 0,
        "bad_mac": 1,
        "replay": 1,
        "too_short": 0,
    }


def test_gmac_frames_stay_clear_and_authenticated():
    security, sa = tc_security(7, GMAC)
    receiver, _ = tc_security(7, GMAC)
    packet = bytes([0x18, 0x01, 0xC0, 0, 0, 1, 0xAB])
    raw = tc.TcFrame(SCID, 0, security.apply(SCID, 0, tc.Segment(1, packet).pack()), 0).pack()
    assert packet in raw
    assert receiver.process(raw, len(raw))[3] == bytes([0xC1]) + packet
    forged = bytearray(raw)
    forged[raw.index(packet) + 6] ^= 1
    forged = with_fecf(forged[:-2])
    assert receiver.process(forged, len(forged))[0] == sdls.BAD_MAC
