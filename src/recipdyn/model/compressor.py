r"""The single-cylinder compressor with a crank-pin clearance as an :class:`ODESystem`.

State ``y = (theta_c, theta_c')``; time ``t`` in s; crank angle ``theta1 = theta1_0 + omega t``.
The right-hand side is ``(theta_c', theta_c'')`` with ``theta_c''`` from

* ``equations="exact"``: Lagrange's equation derived without approximation
  (:mod:`.derivation`, compiled code in :mod:`._generated`), with an exact Jacobian;
* ``equations="paper-printed"``: Eq. (43)-(47) as printed (:mod:`.paper_printed`), whose
  Jacobian's ``d/d theta_c`` column is a central difference (the printed coefficients are a
  comparison variant only).

With ``rc = 0`` the clearance angle has no dynamics (the mechanism is ideal); the kernel then
returns ``theta_c'' = 0`` and the outputs are the ideal slider-crank's.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numba as nb
import numpy as np

from ._generated import clearance_acceleration, clearance_acceleration_jac
from .base import (
    JAC_SIGNATURE,
    RHS_JAC_SIGNATURE,
    RHS_SIGNATURE,
    ODESystem,
    Signal,
    compiled,
    rhs_series,
)
from .cycle import cycle_force_kernel, cycle_states, cycle_summary
from .kinematics import joint_forces, kinematics
from .load import gas_force, gas_force_kernel, mu_kernel, pack_load
from .paper_printed import paper_acceleration
from .parameters import SCHEMA, CompressorParams, ParameterError
from .protocol import Model

__all__ = [
    "CompressorModel", "compressor_model", "equilibrium_theta_c", "pack_params", "Compressor",
    "COMPRESSOR",
]  # fmt: skip

# Layout of the packed parameter vector.
P_R, P_RS, P_L, P_LS, P_M1, P_M2, P_M3, P_J1, P_J2, P_G = range(10)
P_RC, P_D, P_OMEGA, P_TH10, P_LOADKIND, P_LOADAMP, P_LOADSIGN, P_TABLE = range(10, 18)


def pack_params(p: CompressorParams) -> np.ndarray:
    """Flat float64 vector for the compiled kernels (layout: the ``P_*`` constants)."""
    kind, data = pack_load(vars(p))
    head = [p.r, p.rs, p.l, p.ls, p.m1, p.m2, p.m3, p.J1, p.J2, p.g, p.rc, p.d, p.omega]
    head += [p.theta1_0, kind, p.load_amplitude]
    head += [-1.0 if p.load_sign == "physical" else 1.0]
    return np.concatenate([np.asarray(head, dtype=np.float64), data])


@nb.njit(cache=True)
def _force(t, p):
    th1 = p[P_TH10] + p[P_OMEGA] * t
    if p[P_LOADKIND] == 0.0:  # the paper's load: no table slice in the hot path
        return th1, p[P_LOADSIGN] * p[P_LOADAMP] * mu_kernel(th1)
    return th1, gas_force_kernel(th1, p[P_LOADKIND], p[P_LOADAMP], p[P_LOADSIGN], p[P_TABLE:])


@nb.njit(cache=True, inline="always")
def _force_paper(t, p):
    th1 = p[P_TH10] + p[P_OMEGA] * t
    return th1, p[P_LOADSIGN] * p[P_LOADAMP] * mu_kernel(th1)


# The load is chosen when the model is built, not tested at every call: the mere presence of the
# table branch costs the paper-load right-hand side ~10 % (measured: 109 vs 99 ns a call).
@nb.njit(cache=True, inline="always")
def _rhs_exact(t, y, p, out, force):
    out[0] = y[1]
    if p[P_RC] == 0.0:
        out[1] = 0.0
        return
    th1, F = force(t, p)
    out[1] = clearance_acceleration(
        th1, y[0], y[1], F, p[P_R], p[P_L], p[P_LS], p[P_M2], p[P_M3], p[P_J2], p[P_G],
        p[P_RC], p[P_D], p[P_OMEGA],
    )  # fmt: skip


@nb.njit(cache=True, inline="always")
def _rhs_jac_exact(t, y, p, out, J, force):
    out[0] = y[1]
    J[0, 0] = 0.0
    J[0, 1] = 1.0
    if p[P_RC] == 0.0:
        out[1] = 0.0
        J[1, 0] = 0.0
        J[1, 1] = 0.0
        return
    th1, F = force(t, p)
    out[1], J[1, 0], J[1, 1] = clearance_acceleration_jac(
        th1, y[0], y[1], F, p[P_R], p[P_L], p[P_LS], p[P_M2], p[P_M3], p[P_J2], p[P_G],
        p[P_RC], p[P_D], p[P_OMEGA],
    )  # fmt: skip


@compiled(RHS_SIGNATURE)
def rhs_exact(t, y, p, out):
    """Exact equation, the paper's load."""
    _rhs_exact(t, y, p, out, _force_paper)


