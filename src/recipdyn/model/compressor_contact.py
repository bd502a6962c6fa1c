r"""The compressor with a contact-impact clearance joint at the crank pin (2 relative DOF).

The paper's mechanism (crank ``r`` driven at ``omega``, rod ``l`` with centroid at ``ls``,
crosshead on the guide ``y = -d``, the same load) with the massless link replaced by the joint
model the multibody literature uses (Flores, Ambrósio, Claro & Lankarani 2008): the bearing
centre (the rod's big end) is ``B = A + e``, ``A = r (cos theta1, sin theta1)`` the journal
(crank-pin) centre and ``e = (ex, ey)`` free; the rod angle follows from the guide,
``sin theta2 = -(d + r sin theta1 + ey) / l``, and the crosshead from ``x3 = Bx + l cos theta2``.
The journal and bearing interact only through the joint forces of `joints.contact`:
dry contact when the penetration ``delta = |e| - rc`` is positive (the same ``rc`` as the
massless link's length: the radial clearance), with friction, or the oil film of the
lubricated joint. Cartesian ``e`` keeps the equations regular at ``e = 0``.

Equations of motion: Lagrange's equations for ``q = (ex, ey)`` with the crank angle prescribed,
derived by `derive` (no small-clearance approximation) into ``_compressor_contact.py``;
the joint force on the bearing ``(Fx, Fy)``, its torque on the rod about ``B`` and the gas force
on the crosshead enter as generalized forces ``Q_k = F . dB/dq_k + T dtheta2/dq_k +
F_gas dx3/dq_k``, computed in the compiled right-hand side.

State: ``(ex, ey, ex', ey', v_impact, W_in, W_loss)``. The last three are auxiliary (no
degrees of freedom; ``ODESystem.aux_states``): the approach velocity of the current impact
(set by the contact-onset event, used by the damping laws; where the event also tracks
separations, with both pins worn or with the valves, its sign is the joint's phase, negative in
free flight: [`phased_factor`][recipdyn.model.compressor_contact.phased_factor]), and two work
integrals for the energy balance, ``E + U = E0 + U0 + W_in - W_loss`` (``E`` kinetic + gravity
energy of rod and crosshead, ``U = K delta^2.5 / 2.5`` the contact's elastic energy, ``W_in`` the
work of the gas force and of the crank through the journal, ``W_loss`` the work lost in the joint:
contact damping, friction and the oil film's share).

With ``guide = clearance`` the crosshead is a body of its own between the guide's shoes
(`recipdyn.model.components.guide`): its pin's lateral position and its tilt are degrees of
freedom (eight states after the twelve above: position, tilt, their rates, the four corners'
approach velocities), the rod's small end follows it, and both pins may then be ideal.

With ``drive = motor`` the crank angle is a coordinate too (`free_crank_lagrangian`, generated
into ``_compressor_contact_drive.py``): the crank's states ``(theta1, omega1, W_motor)`` come
after every other state, the joints' forces are evaluated at the crank's angle and speed
(`_joints_at`), the crank carries ``J1 + m1 rs^2 + J_drive`` and the motor's torque and the
crank-pin joint's friction torque act on it; ``W_in`` is then the work of the gas and the
motor. Its Jacobian is a central difference (the crank angle enters through ``math.sin``),
and Benettin's method is refused (the saltation matrices with the crank free are not
checked).

The Jacobian is the complex step of the right-hand side (``cs_jac`` of the generated glue,
`recipdyn.model.components.contact`): the compiled kernels take complex states, and
``J[:, k] = Im f(y + i h e_k) / h`` is exact to rounding (no difference is taken), on the
branch of each switch the state is on. A central difference's rounding noise (~1e-4 of the
contact stiffness terms) would keep Benettin's tangent integration at ~10^6 steps a
revolution; Lyapunov exponents are computed from the equations, with the contact onsets'
saltation matrices (tests/test_contact.py checks the
tangent flow against differences of the flow across impacts).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path
from typing import Any

import numba as nb
import numpy as np

from . import valves as va
from ._compressor_contact import (
    both_accelerations,
    both_guide_accelerations,
    crank_accelerations,
    crank_guide_accelerations,
    crosshead_accelerations,
    crosshead_guide_accelerations,
    ideal_guide_accelerations,
)
from ._compressor_contact_drive import (
    both_free_accelerations,
    crank_free_accelerations,
    crosshead_free_accelerations,
)
from .base import (
    EVENT_SIGNATURE,
    RHS_SIGNATURE,
    Event,
    ODESystem,
    Signal,
    compiled,
)
from .components.guide import CLEARANCE, GUIDE_PARAMS, GUIDES
from .components.load import cycle_outputs, cycle_summary
from .joints.contact import (
    FRICTION_LAWS,
    LAWS,
    friction_factor,
    hertz_stiffness,
    hysteresis_factor,
    normal_force,
    short_bearing_forces,
)
from .load import CYCLE_PARAMS
from .parameters import SCHEMA as LINK_SCHEMA
from .protocol import Model, Param, Schema

__all__ = ["CompressorContact", "COMPRESSOR_CONTACT", "lagrangian", "generate", "energy",
           "overlap_half_angle"]  # fmt: skip

_INF = math.inf
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
(P_C1, P_K1, P_RJ1, P_C2, P_K2, P_RJ2, P_CHI, P_MU, P_V0, P_V1, P_FLAW, P_OIL, P_LB, P_EPSDRY,
 P_VMIN, P_OIL2) = range(NHEAD, NHEAD + 16)  # fmt: skip
#: The joints' part of the parameter vector; the load component's slice follows
#: (`recipdyn.model.components.contract.Assembly`).
N_PACKED = NHEAD + 16


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


@lru_cache(maxsize=8)
def lagrangian(joints: str = "crank", guide: bool = False):
    """The derived [`Lagrangian`][recipdyn.model.derive.Lagrangian] of the mechanism with clearance
    at ``joints`` (module docstring); with ``guide``, the crosshead pin's lateral position
    ``yg`` from the guide's centreline is one more coordinate (the guide with clearance,
    `recipdyn.model.components.guide`; ``joints`` may then be ``ideal``: both pins ideal). The
    crosshead's tilt about its pin is not in it: with the crosshead's centre of mass at the pin
    its kinetic energy ``J3 phi'^2 / 2`` couples with nothing, so ``phi'' = M / J3`` (the
    moment of the shoes and of the crosshead pin's friction about the pin), written in the
    glue."""
    import sympy as sp

    from .derive import derive

    t = sp.Symbol("t", real=True)
    e = dict(zip(("e1x", "e1y", "e2x", "e2y"), sp.symbols("e1x e1y e2x e2y", real=True),
                 strict=True))  # fmt: skip
    names = {"crank": ("e1x", "e1y"), "crosshead": ("e2x", "e2y"),
             "both": ("e1x", "e1y", "e2x", "e2y"), "ideal": ()}[joints]  # fmt: skip
    q = tuple(e[k] for k in names)
    qd = tuple(sp.Symbol(f"{k}_dot", real=True) for k in names)
    e = {k: (v if k in names else sp.S.Zero) for k, v in e.items()}
    yg = sp.S.Zero
    if guide:
        yg = sp.Symbol("yg", real=True)
        q, qd = (*q, yg), (*qd, sp.Symbol("yg_dot", real=True))
    r, l, ls, m2, m3, J2, g, d, w, th10 = sp.symbols(" ".join(MECH), real=True)
    Fg, F1x, F1y, F2x, F2y, Tr = sp.symbols(" ".join(INPUTS), real=True)
    F3y = sp.Symbol(GUIDE_INPUTS[0], real=True)
    th1 = th10 + w * t
    Bx, By = r * sp.cos(th1) + e["e1x"], r * sp.sin(th1) + e["e1y"]  # big end (bearing 1)
    th2 = sp.asin((yg + e["e2y"] - d - By) / l)  # small end at y = -d + yg + e2y
    x3 = Bx + l * sp.cos(th2) - e["e2x"]  # crosshead pin (journal 2) = small end - e2
    xg, yg_rod = Bx + ls * sp.cos(th2), By + ls * sp.sin(th2)

    def dt(x):  # total time derivative along q' = qd
        return sp.diff(x, t) + sum(sp.diff(x, a) * b for a, b in zip(q, qd, strict=True))

    T = (m2 * (dt(xg) ** 2 + dt(yg_rod) ** 2) + J2 * dt(th2) ** 2 + m3 * dt(x3) ** 2) / 2
    V = m2 * g * yg_rod
    if guide:  # the crosshead's lateral motion, and its weight
        T = T + m3 * dt(yg) ** 2 / 2
        V = V + m3 * g * yg
    # virtual work: F1 on the big end, F2 on the small end and -F2 on the crosshead pin
    # (together F2 . d e2), the joints' torque on the rod, the gas force (with the guide's
    # friction) on the crosshead along x, the guide's lateral force on it
    Q = [F1x * sp.diff(Bx, k) + F1y * sp.diff(By, k) + F2x * sp.diff(e["e2x"], k)
         + F2y * sp.diff(e["e2y"], k) + Tr * sp.diff(th2, k) + Fg * sp.diff(x3, k)
         + F3y * sp.diff(yg, k) for k in q]  # fmt: skip
    params = (r, l, ls, m2, m3, J2, g, d, w, th10, Fg, F1x, F1y, F2x, F2y, Tr)
    return derive(T, V, q, qd, t, (*params, F3y) if guide else params, Q=Q)


def generate() -> str:
    import sympy as sp

    from .derive import accelerations_source

    head = ['"""Generated by recipdyn.model.derive -- do not edit by hand.', "",
            "Mechanism of the compressor with contact-impact clearance joints "
            "(recipdyn.model.compressor_contact):", "the accelerations qdd of M qdd = b for "
            "clearance at the crank pin, the crosshead pin, or both;", "with the guide's "
            "clearance (``*_guide``), the crosshead's lateral position is the last coordinate.",
            '"""', "", "import numba as nb", "import numpy as np", "", ""]  # fmt: skip
    # numpy's scalar functions instead of math's: the same machine code for real arguments,
    # and the kernels also take complex ones (the complex-step Jacobian, the glue's ``cs_jac``)
    # sin and cos of the crank angle come from the caller (computed once per call)
    bodies = []
    for guide in (False, True):
        for j in GUIDE_JOINTS if guide else JOINTS:
            lag = lagrangian(j, guide)
            th1 = lag.params[MECH.index("theta1_0")] + lag.params[MECH.index("omega")] * lag.t
            n_in = len(INPUTS) + (len(GUIDE_INPUTS) if guide else 0)
            name = f"{j}_guide" if guide else j
            src = accelerations_source(lag, name, n_in, given=(sp.sin(th1), sp.cos(th1)))
            bodies.append(src.replace("math.", "np."))
    return "\n".join(head) + "\n\n".join(bodies)


