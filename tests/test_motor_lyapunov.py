"""Benettin's exponents with a motor drive (issue 30): the crank angle and speed are states,
the system is autonomous.

* the tangent flow, integrated with the Jacobian and mapped through each contact event's
  saltation matrix, equals differences of the flow with the crank free (contact and
  lubricated pins) and on the rigid-pin route;
* the autonomous flow has one exponent 0 (the direction of the flow) to the estimator's
  1/T error;
* the sum of the exponents is the time average of the trace of the Jacobian over the degrees
  of freedom (the events' saltation matrices have determinant 1 on them);
* the flywheel limit: with J_drive large the exponents approach the prescribed crank's.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from test_contact import _events_kw

from recipdyn.analysis.lyapunov import _tangent_reset, tangent_system
from recipdyn.errors import LawRangeWarning, ModelValidityWarning
from recipdyn.integrate import integrate
from recipdyn.model.registry import get_model

#: Impacts at the crank pin with the crank free: 150 rad/s with a tenth of the paper's load
#: (the contact model's event example), an induction motor synchronous just above.
IMPACTS = {"omega": 150.0, "load_amplitude": 2e4, "drive": "motor", "motor_sync_speed": 160.0}


def _values(kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelValidityWarning)
        warnings.simplefilter("ignore", LawRangeWarning)
        m = get_model("compressor")
        return m, m.parameters(kw)


@pytest.mark.parametrize("pins,fraction,eps,bound", [
    ({"crank_joint": "contact"}, 1.0, 1e-5, 2e-3),
    ({"crank_joint": "contact", "crosshead_joint": "contact"}, 0.35, 1e-6, 4e-3),
    ({"crank_joint": "lubricated", "crosshead_joint": "contact"}, 1.0, 1e-5, 2e-3),
], ids=["crank", "both", "oil-and-contact"])  # fmt: skip
def test_tangent_flow_with_the_crank_free_matches_differences_of_the_flow(pins, fraction,
                                                                          eps, bound):  # fmt: skip
    """Hypothesis: with a motor, Benettin's tangent vectors (the glue's Jacobian, each contact
    event's saltation matrix) equal central differences of the flow over an interval with
    impacts (12 onsets at the crank pin over a revolution; 18 onsets and separations with
    both pins worn over 0.35 of one; 6 at the oil-and-contact pair), the crank angle and speed
    perturbed too.

    The differences' own error is O(eps^2): measured at the crank pin 1.8e-2, 1.8e-4 of the
    tangent vector's size at eps = 1e-4, 1e-5, and with both pins 3.9e-2, 4.0e-4 at 1e-5,
    1e-6 (x0.01 a decade), over an integration floor ~6e-5 (rtol 1e-12 over eps); the bounds
    leave 10x. The recorded approach velocities must follow the flow (auxiliary, not
    passive): held at 0, as the system declared them before, the tangent flow was off by 6.5
    times its size at the crank pin (the damping law reads them). One revolution of
    transient grows rounding to ~1e-12 on this chaotic orbit, far below any event's margin."""
    m, v = _values({**IMPACTS, **pins})
    s = m.system(v)
    T, n = m.period(v), s.dim
    assert s.period is None and s.state_names[-3:] == ("theta1", "omega1", "W_motor")
    tight = dict(rtol=1e-12, atol=1e-17)
    ya = integrate(s, m.initial_state(v), (0.0, T), **_events_kw(s, **tight)).y_final
    rc, w, r = v["rc"], v["omega"], v["r"]
    # positions by the clearance, rates by c omega; the crank's angle and speed as the
    # clearance's share of the crank radius
    scale = np.array([rc] * 4 + [rc * w] * 6 + [1.0] * 2 + [rc / r, rc * w / r, 1.0])
    dof = list(s.dof)
    assert {12, 13} <= set(dof) and not {8, 9} & set(dof)
    wv = np.zeros(n)
    wv[dof] = np.random.default_rng(1).standard_normal(len(dof)) * scale[dof]
    ev = s.acting_event
    treset = _tangent_reset(s.rhs, ev.function, ev.reset, n, 1, tuple(s.passive))
    t1 = T * (1.0 + fraction)
    tan = integrate(tangent_system(s, 1), np.concatenate([ya, wv]), (T, t1), event=ev.function,
                    event_direction=ev.direction, event_action="reset", reset=treset,
                    rtol=1e-11, atol=1e-16)  # fmt: skip
    wt = tan.y_final[n:]
    runs = [integrate(s, ya + sign * eps * wv, (T, t1), **_events_kw(s, **tight))
            for sign in (1.0, -1.0)]  # fmt: skip
    assert tan.t_events.size >= 6
    assert runs[0].t_events.size == runs[1].t_events.size == tan.t_events.size
    fd = (runs[0].y_final - runs[1].y_final) / (2.0 * eps)
    rows = [i for i in range(n) if i not in s.passive]  # the motor's work is passive too
    size = np.abs(wt[rows] / scale[rows]).max()
    assert size > 1.0  # the interval's impacts stretch the perturbation
    assert np.abs((fd - wt)[rows] / scale[rows]).max() <= bound * size
    assert np.all(wt[list(s.passive)] == 0.0)
    assert np.any(wt[list(s.aux)] != 0.0)  # an onset recorded a perturbed approach velocity
