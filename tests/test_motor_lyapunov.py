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

from recipdyn.analysis.lyapunov import _tangent_reset, tangent_system
from recipdyn.errors import LawRangeWarning, ModelValidityWarning
from recipdyn.integrate import integrate
from recipdyn.model.registry import get_model
from test_contact import _events_kw

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
    pytest.param({"crank_joint": "contact", "crosshead_joint": "contact"}, 0.35, 1e-6, 4e-3,
                 marks=pytest.mark.slow),
    pytest.param({"crank_joint": "lubricated", "crosshead_joint": "contact"}, 1.0, 1e-5, 2e-3,
                 marks=pytest.mark.slow),
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


def _with_trace(s):
    """``s`` with one more auxiliary state last: the integral of the trace of the Jacobian
    over the degrees of freedom ``s.dof``, so Benettin's run integrates it along its own
    trajectory (a chaotic orbit integrated twice would part)."""
    import numba as nb

    from recipdyn.model.base import (
        EVENT_SIGNATURE,
        JAC_SIGNATURE,
        RHS_JAC_SIGNATURE,
        RHS_SIGNATURE,
        Event,
        ODESystem,
    )

    n, dof = s.dim, np.array(s.dof, dtype=np.int64)
    rhs, jac = s.rhs, s.jac

    @nb.njit(RHS_JAC_SIGNATURE)
    def both(t, z, p, f, J):
        y = z[:n].copy()
        fy, Jy = np.empty(n), np.empty((n, n))
        rhs(t, y, p, fy)
        jac(t, y, p, Jy)
        J[:, :] = 0.0
        J[:n, :n] = Jy
        f[:n] = fy
        f[n] = 0.0
        for i in dof:
            f[n] += Jy[i, i]

    @nb.njit(RHS_SIGNATURE)
    def rhs2(t, z, p, out):
        both(t, z, p, out, np.empty((n + 1, n + 1)))

    @nb.njit(JAC_SIGNATURE)
    def jac2(t, z, p, J):
        both(t, z, p, np.empty(n + 1), J)

    events = ()
    ev = s.acting_event
    if ev is not None:
        event, reset = ev.function, ev.reset

        @nb.njit(EVENT_SIGNATURE)
        def event2(t, z, p):
            return event(t, z[:n].copy(), p)

        @nb.njit(RHS_SIGNATURE)
        def reset2(t, z, p, out):
            o = np.empty(n)
            reset(t, z[:n].copy(), p, o)
            out[:n] = o
            out[n] = z[n]

        events = (Event(ev.name, event2, ev.direction, ev.action, reset2),)
    return ODESystem(rhs=rhs2, jac=jac2, rhs_jac=both, params=s.params,
                     state_names=(*s.state_names, "trace_integral"), events=events,
                     aux_states=s.aux_states + 1, aux=s.aux, passive=s.passive)  # fmt: skip


@pytest.mark.parametrize("kw,revolutions", [
    ({**IMPACTS, "crank_joint": "contact", "contact_law": "hertz"}, 0.5),
    ({"drive": "motor"}, 5.0),
    ({"drive": "motor", "rc": 0.0}, 5.0),
], ids=["contact-impacts", "link", "ideal-pins"])  # fmt: skip
def test_exponent_sum_is_the_mean_trace_of_the_jacobian(kw, revolutions):
    """Hypothesis: the volume of the degrees of freedom grows at the trace of their block of
    the Jacobian, and an impact's saltation matrix has determinant 1 on them (the contact
    force is 0 at the onset and the reset changes only the recorded approach velocity), so
    the sum of the exponents is (1 / T) integral tr J_dof dt along the run, whatever the
    orbit (an identity, not a limit: it holds on this chaotic one). The integral is a state of
    the same run. Hertz's law at the impacts: a damping law reads the recorded approach
    velocity, a memory the degrees of freedom's volume does not contain. The two differ by
    the integration's and the QR's error relative to the log growths that cancel in the sum
    (sum |lambda_i|): measured 4e-8 of it at the impacts (exponents 971 ... -940 /s, sum
    -0.184 /s); the bound is 1e-6 of it."""
    from recipdyn.analysis import lyapunov_spectrum

    m, v = _values(kw)
    s = m.system(v)
    aug = _with_trace(s)
    T = revolutions * m.period(v)
    y0 = np.append(m.initial_state(v), 0.0)
    res = lyapunov_spectrum(aug, y0, T, rtol=1e-10, atol=1e-12)
    assert res.exponents.size == len(s.dof)
    mean_trace = res.y_final[-1] / (res.t_final - res.t_start)
    if "crank_joint" in kw:
        assert res.settings["events"] >= 4
    assert abs(res.exponents.sum() - mean_trace) <= 1e-6 * np.abs(res.exponents).sum()