def _target() -> Path:
    return Path(__file__).with_name("_compressor_contact.py")


#: The inputs the free-crank kernels take besides `INPUTS`: the torque on the crank (the
#: motor's and the crank-pin joint's friction torque on the journal), the crank's inertia
#: about the main bearing (``J1 + m1 rs^2 + J_drive``) and its static moment ``m1 rs``.
CRANK_INPUTS = ("T_crank", "I_crank", "S_crank")


@lru_cache(maxsize=4)
def free_crank_lagrangian(joints: str = "crank"):
    """The derived [`Lagrangian`][recipdyn.model.derive.Lagrangian] of the mechanism with
    clearance at ``joints`` and the crank angle free (a motor drive): coordinates
    ``(theta1, e...)``. The crank adds ``I_crank theta1'^2 / 2`` and ``g S_crank sin
    theta1``; the torque ``T_crank`` acts on it. The joints' forces do virtual work on the
    eccentricities only (``F1 . d e1``: the force on the bearing and its reaction on the
    journal, whose position ``A(theta1)`` moves with the crank), the crank-pin joint's
    friction torque on the journal is in ``T_crank``, the gas force does ``F_gas dx3``. With
    ``theta1 = theta1_0 + omega t`` the eccentricities' rows are `lagrangian`'s (the tests
    check it)."""
    import sympy as sp

    from .derive import derive

    t = sp.Symbol("t", real=True)
    e = dict(zip(("e1x", "e1y", "e2x", "e2y"), sp.symbols("e1x e1y e2x e2y", real=True),
                 strict=True))  # fmt: skip
    names = {"crank": ("e1x", "e1y"), "crosshead": ("e2x", "e2y"),
             "both": ("e1x", "e1y", "e2x", "e2y")}[joints]  # fmt: skip
    th1, th1d = sp.symbols("theta1 theta1_dot", real=True)
    q = (th1, *(e[k] for k in names))
    qd = (th1d, *(sp.Symbol(f"{k}_dot", real=True) for k in names))
    e = {k: (v if k in names else sp.S.Zero) for k, v in e.items()}
    r, l, ls, m2, m3, J2, g, d, w, th10 = sp.symbols(" ".join(MECH), real=True)
    Fg, F1x, F1y, F2x, F2y, Tr = sp.symbols(" ".join(INPUTS), real=True)
    Tc, Ic, Sc = sp.symbols(" ".join(CRANK_INPUTS), real=True)
    Bx, By = r * sp.cos(th1) + e["e1x"], r * sp.sin(th1) + e["e1y"]
    th2 = sp.asin((e["e2y"] - d - By) / l)
    x3 = Bx + l * sp.cos(th2) - e["e2x"]
    xg, yg_rod = Bx + ls * sp.cos(th2), By + ls * sp.sin(th2)

    def dt(x):
        return sum(sp.diff(x, a) * b for a, b in zip(q, qd, strict=True))

    T = (m2 * (dt(xg) ** 2 + dt(yg_rod) ** 2) + J2 * dt(th2) ** 2 + m3 * dt(x3) ** 2
         + Ic * th1d**2) / 2  # fmt: skip
    V = m2 * g * yg_rod + g * Sc * sp.sin(th1)
    Q = [F1x * sp.diff(e["e1x"], k) + F1y * sp.diff(e["e1y"], k) + F2x * sp.diff(e["e2x"], k)
         + F2y * sp.diff(e["e2y"], k) + Tr * sp.diff(th2, k) + Fg * sp.diff(x3, k)
         + Tc * sp.diff(th1, k) for k in q]  # fmt: skip
    params = (r, l, ls, m2, m3, J2, g, d, w, th10, Fg, F1x, F1y, F2x, F2y, Tr, Tc, Ic, Sc)
    return derive(T, V, q, qd, t, params, Q=Q)


def generate_drive() -> str:
    """Source of ``_compressor_contact_drive.py``: the free-crank accelerations of the contact
    joints (`free_crank_lagrangian`) for clearance at the crank pin, the crosshead pin, or
    both."""
    import sympy as sp

    from .derive import accelerations_source

    head = ['"""Generated by ``python -m recipdyn.model.compressor_contact`` -- do not edit by '
            "hand.", "", "Mechanism of the compressor with contact-impact clearance joints and "
            "the crank angle free", "(a motor drive; recipdyn.model.compressor_contact."
            "free_crank_lagrangian): the accelerations", "qdd of M qdd = b, q = (theta1, e...), "
            "for clearance at the crank pin, the crosshead pin,", "or both.", '"""', "",
            "import numba as nb", "import numpy as np", "", ""]  # fmt: skip
    bodies = []
    n_in = len(INPUTS) + len(CRANK_INPUTS)
    for j in JOINTS:
        lag = free_crank_lagrangian(j)
        th1 = lag.q[0]
        src = accelerations_source(lag, f"{j}_free", n_in, given=(sp.sin(th1), sp.cos(th1)))
        bodies.append(src.replace("math.", "np."))
    return "\n".join(head) + "\n\n".join(bodies)


def _drive_target() -> Path:
    return Path(__file__).with_name("_compressor_contact_drive.py")


# The right-hand side's helpers below, down to _rhs, are inlined into the compiled rhs: a call
# between numba functions that pass arrays costs ~30 ns, as much as a quarter of the whole
# evaluation here (189 -> 126 ns per call, 12-state crank-pin case; the same arithmetic, so
# bit-identical results). Cost: ~3 s more compilation on first use, once per machine (cached).


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


@nb.njit(cache=True, inline="always")
def _pair(ex, ey, u, v, w_j, w_b, c, K, Rj, v_imp, oil, p):
    """Forces of one clearance joint, e = (ex, ey) from the journal centre to the bearing
    centre, journal and bearing turning at w_j and w_b: the tuple (F_x, F_y (on the bearing),
    T_b (on the bearing, about its centre), T_j (on the journal), F_n, F_t, power lost)."""
    z = 0.0 * ex  # zero of the state's type (real, or complex for the complex step)
    fx, fy, tb, tj, fnn, ftt, lost = z, z, z, z, z, z, z
    rho = np.sqrt(ex * ex + ey * ey)
    if rho.real == 0.0:
        return fx, fy, tb, tj, fnn, ftt, lost
    delta = rho - c
    nx, ny = ex / rho, ey / rho
    tx, ty = -ny, nx
    drho = nx * u + ny * v  # = delta'
    et = tx * u + ty * v
    Rb = Rj + c
    if delta.real > 0.0:
        vi = v_imp if v_imp.real > p[P_VMIN] else p[P_VMIN]  # (the floor: grazing contacts)
        fn = normal_force(delta, drho, vi, K, p[P_CHI])
        vt = et + w_j * Rj - w_b * Rb  # sliding velocity, bearing relative to journal
        ft = fn * friction_factor(vt, p[P_MU], p[P_V0], p[P_V1], int(p[P_FLAW]))
        fx = -fn * nx + ft * tx
        fy = -fn * ny + ft * ty
        tb = -Rb * ft
        tj = Rj * ft
        fnn = fn
        ftt = ft
        lost = (fn - K * delta * np.sqrt(delta)) * drho - ft * vt
    if oil > 0.0:
        # film forces on the journal, along its eccentricity -n and t_j = k x (-n) = -t
        fr, fth = short_bearing_forces(rho / c, drho / c, et / rho, w_j + w_b, oil, p[P_LB],
                                       Rj, c, p[P_EPSDRY])  # fmt: skip
        bx = fr * nx + fth * tx  # on the bearing: minus the force on the journal
        by = fr * ny + fth * ty
        fx = fx + bx
        fy = fy + by
        fnn = fnn - fr
        ftt = ftt + fth
        lost = lost - (bx * u + by * v)
    return fx, fy, tb, tj, fnn, ftt, lost


@nb.njit(cache=True, inline="always")
def _joints(t, y, p, cfg):
    """Both joints' forces (tuples as `_pair`; a rigid joint's are 0) and (power from
    the crank, power lost in the joints, theta2', x3', cos theta2, sin and cos theta1), the
    crank turning at the prescribed speed."""
    w = p[P_OMEGA]
    return _joints_at(p[P_TH10] + w * t, w, y, p, cfg)


@nb.njit(cache=True, inline="always")
def _joints_at(th1, w, y, p, cfg):
    """`_joints` at the crank angle ``th1`` and speed ``w`` (a free crank's states)."""
    _, c2, th2d, v3, s1, c1 = _kinematics_at(th1, w, p, y[0], y[1], y[4], y[5], y[2], y[3],
                                             y[6], y[7])  # fmt: skip
    z = 0.0 * y[0]
    p_crank = z
    f1 = (z, z, z, z, z, z, z)
    f2 = (z, z, z, z, z, z, z)
    if cfg != 1:  # crank pin: journal on the crank (w), bearing on the rod
        f1 = _pair(y[0], y[1], y[4], y[5], w, th2d, p[P_C1], p[P_K1], p[P_RJ1], _abs(y[8]),
                   p[P_OIL], p)  # fmt: skip
        vjx, vjy = -p[P_R] * w * s1, p[P_R] * w * c1
        p_crank = f1[0] * vjx + f1[1] * vjy - f1[3] * w
    if cfg != 0:  # crosshead pin: journal on the crosshead (not turning), bearing on the rod
        f2 = _pair(y[2], y[3], y[6], y[7], 0.0, th2d, p[P_C2], p[P_K2], p[P_RJ2], _abs(y[9]),
                   p[P_OIL2], p)  # fmt: skip
    return f1, f2, p_crank, f1[6] + f2[6], th2d, v3, c2, s1, c1


