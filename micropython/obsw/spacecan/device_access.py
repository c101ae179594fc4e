"""Low-level access to SpaceCAN equipment for PUS service 2, as an interaction-layer component.

``DEVICE_ACCESS`` is the interface, declared once. ``SpaceCanDeviceAccess`` implements it in
front of a ``Controller``: it is the bus node a driver moves frames for (``receive``,
``poll``, ``next_deadline``, ``take_frames``, ``take_events``, ``tx_error``), passes every
frame of packet-mode nodes to the controller and keeps the replies of raw-mode nodes.

- ``command(device, data)``: raw data mode, the data in REQ frames of up to 8 octets;
  succeeds once queued for the bus.
- ``acquire(device, data)``: the same, then the device's next REP frame is the result;
  fails with ``TIMEOUT`` when none comes within ``timeout`` seconds.
- ``request(device, service, subtype, data)``: a SpaceCAN service request in packet mode;
  the result is the report packets the node sent for it, as ``[service, subtype, data]``
  lists, once the node has completed it; ``REJECTED``, ``FAILED``, ``TIMEOUT`` otherwise.

A device is a SpaceCAN node id, or an id mapped to one by ``devices``. Errors reach the
caller as ``ComponentError`` with the reason as its code. Sans-I/O; the time comes in with
the frames and polls.

The standard's device-level commands of PUS service 2 map onto packet-mode nodes through
their node definitions (the controller's ``nodes``), with addresses made of the node id:

- ``on_off(address)``, an on/off device command: ``address`` is node << 8 | on << 7 | line;
  the node's ``set_bits`` (on) or ``clear_bits`` (off) function with the line's bit as mask;
- ``load_register(address, value)`` and ``dump_register(address)``: a register is a node
  parameter, ``address`` node << 16 | parameter id, ``value`` the parameter's encoded octets
  as an unsigned integer (at most 4 octets); loaded with a parameter set (20,3), dumped with a
  parameter request (20,1);
- ``cpdu(line, duration)``, a CPDU command: ``line`` is node << 8 | output line, pulsed off
  for ``duration`` ms by the node's ``power_cycle`` function;
- ``check(kind, addresses)``: the first of ``addresses`` that names no such device, register
  or line (``kind``: "on_off", "register", "cpdu"), or None.
"""

from obsw.compat import const
from obsw.il.errors import ComponentError
from obsw.il.interface import LOW, Event, Interface, Operation
from obsw.spacecan import encoding as enc
from obsw.spacecan.fragment import Reassembler
from obsw.spacecan.ids import FUNCTION_MASK, ID_REP, NODE_MASK
from obsw.spacecan.requests import COMPLETED

DEVICE_ACCESS_NAME = "DeviceAccess"
DEVICE_ACCESS_ID = const(0x6A)

UNKNOWN_DEVICE = "UNKNOWN_DEVICE"
BAD_REQUEST = "BAD_REQUEST"
TIMEOUT = "TIMEOUT"
_VERIFICATION = const(1)

DEVICE_ACCESS = Interface(
    DEVICE_ACCESS_NAME,
    DEVICE_ACCESS_ID,
    [
        Operation("command", 1, ("device", "data"), asynchronous=True),
        Operation("acquire", 2, ("device", "data"), asynchronous=True),
        Operation("request", 3, ("device", "service", "subtype", "data"), asynchronous=True),
        Operation("on_off", 4, ("address",), asynchronous=True),
        Operation("load_register", 5, ("address", "value"), asynchronous=True),
        Operation("dump_register", 6, ("address",), asynchronous=True),
        Operation("cpdu", 7, ("line", "duration"), asynchronous=True),
        Operation("check", 8, ("kind", "addresses")),
        Event("device_timeout", 16, LOW, fields=("device",)),
    ],
    description="raw commands to equipment and their replies (PUS service 2)",
)


REGISTER_OCTETS = 4  # a register value is an unsigned integer of at most 4 octets
_ON = 0x80


