r"""Symbolic derivation of the clearance-joint equation of motion (sympy).

Two independent derivations of the same equation live here:

1. [`structured_equations`][recipdyn.model.derivation.structured_equations] follows the paper's
   route (Eq. 3-42): exact first and second partial derivatives of the centroid positions
   with respect to the crank angle
   :math:`\theta_1` and the clearance angle :math:`\theta_c`, assembled into

   .. math:: A\,\ddot\theta_c = -C_q\,\dot\theta_c^2 - 2\omega B_q\,\dot\theta_c - \omega^2 D_q
             - G + Q,

   with :math:`A = J_2\theta_{2,c}^2 + \sum_i m_i |\mathbf p_{i,c}|^2`,
   :math:`B_q = J_2\theta_{2,c}\theta_{2,1c} + \sum_i m_i\,\mathbf p_{i,c}\cdot\mathbf p_{i,1c}`,
   :math:`C_q = J_2\theta_{2,c}\theta_{2,cc} + \sum_i m_i\,\mathbf p_{i,c}\cdot\mathbf p_{i,cc}`,
   :math:`D_q = J_2\theta_{2,c}\theta_{2,11} + \sum_i m_i\,\mathbf p_{i,c}\cdot\mathbf p_{i,11}`,
   :math:`G = g\sum_i m_i\,\partial y_i/\partial\theta_c` and
   :math:`Q = F_x\,\partial x_3/\partial\theta_c`
   (subscripts after the comma are partial derivatives). No small-clearance approximation is
   made. The rod angle enters only through :math:`\sin\theta_2 = -(d + r\sin\theta_1 +
   r_c\sin\theta_c)/l` and :math:`\cos\theta_2 = +\sqrt{1-\sin^2\theta_2}` (crosshead on the
   +x side), and sympy differentiates with the exact chain rule
   :math:`\partial\theta_2/\partial\theta_c = -r_c\cos\theta_c/(l\cos\theta_2)`.
   The Jacobian of the state-space right-hand side is derived from the same expressions.
   [`generate_code`][recipdyn.model.derivation.generate_code] prints both as numba kernels into
   ``_generated.py``.

2. [`brute_force_lagrangian`][recipdyn.model.derivation.brute_force_lagrangian] writes the kinetic
   and potential energy with
   :math:`\theta_2 = -\arcsin(\dots)` substituted and lets sympy form
   :math:`\frac{d}{dt}\partial L/\partial\dot\theta_c - \partial L/\partial\theta_c = Q` directly.
   The tests compare the two over random states (and a third, Newton-Euler check in
   [`recipdyn.model.kinematics`][recipdyn.model.kinematics] shows the joint force is along the
   clearance link).

Run ``python -m recipdyn.model.derivation`` to regenerate ``_generated.py``;
``tests/test_derivation.py`` fails if the committed file is out of date.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import sympy as sp

from .derive import KernelPrinter

__all__ = ["SYMBOLS", "structured_equations", "brute_force_lagrangian", "generate_code"]

# Symbols shared by both derivations. F is the horizontal force on the crosshead (+x positive),
# evaluated outside (it depends on the crank angle only).
r, rs, l, ls, m1, m2, m3, J1, J2, g, rc, d, w, F = sp.symbols(
    "r r_s l l_s m1 m2 m3 J1 J2 g r_c d omega F", real=True
)
th1, thc, thcd = sp.symbols("theta1 theta_c thetadot_c", real=True)
SYMBOLS = dict(
    r=r,
    rs=rs,
    l=l,
    ls=ls,
    m1=m1,
    m2=m2,
    m3=m3,
    J1=J1,
    J2=J2,
    g=g,
    rc=rc,
    d=d,
    omega=w,
    F=F,
    theta1=th1,
    theta_c=thc,
    thetadot_c=thcd,
)


def _theta2():
    s2 = -(d + r * sp.sin(th1) + rc * sp.sin(thc)) / l
    return sp.asin(s2)


@lru_cache(maxsize=1)
def structured_equations() -> dict[str, sp.Expr]:
    """Exact coefficients and right-hand side following the paper's structure (Eq. 38-42).

    Returns
    -------
    dict
        ``A, Bq, Cq, Dq, G, Q`` as defined in the module docstring, ``acc`` (the clearance-angle
        acceleration), ``dacc_dthc`` and ``dacc_dthcd`` (its partial derivatives, for the
        Jacobian), and the kinematic partials ``theta2, th2_1, th2_c, th2_11, th2_1c, th2_cc``.
    """
    th2 = _theta2()

    def pt(lam):
        return sp.Matrix(
            [
                r * sp.cos(th1) + rc * sp.cos(thc) + lam * sp.cos(th2),
                r * sp.sin(th1) + rc * sp.sin(thc) + lam * sp.sin(th2),
            ]
        )

    bodies = [(m2, pt(ls)), (m3, pt(l))]  # the crank (m1, J1) does not move with theta_c
    d_c = lambda e: sp.diff(e, thc)
    d_1 = lambda e: sp.diff(e, th1)
    th2_c = d_c(th2)
    A = J2 * th2_c**2
    Bq = J2 * th2_c * d_1(th2_c)
    Cq = J2 * th2_c * d_c(th2_c)
    Dq = J2 * th2_c * d_1(d_1(th2))
    for m, p in bodies:
        pc = p.diff(thc)
        A += m * pc.dot(pc)
        Bq += m * pc.dot(p.diff(th1).diff(thc))
        Cq += m * pc.dot(pc.diff(thc))
        Dq += m * pc.dot(p.diff(th1, 2))
    G = g * m2 * d_c(pt(ls)[1])  # the crosshead's height is fixed at -d
    Q = F * d_c(pt(l)[0])
    acc = (-Cq * thcd**2 - 2 * w * Bq * thcd - w**2 * Dq - G + Q) / A
    return dict(
        A=A, Bq=Bq, Cq=Cq, Dq=Dq, G=G, Q=Q, acc=acc,
        dacc_dthc=sp.diff(acc, thc), dacc_dthcd=sp.diff(acc, thcd),
        theta2=th2, th2_1=d_1(th2), th2_c=th2_c, th2_11=d_1(d_1(th2)),
        th2_1c=d_1(th2_c), th2_cc=d_c(th2_c),
    )  # fmt: skip


@lru_cache(maxsize=1)
def brute_force_lagrangian() -> sp.Expr:
    """Clearance-angle acceleration from the Lagrangian with explicit time (second derivation).

    The crank angle is prescribed, ``theta1 = omega t`` (its offset is irrelevant for the
    equation's form), the clearance angle is an unknown function of time, and sympy forms
    Lagrange's equation with the generalized force ``Q = F dx3/dtheta_c`` (Eq. 34-36).

    Returns
    -------
    sympy.Expr
        ``theta_c''`` in terms of ``theta1, theta_c, thetadot_c`` and the parameters.
    """
    t = sp.symbols("t", real=True)
    q = sp.Function("q")(t)
    a1 = w * t
    s2 = -(d + r * sp.sin(a1) + rc * sp.sin(q)) / l
    a2 = sp.asin(s2)
    x1, y1 = rs * sp.cos(a1), rs * sp.sin(a1)
    x2 = r * sp.cos(a1) + rc * sp.cos(q) + ls * sp.cos(a2)
    y2 = r * sp.sin(a1) + rc * sp.sin(q) + ls * sp.sin(a2)
    x3 = r * sp.cos(a1) + rc * sp.cos(q) + l * sp.cos(a2)
    v2 = lambda x, y: sp.diff(x, t) ** 2 + sp.diff(y, t) ** 2
    T = (m1 * v2(x1, y1) + m2 * v2(x2, y2) + m3 * sp.diff(x3, t) ** 2) / 2
    T += (J1 * sp.diff(a1, t) ** 2 + J2 * sp.diff(a2, t) ** 2) / 2
    V = g * (m1 * y1 + m2 * y2)
    L = T - V
    qd, qdd = sp.symbols("qd qdd")
    eom = sp.diff(sp.diff(L, sp.diff(q, t)), t) - sp.diff(L, q) - F * sp.diff(x3, q)
    eom = eom.subs(sp.diff(q, t, 2), qdd).subs(sp.diff(q, t), qd).subs(q, thc)
    eom = eom.subs(qd, thcd).subs(t, th1 / w)
    coeff = sp.diff(eom, qdd)
    rest = eom.subs(qdd, 0)
    return -rest / coeff


_HEADER = '''"""Generated by ``python -m recipdyn.model.derivation`` -- do not edit by hand.

Exact clearance-angle acceleration and its partial derivatives for the single-DOF massless-link
clearance model (see [`recipdyn.model.derivation`][recipdyn.model.derivation] for the derivation).
The arguments are scalars; the assembler reads them from a throw's mechanism slice
(`recipdyn.model.mechanism.link_kernels`).
"""

import math

import numba as nb

'''


def _kernel(name: str, exprs: list[sp.Expr], outs: list[str], doc: str) -> str:
    repl, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("x"), optimizations="basic")
    lines = [
        "@nb.njit(cache=True, fastmath=False, error_model='numpy')",
        f"def {name}(theta1, theta_c, thetadot_c, F, r, l, ls, m2, m3, J2, g, rc, d, omega):",
        f'    """{doc}"""',
    ]
    printer = KernelPrinter({"standard": "python3"})
    code = printer.doprint

    for sym, e in repl:
        lines.append(f"    {sym} = {code(e)}")
    lines.append("    return " + ", ".join(code(e) for e in reduced))
    del outs
    return "\n".join(lines) + "\n"


def generate_code() -> str:
    """Source of ``_generated.py``: numba kernels for the acceleration and its Jacobian."""
    eq = structured_equations()
    names = dict(
        theta1="theta1", theta_c="theta_c", thetadot_c="thetadot_c", F="F", r="r", l="l",
        l_s="ls", m2="m2", m3="m3", J2="J2", g="g", r_c="rc", d="d", omega="omega",
    )  # fmt: skip
    sub = {s: sp.Symbol(names[s.name]) for s in eq["acc"].free_symbols if s.name in names}
    body = _HEADER
    body += _kernel(
        "clearance_acceleration",
        [eq["acc"].subs(sub)],
        ["acc"],
        "Exact theta_c'' (rad/s^2) from Lagrange's equation, Eq. (38) without approximation.",
    )
    body += "\n\n"
    body += _kernel(
        "clearance_acceleration_jac",
        [eq["acc"].subs(sub), eq["dacc_dthc"].subs(sub), eq["dacc_dthcd"].subs(sub)],
        ["acc", "dacc_dthc", "dacc_dthcd"],
        "theta_c'' and its partial derivatives with respect to theta_c and theta_c'.",
    )
    return body


# The crank as a degree of freedom (a motor drive): theta1 joins theta_c as a coordinate.
th1d, Jd, Tm = sp.symbols("thetadot_1 J_d T_m", real=True)
#: Parameters of the free-crank kernels, in the order of the compressor's packed vector
#: (mechanism first), then the inputs the drive and the load compute per call.
DRIVE_PARAMS = (r, rs, l, ls, m1, m2, m3, J1, J2, g, rc, d, Jd, F, Tm)
DRIVE_INPUTS = 3  # J_d, F, T_m


def _free_crank_energy(ideal: bool):
    """Kinetic and potential energy of the mechanism with the crank angle free; ``ideal``:
    rc = 0 (no clearance coordinate)."""
    q_c = sp.S.Zero if ideal else thc
    s2 = -(d + r * sp.sin(th1) + (0 if ideal else rc) * sp.sin(q_c)) / l
    a2 = sp.asin(s2)
    t = sp.symbols("t", real=True)
    f1 = sp.Function("f1")(t)
    fc = sp.Function("fc")(t)
    sub_t = {th1: f1, thc: fc}
    pos = {
        "x1": rs * sp.cos(th1), "y1": rs * sp.sin(th1),
        "x2": r * sp.cos(th1) + (0 if ideal else rc * sp.cos(thc)) + ls * sp.cos(a2),
        "y2": r * sp.sin(th1) + (0 if ideal else rc * sp.sin(thc)) + ls * sp.sin(a2),
        "x3": r * sp.cos(th1) + (0 if ideal else rc * sp.cos(thc)) + l * sp.cos(a2),
    }  # fmt: skip
    back = {sp.diff(f1, t): th1d, sp.diff(fc, t): thcd, f1: th1, fc: thc}

    def rate(e):
        return sp.diff(e.subs(sub_t), t).subs(back)

    T = (m1 * (rate(pos["x1"]) ** 2 + rate(pos["y1"]) ** 2)
         + m2 * (rate(pos["x2"]) ** 2 + rate(pos["y2"]) ** 2) + m3 * rate(pos["x3"]) ** 2
         + (J1 + Jd) * th1d**2 + J2 * rate(a2) ** 2) / 2  # fmt: skip
    V = g * (m1 * pos["y1"] + m2 * pos["y2"])
    return T, V, pos["x3"]


@lru_cache(maxsize=2)
def free_crank_lagrangian(ideal: bool = False):
    """Lagrange's equations of the mechanism with the crank angle free (a motor drive):
    coordinates ``(theta1, theta_c)`` (``(theta1,)`` for ``ideal``, rc = 0), the crank driven
    by the torque ``T_m`` on an inertia ``J_d`` (motor rotor and flywheel referred to the crank
    shaft), the gas force ``F`` on the crosshead along +x doing the virtual work
    ``F dx3``. With ``theta1'' = 0`` the theta_c row is the prescribed-speed equation
    (`structured_equations`); the tests check it."""
    T, V, x3 = _free_crank_energy(ideal)
    t = sp.symbols("t", real=True)
    if ideal:
        q, qd = (th1,), (th1d,)
        Q = (F * sp.diff(x3, th1) + Tm,)
    else:
        q, qd = (th1, thc), (th1d, thcd)
        Q = (F * sp.diff(x3, th1) + Tm, F * sp.diff(x3, thc))
    from .derive import derive

    return derive(T, V, q, qd, t, DRIVE_PARAMS, Q)


def generate_drive_code() -> str:
    """Source of ``_generated_drive.py``: the free-crank accelerations (rc > 0 and rc = 0)
    and the mechanism's energy ``T + V``, allocation-free numba functions."""
    from .derive import accelerations_source

    head = ('"""Generated by ``python -m recipdyn.model.derivation`` -- do not edit by hand.\n\n'
            "The mechanism with the crank angle free (a motor drive): ``(theta1'', theta_c'')``\n"
            "from Lagrange's equations (`recipdyn.model.derivation.free_crank_lagrangian`),\n"
            "and the mechanism's energy. ``y = (theta1, theta_c, theta1', theta_c')`` (a tuple),\n"
            "``p`` the compressor's mechanism parameters (r, rs, l, ls, m1, m2, m3, J1, J2, g,\n"
            "rc, d), ``u = (J_d, F, T_m)``.\n"
            '"""\n\nimport math\n\nimport numba as nb\n\n\n')  # fmt: skip
    body = accelerations_source(free_crank_lagrangian(False), "free_crank", DRIVE_INPUTS)
    body += "\n\n" + accelerations_source(free_crank_lagrangian(True), "free_crank_ideal",
                                         DRIVE_INPUTS)  # fmt: skip
    T, V, _ = _free_crank_energy(False)
    names = {s: sp.Symbol(n) for s, n in (
        (th1, "theta1"), (thc, "theta_c"), (th1d, "thetadot_1"), (thcd, "thetadot_c"), (r, "r"),
        (rs, "rs"), (l, "l"), (ls, "ls"), (m1, "m1"), (m2, "m2"), (m3, "m3"), (J1, "J1"),
        (J2, "J2"), (g, "g"), (rc, "rc"), (d, "d"), (Jd, "J_d"))}  # fmt: skip
    repl, (e,) = sp.cse([(T + V).subs(names)], symbols=sp.numbered_symbols("x"),
                        optimizations="basic")  # fmt: skip
    printer = KernelPrinter({"standard": "python3"})
    lines = [
        "@nb.njit(cache=True)",
        "def mechanism_energy(theta1, theta_c, thetadot_1, thetadot_c, r, rs, l, ls, m1, m2, "
        "m3, J1, J2, g, rc, d, J_d):",
        '    """Kinetic + potential energy of crank (with J_d), rod and crosshead, J."""',
    ]
    lines += [f"    {s} = {printer.doprint(v)}" for s, v in repl]
    lines.append(f"    return {printer.doprint(e)}")
    return head + body + "\n\n" + "\n".join(lines) + "\n"


def generate_throw_code() -> str:
    """Source of ``mechanism/_generated_throw.py``: one throw's part of the free-crank
    equations (`free_crank_lagrangian` without the drive's inertia and torque), ``M`` and
    ``b`` as tuples, for an assembly of throws on one crankshaft to combine (the crank's row
    gets every throw's contribution, `recipdyn.model.mechanism.link`)."""
    from .derive import system_source

    head = ('"""Generated by ``python -m recipdyn.model.derivation`` -- do not edit by hand.\n\n'
            "One massless-link throw with the crank angle free: the lower triangle of its mass\n"
            "matrix and its right-hand side, ``M (theta1'', theta_c'') = b``\n"
            "(`recipdyn.model.derivation.free_crank_lagrangian` without the drive's inertia\n"
            "``J_d`` and torque ``T_m``, which the crankshaft adds once for all its throws).\n"
            "``y = (theta1, theta_c, theta1', theta_c')`` (a tuple; theta1 the throw's own crank\n"
            "angle, its phase included), ``p`` read at the throw's mechanism slice ``m`` (r, rs,\n"
            "l, ls, m1, m2, m3, J1, J2, g, rc, d), ``u = (F,)`` the gas force on the crosshead.\n"
            '"""\n\nimport math\n\nimport numba as nb\n\n\n')  # fmt: skip
    reads = {sym: f"p[m + {i}]" for i, sym in enumerate(DRIVE_PARAMS[:12])}
    reads.update({Jd: "0.0", Tm: "0.0", F: "u[0]"})
    body = system_source(
        free_crank_lagrangian(False),
        "link_throw",
        reads,
        "(m00, m10, m11, b0, b1) of one throw (no arrays allocated).",
    )
    body += "\n\n" + system_source(
        free_crank_lagrangian(True),
        "link_throw_ideal",
        reads,
        "(m00, b0) of one throw with an ideal crank pin (rc = 0); y = (theta1, theta1').",
    )
    return head + body  # fmt: skip


def _throw_target() -> Path:
    return Path(__file__).parent / "mechanism" / "_generated_throw.py"


def _drive_target() -> Path:
    return Path(__file__).with_name("_generated_drive.py")


def _target() -> Path:
    return Path(__file__).with_name("_generated.py")


if __name__ == "__main__":  # pragma: no cover - developer tool
    _target().write_text(generate_code())
    _drive_target().write_text(generate_drive_code())
    _throw_target().write_text(generate_throw_code())
    print(f"wrote {_target().name}, {_drive_target().name}, {_throw_target().name}")
