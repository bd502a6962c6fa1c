"""Poincaré sections: exact stroboscopic sampling, root-found hyperplane crossings."""

import numba as nb
import numpy as np
import pytest

from recipdyn.analysis.poincare import (
    count_distinct_points,
    hyperplane_section,
    stroboscopic_section,
)
from recipdyn.model import CompressorParams, ODESystem, compressor_model
from recipdyn.model.base import RHS_SIGNATURE


@nb.njit(RHS_SIGNATURE, cache=True)
def _forced_linear(t, y, p, out):
    # x'' + c x' + k x = cos(w t): a unique period-1 attractor
    out[0] = y[1]
    out[1] = -p[0] * y[1] - p[1] * y[0] + np.cos(p[2] * t)


FORCED = ODESystem(rhs=_forced_linear, params=np.array([0.5, 1.0, 1.3]), state_names=("x", "v"),
                   period=2 * np.pi / 1.3)  # fmt: skip


def test_stroboscopic_section_of_a_period_one_orbit_is_one_point():
    """After the transient decays, a damped linearly forced oscillator gives one point, equal to
    the analytic steady state at the section phase."""
    ds = stroboscopic_section(FORCED, [0.0, 0.0], 20, transient_periods=60, rtol=1e-11)
    assert count_distinct_points(np.c_[ds.x, ds.v]) == 1
    c, k, w = 0.5, 1.0, 1.3
    amp = 1 / complex(k - w**2, c * w)  # x = Re(amp e^{i w t})
    t = ds.time.values
    np.testing.assert_allclose(ds.x, (amp * np.exp(1j * w * t)).real, atol=1e-8)
    k = ds.time.values / FORCED.period
    np.testing.assert_allclose(k, np.round(k), atol=1e-12)


def test_ideal_compressor_is_period_one():
    """rc = 0: the ideal mechanism's crosshead is strictly periodic: one section point."""
    m = compressor_model(CompressorParams(rc=0.0))
    ds = stroboscopic_section(m, m.initial_state(), 10, phase=0.5)
    assert count_distinct_points(np.c_[ds.x, ds.v, ds.a]) == 1
    assert ds.x.attrs["units"] == "m"


def test_hyperplane_crossings_are_exact():
    """Upward zero crossings of v in the steady state are the displacement minima,
    x = -|amp|, found to ~1e-9."""
    ds = hyperplane_section(FORCED, [0.0, 0.0], (0.0, 260.0), index=1, value=0.0,
                            direction=1, rtol=1e-12, atol=1e-14)  # fmt: skip
    ds = ds.isel(section=ds.time.values > 200.0)  # after the transient (decay rate 0.25/s)
    amp = abs(1 / complex(1 - 1.3**2, 0.5 * 1.3))
    assert ds.sizes["section"] >= 10
    np.testing.assert_allclose(ds.v, 0.0, atol=1e-10)
    np.testing.assert_allclose(ds.x, -amp, atol=1e-8)


def test_count_distinct_points():
    pts = np.array([[1.0, 2.0], [1.0 + 1e-9, 2.0], [3.0, 4.0]])
    assert count_distinct_points(pts) == 2
    assert count_distinct_points(np.random.default_rng(0).normal(size=(50, 2))) == 50


def test_bad_section_arguments():
    with pytest.raises(ValueError, match="period"):
        stroboscopic_section(ODESystem(rhs=_forced_linear, params=np.ones(3),
                                       state_names=("x", "v")), [0, 0], 3)  # fmt: skip
    with pytest.raises(ValueError, match="index"):
        hyperplane_section(FORCED, [0, 0], (0, 1), index=5)


@nb.njit(RHS_SIGNATURE, cache=True)
def _hopf(t, y, p, out):
    # the Hopf normal form in polar coordinates: r -> 1, theta turns at w + b r^2
    out[0] = p[0] + p[1] * y[1] * y[1]
    out[1] = y[1] * (1.0 - y[1] * y[1])


