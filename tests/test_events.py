"""Events that act: terminal events and state resets (impact laws), located on the dense output.

The bouncing ball has a closed form for everything: dropped from rest at height h0, it first
hits the ground at t1 = sqrt(2 h0 / g) with speed v1 = g t1; after the k-th impact (coefficient
of restitution e) it leaves with e^k v1 and flies for 2 e^k v1 / g. Between impacts y'' = -g is
integrated exactly by any 8th-order method (the solution is a parabola), so the errors are the
event location's (~1e-15 relative) and the accumulation over a few impacts.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest

from recipdyn.errors import ParameterError
from recipdyn.integrate import integrate
from recipdyn.model.base import EVENT_SIGNATURE, RHS_SIGNATURE, ODESystem

G, E, H0 = 9.81, 0.8, 2.0


@nb.njit(RHS_SIGNATURE, cache=True)
def _fall(t, y, p, out):
    out[0] = y[1]
    out[1] = -p[0]


@nb.njit(EVENT_SIGNATURE, cache=True)
def _ground(t, y, p):
    return y[0]


@nb.njit(RHS_SIGNATURE, cache=True)
def _bounce(t, y, p, out):
    out[0] = 0.0
    out[1] = -p[1] * y[1]


BALL = ODESystem(rhs=_fall, params=np.array([G, E]), state_names=("y", "v"), name="ball")


def _impacts(n):
    t1 = math.sqrt(2 * H0 / G)
    v1 = G * t1
    times, speeds = [t1], [v1]
    for k in range(1, n):
        times.append(times[-1] + 2 * E**k * v1 / G)
        speeds.append(E**k * v1)
    return np.array(times), np.array(speeds)


def test_resets_give_the_closed_form_impacts():
    times, speeds = _impacts(8)
    sol = integrate(BALL, [H0, 0.0], (0.0, times[-1] + 0.01), event=_ground, event_direction=-1,
                    event_action="reset", reset=_bounce, rtol=1e-12, atol=1e-12)  # fmt: skip
    assert sol.t_events.size == 8
    np.testing.assert_allclose(sol.t_events, times, rtol=1e-9)
    np.testing.assert_allclose(-sol.y_events[:, 1], speeds, rtol=1e-9)  # impact velocities
    # the delivered coefficient of restitution, impact by impact
    np.testing.assert_allclose(sol.y_events_after[:, 1] / -sol.y_events[:, 1], E, rtol=1e-12)
    assert np.all(np.abs(sol.y_events[:, 0]) < 1e-9)


def test_outputs_after_a_reset_follow_the_new_trajectory():
    """Samples inside the step that contains an impact come from the post-impact parabola."""
    times, speeds = _impacts(3)
    te = np.linspace(0.0, times[2] - 1e-3, 3001)
    sol = integrate(BALL, [H0, 0.0], (0.0, te[-1]), t_eval=te, event=_ground,
                    event_direction=-1, event_action="reset", reset=_bounce)  # fmt: skip
    exact = np.where(te < times[0], H0 - G * te**2 / 2, 0.0)
    mid = (te >= times[0]) & (te < times[1])
    s = te[mid] - times[0]
    exact[mid] = E * speeds[0] * s - G * s**2 / 2
    late = te >= times[1]
    s = te[late] - times[1]
    exact[late] = E * speeds[1] * s - G * s**2 / 2
    np.testing.assert_allclose(sol.y[:, 0], exact, atol=1e-8)


def test_terminal_event_stops_at_the_event():
    times, speeds = _impacts(1)
    te = np.linspace(0, 2 * times[0], 100)  # no sample exactly at the event
    sol = integrate(BALL, [H0, 0.0], (0.0, te[-1]), t_eval=te, event=_ground,
                    event_direction=-1, event_action="terminal")  # fmt: skip
    assert sol.status == 1 and sol.t_final == pytest.approx(times[0], rel=1e-12)
    assert sol.y_final == pytest.approx([0.0, -speeds[0]], abs=1e-9)
    assert sol.t.size == int(np.searchsorted(te, times[0], side="right"))  # nothing after it


def test_record_only_events_do_not_change_the_trajectory():
    te = np.linspace(0, 0.5, 11)
    a = integrate(BALL, [H0, 0.0], (0.0, 0.5), t_eval=te)
    b = integrate(BALL, [H0, 0.0], (0.0, 0.5), t_eval=te, event=_ground)
    assert np.array_equal(a.y, b.y)


def test_event_settings_are_checked():
    with pytest.raises(ParameterError, match="event_action"):
        integrate(BALL, [H0, 0.0], (0, 1), event=_ground, event_action="explode")
    with pytest.raises(ParameterError, match="reset function"):
        integrate(BALL, [H0, 0.0], (0, 1), event=_ground, event_action="reset")
    with pytest.raises(ParameterError, match="needs an event"):
        integrate(BALL, [H0, 0.0], (0, 1), event_action="terminal")
    with pytest.raises(ParameterError, match="dop853"):
        integrate(BALL, [H0, 0.0], (0, 1), event=_ground, method="rk4", h=0.01)


# --- events in the tangent-space (Lyapunov) integration: saltation matrices ---------------


def _impact_oscillator(**kw):
    from recipdyn.model.registry import get_model

    m = get_model("impact-oscillator")
    v = m.parameters(kw)
    return m, v, m.system(v)


@pytest.mark.parametrize("kw", [{}, dict(w=2.0), dict(zeta=0.02, w=3.0, A=0.5)])
def test_exponent_sum_with_impacts_is_exact(kw):
    """Every impact v+ = -r v- has a saltation matrix of determinant r**2 (whatever the
    accelerations before and after), the flow's divergence is -2 zeta, so along any run the
    exponents sum to -2 zeta + 2 N ln(r) / T exactly, N impacts in time T. The QR logs add up
    to log|det| of the tangent map up to rounding and the integration error of the tangent
    vectors (rtol 1e-10 per step, ~1e-8 after 10^4 steps), and the saltation matrices use
    central differences (relative error ~1e-10): a tolerance of 1e-7 per time unit is 100x
    above both, yet a missing or wrong saltation (det 1, or det r) is off by >= 2e-2. The
    identity holds along whatever trajectory a CPU computes, chaotic (the default) or not."""
    from recipdyn.analysis.lyapunov import lyapunov_spectrum

    m, v, s = _impact_oscillator(**kw)
    T = m.period(v)
    r = lyapunov_spectrum(s, m.initial_state(v), 200 * T, t_transient=50 * T)
    n_impacts = r.settings["events"]
    assert n_impacts >= 150  # about one impact per forcing period in these cases
    exact = -2 * v["zeta"] + 2 * n_impacts * np.log(v["r"]) / (r.t_final - r.t_start)
    assert abs(r.sum - exact) < 1e-7


def test_impact_exponents_equal_the_floquet_multipliers_of_a_periodic_orbit():
    """On a stable period-1 impacting orbit (w = 2) the exponents are ln|mu| / T of the
    eigenvalues mu of the one-period map's Jacobian, computed here independently by central
    differences of whole-period integrations with impacts (no saltation matrix involved). The
    Benettin estimate converges like 1/T_avg: its bias is at most ln(cond(V)) / T_avg, V the
    eigenvector matrix (the initial basis's components along the eigenvectors), which sets the
    tolerance; the FD Jacobian's error (~1e-9) is negligible beside it."""
    from recipdyn.analysis.lyapunov import lyapunov_spectrum
    from recipdyn.integrate import propagate

    m, v, s = _impact_oscillator(w=2.0)
    T = m.period(v)
    kw = dict(rtol=1e-12, atol=1e-12)
    y = propagate(s, m.initial_state(v), 0.0, 400 * T, **kw)
    one = lambda y0: propagate(s, y0, 0.0, T, **kw)  # noqa: E731 - forcing is T-periodic
    assert np.abs(one(y) - y).max() < 1e-9  # a period-1 orbit
    J = np.empty((2, 2))
    for i in range(2):
        d = np.zeros(2)
        d[i] = 1e-6
        J[:, i] = (one(y + d) - one(y - d)) / 2e-6
    mu, V = np.linalg.eig(J)
    floquet = np.sort(np.log(np.abs(mu)) / T)[::-1]
    t_avg = 400 * T
    r = lyapunov_spectrum(s, y, t_avg)
    tol = 2 * np.log(np.linalg.cond(V)) / t_avg + 1e-6
    np.testing.assert_allclose(r.exponents, floquet, atol=tol)
    assert r.settings["events"] == 400


def test_a_hyperplane_section_of_a_model_with_impacts_is_refused():
    """The integrator locates one event function: a section plane cannot be added to a model
    whose impacts are an event, and saying so beats integrating through the stop."""
    from recipdyn.analysis.poincare import hyperplane_section

    _, v, s = _impact_oscillator()
    with pytest.raises(ParameterError, match="own reset event"):
        hyperplane_section(s, [-0.5, 0.0], (0.0, 100.0), index=1, value=0.0)
