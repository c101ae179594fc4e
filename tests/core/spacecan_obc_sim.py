"""A simulated OBC for SpaceCAN component tests: an IL node on the simulated network's clock,
the master on the bus, a responder node 5 (CpduN) and equipment components on request."""

from obsw.il.node import Node
from obsw.spacecan.controller import Controller, FailoverPolicy
from obsw.spacecan.equipment import Equipment
from obsw.spacecan.ids import ID_HEARTBEAT
from obsw.spacecan.master import MASTER, SpaceCanMaster
from obsw.spacecan.nodedef import NodeDefinition
from obsw.spacecan.responder import Responder
from obsw.spacecan.sim import NetworkClock, SimNetwork

CPDU = {
    "parameters": [
        {"parameter_id": 1, "parameter_name": "state_bits", "encoding": "u16", "value": 0},
        {"parameter_id": 2, "parameter_name": "board_temp", "encoding": "f32", "value": 24.5},
        {"parameter_id": 3, "parameter_name": "supply_mv", "encoding": "i16", "value": 5020},
    ],
    "housekeeping_reports": [
        {"report_id": 1, "interval": 1.0, "enabled": False, "parameter_ids": [1, 2]},
        {"report_id": 2, "interval": 2.0, "enabled": False, "parameter_ids": [3]},
    ],
    "functions": [
        {
            "function_id": 1,
            "function_name": "set_state_bits",
            "arguments": [{"argument_id": 1, "argument_name": "state_bits", "encoding": "u16"}],
        },
        {
            "function_id": 2,
            "function_name": "pulse",
            "arguments": [
                {"argument_id": 1, "argument_name": "line", "encoding": "u8"},
                {"argument_id": 2, "argument_name": "ms", "encoding": "u16"},
            ],
        },
        {"function_id": 3, "function_name": "self_test"},  # the simulated node fails it
    ],
}
NODE = 5
WAIT = 30.0  # simulated seconds: bounds every wait in the tests


def definition(node_id=NODE):
    return NodeDefinition.from_dict(CPDU, node_id)


class Obc:
    """Network, clock, IL node, controller, master and (optionally) responder node 5."""

    def __init__(self, responder=True, policy=None, node_name="obc", **controller_kw):
        self.net = SimNetwork(trace=True)
        self.clock = NetworkClock(self.net)
        self.node = self.clock.watch(Node(node_name, clock=self.clock))
        kw = {"heartbeat_period": 0.5, "timeout": 0.2, "retries": 2}
        kw.update(controller_kw)
        self.ctrl = Controller(policy=policy, **kw)
        self.ctrl.add_node(NODE, definition())
        self.master = SpaceCanMaster(self.ctrl)
        self.provider = self.node.provide(MASTER, self.master)
        self.net.attach(self.master)
        self.calls = []
        self.resp = None
        if responder:
            self.resp = Responder(NODE, definition(), heartbeat_period=0.5)
            self.resp.on_function = self._on_function
            self.net.attach(self.resp)
        self.proxy = self.node.proxy(MASTER, timeout=WAIT)

    def _on_function(self, fid, args):
        self.calls.append((fid, args))
        if fid == 1:
            self.resp.set_value("state_bits", args[1])
        return fid != 3

    def equipment(self, name="CpduN", node_id=NODE, node=None):
        """Provide an equipment component (on ``node``, default the OBC's); its proxy."""
        node = node if node is not None else self.node
        if node_id not in self.ctrl.nodes:
            self.ctrl.add_node(node_id, definition(node_id))
        eq = Equipment(name, node_id, definition(node_id), timeout=WAIT)
        eq.provide(node)
        return eq, node.proxy(eq.interface, timeout=WAIT)

    def run(self, seconds):
        """Let simulated time pass, IL providers and callbacks included."""
        end = self.net.now + seconds
        while self.net.now < end:
            self.clock.sleep(end - self.net.now)
        self.node.poll()

    def requests_to(self, node_id):
        """Request frames sent to node_id so far: [(bus, data)]."""
        return [(t[1], t[3]) for t in self.net.trace if t[2] == 0x280 + node_id]

    def bus_frames(self):
        return [t for t in self.net.trace if t[2] != ID_HEARTBEAT]


def manual():
    return FailoverPolicy(mode="manual")


def drain(sub):
    out = []
    while True:
        pub = sub.receive()
        if not pub:
            return out
        out.append(pub)
