"""The OBC runtime's UART link to the reconfiguration module (``obsw_host.obc.module_link``)
against both controllers' own logic, each behind a pseudo-terminal as a serial device: at a
first start no context and the onboard time from the DS3231; the context saved in both
safeguard memories; at the next start the TM sequence counts go on and the boot count goes up;
with one controller silent the other carries the link."""

import os
import select
import threading
import time
import tty
import types

import pytest
from obsw.spp import SequenceCounter
from obsw.utc import days_from_civil
from obsw_host.obc.module_link import ModuleLink
from obsw_host.obc.onboard_time import OnboardTime
from test_obc_link import Module

DS3231_DAY = days_from_civil(2026, 11, 24) - days_from_civil(1958, 1, 1)


class Cable:
    """A pseudo-terminal whose other end is a controller's OBC UART (a socket)."""

    def __init__(self, module):
        self.master, slave = os.openpty()
        tty.setraw(slave)
        self.path = os.ttyname(slave)
        self.slave = slave  # kept open: the wires stay between the OBC's starts
        self.module = module
        self.silent = False
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()

    def run(self):
        sock = self.module.obc_end
        while not self.stop.is_set():
            ready, _, _ = select.select([self.master, sock], [], [], 0.01)
            if self.master in ready:
                data = os.read(self.master, 4096)
                if not self.silent:
                    sock.sendall(data)
            if sock in ready:
                data = sock.recv(4096)
                if data and not self.silent:
                    os.write(self.master, data)

    def close(self):
        self.stop.set()
        self.thread.join(2.0)
        os.close(self.master)
        os.close(self.slave)


@pytest.fixture
def cables():
    modules = [Module(0), Module(1)]
    cs = [Cable(m) for m in modules]
    yield cs
    for c in cs:
        c.close()
    for m in modules:
        m.close()


def start(cables, tmp_path, said):
    app = types.SimpleNamespace(sequence=SequenceCounter())
    clock = OnboardTime(str(tmp_path / "onboard_time.json"), time.time)
    link = ModuleLink([c.path for c in cables], app, clock, period=0.5, say=said.append)
    return link, app, clock


def test_context_and_time_across_a_restart(cables, tmp_path):
    cables[1].module.app.rtc.set_day_ms(DS3231_DAY, 3600000)  # 01:00 UTC (days since 1958)
    said = []
    link, app, clock = start(cables, tmp_path, said)
    ctx = link.restore()
    assert "module link: no context kept, a first start" in said
    assert "module link: onboard time from the DS3231" in said
    assert int(clock.now() // 86400) == DS3231_DAY  # the module's clock, not the host's
    assert ctx.boots == 1
    for _ in range(5):
        app.sequence.next(42)
    assert link.save() == 2  # both controllers keep it
    assert said[-1] == "module link: context kept by 2 of 2 controllers (TM counts of APID 42)"
    link.save()
    assert said[-1] == "module link: context kept by 2 of 2 controllers (TM counts of APID 42)"
    assert said.count(said[-1]) == 1  # logged once, not per save
    app.sequence.next(7)
    link.save()  # a save that carries another APID's counts is said
    assert said[-1] == "module link: context kept by 2 of 2 controllers (TM counts of APIDs 7, 42)"
    assert said.count(said[-1]) == 1
    link.close()

    said = []
    link, app, clock = start(cables, tmp_path, said)  # the OBC starts again
    ctx = link.restore()
    assert app.sequence.peek(42) == 5  # its TM counts go on
    assert ctx.boots == 2 and ctx.saves == 3
    assert any(s.startswith("module link: context restored") for s in said)
    link.close()


def test_one_silent_controller_costs_only_its_timeout(cables, tmp_path):
    cables[0].silent = True  # in reset, or its UART cut
    said = []
    link, app, clock = start(cables, tmp_path, said)
    link.restore(timeout=0.3)
    assert link.save(timeout=0.3) == 1
    assert said[-1] == "module link: context kept by 1 of 2 controllers"
    link.close()
