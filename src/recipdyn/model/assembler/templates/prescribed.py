"""Template of a machine's kernels with the crank turning at a prescribed speed.

The assembler (`recipdyn.model.assembler.generate`) writes one module per configuration: this
file verbatim, with the block between the ``<bindings>`` markers replaced by the
configuration's own block of the same form — which component function plays each role
(imports) and the constants of its layout (offsets, counts). As it stands, the block binds the
reference configuration (one throw of the paper's compressor: the paper's load, the exact
equation), so this file is itself a valid module, linted and importable like any other.

Roles (each a compiled function of a component, called, not inlined):

* ``crank(t, y, p, o) -> (theta1, omega1)``: the shaft's crank angle and speed;
* ``throw_acc(th1, thc, thcd, F, w, p, m)``, ``throw_acc_jac(...)``: a throw's clearance
  angle acceleration (and its partial derivatives) at its crank angle ``th1``;
* ``crosshead(th1, thc, w, thcd, p, m) -> (x3, x3')``;
* ``crank_torque(th1, thc, w, thcd, thcdd, a1, F, p, m)``: the torque the shaft applies to a
  throw's crank (recorded per throw);
* ``load_force(th1, p, o)`` (a load without states), or ``load_state_force(y, g, p, o)``,
  ``load_rhs(x3, x3', y, g, a, p, o, out)``, ``load_event(y, g, p, o)``,
  ``load_reset(y, g, p, o, out)`` (a load with states; ``LOAD_STATES``). The roles a
  configuration lacks are bound to `recipdyn.model.assembler.generate.absent`, in branches
  numba removes before typing (``LOAD_STATES`` is a constant);
* with interstage volumes (``INTERSTAGE``): the load's ``load_rhs_lines(x3, x3', y, g, a, p,
  o, ps, ts, pd, td, out)``, ``load_lines(p, o)`` (its set lines) and ``load_flows(dy, a)``
  (its mass flows in and out), and the interstage's ``interstage_line(y, s, p, o) -> (p,
  T)`` and ``interstage_rate(mdot, p, o)`` (`recipdyn.model.components.interstage`).

Constants: ``N_THROWS``; per throw ``k`` the index of its first state ``THROW_STATE[k]`` and
the offsets of its mechanism, phase and load slices (``THROW_MECH``, ``THROW_PHASE``,
``THROW_LOAD``); its load's first state and first auxiliary state (``LOAD_STATE``,
``LOAD_AUX``), their counts (``LOAD_N``, ``LOAD_NAUX``) and the offset of its load's
difference steps (``LOAD_STEPS``: per state a relative and an absolute part); ``SHAFT``, the
offset of the drive's slice; ``N_OBS`` and ``OBS_THROW[k]``, the observer's columns;
``N_INTERSTAGES``, per interstage ``i`` its state ``IS_STATE[i]`` and slice ``IS_PARAM[i]``,
and per throw the interstage its suction takes in from (``THROW_IN[k]``) and its discharge
delivers into (``THROW_OUT[k]``), ``-1`` for a set line (the arrays of interstages hold one
unused ``-1`` when there is none).

A frame on its mounts (``FRAME``; `recipdyn.model.frame`): ``shaking(th1, thc, w, thcd, a1,
thcdd, p, m) -> (fx, fy)``, a throw's shaking force in its own axes (the mechanism's);
``frame_load(k, fx, fy, p, o)``, throw ``k``'s as generalised forces on the frame;
``frame_rhs(qx, qpsi, y, s, w, p, o, out)``, the frame's derivatives; its first state
``FRAME_STATE``, its work integrals ``FRAME_WORK`` and its slice ``FRAME_PARAMS``. Without a
frame they are bound to ``absent`` in branches on ``FRAME`` that numba removes.
"""

import numba as nb
import numpy as np

