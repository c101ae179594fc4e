"""The simulated module's hardware layer, run inside a MicroPython unix-port controller process.

MicroPython subset (it runs under `micropython`, and CPython imports its layout constants).
Shared lines live in a small file both controllers and the host supervisor open (the "wire");
CAN goes through the host's UDP hub; the COM and OBC UARTs are pseudo-terminals; the EEPROMs
and the DS3231 are the core's models, kept in files so they outlive a controller reset.

Run: micropython -m obsw_sim.reconfig_hal ROLE WIRE HUB_A HUB_B COM OBC STATE_DIR CAUSE [BER]
"""

import select
import socket
import sys
import time

from obsw.reconfig.hal import CPDU_MASK, Hal
from obsw.reconfig.models import DS3231Model, M24512Model, SimI2C

WIRE_SIZE = 64
# per controller, at 16 * role:
W_DRIVE = 0  # 1 while driving the D lines
W_DATA = 1  # D lines, 2 bytes little-endian
W_CLOCK = 3  # 0 / 1, 2 = high impedance
W_REQ = 4
W_ALIVE = 5  # edges of the alive line, counted modulo 256 (no edge missed between reads)
W_KICKS = 6  # TPS3813 WDI pulses, counted modulo 256
W_FAULT = 7  # set by the supervisor: 1 = firmware hangs with CPDU_REQ high
W_STEPS = 8  # main loop passes modulo 256 (progress, for the supervisor)
W_KICK_MS = 9  # the last WDI pulse's time on the controller's clock, ms modulo 65536 (2 bytes)
Q_OFFSET = 32  # latched outputs, 2 bytes little-endian
LATCHES = 34
COLLISIONS = 35


def initial_wire(q=0):
    w = bytearray(WIRE_SIZE)
    for base in (0, 16):
        w[base + W_CLOCK] = 2
    w[Q_OFFSET] = q & 0xFF
    w[Q_OFFSET + 1] = q >> 8
    return w


class FileWire:
    """Byte-level access to the shared wire file (unbuffered reads and writes)."""

    def __init__(self, path):
        self.f = open(path, "r+b")
        self.buf = bytearray(WIRE_SIZE)
        self.one = bytearray(1)

    def read(self):
        self.f.seek(0)
        self.f.readinto(self.buf)
        return self.buf

    def get(self, off):
        self.f.seek(off)
        self.f.readinto(self.one)
        return self.one[0]

    def put(self, off, data):
        self.f.seek(off)
        self.f.write(data)