#: The drive's parameters (inert with the prescribed drive: left out of a sweep store's
#: identity then).
_DRIVE_NAMES = ("drive", "motor", "J_drive", "motor_torque", "motor_sync_speed",
                "motor_breakdown_torque", "motor_breakdown_slip", "rs", "m1", "J1")  # fmt: skip

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


@nb.njit(cache=True, inline="always")
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


@nb.njit(cache=True, inline="always")
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
    elif cfg == 1:
        a = crosshead_free_accelerations(0.0, (y[m], y[2], y[3], w1, y[6], y[7]), p, u)
        out[4], out[5], out[6], out[7] = 0.0, 0.0, a[1], a[2]
    else:
        a = both_free_accelerations(0.0, (y[m], y[0], y[1], y[2], y[3], w1, y[4], y[5], y[6],
                                          y[7]), p, u)  # fmt: skip
        out[4], out[5], out[6], out[7] = a[1], a[2], a[3], a[4]
    out[8] = 0.0
    out[9] = 0.0
    out[I_WIN] = fg * v3 + tm * w1
    out[I_WLOSS] = p_loss
    out[m] = w1
    out[m + 1] = a[0]
    out[m + 2] = tm * w1
    return v3, c2


# ---- the guide's clearance (`recipdyn.model.components.guide`): the crosshead pin's lateral
# position ``y[gy]``, the tilt ``y[gy + 1]``, their rates, the corners' phases ``y[gy + 4:]``


@nb.njit(cache=True, inline="always")
def _joints_guide(t, y, p, cfg, gy):
    """`_joints` with the guide's clearance (``cfg`` 3: both pins ideal): the rod's small end
    follows the crosshead pin's lateral position, and the crosshead pin's journal turns with
    the crosshead's tilt."""
    _, c2, th2d, v3, s1, c1 = _kinematics(t, p, y[0], y[1], y[4], y[5], y[2], y[3] + y[gy],
                                          y[6], y[7] + y[gy + 2])  # fmt: skip
    w = p[P_OMEGA]
    z = 0.0 * y[0]
    p_crank = z
    f1 = (z, z, z, z, z, z, z)
    f2 = (z, z, z, z, z, z, z)
    if cfg == 0 or cfg == 2:  # crank pin: journal on the crank (w), bearing on the rod
        f1 = _pair(y[0], y[1], y[4], y[5], w, th2d, p[P_C1], p[P_K1], p[P_RJ1], _abs(y[8]),
                   p[P_OIL], p)  # fmt: skip
        vjx, vjy = -p[P_R] * w * s1, p[P_R] * w * c1
        p_crank = f1[0] * vjx + f1[1] * vjy - f1[3] * w
    if cfg == 1 or cfg == 2:  # crosshead pin: journal on the crosshead (turning with its tilt)
        f2 = _pair(y[2], y[3], y[6], y[7], y[gy + 3], th2d, p[P_C2], p[P_K2], p[P_RJ2],
                   _abs(y[9]), p[P_OIL2], p)  # fmt: skip
    return f1, f2, p_crank, f1[6] + f2[6], th2d, v3, c2, s1, c1


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


@nb.njit(cache=True, inline="always")
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
    phased factors ([`phased_factor`][recipdyn.model.compressor_contact.phased_factor])."""
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
    """At a zero of [`onset_both`][recipdyn.model.compressor_contact.onset_both]: the joint whose
    factor it is changes phase (`_flip`: an onset records its approach velocity)."""
    for i in range(y.shape[0]):
        out[i] = y[i]
    _flip(y, contact_factor(y, p, 2)[1], p, out)


#: Joint configuration codes of the compiled kernels (literals in the generated glue).
CFG = {"crank": 0, "crosshead": 1, "both": 2, "ideal": 3}
#: The joint family at each pin: its parameter and the joints it may be (the massless link
#: exists at the crank pin only, and only in the massless-link model).
PIN_CHOICES = {"crank_joint": ("link", "ideal", "contact", "lubricated"),
               "crosshead_joint": ("ideal", "contact", "lubricated")}  # fmt: skip


def joint_types(values: Mapping[str, Any]) -> tuple[str, str]:
    """The joint at the crank pin and at the crosshead pin (``ideal``, ``contact``,
    ``lubricated``): ``crank_joint`` and ``crosshead_joint`` where given, else from
    ``clearance_joints`` (where the clearance is) and ``joint`` (dry or lubricated)."""
    where = values.get("clearance_joints", "crank")
    kind = "lubricated" if values.get("joint", "dry") == "lubricated" else "contact"
    crank = values.get("crank_joint") or ("ideal" if where in ("crosshead", "ideal") else kind)
    cross = values.get("crosshead_joint") or ("ideal" if where in ("crank", "ideal") else kind)
    return crank, cross


def _resolve_joints(values: dict[str, Any]) -> None:
    """Write the joint family of each pin and the clearance configuration it makes into
    ``values``; refuse, in one line, a combination that does not exist here."""
    from ..errors import ParameterError

    crank, cross = joint_types(values)
    if crank == "link":
        raise ParameterError(
            "crank_joint = 'link' is out of range for this model; allowed: 'ideal', 'contact', "
            "'lubricated' (the massless link is the compressor model's: --model compressor)"
        )
    guide = values.get("guide", "ideal") == "clearance"
    if crank == "ideal" and cross == "ideal" and not guide:
        raise ParameterError(
            "crank_joint = crosshead_joint = 'ideal': no clearance joint left; allowed: "
            "'contact' or 'lubricated' at one pin at least, or guide = 'clearance' (the ideal "
            "mechanism: --model compressor with rc = 0)"
        )
    values["crank_joint"], values["crosshead_joint"] = crank, cross
    values["clearance_joints"] = ("ideal" if crank == cross == "ideal" else
                                  "both" if "ideal" not in (crank, cross) else
                                  "crank" if cross == "ideal" else "crosshead")  # fmt: skip


def load_part(values: Mapping[str, Any]):
    """The load component the values choose (`recipdyn.model.components.load`): a table when
    ``load_table`` is given (a measured indicator diagram, or a real gas's cycle tabulated
    from CoolProp), else the ``load`` parameter's."""
    from .components.load import load_component

    return load_component(values)


#: The roles of a contact law from a user's file (`law_part`): required, then optional.
LAW_ROLES = ("normal", "elastic")
LAW_OPTIONAL = ("friction", "potential")


def law_spec(values: Mapping[str, Any]) -> str | None:
    """The ``contact_law`` of ``values`` (or its alias ``law``) if it names a component of a
    user's module or file (``file.py:OBJ``), else None (one of the built-in laws, `LAWS`)."""
    from .registry import is_spec

    spec = values.get("contact_law", values.get("law"))
    return spec if is_spec(spec) else None


def law_part(values: Mapping[str, Any]):
    """The contact-law component a user's file gives (``contact_law = file.py:OBJ``), or None
    for a built-in law. It must be of the family ``contact_law`` and provide the roles
    `LAW_ROLES` (module ``recipdyn.model.components.contact``, docs/components.md);
    [`ParameterError`][recipdyn.errors.ParameterError] in one line otherwise."""
    from ..errors import ParameterError
    from .components.contract import resolve_component

    spec = law_spec(values)
    if spec is None:
        return None
    law = resolve_component("contact_law", spec, {})
    missing = [r for r in LAW_ROLES if r not in law.kernels]
    if missing:
        raise ParameterError(f"contact_law = {spec!r} provides no {' or '.join(missing)} "
                             f"kernel; a contact law provides {', '.join(LAW_ROLES)} and "
                             f"optionally {', '.join(LAW_OPTIONAL)}")  # fmt: skip
    return law


def law_size(values: Mapping[str, Any]) -> int:
    """The length of the contact law's slice (0 for a built-in law: its ``chi`` is in the
    joints' part, `P_CHI`). The slice follows the joints' part; the guide's and the load's
    follow it."""
    law = law_part(values)
    return 0 if law is None else int(np.asarray(law.pack(values)).size)


def law_source(law, offset: int) -> str:
    """The joints' force functions (`_pair`, `_joints`, `_joints_guide`) with the contact law
    ``law`` of a user's file, its slice at ``offset``: the source of the built-in functions
    with the law's calls in place of the built-in normal force, its elastic part (in the
    power lost) and, if the law has one, the friction; the rest (kinematics, the oil film,
    the torques) is the same text, so the physics stays written once. For the generated glue
    (`recipdyn.model.components.contact`)."""
    import inspect

    pair = inspect.getsource(_pair.py_func)
    swaps = {"normal_force(delta, drho, vi, K, p[P_CHI])":
             f"law_normal(delta, drho, vi, K, p, {offset})",
             "K * delta * np.sqrt(delta)": f"law_elastic(delta, K, p, {offset})"}  # fmt: skip
    if "friction" in law.kernels:
        swaps["friction_factor(vt, p[P_MU], p[P_V0], p[P_V1], int(p[P_FLAW]))"] = (
            f"law_friction(vt, p, {offset})")  # fmt: skip
    for old, new in swaps.items():
        if pair.count(old) != 1:  # pragma: no cover - guards an edit of _pair
            raise RuntimeError(f"_pair no longer holds {old!r} once; update law_source")
        pair = pair.replace(old, new)
    names = sorted(k for k in globals() if k.startswith("P_"))
    head = [f"from {law.module} import {law.kernel(r)} as law_{r}" for r in LAW_ROLES]
    if "friction" in law.kernels:
        head.append(f"from {law.module} import {law.kernel('friction')} as law_friction")
    head.append(
        "from recipdyn.model.compressor_contact import (_abs, _kinematics, _kinematics_at, "
        "friction_factor, short_bearing_forces, " + ", ".join(names) + ")"
    )
    body = [pair] + [inspect.getsource(f.py_func) for f in (_joints_at, _joints,
                                                             _joints_guide)]  # fmt: skip
    return "\n".join(head) + "\n\n\n" + "\n\n".join(body)


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


