"""Runs `obsw` command lines without starting an interpreter for each: this process imports the
command line and its subcommands once, then forks a child per line (its own process, as from
the shell: its own working folder, environment, exit status; standard input empty).

    python obsw_forks.py        then one JSON request a line on standard input:
    {"argv": [...], "cwd": "...", "env": {...}, "out": "FILE", "timeout": S}  ->  {"status": N}

The child writes what it prints (standard output and error, in order) to ``out``; one still
running after ``timeout`` seconds is killed (status -9). Used by
tests/host/test_readme.py for the documentation's plain `obsw ...` lines.
"""

import importlib
import json
import os
import signal
import sys
import time


def _warm(cli):
    for name in cli.COMMANDS:
        try:
            importlib.import_module("obsw_host.commands." + name)
        except Exception:  # an area whose extras are missing: its lines import it themselves
            pass


def _child(cli, req):
    fd = os.open(req["out"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    os.dup2(fd, 1)
    os.dup2(fd, 2)
    null = os.open(os.devnull, os.O_RDONLY)
    os.dup2(null, 0)
    os.chdir(req["cwd"])
    os.environ.clear()
    os.environ.update(req["env"])
    sys.argv = ["obsw"] + req["argv"]
    try:
        status = cli.main(req["argv"])
    except SystemExit as e:
        status = e.code
    except BaseException:
        import traceback

        traceback.print_exc()
        status = 1
    if status is None:
        status = 0
    elif not isinstance(status, int):  # SystemExit("message"): printed, status 1
        print(status, file=sys.stderr)
        status = 1
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except Exception:
            pass
    os._exit(status)


def _wait(pid, timeout):
    """The child's exit status; killed (status -9) if it still runs after ``timeout`` s."""
    end = time.monotonic() + timeout
    while True:
        done, code = os.waitpid(pid, os.WNOHANG)
        if done:
            return os.waitstatus_to_exitcode(code)
        if time.monotonic() > end:
            os.kill(pid, signal.SIGKILL)
            return os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1])
        time.sleep(0.005)


def main():
    sys.path[0] = os.path.dirname(sys.executable)  # as for the `obsw` script, not this folder
    from obsw_host import cli

    _warm(cli)
    print(json.dumps({"ready": True}), flush=True)
    for line in sys.stdin:
        req = json.loads(line)
        pid = os.fork()
        if pid == 0:
            _child(cli, req)
        print(json.dumps({"status": _wait(pid, req.get("timeout", 60))}), flush=True)


if __name__ == "__main__":
    main()
