"""Template of a machine's kernels whose throws have contact-impact (or lubricated) crank pins,
the crank turning at a prescribed speed.

Written per configuration like `prescribed` (the module docstring there): this file verbatim,
the block between the ``<bindings>`` markers replaced by the configuration's names and
constants. As it stands the block binds the reference configuration: one throw of the paper's
compressor with a worn crank pin, the module of which is the template `contact` itself.

Each throw is one joints' configuration (template `contact`: the module of its pins, its load
and its laws, the same for every throw of a machine) whose kernels read the throw's own slice
of the state and of the parameter vector: the template passes them views, ``y[s:s + n]``,
``p[o:o + m]``, ``out[s:s + n]`` (no copy, nothing allocated), so the joints' compiled parts
read a throw's slice as they read a one-throw model's vector. Each throw's slice holds its
own crank angle at ``t = 0`` (the shaft's plus its phase): with the crank prescribed the throws
do not interact, the right-hand side is the throws' side by side and the Jacobian is
block-diagonal (each block the throw's own, the complex step where the throw has it).

Roles (each a compiled function of the throw's module, called on the throw's views):
``throw_rhs(t, y, p, out)``, ``throw_jac(t, y, p, J)``, ``throw_event(t, y, p)``,
``throw_reset(t, y, p, out)``.

Constants: ``N_THROWS``; per throw ``k`` its first state ``THROW_STATE[k]`` and state count
``THROW_N[k]``, the offset of its slice ``THROW_PARAMS[k]`` and its length ``THROW_NP[k]``;
``OWN_EVENT``: the throws' own event functions are phased (they fall through 0 at an onset
*and* a separation, `recipdyn.model.joints.pins.phased_factor`: with a load with states, both
pins worn, or the guide's clearance) or there is one throw; else the machine's event is the
smallest of the throws' phased contact factors (``CFG``: the joints' configuration code, a
literal), since an onset factor alone (``|e| - c``) is negative in contact and would hide
the other throws' onsets in a minimum.

With a motor (``MOTOR``) each throw's module is its joints' configuration with the crank free
(template `contact`, the crank's angle, speed and work the last three states of its slice at
``THROW_CRANK[k]``: its own angle, the shaft's plus its phase, and the shaft's speed). A machine of
one throw is then the one-throw module itself. With several (``SHARED``) each throw's slice
holds its own crank's inertia (``J1 + m1 rs^2``, at ``THROW_CO``, the drive's left out) and
the throws share the crank's acceleration: with a worn crank pin the crank and the rod are
bodies apart, joined by the pin's force, which depends on the states only, so the throw's
crank equation ``I_k alpha_k = T + tau_k`` (its module's, at the torque ``T`` of its torque
law's slice ``THROW_TORQUE[k]``) gives the torque ``tau_k = I_k alpha_k - T`` the rod, the joint and
the crank's weight put on its crank, and the crank turns as

    alpha = (T_m + sum_k tau_k) / (J_drive + sum_k I_k)

(``T_m`` the motor's torque, ``torque`` at the shaft's slice ``SHAFT``: ``J_drive`` then the
torque law's). The rod's big end's acceleration ``B'' = A''(alpha) + e1''`` does not depend on
the crank's (the rod moves under the pin's force), so each throw's crank-pin eccentricity's
acceleration is its own less the crank pin's change, ``e1'' += r (sin, -cos)(theta) (alpha -
alpha_k)``, its other states' unchanged. With an ideal crank pin (``CFG`` 1 or 3: a worn
crosshead pin, the guide's clearance) the rod turns with the crank: the throw's share of the
crank's inertia adds the Schur complement of its rod's and crosshead's mass matrix,
``I_k = J1 + m1 rs^2 + m00 - m_0r M_rr^-1 m_r0``, its torque is ``I_k alpha_k - T``, and its
other accelerations fall by ``k = M_rr^-1 m_r0`` per unit of the crank's
(`recipdyn.model.joints.pins.ideal_share`). The throw's work integrals then hold the shaft's
torque on its crank, ``T_k = T + I_k (alpha - alpha_k)``; the motor's work is the last state,
``W_MOTOR``. The Jacobian: fourth-order central differences of the whole right-hand side, the
steps ``1e-5 max(|y_i|, s_i)``, the scales ``s_i`` in the parameter vector at ``SCALE``.
A held rotor (``HELD``): the crank's acceleration 0, the motor's torque ``-sum_k tau_k``.

Throws of another kind (``HAS_LINK``; ``THROW_KIND[k]`` 1): an ideal throw is its one-throw
module of the massless link (template `prescribed` or `motor`, rc = 0), whose ``rhs``,
``jac``, ``event`` and ``reset`` are bound as ``link_rhs``, ... and called on the throw's
views as a contact throw's are (its events: its load's, ``LINK_EVENTS``, or none). Its crank
angle's offset in its slice and its torque law's are ``THROW_CRANK[k]`` and
``THROW_TORQUE[k]`` (a contact throw's: its module's ``M``, ``MO``). With a motor its module
turns its own crank at ``alpha_k = (T + Q) / I`` (its drive's inertia 0), ``link_share`` (the
motor template's ``share``) gives its ``(I, k)``, and the crank's composition treats it as a
contact throw: ``tau_k = I alpha_k - T``, its clearance angle's acceleration moved by ``-k
(alpha - alpha_k)``. Without ideal throws the ``link_*`` roles are bound to ``absent`` in
branches on ``HAS_LINK`` that numba removes.

A frame on its mounts (``FRAME``; `recipdyn.model.frame`): after the throws' derivatives (and
the shaft's), each contact throw's shaking force from its states and its pins' accelerations
(`recipdyn.model.joints.pins.contact_shaking`; its crank's angle, speed and acceleration the
prescribed ones or its slice's; its crank's static moment ``m1 rs`` at ``FRAME_CRANKS + k``)
is taken by the frame (`recipdyn.model.frame.kernels`: ``throw_load``, ``frame_rhs``; its slice
``FRAME_PARAMS``, its states ``FRAME_STATE``, its work integrals ``FRAME_WORK``). One-way: no
throw reads the frame's states, so the throws' Jacobian is unchanged and the frame's rows are
central differences of the whole right-hand side (`_frame_rows`). Without a frame the
branches on ``FRAME`` are removed.

Interstage volumes (``INTERSTAGE``; `recipdyn.model.components.interstage`): each throw's
module runs its load between the set lines of its own slice; after every throw's call, a
throw whose suction is fed by an interstage (``THROW_IN[k]``) or whose discharge delivers
into one (``THROW_OUT[k]``) has its load's derivatives written again by ``load_rhs_lines``
(the load's ``state_rhs_lines``) at the volume's pressure and the cooler's temperature
(``interstage_line``), the other line its slice's (``load_lines``), its crosshead's place
and speed from its states (a contact throw's pins' kinematics, an ideal throw's
``link_crosshead``), its load's first state, first counter and slice at ``CONTACT_LOAD`` or
``LINK_LOAD`` (offsets in its slice: its module's). Each volume's pressure rate then comes
from its stages' counters' rates (``load_flows``, ``interstage_rate``), at ``IS_STATE[i]``,
its slice at ``IS_PARAM[i]``. The gas force reads the chambers' states only, so the throws'
mechanisms are as before; the volumes couple the throws, so the Jacobian is then the central
differences of the whole right-hand side (`_fd_jac`, an interstage's pressure's scale its
slice's at ``SCALE``). Without one the branches on ``INTERSTAGE`` are removed.

A torsionally flexible shaft (``TORSION``; `recipdyn.model.shaft.flexible`): the crank is a
chain of ``N_NODES`` nodes, the motor's rotor and the flywheel (states ``NODE_ANGLE[0]``,
``NODE_ANGLE[1]``, in the shaft's part) and each throw's crank in the order along the shaft
(``NODE_THROW[j]``: its crank's angle and speed in its slice, at ``THROW_CRANK``). Each
throw's module turns its own crank on a torque of 0 (as under a held rotor), so its crank
equation ``I_k alpha_k = tau_k`` gives its own acceleration; its node's equation adds the
sections' torques, ``I_k alpha = tau_k + T_(j-1) - T_j``, so its crank turns ``(T_(j-1) -
T_j) / I_k`` faster and its other accelerations are corrected as on the rigid shaft
(`_correct`). A section's twist is its nodes' angles less their phases (``NODE_PHASES + j``:
a throw's slice holds its own angle, its node's plus its phase); its torque ``k twist + c
twist'`` (slice ``TORSION_PARAMS``: ``J_motor``, the flywheel's inertia, then per section
``(k, c)``); the rotor turns under the motor's torque law (``motor_torque`` at ``SHAFT + 1``),
the sections' dissipation is the state ``SHAFT_DAMPING``. Without it the branches on
``TORSION`` are removed.
"""

