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
    "shaking",
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


@nb.njit(cache=True)
def shaking(th1, thc, w, thcd, a1, thcdd, p, m):
    """The throw's shaking force on the frame in its own axes, ``(F_x, F_y)`` in N: ``-(m1
    a1 + m2 a2 + m3 a3)`` (`recipdyn.model.mechanism.shaking`), from the crank's angle, speed
    ``w`` and acceleration ``a1`` and the clearance angle, rate and acceleration ``thcdd``.

    The rod angle from the closure ``sin theta2 = -(d + r sin theta1 + rc sin theta_c)/l``
    differentiated twice: ``cos theta2 theta2' = -(r cos theta1 w + rc cos theta_c
    theta_c')/l`` and ``cos theta2 theta2'' = sin theta2 theta2'^2 - (r (cos theta1 a1 - sin
    theta1 w^2) + rc (cos theta_c theta_c'' - sin theta_c theta_c'^2))/l``; a point at ``lam``
    along the rod from its big end, ``r e(theta1) + rc e(theta_c) + lam e(theta2)``,
    accelerates by the same terms (an implementation independent of
    `recipdyn.model.kinematics`, which the record's ``shake_x`` uses)."""
    r, rs, l, ls = p[m + _R], p[m + _RS], p[m + _L], p[m + _LS]
    m1, m2, m3, rc = p[m + _M1], p[m + _M2], p[m + _M3], p[m + _RC]
    c1, s1 = math.cos(th1), math.sin(th1)
    cc, sc = math.cos(thc), math.sin(thc)
    s2 = -(p[m + _D] + r * s1 + rc * sc) / l
    c2 = math.sqrt(1.0 - s2 * s2)
    w2 = -(r * c1 * w + rc * cc * thcd) / (l * c2)
    pin_x = -r * (c1 * w * w + s1 * a1) - rc * (cc * thcd * thcd + sc * thcdd)
    pin_y = r * (c1 * a1 - s1 * w * w) + rc * (cc * thcdd - sc * thcd * thcd)
    a2 = (s2 * w2 * w2 - pin_y / l) / c2
    rod_x = -(c2 * w2 * w2 + s2 * a2)  # e(theta2)'' per unit length
    rod_y = c2 * a2 - s2 * w2 * w2
    fx = -(m1 * rs * (-c1 * w * w - s1 * a1) + m2 * (pin_x + ls * rod_x) + m3 * (pin_x + l * rod_x))
    fy = -(m1 * rs * (-s1 * w * w + c1 * a1) + m2 * (pin_y + ls * rod_y))
    return fx, fy
