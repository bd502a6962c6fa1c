"""Template of the kernels of the contact-impact joints at the pins, for one configuration.

Written per configuration like `prescribed` (the module docstring there): this file verbatim,
the block between the ``<bindings>`` markers replaced by the configuration's names and
constants. As it stands the block binds the reference configuration: the crank pin worn, the
paper's load, the crank prescribed, the guide rigid.

The joints' forces come from the module of the configuration's contact and friction laws
(template `joints`: ``joints``, ``joints_at``, ``joints_guide``, ``joints_guide_at``,
``guide_forces``, ``guide_corner``), the mechanism's accelerations from
`recipdyn.model.joints.pins` (``_accelerate`` and its variants with the guide's clearance and
the crank free), the load's force and states from the load's roles (``load_force``,
``load_force_sc``: from the sine and cosine of the crank angle; ``load_state_force``,
``load_rhs``, ``load_event``, ``load_reset``: a load with states), the motor's torque from
``torque``. A role the configuration lacks is bound to
`recipdyn.model.assembler.generate.absent`, in a branch on a constant numba removes.

Constants: ``CFG`` (0 the crank pin worn, 1 the crosshead pin, 2 both, 3 both ideal: the
guide's clearance only; a literal, so each joints' function compiles once per value);
``MOTOR``, ``HAS_GUIDE``, ``LOAD_STATES``, ``LOAD_SC``; the load's slice ``LO``, its first
state ``G`` and first counter ``A``; the guide's slice ``GO`` and first state ``GY``; with a
motor the crank's first state ``M``, the torque law's slice ``MO``, the crank's inertia and
static moment ``CO``; the observer's width ``N_OBS``.

The state: the joints' twelve (`recipdyn.model.joints.pins.STATE_NAMES`), the guide's eight,
the load's states and counters, with a motor the crank's angle, speed and work last. The
Jacobian: the complex step of the right-hand side with a prescribed crank and a load without
states (exact to rounding), else fourth-order central differences.
"""

import math

import numba as nb
import numpy as np

from recipdyn.model.base import (
    EVENT_SIGNATURE,
    JAC_SIGNATURE,
    RHS_JAC_SIGNATURE,
    RHS_SIGNATURE,
    compiled,
)
from recipdyn.model.joints.guide import S_J3
from recipdyn.model.joints.guide import slice_flip_phases as guide_reset
from recipdyn.model.joints.guide import slice_smallest_factor as guide_factor
from recipdyn.model.joints.pins import (
    _RIGID_MASK,
    CS_STEP,
    I_WIN,
    P_C1,
    P_C2,
    P_L,
    P_OMEGA,
    P_R,
    P_TH10,
    _accelerate,
    _accelerate_free,
    _accelerate_guide,
    _accelerate_guide_free,
    _flip,
    contact_factor,
    onset_both,
    onset_crank,
    onset_crosshead,
    record_both,
    record_crank,
    record_crosshead,
)

# isort: split
# <bindings>
from recipdyn.model.assembler.generate import absent as load_event
from recipdyn.model.assembler.generate import absent as load_force
from recipdyn.model.assembler.generate import absent as load_reset
from recipdyn.model.assembler.generate import absent as load_rhs
from recipdyn.model.assembler.generate import absent as load_state_force
from recipdyn.model.assembler.generate import absent as torque
from recipdyn.model.assembler.templates.joints import (
    guide_corner,
    guide_forces,
    joints,
    joints_at,
    joints_guide,
    joints_guide_at,
)
from recipdyn.model.components.load import paper_force_sc as load_force_sc

A = np.int64(12)
CFG = 0
CO = np.int64(31)
G = np.int64(12)
GO = np.int64(31)
GY = np.int64(12)
HAS_GUIDE = False
LO = np.int64(31)
LOAD_SC = True
LOAD_STATES = False
M = np.int64(12)
MO = np.int64(33)
MOTOR = False
N_OBS = np.int64(21)
# </bindings>

#: The complex-step Jacobian (exact to rounding) where it applies: the crank prescribed (its
#: angle enters the kinematics through math.sin, which takes no complex argument) and the load
#: without states (whose laws are not written for complex states).
CS = not (MOTOR or LOAD_STATES)
#: The columns the complex step takes: the joints' twelve, then the guide's eight.
CS_N = I_WIN + 8 if HAS_GUIDE else I_WIN
#: The observer's first column of the guide's outputs and of the crank's.
OBS_GUIDE = 21
OBS_CRANK = 30 if HAS_GUIDE else 21