import math

import numba as nb
import numpy as np

from recipdyn.model.base import EVENT_SIGNATURE, JAC_SIGNATURE, RHS_SIGNATURE, compiled
from recipdyn.model.frame.kernels import frame_rhs, throw_load
from recipdyn.model.joints.pins import (
    G_GUIDE,
    I_WIN,
    P_L,
    P_OMEGA,
    P_R,
    P_TH10,
    _flip,
    _kinematics_at,
    contact_factor,
    contact_shaking,
    ideal_share,
)
from recipdyn.model.mechanism.link_kernels import crosshead as link_crosshead
from recipdyn.model.mechanism.link_kernels import shaking as link_shaking

# isort: split
# <bindings>
from recipdyn.model.assembler.generate import absent as interstage_line
from recipdyn.model.assembler.generate import absent as interstage_rate
from recipdyn.model.assembler.generate import absent as link_crank
from recipdyn.model.assembler.generate import absent as link_event
from recipdyn.model.assembler.generate import absent as link_jac
from recipdyn.model.assembler.generate import absent as link_reset
from recipdyn.model.assembler.generate import absent as link_rhs
from recipdyn.model.assembler.generate import absent as link_share
from recipdyn.model.assembler.generate import absent as load_flows
from recipdyn.model.assembler.generate import absent as load_lines
from recipdyn.model.assembler.generate import absent as load_rhs_lines
from recipdyn.model.assembler.generate import absent as motor_torque
from recipdyn.model.assembler.generate import absent as torque
from recipdyn.model.assembler.templates.contact import event as throw_event
from recipdyn.model.assembler.templates.contact import jac as throw_jac
from recipdyn.model.assembler.templates.contact import reset as throw_reset
from recipdyn.model.assembler.templates.contact import rhs as throw_rhs

