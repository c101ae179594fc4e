"""Service 23 on a PUS loop with two CFDP entities over a simulated lossy link and the remote
file copy component on an interaction-layer node (test helper)."""

from cfdp_sim import Link, make_pair
from obsw.cfdp.entity import CfdpEntity
from obsw.cfdp.remote_copy import REMOTE_COPY, RemoteCopy
from obsw.il.node import Node
from obsw.pus.services.s23_files import FileManagement
from obsw.pus.services.s23_user import FileUser
from pus_loop import Loop, asyncio

GROUND = 1
SAT = 2
PREFIXES = {"SAT": SAT, "GROUND": GROUND}


class FilesLoop:
    """``loop`` (PUS), ``ground_ent``/``sat_ent`` (CFDP), ``link``, ``files`` (the provider),
    ``user`` (the service user) and ``copy`` (the remote copy component)."""

    def __init__(self, sat_files=None, ground_files=None, loss=0.0, seed=1, store=None, **kw):
        g, s = make_pair(GROUND, SAT, ground_files, sat_files, persist=True, **kw)
        self.ground_ent, self.sat_ent = g, s
        self.link = Link(g, s, seed=seed, loss=loss)
        self.loop = Loop(store=store)
        self.node = Node("obc", clock=self.loop.clock)
        self.copy = RemoteCopy(s)
        self.provider = self.node.provide(REMOTE_COPY, self.copy)
        self.files = self.loop.app.register(
            FileManagement(s.fs, PREFIXES, "SAT", self.node, poll_every=2)
        )
        self.user = self.loop.ground.register(FileUser())
        self._seen = 0
        self.cycles = 0

    def restart_cfdp(self):
        """The CFDP entity process restarts: entity and component come back from the files."""
        s = CfdpEntity(self.sat_ent.mib, self.sat_ent.fs, persist=True)
        s.restore(self.link.now)
        self.sat_ent = s
        self.link.ents[1] = s
        self.node.withdraw(self.provider)
        self.copy = RemoteCopy(s)
        self.provider = self.node.provide(REMOTE_COPY, self.copy)
        self._seen = len(self.link.indications[1])
        for ind in s.pop_indications():
            self.copy.indication(ind)

    def event_ids(self, subtype):
        """IDs of the event reports of severity ``subtype`` sent so far."""
        return [
            (t.data[0] << 8) | t.data[1]
            for t in self.loop.tm
            if t.service == 5 and t.subtype == subtype
        ]

    def restart_pus(self, store):
        """The PUS process restarts: a new loop and provider on the same context store."""
        old = self.loop
        self.loop = Loop(store=store)
        self.loop.clock = old.clock
        self.files = self.loop.app.register(
            FileManagement(self.sat_ent.fs, PREFIXES, "SAT", self.node, poll_every=2)
        )
        self.user = self.loop.ground.register(FileUser())

    def step(self):
        """One round of everything: PUS, CFDP link, component, one application cycle."""
        link = self.link
        self.loop.pump()
        moved = link.step()
        for e in link.ents:
            e.poll(link.now)
        link.indications[1].extend(self.sat_ent.pop_indications())
        link.indications[0].extend(self.ground_ent.pop_indications())
        new = link.indications[1][self._seen :]
        self._seen = len(link.indications[1])
        for ind in new:
            self.copy.indication(ind)
        self.copy.poll(link.now)
        self.node.poll()
        if not moved and not any(e.pending() for e in link.ents):
            ds = [d for d in (e.next_deadline() for e in link.ents) if d is not None]
            if ds:
                link.now = max(link.now, min(ds))
            else:
                link.now += 1.0
        self.loop.app.tick()
        self.cycles += 1
        self.loop.pump()

    def run(self, make=None, until=None, rounds=20000):
        """Send ``make()`` then step until ``until()`` (default: its transaction is done);
        returns make's value."""
        box = []

        async def main():
            if make is not None:
                box.append(make())
            for _ in range(rounds):
                self.step()
                await asyncio.sleep(0)
                if until is not None:
                    if until():
                        break
                elif box and box[0].done and not self.loop.app.tasks:
                    break
            for _ in range(3):
                self.step()
                await asyncio.sleep(0)

        asyncio.run(main())
        return box[0] if box else None
