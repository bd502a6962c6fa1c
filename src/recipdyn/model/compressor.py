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
from dataclasses import fields as dataclass_fields
from functools import lru_cache
from typing import Any

import numpy as np

from .base import ODESystem, Signal, rhs_series
from .components.contract import (
    Assembly,
    Component,
    check_fragments,
    glue_module,
    resolve_component,
    source_digest,
)
from .components.drive import DRIVES, MOTORS
from .components.load import cycle_outputs, cycle_summary, load_component
from .components.mechanism import HEAD, N_HEAD, equilibrium_theta_c, glue_source
from .kinematics import joint_forces, kinematics
from .parameters import PLUGGABLE, SCHEMA, CompressorParams, ParameterError
from .protocol import Model, Schema
from .registry import absolute_spec, is_spec

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


@lru_cache(maxsize=32)
def _plugged_schema(chosen: tuple[tuple[str, str], ...]) -> Schema:
    """The compressor's schema with the components ``(family, spec)`` from users' files: each
    spec one more choice of its family's parameter, each fragment appended (a name may
    belong to one component only)."""
    from dataclasses import replace

    from .components.load import LOADS

    builtin = {"load": LOADS, "motor": MOTORS}
    comps = [resolve_component(f, spec, builtin[f]) for f, spec in chosen]
    check_fragments(comps, base=SCHEMA.params)
    specs = dict(chosen)
    params = tuple(replace(p, choices=(*p.choices, specs[p.name])) if p.name in specs else p
                   for p in SCHEMA)  # fmt: skip
    return Schema(params + tuple(q for c in comps for q in c.params), aliases=SCHEMA.aliases,
                  extras=SCHEMA.extras)  # fmt: skip


#: The axes and signs of every compressor record (``sign_convention``).
SIGN_CONVENTION = (
    "x along the cylinder axis from the crank centre toward the cylinder (theta1 = 0: outer dead "
    "centre, x3 = r + l); y up, gravity along -y; crosshead at y3 = -d; gas_force is the force on "
    "the crosshead along +x: -P (load_sign='physical', gas pushes the piston toward the crank) "
    "or +P (load_sign='paper', the sign of Eq. 46)."
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
        """The [`CompressorParams`][recipdyn.model.parameters.CompressorParams] view of
        ``values`` (the values of components from a user's file left out: `plugged`)."""
        return CompressorParams(**{k: v for k, v in values.items() if k in _FIELDS})

    @staticmethod
    def plugged(values: Mapping[str, Any]) -> dict[str, Any]:
        """The values of components from a user's file (their own fragments)."""
        return {k: v for k, v in values.items() if k not in _FIELDS}

    def schema_for(self, values: Mapping[str, Any]) -> Schema:
        """`parameters.SCHEMA`, or with a load or a torque law from a user's module or file
        (``load = "file.py:OBJ"``) that component's fragment added (adding one is one file:
        docs/components.md)."""
        chosen = tuple((f, absolute_spec(values[f])) for f in PLUGGABLE if is_spec(values.get(f)))
        return _plugged_schema(chosen) if chosen else self.schema

    def parameters(self, values: Mapping[str, Any] | Any | None = None, **kw: Any
                   ) -> dict[str, Any]:  # fmt: skip
        """Validated values; a component spec (``file.py:OBJ``) is made absolute, so records
        and worker processes find its file from any folder."""
        if values is not None and not isinstance(values, Mapping):
            values = super().parameters(values)  # a CompressorParams, valid as a whole
        raw = {**(values or {}), **kw}
        for f in PLUGGABLE:
            if is_spec(raw.get(f)):
                raw[f] = absolute_spec(raw[f])
        return super().parameters(raw)

    def check(self, values: Mapping[str, Any]) -> None:
        self.params(values)  # the ranges that depend on other parameters
        for f in PLUGGABLE:  # a user's component's own checks
            if is_spec(values.get(f)):
                c = resolve_component(f, values[f], {})
                if c.check is not None:
                    c.check(values)

    def system(self, values: Mapping[str, Any]) -> CompressorModel:
        p, extra = self.params(values), tuple(sorted(self.plugged(values).items()))
        try:
            hash((p, extra))
        except TypeError:  # an unhashable value (a table given as lists): built each time
            return compressor_model(p, dict(extra))
        return _system(p, extra)

    def record_attrs(self, values: Mapping[str, Any], y0: np.ndarray | None = None
                     ) -> dict[str, Any]:  # fmt: skip
        """Every model's record attributes (`Model.record_attrs`: its parameters, a user's
        component's too), the axes and signs, the crank frequency, the initial clearance
        angle and how it was chosen, and what the parameter view adds (the load's
        description, its table, the list of assumptions)."""
        p = self.params(values)
        out = super().record_attrs(values, y0)
        out.update({
            "sign_convention": SIGN_CONVENTION,
            "reference": "Xiao et al. (2017), J. Vibroengineering 19(7), "
                         "doi:10.21595/jve.2017.18771",
            "crank_frequency_hz": p.crank_frequency,
        })  # fmt: skip
        if y0 is not None:
            out["theta_c_initial"] = float(y0[0])
            out["thetadot_c_initial"] = float(y0[1])
            out["theta_c_initial_rule"] = (
                "user-set theta_c0" if p.theta_c0 is not None else
                "link aligned with the rod load at t=0 (static equilibrium) + theta_c_offset"
            )  # fmt: skip
        for k, v in p.to_attrs().items():
            out.setdefault(f"param_{k}", v)
        return out

    def values_from_record(self, attrs: Mapping[str, Any]) -> dict[str, Any]:
        """The values a record holds (`Model.values_from_record`), its load table
        included."""
        chosen = {f: attrs[f"param_{f}"] for f in PLUGGABLE if f"param_{f}" in attrs}
        values = self.schema_for(chosen).from_attrs(attrs)
        flat = attrs.get("param_load_table_deg_N")
        if flat is not None and "load_table" in self.schema.extras:
            rows = np.asarray(flat, dtype=float).reshape(-1, 2)
            values["load_table"] = tuple((float(a), float(b)) for a, b in rows)
        self.check(values)
        return values

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


_FIELDS = frozenset(f.name for f in dataclass_fields(CompressorParams))

#: The registered instance (``recipdyn --model compressor``, the default).
COMPRESSOR = Compressor()
