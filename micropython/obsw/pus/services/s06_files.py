"""ST[06] dumps to file (TC[6,20], [6,22]) and their abort (TC[6,12]): the half of
``MemoryManagement`` that writes memory into files of the onboard filestore.

Paths, locks and maximum sizes are those of ST[23] (``obsw.pus.services.file_refs``). A dump
of at most ``chunk`` octets is written at once (atomically) and completes with its request; a
larger one proceeds ``chunk`` octets per cycle of the application process into a temporary
file renamed into place at the end, and its request completes then. TC[6,12] aborts every
such dump in progress: each fails its completion with ``FAILURE_ABORTED`` and leaves no file.
"""

import asyncio

from obsw.pus.messages import FAILURE_ABORTED, FAILURE_FILESTORE, FAILURE_REFUSED
from obsw.pus.services.base import Service
from obsw.pus.services.file_refs import writable_file
from obsw.pus.services.s01_verification import PusFailure
from obsw.pus.services.s06_layouts import DUMP_TO_FILE, OBJECT_DUMP_TO_FILE
from obsw.pus.structure import Structure

_EMPTY = Structure([])


class MemoryFiles(Service):
    """Dumps to file and their abort (see the module text); ``MemoryManagement`` is one."""

    def __init__(self, chunk=4096):
        super().__init__()
        self.chunk = chunk
        self.dumps = 0  # dumps to file in progress
        self.aborted = 0  # dumps to file aborted by TC[6,12]
        self._aborts = 0
        self._cycle = None  # the asyncio.Event dumps to file wait on for the next cycle

    def _file_jobs(self, area, items, spans):
        jobs = []
        names = []
        for i, off in zip(items, spans):
            fs, name = writable_file(self.app, i["repository"], i["file"], i["length"])
            if name in names:
                raise PusFailure(FAILURE_REFUSED, "%s named twice" % name)
            names.append(name)
            jobs.append((area, off, i["length"], fs, name))
        return jobs

    def dump_to_file(self, req):
        tc, area, spans = self._raw_ranges(req, DUMP_TO_FILE)
        return self._dump_files(req, self._file_jobs(area, tc["items"], spans))

    def dump_object_to_file(self, req):
        tc, area, spans = self._object_ranges(req, OBJECT_DUMP_TO_FILE)
        return self._dump_files(req, self._file_jobs(area, tc["items"], spans))

    def _dump_files(self, req, jobs):
        req.start()
        total = 0
        for job in jobs:
            total += job[2]
        if total > self.chunk:
            return self._dump_later(jobs)  # the request completes when the files do
        for area, off, n, fs, name in jobs:
            self._fs(fs.write_atomic, name, area.read(off, n))
        return None

    def _fs(self, fn, *args):
        try:
            return fn(*args)
        except OSError as e:
            raise PusFailure(FAILURE_FILESTORE, str(e)) from None

    async def _next_cycle(self):
        ev = self._cycle
        if ev is None:
            ev = self._cycle = asyncio.Event()
        await ev.wait()

    async def _dump_later(self, jobs):
        gen = self._aborts
        self.dumps += 1
        tmp = None
        try:
            for area, off, n, fs, name in jobs:
                tmp = name + ".part"
                self._fs(fs.write_bytes, tmp, b"")
                done = 0
                while done < n:
                    k = n - done if n - done < self.chunk else self.chunk
                    h = self._fs(fs.open_write, tmp, False)
                    try:
                        self._fs(h.write, done, area.read(off + done, k))
                    finally:
                        h.close()
                    done += k
                    await self._next_cycle()
                    if self._aborts != gen:
                        self.aborted += 1
                        raise PusFailure(FAILURE_ABORTED, "dump aborted by TC[6,12]")
                self._fs(fs.rename, tmp, name)
                tmp = None
        finally:
            self.dumps -= 1
            if tmp is not None and fs.exists(tmp):
                fs.delete(tmp)

    def abort_dumps(self, req):
        req.decode(_EMPTY)
        req.start()
        self._aborts += 1
        self._wake()

    def _wake(self):
        ev = self._cycle
        if ev is not None:
            self._cycle = None
            ev.set()
