r"""The contact-impact joints at the pins: their layout and compiled parts.

What every model with contact or lubricated pin joints shares (`compressor-contact`, with
the dynamic valves `compressor-contact-valves`, and the guide's clearance on the same
kernels): the packed parameter vector of the joints (the ``P_*`` constants, `N_PACKED`) and
their state (`STATE_NAMES`), the kinematics, the mechanism's accelerations given the joints'
and the gas force (`_accelerate`, from the generated ``_compressor_contact``), the same with
the guide's clearance and with the crank free, and the contact events and their resets. The
joints' forces (`recipdyn.model.assembler.templates.joints`: one module per contact law and
friction law) and the kernels of a configuration (`recipdyn.model.assembler.templates.contact`)
are written by the assembler; the laws themselves (normal force, friction, oil film) are
`recipdyn.model.joints.contact`.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .. import valves as va
from .._compressor_contact import (
    both_accelerations,
    both_guide_accelerations,
    crank_accelerations,
    crank_guide_accelerations,
    crosshead_accelerations,
    crosshead_guide_accelerations,
    ideal_guide_accelerations,
)
from .._compressor_contact_drive import (
    both_free_accelerations,
    both_guide_free_accelerations,
    crank_free_accelerations,
    crank_guide_free_accelerations,
    crosshead_free_accelerations,
    crosshead_guide_free_accelerations,
    ideal_guide_free_accelerations,
)
from .._compressor_contact_share import (
    crosshead_free_mass,
    crosshead_guide_free_mass,
    ideal_guide_free_mass,
)
from ..base import EVENT_SIGNATURE, RHS_SIGNATURE, compiled
from ..components.guide import CLEARANCE
from .contact import short_bearing_forces  # noqa: F401 (the joints' template reads it here)

#: Where the clearance is: the crank pin, the crosshead pin, or both (``clearance_joints``).
JOINTS = ("crank", "crosshead", "both")
#: Mechanism parameters of the generated kernels, in order, then their force inputs.
MECH = ("r", "l", "ls", "m2", "m3", "J2", "g", "d", "omega", "theta1_0")
INPUTS = ("F_gas", "F1_x", "F1_y", "F2_x", "F2_y", "T_rod")
NHEAD = len(MECH) + len(INPUTS)

# Packed parameter vector: the 16 symbols of the generated kernels first (the 6 INPUTS slots
# stay 0: the forces are passed per call, as the tuple ``u``).
(P_R, P_L, P_LS, P_M2, P_M3, P_J2, P_G, P_D, P_OMEGA, P_TH10,
 P_FGAS, P_F1X, P_F1Y, P_F2X, P_F2Y, P_TROD) = range(NHEAD)  # fmt: skip
# The oil viscosity of each pin (P_OIL crank pin, P_OIL2 crosshead pin) is 0 at a dry joint.
# The built-in friction laws read (mu, v0, v1) at P_MU (their ``friction(vt, p, o)`` role).
(P_C1, P_K1, P_RJ1, P_C2, P_K2, P_RJ2, P_CHI, P_MU, P_V0, P_V1, P_OIL, P_LB, P_EPSDRY, P_VMIN,
 P_OIL2) = range(NHEAD, NHEAD + 15)  # fmt: skip
#: The joints' part of the parameter vector; the load component's slice follows
#: (`recipdyn.model.components.contract.Assembly`).
N_PACKED = NHEAD + 15


#: The state, the same for every joint configuration (a rigid joint's components stay 0).
STATE_NAMES = ("ex", "ey", "ex_crosshead", "ey_crosshead", "ex_dot", "ey_dot",
               "ex_crosshead_dot", "ey_crosshead_dot", "v_impact", "v_impact_crosshead", "W_in",
               "W_loss")  # fmt: skip
STATE_UNITS = ("m",) * 4 + ("m/s",) * 6 + ("J", "J")
I_WIN, I_WLOSS = 10, 11
#: A rigid joint's states (eccentricity, rate, approach velocity): constant 0 (``ideal``: both
#: pins ideal, with the guide's clearance only).
RIGID = {"crank": (2, 3, 6, 7, 9), "crosshead": (0, 1, 4, 5, 8), "both": (),
         "ideal": tuple(range(10))}  # fmt: skip
#: The same by configuration code (0 crank, 1 crosshead, 2 both, 3 ideal), for the compiled
#: kernels.
_RIGID_MASK = np.array([[i in RIGID[j] for i in range(len(STATE_NAMES))]
                        for j in (*JOINTS, "ideal")])  # fmt: skip


#: The joint configurations with the guide's clearance: the three above, and both pins ideal.
GUIDE_JOINTS = (*JOINTS, "ideal")
#: The guide's force input of the generated kernels with the guide's clearance: the lateral
#: force on the crosshead at its pin (its friction along the guide adds to ``F_gas``).
GUIDE_INPUTS = ("F3_y",)


# The joints' forces (the contact law, the friction law, the oil film) are the module the
# assembler writes per choice of laws (`recipdyn.model.assembler.templates.joints`); the
# accelerations below are compiled once and called, not inlined, by every configuration's
# kernels (`recipdyn.model.assembler.templates.contact`): with numba's reference counting off,
# a call that passes arrays costs ~1 ns (docs/architecture.md, Composing compiled components).


@nb.njit(cache=True, inline="always")
def _abs(x):
    """``|x|`` by the sign of the real part (``abs`` of a complex number is its modulus, which
    would lose the complex step's derivative)."""
    return x if x.real >= 0.0 else -x


@nb.njit(cache=True, inline="always")
def _kinematics(t, p, e1x, e1y, u1, v1, e2x, e2y, u2, v2):
    """(sin theta2, cos theta2, theta2', crosshead velocity x3', sin theta1, cos theta1) from the
    eccentricities, the crank turning at the prescribed speed."""
    w = p[P_OMEGA]
    return _kinematics_at(p[P_TH10] + w * t, w, p, e1x, e1y, u1, v1, e2x, e2y, u2, v2)


@nb.njit(cache=True, inline="always")
def _kinematics_at(th1, w, p, e1x, e1y, u1, v1, e2x, e2y, u2, v2):
    """`_kinematics` at the crank angle ``th1`` and speed ``w`` (a free crank's states)."""
    r, l, d = p[P_R], p[P_L], p[P_D]
    s1, c1 = math.sin(th1), math.cos(th1)
    s2 = (e2y - d - r * s1 - e1y) / l
    c2 = np.sqrt(1.0 - s2 * s2)
    th2d = (v2 - r * w * c1 - v1) / (l * c2)
    v3 = -r * w * s1 + u1 - l * s2 * th2d - u2
    return s2, c2, th2d, v3, s1, c1


@nb.njit(cache=True)
def contact_shaking(th1, w, a1, y, yd, p, m1rs):
    """A contact throw's shaking force on the frame in its own axes, ``(F_x, F_y)`` in N:
    ``-(m1 a1 + m2 a2 + m3 a3)`` (`recipdyn.model.mechanism.shaking`), from the crank's angle
    ``th1``, speed ``w`` and acceleration ``a1``, the throw's states ``y`` (its slice) and
    their derivatives ``yd`` (the pins' eccentricities' accelerations ``yd[4:8]``), its
    parameters ``p`` and its crank's static moment ``m1rs`` (``m1 rs``). An ideal guide (the
    crosshead moves along the stroke only).

    The big end is the crank pin's centre moved by the crank pin's eccentricity, ``B = r
    e(theta1) + e1``; the rod's small end is ``(x3 + e2x, e2y - d)`` (``x3`` the crosshead
    pin's place along the stroke), so ``l sin theta2 = e2y - d - B_y`` differentiated twice
    gives ``theta2''`` (`_kinematics_at` the first derivative); a point ``lam`` along the rod
    from its big end accelerates by ``B'' + lam (e(theta2))''`` and the crosshead by the small
    end's x less ``e2x''``."""
    r, l, ls, m2, m3 = p[P_R], p[P_L], p[P_LS], p[P_M2], p[P_M3]
    s2, c2, th2d, _, s1, c1 = _kinematics_at(th1, w, p, y[0], y[1], y[4], y[5], y[2], y[3],
                                             y[6], y[7])  # fmt: skip
    bx = -r * (c1 * w * w + s1 * a1) + yd[4]
    by = r * (c1 * a1 - s1 * w * w) + yd[5]
    th2dd = ((yd[7] - by) / l + s2 * th2d * th2d) / c2
    rod_x = -(s2 * th2dd + c2 * th2d * th2d)  # e(theta2)'' per unit length
    rod_y = c2 * th2dd - s2 * th2d * th2d
    a3 = bx + l * rod_x - yd[6]
    fx = -(m1rs * (-c1 * w * w - s1 * a1) + m2 * (bx + ls * rod_x) + m3 * a3)
    fy = -(m1rs * (-s1 * w * w + c1 * a1) + m2 * (by + ls * rod_y))
    return fx, fy


#: The first gas state and the first mass counter of a load with states (the dynamic valves),
#: after the joints' twelve.
G_GAS = len(STATE_NAMES)
G_AUX = G_GAS + va.N_GAS


@nb.njit(cache=True)
def _ideal_crank_power(t, y, p, yd, f2):
    """Power of the crank through an ideal crank pin (the crosshead-pin-only configuration),
    from Newton's law for the rod, independent of the Lagrangian: the pin's reaction is
    F_A = m2 a_G - F2 + (0, m2 g) (F2 the crosshead joint's force on the rod, no torque from a
    frictionless pin), its power F_A . v_A."""
    r, l, ls, m2, g, w = p[P_R], p[P_L], p[P_LS], p[P_M2], p[P_G], p[P_OMEGA]
    th1 = p[P_TH10] + w * t
    s1, c1 = math.sin(th1), math.cos(th1)
    s2, c2, th2d, _, _, _ = _kinematics(t, p, 0.0, 0.0, 0.0, 0.0, y[2], y[3], y[6], y[7])
    s2dd = (yd[7] + r * w * w * s1) / l
    th2dd = (s2dd + s2 * th2d * th2d) / c2
    agx = -r * w * w * c1 + ls * (-s2 * th2dd - c2 * th2d * th2d)
    agy = -r * w * w * s1 + ls * (c2 * th2dd - s2 * th2d * th2d)
    fax = m2 * agx - f2[0]
    fay = m2 * agy - f2[1] + m2 * g
    return r * w * (-fax * s1 + fay * c1)


@nb.njit(cache=True)
def _accelerate(t, y, p, out, cfg, j, fg):
    """The mechanism's derivatives ``out[:12]`` (real or complex ``y``, ``out``; no arrays
    allocated) from the joints' forces ``j`` (`_joints`) and the gas force ``fg`` (the load
    component's, in the generated glue: `recipdyn.model.components.contact`); returns
    (crosshead velocity, cos theta2) for a load with states."""
    f1, f2, p_crank, p_loss, _, v3, c2, s1, c1 = j
    # the generated kernels' INPUTS, then sin and cos of the crank angle
    u = (fg, f1[0], f1[1], f2[0], f2[1], f1[2] + f2[2], s1, c1)
    for i in range(4):
        out[i] = y[4 + i]
    if cfg == 0:
        a = crank_accelerations(t, (y[0], y[1], y[4], y[5]), p, u)
        out[4], out[5], out[6], out[7] = a[0], a[1], 0.0, 0.0
    elif cfg == 1:
        a = crosshead_accelerations(t, (y[2], y[3], y[6], y[7]), p, u)
        out[4], out[5], out[6], out[7] = 0.0, 0.0, a[0], a[1]
    else:
        a4 = both_accelerations(t, (y[0], y[1], y[2], y[3], y[4], y[5], y[6], y[7]), p, u)
        out[4], out[5], out[6], out[7] = a4[0], a4[1], a4[2], a4[3]
    p_in = fg * v3 + p_crank
    if cfg == 1:
        p_in += _ideal_crank_power(t, y, p, out, f2)
    out[8] = 0.0
    out[9] = 0.0
    out[I_WIN] = p_in
    out[I_WLOSS] = p_loss
    return v3, c2


@nb.njit(cache=True)
def _accelerate_free(y, p, out, cfg, j, fg, m, tm, co):
    """`_accelerate` with the crank angle free (a motor drive): the derivatives of the
    joints' twelve states and of the crank's ``y[m:m + 3]`` (angle, speed, the motor's work)
    from the joints' forces ``j`` (`_joints_at` at ``y[m], y[m + 1]``), the gas force ``fg``
    and the motor torque ``tm``; ``co``: the offset of the crank's slice (its inertia about
    the main bearing and its static moment, `crank_slice`). The work of the gas and of the
    motor is ``W_in``; the motor's alone is ``y[m + 2]``. Returns (crosshead velocity,
    cos theta2)."""
    f1, f2, _, p_loss, _, v3, c2, s1, c1 = j
    w1 = y[m + 1]
    u = (fg, f1[0], f1[1], f2[0], f2[1], f1[2] + f2[2], tm + f1[3], p[co], p[co + 1], s1, c1)
    for i in range(4):
        out[i] = y[4 + i]
    if cfg == 0:
        a = crank_free_accelerations(0.0, (y[m], y[0], y[1], w1, y[4], y[5]), p, u)
        out[4], out[5], out[6], out[7] = a[1], a[2], 0.0, 0.0
        a0 = a[0]
    elif cfg == 1:
        a = crosshead_free_accelerations(0.0, (y[m], y[2], y[3], w1, y[6], y[7]), p, u)
        out[4], out[5], out[6], out[7] = 0.0, 0.0, a[1], a[2]
        a0 = a[0]
    else:
        a5 = both_free_accelerations(0.0, (y[m], y[0], y[1], y[2], y[3], w1, y[4], y[5], y[6],
                                           y[7]), p, u)  # fmt: skip
        out[4], out[5], out[6], out[7] = a5[1], a5[2], a5[3], a5[4]
        a0 = a5[0]
    out[8] = 0.0
    out[9] = 0.0
    out[I_WIN] = fg * v3 + tm * w1
    out[I_WLOSS] = p_loss
    out[m] = w1
    out[m + 1] = a0
    out[m + 2] = tm * w1
    return v3, c2


@nb.njit(cache=True)
def ideal_share(y, p, cfg, guide, m, gy):
    """With an ideal crank pin (``cfg`` 1: the crosshead pin worn; 3: both ideal, with the
    guide's clearance ``guide``) the rod turns with the crank: from the mass matrix of rod and
    crosshead (generated, `recipdyn.model._compressor_contact_share`) at the crank angle
    ``y[m]``, the throw's share of the crank's inertia, the Schur complement ``I = m00 - m_0r
    M_rr^-1 m_r0``, and ``k = M_rr^-1 m_r0``, by which its other accelerations (the crosshead
    pin's ``e2x'', e2y''``, the guide's ``yg''``; with both pins ideal ``yg''`` alone) fall
    per unit of the crank's: ``q_r'' = M_rr^-1 (b_r - m_r0 theta1'')``. Returns ``(I, k0, k1,
    k2)`` (unused ``k`` 0). No arrays allocated."""
    if cfg == 3:
        m00, m10, m11 = ideal_guide_free_mass((y[m], y[gy]), p)
        k0 = m10 / m11
        return m00 - m10 * k0, k0, 0.0, 0.0
    if not guide:
        m00, m10, m11, m20, m21, m22 = crosshead_free_mass((y[m], y[2], y[3]), p)
        det = m11 * m22 - m21 * m21
        k0 = (m22 * m10 - m21 * m20) / det
        k1 = (m11 * m20 - m21 * m10) / det
        return m00 - m10 * k0 - m20 * k1, k0, k1, 0.0
    m00, m10, m11, m20, m21, m22, m30, m31, m32, m33 = crosshead_guide_free_mass(
        (y[m], y[2], y[3], y[gy]), p
    )
    # the symmetric 3 x 3 M_rr by its cofactors (Cramer's rule)
    c11 = m22 * m33 - m32 * m32
    c12 = m32 * m31 - m21 * m33
    c13 = m21 * m32 - m22 * m31
    c22 = m11 * m33 - m31 * m31
    c23 = m21 * m31 - m11 * m32
    c33 = m11 * m22 - m21 * m21
    det = m11 * c11 + m21 * c12 + m31 * c13
    k0 = (c11 * m10 + c12 * m20 + c13 * m30) / det
    k1 = (c12 * m10 + c22 * m20 + c23 * m30) / det
    k2 = (c13 * m10 + c23 * m20 + c33 * m30) / det
    return m00 - m10 * k0 - m20 * k1 - m30 * k2, k0, k1, k2


# ---- the guide's clearance (`recipdyn.model.components.guide`): the crosshead pin's lateral
# position ``y[gy]``, the tilt ``y[gy + 1]``, their rates, the corners' phases ``y[gy + 4:]``


@nb.njit(cache=True)
def _guide_crank_power(t, y, p, yd, f2, cfg, gy, fgx, fgy):
    """Power of the crank through an ideal crank pin with the guide's clearance, from Newton's
    law for the rod (independent of the Lagrangian): the pin's reaction is
    ``F_A = m2 a_G - F_s + (0, m2 g)``, ``F_s`` the force on the rod at its small end: the
    crosshead joint's (``cfg`` 1), or, with both pins ideal (``cfg`` 3), what the crosshead's
    own Newton's law leaves, ``F_s = (F_gas + F_guide,x, F_guide,y - m3 g) - m3 a_3``
    (``fgx``: the gas force and the guide's friction along x; ``fgy`` the guide's lateral
    force)."""
    r, l, ls, m2, m3, g, w = p[P_R], p[P_L], p[P_LS], p[P_M2], p[P_M3], p[P_G], p[P_OMEGA]
    th1 = p[P_TH10] + w * t
    s1, c1 = math.sin(th1), math.cos(th1)
    s2, c2, th2d, _, _, _ = _kinematics(t, p, 0.0, 0.0, 0.0, 0.0, y[2], y[3] + y[gy], y[6],
                                        y[7] + y[gy + 2])  # fmt: skip
    s2dd = (yd[7] + yd[gy + 2] + r * w * w * s1) / l
    th2dd = (s2dd + s2 * th2d * th2d) / c2
    agx = -r * w * w * c1 + ls * (-s2 * th2dd - c2 * th2d * th2d)
    agy = -r * w * w * s1 + ls * (c2 * th2dd - s2 * th2d * th2d)
    if cfg == 1:
        fsx, fsy = f2[0], f2[1]
    else:
        a3x = -r * w * w * c1 - l * (c2 * th2d * th2d + s2 * th2dd)
        fsx = fgx - m3 * a3x
        fsy = fgy - m3 * g - m3 * yd[gy + 2]
    fax = m2 * agx - fsx
    fay = m2 * agy - fsy + m2 * g
    return r * w * (-fax * s1 + fay * c1)


@nb.njit(cache=True)
def _accelerate_guide(t, y, p, out, cfg, gy, j3, j, fg, gf):
    """`_accelerate` with the guide's clearance: the derivatives of the joints' twelve states
    and of the guide's eight (``y[gy:gy + 8]``) from the joints' forces ``j``
    (`_joints_guide`), the gas force ``fg`` and the guide's ``gf`` (`slice_forces`: the
    resultant on the crosshead at its pin, its moment about the pin, the power lost);
    ``j3`` the crosshead's tilt inertia. Returns (crosshead velocity, cos theta2)."""
    f1, f2, p_crank, p_loss, _, v3, c2, s1, c1 = j
    fx, fy, mz, lost, _ = gf
    fgx = fg + fx
    u = (fgx, f1[0], f1[1], f2[0], f2[1], f1[2] + f2[2], fy, s1, c1)
    for i in range(4):
        out[i] = y[4 + i]
        out[4 + i] = 0.0 * y[0]
    out[gy] = y[gy + 2]
    out[gy + 1] = y[gy + 3]
    if cfg == 0:
        a = crank_guide_accelerations(t, (y[0], y[1], y[gy], y[4], y[5], y[gy + 2]), p, u)
        out[4], out[5], out[gy + 2] = a[0], a[1], a[2]
    elif cfg == 1:
        a = crosshead_guide_accelerations(t, (y[2], y[3], y[gy], y[6], y[7], y[gy + 2]), p, u)
        out[6], out[7], out[gy + 2] = a[0], a[1], a[2]
    elif cfg == 2:
        a5 = both_guide_accelerations(t, (y[0], y[1], y[2], y[3], y[gy], y[4], y[5], y[6],
                                          y[7], y[gy + 2]), p, u)  # fmt: skip
        out[4], out[5], out[6], out[7], out[gy + 2] = a5[0], a5[1], a5[2], a5[3], a5[4]
    else:
        a1 = ideal_guide_accelerations(t, (y[gy], y[gy + 2]), p, u)
        out[gy + 2] = a1[0]
    # the tilt: the shoes' moment and the crosshead pin's friction torque on its journal
    out[gy + 3] = (mz + f2[3]) / j3
    for k in range(4):
        out[gy + 4 + k] = 0.0
    p_in = fg * v3 + p_crank
    if cfg == 1 or cfg == 3:
        p_in += _guide_crank_power(t, y, p, out, f2, cfg, gy, fgx, fy)
    out[8] = 0.0
    out[9] = 0.0
    out[I_WIN] = p_in
    out[I_WLOSS] = p_loss + lost
    return v3, c2


@nb.njit(cache=True)
def _accelerate_guide_free(y, p, out, cfg, gy, j3, j, fg, gf, m, tm, co):
    """`_accelerate_guide` with the crank angle free (a motor drive, as `_accelerate_free`):
    the derivatives of the joints' twelve states, the guide's eight (``y[gy:gy + 8]``) and
    the crank's ``y[m:m + 3]`` from the joints' forces ``j`` (`_joints_guide_at` at ``y[m],
    y[m + 1]``), the gas force ``fg``, the guide's ``gf`` (`slice_forces`), the motor torque
    ``tm``; ``j3`` the crosshead's tilt inertia, ``co`` the offset of the crank's slice. The
    work of the gas and of the motor is ``W_in``, the motor's alone ``y[m + 2]``; the joints'
    and the shoes' losses are ``W_loss``. Returns (crosshead velocity, cos theta2)."""
    f1, f2, _, p_loss, _, v3, c2, s1, c1 = j
    fx, fy, mz, lost, _ = gf
    w1 = y[m + 1]
    u = (fg + fx, f1[0], f1[1], f2[0], f2[1], f1[2] + f2[2], tm + f1[3], p[co], p[co + 1], fy,
         s1, c1)  # fmt: skip
    for i in range(4):
        out[i] = y[4 + i]
        out[4 + i] = 0.0 * y[0]
    out[gy] = y[gy + 2]
    out[gy + 1] = y[gy + 3]
    if cfg == 0:
        a = crank_guide_free_accelerations(0.0, (y[m], y[0], y[1], y[gy], w1, y[4], y[5],
                                                 y[gy + 2]), p, u)  # fmt: skip
        out[4], out[5], out[gy + 2] = a[1], a[2], a[3]
        a0 = a[0]
    elif cfg == 1:
        a = crosshead_guide_free_accelerations(0.0, (y[m], y[2], y[3], y[gy], w1, y[6], y[7],
                                                     y[gy + 2]), p, u)  # fmt: skip
        out[6], out[7], out[gy + 2] = a[1], a[2], a[3]
        a0 = a[0]
    elif cfg == 2:
        a5 = both_guide_free_accelerations(0.0, (y[m], y[0], y[1], y[2], y[3], y[gy], w1, y[4],
                                                 y[5], y[6], y[7], y[gy + 2]), p, u)  # fmt: skip
        out[4], out[5], out[6], out[7], out[gy + 2] = a5[1], a5[2], a5[3], a5[4], a5[5]
        a0 = a5[0]
    else:
        a1 = ideal_guide_free_accelerations(0.0, (y[m], y[gy], w1, y[gy + 2]), p, u)
        out[gy + 2] = a1[1]
        a0 = a1[0]
    # the tilt: the shoes' moment and the crosshead pin's friction torque on its journal
    out[gy + 3] = (mz + f2[3]) / j3
    for k in range(4):
        out[gy + 4 + k] = 0.0
    out[8] = 0.0
    out[9] = 0.0
    out[I_WIN] = fg * v3 + tm * w1
    out[I_WLOSS] = p_loss + lost
    out[m] = w1
    out[m + 1] = a0
    out[m + 2] = tm * w1
    return v3, c2


#: Imaginary step of the complex-step Jacobian: any size far below the states' works (the
#: derivative's error is O(h^2) relative, and no difference is taken).
CS_STEP = 1e-60
# (the complex step, Squire & Trapp 1998, SIAM Rev. 40, 110-112; Martins, Sturdza & Alonso
# 2003, ACM TOMS 29, 245-262: ``J[:, k] = Im f(y + i h e_k) / h``, exact to rounding since no
# difference is taken, on the branch of each switch (contact, clamp, friction law) that the
# real state takes; ``f`` is the real part of the same evaluations. The work integrals act on
# nothing (their columns are 0); with ``skip_rigid`` the columns of a rigid joint's states are
# left 0 too. Written into the glue, `recipdyn.model.components.contact`.)


@compiled(EVENT_SIGNATURE)
def onset_crank(t, y, p):
    return math.sqrt(y[0] * y[0] + y[1] * y[1]) - p[P_C1]


@compiled(EVENT_SIGNATURE)
def onset_crosshead(t, y, p):
    return math.sqrt(y[2] * y[2] + y[3] * y[3]) - p[P_C2]


#: In contact, a phased factor is ``delta/c + PHASE_MARGIN``: just after an onset it is already
#: on its positive side, so the event function leaves zero at once and a crossing of another
#: factor right after is seen. A separation is located at ``delta = -PHASE_MARGIN c`` (1 pm
#: at c = 1 mm), where the contact force is already 0.
PHASE_MARGIN = 1e-9


@nb.njit(cache=True, inline="always")
def phased_factor(y, i, k, c):
    """The contact factor of one joint for an event that tracks onsets *and* separations.

    The joint's phase is the sign of its recorded approach velocity ``y[k]``: positive in
    contact, negative in free flight (its magnitude is then the last impact's). The factor is
    ``-delta/c`` in flight and ``delta/c + PHASE_MARGIN`` in contact: positive in both, it falls
    through 0 at an onset and at a separation, and the reset (`_flip`) makes it positive
    again. So several joints and the valves share one event function, their minimum, and no two
    crossings can cancel (as they could in a product of signed factors)."""
    d = math.sqrt(y[i] * y[i] + y[i + 1] * y[i + 1]) / c - 1.0
    return d + PHASE_MARGIN if y[k] > 0.0 else -d


@nb.njit(cache=True)
def _record(y, ix, iy, iu, iv, k, p, out):
    rho = math.sqrt(y[ix] * y[ix] + y[iy] * y[iy])
    out[k] = max((y[ix] * y[iu] + y[iy] * y[iv]) / rho, p[P_VMIN])


@nb.njit(cache=True)
def _flip(y, j, p, out):
    """The reset of joint ``j`` (0 crank pin, 1 crosshead pin) at a zero of its phased factor:
    from free flight, an onset (the approach velocity is recorded, > 0); in contact, a
    separation (the recorded velocity turns negative: free flight)."""
    ix, iy, iu, iv, k = (0, 1, 4, 5, 8) if j == 0 else (2, 3, 6, 7, 9)
    if y[k] > 0.0:
        out[k] = -y[k]
    else:
        _record(y, ix, iy, iu, iv, k, p, out)


@nb.njit(cache=True)
def contact_factor(y, p, cfg):
    """The smallest phased factor of the worn joint(s) (``cfg`` 0 crank, 1 crosshead, 2 both)
    and the joint it belongs to."""
    f1 = phased_factor(y, 0, 8, p[P_C1]) if cfg != 1 else math.inf
    f2 = phased_factor(y, 2, 9, p[P_C2]) if cfg != 0 else math.inf
    return (f1, 0) if f1 <= f2 else (f2, 1)


@compiled(EVENT_SIGNATURE)
def onset_both(t, y, p):
    """Falls through 0 at an onset or a separation of either joint: the smaller of their
    phased factors ([`phased_factor`][recipdyn.model.joints.pins.phased_factor])."""
    return contact_factor(y, p, 2)[0]


@compiled(RHS_SIGNATURE)
def record_crank(t, y, p, out):
    for i in range(y.shape[0]):
        out[i] = y[i]
    _record(y, 0, 1, 4, 5, 8, p, out)


@compiled(RHS_SIGNATURE)
def record_crosshead(t, y, p, out):
    for i in range(y.shape[0]):
        out[i] = y[i]
    _record(y, 2, 3, 6, 7, 9, p, out)


@compiled(RHS_SIGNATURE)
def record_both(t, y, p, out):
    """At a zero of [`onset_both`][recipdyn.model.joints.pins.onset_both]: the joint whose
    factor it is changes phase (`_flip`: an onset records its approach velocity)."""
    for i in range(y.shape[0]):
        out[i] = y[i]
    _flip(y, contact_factor(y, p, 2)[1], p, out)


#: Joint configuration codes of the compiled kernels (literals in the generated glue).
CFG = {"crank": 0, "crosshead": 1, "both": 2, "ideal": 3}

#: The roles of a contact law from a user's file (`law_part`): required, then optional.
LAW_ROLES = ("normal", "elastic")
LAW_OPTIONAL = ("friction", "potential")


#: The guide's slice, with its clearance: after the joints' part, before the load's.
N_GUIDE = len(CLEARANCE.pack({"d": 0.0, "crosshead_half_length": 1.0,
                              "crosshead_half_height": 1.0, "guide_clearance": 0.0,
                              "guide_stiffness": 1.0, "guide_contact_law": "hertz",
                              "guide_restitution": 1.0, "guide_friction": 0.0,
                              "guide_v0": 1.0, "guide_v1": 2.0, "guide_friction_law": "tanh",
                              "v_impact_min": 1.0, "crosshead_tilt_inertia": 1.0}))  # fmt: skip
#: The guide's first state, with its clearance: after the joints' twelve (a load's follow).
G_GUIDE = len(STATE_NAMES)
N_GUIDE_STATES = len(CLEARANCE.states) + len(CLEARANCE.aux_states)
