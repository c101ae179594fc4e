"""Time acceleration of a whole process tree with Debian's libfaketime.

``environment(speed, offset)`` is what a process needs in its environment so that it and
every process it starts (the OBC's platform manager and its processes, the reconfiguration
controllers, the rig's own threads) see one clock, ``offset`` seconds from the real one at
the start and running ``speed`` times faster: ``LD_PRELOAD`` of libfaketime (``apt-get install
faketime``; ``tools/bootstrap`` installs it) and of ``sem_clockwait.c`` (built here with the
C compiler, once per machine: libfaketime 0.9.10 leaves the call Python's locks use with a
timeout unfaked), ``FAKETIME="+OFFSET xSPEED"`` and ``FAKETIME_DONT_RESET=1`` (children go
on with their parent's clock rather than starting it again). Wall clock, monotonic clock,
sleeps, ``select``/``poll``/``epoll`` timeouts and lock timeouts all follow it, so onboard
time, service 11's releases, CFDP's and COP-1's timers, heartbeats and watchdogs run at the
same speed in every process. ``active()`` says whether this process runs under it.
"""

import glob
import os
import subprocess
import tempfile

LIBFAKETIME = ("/usr/lib/x86_64-linux-gnu/faketime/libfaketime.so.1",
               "/usr/lib/aarch64-linux-gnu/faketime/libfaketime.so.1",
               "/usr/lib/faketime/libfaketime.so.1")  # fmt: skip
SOURCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "sem_clockwait.c")


class FaketimeError(RuntimeError):
    """libfaketime or a C compiler is missing; the message says what to install."""


def library():
    for path in LIBFAKETIME:
        if os.path.exists(path):
            return path
    found = glob.glob("/usr/lib/*/faketime/libfaketime.so.1")
    if found:
        return found[0]
    raise FaketimeError("no libfaketime; expected Debian's faketime (apt-get install faketime)")


def shim():
    """The built ``sem_clockwait`` shim (rebuilt when its source is newer)."""
    cache = os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.join(
        os.path.expanduser("~"), ".cache"), "obsw")  # fmt: skip
    os.makedirs(cache, exist_ok=True)
    out = os.path.join(cache, "sem_clockwait.so")
    if os.path.exists(out) and os.path.getmtime(out) >= os.path.getmtime(SOURCE):
        return out
    part = tempfile.mktemp(suffix=".so", dir=cache)
    cc = os.environ.get("CC", "cc")
    try:
        subprocess.run([cc, "-O2", "-shared", "-fPIC", "-o", part, SOURCE, "-ldl"], check=True,
                       capture_output=True)  # fmt: skip
    except (OSError, subprocess.CalledProcessError) as e:
        raise FaketimeError("could not build %s with %s: %s; expected a C compiler (gcc)" % (
            SOURCE, cc, getattr(e, "stderr", b"") or e)) from None  # fmt: skip
    os.replace(part, out)
    return out


def environment(speed, offset=0.0):
    """The variables that run a process (and its children) ``speed`` times faster."""
    if speed <= 0:
        raise ValueError("speed %r; expected a positive factor" % (speed,))
    return {
        "LD_PRELOAD": "%s %s" % (shim(), library()),
        "FAKETIME": "%+d x%g" % (int(offset), speed),
        "FAKETIME_DONT_RESET": "1",
        "OBSW_FAKETIME": "%g" % speed,
    }


def active():
    """The speed this process runs at under libfaketime, or None."""
    v = os.environ.get("OBSW_FAKETIME")
    return float(v) if v and "libfaketime" in os.environ.get("LD_PRELOAD", "") else None


def clean(pid):
    """Remove the shared memory libfaketime left for process ``pid`` (killed processes leave
    theirs; a later process with the same pid would refuse to start)."""
    for path in glob.glob("/dev/shm/faketime_shm_%d" % pid) + glob.glob(
            "/dev/shm/sem.faketime_sem_%d" % pid):  # fmt: skip
        try:
            os.remove(path)
        except OSError:
            pass