@compiled(RHS_JAC_SIGNATURE)
def rhs_jac_exact(t, y, p, out, J):
    _rhs_jac_exact(t, y, p, out, J, _force_paper)


@compiled(JAC_SIGNATURE, allocates=True)
def jac_exact(t, y, p, out):
    f = np.empty(2)
    _rhs_jac_exact(t, y, p, f, out, _force_paper)


@nb.njit(cache=True, inline="always")
def _force_cycle(t, p):
    th1 = p[P_TH10] + p[P_OMEGA] * t
    return th1, cycle_force_kernel(th1, p[P_TABLE:])


@compiled(RHS_SIGNATURE)
def rhs_exact_cycle(t, y, p, out):
    """Exact equation, the compression-cycle load."""
    _rhs_exact(t, y, p, out, _force_cycle)


@compiled(RHS_JAC_SIGNATURE)
def rhs_jac_exact_cycle(t, y, p, out, J):
    _rhs_jac_exact(t, y, p, out, J, _force_cycle)


@compiled(JAC_SIGNATURE, allocates=True)
def jac_exact_cycle(t, y, p, out):
    f = np.empty(2)
    _rhs_jac_exact(t, y, p, f, out, _force_cycle)


@compiled(RHS_SIGNATURE)
def rhs_exact_table(t, y, p, out):
    """Exact equation, a tabulated load."""
    _rhs_exact(t, y, p, out, _force)


@compiled(RHS_JAC_SIGNATURE)
def rhs_jac_exact_table(t, y, p, out, J):
    _rhs_jac_exact(t, y, p, out, J, _force)


@compiled(JAC_SIGNATURE, allocates=True)
def jac_exact_table(t, y, p, out):
    f = np.empty(2)
    _rhs_jac_exact(t, y, p, f, out, _force)


@nb.njit(cache=True)
def _paper_acc(t, q, qd, p):
    th1, F = _force(t, p)
    return paper_acceleration(
        th1, q, qd, F, p[P_R], p[P_L], p[P_M2], p[P_M3], p[P_J2], p[P_RC], p[P_D], p[P_OMEGA]
    )


@compiled(RHS_SIGNATURE)
def rhs_paper(t, y, p, out):
    out[0] = y[1]
    out[1] = 0.0 if p[P_RC] == 0.0 else _paper_acc(t, y[0], y[1], p)


@compiled(JAC_SIGNATURE)
def jac_paper(t, y, p, out):
    out[0, 0] = 0.0
    out[0, 1] = 1.0
    if p[P_RC] == 0.0:
        out[1, 0] = 0.0
        out[1, 1] = 0.0
        return
    h = 1e-6
    out[1, 0] = (_paper_acc(t, y[0] + h, y[1], p) - _paper_acc(t, y[0] - h, y[1], p)) / (2 * h)
    hd = 1e-6 * max(1.0, abs(y[1]))
    out[1, 1] = (_paper_acc(t, y[0], y[1] + hd, p) - _paper_acc(t, y[0], y[1] - hd, p)) / (2 * hd)


