"""The OBC's side of the UART link against the module's logic: the context round trip (the
newest of two controllers wins), the DS3231's time, a controller that does not answer."""

import socket
import threading

import pytest
from obsw.reconfig.app import ReconfigApp
from obsw.reconfig.hal import PORT_OBC
from obsw.reconfig.models import ModelHal
from obsw.utc import days_from_civil
from obsw_host.obc.context import ContextError, ObcContext
from obsw_host.reconfig.link import ObcLink


class Module:
    """A controller's application on the in-memory hardware layer, its OBC UART a socket."""

    def __init__(self, role=0):
        self.hal = ModelHal(role, rtc_seconds=days_from_civil(2026, 11, 24) * 86400)
        self.app = ReconfigApp(self.hal, recovery={"enabled": False})
        self.obc_end, self.sock = socket.socketpair()
        self.sock.settimeout(0.01)
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()

    def run(self):
        while not self.stop.is_set():
            try:
                data = self.sock.recv(4096)
            except (socket.timeout, OSError):
                data = b""
            if data:
                self.hal.uart_rx[PORT_OBC].extend(data)
            self.app.step()
            out = self.hal.uart_tx[PORT_OBC]
            if out:
                self.sock.sendall(bytes(out))
                self.hal.uart_tx[PORT_OBC] = bytearray()

    def close(self):
        self.stop.set()
        self.thread.join(2.0)
        self.sock.close()
        self.obc_end.close()


@pytest.fixture
def modules():
    ms = [Module(0), Module(1)]
    yield ms
    for m in ms:
        m.close()


def test_context_round_trip_and_newest_wins(modules):
    link = ObcLink(m.obc_end.fileno() for m in modules)
    assert link.read_context() is None  # nothing kept yet
    ctx = ObcContext(mode=2, obt=2.1e9, utc_at=2.1e9, seq={0x100: 77}, obcps=["turn_panel"])
    ctx.saves = 5
    assert link.write_context(ctx) == 2
    older = ObcContext(mode=1, saves=4)
    ObcLink([modules[1].obc_end.fileno()]).write_context(older)
    assert link.read_context() == ctx


def test_time_from_the_ds3231(modules):
    link = ObcLink(m.obc_end.fileno() for m in modules)
    assert link.read_time() is None  # the oscillator-stop flag is up until the time is set
    modules[1].app.rtc.set_day_ms(days_from_civil(2026, 11, 24), 3600000)
    day, ms = link.read_time()
    assert day == days_from_civil(2026, 11, 24)
    assert 3600000 <= ms < 3602000


def test_heartbeats_counted(modules):
    link = ObcLink(m.obc_end.fileno() for m in modules)
    for _ in range(3):
        link.heartbeat()
    link.read_time()  # a round trip: the heartbeats before it have been read
    assert [m.app.link_counters["heartbeats"] for m in modules] == [3, 3]


def test_a_silent_controller_costs_only_the_timeout():
    a, b = socket.socketpair()
    try:
        assert ObcLink([a.fileno()]).read_context(timeout=0.05) is None
    finally:
        a.close()
        b.close()


def test_context_too_large_or_garbage():
    with pytest.raises(ContextError):
        ObcContext(obcps=["x" * 40] * 8).pack()
    with pytest.raises(ContextError):
        ObcContext.unpack(b"\xff\x00")
    with pytest.raises(ContextError):
        ObcContext.unpack(b"\x01")  # a CBOR integer, not a map
