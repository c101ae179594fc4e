"""What the OBC's sockets receive is read into one buffer each and copied at its size: a small
message never costs a buffer of the largest size. A fresh 64-70 kB buffer per message, shrunk
to what came, fragmented the heap of the PUS process: its resident memory grew for hours under
traffic. Measured with tracemalloc's peak, not with time."""

import os
import socket
import tracemalloc

from obsw.spp import TYPE_TM, SpacePacket
from obsw_host.cfdp.filestore import OsFilestore
from obsw_host.cfdp.link import UdpEntity, make_entity
from obsw_host.il.transport import Connection
from obsw_host.il.wire import frame

SMALL = 4096  # octets: far more than a small message and its copies, far less than a buffer


def _peak_of(fn):
    """The most memory ``fn()`` held at once beyond what was traced before it."""
    tracemalloc.start()
    try:
        base = tracemalloc.get_traced_memory()[0]
        tracemalloc.reset_peak()
        fn()
        return tracemalloc.get_traced_memory()[1] - base
    finally:
        tracemalloc.stop()


class _Node:
    def __init__(self):
        self.messages = []

    def deliver(self, msg, origin):
        self.messages.append(msg)

    def link_lost(self, conn):
        pass


class _Transport:
    def __init__(self):
        self.node = _Node()
        self.bad_frames = 0

    def _forget(self, conn):
        pass


def test_an_interaction_layer_message_is_read_without_a_large_buffer():
    a, b = socket.socketpair()
    try:
        transport = _Transport()
        conn = Connection(transport, a)
        msg = [1, 7, "Obc", "cpu_load", None, None]
        for _ in range(3):  # the first reads warm up what is allocated once
            b.sendall(frame(msg))
            assert _peak_of(conn.on_readable) < SMALL
        assert transport.node.messages == [msg] * 3
        assert conn.received == 3 and transport.bad_frames == 0
    finally:
        a.close()
        b.close()


def test_a_cfdp_datagram_is_read_without_a_large_buffer(tmp_path):
    root = tmp_path / "files"
    os.makedirs(root)
    entity = make_entity(1, [2], OsFilestore(str(root)), persist=False)
    link = UdpEntity(entity, ("127.0.0.1", 0), {2: ("127.0.0.1", 9)}, apid=5)
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        wrong = SpacePacket(TYPE_TM, 6, b"\x00" * 40).pack()  # another APID: counted, dropped
        for n in range(1, 4):
            sender.sendto(wrong, link.address)
            link.sock.setblocking(True)
            link.sock.settimeout(5.0)  # waits for the datagram, then reads all there is
            got = link.sock.recv_into(link._buf, 0, socket.MSG_PEEK)
            assert got == len(wrong)
            link.sock.setblocking(False)
            assert _peak_of(lambda: link._receive_all(0.0)) < SMALL
            assert link.bad_packets == n
    finally:
        sender.close()
        link.close()
