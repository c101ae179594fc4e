"""ST[02] device access: raw commands to on-board equipment and the data they return.

The provider talks to the equipment through the ``DeviceAccess`` interaction-layer
component (``obsw.spacecan.device_access``, SpaceCAN in front of the controller):

- TC[2,7] distribute physical device commands: (device ID, octets) items, sent raw;
- TC[2,8] acquire data from physical devices: the same, each answered by a device's reply
  frame, all in one TM[2,9] physical device data report;
- TC[2,10] distribute logical device commands: (device ID, service, subtype, octets) items,
  SpaceCAN service requests the nodes verify;
- TC[2,11] acquire data from logical devices: the same, the nodes' report packets in one
  TM[2,12] logical device data report.

and the device-level commands, through the same component (whose text says how the addresses
name SpaceCAN nodes, their lines and parameters):

- TC[2,1] distribute on/off device commands: on/off device addresses;
- TC[2,2] distribute register load commands: (register address, register value) items;
- TC[2,4] distribute CPDU commands: (CPDU output line, pulse duration in ms) items;
- TC[2,5] dump register data: register addresses, answered by one TM[2,6] register data dump
  report of (register address, register value) items.

The addresses of a device-level request are checked as a whole first: one that names no
device fails the start of execution with ``FAILURE_UNKNOWN_ID`` and the address in the
failure data, and nothing is sent. Items run in order; the first that fails fails the
request's completion with its device ID or address in the failure data (``FAILURE_TIMEOUT``
when the device did not answer, ``FAILURE_UNAVAILABLE`` when the component is not reachable,
``FAILURE_COMPONENT`` otherwise). ``devices`` (device ID -> anything) limits the IDs accepted
by the physical and logical requests (others fail the start).
"""

from obsw.il.errors import CallTimeoutError, ComponentError, InteractionError, UnavailableError
from obsw.pus.fields import field
from obsw.pus.messages import (
    FAILURE_COMPONENT,
    FAILURE_TIMEOUT,
    FAILURE_UNAVAILABLE,
    FAILURE_UNKNOWN_ID,
    SERVICE_DEVICE_ACCESS,
    TC_DEVICE_CPDU,
    TC_DEVICE_LOGICAL_ACQUIRE,
    TC_DEVICE_LOGICAL_COMMAND,
    TC_DEVICE_ON_OFF,
    TC_DEVICE_PHYSICAL_ACQUIRE,
    TC_DEVICE_PHYSICAL_COMMAND,
    TC_DEVICE_REGISTER_DUMP,
    TC_DEVICE_REGISTER_LOAD,
    TM_DEVICE_LOGICAL_DATA_REPORT,
    TM_DEVICE_PHYSICAL_DATA_REPORT,
    TM_DEVICE_REGISTER_DUMP_REPORT,
)
from obsw.pus.services.base import U8, U16, U32, Service, ServiceUser
from obsw.pus.services.s01_verification import PusFailure
from obsw.pus.structure import Repeated, Structure

DEVICE_ID = U16
OCTETS = field(7, 0)
PHYSICAL = Structure([("items", Repeated(U8, [("device", DEVICE_ID), ("data", OCTETS)]))])
LOGICAL = Structure(
    [
        (
            "items",
            Repeated(
                U8,
                [("device", DEVICE_ID), ("service", U8), ("subtype", U8), ("data", OCTETS)],
            ),
        )
    ]
)
ON_OFF_ADDRESS = U16
REGISTER_ADDRESS = U32
REGISTER_VALUE = U32
CPDU_LINE = U16
CPDU_DURATION = U16  # ms
ON_OFF = Structure([("addresses", Repeated(U8, ON_OFF_ADDRESS))])
REGISTERS = Structure(
    [("items", Repeated(U8, [("address", REGISTER_ADDRESS), ("value", REGISTER_VALUE)]))]
)
REGISTER_DUMP = Structure([("addresses", Repeated(U8, REGISTER_ADDRESS))])
CPDU = Structure([("items", Repeated(U8, [("line", CPDU_LINE), ("duration", CPDU_DURATION)]))])
TIMEOUT_REASON = "TIMEOUT"


