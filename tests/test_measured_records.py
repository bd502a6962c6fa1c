"""Measured vibration records (issue 12): two records of a real structure from the open-source
Vibration Toolbox (MIT, examples/data/README.md), analysed end to end, and the verdict rules
they showed to be wrong: a harmonic test against an unresolved 'fundamental' in the first bins
(a drift), and verdicts drawn from a record that is not stationary (a hammer-test decay).

The records are fixed data, so the figures asserted on them are arithmetic on fixed numbers;
each bound below is far from its measured value (stated in the test) compared with the
rounding of another CPU (~1e-13 relative for these non-chaotic computations)."""

from pathlib import Path

import numpy as np
import pytest

from recipdyn.analysis.classify import _line_structure, classify, quarter_rms_ratio
from recipdyn.analysis.signal import assess_signal
from recipdyn.analysis.spectrum import amplitude_spectrum
from recipdyn.analyze import analyze_signal
from recipdyn.defaults import MAX_RMS_RATIO
from recipdyn.io_signal import _is_rate_name, read_signal

DATA = Path(__file__).resolve().parents[1] / "examples" / "data"
# Natural frequencies the toolbox's own curve fits give on the FRFs stored in the same files
# (vibration_toolbox/ema.py doctests: sdof_cf on case1, mdof_cf on case2), Hz.
F_CASE1 = 212.09
F_CASE2 = 192.59


def test_the_rate_is_read_from_a_data_logger_variable():
    """The files hold the rate as ``Time_Sample_Rate`` (no 'fs'): it is found by its name."""
    sig = read_signal(DATA / "vtb_case1.mat", column="Time_chan_2")
    assert sig.fs == 1280.0 and sig.x.size == 4096
    assert any("Time_Sample_Rate" in n for n in sig.notes)
    assert _is_rate_name("Time_Sample_Rate") and _is_rate_name("sampling frequency")
    assert not _is_rate_name("Time_chan_1") and not _is_rate_name("rate_of_rise")


def test_hammer_decay_is_not_given_a_verdict(tmp_path):
    """case1's response decays after the hammer hit (quarters' RMS 2.56, 1.02, 0.43, 0.32:
    ratio 7.95). analyze runs end to end, finds the mode where the toolbox's FRF fit puts it
    (within one 0.3125 Hz bin of 212.09 Hz) and refuses a verdict, naming the reason. Before,
    it said 'periodic': its strongest low line sat in bin 1 (a drift), so every line was a
    'harmonic' of it."""
    s = analyze_signal(DATA / "vtb_case1.mat", tmp_path / "a", column="Time_chan_2",
                       quantity="other")  # fmt: skip
    top = max(s["spectrum"]["peaks"], key=lambda p: p["amplitude"])
    assert abs(top["frequency_hz"] - F_CASE1) <= s["spectrum"]["resolution_hz"]
    v = s["verdict"]
    assert v["verdict"] == "undetermined", v["reasons"]
    assert v["reasons"][0].startswith("not stationary")
    assert v["evidence"]["quarter_rms_ratio"] == pytest.approx(7.95, abs=0.01)
    md = (tmp_path / "a" / "summary.md").read_text()
    assert "crosshead" not in md and "crank order" not in md  # a measured signal, no speed
    assert (tmp_path / "a" / "spectrum.png").stat().st_size > 0


def test_steady_response_record():
    """case2's response is steady (quarters' RMS within 3 %): a 192.8 Hz line (one bin from the
    toolbox's fit, 192.59 Hz) with its 3rd harmonic and sidebands 1.25 Hz away, i.e. a slowly
    modulated vibration. Regular, not chaotic or stochastic: the signal exponents are flat
    (divergence rises 0.48 and 0.28 log units, < 0.5), K = 0.002."""
    x = read_signal(DATA / "vtb_case2.mat", column="Time_chan_2").x
    a = assess_signal(x, 1280.0)
    ev = a.verdict.evidence
    assert ev["quarter_rms_ratio"] < 1.1
    assert abs(ev["spectrum_fundamental_hz"] - F_CASE2) <= 1280.0 / 4096
    assert a.verdict.verdict in ("quasi-periodic", "periodic"), a.verdict.reasons
    assert not any(r.ok and r.exponent > ev["lambda1_signal_tolerance"]
                   for r in a.lyapunov.values())  # fmt: skip


