"""ST[17] test: are-you-alive and the on-board connection test."""

from obsw.pus.messages import (
    SERVICE_TEST,
    TC_TEST_ARE_YOU_ALIVE,
    TC_TEST_ON_BOARD_CONNECTION,
    TM_TEST_ARE_YOU_ALIVE_REPORT,
    TM_TEST_ON_BOARD_CONNECTION_REPORT,
)
from obsw.pus.services.base import APID_FIELD, Service, ServiceUser
from obsw.pus.services.s01_verification import FAILURE_UNKNOWN_ID, PusFailure
from obsw.pus.structure import Structure

EMPTY = Structure([])
CONNECTION = Structure([("apid", APID_FIELD)])


class ServiceTest(Service):
    """The service 17 provider.

    ``peers`` maps the APIDs of other on-board application processes to a function (plain
    or async) that runs a connection test with that process and returns True if it answered.
    The process's own APIDs always answer.
    """

    SERVICE = SERVICE_TEST
    REPORTS = (TM_TEST_ARE_YOU_ALIVE_REPORT, TM_TEST_ON_BOARD_CONNECTION_REPORT)
    HANDLERS = (
        (TC_TEST_ARE_YOU_ALIVE, "are_you_alive"),
        (TC_TEST_ON_BOARD_CONNECTION, "connection_test"),
    )

    def __init__(self, peers=None):
        super().__init__()
        self.peers = peers or {}

    def are_you_alive(self, req):
        if req.tc.data:  # it carries none: acceptance fails with the decoder's reason
            req.decode(EMPTY)
        req.report(TM_TEST_ARE_YOU_ALIVE_REPORT)

    def connection_test(self, req):
        apid = req.decode(CONNECTION)["apid"]
        if apid in self.app.apids:
            req.report(TM_TEST_ON_BOARD_CONNECTION_REPORT, CONNECTION.pack({"apid": apid}))
            return None
        probe = self.peers.get(apid)
        if probe is None:
            raise PusFailure(FAILURE_UNKNOWN_ID, "no application process %d" % apid, req.data)
        req.start()
        result = probe(apid)
        if result is not None and hasattr(result, "send"):
            return self._await_peer(req, apid, result)
        self._peer_answered(req, apid, result)
        return None

    async def _await_peer(self, req, apid, pending):
        self._peer_answered(req, apid, await pending)

    def _peer_answered(self, req, apid, ok):
        if not ok:
            raise PusFailure(FAILURE_UNKNOWN_ID, "process %d did not answer" % apid, req.data)
        req.report(TM_TEST_ON_BOARD_CONNECTION_REPORT, CONNECTION.pack({"apid": apid}))


class ServiceTestUser(ServiceUser):
    """The service 17 user."""

    SERVICE = SERVICE_TEST
    DECODERS = (
        (TM_TEST_ARE_YOU_ALIVE_REPORT, "decode_alive"),
        (TM_TEST_ON_BOARD_CONNECTION_REPORT, "decode_connection"),
    )

    def ping(self, apid):
        """TC[17,1]; the transaction's reply is TM[17,2]."""
        return self.request(apid, TC_TEST_ARE_YOU_ALIVE, b"", TM_TEST_ARE_YOU_ALIVE_REPORT)

    def connection_test(self, apid, target):
        """TC[17,3] asking process ``apid`` whether process ``target`` answers."""
        data = CONNECTION.pack({"apid": target})
        return self.request(
            apid, TC_TEST_ON_BOARD_CONNECTION, data, TM_TEST_ON_BOARD_CONNECTION_REPORT
        )

    def decode_alive(self, tm):
        EMPTY.unpack(tm.data)
        return {"alive": True}

    def decode_connection(self, tm):
        return CONNECTION.unpack(tm.data)
