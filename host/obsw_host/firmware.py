"""MicroPython images from the pinned source: mpy-cross, the Pyboard firmware, a unix port and a
QEMU Cortex-M board with the core frozen; and the QEMU board itself (start, pty, stop).

firmware.py build [all|mpy-cross|pyboard|unix|qemu]   build (cached in build/fw/)
firmware.py qemu [QEMU_ARG...]                         start the QEMU board, print its pty, wait
firmware.py sizes                                      flash and frozen-bytecode table (a stage)

The source: --micropython PATH or $OBSW_MICROPYTHON_SRC (the release archive, a folder holding
it, or an unpacked tree), else the archive in ``shared/micropython`` next to the repository,
else the tag's git tree fetched once into build/fw (checked against the tag's commit; the
submodules the ports need come at the commits that tree pins). Without any of them (no network)
it says in one line what to provide.
Every build is skipped when its inputs (manifests, frozen modules, board files, options) are
unchanged. Python API: ``source()``, ``build_pyboard()``, ``build_unix()``, ``build_qemu()``,
``Qemu(elf, extra_args)`` (``.pty``, ``.close()``), ``pyboard_heap()``.
"""

import hashlib
import os
import pathlib
import re
import select
import shutil
import subprocess
import sys
import tarfile
import time

from obsw_host.mpy import BUDGETS, Manifest, compile_one, missing_from_manifest

ROOT = pathlib.Path(__file__).resolve().parents[2]  # the repository: boards/, manifests/

BUILD = ROOT / "build" / "fw"
VERSION = "1.28.0"
ARCHIVE = "micropython-%s-src.tar.gz" % VERSION
ARCHIVE_SHA256 = "2baa9f8f3aa5fc6dd0bc6dd55c0eea6587ffe3d6bf03a0ccc920c5a3ac4d517d"
GIT_URL = os.environ.get("OBSW_MICROPYTHON_GIT", "https://github.com/micropython/micropython")
GIT_COMMIT = "e0e9fbb17ed6fd06bb76e266ae554784c9c80804"  # the tag v1.28.0
# the submodules the unix, stm32 and qemu ports build with (the tree pins their commits)
GIT_SUBMODULES = ("lib/micropython-lib", "lib/tinyusb", "lib/stm32lib")
GET_SOURCE = (
    "git clone --branch v%s https://github.com/micropython/micropython && "
    "make -C micropython/ports/stm32 submodules" % VERSION
)
PYBOARD = ROOT / "boards" / "OBSW_RECONFIG"
QEMU_BOARD = ROOT / "boards" / "OBSW_QEMU"
# The frozen modules are compiled for this port's 63-bit small ints: mpy-cross assumes 31 bits
# (a 32-bit board's) unless told, and the freezer then writes every integer constant beyond
# 2**30 (a 0xFFFFFFFF mask) as a constant long int, so each operation with it allocates a
# long-int result: 3.4x slower, and with a 64 MB heap, where every collection sweeps it all,
# minutes for a test file that takes seconds from source.
UNIX_OPTIONS = (
    "VARIANT=standard",
    "MICROPY_PY_BTREE=0",
    "MICROPY_PY_FFI=0",
    "MICROPY_PY_SSL=0",
    # the core's @micropython.native hot paths freeze as machine code of the host (x86-64)
    "MPY_CROSS_FLAGS=-march=x64 -msmall-int-bits=63",
)
# STM32F405RG: 1 MiB flash; sectors 1-4 (112 KiB at 0x08004000) hold the filesystem, the
# firmware has sector 0 (16 KiB, vectors) and sectors 5-11 (896 KiB from 0x08020000).
F405_FLASH = 1024 * 1024
F405_FIRMWARE_SPACE = (16 + 896) * 1024
JOBS = os.environ.get("OBSW_JOBS", "2")


class FirmwareError(RuntimeError):
    """No source, no toolchain, or a build that failed."""


def say(text):
    print("firmware: " + text, flush=True)


# -- the source -------------------------------------------------------------------------------


