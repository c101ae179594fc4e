"""Pass prediction (obsw_host.ops.passes) against an independent oracle: skyfield's
find_events on the same TLE, a week of passes over three stations, AOS, culmination and LOS
within 2 s, and no pass missing or extra."""

import pytest
import skyfield.api as skyfield_api
from obsw_host.ops.passes import Predictor, Station
from obsw_host.ops.tle import TleError, checksum, parse

LINE1 = "1 99001U 26001A   26332.50000000  .00001000  00000-0  50000-4 0  9999"
LINE2 = "2 99001  97.4000 330.0000 0001000  90.0000 270.0000 15.20000000   105"
# an ISS-like orbit too: 51.6 degrees, a different altitude and eccentricity
ISS1 = "1 25544U 98067A   26330.25000000  .00016717  00000-0  10270-3 0  9993"
ISS2 = "2 25544  51.6416 247.4627 0006703 130.5360 325.0288 15.49815329 12345"
STATIONS = [
    Station("munich", 48.15, 11.57, 520.0, 10.0, 9600, 38400),
    Station("kiruna", 67.86, 20.96, 390.0, 5.0, 9600, 38400),
    Station("cordoba", -31.52, -64.46, 730.0, 15.0, 9600, 38400),
]
# an inclination of 51.6 degrees never rises high over Kiruna: a station near the equator instead
LOW_STATIONS = (
    STATIONS[:1] + STATIONS[2:] + [Station("singapore", 1.35, 103.82, 15.0, 10.0, 9600, 38400)]
)
TOLERANCE = 2.0  # s: the bound


def _fix(line):
    return line[:68] + str(checksum(line))


def _oracle(line1, line2, station, t0, t1):
    ts = skyfield_api.load.timescale(builtin=True)
    sat = skyfield_api.EarthSatellite(line1, line2, "sat", ts)
    where = skyfield_api.wgs84.latlon(station.latitude, station.longitude, station.altitude)
    t, events = sat.find_events(
        where, ts.from_datetime(t0), ts.from_datetime(t1), altitude_degrees=station.min_elevation
    )
    passes, cur = [], None
    for ti, ev in zip(t, events):
        ts_ = ti.utc_datetime().timestamp()
        if ev == 0:
            cur = [ts_, None, None]
        elif ev == 1 and cur is not None:
            cur[1] = ts_
        elif ev == 2 and cur is not None:
            cur[2] = ts_
            passes.append(tuple(cur))
            cur = None
    return passes


@pytest.mark.parametrize(
    "lines, stations",
    [((LINE1, LINE2), STATIONS), ((_fix(ISS1), _fix(ISS2)), LOW_STATIONS)],
    ids=["sso", "iss"],
)
def test_a_week_of_three_stations_agrees_with_skyfield(lines, stations):
    tle = parse(list(lines))
    pred = Predictor(tle, stations)
    t0 = tle.epoch
    import datetime

    t1 = t0 + datetime.timedelta(days=7)
    ours = pred.passes(t0.timestamp(), t1.timestamp())
    total = 0
    for st in stations:
        mine = [(p.aos, p.tca, p.los) for p in ours if p.station is st]
        theirs = _oracle(lines[0], lines[1], st, t0, t1)
        assert len(theirs) >= 7, "a week over %s has passes" % st.name
        assert len(mine) == len(theirs), (st.name, len(mine), len(theirs))
        for m, o in zip(mine, theirs):
            for a, b, what in zip(m, o, ("AOS", "TCA", "LOS")):
                assert abs(a - b) <= TOLERANCE, (st.name, what, a, b)
        total += len(mine)
    assert total >= 30


def test_tle_checks():
    assert parse([LINE1, LINE2]).epoch.isoformat() == "2026-11-28T12:00:00+00:00"
    bad = LINE1[:68] + str((checksum(LINE1) + 1) % 10)
    with pytest.raises(TleError, match="checksum"):
        parse([bad, LINE2])
    with pytest.raises(TleError, match="69"):
        parse([LINE1[:-1], LINE2])
    with pytest.raises(TleError, match="same object"):
        parse([LINE1, _fix(LINE2[:2] + "99002" + LINE2[7:])])
    with pytest.raises(TleError, match="two lines"):
        parse([LINE1])


def test_volume_follows_the_station_rate():
    tle = parse([LINE1, LINE2])
    pred = Predictor(tle, STATIONS[:1])
    t0 = tle.epoch.timestamp()
    (p, *_) = pred.passes(t0, t0 + 86400)
    assert p.downlink_octets == int(38400 * (p.los - p.aos) / 8)
    assert p.uplink_octets == int(9600 * (p.los - p.aos) / 8)
    assert 300 < p.duration < 900
