"""Find Java and the Yamcs jars, check an instance folder with Yamcs, and run Yamcs on it.

Yamcs 5.12.8 comes from PyPI (``fprime-yamcs-bundle``: the server and web jars) and runs on
Java 17 (Debian ``openjdk-17-jre-headless``); both are development dependencies used as an
external program. ``missing()`` says in one line what is absent and how to get it.
"""

import json
import os
import shutil
import subprocess
import sys
import time
import urllib.error
import urllib.request

VERSION = "5.12.8"
JAVA_HINT = "apt-get install openjdk-17-jre-headless"
BUNDLE_HINT = "pip install fprime-yamcs-bundle==5.12.8.0 (tools/bootstrap installs it)"


class YamcsUnavailable(RuntimeError):
    """Java or the Yamcs jars are not installed."""


def java():
    """The java executable, or None."""
    home = os.environ.get("JAVA_HOME")
    if home and os.path.exists(os.path.join(home, "bin", "java")):
        return os.path.join(home, "bin", "java")
    return shutil.which("java")


def lib_dir():
    """The folder of the Yamcs jars (``fprime_yamcs_bundle.LIB_DIR``), or None."""
    try:
        import fprime_yamcs_bundle
    except ImportError:
        return None
    return str(fprime_yamcs_bundle.LIB_DIR)


def missing():
    """None when Yamcs can run here, else one line saying what is missing and how to get it."""
    if java() is None:
        return "Yamcs needs Java 17, which is not installed: %s" % JAVA_HINT
    if lib_dir() is None:
        return "Yamcs is not installed: %s" % BUNDLE_HINT
    return None


def command(folder, *extra):
    """The command line that runs Yamcs on instance ``folder`` (its working directory)."""
    problem = missing()
    if problem:
        raise YamcsUnavailable(problem)
    return [
        java(),
        "-Xmx512m",
        "-Djava.util.logging.manager=org.yamcs.logging.YamcsLogManager",
        "-Djava.net.preferIPv4Stack=true",
        "-cp",
        os.path.join(lib_dir(), "*"),
        "org.yamcs.YamcsServer",
        "--etc-dir",
        os.path.join(folder, "etc"),
        "--data-dir",
        os.path.join(folder, "data"),
    ] + list(extra)


GUARD_SOURCE = os.path.join(os.path.dirname(__file__), "loopback_bind.c")


def loopback_guard(folder):
    """Environment that keeps every socket Yamcs binds on loopback (``loopback_bind.c``
    preloaded; built with the C compiler into ``folder``), or None without a compiler."""
    cc = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc")
    if cc is None:
        return None
    lib = os.path.join(folder, "loopback_bind.so")
    if not os.path.exists(lib):
        p = subprocess.run(
            [cc, "-shared", "-fPIC", "-O2", "-o", lib, GUARD_SOURCE, "-ldl"],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
        )
        if p.returncode != 0:
            return None
    return {"LD_PRELOAD": lib}


def binds_any_address(folder):
    """True if the configuration has a link that binds all interfaces (Yamcs' UDP TM links)."""
    etc = os.path.join(folder, "etc")
    for name in os.listdir(etc):
        if name.startswith("yamcs.") and name.endswith(".yaml"):
            with open(os.path.join(etc, name)) as f:
                text = f.read()
            if "UdpTmFrameLink" in text or "UdpTmDataLink" in text:
                return True
    return False


def check(folder, timeout=120):
    """Run Yamcs' own validation (``--check``) on the folder; returns (ok, output)."""
    p = subprocess.run(
        command(folder, "--check"),
        cwd=folder,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=timeout,
    )
    return p.returncode == 0, p.stdout


def _die_with_parent():
    """In the child, before exec: end Yamcs when the process that started it ends (Linux), so
    a killed test run leaves no 400 MB JVM behind."""
    try:
        import ctypes
        import signal

        ctypes.CDLL(None).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


class Yamcs:
    """A Yamcs server process on an instance folder, with its log in ``folder/yamcs.log``.

    Start it from a thread that lives as long as it should run (the main thread): on Linux it
    ends with the thread that started it. ``address``: the address its web interface and API
    listen on, as its ``yamcs.yaml`` says (loopback unless operators reach it from elsewhere;
    an "any" address is kept on loopback, see ``loopback_guard``)."""

    def __init__(self, folder, http_port, instance="obsw", env=None, address="127.0.0.1"):
        self.folder = folder
        self.address = address  # where its web interface and API listen
        self.http_port = http_port
        self.instance = instance
        self.env = env
        self.process = None
        self.log_path = os.path.join(folder, "yamcs.log")

    @property
    def url(self):
        return "http://%s:%d" % (self.address, self.http_port)

    def start(self, timeout=60.0):
        """Start Yamcs and return once the instance runs (TimeoutError, with the log's tail,
        if it does not within ``timeout`` s or the process ends)."""
        env = dict(os.environ)
        guard = loopback_guard(self.folder)
        if guard is None and binds_any_address(self.folder):
            raise YamcsUnavailable(
                "this configuration's UDP TM link would listen on every interface; keeping it "
                "on loopback needs a C compiler (apt-get install gcc)"
            )
        env.update(guard or {})
        env.update(self.env or {})
        log = open(self.log_path, "w")
        self.process = subprocess.Popen(
            command(self.folder),
            cwd=self.folder,
            stdout=log,
            stderr=subprocess.STDOUT,
            env=env,
            preexec_fn=_die_with_parent if sys.platform.startswith("linux") else None,
        )
        log.close()
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if self.process.poll() is not None:
                raise TimeoutError(
                    "Yamcs exited with %s:\n%s" % (self.process.returncode, self.tail())
                )
            if self.state() == "RUNNING":
                return self
            time.sleep(0.2)  # polling an external process's HTTP API, not waiting for our code
        self.stop()
        raise TimeoutError("Yamcs did not start within %ss:\n%s" % (timeout, self.tail()))

    def state(self):
        try:
            with urllib.request.urlopen(
                "%s/api/instances/%s" % (self.url, self.instance), timeout=2
            ) as r:
                return json.load(r).get("state")
        except (urllib.error.URLError, OSError, ValueError):
            return None

    def tail(self, n=40):
        try:
            with open(self.log_path) as f:
                return "".join(f.readlines()[-n:])
        except OSError:
            return ""

    def stop(self, timeout=20.0):
        p = self.process
        if p is None:
            return
        if p.poll() is None:
            p.terminate()
            try:
                p.wait(timeout)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        self.process = None

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()
