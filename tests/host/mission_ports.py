"""A port base of a test's own for a mission's processes: with ``OBSW_PORT_BASE`` set to it,
every port of the mission moves (base + APID and the rest), so a test never meets an OBC
already serving on the default ports nor another test run at the same time.

``free_base(offsets)`` returns a base B with B + each offset free on 127.0.0.1 (UDP and TCP);
``free_port()`` one port the kernel picks, for a process that binds it at once; ``stop(proc)``
ends a process a test or a benchmark started (tools/bench/measure.py takes both from here).
A base is free when it is checked, not yet when the mission's processes bind it: so the bases
lie below the kernel's ephemeral ports (32768 and up, where the tests that take a port the
kernel picks get theirs), each pytest worker searches bases of its own (every Nth of N
workers), and the search starts at a place of this process's own, so that runs at the same
time (another checkout's tests) do not all take the first free base and collide on it.
"""

import os
import signal
import socket
import subprocess

SAMPLE = (10, 100, 101)  # the sample spacecraft: PUS (APID 10), CFDP onboard and ground


def _free(port):
    for kind in (socket.SOCK_DGRAM, socket.SOCK_STREAM):
        s = socket.socket(socket.AF_INET, kind)
        try:
            s.bind(("127.0.0.1", port))
        except OSError:
            return False
        finally:
            s.close()
    return True


def free_port(kind=socket.SOCK_DGRAM):
    """A port of 127.0.0.1 that the kernel picks and nothing holds now."""
    s = socket.socket(socket.AF_INET, kind)
    try:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]
    finally:
        s.close()


def stop(proc, grace=10.0):
    """End ``proc``: SIGTERM, then SIGKILL if it still runs after ``grace`` seconds (at once
    with 0); its output pipe closed."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM if grace else signal.SIGKILL)
        try:
            proc.wait(grace or 10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(10)
    if proc.stdout is not None:
        proc.stdout.close()


def free_base(offsets=SAMPLE, low=10000, high=32000, step=337):
    """A port base B with B + every offset free."""
    bases = list(range(low, high - max(offsets), step))
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0")[2:]
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    bases = bases[int(worker or 0) % workers :: workers]
    start = os.getpid() % len(bases)
    for base in bases[start:] + bases[:start]:
        if all(_free(base + offset) for offset in offsets):
            return base
    raise RuntimeError("no free port base for offsets %s" % (offsets,))