@nb.njit(cache=True, inline="always")
def _angle(t, y, p):
    """The crank angle: the crank's state with a motor, else the prescribed one."""
    if MOTOR:
        return y[M]
    return p[P_TH10] + p[P_OMEGA] * t


@nb.njit(cache=True, inline="always")
def _force(t, y, p, s1, c1):
    """The load's gas force on the crosshead along +x."""
    if LOAD_STATES:
        return load_state_force(y, G, p, LO)
    if LOAD_SC:
        return load_force_sc(s1, c1, p, LO)
    return load_force(_angle(t, y, p), p, LO)


@nb.njit(cache=True, inline="always")
def _guide(y, p, v3):
    """The guide's shoes on the crosshead: resultant at its pin, moment, power lost, elastic
    energy."""
    return guide_forces(y, p, GO, GY, v3)


@nb.njit(cache=True, inline="always")
def _mechanism(t, y, p, out):
    """The mechanism's derivatives (the joints', the guide's, the crank's); returns the
    crosshead's velocity and cos theta2."""
    if HAS_GUIDE:
        if MOTOR:
            j = joints_guide_at(y[M], y[M + 1], y, p, CFG, GY)
            return _accelerate_guide_free(y, p, out, CFG, GY, p[GO + S_J3], j,
                                          _force(t, y, p, j[7], j[8]), _guide(y, p, j[5]), M,
                                          torque(y[M + 1], p, MO), CO)  # fmt: skip
        j = joints_guide(t, y, p, CFG, GY)
        return _accelerate_guide(t, y, p, out, CFG, GY, p[GO + S_J3], j,
                                 _force(t, y, p, j[7], j[8]), _guide(y, p, j[5]))  # fmt: skip
    if MOTOR:
        j = joints_at(y[M], y[M + 1], y, p, CFG)
        return _accelerate_free(y, p, out, CFG, j, _force(t, y, p, j[7], j[8]), M,
                                torque(y[M + 1], p, MO), CO)  # fmt: skip
    j = joints(t, y, p, CFG)
    return _accelerate(t, y, p, out, CFG, j, _force(t, y, p, j[7], j[8]))


@nb.njit(cache=True, inline="always")
def _rhs(t, y, p, out):
    v3, c2 = _mechanism(t, y, p, out)
    if LOAD_STATES:  # the cylinder gas and the plates follow the crosshead of the joints' state
        x3 = p[P_R] * math.cos(_angle(t, y, p)) + y[0] + p[P_L] * c2 - y[2]
        load_rhs(x3, v3, y, G, A, p, LO, out)


@compiled(RHS_SIGNATURE)
def rhs(t, y, p, out):
    _rhs(t, y, p, out)


@nb.njit(cache=True, inline="always")
def _rest_step(k):
    """The difference step's scale of the states after the joints': 1e-3 of their unit, and
    0.1 for the guide's lateral position and tilt and its corners' approach velocities (a step
    of 1 um, 1 urad, 1 um/s: with the shoes' forces at 1e7-1e8 N a step of 1e-8 drowned
    d(alpha1)/d(yg) in rounding, ~1e-3 against an entry of ~1e-6)."""
    if HAS_GUIDE:
        return 0.1 if GY <= k < GY + 2 or GY + 4 <= k < GY + 8 else 1e-3
    return 1e-3


@nb.njit(cache=True, inline="always")
def _clearance(p):
    """The clearance that scales the steps: the worn pin's (the smaller one's with both, or
    with the guide's clearance whatever the pins)."""
    if HAS_GUIDE:
        return min(p[P_C1], p[P_C2])
    return p[P_C1] if CFG == 0 else (p[P_C2] if CFG == 1 else min(p[P_C1], p[P_C2]))


