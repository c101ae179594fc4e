"""The SpaceCAN unit of an OBC process: the SpaceCAN master, the equipment components of the CAN
nodes and device access (service 2's path to the nodes), in a thread of its own."""

import threading
import time

from obsw_host.spacecan.obc import ObcSpaceCan


class SpaceCanUnit:
    """The SpaceCAN master, the equipment components and device access, in their own thread."""

    def __init__(self, topology, process, out=print):
        opts = topology.section("spacecan")
        self.out = out
        self.opts = opts
        interface = opts["interface"]
        channels = tuple(opts["channels"])
        buses = None
        if interface == "hub":  # the simulated reconfiguration module's CAN hub (UDP ports)
            from obsw_host.reconfig.canhub import HubBus

            buses = [HubBus(int(channels[0])), HubBus(int(channels[1]))]
        self.obc = ObcSpaceCan(
            topology.equipments(),
            interface=interface,
            channels=channels,
            buses=buses,
            directory=topology.config.il_directory,
            heartbeat_period=float(opts["heartbeat_period"]),
            timeout=float(opts["timeout"]),
            retries=int(opts["retries"]),
            device_access=True,
        )
        self._thread = None

    def start(self):
        self.obc.start()
        if self.opts.get("simulate"):
            self.obc.simulate()
        self.last_loop = time.monotonic()
        self._thread = threading.Thread(
            target=self.obc.serve, kwargs={"until": self._loop}, name="spacecan", daemon=True
        )
        self._thread.start()
        self.out("%r on %s" % (self.obc, self.obc.interface))
        return self

    def _loop(self):
        """Called by the master's loop at each turn: its work still moves."""
        self.last_loop = time.monotonic()
        return False

    def alive(self):
        """The master's loop turned within 2 s (a loop blocked in a call is hung)."""
        if self._thread is None or not self._thread.is_alive():
            return False
        return time.monotonic() - self.last_loop < 2.0

    def stop(self):
        self.obc.stop()
        if self._thread is not None:
            self._thread.join(2.0)
        self.obc.close()