GUIDE_REFUSAL = (
    "Benettin's method is not offered with guide = 'clearance' or drive = 'motor': the "
    "tangent integration across the impacts (the saltation matrices of the guide's four "
    "corners' event, or of the pins' with the crank free) has not been checked against "
    "differences of the flow, as the pins' with a prescribed crank has; set guide = 'ideal' "
    "and drive = 'prescribed' for exponents of worn pins"
)


def has_motor(values: Mapping[str, Any]) -> bool:
    """Whether a motor turns the crank (``drive = motor``: the crank angle and speed are
    states)."""
    return values.get("drive", "prescribed") == "motor"


def _crank_slice(values: Mapping[str, Any]) -> np.ndarray:
    """The free crank's slice: its inertia about the main bearing with the drive's,
    ``J1 + m1 rs^2 + J_drive``, and its static moment ``m1 rs``."""
    m1, rs = float(values["m1"]), float(values["rs"])
    return np.array([float(values["J1"]) + m1 * rs * rs + float(values["J_drive"]), m1 * rs])


def _motor_parts(values: Mapping[str, Any]):
    """The free crank's slice (the drive) and the torque law's component."""
    from .components.contract import Component
    from .components.drive import KERNELS, MOTORS

    crank = Component("drive", "motor", "the free crank with the drive's inertia",
                      module=KERNELS, kernels={}, pack=_crank_slice)  # fmt: skip
    return crank, MOTORS[values["motor"]]


#: The free crank's slice length (`_crank_slice`).
N_CRANK = 2
#: The crank's states with a motor, after every other state.
MOTOR_STATES = (("theta1", "rad"), ("omega1", "rad/s"), ("W_motor", "J"))


def motor_size(values: Mapping[str, Any]) -> int:
    """The length of the torque law's slice."""
    return int(np.asarray(_motor_parts(values)[1].pack(_motor_values(values))).size)


def _motor_values(values: Mapping[str, Any]) -> dict[str, Any]:
    """``values`` as the torque laws read them: a constant torque's default, the mean load
    torque of the ideal mechanism, is the paper's load's, the table's or the ideal-valve
    cycle's (for the dynamic valves)."""
    if values.get("load") in (None, "valves"):
        return {**values, "load": "cycle", "gas": "ideal", "load_table": None}
    return dict(values)


def has_guide(values: Mapping[str, Any]) -> bool:
    """Whether the crosshead's guide has clearance (``guide = clearance``)."""
    return values.get("guide", "ideal") == "clearance"


def first_load_state(values: Mapping[str, Any]) -> int:
    """The index of a load's first state: after the joints' twelve and the guide's eight."""
    return G_GAS + (N_GUIDE_STATES if has_guide(values) else 0)


@lru_cache(maxsize=32)
def _glue(joints: str, load: str, guide: bool = False, law: str | None = None,
          n_law: int = 0, motor: str | None = None, n_motor: int = 0):  # fmt: skip
    from .components.contact import glue_source
    from .components.contract import glue_module, resolve_component, source_digest
    from .components.load import LOADS, VALVES

    part = VALVES if load == VALVES.name else LOADS[load]
    block, stem = "", f"contact_{joints}_{load}"
    if law is not None:  # a contact law of a user's file: its slice first, after the joints'
        law_c = resolve_component("contact_law", law, {})
        block = law_source(law_c, N_PACKED)
        # its edits give a new glue file, never stale machine code
        block += f"\n# contact_law = {law_c.module}: {source_digest(law_c.module)}\n"
        stem += f"_{law_c.name}".replace("-", "_")
    if motor is not None:  # the crank's slice and the torque law's before the load's
        from .components.drive import MOTORS

        first = G_GAS
        src = glue_source(cfg=CFG[joints], joints=joints, load=part,
                          offset=N_PACKED + n_law + N_CRANK + n_motor, first_state=first,
                          law=block, motor=MOTORS[motor],
                          motor_state=first + (va.N_GAS + va.N_AUX if part.states else 0),
                          motor_offset=N_PACKED + n_law + N_CRANK,
                          crank_offset=N_PACKED + n_law)  # fmt: skip
        return glue_module(src, f"{stem}_motor_{motor}")
    if not guide:
        src = glue_source(cfg=CFG[joints], joints=joints, load=part, offset=N_PACKED + n_law,
                          first_state=G_GAS, law=block)  # fmt: skip
        return glue_module(src, stem)
    src = glue_source(cfg=CFG[joints], joints=joints, load=part,
                      offset=N_PACKED + n_law + N_GUIDE, first_state=G_GAS + N_GUIDE_STATES,
                      guide=N_PACKED + n_law, guide_state=G_GUIDE, law=block)  # fmt: skip
    return glue_module(src, f"{stem}_guide")


def kernels(values: Mapping[str, Any], load=None):
    """The generated glue of the joints, the guide, the load ``values`` choose (or ``load``)
    and the contact law of a user's file if one is chosen: a module with ``rhs``, ``jac``,
    ``rhs_jac``, ``event``, ``reset``, ``observe`` and ``fd_jac``
    (`recipdyn.model.components.contact`)."""
    part = load_part(values) if load is None else load
    spec = law_spec(values)
    if has_motor(values):
        from .registry import absolute_spec

        law = None if spec is None else absolute_spec(spec)
        return _glue(values["clearance_joints"], part.name, False, law, law_size(values),
                     values["motor"], motor_size(values))  # fmt: skip
    if spec is not None:
        from .registry import absolute_spec

        return _glue(values["clearance_joints"], part.name, has_guide(values),
                     absolute_spec(spec), law_size(values))  # fmt: skip
    if has_guide(values):
        return _glue(values["clearance_joints"], part.name, True)
    return _glue(values["clearance_joints"], part.name)


def _link(name: str, **changes) -> Param:
    from dataclasses import replace

    return replace(LINK_SCHEMA[name], **changes)


SCHEMA = Schema((
    *(_link(k) for k in ("r", "l", "ls", "m2", "m3", "J2", "g")),
    Param("clearance_joints", "", "crank", "where the clearance is: the crank pin, the crosshead "
          "pin, or both (the other joints are ideal); 'ideal': neither (with guide = "
          "'clearance')", choices=GUIDE_JOINTS, group="joint"),
    _link("rc", description="radial clearance of the crank-pin joint, c = R_b - R_j",
          low=0.0, low_open=True),
    Param("rc_crosshead", "m", 1e-4, "radial clearance of the crosshead-pin joint "
          "(clearance_joints = crosshead or both)", 0.0, 0.05, low_open=True,
          assumed="assumed: a worn crosshead bush", group="joint"),
    _link("d", low_ref="-(l - r - 1.5 (rc + rc_crosshead))",
          high_ref="l - r - 1.5 (rc + rc_crosshead)"),
    Param("joint", "", "dry", "'dry' contact-impact or 'lubricated' (oil film + dry contact "
          "beyond eps_dry) at each clearance joint (crank_joint, crosshead_joint set one pin)",
          choices=("dry", "lubricated"), group="joint"),
    Param("crank_joint", "", None, "the crank-pin joint: 'ideal', 'contact' (dry) or "
          "'lubricated' (default: from clearance_joints and joint; 'link', the massless link, "
          "is the compressor model's)", choices=PIN_CHOICES["crank_joint"], optional=True,
          group="joint"),
    Param("crosshead_joint", "", None, "the crosshead-pin joint: 'ideal', 'contact' (dry) or "
          "'lubricated' (default: from clearance_joints and joint)",
          choices=PIN_CHOICES["crosshead_joint"], optional=True, group="joint"),
    Param("contact_law", "", "lankarani-nikravesh", "normal force law (hysteresis damping)",
          choices=LAWS, group="joint"),
    Param("restitution", "", 0.9, "nominal coefficient of restitution of the law", 0.0, 1.0,
          low_open=True, group="joint"),
    Param("K", "N/m**1.5", None, "contact stiffness of the crank-pin joint (default: Hertz "
          "pin-in-hole from the radii and materials)", 0.0, _INF, low_open=True, group="joint",
          optional=True),
    Param("K_crosshead", "N/m**1.5", None, "contact stiffness of the crosshead-pin joint "
          "(default: Hertz pin-in-hole)", 0.0, _INF, low_open=True, group="joint",
          optional=True),
    Param("journal_radius", "m", 0.05, "crank-pin (journal) radius R_j", 0.0, _INF,
          low_open=True, assumed="assumed: not given in the paper", group="joint"),
    Param("crosshead_pin_radius", "m", 0.03, "crosshead-pin (journal) radius", 0.0, _INF,
          low_open=True, assumed="assumed: not given in the paper", group="joint"),
    Param("bearing_length", "m", 0.06, "bearing length L (oil film)", 0.0, _INF,
          low_open=True, assumed="assumed: not given in the paper", group="joint"),
    Param("E_journal", "Pa", 2.07e11, "Young's modulus of the journal (steel)", 0.0, _INF,
          low_open=True, group="joint"),
    Param("nu_journal", "", 0.3, "Poisson's ratio of the journal", 0.0, 0.5, high_open=True,
          group="joint"),
    Param("E_bearing", "Pa", 2.07e11, "Young's modulus of the bearing (steel)", 0.0, _INF,
          low_open=True, group="joint"),
    Param("nu_bearing", "", 0.3, "Poisson's ratio of the bearing", 0.0, 0.5, high_open=True,
          group="joint"),
    Param("friction", "", 0.0, "Coulomb friction coefficient (0 disables)", 0.0, 2.0,
          group="joint"),
    Param("friction_law", "", "ambrosio", "'ambrosio' (dynamic correction, v0/v1) or 'tanh'",
          choices=FRICTION_LAWS, group="joint"),
    Param("v0", "m/s", 1e-4, "friction: sliding velocity below which there is none", 0.0,
          _INF, low_open=True, group="joint"),
    Param("v1", "m/s", 1e-3, "friction: sliding velocity above which it is full Coulomb", 0.0,
          _INF, low_open=True, group="joint"),
    Param("oil_viscosity", "Pa*s", 0.04, "dynamic viscosity of the oil (joint='lubricated')",
          0.0, 10.0, low_open=True, assumed="assumed: SAE 30 near 80 degC", group="joint"),
    Param("eps_dry", "", 0.95, "eccentricity ratio above which the film force is held "
          "(lubricated)", 0.5, 1.0, high_open=True, group="joint"),
    Param("v_impact_min", "m/s", 1e-3, "floor of the recorded approach velocity (grazing "
          "contacts)", 0.0, _INF, low_open=True, group="joint"),
    Param("guide", "", "ideal", "the crosshead guide: 'ideal' (rigid: the crosshead on y = -d) "
          "or 'clearance' (the crosshead moves sideways and tilts between the shoes and knocks on "
          "them: guide_clearance and the guide_* parameters)", choices=GUIDES, group="guide"),
    *GUIDE_PARAMS,
    _link("omega"), _link("theta1_0"),
    *(_link(k) for k in ("drive", "motor", "J_drive", "motor_torque", "motor_sync_speed",
                         "motor_breakdown_torque", "motor_breakdown_slip")),
    # the crank's own mass and inertia act on a free crank only (drive = motor)
    *(_link(k, group="drive") for k in ("rs", "m1", "J1")),
    _link("load_amplitude"), _link("load_sign"), _link("load"),
    *(_link(k) for k in (*CYCLE_PARAMS, "gas", "suction_temperature")),
    Param("e0_angle", "rad", None, "initial direction of e (default: aligned with the rod "
          "load, as the massless link's default)", -1e6, 1e6, group="initial", optional=True),
    Param("e0_angle_crosshead", "rad", None, "initial direction of the crosshead pin's e "
          "(default: the crank pin's + pi)", -1e6, 1e6, group="initial", optional=True),
    Param("e0_ratio", "", 1.0, "initial |e| / rc of each clearance joint", 0.0, 1.5,
          group="initial"),
    Param("edot0_x", "m/s", 0.0, "initial ex'", -1e3, 1e3, group="initial"),
    Param("edot0_y", "m/s", 0.0, "initial ey'", -1e3, 1e3, group="initial"),
), aliases={"clearance": "rc", "subsidence": "d", "speed": "omega", "crank_speed": "omega",
            "c": "rc", "law": "contact_law"})  # fmt: skip


