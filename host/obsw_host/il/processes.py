"""Child processes of the interaction layer: start one with the right PYTHONPATH, stop it."""

import os
import signal
import subprocess
import sys

import obsw

import obsw_host


def python_path():
    """PYTHONPATH that finds the core and the host packages in a child process."""
    roots = [
        os.path.dirname(os.path.dirname(os.path.abspath(obsw.__file__))),
        os.path.dirname(os.path.dirname(os.path.abspath(obsw_host.__file__))),
    ]
    old = os.environ.get("PYTHONPATH")
    return os.pathsep.join(roots + ([old] if old else []))


def spawn(module, directory, *args):
    """Start ``python -m module --dir directory args...`` as a child process."""
    env = dict(os.environ, PYTHONPATH=python_path(), OBSW_IL_DIR=directory)
    return subprocess.Popen(
        [sys.executable, "-m", module, "--dir", directory, "--quiet", *args],
        env=env,
        stdin=subprocess.DEVNULL,
    )


def stop(proc, timeout=5.0):
    """SIGTERM, then SIGKILL if it does not end in ``timeout``; return the exit status."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
        try:
            return proc.wait(timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
    return proc.wait(timeout)


def remove_tree(path):
    """Remove ``path`` and everything under it, ignoring what is already gone."""
    for root, dirs, files in os.walk(path, topdown=False):
        for f in files:
            try:
                os.remove(os.path.join(root, f))
            except OSError:
                pass
        for d in dirs:
            try:
                os.rmdir(os.path.join(root, d))
            except OSError:
                pass
    try:
        os.rmdir(path)
    except OSError:
        pass
