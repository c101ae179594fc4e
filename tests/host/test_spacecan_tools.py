"""The SpaceCAN monitor's decoding, the obsw spacecan command's parser, and the demo."""

import argparse

import spacecan_demo as demo
from obsw.spacecan.nodedef import NodeDefinition
from obsw_host.commands import spacecan as command
from obsw_host.spacecan.monitor import Monitor

NODE = {
    "parameters": [
        {"parameter_id": 1, "parameter_name": "a", "encoding": "u8", "value": 3},
        {"parameter_id": 4, "parameter_name": "d", "encoding": "i16", "value": -20},
    ],
    "housekeeping_reports": [{"report_id": 1, "interval": 1, "parameter_ids": [1, 4]}],
    "functions": [],
}


def test_monitor_decodes_trace():
    mon = Monitor({1: NodeDefinition.from_dict(NODE)})
    out = []
    for can_id, hexdata in (
        (0x281, "00001101"),
        (0x301, "000001071101"),
        (0x301, "000003190103ffec"),
        (0x180, "aabbcc11223344"),
        (0x281, "0100140102010403"),
        (0x281, "0101" + "04"),
        (0x180, "aa"),
    ):
        out.extend(mon.lines(0, can_id, bytes.fromhex(hexdata), 1.5))
    text = "\n".join(out)
    assert "REQ n1" in out[0] and "(17,1) ping" in out[1]
    assert "(1,7) completed of (17,1)" in text
    assert "report 1 {1: 3, 4: -20}" in text
    assert "ScetTime(coarse_time=287454020" in text
    assert "bad:" in out[-1]


def test_command_parser():
    p = argparse.ArgumentParser()
    command.add_parser(p.add_subparsers())
    a = p.parse_args(
        ["spacecan", "monitor", "--interface", "virtual", "--channel-a", "x", "--duration", "0.1"]
    )
    assert (a.func, a.channel_a, a.channel_b) == (command.monitor, "x", "can1")
    a = p.parse_args(["spacecan", "responder", "--node-id", "3"])
    assert a.func is command.responder and a.node_id == 3


def test_monitor_command_runs_briefly(capsys):
    p = argparse.ArgumentParser()
    command.add_parser(p.add_subparsers())
    args = p.parse_args(
        [
            "spacecan",
            "monitor",
            "--channel-a",
            "mon_a",
            "--channel-b",
            "mon_b",
            "--duration",
            "0.2",
        ]
    )
    assert args.func(args) == 0


def test_demo_shows_failover():
    lines = []
    assert demo.run(out=lines.append) == 0
    text = "\n".join(lines)
    assert "(17,1) ping node 5: completed" in text
    assert "board_temp      = 21.5" in text
    assert "controller switched A -> B" in text
    assert "responder node 5 switched A -> B" in text
    assert "demo done" in text
