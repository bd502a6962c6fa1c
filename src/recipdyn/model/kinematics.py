r"""Exact kinematics of the slider-crank with a clearance link, and the joint forces.

Geometry (paper Fig. 3, Eq. 3-6): the crank A-B turns about A at the origin; the rod's big end
(journal) sits at ``B + r_c e(theta_c)`` where ``e(a) = (cos a, sin a)``; the crosshead C runs at
height ``y3 = -d``. The rod angle follows from the closure (Eq. 4, 6)::

    sin(theta2) = -(d + r sin(theta1) + r_c sin(theta_c)) / l,   cos(theta2) > 0,

and a point at distance ``lam`` from the journal along the rod is
``p = r e(theta1) + r_c e(theta_c) + lam e(theta2)`` (``lam = l_s``: rod centroid,
``lam = l``: crosshead). Its velocity and acceleration follow by the chain rule with the crank
angle prescribed (``theta1' = omega``, ``theta1'' = 0``)::

    p'  = p_1 omega + p_c theta_c'
    p'' = p_11 omega^2 + 2 p_1c omega theta_c' + p_cc theta_c'^2 + p_c theta_c''

with exact partials (``n(a) = (-sin a, cos a)``)::

    theta2_1  = -r cos(theta1) / (l cos(theta2))
    theta2_c  = -r_c cos(theta_c) / (l cos(theta2))
    theta2_11 = (r sin(theta1) + l sin(theta2) theta2_1^2) / (l cos(theta2))
    theta2_cc = (r_c sin(theta_c) + l sin(theta2) theta2_c^2) / (l cos(theta2))
    theta2_1c = tan(theta2) theta2_1 theta2_c
    p_1  = r n1 + lam theta2_1 n2,     p_c  = r_c nc + lam theta2_c n2
    p_11 = -r e1 + lam (theta2_11 n2 - theta2_1^2 e2)
    p_1c = lam (theta2_1c n2 - theta2_1 theta2_c e2)
    p_cc = -r_c ec + lam (theta2_cc n2 - theta2_c^2 e2)

These hand derivations are independent of the sympy code in `derivation`; the tests
compare the two. [`joint_forces`][recipdyn.model.kinematics.joint_forces] solves Newton-Euler for
the rod and the crosshead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .parameters import CompressorParams, ParameterError

__all__ = ["Kinematics", "kinematics", "ideal_mechanism", "ideal_slider_crank", "joint_forces",
           "JointForces"]  # fmt: skip


@dataclass(frozen=True)
class Kinematics:
    """Angles, their partials, and rod-centroid / crosshead motion over samples (SI units)."""

    theta1: np.ndarray
    theta2: np.ndarray
    theta2_dot: np.ndarray
    theta2_ddot: np.ndarray
    x2: np.ndarray
    y2: np.ndarray
    ax2: np.ndarray
    ay2: np.ndarray
    x3: np.ndarray
    v3: np.ndarray
    a3: np.ndarray


def _rod_angle(p: CompressorParams, th1, thc):
    s2 = -(p.d + p.r * np.sin(th1) + p.rc * np.sin(thc)) / p.l
    if np.any(np.abs(s2) >= 1.0):
        bad = float(np.max(np.abs(s2 * p.l)))
        raise ParameterError(
            f"geometry infeasible: |d + r sin(theta1) + rc sin(theta_c)| = {bad:g} m reaches "
            f"the rod length l = {p.l:g} m; reduce d or rc (need |d| < l - r - rc)"
        )
    return np.arcsin(s2), s2, np.sqrt(1.0 - s2 * s2)


def kinematics(p: CompressorParams, t, theta_c, thetadot_c, thetaddot_c, *, theta1=None,
               omega1=None, alpha1=None) -> Kinematics:  # fmt: skip
    """Exact positions, velocities and accelerations for a clearance-angle trajectory.

    Parameters
    ----------
    p : CompressorParams
    t : array_like
        Times, s; the crank angle is ``theta1_0 + omega t`` unless ``theta1`` is given.
    theta_c, thetadot_c, thetaddot_c : array_like
        Clearance angle (rad), its rate (rad/s) and acceleration (rad/s^2) at ``t``; the
        acceleration comes from the equation of motion (not finite differences).
    theta1, omega1, alpha1 : array_like, optional
        The crank's angle, speed and acceleration when the crank is free (a motor drive);
        then ``p' = p_1 omega1 + p_c theta_c'`` and ``p''`` gains ``p_1 alpha1``.
    """
    t = np.asarray(t, dtype=float)
    free = theta1 is not None
    w = np.asarray(omega1, dtype=float) if free else p.omega
    th1 = np.asarray(theta1, dtype=float) if free else p.theta1_0 + w * t
    thc, thcd, thcdd = (np.asarray(a, dtype=float) for a in (theta_c, thetadot_c, thetaddot_c))
    th2, s2, c2 = _rod_angle(p, th1, thc)
    s1, c1, sc, cc = np.sin(th1), np.cos(th1), np.sin(thc), np.cos(thc)
    t2 = s2 / c2
    q1 = -p.r * c1 / (p.l * c2)
    qc = -p.rc * cc / (p.l * c2)
    q11 = (p.r * s1 + p.l * s2 * q1**2) / (p.l * c2)
    qcc = (p.rc * sc + p.l * s2 * qc**2) / (p.l * c2)
    q1c = t2 * q1 * qc
    th2d = q1 * w + qc * thcd
    th2dd = q11 * w**2 + 2 * q1c * w * thcd + qcc * thcd**2 + qc * thcdd
    if alpha1 is not None:
        th2dd = th2dd + q1 * np.asarray(alpha1, dtype=float)

    def point(lam):
        # position, p_1, p_c, p_11, p_1c, p_cc as (x, y) pairs
        pos = (p.r * c1 + p.rc * cc + lam * c2, p.r * s1 + p.rc * sc + lam * s2)
        p1 = (-p.r * s1 - lam * q1 * s2, p.r * c1 + lam * q1 * c2)
        pc = (-p.rc * sc - lam * qc * s2, p.rc * cc + lam * qc * c2)
        p11 = (
            -p.r * c1 + lam * (-q11 * s2 - q1**2 * c2),
            -p.r * s1 + lam * (q11 * c2 - q1**2 * s2),
        )
        p1c = (lam * (-q1c * s2 - q1 * qc * c2), lam * (q1c * c2 - q1 * qc * s2))
        pcc = (
            -p.rc * cc + lam * (-qcc * s2 - qc**2 * c2),
            -p.rc * sc + lam * (qcc * c2 - qc**2 * s2),
        )
        vel = [a * w + b * thcd for a, b in zip(p1, pc, strict=True)]
        acc = [
            a * w**2 + 2 * b * w * thcd + c * thcd**2 + e * thcdd
            for a, b, c, e in zip(p11, p1c, pcc, pc, strict=True)
        ]
        if alpha1 is not None:
            acc = [x + a * np.asarray(alpha1, dtype=float) for x, a in zip(acc, p1, strict=True)]
        return pos, vel, acc

    (x2, y2), _, (ax2, ay2) = point(p.ls)
    (x3, _y3), (v3, _), (a3, _) = point(p.l)
    return Kinematics(th1, th2, th2d, th2dd, x2, y2, ax2, ay2, x3, v3, a3)


def ideal_mechanism(values, theta1, gas_force=0.0) -> dict[str, np.ndarray]:
    """The ideal (rigid-joint) offset slider-crank in closed form, the crank at constant
    ``omega``: the crosshead's motion, the rod's angular motion and the pin forces, from
    Newton-Euler for the crosshead and for the rod about the crank pin.

    ``values``: a mapping with ``r, l, ls, m2, m3, J2, g, d, omega`` (SI); ``theta1``: crank
    angles (rad); ``gas_force``: the force on the crosshead along x (N). With
    ``sin(theta2) = -(d + r sin(theta1)) / l``::

        theta2'  = -r omega cos(theta1) / (l cos(theta2))
        theta2'' = (r omega^2 sin(theta1) / l + sin(theta2) theta2'^2) / cos(theta2)
        x3 = r cos(theta1) + l cos(theta2),   x3'' = -r omega^2 cos(theta1)
             - l (cos(theta2) theta2'^2 + sin(theta2) theta2'')
        crosshead x:   m3 x3'' = F_gas - F_x
        rod about A:   (J2 + m2 ls^2) theta2'' = -m2 ls (c2 a_Ay - s2 a_Ax)
                       + l (c2 F_y - s2 F_x) - m2 g ls c2
        crosshead y:   0 = N - F_y - m3 g

    ``F_x, F_y`` are the force of the crosshead pin on the rod's end, ``N`` the side force the
    guide supplies (positive: the lower shoe pushes up).

    Returns a dict of arrays: ``x, v, a`` (crosshead, m, m/s, m/s^2), ``theta2, omega2,
    alpha2`` (rod), ``force_x, force_y`` (N), ``side_force`` (N).
    """
    keys = ("r", "l", "ls", "m2", "m3", "J2", "g", "d", "omega")
    r, l, ls, m2, m3, J2, g, d, w = (float(values[k]) for k in keys)
    th1 = np.asarray(theta1, dtype=float)
    s1, c1 = np.sin(th1), np.cos(th1)
    s2 = -(d + r * s1) / l
    c2 = np.sqrt(1 - s2**2)
    w2 = -r * w * c1 / (l * c2)
    a2 = (r * w**2 * s1 / l + s2 * w2**2) / c2
    x = r * c1 + l * c2
    v = -r * w * s1 - l * s2 * w2
    a = -r * w**2 * c1 - l * (c2 * w2**2 + s2 * a2)
    fx = gas_force - m3 * a
    aax, aay = -r * w**2 * c1, -r * w**2 * s1
    fy = ((J2 + m2 * ls**2) * a2 + m2 * ls * (c2 * aay - s2 * aax) + m2 * g * ls * c2
          + l * s2 * fx) / (l * c2)  # fmt: skip
    return {"x": x, "v": v, "a": a, "theta2": np.arcsin(s2), "omega2": w2, "alpha2": a2,
            "force_x": fx, "force_y": fy, "side_force": fy + m3 * g}  # fmt: skip


def ideal_slider_crank(p: CompressorParams, t):
    """Closed-form crosshead motion of the ideal (rc = 0) offset slider-crank at the times
    ``t``, ``theta1 = theta1_0 + omega t``
    ([`ideal_mechanism`][recipdyn.model.kinematics.ideal_mechanism]).

    Returns
    -------
    (x3, v3, a3) : tuple of ndarray, in m, m/s, m/s^2.
    """
    t = np.asarray(t, dtype=float)
    m = ideal_mechanism(vars(p), p.theta1_0 + p.omega * t)
    return m["x"], m["v"], m["a"]


@dataclass(frozen=True)
class JointForces:
    """Forces from Newton-Euler on the rod and the crosshead (N).

    ``Fx, Fy``: force of the crank pin on the rod through the clearance joint.
    ``contact``: its component pressing the journal onto the bearing, ``-F . e(theta_c)``;
    positive means the permanent-contact assumption of the massless-link model holds, negative
    means a real joint would separate there (the model then no longer applies).
    ``misalignment``: ``(F x e(theta_c)) / |F|``, zero up to rounding for the exact equation of
    motion (a massless link transmits force only along itself); a check, not a physical output.
    ``guide``: normal force of the guide on the crosshead (+y).
    """

    Fx: np.ndarray
    Fy: np.ndarray
    magnitude: np.ndarray
    direction: np.ndarray
    contact: np.ndarray
    misalignment: np.ndarray
    guide: np.ndarray


def joint_forces(p: CompressorParams, k: Kinematics, theta_c, gas_force_x) -> JointForces:
    """Solve Newton-Euler for the clearance-joint force and the crosshead guide force.

    Unknowns: the joint force F_B on the rod (2), the pin force F_C of the crosshead on the rod
    (its y part; the x part follows from the crosshead) and the guide force N::

        crosshead x:  m3 a3 = F_gas - F_Cx
        rod:          m2 a2 = F_B + F_C - m2 g ey
        rod moment:   J2 theta2'' = (-l_s e2) x F_B + (l - l_s) e2 x F_C
        crosshead y:  0 = N - m3 g - F_Cy
    """
    thc = np.asarray(theta_c, dtype=float)
    c2, s2 = np.cos(k.theta2), np.sin(k.theta2)
    fcx = gas_force_x - p.m3 * k.a3
    fbx = p.m2 * k.ax2 - fcx
    rhs = (
        p.J2 * k.theta2_ddot
        - p.ls * s2 * fbx
        - (p.l - p.ls) * c2 * p.m2 * (k.ay2 + p.g)
        + (p.l - p.ls) * s2 * fcx
    )
    fby = -rhs / (p.l * c2)
    fcy = p.m2 * (k.ay2 + p.g) - fby
    guide = p.m3 * p.g + fcy
    mag = np.hypot(fbx, fby)
    cc, sc = np.cos(thc), np.sin(thc)
    contact = -(fbx * cc + fby * sc)
    with np.errstate(invalid="ignore", divide="ignore"):
        mis = np.where(mag > 0, (fbx * sc - fby * cc) / mag, 0.0)
    return JointForces(fbx, fby, mag, np.arctan2(fby, fbx), contact, mis, guide)
