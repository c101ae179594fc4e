"""The CPDU node on SpaceCAN: state bits and module status as parameters, line commands as
service 8 functions, a housekeeping report. The OBC loads the same definition
(the mission folders' `nodes/cpdu.json`, kept equal to ``DEFINITION`` by a test)."""

from obsw.compat import const
from obsw.spacecan.nodedef import NodeDefinition
from obsw.spacecan.responder import Responder

NODE_NOMINAL = const(10)  # CpduN
NODE_REDUNDANT = const(11)  # CpduR

F_SET_STATE_BITS = const(1)
F_SET_BITS = const(2)
F_CLEAR_BITS = const(3)
F_POWER_CYCLE = const(4)
F_SELECT_OBC = const(5)
F_STORE_CONTEXT = const(6)

P_STATE_BITS = const(1)

_P = (
    (1, "state_bits", "u16"),
    (2, "role", "u8"),
    (3, "boot_count", "u16"),
    (4, "reset_cause", "u8"),
    (5, "hpc_count", "u16"),
    (6, "last_hpc", "u8"),
    (7, "health", "u8"),
    (8, "utc_day", "u16"),
    (9, "utc_ms", "u32"),
    (10, "temperature", "f32"),
    (11, "cpdu_writes", "u32"),
    (12, "battles_lost", "u16"),
    (13, "sgm_devices", "u8"),
    (14, "context", "u32"),
    (15, "in_charge", "bool"),
)
_F = (
    (F_SET_STATE_BITS, "set_state_bits", ((1, "state", "u16"),)),
    (F_SET_BITS, "set_bits", ((1, "mask", "u16"),)),
    (F_CLEAR_BITS, "clear_bits", ((1, "mask", "u16"),)),
    (F_POWER_CYCLE, "power_cycle", ((1, "line", "u8"), (2, "off_ms", "u16"))),
    (F_SELECT_OBC, "select_obc", ((1, "which", "u8"),)),
    (F_STORE_CONTEXT, "store_context", ((1, "value", "u32"),)),
)


def definition_dict():
    """The node definition as spacecan's services JSON."""
    params = []
    for pid, name, encoding in _P:
        params.append(
            {
                "parameter_id": pid,
                "parameter_name": name,
                "encoding": encoding,
                "value": False if encoding == "bool" else 0,
            }
        )
    funcs = []
    for fid, name, args in _F:
        funcs.append(
            {
                "function_id": fid,
                "function_name": name,
                "arguments": [
                    {"argument_id": a, "argument_name": n, "encoding": e} for a, n, e in args
                ],
            }
        )
    return {
        "parameters": params,
        "housekeeping_reports": [
            {"report_id": 1, "interval": 1.0, "enabled": True, "parameter_ids": [1, 7, 3, 5, 8, 9]}
        ],
        "functions": funcs,
    }


def definition(node_id=None):
    return NodeDefinition.from_dict(definition_dict(), node_id)


class CpduNode:
    """A SpaceCAN responder serving the CPDU node; ``app`` carries out the functions.

    ``app`` needs ``lines(mask, value)`` -> bool, ``power_cycle(line, off_ms)`` -> bool,
    ``select_obc(which)`` -> bool and ``store_context(value)`` -> bool.
    """

    def __init__(self, app, node_id=NODE_NOMINAL, heartbeat_period=0.5, **kw):
        self.app = app
        self.responder = Responder(
            node_id, definition(node_id), heartbeat_period=heartbeat_period, **kw
        )
        self.responder.on_function = self._function
        self.calls = 0

    def _function(self, fid, args):
        self.calls += 1
        app = self.app
        if fid == F_SET_STATE_BITS:
            return app.lines(0xFFF, args.get(1, 0))
        if fid == F_SET_BITS:
            m = args.get(1, 0)
            return app.lines(m, m)
        if fid == F_CLEAR_BITS:
            return app.lines(args.get(1, 0), 0)
        if fid == F_POWER_CYCLE:
            return app.power_cycle(args.get(1, 0), args.get(2, 1000))
        if fid == F_SELECT_OBC:
            return app.select_obc(args.get(1, 0))
        if fid == F_STORE_CONTEXT:
            return app.store_context(args.get(1, 0))
        return False

    def update(self, values):
        """Set parameters from {name: value} (unknown names are ignored)."""
        nd = self.responder.nodedef
        for k in values:
            p = nd.parameter(k)
            if p is not None:
                p.value = values[k]
