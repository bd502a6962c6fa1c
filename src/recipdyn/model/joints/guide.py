r"""A slider (crosshead) in a guide with clearance: its equations of motion and contact forces.

The mechanism is a planar slider-crank whose slider is free inside its guide: crank (length
``r``, centroid at ``rs``, mass ``m1``, inertia ``J1`` about its centroid), connecting rod
(``l``, centroid at ``ls`` from the crank pin, ``m2``, ``J2``) and a slider of mass ``m3`` whose
centre is the rod's end (the pin), with tilt inertia ``J3``. Generalised coordinates
``q = (theta1, theta2, phi)``: the crank and rod angles from the guide's axis and the slider's
tilt. The pin is at

.. math:: x = r\cos\theta_1 + l\cos\theta_2,\qquad y = r\sin\theta_1 + l\sin\theta_2,

so the slider's lateral position is free: only the guide's two surfaces, at
:math:`y = -d \pm (b + c)`, hold it (``d`` the guide's offset below the crank axis, ``b`` the
slider's half-height, ``c`` the radial clearance). This is the model of Flores, Leine & Glocker
(2010), *Multibody Syst. Dyn.* 23, 165-190, as the open code siconos implements it (its
mass matrix, gyroscopic and gravity terms are the ones derived here:
``tests/test_guide.py::test_the_derived_equations_are_siconos_hand_written_ones``).

Equations of motion: Lagrange's equations of
:math:`T = \tfrac12[(J_1 + m_1 r_s^2)\dot\theta_1^2 + m_2|\dot{\mathbf r}_G|^2 + J_2\dot\theta_2^2
+ m_3(\dot x^2 + \dot y^2) + J_3\dot\phi^2]` and
:math:`V = g[m_1 r_s\sin\theta_1 + m_2 y_G + m_3 y]` (gravity along −y), derived by
[`recipdyn.model.derive`][recipdyn.model.derive] without a small-angle approximation into
``_guide.py`` (a test regenerates it). The generated function returns the mass matrix and
the right-hand side ``M qdd = b``; the forces enter as generalised forces
:math:`Q_k = F_x\,\partial x/\partial q_k + F_y\,\partial y/\partial q_k
+ M_z\,\partial\phi/\partial q_k + T_c\,\partial\theta_1/\partial q_k` (``F`` the resultant on
the slider at the pin, ``M_z`` its moment about the pin, ``T_c`` a torque on the crank).
With the crank free (the benchmark) all three rows are solved; with the crank speed prescribed
(the compressor) rows 2-3 give :math:`(\ddot\theta_2, \ddot\phi)` at
:math:`\ddot\theta_1 = 0`, and row 1 the torque the drive must supply (for the energy balance).

Contact: each of the slider's four corners, at ``(xi, eta) = (-a, +b), (+a, +b), (-a, -b),
(+a, -b)`` in the slider's frame (numbered as in siconos), against the guide surface on its
side. Penetration ``delta_i = -g_i`` (``g_i`` the gap, siconos's ``g1..g4``); the normal force
is recipdyn's compliant law [`normal_force`][recipdyn.model.joints.contact.normal_force]
(``F = K delta^1.5 (1 + chi delta'/delta'-)``, ``chi`` from the chosen law and restitution,
``delta'-`` the approach velocity recorded by the contact-onset event), and friction is
the friction law the caller names,
[`ambrosio_friction`][recipdyn.model.joints.contact.ambrosio_friction] or ``tanh_friction``
(Coulomb with Ambrósio's regularisation or tanh), on the corner's sliding velocity along the
guide.
"""

from __future__ import annotations

import math
from functools import lru_cache
from pathlib import Path

import numba as nb
import numpy as np

from .contact import normal_force

__all__ = ["MECH", "INPUTS", "CORNERS", "N_HEAD", "lagrangian", "generate", "corner_forces",
           "pin_kinematics", "guide_forces", "smallest_factor", "flip_phases", "slice_forces",
           "slice_smallest_factor", "slice_flip_phases",
           "solve_free", "solve_prescribed", "phased_gap_factor", "corner_kinematics",
           "corner_force"]  # fmt: skip