HOPF = ODESystem(rhs=_hopf, params=np.array([2.0, 0.7]), state_names=("theta", "r"))


def _hopf_exact(t, r0, w=2.0, b=0.7):
    """theta(t) - theta0 and r(t) in closed form: r^2 = 1 / (1 + c e^-2t), c = 1/r0^2 - 1, and
    the integral of r^2 is t + ln((1 + c e^-2t) / (1 + c)) / 2."""
    c = 1.0 / r0**2 - 1.0
    q = 1.0 + c * np.exp(-2.0 * t)
    return w * t + b * (t + 0.5 * np.log(q / (1.0 + c))), 1.0 / np.sqrt(q)


def test_angle_section_of_an_autonomous_system_is_exact():
    """The section once per turn of theta at phase 1 rad, with theta's speed changing as r
    grows: every point lies at theta = 1 + 2 pi k to rounding, and its time and r are the closed
    form's. The bound 1e-9: the integration's error at rtol 1e-12 over ~2 time units of a
    contracting flow is ~1e-11; the Newton iteration stops at 4 eps |theta|."""
    from scipy.optimize import brentq

    from recipdyn.analysis.poincare import angle_section

    r0, th0 = 0.2, 0.3
    ds = angle_section(HOPF, [th0, r0], 6, index=0, turn_time=np.pi, phase=1.0, rtol=1e-12,
                       atol=1e-14)  # fmt: skip
    k = np.arange(6)
    np.testing.assert_allclose(ds.theta, 1.0 + 2 * np.pi * k, rtol=0, atol=1e-13)
    t_exact = [brentq(lambda t, g=g: _hopf_exact(t, r0)[0] - g, 0.0, 40.0, xtol=1e-15)
               for g in 1.0 + 2 * np.pi * k - th0]  # fmt: skip
    np.testing.assert_allclose(ds.time, t_exact, rtol=0, atol=1e-9)
    np.testing.assert_allclose(ds.r, _hopf_exact(np.array(t_exact), r0)[1], rtol=0, atol=1e-9)
    assert ds.attrs["section"] == "angle" and ds.attrs["angle"] == "theta"
    # a transient of 3 turns starts the section 3 turns later: the same points from the 4th on
    later = angle_section(HOPF, [th0, r0], 3, index=0, turn_time=np.pi, phase=1.0,
                          transient_turns=3, rtol=1e-12, atol=1e-14)  # fmt: skip
    np.testing.assert_allclose(later.time, ds.time[3:], rtol=0, atol=1e-9)


def test_angle_times_of_a_record():
    """From a sampled angle: the instants it passes phase + 2 pi k, within the linear
    interpolation's bound h^2 max|theta''| / (8 min theta') of the closed form; an angle that
    does not increase is refused."""
    from scipy.optimize import brentq

    from recipdyn.analysis.poincare import angle_times

    r0, th0 = 0.2, 0.3
    t = np.linspace(0.0, 8.0, 4001)
    dth, _ = _hopf_exact(t, r0)
    ts = angle_times(t, th0 + dth, phase=1.0)
    targets = 1.0 + 2 * np.pi * np.arange(ts.size)
    exact = [brentq(lambda s, g=g: _hopf_exact(s, r0)[0] - g, 0.0, 40.0, xtol=1e-15)
             for g in targets - th0]  # fmt: skip
    h = t[1] - t[0]
    acc = np.abs(np.gradient(np.gradient(dth, h), h)).max()  # |theta''| (its max, sampled)
    bound = h**2 * acc / (8 * 2.0)  # theta' >= w = 2
    assert ts.size == int((th0 + dth[-1] - 1.0) // (2 * np.pi)) + 1
    np.testing.assert_allclose(ts, exact, rtol=0, atol=1.5 * bound)
    with pytest.raises(ValueError, match="increase"):
        angle_times(t, np.cos(t))
