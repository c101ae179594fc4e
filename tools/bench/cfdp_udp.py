"""CFDP over UDP on loopback, two processes: obsw next to cfdp-py, in MB/s, in the same run.

One file (10 MiB, 2 MiB with --quick, random bytes on disk) goes class 2 (acknowledged, closure
requested) from a sending entity in this process to a receiving entity in a child process, each
on its own UDP socket on 127.0.0.1, files on disk on both sides. The time runs from the put
request until the sender has the receiver's Finished PDU; the received file is compared with the
original afterwards.

  obsw     the receiver is the product's `obsw cfdp serve` (python -m obsw_host.cfdp serve,
           space packets with the CFDP APID over UDP); the sender is `CfdpClient`, the
           library behind `obsw cfdp put`.
  cfdp-py  the shape of cfdp-py's UDP example (examples/cfdp-cli-udp): one UDP socket per entity,
           one PDU per datagram, a destination handler in the receiving process and a source
           handler in the sending one, both on cfdp-py's NativeFilestore; single-threaded here
           (a select loop instead of the example's UDP server thread and queues).

Both sides use 1,024-octet segments, a CRC-32 file checksum, 1 s ACK and NAK timers and a 4 MiB
socket receive buffer. The two implementations alternate, run after run, so that both see the
same machine load; the figure is the median of the runs.

Usage: python tools/bench/cfdp_udp.py [--quick] [--json] [--runs N]
"""

import argparse
import json
import os
import random
import select
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time

from measure import child_env, free_port, stop  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

MIB = 1 << 20
SEGMENT = 1024
TIMER = 1.0
RCVBUF = 1 << 22
PEER = "cfdp-py"
MISSION_DIR = os.path.join(ROOT, "examples", "sample")  # the entity `obsw cfdp serve` runs


# --- obsw ------------------------------------------------------------------------------------
class Obsw:
    name = "obsw"

    def __init__(self, work):
        self.work = work
        self.rx_root = os.path.join(work, "obsw-rx")
        self.tx_root = os.path.join(work, "obsw-tx")
        os.makedirs(self.rx_root)
        os.makedirs(self.tx_root)
        self.rx_port, self.tx_port = free_port(), free_port()
        self.proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "obsw_host.cfdp",
                "serve",
                "--mission",
                MISSION_DIR,
                "--id",
                "2",
                "--root",
                self.rx_root,
                "--port",
                str(self.rx_port),
                "--peer",
                "1=127.0.0.1:%d" % self.tx_port,
            ],
            stdout=subprocess.PIPE,
            env=dict(child_env(), OBSW_STATE=os.path.join(work, "obsw-state-rx")),
            text=True,
        )
        line = self.proc.stdout.readline()  # the entity says it is listening
        if "cfdp entity 2" not in line:
            raise SystemExit("obsw cfdp serve did not start: %r" % line)

    def transfer(self, name, data):
        from obsw_host.cfdp.client import CfdpClient
        from obsw_host.sample import load_sdb

        with open(os.path.join(self.tx_root, name), "wb") as f:
            f.write(data)
        client = CfdpClient(
            1,
            {2: ("127.0.0.1", self.rx_port)},
            self.tx_root,
            apid=load_sdb().apid("cfdp"),  # `obsw cfdp serve` runs the sample mission's entity
            cls=2,
            segment=SEGMENT,
            port=self.tx_port,
            timeout=300,
            state=os.path.join(self.work, "obsw-state-tx"),
        )
        try:
            t0 = time.perf_counter()
            result = client.put(name, name)
            dt = time.perf_counter() - t0
        finally:
            client.close()
        return dt, result.delivered and _same(os.path.join(self.rx_root, name), data)

    def close(self):
        stop(self.proc)


def _same(path, data):
    try:
        with open(path, "rb") as f:
            return f.read() == data
    except OSError:
        return False


# --- cfdp-py ---------------------------------------------------------------------------------
def _peer_parts(local, remote):
    """cfdp-py's configuration objects for entity ``local`` talking to ``remote``."""
    from cfdppy import (
        IndicationConfig,
        LocalEntityConfig,
        RemoteEntityConfig,
        RemoteEntityConfigTable,
    )
    from cfdppy_parts import peer_classes
    from spacepackets.cfdp import ChecksumType, TransmissionMode
    from spacepackets.util import ByteFieldU8

    User, Faults, Timers = peer_classes(TIMER)
    cfg = LocalEntityConfig(ByteFieldU8(local), IndicationConfig(), Faults())
    rcfg = RemoteEntityConfig(
        entity_id=ByteFieldU8(remote),
        max_file_segment_len=SEGMENT,
        max_packet_len=SEGMENT + 64,
        closure_requested=True,
        crc_on_transmission=False,
        default_transmission_mode=TransmissionMode.ACKNOWLEDGED,
        crc_type=ChecksumType.CRC_32,
        positive_ack_timer_interval_seconds=TIMER,
        positive_ack_timer_expiration_limit=10,
        nak_timer_interval_seconds=TIMER,
        nak_timer_expiration_limit=10,
        check_limit=10,
    )
    return User, cfg, RemoteEntityConfigTable([rcfg]), Timers


def _udp(port):
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, RCVBUF)
    s.bind(("127.0.0.1", port))
    s.setblocking(False)
    return s


def _recv_all(sock):
    out = []
    while True:
        try:
            out.append(sock.recv(70000))
        except (BlockingIOError, InterruptedError):
            return out


