"""The components' periodic hook: ``tick(now)`` every ``period`` seconds, on the unit's thread.

A component whose class has ``tick`` names its period in the mission file
(``"components": {"Adcs": {"module": ..., "period": 0.2}}``); the unit that serves it runs a
``Ticks`` in its own loop: ``ComponentUnit``'s thread (``serve``) or the PUS process's asyncio
loop (``run``). Ticks keep their rhythm (a late tick does not shift the next ones) and never
pile up (after a stall the missed ones are skipped, not run in a burst). A tick that raises
is logged with its reason (the first of a run of failures, then when it recovers) and the
component keeps its place: its ``alive()`` says whether its work has stopped.
"""

import asyncio
import time

IDLE = 0.2  # seconds a unit with nothing due waits for requests at most


class Ticks:
    """The ``tick`` hooks of built components: ``[(Component, (interface, impl)), ...]``."""

    def __init__(self, components, out=print, clock=time.monotonic):
        self.out = out
        self.clock = clock
        now = clock()
        self.entries = [
            [c.name, impl.tick, c.period, now, False]
            for c, (_, impl) in components
            if c.period is not None
        ]
        self.ticks = 0
        self.failures = 0

    def __bool__(self):
        return bool(self.entries)

    def run_due(self, now=None):
        """Call every hook that is due; returns the seconds until the next one (IDLE if
        none)."""
        now = self.clock() if now is None else now
        nearest = IDLE
        for e in self.entries:
            name, tick, period, due, failing = e
            if now >= due:
                try:
                    tick(now)
                    self.ticks += 1
                    if failing:
                        self.out("component %s: tick works again" % name)
                        e[4] = False
                except Exception as x:  # one component's mistake: said, the others go on
                    self.failures += 1
                    if not failing:
                        self.out("component %s: tick(now) failed: %s: %s" % (
                            name, type(x).__name__, x))  # fmt: skip
                        e[4] = True
                due += period
                if due <= now:  # a stall: skip the missed ticks, keep the phase
                    due += ((now - due) // period + 1) * period
                e[3] = due
            nearest = min(nearest, e[3] - now)
        return max(nearest, 0.0)

    def serve(self, transport, node, running):
        """A unit's loop: requests and ticks on this thread while ``running()``."""
        while running():
            left = self.run_due()
            transport.wait(min(left, IDLE))
            node.poll()

    async def run(self, running):
        """The same in an asyncio loop (the PUS process: its transport is a task beside)."""
        while running():
            await asyncio.sleep(self.run_due())
