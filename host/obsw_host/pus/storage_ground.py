"""Ground calls for the data, storage and file services (2, 4, 6, 13, 14, 15, 23).

    from obsw_host.pus.ground import Ground
    from obsw_host.pus.storage_ground import StorageGround
    with Ground(sdb) as g:
        sg = StorageGround(g, cfdp=ground_udp_entity)     # the ground CFDP entity, if any
        sg.create_store(1, 65536)                          # TC[15,20]
        sg.store_types(1, {10: {3: [25]}}); sg.enable_storage([1])
        sg.summary()                                       # {'stores': [{'store': 1, ...}]}
        sg.retrieve_time(1, t0, t1)                        # on the store's VC (playback)
        op = sg.copy("SAT:/science/a.dat", "GROUND:/a.dat")   # TC[23,14], operation ID
        sg.wait_copy(op)                                   # until TM[23,23] says completed

Each call sends its TC and waits, driving the PUS socket and (while waiting) the ground CFDP
entity, until the completion report, a failure report or the timeout.
"""

import time

from obsw.frames.tm_plan import tm_plan
from obsw.pus.services.s02_device_access import DeviceUser
from obsw.pus.services.s04_statistics import StatisticsUser
from obsw.pus.services.s06_memory import MemoryUser
from obsw.pus.services.s13_large_packets import LargePacketUser
from obsw.pus.services.s14_forwarding import ForwardingUser
from obsw.pus.services.s15_user import StorageUser
from obsw.pus.services.s23_layouts import COPY_ABORTED, COPY_COMPLETED, COPY_FAILED
from obsw.pus.services.s23_user import FileUser

_COPY_OVER = (COPY_COMPLETED, COPY_FAILED, COPY_ABORTED)


