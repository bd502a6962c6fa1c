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