def test_the_autonomous_flow_has_a_zero_exponent():
    """Hypothesis: with the crank free the system is autonomous, and the direction of the
    flow neither grows nor shrinks on average: one exponent is 0. Ideal pins with an
    induction motor: a stable periodic orbit (the crank's speed ripple), exponents 0 and the
    motor's speed regulation (~ -2 1/s). The tangent vector along the flow is the vector
    field itself (d f(y(t))/dt = J f), so once the contracting direction has decayed
    (e^(-2 T/2) ~ 3e-6 over the second half of 40 revolutions) the first vector's log growth
    over [T/2, T] is ln(|f(T)| / |f(T/2)|), at most ln rho, rho = max |f| / min |f| of the
    degrees of freedom's field along the orbit: that half's exponent is within
    ln rho / (T/2) of 0 (plus 1e-3 for the leaked component and the integration). The
    finite-time estimate over the whole run carries the initial vector's projection on the
    flow too; its extrapolation to infinite time (`largest_limit`, the verdict's test) must be
    within twice its error of 0. The other exponent is far outside both bounds."""
    from recipdyn.analysis import lyapunov_spectrum

    m, v = _values({"drive": "motor", "rc": 0.0})
    s = m.system(v)
    assert s.dof == (2, 3)
    T = 40 * m.period(v)
    res = lyapunov_spectrum(s, m.initial_state(v), T)
    times, hist = res.times, res.history
    half = int(np.searchsorted(times, times[-1] / 2))
    growth = hist[-1, 0] * times[-1] - hist[half, 0] * times[half]
    sol = integrate(s, m.initial_state(v), (0.0, T), t_eval=np.linspace(T / 2, T, 4001))
    fnorm = np.array(
        [np.linalg.norm(s.f(t, y)[list(s.dof)]) for t, y in zip(sol.t, sol.y, strict=True)]
    )
    log_rho = float(np.log(fnorm.max() / fnorm.min()))
    assert abs(growth) <= log_rho + 1e-3, (growth, log_rho)
    lam, err = res.largest_limit()
    assert abs(lam) <= 2.0 * err, (lam, err)
    assert res.exponents[1] < min(-10.0 * log_rho / (T / 2), -2.0 * err)


def test_a_sweep_measures_the_exponents_with_a_motor(tmp_path):
    """A sweep with ``--measure lyapunov`` of contact pins driven by a motor is accepted and
    stores each point's exponents (finite; the largest above the sum, which the
    contracting contact modes make negative); the guide's clearance keeps its refusal, with
    the reason."""
    from recipdyn.errors import ParameterError
    from recipdyn.sweep.run import open_sweep, run_sweep
    from recipdyn.sweep.spec import SweepSpec, parse_axis

    base = {**IMPACTS, "crank_joint": "contact"}
    spec = SweepSpec(axes=(parse_axis("load_amplitude=1.5e4:2e4:2", "compressor", base),),
                     measures=("lyapunov",), model="compressor", base=base,
                     settings=dict(revolutions=0.05, transient=0, lyap_revolutions=0.1,
                                   fs=5000.0))  # fmt: skip
    ds = open_sweep(run_sweep(spec, tmp_path, backend="serial", progress=False))
    lam, total = ds["lambda1"].values, ds["lambda_sum"].values
    assert np.all(np.isfinite(lam)) and np.all(lam > total) and np.all(total < 0)
    with pytest.raises(ParameterError, match="guide = 'clearance'"):
        SweepSpec(
            axes=(parse_axis("omega=20:30:2", "compressor"),),
            measures=("lyapunov",),
            model="compressor",
            base={"crank_joint": "contact", "guide": "clearance"},
        )


