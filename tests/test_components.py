"""The compressor assembled from components (model/components): the glue wires each component
to its own slice, the motor drive's closed-form limits and its energy balance."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

import recipdyn
from recipdyn.errors import ParameterError
from recipdyn.model import CompressorParams, compressor_model, ideal_slider_crank
from recipdyn.model._generated import clearance_acceleration
from recipdyn.model._generated_drive import free_crank_accelerations
from recipdyn.model.components.contract import check_fragments
from recipdyn.model.components.drive import INDUCTION, mean_load_torque
from recipdyn.model.components.load import gas_force
from recipdyn.model.paper_printed import paper_acceleration

TABLE = ((0.0, -1.0e4), (90.0, -5.0e4), (180.0, 2.0e4), (270.0, -3.0e4))
LOADS = {"paper": {}, "cycle": {"load": "cycle"}, "table": {"load_table": TABLE},
         "real gas": {"load": "cycle", "gas": "Air"}}  # fmt: skip


@pytest.mark.parametrize("equations", ["exact", "paper-printed"])
@pytest.mark.parametrize("load", list(LOADS))
def test_every_load_is_wired_to_its_own_slice(load, equations, rng):
    """Hypothesis: the generated glue calls the chosen load with its own offset and the drive
    with its own: theta_c'' of the assembled kernel equals the reduced equation evaluated
    with the force of the Python path (``gas_force``, which packs the load on its own) at
    the prescribed crank angle. Same arithmetic in both, so only rounding differences of the
    force (a few ulp) can remain: rel 1e-12."""
    p = CompressorParams(rc=2e-3, omega=31.0, theta1_0=0.4, equations=equations, **LOADS[load])
    m = compressor_model(p)
    for _ in range(20):
        t = float(rng.uniform(0.0, 0.5))
        y = np.array([rng.uniform(-math.pi, math.pi), rng.normal(0.0, 50.0)])
        th1 = p.theta1_0 + p.omega * t
        F = float(gas_force(th1, p))
        if equations == "exact":
            ref = clearance_acceleration(th1, y[0], y[1], F, p.r, p.l, p.ls, p.m2, p.m3, p.J2,
                                         p.g, p.rc, p.d, p.omega)  # fmt: skip
        else:
            ref = paper_acceleration(th1, y[0], y[1], F, p.r, p.l, p.m2, p.m3, p.J2, p.rc, p.d,
                                     p.omega)  # fmt: skip
        assert m.f(t, y)[1] == pytest.approx(ref, rel=1e-12, abs=1e-9)


def test_free_crank_equations_reduce_to_the_prescribed_equation(rng):
    """Two independent derivations: the free-crank Lagrangian (theta1 a coordinate, energies
    written out and differentiated by sympy, ``_generated_drive``) with the motor torque that
    holds theta1'' = 0 gives the theta_c'' of the structured prescribed-speed derivation
    (``_generated``, the paper's route). theta1'' is linear in the torque, so two calls find
    that torque; the residual is rounding of M^-1 b (|theta_c''| up to ~1e6): rel 1e-8."""
    for _ in range(30):
        r, l = rng.uniform(0.05, 0.2), rng.uniform(0.4, 1.0)
        p = np.array([r, rng.uniform(0.0, r), l, rng.uniform(0.1, 0.35), rng.uniform(1, 30),
                      rng.uniform(1, 50), rng.uniform(1, 50), rng.uniform(0.001, 1),
                      rng.uniform(0.01, 2), 9.81, 10 ** rng.uniform(-4, -2.5),
                      rng.uniform(-5e-3, 5e-3)])  # fmt: skip
        th1, thc = rng.uniform(0, 2 * math.pi), rng.uniform(-math.pi, math.pi)
        w1, thcd = rng.uniform(5, 200), rng.normal(0.0, 300.0)
        Jd, F = rng.uniform(0.0, 50.0), rng.uniform(-2e5, 2e5)
        y = (th1, thc, w1, thcd)
        a10 = free_crank_accelerations(0.0, y, p, (Jd, F, 0.0))[0]
        a11 = free_crank_accelerations(0.0, y, p, (Jd, F, 1.0))[0]
        a1, ac = free_crank_accelerations(0.0, y, p, (Jd, F, -a10 / (a11 - a10)))
        ref = clearance_acceleration(th1, thc, thcd, F, p[0], p[2], p[3], p[5], p[6], p[8],
                                     p[9], p[10], p[11], w1)  # fmt: skip
        assert abs(a1) <= 1e-8 * max(1.0, abs(a10))
        assert ac == pytest.approx(ref, rel=1e-8, abs=1e-6)


def test_huge_flywheel_gives_the_ideal_slider_crank():
    """Closed-form limit: with rc = 0 and J_drive -> inf the motor-driven crank keeps its
    initial speed, and the crosshead acceleration approaches the ideal slider-crank's closed
    form at omega. The speed deviates by ~ (load energy swing) / (J omega), so the error
    falls like 1/J_drive (x0.1 a decade; bound x0.2); the integration error (rtol 1e-10) is
    far below the smallest of them."""
    errs = []
    for J in (1e4, 1e5, 1e6):
        p = CompressorParams(rc=0.0, drive="motor", motor="constant", J_drive=J)
        ds = recipdyn.simulate(p, revolutions=1, fs=2000.0, rtol=1e-10, atol=1e-12)
        _, _, a_ref = ideal_slider_crank(replace(p, drive="prescribed"), ds.time.values)
        errs.append(float(np.max(np.abs(ds.a.values - a_ref)) / np.max(np.abs(a_ref))))
    assert errs[1] < 0.2 * errs[0] and errs[2] < 0.2 * errs[1], errs
    assert errs[2] < 1e-3, errs


def test_huge_flywheel_gives_the_prescribed_clearance_motion():
    """The same limit with the clearance: theta_c of the motor-driven model approaches the
    prescribed-speed model's over a revolution (a regular, non-chaotic base case; the
    clearance oscillation is ~1/omega-sensitive, so the bound is on the difference falling
    by x0.2 a decade of J, and below 1e-3 rad at J = 1e6 kg m^2)."""
    ref = recipdyn.simulate(CompressorParams(), revolutions=1, fs=2000.0, rtol=1e-10,
                            atol=1e-12)  # fmt: skip
    errs = []
    for J in (1e4, 1e5, 1e6):
        p = CompressorParams(drive="motor", motor="constant", J_drive=J)
        ds = recipdyn.simulate(p, revolutions=1, fs=2000.0, rtol=1e-10, atol=1e-12)
        errs.append(float(np.max(np.abs(ds.theta_c.values - ref.theta_c.values))))
    assert errs[1] < 0.2 * errs[0] and errs[2] < 0.2 * errs[1], errs
    assert errs[2] < 1e-3, errs


@pytest.mark.parametrize(
    "kw",
    [
        {},
        {"motor": "constant", "load": "cycle"},
        {"rc": 0.0, "load": "cycle"},
        {"rc": 2e-3, "J_drive": 2.0},
    ],
)
def test_energy_balance_closes(kw):
    """Invariant: the massless-link mechanism dissipates nothing, so the energy of crank,
    drive, rod and crosshead changes by the work of the motor and of the gas,
    E(t) - E(0) = W_motor + W_gas. The residual is the integrator's global error in that
    combination, ~ steps x rtol x |W| (~1e4 steps a revolution at rtol 1e-10): bound
    1e-5 max|W|."""
    p = CompressorParams(drive="motor", **kw)
    ds = recipdyn.simulate(p, revolutions=3, fs=2000.0, rtol=1e-10, atol=1e-12)
    E, W = ds.energy.values, ds.W_motor.values + ds.W_gas.values
    scale = max(np.max(np.abs(ds.W_motor.values)), np.max(np.abs(ds.W_gas.values)))
    assert scale > 1e3  # work is done: the check is not empty
    assert np.max(np.abs((E - E[0]) - (W - W[0]))) < 1e-5 * scale


def test_induction_motor_settles_at_the_kloss_slip():
    """Closed form: at steady state the motor's work per revolution equals the gas's, so the
    mean motor torque per radian equals the mean load torque of the ideal mechanism (rc = 0)
    and the speed solves Kloss's curve T(s) = T_load. Two checks: the gas work per radian in
    the run equals that closed form (7 200-point quadrature: 1e-4), and the speed averaged
    over the crank angle gives it through Kloss's curve. The curve is nonlinear, so the
    ripple biases the mean torque at second order: with J = 10 000 kg m^2 the ripple is
    0.8 % and the bias ~1e-3 (measured 1.5e-3 with 12 revolutions of transient from 20.3
    rad/s, a time constant of 0.46 revolutions; at J = 1000, 7.5 % ripple, it is 9 %);
    bound 5e-3."""
    p = CompressorParams(rc=0.0, drive="motor", J_drive=10000.0, omega=20.3)
    ds = recipdyn.simulate(p, revolutions=8, transient=12, fs=2000.0)
    th = ds.theta1.values
    n = int((th[-1] - th[0]) // (2 * math.pi))  # whole revolutions of the recorded part
    end = th[0] + n * 2 * math.pi
    stop = np.searchsorted(th, end)
    T_load = mean_load_torque(vars(p))
    # W at exactly n revolutions (linear interpolation between samples 0.01 rad apart)
    dW = np.interp(end, th, ds.W_gas.values) - ds.W_gas.values[0]
    assert -dW / (n * 2 * math.pi) == pytest.approx(T_load, rel=1e-4)
    # the mean over the crank angle: int w dtheta / int dtheta = int w^2 dt / int w dt
    w = float(np.sum(ds.omega1.values[:stop] ** 2) / np.sum(ds.omega1.values[:stop]))
    s, sb = (p.motor_sync_speed - w) / p.motor_sync_speed, p.motor_breakdown_slip
    T_kloss = 2 * p.motor_breakdown_torque * s * sb / (s * s + sb * sb)
    assert T_kloss == pytest.approx(T_load, rel=5e-3)


def test_combinations_that_do_not_exist_are_refused():
    with pytest.raises(ParameterError, match="prescribed crank only"):
        CompressorParams(drive="motor", equations="paper-printed")
    with pytest.raises(ParameterError, match="motor_sync_speed"):
        CompressorParams(drive="motor", motor_sync_speed=10.0)


def test_component_fragments_cannot_collide():
    """Two components that declare one parameter name are refused (neither could know which
    value it reads)."""
    check_fragments([INDUCTION])
    with pytest.raises(ValueError, match="already declared"):
        check_fragments([INDUCTION, replace(INDUCTION, name="copy")])


@pytest.mark.parametrize(
    "kw",
    [
        {},
        {"load": "cycle"},
        {"load_table": TABLE},
        {"drive": "motor"},
        {"drive": "motor", "motor": "constant", "load": "cycle"},
    ],
)
def test_outputs_are_what_was_integrated(kw):
    """One observation path: the recorded crank angle, speed and gas force are the ones the
    integrated right-hand side used (the glue's observer), so the equation of motion evaluated
    with the recorded values gives the recorded accelerations, to rounding (rel 1e-9: the
    accelerations reach ~1e5 and are formed from the same numbers). A force or crank angle
    recomputed by a second copy of the physics could drift from the dynamics unseen."""
    from recipdyn.model.mechanism.link import HEAD

    p = CompressorParams(rc=2e-3, **kw)
    ds = recipdyn.simulate(p, revolutions=1, fs=500.0)
    head = np.array([getattr(p, k) for k in HEAD])
    n = ds.time.size
    for i in range(0, n, max(1, n // 25)):
        th1, F = float(ds.theta1[i]), float(ds.gas_force[i])
        thc, thcd = float(ds.theta_c[i]), float(ds.thetadot_c[i])
        if p.drive == "motor":
            w1, T = float(ds.omega1[i]), float(ds.motor_torque[i])
            a1, ac = free_crank_accelerations(0.0, (th1, thc, w1, thcd), head, (p.J_drive, F, T))
            assert float(ds.alpha1[i]) == pytest.approx(a1, rel=1e-9, abs=1e-9)
        else:
            ac = clearance_acceleration(th1, thc, thcd, F, p.r, p.l, p.ls, p.m2, p.m3, p.J2,
                                        p.g, p.rc, p.d, p.omega)  # fmt: skip
        assert float(ds.thetaddot_c[i]) == pytest.approx(ac, rel=1e-9, abs=1e-6)