#: Parameters of the generated kernels, in order (the packed vector starts with them).
MECH = ("r", "rs", "l", "ls", "m1", "m2", "m3", "J1", "J2", "J3", "g")
#: Generalised-force inputs passed per call: resultant on the slider at the pin, its moment
#: about the pin, torque on the crank.
INPUTS = ("F_x", "F_y", "M_z", "T_crank")
#: The slider's corners in its own frame, as multiples of (a, b) (siconos's numbering).
CORNERS = ((-1.0, 1.0), (1.0, 1.0), (-1.0, -1.0), (1.0, -1.0))


@lru_cache(maxsize=1)
def lagrangian():
    """The derived [`Lagrangian`][recipdyn.model.derive.Lagrangian] of the slider-crank with the
    slider free in its guide, coordinates ``(theta1, theta2, phi)`` (module docstring)."""
    import sympy as sp

    from ..derive import derive

    t = sp.Symbol("t", real=True)
    q = sp.symbols("theta1 theta2 phi", real=True)
    qd = sp.symbols("theta1_dot theta2_dot phi_dot", real=True)
    r, rs, l, ls, m1, m2, m3, J1, J2, J3, g = sp.symbols(" ".join(MECH), real=True)
    Fx, Fy, Mz, Tc = sp.symbols(" ".join(INPUTS), real=True)
    th1, th2, phi = q
    x = r * sp.cos(th1) + l * sp.cos(th2)
    y = r * sp.sin(th1) + l * sp.sin(th2)
    xg, yg = r * sp.cos(th1) + ls * sp.cos(th2), r * sp.sin(th1) + ls * sp.sin(th2)
    x1, y1 = rs * sp.cos(th1), rs * sp.sin(th1)

    def dt(e):
        return sum(sp.diff(e, a) * b for a, b in zip(q, qd, strict=True))

    T = (m1 * (dt(x1) ** 2 + dt(y1) ** 2) + J1 * qd[0] ** 2 + m2 * (dt(xg) ** 2 + dt(yg) ** 2)
         + J2 * qd[1] ** 2 + m3 * (dt(x) ** 2 + dt(y) ** 2) + J3 * qd[2] ** 2) / 2  # fmt: skip
    V = g * (m1 * y1 + m2 * yg + m3 * y)
    Q = [Fx * sp.diff(x, k) + Fy * sp.diff(y, k) + Mz * sp.diff(phi, k) + Tc * sp.diff(th1, k)
         for k in q]  # fmt: skip
    lag = derive(T, V, q, qd, t, (r, rs, l, ls, m1, m2, m3, J1, J2, J3, g, Fx, Fy, Mz, Tc), Q=Q)
    return lag, T + V


def _system_source(lag, energy, name: str) -> str:
    """``{name}_system(y, p, u)``: the lower triangle of M and b of ``M qdd = b`` as a tuple
    ``(m00, m10, m11, m20, m21, m22, b0, b1, b2)``, and ``{name}_energy(y, p)``: ``T + V``.
    ``y = (q, qd)`` (a tuple), ``p`` the `MECH` parameters, ``u`` the `INPUTS`."""
    import sympy as sp

    from ..derive import KernelPrinter, _body

    n = lag.n
    n_p = len(MECH)
    low = [(i, j) for i in range(n) for j in range(i + 1)]
    exprs = [lag.M[i, j] for i, j in low] + [lag.b[i] for i in range(n)]
    head, vals = _body(lag, [sp.trigsimp(sp.expand(e)) for e in exprs])
    for i in range(n_p, len(lag.params)):
        head[head.index(f"    _p{i} = p[{i}]")] = f"    _p{i} = u[{i - n_p}]"
    out = ["@nb.njit(cache=True)", f"def {name}_system(y, p, u):",
           '    """Lower triangle of M, then b, of M qdd = b (a tuple)."""', *head,
           "    return (" + ", ".join([*(vals[k] for k in range(len(low))),
                                       *(vals[len(low) + i] for i in range(n))]) + ")"]  # fmt: skip
    # the energy: in the same names (no inputs)
    sub = {s: sp.Symbol(f"_q{i}") for i, s in enumerate(lag.q)}
    sub.update({s: sp.Symbol(f"_qd{i}") for i, s in enumerate(lag.qd)})
    sub.update({s: sp.Symbol(f"_p{i}") for i, s in enumerate(lag.params[:n_p])})
    energy = sp.trigsimp(sp.expand(energy)).subs(sub)
    repl, (e,) = sp.cse([energy], symbols=sp.numbered_symbols("x"), optimizations="basic")
    pr = KernelPrinter({"standard": "python3"})
    out += [
        "",
        "",
        "@nb.njit(cache=True)",
        f"def {name}_energy(y, p):",
        '    """Kinetic + potential (gravity) energy T + V of crank, rod and slider, J."""',
    ]
    out += [f"    _q{i} = y[{i}]" for i in range(n)]
    out += [f"    _qd{i} = y[{n + i}]" for i in range(n)]
    out += [f"    _p{i} = p[{i}]" for i in range(n_p)]
    out += [f"    {s} = {pr.doprint(v)}" for s, v in repl]
    out.append(f"    return {pr.doprint(e)}")
    return "\n".join(out + [""])


