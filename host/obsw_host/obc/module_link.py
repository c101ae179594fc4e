"""The OBC's UART link to the reconfiguration module, in the PUS process (``platform.
module_uarts``: the serial devices to its two controllers; docs/autonomy.md).

At start the OBC reads back, through the module, the DS3231's time and the context it left in
the safeguard memory (``obsw_host.obc.context``): its onboard time is set from the DS3231 when
the host clock differs by more than a second (a Raspberry Pi has no clock of its own after a
power cycle; with the DS3231's oscillator stopped the context's time is taken, late by the time
the OBC was off), its TM sequence counts go on from the saved ones, its boot count goes up, and
the procedures that were running are named in an event (an operator decides whether to start
them again). While it runs it sends a heartbeat on every beat of the PUS process's cycle and
saves its context every ``platform.context_period`` seconds; the module's recovery watches the
heartbeats (with the SpaceCAN ones). A controller that does not answer (in reset, or a cut UART)
costs only its timeout: the other carries the link.
"""

import asyncio
import os
import termios
import time
import tty

from obsw.pluto.obcp import INACTIVE

from obsw_host.obc.context import ObcContext
from obsw_host.reconfig.link import ObcLink

EPOCH_1958 = -4383 * 86400  # 1958-01-01 in Unix seconds
STEP = 1.0  # s: a DS3231 time this far from the onboard time sets it


def open_uart(path):
    """A serial device (or a pseudo-terminal) in raw mode, non-blocking."""
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    try:
        tty.setraw(fd)
    except termios.error:
        pass  # not a terminal (a test's pipe): taken as it is
    return fd


class ModuleLink:
    """The link on ``devices`` for the PUS unit's ``app`` (its sequence counts), ``onboard_time``
    (``OnboardTime``) and ``engine`` (the OBCP engine, or None); ``say`` hears what it does."""

    def __init__(self, devices, app, onboard_time, engine=None, period=1.0, say=print,
                 timeout=1.0):  # fmt: skip
        self.fds = [open_uart(d) for d in devices]
        self.link = ObcLink(self.fds)
        self.app = app
        self.onboard_time = onboard_time
        self.engine = engine
        self.period = period
        self.timeout = timeout  # the module's answers: its context at start; a save's, half
        self.say = say
        self.context = ObcContext()
        self.kept = 0  # controllers that acknowledged the last save
        self.apids = []  # the APIDs whose TM counts the last save logged carried

    def restore(self, timeout=None):
        """Time and context from the module at start; the context (a first start: empty)."""
        timeout = self.timeout if timeout is None else timeout
        rtc = self.link.read_time(timeout)
        ctx = self.link.read_context(timeout)
        if ctx is None:
            ctx = ObcContext()
            self.say("module link: no context kept, a first start")
        else:
            self.say("module link: context restored: %r" % (ctx,))
            for apid, count in ctx.seq.items():
                self.app.sequence.set(int(apid), int(count) & 0x3FFF)
            if ctx.obcps:
                self.say("module link: procedures running before: %s" % ", ".join(ctx.obcps))
        if rtc is not None:
            # the DS3231 keeps UTC (day, ms since 1958); onboard time is TAI of the same epoch
            utc = rtc[0] * 86400 + rtc[1] / 1000.0
            self._set(utc + self._leap(), "the DS3231")
        elif ctx.saves:
            self._set(ctx.obt, "the context (the DS3231 stopped)")
        ctx.boots += 1
        ctx.mode = ctx.mode or 1
        self.context = ctx
        return ctx

    def _leap(self):
        """TAI - UTC now, from the host clock's pair (``obsw_host.pus.onboard.tai_now``)."""
        from obsw_host.pus.tai import tai_now

        return tai_now() - (time.time() - EPOCH_1958)

    def _set(self, t, source):
        if abs(self.onboard_time.now() - t) > STEP:
            self.onboard_time.set_time(t)
            self.say("module link: onboard time from %s" % source)

    def save(self, timeout=None):
        """Send the context as it is now; how many controllers kept it."""
        ctx = self.context
        ctx.obt = self.onboard_time.now()
        ctx.utc_at = time.time() - EPOCH_1958
        ctx.seq = self.app.sequence.counts()
        if self.engine is not None:
            states = self.engine.states
            ctx.obcps = [n for n in self.engine.obcps if states.get(n, INACTIVE) != INACTIVE]
        ctx.saves += 1
        kept = self.link.write_context(ctx, self.timeout / 2 if timeout is None else timeout)
        apids = sorted(int(a) for a in ctx.seq)
        # the first save that was kept, then each change in how many keep it or in the APIDs
        # whose TM counts it carries (a first start's first saves may carry none)
        if kept != self.kept or (kept and apids != self.apids):
            counts = ""
            if apids:
                counts = " (TM counts of APID%s %s)" % (
                    "s" if len(apids) > 1 else "",
                    ", ".join(str(a) for a in apids),
                )
            self.say(
                "module link: context kept by %d of %d controllers%s"
                % (kept, len(self.fds), counts)
            )
            self.apids = apids
        self.kept = kept
        return kept

    async def run(self, beat, running):
        """Heartbeats every ``beat`` s and a save every ``period`` s while ``running()``."""
        next_save = 0.0
        loop = asyncio.get_running_loop()
        while running():
            self.link.heartbeat()
            if time.monotonic() >= next_save:
                next_save = time.monotonic() + self.period
                await loop.run_in_executor(None, self.save)  # waits for the answers
            await asyncio.sleep(beat)

    def close(self):
        for fd in self.fds:
            try:
                os.close(fd)
            except OSError:
                pass
