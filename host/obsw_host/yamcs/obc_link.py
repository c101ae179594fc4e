"""Yamcs' packet links to an OBC that already runs (``obsw obc serve``), for ``obsw yamcs run
--obc HOST:PORT``.

The packet gateway (``gateway.PacketGateway``) sends Yamcs' TCs of the PUS APID to the OBC's PUS
process at HOST:PORT and CFDP PDUs to its CFDP entity (the mission's CFDP port on HOST). Its UDP
socket is bound to the mission's ground CFDP port, where the OBC's CFDP entity sends the ground
entity's PDUs, and it subscribes there to the PUS process's TM (``tm_fanout.SUBSCRIBE`` every
third of the linger time), so events and periodic housekeeping reach Yamcs without a TC.
"""

import threading

from obsw_host.pus.tm_fanout import LINGER, SUBSCRIBE, UNSUBSCRIBE
from obsw_host.yamcs.gateway import PacketGateway


def parse_address(text):
    """'HOST:PORT' -> (host, port); ValueError naming what was expected."""
    host, sep, port = str(text).rpartition(":")
    try:
        if not sep or not host:
            raise ValueError
        number = int(port)
        if not 0 < number < 65536:
            raise ValueError
    except ValueError:
        raise ValueError("--obc %r: expected HOST:PORT of the OBC's PUS process" % text) from None
    return host, number


class ObcLink:
    """The gateway between Yamcs and a running OBC of mission ``ids`` (see the module text).
    ``obc``: (host, port) of its PUS process; ``ports``: Yamcs' link ports (``pus``, ``cfdp``);
    ``listen``: the address of its UDP socket (loopback; this machine's address on the OBC's
    network when the OBC runs elsewhere)."""

    def __init__(self, ids, obc, ports, listen="127.0.0.1"):
        host, port = obc
        self.obc = (host, port)
        pus_apid = ids.pus_apid
        cfdp_apid = ids.apid("cfdp")
        self.gateway = PacketGateway(
            tcp_ports={"pus": ports["pus"], "cfdp": ports["cfdp"]},
            apids={"cfdp": [cfdp_apid]},
            tm_port=ids.ports.cfdp_ground,
            routes={pus_apid: (host, port), cfdp_apid: (host, ids.ports.cfdp)},
            udp_host=listen,
        )
        self._stop = threading.Event()
        self._thread = None

    def ports(self):
        return dict(self.gateway.ports)

    def _subscribe(self):
        while True:
            try:
                self.gateway.udp.sendto(SUBSCRIBE, self.obc)
            except OSError:
                pass  # the OBC is not there (yet): try again next period
            if self._stop.wait(LINGER / 3):
                return

    def start(self):
        self.gateway.start()
        self._thread = threading.Thread(target=self._subscribe, name="obc-subscribe", daemon=True)
        self._thread.start()
        return self

    def close(self):
        self._stop.set()
        if self._thread is not None:
            self._thread.join(2)
            try:
                self.gateway.udp.sendto(UNSUBSCRIBE, self.obc)
            except OSError:
                pass
        self.gateway.close()
