"""Benchmark of the interaction layer next to the thesis design (pyzmq REQ/REP, PUB/SUB + JSON).

Cases, each measured for obsw and for pyzmq+JSON in the same run, in short interleaved runs:
  round trips, 1 process     a synchronous call and its reply (ZeroMQ: REP served by a thread)
  round trips, 2 processes   the same, the provider in a child process (Unix socket / ipc://)
  fan-out, 1 process         publications delivered per second to N subscribers
  fan-out, 2 processes       the publisher in a child process, N subscribers in this one

The 2-process round trips are measured with --repeats (5) fresh process pairs: the row is
the median of their figures, and their ratios are printed (the spread).

Usage: python tools/bench/il.py [--quick] [--json] [--subscribers N] [--repeats N]
"""

import argparse
import gc
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from measure import stop  # noqa: E402
from obsw.il.interface import DATA, Attribute, Event, Interface, Operation  # noqa: E402

BENCH = Interface(
    "Bench",
    0x7F,
    [
        Attribute("angle", 1, DATA),
        Operation("set_angle", 2, ("angle",)),
        Operation("emit", 3, ("n",)),
        Event("tick", 4),
    ],
)
PAYLOAD = {"angle": 30.0, "unit": "deg"}


class Panel:
    angle = 0.0

    def il_bind(self, provider):
        self.il = provider

    def set_angle(self, angle):
        self.angle = angle
        return angle

    def emit(self, n):
        emit = self.il.emit
        for i in range(n):
            emit("tick", [i, PAYLOAD])
        return n


def _env():
    from obsw_host.il.processes import python_path

    return dict(os.environ, PYTHONPATH=python_path())


def _child(*args):
    return subprocess.Popen(
        [sys.executable, os.path.abspath(__file__), "--child", *args],
        env=_env(),
        stdin=subprocess.DEVNULL,
    )


# ------------------------------------------------------------------------------ children


def child_obsw(directory):
    import signal

    from obsw.il.node import Node
    from obsw_host.il.transport import SocketTransport

    node = Node("bench-provider")
    transport = SocketTransport(node, directory)
    node.provide(BENCH, Panel(), inbox=64)
    signal.signal(signal.SIGTERM, lambda *a: transport.stop())
    try:
        transport.serve()
    finally:
        transport.close()


def child_zmq_rep(address):
    """The thesis's provider: REP socket, [name, json args] in, [name, code, json] out."""
    import zmq

    ctx = zmq.Context()
    rep = ctx.socket(zmq.REP)
    rep.bind(address)
    panel = Panel()
    while True:
        name, args = rep.recv_multipart()
        if name == b"stop":
            rep.send_multipart([name, b"0", b"null"])
            break
        fn = getattr(panel, name.decode().split(".", 1)[1])
        rep.send_multipart([name, b"0", json.dumps(fn(*json.loads(args))).encode()])
    rep.close()
    ctx.term()


def child_zmq_pub(ctl, pub_address):
    """The thesis's publisher: PUB socket, [name, json value]; a REP socket to be told when."""
    import zmq

    ctx = zmq.Context()
    rep = ctx.socket(zmq.REP)
    rep.bind(ctl)
    pub = ctx.socket(zmq.PUB)
    pub.setsockopt(zmq.SNDHWM, 0)
    pub.bind(pub_address)
    while True:
        cmd = json.loads(rep.recv())
        if cmd[0] == "stop":
            rep.send(b"null")
            break
        if cmd[0] == "sync":
            pub.send_multipart([b"Bench.sync", b"null"])
        else:
            for i in range(cmd[1]):
                pub.send_multipart([b"Bench.tick", json.dumps([i, PAYLOAD]).encode()])
        rep.send(b"null")
    pub.close(linger=1000)
    rep.close()
    ctx.term()


# ------------------------------------------------------------------------------ obsw


def obsw_rt_local(n):
    from obsw.il.node import Node

    node = Node("bench")
    node.provide(BENCH, Panel())
    proxy = node.proxy(BENCH, timeout=5.0)
    set_angle = proxy.set_angle
    t = time.perf_counter()
    for i in range(n):
        set_angle(i)
    return n / (time.perf_counter() - t)


