"""The thesis' twelve-step chain on one machine, every step a real process or a real link.

ground (PUS user) -> TC frames in CLTUs on two pseudo-terminal UARTs -> frame processor ->
PUS application process -> service 18 -> PLUTO procedure on the OBCP engine -> interaction
layer -> the CPDU's equipment component -> SpaceCAN master -> CAN (the reconfiguration module's
UDP hub, buses A and B) -> both reconfiguration controllers as MicroPython unix-port processes
-> CPDU lines switch -> housekeeping and verification back through TM frames.

``Chain(work, mission=DIR)`` copies a mission folder (default: the sample's) into ``work`` and
points its mission file at the chain's links: the SpaceCAN hub of the simulated
reconfiguration module (``obsw_sim.reconfig.ReconfigSim``, on the mission's ids), two
pseudo-terminal UARTs, free UDP ports and the module's TC keys. The mission's CPDU line that
its platform manager power-cycles (``platform.power_cycle``) powers the OBC: the OBC is
``obsw obc serve`` of that mission (the platform manager and the mission's processes, its
plug-in components among them). The ground station holds the other ends of the OBC's UARTs;
the ground's PUS user talks to it. Every name and id comes from the mission: the CPDU is the
reconfiguration module's nominal node, the procedure drives its ``set_state_bits``.
"""

import json
import os
import select
import shutil
import sys
import threading
import time

from obsw_host.frames.links import FdLink
from obsw_host.mission import defaults
from obsw_host.mission.ids import MissionIds

SWITCH = """\
// Switch CPDU lines through the nominal controller and confirm the new state.
procedure
  main
    initiate and confirm set_state_bits of %s with arguments state := %d end with;
  end main
end procedure
"""


def _station_class():
    from obsw.frames import fop as F
    from obsw_host.frames.station import GroundStation

    class OperatorStation(GroundStation):
        """A ground station whose operator, when FOP-1 has given up, initiates the AD service
        again: with Unlock when the last CLCW says FARM-1 is in lockout (frames lost or
        duplicated beyond its window: FARM-1 ignores Set V(R) then), else with Set V(R) (a
        restarted frame processor's FARM-1 starts again at V(R) = 0), so frame numbering
        restarts on both sides."""

        started = False

        def step(self, timeout=0.02):
            # wait on the mission control socket as well as on the links, so a TC goes out
            # as soon as it comes (the base class waits on the links only)
            select.select([self.sock] + self.ground.links, [], [], timeout)
            fop = self.ground.fop
            if self.started and fop.state == F.INITIAL:
                clcw = self.ground.demux.clcw
                if clcw is not None and clcw.lockout:
                    self.ground.initiate(self.now(), F.INITIATE_AD_WITH_UNLOCK)
                else:
                    self.ground.initiate(self.now(), F.INITIATE_AD_WITH_SET_VR, fop.vs)
                self._initiated = True
            self.started = True
            super().step(0)

    return OperatorStation


