"""Heap figures on a board (frozen into the QEMU board image, so its own code takes no heap).

reconfig(passes): the reconfiguration application from its frozen entry point for a long
simulated session on the in-memory hardware layer: SpaceCAN traffic from an OBC master
(heartbeats, SYNC, UTC, function calls and parameter requests), an essential TC (an HPC in
CLTUs) every 1000 passes, and safeguard writes (the OBC's context, the state record).
pluto(path, spec): a PLUTO procedure loaded and run to its end against a simulated system.

Figures (bytes): "free" is gc.mem_free() after gc.collect(); the low-water mark is the least of
the samples taken every 100 passes; flat: after warm-up, the peak of the live heap in the second
half of the session is at most 512 bytes above that of the first half.
"""

import gc
import json

import micropython

FLAT_BYTES = 512


def _free():
    gc.collect()
    return gc.mem_free()


def _total():
    gc.collect()
    return gc.mem_free() + gc.mem_alloc()


def reconfig(passes=20000, sample=100):
    total = _total()
    free0 = _free()
    import obsw.reconfig.app as app_module  # the image's entry point, frozen

    free_import = _free()
    from obsw.frames import cltu, tc
    from obsw.reconfig.essential import HPC_POWER_CYCLE, Hpc
    from obsw.reconfig.models import ModelHal
    from obsw.reconfig.node import NODE_NOMINAL, definition
    from obsw.spacecan.controller import Controller

    hal = ModelHal(rtc_seconds=21550 * 86400, eeprom_size=2048)
    ctrl = Controller(heartbeat_period=0.5)
    ctrl.add_node(NODE_NOMINAL, definition(NODE_NOMINAL))
    ctrl.start(0.0)
    seg = tc.Segment(63, Hpc(HPC_POWER_CYCLE, (2, 100)).packet()).pack()
    hpc = cltu.encode(tc.TcFrame(0x42, 0, seg, 0, bypass=True).pack())
    del seg
    free_rig = _free()
    app = app_module.ReconfigApp(hal)
    live = []
    low = free_rig
    calls = 0
    for i in range(passes):
        now = hal.now / 1000000
        for bus, can_id, data in ctrl.take_frames():
            hal.can_rx[bus].append((can_id, data))
        hal.idle(app.step())
        for bus, can_id, data in hal.can_tx:
            ctrl.receive(bus, can_id, data, now)
        hal.can_tx = []
        hal.uart_tx[0] = bytearray()
        ctrl.poll(now)
        ctrl.take_events()  # the OBC side reads its events
        k = i % 1000
        if k == 500:
            hal.uart_rx[0].extend(hpc)
        elif k == 100:
            ctrl.call_function(NODE_NOMINAL, 6, now=now, args={1: i})  # store the context
            calls += 1
        elif k == 300:
            ctrl.call_function(NODE_NOMINAL, 1, now=now, args={1: i & 0xFF0})  # state bits
            calls += 1
        elif k == 700:
            ctrl.request_parameters(NODE_NOMINAL, [1, 7], now)
        elif k == 900:
            ctrl.send_utc(21550, (i * 10) % 86400000, now=now)
        if i % sample == sample - 1:
            f = _free()
            if f < low:
                low = f
            live.append(free_rig - f)
    warm = live[len(live) // 5 :]
    half = len(warm) // 2
    spread = max(warm) - min(warm)
    growth = max(warm[half:]) - max(warm[:half])
    c = app.counters
    print("heap total %d" % total)
    print("heap after import %d" % (free0 - free_import))
    print("heap of the application %d" % max(warm))
    print("heap low-water free %d (%.1f%%)" % (low, 100.0 * low / total))
    flat = growth <= FLAT_BYTES
    print(
        "heap flat %s (peak grew %d bytes from the first to the second half; spread %d)"
        % ("yes" if flat else "no", growth, spread)
    )
    print(
        "passes %d errors %d hpcs %d saves %d calls %d wdt-kicks %d"
        % (
            c["steps"],
            c["loop_errors"],
            app.essential.counters["hpcs"],
            c["saves"],
            calls,
            hal.kick_count,
        )
    )
    micropython.mem_info()
    ok = c["loop_errors"] == 0 and flat and app.essential.counters["hpcs"] > 0
    return ok, low, total


def pluto(path, spec_path=None):
    from obsw.pluto.interp import Procedure, load
    from obsw.pluto.system import SimulatedSystem, run_virtual

    total = _total()
    free0 = _free()
    with open(path) as f:
        src = f.read()
    spec = {}
    if spec_path:
        with open(spec_path) as f:
            spec = json.load(f)
    sim = SimulatedSystem(spec)
    free_loaded = _free()
    proc = Procedure(load(src, sim), sim)
    del src
    free_compiled = _free()
    proc.start(sim.now)
    end = run_virtual(proc, sim)
    free_end = _free()
    lines = len(sim.logs) + len(sim.user_messages)
    print("pluto total %d" % total)
    print("pluto procedure compiled %d" % (free_loaded - free_compiled))
    print("pluto heap after the run %d" % (free0 - free_end))
    print("pluto free after the run %d (%.1f%%)" % (free_end, 100.0 * free_end / total))
    print(
        "pluto %s after %d s, %d statements, %d messages"
        % (proc.outcome, end - sim.start, proc.statements, lines)
    )
    return proc.outcome == "confirmed", free_end, total