def generate() -> str:
    """Source of ``_guide.py`` (regenerate with ``python -m recipdyn.model.joints.guide``)."""
    lag, energy = lagrangian()
    head = ('"""Generated by recipdyn.model.joints.guide -- do not edit by hand.\n\n'
            "The slider-crank with the slider free in its guide (recipdyn.model.joints.guide):\n"
            "M and b of M qdd = b for q = (theta1, theta2, phi), and the energy T + V.\n"
            '"""\n\nimport numba as nb\nimport numpy as np\n\n\n')  # fmt: skip
    # numpy's scalar functions: the same machine code for real arguments, and the kernels
    # also take complex ones (the complex-step Jacobian of `compressor_guide`)
    return head + _system_source(lag, energy, "guide").replace("math.", "np.")


def _target() -> Path:
    return Path(__file__).with_name("_guide.py")


# ---- the compiled parts shared by the benchmark and the compressor ---------------------------


@nb.njit(cache=True, inline="always")
def solve_free(m00, m10, m11, m20, m21, m22, b0, b1, b2):
    """``M qdd = b`` for the symmetric positive definite 3 x 3 ``M`` (straight-line
    ``L D L^T``, no pivoting: stable for a mass matrix)."""
    d0 = m00
    l10 = m10 / d0
    l20 = m20 / d0
    d1 = m11 - l10 * l10 * d0
    l21 = (m21 - l20 * l10 * d0) / d1
    d2 = m22 - l20 * l20 * d0 - l21 * l21 * d1
    z0 = b0
    z1 = b1 - l10 * z0
    z2 = b2 - l20 * z0 - l21 * z1
    a2 = z2 / d2
    a1 = z1 / d1 - l21 * a2
    a0 = z0 / d0 - l10 * a1 - l20 * a2
    return a0, a1, a2


@nb.njit(cache=True, inline="always")
def solve_prescribed(m00, m10, m11, m20, m21, m22, b0, b1, b2):
    """Rows and columns 2-3 of ``M qdd = b`` at ``theta1'' = 0`` (the crank speed prescribed):
    ``(theta2'', phi'', T)``, ``T = M[0, 1:] qdd[1:] - b0`` the torque on the crank the motion
    needs (b0 taken without a crank torque input)."""
    det = m11 * m22 - m21 * m21
    a1 = (b1 * m22 - m21 * b2) / det
    a2 = (m11 * b2 - m21 * b1) / det
    return a1, a2, m10 * a1 + m20 * a2 - b0


#: In contact a corner's phased factor is ``delta/L + PHASE_MARGIN`` (``L`` the event's length
#: scale): a separation is located at ``delta = -PHASE_MARGIN L``, where the force is already 0.
PHASE_MARGIN = 1e-9


@nb.njit(cache=True, inline="always")
def phased_gap_factor(delta, v_phase, scale):
    """The event factor of one corner: ``-delta/scale`` in free flight (``v_phase < 0``),
    ``delta/scale + PHASE_MARGIN`` in contact (``v_phase > 0``). Positive in both phases, it
    falls through 0 at an onset and at a separation; the reset flips the phase, so the
    smallest factor of all corners is one event function that sees every onset and
    separation (as `recipdyn.model.joints.pins.phased_factor` does for pins)."""
    return delta / scale + PHASE_MARGIN if v_phase > 0.0 else -delta / scale


