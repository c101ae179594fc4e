"""Memory snapshots of the OBC's processes on request, for the soak benchmark and for a hunt.

With ``$OBSW_TRACEMALLOC`` naming a folder, each process (the platform manager and every unit
process) traces its allocations from its start (``tracemalloc``, a few frames deep) and, on
SIGUSR2, writes a snapshot there as ``NAME-PID-N.snap`` (``$OBSW_TRACEMALLOC_FRAMES`` sets
the frames kept, default 4); with ``$OBSW_TRACEMALLOC_PERIOD`` (seconds) it also appends the
memory it traces now, and tracemalloc's own, to ``NAME-PID.traced`` that often. Without it
nothing is traced and the signal keeps its default. ``growers(old, new)`` names the lines
whose memory grew most between two snapshots of one process.
"""

import os
import signal

ENV = "OBSW_TRACEMALLOC"
FRAMES = 4  # deep enough to tell the caller that keeps a list from the list's append


def install(name):
    """Trace this process's allocations when ``$OBSW_TRACEMALLOC`` is set (see the module
    text); returns the folder, or None."""
    folder = os.environ.get(ENV)
    if not folder or not hasattr(signal, "SIGUSR2"):
        return None
    import tracemalloc

    os.makedirs(folder, exist_ok=True)
    tracemalloc.start(int(os.environ.get(ENV + "_FRAMES") or FRAMES))
    count = [0]
    safe = "".join(c if c.isalnum() or c in "-_." else "_" for c in name)

    def dump(signum, frame):
        count[0] += 1
        path = os.path.join(folder, "%s-%d-%d.snap" % (safe, os.getpid(), count[0]))
        tracemalloc.take_snapshot().dump(path + ".part")
        os.replace(path + ".part", path)  # a reader never sees half a snapshot

    signal.signal(signal.SIGUSR2, dump)
    period = float(os.environ.get(ENV + "_PERIOD") or 0)
    if period > 0:
        import threading

        path = os.path.join(folder, "%s-%d.traced" % (safe, os.getpid()))
        threading.Thread(target=_record, args=(path, period), daemon=True).start()
    return folder


def _record(path, period):
    """Append 'unix-time traced-bytes tracemalloc-bytes' to ``path`` every ``period`` seconds
    (cheap: no snapshot, so the process's memory does not jump as it does when one is taken).
    The third figure is tracemalloc's own memory, which grows with every new call path it sees
    and is part of the process's RSS though the process does not hold it."""
    import time
    import tracemalloc

    while True:
        with open(path, "a") as f:
            f.write("%.1f %d %d\n" % (time.time(), tracemalloc.get_traced_memory()[0],
                                       tracemalloc.get_tracemalloc_memory()))  # fmt: skip
        time.sleep(period)


def growers(old_path, new_path, top=10):
    """The ``top`` source lines whose allocations grew most from snapshot ``old_path`` to
    ``new_path``: (bytes grown, blocks grown, "file:line") each, largest first."""
    import tracemalloc

    old = tracemalloc.Snapshot.load(old_path)
    new = tracemalloc.Snapshot.load(new_path)
    keep = [tracemalloc.Filter(False, tracemalloc.__file__)]
    stats = new.filter_traces(keep).compare_to(old.filter_traces(keep), "lineno")
    out = []
    for s in sorted(stats, key=lambda s: -s.size_diff)[:top]:
        if s.size_diff <= 0:
            break
        f = s.traceback[0]
        out.append((s.size_diff, s.count_diff, "%s:%d" % (_short(f.filename), f.lineno)))
    return out


def _short(path):
    for marker in ("/obsw_host/", "/obsw_sim/", "/obsw/", "/lib/python"):
        i = path.rfind(marker)
        if i >= 0:
            return path[i + 1 :]
    return path
