"""Template of a machine's kernels with the crank free, driven by a motor.

Written per configuration like `prescribed` (the module docstring there): this file verbatim,
the block between the ``<bindings>`` markers replaced by the configuration's names and
constants. As it stands the block binds the reference configuration: one throw of the paper's
compressor on the induction motor.

The crank angle and speed are states (``y[CRANK]``, ``y[CRANK + 1]``), the motor's work
``y[MOTOR_WORK]``, and each throw's gas work ``y[THROW_WORK[k]]``. The throws share the crank:
each one's equations ``M (theta1'', theta_c'') = b`` give its clearance angle's
acceleration affine in the crank's, ``theta_c'' = c - k theta1''``, and with it the throw's
share ``(I, Q)`` of the crank's equation (``free_contribution``), so the crank's acceleration
is ``theta1'' = (T_m + sum Q) / (J_drive + sum I)`` without a derivation of the whole machine.

A held rotor (``HELD``, the torque law ``held``, `recipdyn.model.components.drive`) has no
torque law: its torque is the one that keeps its speed, the throws' shares' (their sum with
the sign turned) on a rigid shaft, the coupling's on a flexible one, so its acceleration is
0 exactly and ``MOTOR_WORK`` integrates that torque.

Roles: ``torque(omega1, p, o)`` (the motor's torque law), ``free_contribution(th1, thc, w,
thcd, F, p, m) -> (I, Q, k, c)``, ``crosshead``, ``crank_torque``, and the loads' roles as in
`prescribed` (with interstage volumes, theirs too).
Constants: ``CRANK``, ``SHAFT`` (the offset of ``J_drive``), ``MOTOR`` (the torque law's
slice), ``THROW_WORK``, ``STEP_KIND`` (per state: how the Jacobian's central differences
step it: ``0`` an angle, absolute 1e-4; ``1`` a rate, 1e-4 max(1, |y|); ``2`` a load's
state, by the load's own differences ``1e-7 (|y| (1 + rel) + abs)`` with ``(rel, abs)`` at
``p[STEP_AT[i]]`` (its slice of steps, as in `prescribed`; an interstage's pressure, whose
``STEP_AT`` is ``-1``: 1e-7 max(|y|, 1e-3)); ``3`` a column left 0, a work integral or a
counter nothing depends on), and the throws', the loads' and the interstage volumes' as in
`prescribed`; a frame on its mounts (``FRAME``) as in `prescribed`, shaken by the throws at
the crank's acceleration; ``MOTOR_WORK`` (the motor's work's state).

A torsionally flexible shaft (``TORSION``, `recipdyn.model.shaft.flexible`): the crank's
states are the rotor's, followed by the other ``N_NODES - 1`` nodes' angles and speeds (the
flywheel, then the throws along the shaft); each throw's crank turns with its node
(``THROW_NODE[k]``: its angle's state) and its share ``(I, Q)`` goes to its node's equation
instead of the one crank's; the role ``shaft_nodes`` gives the nodes' accelerations from
their shares, the motor's torque and the sections' springs (its slice ``TORSION_PARAMS``, its
dissipation's state ``SHAFT_DAMPING``), ``shaft_section`` a section's twist and torque (the
observer's columns from ``OBS_SECTION``). Without it (``TORSION`` False) the branches are
pruned and the module computes what it did before, to the bit.
"""

import numba as nb
import numpy as np

from recipdyn.model.base import EVENT_SIGNATURE, JAC_SIGNATURE, RHS_SIGNATURE, compiled

# isort: split
# <bindings>
from recipdyn.model.assembler.generate import absent as frame_load
from recipdyn.model.assembler.generate import absent as frame_rhs
from recipdyn.model.assembler.generate import absent as interstage_line
from recipdyn.model.assembler.generate import absent as interstage_rate
from recipdyn.model.assembler.generate import absent as load_event
from recipdyn.model.assembler.generate import absent as load_flows
from recipdyn.model.assembler.generate import absent as load_lines
from recipdyn.model.assembler.generate import absent as load_reset
from recipdyn.model.assembler.generate import absent as load_rhs
from recipdyn.model.assembler.generate import absent as load_rhs_lines
from recipdyn.model.assembler.generate import absent as load_state_force
from recipdyn.model.assembler.generate import absent as shaft_nodes
from recipdyn.model.assembler.generate import absent as shaft_section
from recipdyn.model.assembler.generate import absent as shaking
from recipdyn.model.components.drive_kernels import induction_torque as torque
from recipdyn.model.components.load import paper_force as load_force
from recipdyn.model.mechanism.link_kernels import crank_torque, crosshead, free_contribution

