r"""The compressor with a contact-impact clearance joint at the crank pin (2 relative DOF).

The paper's mechanism (crank ``r`` driven at ``omega``, rod ``l`` with centroid at ``ls``,
crosshead on the guide ``y = -d``, the same load) with the massless link replaced by the joint
model the multibody literature uses (Flores, Ambrósio, Claro & Lankarani 2008): the bearing
centre (the rod's big end) is ``B = A + e``, ``A = r (cos theta1, sin theta1)`` the journal
(crank-pin) centre and ``e = (ex, ey)`` free; the rod angle follows from the guide,
``sin theta2 = -(d + r sin theta1 + ey) / l``, and the crosshead from ``x3 = Bx + l cos theta2``.
The journal and bearing interact only through the joint forces of :mod:`.joints.contact`:
dry contact when the penetration ``delta = |e| - rc`` is positive (the same ``rc`` as the
massless link's length: the radial clearance), with friction, or the oil film of the
lubricated joint. Cartesian ``e`` keeps the equations regular at ``e = 0``.

Equations of motion: Lagrange's equations for ``q = (ex, ey)`` with the crank angle prescribed,
derived by :mod:`.derive` (no small-clearance approximation) into ``_compressor_contact.py``;
the joint force on the bearing ``(Fx, Fy)``, its torque on the rod about ``B`` and the gas force
on the crosshead enter as generalized forces ``Q_k = F . dB/dq_k + T dtheta2/dq_k +
F_gas dx3/dq_k``, computed in the compiled right-hand side.

State: ``(ex, ey, ex', ey', v_impact, W_in, W_loss)``. The last three are auxiliary (no
degrees of freedom; ``ODESystem.aux_states``): the approach velocity of the current impact
(set by the contact-onset event, used by the damping laws), and two work integrals for the
energy balance, ``E + U = E0 + U0 + W_in - W_loss`` (``E`` kinetic + gravity energy of rod and
crosshead, ``U = K delta^2.5 / 2.5`` the contact's elastic energy, ``W_in`` the work of the gas
force and of the crank through the journal, ``W_loss`` the work lost in the joint: contact
damping, friction and the oil film's share).

The Jacobian is a central difference of the right-hand side (steps scaled by the clearance),
the checked fallback of the model interface (the contact laws are not everywhere smooth).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path
from typing import Any

import numba as nb
import numpy as np

from ._compressor_contact import contact_mechanism_system as _mechanism
from .base import EVENT_SIGNATURE, JAC_SIGNATURE, RHS_SIGNATURE, Event, ODESystem, Signal
from .joints.contact import (
    FRICTION_LAWS,
    LAWS,
    friction_factor,
    hertz_stiffness,
    hysteresis_factor,
    normal_force,
    short_bearing_forces,
)
from .load import gas_force_kernel, pack_table
from .parameters import SCHEMA as LINK_SCHEMA
from .protocol import Model, Param, Schema

__all__ = ["CompressorContact", "COMPRESSOR_CONTACT", "lagrangian", "generate", "energy"]

_INF = math.inf
#: Mechanism parameters of the generated kernel, in order, then its force inputs.
MECH = ("r", "l", "ls", "m2", "m3", "J2", "g", "d", "omega", "theta1_0")
INPUTS = ("F_gas", "F_x", "F_y", "T_rod")

# Packed parameter vector: the generated kernel's 14 slots first (inputs filled per call).
(P_R, P_L, P_LS, P_M2, P_M3, P_J2, P_G, P_D, P_OMEGA, P_TH10,
 P_FGAS, P_FX, P_FY, P_TROD) = range(14)  # fmt: skip
(P_C, P_K, P_CHI, P_RJ, P_MU, P_V0, P_V1, P_FLAW, P_OIL, P_LB, P_EPSDRY, P_VMIN,
 P_LOADAMP, P_LOADSIGN, P_LOADKIND, P_TABLE) = range(14, 30)  # fmt: skip


@lru_cache(maxsize=1)
def lagrangian():
    """The derived :class:`~recipdyn.model.derive.Lagrangian` of the mechanism."""
    import sympy as sp

    from .derive import derive

    t = sp.Symbol("t", real=True)
    ex, ey, u, v = sp.symbols("ex ey u v", real=True)
    r, l, ls, m2, m3, J2, g, d, w, th10 = sp.symbols(" ".join(MECH), real=True)
    Fg, Fx, Fy, Tr = sp.symbols(" ".join(INPUTS), real=True)
    th1 = th10 + w * t
    Bx, By = r * sp.cos(th1) + ex, r * sp.sin(th1) + ey
    th2 = sp.asin(-(d + By) / l)
    x3 = Bx + l * sp.cos(th2)
    xg, yg = Bx + ls * sp.cos(th2), By + ls * sp.sin(th2)

    def dt(e):  # total time derivative along (ex, ey) = (u, v)
        return sp.diff(e, t) + sp.diff(e, ex) * u + sp.diff(e, ey) * v

    T = (m2 * (dt(xg) ** 2 + dt(yg) ** 2) + J2 * dt(th2) ** 2 + m3 * dt(x3) ** 2) / 2
    V = m2 * g * yg
    Q = [Fx * sp.diff(Bx, q) + Fy * sp.diff(By, q) + Tr * sp.diff(th2, q) + Fg * sp.diff(x3, q)
         for q in (ex, ey)]  # fmt: skip
    return derive(T, V, (ex, ey), (u, v), t, (r, l, ls, m2, m3, J2, g, d, w, th10, Fg, Fx, Fy,
                                              Tr), Q=Q)  # fmt: skip


def generate() -> str:
    from .derive import kernel_source

    return kernel_source(lagrangian(), "contact_mechanism",
                         "Mechanism of the compressor with a contact-impact crank-pin joint "
                         "(recipdyn.model.compressor_contact).", jacobian=False)  # fmt: skip


def _target() -> Path:
    return Path(__file__).with_name("_compressor_contact.py")


@nb.njit(cache=True)
def _joint(t, y, p, out5):
    """Joint quantities: out5 = [F_x, F_y, T_rod, F_n, F_t] (on the bearing) and returns
    (power from the crank, power lost in the joint, theta2', crosshead velocity x3')."""
    ex, ey, u, v = y[0], y[1], y[2], y[3]
    r, l, d, w = p[P_R], p[P_L], p[P_D], p[P_OMEGA]
    th1 = p[P_TH10] + w * t
    s1, c1 = math.sin(th1), math.cos(th1)
    s2 = -(d + r * s1 + ey) / l
    c2 = math.sqrt(1.0 - s2 * s2)
    th2d = -(r * w * c1 + v) / (l * c2)
    v3 = -r * w * s1 + u - l * s2 * th2d  # x3 = Bx + l cos(theta2)
    vjx, vjy = -r * w * s1, r * w * c1  # journal-centre velocity
    c = p[P_C]
    rho = math.sqrt(ex * ex + ey * ey)
    delta = rho - c
    for i in range(5):
        out5[i] = 0.0
    if rho == 0.0:
        return 0.0, 0.0, th2d, v3
    nx, ny = ex / rho, ey / rho
    tx, ty = -ny, nx
    drho = nx * u + ny * v  # = delta'
    et = tx * u + ty * v
    Rj = p[P_RJ]
    Rb = Rj + c
    fx = 0.0
    fy = 0.0
    trod = 0.0
    p_crank = 0.0
    p_loss = 0.0
    if delta > 0.0:
        K = p[P_K]
        fn = normal_force(delta, drho, max(y[4], p[P_VMIN]), K, p[P_CHI])
        vt = et + w * Rj - th2d * Rb  # sliding velocity, bearing relative to journal
        ft = fn * friction_factor(vt, p[P_MU], p[P_V0], p[P_V1], int(p[P_FLAW]))
        fx += -fn * nx + ft * tx
        fy += -fn * ny + ft * ty
        trod += -Rb * ft
        out5[3] = fn
        out5[4] = ft
        p_crank += -fn * (nx * vjx + ny * vjy) + ft * (tx * vjx + ty * vjy - w * Rj)
        p_loss += (fn - K * delta * math.sqrt(delta)) * drho - ft * vt
    if p[P_OIL] > 0.0:
        # film forces on the journal, along its eccentricity -n and t_j = k x (-n) = -t
        eps = rho / c
        dgam = et / rho
        fr, fth = short_bearing_forces(eps, drho / c, dgam, w + th2d, p[P_OIL], p[P_LB], Rj,
                                       c, p[P_EPSDRY])  # fmt: skip
        bx = fr * nx + fth * tx  # on the bearing: minus the force on the journal
        by = fr * ny + fth * ty
        fx += bx
        fy += by
        out5[3] += -fr
        out5[4] += fth
        p_crank += bx * vjx + by * vjy
        p_loss += -(bx * u + by * v)
    out5[0] = fx
    out5[1] = fy
    out5[2] = trod
    return p_crank, p_loss, th2d, v3


@nb.njit(cache=True)
def _gas(t, p):
    th1 = p[P_TH10] + p[P_OMEGA] * t
    return gas_force_kernel(th1, p[P_LOADKIND], p[P_LOADAMP], p[P_LOADSIGN], p[P_TABLE:])


@nb.njit(RHS_SIGNATURE, cache=True)
def rhs(t, y, p, out):
    q = p[:14].copy()
    f5 = np.empty(5)
    p_crank, p_loss, _, v3 = _joint(t, y, p, f5)
    fg = _gas(t, p)
    q[P_FGAS] = fg
    q[P_FX] = f5[0]
    q[P_FY] = f5[1]
    q[P_TROD] = f5[2]
    M = np.empty((2, 2))
    b = np.empty(2)
    _mechanism(t, y, q, M, b)
    det = M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0]
    out[0] = y[2]
    out[1] = y[3]
    out[2] = (b[0] * M[1, 1] - M[0, 1] * b[1]) / det
    out[3] = (M[0, 0] * b[1] - M[1, 0] * b[0]) / det
    out[4] = 0.0
    out[5] = fg * v3 + p_crank  # gas power + crank power through the journal
    out[6] = p_loss


@nb.njit(JAC_SIGNATURE, cache=True)
def jac(t, y, p, J):
    n = y.shape[0]
    yp = y.copy()
    f1 = np.empty(n)
    f2 = np.empty(n)
    c = p[P_C]
    for k in range(n):
        scale = c if k < 2 else (c * p[P_OMEGA] if k < 5 else 1.0)
        h = 1e-6 * max(abs(y[k]), scale)
        yp[k] = y[k] + h
        rhs(t, yp, p, f1)
        yp[k] = y[k] - h
        rhs(t, yp, p, f2)
        yp[k] = y[k]
        for i in range(n):
            J[i, k] = (f1[i] - f2[i]) / (2.0 * h)


@nb.njit(EVENT_SIGNATURE, cache=True)
def onset(t, y, p):
    return math.sqrt(y[0] * y[0] + y[1] * y[1]) - p[P_C]


@nb.njit(RHS_SIGNATURE, cache=True)
def record_approach(t, y, p, out):
    for i in range(y.shape[0]):
        out[i] = y[i]
    rho = math.sqrt(y[0] * y[0] + y[1] * y[1])
    out[4] = max((y[0] * y[2] + y[1] * y[3]) / rho, p[P_VMIN])


def _link(name: str, **changes) -> Param:
    from dataclasses import replace

    return replace(LINK_SCHEMA[name], **changes)


SCHEMA = Schema((
    *(_link(k) for k in ("r", "l", "ls", "m2", "m3", "J2", "g")),
    _link("rc", description="radial clearance of the crank-pin joint, c = R_b - R_j",
          low=0.0, low_open=True),
    _link("d"),
    Param("joint", "", "dry", "'dry' contact-impact or 'lubricated' (oil film + dry contact "
          "beyond eps_dry)", choices=("dry", "lubricated"), group="joint"),
    Param("contact_law", "", "lankarani-nikravesh", "normal force law (hysteresis damping)",
          choices=LAWS, group="joint"),
    Param("restitution", "", 0.9, "nominal coefficient of restitution of the law", 0.0, 1.0,
          low_open=True, group="joint"),
    Param("K", "N/m**1.5", None, "contact stiffness (default: Hertz pin-in-hole from the radii "
          "and materials)", 0.0, _INF, low_open=True, group="joint", optional=True),
    Param("journal_radius", "m", 0.05, "crank-pin (journal) radius R_j", 0.0, _INF,
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
    _link("omega"), _link("theta1_0"),
    _link("load_amplitude"), _link("load_sign"),
    Param("e0_angle", "rad", None, "initial direction of e (default: aligned with the rod "
          "load, as the massless link's default)", -1e6, 1e6, group="initial", optional=True),
    Param("e0_ratio", "", 1.0, "initial |e| / rc", 0.0, 1.5, group="initial"),
    Param("edot0_x", "m/s", 0.0, "initial ex'", -1e3, 1e3, group="initial"),
    Param("edot0_y", "m/s", 0.0, "initial ey'", -1e3, 1e3, group="initial"),
), aliases={"clearance": "rc", "subsidence": "d", "speed": "omega", "crank_speed": "omega",
            "c": "rc", "law": "contact_law"})  # fmt: skip


def stiffness(values: Mapping[str, Any]) -> float:
    """K (N/m^1.5): the value given, or Hertz's pin-in-hole formula."""
    if values.get("K") is not None:
        return float(values["K"])
    rj = float(values["journal_radius"])
    return hertz_stiffness(rj, rj + float(values["rc"]), values["E_journal"],
                           values["nu_journal"], values["E_bearing"],
                           values["nu_bearing"])  # fmt: skip


