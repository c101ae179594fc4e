"""Ground time correlation: onboard time against UTC from TM[9,2]/[9,3] time reports.

The practice of PUS missions (ECSS-E-ST-70-41C 6.9, time reports; ECSS-E-70-11 and the CCSDS
time-correlation practice of ESA's ground systems): the ground stamps each time report with its
earth reception time (ERT); the report was generated at ``ERT - link delay`` (the known
propagation and onboard delay), when the onboard time was the one it carries. A straight line
fitted by least squares through the pairs (onboard time, generation UTC) gives the onboard
clock's offset at a reference time and its drift (rate error); the residuals show the jitter.
The correction goes up as a mission function (``OnboardTime.correct``, TC[8,1]) with the
offset in milliseconds and the drift in parts per billion; the OBC subtracts both.

Run: ``python -m obsw_host.pus.timecorr SAMPLES --delay SECONDS`` (lines "obt ert" in seconds).
"""

import argparse
import sys

FUNCTION = "OnboardTime.correct"


class CorrelationError(ValueError):
    """Too few time reports, or all at the same onboard time: no line can be fitted."""


class Correlation:
    """Onboard time = UTC + ``offset`` + ``drift`` * (UTC - ``ref``); times in seconds."""

    def __init__(self, ref, offset, drift, rms, n):
        self.ref = ref
        self.offset = offset
        self.drift = drift
        self.rms = rms
        self.n = n

    def utc(self, obt):
        """The UTC of an onboard time."""
        return self.ref + (obt - self.ref - self.offset) / (1.0 + self.drift)

    def correction(self, at=None):
        """The function's arguments: ``offset_ms`` (the clock's error at UTC ``at``, when the TC
        goes up; default the reference time) and ``drift_ppb``, to take off on board from
        then on (``obsw_host.obc.onboard_time``)."""
        offset = self.offset + self.drift * ((self.ref if at is None else at) - self.ref)
        return {"offset_ms": round(offset * 1000), "drift_ppb": round(self.drift * 1e9)}

    def __repr__(self):
        return "Correlation(offset %.6f s at %.3f, drift %.3f ppm, rms %.6f s, %d reports)" % (
            self.offset,
            self.ref,
            self.drift * 1e6,
            self.rms,
            self.n,
        )


def correlate(samples, link_delay=0.0):
    """Fit ``obt = utc + offset + drift * (utc - ref)`` to ``samples`` of (obt, ert) by least
    squares, with utc = ert - link_delay and ref the mean generation UTC."""
    pairs = [(float(obt), float(ert) - link_delay) for obt, ert in samples]
    n = len(pairs)
    if n < 2:
        raise CorrelationError("time correlation needs 2 time reports or more, got %d" % n)
    ref = sum(u for _, u in pairs) / n
    xs = [u - ref for _, u in pairs]
    ys = [obt - u for obt, u in pairs]  # the onboard clock's error at each report
    sxx = sum(x * x for x in xs)
    if sxx == 0.0:
        raise CorrelationError("the %d time reports were all generated at once" % n)
    mean_y = sum(ys) / n
    drift = sum(x * (y - mean_y) for x, y in zip(xs, ys)) / sxx
    offset = mean_y
    res = [y - (offset + drift * x) for x, y in zip(xs, ys)]
    rms = (sum(r * r for r in res) / n) ** 0.5
    return Correlation(ref, offset, drift, rms, n)


def uplink(ground, correlation, at=None, apid=None, timeout=None):
    """TC[8,1] ``OnboardTime.correct`` with the correction for UTC ``at`` (now, in the time
    reports' epoch); the ground's Transaction."""
    args = correlation.correction(at)
    return ground.perform(FUNCTION, apid=apid, timeout=timeout, **args)


def samples_from(ground_received, decode):
    """(obt, ert) pairs from a ground's received TM: ``decode(tm)`` gives the report's time
    (``TimeUser.decode_time``) for TM[9,2]/[9,3], ``ert`` is when the ground received it."""
    out = []
    for tm, ert in ground_received:
        if tm.service == 9 and tm.subtype in (2, 3):
            out.append((decode(tm)["time"], ert))
    return out


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m obsw_host.pus.timecorr", description=__doc__)
    p.add_argument("samples", help='file of lines "OBT ERT" (seconds)')
    p.add_argument("--delay", type=float, default=0.0, help="known link delay (s)")
    args = p.parse_args(argv)
    samples = []
    with open(args.samples) as f:
        for line in f:
            parts = line.split()
            if len(parts) >= 2 and not line.startswith("#"):
                samples.append((float(parts[0]), float(parts[1])))
    try:
        c = correlate(samples, args.delay)
    except CorrelationError as e:
        print("error: %s" % e, file=sys.stderr)
        return 2
    print(c)
    print("correction: %s %s" % (FUNCTION, c.correction()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
