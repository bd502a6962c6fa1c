"""Compiled functions of the massless-link throw (`recipdyn.model.mechanism.link`), by role.

Each reads the throw's mechanism slice of the parameter vector at the offset ``m`` (``r, rs,
l, ls, m1, m2, m3, J1, J2, g, rc, d``: `link.MECHANISM`) and takes the throw's own crank angle
``th1`` (the shaft's plus the throw's phase) and speed ``w``. They are compiled once, called
(not inlined) by every assembled machine that holds the throw, and receive their offsets as
``int64`` values, so one compilation serves every configuration
(docs/architecture.md, Composing compiled components).
"""

import math

import numba as nb

from .._generated import clearance_acceleration, clearance_acceleration_jac
from ..paper_printed import paper_acceleration
from ._generated_throw import link_throw_ideal_system, link_throw_system

__all__ = [
    "acceleration",
    "acceleration_jac",
    "printed_acceleration",
    "printed_acceleration_jac",
    "crosshead",
    "free_contribution",
    "crank_torque",
]

# the mechanism slice, in order (link.MECHANISM)
_R, _RS, _L, _LS, _M1, _M2, _M3, _J1, _J2, _G, _RC, _D = range(12)


@nb.njit(cache=True)
def acceleration(th1, thc, thcd, F, w, p, m):
    """theta_c'' with the crank turning at ``w`` (theta1'' = 0): the exact equation
    (`recipdyn.model.derivation`); 0 for an ideal pin (rc = 0: the angle does not move)."""
    if p[m + _RC] == 0.0:
        return 0.0
    return clearance_acceleration(th1, thc, thcd, F, p[m + _R], p[m + _L], p[m + _LS],
                                  p[m + _M2], p[m + _M3], p[m + _J2], p[m + _G], p[m + _RC],
                                  p[m + _D], w)  # fmt: skip


@nb.njit(cache=True)
def acceleration_jac(th1, thc, thcd, F, w, p, m):
    """(theta_c'', d theta_c''/d theta_c, d theta_c''/d theta_c'): the exact partial
    derivatives of the same equation; zeros for an ideal pin."""
    if p[m + _RC] == 0.0:
        return 0.0, 0.0, 0.0
    return clearance_acceleration_jac(th1, thc, thcd, F, p[m + _R], p[m + _L], p[m + _LS],
                                      p[m + _M2], p[m + _M3], p[m + _J2], p[m + _G],
                                      p[m + _RC], p[m + _D], w)  # fmt: skip


@nb.njit(cache=True)
def printed_acceleration(th1, thc, thcd, F, w, p, m):
    """theta_c'' from the paper's printed Eq. (43)-(47) (`recipdyn.model.paper_printed`, a
    comparison variant); 0 for an ideal pin."""
    if p[m + _RC] == 0.0:
        return 0.0
    return paper_acceleration(th1, thc, thcd, F, p[m + _R], p[m + _L], p[m + _M2], p[m + _M3],
                              p[m + _J2], p[m + _RC], p[m + _D], w)  # fmt: skip


@nb.njit(cache=True)
def printed_acceleration_jac(th1, thc, thcd, F, w, p, m):
    """The printed equation and its partial derivatives by central differences (the printed
    coefficients have no derived Jacobian): steps 1e-6 rad and 1e-6 max(1, |theta_c'|)."""
    a = printed_acceleration(th1, thc, thcd, F, w, p, m)
    if p[m + _RC] == 0.0:
        return a, 0.0, 0.0
    h = 1e-6
    da = (printed_acceleration(th1, thc + h, thcd, F, w, p, m)
          - printed_acceleration(th1, thc - h, thcd, F, w, p, m)) / (2 * h)  # fmt: skip
    hd = 1e-6 * max(1.0, abs(thcd))
    dd = (printed_acceleration(th1, thc, thcd + hd, F, w, p, m)
          - printed_acceleration(th1, thc, thcd - hd, F, w, p, m)) / (2 * hd)  # fmt: skip
    return a, da, dd


@nb.njit(cache=True)
def crosshead(th1, thc, w, thcd, p, m):
    """``(x3, x3')`` of the crosshead, m and m/s, from the crank and clearance angles and
    rates (the closure ``sin theta2 = -(d + r sin theta1 + rc sin theta_c)/l``, ``cos theta2 >
    0``; `recipdyn.model.kinematics`)."""
    r, l, rc = p[m + _R], p[m + _L], p[m + _RC]
    s2 = -(p[m + _D] + r * math.sin(th1) + rc * math.sin(thc)) / l
    c2 = math.sqrt(1.0 - s2 * s2)
    th2d = -(r * w * math.cos(th1) + rc * thcd * math.cos(thc)) / (l * c2)
    x = r * math.cos(th1) + rc * math.cos(thc) + l * c2
    v = -r * w * math.sin(th1) - rc * thcd * math.sin(thc) - l * s2 * th2d
    return x, v


@nb.njit(cache=True)
def free_contribution(th1, thc, w, thcd, F, p, m):
    """The throw's part of a free crank's equation: ``(I, Q, k, c)`` such that the crank's
    acceleration is ``alpha1 = (T_m + sum Q) / (J_drive + sum I)`` over the throws and this
    throw's clearance angle then accelerates at ``theta_c'' = c - k alpha1``.

    From the throw's ``M (theta1'', theta_c'') = b`` (`_generated_throw`, without the
    drive's inertia and torque): the theta_c row gives ``theta_c'' = (b1 - m10 alpha1) /
    m11``, which put in the theta1 row leaves ``(m00 - m10**2 / m11) alpha1 = b0 - m10 b1 /
    m11`` for this throw's share. An ideal pin (rc = 0) has theta1 alone: ``(m00, b0, 0, 0)``.
    """
    u = (F,)
    if p[m + _RC] == 0.0:
        m00, b0 = link_throw_ideal_system((th1, w), p, m, u)
        return m00, b0, 0.0, 0.0
    m00, m10, m11, b0, b1 = link_throw_system((th1, thc, w, thcd), p, m, u)
    k = m10 / m11
    c = b1 / m11
    return m00 - k * m10, b0 - k * b1, k, c


@nb.njit(cache=True)
def crank_torque(th1, thc, w, thcd, thcdd, a1, F, p, m):
    """The torque the shaft applies to this throw's crank, N m: the theta1 row of the throw's
    ``M qdd = b`` (`_generated_throw`) at the crank's acceleration ``a1`` (0 with a
    prescribed speed) and the clearance angle's ``thcdd``. Over the throws of a machine
    driven by a motor their sum is ``T_m - J_drive a1``; with ``F v3`` it closes each throw's
    own energy balance, ``dE/dt = torque w + F v3``."""
    u = (F,)
    if p[m + _RC] == 0.0:
        m00, b0 = link_throw_ideal_system((th1, w), p, m, u)
        return m00 * a1 - b0
    m00, m10, m11, b0, b1 = link_throw_system((th1, thc, w, thcd), p, m, u)
    return m00 * a1 + m10 * thcdd - b0