CFG = 0
CONTACT_LOAD = np.array([12, 12, 31], dtype=np.int64)
FRAME = False
FRAME_CRANKS = np.int64(0)
FRAME_PARAMS = np.int64(0)
FRAME_STATE = np.int64(0)
FRAME_WORK = np.int64(0)
HAS_GUIDE = False
HAS_LINK = False
HELD = False
INTERSTAGE = False
IS_PARAM = np.array([-1], dtype=np.int64)
IS_STATE = np.array([-1], dtype=np.int64)
LINK_EVENTS = False
LINK_LOAD = np.array([0, 0, 0], dtype=np.int64)
LINK_MECH = np.int64(0)
LINK_PHASE = np.int64(0)
LINK_SHAFT = np.int64(0)
MOTOR = False
N_INTERSTAGES = np.int64(0)
N_NODES = np.int64(1)
NODE_ANGLE = np.array([0], dtype=np.int64)
NODE_PHASES = np.int64(0)
NODE_THROW = np.array([-1], dtype=np.int64)
N_THROWS = np.int64(1)
OWN_EVENT = True
SCALE = np.int64(33)
SHAFT = np.int64(33)
SHAFT_DAMPING = np.int64(0)
SHARED = False
THROW_CO = np.int64(31)
THROW_CRANK = np.array([12], dtype=np.int64)
THROW_IN = np.array([-1], dtype=np.int64)
THROW_KIND = np.array([0], dtype=np.int64)
THROW_N = np.array([12], dtype=np.int64)
THROW_NP = np.array([33], dtype=np.int64)
THROW_OUT = np.array([-1], dtype=np.int64)
THROW_PARAMS = np.array([0], dtype=np.int64)
THROW_STATE = np.array([0], dtype=np.int64)
THROW_TORQUE = np.array([33], dtype=np.int64)
TORSION = False
TORSION_PARAMS = np.int64(0)
W_MOTOR = np.int64(12)
# </bindings>