def _candidates(explicit):
    if explicit:
        yield pathlib.Path(explicit)
        return
    env = os.environ.get("OBSW_MICROPYTHON_SRC")
    if env:
        yield pathlib.Path(env)
        return
    # next to the repository or inside it
    for base in (ROOT.parent / "shared" / "micropython", ROOT / "shared" / "micropython"):
        yield base


def _tree(path):
    return path.is_dir() and (path / "py" / "mpconfig.h").is_file()


def source(explicit=None):
    """The MicroPython tree to build from (unpacked into build/fw once)."""
    for c in _candidates(explicit):
        if _tree(c):
            return c
        archive = c / ARCHIVE if c.is_dir() else c
        if archive.is_file():
            return _unpack(archive)
        if explicit or os.environ.get("OBSW_MICROPYTHON_SRC"):
            raise FirmwareError("no MicroPython %s source at %s" % (VERSION, c))
    return fetch()


def _git(*args, cwd=None):
    r = subprocess.run(("git",) + args, cwd=cwd, capture_output=True, text=True, timeout=900)
    if r.returncode:
        lines = (r.stderr or r.stdout).strip().splitlines() or ["exit status %d" % r.returncode]
        raise FirmwareError("git %s: %s" % (args[0], lines[-1]))
    return r.stdout.strip()


def fetch(dest=None):
    """The tag's tree, fetched once into build/fw (``GIT_URL``), checked against ``GIT_COMMIT``;
    a ``FirmwareError`` of one line when it cannot be had."""
    dest = pathlib.Path(dest or BUILD / ("micropython-%s-git" % VERSION))
    stamp = dest / ".obsw-fetched"
    if stamp.is_file() and stamp.read_text().strip() == GIT_COMMIT:
        return dest
    say("no MicroPython %s source here: fetching the tag from %s" % (VERSION, GIT_URL))
    try:
        if dest.exists():
            shutil.rmtree(dest)
        dest.parent.mkdir(parents=True, exist_ok=True)
        _git("clone", "-q", "--depth", "1", "--branch", "v" + VERSION, GIT_URL, str(dest))
        commit = _git("rev-parse", "HEAD", cwd=dest)
        if commit != GIT_COMMIT:
            raise FirmwareError(
                "the tag v%s at %s is commit %s, not the pinned %s"
                % (VERSION, GIT_URL, commit, GIT_COMMIT)  # fmt: skip
            )
        _git("submodule", "update", "-q", "--init", "--depth", "1", *GIT_SUBMODULES, cwd=dest)
    except (FirmwareError, OSError, subprocess.SubprocessError) as e:
        shutil.rmtree(dest, ignore_errors=True)
        raise FirmwareError(
            "no MicroPython %s source (%s): set OBSW_MICROPYTHON_SRC to %s or to a tree "
            "(%s)" % (VERSION, e, ARCHIVE, GET_SOURCE)
        ) from None
    stamp.write_text(GIT_COMMIT + "\n")
    say("fetched MicroPython %s (commit %s)" % (VERSION, GIT_COMMIT[:12]))
    return dest


def _unpack(archive):
    dest = BUILD / ("micropython-" + VERSION)
    stamp = dest / ".obsw-unpacked"
    st = archive.stat()
    key = "%s %d %d" % (archive.resolve(), st.st_size, int(st.st_mtime))
    if stamp.is_file() and stamp.read_text() == key:
        return dest / "micropython"
    digest = hashlib.sha256(archive.read_bytes()).hexdigest()
    if digest != ARCHIVE_SHA256:
        say("warning: %s has sha256 %s, not the pinned release's" % (archive, digest))
    say("unpacking %s into %s" % (archive, dest))
    if dest.exists():
        shutil.rmtree(dest)
    dest.mkdir(parents=True)
    with tarfile.open(archive) as t:
        t.extractall(dest, filter="tar") if hasattr(tarfile, "data_filter") else t.extractall(dest)
    stamp.write_text(key)
    return dest / "micropython"