def equilibrium_theta_c(p: CompressorParams, t: float = 0.0) -> float:
    r"""Clearance angle at which the link is aligned with the rod load at time ``t``.

    The gas force on the crosshead is transmitted along the rod; the massless link is in
    static equilibrium when it points along the rod, ``sin(theta_c - theta2) = 0``, i.e.
    ``dx3/dtheta_c = 0``. The stable branch has the journal pushed away from the load:
    ``theta_c = theta2 + pi`` when the force on the crosshead points toward the crank
    (``F_x < 0``, physical sign, rod in compression) and ``theta_c = theta2`` when it points
    away (``F_x > 0``, the paper's sign, rod in tension). theta2 depends weakly on theta_c
    (``|d theta2/d theta_c| <= rc/(l cos theta2)``), so a fixed-point iteration converges.
    """
    th1 = p.theta1_0 + p.omega * t
    F = float(gas_force(th1, p))
    shift = math.pi if F <= 0.0 else 0.0
    thc = shift
    for _ in range(100):
        s2 = -(p.d + p.r * math.sin(th1) + p.rc * math.sin(thc)) / p.l
        new = math.asin(s2) + shift
        if abs(new - thc) < 1e-15:
            break
        thc = new
    return thc


@dataclass(frozen=True)
class CompressorModel(ODESystem):
    """The compressor as a 2-state ODE with crosshead outputs (see module docstring)."""

    cparams: CompressorParams = field(default_factory=CompressorParams)

    def initial_state(self) -> np.ndarray:
        """``(theta_c0, thetadot_c0)``; default theta_c0: :func:`equilibrium_theta_c` + offset."""
        p = self.cparams
        thc0 = equilibrium_theta_c(p) if p.theta_c0 is None else p.theta_c0
        return np.array([thc0 + p.theta_c_offset, p.thetadot_c0])

    def accelerations(self, t: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Clearance-angle acceleration at each sample, from the equation of motion."""
        return rhs_series(self.rhs, self.params, t, y)[:, 1]

    def outputs(self, t: np.ndarray, y: np.ndarray) -> dict[str, Signal]:
        """Crosshead motion, rod angle, clearance state, gas force and joint forces."""
        p = self.cparams
        thc, thcd = y[:, 0], y[:, 1]
        thcdd = self.accelerations(t, y)
        k = kinematics(p, t, thc, thcd, thcdd)
        return {
            **mechanism_outputs(p, k, thc, thcd, thcdd, gas_force(k.theta1, p)),
            **cycle_outputs(vars(p), k.theta1),
        }


def mechanism_outputs(p: CompressorParams, k, thc, thcd, thcdd, fg) -> dict[str, Signal]:
    """The massless-link mechanism's signals from its kinematics ``k`` (:func:`kinematics`)
    and the gas force ``fg`` on the crosshead, whatever load gives it."""
    jf = joint_forces(p, k, thc, fg)
    return {
        "x": Signal(k.x3, "m", "crosshead displacement x3"),
        "v": Signal(k.v3, "m/s", "crosshead velocity"),
        "a": Signal(k.a3, "m/s**2", "crosshead acceleration"),
        "theta1": Signal(k.theta1, "rad", "crank angle"),
        "theta2": Signal(k.theta2, "rad", "connecting-rod angle"),
        "theta_c": Signal(thc, "rad", "clearance angle"),
        "thetadot_c": Signal(thcd, "rad/s", "clearance angular velocity"),
        "thetaddot_c": Signal(thcdd, "rad/s**2", "clearance angular acceleration"),
        "gas_force": Signal(fg, "N", "gas force on the crosshead along +x"),
        "joint_force_x": Signal(jf.Fx, "N", "clearance-joint force on the rod, x"),
        "joint_force_y": Signal(jf.Fy, "N", "clearance-joint force on the rod, y"),
        "joint_force": Signal(jf.magnitude, "N", "clearance-joint force magnitude"),
        "joint_force_angle": Signal(jf.direction, "rad", "clearance-joint force direction"),
        "contact_force": Signal(jf.contact, "N",
                                "joint contact force (>0: permanent contact holds)"),
        "guide_force": Signal(jf.guide, "N", "guide normal force on the crosshead"),
    }  # fmt: skip


def cycle_outputs(values: Mapping[str, Any], theta1: np.ndarray) -> dict[str, Signal]:
    """Cylinder pressures and volumes of the compression-cycle load (none for other loads),
    for any joint model whose parameters include the cycle's."""
    if values.get("load") != "cycle" or values.get("load_table") is not None:
        return {}
    if values.get("gas", "ideal") != "ideal":
        from .realgas import real_gas_states

        st = real_gas_states(theta1, values)
    else:
        st = cycle_states(theta1, pack_load(values)[1])
    return {
        "p_head": Signal(st["p_head"], "Pa", "head-end cylinder pressure (absolute)"),
        "p_crank": Signal(st["p_crank"], "Pa", "crank-end cylinder pressure (absolute)"),
        "V_head": Signal(st["V_head"], "m**3", "head-end cylinder volume"),
        "V_crank": Signal(st["V_crank"], "m**3", "crank-end cylinder volume"),
    }


def compressor_model(p: CompressorParams | None = None) -> CompressorModel:
    """Build the ODE model for ``p`` (default: the paper's base case)."""
    p = CompressorParams() if p is None else p
    if not isinstance(p, CompressorParams):
        raise ParameterError(f"expected CompressorParams, got {type(p).__name__}")
    if p.equations != "exact":
        rhs, jac, rhs_jac = rhs_paper, jac_paper, None
    elif p.load_table is None and p.load == "paper":
        rhs, jac, rhs_jac = rhs_exact, jac_exact, rhs_jac_exact
    elif p.load_table is None and p.gas == "ideal":
        rhs, jac, rhs_jac = rhs_exact_cycle, jac_exact_cycle, rhs_jac_exact_cycle
    else:
        rhs, jac, rhs_jac = rhs_exact_table, jac_exact_table, rhs_jac_exact_table
    return CompressorModel(
        rhs=rhs,
        jac=jac,
        rhs_jac=rhs_jac,
        params=pack_params(p),
        state_names=("theta_c", "thetadot_c"),
        state_units=("rad", "rad/s"),
        period=p.crank_period,
        name=f"compressor-{p.equations}",
        attrs=p.to_attrs(),
        cparams=p,
    )


class Compressor(Model):
    """The paper's compressor as a registered model (schema: :data:`parameters.SCHEMA`).

    ``equations`` selects the exact derivation or the paper's printed Eq. (43)-(47).
    """

    name = "compressor"
    description = (
        "single-cylinder reciprocating compressor, massless-link clearance at the crank pin and "
        "crosshead subsidence (Xiao et al. 2017)"
    )
    state_names = ("theta_c", "thetadot_c")
    state_units = ("rad", "rad/s")
    schema = SCHEMA
    section_signals = (("theta_c", "rad"), ("thetadot_c", "rad/s"), ("x", "m"), ("v", "m/s"),
                       ("a", "m/s**2"))  # fmt: skip
    vibration_signal = ("a", "m/s**2")
    section_pair = ("v", "a")
    validity_bounds = ((
        "contact_force", "N", 0.0,
        "the massless link can only push: a negative joint contact force means the pin would "
        "leave the bearing wall, where the permanent-contact model no longer holds",
        "the contact-impact joint (--model compressor-contact)",
    ),)  # fmt: skip

    summary_verdicts = ("api618_pin_reversal",)

    def has_dynamics(self, values: Mapping[str, Any]) -> bool:
        return float(values["rc"]) > 0.0  # rc = 0: the ideal mechanism, no clearance dynamics

    def validity_applies(self, values: Mapping[str, Any]) -> bool:
        """The link's bound (it can only push) needs a link: with rc = 0 the crank pin is an
        ideal joint that carries a reversing load (the cycle load's rod-load reversal)."""
        return float(values["rc"]) > 0.0

    @staticmethod
    def params(values: Mapping[str, Any]) -> CompressorParams:
        return CompressorParams(**values)

    def check(self, values: Mapping[str, Any]) -> None:
        self.params(values)  # the ranges that depend on other parameters

    def system(self, values: Mapping[str, Any]) -> CompressorModel:
        return compressor_model(self.params(values))

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        return self.system(values).initial_state()

    def period(self, values: Mapping[str, Any]) -> float:
        return 2.0 * math.pi / float(values["omega"])

    def outputs(self, values: Mapping[str, Any], t: np.ndarray, y: np.ndarray
                ) -> dict[str, Signal]:  # fmt: skip
        return self.system(values).outputs(t, y)

    def run_summary(self, values: Mapping[str, Any], ds: Any) -> dict[str, Any]:
        """With ``load = "cycle"``: the API 618 pin-load reversal and the cycle's indicated
        power and volumetric efficiencies (:func:`recipdyn.model.cycle.cycle_summary`)."""
        return cycle_summary(values, ds)


#: The registered instance (``recipdyn --model compressor``, the default).
COMPRESSOR = Compressor()
