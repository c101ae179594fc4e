"""Pass prediction: when the mission's ground stations see the spacecraft, and what each pass
can carry.

The orbit is the mission's TLE propagated with SGP4 (``sgp4`` from PyPI), rotated from TEME to
the Earth-fixed frame by the Greenwich mean sidereal time (IAU 1982, UT1 taken as UTC: the
sub-second difference moves a pass by far less than the 10 ms the times are found to), and seen
from each station on the WGS84 ellipsoid. A pass is a maximum of elevation above the station's
``min_elevation``: the elevation is sampled every ``STEP`` seconds, each local maximum refined,
and AOS and LOS found by bisection to ``EPSILON`` seconds. Only passes that rise and set inside
the window are listed. Times are POSIX seconds (UTC) inside, ISO UTC strings outside.
"""

import math

from obsw_host.ops.tle import format_time

STEP = 30.0  # sampling of the elevation, s (a LEO pass above 0 degrees lasts minutes)
EPSILON = 0.01  # AOS, LOS and the culmination are found to this, s
_A = 6378.137  # WGS84 equatorial radius, km
_F = 1 / 298.257223563  # WGS84 flattening
_E2 = _F * (2 - _F)
_UNIX_JD = 2440587.5  # the Julian date of 1970-01-01T00:00:00Z


class Station:
    """A ground station of the mission file (``stations[]``)."""

    def __init__(self, name, latitude, longitude, altitude, min_elevation, uplink_bps,
                 downlink_bps):  # fmt: skip
        self.name = name
        self.latitude = latitude
        self.longitude = longitude
        self.altitude = altitude
        self.min_elevation = min_elevation
        self.uplink_bps = uplink_bps
        self.downlink_bps = downlink_bps
        lat, lon, h = math.radians(latitude), math.radians(longitude), altitude / 1000.0
        n = _A / math.sqrt(1 - _E2 * math.sin(lat) ** 2)
        self.ecef = (
            (n + h) * math.cos(lat) * math.cos(lon),
            (n + h) * math.cos(lat) * math.sin(lon),
            (n * (1 - _E2) + h) * math.sin(lat),
        )
        self.up = (math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat))

    @classmethod
    def from_doc(cls, d):
        return cls(d["name"], d["latitude"], d["longitude"], d["altitude"], d["min_elevation"],
                   d["uplink_bps"], d["downlink_bps"])  # fmt: skip


class Pass:
    """One pass of the spacecraft over ``station``: ``aos``, ``tca``, ``los`` (POSIX seconds,
    UTC), ``max_elevation`` (degrees); what it can carry follows from the station's rates."""

    def __init__(self, station, aos, tca, los, max_elevation):
        self.station = station
        self.aos = aos
        self.tca = tca
        self.los = los
        self.max_elevation = max_elevation

    @property
    def duration(self):
        return self.los - self.aos

    @property
    def downlink_octets(self):
        return int(self.station.downlink_bps * self.duration / 8)

    @property
    def uplink_octets(self):
        return int(self.station.uplink_bps * self.duration / 8)

    def to_dict(self):
        return {
            "station": self.station.name,
            "aos": format_time(_datetime(self.aos)),
            "tca": format_time(_datetime(self.tca)),
            "los": format_time(_datetime(self.los)),
            "max_elevation": round(self.max_elevation, 2),
            "duration": round(self.duration, 1),
            "downlink_octets": self.downlink_octets,
            "uplink_octets": self.uplink_octets,
        }

    def __repr__(self):
        return "Pass(%s, %s, %.0f s, %.1f deg)" % (
            self.station.name, format_time(_datetime(self.aos)), self.duration,
            self.max_elevation)  # fmt: skip


def _datetime(t):
    import datetime

    return datetime.datetime.fromtimestamp(t, datetime.timezone.utc)


def gmst(t):
    """Greenwich mean sidereal time (IAU 1982) at POSIX time ``t`` (UT1 = UTC), radians."""
    tut1 = (t / 86400.0 + _UNIX_JD - 2451545.0) / 36525.0
    s = ((-6.2e-6 * tut1 + 0.093104) * tut1 + (876600.0 * 3600 + 8640184.812866)) * tut1
    s += 67310.54841
    return math.radians((s / 240.0) % 360.0)