def obsw_fanout_local(n, subs):
    from obsw.il.node import Node

    node = Node("bench")
    provider = node.provide(BENCH, Panel())
    queues = [node.subscribe("Bench.tick", timeout=1.0, length=n).queue for _ in range(subs)]
    t = time.perf_counter()
    emit = provider.emit
    got = 0
    for start in range(0, n, 64):
        for i in range(start, min(n, start + 64)):
            emit("tick", [i, PAYLOAD])
        for q in queues:
            while q._count:
                q.receive()
                got += 1
    assert got == n * subs
    return got / (time.perf_counter() - t)


class ObswRemote:
    def __init__(self):
        from obsw.il.node import Node
        from obsw_host.il.transport import SocketTransport

        self.dir = tempfile.mkdtemp(prefix="obsw-bench-")
        self.proc = _child("obsw", self.dir)
        self.node = Node("bench-user")
        self.transport = SocketTransport(self.node, self.dir, listen=False)
        self.proxy = self.node.proxy(BENCH, timeout=30.0)
        self.proxy.get("angle")  # resolves the name: waits until the child is up

    def round_trips(self, n):
        set_angle = self.proxy.set_angle
        t = time.perf_counter()
        for i in range(n):
            set_angle(i)
        return n / (time.perf_counter() - t)

    def fan_out(self, n, subs):
        queues = [
            self.node.subscribe("Bench.tick", timeout=5.0, length=n).queue for _ in range(subs)
        ]
        t = time.perf_counter()
        self.proxy.emit(n)
        got = 0
        deadline = time.monotonic() + 60
        while got < n * subs and time.monotonic() < deadline:
            for q in queues:
                while q._count:
                    q.receive()
                    got += 1
            if got < n * subs:
                self.transport.wait(0.05)
        elapsed = time.perf_counter() - t
        for sub in list(self.node._subs.get(("Bench", "tick"), [])):
            sub.cancel()
        assert got == n * subs, (got, n * subs)
        return got / elapsed

    def close(self):
        self.transport.close()
        stop(self.proc)
        shutil.rmtree(self.dir, ignore_errors=True)


# ------------------------------------------------------------------------------ ZeroMQ + JSON


def _zmq_call(req, name, args):
    req.send_multipart([name, json.dumps(args).encode()])
    _, code, data = req.recv_multipart()
    if code != b"0":
        raise RuntimeError(data)
    return json.loads(data)


def zmq_rt_local(n):
    import zmq

    ctx = zmq.Context()
    address = "inproc://bench-rep"
    rep = ctx.socket(zmq.REP)
    rep.bind(address)

    def serve():
        panel = Panel()
        while True:
            name, args = rep.recv_multipart()
            if name == b"stop":
                rep.send_multipart([name, b"0", b"null"])
                return
            fn = getattr(panel, name.decode().split(".", 1)[1])
            rep.send_multipart([name, b"0", json.dumps(fn(*json.loads(args))).encode()])

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    req = ctx.socket(zmq.REQ)
    req.connect(address)
    t = time.perf_counter()
    for i in range(n):
        _zmq_call(req, b"Bench.set_angle", [i])
    rate = n / (time.perf_counter() - t)
    _zmq_call(req, b"stop", [])
    thread.join(10)
    req.close()
    rep.close()
    ctx.term()
    return rate


def zmq_fanout_local(n, subs):
    import zmq

    ctx = zmq.Context()
    pub = ctx.socket(zmq.PUB)
    pub.setsockopt(zmq.SNDHWM, 0)
    pub.bind("inproc://bench-pub")
    socks = []
    for _ in range(subs):
        s = ctx.socket(zmq.SUB)
        s.setsockopt(zmq.RCVHWM, 0)
        s.connect("inproc://bench-pub")
        s.setsockopt(zmq.SUBSCRIBE, b"Bench.tick")
        socks.append(s)
    # inproc subscriptions take effect once the PUB side has processed them: sync first
    pending = set(range(subs))
    deadline = time.monotonic() + 10
    while pending and time.monotonic() < deadline:
        pub.send_multipart([b"Bench.tick", b"null"])
        for i in list(pending):
            if socks[i].poll(1):
                pending.discard(i)
    for s in socks:
        while s.poll(0):
            s.recv_multipart()
    t = time.perf_counter()
    got = 0
    for start in range(0, n, 64):
        for i in range(start, min(n, start + 64)):
            pub.send_multipart([b"Bench.tick", json.dumps([i, PAYLOAD]).encode()])
        for s in socks:
            while s.poll(0):
                _, data = s.recv_multipart()
                json.loads(data)
                got += 1
    rate = got / (time.perf_counter() - t)
    for s in socks:
        s.close()
    pub.close()
    ctx.term()
    assert got == n * subs, (got, n * subs)
    return rate


