#!/usr/bin/env python3
"""The Raspberry Pi path on ARM, as far as one x86 machine goes: a Debian bookworm arm64 root
file system (Raspberry Pi OS is Debian bookworm for arm64) built from Debian's packages with
debootstrap, run under QEMU user emulation (qemu-user-static through binfmt_misc), with obsw
installed there by pip from PyPI's aarch64 wheels as docs/raspberry-pi.md installs it. Then, in
that root:

  1. `obsw mission check` of the Pi example mission (boards/raspberry-pi) with its key file;
  2. `systemd-analyze verify` of the unit `obsw obc install-service` writes for it;
  3. `obsw obc serve` of the Pi mission with its hardware replaced by stand-ins (virtual CAN
     with simulated nodes, pseudo-terminal UARTs, no watchdog device, no module link), answering
     `obsw ground ping`;
  4. the core tests (tests/core) on the arm64 CPython.

Needs root, debootstrap and qemu-user-static (Debian packages); prints why and exits 0 with a
skip line when they are missing. The root file system is kept in build/arm64/ and reused
(`--fresh` builds it again). See docs/hardware.md.

    sudo tools/arm64.py [--fresh] [--no-tests] [--record]
"""

import argparse
import functools
import json
import os
import shutil
import socket
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PACKAGES = "python3,python3-venv,python3-pip,ca-certificates,systemd"
MIRROR = "http://deb.debian.org/debian"
SRC = "/opt/src/obsw"  # the checkout inside the root file system
VENV = "/opt/obsw"  # where docs/raspberry-pi.md installs obsw
BINFMT = "/proc/sys/fs/binfmt_misc"


class Stage:
    """Runs the steps, each timed, and keeps the tally."""

    def __init__(self):
        self.passed = self.failed = 0
        self.t0 = time.monotonic()
        self.lines = []

    def say(self, line):
        self.lines.append(line)
        print(line, flush=True)

    def step(self, title, fn):
        t = time.monotonic()
        try:
            detail = fn()
        except Exception as e:  # a step that fails says why; the others still run
            self.failed += 1
            self.say("FAIL %-50s %7.1f s  %s" % (title, time.monotonic() - t, e))
            return None
        self.passed += 1
        self.say("ok   %-50s %7.1f s  %s" % (title, time.monotonic() - t, detail or ""))
        return detail


def why_not():
    """Why emulation cannot run here, or None."""
    if os.geteuid() != 0:
        return "needs root (debootstrap, chroot)"
    for tool in ("debootstrap", "qemu-aarch64-static"):
        if not shutil.which(tool):
            return "needs %s (apt-get install debootstrap qemu-user-static)" % tool
    if not os.path.exists(BINFMT + "/register"):
        subprocess.run(["mount", "-t", "binfmt_misc", "binfmt_misc", BINFMT], capture_output=True)
    if not os.path.exists(BINFMT + "/qemu-aarch64") and shutil.which("update-binfmts"):
        subprocess.run(["update-binfmts", "--enable", "qemu-aarch64"], capture_output=True)
    if not os.path.exists(BINFMT + "/qemu-aarch64"):
        return "binfmt_misc has no qemu-aarch64 entry (the kernel cannot run arm64 programs)"
    return None


def run(cmd, **kw):
    res = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if res.returncode != 0:
        tail = (res.stdout + res.stderr).strip().splitlines()[-5:]
        what = " ".join(cmd[:4])
        raise RuntimeError("%s: exit %d: %s" % (what, res.returncode, " | ".join(tail)))
    return res.stdout


class Rootfs:
    def __init__(self, path):
        self.path = path
        self.mounts = []

    def chroot(self, script, timeout=1800, check=True):
        """Run a shell script in the arm64 root; its output."""
        env = {"PATH": VENV + "/bin:/usr/sbin:/usr/bin:/sbin:/bin", "HOME": "/root",
               "LANG": "C.UTF-8", "PIP_DISABLE_PIP_VERSION_CHECK": "1"}  # fmt: skip
        for name in ("OBSW_PORT_BASE", "http_proxy", "https_proxy", "PIP_INDEX_URL"):
            if os.environ.get(name):
                env[name] = os.environ[name]
        cmd = [shutil.which("chroot"), self.path, "/bin/sh", "-c", script]
        if not check:
            return subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout)
        return run(cmd, env=env, timeout=timeout)

    def mount(self):
        for kind, target in (("proc", "proc"), ("devpts", "dev/pts"), ("tmpfs", "dev/shm")):
            where = os.path.join(self.path, target)
            os.makedirs(where, exist_ok=True)
            opts = ["-o", "gid=5,mode=620,ptmxmode=666,newinstance"] if kind == "devpts" else []
            run(["mount", "-t", kind] + opts + [kind, where])
            self.mounts.append(where)
        ptmx = os.path.join(self.path, "dev/ptmx")
        if os.path.lexists(ptmx):
            os.remove(ptmx)
        os.symlink("pts/ptmx", ptmx)

    def unmount(self):
        for where in reversed(self.mounts):
            subprocess.run(["umount", "-l", where], capture_output=True)
        self.mounts = []