class Chain:
    """The chain (see the module text); ``start()``/``stop()`` or a context manager."""

    # the reconfiguration module's autonomous recovery in the chain: a hung OBC is power-cycled
    # after 8 s without a SpaceCAN heartbeat (the OBC's processes restart faster than that)
    RECOVERY = {"deadline": 8.0, "boot_grace": 20.0, "off_ms": 300, "max_failures": 10}
    # the redundant OBC's CPDU line: above the four lines the chain's procedures switch
    REDUNDANT_LINE = 8

    # the sample in three processes, so that each can be killed alone
    SAMPLE_PROCESSES = {
        "core": ["pus", "cfdp", "obcp", "SolarPanel"],
        "can": ["spacecan"],
        "frames": ["frames"],
    }

    def __init__(self, work, out=None, timeout=10.0, recovery=None, mission=None, processes=None):
        from obsw_host.sample import MISSION_DIR

        self.work = work
        self.mission_dir = os.path.join(work, "mission")  # the mission's copy, its paths kept
        shutil.copytree(
            mission or MISSION_DIR, self.mission_dir, ignore=shutil.ignore_patterns("__pycache__")
        )
        self.ids = MissionIds.locate(self.mission_dir)
        nodes = {n.node_id: name for name, n in self.ids.sdb.nodes.items()}
        self.cpdu = nodes[self.ids.reconfig_nodes[0]]  # the nominal controller's node
        power = dict(defaults.PLATFORM["power_cycle"])
        power.update((self.ids.config.doc.get("platform") or {}).get("power_cycle") or {})
        self.power_cycler = power["component"]
        self.obc_line = power["line"]  # the CPDU line that powers the (nominal) OBC
        self.processes = processes or (None if mission else self.SAMPLE_PROCESSES)
        self.recovery = dict(self.RECOVERY, **(recovery or {}))
        # the nominal and the redundant OBC: the same mission, each its own state folder
        self.recovery["lines"] = [self.obc_line, self.REDUNDANT_LINE]
        self.out = out
        self.timeout = timeout
        self.state = os.path.join(work, "obc-state")
        self.config_path = os.path.join(self.mission_dir, "chain.json")
        self.sim = None
        self.station = None
        self.ground = None
        self.obcp = None
        self.sdb = None
        self._uarts = []
        self._hk = set()  # structures defined on board
        self.platform = {}  # platform manager settings for the OBC's next boot
        self.sections = {}  # more mission file sections for the OBC's next boot ("contact")
        self.sim_options = {}  # more options of the reconfiguration module (ReconfigSim)
        # CFDP through the frames: the OBC's entity sends its PDUs to the frame processor's TM
        # input, the station hands the CFDP APID's packets to the ground entity on
        # ``cfdp_ground_port`` and takes its TC packets up (else CFDP goes over UDP directly)
        self.cfdp_frames = False
        self.tm_frame_length = 256  # the OBC's TM frames, as the station decodes them
        self._stop = threading.Event()
        self._thread = None

    def say(self, text):
        if self.out is not None:
            self.out(text)

    # -------------------------------------------------------------------------- set-up

    def _pty(self):
        import tty

        controller, device = os.openpty()
        tty.setraw(device)
        self._uarts.append(device)  # kept open: a restarted frame processor finds it as it was
        return controller, os.ttyname(device)

    def write_config(self, hub_ports, uart_a, uart_b, redundant=False):
        """The mission file of the OBC about to boot (the redundant one: its own state folder
        and its own CPDU line to ask a power cycle of)."""
        with open(self.ids.config.path) as f:
            doc = json.load(f)
        doc["name"] = "chain"
        doc["state"] = self.state + ("-redundant" if redundant else "")
        if self.processes:
            doc["processes"] = self.processes
        doc["ports"] = {  # free ports: several chains may run at once
            "pus": self.pus_port,
            "cfdp": self.cfdp_port,
            "tm": self.tm_port,
            "playback": self.playback_port,
            "cfdp_ground": self.cfdp_ground_port,
        }
        doc.setdefault("spacecan", {}).update(
            interface="hub",
            channels=list(hub_ports),
            simulate=False,
            heartbeat_period=0.2,
            timeout=0.3,
            retries=3,
        )
        frames = doc.setdefault("frames", {})
        frames.pop("tc_security", None)  # signed TC frames, as the module's are
        frames.update(
            uart_a=uart_a,
            uart_b=uart_b,
            clcw_period=0.2,
            tm_frame_length=self.tm_frame_length,
            keys=self.sim.key_file,  # the mission's TC keys: the OBC's and the module's
        )
        platform = doc.setdefault("platform", {})
        platform.update(heartbeat=0.2, deadline=2.0, start_timeout=30.0, max_failures=20)
        # the UART link to the module: context and time across power cycles and switch-overs
        platform.update(module_uarts=list(self.sim.obc_uart_paths), context_period=0.5)
        platform.update(self.platform)
        if self.cfdp_frames:
            ground = self.ids.cfdp_entities[1]
            doc.setdefault("cfdp", {})["peers"] = {str(ground): "127.0.0.1:%d" % self.tm_port}
        for name, section in self.sections.items():  # over what the chain set
            doc.setdefault(name, {}).update(section)
        if redundant:
            cycle = dict(defaults.PLATFORM["power_cycle"], **(platform.get("power_cycle") or {}))
            platform["power_cycle"] = dict(cycle, line=self.REDUNDANT_LINE)
        partial = self.config_path + ".part"
        with open(partial, "w") as f:
            json.dump(doc, f, indent=2)
        os.replace(partial, self.config_path)  # the test polls for the file: never half written
        return doc

    @property
    def active_line(self):
        """The CPDU line of the OBC in service: the redundant one once switched over."""
        if self.sim is not None and self.sim.lines() >> self.obc_line & 1 == 0:
            if self.sim.lines() >> self.REDUNDANT_LINE & 1:
                return self.REDUNDANT_LINE
        return self.obc_line

    @property
    def obc_bit(self):
        """The state bit of the OBC in service: every state the chain sets keeps it on."""
        return 1 << self.active_line

    def _obc_command(self, sim):
        redundant = sim.obc_which == 1
        self.write_config(sim.hub.ports, self.uart_paths[0], self.uart_paths[1], redundant)
        return [sys.executable, "-m", "obsw_host.obc", self.config_path]

    def start(self):
        from obsw.pus import sdb as sdb_module
        from obsw_host.frames import keys
        from obsw_host.mission.config import load
        from obsw_host.pus.ground import Ground
        from obsw_host.pus.obcp_ground import ObcpGround

        from obsw_sim.reconfig import ReconfigSim

        os.makedirs(self.state, exist_ok=True)
        ports = _free_ports(5)
        self.pus_port, self.cfdp_port, self.tm_port, self.playback_port = ports[:4]
        self.cfdp_ground_port = ports[4]  # where the OBC's CFDP entity finds the ground's
        ends = [self._pty(), self._pty()]
        self.uart_paths = [path for _, path in ends]
        self.links = [FdLink(ends[0][0], "A"), FdLink(ends[1][0], "B")]
        sim_dir = os.path.join(self.work, "reconfig")
        os.makedirs(sim_dir, exist_ok=True)
        self.sim = ReconfigSim(
            sim_dir,
            obc_command=self._obc_command,
            out=self.out,
            recovery=self.recovery,
            ids=self.ids,
            obc_lines=(self.obc_line, self.REDUNDANT_LINE),
            initial_lines=1 << self.obc_line,
            **self.sim_options,
        )
        security, state = keys.load(self.sim.key_file, os.path.join(self.work, "station.state"))
        routes = None
        if self.cfdp_frames:
            routes = {self.ids.apid("cfdp"): ("127.0.0.1", self.cfdp_ground_port)}
        self.station = _station_class()(
            self.links,
            self.ids.scid,
            vcid=self.ids.tc_vc,
            map_id=self.ids.maps["packets"],
            tm_frame_length=self.tm_frame_length,
            security=security,
            state=state,
            routes=routes,
        )
        self._thread = threading.Thread(target=self.station.run, args=(self._stop,), daemon=True)
        self._thread.start()
        self.sim.start()
        if not self.sim.wait_for(lambda: os.path.exists(self.config_path), 20.0):
            raise TimeoutError("the OBC was never powered")
        self.config = load(self.config_path)
        self.sdb = sdb_module.load(self.config.sdb_path)
        self.ground = Ground(self.sdb, target=self.station.address[:2], timeout=self.timeout)
        self.obcp = ObcpGround(self.ground)
        return self

    def stop(self):
        if self.ground is not None:
            self.ground.close()
        if self.sim is not None:
            self.sim.stop()  # kills the OBC (the platform manager: its processes follow it)
        self._stop.set()
        if self._thread is not None:
            self._thread.join(2.0)
        if self.station is not None:
            self.station.close()
        for fd in self._uarts:
            try:
                os.close(fd)
            except OSError:
                pass

    def __enter__(self):
        try:
            return self.start()
        except BaseException:
            self.stop()  # a chain that did not come up leaves no controller or OBC running
            raise

    def __exit__(self, *exc):
        self.stop()

    # -------------------------------------------------------------------------- operations

    def wait_up(self, timeout=60.0):
        """Ping through the whole chain until one completes; the time it took."""
        t0 = time.monotonic()
        end = t0 + timeout
        while time.monotonic() < end:
            try:
                if self.ground.ping(timeout=1.0).ok:
                    return time.monotonic() - t0
            except Exception:
                pass
        raise TimeoutError("no ping completed through the chain within %ss" % timeout)

    def switch(self, state, name="switch", timeout=None):
        """Load and activate the CPDU procedure for ``state``; wait for its end event.

        Returns the transaction of the activation and the procedure's final event."""
        timeout = timeout or self.timeout
        tx = self.obcp.load(name, SWITCH % (self.cpdu, state | self.obc_bit), timeout=timeout)
        if not tx.ok:
            raise RuntimeError("load refused: %s" % tx.verification())
        since = len(self.ground.received)
        tx = self.obcp.activate(name, timeout=timeout)
        done = self.wait_event(("obcp.finished", "obcp.failed"), since, timeout)
        return tx, done

    def wait_event(self, names, since=0, timeout=None):
        """The first event named in ``names`` received after index ``since``, or None."""
        ids = {self.sdb.event(n).id: n for n in names}
        end = time.monotonic() + (timeout or self.timeout)
        while time.monotonic() < end:
            self.ground.poll(0.02)
            for tm, _ in self.ground.received[since:]:
                if tm.service == 5 and len(tm.data) >= 2:
                    eid = (tm.data[0] << 8) | tm.data[1]
                    if eid in ids:
                        return ids[eid]
        return None

    def cpdu_housekeeping(self, sid=99):
        """The nominal CPDU's parameters (by attribute name) in a one-shot housekeeping report
        through the TM frames."""
        known = {p.qualified for p in self.sdb.parameters.values()}
        names = ["%s.%s" % (self.cpdu, a) for a in ("state_bits", "health", "in_charge")]
        names = [n for n in names if n in known]
        if sid not in self._hk:
            periodic = [st["sid"] for st in self.sdb.housekeeping if st["enabled"]]
            self.ground.disable_hk(periodic)  # the mission's periodic reports: one-shots here
            tx = self.ground.create_hk(sid, 10, names)
            if not tx.ok:
                raise RuntimeError("structure %d not created: %s" % (sid, tx.verification()))
            self._hk.add(sid)
        tx = self.ground.housekeeping(sid)
        if not tx.ok or not tx.reply or "values" not in tx.reply:
            raise RuntimeError(
                "no housekeeping report %d: %s %r" % (sid, tx.verification(), tx.reply)
            )
        return {k.split(".", 1)[1]: v for k, v in tx.reply["values"].items()}

    def lines(self):
        return self.sim.lines()

    @property
    def station_alive(self):
        """Whether the ground station's thread runs (None before it started)."""
        return self._thread.is_alive() if self._thread is not None else None

    def pid_of(self, process):
        """The pid of OBC process ``process`` as the platform manager last reported it."""
        mark = "[platform] %s up (pid " % process
        for _, text in reversed(self.sim.log_lines()):
            i = text.find(mark)
            if i >= 0:
                return int(text[i + len(mark) :].split(")")[0])
        return None