def _failure(error, device, ident=DEVICE_ID):
    data = ident.pack(device) if device is not None else b""
    if isinstance(error, CallTimeoutError):
        return PusFailure(FAILURE_TIMEOUT, error.message, data)
    if isinstance(error, ComponentError) and error.code == TIMEOUT_REASON:
        return PusFailure(FAILURE_TIMEOUT, error.message, data)
    if isinstance(error, UnavailableError):
        return PusFailure(FAILURE_UNAVAILABLE, error.message, data)
    return PusFailure(FAILURE_COMPONENT, str(error), data)


class DeviceAccess(Service):
    """The service 2 provider, calling ``component`` on the interaction-layer ``node``."""

    SERVICE = SERVICE_DEVICE_ACCESS
    REPORTS = (
        TM_DEVICE_REGISTER_DUMP_REPORT,
        TM_DEVICE_PHYSICAL_DATA_REPORT,
        TM_DEVICE_LOGICAL_DATA_REPORT,
    )
    HANDLERS = (
        (TC_DEVICE_ON_OFF, "on_off"),
        (TC_DEVICE_REGISTER_LOAD, "load_registers"),
        (TC_DEVICE_CPDU, "cpdu"),
        (TC_DEVICE_REGISTER_DUMP, "dump_registers"),
        (TC_DEVICE_PHYSICAL_COMMAND, "physical_command"),
        (TC_DEVICE_PHYSICAL_ACQUIRE, "physical_acquire"),
        (TC_DEVICE_LOGICAL_COMMAND, "logical_command"),
        (TC_DEVICE_LOGICAL_ACQUIRE, "logical_acquire"),
    )

    def __init__(self, node, devices=None, timeout=5.0, component="DeviceAccess"):
        super().__init__()
        self.node = node
        self.devices = devices
        self.timeout = timeout
        self.component = component

    def _decode(self, req, layout):
        items = req.decode(layout)["items"]
        if self.devices is not None:
            for i in items:
                if i["device"] not in self.devices:
                    raise PusFailure(
                        FAILURE_UNKNOWN_ID,
                        "no device %d" % i["device"],
                        DEVICE_ID.pack(i["device"]),
                    )
        req.start()
        return items

    async def _call(self, operation, args, device, ident=DEVICE_ID):
        try:
            pending = self.node.start(self.component + "." + operation, args, timeout=self.timeout)
            return await pending.wait(self.timeout)
        except (InteractionError, ValueError) as e:
            raise _failure(e, device, ident) from None

    async def _check(self, req, kind, addresses, ident):
        """Fail the start if one of ``addresses`` names no device of ``kind``."""
        bad = await self._call("check", (kind, list(addresses)), None, ident)
        if bad is not None:
            raise PusFailure(
                FAILURE_UNKNOWN_ID, "no %s address 0x%X" % (kind, bad), ident.pack(bad)
            )
        req.start()

    async def on_off(self, req):
        addresses = req.decode(ON_OFF)["addresses"]
        await self._check(req, "on_off", addresses, ON_OFF_ADDRESS)
        for a in addresses:
            await self._call("on_off", (a,), a, ON_OFF_ADDRESS)

    async def load_registers(self, req):
        items = req.decode(REGISTERS)["items"]
        await self._check(req, "register", [i["address"] for i in items], REGISTER_ADDRESS)
        for i in items:
            a = i["address"]
            await self._call("load_register", (a, i["value"]), a, REGISTER_ADDRESS)

    async def cpdu(self, req):
        items = req.decode(CPDU)["items"]
        await self._check(req, "cpdu", [i["line"] for i in items], CPDU_LINE)
        for i in items:
            await self._call("cpdu", (i["line"], i["duration"]), i["line"], CPDU_LINE)

    async def dump_registers(self, req):
        addresses = req.decode(REGISTER_DUMP)["addresses"]
        await self._check(req, "register", addresses, REGISTER_ADDRESS)
        out = []
        for a in addresses:
            value = await self._call("dump_register", (a,), a, REGISTER_ADDRESS)
            out.append({"address": a, "value": value})
        req.report(TM_DEVICE_REGISTER_DUMP_REPORT, REGISTERS.pack({"items": out}))

    async def physical_command(self, req):
        for i in self._decode(req, PHYSICAL):
            await self._call("command", (i["device"], i["data"]), i["device"])

    async def physical_acquire(self, req):
        out = []
        for i in self._decode(req, PHYSICAL):
            data = await self._call("acquire", (i["device"], i["data"]), i["device"])
            out.append({"device": i["device"], "data": bytes(data)})
        req.report(TM_DEVICE_PHYSICAL_DATA_REPORT, PHYSICAL.pack({"items": out}))

    async def _logical(self, req):
        out = []
        for i in self._decode(req, LOGICAL):
            args = (i["device"], i["service"], i["subtype"], i["data"])
            packets = await self._call("request", args, i["device"])
            for service, subtype, data in packets or ():
                out.append(
                    {"device": i["device"], "service": service, "subtype": subtype, "data": data}
                )
        return out

    async def logical_command(self, req):
        await self._logical(req)

    async def logical_acquire(self, req):
        out = await self._logical(req)
        req.report(TM_DEVICE_LOGICAL_DATA_REPORT, LOGICAL.pack({"items": out}))


