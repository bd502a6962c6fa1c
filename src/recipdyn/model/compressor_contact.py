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
free flight: [`phased_factor`][recipdyn.model.joints.pins.phased_factor]), and two work
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
(`recipdyn.model.joints.pins._joints_at`), the crank carries ``J1 + m1 rs^2 + J_drive`` and the
motor's torque and the crank-pin joint's friction torque act on it; ``W_in`` is then the work
of the gas and the motor. With the guide's clearance too (``free_crank_lagrangian(joints,
guide=True)``, kernels ``*_guide_free``: coordinates ``(theta1, e..., yg)``, the same
crosshead lateral kinetic energy, weight and ``F3_y`` work as `lagrangian`'s), the guide's
eight states come after the joints' (and the valves' after them), the crank's last, and
``W_loss`` holds the shoes' losses as with a prescribed crank. Its Jacobian is a central
difference (the crank angle enters through ``math.sin``); Benettin's method runs with the crank
free too: the recorded approach velocities are auxiliary states whose tangent components follow
the flow (the damping law reads them), and tests/test_motor_lyapunov.py checks the tangent flow
against differences of the flow across impacts, the exponent sum against the trace of the
Jacobian and the flow direction's zero exponent; with the guide's clearance it is refused (its
corners' saltation matrices are not checked, whatever the drive).

The Jacobian is the complex step of the right-hand side (``cs_jac`` of the generated glue,
`recipdyn.model.components.contact`): the compiled kernels take complex states, and
``J[:, k] = Im f(y + i h e_k) / h`` is exact to rounding (no difference is taken), on the
branch of each switch the state is on. A central difference's rounding noise (~1e-4 of the
contact stiffness terms) would keep Benettin's tangent integration at ~10^6 steps a
revolution; Lyapunov exponents are computed from the equations, with the contact onsets'
saltation matrices (tests/test_contact.py checks the
tangent flow against differences of the flow across impacts).