# -- mbed TLS, for cryptolib ------------------------------------------------------------------
# The pinned archive leaves MicroPython's lib/mbedtls submodule empty. cryptolib (the AES block
# function SDLS GCM needs on the board) takes its AES from mbed TLS: Debian's source of it
# (bookworm's mbedtls 2.28.3, the release modhashlib also supports) goes into that folder.
MBEDTLS_VERSION = "2.28.3"
MBEDTLS_ARCHIVE = "mbedtls_%s.orig.tar.gz" % MBEDTLS_VERSION
MBEDTLS_URL = "http://deb.debian.org/debian/pool/main/m/mbedtls/" + MBEDTLS_ARCHIVE
MBEDTLS_SHA256 = "3b4953aa55a681e084d31892d9904cc5328d6b4958ea57b90ae4b4f94ae69a8d"


_NO_MBEDTLS = []  # why the source could not be had, once per process


def _mbedtls_archive():
    """Debian's mbed TLS source archive: $OBSW_MBEDTLS_SRC, build/fw's copy, else downloaded
    from Debian's archive (checked against the pinned SHA-256); None if it cannot be had."""
    import urllib.request

    given = os.environ.get("OBSW_MBEDTLS_SRC")
    path = pathlib.Path(given) if given else BUILD / MBEDTLS_ARCHIVE
    if _NO_MBEDTLS:
        return None
    if not path.is_file() and not given:
        say("downloading %s" % MBEDTLS_URL)
        try:
            with urllib.request.urlopen(MBEDTLS_URL, timeout=60) as r:
                data = r.read()
        except OSError as e:
            say("no mbed TLS source (%s): the images leave cryptolib out" % e)
            _NO_MBEDTLS.append(str(e))
            return None
        BUILD.mkdir(parents=True, exist_ok=True)
        part = path.with_suffix(".part")
        part.write_bytes(data)
        os.replace(part, path)
    if not path.is_file():
        say("no mbed TLS source at %s: the images leave cryptolib out" % path)
        _NO_MBEDTLS.append(str(path))
        return None
    if hashlib.sha256(path.read_bytes()).hexdigest() != MBEDTLS_SHA256:
        raise FirmwareError("%s is not Debian's mbedtls %s (sha256)" % (path, MBEDTLS_VERSION))
    return path


def add_mbedtls(tree):
    """Put mbed TLS's source into ``tree``/lib/mbedtls if it is not there; True if it is."""
    lib = tree / "lib" / "mbedtls"
    if (lib / "library" / "aes.c").is_file():
        return True
    archive = _mbedtls_archive()
    if archive is None:
        return False
    with tarfile.open(archive) as t:
        members = [m for m in t.getmembers() if m.name.count("/") and m.isfile()]
        top = members[0].name.split("/")[0]
        for m in members:
            rel = m.name[len(top) + 1 :]
            if rel.startswith(("include/", "library/")):
                dest = lib / rel
                dest.parent.mkdir(parents=True, exist_ok=True)
                dest.write_bytes(t.extractfile(m).read())
    say("mbed TLS %s source in %s (for cryptolib)" % (MBEDTLS_VERSION, lib))
    return True


# -- toolchains ---------------------------------------------------------------------------------


def need(tool, package):
    if shutil.which(tool) is None:
        raise FirmwareError(
            "%s not found: sudo apt-get install -y gcc-arm-none-eabi libnewlib-arm-none-eabi "
            "qemu-system-arm (%s)" % (tool, package)
        )


# -- cached builds ------------------------------------------------------------------------------


def _hash_inputs(paths, options):
    h = hashlib.sha256()
    for p in sorted(set(str(p) for p in paths)):
        h.update(p.encode())
        h.update(pathlib.Path(p).read_bytes())
    for o in options:
        h.update(o.encode())
    return h.hexdigest()


def manifest_inputs(manifest):
    """The manifest files and every module they freeze."""
    m = Manifest()
    m.execute(manifest)
    return [str(src) for src, _ in m.modules] + m.included


def _files_under(folder):
    return [str(p) for p in pathlib.Path(folder).rglob("*") if p.is_file()]