class ZmqRemote:
    def __init__(self):
        import zmq

        self.zmq = zmq
        self.dir = tempfile.mkdtemp(prefix="zmq-bench-")
        self.rep_address = "ipc://%s/rep" % self.dir
        self.ctl_address = "ipc://%s/ctl" % self.dir
        self.pub_address = "ipc://%s/pub" % self.dir
        self.rep_proc = _child("zmq-rep", self.rep_address)
        self.pub_proc = _child("zmq-pub", self.ctl_address, self.pub_address)
        self.ctx = zmq.Context()
        self.req = self.ctx.socket(zmq.REQ)
        self.req.connect(self.rep_address)
        self.ctl = self.ctx.socket(zmq.REQ)
        self.ctl.connect(self.ctl_address)
        _zmq_call(self.req, b"Bench.set_angle", [0])  # waits until the child is up

    def round_trips(self, n):
        req = self.req
        t = time.perf_counter()
        for i in range(n):
            _zmq_call(req, b"Bench.set_angle", [i])
        return n / (time.perf_counter() - t)

    def fan_out(self, n, subs):
        zmq = self.zmq
        socks = []
        poller = zmq.Poller()
        for _ in range(subs):
            s = self.ctx.socket(zmq.SUB)
            s.setsockopt(zmq.RCVHWM, 0)
            s.connect(self.pub_address)
            s.setsockopt(zmq.SUBSCRIBE, b"Bench.")
            socks.append(s)
            poller.register(s, zmq.POLLIN)
        pending = set(range(subs))  # the slow-joiner handshake of the ZeroMQ guide
        deadline = time.monotonic() + 20
        while pending and time.monotonic() < deadline:
            self.ctl.send(b'["sync"]')
            self.ctl.recv()
            for i in list(pending):
                if socks[i].poll(10):
                    pending.discard(i)
        for s in socks:
            while s.poll(0):
                s.recv_multipart()
        got = 0
        t = time.perf_counter()
        self.ctl.send(json.dumps(["go", n]).encode())
        done = False
        deadline = time.monotonic() + 60
        while (got < n * subs or not done) and time.monotonic() < deadline:
            for s, _ in poller.poll(50):
                while s.poll(0):
                    name, data = s.recv_multipart()
                    if name == b"Bench.tick":
                        json.loads(data)
                        got += 1
            if not done and self.ctl.poll(0):
                self.ctl.recv()
                done = True
        elapsed = time.perf_counter() - t
        for s in socks:
            s.close(linger=0)
        assert got == n * subs, (got, n * subs)
        return got / elapsed

    def close(self):
        _zmq_call(self.req, b"stop", [])
        self.ctl.send(b'["stop"]')
        self.ctl.recv()
        self.req.close()
        self.ctl.close()
        self.ctx.term()
        for p in (self.rep_proc, self.pub_proc):
            p.wait(10)
        shutil.rmtree(self.dir, ignore_errors=True)


# ------------------------------------------------------------------------------ main


def paired(ours, theirs, runs):
    """Interleaved short runs of both implementations, so both see the same machine load.

    Each pair runs the two back to back, the order alternating from pair to pair; the result
    is the median rate of each and the median of the per-pair ratios (the ratio of two runs a
    moment apart, which a change of load between pairs does not skew)."""
    a, b, r = [], [], []
    for i in range(runs):
        if i & 1:
            y = theirs()
            x = ours()
        else:
            x = ours()
            y = theirs()
        a.append(x)
        b.append(y)
        r.append(x / y)
    return statistics.median(a), statistics.median(b), statistics.median(r)