class StorageGround:
    """The users of services 2, 4, 6, 13, 14, 15 and 23 on a ``Ground``'s user process."""

    def __init__(self, ground, cfdp=None):
        self.ground = ground
        self.cfdp = cfdp  # an obsw_host.cfdp.link.UdpEntity stepped while waiting
        sdb = ground.sdb
        reg = ground.proc.register
        self.files = reg(FileUser())
        self.storage = reg(StorageUser())
        self.forwarding = reg(ForwardingUser())
        self.large = reg(LargePacketUser())
        self.memory = reg(MemoryUser())
        self.devices = reg(DeviceUser())
        if sdb is not None:
            types = lambda pid: sdb.parameter(pid).type  # noqa: E731
            names = lambda pid: sdb.parameter(pid).qualified  # noqa: E731
            ids = lambda key: sdb.parameter(key).id  # noqa: E731
            self.statistics = reg(StatisticsUser(types, names, ids))
        else:
            self.statistics = None
        self.next_operation = 1

    @property
    def apid(self):
        return self.ground.apid

    # -------------------------------------------------------------------------- waiting

    def step(self, wait=0.005):
        """Receive TM for up to ``wait`` seconds and let the ground CFDP entity work."""
        self.ground.poll(wait if self.cfdp is None else 0.0)
        if self.cfdp is not None:
            self.cfdp.step(wait)

    def wait_until(self, predicate, timeout=10.0):
        end = time.monotonic() + timeout
        while not predicate():
            if time.monotonic() > end:
                return False
            self.step()
        return True

    def issue(self, tx, timeout=None):
        """Wait for ``tx`` (a Transaction) to be done; returns it."""
        if self.ground.log is not None:
            from obsw_host.pus import text

            self.ground.log(text.tc_line(tx.tc))
        self.wait_until(lambda: tx.done, self.ground.timeout if timeout is None else timeout)
        return tx

    # -------------------------------------------------------------------------- ST[15]

    def create_store(self, store, size, kind=0, vc=None):
        """TC[15,20]: a circular (``kind`` 0) or bounded (1) store of ``size`` bytes whose
        retrievals go down on virtual channel ``vc`` (the mission's playback VC unless told:
        the database's ``frames.tm_vcs.playback``)."""
        if vc is None:
            sdb = self.ground.sdb
            vc = tm_plan(sdb.tm_vcs if sdb is not None else None)["playback"]
        return self.issue(
            self.storage.create(
                self.apid, [{"store": store, "size": size, "kind": kind, "vc": vc}]
            )
        )

    def store_types(self, store, selection):
        return self.issue(self.storage.add_types(self.apid, store, selection))

    def store_hk(self, store, sids, apid=None):
        """The store keeps housekeeping structures ``sids`` of ``apid`` only. A new store keeps
        every structure of its APID, as real-time forwarding does, and structures added to
        "every" change nothing: this deletes the APID's selection first (TC[15,30]; refused
        when it had none, which is as good), then adds ``sids`` (TC[15,29], returned)."""
        apid = apid or self.apid
        self.issue(self.storage.delete_hk(self.apid, store, {apid: []}))
        selection = {apid: list(sids)}
        return self.issue(self.storage.add_hk(self.apid, store, selection))

    def enable_storage(self, stores=()):
        return self.issue(self.storage.enable(self.apid, stores))

    def disable_storage(self, stores=()):
        return self.issue(self.storage.disable(self.apid, stores))

    def summary(self, stores=()):
        """TC[15,12]; the decoded TM[15,13] (``tx.reply``)."""
        return self.issue(self.storage.report_summary(self.apid, stores))

    def store_status(self):
        return self.issue(self.storage.report_status(self.apid))

    def retrieve_time(self, store, start, end):
        return self.issue(self.storage.retrieve_time(self.apid, store, start, end))

    def retrieve_sequence(self, store, first, last):
        return self.issue(self.storage.retrieve_sequence(self.apid, store, first, last))

    def delete_content(self, time_tag, stores=()):
        return self.issue(self.storage.delete_content(self.apid, time_tag, stores))

    # -------------------------------------------------------------------------- ST[14]

    def forward_hk(self, sids, apid=None):
        """Forward housekeeping structures ``sids`` of ``apid`` in real time ([] for all)."""
        return self.issue(self.forwarding.add_hk(self.apid, {apid or self.apid: list(sids)}))

    def withhold_hk(self, sids=(), apid=None):
        """Stop forwarding housekeeping structures in real time (none named: all of them)."""
        return self.issue(self.forwarding.delete_hk(self.apid, {apid or self.apid: list(sids)}))

    def forwarding_types(self):
        return self.issue(self.forwarding.report_types(self.apid))

    # -------------------------------------------------------------------------- ST[23]

    def _op(self, operation):
        if operation is None:
            operation = self.next_operation
            self.next_operation = (operation % 0xFFFF) + 1
        return operation

    def copy(self, source, target, operation=None, move=False):
        """TC[23,14] (or [23,15]); returns (operation ID, transaction)."""
        op = self._op(operation)
        fn = self.files.move if move else self.files.copy
        return op, self.issue(fn(self.apid, op, source, target))

    def copy_status(self, operation):
        """The last TM[23,23] entry of ``operation`` seen, or None."""
        return self.files.copy_status.get(operation)

    def wait_copy(self, operation, timeout=30.0):
        """Wait until a copy status report says ``operation`` is over; returns that entry."""
        ok = self.wait_until(
            lambda: (self.copy_status(operation) or {}).get("status") in _COPY_OVER, timeout
        )
        return self.copy_status(operation) if ok else None

    def copy_reports(self, interval):
        return self.issue(self.files.enable_reports(self.apid, interval))

    def attributes(self, path):
        return self.issue(self.files.attributes(self.apid, path))

    def find(self, repository, pattern):
        return self.issue(self.files.find(self.apid, repository, pattern))

    def directory(self, repository):
        return self.issue(self.files.summary(self.apid, repository))

    def delete_file(self, path):
        return self.issue(self.files.delete(self.apid, path))

    # -------------------------------------------------------------------------- ST[04], [06]

    def statistics_report(self, reset=False):
        return self.issue(self.statistics.report(self.apid, reset))

    def dump_memory(self, memory, address, length):
        return self.issue(self.memory.dump(self.apid, memory, [(address, length)]))

    def check_memory(self, memory, address, length):
        return self.issue(self.memory.check(self.apid, memory, [(address, length)]))