def bootstrap(rootfs, fresh):
    if fresh and os.path.isdir(rootfs.path):
        shutil.rmtree(rootfs.path)
    if os.path.exists(os.path.join(rootfs.path, "usr/bin/python3")):
        return "reused %s" % os.path.relpath(rootfs.path, ROOT)
    os.makedirs(rootfs.path, exist_ok=True)
    run(["debootstrap", "--arch=arm64", "--variant=minbase", "--include=" + PACKAGES,
         "bookworm", rootfs.path, MIRROR], timeout=3600)  # fmt: skip
    return "debian bookworm arm64, %s" % rootfs.chroot("uname -m; python3 --version").split()


def install(rootfs):
    """The checkout copied in, then `pip install` into /opt/obsw as the Pi guide does."""
    dest = rootfs.path + SRC
    if os.path.isdir(dest):
        shutil.rmtree(dest)
    os.makedirs(dest)
    files = run(["git", "-C", ROOT, "ls-files", "-z", "-co", "--exclude-standard"])
    tar = subprocess.Popen(["tar", "-C", ROOT, "--null", "-T", "-", "-cf", "-"],
                           stdin=subprocess.PIPE, stdout=subprocess.PIPE)  # fmt: skip
    untar = subprocess.Popen(["tar", "-C", dest, "-xf", "-"], stdin=tar.stdout)
    tar.stdin.write(files.encode())
    tar.stdin.close()
    if untar.wait() != 0 or tar.wait() != 0:
        raise RuntimeError("copying the checkout failed")
    certs = "/etc/ssl/certs/ca-certificates.crt"  # the host's trust (a proxy's CA too)
    if os.path.exists(certs):
        shutil.copy(certs, rootfs.path + certs)
    rootfs.chroot("[ -x %s/bin/pip ] || python3 -m venv %s" % (VENV, VENV))
    rootfs.chroot("%s/bin/pip install -q %s pytest hypothesis" % (VENV, SRC))  # + the tests
    machine = "import platform; print(platform.machine())"
    out = rootfs.chroot("%s/bin/obsw --version; %s/bin/python -c '%s'" % (VENV, VENV, machine))
    return ", ".join(out.split())


def pi_mission(rootfs):
    """boards/raspberry-pi installed as /etc/obsw, its key file made with obsw frames keygen."""
    etc = rootfs.path + "/etc/obsw"
    if os.path.isdir(etc):
        shutil.rmtree(etc)
    shutil.copytree(os.path.join(ROOT, "boards", "raspberry-pi"), etc)
    rootfs.chroot("obsw frames keygen /etc/obsw/tc.keys >/dev/null")
    return rootfs.chroot("obsw mission check /etc/obsw").strip()


def unit(rootfs):
    rootfs.chroot("id obsw >/dev/null 2>&1 || useradd --system --home-dir /var/lib/obsw obsw")
    rootfs.chroot("obsw obc install-service /etc/obsw >/dev/null")
    rootfs.chroot("systemd-analyze verify /etc/systemd/system/obsw.service")
    return "systemd-analyze verify: no complaint"


def stand_ins(rootfs):
    """The Pi mission with its hardware replaced by what an emulated root has."""
    with open(rootfs.path + "/etc/obsw/mission.json") as f:
        mission = json.load(f)
    mission.pop("$schema", None)
    mission["state"] = "/var/lib/obsw-emulated"
    mission["spacecan"].update(interface="virtual", channels=["can-a", "can-b"], simulate=True)
    mission["frames"].update(uart_a="pty", uart_b="pty")
    mission["platform"].update(watchdog=None, module_uarts=None)
    folder = rootfs.path + "/etc/obsw-emulated"
    if os.path.isdir(folder):
        shutil.rmtree(folder)
    shutil.copytree(rootfs.path + "/etc/obsw", folder)
    with open(folder + "/mission.json", "w") as f:
        json.dump(mission, f, indent=2)