def stiffness(values: Mapping[str, Any], joint: str = "crank") -> float:
    """K (N/m^1.5) of a clearance joint: the value given, or Hertz's pin-in-hole formula."""
    key, rc, rj = (("K", "rc", "journal_radius") if joint == "crank" else
                   ("K_crosshead", "rc_crosshead", "crosshead_pin_radius"))  # fmt: skip
    if values.get(key) is not None:
        return float(values[key])
    rj = float(values[rj])
    return hertz_stiffness(rj, rj + float(values[rc]), values["E_journal"],
                           values["nu_journal"], values["E_bearing"],
                           values["nu_bearing"])  # fmt: skip


#: The widest overlap half-angle (degrees) at which the point-contact law is taken to hold:
#: Hertz's theory needs a contact small against the radii (Johnson 1985, Contact Mechanics,
#: sec. 4.1) and must not be used when the contact arc is of the order of the radius
#: (Mostofi & Gohar, summarised in Lubricants 10 (2022) 233,
#: doi:10.3390/lubricants10100233). "Of the order" is taken here as an arc 2 phi R_j as long
#: as the radius R_j: phi = 0.5 rad = 28.6 deg (the paper's
#: base case, c = 1 mm, reaches 23 deg; c = 0.1 mm under the same load 45 deg).
HERTZ_ARC_LIMIT_DEG = math.degrees(0.5)


def overlap_half_angle(R_j: float, c: float, delta: float) -> float:
    """Half-angle (degrees) of the arc over which a journal of radius ``R_j`` overlaps its
    bearing (radius ``R_j + c``) at penetration ``delta``, seen from the bearing centre: from
    the two circles' intersection, ``cos phi = (R_b^2 + |e|^2 - R_j^2) / (2 R_b |e|)`` with
    ``|e| = c + delta``; ``1 - cos phi ~ delta / (c + delta)`` for ``R_j >> c``. 0 without
    contact. Hertz's law (and the damping laws built on it) assume a contact small against the
    radii: an arc of tens of degrees means the real, conformal contact is far from it."""
    if delta <= 0.0:
        return 0.0
    rb, e = R_j + c, c + delta
    cos_phi = (rb * rb + e * e - R_j * R_j) / (2.0 * rb * e)
    return math.degrees(math.acos(min(1.0, max(-1.0, cos_phi))))


def pack(values: Mapping[str, Any], load=None) -> np.ndarray:
    """The joints' parameters (layout: the ``P_*`` constants), then the slice of the load
    component (``load``, default: the one the values choose, `load_part`)."""
    from .components.contract import Assembly

    v = values
    pins = joint_types(v)
    head = [v[k] for k in MECH] + [0.0] * len(INPUTS)
    head += [v["rc"], stiffness(v, "crank"), v["journal_radius"],
             v["rc_crosshead"], stiffness(v, "crosshead"), v["crosshead_pin_radius"],
             0.0 if law_spec(v) else hysteresis_factor(v["contact_law"], v["restitution"]),
             v["friction"], v["v0"],
             v["v1"], float(FRICTION_LAWS.index(v["friction_law"])),
             v["oil_viscosity"] if pins[0] == "lubricated" else 0.0, v["bearing_length"],
             v["eps_dry"], v["v_impact_min"],
             v["oil_viscosity"] if pins[1] == "lubricated" else 0.0]  # fmt: skip
    part = load_part(v) if load is None else load
    law = law_part(v)  # a contact law of a user's file: its slice first
    first = () if law is None else (law,)
    n_law = law_size(v)
    if has_motor(v):  # the crank's and the torque law's slices, then the load's
        crank, motor = _motor_parts(v)
        vec, offsets = Assembly(N_PACKED, (*first, crank, motor, part)).pack(
            np.asarray(head, dtype=np.float64), _motor_values(v))  # fmt: skip
        assert offsets["drive"] == N_PACKED + n_law  # literals in the glue
        assert offsets["load"] == N_PACKED + n_law + N_CRANK + motor_size(v)
        return vec
    if has_guide(v):
        vec, offsets = Assembly(N_PACKED, (*first, CLEARANCE, part)).pack(
            np.asarray(head, dtype=np.float64), v)  # fmt: skip
        assert offsets["guide"] == N_PACKED + n_law  # literals in the glue
        assert offsets["load"] == N_PACKED + n_law + N_GUIDE
        return vec
    vec, offsets = Assembly(N_PACKED, (*first, part)).pack(np.asarray(head, dtype=np.float64),
                                                           v)  # fmt: skip
    assert offsets["load"] == N_PACKED + n_law  # a literal in the glue
    return vec


def _law_energy(values: Mapping[str, Any], delta: np.ndarray, joint: str) -> np.ndarray:
    """The elastic energy stored at penetrations ``delta`` (>= 0) by the contact law of a
    user's file: its ``potential(delta, K, p, o)`` if it has one, else the integral of its
    ``elastic`` force from 0 to ``delta`` (adaptive quadrature, relative error 1e-12)."""
    import importlib

    from scipy.integrate import quad

    law = law_part(values)
    mod = importlib.import_module(law.module)
    p, o, K = pack(values), N_PACKED, stiffness(values, joint)
    out = np.zeros_like(delta)
    if "potential" in law.kernels:
        fun = getattr(mod, law.kernel("potential"))
        for i in np.flatnonzero(delta > 0.0):
            out[i] = fun(float(delta[i]), K, p, o)
        return out
    fun = getattr(mod, law.kernel("elastic"))
    for i in np.flatnonzero(delta > 0.0):
        out[i] = quad(fun, 0.0, float(delta[i]), args=(K, p, o), epsabs=0.0, epsrel=1e-12)[0]
    return out


def energy(values: Mapping[str, Any], t: np.ndarray, y: np.ndarray, theta1=None,
           omega1=None) -> dict[str, np.ndarray]:  # fmt: skip
    """Kinetic + gravity energy of rod and crosshead and the contacts' elastic energy (J);
    ``theta1``, ``omega1``: a free crank's angle and speed (default: the prescribed
    ``theta1_0 + omega t`` and ``omega``)."""
    r, l, ls, m2, m3, J2, g, d, w, th10 = (float(values[k]) for k in MECH)
    th1 = th10 + w * t if theta1 is None else theta1
    w = w if omega1 is None else omega1
    y = np.atleast_2d(y)
    e1x, e1y, e2x, e2y, u1, v1, u2, v2 = (y[:, i] for i in range(8))
    ys, vs = e2y, v2  # the small end's lateral position and velocity, from y = -d
    if has_guide(values):  # it follows the crosshead pin's lateral position
        ys, vs = e2y + y[:, G_GUIDE], v2 + y[:, G_GUIDE + 2]
    s2 = (ys - d - r * np.sin(th1) - e1y) / l
    c2 = np.sqrt(1.0 - s2**2)
    vbx, vby = -r * w * np.sin(th1) + u1, r * w * np.cos(th1) + v1
    th2d = (vs - vby) / (l * c2)
    vgx, vgy = vbx - ls * s2 * th2d, vby + ls * c2 * th2d
    v3 = vbx - l * s2 * th2d - u2
    kin = 0.5 * (m2 * (vgx**2 + vgy**2) + J2 * th2d**2 + m3 * v3**2)
    pot = m2 * g * (r * np.sin(th1) + e1y + ls * s2)
    d1 = np.maximum(np.hypot(e1x, e1y) - float(values["rc"]), 0.0)
    d2 = np.maximum(np.hypot(e2x, e2y) - float(values["rc_crosshead"]), 0.0)
    if law_spec(values) is not None:
        elastic = _law_energy(values, d1, "crank") + _law_energy(values, d2, "crosshead")
    else:
        elastic = stiffness(values, "crank") * d1**2.5 / 2.5
        elastic = elastic + stiffness(values, "crosshead") * d2**2.5 / 2.5
    if has_guide(values):  # the crosshead's lateral motion, tilt and weight
        from .components.guide import tilt_inertia

        yg, ygd, phid = y[:, G_GUIDE], y[:, G_GUIDE + 2], y[:, G_GUIDE + 3]
        kin = kin + 0.5 * (m3 * ygd**2 + tilt_inertia(values) * phid**2)
        pot = pot + m3 * g * yg
    return {"mechanical": kin + pot, "elastic": elastic}