def child_peer_receiver(port, peer_port):
    """cfdp-py's receiving entity: a destination handler on a UDP socket, until terminated."""
    import warnings

    from cfdppy.filestore import NativeFilestore
    from cfdppy.handler.dest import DestHandler
    from spacepackets.cfdp.pdu import PduFactory

    warnings.filterwarnings("ignore")
    User, cfg, table, Timers = _peer_parts(2, 1)
    dest = DestHandler(cfg, User(NativeFilestore()), table, Timers())
    sock = _udp(port)
    peer = ("127.0.0.1", peer_port)
    print("cfdp-py entity 2 on %d" % port, flush=True)

    def drain():
        while dest.packets_ready:
            sock.sendto(dest.get_next_packet().pack(), peer)

    while True:
        r, _, _ = select.select([sock], [], [], 0.01)
        for raw in _recv_all(sock) if r else ():
            try:
                dest.state_machine(PduFactory.from_raw(raw))
            except Exception as e:  # a PDU the handler refuses: go on, as the example does
                if os.environ.get("BENCH_DEBUG"):
                    print("dest", type(e).__name__, e, file=sys.stderr)
            drain()
        dest.state_machine()  # timers
        drain()


class Peer:
    name = PEER

    def __init__(self, work):
        self.work = work
        self.rx_root = os.path.join(work, "peer-rx")
        self.tx_root = os.path.join(work, "peer-tx")
        os.makedirs(self.rx_root)
        os.makedirs(self.tx_root)
        self.rx_port, self.tx_port = free_port(), free_port()
        self.proc = subprocess.Popen(
            [
                sys.executable,
                os.path.abspath(__file__),
                "--child",
                str(self.rx_port),
                str(self.tx_port),
            ],
            stdout=subprocess.PIPE,
            env=child_env(),
            text=True,
        )
        line = self.proc.stdout.readline()
        if "cfdp-py entity 2" not in line:
            raise SystemExit("cfdp-py receiver did not start: %r" % line)
        self.seq = 0

    def transfer(self, name, data):
        from pathlib import Path

        from cfdppy import PutRequest
        from cfdppy.filestore import NativeFilestore
        from cfdppy.handler.source import SourceHandler
        from spacepackets.cfdp import TransmissionMode
        from spacepackets.cfdp.pdu import PduFactory
        from spacepackets.seqcount import SeqCountProvider
        from spacepackets.util import ByteFieldU8

        src_path = os.path.join(self.tx_root, name)
        with open(src_path, "wb") as f:
            f.write(data)
        User, cfg, table, Timers = _peer_parts(1, 2)
        user = User(NativeFilestore())
        seq = SeqCountProvider(16)
        for _ in range(self.seq):
            seq.get_and_increment()
        self.seq += 1
        source = SourceHandler(cfg, user, table, Timers(), seq)
        sock = _udp(self.tx_port)
        peer = ("127.0.0.1", self.rx_port)
        dst_path = os.path.join(self.rx_root, name)
        try:
            t0 = time.perf_counter()
            source.put_request(
                PutRequest(
                    ByteFieldU8(2),
                    Path(src_path),
                    Path(dst_path),
                    TransmissionMode.ACKNOWLEDGED,
                    True,
                )
            )
            end = time.monotonic() + 300
            while not user.done and time.monotonic() < end:
                moved = False
                for raw in _recv_all(sock):
                    try:
                        source.state_machine(PduFactory.from_raw(raw))
                    except Exception as e:  # e.g. a late PDU of the previous transaction
                        if os.environ.get("BENCH_DEBUG"):
                            print("source", type(e).__name__, e, file=sys.stderr)
                    while source.packets_ready:
                        sock.sendto(source.get_next_packet().pack(), peer)
                    moved = True
                source.state_machine()
                while source.packets_ready:
                    sock.sendto(source.get_next_packet().pack(), peer)
                    moved = True
                if not moved:
                    select.select([sock], [], [], 0.005)
            dt = time.perf_counter() - t0
        finally:
            sock.close()
        return dt, user.done and _same(dst_path, data)

    def close(self):
        stop(self.proc)


# --- main ------------------------------------------------------------------------------------
def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="2 MiB, one run each")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--runs", type=int, help="runs of each implementation (default 3, quick 1)")
    ap.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        child_peer_receiver(int(args.child[0]), int(args.child[1]))
        return 0
    import warnings

    warnings.filterwarnings("ignore")
    mib = 2 if args.quick else 10
    runs = args.runs or (1 if args.quick else 3)
    data = random.Random(mib).randbytes(mib * MIB)
    work = tempfile.mkdtemp(prefix="obsw-cfdp-udp-")
    impls = []
    rates = {}
    try:
        impls = [Obsw(work), Peer(work)]
        for r in range(runs):
            order = impls if r % 2 == 0 else impls[::-1]
            for impl in order:
                dt, ok = impl.transfer("f%d.bin" % r, data)
                if not ok:
                    raise SystemExit("%s transfer over UDP failed" % impl.name)
                rates.setdefault(impl.name, []).append(len(data) / dt / 1e6)
    finally:
        for impl in impls:
            impl.close()
        shutil.rmtree(work, ignore_errors=True)
    case = "class 2 %d MiB over UDP, 2 processes" % mib
    ours = statistics.median(rates["obsw"])
    theirs = statistics.median(rates[PEER])
    if args.json:
        rows = [
            {"case": case, "impl": name, "value": round(statistics.median(v), 2), "unit": "MB/s"}
            for name, v in rates.items()
        ]
        for row in rows:
            row["higher_is_better"] = True
        print(json.dumps({"bench": "cfdp_udp", "rows": rows}))
        return 0
    print("%-42s %10s %10s %8s" % ("case", "obsw", PEER, "ratio"))
    print("%-42s %10.2f %10.2f %7.1fx  MB/s" % (case, ours, theirs, ours / theirs))
    return 0


if __name__ == "__main__":
    sys.exit(main())
