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
"""

from obsw.compat import const
from obsw.il.errors import ComponentError
from obsw.il.interface import LOW, Event, Interface, Operation
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
        Event("device_timeout", 16, LOW, fields=("device",)),
    ],
    description="raw commands to equipment and their replies (PUS service 2)",
)


def _frames(data):
    data = bytes(data)
    if not data:
        return [b""]
    return [data[i : i + 8] for i in range(0, len(data), 8)]


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
        self._requests[id(req)] = [job, node, []]
        req.on_done = self._done

    def _done(self, req):
        entry = self._requests.pop(id(req), None)
        if entry is None:
            return
        job = entry[0]
        if req.status == COMPLETED:
            job.succeed(entry[2])
        else:
            job.fail(ComponentError(req.status.upper(), req.error or req.status))

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
