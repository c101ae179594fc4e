"""The processor time of a process tree, by process, over real seconds (Linux ``/proc``).

``sample(pids, seconds)`` reads each process's user and system time (``/proc/PID/stat``) and
the machine's uptime (``/proc/uptime``, which time acceleration does not fake) at the start
and the end, and returns ``{pid: (name, percent of one core)}``. Threads count with their
process. ``tree(pid)`` is the process and every process below it.
"""

import os

from obsw_sim.reconfig import descendants

TICKS = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100


def _uptime():
    with open("/proc/uptime") as f:
        return float(f.read().split()[0])


def _stat(pid):
    """(name, user + system ticks) of a process, or None once it is gone."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            text = f.read()
        with open("/proc/%d/cmdline" % pid, "rb") as f:
            argv = [a.decode(errors="replace") for a in f.read().split(b"\0") if a]
    except OSError:
        return None
    fields = text[text.rindex(")") + 2 :].split()
    return _name(argv), int(fields[11]) + int(fields[12])


def _name(argv):
    """A short name: the module or script a Python or MicroPython process runs."""
    for i, a in enumerate(argv):
        if a == "-m" and i + 1 < len(argv):
            rest = [x for x in argv[i + 2 :] if not x.startswith("/")][:2]
            return " ".join([argv[i + 1]] + rest)
    for a in argv[1:]:
        if a.endswith(".py"):
            return os.path.basename(a)
    return os.path.basename(argv[0]) if argv else "?"


def tree(pid):
    """``pid`` and the pids of its children, grandchildren, ..."""
    return [pid] + descendants(pid)


def sample(pids, seconds, wait):
    """{pid: (name, % of one core)} over ``seconds`` real seconds; ``wait(s)`` waits ``s``
    real seconds (under time acceleration a sleep of ``s`` times the speed)."""
    before = {p: _stat(p) for p in pids}
    t0 = _uptime()
    wait(seconds)
    took = _uptime() - t0
    out = {}
    for p, b in before.items():
        a = _stat(p)
        if a is None or b is None:
            continue
        out[p] = (a[0], 100.0 * (a[1] - b[1]) / TICKS / took)
    return out