class SimHal(Hal):
    """One controller of the simulated module."""

    def __init__(self, role, wire, hub_ports, com, obc, state_dir, cause=0, bit_error_gap=0):
        self.role = role
        self.wire = FileWire(wire)
        self.base = 16 * role
        self.other = 16 * (1 - role)
        self.cause = cause
        self._t0 = time.ticks_us()
        self._acc = 0
        self._last = self._t0
        self.i2c = SimI2C(seed=17 + role, bit_error_gap=bit_error_gap)
        prefix = "%s/%s" % (state_dir, "nominal" if role == 0 else "redundant")
        self.i2c.devices[0x50] = M24512Model(prefix + "_eeprom0.bin")
        self.i2c.devices[0x51] = M24512Model(prefix + "_eeprom1.bin")
        self.i2c.devices[0x68] = DS3231Model(self._seconds, prefix + "_rtc.json")
        self.hub = [socket.getaddrinfo("127.0.0.1", p)[0][-1] for p in hub_ports]
        self.can = []
        for b in (0, 1):
            s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            s.bind(socket.getaddrinfo("127.0.0.1", 0)[0][-1])
            s.setblocking(False)
            s.sendto(b"", self.hub[b])  # register with the hub
            self.can.append(s)
        self.uarts = [self._open_tty(com), self._open_tty(obc)]
        self.poll = select.poll()
        for s in self.can:
            self.poll.register(s, select.POLLIN)
        for u in self.uarts:
            self.poll.register(u, select.POLLIN)
        self._rx = bytearray(512)
        self._kicks = 0
        self._steps = 0
        self._level = 0
        self._edges = self.wire.get(self.base + W_ALIVE)
        self.wire.put(self.base + W_REQ, b"\x00")

    def _open_tty(self, path):
        import termios

        f = open(path, "r+b")
        a = termios.tcgetattr(f.fileno())
        a[6][5] = 0  # VTIME
        a[6][6] = 0  # VMIN: reads return what is there, at once
        termios.tcsetattr(f.fileno(), termios.TCSANOW, a)
        return f

    def _seconds(self):
        return time.time_ns() / 1000000000

    def now_us(self):
        t = time.ticks_us()
        self._acc += time.ticks_diff(t, self._last)
        self._last = t
        return self._acc

    # -- CPDU lines ---------------------------------------------------------------------------

    def cpdu_data(self, bits):
        bits &= CPDU_MASK
        self.wire.put(self.base + W_DRIVE, bytes((1, bits & 0xFF, bits >> 8)))

    def _resolve(self, w, off):
        """Level of a line both drive: the nominal's output wins (the redundant's has
        resistors in series); undriven lines are pulled down."""
        if w[off] != 2:
            return w[off]
        return w[16 + off] if w[16 + off] != 2 else 0

    def cpdu_clock(self, level):
        w = self.wire.read()
        before = self._resolve(w, W_CLOCK)
        self.wire.put(self.base + W_CLOCK, bytes((1 if level else 0,)))
        w = self.wire.read()
        if self._resolve(w, W_CLOCK) and not before:
            if w[W_DRIVE]:
                q = w[W_DATA] | (w[W_DATA + 1] << 8)
            elif w[16 + W_DRIVE]:
                q = w[16 + W_DATA] | (w[16 + W_DATA + 1] << 8)
            else:
                q = 0
            self.wire.put(Q_OFFSET, bytes((q & 0xFF, q >> 8, (w[LATCHES] + 1) & 0xFF)))
            if w[W_DRIVE] and w[16 + W_DRIVE]:
                self.wire.put(COLLISIONS, bytes(((w[COLLISIONS] + 1) & 0xFF,)))

    def cpdu_release(self):
        self.wire.put(self.base + W_DRIVE, b"\x00")
        self.wire.put(self.base + W_CLOCK, b"\x02")

    def cpdu_readback(self):
        w = self.wire.read()
        return w[Q_OFFSET] | (w[Q_OFFSET + 1] << 8)

    def req(self, level):
        self.wire.put(self.base + W_REQ, b"\x01" if level else b"\x00")

    def other_req(self):
        return self.wire.get(self.other + W_REQ) != 0

    def alive(self, level):
        self._steps = (self._steps + 1) & 0xFF
        if level != self._level:  # an edge: the other controller's edge detector counts it
            self._level = level
            self._edges = (self._edges + 1) & 0xFF
            self.wire.put(self.base + W_ALIVE, bytes((self._edges,)))
        self.wire.put(self.base + W_STEPS, bytes((self._steps,)))
        if self.wire.get(self.base + W_FAULT):
            self._hang()

    def _hang(self):
        # a firmware bug: the request line stays high and the loop never comes back
        self.req(1)
        print("[%s] fault injected: CPDU_REQ stuck high, loop hung" % "NR"[self.role])
        while True:
            time.sleep_ms(50)

    def other_alive(self):
        """The other controller's alive line as its edge count: changed since the last read
        when the line moved, however often (a level read between two passes of a loop that
        idles may find it back where it was)."""
        return self.wire.get(self.other + W_ALIVE)

    def wdi(self, level):
        if level:
            # the pulse's time first: the supervisor reads it when it sees the count change
            t = time.ticks_ms() & 0xFFFF
            self.wire.put(self.base + W_KICK_MS, bytes((t & 0xFF, t >> 8)))
            self._kicks = (self._kicks + 1) & 0xFF
            self.wire.put(self.base + W_KICKS, bytes((self._kicks,)))

    # -- buses --------------------------------------------------------------------------------

    def can_recv(self, bus):
        try:
            d = self.can[bus].recv(16)  # one datagram (readinto would run several together)
        except OSError:
            return None
        if len(d) < 2:
            return None
        return (d[0] << 8) | d[1], d[2:]

    def can_send(self, bus, can_id, data):
        try:
            self.can[bus].sendto(bytes((can_id >> 8, can_id & 0xFF)) + bytes(data), self.hub[bus])
            return True
        except OSError:
            return False

    def uart_read(self, port):
        n = self.uarts[port].readinto(self._rx)
        return bytes(self._rx[:n]) if n else b""

    def uart_write(self, port, data):
        self.uarts[port].write(data)

    def reset_cause(self):
        return self.cause

    def reset(self):
        sys.exit(3)

    def idle(self, ms):
        if ms > 0:
            self.poll.poll(ms)


def main(argv):
    from obsw.reconfig.app import ReconfigApp

    role = int(argv[0])
    hal = SimHal(
        role,
        argv[1],
        (int(argv[2]), int(argv[3])),
        argv[4],
        argv[5],
        argv[6],
        int(argv[7]),
        int(argv[8]) if len(argv) > 8 else 0,
    )
    security = None
    if len(argv) > 9:
        from obsw.reconfig.essential import security_from_file

        security = security_from_file(argv[9])
        if security is None:
            raise OSError("no SDLS key file %s" % argv[9])
    from obsw.reconfig import mission

    ids = mission.load(argv[6] + "/" + mission.FILE) or {}  # as on a board's flash
    ids.setdefault("recovery", {"enabled": False})  # a board's default is on; a sim's is off
    app = ReconfigApp(hal, essential_security=security, **ids)
    tag = "NR"[role]

    def log(text):
        print("[%s] %s" % (tag, text))

    app.log = log
    app.step()
    log("ready")
    app.run()


if __name__ == "__main__":
    main(sys.argv[1:])
