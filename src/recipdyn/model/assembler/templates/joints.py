"""Template of the contact joints' forces at the pins, for one contact law and friction law.

The assembler (`recipdyn.model.assembler.generate`) writes one module per choice of the laws:
this file verbatim, with the block between the ``<bindings>`` markers replaced by that
choice's names and constants; every configuration of the joints (load, drive, guide) calls
the module's functions, compiled once for it (docs/architecture.md, Composing compiled
components). As it stands the block binds the built-in law (`joints.contact.normal_force`,
its hysteresis factor at ``P_CHI``), Ambrósio's friction at the pins and at the guide's shoes.

Roles (compiled functions that take real or complex arguments: the contact model's Jacobian
is the complex step of its right-hand side; they branch on ``.real``):

* ``law_normal(delta, ddelta, v_impact, K, p, o) -> F_n`` and ``law_elastic(delta, K, p, o)``:
  the normal-force law and its conservative part (a contact law's roles, its slice at
  ``LO``);
* ``friction(vt, p, o) -> F_t / F_n`` at the pins (its slice at ``FO``);
* ``guide_friction(vt, p, o)`` at the guide's shoes (its slice in the guide's).

Functions: `joints`, `joints_at` (both pins' forces, the crank prescribed or free),
`joints_guide`, `joints_guide_at` (the same with the guide's clearance: the rod's small end
follows the crosshead pin's lateral position), `guide_forces` and `guide_corner` (the guide's
shoes). ``cfg``: 0 the crank pin worn, 1 the crosshead pin, 2 both, 3 both ideal (the guide's
clearance only); a rigid joint's forces are 0.
"""

import numba as nb
import numpy as np

from recipdyn.model.joints.guide import (
    S_A,
    S_B,
    S_C,
    S_CHI,
    S_K,
    S_MU,
    S_VMIN,
    corner_force,
    slice_forces,
)
from recipdyn.model.joints.pins import (
    P_C1,
    P_C2,
    P_EPSDRY,
    P_K1,
    P_K2,
    P_LB,
    P_OIL,
    P_OIL2,
    P_OMEGA,
    P_R,
    P_RJ1,
    P_RJ2,
    P_TH10,
    P_VMIN,
    _abs,
    _kinematics_at,
    short_bearing_forces,
)

# isort: split
# <bindings>
from recipdyn.model.joints.contact import ambrosio_friction as friction
from recipdyn.model.joints.contact import ambrosio_friction as guide_friction
from recipdyn.model.joints.contact import power_law_elastic as law_elastic
from recipdyn.model.joints.contact import power_law_normal as law_normal

FO = np.int64(23)
LO = np.int64(22)
# </bindings>


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
        fn = law_normal(delta, drho, vi, K, p, LO)
        vt = et + w_j * Rj - w_b * Rb  # sliding velocity, bearing relative to journal
        ft = fn * friction(vt, p, FO)
        fx = -fn * nx + ft * tx
        fy = -fn * ny + ft * ty
        tb = -Rb * ft
        tj = Rj * ft
        fnn = fn
        ftt = ft
        lost = (fn - law_elastic(delta, K, p, LO)) * drho - ft * vt
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


@nb.njit(cache=True)
def joints_at(th1, w, y, p, cfg):
    """Both joints' forces (tuples as `_pair`; a rigid joint's are 0) and (power from the
    crank, power lost in the joints, theta2', x3', cos theta2, sin and cos theta1) at the crank
    angle ``th1`` and speed ``w``."""
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


@nb.njit(cache=True)
def joints(t, y, p, cfg):
    """`joints_at` with the crank turning at the prescribed speed."""
    w = p[P_OMEGA]
    return joints_at(p[P_TH10] + w * t, w, y, p, cfg)


@nb.njit(cache=True)
def joints_guide_at(th1, w, y, p, cfg, gy):
    """`joints_at` with the guide's clearance (its states from ``y[gy]``): the rod's small end
    follows the crosshead pin's lateral position, and the crosshead pin's journal turns with
    the crosshead's tilt."""
    _, c2, th2d, v3, s1, c1 = _kinematics_at(th1, w, p, y[0], y[1], y[4], y[5], y[2],
                                             y[3] + y[gy], y[6], y[7] + y[gy + 2])  # fmt: skip
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
def joints_guide(t, y, p, cfg, gy):
    """`joints_guide_at` with the crank turning at the prescribed speed."""
    w = p[P_OMEGA]
    return joints_guide_at(p[P_TH10] + w * t, w, y, p, cfg, gy)


@nb.njit(cache=True)
def guide_forces(y, p, go, gy, v3):
    """The guide's shoes on the crosshead (its slice at ``go``, its states from ``y[gy]``): the
    resultant at its pin, the moment about the pin, the power lost, the elastic energy."""
    return slice_forces(p, go, guide_friction, y[gy], v3, y[gy + 2], y[gy + 1], y[gy + 3],
                        y[gy + 4], y[gy + 5], y[gy + 6], y[gy + 7])  # fmt: skip


@nb.njit(cache=True)
def guide_corner(k, y, p, go, gy, v3):
    """Corner ``k``'s contact with its shoe (`recipdyn.model.joints.guide.corner_force`)."""
    return corner_force(k, y[gy], v3, y[gy + 2], y[gy + 1], y[gy + 3], p[go + S_A],
                        p[go + S_B], p[go + S_C], p[go + S_K], p[go + S_CHI], guide_friction,
                        p, go + S_MU, p[go + S_VMIN], y[gy + 4 + k])  # fmt: skip
