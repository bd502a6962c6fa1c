"""The N-coordinate Euler-Lagrange generator (recipdyn.model.derive)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from recipdyn.integrate import integrate
from recipdyn.model.reference import double_pendulum as dp
from recipdyn.model.registry import get_model


def test_generated_double_pendulum_is_up_to_date():
    committed = (Path(dp.__file__).with_name("_double_pendulum.py")).read_text()
    assert committed == dp.generate(), "run: python -m recipdyn.model.reference.double_pendulum"


def _textbook(m1, m2, l1, l2, g, q1, q2, w1, w2):
    """Closed-form accelerations of the undamped double pendulum (derived by hand in every
    mechanics text, e.g. the form given by myPhysicsLab's 'Double Pendulum')."""
    den = 2 * m1 + m2 - m2 * math.cos(2 * q1 - 2 * q2)
    a1 = (
        -g * (2 * m1 + m2) * math.sin(q1)
        - m2 * g * math.sin(q1 - 2 * q2)
        - 2 * math.sin(q1 - q2) * m2 * (w2**2 * l2 + w1**2 * l1 * math.cos(q1 - q2))
    ) / (l1 * den)
    a2 = (2 * math.sin(q1 - q2) * (w1**2 * l1 * (m1 + m2) + g * (m1 + m2) * math.cos(q1)
          + w2**2 * l2 * m2 * math.cos(q1 - q2))) / (l2 * den)  # fmt: skip
    return a1, a2


def test_double_pendulum_matches_the_closed_form(rng):
    """Generated kernel vs an independent hand derivation, 50 random states and parameters."""
    m = get_model("double-pendulum")
    for _ in range(50):
        v = m.parameters(m1=rng.uniform(0.2, 3), m2=rng.uniform(0.2, 3), l1=rng.uniform(0.3, 2),
                         l2=rng.uniform(0.3, 2), c=0.0)  # fmt: skip
        y = rng.uniform(-3, 3, 4)
        f = m.system(v).f(0.0, y)
        a1, a2 = _textbook(v["m1"], v["m2"], v["l1"], v["l2"], v["g"], *y)
        assert f[:2] == pytest.approx(y[2:], abs=0)
        assert f[2] == pytest.approx(a1, rel=1e-10, abs=1e-10)
        assert f[3] == pytest.approx(a2, rel=1e-10, abs=1e-10)


def test_energy_is_conserved_along_a_chaotic_run():
    """c = 0: the energy is an invariant of the exact flow, so its drift measures only the
    integration error (~ steps x rtol |E|: ~5e3 steps x 1e-10), whatever trajectory rounding
    picks on this CPU. Bound: 1e-6 relative."""
    m = get_model("double-pendulum")
    v = m.parameters()
    te = np.linspace(0, 20, 2001)
    sol = integrate(m.system(v), m.initial_state(v), (0, 20), t_eval=te)
    E = dp.energy(v, sol.y)
    assert np.max(np.abs(E - E[0])) < 1e-6 * abs(E[0])


def test_damping_dissipates_exactly_what_the_generalized_force_does():
    """With joint damping c the energy balance is E(T) - E(0) = -c int (w1^2 + w2^2) dt; the
    integral by Simpson's rule on 4001 dense samples (error ~1e-9 here)."""
    from scipy.integrate import simpson

    m = get_model("double-pendulum")
    v = m.parameters(c=0.05)
    te = np.linspace(0, 10, 4001)
    sol = integrate(m.system(v), m.initial_state(v), (0, 10), t_eval=te, rtol=1e-11,
                    atol=1e-12)  # fmt: skip
    E = dp.energy(v, sol.y)
    loss = v["c"] * simpson(sol.y[:, 2] ** 2 + sol.y[:, 3] ** 2, x=te)
    assert E[-1] - E[0] == pytest.approx(-loss, rel=1e-6)
    assert loss > 0.01 * abs(E[0])  # the check is not vacuous


def test_generator_reproduces_the_compressor_equation(rng):
    """The compressor's one-coordinate equation from the generic generator (T, V and
    Q = F dx3/dtheta_c with the crank angle prescribed, theta1 = omega t) equals the proven
    kernel of recipdyn.model.derivation (itself checked against two other derivations)."""
    from recipdyn.model import CompressorParams, compressor_model
    from recipdyn.model.derive import derive

    t = sp.Symbol("t", real=True)
    q, w = sp.symbols("q w", real=True)
    r, rs, l, ls, m1, m2, m3, J1, J2, g, rc, d, om, F = sp.symbols(
        "r rs l ls m1 m2 m3 J1 J2 g rc d om F", real=True)  # fmt: skip
    a1 = om * t
    a2 = sp.asin(-(d + r * sp.sin(a1) + rc * sp.sin(q)) / l)

    def dt(e):
        return sp.diff(e, q) * w + sp.diff(e, t)

    x2 = r * sp.cos(a1) + rc * sp.cos(q) + ls * sp.cos(a2)
    y2 = r * sp.sin(a1) + rc * sp.sin(q) + ls * sp.sin(a2)
    x3 = r * sp.cos(a1) + rc * sp.cos(q) + l * sp.cos(a2)
    T = (m2 * (dt(x2) ** 2 + dt(y2) ** 2) + m3 * dt(x3) ** 2 + J2 * dt(a2) ** 2) / 2
    V = g * m2 * y2
    params = (r, l, ls, m2, m3, J2, g, rc, d, om, F)
    lag = derive(T, V, (q,), (w,), t, params, Q=(F * sp.diff(x3, q),))
    acc = sp.lambdify((t, q, w, *params), lag.accelerations()[0], "math")
    for _ in range(20):
        p = CompressorParams(rc=rng.uniform(1e-4, 5e-3), d=rng.uniform(-5e-3, 5e-3),
                             omega=rng.uniform(5, 150), m2=rng.uniform(5, 40))  # fmt: skip
        mod = compressor_model(p)
        tt, y = rng.uniform(0, 1), np.array([rng.uniform(-4, 4), rng.uniform(-50, 50)])
        force = float(mod.outputs(np.array([tt]), y[None, :])["gas_force"].values[0])
        ours = acc(tt, y[0], y[1], p.r, p.l, p.ls, p.m2, p.m3, p.J2, p.g, p.rc, p.d, p.omega,
                   force)  # fmt: skip
        assert ours == pytest.approx(mod.f(tt, y)[1], rel=1e-9)


def test_stray_symbols_are_refused():
    from recipdyn.model.derive import derive

    t, q, w, k, z = sp.symbols("t q w k z")
    with pytest.raises(ValueError, match="without a value"):
        derive(w**2 / 2, k * q**2 / 2 + z, (q,), (w,), t, (k,))


def _compiled(source: str, name: str):
    import numba as nb

    ns = {"nb": nb, "np": np, "math": math}
    exec(compile(source.replace("cache=True", "cache=False"), f"<generated {name}>", "exec"), ns)
    return ns[name]


def test_allocation_free_accelerations_match_the_generated_rhs(rng):
    """``accelerations_source`` (scalar L D L^T, the last parameters from a tuple) against the
    array kernel of the same Lagrangian (``numpy.linalg.solve`` path), 50 random states: the
    two differ only by rounding in the solve (|M| is well conditioned here), so 1e-10."""
    from recipdyn.model.derive import accelerations_source

    m = get_model("double-pendulum")
    lag = dp.lagrangian()
    acc = _compiled(accelerations_source(lag, "dp", inputs=2), "dp_accelerations")
    for _ in range(50):
        v = m.parameters(m1=rng.uniform(0.2, 3), m2=rng.uniform(0.2, 3), c=rng.uniform(0, 1))
        s = m.system(v)
        y = rng.uniform(-3, 3, 4)
        p = s.params
        k = len(lag.params) - 2
        a = acc(0.0, y, p[:k].copy(), (p[k], p[k + 1]))
        assert np.allclose(a, s.f(0.0, y)[2:], rtol=1e-10, atol=1e-10)


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_straight_line_ldl_solves_spd_systems(n, rng):
    """The unrolled L D L^T of the generated kernels against numpy.linalg.solve on random
    symmetric positive definite matrices (condition numbers up to ~1e6): the residual is at
    rounding level, |M x - b| <= 1e-9 |M| |x|."""
    from recipdyn.model.derive import _ldl_solve

    args = [f"m{i}{j}" for i in range(n) for j in range(i + 1)] + [f"b{i}" for i in range(n)]
    src = "\n".join([f"def solve({', '.join(args)}):", *_ldl_solve(n),
                     "    return (" + ", ".join(f"a{i}" for i in range(n)) + ",)"])  # fmt: skip
    solve = _compiled(src, "solve")
    for _ in range(20):
        q, _ = np.linalg.qr(rng.normal(size=(n, n)))
        M = q @ np.diag(np.logspace(0, rng.uniform(0, 6), n)) @ q.T
        b = rng.normal(size=n)
        x = np.array(solve(*[M[i, j] for i in range(n) for j in range(i + 1)], *b))
        assert np.abs(M @ x - b).max() <= 1e-9 * np.abs(M).max() * np.abs(x).max()
        assert np.allclose(x, np.linalg.solve(M, b), rtol=1e-6 * 10 ** (n / 2))