def test_a_line_in_the_first_bins_is_not_a_fundamental():
    """A drift (bin 1) beside two incommensurate tones (100 and 100 sqrt 2 bins): the old rule
    took bin 1 as the fundamental, made both tones its harmonics and said 'periodic'. The
    drift is left out (counted) and the tones are not harmonics of each other."""
    n, fs = 8192, 1.0
    t = np.arange(n)
    x = (3.0 * np.sin(2 * np.pi * t / n + 0.3) + np.sin(2 * np.pi * 100 / n * t)
         + 0.7 * np.sin(2 * np.pi * 100 * np.sqrt(2) / n * t))  # fmt: skip
    out = _line_structure(amplitude_spectrum(x, fs))
    assert out["unresolved_lines"] >= 1
    assert out["fundamental_hz"] == pytest.approx(100 / n, abs=1.5 / n)
    assert out["harmonic_fraction"] < 1
    v = classify(spectrum=amplitude_spectrum(x, fs), k01=0.0, lambda1=0.0)
    assert v.verdict == "quasi-periodic", v.reasons
    # a record of 5 periods (a 5-revolution sweep point): its fundamental, at 5 bins, is kept
    short = sum(a * np.sin(2 * np.pi * 5 * k / n * t) for k, a in ((1, 1.0), (2, 0.5), (3, 0.3)))
    out = _line_structure(amplitude_spectrum(short, fs))
    assert out["fundamental_hz"] == pytest.approx(5 / n) and out["harmonic_fraction"] == 1
    assert "unresolved_lines" not in out


def test_quarter_rms_ratio_of_a_decay_and_of_noise():
    """An exponential decay exp(-t/tau) over quarters of length Q: the RMS ratio of the first to
    the last quarter is exp(3Q/tau) up to the oscillation's share of a quarter (200 periods a
    quarter here: < 1e-3 relative). White noise of 20 000 samples: each quarter's RMS has a
    relative scatter of 1/sqrt(2 * 5000) = 1 %, so the ratio stays below 1.2 (20 sigma)."""
    n, tau = 40_000, 20_000.0
    t = np.arange(n)
    x = np.exp(-t / tau) * np.sin(2 * np.pi * 0.02 * t)
    assert quarter_rms_ratio(x) == pytest.approx(np.exp(3 * (n / 4) / tau), rel=2e-3)
    rng = np.random.default_rng(0)
    assert quarter_rms_ratio(rng.standard_normal(20_000)) < 1.2
    stops = np.r_[np.tile([1.0, -1.0], 150), np.zeros(100)]  # mean exactly 0
    assert quarter_rms_ratio(stops) == np.inf
    v = classify(lambda1=5.0, k01=0.95, rms_ratio=MAX_RMS_RATIO * 1.01)
    assert v.verdict == "undetermined" and v.reasons[0].startswith("not stationary")
    assert classify(lambda1=5.0, k01=0.95, rms_ratio=MAX_RMS_RATIO).verdict == "chaotic"


def test_a_runup_with_a_tacho_gets_no_verdict_and_speed_ripple_does_not_count():
    """A 5 -> 15 Hz linear run-up over 4 s (orders 3 and 7.5): the quarters' mean speeds are
    f0 + (f1 - f0)(k + 1/2)/4, ratio 13.75/6.25 = 2.2 exactly for the continuous ramp (the
    sampled quarters' ends shift it by O(1/n) = 1e-4). Its RMS hardly changes (ratio < 1.1),
    so only the speed says it is not stationary. A constant 10 Hz with a 5 % speed ripple
    at the rotation frequency, normal for a reciprocating machine, keeps the ratio at 1 to
    the ripple's unfinished period over a 10-revolution quarter (0.05 / (2 pi 10) < 1e-3): its
    verdict comes from its once-per-revolution section (periodic)."""
    fs, T, f0, f1 = 2000.0, 4.0, 5.0, 15.0
    t = np.arange(int(T * fs)) / fs
    revs = f0 * t + (f1 - f0) * t**2 / (2 * T)
    x = np.sin(2 * np.pi * 3 * revs) + 0.4 * np.sin(2 * np.pi * 7.5 * revs)
    a = assess_signal(x, fs, revs=revs)
    assert a.verdict.evidence["quarter_speed_ratio"] == pytest.approx(2.2, rel=1e-3)
    assert a.verdict.evidence["quarter_rms_ratio"] < 1.1
    assert a.verdict.verdict == "undetermined"
    assert "mean speed" in a.verdict.reasons[0]
    revs = 10.0 * t + 0.05 / (2 * np.pi) * np.sin(2 * np.pi * 10.0 * t)
    b = assess_signal(np.sin(2 * np.pi * 2 * revs), fs, revs=revs)
    assert b.verdict.evidence["quarter_speed_ratio"] < 1.001
    assert b.verdict.verdict == "periodic", b.verdict.reasons
