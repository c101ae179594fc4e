"""The OBC's onboard time: the host clock in the PUS epoch, less the correction the ground's
time correlation uplinked, kept across restarts.

The ground fits the onboard clock's error from time reports (``obsw_host.pus.timecorr``) and
sends TC[8,1] ``OnboardTime.correct`` with ``offset_ms`` (the error when it sends the TC) and
``drift_ppb`` (its rate error). A correction received when the raw (uncorrected) onboard time
is ``t0`` gives ``now() = raw - (offset + drift * (raw - t0))`` from then on; a later one
replaces it (the ground's fit is against the corrected time it reported, so the new offset
and drift add to what is applied: ``offset`` to the current total error at ``t0``, ``drift``
to the current drift). The correction is written atomically to the state folder before it
applies, so after a restart or a power cycle the OBC starts with it: service 11 releases
scheduled TCs at their onboard time and stored packets keep increasing times.
"""

import json
import math
import os

from obsw import jsonsafe
from obsw.il.interface import DATA, INFO, Attribute, Event, Interface, Operation

ONBOARD_TIME = Interface(
    "OnboardTime",
    0x7E30,
    [
        Attribute("offset_ms", 1, DATA, type="i32", unit="ms", description="error taken off"),
        Attribute("drift_ppb", 2, DATA, type="i32", description="rate error taken off, 1e-9"),
        Attribute("corrections", 3, DATA, type="u32", description="corrections applied"),
        Operation("correct", 4, ("offset_ms", "drift_ppb"), description="take this error off"),
        Event("corrected", 5, INFO, fields=("offset_ms", "drift_ppb")),
    ],
    description="the onboard time and its correction from the ground (obsw_host.obc.onboard_time)",
)
LIMIT_MS = 10 * 365 * 86400 * 1000  # a larger offset is a mistake, not a clock error
LIMIT_PPB = 10**8  # 10 %


class OnboardTime:
    """The corrected onboard time (see the module text); ``raw()`` is the uncorrected clock,
    ``path`` the state file."""

    def __init__(self, path, raw):
        self.path = path
        self.raw = raw
        self.offset = 0.0  # s, at t0
        self.drift = 0.0
        self.t0 = 0.0
        self.corrections = 0
        self.il = None
        try:
            with open(path, "rb") as f:
                saved = jsonsafe.loads(f.read(4096))
            values = [float(saved[k]) for k in ("offset", "drift", "t0")]
            if not all(math.isfinite(v) for v in values) or abs(values[1]) >= 1.0:
                raise ValueError("correction out of range: %r" % (values,))
            self.offset, self.drift, self.t0 = values
            self.corrections = int(saved.get("corrections", 0))
        except OSError:
            pass  # no correction yet: the raw clock
        except (ValueError, KeyError, TypeError, AttributeError):
            self.offset, self.drift, self.t0 = 0.0, 0.0, 0.0  # unreadable: the raw clock
            try:
                os.replace(path, path + ".bad")
            except OSError:
                pass
        # the attributes PUS reads: the correction in the units it was uplinked in
        self.offset_ms = round(self.offset * 1000)
        self.drift_ppb = round(self.drift * 1e9)

    def il_bind(self, provider):
        self.il = provider

    def error(self, raw):
        """The error taken off at raw time ``raw``, in seconds."""
        return self.offset + self.drift * (raw - self.t0)

    def now(self):
        raw = self.raw()
        return raw - self.error(raw)

    def set_time(self, t):
        """The onboard time is ``t`` now (from the module's DS3231 at start): the offset
        becomes what the raw clock is off by, the drift stays."""
        raw = self.raw()
        self._apply(raw - t, self.drift, raw, self.corrections)

    def correct(self, offset_ms, drift_ppb):
        from obsw.il.errors import ComponentError

        if not -LIMIT_MS <= offset_ms <= LIMIT_MS or not -LIMIT_PPB <= drift_ppb <= LIMIT_PPB:
            raise ComponentError(
                "OUT_OF_RANGE",
                "%d ms and %d ppb: beyond any clock error" % (offset_ms, drift_ppb),
            )
        raw = self.raw()
        offset = self.error(raw) + offset_ms / 1000.0
        self._apply(offset, self.drift + drift_ppb * 1e-9, raw, self.corrections + 1)
        if self.il is not None:
            self.il.emit("corrected", {"offset_ms": offset_ms, "drift_ppb": drift_ppb})
        return True

    def _apply(self, offset, drift, raw, corrections):
        """Write the correction, then take it (a power cut leaves the old or the new one)."""
        saved = {"offset": offset, "drift": drift, "t0": raw, "corrections": corrections}
        part = self.path + ".part"
        with open(part, "w") as f:
            json.dump(saved, f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(part, self.path)  # the old correction or the new one, never half of one
        self.offset, self.drift, self.t0 = offset, drift, raw
        figures = {
            "offset_ms": round(offset * 1000),
            "drift_ppb": round(drift * 1e9),
            "corrections": corrections,
        }
        for name, value in figures.items():
            if self.il is not None:
                self.il.update(name, value)  # sets it and publishes it
            else:
                setattr(self, name, value)
