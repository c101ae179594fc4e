"""SpaceCAN CAN identifiers (11-bit, CANopen COB-ID style), bus numbers and node id checks."""

from obsw.compat import const

FULL_MASK = const(0x7FF)
FUNCTION_MASK = const(0x780)
NODE_MASK = const(0x07F)

ID_SYNC = const(0x080)
ID_SCET = const(0x180)
ID_UTC = const(0x200)
ID_REQ = const(0x280)  # controller -> node: 0x280 + node id
ID_REP = const(0x300)  # node -> controller: 0x300 + node id
ID_MESSAGE = const(0x380)  # allocated, unused on the wire
ID_HEARTBEAT = const(0x700)  # exactly; no node id added

CONTROLLER_NODE_ID = const(0)
MIN_NODE_ID = const(1)
MAX_NODE_ID = const(127)

BUS_A = const(0)  # nominal
BUS_B = const(1)  # redundant
BUS_NAMES = ("A", "B")


class NodeIdError(ValueError):
    """A responder node id outside 1..127."""

    def __init__(self, node_id):
        super().__init__("node id must be 1..127, got %r" % (node_id,))
        self.node_id = node_id


def check_node_id(node_id):
    """Return node_id if it is a valid responder id (1..127), else raise NodeIdError."""
    if not isinstance(node_id, int) or isinstance(node_id, bool):
        raise NodeIdError(node_id)
    if node_id < MIN_NODE_ID or node_id > MAX_NODE_ID:
        raise NodeIdError(node_id)
    return node_id


def req_id(node_id):
    """CAN id of a request (telecommand) to node_id."""
    return ID_REQ + node_id


def rep_id(node_id):
    """CAN id of a reply (telemetry) from node_id."""
    return ID_REP + node_id


def function_of(can_id):
    return can_id & FUNCTION_MASK


def node_of(can_id):
    return can_id & NODE_MASK


def other_bus(bus):
    return BUS_B if bus == BUS_A else BUS_A


def bus_name(bus):
    return BUS_NAMES[bus] if bus in (0, 1) else str(bus)


def describe(can_id):
    """Short name of what a CAN id carries, e.g. 'REQ n1', 'HEARTBEAT'."""
    if can_id == ID_HEARTBEAT:
        return "HEARTBEAT"
    if can_id == ID_SYNC:
        return "SYNC"
    if can_id == ID_SCET:
        return "SCET"
    if can_id == ID_UTC:
        return "UTC"
    f = can_id & FUNCTION_MASK
    n = can_id & NODE_MASK
    if f == ID_REQ:
        return "REQ n%d" % n
    if f == ID_REP:
        return "REP n%d" % n
    if can_id == ID_MESSAGE:
        return "MESSAGE"
    return "0x%03x" % can_id
