"""The OBC's SpaceCAN master and equipment components: served in their own process over
python-can virtual channels (with simulated responders) and used from this process through
the interaction layer's socket transport. Readiness and outcomes are awaited with deadlines."""

import json
import os
import uuid

import can as can
import pytest
from obsw.il.errors import ComponentError  # noqa: E402
from obsw.il.node import Node  # noqa: E402
from obsw.spacecan.equipment import Equipment, equipment_interface  # noqa: E402
from obsw.spacecan.master import MASTER  # noqa: E402
from obsw.spacecan.nodedef import NodeDefinition  # noqa: E402
from obsw_host.il.processes import spawn, stop  # noqa: E402
from obsw_host.il.transport import SocketTransport  # noqa: E402
from obsw_host.spacecan.adapter import BusFaults  # noqa: E402
from obsw_host.spacecan.obc import (  # noqa: E402
    ObcSpaceCan,
    cpdu_node,
    parse_equipment,
    simulated_responder,
)

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="needs Unix processes")

CPDU = equipment_interface("CpduN", 5, NodeDefinition.from_dict(cpdu_node()))
WAIT = 20.0  # bound on every wait; none is expected to take near this long


def channels():
    tag = uuid.uuid4().hex[:8]
    return ("obcA" + tag, "obcB" + tag)


@pytest.fixture
def obc_process(tmp_path):
    directory = str(tmp_path)
    a, b = channels()
    proc = spawn(
        "obsw_host.spacecan.obc",
        directory,
        "--interface",
        "virtual",
        "--channel-a",
        a,
        "--channel-b",
        b,
        "--equipment",
        "CpduN:5",
        "--simulate",
        "--heartbeat-period",
        "0.1",
        "--timeout",
        "0.2",
        "--retries",
        "2",
    )
    node = Node("test-user")
    transport = SocketTransport(node, directory, listen=False)
    yield node, proc
    transport.close()
    assert stop(proc) == 0


def test_function_call_and_housekeeping_across_processes(obc_process):
    user, proc = obc_process
    cpdu = user.proxy(CPDU, timeout=WAIT)
    values = cpdu.subscribe("state_bits", length=32)
    reports = cpdu.subscribe("housekeeping", length=32)
    updates = []
    rec = cpdu.set_state_bits(0x0A5, on_status=lambda p, s, v: updates.append(v)).result(WAIT)
    assert rec["status"] == "completed"
    assert (rec["service"], rec["subtype"], rec["reports"]) == (8, 1, [1, 7])
    assert {"status": "sent", "bus": 0, "attempt": 1, "reports": []} in updates
    assert cpdu.request_parameters(["state_bits", "health"]).result(WAIT) == {
        "state_bits": 0x0A5,
        "health": 0,
    }
    assert cpdu.state_bits == 0x0A5
    pub = values.receive(timeout=WAIT)
    while pub and pub.value != 0x0A5:  # reports sent before the call carry the old value
        pub = values.receive(timeout=WAIT)
    assert pub.name == "CpduN.state_bits"
    hk = reports.receive(timeout=WAIT)
    assert hk.value["report_id"] == 1
    names = {p["parameter_id"]: p["parameter_name"] for p in cpdu_node()["parameters"]}
    report = cpdu_node()["housekeeping_reports"][0]
    assert set(hk.value["values"]) == {names[i] for i in report["parameter_ids"]}
    with pytest.raises(ComponentError) as e:
        cpdu.set_state_bits(70000).result(WAIT)  # u16: refused before anything is sent
    assert e.value.code == "BAD_REQUEST"


def test_master_operations_timeout_and_bus_switch_across_processes(obc_process):
    user, proc = obc_process
    master = user.proxy(MASTER, timeout=WAIT)
    cpdu = user.proxy(CPDU, timeout=WAIT)
    assert master.ping(5).result(WAIT)["result"] is True
    failovers = master.subscribe("bus_failover", length=8)
    assert master.switch_bus("B") == 1
    assert master.active_bus == 1
    pub = failovers.receive(timeout=WAIT)
    assert pub.value == {"old": "A", "new": "B", "reason": "commanded"}
    rec = cpdu.set_state_bits(0x00F).result(WAIT)
    assert (rec["status"], rec["bus"]) == ("completed", 1)
    status = master.bus_status
    assert [s["active"] for s in status] == [False, True]
    assert master.rx_frames > 0
    with pytest.raises(ComponentError) as e:
        master.ping(9).result(WAIT)  # no node 9 on the bus: a timeout, not a hang
    assert e.value.code == "TIMEOUT"
    assert e.value.data["node"] == 9


def test_bus_a_dies_mid_command_in_process():
    eq = parse_equipment("CpduN:5")
    faults = BusFaults()
    with ObcSpaceCan(
        [eq],
        channels=channels(),
        transport=False,
        faults=faults,
        heartbeat_period=0.1,
        timeout=0.15,
        retries=3,
    ) as obc:
        obc.simulate()
        cpdu = obc.node.proxy(eq.interface, timeout=WAIT)
        master = obc.node.proxy(MASTER, timeout=WAIT)
        failovers = master.subscribe("bus_failover", length=8)
        assert cpdu.ping().result(WAIT)["bus"] == 0
        faults.kill(0)
        rec = cpdu.set_state_bits(0x123).result(WAIT)
        assert (rec["status"], rec["bus"]) == ("completed", 1)
        assert rec["attempts"] >= 2
        assert master.active_bus == 1
        assert failovers.receive(timeout=WAIT).value["new"] == "B"
        assert cpdu.request_parameters("state_bits").result(WAIT) == {"state_bits": 0x123}
        assert obc.adapter.counters["loop_errors"] == 0


def test_equipment_spec_and_simulated_node(tmp_path):
    path = tmp_path / "node.json"
    path.write_text(json.dumps(cpdu_node()))
    eq = parse_equipment("Pdu:7:%s" % path)
    assert isinstance(eq, Equipment)
    assert (eq.name, eq.node_id, eq.interface.id) == ("Pdu", 7, 0x107)
    with pytest.raises(ValueError):
        parse_equipment("Pdu")
    resp = simulated_responder(7, cpdu_node())
    assert resp.on_function(1, {1: 42}) is True
    assert resp.get_value("state_bits") == 42


def test_cli_has_master_subcommand():
    from obsw_host.cli import build_parser

    args = build_parser().parse_args(
        ["spacecan", "master", "--equipment", "CpduN:5", "--simulate", "--duration", "1"]
    )
    assert (args.equipment, args.simulate, args.duration) == (["CpduN:5"], True, 1.0)


def test_demo_shows_the_equipment_component():
    import spacecan_demo as demo

    lines = []
    assert demo.run(out=lines.append) == 0
    text = "\n".join(lines)
    assert "proxy call CpduN.set_cpdu_line(line=1, on=True): completed" in text
    assert "sent -> accepted -> completed" in text
    assert "attribute CpduN.cpdu_lines = 0b0111, fed by housekeeping" in text
    assert "ComponentError BAD_REQUEST" in text
    assert "event SpaceCanMaster.bus_failover" in text
    assert "issued as A died: completed on bus B" in text
    assert "cpdu_lines now 0b1111" in text
