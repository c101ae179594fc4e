"""`obsw board`: build, deploy, flash, repl and test the reconfiguration module's Pyboard."""


def add_parser(sub):
    p = sub.add_parser("board", help="Pyboard firmware for the reconfiguration module")
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    b = s.add_parser("build", help="build firmware with the official stm32 port")
    b.add_argument("--micropython", help="MicroPython checkout (default $MICROPYTHON_DIR)")
    b.add_argument("-j", "--jobs", type=int, default=2)
    b.set_defaults(func=_build)
    for name, fn, text in (
        ("deploy", _deploy, "mpy-cross the modules and copy them with mpremote"),
        ("flash", _flash, "bootloader via mpremote, then DFU"),
        ("repl", _repl, "open the board's REPL"),
        ("test", _test, "run board test files on the board"),
    ):
        q = s.add_parser(name, help=text)
        q.add_argument("--port", help="serial port (default: mpremote's auto)")
        if name == "flash":
            q.add_argument("firmware", help="firmware.dfu from `obsw board build`")
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

    src = args.micropython or os.environ.get("MICROPYTHON_DIR")

    def go():
        print("firmware in %s" % board.build(src, args.jobs))

    return _guard(go)


def _deploy(args):
    from obsw_host import board

    return _guard(lambda: print("%d modules deployed" % len(board.deploy(args.port))))


def _flash(args):
    from obsw_host import board

    return _guard(lambda: board.flash(args.firmware, args.port))


def _repl(args):
    from obsw_host import board

    return _guard(lambda: board.repl(args.port))


def _test(args):
    from obsw_host import board

    return _guard(lambda: 1 if board.test(args.files, args.port) else 0)