@nb.njit(cache=True, inline="always")
def corner_kinematics(k, y_rel, vx, vy, phi, phid, a, b):
    """Corner ``k``'s offset from the pin ``(dx, dy)``, its penetration plus ``c`` into its
    guide surface (the caller subtracts the clearance), the penetration rate, the corner's
    sliding velocity along the guide and its side (+1 upper surface, -1 lower).

    ``y_rel`` is the pin's lateral position from the guide's centreline, ``vx, vy`` its
    velocity; the surfaces are at ``y_rel = +-(b + c)``."""
    xi = a if k == 1 or k == 3 else -a
    side = 1.0 if k < 2 else -1.0
    eta = side * b
    s, co = np.sin(phi), np.cos(phi)
    dx = xi * co - eta * s
    dy = xi * s + eta * co
    pen = side * (y_rel + dy) - b
    dpen = side * (vy + phid * dx)
    vt = vx - phid * dy
    return dx, dy, pen, dpen, vt, side


@nb.njit(cache=True, inline="always")
def corner_force(k, y_rel, vx, vy, phi, phid, a, b, c, K, chi, friction, p, fo, vmin, v_imp):
    """One corner's contact: the force on the slider ``(f_x, f_y)``, its moment about the pin,
    the power lost (contact damping and friction), the elastic energy, the normal and the
    friction force. ``v_imp`` is the corner's recorded approach velocity (its sign the phase,
    its magnitude floored at ``vmin`` scales the damping). ``friction(vt, p, fo)``: the
    friction law, ``F_t / F_n`` with its slice ``(mu, v0, v1)`` at ``fo`` (a built-in law of
    `recipdyn.model.joints.contact`, named by the caller: each law compiles its own
    kernel)."""
    dx, dy, pen, dpen, vt, side = corner_kinematics(k, y_rel, vx, vy, phi, phid, a, b)
    delta = pen - c
    z = 0.0 * delta  # zero of the state's type (real, or complex for the complex step)
    if delta.real <= 0.0:
        return z, z, z, z, z, z, z
    vi = v_imp if v_imp.real >= 0.0 else -v_imp
    fn = normal_force(delta, dpen, vi if vi.real > vmin else vmin + z, K, chi) + z
    ft = fn * friction(vt, p, fo)
    cy = -side * fn
    lost = (fn - K * delta * np.sqrt(delta)) * dpen - ft * vt
    return ft, cy, dx * cy - dy * ft, lost, K * delta * delta * np.sqrt(delta) / 2.5, fn, ft


@nb.njit(cache=True, inline="always")
def corner_forces(y_rel, vx, vy, phi, phid, a, b, c, K, chi, friction, p, fo, vmin,
                  v1i, v2i, v3i, v4i):  # fmt: skip
    """The four corners' contact summed: the resultant on the slider ``(F_x, F_y)`` at the
    pin, its moment ``M_z`` about the pin, the power lost, the elastic energy (tuple of 5);
    ``v1i..v4i`` the corners' recorded approach velocities."""
    c1 = corner_force(0, y_rel, vx, vy, phi, phid, a, b, c, K, chi, friction, p, fo, vmin, v1i)
    c2 = corner_force(1, y_rel, vx, vy, phi, phid, a, b, c, K, chi, friction, p, fo, vmin, v2i)
    c3 = corner_force(2, y_rel, vx, vy, phi, phid, a, b, c, K, chi, friction, p, fo, vmin, v3i)
    c4 = corner_force(3, y_rel, vx, vy, phi, phid, a, b, c, K, chi, friction, p, fo, vmin, v4i)
    return (c1[0] + c2[0] + c3[0] + c4[0], c1[1] + c2[1] + c3[1] + c4[1],
            c1[2] + c2[2] + c3[2] + c4[2], c1[3] + c2[3] + c3[3] + c4[3],
            c1[4] + c2[4] + c3[4] + c4[4])  # fmt: skip


# ---- packed parameters shared by every model built on this joint ------------------------------
#: The guide's slice of the parameter vector, from its first value (its offset ``o``): the
#: guide's offset below the crank axis, the slider's half-length and half-height, the radial
#: clearance, the contact stiffness and hysteresis factor, friction (coefficient, v0, v1: the
#: friction law's slice), the floor of the approach velocity, the event's length scale, the
#: slider's tilt inertia (read by the glue of the contact joints only; the benchmark and
#: `compressor-guide` have it in the `MECH` head).
(S_D, S_A, S_B, S_C, S_K, S_CHI, S_MU, S_V0, S_V1, S_VMIN, S_SCALE,
 S_J3) = range(12)  # fmt: skip