# lines make writes for a clean build of the pinned source (one per step: CC, GEN, LINK, ...):
# the first build's progress is measured against these, later ones against their last build
_STEPS = {"mpy-cross": 157, "firmware.dfu": 527, "firmware.elf": 591}
PROGRESS_EVERY = 10.0  # seconds between progress lines


def _lines(path):
    with open(path, "rb") as f:
        return sum(1 for _ in f)


def _record_steps(path, n):
    """Keep the largest step count seen (a clean build's), not an incremental build's few."""
    try:
        n = max(n, int(path.read_text()))
    except (OSError, ValueError):
        pass
    path.write_text(str(n))


def _run_with_progress(cmd, log_file, log, out, artifact):
    """make into ``log_file``; a progress line every PROGRESS_EVERY seconds while it runs."""
    steps = out / ".obsw-steps"
    try:
        total = int(steps.read_text())
    except (OSError, ValueError):
        total = _STEPS.get(artifact)
    proc = subprocess.Popen(cmd, stdout=log_file, stderr=subprocess.STDOUT)
    t0 = time.monotonic()
    while True:
        try:
            return proc.wait(timeout=PROGRESS_EVERY)
        except subprocess.TimeoutExpired:
            done, dt = _lines(log), time.monotonic() - t0
            if total:
                pct = min(99, 100 * done // total)
                say(
                    "building %s: %d%% (%d of about %d steps), %.0f s"
                    % (artifact, pct, done, total, dt)
                )
            else:
                say("building %s: %d steps, %.0f s" % (artifact, done, dt))
        except BaseException:
            proc.kill()  # Ctrl-C or SIGTERM: no make left running
            proc.wait()
            raise


def _make(tree, out, artifact, inputs, args):
    """Run make unless ``out``'s stamp says these inputs built ``artifact`` already."""
    key = _hash_inputs(inputs, [str(tree)] + list(args))
    stamp = out / ".obsw-inputs"
    if (out / artifact).is_file() and stamp.is_file() and stamp.read_text() == key:
        say("cached %s" % (out / artifact))
        return out / artifact, 0.0
    t0 = time.monotonic()
    # make recompiles a file when its source changes, not when the options do: a build with
    # other options (cryptolib in or out, another heap, the board's settings such as its float)
    # starts from a clean folder, and the frozen modules are always compiled again
    options = "\n".join(
        [str(tree)]
        + list(args)
        + [str(p) for p in inputs if "mbedtls" in str(p)]
        + [pathlib.Path(p).read_text() for p in inputs if "mpconfigboard" in str(p)]
    )
    was = out / ".obsw-options"
    if out.exists() and (not was.is_file() or was.read_text() != options):
        shutil.rmtree(out)
    shutil.rmtree(out / "frozen_mpy", ignore_errors=True)
    cmd = ["make", "-j" + JOBS] + list(args)
    say("$ " + " ".join(cmd))
    log = out.parent / (out.name + ".log")
    out.mkdir(parents=True, exist_ok=True)
    with open(log, "w") as f:
        rc = _run_with_progress(cmd, f, log, out, artifact)
    if rc or not (out / artifact).is_file():
        tail = log.read_text().splitlines()[-25:]
        raise FirmwareError("build failed (log %s):\n%s" % (log, "\n".join(tail)))
    stamp.write_text(key)
    was.write_text(options)
    _record_steps(out / ".obsw-steps", _lines(log))
    dt = time.monotonic() - t0
    say("built %s in %.1f s" % (out / artifact, dt))
    return out / artifact, dt


def _crypto_inputs(tree):
    """The board fragment that adds cryptolib, and whether mbed TLS is there to add it."""
    common = ROOT / "boards" / "common"
    marker = tree / "lib" / "mbedtls" / "library" / "aes.c"
    return [common / "cryptolib.mk", common / "obsw_mbedtls_config.h"] + (
        [marker] if marker.is_file() else []
    )


def build_mpy_cross(src=None):
    tree = source(src)
    out = tree / "mpy-cross" / "build"
    return _make(tree, out, "mpy-cross", [], ["-C", str(tree / "mpy-cross")])[0]


def build_pyboard(src=None):
    """boards/OBSW_RECONFIG with the stm32 port: returns the build folder (firmware.dfu/.hex)."""
    need("arm-none-eabi-gcc", "gcc-arm-none-eabi")
    tree = source(src)
    build_mpy_cross(src)
    out = BUILD / "pyboard"
    add_mbedtls(tree)
    inputs = _files_under(PYBOARD) + manifest_inputs(ROOT / "manifests" / "reconfig.py")
    inputs += _crypto_inputs(tree)
    args = ["-C", str(tree / "ports" / "stm32"), "BOARD_DIR=" + str(PYBOARD), "BUILD=" + str(out)]
    _make(tree, out, "firmware.dfu", inputs, args)
    return out


def build_unix(src=None):
    """The unix port with manifests/unix.py (asyncio and the core) frozen: the executable."""
    tree = source(src)
    build_mpy_cross(src)
    out = BUILD / "unix"
    manifest = ROOT / "manifests" / "unix.py"
    args = ["-C", str(tree / "ports" / "unix"), "BUILD=" + str(out)]
    args += list(UNIX_OPTIONS) + ["FROZEN_MANIFEST=" + str(manifest)]
    return _make(tree, out, "micropython", manifest_inputs(manifest), args)[0]


def _pyboard_symbols(src=None):
    elf = build_pyboard(src) / "firmware.elf"
    out = subprocess.run(["arm-none-eabi-nm", str(elf)], capture_output=True, text=True).stdout
    sym = {}
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 3:
            sym[parts[2]] = int(parts[0], 16)
    return sym


def pyboard_heap(src=None):
    """Bytes between _heap_start and _heap_end of the Pyboard firmware (its GC heap)."""
    sym = _pyboard_symbols(src)
    return sym["_heap_end"] - sym["_heap_start"]


# ports/stm32/mpconfigport.h: MICROPY_STACK_CHECK_MARGIN, what the stm32 port keeps back
STM32_STACK_MARGIN = 1024


def pyboard_stack_limit(src=None):
    """The C stack a Pyboard's Python code may use before 'maximum recursion depth exceeded':
    _estack - _sstack of its ELF less the stm32 port's check margin."""
    sym = _pyboard_symbols(src)
    return sym["_estack"] - sym["_sstack"] - STM32_STACK_MARGIN


# a float constant the freezer cannot write for a single-precision image (beyond +-3.4e38, inf)
_UNFREEZABLE = re.compile(r"[0-9.]e\+?([4-9][0-9]|[1-9][0-9]{2})\b|\binf\b")
BOARD_TESTS = BUILD / "board-tests"


def stage_board_tests():
    """Copy the core tests and their support modules that freeze into build/fw/board-tests
    (frozen into the QEMU image); returns the names of those that do not (run from source)."""
    BOARD_TESTS.mkdir(parents=True, exist_ok=True)
    left = []
    wanted = set()
    for p in sorted((ROOT / "tests" / "core").glob("*.py")):
        text = p.read_text()
        if _UNFREEZABLE.search(text):
            left.append(p.name)
            continue
        wanted.add(p.name)
        dst = BOARD_TESTS / p.name
        if not dst.is_file() or dst.read_text() != text:
            dst.write_text(text)
    for old in BOARD_TESTS.glob("*.py"):
        if old.name not in wanted:
            old.unlink()
    return left


def build_qemu(src=None, heap=None):
    """boards/OBSW_QEMU (mps2-an385, Cortex-M3) with manifests/qemu.py frozen, a GC heap of
    ``heap`` bytes (default: the Pyboard's) and the Pyboard's C stack limit. Returns
    firmware.elf."""
    need("arm-none-eabi-gcc", "gcc-arm-none-eabi")
    tree = source(src)
    build_mpy_cross(src)
    heap = heap or pyboard_heap(src)
    stage_board_tests()
    out = BUILD / ("qemu-%d" % heap)
    manifest = ROOT / "manifests" / "qemu.py"
    args = ["-C", str(tree / "ports" / "qemu"), "BOARD=OBSW_QEMU", "BOARD_DIR=" + str(QEMU_BOARD)]
    args += [
        "BUILD=" + str(out),
        "MICROPY_HEAP_SIZE=%d" % heap,
        "OBSW_STACK_LIMIT=%d" % pyboard_stack_limit(src),
        "FROZEN_MANIFEST=" + str(manifest),
    ]
    add_mbedtls(tree)
    inputs = _files_under(QEMU_BOARD) + manifest_inputs(manifest) + _crypto_inputs(tree)
    return _make(tree, out, "firmware.elf", inputs, args)[0]


# -- the QEMU board -----------------------------------------------------------------------------


class Qemu:
    """qemu-system-arm running firmware.elf with its UART on a pty (``.pty``) for mpremote.

    ``extra_args`` go to qemu as they are (e.g. ``["-icount", "shift=0"]``)."""

    def __init__(self, elf, extra_args=(), timeout=20):
        need("qemu-system-arm", "qemu-system-arm")
        cmd = ["qemu-system-arm", "-machine", "mps2-an385", "-nographic", "-monitor", "null"]
        cmd += ["-semihosting", "-bios", "none", "-serial", "pty", "-kernel", str(elf)]
        cmd += list(extra_args)
        self.cmd = cmd
        self.proc = subprocess.Popen(
            cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT
        )
        self.pty = None
        seen = b""
        end = time.monotonic() + timeout
        while self.pty is None and time.monotonic() < end:
            r, _, _ = select.select([self.proc.stdout], [], [], 0.5)
            if r:
                chunk = os.read(self.proc.stdout.fileno(), 4096)
                if not chunk:
                    break
                seen += chunk
                m = re.search(rb"(/dev/pts/\d+)", seen)
                if m:
                    self.pty = m.group(1).decode()
        if self.pty is None:
            self.close()
            raise FirmwareError("qemu gave no pty: %s" % seen.decode(errors="replace"))

    def close(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.proc.stdout.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def mpremote(pty, *args, timeout=300):
    """Run mpremote against ``pty``; returns (exit status, output)."""
    tool = shutil.which("mpremote") or str(ROOT / ".venv" / "bin" / "mpremote")
    cmd = [tool, "connect", pty] + list(args)
    try:
        res = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired as e:
        out = e.stdout.decode(errors="replace") if isinstance(e.stdout, bytes) else e.stdout
        return -1, (out or "") + "\n[timed out after %d s]" % timeout
    return res.returncode, res.stdout + res.stderr


# -- the firmware stage -------------------------------------------------------------------------


def _sections(elf):
    out = subprocess.run(["arm-none-eabi-size", "-A", str(elf)], capture_output=True, text=True)
    sizes = {}
    for line in out.stdout.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[1].isdigit():
            sizes[parts[0]] = int(parts[1])
    return sizes


_SIZES = {}  # source path -> (bytes of bytecode, error): images share most modules


def _frozen_size(manifest):
    """Bytes of Pyboard (armv7emsp) bytecode that ``manifest`` freezes, and failures."""
    m = Manifest()
    m.execute(manifest)
    total, bad = 0, []
    tmp = BUILD / "frozen-sizes"
    for src, name in m.modules:
        if src not in _SIZES:
            dst = tmp / (name[:-3] + ".mpy")
            ok, err = compile_one(src, dst, "armv7emsp", name)
            _SIZES[src] = (dst.stat().st_size, None) if ok else (0, err)
        size, err = _SIZES[src]
        total += size
        if err:
            bad.append("%s: %s" % (name, err))
    return total, bad


def stage_sizes():
    t0 = time.monotonic()
    passed = failed = 0
    try:
        out = build_pyboard()
        passed += 1
    except FirmwareError as e:
        print(e)
        print("firmware: 0 passed, 1 failed")
        return 1
    s = _sections(out / "firmware.elf")
    flash = sum(s.get(k, 0) for k in (".isr_vector", ".isr_extratext", ".text", ".ARM", ".data"))
    ram = s.get(".data", 0) + s.get(".bss", 0)
    heap = pyboard_heap()
    print("Pyboard firmware %s" % (out / "firmware.dfu"))
    print("  %-40s %9s %9s %6s" % ("", "used", "space", "use"))
    for label, used, space in (
        ("flash (firmware)", flash, F405_FIRMWARE_SPACE),
        ("flash (whole STM32F405, 1 MiB)", flash, F405_FLASH),
        ("RAM .data+.bss (of 128 KiB)", ram, 128 * 1024),
        ("GC heap for the application", heap, 128 * 1024),
    ):
        print("  %-40s %9d %9d %5.1f%%" % (label, used, space, 100.0 * used / space))
    if flash > F405_FIRMWARE_SPACE:
        failed += 1
        print("  firmware over the flash space")
    else:
        passed += 1
    print("\nfrozen bytecode per image (armv7emsp)")
    print("  %-24s %9s %9s %6s" % ("image", "bytes", "budget", "use"))
    for mpath in sorted((ROOT / "manifests").glob("*.py")):
        total, bad = _frozen_size(mpath)
        budget = BUDGETS.get(mpath.name, F405_FIRMWARE_SPACE - flash + total)
        print("  %-24s %9d %9d %5.1f%%" % (mpath.name, total, budget, 100.0 * total / budget))
        for b in bad:
            print("    FAILED " + b)
        if bad or total > budget:
            failed += 1
        else:
            passed += 1
    entry = PYBOARD / "reconfig_main.py"
    roots = [ROOT / "micropython", ROOT / "boards" / "common", PYBOARD]
    missing = missing_from_manifest(ROOT / "manifests" / "reconfig.py", [entry], roots)
    print("\nreconfig.py freezes every module reconfig_main.py imports: %s"
          % ("yes" if not missing else "no, it misses " + ", ".join(missing)))  # fmt: skip
    passed, failed = passed + (not missing), failed + bool(missing)
    symbols = _pyboard_symbols()
    has = "mp_module_cryptolib" in symbols and "mbedtls_aes_crypt_ctr" in symbols
    if has or (source() / "lib" / "mbedtls" / "library" / "aes.c").is_file():
        print("cryptolib (mbed TLS %s AES) in the Pyboard image: %s"
              % (MBEDTLS_VERSION, "yes" if has else "no"))  # fmt: skip
        passed, failed = passed + has, failed + (not has)
    else:
        print("cryptolib not in the images: no mbed TLS source (GCM runs over AES in Python)")
    # the other images now, once: later stages and tests (several at a time) find them built
    for name, build in (("unix port", build_unix), ("QEMU board", build_qemu)):
        try:
            print("%s image %s" % (name, build()))
            passed += 1
        except FirmwareError as e:
            print("%s image: %s" % (name, e))
            failed += 1
    print("firmware stage time %.1f s" % (time.monotonic() - t0))
    print("firmware: %d passed, %d failed" % (passed, failed))
    return 1 if failed else 0


def main(argv):
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__)
        return 0 if argv else 2
    try:
        if argv[0] == "build":
            what = argv[1] if len(argv) > 1 else "all"
            if what in ("all", "mpy-cross"):
                say("mpy-cross %s" % build_mpy_cross())
            if what in ("all", "pyboard"):
                say("Pyboard firmware in %s (heap %d bytes)" % (build_pyboard(), pyboard_heap()))
            if what in ("all", "unix"):
                say("unix port %s" % build_unix())
            if what in ("all", "qemu"):
                say("QEMU board %s" % build_qemu())
            return 0
        if argv[0] == "qemu":
            with Qemu(build_qemu(), argv[1:]) as q:
                print(q.pty, flush=True)
                try:
                    q.proc.wait()
                except KeyboardInterrupt:
                    pass
            return 0
        if argv[0] == "sizes":
            return stage_sizes()
    except FirmwareError as e:
        print("firmware: %s" % e)
        return 1
    print(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
