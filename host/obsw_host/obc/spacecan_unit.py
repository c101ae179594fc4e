"""The SpaceCAN unit of an OBC process: the SpaceCAN master, the equipment components of the CAN
nodes and device access (service 2's path to the nodes), in a thread of its own."""

import threading

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
        self._thread = threading.Thread(target=self.obc.serve, name="spacecan", daemon=True)
        self._thread.start()
        self.out("%r on %s" % (self.obc, self.obc.interface))
        return self

    def alive(self):
        return self._thread is not None and self._thread.is_alive()

    def stop(self):
        self.obc.stop()
        if self._thread is not None:
            self._thread.join(2.0)
        self.obc.close()
