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