def cross_round_trips(n, runs, repeats):
    """The 2-process round trips ``repeats`` times, each with fresh processes on both sides
    (where the scheduler places them changes the figure more than anything): the medians of
    the repeats' figures and ratios, and the repeats' ratios (their spread)."""
    results = []
    for _ in range(repeats):
        ours = ObswRemote()
        theirs = ZmqRemote()
        try:
            ours.round_trips(n // 10)  # warm up
            theirs.round_trips(n // 10)
            a, b = ours.round_trips, theirs.round_trips
            results.append(paired(lambda a=a: a(n), lambda b=b: b(n), runs))
        finally:
            ours.close()
            theirs.close()
    ratios = [r for _, _, r in results]
    medians = tuple(statistics.median(x[i] for x in results) for i in range(3))
    return medians + (ratios,)


def measure(quick, subs, repeats=5):
    # many short interleaved runs rather than a few long ones: on a shared machine the load
    # changes within seconds
    runs = 9 if quick else 21
    n_rt = 1500 if quick else 4000
    n_rt_local = 20000 if quick else 50000
    n_pub = 1000 if quick else 3000
    rows = []

    def add(case, unit, values):
        values = tuple(values)
        rows.append((case, unit) + values + ((None,) if len(values) == 3 else ()))

    # the cross-process cases first, in a fresh interpreter: the garbage of the in-process
    # runs would otherwise slow the socket loops of both implementations
    add(
        "round trips, 2 processes",
        "round trips/s",
        cross_round_trips(n_rt, runs, 1 if quick else repeats),
    )
    ours = ObswRemote()
    theirs = ZmqRemote()
    try:
        add(
            "fan-out to %d subscribers, 2 processes" % subs,
            "deliveries/s",
            paired(lambda: ours.fan_out(n_pub, subs), lambda: theirs.fan_out(n_pub, subs), runs),
        )
    finally:
        ours.close()
        theirs.close()
    gc.collect()
    add(
        "round trips, 1 process",
        "round trips/s",
        paired(lambda: obsw_rt_local(n_rt_local), lambda: zmq_rt_local(n_rt // 2), runs),
    )
    add(
        "fan-out to %d subscribers, 1 process" % subs,
        "deliveries/s",
        paired(
            lambda: obsw_fanout_local(n_pub, subs), lambda: zmq_fanout_local(n_pub, subs), runs
        ),
    )
    return rows


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="smaller runs (under a minute)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--subscribers", type=int, default=10)
    p.add_argument(
        "--repeats", type=int, default=5, help="fresh process pairs for 2-process round trips"
    )
    p.add_argument("--child", nargs="+", help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.child:
        kind, rest = args.child[0], args.child[1:]
        {"obsw": child_obsw, "zmq-rep": child_zmq_rep, "zmq-pub": child_zmq_pub}[kind](*rest)
        return 0
    from obsw_host.il.wire import CODEC

    rows = measure(args.quick, args.subscribers, args.repeats)
    if args.json:
        out = []
        for case, unit, ours, theirs, ratio, ratios in rows:
            row = {
                "case": case,
                "impl": "obsw",
                "value": ours,
                "unit": unit,
                "higher_is_better": True,
                "ratio": round(ratio, 2),
            }
            if ratios:
                row["ratios"] = [round(r, 2) for r in ratios]
            out.append(row)
            out.append(
                {
                    "case": case,
                    "impl": "pyzmq",
                    "value": theirs,
                    "unit": unit,
                    "higher_is_better": True,
                }
            )
        print(json.dumps({"bench": "il", "rows": out}))
        return 0
    print("interaction layer (codec %s); pyzmq+JSON = the thesis design" % CODEC)
    print("%-36s %14s %14s %7s  %s" % ("case", "obsw", "pyzmq+JSON", "ratio", "unit"))
    for case, unit, ours, theirs, ratio, ratios in rows:
        print("%-36s %14.0f %14.0f %6.1fx  %s" % (case, ours, theirs, ratio, unit))
        if ratios and len(ratios) > 1:
            each = ", ".join("%.1fx" % r for r in ratios)
            print("%-36s ratio of each of %d fresh process pairs: %s (spread %.1f-%.1fx)" % (
                "", len(ratios), each, min(ratios), max(ratios)))  # fmt: skip
    print("(ratio: median of the ratios of interleaved pairs of runs; 2-process round trips:")
    print(" the median over fresh process pairs)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
