"""A peer process for tests/host/test_il_processes.py: provides component A or B.

``ping(path)`` calls the next component of ``path`` synchronously (so A -> B -> A is a
cycle across two processes); ``emit(n, size)`` publishes ``n`` events of ``size`` bytes;
``add(job, a, b)`` is asynchronous and reports progress before its result.
"""

import argparse
import signal
import sys

from obsw.il.interface import Event, Interface, Operation
from obsw.il.node import Node
from obsw_host.il.transport import SocketTransport


def interface(name, ident):
    return Interface(
        name,
        ident,
        [
            Operation("ping", 1, ("path",)),
            Operation("emit", 2, ("n", "size")),
            Operation("add", 3, ("a", "b"), asynchronous=True),
            Operation("pid", 4),
            Event("tick", 5),
        ],
    )


class Peer:
    def __init__(self, name):
        self.name = name

    def il_bind(self, provider):
        self.il = provider

    def ping(self, path):
        if not path:
            return self.name
        return self.name + ">" + self.il.node.call(path[0] + ".ping", (path[1:],), timeout=5.0)

    def emit(self, n, size):
        for i in range(n):
            self.il.emit("tick", {"i": i, "blob": bytes(size)})
        return n

    def add(self, job, a, b):
        job.update("adding")
        job.succeed(a + b)

    def pid(self):
        import os

        return os.getpid()


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--dir", required=True)
    p.add_argument("--quiet", action="store_true")
    p.add_argument("name")
    args = p.parse_args()
    node = Node("peer-" + args.name)
    transport = SocketTransport(node, args.dir)
    node.provide(interface(args.name, ord(args.name)), Peer(args.name))
    signal.signal(signal.SIGTERM, lambda *a: transport.stop())
    try:
        transport.serve()
    finally:
        transport.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
