"""recipdyn.analysis.channel: clipping, the converter step and mains hum read from a channel's
own samples, on synthetic signals of known truth (seeded). Their use on records through
drawn chains: tests/test_diagnosis_chainrange.py and benchmarks/bench_chain_checks.py."""

from __future__ import annotations

import math

import numpy as np
import pytest

from recipdyn.analysis.channel import clipping, level_spacing, mains_hum


def _adc(y, full, bits):
    """Mid-tread rounding to ``2**bits`` codes over +-full (as `recipdyn.sensors.adc`)."""
    lsb = 2 * full / 2**bits
    return np.clip(np.round((y + full) / lsb), 0, 2**bits - 1) * lsb - full, lsb


def _machine(rng, n=40000, fs=10000.0, f_rev=3.3):
    """A periodic 'machine' signal (crank orders 1-40 with random amplitudes and phases, an
    impulse train's spectrum) plus white noise, and its crank angle in revolutions."""
    t = np.arange(n) / fs
    revs = f_rev * t
    k = np.arange(1, 41)[:, None]
    amp = rng.uniform(0.2, 1.0, (40, 1))
    y = np.sum(amp * np.sin(2 * np.pi * k * revs + rng.uniform(0, 2 * np.pi, (40, 1))), axis=0)
    return t, revs, y + 0.5 * rng.standard_normal(n)


@pytest.mark.parametrize("bits", [8, 12, 16])
def test_the_converter_step_is_read_where_the_noise_visits_adjacent_codes(bits):
    """A noisy signal through a ``bits``-bit converter: the step is the LSB (to rounding);
    an unquantised signal has none."""
    rng = np.random.default_rng(bits)
    _, _, y = _machine(rng)
    q, lsb = _adc(y, 20.0, bits)
    assert level_spacing(q) == pytest.approx(lsb, rel=1e-9)
    assert math.isnan(level_spacing(y))


def test_clipping_is_found_on_clipped_signals_and_never_on_unclipped_ones():
    """50 seeded noisy machine signals through a 16-bit converter: none clipped while the
    range holds them (the extreme is reached once: noise), every one clipped when the range
    is 80 % of the peak, naming the end; a smooth, over-sampled, quantised sine (whose peaks
    sit on one code for several samples, turning over within a step) is not clipped."""
    for seed in range(50):
        rng = np.random.default_rng(seed)
        _, _, y = _machine(rng)
        peak = float(np.max(np.abs(y)))
        ok, _ = _adc(y, 1.2 * peak, 16)
        assert not clipping(ok).clipped, seed
        bad, _ = _adc(y, 0.8 * peak, 16)
        c = clipping(bad)
        assert c.clipped and c.samples > 0 and "flat" in c.text(), seed
    t = np.arange(20000) / 10000.0
    sine, _ = _adc(np.sin(2 * np.pi * 2.0 * t), 1.0, 12)
    assert not clipping(sine).clipped


def test_the_hum_interval_covers_the_hum_it_was_given():
    """60 seeded signals: a machine's periodic signal (40 crank orders), white noise, and a
    hum at 50 Hz of a drawn amplitude (0.02-0.3 of the noise's sd, so the fit's noise
    matters). The synchronous average removed first, the 95 % interval must hold the
    amplitude given in 95 % of draws: at least 52 of 60 (the binomial's 1st percentile for
    p = 0.95 is 53). Without the crank angle the machine's order near 50 Hz is read as hum
    when it lies on it."""
    hits = 0
    for seed in range(60):
        rng = np.random.default_rng(100 + seed)
        t, revs, y = _machine(rng)
        a = rng.uniform(0.01, 0.15)
        h = mains_hum(y + a * np.sin(2 * np.pi * 50.0 * t + rng.uniform(0, 6.3)), 10000.0,
                      50.0, revs=revs)  # fmt: skip
        hits += h.lo <= a <= h.hi
    assert hits >= 52, hits


def test_a_mains_harmonic_on_an_order_of_the_speed_is_not_estimated():
    """At a speed whose 14th order is 50 Hz (and 60 Hz its 16.8th) the synchronous average
    holds the 50 Hz hum: not estimated, saying so; the 60 Hz hum beside the orders is read."""
    rng = np.random.default_rng(7)
    t, revs, y = _machine(rng, f_rev=50.0 / 14)
    h = mains_hum(y + 0.3 * np.sin(2 * np.pi * 50 * t), 10000.0, 50.0, revs=revs)
    assert math.isnan(h.amplitude) and "order" in h.note
    h = mains_hum(y + 0.3 * np.sin(2 * np.pi * 60 * t), 10000.0, 60.0, revs=revs)
    assert h.lo <= 0.3 <= h.hi
    assert h.db == pytest.approx(20 * math.log10(h.amplitude / h.rms))
