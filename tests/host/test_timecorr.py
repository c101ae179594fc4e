"""Ground time correlation: offset and drift recovered by least squares from time reports."""

import random

import pytest
from obsw_host.pus.timecorr import Correlation, CorrelationError, correlate, main, uplink


def reports(offset, drift, delay, n=50, jitter=0.0, t0=2.1e9, step=16.0, seed=1):
    rng = random.Random(seed)
    out = []
    for i in range(n):
        utc = t0 + i * step
        obt = utc + offset + drift * (utc - t0)
        out.append((obt, utc + delay + rng.gauss(0.0, jitter)))
    return out


def test_offset_and_drift_exact():
    c = correlate(reports(0.25, 20e-6, 0.004), link_delay=0.004)
    ref = 2.1e9 + 49 * 16.0 / 2
    assert c.drift == pytest.approx(20e-6, rel=1e-6)
    assert c.offset == pytest.approx(0.25 + 20e-6 * (ref - 2.1e9), abs=1e-6)
    assert c.rms < 1e-6
    assert c.correction()["drift_ppb"] == 20000


def test_jitter_averages_out():
    c = correlate(reports(-1.5, -3e-6, 0.12, n=400, jitter=0.002), link_delay=0.12)
    assert c.drift == pytest.approx(-3e-6, abs=2e-7)
    assert c.rms == pytest.approx(0.002, rel=0.2)
    utc = 2.1e9 + 100.0
    assert c.utc(utc - 1.5 - 3e-6 * 100.0) == pytest.approx(utc, abs=1e-3)


def test_ignoring_the_link_delay_biases_the_offset():
    c = correlate(reports(0.0, 0.0, 0.3))
    assert c.offset == pytest.approx(-0.3, abs=1e-6)  # the reports look late by the delay


def test_too_few_or_degenerate():
    with pytest.raises(CorrelationError):
        correlate([(1.0, 2.0)])
    with pytest.raises(CorrelationError):
        correlate([(1.0, 2.0), (1.0, 2.0)])


def test_uplink_is_a_mission_function():
    calls = []

    class Ground:
        def perform(self, key, apid=None, timeout=None, **arguments):
            calls.append((key, arguments))
            return "tx"

    assert uplink(Ground(), Correlation(0.0, 0.0126, 1e-6, 0.0, 2)) == "tx"
    assert calls == [("OnboardTime.correct", {"offset_ms": 13, "drift_ppb": 1000})]


def test_command_line(tmp_path, capsys):
    f = tmp_path / "reports.txt"
    f.write_text("".join("%.6f %.6f\n" % r for r in reports(0.5, 0.0, 0.01, n=10)))
    assert main([str(f), "--delay", "0.01"]) == 0
    assert "offset 0.500000 s" in capsys.readouterr().out
    f.write_text("1 2\n")
    assert main([str(f)]) == 2