def pack(values: Mapping[str, Any]) -> np.ndarray:
    v = values
    head = [v[k] for k in MECH] + [0.0] * 4
    head += [v["rc"], stiffness(v), hysteresis_factor(v["contact_law"], v["restitution"]),
             v["journal_radius"], v["friction"], v["v0"], v["v1"],
             float(FRICTION_LAWS.index(v["friction_law"])),
             v["oil_viscosity"] if v["joint"] == "lubricated" else 0.0, v["bearing_length"],
             v["eps_dry"], v["v_impact_min"], v["load_amplitude"],
             -1.0 if v["load_sign"] == "physical" else 1.0, 0.0]  # fmt: skip
    return np.concatenate([np.asarray(head, dtype=np.float64), pack_table(None)])


def energy(values: Mapping[str, Any], t: np.ndarray, y: np.ndarray) -> dict[str, np.ndarray]:
    """Kinetic + gravity energy of rod and crosshead and the contact's elastic energy (J)."""
    r, l, ls, m2, m3, J2, g, d, w, th10 = (float(values[k]) for k in MECH)
    th1 = th10 + w * t
    ex, ey, u, v = y[:, 0], y[:, 1], y[:, 2], y[:, 3]
    s2 = -(d + r * np.sin(th1) + ey) / l
    c2 = np.sqrt(1.0 - s2**2)
    th2d = -(r * w * np.cos(th1) + v) / (l * c2)
    vbx, vby = -r * w * np.sin(th1) + u, r * w * np.cos(th1) + v
    vgx, vgy = vbx - ls * s2 * th2d, vby + ls * c2 * th2d
    v3 = vbx - l * s2 * th2d
    kin = 0.5 * (m2 * (vgx**2 + vgy**2) + J2 * th2d**2 + m3 * v3**2)
    pot = m2 * g * (r * np.sin(th1) + ey + ls * s2)
    delta = np.maximum(np.hypot(ex, ey) - float(values["rc"]), 0.0)
    return {"mechanical": kin + pot, "elastic": stiffness(values) * delta**2.5 / 2.5}