#: The throws' rods turn with their cranks (an ideal crank pin).
IDEAL_CRANK = CFG == 1 or CFG == 3


@nb.njit(cache=True)
def _share(y, p, k):
    """Contact throw ``k``'s share of the crank's inertia beyond its crank's own, and ``k`` of
    its other accelerations (`recipdyn.model.joints.pins.ideal_share`); none with a worn
    crank pin."""
    if IDEAL_CRANK:
        s, n, o, m = THROW_STATE[k], THROW_N[k], THROW_PARAMS[k], THROW_NP[k]
        return ideal_share(y[s : s + n], p[o : o + m], CFG, HAS_GUIDE, THROW_CRANK[k], G_GUIDE)
    return 0.0, 0.0, 0.0, 0.0


@nb.njit(cache=True)
def _is_link(k):
    """Whether throw ``k`` is an ideal (link family) throw (``THROW_KIND`` 1)."""
    return HAS_LINK and THROW_KIND[k] == 1


@nb.njit(cache=True)
def _inertia(y, p, k):
    """Throw ``k``'s share of the crank's inertia and the coefficients of its accelerations
    on the crank's: a contact throw's crank's own (at ``THROW_CO``) and its rod's with an
    ideal crank pin (`_share`); an ideal throw's ``(I, k)`` of its equations (its module's
    ``share``: the massless link's ``free_contribution``)."""
    if HAS_LINK:
        if THROW_KIND[k] == 1:
            s, n, o, m = THROW_STATE[k], THROW_N[k], THROW_PARAMS[k], THROW_NP[k]
            i_k, c_k = link_share(y[s : s + n], p[o : o + m], 0)
            return i_k, c_k, 0.0, 0.0
    share = _share(y, p, k)
    return p[THROW_PARAMS[k] + THROW_CO] + share[0], share[1], share[2], share[3]


@nb.njit(cache=True)
def _correct(y, p, out, k, share, da):
    """Throw ``k``'s own accelerations moved from its crank's acceleration at its own torque
    alone to the shaft's, ``da`` more (module docstring)."""
    s, o = THROW_STATE[k], THROW_PARAMS[k]
    if _is_link(k):  # its clearance angle's: theta_c'' = c - k alpha
        out[s + 1] -= share[1] * da
    elif CFG == 3:  # the guide's lateral position alone
        out[s + G_GUIDE + 2] -= share[1] * da
    elif CFG == 1:  # the crosshead pin (and the guide's lateral position)
        out[s + 6] -= share[1] * da
        out[s + 7] -= share[2] * da
        if HAS_GUIDE:
            out[s + G_GUIDE + 2] -= share[3] * da
    else:  # the crank pin's eccentricity: the rod's big end does not depend on alpha
        th = y[s + THROW_CRANK[k]]
        r = p[o + P_R]
        out[s + 4] += r * math.sin(th) * da
        out[s + 5] -= r * math.cos(th) * da


