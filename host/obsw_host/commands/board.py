"""`obsw board`: build, deploy, flash, repl and test the reconfiguration module's Pyboard."""

import signal
import sys

from obsw_host.mission import ids as mission_ids


def add_parser(sub):
    p = sub.add_parser("board", help="Pyboard firmware for the reconfiguration module")
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    b = s.add_parser(
        "build", help="build the Pyboard firmware, unix port and QEMU board (pinned source)"
    )
    b.add_argument(
        "--micropython",
        help="the MicroPython 1.28.0 source: release archive, folder holding it, or tree "
        "(default $OBSW_MICROPYTHON_SRC, then ../shared/micropython)",
    )
    b.add_argument(
        "--image",
        action="append",
        choices=("pyboard", "unix", "qemu"),
        help="what to build (repeatable; default: all three)",
    )
    b.add_argument("-j", "--jobs", type=int, default=2)
    b.set_defaults(func=_build)
    q = s.add_parser("qemu", help="start the QEMU Cortex-M board and print its pty")
    q.add_argument(
        "qemu_args", nargs="*", help="extra qemu arguments (after --), e.g. -- -icount shift=0"
    )
    q.set_defaults(func=_qemu)
    for name, fn, text in (
        ("deploy", _deploy, "mpy-cross the modules and copy them with mpremote"),
        ("flash", _flash, "bootloader via mpremote, then DFU"),
        ("repl", _repl, "open the board's REPL"),
        ("test", _test, "run board test files on the board"),
        ("update", _update, "stage a signed package of the application (obsw update build)"),
    ):
        q = s.add_parser(name, help=text)
        q.add_argument(
            "--port", "--device", help="serial port or QEMU pty (default: mpremote's auto)"
        )
        if name == "flash":
            q.add_argument("firmware", help="firmware.dfu from `obsw board build`")
        if name == "deploy":
            q.add_argument(
                "--march",
                help="mpy-cross architecture (default: the board's own, else armv7emsp)",
            )
            q.add_argument("--keys", help="the board's SDLS key file, installed as tc.keys")
            mission_ids.add_arguments(q)
            q.add_argument(
                "--insecure",
                action="store_true",
                help="no keys: let the board take essential TCs unauthenticated (logged)",
            )
        if name == "update":
            q.add_argument("package", help="from obsw update build --target reconfig")
        if name == "test":
            q.add_argument(
                "files", nargs="*", help="test files (default: the reconfiguration core tests)"
            )
        q.set_defaults(func=fn)


def _guard(fn):
    from obsw_host.board import BoardError

    try:
        return fn() or 0
    except BoardError as e:
        print("obsw board: %s" % e)
        return 2


def _build(args):
    import os

    from obsw_host import board

    os.environ["OBSW_JOBS"] = str(args.jobs)

    def go():
        for image, path in board.build(args.micropython, args.image or board.IMAGES).items():
            print("%-8s %s" % (image, path))

    return _guard(go)


def _qemu(args):
    from obsw_host import board

    def go():
        q = board.qemu(args.qemu_args)
        # SIGTERM (a service manager, `kill`) ends QEMU too, as Ctrl-C does, not only this
        # process; SIGHUP (the terminal closed) likewise
        try:  # from here on a signal (even right after the line below) still closes QEMU
            for signum in (signal.SIGTERM, signal.SIGHUP):
                signal.signal(signum, _interrupt)
            print("QEMU board on %s (obsw board deploy|test|repl --port %s); Ctrl-C ends it"
                  % (q.pty, q.pty), flush=True)  # fmt: skip
            q.proc.wait()
        except KeyboardInterrupt:
            pass
        finally:
            q.close()

    return _guard(go)


def _interrupt(signum, frame):
    raise KeyboardInterrupt


def _mission(args):
    """The ids of the mission deploy names or finds, or None when there is none to find (a
    mission found with a mistake stops the deploy before anything is copied)."""
    from obsw_host.errors import UserError
    from obsw_host.mission.folder import locate

    if getattr(args, "mission", None) is None and getattr(args, "sdb", None) is None:
        try:
            locate(None)
        except UserError:
            return None
    ids = mission_ids.from_args(args)
    ids.reconfig_board()
    return ids


def _deploy(args):
    from obsw_host import board

    def go():
        ids = _mission(args)
        names = board.deploy(
            args.port,
            march=args.march,
            keys=args.keys,
            insecure=args.insecure,
            progress=_progress,
            ids=ids,
        )
        print("%d modules deployed" % len(names))
        if ids is not None:
            print("mission.json of %s installed on the board" % ids.name)
            if board.update_key(ids) is not None:
                print("update.pub installed: the board takes packages signed for %s" % ids.name)
            else:
                print("update.pub NOT installed (the mission names no update.public_key): "
                      "the board refuses every update package")  # fmt: skip
        else:
            print(
                "mission.json NOT installed (no mission: --mission DIR, ./mission.json or "
                "$OBSW_MISSION): the board keeps the one it has, else its built-in ids"
            )
        if args.keys:
            print("SDLS keys installed on the board as tc.keys (from %s)" % args.keys)
        elif args.insecure:
            print("SDLS OFF on the board (tc.insecure): essential TCs accepted unauthenticated")
        else:
            print(
                "SDLS keys NOT installed (no --keys): unless the board already has tc.keys, "
                "it refuses every essential TC"
            )

    return _guard(go)


def _progress(text):
    """One step of long work on stderr: rewritten in place on a terminal, a line otherwise."""
    if sys.stderr.isatty():
        sys.stderr.write("\r\x1b[K" + text)
        if text.startswith("copying"):
            sys.stderr.write("\n")
    else:
        sys.stderr.write(text + "\n")
    sys.stderr.flush()


def _flash(args):
    from obsw_host import board

    return _guard(lambda: board.flash(args.firmware, args.port))


def _repl(args):
    from obsw_host import board

    return _guard(lambda: board.repl(args.port))


def _update(args):
    from obsw_host import board

    def go():
        line = board.update(args.package, args.port)
        print(line)
        return 0 if line.startswith("staged") else 1

    return _guard(go)


def _test(args):
    from obsw_host import board

    return _guard(lambda: 1 if board.test(args.files, args.port) else 0)
