"""The systems of the Lyapunov calibration study (``bench_lyap_calibration.py``).

Flows, delay equations, maps and regular or stochastic signals, each with the equations'
largest Lyapunov exponent from Benettin's method (flows: `recipdyn.analysis.lyapunov_spectrum`
with the exact Jacobians below; maps: `lyapunov_spectrum_map`; delay equations: the tangent of
a method-of-steps discretisation, `dde_lyapunov`). Parameters are the usual ones of the cited
papers; every Jacobian is checked against central differences (`check_jacobians`).

References (equations and parameters)
-------------------------------------
Lorenz (1963); Rossler (1976, 1979); Ueda (1979); Chen & Ueta (1999), Int. J. Bifurc. Chaos 9,
1465; Lu & Chen (2002), Int. J. Bifurc. Chaos 12, 659; Chua: Matsumoto, Chua & Komuro (1985),
IEEE TCAS 32, 797 (the dimensionless double scroll); Thomas (1999), Int. J. Bifurc. Chaos 9,
1889; Halvorsen: Sprott, *Elegant Chaos* (2010), eq. (5.50); Sprott (1994), Phys. Rev. E 50,
R647 (cases B, C, D, F, G, J, K, N, R, S); Rucklidge (1992), J. Fluid Mech. 237, 209;
Shimizu & Morioka (1980), Phys. Lett. A 76, 201; Genesio & Tesi (1992), Automatica 28, 531;
Moore & Spiegel (1966), Astrophys. J. 143, 871; Shaw (1981), Z. Naturforsch. 36a, 80
(Burke-Shaw); Lorenz (1984), Tellus 36A, 98; Aizawa & Uezu (1982), Prog. Theor. Phys. 67, 982;
Lorenz (1996), "Predictability" (Lorenz-96); Mackey & Glass (1977), Science 197, 287, and
Farmer (1982), Physica D 4, 366 (its exponents at delays 17-30); Ikeda & Matsumoto (1987),
Physica D 29, 223; Gurney, Blythe & Nisbet (1980), Nature 287, 17 (Nicholson's blowflies); Henon
(1976); Lozi (1978); Ikeda (1979); Nusse & Yorke (1994) (Tinkerbell); Holmes (1979) (the
Duffing map); Politi & Torcini (1992), Chaos 2, 293 (coupled Henon maps); Kaneko (1989),
Physica D 34, 1 (coupled logistic lattice); Bollerslev (1986) (GARCH); Sprott, *Chaos and
Time-Series Analysis* (2003), App. A (published exponents).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba as nb
import numpy as np

from recipdyn.model.base import JAC_SIGNATURE, RHS_SIGNATURE, DiscreteMap, ODESystem, compiled
from recipdyn.model.reference import systems as S

# --- flows ------------------------------------------------------------------------------------


@compiled(RHS_SIGNATURE)
def _chen(t, y, p, out):
    out[0] = p[0] * (y[1] - y[0])
    out[1] = (p[2] - p[0]) * y[0] - y[0] * y[2] + p[2] * y[1]
    out[2] = y[0] * y[1] - p[1] * y[2]


@compiled(JAC_SIGNATURE)
def _chen_jac(t, y, p, J):
    J[0, 0], J[0, 1], J[0, 2] = -p[0], p[0], 0.0
    J[1, 0], J[1, 1], J[1, 2] = p[2] - p[0] - y[2], p[2], -y[0]
    J[2, 0], J[2, 1], J[2, 2] = y[1], y[0], -p[1]


@compiled(RHS_SIGNATURE)
def _lu(t, y, p, out):
    out[0] = p[0] * (y[1] - y[0])
    out[1] = -y[0] * y[2] + p[2] * y[1]
    out[2] = y[0] * y[1] - p[1] * y[2]


@compiled(JAC_SIGNATURE)
def _lu_jac(t, y, p, J):
    J[0, 0], J[0, 1], J[0, 2] = -p[0], p[0], 0.0
    J[1, 0], J[1, 1], J[1, 2] = -y[2], p[2], -y[0]
    J[2, 0], J[2, 1], J[2, 2] = y[1], y[0], -p[1]


@compiled(RHS_SIGNATURE)
def _chua(t, y, p, out):
    x = y[0]
    f = p[3] * x + 0.5 * (p[2] - p[3]) * (abs(x + 1.0) - abs(x - 1.0))
    out[0] = p[0] * (y[1] - x - f)
    out[1] = x - y[1] + y[2]
    out[2] = -p[1] * y[1]


@compiled(JAC_SIGNATURE)
def _chua_jac(t, y, p, J):
    df = p[2] if abs(y[0]) < 1.0 else p[3]
    J[0, 0], J[0, 1], J[0, 2] = -p[0] * (1.0 + df), p[0], 0.0
    J[1, 0], J[1, 1], J[1, 2] = 1.0, -1.0, 1.0
    J[2, 0], J[2, 1], J[2, 2] = 0.0, -p[1], 0.0


@compiled(RHS_SIGNATURE)
def _thomas(t, y, p, out):
    out[0] = math.sin(y[1]) - p[0] * y[0]
    out[1] = math.sin(y[2]) - p[0] * y[1]
    out[2] = math.sin(y[0]) - p[0] * y[2]


@compiled(JAC_SIGNATURE)
def _thomas_jac(t, y, p, J):
    J[0, 0], J[0, 1], J[0, 2] = -p[0], math.cos(y[1]), 0.0
    J[1, 0], J[1, 1], J[1, 2] = 0.0, -p[0], math.cos(y[2])
    J[2, 0], J[2, 1], J[2, 2] = math.cos(y[0]), 0.0, -p[0]


@compiled(RHS_SIGNATURE)
def _halvorsen(t, y, p, out):
    a = p[0]
    out[0] = -a * y[0] - 4.0 * y[1] - 4.0 * y[2] - y[1] ** 2
    out[1] = -a * y[1] - 4.0 * y[2] - 4.0 * y[0] - y[2] ** 2
    out[2] = -a * y[2] - 4.0 * y[0] - 4.0 * y[1] - y[0] ** 2


@compiled(JAC_SIGNATURE)
def _halvorsen_jac(t, y, p, J):
    a = p[0]
    J[0, 0], J[0, 1], J[0, 2] = -a, -4.0 - 2.0 * y[1], -4.0
    J[1, 0], J[1, 1], J[1, 2] = -4.0, -a, -4.0 - 2.0 * y[2]
    J[2, 0], J[2, 1], J[2, 2] = -4.0 - 2.0 * y[0], -4.0, -a


@compiled(RHS_SIGNATURE)
def _sprott(t, y, p, out):
    """Sprott's (1994) simple flows, the case chosen by p[0] (B=1, C=2, D=3, F=5, G=6, J=9,
    K=10, N=13, R=17, S=18)."""
    c = int(p[0])
    x, v, z = y[0], y[1], y[2]
    if c == 1:
        out[0], out[1], out[2] = v * z, x - v, 1.0 - x * v
    elif c == 2:
        out[0], out[1], out[2] = v * z, x - v, 1.0 - x * x
    elif c == 3:
        out[0], out[1], out[2] = -v, x + z, x * z + 3.0 * v * v
    elif c == 5:
        out[0], out[1], out[2] = v + z, -x + 0.5 * v, x * x - z
    elif c == 6:
        out[0], out[1], out[2] = 0.4 * x + z, x * z - v, -x + v
    elif c == 9:
        out[0], out[1], out[2] = 2.0 * z, -2.0 * v + z, -x + v + v * v
    elif c == 10:
        out[0], out[1], out[2] = x * v - z, x - v, x + 0.3 * z
    elif c == 13:
        out[0], out[1], out[2] = -2.0 * v, x + z * z, 1.0 + v - 2.0 * z
    elif c == 17:
        out[0], out[1], out[2] = 0.9 - v, 0.4 + z, x * v - z
    else:
        out[0], out[1], out[2] = -x - 4.0 * v, x + z * z, 1.0 + x


@compiled(JAC_SIGNATURE)
def _sprott_jac(t, y, p, J):
    c = int(p[0])
    x, v, z = y[0], y[1], y[2]
    J[:, :] = 0.0
    if c == 1:
        J[0, 1], J[0, 2] = z, v
        J[1, 0], J[1, 1] = 1.0, -1.0
        J[2, 0], J[2, 1] = -v, -x
    elif c == 2:
        J[0, 1], J[0, 2] = z, v
        J[1, 0], J[1, 1] = 1.0, -1.0
        J[2, 0] = -2.0 * x
    elif c == 3:
        J[0, 1] = -1.0
        J[1, 0], J[1, 2] = 1.0, 1.0
        J[2, 0], J[2, 1], J[2, 2] = z, 6.0 * v, x
    elif c == 5:
        J[0, 1], J[0, 2] = 1.0, 1.0
        J[1, 0], J[1, 1] = -1.0, 0.5
        J[2, 0], J[2, 2] = 2.0 * x, -1.0
    elif c == 6:
        J[0, 0], J[0, 2] = 0.4, 1.0
        J[1, 0], J[1, 1], J[1, 2] = z, -1.0, x
        J[2, 0], J[2, 1] = -1.0, 1.0
    elif c == 9:
        J[0, 2] = 2.0
        J[1, 1], J[1, 2] = -2.0, 1.0
        J[2, 0], J[2, 1] = -1.0, 1.0 + 2.0 * v
    elif c == 10:
        J[0, 0], J[0, 1], J[0, 2] = v, x, -1.0
        J[1, 0], J[1, 1] = 1.0, -1.0
        J[2, 0], J[2, 2] = 1.0, 0.3
    elif c == 13:
        J[0, 1] = -2.0
        J[1, 0], J[1, 2] = 1.0, 2.0 * z
        J[2, 1], J[2, 2] = 1.0, -2.0
    elif c == 17:
        J[0, 1] = -1.0
        J[1, 2] = 1.0
        J[2, 0], J[2, 1], J[2, 2] = v, x, -1.0
    else:
        J[0, 0], J[0, 1] = -1.0, -4.0
        J[1, 0], J[1, 2] = 1.0, 2.0 * z
        J[2, 0] = 1.0


@compiled(RHS_SIGNATURE)
def _jerk(t, y, p, out):
    """x''' = j(x, x', x''): Genesio-Tesi (p[0] = 0: -a x'' - b x' - c x + x^2) or
    Moore-Spiegel (p[0] = 1: -x'' - (T - R + R x^2) x' - T x), constants p[1..3]."""
    out[0] = y[1]
    out[1] = y[2]
    if p[0] == 0.0:
        out[2] = -p[1] * y[2] - p[2] * y[1] - p[3] * y[0] + y[0] ** 2
    else:
        out[2] = -y[2] - (p[1] - p[2] + p[2] * y[0] ** 2) * y[1] - p[1] * y[0]


@compiled(JAC_SIGNATURE)
def _jerk_jac(t, y, p, J):
    J[:, :] = 0.0
    J[0, 1] = 1.0
    J[1, 2] = 1.0
    if p[0] == 0.0:
        J[2, 0], J[2, 1], J[2, 2] = -p[3] + 2.0 * y[0], -p[2], -p[1]
    else:
        J[2, 0] = -2.0 * p[2] * y[0] * y[1] - p[1]
        J[2, 1] = -(p[1] - p[2] + p[2] * y[0] ** 2)
        J[2, 2] = -1.0


@compiled(RHS_SIGNATURE)
def _rucklidge(t, y, p, out):
    out[0] = -p[0] * y[0] + p[1] * y[1] - y[1] * y[2]
    out[1] = y[0]
    out[2] = -y[2] + y[1] ** 2


@compiled(JAC_SIGNATURE)
def _rucklidge_jac(t, y, p, J):
    J[0, 0], J[0, 1], J[0, 2] = -p[0], p[1] - y[2], -y[1]
    J[1, 0], J[1, 1], J[1, 2] = 1.0, 0.0, 0.0
    J[2, 0], J[2, 1], J[2, 2] = 0.0, 2.0 * y[1], -1.0


@compiled(RHS_SIGNATURE)
def _shimizu(t, y, p, out):
    out[0] = y[1]
    out[1] = y[0] - p[0] * y[1] - y[0] * y[2]
    out[2] = -p[1] * y[2] + y[0] ** 2


@compiled(JAC_SIGNATURE)
def _shimizu_jac(t, y, p, J):
    J[0, 0], J[0, 1], J[0, 2] = 0.0, 1.0, 0.0
    J[1, 0], J[1, 1], J[1, 2] = 1.0 - y[2], -p[0], -y[0]
    J[2, 0], J[2, 1], J[2, 2] = 2.0 * y[0], 0.0, -p[1]


@compiled(RHS_SIGNATURE)
def _burke_shaw(t, y, p, out):
    out[0] = -p[0] * (y[0] + y[1])
    out[1] = -y[1] - p[0] * y[0] * y[2]
    out[2] = p[0] * y[0] * y[1] + p[1]


@compiled(JAC_SIGNATURE)
def _burke_shaw_jac(t, y, p, J):
    J[0, 0], J[0, 1], J[0, 2] = -p[0], -p[0], 0.0
    J[1, 0], J[1, 1], J[1, 2] = -p[0] * y[2], -1.0, -p[0] * y[0]
    J[2, 0], J[2, 1], J[2, 2] = p[0] * y[1], p[0] * y[0], 0.0


@compiled(RHS_SIGNATURE)
def _lorenz84(t, y, p, out):
    a, b, F, G = p[0], p[1], p[2], p[3]
    out[0] = -(y[1] ** 2) - y[2] ** 2 - a * y[0] + a * F
    out[1] = y[0] * y[1] - b * y[0] * y[2] - y[1] + G
    out[2] = b * y[0] * y[1] + y[0] * y[2] - y[2]


@compiled(JAC_SIGNATURE)
def _lorenz84_jac(t, y, p, J):
    a, b = p[0], p[1]
    J[0, 0], J[0, 1], J[0, 2] = -a, -2.0 * y[1], -2.0 * y[2]
    J[1, 0], J[1, 1], J[1, 2] = y[1] - b * y[2], y[0] - 1.0, -b * y[0]
    J[2, 0], J[2, 1], J[2, 2] = b * y[1] + y[2], b * y[0], y[0] - 1.0


@compiled(RHS_SIGNATURE)
def _aizawa(t, y, p, out):
    a, b, c, d, e, f = p[0], p[1], p[2], p[3], p[4], p[5]
    x, v, z = y[0], y[1], y[2]
    out[0] = (z - b) * x - d * v
    out[1] = d * x + (z - b) * v
    out[2] = c + a * z - z**3 / 3.0 - (x * x + v * v) * (1.0 + e * z) + f * z * x**3


@compiled(JAC_SIGNATURE)
def _aizawa_jac(t, y, p, J):
    a, b, d, e, f = p[0], p[1], p[3], p[4], p[5]
    x, v, z = y[0], y[1], y[2]
    J[0, 0], J[0, 1], J[0, 2] = z - b, -d, x
    J[1, 0], J[1, 1], J[1, 2] = d, z - b, v
    J[2, 0] = -2.0 * x * (1.0 + e * z) + 3.0 * f * z * x * x
    J[2, 1] = -2.0 * v * (1.0 + e * z)
    J[2, 2] = a - z * z - (x * x + v * v) * e + f * x**3


@compiled(RHS_SIGNATURE)
def _vdp(t, y, p, out):
    """Van der Pol, forced: x'' - mu (1 - x^2) x' + x = A cos(w t)."""
    out[0] = y[1]
    out[1] = p[0] * (1.0 - y[0] ** 2) * y[1] - y[0] + p[1] * math.cos(p[2] * t)


@compiled(JAC_SIGNATURE)
def _vdp_jac(t, y, p, J):
    J[0, 0], J[0, 1] = 0.0, 1.0
    J[1, 0], J[1, 1] = -2.0 * p[0] * y[0] * y[1] - 1.0, p[0] * (1.0 - y[0] ** 2)


def _ode(rhs, jac, params, dim, name, period=None):
    return ODESystem(rhs=rhs, jac=jac, params=np.asarray(params, dtype=float),
                     state_names=tuple(f"y{i}" for i in range(dim)), name=name,
                     period=period)  # fmt: skip


# --- maps -------------------------------------------------------------------------------------


@compiled(RHS_SIGNATURE)
def _holmes(n, x, p, out):
    out[0] = x[1]
    out[1] = -p[1] * x[0] + p[0] * x[1] - x[1] ** 3


@compiled(JAC_SIGNATURE)
def _holmes_jac(n, x, p, J):
    J[0, 0], J[0, 1] = 0.0, 1.0
    J[1, 0], J[1, 1] = -p[1], p[0] - 3.0 * x[1] ** 2


@compiled(RHS_SIGNATURE)
def _logistic_lattice(n, x, p, out):
    """Kaneko's coupled map lattice: x_i' = (1 - e) g(x_i) + e/2 (g(x_{i-1}) + g(x_{i+1})),
    g(x) = r x (1 - x), periodic boundary."""
    m = x.shape[0]
    r, e = p[0], p[1]
    for i in range(m):
        g0 = r * x[i] * (1.0 - x[i])
        gl = r * x[(i - 1) % m] * (1.0 - x[(i - 1) % m])
        gr = r * x[(i + 1) % m] * (1.0 - x[(i + 1) % m])
        out[i] = (1.0 - e) * g0 + 0.5 * e * (gl + gr)


@compiled(JAC_SIGNATURE)
def _logistic_lattice_jac(n, x, p, J):
    m = x.shape[0]
    r, e = p[0], p[1]
    J[:, :] = 0.0
    for i in range(m):
        J[i, i] += (1.0 - e) * r * (1.0 - 2.0 * x[i])
        J[i, (i - 1) % m] += 0.5 * e * r * (1.0 - 2.0 * x[(i - 1) % m])
        J[i, (i + 1) % m] += 0.5 * e * r * (1.0 - 2.0 * x[(i + 1) % m])


@compiled(RHS_SIGNATURE)
def _coupled_henon(n, x, p, out):
    """Two Henon maps coupled through their x (Politi & Torcini 1992): u1 = (1 - c) x1 + c x2,
    x1' = 1 - a u1^2 + y1, y1' = b x1, and the same with 1 and 2 exchanged."""
    a, b, c = p[0], p[1], p[2]
    u1 = (1.0 - c) * x[0] + c * x[2]
    u2 = (1.0 - c) * x[2] + c * x[0]
    out[0] = 1.0 - a * u1 * u1 + x[1]
    out[1] = b * x[0]
    out[2] = 1.0 - a * u2 * u2 + x[3]
    out[3] = b * x[2]


@compiled(JAC_SIGNATURE)
def _coupled_henon_jac(n, x, p, J):
    a, b, c = p[0], p[1], p[2]
    u1 = (1.0 - c) * x[0] + c * x[2]
    u2 = (1.0 - c) * x[2] + c * x[0]
    J[:, :] = 0.0
    J[0, 0], J[0, 1], J[0, 2] = -2.0 * a * u1 * (1.0 - c), 1.0, -2.0 * a * u1 * c
    J[1, 0] = b
    J[2, 0], J[2, 2], J[2, 3] = -2.0 * a * u2 * c, -2.0 * a * u2 * (1.0 - c), 1.0
    J[3, 2] = b


def _map(step, jac, params, dim, name):
    return DiscreteMap(step=step, jac=jac, params=np.asarray(params, dtype=float),
                       state_names=tuple(f"x{i}" for i in range(dim)), name=name)  # fmt: skip


# --- delay equations ----------------------------------------------------------------------------
# x'(t) = f(x(t), x(t - tau)); kinds: 0 Mackey-Glass (beta, gamma, n), 1 Ikeda (mu, x0),
# 2 Nicholson's blowflies (delta, P).


@nb.njit(cache=True)
def _dde_f(kind, x, xd, p):
    """(f, df/dx, df/dxd)."""
    if kind == 0:
        q = xd ** p[2]
        f = p[0] * xd / (1.0 + q) - p[1] * x
        dfd = p[0] * (1.0 + q - p[2] * q) / (1.0 + q) ** 2
        return f, -p[1], dfd
    if kind == 1:
        return -x + p[0] * math.sin(xd - p[1]), -1.0, p[0] * math.cos(xd - p[1])
    e = math.exp(-xd)
    return -p[0] * x + p[1] * xd * e, -p[0], p[1] * (1.0 - xd) * e


@nb.njit(cache=True)
def _dde_run(kind, p, d, h, x_init, n_steps, every, renorm, tangent):
    """Method of steps with RK4, ``d`` steps a delay (h = tau / d); the delayed value at a
    half step by cubic interpolation (4th order) of the stored values. Returns the samples
    every ``every`` steps, the final history (d + 3 values) and, if ``tangent``, the largest
    exponent of the discretised system: the linearised step applied to a tangent history,
    renormalised every ``renorm`` steps (Benettin)."""
    m = d + 3  # ring buffer: x[i - d - 1] ... x[i + 1]
    buf = np.empty(m)
    tb = np.empty(m)
    for k in range(m):
        buf[k] = x_init[k]
        tb[k] = 1.0 if k == m - 2 else 0.0
    # index j of the ring holds x at step (j - (m - 2)) relative to the start, shifted
    out = np.empty(n_steps // every + 1)
    n_out = 0
    head = m - 2  # position of the current x[i]
    log_sum = 0.0
    for i in range(n_steps):
        # positions of x[i - d - 1], x[i - d], x[i - d + 1], x[i - d + 2]
        j0 = (head - d - 1) % m
        j1 = (head - d) % m
        j2 = (head - d + 1) % m
        j3 = (head - d + 2) % m
        a, b = buf[j1], buf[j2]
        mid = (-buf[j0] + 9.0 * a + 9.0 * b - buf[j3]) / 16.0
        xi = buf[head]
        k1, g1, d1 = _dde_f(kind, xi, a, p)
        k2, g2, d2 = _dde_f(kind, xi + 0.5 * h * k1, mid, p)
        k3, g3, d3 = _dde_f(kind, xi + 0.5 * h * k2, mid, p)
        k4, g4, d4 = _dde_f(kind, xi + h * k3, b, p)
        new = xi + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        if tangent:
            ta, tbb = tb[j1], tb[j2]
            tm = (-tb[j0] + 9.0 * ta + 9.0 * tbb - tb[j3]) / 16.0
            tx = tb[head]
            e1 = g1 * tx + d1 * ta
            e2 = g2 * (tx + 0.5 * h * e1) + d2 * tm
            e3 = g3 * (tx + 0.5 * h * e2) + d3 * tm
            e4 = g4 * (tx + h * e3) + d4 * tbb
            tnew = tx + h / 6.0 * (e1 + 2.0 * e2 + 2.0 * e3 + e4)
        head = (head + 1) % m
        buf[head] = new
        if tangent:
            tb[head] = tnew
            if (i + 1) % renorm == 0:
                s = 0.0
                for k in range(m):
                    s += tb[k] * tb[k]
                s = math.sqrt(s)
                log_sum += math.log(s)
                for k in range(m):
                    tb[k] /= s
        if (i + 1) % every == 0:
            out[n_out] = new
            n_out += 1
    final = np.empty(m)
    for k in range(m):
        final[k] = buf[(head + 2 + k) % m]
    lam = log_sum / (n_steps * h) if tangent else 0.0
    return out[:n_out], final, lam


@dataclass(frozen=True)
class Delay:
    """x' = f(x(t), x(t - tau)) of ``kind`` with constants ``params``."""

    kind: int
    params: tuple
    tau: float
    x0: float = 1.2

    def _history(self, d, rng=None):
        x = np.full(d + 3, self.x0)
        if rng is not None:
            x = x + 1e-3 * rng.standard_normal(d + 3)
        return x

    def series(self, n, dt, transient=2000.0, steps_per_sample=None, seed=0):
        """``n`` samples every ``dt`` after ``transient`` time units (history ``x0`` plus a
        seeded perturbation)."""
        every = steps_per_sample or max(1, int(round(dt / 0.02)))
        h = dt / every
        d = int(round(self.tau / h))
        if abs(d * h - self.tau) > 1e-9 * self.tau:
            raise ValueError(f"dt = {dt} does not divide the delay {self.tau} in steps")
        rng = np.random.default_rng(seed)
        p = np.asarray(self.params, dtype=float)
        n_tr = int(round(transient / h))
        _, hist, _ = _dde_run(self.kind, p, d, h, self._history(d, rng), n_tr, n_tr, 1, False)
        out, _, _ = _dde_run(self.kind, p, d, h, hist, n * every, every, 1, False)
        return out[:n]

    def lyapunov(self, t_total, h, transient=2000.0, seed=0):
        """Largest exponent of the discretised equation (step ``h``), renormalised once a
        delay."""
        d = int(round(self.tau / h))
        p = np.asarray(self.params, dtype=float)
        rng = np.random.default_rng(seed)
        n_tr = int(round(transient / h))
        _, hist, _ = _dde_run(self.kind, p, d, h, self._history(d, rng), n_tr, n_tr, 1, False)
        _, _, lam = _dde_run(self.kind, p, d, h, hist, int(round(t_total / h)),
                             int(round(t_total / h)), d, True)  # fmt: skip
        return lam


# --- the catalogue ------------------------------------------------------------------------------


@dataclass
class System:
    """One system of the study. ``kind``: flow, delay, map or negative. ``make`` returns the
    ODESystem / DiscreteMap / Delay; ``published``: (lambda1, source) where one is known."""

    name: str
    kind: str
    make: object
    y0: tuple = ()
    transient: float = 200.0
    published: tuple | None = None
    note: str = ""
    params: dict = field(default_factory=dict)
    truth_time: float = 5000.0
    component: int = 0


def _flow(name, rhs, jac, p, dim, y0, **kw):
    period = kw.pop("period", None)
    return System(name, "flow", lambda: _ode(rhs, jac, p, dim, name, period), tuple(y0), **kw)


SPROTT = {"B": 1, "C": 2, "D": 3, "F": 5, "G": 6, "J": 9, "K": 10, "N": 13, "R": 17, "S": 18}
SPROTT_Y0 = {"B": (0.1, 0.1, 0.1), "C": (0.1, 0.1, 0.1), "D": (0.1, 0.1, 0.1),
             "F": (0.1, 0.1, 0.1), "G": (0.1, 0.1, 0.1), "J": (0.1, 0.1, 0.1),
             "K": (0.1, 0.1, 0.1), "N": (0.1, 0.1, 0.1), "R": (0.1, 0.1, 0.1),
             "S": (0.1, 0.1, 0.1)}  # fmt: skip

SPROTT_2003 = "Sprott, Chaos and Time-Series Analysis (2003), App. A"


def catalogue() -> dict[str, System]:
    """Every candidate system (name -> System); the study keeps the chaotic ones."""
    c: dict[str, System] = {}

    def add(s):
        c[s.name] = s

    add(System("lorenz", "flow", S.lorenz, (1.0, 1.0, 1.0), 50.0, (0.9056, SPROTT_2003),
               params=dict(sigma=10, rho=28, beta="8/3")))  # fmt: skip
    add(System("rossler", "flow", S.rossler, (1.0, 1.0, 1.0), 200.0, (0.0714, SPROTT_2003),
               params=dict(a=0.2, b=0.2, c=5.7)))  # fmt: skip
    add(System("rossler-hyper", "flow", S.rossler_hyper, (-10.0, -6.0, 0.0, 10.0), 200.0,
               (0.1120, SPROTT_2003), params=dict(a=0.25, b=3, c=0.5, d=0.05)))  # fmt: skip
    add(System("ueda", "flow", S.ueda, (2.5, 0.0), 200.0, (0.1034, SPROTT_2003),
               params=dict(k=0.05, B=7.5)))  # fmt: skip
    add(_flow("chen", _chen, _chen_jac, [35, 3, 28], 3, (-10.0, 0.0, 37.0), transient=50.0,
              params=dict(a=35, b=3, c=28)))  # fmt: skip
    add(_flow("lu", _lu, _lu_jac, [36, 3, 20], 3, (1.0, 1.0, 1.0), transient=50.0,
              params=dict(a=36, b=3, c=20)))  # fmt: skip
    add(_flow("chua", _chua, _chua_jac, [15.6, 28.0, -1.143, -0.714], 3, (0.7, 0.0, 0.0),
              transient=200.0, params=dict(alpha=15.6, beta=28, m0=-1.143, m1=-0.714)))  # fmt: skip
    add(_flow("thomas", _thomas, _thomas_jac, [0.18], 3, (0.1, 0.0, 0.0),
              transient=1000.0, truth_time=20000.0, params=dict(b=0.18)))  # fmt: skip
    add(_flow("halvorsen", _halvorsen, _halvorsen_jac, [1.27], 3, (-1.48, -1.51, 2.04),
              transient=100.0, params=dict(a=1.27)))  # fmt: skip
    for k, case in SPROTT.items():
        add(_flow(f"sprott-{k}", _sprott, _sprott_jac, [case], 3, SPROTT_Y0[k],
                  transient=500.0, truth_time=20000.0, params=dict(case=k)))  # fmt: skip
    add(_flow("genesio-tesi", _jerk, _jerk_jac, [0.0, 0.44, 1.1, 1.0], 3, (0.1, 0.1, 0.1),
              transient=500.0, truth_time=20000.0, params=dict(a=0.44, b=1.1, c=1)))  # fmt: skip
    add(_flow("moore-spiegel", _jerk, _jerk_jac, [1.0, 6.0, 20.0, 0.0], 3, (0.1, 0.0, 0.0),
              transient=500.0, params=dict(T=6, R=20)))  # fmt: skip
    add(_flow("rucklidge", _rucklidge, _rucklidge_jac, [2.0, 6.7], 3, (1.0, 0.0, 4.5),
              transient=500.0, params=dict(kappa=2, lam=6.7)))  # fmt: skip
    add(_flow("shimizu-morioka", _shimizu, _shimizu_jac, [0.75, 0.45], 3, (0.1, 0.0, 0.0),
              transient=500.0, truth_time=20000.0, params=dict(a=0.75, b=0.45)))  # fmt: skip
    add(_flow("burke-shaw", _burke_shaw, _burke_shaw_jac, [10.0, 4.272], 3, (0.6, 0.0, 0.0),
              transient=100.0, params=dict(s=10, v=4.272)))  # fmt: skip
    add(_flow("lorenz84", _lorenz84, _lorenz84_jac, [0.25, 4.0, 8.0, 1.0], 3, (1.0, 1.0, 1.0),
              transient=500.0, truth_time=20000.0, params=dict(a=0.25, b=4, F=8, G=1)))  # fmt: skip
    add(_flow("aizawa", _aizawa, _aizawa_jac, [0.95, 0.7, 0.6, 3.5, 0.25, 0.1], 3,
              (0.1, 0.0, 0.0), transient=500.0, truth_time=20000.0,
              params=dict(a=0.95, b=0.7, c=0.6, d=3.5, e=0.25, f=0.1)))  # fmt: skip
    add(_flow("vdp-forced", _vdp, _vdp_jac, [3.0, 5.0, 1.788], 2, (0.1, 0.0),
              period=2 * math.pi / 1.788, transient=500.0, truth_time=20000.0,
              params=dict(mu=3, A=5, omega=1.788)))  # fmt: skip
    for n in (5, 6, 8, 10, 20):
        add(System(f"lorenz96-{n}", "flow", lambda n=n: S.lorenz96(n, 8.0),
                   (8.01,) + (8.0,) * (n - 1), 200.0, params=dict(N=n, F=8)))  # fmt: skip
    # delay equations (Mackey-Glass: beta 0.2, gamma 0.1, n 10)
    for tau in (17.0, 23.0, 30.0):
        add(System(f"mackey-glass-{tau:.0f}", "delay", Delay(0, (0.2, 0.1, 10.0), tau), (),
                   2000.0, params=dict(beta=0.2, gamma=0.1, n=10, tau=tau)))  # fmt: skip
    add(System("ikeda-delay", "delay", Delay(1, (5.0, 0.0), 2.0, 0.5), (), 500.0,
               params=dict(mu=5, x0=0, tau=2)))  # fmt: skip
    add(System("blowflies", "delay", Delay(2, (1.0, 20.0), 10.0, 1.0), (), 2000.0,
               params=dict(delta=1, P=20, tau=10)))  # fmt: skip
    # maps
    add(System("logistic", "map", S.logistic_map, (0.3,), 1000, (math.log(2.0), "exact"),
               params=dict(r=4)))  # fmt: skip
    add(System("henon", "map", S.henon, (0.1, 0.1), 1000, (0.41922, SPROTT_2003),
               params=dict(a=1.4, b=0.3)))  # fmt: skip
    add(System("ikeda", "map", S.ikeda_map, (0.1, 0.1), 1000, (0.5076, SPROTT_2003),
               params=dict(u=0.9)))  # fmt: skip
    add(System("lozi", "map", S.lozi_map, (0.1, 0.1), 1000, (0.4702, SPROTT_2003),
               params=dict(a=1.7, b=0.5)))  # fmt: skip
    add(System("tinkerbell", "map", S.tinkerbell_map, (-0.72, -0.64), 1000,
               params=dict(a=0.9, b=-0.6013, c=2, d=0.5)))  # fmt: skip
    add(System("holmes", "map", lambda: _map(_holmes, _holmes_jac, [2.75, 0.2], 2, "holmes"),
               (0.1, 0.1), 1000, params=dict(a=2.75, b=0.2)))  # fmt: skip
    add(System("logistic-lattice", "map",
               lambda: _map(_logistic_lattice, _logistic_lattice_jac, [4.0, 0.1], 4,
                            "logistic-lattice"),
               (0.1, 0.3, 0.5, 0.7), 1000, params=dict(r=4, eps=0.1, sites=4)))  # fmt: skip
    add(System("coupled-henon", "map",
               lambda: _map(_coupled_henon, _coupled_henon_jac, [1.4, 0.3, 0.1], 4,
                            "coupled-henon"),
               (0.1, 0.1, 0.2, 0.1), 1000, params=dict(a=1.4, b=0.3, c=0.1)))  # fmt: skip
    return c


def check_jacobians(names=None, rng=None) -> float:
    """Largest relative difference between each flow's and map's Jacobian and central
    differences of its right-hand side at points near its start (must be ~1e-7)."""
    rng = rng or np.random.default_rng(0)
    worst = 0.0
    for s in catalogue().values():
        if s.kind not in ("flow", "map") or (names and s.name not in names):
            continue
        sys_ = s.make()
        f = sys_.rhs if s.kind == "flow" else sys_.step
        n = len(s.y0)
        for _ in range(3):
            y = np.asarray(s.y0, float) + 0.5 * rng.standard_normal(n)
            J = np.empty((n, n))
            sys_.jac(0.3, y, sys_.params, J)
            Jn = np.empty((n, n))
            for j in range(n):
                e = np.zeros(n)
                e[j] = 1e-6
                a, b = np.empty(n), np.empty(n)
                f(0.3, y + e, sys_.params, a)
                f(0.3, y - e, sys_.params, b)
                Jn[:, j] = (a - b) / 2e-6
            worst = max(worst, float(np.max(np.abs(J - Jn)) / max(1.0, np.max(np.abs(J)))))
    return worst