@pytest.mark.parametrize("kw", [
    {"drive": "motor"},
    {"drive": "motor", "load": "cycle"},
    {"drive": "motor", "rc": 0.0},
], ids=["link-paper-load", "link-cycle", "ideal-pins"])  # fmt: skip
def test_rigid_pin_route_tangent_flow_with_a_motor(kw):
    """Hypothesis: on the rigid-pin route (`crank_joint` = link or ideal) with a motor no
    saltation matrix is missing: the loads are continuous in the crank angle, now a state (the
    paper's mu has kinks only, at 7 pi/16, pi, 23 pi/16; the cycle's pressure is continuous
    through the valve events), so the tangent flow over a revolution that crosses every
    kink equals central differences of the flow. A jump in the force would need a saltation
    matrix and miss the tangent flow by the jump over the crank speed. Errors: the
    difference's O(eps^2) and the Jacobian's (Richardson differences, ~1e-6 relative):
    measured 8e-7 and 7e-7 of the vector's size with the paper's load and the ideal pins;
    the massless link under the cycle's reversing load (outside its validity, but the same
    equations) stretches the vector 2.6e6-fold and its differences give 1.7e-3, 1.6e-5,
    3.6e-5 at eps = 1e-4, 1e-5, 1e-6 (eps^2, then the integration's floor). The bound 1e-3
    at eps = 1e-5."""
    m, v = _values(kw)
    s = m.system(v)
    T, n = m.period(v), s.dim
    y0 = integrate(s, m.initial_state(v), (0.0, T), rtol=1e-12, atol=1e-14).y_final
    scale = np.array([1e-2, 1e-2 * v["omega"], 1e-2, 1e-2 * v["omega"], 1.0, 1.0])
    wv = np.zeros(n)
    wv[list(s.dof)] = np.random.default_rng(2).standard_normal(len(s.dof)) * scale[list(s.dof)]
    tan = integrate(tangent_system(s, 1), np.concatenate([y0, wv]), (T, 2 * T), rtol=1e-12,
                    atol=1e-14).y_final[n:]  # fmt: skip
    eps = 1e-5
    ends = [integrate(s, y0 + sg * eps * wv, (T, 2 * T), rtol=1e-12, atol=1e-14).y_final
            for sg in (1.0, -1.0)]  # fmt: skip
    fd = (ends[0] - ends[1]) / (2 * eps)
    dof = list(s.dof)
    size = np.abs(tan[dof] / scale[dof]).max()
    err = np.abs((fd - tan)[dof] / scale[dof]).max()
    assert err <= 1e-3 * size


def _pin_tangent(kw, T):
    """The tangent flow over [0, T] from the initial state of 4 vectors along the crank pin's
    eccentricity and its rate (none along the crank), its rows of the pin (scaled)."""
    m, v = _values(kw)
    s = m.system(v)
    n, rows = s.dim, [0, 1, 4, 5]
    scale = np.array([v["rc"]] * 2 + [v["rc"] * v["omega"]] * 2)
    W0 = np.zeros((n, 4))
    W0[rows] = np.diag(scale)
    ev = s.acting_event
    treset = _tangent_reset(s.rhs, ev.function, ev.reset, n, 4, tuple(s.passive))
    tan = integrate(tangent_system(s, 4), np.concatenate([m.initial_state(v), W0.ravel()]),
                    (0.0, T), event=ev.function, event_direction=ev.direction,
                    event_action="reset", reset=treset, rtol=1e-11, atol=1e-16)  # fmt: skip
    W = tan.y_final[n:].reshape(n, 4)[rows] / scale[:, None]
    return W, tan.t_events.size


@pytest.mark.slow
def test_a_huge_flywheel_gives_the_prescribed_cranks_tangent_flow():
    """Limit J_drive -> inf (a constant torque equal to the mean load torque, so the mean
    speed stays at omega): the crank's speed ripple falls like 1 / J, the trajectory
    approaches the prescribed crank's (tests/test_motor_drive.py), and so does the tangent
    flow of the pin's perturbations: a perturbation of the pin moves the crank by a torque
    over J. Over a quarter revolution with impacts (start-up included), the tangent matrix of
    the pin's four directions approaches the prescribed model's (so do its finite-time
    exponents, ln of the R diagonal of its QR over T: the flywheel limit of the spectrum, the
    crank's two exponents aside). Measured: the largest difference of the matrices 3.5e-4,
    4.0e-5, 3.3e-5 of its largest entry at J = 3e4, 3e5, 3e6 kg m^2: x0.12 the first decade,
    as the trajectory's (0.05-0.2 a decade), then a floor, presumably the two glues'
    Jacobians (a fourth-order difference with the crank free, a complex step with it
    prescribed); the bound 1e-4. The finite-time exponents (582, 114, -99, -838 1/s over
    this quarter revolution) then agree to 0.4 1/s, the bound 1 % of the largest."""
    base = {"crank_joint": "contact", "omega": 150.0, "load_amplitude": 2e4}
    T = 0.25 * 2 * np.pi / base["omega"]
    Wp, n_ev = _pin_tangent(base, T)
    assert n_ev >= 4
    lam_p = np.log(np.abs(np.diag(np.linalg.qr(Wp)[1]))) / T
    diffs = []
    for J in (3e4, 3e5, 3e6):
        Wm, n_m = _pin_tangent({**base, "drive": "motor", "motor": "constant", "J_drive": J}, T)
        assert n_m == n_ev
        lam_m = np.log(np.abs(np.diag(np.linalg.qr(Wm)[1]))) / T
        diffs.append(np.abs(Wm - Wp).max() / np.abs(Wp).max())
    assert np.abs(lam_m - lam_p).max() <= 1e-2 * np.abs(lam_p).max()
    assert 0.05 < diffs[1] / diffs[0] < 0.2, diffs
    assert diffs[2] <= diffs[1] and diffs[2] < 1e-4, diffs
