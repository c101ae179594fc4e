"""Pass plans: the service 11 time-tagged commands that fly a pass, and the check of a plan
against the onboard schedule report.

For each pass: the transmitter on ``lead`` seconds before AOS and off ``lag`` seconds after
LOS. The dump needs no command: the OBC's store-and-forward starts it at AOS from its pass
table and contact state (``obsw.frames.downlink.StoreForward``). Requests are in the words of
``obsw ground`` (``function NAME``), so a plan is uplinked with
``obsw ground schedule insert --at``.
"""

from obsw_host.ops.tle import format_time

TX_ON = "function Radio.transmitter_on"
TX_OFF = "function Radio.transmitter_off"


class Step:
    """One planned command: release ``time`` (POSIX s, UTC), ``request`` (words), ``what``."""

    def __init__(self, time, request, what, station):
        self.time = time
        self.request = request
        self.what = what
        self.station = station

    def to_dict(self):
        import datetime

        at = datetime.datetime.fromtimestamp(self.time, datetime.timezone.utc)
        return {"at": format_time(at), "time": round(self.time, 3), "request": self.request,
                "what": self.what, "station": self.station}  # fmt: skip

    def __str__(self):
        d = self.to_dict()
        return "%s  %-44s # %s, %s" % (d["at"], d["request"], d["what"], d["station"])


def plan(passes, lead=60.0, lag=30.0, tx_on=TX_ON, tx_off=TX_OFF):
    """The steps of ``passes`` in time order. A transmitter already on (overlapping passes,
    or passes closer than lead + lag) stays on: one on, one off around them."""
    steps = []
    windows = []
    for p in sorted(passes, key=lambda p: p.aos):
        on, off = p.aos - lead, p.los + lag
        if windows and on <= windows[-1][1]:
            windows[-1][1] = max(windows[-1][1], off)
            windows[-1][2].append(p)
        else:
            windows.append([on, off, [p]])
    for on, off, group in windows:
        name = "+".join(p.station.name for p in group)
        if tx_on:
            steps.append(Step(on, tx_on, "transmitter on", name))
        if tx_off:
            steps.append(Step(off, tx_off, "transmitter off", name))
    steps.sort(key=lambda s: s.time)
    return steps


def check_schedule(steps, report, tolerance=1.0):
    """Problems (one line each) between planned ``steps`` and an onboard schedule ``report``:
    ``{"activities": [{"time": POSIX s, "request": words}, ..]}``: every planned command is on
    board within ``tolerance`` seconds of its time, and nothing else is."""
    onboard = [(a["time"], a["request"]) for a in report.get("activities", [])]
    left = list(onboard)
    problems = []
    for s in steps:
        match = None
        for a in left:
            if a[1] == s.request and abs(a[0] - s.time) <= tolerance:
                match = a
                break
        if match is None:
            problems.append("missing on board: %s" % s)
        else:
            left.remove(match)
    for t, req in left:
        problems.append("on board but not planned: %.3f %s" % (t, req))
    return problems