Where the code is: this module holds the derivations (`lagrangian`, `generate`; with a motor
`free_crank_lagrangian`, `generate_drive`); the model of ``--model compressor-contact`` is the
one assembler's machine of one contact throw (`recipdyn.model.assembler.model.OneContact`,
the family's route ``contact``), whose joints' configuration part (schema, packing, outputs,
summaries; shared with the dynamic valves' part) is
`recipdyn.model.components.contact_model`; the compiled parts (layout, joints' forces,
accelerations, events) are `recipdyn.model.joints.pins`, and the glue that joins them with a
load `recipdyn.model.components.contact`.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from .joints.pins import GUIDE_INPUTS, GUIDE_JOINTS, INPUTS, JOINTS, MECH

__all__ = ["lagrangian", "generate"]


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


@lru_cache(maxsize=8)
def free_crank_lagrangian(joints: str = "crank", guide: bool = False):
    """The derived [`Lagrangian`][recipdyn.model.derive.Lagrangian] of the mechanism with
    clearance at ``joints`` and the crank angle free (a motor drive): coordinates
    ``(theta1, e...)``. The crank adds ``I_crank theta1'^2 / 2`` and ``g S_crank sin
    theta1``; the torque ``T_crank`` acts on it. The joints' forces do virtual work on the
    eccentricities only (``F1 . d e1``: the force on the bearing and its reaction on the
    journal, whose position ``A(theta1)`` moves with the crank), the crank-pin joint's
    friction torque on the journal is in ``T_crank``, the gas force does ``F_gas dx3``. With
    ``guide``, the crosshead pin's lateral position ``yg`` is the last coordinate, as in
    `lagrangian` (its kinetic energy ``m3 yg'^2 / 2``, its weight, the guide's lateral force
    ``F3_y`` the last input; ``joints`` may then be ``ideal``). With ``theta1 = theta1_0 +
    omega t`` the other rows are `lagrangian`'s (the tests check it)."""
    import sympy as sp

    from .derive import derive

    t = sp.Symbol("t", real=True)
    e = dict(zip(("e1x", "e1y", "e2x", "e2y"), sp.symbols("e1x e1y e2x e2y", real=True),
                 strict=True))  # fmt: skip
    names = {"crank": ("e1x", "e1y"), "crosshead": ("e2x", "e2y"),
             "both": ("e1x", "e1y", "e2x", "e2y"), "ideal": ()}[joints]  # fmt: skip
    th1, th1d = sp.symbols("theta1 theta1_dot", real=True)
    q = (th1, *(e[k] for k in names))
    qd = (th1d, *(sp.Symbol(f"{k}_dot", real=True) for k in names))
    e = {k: (v if k in names else sp.S.Zero) for k, v in e.items()}
    yg = sp.S.Zero
    if guide:
        yg = sp.Symbol("yg", real=True)
        q, qd = (*q, yg), (*qd, sp.Symbol("yg_dot", real=True))
    r, l, ls, m2, m3, J2, g, d, w, th10 = sp.symbols(" ".join(MECH), real=True)
    Fg, F1x, F1y, F2x, F2y, Tr = sp.symbols(" ".join(INPUTS), real=True)
    Tc, Ic, Sc = sp.symbols(" ".join(CRANK_INPUTS), real=True)
    F3y = sp.Symbol(GUIDE_INPUTS[0], real=True)
    Bx, By = r * sp.cos(th1) + e["e1x"], r * sp.sin(th1) + e["e1y"]
    th2 = sp.asin((yg + e["e2y"] - d - By) / l)
    x3 = Bx + l * sp.cos(th2) - e["e2x"]
    xg, yg_rod = Bx + ls * sp.cos(th2), By + ls * sp.sin(th2)

    def dt(x):
        return sum(sp.diff(x, a) * b for a, b in zip(q, qd, strict=True))

    T = (m2 * (dt(xg) ** 2 + dt(yg_rod) ** 2) + J2 * dt(th2) ** 2 + m3 * dt(x3) ** 2
         + Ic * th1d**2) / 2  # fmt: skip
    V = m2 * g * yg_rod + g * Sc * sp.sin(th1)
    if guide:  # the crosshead's lateral motion, and its weight
        T = T + m3 * dt(yg) ** 2 / 2
        V = V + m3 * g * yg
    Q = [F1x * sp.diff(e["e1x"], k) + F1y * sp.diff(e["e1y"], k) + F2x * sp.diff(e["e2x"], k)
         + F2y * sp.diff(e["e2y"], k) + Tr * sp.diff(th2, k) + Fg * sp.diff(x3, k)
         + Tc * sp.diff(th1, k) + F3y * sp.diff(yg, k) for k in q]  # fmt: skip
    params = (r, l, ls, m2, m3, J2, g, d, w, th10, Fg, F1x, F1y, F2x, F2y, Tr, Tc, Ic, Sc)
    return derive(T, V, q, qd, t, (*params, F3y) if guide else params, Q=Q)


def generate_drive() -> str:
    """Source of ``_compressor_contact_drive.py``: the free-crank accelerations of the contact
    joints (`free_crank_lagrangian`) for clearance at the crank pin, the crosshead pin, or
    both; then with the guide's clearance (``*_guide_free``: the crosshead's lateral position
    the last coordinate), for those and both pins ideal."""
    import sympy as sp

    from .derive import accelerations_source

    head = ['"""Generated by ``python -m recipdyn.model.compressor_contact`` -- do not edit by '
            "hand.", "", "Mechanism of the compressor with contact-impact clearance joints and "
            "the crank angle free", "(a motor drive; recipdyn.model.compressor_contact."
            "free_crank_lagrangian): the accelerations", "qdd of M qdd = b, q = (theta1, e...), "
            "for clearance at the crank pin, the crosshead pin,", "or both; with the guide's "
            "clearance (``*_guide_free``), q = (theta1, e..., yg), also for", "both pins "
            "ideal.", '"""', "", "import numba as nb", "import numpy as np", "", ""]  # fmt: skip
    bodies = []
    for guide in (False, True):
        n_in = len(INPUTS) + len(CRANK_INPUTS) + (len(GUIDE_INPUTS) if guide else 0)
        for j in GUIDE_JOINTS if guide else JOINTS:
            lag = free_crank_lagrangian(j, guide)
            th1 = lag.q[0]
            name = f"{j}_guide_free" if guide else f"{j}_free"
            src = accelerations_source(lag, name, n_in, given=(sp.sin(th1), sp.cos(th1)))
            bodies.append(src.replace("math.", "np."))
    return "\n".join(head) + "\n\n".join(bodies)


def _drive_target() -> Path:
    return Path(__file__).with_name("_compressor_contact_drive.py")


#: The configurations whose rod turns with the crank (an ideal crank pin): the worn crosshead
#: pin, then the guide's clearance with it or with both pins ideal, as (joints, guide).
SHARE_CONFIGS = (("crosshead", False), ("crosshead", True), ("ideal", True))


def generate_share() -> str:
    """Source of ``_compressor_contact_share.py``: for the configurations whose crank pin is
    ideal (`SHARE_CONFIGS`), the lower triangle of the mass matrix of `free_crank_lagrangian`
    without the crank's own inertia (rod and crosshead only), ``(m00, m10, m11, ...)`` from
    the coordinates ``q = (theta1, e2x, e2y[, yg])`` or ``(theta1, yg)`` and the joints'
    packed parameters: what a machine of several throws on a motor needs for each such
    throw's share of the crank's inertia (its Schur complement) and the dependence of its
    other accelerations on the crank's (`recipdyn.model.joints.pins.ideal_share`)."""
    import sympy as sp

    from .derive import KernelPrinter

    head = ['"""Generated by ``python -m recipdyn.model.compressor_contact`` -- do not edit by '
            "hand.", "", "The mass matrix (lower triangle, rod and crosshead: the crank's own "
            "inertia left out) of the", "mechanism with an ideal crank pin and the crank angle "
            "free (recipdyn.model.compressor_contact.", "free_crank_lagrangian), q = (theta1, "
            "e2x, e2y[, yg]) or (theta1, yg), read from the tuple ``q``;", "``p`` the joints' "
            'packed parameters (r, l, ls, m2, m3, J2, g, d first).', '"""', "",
            "import numba as nb", "import numpy as np", "", ""]  # fmt: skip
    printer = KernelPrinter({"standard": "python3"})
    bodies = []
    for joints, guide in SHARE_CONFIGS:
        lag = free_crank_lagrangian(joints, guide)
        ic = lag.params[17]
        assert str(ic) == "I_crank", ic
        n = lag.n
        low = [(i, j) for i in range(n) for j in range(i + 1)]
        sub = {ic: sp.S.Zero}
        sub.update({v: sp.Symbol(f"_q{i}") for i, v in enumerate(lag.q)})
        sub.update({v: sp.Symbol(f"_p{i}") for i, v in enumerate(lag.params) if v != ic})
        exprs = [lag.M[i, j].subs(sub) for i, j in low]
        repl, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("x"), optimizations="basic")
        used = set().union(*(e.free_symbols for e in exprs))
        name = f"{joints}_guide_free_mass" if guide else f"{joints}_free_mass"
        doc = '    """(m00, m10, m11, ...) of rod and crosshead (no arrays allocated)."""'
        lines = ["@nb.njit(cache=True)", f"def {name}(q, p):", doc]
        lines += [f"    _q{i} = q[{i}]" for i in range(n) if sp.Symbol(f"_q{i}") in used]
        lines += [f"    _p{i} = p[{i}]" for i in range(len(lag.params))
                  if sp.Symbol(f"_p{i}") in used]  # fmt: skip
        lines += [f"    {v} = {printer.doprint(e)}" for v, e in repl]
        lines.append("    return (" + ", ".join(printer.doprint(e) for e in reduced) + ")")
        bodies.append("\n".join(lines).replace("math.", "np.") + "\n")
    return "\n".join(head) + "\n\n".join(bodies)


def _share_target() -> Path:
    return Path(__file__).with_name("_compressor_contact_share.py")


if __name__ == "__main__":  # pragma: no cover - developer tool
    _target().write_text(generate())
    _drive_target().write_text(generate_drive())
    _share_target().write_text(generate_share())
    print(f"wrote {_target().name}, {_drive_target().name}, {_share_target().name}")