@nb.njit(cache=True)
def _shaft(y, p, out):
    """With a motor and several throws: the crank's acceleration from the throws' torques on
    their cranks, and each throw's derivatives at it (module docstring); ``out`` holds each
    throw's own derivatives at its own crank acceleration on entry."""
    w = y[THROW_STATE[0] + THROW_CRANK[0] + 1]
    tm = 0.0 if HELD else torque(w, p, SHAFT + 1)
    num = tm
    den = p[SHAFT]
    for k in range(N_THROWS):
        s, o, c = THROW_STATE[k], THROW_PARAMS[k], THROW_CRANK[k]
        share = _inertia(y, p, k)
        ic = share[0]
        num += ic * out[s + c + 1] - torque(w, p, o + THROW_TORQUE[k])
        den += ic
        if _is_link(k):  # its share held in its crank's rate and work slots until below
            out[s + c] = ic
            out[s + c + 2] = share[1]
    if HELD:  # the rotor's torque is the one that holds its speed: the throws' sum's opposite
        tm = -num
        alpha = 0.0
    else:
        alpha = num / den
    for k in range(N_THROWS):
        s, o, c = THROW_STATE[k], THROW_PARAMS[k], THROW_CRANK[k]
        if _is_link(k):  # (its share, held above; its crank's rate back: the speed)
            share = (out[s + c], out[s + c + 2], 0.0, 0.0)
            out[s + c] = y[s + c + 1]
        else:
            share = _inertia(y, p, k)
        ic = share[0]
        da = alpha - out[s + c + 1]
        _correct(y, p, out, k, share, da)
        tk = torque(w, p, o + THROW_TORQUE[k]) + ic * da  # the shaft's torque on its crank
        if not _is_link(k):  # (the joint's work integral holds the shaft's work on it)
            out[s + I_WIN] += ic * da * w
        out[s + c + 1] = alpha
        out[s + c + 2] = tk * w
    out[W_MOTOR] = tm * w


@nb.njit(cache=True)
def _rhs(t, y, p, out):
    for k in range(N_THROWS):
        s, n, o, m = THROW_STATE[k], THROW_N[k], THROW_PARAMS[k], THROW_NP[k]
        if HAS_LINK:
            if THROW_KIND[k] == 1:
                link_rhs(t, y[s : s + n], p[o : o + m], out[s : s + n])
                continue
        throw_rhs(t, y[s : s + n], p[o : o + m], out[s : s + n])
    if INTERSTAGE:
        _interstages(t, y, p, out)
    if SHARED:
        if TORSION:
            _torsion(y, p, out)
        else:
            _shaft(y, p, out)
    if FRAME:
        _frame(t, y, p, out)


@nb.njit(cache=True)
def _torsion(y, p, out):
    """On a flexible shaft: each node's acceleration from its torques (module docstring);
    ``out`` holds each throw's own derivatives at its own crank's acceleration under a torque
    of 0 on entry."""
    o = TORSION_PARAMS
    rotor = NODE_ANGLE[0]
    tm = motor_torque(y[rotor + 1], p, SHAFT + 1)
    loss = 0.0
    upstream = 0.0  # the torque of the section before node j
    for j in range(N_NODES):
        a = NODE_ANGLE[j]
        torque_j = 0.0
        if j < N_NODES - 1:
            b = NODE_ANGLE[j + 1]
            twist = (y[a] - p[NODE_PHASES + j]) - (y[b] - p[NODE_PHASES + j + 1])
            rate = y[a + 1] - y[b + 1]
            kk, cc = p[o + 2 + 2 * j], p[o + 3 + 2 * j]
            torque_j = kk * twist + cc * rate
            loss += cc * rate * rate
        net = upstream - torque_j
        upstream = torque_j
        if j < 2:  # the rotor (the motor's torque on it) and the flywheel
            out[a] = y[a + 1]
            out[a + 1] = (net + (tm if j == 0 else 0.0)) / p[o + j]
            continue
        k = NODE_THROW[j]
        s, c = THROW_STATE[k], THROW_CRANK[k]
        share = _inertia(y, p, k)
        da = net / share[0]
        _correct(y, p, out, k, share, da)
        w = y[s + c + 1]
        if not _is_link(k):  # (the joint's work integral holds the shaft's work on it)
            out[s + I_WIN] += net * w
        out[s + c + 1] += da
        out[s + c + 2] = net * w
    out[W_MOTOR] = tm * y[rotor + 1]
    out[SHAFT_DAMPING] = loss


