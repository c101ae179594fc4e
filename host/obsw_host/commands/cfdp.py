"""`obsw cfdp`: put and get files over CFDP, ask a remote entity for status, run an entity."""

import os
import sys
import time

from obsw.cfdp import msgs
from obsw.cfdp.defs import CONDITION_NAMES, NO_ERROR

from obsw_host.net import DEFAULT_HOST

DEFAULT_PEER = "2=127.0.0.1:5100"
STATUS_NAMES = {0: "undefined", 1: "active", 2: "terminated", 3: "unrecognized"}
FILE_STATUS = {0: "discarded", 1: "discarded by filestore", 2: "retained", 3: "unreported"}


def _common(p, local_id, port):
    p.add_argument(
        "--id",
        type=int,
        default=int(os.environ.get("OBSW_CFDP_ID", local_id)),
        help="local entity id (default %(default)s, or $OBSW_CFDP_ID)",
    )
    p.add_argument("--port", type=int, default=port, help="local UDP port (0: any)")
    p.add_argument(
        "--peer",
        action="append",
        metavar="ID=HOST:PORT",
        help="a remote entity and its UDP address (default %s)" % DEFAULT_PEER,
    )
    p.add_argument(
        "--root", default=None, help="filestore directory (default $OBSW_FILESTORE or ./filestore)"
    )
    p.add_argument(
        "--class",
        dest="cls",
        type=int,
        choices=(1, 2),
        default=2,
        help="CFDP class: 1 unacknowledged, 2 acknowledged (default 2)",
    )
    p.add_argument("--segment", type=int, default=1024, help="file segment size in octets")
    p.add_argument("--timeout", type=float, default=600.0, help="give up after seconds")
    p.add_argument("--loss", type=float, default=0.0, help="drop this fraction of sent PDUs")


def add_parser(sub):
    p = sub.add_parser(
        "cfdp", help="CFDP file transfer (put, get, status, serve)", description=__doc__
    )
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    put = s.add_parser("put", help="send a local file to a remote entity")
    put.add_argument("source", help="file name in the local filestore")
    put.add_argument("dest", nargs="?", help="file name at the remote entity")
    _common(put, 1, 0)
    put.set_defaults(func=cmd_put)
    get = s.add_parser("get", help="fetch a remote file (proxy put)")
    get.add_argument("source", help="file name at the remote entity")
    get.add_argument("dest", nargs="?", help="file name in the local filestore")
    _common(get, 1, 0)
    get.set_defaults(func=cmd_get)
    st = s.add_parser("status", help="ask a remote entity about a transaction or a directory")
    st.add_argument("what", help="SOURCE:SEQ of a transaction, or a directory name")
    _common(st, 1, 0)
    st.set_defaults(func=cmd_status)
    sv = s.add_parser("serve", help="run a CFDP entity process (the onboard one by default)")
    _serve_args(sv)
    sv.set_defaults(func=cmd_serve)


def _serve_args(p):
    _common(p, 2, 5000 + 100)
    p.add_argument(
        "--host", default=DEFAULT_HOST, help="address to listen on (default %(default)s)"
    )
    p.add_argument("--ground", action="store_true", help="send TC packets (default TM)")


def _setup(args, onboard=False):
    from obsw_host.cfdp.filestore import RootedFilestore
    from obsw_host.cfdp.link import UdpEntity, make_entity, packet_type_for, parse_peer

    peers = dict(parse_peer(t) for t in (args.peer or [DEFAULT_PEER]))
    fs = RootedFilestore(args.root)
    ent = make_entity(args.id, peers, fs, mode=2 - args.cls, segment=args.segment, persist=onboard)
    if not onboard:
        # keep transaction ids unique across runs of the command
        ent.persist = True
        ent.load_seq()
    udp = UdpEntity(
        ent,
        (getattr(args, "host", DEFAULT_HOST), args.port),
        peers,
        packet_type=packet_type_for(onboard),
        loss=args.loss,
    )
    return udp, peers


class Progress:
    """A one-line progress bar on stderr and the transfer summary."""

    def __init__(self, out=sys.stderr, width=30):
        self.out = out
        self.width = width
        self.start = time.monotonic()
        self.last = 0.0

    def show(self, done, total, force=False):
        now = time.monotonic()
        if not force and now - self.last < 0.1:
            return
        self.last = now
        frac = done / total if total else 1.0
        n = int(frac * self.width)
        rate = done / max(now - self.start, 1e-6) / 1e6
        self.out.write(
            "\r[%s%s] %5.1f%% %d/%d B %.2f MB/s"
            % ("#" * n, "." * (self.width - n), frac * 100, done, total, rate)
        )
        self.out.flush()

    def end(self):
        self.out.write("\n")


