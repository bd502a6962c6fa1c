r"""The massless link at the crank pin as a model: what its models share.

`compressor` (`recipdyn.model.compressor`, the paper's load, a table, the ideal cycle or a
load of your own, with a prescribed crank or a motor) and `compressor-valves`
(`recipdyn.model.compressor_valves`, the cylinder gas with dynamic valves as states) are the
same mechanism with the same parameters, validation, records and signals: `LinkModel` holds
them, and `mechanism_outputs` the mechanism's recorded signals, whatever load drives it. Each
model adds its own system, initial state and outputs.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import fields as dataclass_fields
from functools import lru_cache
from typing import Any

import numpy as np

from ...errors import ParameterError
from ..base import Signal
from ..kinematics import joint_forces
from ..parameters import PLUGGABLE, SCHEMA, CompressorParams
from ..protocol import Model, Schema
from ..registry import absolute_spec, is_spec
from .contract import check_fragments, resolve_component
from .drive import MOTORS
from .mechanism import HEAD

__all__ = ["LinkModel", "mechanism_energy_series", "mechanism_outputs", "SIGN_CONVENTION"]


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


def mechanism_energy_series(p: CompressorParams, y: np.ndarray) -> np.ndarray:
    """``T + V`` of crank (with ``J_drive``), rod and crosshead at each sample of a motor-driven
    run, J (the generated expression of the free-crank derivation)."""
    from .._generated_drive import mechanism_energy

    args = [getattr(p, k) for k in HEAD] + [p.J_drive]
    return np.array([mechanism_energy(a, c, w, cd, *args)
                     for c, cd, a, w in y[:, :4]])  # fmt: skip


@lru_cache(maxsize=32)
def _plugged_schema(chosen: tuple[tuple[str, str], ...]) -> Schema:
    """The compressor's schema with the components ``(family, spec)`` from users' files: each
    spec one more choice of its family's parameter, each fragment appended (a name may
    belong to one component only)."""
    from dataclasses import replace

    from .load import LOADS

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


class LinkModel(Model):
    """The massless-link compressor's parameters, validation, records and signals
    (`recipdyn.model.parameters.SCHEMA`); a model adds ``name``, ``description``,
    ``system``, ``initial_state``, ``outputs`` and ``run_summary``."""

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
                if c.states or c.aux_states:  # (no initial states are declared for them)
                    raise ParameterError(f"{f} = {values[f]!r} has states: a {f} of your own "
                                         "with states runs at a contact or lubricated pin or in "
                                         "the worn guide; allowed on the massless link and ideal "
                                         f"pins: a {f} of your own without states, or load = "
                                         "'valves'")  # fmt: skip
                if c.check is not None:
                    c.check(values)

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

    def period(self, values: Mapping[str, Any]) -> float:
        return 2.0 * math.pi / float(values["omega"])


_FIELDS = frozenset(f.name for f in dataclass_fields(CompressorParams))
