"""Compiled functions of the torsionally flexible shaft (`recipdyn.model.shaft.flexible`), by
role.

The nodes' states are contiguous: node ``j``'s angle at ``y[s + 2 j]``, its speed at ``y[s + 2
j + 1]`` (node 0 the rotor, 1 the flywheel, then the throws along the shaft). Each function
reads the shaft's slice of the parameter vector at the offset ``o``: ``J_motor``, the
flywheel's inertia, then per section ``(k, c)``. Compiled once and linked by every
configuration that holds a flexible shaft (docs/architecture.md, Composing compiled
components).
"""

import numba as nb

__all__ = ["section", "nodes_rhs"]

_J_MOTOR, _J_FLYWHEEL, _SECTIONS = 0, 1, 2


@nb.njit(cache=True)
def section(y, s, i, p, o):
    """Section ``i`` (between nodes ``i`` and ``i + 1``): ``(twist, twist rate, torque)``, the
    twist ``theta_i - theta_(i+1)`` and the torque ``k twist + c twist'`` it carries from node
    ``i`` to node ``i + 1``."""
    a = s + 2 * i
    twist = y[a] - y[a + 2]
    rate = y[a + 1] - y[a + 3]
    b = o + _SECTIONS + 2 * i
    return twist, rate, p[b] * twist + p[b + 1] * rate


@nb.njit(cache=True)
def nodes_rhs(tm, n, y, s, w, p, o, out):
    """The ``n`` nodes' derivatives at ``out[s + 2 j]`` (the speed) and ``out[s + 2 j + 1]``
    (``J_j theta_j'' = Q_j + T_(j-1) - T_j``, `recipdyn.model.shaft.flexible`): node 0 the
    rotor, ``(J_motor, tm)``; node 1 the flywheel, ``(J_drive - J_motor, 0)``; a throw's node
    ``(I, Q)``, its share of a free crank's equation, which the caller left at ``out[s + 2
    j]``, ``out[s + 2 j + 1]``. At ``out[w]`` the sections' dissipation ``sum c twist'^2``."""
    loss = 0.0
    upstream = 0.0  # the torque of the section before node j
    for j in range(n):
        a = s + 2 * j
        if j == 0:
            inertia, load = p[o + _J_MOTOR], tm
        elif j == 1:
            inertia, load = p[o + _J_FLYWHEEL], 0.0
        else:
            inertia, load = out[a], out[a + 1]
        load += upstream
        if j < n - 1:
            _, rate, torque = section(y, s, j, p, o)
            load -= torque
            loss += p[o + _SECTIONS + 2 * j + 1] * rate * rate
            upstream = torque
        out[a] = y[a + 1]
        out[a + 1] = load / inertia
    out[w] = loss