@nb.njit(cache=True)
def _crank(t, y, p, k):
    """Throw ``k``'s crank angle and speed: its slice's (a motor), an ideal throw's module's
    (the shaft's: its phase is added by the caller), or a contact throw's prescribed ones."""
    s, n, o, m = THROW_STATE[k], THROW_N[k], THROW_PARAMS[k], THROW_NP[k]
    if MOTOR:
        c = THROW_CRANK[k]
        return y[s + c], y[s + c + 1]
    if _is_link(k):
        if HAS_LINK:
            return link_crank(t, y[s : s + n], p[o : o + m], LINK_SHAFT)
    w = p[o + P_OMEGA]
    return p[o + P_TH10] + w * t, w


@nb.njit(cache=True)
def _crosshead(t, y, p, k):
    """Throw ``k``'s crosshead's place and speed along its stroke, from its states: a contact
    throw's big end moved by its crank pin's eccentricity and its small end by its crosshead
    pin's (`recipdyn.model.joints.pins`; an ideal guide), an ideal throw's massless link's."""
    s, o = THROW_STATE[k], THROW_PARAMS[k]
    th, w = _crank(t, y, p, k)
    if _is_link(k):
        if HAS_LINK:
            return link_crosshead(th + p[o + LINK_PHASE], y[s], w, y[s + 1], p, o + LINK_MECH)
    _, c2, _, v3, _, _ = _kinematics_at(th, w, p[o:], y[s], y[s + 1], y[s + 4], y[s + 5],
                                        y[s + 2], y[s + 3], y[s + 6], y[s + 7])  # fmt: skip
    return p[o + P_R] * math.cos(th) + y[s] + p[o + P_L] * c2 - y[s + 2], v3


@nb.njit(cache=True)
def _load_offsets(k):
    """Throw ``k``'s load's first state, first counter and slice (in its slice: its
    module's)."""
    if _is_link(k):
        return LINK_LOAD[0], LINK_LOAD[1], LINK_LOAD[2]
    return CONTACT_LOAD[0], CONTACT_LOAD[1], CONTACT_LOAD[2]


@nb.njit(cache=True)
def _interstages(t, y, p, out):
    """Each throw joined to an interstage volume: its load's derivatives again between the
    volume's line and its slice's other line; then each volume's pressure rate from its
    stages' counters' rates (module docstring)."""
    for k in range(N_THROWS):
        i, j = THROW_IN[k], THROW_OUT[k]
        if i < 0 and j < 0:
            continue
        s, n, o, m = THROW_STATE[k], THROW_N[k], THROW_PARAMS[k], THROW_NP[k]
        g, a, lo = _load_offsets(k)
        pk = p[o : o + m]
        ps, ts, pd, td = load_lines(pk, lo)
        if i >= 0:
            ps, ts = interstage_line(y, IS_STATE[i], p, IS_PARAM[i])
        if j >= 0:
            pd, td = interstage_line(y, IS_STATE[j], p, IS_PARAM[j])
        x, v = _crosshead(t, y, p, k)
        load_rhs_lines(x, v, y[s : s + n], g, a, pk, lo, ps, ts, pd, td, out[s : s + n])
    for i in range(N_INTERSTAGES):
        mdot = 0.0
        for k in range(N_THROWS):
            a = THROW_STATE[k] + _load_offsets(k)[1]
            if THROW_OUT[k] == i:
                mdot += load_flows(out, a)[1]
            if THROW_IN[k] == i:
                mdot -= load_flows(out, a)[0]
        out[IS_STATE[i]] = interstage_rate(mdot, p, IS_PARAM[i])


