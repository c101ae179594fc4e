"""`obsw cfdp`: put and get files over CFDP, ask a remote entity for status, run an entity.

Entity ids, the CFDP APID and the ports come from the mission (``--mission DIR``, see
``obsw_host.mission.ids``): a ground client is the ground filestore's entity and talks to the
onboard one on the mission's CFDP port; ``serve`` runs the onboard entity, its peer the ground's.
"""

import argparse
import os
import sys
import time

from obsw.cfdp.filestore import FilestoreError

from obsw_host.cfdp.client import parse_transaction
from obsw_host.errors import UserError
from obsw_host.mission import ids as mission_ids
from obsw_host.mission.errors import display
from obsw_host.net import DEFAULT_HOST


def _common(p):
    mission_ids.add_arguments(p)
    p.add_argument(
        "--id",
        type=int,
        default=int(os.environ["OBSW_CFDP_ID"]) if os.environ.get("OBSW_CFDP_ID") else None,
        help="local entity id (default: $OBSW_CFDP_ID, else the mission's filestore entity)",
    )
    p.add_argument("--port", type=int, help="local UDP port (0: any; default: the mission's)")
    p.add_argument(
        "--peer",
        action="append",
        metavar="ID=HOST:PORT",
        help="a remote entity and its UDP address (default: the mission's other entity)",
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
    p.add_argument(
        "--timeout", type=float, default=60.0, help="give up after seconds (default 60)"
    )
    p.add_argument(
        "--answer-timeout",
        type=float,
        default=5.0,
        help="seconds to wait for the remote entity's first answer (default 5)",
    )
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--loss", type=float, default=0.0, help="drop this fraction of sent PDUs")


def add_parser(sub):
    p = sub.add_parser(
        "cfdp",
        help="CFDP file transfer (put, get, status, serve)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    put = s.add_parser("put", help="send a local file to a remote entity")
    put.add_argument("source", help="file name in the local filestore")
    put.add_argument("dest", nargs="?", help="file name at the remote entity")
    _common(put)
    put.set_defaults(func=cmd_put)
    get = s.add_parser("get", help="fetch a remote file (proxy put)")
    get.add_argument("source", help="file name at the remote entity")
    get.add_argument("dest", nargs="?", help="file name in the local filestore")
    _common(get)
    get.set_defaults(func=cmd_get)
    st = s.add_parser("status", help="ask a remote entity about a transaction or a directory")
    st.add_argument("what", help="SOURCE:SEQ of a transaction, or a directory name")
    _common(st)
    st.set_defaults(func=cmd_status)
    sv = s.add_parser("serve", help="run a CFDP entity process (the onboard one by default)")
    _serve_args(sv)
    sv.set_defaults(func=cmd_serve)


def _serve_args(p):
    _common(p)
    p.add_argument(
        "--host", default=DEFAULT_HOST, help="address to listen on (default %(default)s)"
    )
    p.add_argument("--ground", action="store_true", help="send TC packets (default TM)")


class Endpoints:
    """The local entity id, UDP port, peers and APID of a command, from the mission unless
    the command line says otherwise. ``onboard``: the onboard entity (``serve``)."""

    def __init__(self, args, onboard):
        ids = mission_ids.from_args(args)
        sat, ground = ids.cfdp_entities
        host = getattr(args, "host", DEFAULT_HOST)
        self.apid = ids.apid("cfdp")
        if onboard:
            default_id, port, peer = sat, ids.ports.cfdp, (ground, ids.ports.cfdp_ground)
        else:
            # the ground entity's port of the mission: where the onboard entity sends to it
            default_id, port, peer = ground, ids.ports.cfdp_ground, (sat, ids.ports.cfdp)
        self.id = args.id if args.id is not None else default_id
        self.port = args.port if args.port is not None else port
        if args.peer:
            self.peers = dict(_parse_peer(t) for t in args.peer)
        else:
            self.peers = {peer[0]: (host, peer[1])}


def _parse_peer(text):
    from obsw_host.cfdp.link import parse_peer

    return parse_peer(text)


def _setup(args, onboard=False):
    from obsw_host.cfdp.filestore import RootedFilestore
    from obsw_host.cfdp.link import UdpEntity, make_entity, packet_type_for

    ends = Endpoints(args, onboard=onboard)
    peers = ends.peers
    fs = RootedFilestore(args.root)
    state = None
    if onboard:  # the entity's own state: outside the filestore, where PDUs cannot write
        from obsw_host.cfdp.client import state_dir

        state = os.path.join(state_dir(), "cfdp-serve-%d" % ends.id)
    ent = make_entity(
        ends.id, peers, fs, mode=2 - args.cls, segment=args.segment, persist=onboard, state=state
    )
    udp = UdpEntity(
        ent,
        (getattr(args, "host", DEFAULT_HOST), ends.port),
        peers,
        apid=ends.apid,
        packet_type=packet_type_for(onboard),
        loss=args.loss,
    )
    return udp, peers


class Progress:
    """A one-line progress bar on stderr: bytes the receiver confirmed (class 2)."""

    def __init__(self, out=sys.stderr, width=30):
        self.out = out
        self.width = width
        self.last = 0.0
        self.shown = False

    def show(self, done, total, force=False):
        now = time.monotonic()
        if not self.out.isatty() or (not force and now - self.last < 0.1):
            return
        self.last = now
        frac = done / total if total else 1.0
        n = int(frac * self.width)
        self.out.write(
            "\r[%s%s] %5.1f%% %d/%d B confirmed"
            % ("#" * n, "." * (self.width - n), frac * 100, done, total)
        )
        self.out.flush()
        self.shown = True

    def end(self):
        if self.shown:
            self.out.write("\n")


def _client(args):
    from obsw_host.cfdp.client import CfdpClient

    ends = Endpoints(args, onboard=False)
    return CfdpClient(
        ends.id,
        ends.peers,
        args.root,
        apid=ends.apid,
        cls=args.cls,
        segment=args.segment,
        port=ends.port,
        loss=args.loss,
        timeout=args.timeout,
        answer_timeout=args.answer_timeout,
    )


def _report(args, result):
    import json

    if args.json:
        print(json.dumps(result.as_dict()))
    else:
        print(result.line())
        if result.kind != "status" and result.stats:
            st = result.stats
            print(
                "PDUs: %d sent, %d received, %d dropped on purpose; %d retransmitted, "
                "%d NAKs received"
                % (
                    st["pdus_sent"],
                    st["pdus_received"],
                    st["pdus_dropped"],
                    st["retransmitted_pdus"],
                    st["naks_received"],
                )
            )
    return 0 if result.delivered else 1


def _transfer(args, method, *names):
    bar = None if args.json else Progress()
    with _client(args) as c:
        try:
            result = getattr(c, method)(*names, on_progress=bar.show if bar else None)
            if bar and result.delivered:
                bar.show(result.size, result.size, True)
        finally:
            if bar:
                bar.end()
    return _report(args, result)


def cmd_put(args):
    from obsw_host.cfdp.filestore import RootedFilestore

    Endpoints(args, onboard=False)  # a mistake in the peers or the mission is said first
    fs = RootedFilestore(args.root)
    try:
        found = os.path.isfile(fs.path(args.source))
    except FilestoreError:
        found = False
    if not found:
        raise UserError(
            "no file %s in the filestore folder %s/" % (args.source, display(fs.root)),
            expected="a file inside the filestore folder, named from it (copy the file there, "
            "or name another folder with --root or $OBSW_FILESTORE)",
        )
    return _transfer(args, "put", args.source, args.dest)


def cmd_get(args):
    return _transfer(args, "get", args.source, args.dest)


def cmd_status(args):
    parse_transaction(args.what)  # a mistake is one line before any port is bound
    with _client(args) as c:
        result = c.status(args.what)
    if args.json:
        return _report(args, result)
    if result.answer is None:
        print("failed: no answer from entity %d within %gs" % (result.remote, args.timeout))
        return 1
    print(result.answer, end="" if result.answer.endswith("\n") else "\n")
    return 0


def cmd_serve(args):
    udp, peers = _setup(args, onboard=not args.ground)
    ent = udp.entity
    n = ent.restore(time.monotonic())
    print(
        "cfdp entity %d on udp %s:%d, filestore %s, %d transaction(s) restored"
        % (ent.mib.entity_id, udp.address[0], udp.address[1], ent.fs.root, n),
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