_LAW_SCHEMAS: dict[tuple[int, str], tuple[Schema, Schema]] = {}


def _law_schema(schema: Schema, spec: str) -> Schema:
    """``schema`` with the contact law ``spec`` of a user's file (remembered per schema and
    spec): the spec one more choice of ``contact_law``, the law's fragment appended (a name
    that ``schema`` already has is refused)."""
    from dataclasses import replace

    from ..errors import ParameterError
    from .components.contract import check_fragments

    key = (id(schema), spec)
    hit = _LAW_SCHEMAS.get(key)
    if hit is None or hit[0] is not schema:
        law = law_part({"contact_law": spec})
        try:
            check_fragments((law,), base=schema.params)
        except ValueError as exc:
            raise ParameterError(f"contact_law = {spec!r}: {exc}") from None
        params = tuple(replace(p, choices=(*p.choices, spec)) if p.name == "contact_law" else p
                       for p in schema)  # fmt: skip
        hit = _LAW_SCHEMAS[key] = schema, Schema((*params, *law.params), schema.aliases,
                                                 schema.extras)  # fmt: skip
    return hit[1]


class CompressorContact(Model):
    """The compressor with contact-impact (dry or lubricated) clearance joints at the crank
    pin, the crosshead pin, or both."""

    mean_signals = (
        ("contact", "contact_fraction", "1"),
        ("contact_crosshead", "contact_fraction_crosshead", "1"),
    )
    max_signals = (
        ("eccentricity_ratio", "max_eccentricity_ratio", "1"),
        ("eccentricity_ratio_crosshead", "max_eccentricity_ratio_crosshead", "1"),
    )
    name = "compressor-contact"
    description = ("compressor with contact-impact clearance joints at the crank pin, the "
                   "crosshead pin or both (free flight, impacts, friction, oil film; Flores et "
                   "al. 2008)")  # fmt: skip
    state_names = STATE_NAMES
    state_units = STATE_UNITS
    schema = SCHEMA
    section_signals = (("ex", "m"), ("ey", "m"), ("x", "m"), ("v", "m/s"), ("a", "m/s**2"))
    vibration_signal = ("a", "m/s**2")
    section_pair = ("v", "a")
    summary_verdicts = ("api618_pin_reversal",)
    #: The paper's load never reverses (the journal stays on the wall); at 150 rad/s with a
    #: tenth of it, inertia separates the journal and it impacts several times a revolution.
    event_example = {"omega": 150.0, "load_amplitude": 2e4}

    def check(self, values: Mapping[str, Any]) -> None:
        from ..errors import ParameterError

        if values["rc"] >= values["r"]:
            raise ParameterError(f"rc = {values['rc']!r} m is out of range; allowed: "
                                 f"(0, r = {values['r']!r}) m")  # fmt: skip
        dmax = values["l"] - values["r"] - 1.5 * (values["rc"] + values["rc_crosshead"])
        if not abs(values["d"]) < dmax:
            raise ParameterError(
                f"d = {values['d']!r} m is out of range; allowed: "
                f"(-{dmax:g}, {dmax:g}) m (l - r - 1.5 (rc + rc_crosshead))"
            )
        if values["v1"] <= values["v0"]:
            raise ParameterError(f"v1 = {values['v1']!r} m/s must exceed v0 = "
                                 f"{values['v0']!r} m/s")  # fmt: skip
        if has_motor(values):
            if has_guide(values):
                raise ParameterError("drive = 'motor' with guide = 'clearance' is not "
                                     "available yet; allowed with the guide clearance: drive "
                                     "= 'prescribed'")  # fmt: skip
            check = _motor_parts(values)[1].check
            if check is not None:
                check(values)
        law = law_part(values)
        if law is not None:
            if values.get("clearance_joints") == "ideal":
                raise ParameterError(
                    f"contact_law = {values['contact_law']!r}: no pin joint has contact in "
                    "this configuration (both pins ideal); a contact law belongs to "
                    "crank_joint or crosshead_joint = 'contact' | 'lubricated'"
                )
            if law.check is not None:
                law.check(values)

    def schema_for(self, values: Mapping[str, Any]) -> Schema:
        """The schema; with a contact law of a user's file (``contact_law = file.py:OBJ``)
        that spec one more choice of ``contact_law`` and the law's fragment appended (its
        parameters validated, recorded and swept like the built-in ones)."""
        from .registry import absolute_spec

        spec = law_spec(values)
        if spec is None:
            return self.schema
        return _law_schema(self.schema, absolute_spec(spec))

    def parameters(self, values: Mapping[str, Any] | None = None, **kw: Any) -> dict[str, Any]:
        """Validated values; besides the schema's, a force table as the massless link takes
        it: ``load_table`` (rows of crank angle in deg and force in N, or a CSV file of them,
        `recipdyn.model.load.read_load_table`) or ``pressure_table`` (a measured indicator
        diagram, a CSV file, `recipdyn.model.load.read_pressure_table`, with this run's bore,
        rod diameter and frame pressure). The table replaces the ``load`` (the table load
        component)."""
        from .registry import absolute_spec, is_spec

        v = {**(values or {}), **kw}
        table, ptab = v.pop("load_table", None), v.pop("pressure_table", None)
        for k in ("contact_law", "law"):  # a law of a user's file: found from any folder
            if is_spec(v.get(k)):
                v[k] = absolute_spec(v[k])
        out = self.schema_for(v).validate(v)
        _resolve_joints(out)
        self.check(out)
        tab = self._table(out, table, ptab)
        if tab is not None:
            out["load_table"] = tab
        return out

    def record_attrs(self, values: Mapping[str, Any], y0: np.ndarray | None = None
                     ) -> dict[str, Any]:  # fmt: skip
        """`Model.record_attrs`, with a table load's rows (``param_load_table_deg_N``: it has
        no schema row)."""
        out = super().record_attrs(values, y0)
        if values.get("load_table") is not None:
            out["param_load_table_deg_N"] = [float(x) for row in values["load_table"] for x in row]
        return out

    def values_from_record(self, attrs: Mapping[str, Any]) -> dict[str, Any]:
        """`Model.values_from_record`, the table load's rows included."""
        values = super().values_from_record(attrs)
        flat = attrs.get("param_load_table_deg_N")
        if flat is not None:
            rows = np.asarray(flat, dtype=float).reshape(-1, 2)
            values["load_table"] = tuple((float(a), float(b)) for a, b in rows)
        return values

    @staticmethod
    def _table(values: Mapping[str, Any], table: Any, ptab: Any) -> Any:
        from ..errors import ParameterError
        from .load import read_load_table, read_pressure_table
        from .parameters import _validate_table

        if table is not None and ptab is not None:
            raise ParameterError("pressure_table and load_table: give one of them")
        if ptab is not None:
            return read_pressure_table(ptab, bore=values["bore"],
                                       rod_diameter=values["rod_diameter"],
                                       frame_pressure=values["frame_pressure"])  # fmt: skip
        if table is None:
            return None
        if not isinstance(table, (list, tuple)):
            return read_load_table(table)
        rows = tuple(tuple(float(x) for x in row) for row in table)
        _validate_table(rows)
        return rows

    def load_part(self, values: Mapping[str, Any]):
        """The load component of this model for ``values`` (`load_part`)."""
        return load_part(values)

    def kernels(self, values: Mapping[str, Any]):
        """The generated glue of the joints and the load (`kernels`)."""
        return kernels(values, self.load_part(values))

    def events(self, values: Mapping[str, Any]) -> tuple[Event, ...]:
        joints = values["clearance_joints"]
        k = self.kernels(values)
        onset, record = k.event, k.reset
        if has_guide(values):
            return (Event("impact", onset, direction=-1, action="reset", reset=record,
                          description="contact onset or separation of a crosshead corner on "
                          "a guide shoe or at a worn pin (the smallest phased factor falls "
                          "through 0): at an onset the approach velocity is recorded for the "
                          "damping law"),)  # fmt: skip
        if joints == "both":
            return (Event("impact", onset, direction=-1, action="reset", reset=record,
                          description="contact onset or separation at either joint (the "
                          "smaller phased factor falls through 0): at an onset the approach "
                          "velocity is recorded for the damping law"),)  # fmt: skip
        where = "|e| = rc" if joints == "crank" else "|e_crosshead| = rc_crosshead"
        return (Event("impact", onset, direction=1, action="reset", reset=record,
                      description=f"contact onset ({where}, approaching): the approach "
                      "velocity is recorded for the damping law"),)  # fmt: skip

    def states(self, values: Mapping[str, Any]) -> tuple[tuple[str, str], ...]:
        """The joints' twelve states; with the guide's clearance, its eight after them; with a
        motor, the crank's three last (`MOTOR_STATES`)."""
        own = tuple(zip(STATE_NAMES, STATE_UNITS, strict=True))
        if has_guide(values):
            own = own + CLEARANCE.states + CLEARANCE.aux_states
        return own + self._load_states(values) + (MOTOR_STATES if has_motor(values) else ())

    def _load_states(self, values: Mapping[str, Any]) -> tuple[tuple[str, str], ...]:
        """A load's states (none: the dynamic valves' model adds its own)."""
        return ()

    #: Why Benettin's method is refused with the guide's clearance (a subclass that refuses it
    #: always says its own reason).
    lyapunov_refusal = GUIDE_REFUSAL

    def state_scale(self, values: Mapping[str, Any]) -> np.ndarray:
        """The default (``max(1, |y0|)``); with the guide's clearance, its lateral position
        0.02 m and tilt 0.01 rad (perturbations of a few percent put the crosshead ~1 mm into
        a shoe, as `compressor-guide`'s), the corners' approach velocities 1 mm/s."""
        s = np.maximum(1.0, np.abs(self.initial_state(values)))
        if has_guide(values):
            g = G_GUIDE
            s[g], s[g + 1] = 0.02, 0.01
            s[g + 4 : g + 8] = 1e-3
        return s

    def identity_values(self, values: Mapping[str, Any]) -> dict[str, Any]:
        """Without the guide's parameters while the guide is ideal (they have no effect then),
        so a sweep store of the contact joints keeps its digest."""
        inert = set() if has_motor(values) else set(_DRIVE_NAMES)
        if not has_guide(values):
            inert |= {"guide", *(p.name for p in GUIDE_PARAMS)}
        return {k: v for k, v in values.items() if k not in inert}

    def lyapunov_supported(self, values: Mapping[str, Any]) -> bool:
        """Not with the guide's clearance: its corners' saltation matrices have not been
        checked against differences of the flow (as the pins' have); nor with a motor (the
        same check with the crank free is not made)."""
        return (self.lyapunov_refusal == GUIDE_REFUSAL and not has_guide(values)
                and not has_motor(values))  # fmt: skip

    def _motor_system(self, values: Mapping[str, Any]) -> ODESystem:
        """The joints with the crank free: autonomous, the crank's states last."""
        k = self.kernels(values)
        names, units = zip(*self.states(values), strict=True)
        return ODESystem(rhs=k.rhs, jac=k.jac, rhs_jac=None,
                         params=pack(values, self.load_part(values)), state_names=names,
                         state_units=units, period=None, name=self.name,
                         events=self.events(values), aux_states=1,
                         passive=(*RIGID[values["clearance_joints"]], 8, 9, I_WIN, I_WLOSS,
                                  *range(G_GAS, len(names) - 3)))  # fmt: skip

    def system(self, values: Mapping[str, Any]) -> ODESystem:
        if has_motor(values):
            return self._motor_system(values)
        k = self.kernels(values)
        if has_guide(values):
            names, units = zip(*self.states(values), strict=True)
            return ODESystem(rhs=k.rhs, jac=k.jac, rhs_jac=k.rhs_jac,
                             params=pack(values, self.load_part(values)), state_names=names,
                             state_units=units, period=self.period(values), name=self.name,
                             events=self.events(values), aux_states=4,
                             passive=(*RIGID[values["clearance_joints"]], 8, 9, I_WIN,
                                      I_WLOSS))  # fmt: skip
        return ODESystem(rhs=k.rhs, jac=k.jac, rhs_jac=k.rhs_jac,
                         params=pack(values, self.load_part(values)),
                         state_names=self.state_names,
                         state_units=self.state_units, period=self.period(values),
                         name=self.name, events=self.events(values), aux_states=4,
                         passive=(*RIGID[values["clearance_joints"]], I_WIN, I_WLOSS))  # fmt: skip

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        """Both eccentricities along the rod load as the massless link's equilibrium (rod in
        compression: the crank pin's e points from the crosshead to the crank, the crosshead
        pin's the other way), at rest relative to the journals; a rigid joint's are 0."""
        ang = values["e0_angle"]
        if ang is None:
            from .components.mechanism import equilibrium_theta_c
            from .parameters import CompressorParams

            keys = (
                *MECH,
                "rc",
                "load_amplitude",
                "load_sign",
                "load",
                *CYCLE_PARAMS,
                "gas",
                "suction_temperature",
            )
            cp = CompressorParams(rs=0.0, load_table=values.get("load_table"),
                                  **{k: values[k] for k in keys})  # fmt: skip
            ang = equilibrium_theta_c(cp)
        ang2 = values["e0_angle_crosshead"]
        ang2 = ang + math.pi if ang2 is None else ang2
        y = np.zeros(len(STATE_NAMES))
        joints = values["clearance_joints"]
        if joints not in ("crosshead", "ideal"):
            e = values["e0_ratio"] * values["rc"]
            y[[0, 1, 4, 5]] = (e * math.cos(ang), e * math.sin(ang), values["edot0_x"],
                               values["edot0_y"])  # fmt: skip
        if joints not in ("crank", "ideal"):
            e = values["e0_ratio"] * values["rc_crosshead"]
            y[[2, 3]] = e * math.cos(ang2), e * math.sin(ang2)
        y[8] = y[9] = values["v_impact_min"]
        if self.tracks_separations(values):  # the phase: + in contact, - in free flight
            sign = 1.0 if values["e0_ratio"] >= 1.0 else -1.0
            y[8] = y[9] = sign * values["v_impact_min"]
        if has_guide(values):
            # the crosshead centred in its guide, level, moving along it; with no clearance
            # its corners touch the shoes already (in contact)
            sign = 1.0 if values["guide_clearance"] == 0 else -1.0
            g = np.zeros(N_GUIDE_STATES)
            g[4:] = sign * values["v_impact_min"]
            y = np.concatenate([y, g])
        if has_motor(values):  # the crank at theta1_0 turning at omega, no work done yet
            y = np.concatenate([y, [float(values["theta1_0"]), float(values["omega"]), 0.0]])
        return y

    def tracks_separations(self, values: Mapping[str, Any]) -> bool:
        """Whether the event also locates separations (the phase is then the sign of
        ``v_impact``; [`phased_factor`][recipdyn.model.compressor_contact.phased_factor]): with
        clearance at both pins, or with the guide's clearance."""
        return values["clearance_joints"] == "both" or has_guide(values)

    def period(self, values: Mapping[str, Any]) -> float:
        return 2.0 * math.pi / float(values["omega"])

    def outputs(self, values: Mapping[str, Any], t: np.ndarray, y: np.ndarray
                ) -> dict[str, Signal]:  # fmt: skip
        s = self.system(values)
        t = np.ascontiguousarray(t, dtype=float)
        y = np.ascontiguousarray(y, dtype=float)
        j = self.kernels(values).observe(t, y, s.params)
        r, l, d, w = (float(values[k]) for k in ("r", "l", "d", "omega"))
        th1 = float(values["theta1_0"]) + w * t
        motor = has_motor(values)
        alpha = 0.0
        if motor:  # the crank's angle, speed and acceleration: the observer's
            th1, w, alpha = j[:, 21], j[:, 22], j[:, 23]
        e1x, e1y, e2x, e2y = (y[:, i] for i in range(4))
        guide = has_guide(values)
        e2ydd = j[:, 17]
        if guide:  # the small end follows the crosshead pin's lateral position
            e2y, e2ydd = e2y + y[:, G_GUIDE], e2ydd + j[:, 21]
        s2 = (e2y - d - r * np.sin(th1) - e1y) / l
        c2 = np.sqrt(1.0 - s2**2)
        th2d = j[:, 18]
        # theta2'' from sin(theta2)'' = (e2y'' - By'') / l, By'' = -r w^2 sin(theta1) + e1y''
        # (with a free crank By'' has r alpha cos(theta1) too, and x3'' -r alpha sin(theta1))
        s2dd = (e2ydd + r * w**2 * np.sin(th1) - r * alpha * np.cos(th1) - j[:, 15]) / l
        th2dd = (s2dd + s2 * th2d**2) / c2
        x3 = r * np.cos(th1) + e1x + l * c2 - e2x
        a3 = (-r * w**2 * np.cos(th1) - r * alpha * np.sin(th1) + j[:, 14]
              - l * (c2 * th2d**2 + s2 * th2dd) - j[:, 16])  # fmt: skip
        if not motor:
            en = energy(values, t, y)
        else:  # the crank and the drive: I_crank w^2 / 2 + g S_crank sin(theta1)
            en = energy(values, t, y, th1, w)
            ic, sc = _crank_slice(values)
            en["mechanical"] = (en["mechanical"] + 0.5 * ic * w**2
                                + float(values["g"]) * sc * np.sin(th1))  # fmt: skip
        sig = {
            "x": Signal(x3, "m", "crosshead displacement x3"),
            "v": Signal(j[:, 19], "m/s", "crosshead velocity"),
            "a": Signal(a3, "m/s**2", "crosshead acceleration"),
            "theta1": Signal(th1, "rad", "crank angle"),
            "theta2": Signal(np.arcsin(s2), "rad", "connecting-rod angle"),
            "gas_force": Signal(j[:, 20], "N", "gas force on the crosshead along +x"),
            "energy": Signal(en["mechanical"] + en["elastic"], "J",
                             "kinetic + gravity energy of rod and crosshead + contact elastic"),
            **cycle_outputs(values, th1),
        }  # fmt: skip
        if guide:
            en_g = j[:, 28]
            sig["energy"] = Signal(en["mechanical"] + en["elastic"] + en_g, "J",
                                   "kinetic + gravity energy of rod and crosshead + contact "
                                   "elastic (pins and guide shoes)")  # fmt: skip
            sig.update(_guide_outputs(y, j))
        joints = values["clearance_joints"]
        for key, where, row, (ix, iy), rc in (
            ("", "crank-pin", 0, (0, 1), "rc"),
            ("_crosshead", "crosshead-pin", 1, (2, 3), "rc_crosshead"),
        ):  # fmt: skip
            if joints not in ("both", where.split("-")[0]):
                continue
            ex, ey = y[:, ix], y[:, iy]
            rho = np.hypot(ex, ey)
            c = float(values[rc])
            delta = rho - c
            f = j[:, 7 * row : 7 * row + 7]
            sig.update({
                "ex" + key: Signal(ex, "m", f"{where} eccentricity x (bearing centre - journal "
                                   "centre)"),
                "ey" + key: Signal(ey, "m", f"{where} eccentricity y"),
                "eccentricity_ratio" + key: Signal(rho / c, "", f"{where} |e| / {rc}"),
                "delta" + key: Signal(delta, "m", f"{where} penetration |e| - {rc} (> 0: in "
                                      "contact)"),
                "contact" + key: Signal((delta > 0).astype(float), "", f"{where} contact: 1 in "
                                        "contact, 0 in free flight"),
                "normal_force" + key: Signal(f[:, 4], "N", f"{where} normal force on the "
                                             "bearing (contact + film)"),
                "tangential_force" + key: Signal(f[:, 5], "N", f"{where} tangential force on "
                                                 "the bearing"),
                "joint_force_x" + key: Signal(f[:, 0], "N", f"{where} joint force on the rod, "
                                              "x"),
                "joint_force_y" + key: Signal(f[:, 1], "N", f"{where} joint force on the rod, "
                                              "y"),
                "joint_force" + key: Signal(np.hypot(f[:, 0], f[:, 1]), "N", f"{where} joint "
                                            "force magnitude"),
            })  # fmt: skip
        if motor:
            m = len(y[0]) - 3
            d = self.system(values)
            from .base import rhs_series

            tm = rhs_series(d.rhs, d.params, t, y)[:, m + 2] / w
            sig.update({
                "omega1": Signal(w, "rad/s", "crank speed"),
                "alpha1": Signal(alpha, "rad/s**2", "crank angular acceleration"),
                "motor_torque": Signal(tm, "N*m", "motor torque at the crank"),
                "W_motor": Signal(y[:, m + 2], "J", "work done by the motor since t = 0"),
                "W_gas": Signal(y[:, I_WIN] - y[:, m + 2], "J",
                                "work done by the gas on the crosshead since t = 0"),
            })  # fmt: skip
            sig["energy"] = Signal(sig["energy"].values, "J", "kinetic + gravity energy of "
                                   "crank (with the drive), rod and crosshead + contact "
                                   "elastic")  # fmt: skip
        if "ex" not in sig:  # an ideal crank pin: no eccentricity (the section signals name it)
            zero = np.zeros_like(t)
            sig["ex"] = Signal(zero, "m", "crank-pin eccentricity x (ideal pin: 0)")
            sig["ey"] = Signal(zero.copy(), "m", "crank-pin eccentricity y (ideal pin: 0)")
        return sig

    def law_range(self, values: Mapping[str, Any], ds: Any) -> str:
        """The point-contact law beyond its range: at a joint whose deepest penetration gives
        an overlap arc (`overlap_half_angle`) wider than `HERTZ_ARC_LIMIT_DEG`."""
        out = []
        for key, rc, rj, where in (("", "rc", "journal_radius", "crank pin"),
                                   ("_crosshead", "rc_crosshead", "crosshead_pin_radius",
                                    "crosshead pin")):  # fmt: skip
            if "delta" + key not in ds:
                continue
            pen = float(max(np.nanmax(ds["delta" + key].values), 0.0))
            c = float(values[rc])
            arc = overlap_half_angle(float(values[rj]), c, pen)
            if arc > HERTZ_ARC_LIMIT_DEG:
                out.append(f"{where}: penetration {pen * 1e6:.4g} um = {100 * pen / c:.3g} % of "
                           f"the clearance, contact arc +-{arc:.3g} deg")  # fmt: skip
        if not out:
            return ""
        return (f"the point-contact law {values['contact_law']!r} is stretched beyond its range "
                f"({'; '.join(out)} > {HERTZ_ARC_LIMIT_DEG:.3g} deg, an arc as long as the "
                "radius): Hertz's theory assumes a contact small against the radii (Johnson "
                "1985, Contact Mechanics, sec. 4.1) and does not hold when the arc is of the "
                "order of the radius (Mostofi & Gohar, as summarised in Lubricants 10 "
                "(2022) 233); the forces and accelerations are the model's, not a real "
                "bearing's: set a stiffer K or a larger clearance")  # fmt: skip

    def run_summary(self, values: Mapping[str, Any], ds: Any) -> dict[str, float]:
        """Per clearance joint (suffix ``_crosshead`` for the crosshead pin): impacts (count,
        per revolution, approach velocities), maximum penetration (in m and as a fraction of
        the clearance) with the half-angle of the overlap arc there
        ([`overlap_half_angle`][recipdyn.model.compressor_contact.overlap_half_angle]: how far the
        contact is from the small contact the point-contact law assumes), contact fraction (free
        flight is the rest), peak and RMS joint force; the energy lost in the joints and the
        energy-balance residual over the recorded interval; the peak crosshead acceleration."""
        out: dict[str, float] = {}
        t = ds["time"].values
        revs = (t[-1] - t[0]) / self.period(values) if t.size > 1 else float("nan")
        if has_guide(values):
            ds, guide_summary = _guide_summary(values, ds, revs)
            out.update(guide_summary)
        joints = values["clearance_joints"]
        active = [("", 0, 1, 4, 5, "rc")] if joints not in ("crosshead", "ideal") else []
        if joints not in ("crank", "ideal"):
            active.append(("_crosshead", 2, 3, 6, 7, "rc_crosshead"))
        has_ev = "impact_time" in ds
        if has_ev:
            ev = np.column_stack([ds[f"impact_{k}"].values for k in STATE_NAMES[:8]])
            rel = np.column_stack([np.abs(np.hypot(ev[:, 0], ev[:, 1]) / values["rc"] - 1.0),
                                   np.abs(np.hypot(ev[:, 2], ev[:, 3])
                                          / values["rc_crosshead"] - 1.0)])  # fmt: skip
            owner = np.argmin(rel, axis=1) if joints == "both" else np.full(
                len(ev), 0 if joints == "crank" else 1)  # fmt: skip
        for key, ix, iy, iu, iv, rc in active:
            if has_ev:
                mine = owner == (0 if key == "" else 1)
                vr = (ev[mine, ix] * ev[mine, iu] + ev[mine, iy] * ev[mine, iv]) / np.hypot(
                    ev[mine, ix], ev[mine, iy])  # fmt: skip
                vr = vr[vr > 0]  # onsets (with both joints the separations are events too)
            else:
                vr = np.empty(0)
            force = ds["joint_force" + key].values
            pen = float(max(ds["delta" + key].values.max(), 0.0))
            c = float(values[rc])
            rj = float(values["journal_radius" if key == "" else "crosshead_pin_radius"])
            out.update({
                f"impacts{key}": float(vr.size),
                f"impacts_per_revolution{key}": vr.size / revs if revs > 0 else float("nan"),
                f"impact_velocity_mean{key}_m_s": float(vr.mean()) if vr.size else 0.0,
                f"impact_velocity_max{key}_m_s": float(vr.max()) if vr.size else 0.0,
                f"max_penetration{key}_m": pen,
                f"max_penetration_ratio{key}": pen / c,
                f"contact_arc{key}_deg": overlap_half_angle(rj, c, pen),
                f"contact_fraction{key}": float(ds["contact" + key].values.mean()),
                f"peak_joint_force{key}_N": float(force.max()),
                f"rms_joint_force{key}_N": float(np.sqrt(np.mean(force**2))),
            })  # fmt: skip
        E = ds["energy"].values
        w_in, w_loss = ds["W_in"].values, ds["W_loss"].values
        bal = E - E[0] - ((w_in - w_in[0]) - (w_loss - w_loss[0]))
        out.update({
            "energy_lost_in_joints_J": float(w_loss[-1] - w_loss[0]),
            "energy_balance_residual": float(np.abs(bal).max() / max(np.abs(E).max(), 1e-300)),
            "peak_abs_a_m_s2": float(np.abs(ds["a"].values).max()),
        })  # fmt: skip
        out.update(cycle_summary(values, ds))
        return out