def _frames(data):
    data = bytes(data)
    if not data:
        return [b""]
    return [data[i : i + 8] for i in range(0, len(data), 8)]


def _no_result(req):
    return None


_CHECKS = {
    "on_off": lambda a: "set_bits" if a & _ON else "clear_bits",
    "cpdu": lambda a: "power_cycle",
}


class SpaceCanDeviceAccess:
    """The provider's implementation (see the module text); ``raw_nodes`` are the nodes
    that work in raw data mode."""

    def __init__(self, controller, raw_nodes=(), devices=None, timeout=1.0):
        self.controller = controller
        self.raw_nodes = set(raw_nodes)
        self.devices = dict(devices or {})
        self.timeout = timeout
        self.now = 0.0
        self.provider = None
        self._waiting = {}  # node -> [job, deadline] of a raw acquisition
        self._requests = {}  # id(request) -> [job, node, packets]
        self._reassembler = Reassembler()
        self.raw_replies = 0
        self.unexpected = 0

    def il_bind(self, provider):
        self.provider = provider

    def _node(self, device):
        node = self.devices.get(device, device)
        if not isinstance(node, int) or not 1 <= node <= 127:
            raise ComponentError(UNKNOWN_DEVICE, "no device %r" % (device,))
        return node

    # -------------------------------------------------------------------------- operations

    def _raw(self, device, data):
        node = self._node(device)
        if node not in self.raw_nodes:
            raise ComponentError(BAD_REQUEST, "device %r is not in raw data mode" % (device,))
        for frame in _frames(data):
            self.controller.send_raw(node, frame)
        return node

    def command(self, job, device, data):
        self._raw(device, data)
        job.succeed({"device": device, "octets": len(data)})

    def acquire(self, job, device, data):
        node = self._node(device)
        if node in self._waiting:
            raise ComponentError(BAD_REQUEST, "device %r has an acquisition running" % (device,))
        self._raw(device, data)
        self._waiting[node] = [job, self.now + self.timeout, device]

    def request(self, job, device, service, subtype, data):
        node = self._node(device)
        try:
            req = self.controller.request(node, service, subtype, bytes(data), self.now)
        except ValueError as e:
            raise ComponentError(BAD_REQUEST, str(e)) from None
        self._track(job, node, req)

    def _track(self, job, node, req, result=None):
        """Finish ``job`` when the node completes ``req``: with the report packets it sent,
        or ``result(req)``."""
        self._requests[id(req)] = [job, node, [], result]
        req.on_done = self._done

    def _done(self, req):
        entry = self._requests.pop(id(req), None)
        if entry is None:
            return
        job = entry[0]
        if req.status == COMPLETED:
            try:
                job.succeed(entry[2] if entry[3] is None else entry[3](req))
            except (ValueError, KeyError, TypeError) as e:
                job.fail(ComponentError(BAD_REQUEST, str(e)))
        else:
            job.fail(ComponentError(req.status.upper(), req.error or req.status))

    # -------------------------------------------------------------------------- PUS devices

    def _definition(self, node):
        nodedef = self.controller.nodes.get(node) if 1 <= node <= 127 else None
        if nodedef is None:
            raise ComponentError(UNKNOWN_DEVICE, "no node definition for node %d" % node)
        return nodedef

    def _line_function(self, address, name):
        """(node, function, line) of an on/off address or CPDU line and its function."""
        node = address >> 8
        f = self._definition(node).function_by_name(name)
        if f is None:
            raise ComponentError(UNKNOWN_DEVICE, "node %d has no %s function" % (node, name))
        return node, f, address & 0xFF

    def _register(self, address):
        """(node, parameter) of a register address."""
        node, pid = address >> 16, address & 0xFFFF
        p = self._definition(node).parameters.get(pid)
        if p is None or p.encoding == "bool" or enc.size(p.encoding) > REGISTER_OCTETS:
            raise ComponentError(UNKNOWN_DEVICE, "no register 0x%08X" % address)
        return node, p

    def _function_call(self, job, node, f, values):
        args = {}
        for a, v in zip(sorted(f.arguments), values):
            args[a] = v
        try:
            req = self.controller.call_function(node, f.function_id, self.now, args)
        except ValueError as e:
            raise ComponentError(BAD_REQUEST, str(e)) from None
        self._track(job, node, req, _no_result)

    def on_off(self, job, address):
        name = "set_bits" if address & _ON else "clear_bits"
        node, f, line = self._line_function(address, name)
        self._function_call(job, node, f, (1 << (line & 0x7F),))

    def cpdu(self, job, line, duration):
        node, f, output = self._line_function(line, "power_cycle")
        self._function_call(job, node, f, (output, duration))

    def load_register(self, job, address, value):
        node, p = self._register(address)
        width = enc.size(p.encoding)
        if not 0 <= value < 1 << (8 * width):
            raise ComponentError(BAD_REQUEST, "register value 0x%X: more than %d octets"
                                 % (value, width))  # fmt: skip
        try:
            v = enc.decode(p.encoding, value.to_bytes(width, "big"))[0]
            req = self.controller.set_parameters(node, {p.parameter_id: v}, self.now)
        except ValueError as e:
            raise ComponentError(BAD_REQUEST, str(e)) from None
        self._track(job, node, req, _no_result)

    def dump_register(self, job, address):
        node, p = self._register(address)
        try:
            req = self.controller.request_parameters(node, [p.parameter_id], self.now)
        except ValueError as e:
            raise ComponentError(BAD_REQUEST, str(e)) from None

        def value(r):
            return int.from_bytes(enc.encode(p.encoding, r.result[p.parameter_id]), "big")

        self._track(job, node, req, value)

    def check(self, kind, addresses):
        for a in addresses:
            try:
                if kind == "register":
                    self._register(a)
                else:
                    self._line_function(a, _CHECKS[kind](a))
            except (ComponentError, KeyError):
                return a
        return None

    # -------------------------------------------------------------------------- bus node

    def receive(self, bus, can_id, data, now):
        self.now = now
        node = can_id & NODE_MASK
        if can_id & FUNCTION_MASK == ID_REP and node in self.raw_nodes:
            w = self._waiting.pop(node, None)
            if w is None:
                self.unexpected += 1
                return
            self.raw_replies += 1
            w[0].succeed(bytes(data))
            return
        self.observe(bus, can_id, data, now)
        self.controller.receive(bus, can_id, data, now)

    def observe(self, bus, can_id, data, now):
        """See a frame on its way to the controller (when another bus node, e.g. the
        SpaceCAN master, gets the frames): keep the reports of this component's requests."""
        self.now = now
        if self._requests and can_id & FUNCTION_MASK == ID_REP:
            self._collect(can_id & NODE_MASK, bus, can_id, data, now)

    def _collect(self, node, bus, can_id, data, now):
        """Keep the report packets (not the verification ones) a node sends for a request."""
        for entry in self._requests.values():
            if entry[1] == node:
                packet = self._reassembler.push(can_id | (bus << 11), data, now)
                if packet is not None and len(packet) >= 2 and packet[0] != _VERIFICATION:
                    entry[2].append([packet[0], packet[1], bytes(packet[2:])])
                return

    def poll(self, now):
        self.now = now
        self.controller.poll(now)
        for node in list(self._waiting):
            job, deadline, device = self._waiting[node]
            if now >= deadline:
                del self._waiting[node]
                job.fail(ComponentError(TIMEOUT, "no reply from device %r" % (device,)))
                if self.provider is not None:
                    self.provider.emit("device_timeout", {"device": device})

    step = poll

    def next_deadline(self):
        best = self.controller.next_deadline()
        for w in self._waiting.values():
            if best is None or w[1] < best:
                best = w[1]
        return best

    def take_frames(self):
        return self.controller.take_frames()

    def take_events(self):
        return self.controller.take_events()

    def tx_error(self, bus, now):
        self.controller.tx_error(bus, now)