from recipdyn.model.base import (
    EVENT_SIGNATURE,
    JAC_SIGNATURE,
    RHS_JAC_SIGNATURE,
    RHS_SIGNATURE,
    compiled,
)

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
from recipdyn.model.assembler.generate import absent as shaking
from recipdyn.model.components.drive_kernels import prescribed_crank as crank
from recipdyn.model.components.load import paper_force as load_force
from recipdyn.model.mechanism.link_kernels import acceleration as throw_acc
from recipdyn.model.mechanism.link_kernels import acceleration_jac as throw_acc_jac
from recipdyn.model.mechanism.link_kernels import crank_torque, crosshead

FRAME = False
FRAME_PARAMS = np.int64(0)
FRAME_STATE = np.int64(0)
FRAME_WORK = np.int64(0)
INTERSTAGE = False
IS_PARAM = np.array([-1], dtype=np.int64)
IS_STATE = np.array([-1], dtype=np.int64)
LOAD_STATES = False
N_INTERSTAGES = np.int64(0)
N_THROWS = np.int64(1)
SHAFT = np.int64(0)
THROW_IN = np.array([-1], dtype=np.int64)
THROW_OUT = np.array([-1], dtype=np.int64)
THROW_STATE = np.array([0], dtype=np.int64)
THROW_MECH = np.array([2], dtype=np.int64)
THROW_PHASE = np.array([14], dtype=np.int64)
THROW_LOAD = np.array([15], dtype=np.int64)
LOAD_STATE = np.array([2], dtype=np.int64)
LOAD_AUX = np.array([2], dtype=np.int64)
LOAD_N = np.array([0], dtype=np.int64)
LOAD_NAUX = np.array([0], dtype=np.int64)
LOAD_STEPS = np.array([15], dtype=np.int64)
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
def _throw(th1, w, y, p, k, out):
    """Throw ``k``'s derivatives: its clearance angle's, then its load's states'."""
    s, m = THROW_STATE[k], THROW_MECH[k]
    thk = th1 + p[THROW_PHASE[k]]
    out[s] = y[s + 1]
    if LOAD_STATES:
        x, v = crosshead(thk, y[s], w, y[s + 1], p, m)
        _load_rhs(x, v, y, p, k, out)
    out[s + 1] = throw_acc(thk, y[s], y[s + 1], _force(thk, y, p, k), w, p, m)


@nb.njit(cache=True)
def _frame(th1, w, a1, y, p, out):
    """The frame's derivatives: every throw's shaking force, from its state and its
    clearance angle's acceleration already in ``out``, as generalised forces on the frame."""
    qx = 0.0
    qpsi = 0.0
    for k in range(N_THROWS):
        s, m = THROW_STATE[k], THROW_MECH[k]
        fx, fy = shaking(th1 + p[THROW_PHASE[k]], y[s], w, y[s + 1], a1, out[s + 1], p, m)
        gx, gpsi = frame_load(k, fx, fy, p, FRAME_PARAMS)
        qx += gx
        qpsi += gpsi
    frame_rhs(qx, qpsi, y, FRAME_STATE, FRAME_WORK, p, FRAME_PARAMS, out)


@nb.njit(cache=True)
def _rhs(t, y, p, out):
    th1, w = crank(t, y, p, SHAFT)
    for k in range(N_THROWS):
        _throw(th1, w, y, p, k, out)
    if FRAME:
        _frame(th1, w, 0.0, y, p, out)
    if INTERSTAGE:
        _interstages(p, out)


@compiled(RHS_SIGNATURE)
def rhs(t, y, p, out):
    _rhs(t, y, p, out)


@nb.njit(cache=True)
def _throw_jac(th1, w, y, p, k, out, J):
    """Throw ``k``'s derivatives and the exact partial derivatives of its clearance angle's
    (a load without states: the throws are independent, the rest of ``J`` is 0)."""
    s, m = THROW_STATE[k], THROW_MECH[k]
    thk = th1 + p[THROW_PHASE[k]]
    out[s] = y[s + 1]
    J[s, s] = 0.0
    J[s, s + 1] = 1.0
    F = _force(thk, y, p, k)
    out[s + 1], J[s + 1, s], J[s + 1, s + 1] = throw_acc_jac(thk, y[s], y[s + 1], F, w, p, m)