def _guide_outputs(y: np.ndarray, j: np.ndarray) -> dict[str, Signal]:
    """The guide's outputs from its states and the observer's columns (21-29)."""
    g = G_GUIDE
    return {
        "guide_y": Signal(y[:, g], "m", "crosshead lateral position from the guide's "
                          "centreline (+ up)"),
        "guide_v": Signal(y[:, g + 2], "m/s", "crosshead lateral velocity"),
        "guide_acc": Signal(j[:, 21], "m/s**2", "crosshead lateral acceleration (what an "
                            "accelerometer on the guide sees of the knock)"),
        "tilt": Signal(y[:, g + 1], "rad", "crosshead tilt in the guide"),
        "shoe_force_upper": Signal(j[:, 25], "N", "normal force of the upper shoe"),
        "shoe_force_lower": Signal(j[:, 26], "N", "normal force of the lower shoe"),
        "side_force": Signal(j[:, 23], "N", "net side force of the guide on the crosshead "
                             "(+ up)"),
        "guide_friction_force": Signal(j[:, 22], "N", "friction force of the shoes on the "
                                       "crosshead along +x"),
        "guide_contact": Signal((j[:, 27] > 0).astype(float), "", "1 while a corner touches "
                                "a shoe"),
    }  # fmt: skip