FRAME = False
FRAME_PARAMS = np.int64(0)
FRAME_STATE = np.int64(0)
FRAME_WORK = np.int64(0)
LOAD_STATES = False
N_THROWS = np.int64(1)
CRANK = np.int64(2)
SHAFT = np.int64(0)
MOTOR = np.int64(1)
MOTOR_WORK = np.int64(4)
HELD = False
TORSION = False
N_NODES = np.int64(1)
TORSION_PARAMS = np.int64(0)
SHAFT_DAMPING = np.int64(0)
THROW_NODE = np.array([2], dtype=np.int64)
OBS_SECTION = np.int64(0)
INTERSTAGE = False
N_INTERSTAGES = np.int64(0)
IS_STATE = np.array([-1], dtype=np.int64)
IS_PARAM = np.array([-1], dtype=np.int64)
THROW_IN = np.array([-1], dtype=np.int64)
THROW_OUT = np.array([-1], dtype=np.int64)
THROW_STATE = np.array([0], dtype=np.int64)
THROW_WORK = np.array([5], dtype=np.int64)
THROW_MECH = np.array([4], dtype=np.int64)
THROW_PHASE = np.array([16], dtype=np.int64)
THROW_LOAD = np.array([17], dtype=np.int64)
LOAD_STATE = np.array([6], dtype=np.int64)
LOAD_AUX = np.array([6], dtype=np.int64)
STEP_KIND = np.array([0, 1, 0, 1, 3, 3], dtype=np.int64)
STEP_AT = np.array([-1, -1, -1, -1, -1, -1], dtype=np.int64)
N_OBS = np.int64(5)
OBS_THROW = np.array([2], dtype=np.int64)
# </bindings>


@nb.njit(cache=True)
def _force(th1, y, p, k):
    """Throw ``k``'s gas force on its crosshead along +x."""
    if LOAD_STATES:
        return load_state_force(y, LOAD_STATE[k], p, THROW_LOAD[k])
    return load_force(th1, p, THROW_LOAD[k])


@nb.njit(cache=True)
def _load_rhs(x, v, y, p, k, out):
    """Throw ``k``'s load's derivatives, between its set lines or an interstage volume's."""
    g, a, o = LOAD_STATE[k], LOAD_AUX[k], THROW_LOAD[k]
    if INTERSTAGE:
        ps, ts, pd, td = load_lines(p, o)
        i, j = THROW_IN[k], THROW_OUT[k]
        if i >= 0:
            ps, ts = interstage_line(y, IS_STATE[i], p, IS_PARAM[i])
        if j >= 0:
            pd, td = interstage_line(y, IS_STATE[j], p, IS_PARAM[j])
        load_rhs_lines(x, v, y, g, a, p, o, ps, ts, pd, td, out)
    else:
        load_rhs(x, v, y, g, a, p, o, out)


@nb.njit(cache=True)
def _interstages(p, out):
    """Each interstage volume's pressure rate from the flows its stages' loads delivered into
    ``out`` (after every throw's)."""
    for i in range(N_INTERSTAGES):
        mdot = 0.0
        for k in range(N_THROWS):
            if THROW_OUT[k] == i:
                mdot += load_flows(out, LOAD_AUX[k])[1]
            if THROW_IN[k] == i:
                mdot -= load_flows(out, LOAD_AUX[k])[0]
        out[IS_STATE[i]] = interstage_rate(mdot, p, IS_PARAM[i])


@nb.njit(cache=True)
def _crank(th1, w1, y, p, k):
    """Throw ``k``'s crank angle and speed: the crank's (``th1``, ``w1``) or, on a flexible
    shaft, its node's, with its phase."""
    if TORSION:
        n = THROW_NODE[k]
        return y[n] + p[THROW_PHASE[k]], y[n + 1]
    return th1 + p[THROW_PHASE[k]], w1