class Predictor:
    """The mission's orbit (a ``Tle``) seen from its stations."""

    def __init__(self, tle, stations):
        self.tle = tle
        self.stations = list(stations)
        self._sat = tle.satrec()

    def ecef(self, t):
        """The spacecraft's Earth-fixed position at POSIX time ``t``, km."""
        jd = t / 86400.0 + _UNIX_JD
        whole = math.floor(jd)
        err, r, _ = self._sat.sgp4(whole, jd - whole)
        if err:
            raise ValueError("SGP4 error %d at %s; expected a TLE valid then" % (
                err, format_time(_datetime(t))))  # fmt: skip
        g = gmst(t)
        c, s = math.cos(g), math.sin(g)
        return (c * r[0] + s * r[1], -s * r[0] + c * r[1], r[2])

    def elevation(self, station, t, at=None):
        """Elevation of the spacecraft above ``station``'s horizon, degrees (``at``: its ECEF
        position at ``t`` when already known)."""
        x, y, z = at or self.ecef(t)
        sx, sy, sz = station.ecef
        dx, dy, dz = x - sx, y - sy, z - sz
        u = station.up
        return math.degrees(math.asin((dx * u[0] + dy * u[1] + dz * u[2])
                                      / math.sqrt(dx * dx + dy * dy + dz * dz)))  # fmt: skip

    def passes(self, start, end, stations=None):
        """Every pass that rises and sets in [start, end] (POSIX s), by AOS."""
        stations = self.stations if stations is None else stations
        n = int((end - start) // STEP) + 1
        times = [start + i * STEP for i in range(n)]
        if times[-1] < end:
            times.append(end)
        positions = [self.ecef(t) for t in times]
        found = []
        for st in stations:
            els = [self.elevation(st, t, p) for t, p in zip(times, positions)]
            found += self._passes_over(st, times, els)
        found.sort(key=lambda p: (p.aos, p.station.name))
        return found

    def _passes_over(self, st, times, els):
        out = []
        last_los = None
        for i in range(1, len(times) - 1):
            if not (els[i - 1] < els[i] >= els[i + 1]):
                continue
            tca, top = self._culmination(st, times[i - 1], times[i + 1])
            if top < st.min_elevation:
                continue
            j = i  # back to the last sample below the horizon mask
            while j > 0 and els[j] >= st.min_elevation:
                j -= 1
            k = i
            while k < len(times) - 1 and els[k] >= st.min_elevation:
                k += 1
            if els[j] >= st.min_elevation or els[k] >= st.min_elevation:
                continue  # in view at the window's edge: not a whole pass
            aos = self._crossing(st, times[j], min(times[j + 1], tca), rising=True)
            los = self._crossing(st, max(times[k - 1], tca), times[k], rising=False)
            if last_los is not None and aos < last_los:
                continue  # a second maximum of the same pass
            last_los = los
            out.append(Pass(st, aos, tca, los, top))
        return out

    def _culmination(self, st, a, b):
        """Golden-section search of the elevation's maximum in [a, b]: (time, degrees)."""
        g = (math.sqrt(5) - 1) / 2
        c, d = b - g * (b - a), a + g * (b - a)
        fc, fd = self.elevation(st, c), self.elevation(st, d)
        while b - a > EPSILON:
            if fc > fd:
                b, d, fd = d, c, fc
                c = b - g * (b - a)
                fc = self.elevation(st, c)
            else:
                a, c, fc = c, d, fd
                d = a + g * (b - a)
                fd = self.elevation(st, d)
        t = (a + b) / 2
        return t, self.elevation(st, t)

    def _crossing(self, st, a, b, rising):
        """Bisection of the time the elevation crosses ``min_elevation`` in [a, b]."""
        while b - a > EPSILON:
            m = (a + b) / 2
            above = self.elevation(st, m) >= st.min_elevation
            if above == rising:
                b = m
            else:
                a = m
        return (a + b) / 2


def from_mission(doc):
    """The ``Predictor`` of a checked mission file's ``orbit`` and ``stations``."""
    from obsw_host.ops.tle import parse

    orbit = doc["orbit"]
    tle = parse(orbit["tle"], orbit.get("name"))
    return Predictor(tle, [Station.from_doc(s) for s in doc["stations"]])