def _free_ports(n):
    import socket

    socks = []
    for _ in range(n):
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        s.bind(("127.0.0.1", 0))
        socks.append(s)
    ports = [s.getsockname()[1] for s in socks]
    for s in socks:
        s.close()
    return ports


def demo(out=print):
    """The chain, then its faults, narrated; returns 0 if every step went as expected."""
    import shutil
    import signal
    import tempfile

    from obsw.reconfig.essential import HPC_POWER_CYCLE, Hpc

    work = tempfile.mkdtemp(prefix="obsw-chain-")
    ok = True

    def check(what, good, t0):
        nonlocal ok
        ok = ok and bool(good)
        out("  %-66s %s (%.2f s)" % (what, "ok" if good else "FAILED", time.monotonic() - t0))

    def ping_until_ok(chain, timeout=60.0):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            try:
                if chain.ground.ping(timeout=3.0).ok:
                    return True
            except Exception:
                pass
        return False

    try:
        out("  starting: ground station on two pty UARTs, the OBC (frames, core, can processes")
        out("  under the platform manager), the CAN hub, both MicroPython reconfiguration")
        out("  controllers; CPDU line 0 powers the OBC")
        with Chain(work) as chain:
            t = time.monotonic()
            chain.wait_up(60.0)
            check("ping through CLTUs, frame processor, PUS, TM frames", True, t)
            t = time.monotonic()
            tx, end = chain.switch(0x005, timeout=20.0)
            check(
                "TC[18,3] -> PLUTO -> %s.set_state_bits -> SpaceCAN -> CPDU 0x%03x"
                % (chain.cpdu, chain.lines()),
                tx.ok and end == "obcp.finished" and chain.lines() == 0x005 | chain.obc_bit,
                t,
            )
            t = time.monotonic()
            end_t = t + 20.0
            hk = None
            while time.monotonic() < end_t:
                hk = chain.cpdu_housekeeping()
                if hk.get("state_bits") == 5 | chain.obc_bit:
                    break
            check("housekeeping through TM frames: %s.state_bits = %s" % (chain.cpdu, hk.get(
                "state_bits")), hk.get("state_bits") == 5 | chain.obc_bit, t)  # fmt: skip
            for name in chain.config.processes:
                pid = chain.pid_of(name)
                t = time.monotonic()
                os.kill(pid, signal.SIGKILL)
                while chain.pid_of(name) in (None, pid) and time.monotonic() < t + 30:
                    time.sleep(0.05)
                check("OBC process %s killed: restarted, serving again" % name,
                      ping_until_ok(chain), t)  # fmt: skip
            chain.sim.hub.kill(0)
            t = time.monotonic()
            tx, end = chain.switch(0x007, name="bus_b", timeout=20.0)
            check("bus A cut: CPDU switched over bus B", tx.ok and chain.lines() == 0x007, t)
            chain.sim.hub.revive(0)
            chain.links[0].enabled = False
            t = time.monotonic()
            check("UART A cut: ping over UART B", ping_until_ok(chain), t)
            chain.links[0].enabled = True
            boots = chain.sim.obc_boots
            chain.sim.kill_obc()
            t = time.monotonic()
            chain.sim.send_hpc(Hpc(HPC_POWER_CYCLE, (chain.obc_line, 200)))
            chain.sim.wait_for(lambda: chain.sim.obc_boots == boots + 1, 30.0)
            check("OBC killed: power-cycled by an essential TC, serving again",
                  ping_until_ok(chain), t)  # fmt: skip
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return 0 if ok else 1