def free_base():
    """A port base with 200 free UDP ports above it (the mission's ports move with it)."""
    for _ in range(50):
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        s.bind(("127.0.0.1", 0))
        base = s.getsockname()[1] // 10 * 10
        s.close()
        if 20000 <= base <= 60000:
            return base
    return 41000


def serve_and_ping(rootfs):
    stand_ins(rootfs)
    os.environ["OBSW_PORT_BASE"] = str(free_base())
    rootfs.chroot("rm -rf /var/lib/obsw-emulated")
    server = subprocess.Popen(
        [shutil.which("chroot"), rootfs.path, "/bin/sh", "-c",
         "exec %s/bin/obsw obc serve /etc/obsw-emulated" % VENV],
        env={"PATH": VENV + "/bin:/usr/bin:/bin", "HOME": "/root", "LANG": "C.UTF-8",
             "OBSW_PORT_BASE": os.environ["OBSW_PORT_BASE"]},
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True,
    )  # fmt: skip
    try:
        t = time.monotonic()
        deadline = t + 300
        answer = None
        while time.monotonic() < deadline and server.poll() is None:
            res = rootfs.chroot("obsw ground --mission /etc/obsw-emulated ping", timeout=120,
                                check=False)  # fmt: skip
            if res.returncode == 0:
                answer = res.stdout.strip().splitlines()[-1]
                break
        if answer is None:
            raise RuntimeError("no answer to ping (serve %s)" % (
                "ended" if server.poll() is not None else "still silent"))  # fmt: skip
        return "answered in %.1f s after start: %s" % (time.monotonic() - t, answer)
    finally:
        os.killpg(server.pid, 15)
        try:
            server.wait(30)
        except subprocess.TimeoutExpired:
            os.killpg(server.pid, 9)
            server.wait()


def core_tests(rootfs):
    res = rootfs.chroot("cd %s && %s/bin/python -m pytest -q -o addopts= -p no:cacheprovider "
                        "tests/core" % (SRC, VENV), timeout=3600, check=False)  # fmt: skip
    lines = (res.stdout + res.stderr).strip().splitlines()
    summary = [x for x in lines if " passed" in x or " failed" in x or " error" in x]
    if res.returncode or not summary:
        raise RuntimeError("exit %d: %s" % (res.returncode, " | ".join((summary or lines)[-3:])))
    return summary[-1]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rootfs", default=os.path.join(ROOT, "build", "arm64", "rootfs"))
    ap.add_argument("--fresh", action="store_true", help="build the root file system again")
    ap.add_argument("--no-tests", action="store_true", help="skip the core tests (the longest)")
    ap.add_argument("--record", action="store_true", help="write docs/arm64-last-run.txt")
    args = ap.parse_args(argv)
    reason = why_not()
    if reason:
        print("arm64 emulation not available here: %s" % reason)
        print("0 passed, 0 failed, 1 skipped")
        return 0
    stage = Stage()
    rootfs = Rootfs(os.path.abspath(args.rootfs))
    steps = [
        ("pip install obsw (aarch64 wheels)", install),
        ("obsw mission check boards/raspberry-pi", pi_mission),
        ("obsw obc install-service, systemd-analyze verify", unit),
        ("obsw obc serve (stand-ins), obsw ground ping", serve_and_ping),
    ]
    if not args.no_tests:
        steps.append(("the core tests on arm64 CPython", core_tests))
    build = functools.partial(bootstrap, rootfs, args.fresh)
    built = stage.step("debootstrap a Debian bookworm arm64 root", build)
    if built is not None:
        rootfs.mount()
        try:
            for title, fn in steps:
                if stage.step(title, functools.partial(fn, rootfs)) is None and fn is install:
                    break
        finally:
            rootfs.unmount()
    stage.say("arm64: %.0f s in all" % (time.monotonic() - stage.t0))
    if args.record:
        with open(os.path.join(ROOT, "docs", "arm64-last-run.txt"), "w") as f:
            f.write("    " + "\n    ".join(stage.lines) + "\n")
    print("%d passed, %d failed" % (stage.passed, stage.failed))
    return 1 if stage.failed else 0


if __name__ == "__main__":
    sys.exit(main())
