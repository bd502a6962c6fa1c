r"""The single-cylinder compressor with a crank-pin clearance as an
[`ODESystem`][recipdyn.model.base.ODESystem].

State ``y = (theta_c, theta_c')``; time ``t`` in s; crank angle ``theta1 = theta1_0 + omega t``.
The right-hand side is ``(theta_c', theta_c'')`` with ``theta_c''`` from

* ``equations="exact"``: Lagrange's equation derived without approximation
  (`derivation`, compiled code in `_generated`), with an exact Jacobian;
* ``equations="paper-printed"``: Eq. (43)-(47) as printed (`paper_printed`), whose
  Jacobian's ``d/d theta_c`` column is a central difference (the printed coefficients are a
  comparison variant only).

With ``rc = 0`` the clearance angle has no dynamics (the mechanism is ideal); the kernel then
returns ``theta_c'' = 0`` and the outputs are the ideal slider-crank's.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

from .base import ODESystem, Signal, rhs_series
from .components.contract import Assembly, Component, glue_module
from .components.drive import DRIVES, MOTORS
from .components.load import cycle_outputs, cycle_summary, load_component
from .components.mechanism import HEAD, N_HEAD, equilibrium_theta_c, glue_source
from .kinematics import joint_forces, kinematics
from .parameters import SCHEMA, CompressorParams, ParameterError
from .protocol import Model

__all__ = [
    "CompressorModel", "compressor_model", "equilibrium_theta_c", "Compressor",
    "COMPRESSOR",
]  # fmt: skip


def assembly(p: CompressorParams) -> tuple[Assembly, dict[str, Component]]:
    """The components ``p`` chooses and their assembly (drive, its torque law, load: the
    load last, since a table's length varies)."""
    v = vars(p)
    parts = {"drive": DRIVES[p.drive], "load": load_component(v)}
    if p.drive == "motor":
        parts["motor"] = MOTORS[p.motor]
    order = [parts[f] for f in ("drive", "motor", "load") if f in parts]
    return Assembly(N_HEAD, tuple(order)), parts


def pack_assembled(p: CompressorParams) -> tuple[np.ndarray, dict[str, int], dict]:
    """The parameter vector of the assembled kernels, each part's offset, the parts."""
    asm, parts = assembly(p)
    head = np.array([getattr(p, k) for k in HEAD], dtype=np.float64)
    vec, offsets = asm.pack(head, vars(p))
    return vec, offsets, parts


@lru_cache(maxsize=64)
def _kernels(equations: str, drive: str, motor: str | None, load: str,
             offsets: tuple[tuple[str, int], ...]):  # fmt: skip
    """The generated glue's kernels for one combination (cached per process; on disk by
    numba)."""
    from .components.load import LOADS

    src = glue_source(
        equations=equations,
        drive=DRIVES[drive],
        load=LOADS[load],
        motor=None if motor is None else MOTORS[motor],
        offsets=dict(offsets),
    )
    stem = f"compressor_{drive}_{load}_{equations}".replace("-", "_")  # fmt: skip
    mod = glue_module(src, stem if motor is None else f"{stem}_{motor}")
    return mod.rhs, mod.jac, mod.rhs_jac, mod.observe


@dataclass(frozen=True)
class CompressorModel(ODESystem):
    """The compressor as an ODE with crosshead outputs (see module docstring)."""

    cparams: CompressorParams = field(default_factory=CompressorParams)
    #: ``observe(t, y, p) -> (n, 3)``: crank angle, crank speed and gas force at each sample,
    #: from the compiled functions that were integrated (the generated glue)
    observer: Any = None

    def initial_state(self) -> np.ndarray:
        """``(theta_c0, thetadot_c0)`` (with a motor, then ``theta1_0, omega, 0, 0``);
        default theta_c0: `equilibrium_theta_c` + offset."""
        p = self.cparams
        thc0 = equilibrium_theta_c(p) if p.theta_c0 is None else p.theta_c0
        y0 = [thc0 + p.theta_c_offset, p.thetadot_c0]
        if p.drive == "motor":
            y0 += [p.theta1_0, p.omega, 0.0, 0.0]
        return np.array(y0)

    def accelerations(self, t: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Clearance-angle acceleration at each sample, from the equation of motion."""
        return rhs_series(self.rhs, self.params, t, y)[:, 1]

    def outputs(self, t: np.ndarray, y: np.ndarray) -> dict[str, Signal]:
        """Crosshead motion, rod angle, clearance state, gas force and joint forces (with a
        motor: crank speed and acceleration, motor torque, energies)."""
        p = self.cparams
        f = rhs_series(self.rhs, self.params, t, y)
        obs = self.observer(np.ascontiguousarray(t, dtype=np.float64),
                            np.ascontiguousarray(y, dtype=np.float64), self.params)  # fmt: skip
        th1, w1, F = obs[:, 0], obs[:, 1], obs[:, 2]
        thc, thcd, thcdd = y[:, 0], y[:, 1], f[:, 1]
        if p.drive != "motor":
            k = kinematics(p, t, thc, thcd, thcdd, theta1=th1, omega1=w1)
            return {
                **mechanism_outputs(p, k, thc, thcd, thcdd, F),
                **cycle_outputs(vars(p), k.theta1),
            }
        a1 = f[:, 3]
        k = kinematics(p, t, thc, thcd, thcdd, theta1=th1, omega1=w1, alpha1=a1)
        out = {
            **mechanism_outputs(p, k, thc, thcd, thcdd, F),
            **cycle_outputs(vars(p), th1),
            "omega1": Signal(w1, "rad/s", "crank speed"),
            "alpha1": Signal(a1, "rad/s**2", "crank angular acceleration"),
            "motor_torque": Signal(f[:, 4] / w1, "N*m", "motor torque at the crank"),
            "W_motor": Signal(y[:, 4], "J", "work done by the motor since t = 0"),
            "W_gas": Signal(y[:, 5], "J", "work done by the gas on the crosshead since t = 0"),
            "energy": Signal(mechanism_energy_series(p, y), "J",
                             "kinetic + potential energy of the mechanism and the drive"),
        }  # fmt: skip
        return out


def mechanism_energy_series(p: CompressorParams, y: np.ndarray) -> np.ndarray:
    """``T + V`` of crank (with ``J_drive``), rod and crosshead at each sample of a motor-driven
    run, J (the generated expression of the free-crank derivation)."""
    from ._generated_drive import mechanism_energy

    args = [getattr(p, k) for k in HEAD] + [p.J_drive]
    return np.array([mechanism_energy(a, c, w, cd, *args)
                     for c, cd, a, w in y[:, :4]])  # fmt: skip


def mechanism_outputs(p: CompressorParams, k, thc, thcd, thcdd, fg) -> dict[str, Signal]:
    """The massless-link mechanism's signals from its kinematics ``k``
    ([`kinematics`][recipdyn.model.kinematics.kinematics]) and the gas force ``fg`` on the
    crosshead, whatever load gives it."""
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


def compressor_model(p: CompressorParams | None = None) -> CompressorModel:
    """Build the ODE model for ``p`` (default: the paper's base case), assembled from the
    components ``p`` chooses (`assembly`)."""
    p = CompressorParams() if p is None else p
    if not isinstance(p, CompressorParams):
        raise ParameterError(f"expected CompressorParams, got {type(p).__name__}")
    vec, offsets, parts = pack_assembled(p)
    motor = parts.get("motor")
    rhs, jac, rhs_jac, observe = _kernels(
        p.equations,
        p.drive,
        None if motor is None else motor.name,
        parts["load"].name,
        tuple(sorted(offsets.items())),
    )
    names, units = ("theta_c", "thetadot_c"), ("rad", "rad/s")
    extra: dict[str, Any] = {}
    if p.drive == "motor":
        names += ("theta1", "omega1", "W_motor", "W_gas")
        units += ("rad", "rad/s", "J", "J")
        # the crank is a state: the system is autonomous; with rc = 0 the clearance angle
        # never moves
        extra = dict(period=None, aux_states=2,
                     passive=(4, 5) if p.rc > 0 else (0, 1, 4, 5))  # fmt: skip
    return CompressorModel(
        rhs=rhs,
        jac=jac,
        rhs_jac=rhs_jac,
        params=vec,
        state_names=names,
        state_units=units,
        period=extra.pop("period", p.crank_period),
        name=f"compressor-{p.equations}",
        attrs=p.to_attrs(),
        cparams=p,
        observer=observe,
        **extra,
    )


class Compressor(Model):
    """The paper's compressor as a registered model (schema: `parameters.SCHEMA`).

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

    def states(self, values: Mapping[str, Any]) -> tuple[tuple[str, str], ...]:
        """``theta_c, thetadot_c``; a motor drive adds the crank angle and speed and the work
        integrals of the motor and the gas."""
        out = super().states(values)
        if values.get("drive", "prescribed") == "motor":
            out += (("theta1", "rad"), ("omega1", "rad/s"), ("W_motor", "J"), ("W_gas", "J"))
        return out

    def has_dynamics(self, values: Mapping[str, Any]) -> bool:
        # rc = 0 with a prescribed crank: the ideal mechanism, nothing moves but the crank
        return float(values["rc"]) > 0.0 or values.get("drive", "prescribed") == "motor"

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
        power and volumetric efficiencies
        (`recipdyn.model.components.load.cycle_summary`)."""
        return cycle_summary(values, ds)


#: The registered instance (``recipdyn --model compressor``, the default).
COMPRESSOR = Compressor()
