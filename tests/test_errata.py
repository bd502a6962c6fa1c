"""Errata of the printed equations (docs/errata.md): each is shown against exact derivatives.

Each test states the printed form, the exact form, and shows that the exact form agrees with
sympy's derivative while the printed one does not.
"""

import numpy as np
import pytest
import sympy as sp

from recipdyn.model.derivation import SYMBOLS as S
from recipdyn.model.derivation import structured_equations
from recipdyn.model.paper_printed import paper_coefficients

EQ = structured_equations()
th1, thc, r, l, rc, d = (S[k] for k in ("theta1", "theta_c", "r", "l", "rc", "d"))
VALS = {th1: 0.7, thc: 2.1, r: 0.12, l: 0.6, rc: 1e-3, d: 1e-3}


def _num(expr):
    return float(expr.subs(VALS).evalf())


def _th2():
    return _num(EQ["theta2"])


def test_erratum_eq20_denominator_cos_theta2_not_cos_theta_c():
    """Eq. (20): d2(theta2)/d(theta_c)^2 has l^2 cos^3(theta2) in the denominator, not
    cos^3(theta_c) (and its left side is mislabelled d/d(theta1)^2)."""
    t2 = _th2()
    num = VALS[rc] * VALS[l] * np.sin(VALS[thc]) * np.cos(t2) ** 2
    num += (VALS[rc] * np.cos(VALS[thc])) ** 2 * np.sin(t2)
    exact = _num(EQ["th2_cc"])
    assert num / (VALS[l] ** 2 * np.cos(t2) ** 3) == pytest.approx(exact, rel=1e-12)
    assert num / (VALS[l] ** 2 * np.cos(VALS[thc]) ** 3) != pytest.approx(exact, rel=1e-2)


def test_erratum_eq21_denominator_cubed():
    """Eq. (21): the mixed derivative has l^2 cos^3(theta2), not cos^2(theta2)."""
    t2 = _th2()
    num = VALS[r] * VALS[rc] * np.sin(t2) * np.cos(VALS[th1]) * np.cos(VALS[thc])
    exact = _num(EQ["th2_1c"])
    assert num / (VALS[l] ** 2 * np.cos(t2) ** 3) == pytest.approx(exact, rel=1e-12)
    assert num / (VALS[l] ** 2 * np.cos(t2) ** 2) != pytest.approx(exact, rel=1e-6)


def test_erratum_eq18_thetadot_c_squared():
    """Eq. (18): the d2(theta2)/d(theta_c)^2 term multiplies theta_c'^2, not theta_1'^2: the
    second time derivative of theta2 along a path agrees only with the corrected form."""
    t = sp.symbols("t")
    w, a, b = 20.0, 0.3, 150.0  # theta1 = w t, theta_c = a + b t (theta_c'' = 0)
    path = {th1: w * t, thc: a + b * t}
    th2_t = EQ["theta2"].subs(path).subs({r: 0.12, l: 0.6, rc: 1e-3, d: 1e-3})
    t0 = 0.01
    exact_dd = float(sp.diff(th2_t, t, 2).subs(t, t0))
    at = {th1: w * t0, thc: a + b * t0, r: 0.12, l: 0.6, rc: 1e-3, d: 1e-3}
    q11, q1c, qcc = (float(EQ[k].subs(at)) for k in ("th2_11", "th2_1c", "th2_cc"))
    corrected = q11 * w**2 + 2 * q1c * w * b + qcc * b**2
    printed = q11 * w**2 + 2 * q1c * w * b + qcc * w**2
    assert corrected == pytest.approx(exact_dd, rel=1e-10)
    assert printed != pytest.approx(exact_dd, rel=1e-3)


def _coefficients(rc_val, th1_v=0.9, thc_v=2.5):
    """Exact A, B, C, D in the paper's normalisation A th'' = B th' + C th'^2 + D (g = 0)."""
    vals = dict(theta1=th1_v, theta_c=thc_v, F=1e5, r=0.12, l=0.6, ls=0.3, m2=20.0, m3=30.0,
                J2=0.6, g=0.0, rc=rc_val, d=1e-3, omega=20.0)  # fmt: skip
    sub = {S[k]: v for k, v in vals.items()}
    A = float(EQ["A"].subs(sub))
    B = -2 * 20.0 * float(EQ["Bq"].subs(sub))
    C = -float(EQ["Cq"].subs(sub))
    D = float((-(20.0**2) * EQ["Dq"] - EQ["G"] + EQ["Q"]).subs(sub))
    printed = paper_coefficients(th1_v, thc_v, 1e5, 0.12, 0.6, 20.0, 30.0, 0.6, rc_val, 1e-3, 20.0)
    return (A, B, C, D), printed


def test_erratum_eq43_sign_of_rod_cross_term():
    """Eq. (43): with l = 2 l_s, A is exact except for the sign of the rod's cross term:
    printed + a2 cos(theta_c) sin(theta_c) tan(theta2), exact - (flipping it gives A to
    rounding)."""
    (A, *_), (Ap, *_) = _coefficients(1e-3)
    t2 = _th2_at(0.9, 2.5, 1e-3)
    fix = -2 * 20.0 * 1e-3**2 * np.cos(2.5) * np.sin(2.5) * np.tan(t2)
    assert Ap != pytest.approx(A, rel=1e-3)
    assert Ap + fix == pytest.approx(A, rel=1e-12)


def _th2_at(t1, tc, rcv):
    return -np.arcsin((1e-3 + 0.12 * np.sin(t1) + rcv * np.sin(tc)) / 0.6)


@pytest.mark.parametrize("name, idx", [("B", 1), ("C", 2)])
def test_printed_B_C_are_not_small_clearance_limits(name, idx):
    """Eq. (44)-(45) are not the rc -> 0 limit of the exact coefficients: their relative error
    does not shrink as rc decreases 100-fold (so it is not the 'rc x + y ~ y' approximation)."""
    errs = []
    for rcv in (1e-3, 1e-5):
        ex, pr = _coefficients(rcv)
        errs.append(abs(pr[idx] / ex[idx] - 1))
    assert min(errs) > 0.05, errs
    assert errs[1] > 0.3 * errs[0]


def test_printed_D_gas_term_is_exact_with_paper_sign():
    """The gas-load part of Eq. (46), d1 (-sin th_c + tan th2 cos th_c) with d1 = P rc, equals
    P dx3/d(theta_c): the printed equation applies +P along +x (load_sign='paper')."""
    sub = {S["r"]: 0.12, S["l"]: 0.6, S["rc"]: 1e-3, S["d"]: 1e-3, S["theta1"]: 0.9,
           S["theta_c"]: 2.5, S["F"]: 1.0}  # fmt: skip
    q = float(EQ["Q"].subs(sub))
    t2 = _th2_at(0.9, 2.5, 1e-3)
    assert 1e-3 * (-np.sin(2.5) + np.tan(t2) * np.cos(2.5)) == pytest.approx(q, rel=1e-12)