@nb.njit(cache=True)
def _frame(t, y, p, out):
    """The frame's derivatives: every throw's shaking force (`contact_shaking`, from its
    states and its pins' accelerations already in ``out``; its crank's static moment at
    ``FRAME_CRANKS + k``) as generalised forces on the frame (one-way: no throw reads the
    frame's states)."""
    qx = 0.0
    qpsi = 0.0
    for k in range(N_THROWS):
        s, n, o, m = THROW_STATE[k], THROW_N[k], THROW_PARAMS[k], THROW_NP[k]
        pk = p[o : o + m]
        if MOTOR:  # its own crank's angle, the shaft's speed and acceleration
            c = THROW_CRANK[k]
            th, w, a = y[s + c], y[s + c + 1], out[s + c + 1]
        else:
            w = pk[P_OMEGA]
            th, a = pk[P_TH10] + w * t, 0.0
        if HAS_LINK:  # (pruned without ideal throws: their roles are absent then)
            if THROW_KIND[k] == 1:
                fx, fy = _link_shaking(t, y[s : s + n], pk, out[s : s + n], THROW_CRANK[k])
            else:
                fx, fy = contact_shaking(th, w, a, y[s : s + n], out[s : s + n], pk,
                                         p[FRAME_CRANKS + k])  # fmt: skip
        else:
            fx, fy = contact_shaking(th, w, a, y[s : s + n], out[s : s + n], pk,
                                     p[FRAME_CRANKS + k])  # fmt: skip
        gx, gpsi = throw_load(k, fx, fy, p, FRAME_PARAMS)
        qx += gx
        qpsi += gpsi
    frame_rhs(qx, qpsi, y, FRAME_STATE, FRAME_WORK, p, FRAME_PARAMS, out)


@nb.njit(cache=True)
def _link_shaking(t, y, p, out, c):
    """An ideal throw's shaking force in its own axes (`recipdyn.model.mechanism.link_kernels`
    ``shaking``) on its views: its crank's angle its module's (``link_crank`` at its drive's
    slice ``LINK_SHAFT``, or with a motor its slice's at ``c``) plus its module's phase (at
    ``LINK_PHASE``), its clearance angle's states and acceleration (``out[1]``, at the
    shaft's acceleration), its mechanism's slice at ``LINK_MECH``."""
    if MOTOR:
        th, w, a = y[c], y[c + 1], out[c + 1]
    else:
        th, w = link_crank(t, y, p, LINK_SHAFT)
        a = 0.0
    return link_shaking(th + p[LINK_PHASE], y[0], w, y[1], a, out[1], p, LINK_MECH)


@compiled(RHS_SIGNATURE)
def rhs(t, y, p, out):
    _rhs(t, y, p, out)


@nb.njit(cache=True)
def _fd_jac(t, y, p, J):
    """Fourth-order central differences of the whole right-hand side (truncation O(h^4)),
    steps ``1e-5 max(|y_i|, s_i)`` (the scales at ``SCALE``: each throw's own module's)."""
    _fd_rows(t, y, p, J, np.arange(y.shape[0]))


@nb.njit(cache=True)
def _fd_rows(t, y, p, J, rows):
    """The ``rows`` of ``J`` by the central differences of `_fd_jac`, the rest left as it
    is."""
    n = y.shape[0]
    yp = y.copy()
    f = np.empty((4, n))
    for k in range(n):
        h = 1e-5 * max(abs(y[k]), p[SCALE + k])
        for m, step in enumerate((h, -h, 2.0 * h, -2.0 * h)):
            yp[k] = y[k] + step
            _rhs(t, yp, p, f[m])
        yp[k] = y[k]
        for i in rows:
            J[i, k] = (8.0 * (f[0, i] - f[1, i]) - (f[2, i] - f[3, i])) / (12.0 * h)