class DeviceUser(ServiceUser):
    """The service 2 user."""

    SERVICE = SERVICE_DEVICE_ACCESS
    DECODERS = (
        (TM_DEVICE_REGISTER_DUMP_REPORT, "decode_registers"),
        (TM_DEVICE_PHYSICAL_DATA_REPORT, "decode_physical"),
        (TM_DEVICE_LOGICAL_DATA_REPORT, "decode_logical"),
    )

    def on_off(self, apid, addresses):
        """On/off device commands: ``addresses`` (node << 8 | on << 7 | line on SpaceCAN)."""
        return self.request(apid, TC_DEVICE_ON_OFF, ON_OFF.pack({"addresses": list(addresses)}))

    def load_registers(self, apid, values):
        """Register load commands: ``values`` maps register address -> register value."""
        items = [{"address": a, "value": v} for a, v in values.items()]
        return self.request(apid, TC_DEVICE_REGISTER_LOAD, REGISTERS.pack({"items": items}))

    def cpdu(self, apid, items):
        """CPDU commands: ``items`` are (output line, pulse duration in ms) pairs."""
        data = CPDU.pack({"items": [{"line": ln, "duration": d} for ln, d in items]})
        return self.request(apid, TC_DEVICE_CPDU, data)

    def dump_registers(self, apid, addresses):
        data = REGISTER_DUMP.pack({"addresses": list(addresses)})
        return self.request(apid, TC_DEVICE_REGISTER_DUMP, data, TM_DEVICE_REGISTER_DUMP_REPORT)

    def decode_registers(self, tm):
        """{"registers": [(address, value), ...]} in the order dumped."""
        items = REGISTERS.unpack(tm.data)["items"]
        return {"registers": [(i["address"], i["value"]) for i in items]}

    def _physical(self, items):
        return PHYSICAL.pack({"items": [{"device": d, "data": bytes(b)} for d, b in items]})

    def command(self, apid, items):
        """``items``: (device ID, octets) pairs, sent raw."""
        return self.request(apid, TC_DEVICE_PHYSICAL_COMMAND, self._physical(items))

    def acquire(self, apid, items):
        return self.request(
            apid,
            TC_DEVICE_PHYSICAL_ACQUIRE,
            self._physical(items),
            TM_DEVICE_PHYSICAL_DATA_REPORT,
        )

    def _logical(self, items):
        return LOGICAL.pack(
            {
                "items": [
                    {"device": d, "service": s, "subtype": t, "data": bytes(b)}
                    for d, s, t, b in items
                ]
            }
        )

    def logical_command(self, apid, items):
        """``items``: (device ID, service, subtype, octets), as SpaceCAN service requests."""
        return self.request(apid, TC_DEVICE_LOGICAL_COMMAND, self._logical(items))

    def logical_acquire(self, apid, items):
        return self.request(
            apid, TC_DEVICE_LOGICAL_ACQUIRE, self._logical(items), TM_DEVICE_LOGICAL_DATA_REPORT
        )

    def decode_physical(self, tm):
        return {"items": [(i["device"], i["data"]) for i in PHYSICAL.unpack(tm.data)["items"]]}

    def decode_logical(self, tm):
        items = LOGICAL.unpack(tm.data)["items"]
        return {"items": [(i["device"], i["service"], i["subtype"], i["data"]) for i in items]}
