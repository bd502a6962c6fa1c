"""A reference port for the engine benchmarks (issue 15, targets 4 and 6).

A deliberately plain numba program for one job: integrate the compressor's exact equation
(Lagrange's equation of the clearance angle, the same generated expression the model uses) with
Dormand-Prince 8(5,3) and, for Benettin's method, its variational equation. It shares nothing
with recipdyn's integrator: the right-hand side is a global of the compiled loop (so numba
inlines it; recipdyn calls it through a function pointer), there are no events, no dense output,
no output buffers and no step statistics. Step control is Hairer's as SciPy writes it (so at
equal tolerances both programs take nearly the same steps; the step counts are reported so a
difference in work shows). What remains between the two is overhead: the benchmark's ratio.

Only the tableau is read from SciPy (the coefficients are data, not code).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from recipdyn.model._generated import clearance_acceleration, clearance_acceleration_jac
from recipdyn.model.load import mu_kernel


def tableau():
    from scipy.integrate import DOP853 as S

    return (np.ascontiguousarray(S.A[:12, :12]), np.ascontiguousarray(S.B),
            np.ascontiguousarray(S.C[:12]), np.ascontiguousarray(S.E3),
            np.ascontiguousarray(S.E5))  # fmt: skip


def params(p) -> np.ndarray:
    """[r, l, ls, m2, m3, J2, g, rc, d, omega, theta1_0, F0] (F0: signed load amplitude)."""
    sign = -1.0 if p.load_sign == "physical" else 1.0
    return np.array([p.r, p.l, p.ls, p.m2, p.m3, p.J2, p.g, p.rc, p.d, p.omega, p.theta1_0,
                     sign * p.load_amplitude])  # fmt: skip


@nb.njit(cache=True, inline="always")
def _acc(t, q, qd, P):
    th1 = P[10] + P[9] * t
    F = P[11] * mu_kernel(th1)
    return clearance_acceleration(th1, q, qd, F, P[0], P[1], P[2], P[3], P[4], P[5], P[6],
                                  P[7], P[8], P[9])  # fmt: skip


@nb.njit(cache=True, inline="always")
def rhs(t, y, P, out):
    """The state, and when ``y`` is longer, the tangent vectors ``W`` (2 x k, row-major)."""
    out[0] = y[1]
    out[1] = _acc(t, y[0], y[1], P)
    if y.shape[0] > 2:
        th1 = P[10] + P[9] * t
        F = P[11] * mu_kernel(th1)
        _, a_q, a_qd = clearance_acceleration_jac(th1, y[0], y[1], F, P[0], P[1], P[2], P[3],
                                                  P[4], P[5], P[6], P[7], P[8], P[9])  # fmt: skip
        k = (y.shape[0] - 2) // 2
        for j in range(k):
            out[2 + j] = y[2 + k + j]
            out[2 + k + j] = a_q * y[2 + j] + a_qd * y[2 + k + j]


@nb.njit(cache=True)
def _step(t, y, f, h, P, A, B, C, E3, E5, K, yt, y_new, f_new, rtol, atol):
    """One DOP853 step from (t, y) with size h; returns the error norm (SciPy's)."""
    n = y.shape[0]
    for j in range(n):
        K[0, j] = f[j]
    for s in range(1, 12):
        for j in range(n):
            acc = 0.0
            for m in range(s):
                acc += A[s, m] * K[m, j]
            yt[j] = y[j] + h * acc
        rhs(t + C[s] * h, yt, P, K[s])
    for j in range(n):
        acc = 0.0
        for m in range(12):
            acc += B[m] * K[m, j]
        y_new[j] = y[j] + h * acc
    rhs(t + h, y_new, P, f_new)
    for j in range(n):
        K[12, j] = f_new[j]
    e5 = 0.0
    e3 = 0.0
    for j in range(n):
        sc = atol + max(abs(y[j]), abs(y_new[j])) * rtol
        a5 = 0.0
        a3 = 0.0
        for m in range(13):
            a5 += K[m, j] * E5[m]
            a3 += K[m, j] * E3[m]
        e5 += (a5 / sc) ** 2
        e3 += (a3 / sc) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * n)


@nb.njit(cache=True)
def solve(t0, y, t1, h, P, A, B, C, E3, E5, rtol, atol, counts):
    """Integrate ``y`` in place from t0 to t1 starting with step ``h``; returns the next step.
    ``counts += [steps, rejected steps]``."""
    n = y.shape[0]
    K = np.empty((13, n))
    yt = np.empty(n)
    y_new = np.empty(n)
    f_new = np.empty(n)
    f = np.empty(n)
    rhs(t0, y, P, f)
    t = t0
    while t < t1:
        rejected = False
        while True:
            hh = min(h, t1 - t)
            err = _step(t, y, f, hh, P, A, B, C, E3, E5, K, yt, y_new, f_new, rtol, atol)
            if err < 1.0:
                fac = 10.0 if err == 0.0 else min(10.0, 0.9 * err ** (-1.0 / 8.0))
                if rejected:
                    fac = min(1.0, fac)
                h = hh * fac
                break
            h = hh * max(0.2, 0.9 * err ** (-1.0 / 8.0))
            rejected = True
            counts[1] += 1
        counts[0] += 1
        t += hh
        for j in range(n):
            y[j] = y_new[j]
            f[j] = f_new[j]
    return h


@nb.njit(cache=True)
def benettin(t0, y0, period, n_periods, per_period, P, A, B, C, E3, E5, rtol, atol, counts):
    """Both exponents of the compressor: state and two tangent vectors integrated together,
    Gram-Schmidt (the QR of a 2 x 2 matrix) ``per_period`` times per crank period."""
    z = np.zeros(6)
    z[0] = y0[0]
    z[1] = y0[1]
    z[2] = 1.0  # W = identity, row-major: z[2:4] = W[0, :], z[4:6] = W[1, :]
    z[5] = 1.0
    sums = np.zeros(2)
    h = 1e-4
    dt = period / per_period
    t = t0
    for i in range(n_periods * per_period):
        t_next = t0 + (i + 1) * dt
        h = solve(t, z, t_next, h, P, A, B, C, E3, E5, rtol, atol, counts)
        t = t_next
        a0, a1 = z[2], z[4]  # first column
        b0, b1 = z[3], z[5]  # second column
        r11 = math.sqrt(a0 * a0 + a1 * a1)
        q0, q1 = a0 / r11, a1 / r11
        r12 = q0 * b0 + q1 * b1
        c0, c1 = b0 - r12 * q0, b1 - r12 * q1
        r22 = math.sqrt(c0 * c0 + c1 * c1)
        sums[0] += math.log(r11)
        sums[1] += math.log(r22)
        z[2], z[4] = q0, q1
        z[3], z[5] = c0 / r22, c1 / r22
    return sums / (t - t0)
