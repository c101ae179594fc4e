"""Decode SpaceCAN traffic for people: a line per frame, one more per completed service packet."""

from obsw.spacecan import packets as pk
from obsw.spacecan.fragment import Reassembler
from obsw.spacecan.ids import (
    FUNCTION_MASK,
    ID_REP,
    ID_REQ,
    ID_SCET,
    ID_UTC,
    NODE_MASK,
    bus_name,
    describe,
)
from obsw.spacecan.timeframes import ScetTime, UtcTime

_SERVICE_NAMES = {
    (1, 1): "accepted",
    (1, 2): "rejected",
    (1, 7): "completed",
    (1, 8): "failed",
    (3, 5): "enable HK",
    (3, 6): "disable HK",
    (3, 25): "HK report",
    (3, 27): "one-shot HK",
    (8, 1): "perform function",
    (17, 1): "ping",
    (17, 2): "ping report",
    (20, 1): "request parameters",
    (20, 2): "parameter report",
    (20, 3): "set parameters",
}


class Monitor:
    """Turns frames into text; with node definitions ({node_id: NodeDefinition}) values too."""

    def __init__(self, nodes=None, packets=True):
        self.nodes = nodes or {}
        self.packets = packets
        self.reassembler = Reassembler(timeout=1.0)

    def lines(self, bus, can_id, data, now):
        data = bytes(data)
        out = [
            "%10.3f %s %03x [%d] %-16s %s"
            % (now, bus_name(bus), can_id, len(data), data.hex(), describe(can_id))
        ]
        try:
            if can_id == ID_SCET:
                out[0] += " %r" % (ScetTime.unpack(data),)
            elif can_id == ID_UTC:
                out[0] += " %r" % (UtcTime.unpack(data),)
        except ValueError as e:
            out[0] += " (bad: %s)" % e
        f = can_id & FUNCTION_MASK
        if self.packets and f in (ID_REQ, ID_REP):
            packet = self.reassembler.push(can_id | (bus << 11), data, now)
            if packet is not None and len(packet) >= 2:
                out.append("%10s   %s" % ("", self._packet(can_id & NODE_MASK, packet)))
        return out

    def _packet(self, node, packet):
        s, t, data = packet[0], packet[1], packet[2:]
        text = "(%d,%d) %s" % (s, t, _SERVICE_NAMES.get((s, t), "?"))
        nodedef = self.nodes.get(node)
        try:
            if s == 1 and len(data) >= 2:
                text += " of (%d,%d)" % (data[0], data[1])
            elif (s, t) == (20, 2) and nodedef is not None:
                text += " %r" % dict(pk.unpack_values(nodedef, data))
            elif (s, t) == (3, 25) and nodedef is not None:
                rid, values = pk.unpack_hk(nodedef, data)
                text += " report %d %r" % (rid, dict(values))
            elif (s, t) in ((20, 1), (3, 5), (3, 6), (3, 27)):
                text += " ids %r" % pk.unpack_ids(data)
            elif data:
                text += " data %s" % data.hex()
        except ValueError as e:
            text += " (cannot decode: %s)" % e
        return text
