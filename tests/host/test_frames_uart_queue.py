"""Writing to a UART nobody reads never blocks the frame processor: each link queues a bounded
number of frames, drops the oldest beyond and counts the drops, which the frame processor's
``FrameProcessor`` component publishes (housekeeping SID 3 of the sample)."""

import os
import select
import socket
import threading
import time
import tty

from obsw.il.node import Node
from obsw.il.queue import EMPTY
from obsw.spp import SpacePacket
from obsw_host.frames.links import FdLink
from obsw_host.frames.processor import FrameProcessorHost
from obsw_host.obc.frames_unit import FrameCounters
from obsw_host.obc.topology import FRAME_PROCESSOR
from obsw_host.sample import load_sdb


def unread_pty():
    """A pty whose device end is open and never read: its buffer fills, then writes block."""
    controller, device = os.openpty()
    tty.setraw(device)
    return controller, device


def completes(work, deadline=60.0):
    """True once ``work()`` has returned, False if it still runs at the deadline (it blocked)."""
    done = threading.Event()

    def run():
        work()
        done.set()

    threading.Thread(target=run, daemon=True).start()
    return done.wait(deadline)


def test_a_link_nobody_reads_drops_the_oldest_frames_and_never_blocks():
    controller, device = unread_pty()
    link = FdLink(controller, "A", queue=8)
    frame = bytes(range(256)) * 4

    def write_all():
        for _ in range(2000):  # ~2 MB: far beyond the pty's buffer
            link.write(frame)

    assert completes(write_all)  # the blocking link would wait forever here
    assert 0 < link.pending() <= 8
    written = 2000 - link.pending() - link.dropped
    assert written > 0  # what the buffer took went out
    # the reader comes back: the queue drains, frames whole and in order
    os.set_blocking(device, False)
    got = bytearray()
    for _ in range(10000):
        try:
            got += os.read(device, 65536)
        except BlockingIOError:
            pass
        if link.flush() == 0:
            break
    expected = (2000 - link.dropped) * len(frame)
    deadline = time.monotonic() + 10.0
    while len(got) < expected and time.monotonic() < deadline:  # the pty's buffer, read out
        try:
            got += os.read(device, 65536)
        except BlockingIOError:
            select.select([device], [], [], 0.1)
    assert link.pending() == 0
    assert len(got) == expected
    assert bytes(got[-len(frame) :]) == frame
    link.close()
    os.close(device)


def test_the_frame_processor_keeps_serving_with_both_uarts_unread():
    sdb = load_sdb()
    ends = [unread_pty(), unread_pty()]
    links = [FdLink(c, n, queue=4) for (c, _), n in zip(ends, "AB")]
    fp = FrameProcessorHost(links[0], links[1], 0x42, tm_port=0, tm_plan=sdb.tm_vcs)
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    packet = SpacePacket(0, 10, bytes(200)).pack()
    try:

        def feed():
            for _ in range(300):  # TM for a COM module that reads nothing
                for _ in range(20):
                    tx.sendto(packet, ("127.0.0.1", fp.tm_port))
                fp.step(0)

        assert completes(feed)
        assert all(link.dropped > 0 for link in links)
        assert all(link.pending() <= 4 for link in links)
    finally:
        tx.close()
        fp.close()
        for _, device in ends:
            os.close(device)


def test_the_drops_are_published_as_attributes():
    class Link:
        dropped = 0

    links = [Link(), Link()]
    node = Node("frames")
    counters = FrameCounters(links)
    node.provide(FRAME_PROCESSOR, counters)
    sub = node.subscribe("FrameProcessor.uart_b_dropped", timeout=1.0)
    counters.publish()
    assert sub.receive() is EMPTY  # nothing changed: nothing published
    links[1].dropped = 7
    counters.publish()
    assert sub.receive().value == 7
    assert node.get("FrameProcessor.uart_b_dropped", timeout=1.0) == 7
    assert node.get("FrameProcessor.uart_a_dropped", timeout=1.0) == 0


def test_a_serial_port_nobody_reads_never_blocks_either():
    from obsw_host.frames.links import SerialLink

    controller, device = os.openpty()
    tty.setraw(device)
    path = os.ttyname(device)
    os.close(device)
    link = SerialLink(path, queue=4)  # the device end, as the OBC opens its UART

    def write_all():
        for _ in range(1000):
            link.write(bytes(1024))

    assert completes(write_all)
    assert link.dropped > 0 and link.pending() <= 4
    link.close()
    os.close(controller)
