"""Reference dynamical systems with exact Jacobians (for tests, benchmarks and examples).

Published Lyapunov exponents (Sprott, *Chaos and Time-Series Analysis*, 2003, Table A.1 and
the accompanying tables): Lorenz (10, 28, 8/3): 0.9056, 0, -14.5723; Rossler (0.2, 0.2, 5.7):
0.0714, 0, -5.3943; Henon (1.4, 0.3): 0.41922, -1.62319; Ueda x'' + 0.05 x' + x^3 = 7.5 cos t:
0.1034 (sum -0.05); Rossler hyperchaos (0.25, 3, 0.5, 0.05): 0.1120, 0.0190, 0, -25.1872;
Ikeda (0.9): 0.5076, -0.7183; Lozi
(1.7, 0.5): 0.4702, -1.1634; logistic (4): ln 2. The tests recompute each from the equations
(Benettin/QR) before any estimator is compared with it.
"""

from __future__ import annotations

import math

import numpy as np

from ..base import JAC_SIGNATURE, RHS_SIGNATURE, DiscreteMap, ODESystem, compiled

__all__ = [
    "lorenz",
    "rossler",
    "rossler_hyper",
    "lorenz96",
    "ueda",
    "linear",
    "henon",
    "standard_map",
    "logistic_map",
    "ikeda_map",
    "tinkerbell_map",
    "lozi_map",
]


@compiled(RHS_SIGNATURE)
def _lorenz(t, y, p, out):
    out[0] = p[0] * (y[1] - y[0])
    out[1] = y[0] * (p[1] - y[2]) - y[1]
    out[2] = y[0] * y[1] - p[2] * y[2]


@compiled(JAC_SIGNATURE)
def _lorenz_jac(t, y, p, J):
    J[0, 0], J[0, 1], J[0, 2] = -p[0], p[0], 0.0
    J[1, 0], J[1, 1], J[1, 2] = p[1] - y[2], -1.0, -y[0]
    J[2, 0], J[2, 1], J[2, 2] = y[1], y[0], -p[2]


def lorenz(sigma: float = 10.0, rho: float = 28.0, beta: float = 8.0 / 3.0) -> ODESystem:
    return ODESystem(rhs=_lorenz, jac=_lorenz_jac, params=np.array([sigma, rho, beta]),
                     state_names=("x", "y", "z"), name="lorenz")  # fmt: skip


@compiled(RHS_SIGNATURE)
def _rossler(t, y, p, out):
    out[0] = -y[1] - y[2]
    out[1] = y[0] + p[0] * y[1]
    out[2] = p[1] + y[2] * (y[0] - p[2])


@compiled(JAC_SIGNATURE)
def _rossler_jac(t, y, p, J):
    J[0, 0], J[0, 1], J[0, 2] = 0.0, -1.0, -1.0
    J[1, 0], J[1, 1], J[1, 2] = 1.0, p[0], 0.0
    J[2, 0], J[2, 1], J[2, 2] = y[2], 0.0, y[0] - p[2]


def rossler(a: float = 0.2, b: float = 0.2, c: float = 5.7) -> ODESystem:
    return ODESystem(rhs=_rossler, jac=_rossler_jac, params=np.array([a, b, c]),
                     state_names=("x", "y", "z"), name="rossler")  # fmt: skip


@compiled(RHS_SIGNATURE)
def _rossler_hyper(t, y, p, out):
    out[0] = -y[1] - y[2]
    out[1] = y[0] + p[0] * y[1] + y[3]
    out[2] = p[1] + y[0] * y[2]
    out[3] = -p[2] * y[2] + p[3] * y[3]


@compiled(JAC_SIGNATURE)
def _rossler_hyper_jac(t, y, p, J):
    J[:, :] = 0.0
    J[0, 1], J[0, 2] = -1.0, -1.0
    J[1, 0], J[1, 1], J[1, 3] = 1.0, p[0], 1.0
    J[2, 0], J[2, 2] = y[2], y[0]
    J[3, 2], J[3, 3] = -p[2], p[3]


def rossler_hyper(a: float = 0.25, b: float = 3.0, c: float = 0.5, d: float = 0.05) -> ODESystem:
    """Rossler's hyperchaotic flow (Rossler 1979, Phys. Lett. A 71, 155): four dimensions, two
    positive exponents. Start from (-10, -6, 0, 10)."""
    return ODESystem(rhs=_rossler_hyper, jac=_rossler_hyper_jac,
                     params=np.array([a, b, c, d]), state_names=("x", "y", "z", "w"),
                     name="rossler-hyper")  # fmt: skip