#: The same after the `MECH` head (the benchmark's and `compressor-guide`'s layout).
(P_D, P_A, P_B, P_C, P_K, P_CHI, P_MU, P_V0, P_V1, P_VMIN,
 P_SCALE) = range(len(MECH), len(MECH) + 11)  # fmt: skip
N_HEAD = len(MECH) + 11


@nb.njit(cache=True, inline="always")
def pin_kinematics(p, th1, th1d, th2, th2d):
    """The pin's lateral position from the guide's centreline and its velocity (x', y')."""
    r, l = p[0], p[2]
    s1, c1 = np.sin(th1), np.cos(th1)
    s2, c2 = np.sin(th2), np.cos(th2)
    return (r * s1 + l * s2 + p[P_D], -r * s1 * th1d - l * s2 * th2d,
            r * c1 * th1d + l * c2 * th2d)  # fmt: skip


@nb.njit(cache=True, inline="always")
def slice_forces(p, o, friction, y_rel, vx, vy, phi, phid, v1i, v2i, v3i, v4i):
    """`corner_forces` with the guide's slice at ``o`` (layout ``S_*``) and the friction law
    ``friction`` (its slice at ``o + S_MU``)."""
    return corner_forces(y_rel, vx, vy, phi, phid, p[o + S_A], p[o + S_B], p[o + S_C],
                         p[o + S_K], p[o + S_CHI], friction, p, o + S_MU, p[o + S_VMIN], v1i,
                         v2i, v3i, v4i)  # fmt: skip


@nb.njit(cache=True, inline="always")
def guide_forces(p, friction, y_rel, vx, vy, phi, phid, v1i, v2i, v3i, v4i):
    """`corner_forces` with the guide's packed parameters."""
    return slice_forces(p, P_D, friction, y_rel, vx, vy, phi, phid, v1i, v2i, v3i, v4i)


@nb.njit(cache=True, inline="always")
def slice_smallest_factor(p, o, y_rel, vx, vy, phi, phid, y, k0):
    """The smallest phased factor of the four corners (their phases in ``y[k0:k0 + 4]``) and
    its corner, with the guide's slice at ``o``: one event function for every onset and
    separation."""
    best, which = math.inf, 0
    for k in range(4):
        _, _, pen, _, _, _ = corner_kinematics(k, y_rel, vx, vy, phi, phid, p[o + S_A],
                                               p[o + S_B])  # fmt: skip
        f = phased_gap_factor(pen - p[o + S_C], y[k0 + k], p[o + S_SCALE])
        if f < best:
            best, which = f, k
    return best, which


@nb.njit(cache=True, inline="always")
def smallest_factor(p, y_rel, vx, vy, phi, phid, y, k0):
    """`slice_smallest_factor` with the guide's packed parameters."""
    return slice_smallest_factor(p, P_D, y_rel, vx, vy, phi, phid, y, k0)


@nb.njit(cache=True, inline="always")
def slice_flip_phases(p, o, y_rel, vx, vy, phi, phid, y, k0, out):
    """The reset at a zero of `slice_smallest_factor`: every corner whose factor has reached
    the crossing changes phase, the event's own and any other at or below zero (a flat impact
    puts two corners on their surface at the same instant: both must be reset, or the second
    would stay in its free-flight phase while it penetrates). At an onset the approach
    velocity (the penetration rate, floored at the packed ``v_impact_min``) is recorded; at a
    separation the recorded value turns negative (free flight)."""
    best = slice_smallest_factor(p, o, y_rel, vx, vy, phi, phid, y, k0)[0]
    for k in range(4):
        _, _, pen, dpen, _, _ = corner_kinematics(k, y_rel, vx, vy, phi, phid, p[o + S_A],
                                                  p[o + S_B])  # fmt: skip
        if phased_gap_factor(pen - p[o + S_C], y[k0 + k], p[o + S_SCALE]) > max(best, 0.0):
            continue
        if y[k0 + k] > 0.0:
            out[k0 + k] = -y[k0 + k]
        else:
            out[k0 + k] = max(dpen, p[o + S_VMIN])


@nb.njit(cache=True, inline="always")
def flip_phases(p, y_rel, vx, vy, phi, phid, y, k0, out):
    """`slice_flip_phases` with the guide's packed parameters."""
    slice_flip_phases(p, P_D, y_rel, vx, vy, phi, phid, y, k0, out)


if __name__ == "__main__":  # pragma: no cover - developer tool
    _target().write_text(generate())
    print(f"wrote {_target().name}")