@compiled(JAC_SIGNATURE, allocates=True)
def jac(t, y, p, J):
    """Block-diagonal: each throw's own Jacobian (its module's ``jac``) on its states; the
    throws do not interact with the crank prescribed (or with one throw). With a motor and
    several throws, which share the crank's acceleration, or with interstage volumes, which
    join the throws' loads: central differences of the whole right-hand side (`_fd_jac`)."""
    if SHARED or INTERSTAGE:
        _fd_jac(t, y, p, J)
        return
    for i in range(y.shape[0]):
        for j in range(y.shape[0]):
            J[i, j] = 0.0
    for k in range(N_THROWS):
        s, n, o, m = THROW_STATE[k], THROW_N[k], THROW_PARAMS[k], THROW_NP[k]
        block = np.zeros((n, n))
        if _is_link(k):
            if HAS_LINK:
                link_jac(t, y[s : s + n], p[o : o + m], block)
        else:
            throw_jac(t, y[s : s + n], p[o : o + m], block)
        for i in range(n):
            for j in range(n):
                J[s + i, s + j] = block[i, j]
    if FRAME:  # its rows over every column (the throws' rows do not read the frame's states)
        _frame_rows(t, y, p, J)


@nb.njit(cache=True)
def _frame_rows(t, y, p, J):
    """The frame's rows (its states and work integrals) by the fourth-order central
    differences of `_fd_jac` (its steps), the rest of ``J`` left as it is."""
    rows = np.concatenate((np.arange(FRAME_STATE, FRAME_STATE + 6),
                           np.arange(FRAME_WORK, FRAME_WORK + 2)))  # fmt: skip
    _fd_rows(t, y, p, J, rows)


@nb.njit(cache=True)
def _factor(t, y, p, k):
    """Throw ``k``'s event factor (positive between its events)."""
    s, n, o, m = THROW_STATE[k], THROW_N[k], THROW_PARAMS[k], THROW_NP[k]
    if HAS_LINK:
        if THROW_KIND[k] == 1:  # its load's events (the dynamic valves), or none
            if LINK_EVENTS:
                return link_event(t, y[s : s + n], p[o : o + m])
            return np.inf
    if OWN_EVENT:
        return throw_event(t, y[s : s + n], p[o : o + m])
    return contact_factor(y[s : s + n], p[o : o + m], CFG)[0]


@compiled(EVENT_SIGNATURE)
def event(t, y, p):
    """The smallest of the throws' event factors."""
    low = np.inf
    for k in range(N_THROWS):
        low = min(low, _factor(t, y, p, k))
    return low


@compiled(RHS_SIGNATURE)
def reset(t, y, p, out):
    """The reset of every throw whose factor is the smallest (at the event) or below 0: two
    throws whose events coincide (identical throws in phase) change phase together; reset
    one by one, the other's factor would stay below 0 after the first reset and the event
    function, their minimum, would never cross 0 again. The other throws' states
    unchanged."""
    low = np.inf
    for k in range(N_THROWS):
        low = min(low, _factor(t, y, p, k))
    for i in range(y.shape[0]):
        out[i] = y[i]
    for k in range(N_THROWS):
        if _factor(t, y, p, k) > max(low, 0.0):
            continue
        s, n, o, m = THROW_STATE[k], THROW_N[k], THROW_PARAMS[k], THROW_NP[k]
        if HAS_LINK:
            if THROW_KIND[k] == 1:
                if LINK_EVENTS:
                    link_reset(t, y[s : s + n], p[o : o + m], out[s : s + n])
                continue
        if OWN_EVENT:
            throw_reset(t, y[s : s + n], p[o : o + m], out[s : s + n])
        else:
            yk = y[s : s + n]
            pk = p[o : o + m]
            _flip(yk, contact_factor(yk, pk, CFG)[1], pk, out[s : s + n])