@nb.njit(cache=True)
def _fd_columns(t, y, p, J, skip_passive):
    """Fourth-order central differences (truncation O(h^4)), steps scaled by the clearance
    (positions), c omega (rates), work integrals 1 J, the states after the joints' by
    `_rest_step` (of their unit, at least). With ``skip_passive`` the columns of the joints'
    work integrals (nothing depends on them) and of a rigid pin's states are left 0: the
    tangent flow's components along them stay 0, so it never reads them."""
    n = y.shape[0]
    yp = y.copy()
    f = np.empty((4, n))
    c = _clearance(p)
    for k in range(n):
        if skip_passive and (k == I_WIN or k == I_WIN + 1 or (k < I_WIN and _RIGID_MASK[CFG, k])):
            for i in range(n):
                J[i, k] = 0.0
            continue
        scale = c if k < 4 else (c * p[P_OMEGA] if k < 10 else (1.0 if k < 12 else _rest_step(k)))
        h = 1e-5 * max(abs(y[k]), scale)
        for m, step in enumerate((h, -h, 2.0 * h, -2.0 * h)):
            yp[k] = y[k] + step
            _rhs(t, yp, p, f[m])
        yp[k] = y[k]
        for i in range(n):
            J[i, k] = (8.0 * (f[0, i] - f[1, i]) - (f[2, i] - f[3, i])) / (12.0 * h)


@nb.njit(cache=True)
def fd_jac(t, y, p, J):
    _fd_columns(t, y, p, J, False)


@nb.njit(cache=True)
def _cs_columns(t, y, p, f, J, skip_rigid):
    """The complex step, ``J[:, k] = Im f(y + i h e_k) / h`` (Squire & Trapp 1998; exact to
    rounding since no difference is taken), over the columns of the `CS_N` states that move;
    the work integrals' left 0, with ``skip_rigid`` a rigid pin's too (for the tangent flow,
    whose components along them stay 0); ``f`` the real part of the same evaluations."""
    n = y.shape[0]
    yc = np.empty(n, np.complex128)
    fc = np.empty(n, np.complex128)
    for i in range(n):
        yc[i] = y[i]
    J[:, :] = 0.0
    first = True
    for m in range(CS_N):
        k = m if m < I_WIN else m - I_WIN + GY  # then the guide's states
        if m < I_WIN and skip_rigid and _RIGID_MASK[CFG, k]:
            continue
        yc[k] = complex(y[k], CS_STEP)
        _mechanism(t, yc, p, fc)
        yc[k] = y[k]
        for i in range(n):
            J[i, k] = fc[i].imag / CS_STEP
        if first:
            for i in range(n):
                f[i] = fc[i].real
            first = False


@nb.njit(cache=True)
def cs_jac(t, y, p, J):
    f = np.empty(y.shape[0])
    _cs_columns(t, y, p, f, J, False)


@compiled(JAC_SIGNATURE, allocates=True)
def jac(t, y, p, J):
    if CS:
        cs_jac(t, y, p, J)
    else:
        fd_jac(t, y, p, J)


if CS:

    @compiled(RHS_JAC_SIGNATURE, allocates=True)
    def rhs_jac(t, y, p, f, J):
        _cs_columns(t, y, p, f, J, True)

elif MOTOR and not HAS_GUIDE:

    @compiled(RHS_JAC_SIGNATURE, allocates=True)
    def rhs_jac(t, y, p, f, J):
        """For the tangent flow: the passive columns (a rigid pin's, the work integrals') left
        0."""
        _rhs(t, y, p, f)
        _fd_columns(t, y, p, J, True)

else:
    rhs_jac = None


@nb.njit(cache=True, inline="always")
def _joint_factor(y, p):
    if CFG == 3:
        return math.inf
    return contact_factor(y, p, CFG)[0]


@nb.njit(cache=True, inline="always")
def _load_factor(y, p):
    if LOAD_STATES:
        return load_event(y, G, p, LO)
    return math.inf


@nb.njit(cache=True, inline="always")
def _guide_factor(y, p):
    # the corners' phased factors do not depend on the axial velocity
    return guide_factor(p, GO, y[GY], 0.0, y[GY + 2], y[GY + 1], y[GY + 3], y, GY + 4)[0]


@compiled(EVENT_SIGNATURE)
def event(t, y, p):
    """The smallest event factor of the guide's corners, the joints and the load (each
    positive between its events); without the guide's clearance or a load with states, the
    joints' own: an onset at one pin, an onset or a separation with both."""
    if HAS_GUIDE:
        return min(_guide_factor(y, p), _joint_factor(y, p), _load_factor(y, p))
    if LOAD_STATES:
        return min(contact_factor(y, p, CFG)[0], load_event(y, G, p, LO))
    if CFG == 0:
        return onset_crank(t, y, p)
    if CFG == 1:
        return onset_crosshead(t, y, p)
    return onset_both(t, y, p)