@compiled(RHS_SIGNATURE)
def _lorenz96(t, y, p, out):
    n = y.shape[0]
    for i in range(n):
        out[i] = (y[(i + 1) % n] - y[(i - 2) % n]) * y[(i - 1) % n] - y[i] + p[0]


@compiled(JAC_SIGNATURE)
def _lorenz96_jac(t, y, p, J):
    n = y.shape[0]
    J[:, :] = 0.0
    for i in range(n):
        J[i, (i + 1) % n] += y[(i - 1) % n]
        J[i, (i - 2) % n] -= y[(i - 1) % n]
        J[i, (i - 1) % n] += y[(i + 1) % n] - y[(i - 2) % n]
        J[i, i] -= 1.0


def lorenz96(n: int = 10, F: float = 8.0) -> ODESystem:
    """Lorenz (1996) ``x_i' = (x_{i+1} - x_{i-2}) x_{i-1} - x_i + F``, cyclic, ``n`` >= 4."""
    return ODESystem(rhs=_lorenz96, jac=_lorenz96_jac, params=np.array([F]),
                     state_names=tuple(f"x{i}" for i in range(n)), name="lorenz96")  # fmt: skip


@compiled(RHS_SIGNATURE)
def _ueda(t, y, p, out):
    out[0] = y[1]
    out[1] = -p[0] * y[1] - y[0] ** 3 + p[1] * math.cos(t)


@compiled(JAC_SIGNATURE)
def _ueda_jac(t, y, p, J):
    J[0, 0], J[0, 1] = 0.0, 1.0
    J[1, 0], J[1, 1] = -3.0 * y[0] ** 2, -p[0]


def ueda(k: float = 0.05, B: float = 7.5) -> ODESystem:
    """Ueda's oscillator ``x'' + k x' + x^3 = B cos t``: periodically forced, period 2 pi."""
    return ODESystem(rhs=_ueda, jac=_ueda_jac, params=np.array([k, B]), state_names=("x", "v"),
                     period=2 * math.pi, name="ueda")  # fmt: skip


@compiled(RHS_SIGNATURE)
def _linear(t, y, p, out):
    n = y.shape[0]
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += p[i * n + j] * y[j]
        out[i] = s


@compiled(JAC_SIGNATURE)
def _linear_jac(t, y, p, J):
    n = y.shape[0]
    for i in range(n):
        for j in range(n):
            J[i, j] = p[i * n + j]


def linear(A) -> ODESystem:
    """``y' = A y``: the Lyapunov exponents are the real parts of A's eigenvalues."""
    A = np.asarray(A, dtype=float)
    return ODESystem(rhs=_linear, jac=_linear_jac, params=A.ravel().copy(),
                     state_names=tuple(f"y{i}" for i in range(A.shape[0])),
                     name="linear")  # fmt: skip


@compiled(RHS_SIGNATURE)
def _henon(n, x, p, out):
    out[0] = 1.0 - p[0] * x[0] ** 2 + x[1]
    out[1] = p[1] * x[0]


@compiled(JAC_SIGNATURE)
def _henon_jac(n, x, p, J):
    J[0, 0], J[0, 1] = -2.0 * p[0] * x[0], 1.0
    J[1, 0], J[1, 1] = p[1], 0.0


def henon(a: float = 1.4, b: float = 0.3) -> DiscreteMap:
    return DiscreteMap(step=_henon, jac=_henon_jac, params=np.array([a, b]),
                       state_names=("x", "y"), name="henon")  # fmt: skip


@compiled(RHS_SIGNATURE)
def _standard(n, x, p, out):
    pn = x[1] + p[0] * math.sin(x[0])
    out[0] = (x[0] + pn) % (2.0 * math.pi)
    out[1] = pn


@compiled(JAC_SIGNATURE)
def _standard_jac(n, x, p, J):
    c = p[0] * math.cos(x[0])
    J[0, 0], J[0, 1] = 1.0 + c, 1.0
    J[1, 0], J[1, 1] = c, 1.0


def standard_map(K: float = 6.0) -> DiscreteMap:
    """Chirikov's standard map (area-preserving: its exponents are symmetric)."""
    return DiscreteMap(step=_standard, jac=_standard_jac, params=np.array([K]),
                       state_names=("theta", "p"), name="standard")  # fmt: skip