def _guide_summary(values: Mapping[str, Any], ds: Any, revs: float) -> tuple[Any, dict]:
    """The record without the guide's events (an event whose corners changed phase), and
    the guide's figures: shoe impacts (count, per revolution, largest approach velocity),
    the peak lateral acceleration, the largest lateral excursion, the contact fraction."""
    out: dict[str, float] = {}
    if "impact_time" in ds:
        names = [f"v_impact_guide_{k}" for k in range(1, 5)]
        before = np.column_stack([ds[f"impact_{k}"].values for k in names])
        after = np.column_stack([ds[f"impact_{k}_after"].values for k in names])
        mine = (before != after).any(axis=1)
        onset = (after > 0) & (before <= 0)
        vel = after[onset]
        out.update({
            "impacts_guide": float(onset.sum()),
            "impacts_per_revolution_guide": onset.sum() / revs if revs > 0 else float("nan"),
            "impact_velocity_max_guide_m_s": float(vel.max()) if vel.size else 0.0,
        })  # fmt: skip
        ds = ds.isel(impact_event=np.flatnonzero(~mine))
    c = float(values["guide_clearance"])
    excursion = float(np.abs(ds["guide_y"].values).max())
    out.update({
        "peak_abs_guide_acc_m_s2": float(np.abs(ds["guide_acc"].values).max()),
        "max_lateral_excursion_m": excursion,
        "max_lateral_excursion_ratio": excursion / c if c > 0 else float("nan"),
        "guide_contact_fraction": float(ds["guide_contact"].values.mean()),
    })  # fmt: skip
    return ds, out


COMPRESSOR_CONTACT = CompressorContact()

if __name__ == "__main__":  # pragma: no cover - developer tool
    _target().write_text(generate())
    _drive_target().write_text(generate_drive())
    print(f"wrote {_target().name}, {_drive_target().name}")