def summary(udp, started, fin, nbytes):
    st = udp.entity.stats
    dt = time.monotonic() - started
    cond = fin.get("condition", NO_ERROR) if fin else None
    lines = [
        "result: %s" % (CONDITION_NAMES.get(cond, cond) if fin else "no answer"),
        "bytes: %d in %.2f s (%.2f MB/s)" % (nbytes, dt, nbytes / max(dt, 1e-6) / 1e6),
        "PDUs: %d sent, %d received, %d dropped on purpose"
        % (udp.sent, udp.received, udp.dropped),
        "retransmissions: %d file data PDUs (%d octets), %d NAKs sent, %d NAKs received"
        % (
            st["retransmitted_pdus"],
            st["retransmitted_bytes"],
            st["naks_sent"],
            st["naks_received"],
        ),
    ]
    if fin:
        lines.append("file status: %s" % FILE_STATUS.get(fin.get("file_status"), "?"))
    return "\n".join(lines)


def cmd_put(args):
    udp, peers = _setup(args)
    remote = next(iter(peers))
    ent = udp.entity
    tid = ent.put(remote, args.source, args.dest or args.source, now=time.monotonic())
    size = ent.find(tid).size
    bar = Progress()
    fin = {}
    started = time.monotonic()

    def on(ind):
        if ind.kind == "finished" and ind.tid == tid:
            fin.update(ind.info)

    udp.on_indication = on

    def done():
        tx = ent.find(tid)
        if tx is not None:
            bar.show(tx.progress, size)
        return bool(fin)

    ok = udp.run_until(done, args.timeout)
    bar.show(size if fin else 0, size, True)
    bar.end()
    print(summary(udp, started, fin, size))
    udp.close()
    return 0 if ok and fin.get("condition") == NO_ERROR else 1


def cmd_get(args):
    udp, peers = _setup(args)
    remote = next(iter(peers))
    ent = udp.entity
    dest = args.dest or args.source.replace("\\", "/").split("/")[-1]
    req = ent.put(
        remote, messages=[msgs.proxy_put_request(args.id, args.source, dest)], now=time.monotonic()
    )
    bar = Progress()
    fin = {}
    resp = {}
    started = time.monotonic()

    def on(ind):
        origin = ind.info.get("origin") == req
        if ind.kind == "finished" and origin and ind.info.get("dest_name"):
            fin.update(ind.info)
        elif ind.kind == "proxy_response" and origin and "condition" in ind.info["fields"]:
            resp.update(ind.info["fields"])

    udp.on_indication = on

    def done():
        for tx in ent.tx.values():
            if tx.role == "R" and tx.origin == req and tx.meta:
                bar.show(tx.progress_of(), tx.meta["size"])
        if resp and resp.get("condition", 0) != NO_ERROR:
            return True
        return bool(fin) and bool(resp)

    ok = udp.run_until(done, args.timeout)
    size = fin.get("size", 0)
    bar.show(size, size, True)
    bar.end()
    print(summary(udp, started, fin or resp, size))
    udp.close()
    good = ok and fin.get("condition") == NO_ERROR and resp.get("condition") == NO_ERROR
    return 0 if good else 1


def cmd_status(args):
    udp, peers = _setup(args)
    remote = next(iter(peers))
    ent = udp.entity
    now = time.monotonic()
    if ":" in args.what:
        src, seq = (int(x, 0) for x in args.what.split(":"))
        req = ent.put(
            remote, messages=[msgs.remote_status_report_request((src, seq), "")], now=now
        )
    else:
        listing = "listing-%d.txt" % int(now)
        req = ent.put(
            remote, messages=[msgs.directory_listing_request(args.what, listing)], now=now
        )
    resp = {}
    fin = {}

    def on(ind):
        if ind.kind == "proxy_response" and ind.info.get("origin") == req:
            resp.update(ind.info["fields"])
        elif ind.kind == "finished" and ind.info.get("origin") == req:
            fin.update(ind.info)

    udp.on_indication = on
    ok = udp.run_until(lambda: bool(resp) and (":" in args.what or bool(fin)), args.timeout)
    udp.close()
    if not ok:
        print("no answer from entity %d" % remote)
        return 1
    if ":" in args.what:
        print("transaction %s: %s" % (args.what, STATUS_NAMES.get(resp["status"], "?")))
    else:
        print(ent.fs.read_bytes(listing).decode(), end="")
    return 0


def cmd_serve(args):
    udp, peers = _setup(args, onboard=not args.ground)
    ent = udp.entity
    n = ent.restore(time.monotonic())
    print(
        "cfdp entity %d on udp %s:%d, filestore %s, %d transaction(s) restored"
        % (args.id, udp.address[0], udp.address[1], ent.fs.root, n),
        flush=True,
    )

    def on(ind):
        info = " ".join(
            "%s=%s" % (k, ind.info[k])
            for k in sorted(ind.info)
            if k not in ("messages", "responses", "fields")
        )
        print("%s %d:%d %s" % (ind.kind, ind.tid[0], ind.tid[1], info), flush=True)

    udp.on_indication = on
    try:
        udp.run_until(lambda: False, None)
    except KeyboardInterrupt:
        pass
    finally:
        udp.close()
    return 0