@compiled(RHS_JAC_SIGNATURE)
def rhs_jac(t, y, p, out, J):
    """The right-hand side and the Jacobian in one call, for a configuration whose loads
    have no states and without a frame (the assembler hands it out only then; with a frame
    its derivatives are right, the frame's rows of ``J`` are not written)."""
    th1, w = crank(t, y, p, SHAFT)
    for k in range(N_THROWS):
        _throw_jac(th1, w, y, p, k, out, J)
    if FRAME:
        _frame(th1, w, 0.0, y, p, out)


@nb.njit(cache=True)
def _load_columns(th1, w, y, p, k, J):
    """Throw ``k`` with a load with states: the clearance angle's dependence on the load's
    states (through the gas force, in which the equation is linear) and the load's rows, by
    central differences of the load's laws (its stops and regularised nozzles are not smooth
    everywhere), with each load state's step ``1e-7 (|y| (1 + rel) + abs)`` from its slice;
    the clearance angle and its rate by ``1e-6 (|y| + 1)`` (at 1e-7 the rounding of the
    chamber pressures' derivatives, ~1e6 Pa/s, left 7e-5 of an entry in a leaking valve's
    rows)."""
    s, m, lo = THROW_STATE[k], THROW_MECH[k], THROW_LOAD[k]
    g, a, ng, na = LOAD_STATE[k], LOAD_AUX[k], LOAD_N[k], LOAD_NAUX[k]
    thk = th1 + p[THROW_PHASE[k]]
    F = load_state_force(y, g, p, lo)
    acc = throw_acc(thk, y[s], y[s + 1], F, w, p, m)
    dF = 1.0 + abs(F)
    dadF = (throw_acc(thk, y[s], y[s + 1], F + dF, w, p, m) - acc) / dF
    n = y.shape[0]
    yy = y.copy()
    f1 = np.zeros(n)
    f2 = np.zeros(n)
    for c in range(ng + 2):
        j = s + c if c < 2 else g + c - 2
        st = LOAD_STEPS[k] + 2 * (c - 2)
        h = 1e-6 * (abs(y[j]) + 1.0) if c < 2 else 1e-7 * (abs(y[j]) * (1.0 + p[st]) + p[st + 1])
        yy[j] = y[j] + h
        x, v = crosshead(thk, yy[s], w, yy[s + 1], p, m)
        _load_rhs(x, v, yy, p, k, f1)
        Fp = load_state_force(yy, g, p, lo)
        yy[j] = y[j] - h
        x, v = crosshead(thk, yy[s], w, yy[s + 1], p, m)
        _load_rhs(x, v, yy, p, k, f2)
        Fm = load_state_force(yy, g, p, lo)
        yy[j] = y[j]
        if c >= 2:
            J[s + 1, j] = dadF * (Fp - Fm) / (2.0 * h)
        for i in range(ng):
            J[g + i, j] = (f1[g + i] - f2[g + i]) / (2.0 * h)
        for i in range(na):
            J[a + i, j] = (f1[a + i] - f2[a + i]) / (2.0 * h)


@nb.njit(cache=True)
def _difference(t, y, p, j, h, yy, f1, f2, J):
    """Column ``j`` of ``J``: central differences of the whole right-hand side, step ``h``."""
    yy[j] = y[j] + h
    _rhs(t, yy, p, f1)
    yy[j] = y[j] - h
    _rhs(t, yy, p, f2)
    yy[j] = y[j]
    for i in range(y.shape[0]):
        J[i, j] = (f1[i] - f2[i]) / (2.0 * h)