@nb.njit(cache=True)
def _alpha(f, k):
    """Throw ``k``'s crank's acceleration in the derivatives ``f``: the crank's or its
    node's."""
    if TORSION:
        return f[THROW_NODE[k] + 1]
    return f[CRANK + 1]


@nb.njit(cache=True)
def share(y, p, k):
    """Throw ``k``'s share of the crank's inertia ``I`` and the coefficient ``k`` of its
    clearance angle's acceleration on the crank's (``theta_c'' = c - k theta1''``,
    `free_contribution`): what a machine that hosts this module's throws beside others needs
    to turn their common crank (template `contact_throws`)."""
    s, m = THROW_STATE[k], THROW_MECH[k]
    thk, wk = _crank(y[CRANK], y[CRANK + 1], y, p, k)
    inertia, _, coef, _ = free_contribution(thk, y[s], wk, y[s + 1], _force(thk, y, p, k), p, m)
    return inertia, coef


@nb.njit(cache=True)
def _rhs(t, y, p, out):
    th1 = y[CRANK]
    w1 = y[CRANK + 1]
    if HELD:  # the rotor's torque is the one that holds its speed: found below
        Tm = 0.0
    else:
        Tm = torque(w1, p, MOTOR)
    inertia = p[SHAFT]
    load = Tm
    for k in range(N_THROWS):  # each throw's share of its crank's equation
        s, m = THROW_STATE[k], THROW_MECH[k]
        thk, wk = _crank(th1, w1, y, p, k)
        F = _force(thk, y, p, k)
        inertia_k, load_k, out[s], out[s + 1] = free_contribution(thk, y[s], wk, y[s + 1], F,
                                                                  p, m)  # fmt: skip
        if TORSION:  # (held at its node's place until the nodes' equations)
            out[THROW_NODE[k]] = inertia_k
            out[THROW_NODE[k] + 1] = load_k
        else:
            inertia += inertia_k
            load += load_k
        out[THROW_WORK[k]] = F  # (held here until the crosshead's speed is known)
    if TORSION:
        if HELD:  # the coupling's torque: the rotor's equation then gives it no acceleration
            Tm = shaft_section(y, CRANK, 0, p, TORSION_PARAMS)[2]
        shaft_nodes(Tm, N_NODES, y, CRANK, SHAFT_DAMPING, p, TORSION_PARAMS, out)
    else:
        if HELD:  # the torque the throws' shares ask: the crank does not accelerate
            Tm = -load
            load = 0.0
        out[CRANK] = w1
        out[CRANK + 1] = load / inertia
    out[MOTOR_WORK] = Tm * w1
    for k in range(N_THROWS):  # each throw's own accelerations, its gas work, its load
        s, m = THROW_STATE[k], THROW_MECH[k]
        thk, wk = _crank(th1, w1, y, p, k)
        out[s + 1] = out[s + 1] - out[s] * _alpha(out, k)
        out[s] = y[s + 1]
        x, v = crosshead(thk, y[s], wk, y[s + 1], p, m)
        out[THROW_WORK[k]] = out[THROW_WORK[k]] * v
        if LOAD_STATES:
            _load_rhs(x, v, y, p, k, out)
    if INTERSTAGE:
        _interstages(p, out)
    if FRAME:
        _frame(y, p, out)


@nb.njit(cache=True)
def _frame(y, p, out):
    """The frame's derivatives: every throw's shaking force, from its state and its
    clearance angle's acceleration already in ``out``, as generalised forces on the frame."""
    qx = 0.0
    qpsi = 0.0
    for k in range(N_THROWS):
        s, m = THROW_STATE[k], THROW_MECH[k]
        thk, wk = _crank(y[CRANK], y[CRANK + 1], y, p, k)
        fx, fy = shaking(thk, y[s], wk, y[s + 1], _alpha(out, k), out[s + 1], p, m)
        gx, gpsi = frame_load(k, fx, fy, p, FRAME_PARAMS)
        qx += gx
        qpsi += gpsi
    frame_rhs(qx, qpsi, y, FRAME_STATE, FRAME_WORK, p, FRAME_PARAMS, out)


