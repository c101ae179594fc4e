"""The frame processor unit of an OBC process: two UARTs to the COM module, UDP to the
application processes, and the ``FrameProcessor`` component with the UARTs' drop counters."""

import os
import threading
import time
import tty

from obsw.il.node import Node

from obsw_host.frames import policy
from obsw_host.frames.coding import LinkSettings
from obsw_host.frames.links import FdLink, SerialLink
from obsw_host.frames.processor import FrameProcessorHost, sdb_events, security_options
from obsw_host.il.transport import SocketTransport
from obsw_host.mission.ids import event_id
from obsw_host.obc.topology import FRAME_PROCESSOR


class FrameCounters:
    """``FRAME_PROCESSOR``: frames each UART's queue dropped (nobody read it in time)."""

    def __init__(self, links):
        self.links = links
        self.il = None
        self._published = (0, 0)

    def il_bind(self, provider):
        self.il = provider

    @property
    def uart_a_dropped(self):
        return getattr(self.links[0], "dropped", 0)

    @property
    def uart_b_dropped(self):
        return getattr(self.links[1], "dropped", 0)

    def publish(self):
        """Publish the counters that changed since the last call (from the IL's thread)."""
        now = (self.uart_a_dropped, self.uart_b_dropped)
        if now != self._published and self.il is not None:
            for name, old, new in zip(("uart_a_dropped", "uart_b_dropped"), self._published, now):
                if old != new:
                    self.il.node.publish(FRAME_PROCESSOR.name, name, new)
            self._published = now
        return False


class FramesUnit:
    """The frame processor on two UARTs (device paths, or ``pty``: a pseudo-terminal pair
    whose other end's path is written to ``STATE/uart_a`` and ``STATE/uart_b``); with
    ``keys`` (a key file) TC frames are authenticated. Writing to a UART never blocks the
    frame processor: each link queues at most ``uart_queue`` frames and drops the oldest
    beyond; the drops are attributes of the ``FrameProcessor`` component (housekeeping)."""

    def __init__(self, topology, process, out=print):
        config = topology.config
        sdb = topology.sdb
        opts = topology.section("frames")
        self.out = out
        links = []
        self.paths = {}
        queue = int(opts["uart_queue"])
        for side in ("a", "b"):
            dev = opts["uart_" + side]
            if dev == "pty":
                controller, path = _pty()
                links.append(FdLink(controller, side.upper(), queue=queue))
                with open(os.path.join(config.state, "uart_" + side), "w") as f:
                    f.write(path + "\n")
                self.paths[side] = path
            else:
                path = config.resolve(dev) if dev.startswith(".") else dev
                links.append(SerialLink(path, queue=queue))
                self.paths[side] = dev
        ids = topology.ids
        ports = ids.ports
        link = LinkSettings.of(config)  # the TM coding and the radio's rate
        security = {}
        key_path = policy.check(config)  # secure by default: keys, or "tc_security": "none"
        if key_path is None:
            out(policy.OFF_WARNING)
        else:  # TC (and TM, where the file has SAs for it) protected with SDLS
            state = os.path.join(config.state, "frames.keys.state")
            security = security_options(key_path, sdb, state)
        if "event_apid" not in security:  # no SDLS: the overflow event still has its APID
            try:
                security["event_apid"], security["event_ids"] = sdb_events(sdb)
            except KeyError:
                pass
        self.fp = FrameProcessorHost(
            links[0],
            links[1],
            ids.scid,
            host=config.host,
            routes=ports.routes(config.host),
            default_route=ports.route(config.host),
            tm_port=ports.tm,
            vc_ports={ids.playback_vc: ports.playback},
            tm_plan=ids.tm_vcs,
            tm_channels=ids.tm_channels(),
            tm_vc_of_apid=ids.tm_vc_of_apid(),
            tc_vcids=(ids.tc_vc,),
            tm_frame_length=int(opts["tm_frame_length"]),
            clcw_period=float(opts["clcw_period"]),
            tm_coding=link.encoder(),
            downlink_bps=link.downlink_bps,
            tm_spill=link.tm_spill,
            overflow_event=event_id(sdb, "frames.tm_overflow"),
            **security,
        )
        self.last_step = time.monotonic()
        self._stop = threading.Event()
        self._thread = None
        self.node = Node("obc-frames")
        self.transport = SocketTransport(self.node, config.il_directory)
        self.counters = FrameCounters(self.fp.links)
        self.node.provide(FRAME_PROCESSOR, self.counters)
        self._il_thread = None

    def _run(self):
        while not self._stop.is_set():
            self.fp.step(0.05)
            self.last_step = time.monotonic()

    def _serve_il(self):
        """The transport's thread: serves the counters and publishes them when they change."""
        self.transport.serve(until=lambda: self.counters.publish() or self._stop.is_set())

    def start(self):
        self._thread = threading.Thread(target=self._run, name="frames", daemon=True)
        self._thread.start()
        self._il_thread = threading.Thread(target=self._serve_il, name="frames-il", daemon=True)
        self._il_thread.start()
        self.out(
            "frame processor: UART A %s, UART B %s, TM in on udp %d"
            % (self.paths["a"], self.paths["b"], self.fp.tm_port)
        )
        return self

    def alive(self):
        return self._thread is not None and time.monotonic() - self.last_step < 2.0

    def stop(self):
        self._stop.set()
        self.transport.stop()
        for thread in (self._thread, self._il_thread):
            if thread is not None:
                thread.join(2.0)
        self.transport.close()
        self.fp.close()


def _pty():
    controller, device = os.openpty()
    tty.setraw(device)
    path = os.ttyname(device)
    # the device end stays open here: with no one on it, the controller end would read EIO
    # (and be "readable") until the ground opens the path
    return controller, path
