"""A CFDP client for scripts and the `obsw cfdp` command: put, get and status, returning results.

    from obsw_host.cfdp.client import CfdpClient
    with CfdpClient(1, {2: ("127.0.0.1", 5100)}, root="ground-files", apid=100) as c:
        result = c.put("patch.bin")          # a Result: result.delivered, result.condition
        print(result.line())                 # "delivered patch.bin to entity 2: 1024 B in .."

Transaction sequence numbers never repeat for a local entity: they are kept per entity id in
the user's state folder (``$OBSW_STATE``, else ``$XDG_STATE_HOME/obsw``, else
``~/.local/state/obsw``), under a lock, whatever directory the client runs from. When the
remote entity sends nothing back within ``answer_timeout`` seconds the call raises ``NoAnswer``
naming the address and what to start there. In class 2, progress counts the bytes the
receiver has confirmed (its keep-alive and Finished PDUs), not the bytes sent.
"""

import os
import sys
import time

from obsw.cfdp import msgs
from obsw.cfdp.defs import CONDITION_NAMES, NO_ERROR

from obsw_host.errors import NoAnswer

STATUS_NAMES = {0: "undefined", 1: "active", 2: "terminated", 3: "unrecognized"}
FILE_STATUS = {0: "discarded", 1: "discarded by filestore", 2: "retained", 3: "unreported"}
TIMEOUT = 60.0  # seconds for a whole transaction
ANSWER_TIMEOUT = 5.0  # seconds to wait for the first PDU from the remote entity
CANCEL_WAIT = 10.0  # seconds a cancelled transaction may take to tell the receiver (Ctrl-C)


def state_dir():
    base = os.environ.get("OBSW_STATE")
    if not base:
        xdg = os.environ.get("XDG_STATE_HOME") or os.path.join(
            os.path.expanduser("~"), ".local", "state"
        )
        base = os.path.join(xdg, "obsw")
    return base


def next_sequence(entity_id, width=2, folder=None):
    """The next transaction sequence number of ``entity_id`` (1 .. 2**(8*width)-1), kept in a
    file under ``folder`` (default ``state_dir()``) and advanced under an exclusive lock."""
    import fcntl

    folder = folder or state_dir()
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, "cfdp-entity-%d.seq" % entity_id)
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        text = os.read(fd, 32).decode().strip()
        seq = int(text) if text.isdigit() else 1
        if not 1 <= seq < 1 << (8 * width):
            seq = 1
        following = seq + 1 if seq + 1 < 1 << (8 * width) else 1
        os.lseek(fd, 0, os.SEEK_SET)
        os.ftruncate(fd, 0)
        os.write(fd, str(following).encode())
        return seq
    finally:
        os.close(fd)


def parse_transaction(what):
    """``SOURCE:SEQ`` as (source, sequence number); None for a directory name (no colon)."""
    if ":" not in what:
        return None
    try:
        src, seq = (int(x, 0) for x in what.split(":"))
    except ValueError:
        from obsw_host.errors import UserError

        raise UserError("transaction %r" % what, expected="SOURCE:SEQ") from None
    return src, seq


class Result:
    """The outcome of a put, get or status request."""

    def __init__(self, kind, name, remote, address):
        self.kind = kind
        self.name = name
        self.remote = remote
        self.address = address
        self.tid = None
        self.condition = None  # CFDP condition code of the Finished PDU, None if none came
        self.file_status = None
        self.size = 0
        self.seconds = 0.0
        self.answer = None  # status: the transaction status, or the directory listing text
        self.stats = {}

    @property
    def delivered(self):
        return self.condition == NO_ERROR

    @property
    def condition_name(self):
        return CONDITION_NAMES.get(self.condition, str(self.condition))

    def line(self):
        """One line: delivered or failed, with the condition."""
        if self.kind == "status":
            return str(self.answer)
        verb = "delivered" if self.kind == "put" else "received"
        where = "to" if self.kind == "put" else "from"
        if self.delivered:
            rate = self.size / max(self.seconds, 1e-6) / 1e6
            return "%s %s %s entity %d: %d B in %.2f s (%.2f MB/s)" % (
                verb,
                self.name,
                where,
                self.remote,
                self.size,
                self.seconds,
                rate,
            )
        if self.condition is None:
            return "failed: %s %s entity %d: no Finished PDU within the timeout" % (
                self.name,
                where,
                self.remote,
            )
        return "failed: %s %s entity %d: %s" % (self.name, where, self.remote, self.condition_name)

    def as_dict(self):
        return {
            "kind": self.kind,
            "name": self.name,
            "remote": self.remote,
            "transaction": list(self.tid) if self.tid else None,
            "delivered": self.delivered,
            "condition": self.condition_name if self.condition is not None else None,
            "file_status": FILE_STATUS.get(self.file_status),
            "size": self.size,
            "seconds": round(self.seconds, 3),
            "answer": self.answer,
            "stats": self.stats,
        }


