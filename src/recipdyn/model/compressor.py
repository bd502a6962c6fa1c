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

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

from .base import ODESystem, Signal, rhs_series
from .components.contract import (
    Assembly,
    Component,
    glue_module,
    resolve_component,
    source_digest,
)
from .components.drive import DRIVES, MOTORS
from .components.link import LinkModel, mechanism_energy_series, mechanism_outputs
from .components.load import cycle_outputs, cycle_summary, load_component
from .components.mechanism import HEAD, N_HEAD, equilibrium_theta_c, glue_source
from .kinematics import kinematics
from .parameters import CompressorParams, ParameterError
from .registry import is_spec

__all__ = [
    "CompressorModel", "compressor_model", "equilibrium_theta_c", "Compressor",
    "COMPRESSOR",
]  # fmt: skip


def assembly(p: CompressorParams) -> tuple[Assembly, dict[str, Component]]:
    """The components ``p`` chooses and their assembly (drive, its torque law, load: the
    load last, since a table's length varies). A load or torque law may come from a user's
    module or file (``load = "file.py:OBJ"``, `resolve_component`)."""
    v = vars(p)
    load = resolve_component("load", p.load, {}) if is_spec(p.load) else load_component(v)
    parts = {"drive": DRIVES[p.drive], "load": load}
    if p.drive == "motor":
        parts["motor"] = resolve_component("motor", p.motor, MOTORS)
    order = [parts[f] for f in ("drive", "motor", "load") if f in parts]
    return Assembly(N_HEAD, tuple(order)), parts


def pack_assembled(p: CompressorParams, extra: Mapping[str, Any] | None = None
                   ) -> tuple[np.ndarray, dict[str, int], dict]:  # fmt: skip
    """The parameter vector of the assembled kernels, each part's offset, the parts
    (``extra``: the values of components from a user's file, beside ``p``'s)."""
    asm, parts = assembly(p)
    head = np.array([getattr(p, k) for k in HEAD], dtype=np.float64)
    vec, offsets = asm.pack(head, {**vars(p), **(extra or {})})
    return vec, offsets, parts


@lru_cache(maxsize=64)
def _kernels(equations: str, drive: str, motor: str | None, load: str,
             offsets: tuple[tuple[str, int], ...]):  # fmt: skip
    """The generated glue's kernels for one combination (cached per process; on disk by
    numba)."""
    from .components.load import LOADS

    load_c = resolve_component("load", load, LOADS)
    motor_c = None if motor is None else resolve_component("motor", motor, MOTORS)
    src = glue_source(
        equations=equations,
        drive=DRIVES[drive],
        load=load_c,
        motor=motor_c,
        offsets=dict(offsets),
    )
    for c in (load_c, motor_c):  # a user's file: its edits give a new glue file, never stale
        if c is not None and c.module not in ("recipdyn", "") and not c.module.startswith(
                "recipdyn."):  # fmt: skip
            src += f"\n# {c.family} = {c.module}: {source_digest(c.module)}\n"
    stem = f"compressor_{drive}_{load_c.name}_{equations}".replace("-", "_")  # fmt: skip
    mod = glue_module(src, stem if motor_c is None else f"{stem}_{motor_c.name}")
    return mod.rhs, mod.jac, mod.rhs_jac, mod.observe


@dataclass(frozen=True)
class CompressorModel(ODESystem):
    """The compressor as an ODE with crosshead outputs (see module docstring)."""

    cparams: CompressorParams = field(default_factory=CompressorParams)
    #: ``observe(t, y, p) -> (n, 3)``: crank angle, crank speed and gas force at each sample,
    #: from the compiled functions that were integrated (the generated glue)
    observer: Any = None
    #: the values of components from a user's file, ``((name, value), ...)`` (beside ``cparams``)
    plugged: tuple = ()

    def initial_state(self) -> np.ndarray:
        """``(theta_c0, thetadot_c0)`` (with a motor, then ``theta1_0, omega, 0, 0``);
        default theta_c0: `equilibrium_theta_c` + offset."""
        p = self.cparams
        thc0 = p.theta_c0
        if thc0 is None:
            thc0 = equilibrium_theta_c(p, extra=dict(self.plugged))
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


def compressor_model(p: CompressorParams | None = None,
                     extra: Mapping[str, Any] | None = None) -> CompressorModel:  # fmt: skip
    """Build the ODE model for ``p`` (default: the paper's base case), assembled from the
    components ``p`` chooses (`assembly`); ``extra``: the parameter values of components
    from a user's file (`Compressor.schema_for`)."""
    p = CompressorParams() if p is None else p
    if not isinstance(p, CompressorParams):
        raise ParameterError(f"expected CompressorParams, got {type(p).__name__}")
    plugged = tuple(sorted((extra or {}).items()))
    vec, offsets, parts = pack_assembled(p, extra)
    motor = parts.get("motor")
    rhs, jac, rhs_jac, observe = _kernels(
        p.equations,
        p.drive,
        None if motor is None else (p.motor if is_spec(p.motor) else motor.name),
        p.load if is_spec(p.load) else parts["load"].name,
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
        plugged=plugged,
        **extra,
    )


@lru_cache(maxsize=16)
def _system(p: CompressorParams, extra: tuple[tuple[str, Any], ...] = ()) -> CompressorModel:
    # one system per parameter set and process: a streamed run asks for it per block
    return compressor_model(p, dict(extra))


class Compressor(LinkModel):
    """The paper's compressor as a registered model (schema: `parameters.SCHEMA`).

    ``equations`` selects the exact derivation or the paper's printed Eq. (43)-(47).
    """

    name = "compressor"
    description = (
        "single-cylinder reciprocating compressor, massless-link clearance at the crank pin and "
        "crosshead subsidence (Xiao et al. 2017)"
    )

    def system(self, values: Mapping[str, Any]) -> CompressorModel:
        p, extra = self.params(values), tuple(sorted(self.plugged(values).items()))
        try:
            hash((p, extra))
        except TypeError:  # an unhashable value (a table given as lists): built each time
            return compressor_model(p, dict(extra))
        return _system(p, extra)

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        return self.system(values).initial_state()

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
