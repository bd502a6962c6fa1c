"""Lyapunov exponents from signals: Wolf, Rosenstein, Kantz; embedding helpers."""

import numpy as np
import pytest

from recipdyn.analysis import (
    delay_embed,
    estimate_delay,
    estimate_dimension,
    lyap_kantz,
    lyap_rosenstein,
    lyap_wolf,
)
from recipdyn.integrate import integrate
from recipdyn.model.reference import systems as S

LAMBDA_LORENZ = 0.9056


@pytest.fixture(scope="module")
def lorenz_x():
    """The Lorenz x-signal (20 000 samples at dt = 0.01 after a transient of 50) from four
    starts 1e-6 apart: four independent samples of the chaotic signal, as four CPUs' rounding
    would give."""
    dt = 0.01
    runs = [integrate(S.lorenz(), np.array([1.0, 1.0, 1.0]) * (1 + 1e-6 * i),
                      (0, 50 + 20000 * dt), t_eval=50 + np.arange(20000) * dt, rtol=1e-10)
            for i in range(4)]  # fmt: skip
    return [r.y[:, 0] for r in runs], dt


#: Bounds on the mean relative error of the four signals' estimates. Measured on 16 signals
#: (relative to 0.9056): Wolf +11.2 % mean, sigma 4.7 % (+5 ... +24 %: one signal held to 15 %
#: failed for some starts, i.e. on some CPUs); Rosenstein +1.3 %, sigma 3.8 %; Kantz +5.2 %,
#: sigma 3.0 %. Bound = |mean| + 4 sigma / 2.
BOUNDS = {"lyap_wolf": 0.21, "lyap_rosenstein": 0.10, "lyap_kantz": 0.12}


@pytest.mark.parametrize("method", [lyap_wolf, lyap_rosenstein, lyap_kantz])
def test_lorenz_within_their_measured_accuracy(lorenz_x, method):
    """Default settings (everything estimated from the data) give lambda1 of the Lorenz
    x-signal within each estimator's measured accuracy of 0.906 (all within the 25 % that the
    chaotic test signals are held to)."""
    xs, dt = lorenz_x
    rs = [method(x, dt) for x in xs]
    err = np.mean([r.exponent for r in rs]) / LAMBDA_LORENZ - 1.0
    assert abs(err) < BOUNDS[method.__name__], err
    assert all(r.params["dim"] >= 2 and r.params["delay"] >= 1 for r in rs)


@pytest.mark.parametrize("method", [lyap_wolf, lyap_rosenstein, lyap_kantz])
@pytest.mark.parametrize("kind", ["periodic", "quasi-periodic"])
def test_regular_signals_give_no_positive_exponent(method, kind):
    """A sine and an incommensurate two-tone signal: lambda1 <= 0.02 (per time unit; compare
    0.9 for Lorenz at the same sampling)."""
    t = np.arange(20000) * 0.01
    x = np.sin(2 * np.pi * 0.7 * t)
    if kind == "quasi-periodic":
        x = x + 0.6 * np.sin(2 * np.pi * 0.7 * np.sqrt(2) * t)
    assert method(x, 0.01).exponent <= 0.02


def test_zero_distances_do_not_give_minus_inf():
    """An exactly repeating record (period of 100 samples) has neighbours at distance 0: the
    estimates stay finite."""
    x = np.tile(np.sin(2 * np.pi * np.arange(100) / 100), 60)
    for method in (lyap_wolf, lyap_rosenstein, lyap_kantz):
        assert np.isfinite(method(x, 1.0).exponent)


def test_fit_stops_before_saturation(lorenz_x):
    """The automatic Rosenstein fit ends before the divergence curve saturates (each signal)."""
    xs, dt = lorenz_x
    for x in xs:
        r = lyap_rosenstein(x, dt)
        lo, hi = r.fit
        c = r.curve
        assert c[hi] < c[0] + 0.75 * (np.nanmax(c) - c[0])
        assert hi > lo + 3


def test_embedding_helpers(lorenz_x):
    xs, _ = lorenz_x
    X = delay_embed(np.arange(10.0), 3, 2)
    np.testing.assert_array_equal(X[0], [0, 2, 4])
    assert X.shape == (6, 3)
    for x in xs:
        tau = estimate_delay(x)
        assert 8 <= tau <= 25  # ~0.16 s for Lorenz x at dt = 0.01 (first AMI minimum)
        assert 2 <= estimate_dimension(x, tau) <= 4
    with pytest.raises(ValueError):
        delay_embed(np.arange(5.0), 4, 2)


def test_bad_signals():
    with pytest.raises(ValueError, match="constant"):
        lyap_rosenstein(np.ones(500))
    with pytest.raises(ValueError, match="NaN"):
        lyap_wolf(np.r_[np.ones(100), np.nan])