class CfdpClient:
    """A ground CFDP entity on UDP for one or more requests (see the module text)."""

    def __init__(
        self,
        local_id,
        peers,
        root=None,
        *,
        apid,
        cls=2,
        segment=1024,
        port=0,
        loss=0.0,
        timeout=TIMEOUT,
        answer_timeout=ANSWER_TIMEOUT,
        state=None,
    ):
        from obsw_host.cfdp.filestore import RootedFilestore
        from obsw_host.cfdp.link import UdpEntity, make_entity, packet_type_for

        self.local_id = local_id
        self.peers = dict(peers)
        self.timeout = timeout
        self.answer_timeout = answer_timeout
        self.state = state
        fs = RootedFilestore(root)
        self.entity = make_entity(
            local_id, self.peers, fs, mode=2 - cls, segment=segment, persist=False
        )
        self.udp = UdpEntity(
            self.entity,
            ("127.0.0.1", port),
            self.peers,
            apid=apid,
            packet_type=packet_type_for(False),
            loss=loss,
        )
        self.udp.on_indication = self._indication
        self._handlers = []

    def close(self):
        self.udp.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _indication(self, ind):
        for fn in list(self._handlers):
            fn(ind)

    def _remote(self, remote):
        return remote if remote is not None else next(iter(self.peers))

    def _fresh_seq(self):
        self.entity.seq = next_sequence(self.local_id, self.entity.mib.seq_len, self.state)

    def _run(self, done, result, remote, progress=None):
        """Step until ``done()``; NoAnswer if the remote stays silent (class 2 and requests)."""
        start = time.monotonic()
        received = self.udp.received
        answered = False
        end = start + self.timeout
        while not done():
            now = time.monotonic()
            if self.udp.received != received:
                answered = True
            if not answered and now - start > self.answer_timeout and self._expects_answer():
                host, port = self.peers[remote][:2]
                raise NoAnswer(
                    "no entity answered at %s:%d within %g s: is `obsw cfdp serve` (or `obsw "
                    "obc serve`) running there?" % (host, port, self.answer_timeout)
                )
            if now > end:
                break
            self.udp.step()
            if progress is not None:
                progress()
        result.seconds = time.monotonic() - start
        st = self.entity.stats
        result.stats = {
            "pdus_sent": self.udp.sent,
            "pdus_received": self.udp.received,
            "pdus_dropped": self.udp.dropped,
            "retransmitted_pdus": st.get("retransmitted_pdus", 0),
            "naks_received": st.get("naks_received", 0),
            "naks_sent": st.get("naks_sent", 0),
        }
        return result

    def cancel(self, tid, finished, seconds=CANCEL_WAIT):
        """Cancel transaction ``tid`` (CFDP cancel request): its EOF (cancel) goes to the
        receiver, which discards the partial file; steps the entity until ``finished()`` (the
        EOF acknowledged in class 2) or for at most ``seconds``."""
        self.entity.cancel(tid, time.monotonic())
        end = time.monotonic() + seconds
        while not finished() and time.monotonic() < end:
            self.udp.step()

    def _expects_answer(self):
        return any(r.mode == 0 for r in self.entity.mib.remotes.values()) or self._request

    _request = False

    def put(self, source, dest=None, remote=None, on_progress=None):
        """Send local file ``source``; returns a Result. ``on_progress(confirmed, size)``."""
        remote = self._remote(remote)
        self._fresh_seq()
        ent = self.entity
        tid = ent.put(remote, source, dest or source, now=time.monotonic())
        tx = ent.find(tid)
        result = Result("put", source, remote, self.peers[remote])
        result.tid = tid
        result.size = tx.size
        fin = {}

        def on(ind):
            if ind.kind == "finished" and ind.tid == tid:
                fin.update(ind.info)

        def progress():
            t = ent.find(tid)
            confirmed = result.size if fin else (getattr(t, "peer_progress", 0) if t else 0)
            on_progress(confirmed, result.size)

        self._handlers.append(on)
        self._request = False
        try:
            self._run(lambda: bool(fin), result, remote, progress if on_progress else None)
        except KeyboardInterrupt:  # Ctrl-C: cancel, so the receiver keeps no partial file
            print("cancelling the transfer (Ctrl-C again leaves at once)", file=sys.stderr)
            self.cancel(tid, lambda: bool(fin))
            raise
        finally:
            self._handlers.remove(on)
        if fin:
            result.condition = fin.get("condition", NO_ERROR)
            result.file_status = fin.get("file_status")
        return result

    def get(self, source, dest=None, remote=None, on_progress=None):
        """Fetch remote file ``source`` by proxy put into the local filestore; a Result."""
        remote = self._remote(remote)
        self._fresh_seq()
        ent = self.entity
        dest = dest or source.replace("\\", "/").split("/")[-1]
        req = ent.put(
            remote,
            messages=[msgs.proxy_put_request(self.local_id, source, dest)],
            now=time.monotonic(),
        )
        result = Result("get", source, remote, self.peers[remote])
        result.tid = req
        fin, resp = {}, {}

        def on(ind):
            origin = ind.info.get("origin") == req
            if ind.kind == "finished" and origin and ind.info.get("dest_name"):
                fin.update(ind.info)
            elif ind.kind == "proxy_response" and origin and "condition" in ind.info["fields"]:
                resp.update(ind.info["fields"])

        def done():
            if resp and resp.get("condition", 0) != NO_ERROR:
                return True
            return bool(fin) and bool(resp)

        def progress():
            for tx in ent.tx.values():
                if tx.role == "R" and tx.origin == req and tx.meta:
                    on_progress(tx.progress_of(), tx.meta["size"])

        self._handlers.append(on)
        self._request = True
        try:
            self._run(done, result, remote, progress if on_progress else None)
        finally:
            self._handlers.remove(on)
        result.size = fin.get("size", 0)
        if resp.get("condition", NO_ERROR) != NO_ERROR:
            result.condition = resp["condition"]
        elif fin:
            result.condition = fin.get("condition", NO_ERROR)
            result.file_status = fin.get("file_status")
        return result

    def status(self, what, remote=None):
        """``SOURCE:SEQ``: a transaction's status; else a remote directory's listing."""
        remote = self._remote(remote)
        self._fresh_seq()
        ent = self.entity
        now = time.monotonic()
        transaction = parse_transaction(what)
        if transaction:
            message = msgs.remote_status_report_request(transaction, "")
        else:
            listing = "listing-%d-%d.txt" % (self.local_id, ent.seq)
            message = msgs.directory_listing_request(what, listing)
        req = ent.put(remote, messages=[message], now=now)
        result = Result("status", what, remote, self.peers[remote])
        result.tid = req
        resp, fin = {}, {}

        def on(ind):
            if ind.kind == "proxy_response" and ind.info.get("origin") == req:
                resp.update(ind.info["fields"])
            elif ind.kind == "finished" and ind.info.get("origin") == req:
                fin.update(ind.info)

        self._handlers.append(on)
        self._request = True
        try:
            self._run(lambda: bool(resp) and (transaction or bool(fin)), result, remote)
        finally:
            self._handlers.remove(on)
        if transaction and resp:
            result.condition = NO_ERROR
            result.answer = "transaction %s: %s" % (what, STATUS_NAMES.get(resp["status"], "?"))
        elif fin:
            result.condition = fin.get("condition", NO_ERROR)
            result.answer = ent.fs.read_bytes(listing).decode()
            try:
                ent.fs.delete(listing)
            except Exception:  # the listing is shown; a leftover file is harmless
                pass
        return result