@nb.njit(cache=True)
def _coupled_jac(t, y, p, J):
    """With interstage volumes the throws' loads couple through them: every column by central
    differences of the whole right-hand side, each state stepped as in `_load_columns` (an
    interstage's pressure by ``1e-7 (|p| + 1 kPa)``); the counters' columns stay 0 (nothing
    depends on them)."""
    n = y.shape[0]
    yy = y.copy()
    f1 = np.empty(n)
    f2 = np.empty(n)
    for k in range(N_THROWS):
        s, g = THROW_STATE[k], LOAD_STATE[k]
        for c in range(LOAD_N[k] + 2):
            j = s + c if c < 2 else g + c - 2
            st = LOAD_STEPS[k] + 2 * (c - 2)
            if c < 2:
                h = 1e-6 * (abs(y[j]) + 1.0)
            else:
                h = 1e-7 * (abs(y[j]) * (1.0 + p[st]) + p[st + 1])
            _difference(t, y, p, j, h, yy, f1, f2, J)
    for i in range(N_INTERSTAGES):
        j = IS_STATE[i]
        _difference(t, y, p, j, 1e-7 * (abs(y[j]) + 1e3), yy, f1, f2, J)


@compiled(JAC_SIGNATURE, allocates=True)
def jac(t, y, p, J):
    n = y.shape[0]
    for i in range(n):
        for j in range(n):
            J[i, j] = 0.0
    if INTERSTAGE:
        _coupled_jac(t, y, p, J)
    else:
        f = np.empty(n)
        th1, w = crank(t, y, p, SHAFT)
        for k in range(N_THROWS):
            _throw_jac(th1, w, y, p, k, f, J)
            if LOAD_STATES:
                _load_columns(th1, w, y, p, k, J)
    if FRAME:  # (its own rows over every column: the frame's states too)
        _frame_rows(t, y, p, J)


@nb.njit(cache=True)
def _frame_rows(t, y, p, J):
    """The frame's rows (its states and work integrals) by central differences of the
    right-hand side, steps ``1e-6 (|y| + 1)``: linear in the frame's own states (exact to
    rounding, ~eps |f| / h), smooth in the throws' (truncation ~h^2); the work integrals'
    columns stay 0 (nothing depends on them)."""
    n = y.shape[0]
    yy = y.copy()
    f1 = np.empty(n)
    f2 = np.empty(n)
    for j in range(n):
        if FRAME_WORK <= j < FRAME_WORK + 2:
            continue
        h = 1e-6 * (abs(y[j]) + 1.0)
        yy[j] = y[j] + h
        _rhs(t, yy, p, f1)
        yy[j] = y[j] - h
        _rhs(t, yy, p, f2)
        yy[j] = y[j]
        for i in range(6):
            J[FRAME_STATE + i, j] = (f1[FRAME_STATE + i] - f2[FRAME_STATE + i]) / (2.0 * h)
        for i in range(2):
            J[FRAME_WORK + i, j] = (f1[FRAME_WORK + i] - f2[FRAME_WORK + i]) / (2.0 * h)


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
    """The outputs compiled code computes from the integrated states, by the functions that
    were integrated: the crank's angle and speed (columns 0, 1), then per throw its crank
    angle, its gas force and the torque the shaft applies to its crank (columns
    ``OBS_THROW[k]`` to ``+ 2``)."""
    out = np.empty((t.shape[0], N_OBS))
    for i in range(t.shape[0]):
        yi = y[i]
        th1, w = crank(t[i], yi, p, SHAFT)
        out[i, 0] = th1
        out[i, 1] = w
        for k in range(N_THROWS):
            s, m, c = THROW_STATE[k], THROW_MECH[k], OBS_THROW[k]
            thk = th1 + p[THROW_PHASE[k]]
            F = _force(thk, yi, p, k)
            acc = throw_acc(thk, yi[s], yi[s + 1], F, w, p, m)
            out[i, c] = thk
            out[i, c + 1] = F
            out[i, c + 2] = crank_torque(thk, yi[s], w, yi[s + 1], acc, 0.0, F, p, m)
    return out
