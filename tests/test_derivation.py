"""The exact equation of motion: generated code, two independent derivations, the Jacobian."""

import numpy as np
import pytest
import sympy as sp

from recipdyn.model import derivation
from recipdyn.model._generated import clearance_acceleration, clearance_acceleration_jac
from recipdyn.model.derivation import SYMBOLS as S

ARGS = ["theta1", "theta_c", "thetadot_c", "F", "r", "l", "ls", "m2", "m3", "J2", "g", "rc", "d",
        "omega"]  # fmt: skip


def _random_states(rng, n):
    for _ in range(n):
        yield dict(
            theta1=rng.uniform(0, 2 * np.pi), theta_c=rng.uniform(-np.pi, np.pi),
            thetadot_c=rng.normal(0, 300.0), F=rng.uniform(-2e5, 2e5), r=rng.uniform(0.05, 0.2),
            l=rng.uniform(0.4, 1.0), ls=rng.uniform(0.1, 0.35), m2=rng.uniform(1, 50),
            m3=rng.uniform(1, 50), J2=rng.uniform(0.01, 2), g=9.81,
            rc=10 ** rng.uniform(-5, -2), d=rng.uniform(-5e-3, 5e-3), omega=rng.uniform(5, 200),
        )  # fmt: skip


def test_generated_code_is_up_to_date():
    """The committed _generated.py is exactly what the derivation prints now."""
    from pathlib import Path

    committed = Path(derivation.__file__).with_name("_generated.py").read_text()
    assert committed == derivation.generate_code()


def test_generated_drive_code_is_up_to_date():
    """The committed _generated_drive.py (the free crank of a motor drive) is exactly what the
    derivation prints now."""
    from pathlib import Path

    committed = Path(derivation.__file__).with_name("_generated_drive.py").read_text()
    assert committed == derivation.generate_drive_code()


def test_generated_throw_code_is_up_to_date():
    """The committed mechanism/_generated_throw.py (one throw's share of a free crank's
    equations, for machines of several throws) is exactly what the derivation prints now."""
    from pathlib import Path

    committed = Path(derivation.__file__).parent / "mechanism" / "_generated_throw.py"
    assert committed.read_text() == derivation.generate_throw_code()


def test_a_throws_share_solved_alone_is_the_one_throw_free_crank(rng):
    """The throw's own ``M`` and ``b`` (without the drive) with the drive's inertia and torque
    added to its crank row, solved, give the free-crank accelerations of the one-throw
    derivation (`_generated_drive`), at 30 random states and geometries: the two printed
    forms of one Lagrangian agree to rounding (1e-9 relative)."""
    from recipdyn.model._generated_drive import free_crank_accelerations
    from recipdyn.model.mechanism._generated_throw import link_throw_system

    for c in _random_states(rng, 30):
        p = np.array(
            [
                c["r"],
                c["r"] * rng.uniform(0, 1),
                c["l"],
                c["ls"],
                rng.uniform(1, 30),
                c["m2"],
                c["m3"],
                rng.uniform(0, 1),
                c["J2"],
                c["g"],
                c["rc"],
                c["d"],
            ]
        )
        y = (rng.uniform(0, 6.3), rng.uniform(0, 6.3), rng.uniform(5, 30), rng.normal(0, 50))
        F, Jd, Tm = rng.normal(0, 1e5), rng.uniform(1, 1e4), rng.normal(0, 1e4)
        m00, m10, m11, b0, b1 = link_throw_system(y, p, 0, (F,))
        M = np.array([[m00 + Jd, m10], [m10, m11]])
        want = np.linalg.solve(M, [b0 + Tm, b1])
        got = free_crank_accelerations(0.0, y, p, (Jd, F, Tm))
        assert np.allclose(got, want, rtol=1e-9, atol=1e-9 * np.abs(want).max()), (got, want)


def test_structured_equals_brute_force_lagrangian(rng):
    """Hypothesis: the paper-structured derivation (exact partials, Eq. 38-42 form) and a
    brute-force Lagrangian with theta2 = -asin(...) substituted give the same theta_c''."""
    sym = [S[k] if k != "ls" else S["ls"] for k in ARGS]
    f_struct = sp.lambdify(sym, derivation.structured_equations()["acc"], "numpy")
    f_brute = sp.lambdify(sym, derivation.brute_force_lagrangian(), "numpy")
    for st in _random_states(rng, 40):
        a = [st[k] for k in ARGS]
        ref = f_brute(*a)
        assert f_struct(*a) == pytest.approx(ref, rel=1e-10, abs=1e-10 * abs(st["F"]))


def test_compiled_kernel_matches_symbolic(rng):
    """The compiled kernel evaluates the symbolic expression to rounding."""
    sym = [S[k] for k in ARGS]
    f = sp.lambdify(sym, derivation.structured_equations()["acc"], "numpy")
    for st in _random_states(rng, 40):
        a = [st[k] for k in ARGS]
        assert clearance_acceleration(*a) == pytest.approx(f(*a), rel=1e-11)


def test_jacobian_matches_finite_differences(rng):
    """d(theta_c'')/d(theta_c) and /d(theta_c') agree with central differences."""
    for st in _random_states(rng, 30):
        a = [st[k] for k in ARGS]
        acc, dq, dqd = clearance_acceleration_jac(*a)
        assert acc == pytest.approx(clearance_acceleration(*a), rel=1e-13)
        for idx, deriv, h in ((1, dq, 1e-6), (2, dqd, 1e-3)):
            ap, am = list(a), list(a)
            ap[idx] += h
            am[idx] -= h
            fd = (clearance_acceleration(*ap) - clearance_acceleration(*am)) / (2 * h)
            assert deriv == pytest.approx(fd, rel=1e-5, abs=1e-6 * abs(acc) + 1e-9)


def test_combined_rhs_jac_equals_separate_kernels(rng):
    """The model's rhs_jac gives rhs and jac to rounding (used by the tangent integration)."""
    from recipdyn.model import CompressorParams, compressor_model

    m = compressor_model(CompressorParams(rc=2e-3, d=1e-3))
    for _ in range(20):
        t, y = rng.uniform(0, 1), np.array([rng.uniform(-3, 3), rng.normal(0, 200)])
        f, J = np.empty(2), np.empty((2, 2))
        m.rhs_jac(t, y, m.params, f, J)
        np.testing.assert_allclose(f, m.f(t, y), rtol=1e-12)
        np.testing.assert_allclose(J, m.jacobian(t, y), rtol=1e-12)