@compiled(RHS_SIGNATURE)
def rhs(t, y, p, out):
    _rhs(t, y, p, out)


@compiled(JAC_SIGNATURE, allocates=True)
def jac(t, y, p, J):
    """Central differences with one Richardson step, (4 D(h/2) - D(h)) / 3: truncation
    O(h**4), rounding ~eps |f| / h, with each state's step by its kind (``STEP_KIND``): with
    |f| ~ 1e6 (theta_c'') rounding ~2e-6 and truncation ~1e-10 for the angles and rates; a
    load's states step by 1e-7 of their own scale (the load's ``steps``: its stops and
    regularised nozzles are not smooth everywhere, and a plate's velocity needs a step of its
    own size, not of its value's, which passes through 0). The work integrals' and counters'
    columns are 0 (nothing depends on them)."""
    n = y.shape[0]
    fp = np.empty(n)
    fm = np.empty(n)
    d1 = np.empty(n)
    yy = y.copy()
    for k in range(n):
        kind = STEP_KIND[k]
        if kind == 3:
            for i in range(n):
                J[i, k] = 0.0
            continue
        if kind == 0:
            h = 1e-4
        elif kind == 1:
            h = 1e-4 * max(1.0, abs(y[k]))
        elif STEP_AT[k] >= 0:
            a = STEP_AT[k]
            h = 1e-7 * (abs(y[k]) * (1.0 + p[a]) + p[a + 1])
        else:
            h = 1e-7 * max(abs(y[k]), 1e-3)
        for level in range(2):
            hk = h if level == 0 else 0.5 * h
            yy[k] = y[k] + hk
            _rhs(t, yy, p, fp)
            yy[k] = y[k] - hk
            _rhs(t, yy, p, fm)
            yy[k] = y[k]
            for i in range(n):
                dk = (fp[i] - fm[i]) / (2.0 * hk)
                if level == 0:
                    d1[i] = dk
                else:
                    J[i, k] = (4.0 * dk - d1[i]) / 3.0


@compiled(EVENT_SIGNATURE)
def event(t, y, p):
    """The smallest of the throws' load event factors (each positive between its events)."""
    low = np.inf
    for k in range(N_THROWS):
        low = min(low, load_event(y, LOAD_STATE[k], p, THROW_LOAD[k]))
    return low


@compiled(RHS_SIGNATURE)
def reset(t, y, p, out):
    """The reset of the throw whose load's event factor is the smallest (at the event)."""
    best, low = 0, np.inf
    for k in range(N_THROWS):
        e = load_event(y, LOAD_STATE[k], p, THROW_LOAD[k])
        if e < low:
            best, low = k, e
    load_reset(y, LOAD_STATE[best], p, THROW_LOAD[best], out)


@nb.njit(cache=True)
def observe(t, y, p):
    """The crank's angle and speed (columns 0, 1: on a flexible shaft the rotor's), then per
    throw its crank angle, its gas force and the torque the shaft applies to its crank
    (columns ``OBS_THROW[k]`` to ``+ 2``), then on a flexible shaft each section's twist and
    torque (from ``OBS_SECTION``), by the functions that were integrated."""
    out = np.empty((t.shape[0], N_OBS))
    f = np.empty(y.shape[1])
    for i in range(t.shape[0]):
        yi = y[i]
        _rhs(t[i], yi, p, f)
        th1 = yi[CRANK]
        w1 = yi[CRANK + 1]
        out[i, 0] = th1
        out[i, 1] = w1
        for k in range(N_THROWS):
            s, m, c = THROW_STATE[k], THROW_MECH[k], OBS_THROW[k]
            thk, wk = _crank(th1, w1, yi, p, k)
            F = _force(thk, yi, p, k)
            out[i, c] = thk
            out[i, c + 1] = F
            out[i, c + 2] = crank_torque(thk, yi[s], wk, yi[s + 1], f[s + 1], _alpha(f, k), F,
                                         p, m)  # fmt: skip
        if TORSION:
            for j in range(N_NODES - 1):
                twist, _, tq = shaft_section(yi, CRANK, j, p, TORSION_PARAMS)
                out[i, OBS_SECTION + 2 * j] = twist
                out[i, OBS_SECTION + 2 * j + 1] = tq
    return out
