r"""A machine as a [`Model`][recipdyn.model.protocol.Model]: what every layer above uses.

`MachineModel` is a machine read from a file or built in Python (`recipdyn.model.machine`):
its schema holds each part's parameters under the part's name (``throw2.rc``,
``shaft.J_drive``, ``stage1.suction_pressure``), each with its unit, range and default (the
file's value, else the compressor's); `system` assembles it (`.assemble`) and its records
hold every throw's signals under the throw's name (``throw2.a``) and the crank's (``theta1``,
``omega1``, ``energy``).

`ContactMachine` is a machine whose throws have contact or lubricated crank pins (the
family `.contact_throws`); `MachineModel(machine)` builds one for such a machine.

`OneThrow` is the compressor of one throw with the massless link or an ideal crank pin, as
``--model compressor`` (and ``compressor-valves``) take it: the compressor's names
(``rc``, ``omega``) and selectors (``load``, ``drive``, ``motor``, ``equations``) choose the
one throw's parts, so every record, config and sweep store made before the assembler still
runs, with the same values. Both go through the same assembler and templates: one path.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import fields as dataclass_fields
from dataclasses import replace
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import ParameterError
from ..machine.description import (
    FED_NAMES,
    SHAFT_NAMES,
    STAGE_NAMES,
    THROW_TORSION_NAMES,
    Machine,
    Shaft,
    Throw,
)
from ..mechanism.link import (
    PHASE,
    SIGN_CONVENTION,
    equilibrium_theta_c,
    mechanism_energy,
    mechanism_outputs,
)
from ..parameters import PLUGGABLE, SCHEMA, CompressorParams
from ..protocol import Model, Param, Schema
from ..registry import absolute_spec, is_spec
from .assemble import (
    Configuration,
    assemble,
    family_of,
    frame_values,
    load_of,
    throw_family,
    throw_values,
)

if TYPE_CHECKING:
    from ..base import Event, Signal
    from .contact_throws import ContactConfiguration
    from .system import AssembledSystem

__all__ = [
    "MachineModel",
    "ContactMachine",
    "OneThrow",
    "LINK",
    "OneContact",
    "ONE_THROW",
    "one_throw",
    "LINK_VALVES",  # noqa: F822 (built on first use, __getattr__)
    "CONTACT",  # noqa: F822
    "CONTACT_VALVES",  # noqa: F822
    "VALVES_SCHEMA",  # noqa: F822
    "machine_schema",
    "compressor_model",
]

_FIELDS = frozenset(f.name for f in dataclass_fields(CompressorParams))

#: The compressor with dynamic valves: the massless link's parameters without the paper's
#: load and equations, with the valves'.
_DROP = {"load", "load_amplitude", "load_sign", "equations", "gas"}


@lru_cache(maxsize=1)
def _valves_schema() -> Schema:
    """`VALVES_SCHEMA` (the valves' parameters live beside their compiled code: built when
    first asked for, so a machine without valves is validated before numba loads)."""
    from .. import valves as va

    return Schema((*(p for p in SCHEMA if p.name not in _DROP), *va.SCHEMA_PARAMS),
                  aliases=dict(SCHEMA.aliases))  # fmt: skip


#: The structure's keys, which a machine file gives as parts, not parameters.
_SELECTORS = ("load", "drive", "motor", "equations")
#: The cycle's parameters, which a throw with the paper's load does not have.
_CYCLE_GROUP = "cycle"


def _throw_params(throw: Throw, shaft: Shaft, frame: bool = False) -> tuple[Param, ...]:
    """A throw's parameters under their local names: its configuration's (the compressor's
    schema for its load, `VALVES_SCHEMA` for the dynamic valves; a load of a user's file
    adds its own) without the shaft's, the stages' and the selectors, with its ``phase``; a
    throw with contact joints, theirs (`.contact_throws.contact_throw_params`; on a
    ``frame`` its crank's ``rs``, ``m1`` too)."""
    if throw_family(throw) == "contact":
        from .contact_throws import contact_throw_params

        return contact_throw_params(throw, shaft, frame)
    if throw.load == "valves":
        base = list(_valves_schema())
    else:
        base = [p for p in SCHEMA if not (throw.load != "cycle" and p.group == _CYCLE_GROUP)]
        if throw.load != "paper":
            base = [p for p in base if p.name not in ("load_amplitude", "load_sign")]
        if is_spec(throw.load):
            from ..components.contract import resolve_component
            from ..components.load import LOADS

            base += list(resolve_component("load", throw.load, LOADS).params)
    skip = {*SHAFT_NAMES, *STAGE_NAMES, *_SELECTORS}
    out = [p for p in base if p.name not in skip and p.group != "drive"]
    if throw.crank_joint == "ideal":
        out = [p for p in out if p.name != "rc"]
    if shaft.torsion:  # the crankshaft section that ends at its crank
        from ..shaft.flexible import THROW_PARAMS

        out += THROW_PARAMS
    return (*out, PHASE)


def _shaft_params(shaft: Shaft) -> tuple[Param, ...]:
    from ..components.contract import resolve_component
    from ..components.drive import MOTOR, MOTORS

    out = [SCHEMA["omega"], SCHEMA["theta1_0"]]
    if shaft.drive == "motor":
        out += list(MOTOR.params) + list(resolve_component("motor", shaft.motor, MOTORS).params)
    if shaft.torsion:
        from ..shaft.flexible import PARAMS

        out += PARAMS
    return tuple(out)


def _with_default(p: Param, name: str, raw: Any) -> Param:
    """``p`` under ``name`` with the default ``raw`` (a machine file's value, with units); a
    derivation rule reads the names of its own namespace (`protocol.derive_value`), and a
    value the file gives replaces it."""
    from ...quantity import to_unit

    q = replace(p, name=name)
    if raw is None:
        return q
    value = str(raw) if p.choices is not None else to_unit(name, raw, p.unit)
    return replace(q, default=q.check(value), derive="")  # (the file's value, not the rule's)


def machine_schema(machine: Machine) -> Schema:
    """The schema of a machine: each throw's parameters under its name, the shaft's under
    ``shaft.``, each stage's under its name (one throw: the compressor's names); each default
    the file's value, else the compressor's."""
    params: list[Param] = []
    extras: list[str] = []
    for p in _shaft_params(machine.shaft):
        params.append(_with_default(p, machine.prefix("shaft") + p.name,
                                    machine.shaft.values.get(p.name)))  # fmt: skip
    for st in machine.stages:
        throws = [t for t in machine.throws if t.stage == st.name]
        fed = machine.interstage_into(st.name) is not None  # (its suction: the interstage's)
        if any(t.load in ("cycle", "valves") for t in throws):
            for name in STAGE_NAMES:
                if not (fed and name in FED_NAMES):
                    params.append(_with_default(SCHEMA[name], machine.prefix(st.name) + name,
                                                st.values.get(name)))  # fmt: skip
    if machine.interstages:
        from ..components.interstage import PARAMS as INTERSTAGE_PARAMS

        for i in machine.interstages:
            params += [_with_default(p, f"{i.name}.{p.name}", i.values.get(p.name))
                       for p in INTERSTAGE_PARAMS]  # fmt: skip
    for t in machine.throws:
        given = t.values
        own = _throw_params(t, machine.shaft, machine.frame is not None)
        known = {p.name for p in own} | {"load_table"}
        for k in given:
            if k not in known:
                hint = (
                    ""
                    if k not in THROW_TORSION_NAMES
                    else " (a crankshaft section's: the shaft needs a [shaft.torsion] table)"
                )
                raise ParameterError(f"machine {machine.name!r}: {t.name}.{k} is not a parameter "
                                     f"of a throw with load = {t.load!r}{hint}")  # fmt: skip
        pre = machine.prefix(t.name)
        params += [_with_default(p, pre + p.name, given.get(p.name)) for p in own]
        if t.load == "table":
            extras.append(pre + "load_table")
    if machine.frame is not None:  # always under frame. (no compressor name is the frame's)
        from ..frame.body import local_params

        given = dict(machine.frame.values)
        for m in machine.frame.mounts:
            given.update({f"{m.name}.{k}": v for k, v in m.values.items()})
        params += [_with_default(p, "frame." + p.name, given.get(p.name))
                   for p in local_params(machine.frame)]  # fmt: skip
    return Schema(tuple(params), extras=tuple(extras))


def _prefixed_message(prefix: str, exc: ParameterError) -> ParameterError:
    """A throw's refusal with its namespace: ``rc = ...`` becomes ``throw2.rc = ...``."""
    return ParameterError(f"{prefix}{exc}" if prefix else str(exc))


@lru_cache(maxsize=32)
def _configuration(model_key, machine: Machine, items: tuple) -> Configuration:
    return assemble(machine, dict(items))


class MachineModel(Model):
    """A machine of any number of throws (module docstring)."""

    validity_bounds_instead = "the contact-impact joint (--model compressor-contact)"

    def __new__(cls, machine: Machine | None = None, *args: Any, **kw: Any):
        """A machine of contact throws is a `.contact_throws.ContactMachine` (the family
        `.assemble.FAMILIES` maps its ``crank_joint`` to; ``machine`` None: unpickling)."""
        if cls is MachineModel and machine is not None and family_of(machine) == "contact":
            cls = ContactMachine
        return super().__new__(cls)

    def __init__(self, machine: Machine, schema: Schema | None = None) -> None:
        self.machine = machine
        self.name = machine.name
        n = len(machine.throws)
        self.description = machine.description or (
            f"{n} throws on one crankshaft ({machine.shaft.drive} drive), massless links"
        )
        if machine.source:
            self.spec = machine.source
        self.schema = schema if schema is not None else machine_schema(machine)
        pre = [machine.prefix(t.name) for t in machine.throws]
        self.section_signals = tuple((f"{q}{s}", u) for q in pre for s, u in (
            ("theta_c", "rad"), ("thetadot_c", "rad/s"), ("x", "m"), ("v", "m/s"),
            ("a", "m/s**2")))  # fmt: skip
        accel = next((s.signal for s in machine.sensors if s.kind == "accelerometer"), None)
        # with a frame, by default the first throw's accelerometer: its crosshead's + the frame's
        self.vibration_signal = (accel or f"{pre[0]}{'a' if machine.frame is None else 'accel'}",
                                 "m/s**2")  # fmt: skip
        self.section_pair = (f"{pre[0]}v", f"{pre[0]}a")
        if not machine.flat:
            self.summary_verdicts = tuple(f"{q}api618_pin_reversal" for q in pre)
        self.validity_bounds = tuple((
            f"{q}contact_force", "N", 0.0,
            "the massless link can only push: a negative joint contact force means the pin "
            "would leave the bearing wall, where the permanent-contact model no longer holds",
            self.validity_bounds_instead) for q, t in zip(pre, machine.throws, strict=True)
            if machine.frame is None or t.crank_joint == "link")  # fmt: skip
        if machine.frame is not None:  # (a machine with a frame: its ideal pins have no link)
            from ..frame.body import FEEDBACK_LIMIT

            self.validity_bounds += ((
                "frame_coupling_margin", "", 0.0,
                f"the frame's acceleration at a guide moves that throw's parts by more than "
                f"{FEEDBACK_LIMIT:g} of its shaking force (frame_feedback), and the frame is "
                "coupled one way (its motion does not act on the throws)",
                "a stiffer or heavier frame (frame.mount*.k_x, frame.mass), away from its "
                "resonances; a frame coupled both ways is not modelled yet"),)  # fmt: skip
        if any(t.load == "valves" for t in machine.throws):
            self.lyapunov_refusal = (
                "valve plates come to rest on their stops in resets with a singular saltation "
                "matrix (Benettin's QR is undefined there); use the signal estimators or "
                "load=cycle (ideal valves)"
            )
            self.event_example = {}

    @property
    def state_names(self) -> tuple[str, ...]:
        """The states at the defaults (assembled when first asked for: building the model
        loads no compiled code, so a bad value is refused before numba loads)."""
        return tuple(n for n, _ in self._default_states())

    @property
    def state_units(self) -> tuple[str, ...]:
        return tuple(u for _, u in self._default_states())

    def _default_states(self) -> tuple[tuple[str, str], ...]:
        if "_states0" not in self.__dict__:
            self.__dict__["_states0"] = self.states(self.parameters())
        return self.__dict__["_states0"]

    # -- what the values choose --------------------------------------------------------
    def structure(self, values: Mapping[str, Any]) -> Machine:
        """The machine at ``values`` (fixed for a machine file)."""
        return self.machine

    def throws(self, values: Mapping[str, Any]) -> list[dict[str, Any]]:
        """Each throw's values under the compressor's names (`.assemble.throw_values`)."""
        m = self.structure(values)
        return [throw_values(m, values, k) for k in range(len(m.throws))]

    @staticmethod
    def throw_params(local: Mapping[str, Any]) -> CompressorParams:
        """A throw's [`CompressorParams`][recipdyn.model.parameters.CompressorParams] (its
        geometry, masses, load and the shaft's speed; checks across its parameters)."""
        kw = {k: v for k, v in local.items() if k in _FIELDS}
        if local.get("load") == "valves":
            kw = {k: v for k, v in kw.items() if k not in ("gas", "load")}
            kw["load"] = "cycle"
        elif is_spec(local.get("load")) or local.get("load") == "table":
            kw.pop("load", None)
        g = float(kw.get("g", 0.0))
        if g < 0.0:  # a throw turned by 180 deg: its weight along its own +y (`throw_values`)
            p = CompressorParams(**{**kw, "g": -g})  # checked as the user gave it
            object.__setattr__(p, "g", g)
            return p
        return CompressorParams(**kw)

    def plugged(self, local: Mapping[str, Any]) -> dict[str, Any]:
        """A throw's values of components from a user's file (their own fragments)."""
        if not any(is_spec(local.get(f)) for f in PLUGGABLE):
            return {}
        return {k: v for k, v in local.items() if k not in _FIELDS and k != "phase"}

    def configuration(self, values: Mapping[str, Any]) -> Configuration:
        """The machine assembled at validated ``values`` (remembered per values: a streamed
        run asks per block)."""
        machine = self.structure(values)
        items = tuple(sorted(values.items()))
        try:
            hash(items)
        except TypeError:  # an unhashable value (a table as lists): assembled each time
            return assemble(machine, dict(values))
        return _configuration(id(type(self)), machine, items)

    # -- parameters ----------------------------------------------------------------------
    def _file_extras(self) -> dict[str, Any]:
        """The values a machine file gives beside the schema: a throw's ``load_table`` (rows,
        or a CSV file relative to the machine file), as ``throwK.load_table``."""
        from pathlib import Path

        out = {}
        for t in self.machine.throws:
            table = t.values.get("load_table")
            if isinstance(table, str):
                from ..load import read_load_table

                path = Path(table)
                if not path.is_absolute() and self.machine.source:
                    path = Path(self.machine.source).parent / path
                table = read_load_table(path)
            if table is not None:
                out[self.machine.prefix(t.name) + "load_table"] = tuple(
                    tuple(map(float, r)) for r in table)  # fmt: skip
        return out

    def parameters(self, values: Mapping[str, Any] | Any | None = None, **kw: Any
                   ) -> dict[str, Any]:  # fmt: skip
        """Validated values: the machine file's (its tables too), updated with ``values``."""
        if values is not None and not isinstance(values, Mapping):
            return super().parameters(values, **kw)
        return super().parameters({**self._file_extras(), **(values or {}), **kw})

    def check(self, values: Mapping[str, Any]) -> None:
        """Each throw's checks across its parameters (rs <= r, rc < r, |d| < l - r - rc, the
        motor's slip), refused with the throw's namespace."""
        machine = self.structure(values)
        for t, local in zip(machine.throws, self.throws(values), strict=True):
            try:
                self.throw_params(local)
                if is_spec(local.get("load")):  # a user's component's own checks
                    load = load_of(local)
                    if load.check is not None:
                        load.check(local)
            except ParameterError as exc:
                raise _prefixed_message(machine.prefix(t.name), exc) from None
        if machine.frame is not None:
            from ..frame.body import check as frame_check

            frame_check(machine.frame, frame_values(values))
        if machine.shaft.torsion:
            from ..shaft.flexible import check as torsion_check

            torsion_check(machine, values)
        self._check_interstages(machine, values)

    def _check_interstages(self, machine: Machine, values: Mapping[str, Any]) -> None:
        """An interstage holds the cylinders' ideal gas: its stages' throws take the ideal
        gas with one gas constant."""
        locals_ = dict(zip((t.name for t in machine.throws), self.throws(values), strict=True))
        for i in machine.interstages:
            joined = [t.name for t in machine.throws if t.stage in (i.upstream, i.downstream)]
            for name in joined:
                if locals_[name].get("gas", "ideal") != "ideal":
                    raise ParameterError(f"{name}.gas = {locals_[name]['gas']!r}: interstage "
                                         f"{i.name!r} holds an ideal gas (a real gas's line "
                                         "states are tabulated at set pressures); allowed: "
                                         "'ideal'")  # fmt: skip
            r = {float(locals_[n]["gas_constant"]) for n in joined}
            if len(r) > 1:
                raise ParameterError(f"interstage {i.name!r}: its stages' throws have gas "
                                     f"constants {sorted(r)} J/(kg*K): one gas flows through "
                                     "it; give them one gas_constant")  # fmt: skip

    def period(self, values: Mapping[str, Any]) -> float:
        """The crank period at ``omega``: the forcing period with a prescribed crank, the
        nominal one with a motor (runs and sweeps count revolutions in it; the system itself
        is autonomous then, its ``period`` None)."""
        return 2.0 * math.pi / float(self._shaft(values, "omega"))

    def _shaft(self, values: Mapping[str, Any], name: str) -> Any:
        return values[f"{self.structure(values).prefix('shaft')}{name}"]

    def section_angle(self, values: Mapping[str, Any]) -> str | None:
        """``theta1`` with a motor (a state: the section once per turn of the crank)."""
        return "theta1" if self.structure(values).shaft.drive == "motor" else None

    def has_dynamics(self, values: Mapping[str, Any]) -> bool:
        return self.structure(values).shaft.drive == "motor" or any(
            float(v["rc"]) > 0.0 for v in self.throws(values)
        )

    def validity_applies(self, values: Mapping[str, Any]) -> bool:
        """The link's bound (it can only push) needs a link: rc > 0 at some throw; the
        frame's one-way coupling (a machine with a frame) always."""
        if self.structure(values).frame is not None:
            return True
        return any(float(v["rc"]) > 0.0 for v in self.throws(values))

    def lyapunov_supported(self, values: Mapping[str, Any]) -> bool:
        return not any(t.load == "valves" for t in self.structure(values).throws)

    # -- the system ----------------------------------------------------------------------
    def states(self, values: Mapping[str, Any]) -> tuple[tuple[str, str], ...]:
        return self.configuration(values).layout.state.named()

    def events(self, values: Mapping[str, Any]) -> tuple[Event, ...]:
        from ..base import Event

        c = self.configuration(values)
        if not c.has_states:
            return ()
        return (Event("impact", c.kernels.event, direction=-1, action="reset",
                      reset=c.kernels.reset, description="a valve plate reaches its seat or "
                      "guard: rebound with the restitution, or rest"),)  # fmt: skip

    def system(self, values: Mapping[str, Any]) -> AssembledSystem:
        from .system import AssembledSystem, Frozen

        c = self.configuration(values)
        machine = c.machine
        motor = c.motor is not None
        exact = machine.throws[0].equations == "exact"
        names, units = zip(*c.layout.state.named(), strict=True)
        return AssembledSystem(
            rhs=c.kernels.rhs,
            jac=c.kernels.jac,
            rhs_jac=c.kernels.rhs_jac
            if not (motor or c.has_states or machine.frame is not None) and exact
            else None,
            params=c.params,
            state_names=names,
            state_units=units,
            period=None if motor else self.period(values),
            name=self.system_name(values),
            attrs=self.system_attrs(values),
            events=self.events(values),
            aux_states=c.aux_states,
            passive=c.passive(self.throws(values)),
            model=self,
            values=Frozen(values),
        )

    def system_name(self, values: Mapping[str, Any]) -> str:
        return self.name

    def system_attrs(self, values: Mapping[str, Any]) -> dict[str, Any]:
        return dict(values)

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        """Per throw: the link aligned with its rod load at its crank angle (static
        equilibrium) plus ``theta_c_offset``, or ``theta_c0``, at rest; the crank at
        ``theta1_0`` turning at ``omega`` (a motor), works 0; a load's states at the throw's
        crank angle (the dynamic valves: the ideal cycle's pressures, plates closed), its
        counters 0."""
        from .. import valves as va

        c = self.configuration(values)
        st = c.layout.state
        y = np.zeros(st.size)
        for t, local in zip(c.machine.throws, self.throws(values), strict=True):
            p = self.throw_params(local)
            phase = float(local["phase"])
            s = st.start(f"{t.name}.mechanism")
            if p.theta_c0 is not None:
                thc = p.theta_c0
            else:
                thc = equilibrium_theta_c(p, extra=self.plugged(local), phase=phase)
            y[s], y[s + 1] = thc + p.theta_c_offset, p.thetadot_c0
            load = c.loads[0]
            if load.states:
                g = st.start(f"{t.name}.load")
                if load.name == "valves":
                    cyc = c.params[c.layout.params[f"{t.name}.load"]][: _n_cycle()]
                    y[g : g + len(load.states)] = va.gas_initial(local, cyc, p.theta1_0 + phase)
                else:
                    init = np.asarray(load.initial(local), dtype=float)
                    y[g : g + len(load.states)] = init[: len(load.states)]
                    a = st.start(f"{t.name}.load_aux")
                    y[a : a + len(load.aux_states)] = init[len(load.states) :]
        if c.motor is not None:
            y[st["theta1"]] = float(self._shaft(values, "theta1_0"))
            y[st["omega1"]] = float(self._shaft(values, "omega"))
        if c.machine.shaft.torsion:  # each node behind the one before by its section's twist
            from ..base import rhs_series
            from ..shaft.flexible import stiffnesses, twisted_start

            nodes = st.parts["shaft.nodes"]
            o = c.layout.params.start("shaft.torsion")

            def rhs(yy):
                return rhs_series(c.kernels.rhs, c.params, np.zeros(1), yy[None, :])[0]

            y = twisted_start(rhs, y, [st["theta1"], *range(nodes.start, nodes.stop, 2)],
                              (c.params[o], c.params[o + 1]),
                              stiffnesses(c.machine, values),
                              held=c.motor.name == "held")  # fmt: skip
        for i in c.machine.interstages:  # at the upstream stage's set discharge pressure
            y[st[f"{i.name}.p"]] = float(values[f"{i.upstream}.discharge_pressure"])
        return y

    def state_scale(self, values: Mapping[str, Any]) -> np.ndarray:
        """``max(1, |y0|)``; a load's states at their own size (the valves':
        [`gas_scale`][recipdyn.model.valves.gas_scale])."""
        from .. import valves as va

        c = self.configuration(values)
        y0 = self.initial_state(values)
        out = np.maximum(1.0, np.abs(y0))
        if c.loads[0].name == "valves":
            for t, local in zip(c.machine.throws, self.throws(values), strict=True):
                out = va.gas_scale(local, y0, c.layout.state.start(f"{t.name}.load"),
                                   c.layout.state.start(f"{t.name}.load_aux"), out)  # fmt: skip
        return out

    # -- outputs -------------------------------------------------------------------------
    def outputs(self, values: Mapping[str, Any], t: np.ndarray, y: np.ndarray,
                dy: np.ndarray | None = None) -> dict[str, Signal]:  # fmt: skip
        """Per throw: its crosshead's motion, rod angle, clearance state, gas force, joint and
        guide forces, and its cylinder's signals (the cycle's pressures and volumes; the
        valves' pressures, volumes, temperatures and mass flows), under its name; with a motor
        the crank's speed and acceleration, the motor's torque and work, each throw's gas work
        and the machine's energy. The crank angle, speed and gas forces come from the
        compiled observer: the functions that were integrated. ``dy``: the derivatives at
        ``y`` when they are not this model's own (a throw's slice of a machine whose crank
        other throws share, `ContactMachine`); by default its right-hand side's."""
        from .. import valves as va
        from ..base import Signal, rhs_series
        from ..components.load import cycle_outputs
        from ..kinematics import kinematics

        c = self.configuration(values)
        st, ov = c.layout.state, c.layout.outputs
        t = np.ascontiguousarray(t, dtype=np.float64)
        y = np.ascontiguousarray(y, dtype=np.float64)
        if dy is None:
            dy = rhs_series(c.kernels.rhs, c.params, t, y)
        obs = c.kernels.observe(t, y, c.params)
        w1 = obs[:, ov["omega1"]]
        motor = c.motor is not None
        a1 = dy[:, st["omega1"]] if motor else None
        torsion = c.machine.shaft.torsion
        out: dict[str, Signal] = {}
        frame = None if c.machine.frame is None else _FrameRecord(c, values, y, dy)
        energy = np.zeros(t.shape[0])
        shake = np.zeros((4, t.shape[0]))  # the frame's F_x, F_y, M_x, M_y
        for k, (th, local) in enumerate(zip(c.machine.throws, self.throws(values), strict=True)):
            pre = c.machine.prefix(th.name)
            p = self.throw_params(local)
            s = st.start(f"{th.name}.mechanism")
            thc, thcd, thcdd = y[:, s], y[:, s + 1], dy[:, s + 1]
            th1 = obs[:, ov[f"{th.name}.theta1"]]
            fg = obs[:, ov[f"{th.name}.gas_force"]]
            wk, ak = w1, a1  # its crank's speed and acceleration: the crank's or its node's
            if torsion:
                n = st[f"{pre}theta_shaft"]
                wk, ak = y[:, n + 1], dy[:, n + 1]
            kin = kinematics(p, t, thc, thcd, thcdd, theta1=th1, omega1=wk, alpha1=ak)
            own = mechanism_outputs(p, kin, thc, thcd, thcdd, fg)
            own["crank_torque"] = Signal(
                obs[:, ov[f"{th.name}.crank_torque"]],
                "N*m",
                "torque the shaft applies to this throw's crank",
            )
            if c.loads[0].name == "valves":
                g, a = st.start(f"{th.name}.load"), st.start(f"{th.name}.load_aux")
                cyc = c.params[c.layout.params[f"{th.name}.load"]][: _n_cycle()]
                own.update(va.gas_outputs(local, kin.x3, y, dy, g, a, cyc))
            else:
                own.update(cycle_outputs(local, th1))
            if motor:
                iw = st.start(f"{th.name}.work")
                own["W_gas"] = Signal(
                    y[:, iw], "J", "work done by the gas on the crosshead since t = 0"
                )
                own_energy = mechanism_energy(p, th1, thc, wk, thcd)
                if not c.machine.flat:
                    own["energy"] = Signal(own_energy, "J", "kinetic + potential energy of this "
                                           "throw's crank, rod and crosshead")  # fmt: skip
                if torsion:  # (the drive's nodes and the springs: `_torsion_outputs`)
                    energy += own_energy
                elif not c.machine.flat:
                    energy += own_energy + 0.5 * p.J_drive * w1 * w1 if k == 0 else own_energy
                else:  # (the drive's inertia in the same expression, as before the assembler)
                    energy += mechanism_energy(p, th1, thc, w1, thcd, p.J_drive)
            if not c.machine.flat:
                own["theta1"] = Signal(th1, "rad", "crank angle of this throw in its own axes "
                                       "(the shaft's, or on a flexible shaft its node's, + "
                                       "phase - cylinder_angle)")  # fmt: skip
                own.update(_shaking(p, kin, fg, wk, ak, th, shake))
            if frame is not None:
                from ..mechanism.shaking import throw_shaking

                own.update(frame.at_guide(th, own["a"].values))
                frame.throws.append((p.m1 + p.m2 + p.m3, own["frame_a"].values,
                                     throw_shaking(p, kin, wk, ak)[0]))  # fmt: skip
            out.update({pre + name: sig for name, sig in own.items()})
        if motor:
            out.update({
                "omega1": Signal(w1, "rad/s", "crank speed"),
                "alpha1": Signal(a1, "rad/s**2", "crank angular acceleration"),
                "motor_torque": Signal(dy[:, st["W_motor"]] / w1, "N*m",
                                       "motor torque at the crank"),
                "W_motor": Signal(y[:, st["W_motor"]], "J", "work done by the motor since t = 0"),
                "energy": Signal(energy, "J", "kinetic + potential energy of the mechanism and "
                                 "the drive"),
            })  # fmt: skip
        if torsion:
            shaft = _torsion_outputs(c, y, dy, obs)
            energy += shaft.pop("_energy").values
            out.update(shaft)
            out["energy"] = Signal(energy, "J", "kinetic + potential energy of the mechanisms, "
                                   "the drive's nodes and the shaft's sections")  # fmt: skip
        out.update(_interstage_outputs(c, y, dy))
        if not c.machine.flat:
            out["theta1"] = Signal(obs[:, ov["theta1"]], "rad", "crank angle of the shaft")
            out.update({
                "shake_x": Signal(shake[0], "N", "shaking force on the frame along x: the sum "
                                  "over the throws of -(m1 a1 + m2 a2 + m3 a3)"),
                "shake_y": Signal(shake[1], "N", "shaking force on the frame along y"),
                "shake_moment_x": Signal(shake[2], "N*m", "shaking moment on the frame about "
                                         "the x axis through z = 0: -sum z_k F_y,k"),
                "shake_moment_y": Signal(shake[3], "N*m", "shaking moment on the frame about "
                                         "the y axis through z = 0: sum z_k F_x,k"),
            })  # fmt: skip
        if frame is not None:
            out.update(frame.signals())
        return out

    def run_summary(self, values: Mapping[str, Any], ds: Any) -> dict[str, Any]:
        """Per throw, its cylinder's figures (`_throw_summary`) and, whatever its load, the
        API 618 rod load and crosshead-pin reversal over the last revolution, under its name;
        the frame's combined load (`_frame_summary`); a flexible shaft's natural frequencies
        and API 618's torsional separation at the run's mean speed
        (`recipdyn.model.shaft.torsion.torsion_summary`)."""
        from ..cycle import pin_reversal_summary

        machine = self.structure(values)
        out: dict[str, Any] = {}
        if "frame_feedback" in ds.variables:  # the frame on its mounts: one-way coupling
            out["frame_feedback_ratio"] = float(np.max(ds["frame_feedback"].values))
        if machine.shaft.torsion:
            from ..shaft.torsion import torsion_summary

            speed = (float(np.mean(ds["omega1"].values)) if "omega1" in ds.variables
                     else float(self._shaft(values, "omega")))  # fmt: skip
            out.update(torsion_summary(machine, values, speed / (2.0 * math.pi)))
        if machine.flat:
            return {**self._throw_summary(self.throws(values)[0], ds), **out}
        for t, local in zip(machine.throws, self.throws(values), strict=True):
            pre = f"{t.name}."
            view = ds[[k for k in ds.data_vars if str(k).startswith(pre)]]
            view = view.rename({k: str(k)[len(pre) :] for k in view.data_vars})
            view = view.assign_attrs(ds.attrs)
            own = self._throw_summary(local, view)
            if "api618_pin_reversal" not in own and {"theta1", "a", "gas_force"} <= set(view):
                own.update(pin_reversal_summary(local, view))
            for k, v in own.items():
                out[pre + k] = v
        out.update(_frame_summary(ds, float(self._shaft(values, "omega"))))
        return out

    @staticmethod
    def _throw_summary(local: Mapping[str, Any], ds: Any) -> dict[str, Any]:
        """A throw's figures: with the cycle, the API 618 pin-load reversal and the indicated
        power and volumetric efficiencies; with the dynamic valves, theirs too."""
        from .. import valves as va
        from ..components.load import cycle_summary

        if local.get("load") == "valves":
            return va.valve_summary(local, ds)
        return cycle_summary(local, ds)

    def record_attrs(self, values: Mapping[str, Any], y0: np.ndarray | None = None
                     ) -> dict[str, Any]:  # fmt: skip
        machine = self.structure(values)
        out = super().record_attrs(values, y0)
        out.update({"sign_convention": SIGN_CONVENTION, "throws": len(machine.throws)})
        if not machine.flat:  # each throw's placement on the frame (structure, not parameters)
            for t in machine.throws:
                out[f"{t.name}.cylinder_angle_deg"] = math.degrees(t.cylinder_angle)
                out[f"{t.name}.axial_position_m"] = t.axial_position
            out["frame_axes"] = FRAME_AXES
        if machine.frame is not None:  # its mounts' places (structure, not parameters)
            for m in machine.frame.mounts:
                out[f"frame.{m.name}.x_m"] = m.x
                out[f"frame.{m.name}.z_m"] = m.z
            out.setdefault("frame_axes", FRAME_AXES)
        return out


class ContactMachine(MachineModel):
    """A machine whose throws have contact-impact or lubricated crank pins
    (`.contact_throws`: their parameters, layout and kernels; each throw's signals and
    summary its one-throw model's under its name): `MachineModel` builds one for such a
    machine."""

    validity_bounds = ()

    def __init__(self, machine: Machine, schema: Schema | None = None) -> None:
        from .contact_throws import refusal

        why = refusal(machine)
        if why is not None:
            raise ParameterError(why)
        super().__init__(machine, schema)
        self.description = machine.description or (
            f"{len(machine.throws)} throws on one crankshaft ({machine.shaft.drive} drive), "
            "contact-impact pins"
        )
        from .contact_throws import is_contact

        pre = [machine.prefix(t.name) for t in machine.throws]
        worn = [q for q, t in zip(pre, machine.throws, strict=True) if is_contact(t)]
        self.section_signals = tuple((f"{q}{s}", u) for q, t in zip(pre, machine.throws,
                                                                     strict=True)
                                     for s, u in (*((("ex", "m"), ("ey", "m")) if is_contact(t)
                                                    else (("theta_c", "rad"),
                                                          ("thetadot_c", "rad/s"))),
                                                  ("x", "m"), ("v", "m/s"),
                                                  ("a", "m/s**2")))  # fmt: skip
        # on a frame its one-way coupling's bound (MachineModel's), no link's
        self.validity_bounds = tuple(b for b in self.validity_bounds
                                     if b[0] == "frame_coupling_margin")  # fmt: skip
        self.summary_verdicts = tuple(f"{q}api618_pin_reversal" for q in pre)
        self.mean_signals = tuple((f"{q}contact", f"{q}contact_fraction", "1") for q in worn)
        self.max_signals = tuple((f"{q}eccentricity_ratio", f"{q}max_eccentricity_ratio", "1")
                                 for q in worn)  # fmt: skip
        self.event_example = {
            "shaft.omega" if not machine.flat else "omega": 150.0,
            **{
                f"{q}load_amplitude": 2e4
                for q, t in zip(pre, machine.throws, strict=True)
                if t.load == "paper"
            },
        }
        # (the reason, said when `lyapunov_supported` is False)
        self.lyapunov_refusal = next(
            (m.lyapunov_refusal for m in map(_one_model, machine.throws) if m.lyapunov_refusal),
            "",
        )
        if machine.frame is not None:
            self.lyapunov_refusal = (
                "Lyapunov exponents of contact throws on a [frame] are not offered yet (the "
                "frame's states as passive components are checked for ideal throws only); "
                "offered without the [frame], or with ideal throws"
            )
        elif machine.shaft.torsion:
            self.lyapunov_refusal = (
                "Lyapunov exponents of contact throws on a flexible shaft ([shaft.torsion]) "
                "are not offered yet (each throw's crank is its node: not checked); offered on "
                "a rigid shaft with drive = 'prescribed'"
            )
        elif machine.interstages:
            self.lyapunov_refusal = (
                "Lyapunov exponents of contact throws joined by an [[interstage]] are not "
                "offered yet (checked for the massless link's throws only); offered without "
                "the interstage, or with ideal throws"
            )
        elif len(machine.throws) > 1 and machine.shaft.drive == "motor":
            self.lyapunov_refusal = (
                "each throw of a machine of several contact throws on a motor carries its own "
                "copy of the crank's angle and speed (one degree of freedom, counted once per "
                "throw: Benettin's method would add a spurious exponent for each); offered "
                "with drive = 'prescribed' or one throw"
            )

    def contact(self, values: Mapping[str, Any]) -> ContactConfiguration:
        """The machine resolved at validated ``values`` (remembered per values,
        `.contact_throws.contact_configuration`)."""
        from .contact_throws import contact_configuration

        return contact_configuration(self.structure(values), tuple(sorted(values.items())),
                                     _one_model)  # fmt: skip

    def contact_values(self, values: Mapping[str, Any]) -> list[dict[str, Any]]:
        """Each throw's values as the one-throw contact model takes them."""
        return list(self.contact(values).locals)

    # -- what MachineModel does for the massless link ----------------------------------
    def check(self, values: Mapping[str, Any]) -> None:
        """Each throw's checks (its one-throw model's), refused with its namespace."""
        from .contact_throws import is_contact, same_joints, throw_contact_values
        from .contact_throws import throw_link_values as link

        machine = self.structure(values)
        locals_ = [throw_contact_values(machine, t, v) if is_contact(t)
                   else link(machine, t, v, _one_model(t))
                   for t, v in zip(machine.throws, self.throws(values), strict=True)]  # fmt: skip
        same_joints(machine, locals_)
        if machine.shaft.torsion:
            from ..shaft.flexible import check as torsion_check

            torsion_check(machine, values)
        self._check_interstages(machine, values)

    def has_dynamics(self, values: Mapping[str, Any]) -> bool:
        return True

    def validity_applies(self, values: Mapping[str, Any]) -> bool:
        """The frame's one-way coupling (a machine with a frame); nothing else."""
        return self.structure(values).frame is not None

    def lyapunov_supported(self, values: Mapping[str, Any]) -> bool:
        """Where every throw's joints have it (`system`: each throw's recorded approach
        velocities are auxiliary components, its work integrals passive), with a prescribed
        crank or one throw, and no frame (`lyapunov_refusal`)."""
        machine = self.structure(values)
        several_on_motor = len(machine.throws) > 1 and machine.shaft.drive == "motor"
        if machine.frame is not None or several_on_motor or machine.interstages:
            return False
        if machine.shaft.torsion:
            return False
        return all(_one_model(t).lyapunov_supported(v) for t, v in zip(
            machine.throws, self.contact_values(values), strict=True))  # fmt: skip

    def states(self, values: Mapping[str, Any]) -> tuple[tuple[str, str], ...]:
        return self.contact(values).layout.state.named()

    def events(self, values: Mapping[str, Any]) -> tuple[Event, ...]:
        from ..base import Event

        c = self.contact(values)
        k = c.kernels
        if len(c.locals) == 1:  # the one-throw model's event, on the machine's module
            (own,) = _one_model(c.machine.throws[0]).events(c.locals[0])
            return (Event(own.name, k.event, direction=own.direction, action=own.action,
                          reset=k.reset, description=own.description),)  # fmt: skip
        return (Event("impact", k.event, direction=-1, action="reset", reset=k.reset,
                      description="contact onset or separation at a throw's worn crank pin "
                      "(the smallest of the throws' phased factors falls through 0): at an "
                      "onset the approach velocity is recorded for the damping law"),)  # fmt: skip

    def system(self, values: Mapping[str, Any]) -> AssembledSystem:
        from ..joints.pins import I_WIN, I_WLOSS, RIGID
        from .contact_throws import is_contact, shared
        from .system import AssembledSystem, Frozen

        c = self.contact(values)
        st = c.layout.state
        passive, aux, counters = [], (), []
        for t, v in zip(c.machine.throws, c.locals, strict=True):
            s = st.start(f"{t.name}.mechanism")
            if not is_contact(t):  # an ideal throw: its one-throw configuration's
                own_c = _one_model(t).configuration(v)
                passive += [s + i for i in own_c.passive([v])]
                n = st.parts[f"{t.name}.mechanism"].stop - s
                counters += range(s + n - own_c.aux_states, s + n)
                continue
            passive += [s + i for i in (*RIGID[v["clearance_joints"]], I_WIN, I_WLOSS)]
        first = next(k for k, t in enumerate(c.machine.throws) if is_contact(t))
        own = _one_model(c.machine.throws[first]).system(c.locals[first])  # (its aux states)
        aux_states = own.aux_states
        if len(c.locals) == 1 and c.machine.shaft.drive == "motor":  # the model's own
            passive, aux = list(own.passive), own.aux
        pre = [c.machine.prefix(t.name) for t in c.machine.throws]
        if shared(c.machine):  # the work integrals of the shaft on each crank and the motor's
            passive += [st[q + "W_crank"] for q in pre] + [st["W_motor"]]
            if c.machine.shaft.torsion:  # (and the sections' dissipation)
                passive.append(st.start("shaft.work") + 1)
            aux_states = 1
        if c.machine.frame is not None:  # its states and work integrals (one-way: passive)
            for part in ("frame", "frame.work"):
                passive += range(*st.parts[part].indices(st.size))
        if len(c.locals) > 1 or c.machine.frame is not None:  # every throw's recorded values
            # by index (Lyapunov's aux); the frame's states, after the throws', passive
            recorded = set(counters)
            for t, v in zip(c.machine.throws, c.locals, strict=True):
                if is_contact(t):  # its one-throw model's: approach velocities, counters
                    s = st.start(f"{t.name}.mechanism")
                    one = own if v is c.locals[first] else _one_model(t).system(v)
                    recorded |= {s + i for i in (*range(one.dim - one.aux_states, one.dim),
                                                 *one.aux)}  # fmt: skip
            aux = tuple(sorted(recorded - set(passive)))
            last = c.machine.frame is None and not c.machine.interstages  # (W_motor last)
            aux_states = 1 if shared(c.machine) and last else 0
        names, units = zip(*st.named(), strict=True)
        return AssembledSystem(
            rhs=c.kernels.rhs,
            jac=c.kernels.jac,
            rhs_jac=None,
            params=c.params,
            state_names=names,
            state_units=units,
            period=self.period(values),
            name=self.system_name(values),
            attrs=self.system_attrs(values),
            events=self.events(values),
            aux_states=aux_states,
            aux=aux,
            passive=tuple(sorted(passive)),
            model=self,
            values=Frozen(values),
        )

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        """Each throw's one-throw initial state (the pin along its rod load at its own crank
        angle, `ContactJoints.initial_state`); with several throws each recorded approach
        velocity carries its pin's phase (+ in contact, - in free flight)."""
        from .contact_throws import is_contact

        c = self.contact(values)
        parts = []
        for t, v in zip(c.machine.throws, c.locals, strict=True):
            model = _one_model(t)
            y = model.initial_state(v)
            if is_contact(t) and len(c.locals) > 1 and not model.tracks_separations(v):
                sign = 1.0 if v["e0_ratio"] >= 1.0 else -1.0
                y[8] = y[9] = sign * v["v_impact_min"]
            parts.append(y)
        st = c.layout.state
        if "shaft.nodes" in st.parts:  # the rotor and the flywheel at the shaft's start
            th0, w0 = (float(self._shaft(values, k)) for k in ("theta1_0", "omega"))
            parts.append(np.array([th0, w0, th0, w0]))
        if "shaft.work" in st.parts:  # the motor's work (and the sections' dissipation)
            parts.append(np.zeros(len(st.names[st.parts["shaft.work"]])))
        if c.machine.frame is not None:  # the frame at rest on its mounts, its works 0
            parts.append(np.zeros(8))
        for i in c.machine.interstages:  # at the upstream stage's set discharge pressure
            parts.append(np.array([float(values[f"{i.upstream}.discharge_pressure"])]))
        y0 = np.concatenate(parts)
        if "shaft.nodes" in st.parts:
            y0 = _twisted(c, values, y0)
        return y0

    def state_scale(self, values: Mapping[str, Any]) -> np.ndarray:
        """Each throw's one-throw scales (the gas states at their own size)."""
        c = self.contact(values)
        own = [_one_model(t).state_scale(v)
               for t, v in zip(c.machine.throws, c.locals, strict=True)]  # fmt: skip
        if "shaft.nodes" in c.layout.state.parts:
            own.append(np.ones(4))
        if "shaft.work" in c.layout.state.parts:
            st = c.layout.state
            own.append(np.ones(len(st.names[st.parts["shaft.work"]])))
        if c.machine.frame is not None:  # (its displacements at their own size: microns)
            own.append(np.array([1e-6] * 3 + [1e-4] * 3 + [1.0] * 2))
        for i in c.machine.interstages:  # (a pressure: its own size)
            own.append(np.array([float(values[f"{i.upstream}.discharge_pressure"])]))
        return np.concatenate(own)

    def outputs(self, values: Mapping[str, Any], t: np.ndarray, y: np.ndarray
                ) -> dict[str, Signal]:  # fmt: skip
        """Each throw's signals, the one-throw contact model's of its states (its crank angle
        its own: the shaft's plus its phase), under its name; the shaft's crank angle."""
        from ..base import Signal, rhs_series
        from .contact_throws import is_contact, shared

        c = self.contact(values)
        y = np.asarray(y, dtype=np.float64)
        out: dict[str, Signal] = {}
        dy = None
        frame = None
        stages = bool(c.machine.interstages)
        if (shared(c.machine) and c.link_module is not None) or c.machine.frame is not None \
                or stages:  # fmt: skip
            dy = rhs_series(c.kernels.rhs, c.params, np.asarray(t, dtype=np.float64), y)
        if c.machine.frame is not None:
            frame = _FrameRecord(c, values, y, dy)
        for th, v in zip(c.machine.throws, c.locals, strict=True):
            part = c.layout.state.parts[f"{th.name}.mechanism"]
            yk = np.ascontiguousarray(y[:, part])
            if is_contact(th) and stages and th.load == "valves":  # its lines: the machine's
                own = _one_model(th).outputs(v, t, yk, np.ascontiguousarray(dy[:, part]))
            elif is_contact(th):
                own = _one_model(th).outputs(v, t, yk)
            else:  # an ideal throw: its one-throw model's, at the shaft's acceleration
                own = _one_model(th).outputs(v, t, yk, None if dy is None else dy[:, part])
                own.setdefault("theta1", Signal(
                    yk[:, 2] if "theta1" in dict(_one_model(th).states(v)) else
                    float(v["theta1_0"]) + float(v["omega"]) * np.asarray(t, dtype=float),
                    "rad", "crank angle of this throw (the shaft's + phase)"))  # fmt: skip
            pre = c.machine.prefix(th.name)
            if frame is not None:  # its accelerometer: its crosshead's + the frame's
                own.update(frame.at_guide(th, own["a"].values))
                own.update(_contact_shaking(c, th, v, t, y, dy))
                frame.throws.append((float(v["m1"]) + float(v["m2"]) + float(v["m3"]),
                                     own["frame_a"].values, own["_fx"].values))  # fmt: skip
                del own["_fx"]
            out.update({pre + k: s for k, s in own.items()})
        if frame is not None:
            names = [c.machine.prefix(th.name) for th in c.machine.throws]
            out["shake_x"] = Signal(sum(out[q + "shake_x"].values for q in names), "N",
                                    "shaking force on the frame along x: the sum over the "
                                    "throws of -(m1 a1 + m2 a2 + m3 a3)")  # fmt: skip
            out.update(frame.signals())
        if stages:
            out.update(_contact_interstage_outputs(c, y, dy))
        if shared(c.machine):
            crank = _shared_crank(c, values, t, y, out)
            for q in (c.machine.prefix(th.name) for th in c.machine.throws):
                for k in ("alpha1", "motor_torque", "W_motor", "omega1"):  # (the shaft's now)
                    out.pop(q + k, None)
            out.update(crank)
        elif not c.machine.flat and c.machine.shaft.drive == "motor":  # (one throw, named)
            pre, phase = c.machine.prefix(c.machine.throws[0].name), self.throws(values)[0]["phase"]
            out["theta1"] = Signal(out[pre + "theta1"].values - float(phase), "rad",
                                   "crank angle of the shaft")  # fmt: skip
        elif not c.machine.flat:
            w = float(self._shaft(values, "omega"))
            th1 = float(self._shaft(values, "theta1_0")) + w * np.asarray(t, dtype=np.float64)
            out["theta1"] = Signal(th1, "rad", "crank angle of the shaft")
        return out

    def run_summary(self, values: Mapping[str, Any], ds: Any) -> dict[str, Any]:
        """Each throw's figures (`ContactJoints.run_summary` of its signals and of the
        events at which its own pin changed phase), under its name."""
        from .contact_throws import is_contact

        c = self.contact(values)
        out: dict[str, Any] = {}
        if "frame_feedback" in ds.variables:  # the frame on its mounts: one-way coupling
            out["frame_feedback_ratio"] = float(np.max(ds["frame_feedback"].values))
        if c.machine.flat:
            return {**_one_model(c.machine.throws[0]).run_summary(c.locals[0], ds), **out}
        for th, v in zip(c.machine.throws, c.locals, strict=True):
            pre = f"{th.name}."
            ev = f"impact_{pre}"
            rename = {"impact_time": "impact_time"} if "impact_time" in ds.data_vars else {}
            for k in map(str, ds.data_vars):
                if k.startswith(pre):
                    rename[k] = k[len(pre) :]
                elif k.startswith(ev):  # (its crank's work under its one-throw name)
                    own = k[len(ev) :]
                    rename[k] = "impact_" + _ONE_THROW_NAMES.get(own, own)
            view = ds[list(rename)].rename(rename).assign_attrs(ds.attrs)
            if not is_contact(th):  # an ideal throw: its cylinder's figures and its rod load
                own = MachineModel._throw_summary({**v, "load": th.load}, view)
                if "api618_pin_reversal" not in own and {"theta1", "a", "gas_force"} <= set(view):
                    from ..cycle import pin_reversal_summary

                    own.update(pin_reversal_summary(v, view))
                out.update({pre + k: val for k, val in own.items()})
                continue
            if "impact_time" in view:  # its own events: where its reset moved its states
                part = c.layout.state.parts[f"{th.name}.mechanism"]
                names = [n[len(pre) :] for n in c.layout.state.names[part]]
                names = [_ONE_THROW_NAMES.get(n, n) for n in names]
                moved = np.column_stack(
                    [view[f"impact_{n}"].values != view[f"impact_{n}_after"].values for n in names]
                )
                view = view.isel(impact_event=np.flatnonzero(moved.any(axis=1)))
            for k, val in _one_model(th).run_summary(v, view).items():
                out[pre + k] = val
        if "W_motor" in ds.data_vars and "shaft.work" in c.layout.state.parts:
            out["energy_balance_residual"] = _energy_residual(c, ds)
        return out


def _contact_shaking(c: ContactConfiguration, throw: Throw, local: Mapping[str, Any],
                     t: np.ndarray, y: np.ndarray, dy: np.ndarray
                     ) -> dict[str, Signal]:  # fmt: skip
    """A throw's shaking force on the frame (the compiled function the frame's equations read,
    at each sample: a contact throw's `recipdyn.model.joints.pins.contact_shaking`, an ideal
    throw's `recipdyn.model.mechanism.link_kernels.shaking`) in the frame's axes
    (``shake_x``) and in its own along its stroke (``_fx``, for the frame's feedback)."""
    from ..base import Signal
    from ..frame.body import _cos_sin
    from ..joints.pins import contact_shaking
    from ..mechanism.link_kernels import shaking
    from .contact_throws import is_contact

    st = c.layout.state
    part = st.parts[f"{throw.name}.mechanism"]
    o = c.layout.params.parts[throw.name]
    pk = c.params[o]
    m1rs = float(local["m1"]) * float(local["rs"])
    t = np.asarray(t, dtype=np.float64)
    w0 = float(local["omega"])
    fx = np.empty(t.shape[0])
    fy = np.empty(t.shape[0])
    motor = c.machine.shaft.drive == "motor"
    link = None if is_contact(throw) else c.link_module
    crank = int(c.throw_module.M if link is None else getattr(link, "CRANK", 0))
    for i in range(t.shape[0]):
        yk, dk = y[i, part], dy[i, part]
        if motor:
            th, w, a = yk[crank], yk[crank + 1], dk[crank + 1]
        else:
            th, w, a = float(local["theta1_0"]) + w0 * t[i], w0, 0.0
        if link is None:
            fx[i], fy[i] = contact_shaking(th, w, a, yk, dk, pk, m1rs)
        else:
            fx[i], fy[i] = shaking(th + pk[int(link.THROW_PHASE[0])], yk[0], w, yk[1], a,
                                   dk[1], pk, int(link.THROW_MECH[0]))  # fmt: skip
    cs, sn = _cos_sin(throw.cylinder_angle)
    gx = cs * fx - sn * fy
    return {"shake_x": Signal(gx, "N", "this throw's shaking force on the frame along the "
                              "frame's x: -(m1 a1 + m2 a2 + m3 a3)"),
            "_fx": Signal(fx, "N", "")}  # fmt: skip


#: A throw's state in a machine whose crank several throws share, by its name in the
#: one-throw model (`.contact_throws`: the shaft's work on its crank, there the motor's).
_ONE_THROW_NAMES = {"W_crank": "W_motor", "W_crank_after": "W_motor_after"}


def _twisted(c: ContactConfiguration, values: Mapping[str, Any], y: np.ndarray) -> np.ndarray:
    """``y`` with the flexible shaft's nodes twisted as the rigid shaft's motion asks
    (`recipdyn.model.shaft.flexible.twisted_start`), on the nodes' angles less their phases (a
    throw's crank angle in its slice is its node's plus its phase)."""
    from ..base import rhs_series
    from ..shaft.flexible import stiffnesses, twisted_start

    k = c.kernels
    angles = [int(a) for a in k.NODE_ANGLE]
    phases = c.params[int(k.NODE_PHASES) : int(k.NODE_PHASES) + len(angles)]
    o = int(k.TORSION_PARAMS)

    def shifted(z: np.ndarray, sign: float) -> np.ndarray:
        z = np.array(z, dtype=np.float64)
        z[angles] += sign * phases
        return z

    def rhs(z: np.ndarray) -> np.ndarray:
        return rhs_series(k.rhs, c.params, np.zeros(1), shifted(z, 1.0)[None, :])[0]

    z = twisted_start(rhs, shifted(y, -1.0), angles, (c.params[o], c.params[o + 1]),
                      stiffnesses(c.machine, values))  # fmt: skip
    return shifted(z, 1.0)


def _contact_interstage_outputs(c: ContactConfiguration, y: np.ndarray, dy: np.ndarray
                                ) -> dict[str, Signal]:  # fmt: skip
    """`_interstage_outputs` of a machine of contact throws: each throw's mass counters at its
    module's offset in its slice (a contact throw's ``A``, an ideal throw's ``LOAD_AUX``)."""
    from .contact_throws import is_contact

    st, pv = c.layout.state, c.layout.params
    link = c.link_module
    counters = {t.name: st.start(f"{t.name}.mechanism")
                + (int(c.throw_module.A) if is_contact(t) else int(link.LOAD_AUX[0]))
                for t in c.machine.throws}  # fmt: skip
    gas = {i.name: tuple(c.params[pv[i.name]]) for i in c.machine.interstages}
    return _interstage_signals(c.machine, st, y, dy, counters, gas)


def _energy_residual(c: ContactConfiguration, ds: Any) -> float:
    """The machine's energy balance over the record, ``W_motor + sum_k W_gas,k = dE + sum_k
    W_loss,k``: its largest residual over the largest of the energy and the motor's work."""
    pre = [c.machine.prefix(th.name) for th in c.machine.throws]
    E, Wm = ds["energy"].values, ds["W_motor"].values
    Wg = sum(ds[q + "W_gas"].values for q in pre)
    Wl = sum(ds[q + "W_loss"].values for q in pre if q + "W_loss" in ds)  # (ideal: none)
    damping = c.machine.prefix("shaft") + "W_shaft_damping"
    if damping in ds:  # (a flexible shaft's sections)
        Wl = Wl + ds[damping].values
    bal = (Wm - Wm[0]) + (Wg - Wg[0]) - (E - E[0]) - (Wl - Wl[0])
    return float(np.abs(bal).max() / max(np.abs(E).max(), np.abs(Wm).max(), 1e-300))


def _one_model(throw: Throw):
    """A throw's one-throw model: the contact joints' (`.contact_throws.one_model`), or for
    an ideal throw beside them the massless link's (``--model compressor``, with the dynamic
    valves ``compressor-valves``)."""
    from .contact_throws import is_contact, one_model

    if is_contact(throw):
        return one_model(throw)
    return _link_valves_model() if throw.load == "valves" else LINK


@lru_cache(maxsize=1)
def _link_valves_model() -> OneThrow:
    return _link_valves()


def _shared_crank(c: ContactConfiguration, values: Mapping[str, Any], t: np.ndarray,
                  y: np.ndarray, out: Mapping[str, Signal]) -> dict[str, Signal]:  # fmt: skip
    """The signals of a motor's crank that several contact throws share: the shaft's angle,
    speed and acceleration, the motor's torque and work, the machine's energy (each throw's,
    its own crank's included, and the drive's) and per throw the shaft's torque on its crank
    (``crank_torque``) and work (``W_crank``); they replace each throw's one-throw model's
    crank signals (its own ``alpha1``, ``motor_torque``, ``W_motor``, ``omega1``), which the
    caller drops."""
    from ..base import Signal, rhs_series

    st = c.layout.state
    machine = c.machine
    pre = [machine.prefix(th.name) for th in machine.throws]
    dy = rhs_series(c.kernels.rhs, c.params, t, y)
    w = y[:, st[pre[0] + "omega1"]]
    torsion = "shaft.nodes" in st.parts
    sig: dict[str, Signal] = {}
    for q in pre:
        wk = y[:, st[q + "omega1"]]  # (its node's speed on a flexible shaft)
        sig[q + "crank_torque"] = Signal(dy[:, st[q + "W_crank"]] / wk, "N*m",
                                         "torque of the shaft on the throw's crank")  # fmt: skip
        sig[q + "W_crank"] = Signal(y[:, st[q + "W_crank"]], "J", "work of the shaft on the "
                                    "throw's crank since t = 0")  # fmt: skip
    j_drive = float(c.params[c.layout.params.start("shaft")])
    phase = float(throw_values(machine, values, 0)["phase"])
    energy = 0.5 * j_drive * w**2 + sum(out[q + "energy"].values for q in pre)
    sig.update({
        "theta1": Signal(y[:, st[pre[0] + "theta1"]] - phase, "rad", "crank angle of the shaft"),
        "omega1": Signal(w, "rad/s", "crank speed"),
        "alpha1": Signal(dy[:, st[pre[0] + "omega1"]], "rad/s**2",
                         "crank angular acceleration"),
        "motor_torque": Signal(dy[:, st["W_motor"]] / w, "N*m", "motor torque at the crank"),
        "W_motor": Signal(y[:, st["W_motor"]], "J", "work done by the motor since t = 0"),
        "energy": Signal(energy, "J", "the machine's energy: the drive's kinetic energy and "
                         "each throw's (its crank, rod and crosshead, contact elastic)"),
    })  # fmt: skip
    if torsion:
        sig.update(_torsion_crank(c, y, dy, out))
    return sig


def _torsion_crank(c: ContactConfiguration, y: np.ndarray, dy: np.ndarray,
                   out: Mapping[str, Signal]) -> dict[str, Signal]:  # fmt: skip
    """On a flexible shaft: the rotor's angle, speed and acceleration (the shaft's crank
    signals), the motor's torque, each section's twist and torque, the sections' dissipation,
    and the machine's energy (the rotor's, the flywheel's, each throw's, the sections'
    elastic)."""
    from ..base import Signal
    from ..shaft.flexible import section_names

    st, k = c.layout.state, c.kernels
    pre = [c.machine.prefix(th.name) for th in c.machine.throws]
    angles = [int(a) for a in k.NODE_ANGLE]
    phases = c.params[int(k.NODE_PHASES) : int(k.NODE_PHASES) + len(angles)]
    o = int(k.TORSION_PARAMS)
    rotor = angles[0]
    w0 = y[:, rotor + 1]
    energy = (0.5 * c.params[o] * w0**2 + 0.5 * c.params[o + 1] * y[:, angles[1] + 1] ** 2
              + sum(out[q + "energy"].values for q in pre))  # fmt: skip
    sig: dict[str, Signal] = {}
    for j, name in enumerate(section_names(c.machine)):
        a, b = angles[j], angles[j + 1]
        twist = (y[:, a] - phases[j]) - (y[:, b] - phases[j + 1])
        torque = c.params[o + 2 + 2 * j] * twist + c.params[o + 3 + 2 * j] * (
            y[:, a + 1] - y[:, b + 1]
        )
        energy = energy + 0.5 * c.params[o + 2 + 2 * j] * twist**2
        sig[name + "twist"] = Signal(twist, "rad", "twist of the shaft's section: its driving "
                                     "end's angle less its driven end's")  # fmt: skip
        sig[name + "torque"] = Signal(torque, "N*m", "torque the section carries")
    damping = st.start("shaft.work") + 1
    sig.update({
        "theta1": Signal(y[:, rotor], "rad", "angle of the motor's rotor"),
        "omega1": Signal(w0, "rad/s", "speed of the motor's rotor"),
        "alpha1": Signal(dy[:, rotor + 1], "rad/s**2", "acceleration of the motor's rotor"),
        "motor_torque": Signal(dy[:, st["W_motor"]] / w0, "N*m", "motor torque on its rotor"),
        st.names[damping]: Signal(y[:, damping], "J", "energy the shaft's sections dissipated "
                                  "since t = 0"),
        "energy": Signal(energy, "J", "the machine's energy: the rotor's and flywheel's kinetic "
                         "energy, each throw's, the sections' elastic energy"),
    })  # fmt: skip
    return sig


#: The frame's axes, in which the machine's shaking forces and moments are given.
FRAME_AXES = (
    "frame: x along the line of stroke of a throw with cylinder_angle 0 (from the shaft toward "
    "its cylinder), y up, z along the crankshaft (axial_position); a throw's own axes are the "
    "frame's turned by its cylinder_angle about z"
)


def _frame_summary(ds: Any, omega: float) -> dict[str, float]:
    """The frame's combined load over the record's last revolution: the largest shaking
    force (the magnitude of ``(shake_x, shake_y)``), its largest x and y components, and the
    largest shaking moment (the magnitude of ``(shake_moment_x, shake_moment_y)``); empty for
    a record shorter than a revolution."""
    from ..cycle import covers_revolution, last_revolution

    if not {"theta1", "shake_x"} <= set(ds.variables):
        return {}
    part = last_revolution(ds, omega)
    th = np.asarray(part["theta1"].values, dtype=float)
    last = th >= th[-1] - 2.0 * math.pi
    if np.count_nonzero(last) < 8 or not covers_revolution(th):
        return {}
    f = {k: np.asarray(part[k].values, dtype=float)[last]
         for k in ("shake_x", "shake_y", "shake_moment_x", "shake_moment_y")}  # fmt: skip
    return {
        "frame_peak_force_N": float(np.max(np.hypot(f["shake_x"], f["shake_y"]))),
        "frame_peak_force_x_N": float(np.max(np.abs(f["shake_x"]))),
        "frame_peak_force_y_N": float(np.max(np.abs(f["shake_y"]))),
        "frame_peak_moment_N_m": float(np.max(np.hypot(f["shake_moment_x"],
                                                       f["shake_moment_y"]))),
    }  # fmt: skip


def _shaking(p, kin, fg, w1, a1, throw: Throw, total: np.ndarray) -> dict[str, Signal]:
    """A throw's shaking force on the frame, in the frame's axes, and its rod load at the
    crosshead pin (`recipdyn.model.mechanism.shaking`); its force and moments added to
    ``total`` (F_x, F_y, M_x, M_y)."""
    from ..base import Signal
    from ..mechanism.shaking import in_frame, rod_load, throw_shaking

    fx, fy = in_frame(*throw_shaking(p, kin, w1, a1), throw.cylinder_angle)
    z = throw.axial_position
    total += (fx, fy, -z * fy, z * fx)
    return {
        "shake_x": Signal(fx, "N", "this throw's shaking force on the frame along the "
                          "frame's x: -(m1 a1 + m2 a2 + m3 a3)"),
        "shake_y": Signal(fy, "N", "this throw's shaking force on the frame along y"),
        "rod_load": Signal(rod_load(p, kin, fg), "N", "combined rod load at the crosshead "
                           "pin, m3 a - gas_force (> 0: compression; API 618)"),
    }  # fmt: skip


class _FrameRecord:
    """The frame's signals of a record (`recipdyn.model.frame.body`): its motion at each
    throw's guide from the integrated states and the compiled right-hand side's accelerations
    (``dy``), its energy and its mounts' forces, and the one-way coupling's neglected term."""

    def __init__(self, c: Configuration, values: Mapping[str, Any], y: np.ndarray,
                 dy: np.ndarray) -> None:  # fmt: skip
        from ..frame.body import matrices

        self.local = frame_values(values)
        self.M, self.K, self.C = matrices(c.machine.frame, self.local)
        s = c.layout.state.start("frame")
        self.q, self.qd, self.qdd = y[:, s : s + 3], y[:, s + 3 : s + 6], dy[:, s + 3 : s + 6]
        self.throws: list[tuple] = []

    def at_guide(self, throw: Throw, a: np.ndarray) -> dict[str, Signal]:
        """Throw ``throw``'s: the frame's motion at its guide along its stroke, and its
        accelerometer's reading (its crosshead's acceleration ``a`` + the frame's)."""
        from ..base import Signal
        from ..frame.body import at_guide

        fa = at_guide(throw, self.local, self.qdd)
        return {
            "frame_x": Signal(at_guide(throw, self.local, self.q), "m", "the frame's "
                              "displacement at this throw's guide along its stroke"),
            "frame_v": Signal(at_guide(throw, self.local, self.qd), "m/s", "the frame's "
                              "velocity at this throw's guide along its stroke"),
            "frame_a": Signal(fa, "m/s**2", "the frame's acceleration at this throw's guide "
                              "along its stroke"),
            "accel": Signal(a + fa, "m/s**2", "accelerometer on this throw's crosshead: its "
                            "acceleration a along the stroke + the frame's at its guide"),
        }  # fmt: skip

    def signals(self) -> dict[str, Signal]:
        """The frame's own: its energy, the mounts' force and moment on it, and the neglected
        feedback per sample (``frame_feedback``: the largest over the throws of
        ``(m1 + m2 + m3) |a_f|`` over the throw's largest shaking force along its stroke)."""
        from ..base import Signal
        from ..frame.body import FEEDBACK_LIMIT, energy

        mounts = -(self.q @ self.K.T + self.qd @ self.C.T)
        feedback = np.zeros(self.q.shape[0])
        for mass, fa, fx in self.throws:  # (each throw's moving mass, frame_a, shaking F_x)
            top = float(np.max(np.abs(fx)))
            if top > 0.0:
                feedback = np.maximum(feedback, mass * np.abs(fa) / top)
        return {
            "frame_energy": Signal(energy(self.M, self.K, self.q, self.qd), "J", "the frame's "
                                   "kinetic energy + its mounts' strain energy"),
            "frame_mount_force_x": Signal(mounts[:, 0], "N", "the mounts' force on the frame "
                                          "along x (springs and dampers)"),
            "frame_mount_moment": Signal(mounts[:, 2], "N*m", "the mounts' moment on the frame "
                                         "about the vertical axis through its centre of mass"),
            "frame_feedback": Signal(feedback, "", "the neglected feedback of the frame on the "
                                     "throws (one-way coupling): max over the throws of "
                                     "(m1+m2+m3)|frame_a| / max|its shaking force along x|"),
            "frame_coupling_margin": Signal(FEEDBACK_LIMIT - feedback, "", "the validity "
                                            "bound's margin: FEEDBACK_LIMIT - frame_feedback "
                                            "(< 0: the one-way coupling no longer holds)"),
        }  # fmt: skip


def _torsion_outputs(c: Configuration, y: np.ndarray, dy: np.ndarray,
                     obs: np.ndarray) -> dict[str, Signal]:  # fmt: skip
    """A flexible shaft's: each section's twist and torque (the observer's columns: the
    functions that were integrated), each throw's node's acceleration, the flywheel's, and
    (under ``_energy``, for the machine's) the rotor's, the flywheel's and the sections'
    energy."""
    from ..base import Signal
    from ..shaft.flexible import nodes, section_names

    m = c.machine
    st, ov, pv = c.layout.state, c.layout.outputs, c.layout.params
    o = pv.start("shaft.torsion")
    j_motor, j_fly = c.params[o], c.params[o + 1]
    fly = st[m.prefix("shaft") + "theta_flywheel"]
    energy = 0.5 * (j_motor * y[:, st["omega1"]] ** 2 + j_fly * y[:, fly + 1] ** 2)
    out: dict[str, Signal] = {}
    names = nodes(m)
    for i, q in enumerate(section_names(m)):
        twist, torque = obs[:, ov[q + "twist"]], obs[:, ov[q + "torque"]]
        energy = energy + 0.5 * c.params[o + 2 + 2 * i] * twist**2
        ends = f"between the {names[i]} and the {names[i + 1]}"
        out[q + "twist"] = Signal(twist, "rad", f"twist of the shaft {ends} (the first's angle "
                                  "less the second's)")  # fmt: skip
        out[q + "torque"] = Signal(torque, "N*m", f"torque the shaft carries {ends} (spring "
                                   "and damper)")  # fmt: skip
    out[m.prefix("shaft") + "alpha_flywheel"] = Signal(
        dy[:, fly + 1], "rad/s**2", "the flywheel's angular acceleration"
    )
    for t in m.throws:
        n = st[m.prefix(t.name) + "theta_shaft"]
        out[m.prefix(t.name) + "alpha_shaft"] = Signal(dy[:, n + 1], "rad/s**2", "angular "
                                                       "acceleration of this throw's crank "
                                                       "(its node of the shaft)")  # fmt: skip
    out["_energy"] = Signal(energy, "J", "")
    return out


def _interstage_outputs(c: Configuration, y: np.ndarray, dy: np.ndarray) -> dict[str, Signal]:
    """Per interstage volume: its pressure (a state), its gas's mass, and the mass flows its
    upstream stage delivers into it and its downstream stage takes from it (the cylinders'
    counters' rates: the flows that were integrated)."""
    st, pv = c.layout.state, c.layout.params
    counters = {t.name: st.start(f"{t.name}.load_aux") for t in c.machine.throws}
    gas = {i.name: tuple(c.params[pv[f"{i.name}.{k}"]]
                         for k in ("volume", "cooler_temperature", "gas_constant"))
           for i in c.machine.interstages}  # fmt: skip
    return _interstage_signals(c.machine, st, y, dy, counters, gas)


def _interstage_signals(machine: Machine, st: Any, y: np.ndarray, dy: np.ndarray,
                        counters: Mapping[str, int], gas: Mapping[str, tuple]
                        ) -> dict[str, Signal]:  # fmt: skip
    """The interstage signals of `_interstage_outputs`, from each throw's first mass counter's
    index (``counters``: suction head, discharge head, suction crank, discharge crank) and
    each volume's ``(volume, cooler temperature, gas constant)``."""
    from ..base import Signal

    out: dict[str, Signal] = {}
    for i in machine.interstages:
        pi = y[:, st[f"{i.name}.p"]]
        vol, temp, gas_r = gas[i.name]
        flows = {"in": np.zeros(y.shape[0]), "out": np.zeros(y.shape[0])}
        for t in machine.throws:
            a = counters[t.name]
            if t.stage == i.upstream:
                flows["in"] += dy[:, a + 1] + dy[:, a + 3]
            if t.stage == i.downstream:
                flows["out"] += dy[:, a] + dy[:, a + 2]
        out[f"{i.name}.p"] = Signal(pi, "Pa", f"interstage pressure: {i.upstream}'s discharge, "
                                    f"{i.downstream}'s suction (absolute)")  # fmt: skip
        out[f"{i.name}.mass"] = Signal(pi * vol / (gas_r * temp), "kg",
                                       "gas mass in the interstage volume")  # fmt: skip
        out[f"{i.name}.mdot_in"] = Signal(flows["in"], "kg/s", f"mass flow {i.upstream}'s "
                                          "discharge valves deliver into the volume")  # fmt: skip
        out[f"{i.name}.mdot_out"] = Signal(flows["out"], "kg/s", f"mass flow {i.downstream}'s "
                                           "suction valves take from the volume")  # fmt: skip
    return out


def _n_cycle() -> int:
    from ..cycle import N_CYCLE

    return N_CYCLE


# -- the compressor of one throw: the compressor's names and selectors ----------------------


_PLUGGED: dict[tuple[int, tuple], Schema] = {}


def _plugged_schema(base: Schema, chosen: tuple[tuple[str, str], ...]) -> Schema:
    """``base`` with the components ``(family, spec)`` from users' files: each spec one more
    choice of its family's parameter, each fragment appended (a name may belong to one
    component only). Remembered per base schema and choice."""
    key = (id(base), chosen)
    if key not in _PLUGGED:
        _PLUGGED[key] = _plug(base, chosen)
    return _PLUGGED[key]


def _plug(base: Schema, chosen: tuple[tuple[str, str], ...]) -> Schema:
    from ..components.contract import check_fragments, resolve_component
    from ..components.drive import MOTORS
    from ..components.load import LOADS

    builtin = {"load": LOADS, "motor": MOTORS}
    comps = [resolve_component(f, spec, builtin[f]) for f, spec in chosen]
    check_fragments(comps, base=base.params)
    specs = dict(chosen)
    params = tuple(replace(p, choices=(*p.choices, specs[p.name])) if p.name in specs else p
                   for p in base)  # fmt: skip
    return Schema(params + tuple(q for c in comps for q in c.params), aliases=base.aliases,
                  extras=base.extras)  # fmt: skip


class OneThrow(MachineModel):
    """The compressor of one throw with the massless link (or an ideal pin, rc = 0): the
    machine its selectors choose (module docstring)."""

    def __init__(self, name: str, description: str, schema: Schema, valves: bool = False,
                 instead: str = "the contact-impact joint (--model compressor-contact)"
                 ) -> None:  # fmt: skip
        self.valves = valves
        self.validity_bounds_instead = instead
        super().__init__(Machine(name=name, description=description), schema=schema)
        self.section_signals = (("theta_c", "rad"), ("thetadot_c", "rad/s"), ("x", "m"),
                                ("v", "m/s"), ("a", "m/s**2"))  # fmt: skip
        self.vibration_signal = ("a", "m/s**2")
        self.section_pair = ("v", "a")
        if valves:
            self.lyapunov_refusal = (
                "valve plates come to rest on their stops in resets with a singular saltation "
                "matrix (Benettin's QR is undefined there); use the signal estimators or "
                "--model compressor with load=cycle (ideal valves)"
            )
        # withheld ('invalid') when the run leaves the massless link's validity, valves too
        self.summary_verdicts = ("api618_pin_reversal",)

    def structure(self, values: Mapping[str, Any]) -> Machine:
        load = "valves" if self.valves else values.get("load", "paper")
        throw = Throw(load=load, equations=values.get("equations", "exact"))
        shaft = Shaft(drive=values.get("drive", "prescribed"),
                      motor=values.get("motor", "induction"))  # fmt: skip
        return _one_throw(self.machine.name, self.machine.description, throw, shaft)

    def system_name(self, values: Mapping[str, Any]) -> str:
        if self.valves:
            return self.name
        return f"compressor-{values.get('equations', 'exact')}"

    def system_attrs(self, values: Mapping[str, Any]) -> dict[str, Any]:
        return self.params(values).to_attrs()

    @classmethod
    def params(cls, values: Mapping[str, Any]) -> CompressorParams:
        """The [`CompressorParams`][recipdyn.model.parameters.CompressorParams] view of
        ``values`` (the values of components from a user's file left out)."""
        if values.get("load") is None and "valve_lift" in values:
            return cls.throw_params({**values, "load": "valves"})
        return CompressorParams(**{k: v for k, v in values.items() if k in _FIELDS})

    def lyapunov_supported(self, values: Mapping[str, Any]) -> bool:
        return not self.valves

    def schema_for(self, values: Mapping[str, Any]) -> Schema:
        """The compressor's schema, or with a load or a torque law from a user's module or
        file (``load = "file.py:OBJ"``) that component's fragment added."""
        chosen = tuple((f, absolute_spec(values[f])) for f in PLUGGABLE if is_spec(values.get(f)))
        return _plugged_schema(self.schema, chosen) if chosen else self.schema

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
        from ..components.contract import resolve_component

        self.params(values) if not self.valves else self.throw_params(
            {**values, "load": "valves"}
        )  # the ranges that depend on other parameters
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
        """Every model's record attributes, the axes and signs, the paper, the crank
        frequency, the initial clearance angle and how it was chosen, and what the parameter
        view adds (the load's description, its table, the list of assumptions)."""
        p = self.params(values)
        out = Model.record_attrs(self, values, y0)
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
        """The values a record holds, its load table included."""
        chosen = {f: attrs[f"param_{f}"] for f in PLUGGABLE if f"param_{f}" in attrs}
        values = self.schema_for(chosen).from_attrs(attrs)
        flat = attrs.get("param_load_table_deg_N")
        if flat is not None and "load_table" in self.schema.extras:
            rows = np.asarray(flat, dtype=float).reshape(-1, 2)
            values["load_table"] = tuple((float(a), float(b)) for a, b in rows)
        self.check(values)
        return values


@lru_cache(maxsize=64)
def _one_throw(name: str, description: str, throw: Throw, shaft: Shaft) -> Machine:
    return Machine(name=name, description=description, shaft=shaft, throws=(throw,))


#: ``--model compressor``'s massless link and ideal pin (`recipdyn.model.family`, route
#: ``link``): the paper's load, a table, the ideal cycle or a load of a user's file.
LINK = OneThrow(
    "compressor",
    "single-cylinder reciprocating compressor, massless-link clearance at the crank pin and "
    "crosshead subsidence (Xiao et al. 2017)",
    SCHEMA,
)


def _link_valves() -> OneThrow:
    """The same mechanism with the cylinder gas and dynamic plate valves as states (route
    ``link-valves``, the preset ``compressor-valves``), built when first asked for."""
    return OneThrow(
        "compressor-valves",
        "the compressor (massless-link clearance) driven by the compression cycle with dynamic "
        "plate valves: cylinder pressures and valves as states",
        _valves_schema(),
        valves=True,
        instead="the contact-impact joint with dynamic valves (--model compressor-contact-valves)",
    )


class OneContact(ContactMachine):
    """The compressor of one throw with contact-impact or lubricated pins or the guide's
    clearance, as ``--model compressor`` takes it (routes ``contact`` and ``contact-valves``
    of `recipdyn.model.family`; the presets ``compressor-contact``,
    ``compressor-contact-valves``, ``compressor-guide``): the machine of one contact throw
    its selectors choose (``crank_joint``, ``crosshead_joint``, ``guide``, ``load``,
    ``drive``, ``motor``), under the compressor's names, so every record, config and sweep
    store made before still runs with the same values.

    Its system is the assembler's (`.contact_throws.one_throw_configuration`: the throw's
    slice of the parameter vector and of the state, the kernels of its joints'
    configuration, template ``contact``); with one throw the template ``contact_throws``
    calls those kernels on the whole vector and adds nothing, so the machine's kernels are
    the throw's module itself (no second module to compile: tests/test_contact_throws.py
    checks a machine file of one throw through ``contact_throws`` against this, to the bit).
    What a throw's values mean (schema, checks, packing, states, signals, summary, events)
    is its joints' configuration part (`.contact_throws.joints_part`), as for every throw of
    a `ContactMachine`."""

    def __init__(self, valves: bool = False) -> None:
        from .contact_throws import joints_part

        part = joints_part(valves)
        self.part = part
        self.valves = valves
        self.machine = Machine(name=part.name, description=part.description)
        self.name, self.description, self.schema = part.name, part.description, part.schema
        for k in ("state_names", "state_units", "section_signals", "vibration_signal",
                  "section_pair", "summary_verdicts", "event_example", "mean_signals",
                  "max_signals", "lyapunov_refusal", "validity_bounds"):  # fmt: skip
            setattr(self, k, getattr(part, k))

    # the declarations are the part's (class values of the contact joints: no assembly)
    state_names = ()  # type: ignore[assignment]
    state_units = ()  # type: ignore[assignment]

    def structure(self, values: Mapping[str, Any]) -> Machine:
        """The machine of one throw at ``values`` (its pins, guide, load and drive)."""
        from ..components.contact_model import joint_types

        crank, cross = joint_types(values)
        load = "valves" if self.valves else values.get("load", "paper")
        throw = Throw(crank_joint=crank, crosshead_joint=cross,
                      guide=values.get("guide", "ideal"),
                      load=load if isinstance(load, str) else "paper")  # fmt: skip
        shaft = Shaft(drive=values.get("drive", "prescribed"),
                      motor=values.get("motor", "induction"))  # fmt: skip
        return _one_throw(self.name, self.description, throw, shaft)

    def contact(self, values: Mapping[str, Any]) -> ContactConfiguration:
        """The machine of one throw assembled at validated ``values``."""
        from .contact_throws import one_throw_configuration

        return one_throw_configuration(self.structure(values), values)

    def throws(self, values: Mapping[str, Any]) -> list[dict[str, Any]]:
        return [{**values, "phase": 0.0}]

    # -- the system: the assembler's ---------------------------------------------------
    def system(self, values: Mapping[str, Any]) -> AssembledSystem:
        """The assembled machine's parameter vector, state layout and kernels; the tangent
        space's declarations (auxiliary and passive states) the joints' configuration's."""
        from .system import AssembledSystem, Frozen

        c = self.contact(values)
        k = c.throw_module  # (one throw: the machine's kernels, class docstring)
        own = self.part.tangent(values)
        names, units = zip(*c.layout.state.named(), strict=True)
        return AssembledSystem(
            rhs=k.rhs,
            jac=k.jac,
            rhs_jac=own["rhs_jac"] and k.rhs_jac,
            params=c.params,
            state_names=names,
            state_units=units,
            period=own["period"],
            name=self.name,
            events=self.events(values),
            aux_states=own["aux_states"],
            aux=own["aux"],
            passive=own["passive"],
            model=self,
            values=Frozen(values),
        )

    def events(self, values: Mapping[str, Any]) -> tuple[Event, ...]:
        return self.part.events(values)

    def states(self, values: Mapping[str, Any]) -> tuple[tuple[str, str], ...]:
        return self.part.states(values)

    # -- what a throw's values mean: its joints' configuration part ---------------------
    def schema_for(self, values: Mapping[str, Any]) -> Schema:
        return self.part.schema_for(values)

    def parameters(self, values: Mapping[str, Any] | Any | None = None, **kw: Any
                   ) -> dict[str, Any]:  # fmt: skip
        return self.part.parameters(values, **kw)

    def check(self, values: Mapping[str, Any]) -> None:
        self.part.check(values)

    def period(self, values: Mapping[str, Any]) -> float:
        return self.part.period(values)

    def section_angle(self, values: Mapping[str, Any]) -> str | None:
        """None: the family (`recipdyn.model.family.Compressor.section_angle`) says where a
        one-throw record's section is taken, as before."""
        return None

    def validity_applies(self, values: Mapping[str, Any]) -> bool:
        """True (the protocol's default; the joints have no bounds of their own)."""
        return True

    def lyapunov_supported(self, values: Mapping[str, Any]) -> bool:
        return self.part.lyapunov_supported(values)

    def identity_values(self, values: Mapping[str, Any]) -> dict[str, Any]:
        return self.part.identity_values(values)

    def law_range(self, values: Mapping[str, Any], ds: Any) -> str:
        return self.part.law_range(values, ds)

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        return self.part.initial_state(values)

    def state_scale(self, values: Mapping[str, Any]) -> np.ndarray:
        return self.part.state_scale(values)

    def outputs(self, values: Mapping[str, Any], t: np.ndarray, y: np.ndarray
                ) -> dict[str, Signal]:  # fmt: skip
        return self.part.outputs(values, t, y)

    def run_summary(self, values: Mapping[str, Any], ds: Any) -> dict[str, Any]:
        return self.part.run_summary(values, ds)

    def record_attrs(self, values: Mapping[str, Any], y0: np.ndarray | None = None
                     ) -> dict[str, Any]:  # fmt: skip
        """The protocol's record attributes (`Model.record_attrs`: the joints' schema, not the
        machine's), with a table load's rows (``param_load_table_deg_N``: it has no schema
        row)."""
        out = Model.record_attrs(self, values, y0)
        if values.get("load_table") is not None:
            out["param_load_table_deg_N"] = [float(x) for row in values["load_table"] for x in row]
        return out

    def values_from_record(self, attrs: Mapping[str, Any]) -> dict[str, Any]:
        """`Model.values_from_record` (the joints' schema and checks), the table load's rows
        included."""
        values = Model.values_from_record(self, attrs)
        flat = attrs.get("param_load_table_deg_N")
        if flat is not None:
            rows = np.asarray(flat, dtype=float).reshape(-1, 2)
            values["load_table"] = tuple((float(a), float(b)) for a, b in rows)
        return values

    # -- what the joints' kernels offer beyond the protocol ---------------------------
    def kernels(self, values: Mapping[str, Any]):
        """The compiled kernels at validated ``values`` (the throw's module)."""
        return self.contact(values).throw_module

    def load_part(self, values: Mapping[str, Any]):
        return self.part.load_part(values)

    def tracks_separations(self, values: Mapping[str, Any]) -> bool:
        return self.part.tracks_separations(values)


#: The compressor of one throw by route (`recipdyn.model.family.route`: which machine the
#: selectors describe): every configuration of ``--model compressor`` is one of these.
ONE_THROW = {"link": "LINK", "link-valves": "LINK_VALVES", "contact": "CONTACT",
             "contact-valves": "CONTACT_VALVES"}  # fmt: skip


def one_throw(route: str) -> MachineModel:
    """The machine of one throw of route ``route`` (`ONE_THROW`; built when first asked
    for)."""
    name = ONE_THROW[route]
    return globals()[name] if name in globals() else __getattr__(name)


def __getattr__(name: str):
    if name == "VALVES_SCHEMA":
        return _valves_schema()
    if name in ("LINK_VALVES", "CONTACT", "CONTACT_VALVES"):
        globals()[name] = (_link_valves() if name == "LINK_VALVES"
                           else OneContact(valves=name == "CONTACT_VALVES"))  # fmt: skip
        return globals()[name]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def compressor_model(p: CompressorParams | None = None,
                     extra: Mapping[str, Any] | None = None) -> AssembledSystem:  # fmt: skip
    """The one-throw compressor's system for ``p`` (default: the paper's base case),
    assembled (`.assemble`); ``extra``: the parameter values of components from a user's
    file."""
    p = CompressorParams() if p is None else p
    if not isinstance(p, CompressorParams):
        raise ParameterError(f"expected CompressorParams, got {type(p).__name__}")
    values = {f.name: getattr(p, f.name) for f in dataclass_fields(CompressorParams)}
    return LINK.system(LINK.parameters({**values, **(extra or {})}))