@compiled(RHS_SIGNATURE)
def reset(t, y, p, out):
    """The factor at zero acts: a corner's (it changes phase), a joint's (an onset records its
    approach velocity; with both pins or a load, a separation flips its phase) or the load's (a
    valve plate rebounds or rests)."""
    if HAS_GUIDE:
        fg = abs(_guide_factor(y, p))
        fj = abs(_joint_factor(y, p))
        fl = abs(_load_factor(y, p))
        for i in range(y.shape[0]):
            out[i] = y[i]
        if fg <= fj and fg <= fl:
            guide_reset(p, GO, y[GY], 0.0, y[GY + 2], y[GY + 1], y[GY + 3], y, GY + 4, out)
        elif fj <= fl:
            if CFG != 3:
                _flip(y, contact_factor(y, p, CFG)[1], p, out)
        elif LOAD_STATES:
            load_reset(y, G, p, LO, out)
        return
    if LOAD_STATES:
        own = load_event(y, G, p, LO)
        f, j = contact_factor(y, p, CFG)
        if abs(own) < abs(f):
            load_reset(y, G, p, LO, out)
            return
        for i in range(y.shape[0]):
            out[i] = y[i]
        _flip(y, j, p, out)
        return
    if CFG == 0:
        record_crank(t, y, p, out)
    elif CFG == 1:
        record_crosshead(t, y, p, out)
    else:
        record_both(t, y, p, out)


@nb.njit(cache=True)
def observe(t, y, p):
    """Per sample: both joints' rows of `_pair` (14), the accelerations e1'', e2'' (4),
    theta2', x3', gas force; with the guide's clearance then the guide's: the crosshead pin's
    lateral acceleration, the shoes' resultant (x, y) and moment, the upper and lower shoes'
    normal forces, the corners in contact, the shoes' elastic energy, the tilt's acceleration;
    with a motor then the crank's angle, speed and acceleration."""
    n = t.shape[0]
    out = np.zeros((n, N_OBS))
    d = np.empty(y.shape[1])
    for i in range(n):
        yi = y[i].copy()
        _rhs(t[i], yi, p, d)
        if HAS_GUIDE:
            if MOTOR:
                j = joints_guide_at(yi[M], yi[M + 1], yi, p, CFG, GY)
            else:
                j = joints_guide(t[i], yi, p, CFG, GY)
        elif MOTOR:
            j = joints_at(yi[M], yi[M + 1], yi, p, CFG)
        else:
            j = joints(t[i], yi, p, CFG)
        f1, f2, _, _, th2d, v3, _, s1, c1 = j
        for k in range(7):
            out[i, k] = f1[k]
            out[i, 7 + k] = f2[k]
        out[i, 14:18] = d[4:8]
        out[i, 18] = th2d
        out[i, 19] = v3
        if HAS_GUIDE or MOTOR:
            out[i, 20] = _force(t[i], yi, p, s1, c1)
        else:
            th1 = p[P_TH10] + p[P_OMEGA] * t[i]
            out[i, 20] = _force(t[i], yi, p, math.sin(th1), math.cos(th1))
        if HAS_GUIDE:
            fx, fy, mz, _, elastic = _guide(yi, p, v3)
            out[i, OBS_GUIDE] = d[GY + 2]
            out[i, OBS_GUIDE + 1] = fx
            out[i, OBS_GUIDE + 2] = fy
            out[i, OBS_GUIDE + 3] = mz
            for k in range(4):
                fk = guide_corner(k, yi, p, GO, GY, v3)
                out[i, OBS_GUIDE + 4 if k < 2 else OBS_GUIDE + 5] += fk[5]
                if fk[5] > 0.0:
                    out[i, OBS_GUIDE + 6] += 1.0
            out[i, OBS_GUIDE + 7] = elastic
            out[i, OBS_GUIDE + 8] = d[GY + 3]
        if MOTOR:
            out[i, OBS_CRANK] = yi[M]
            out[i, OBS_CRANK + 1] = yi[M + 1]
            out[i, OBS_CRANK + 2] = d[M + 1]
    return out
