"""`obsw packet decode|encode` through the CLI entry point: JSON, hex and exit codes."""

import json

import pytest
from obsw.crc import crc16_ccitt
from obsw_host.cli import main

# TC[17,1], APID 0x073, count 25, all ack flags, source 0 (fields worked out by hand)
TC_HEAD = "1873c01900062f11010000"
TC_HEX = TC_HEAD + "%04x" % crc16_ccitt(bytes.fromhex(TC_HEAD))
# TM[3,25], APID 0x065, count 5, time ref 1, counter 7, destination 9, CUC 0x01020304.0x0506
TM_HEAD = "0865c005001021031900070009010203040506aabb"
TM_HEX = TM_HEAD + "%04x" % crc16_ccitt(bytes.fromhex(TM_HEAD))


def run(capsys, *argv):
    code = main(["packet", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_decode_tc(capsys):
    code, out, err = run(capsys, "decode", TC_HEX)
    assert code == 0 and err == ""
    doc = json.loads(out)
    assert doc["space_packet"] == {
        "apid": 0x73,
        "data_length": 6,
        "idle": False,
        "packet_length": 13,
        "sec_header_flag": True,
        "seq_count": 25,
        "seq_flags": "unsegmented",
        "type": "TC",
        "version": 0,
    }
    pus = doc["pus"]
    assert (pus["service"], pus["subtype"], pus["message"]) == (17, 1, "TC_TEST_ARE_YOU_ALIVE")
    assert pus["ack"] == 15 and pus["ack_flags"] == [
        "acceptance",
        "start",
        "progress",
        "completion",
    ]
    assert pus["source_id"] == 0 and pus["pus_version"] == 2
    assert pus["pec"] == "0x" + TC_HEX[-4:]
    assert doc["data"] == ""
    assert out == json.dumps(doc, indent=2, sort_keys=True) + "\n"  # stable, pretty


def test_decode_tm_with_spaces(capsys):
    spaced = " ".join(TM_HEX[i : i + 4] for i in range(0, len(TM_HEX), 4))
    code, out, _ = run(capsys, "decode", spaced)
    assert code == 0
    doc = json.loads(out)
    assert doc["space_packet"]["type"] == "TM"
    pus = doc["pus"]
    assert pus["message"] == "TM_HK_HK_REPORT"
    assert (pus["message_counter"], pus["destination_id"], pus["time_ref_status"]) == (7, 9, 1)
    assert pus["time"] == [0x01020304, 0x0506]
    assert pus["time_seconds"] == pytest.approx(0x01020304 + 0x0506 / 65536)
    assert doc["data"] == "aabb"


def test_decode_plain_space_packet(capsys):
    code, out, _ = run(capsys, "decode", "07ffc0050003" + "55aa55aa")
    assert code == 0
    doc = json.loads(out)
    assert doc["space_packet"]["idle"] is True
    assert "pus" not in doc and doc["data"] == "55aa55aa"


@pytest.mark.parametrize(
    "hexstr, words",
    [
        ("18730", "odd number of hex digits"),
        ("zz", "not hexadecimal"),
        ("1873c0", "too short: 3 bytes, needs 6"),
        (TC_HEX[:-2], "13"),
        (TC_HEX[:-4] + "0000", "packet error control 0x0000, computed 0x" + TC_HEX[-4:]),
        (TC_HEX + "00", "packet data length field says 13"),
        ("3873" + TC_HEX[4:], "packet version number 1, expected 0"),
    ],
)
def test_decode_malformed(capsys, hexstr, words):
    code, out, err = run(capsys, "decode", hexstr)
    assert code == (2 if "hex" in words else 1) and out == ""  # 2: the hex itself is wrong
    assert err.startswith("obsw packet decode: ") and err.count("\n") == 1
    assert words in err


def test_encode_matches_hand_vector(capsys):
    code, out, _ = run(capsys, "encode", "--apid", "0x73", "--service", "17", "--subtype", "1")
    assert code == 0
    raw = bytes.fromhex(out.strip())
    assert raw[:11].hex() == "1873c00000062f11010000"  # sequence count 0 by default
    assert crc16_ccitt(raw) == 0
    code, out, _ = run(
        capsys, "encode", "--apid", "0x73", "--service", "17", "--subtype", "1", "--seq", "25"
    )
    assert out.strip() == TC_HEX


def test_encode_options_round_trip(capsys):
    code, out, _ = run(
        capsys,
        "encode",
        "--apid=256",
        "--service=20",
        "--subtype=3",
        "--ack=acceptance,completion",
        "--source-id=0xabcd",
        "--seq=16383",
        "--data=01 02 03 04",
    )
    assert code == 0
    raw = out.strip()
    assert raw[:22] == "1900ffff000a291403abcd"
    code, out, _ = run(capsys, "decode", raw)
    pus = json.loads(out)["pus"]
    assert pus["ack_flags"] == ["acceptance", "completion"]
    assert pus["source_id"] == 0xABCD
    assert json.loads(out)["data"] == "01020304"


def test_encode_without_pec(capsys):
    code, out, _ = run(capsys, "encode", "--apid=1", "--service=17", "--subtype=1", "--no-pec")
    assert out.strip() == "1801c00000042f11010000"


@pytest.mark.parametrize(
    "argv, words",
    [
        (["--apid=2048", "--service=17", "--subtype=1"], "APID 2048 out of range 0..2047"),
        (["--apid=1", "--service=256", "--subtype=1"], "service type 256"),
        (["--apid=1", "--service=17", "--subtype=1", "--ack=sometimes"], "unknown ack"),
        (["--apid=1", "--service=17", "--subtype=1", "--data=abc"], "odd number"),
        (["--apid=1", "--service=17", "--subtype=1", "--seq=16384"], "sequence count"),
    ],
)
def test_encode_errors(capsys, argv, words):
    code, out, err = run(capsys, "encode", *argv)
    assert code == 2 and out == ""  # a user mistake
    assert err.startswith("obsw packet encode: ") and words in err


@pytest.mark.parametrize("argv", [["--help"], ["decode", "--help"], ["encode", "--help"]])
def test_help(capsys, argv):
    with pytest.raises(SystemExit) as e:
        main(["packet", *argv])
    assert e.value.code == 0
    assert "usage: obsw packet" in capsys.readouterr().out