@nb.njit(cache=True)
def _joint_series(rhs, t, y, p):
    """Per sample: F_x, F_y, T_rod, F_n, F_t, ex'', ey'', theta2', x3', gas force."""
    n = t.shape[0]
    out = np.empty((n, 10))
    f5 = np.empty(5)
    f = np.empty(y.shape[1])
    for i in range(n):
        yi = y[i].copy()
        rhs(t[i], yi, p, f)
        _, _, th2d, v3 = _joint(t[i], yi, p, f5)
        out[i, 0:5] = f5
        out[i, 5] = f[2]
        out[i, 6] = f[3]
        out[i, 7] = th2d
        out[i, 8] = v3
        out[i, 9] = _gas(t[i], p)
    return out


class CompressorContact(Model):
    """The compressor with a contact-impact (dry or lubricated) crank-pin clearance joint."""

    name = "compressor-contact"
    description = ("compressor with a contact-impact crank-pin clearance joint (free flight, "
                   "impacts, friction, oil film; Flores et al. 2008)")  # fmt: skip
    state_names = ("ex", "ey", "ex_dot", "ey_dot", "v_impact", "W_in", "W_loss")
    state_units = ("m", "m", "m/s", "m/s", "m/s", "J", "J")
    schema = SCHEMA
    section_signals = (("ex", "m"), ("ey", "m"), ("x", "m"), ("v", "m/s"), ("a", "m/s**2"))
    vibration_signal = ("a", "m/s**2")
    section_pair = ("v", "a")
    #: The paper's load never reverses (the journal stays on the wall); at 150 rad/s with a
    #: tenth of it, inertia separates the journal and it impacts several times a revolution.
    event_example = {"omega": 150.0, "load_amplitude": 2e4}
    lyapunov_refusal = (
        "Benettin's method needs an exact Jacobian; this model's is a finite difference, whose "
        "rounding noise (~1e-4 of the contact stiffness terms) forces the tangent integration "
        "into ~10^6 steps per revolution at rtol 1e-10. Use the signal estimators "
        "(recipdyn analyze) until the exact Jacobian is generated"
    )

    def check(self, values: Mapping[str, Any]) -> None:
        from ..errors import ParameterError

        if values["rc"] >= values["r"]:
            raise ParameterError(f"rc = {values['rc']!r} m is out of range; allowed: "
                                 f"(0, r = {values['r']!r}) m")  # fmt: skip
        dmax = values["l"] - values["r"] - 1.5 * values["rc"]
        if not abs(values["d"]) < dmax:
            raise ParameterError(f"d = {values['d']!r} m is out of range; allowed: "
                                 f"(-{dmax:g}, {dmax:g}) m (l - r - 1.5 rc)")  # fmt: skip
        if values["v1"] <= values["v0"]:
            raise ParameterError(f"v1 = {values['v1']!r} m/s must exceed v0 = "
                                 f"{values['v0']!r} m/s")  # fmt: skip

    def events(self, values: Mapping[str, Any]) -> tuple[Event, ...]:
        return (Event("impact", onset, direction=1, action="reset", reset=record_approach,
                      description="contact onset (|e| = rc, approaching): the approach "
                      "velocity is recorded for the damping law"),)  # fmt: skip

    def system(self, values: Mapping[str, Any]) -> ODESystem:
        return ODESystem(rhs=rhs, jac=jac, params=pack(values), state_names=self.state_names,
                         state_units=self.state_units, period=self.period(values),
                         name=self.name, events=self.events(values), aux_states=3)  # fmt: skip

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        ang = values["e0_angle"]
        if ang is None:  # as the massless link: e along the rod load (rod in compression)
            from .compressor import equilibrium_theta_c
            from .parameters import CompressorParams

            cp = CompressorParams(**{k: values[k] for k in (*MECH, "rc", "load_amplitude",
                                                            "load_sign")})  # fmt: skip
            ang = equilibrium_theta_c(cp)
        e = values["e0_ratio"] * values["rc"]
        return np.array([e * math.cos(ang), e * math.sin(ang), values["edot0_x"],
                         values["edot0_y"], values["v_impact_min"], 0.0, 0.0])  # fmt: skip

    def period(self, values: Mapping[str, Any]) -> float:
        return 2.0 * math.pi / float(values["omega"])

    def outputs(self, values: Mapping[str, Any], t: np.ndarray, y: np.ndarray
                ) -> dict[str, Signal]:  # fmt: skip
        s = self.system(values)
        t = np.ascontiguousarray(t, dtype=float)
        y = np.ascontiguousarray(y, dtype=float)
        j = _joint_series(s.rhs, t, y, s.params)
        r, l, d, w = (float(values[k]) for k in ("r", "l", "d", "omega"))
        th1 = float(values["theta1_0"]) + w * t
        ex, ey = y[:, 0], y[:, 1]
        s2 = -(d + r * np.sin(th1) + ey) / l
        c2 = np.sqrt(1.0 - s2**2)
        th2d = j[:, 7]
        # theta2'' from sin(theta2)'' = -(-r w^2 sin(theta1) + ey'') / l
        s2dd = -(-r * w**2 * np.sin(th1) + j[:, 6]) / l
        th2dd = (s2dd + s2 * th2d**2) / c2
        x3 = r * np.cos(th1) + ex + l * c2
        v3 = j[:, 8]
        a3 = -r * w**2 * np.cos(th1) + j[:, 5] - l * (c2 * th2d**2 + s2 * th2dd)
        rho = np.hypot(ex, ey)
        delta = rho - float(values["rc"])
        en = energy(values, t, y)
        fn = j[:, 3]
        sig = {
            "x": Signal(x3, "m", "crosshead displacement x3"),
            "v": Signal(v3, "m/s", "crosshead velocity"),
            "a": Signal(a3, "m/s**2", "crosshead acceleration"),
            "theta1": Signal(th1, "rad", "crank angle"),
            "theta2": Signal(np.arcsin(s2), "rad", "connecting-rod angle"),
            "ex": Signal(ex, "m", "eccentricity x (bearing centre - journal centre)"),
            "ey": Signal(ey, "m", "eccentricity y"),
            "eccentricity_ratio": Signal(rho / float(values["rc"]), "", "|e| / rc"),
            "delta": Signal(delta, "m", "penetration |e| - rc (> 0: in contact)"),
            "contact": Signal((delta > 0).astype(float), "", "1 in contact, 0 in free flight"),
            "normal_force": Signal(fn, "N", "joint normal force on the bearing (contact + film)"),
            "tangential_force": Signal(j[:, 4], "N", "joint tangential force on the bearing"),
            "joint_force_x": Signal(j[:, 0], "N", "joint force on the rod, x"),
            "joint_force_y": Signal(j[:, 1], "N", "joint force on the rod, y"),
            "joint_force": Signal(np.hypot(j[:, 0], j[:, 1]), "N", "joint force magnitude"),
            "gas_force": Signal(j[:, 9], "N", "gas force on the crosshead along +x"),
            "energy": Signal(en["mechanical"] + en["elastic"], "J",
                             "kinetic + gravity energy of rod and crosshead + contact elastic"),
        }  # fmt: skip
        return sig


COMPRESSOR_CONTACT = CompressorContact()

if __name__ == "__main__":  # pragma: no cover - developer tool
    _target().write_text(generate())
    print(f"wrote {_target().name}")