@compiled(RHS_SIGNATURE)
def _logistic(n, x, p, out):
    out[0] = p[0] * x[0] * (1.0 - x[0])


@compiled(JAC_SIGNATURE)
def _logistic_jac(n, x, p, J):
    J[0, 0] = p[0] * (1.0 - 2.0 * x[0])


def logistic_map(r: float = 4.0) -> DiscreteMap:
    return DiscreteMap(step=_logistic, jac=_logistic_jac, params=np.array([r]),
                       state_names=("x",), name="logistic")  # fmt: skip


@compiled(RHS_SIGNATURE)
def _ikeda(n, x, p, out):
    t = 0.4 - 6.0 / (1.0 + x[0] ** 2 + x[1] ** 2)
    c, s = math.cos(t), math.sin(t)
    out[0] = 1.0 + p[0] * (x[0] * c - x[1] * s)
    out[1] = p[0] * (x[0] * s + x[1] * c)


@compiled(JAC_SIGNATURE)
def _ikeda_jac(n, x, p, J):
    r2 = 1.0 + x[0] ** 2 + x[1] ** 2
    t = 0.4 - 6.0 / r2
    c, s = math.cos(t), math.sin(t)
    tx, ty = 12.0 * x[0] / r2**2, 12.0 * x[1] / r2**2  # dt/dx, dt/dy
    u, v = x[0] * c - x[1] * s, x[0] * s + x[1] * c  # d(u)/dt = -v, d(v)/dt = u
    J[0, 0], J[0, 1] = p[0] * (c - v * tx), p[0] * (-s - v * ty)
    J[1, 0], J[1, 1] = p[0] * (s + u * tx), p[0] * (c + u * ty)


def ikeda_map(u: float = 0.9) -> DiscreteMap:
    """Ikeda (1979) map of a ring laser cavity, in Hammel-Jones-Moloney form."""
    return DiscreteMap(step=_ikeda, jac=_ikeda_jac, params=np.array([u]),
                       state_names=("x", "y"), name="ikeda")  # fmt: skip


@compiled(RHS_SIGNATURE)
def _tinkerbell(n, x, p, out):
    out[0] = x[0] ** 2 - x[1] ** 2 + p[0] * x[0] + p[1] * x[1]
    out[1] = 2.0 * x[0] * x[1] + p[2] * x[0] + p[3] * x[1]


@compiled(JAC_SIGNATURE)
def _tinkerbell_jac(n, x, p, J):
    J[0, 0], J[0, 1] = 2.0 * x[0] + p[0], -2.0 * x[1] + p[1]
    J[1, 0], J[1, 1] = 2.0 * x[1] + p[2], 2.0 * x[0] + p[3]


def tinkerbell_map(a: float = 0.9, b: float = -0.6013, c: float = 2.0,
                   d: float = 0.5) -> DiscreteMap:  # fmt: skip
    """The Tinkerbell map (Nusse & Yorke 1994); start from (-0.72, -0.64)."""
    return DiscreteMap(step=_tinkerbell, jac=_tinkerbell_jac, params=np.array([a, b, c, d]),
                       state_names=("x", "y"), name="tinkerbell")  # fmt: skip


@compiled(RHS_SIGNATURE)
def _lozi(n, x, p, out):
    out[0] = 1.0 - p[0] * abs(x[0]) + x[1]
    out[1] = p[1] * x[0]


@compiled(JAC_SIGNATURE)
def _lozi_jac(n, x, p, J):
    J[0, 0], J[0, 1] = -p[0] * (1.0 if x[0] >= 0 else -1.0), 1.0
    J[1, 0], J[1, 1] = p[1], 0.0


def lozi_map(a: float = 1.7, b: float = 0.5) -> DiscreteMap:
    """Lozi (1978): the piecewise-linear Henon map."""
    return DiscreteMap(step=_lozi, jac=_lozi_jac, params=np.array([a, b]),
                       state_names=("x", "y"), name="lozi")  # fmt: skip


def iterate(dmap: DiscreteMap, x0, n: int, n_transient: int = 0) -> np.ndarray:
    """Orbit of a map: array of shape (n, dim) after ``n_transient`` discarded iterations."""
    x = np.asarray(x0, dtype=float).copy()
    out = np.empty((n, dmap.dim))
    buf = np.empty(dmap.dim)
    for i in range(n_transient + n):
        dmap.step(float(i), x, dmap.params, buf)
        x[:] = buf
        if i >= n_transient:
            out[i - n_transient] = x
    return out
