r"""Throws whose crank pins are contact-impact (or lubricated) joints: their family of the machine.

A throw with ``crank_joint = contact | lubricated`` is one configuration of the contact joints
(`recipdyn.model.components.contact_model`, the model of ``--model compressor-contact``): its
parameters are that model's under the throw's name (``throw2.rc``, ``throw2.K``,
``throw2.friction``, ``throw2.phase``), its states the joints' twelve (`STATE_NAMES`, under
the throw's name), its kernels that configuration's generated module (template ``contact``).
`assemble_contact` places every throw's slice of the parameter vector and of the state one
after another (each slice the one-throw vector of that throw: its crank angle at ``t = 0`` is
the shaft's ``theta1_0`` plus its ``phase``) and writes the machine's module from the template
``contact_throws``, which calls each throw's compiled kernels on views of its slices: the
joints' compiled parts read a throw's slice as they read a one-throw model's vector, and are
compiled once for every machine that holds them.

With the crank prescribed the throws do not interact (each throw's motion is its crank's,
given): the right-hand side is the throws' side by side, the Jacobian block-diagonal, and a
machine of one throw is ``--model compressor-contact`` itself (the same module, the same
arithmetic, the same event; tests/test_contact_throws.py checks the records to the bit). With
several throws the event is the smallest of the throws' phased contact factors (onsets and
separations, `recipdyn.model.joints.pins.phased_factor`): the recorded approach velocity's
sign is then each pin's phase (negative in free flight).

Not yet (refused in one line): a motor (the joints' share of a free crank's equation), the
dynamic valves or a load of a user's file, a load table, the crosshead pin's clearance and the
guide's (per throw: ``crosshead_joint``, ``guide``), a frame, an interstage volume, a throw on
the other side of the shaft (``cylinder_angle``), and throws of different families in one
machine (`recipdyn.model.assembler.assemble.family_of`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import ParameterError
from ..machine.description import SHAFT_NAMES, STAGE_NAMES, Machine, Throw
from ..mechanism.link import PHASE
from .layout import Layout, SlicesBuilder
from .model import MachineModel, _prefixed_message

if TYPE_CHECKING:
    from ..base import Event, Signal
    from ..protocol import Param
    from .system import AssembledSystem

__all__ = ["ContactMachine", "ContactConfiguration", "assemble_contact", "contact_throw_params",
           "LOADS"]  # fmt: skip

#: The loads a contact throw of a machine takes today.
LOADS = ("paper", "cycle", "valves")
#: The one-throw model's parameters a throw of a machine does not take: the shaft's, the
#: stage's, the structure (the throw's load and pins: its ``crank_joint``), the crosshead
#: pin's and the guide's clearance (not yet), the drive's.
_STRUCTURE = ("load", "drive", "motor", "equations", "clearance_joints", "joint", "crank_joint",
              "crosshead_joint", "guide", "rs", "m1", "J1")  # fmt: skip


def one_model(throw: Throw):
    """The one-throw model of a contact throw: ``compressor-contact``, or with the dynamic
    valves ``compressor-contact-valves``."""
    if throw.load == "valves":
        from ..compressor_contact_valves import COMPRESSOR_CONTACT_VALVES

        return COMPRESSOR_CONTACT_VALVES
    from ..compressor_contact import COMPRESSOR_CONTACT

    return COMPRESSOR_CONTACT


def contact_throw_params(throw: Throw) -> tuple[Param, ...]:
    """A contact throw's parameters under their local names (its one-throw model's,
    without the shaft's, the stage's and the structure's; the cycle's with ``load = cycle``
    or ``valves`` only, the paper load's with ``load = paper`` only), with its ``phase``."""
    from ..components.guide import GUIDE_PARAMS

    skip = {*SHAFT_NAMES, *STAGE_NAMES, *_STRUCTURE, *(p.name for p in GUIDE_PARAMS)}
    schema = one_model(throw).schema
    out = [p for p in schema if p.name not in skip and p.group not in ("drive", "guide")]
    out = [p for p in out if p.name not in ("rc_crosshead", "K_crosshead",
                                            "crosshead_pin_radius", "e0_angle_crosshead")]
    if throw.load == "paper":
        out = [p for p in out if p.group != "cycle" and p.name != "gas"]
    if throw.load != "paper":
        out = [p for p in out if p.name not in ("load_amplitude", "load_sign")]
    return (*out, PHASE)


def refusal(machine: Machine) -> str | None:
    """Why a machine of contact throws cannot be assembled yet (one line), or None."""
    where = f"machine {machine.name!r}"
    if machine.shaft.drive != "prescribed":
        return (f"{where}: drive = {machine.shaft.drive!r} with contact crank pins is not "
                "modelled yet (the joints' share of a free crank's equation); allowed: "
                "'prescribed', or one throw: --model compressor-contact --set drive=motor")
    if machine.frame is not None:
        return (f"{where}: a [frame] with contact crank pins is not modelled yet; allowed: "
                "crank_joint = 'link' | 'ideal'")  # fmt: skip
    if machine.interstages:
        return (f"{where}: an [[interstage]] with contact crank pins is not modelled yet; "
                "allowed: crank_joint = 'link' | 'ideal'")  # fmt: skip
    for t in machine.throws:
        if t.load not in LOADS:
            return (f"{where}: {t.name}.load = {t.load!r} with crank_joint = "
                    f"{t.crank_joint!r} is not modelled yet on a machine; allowed: "
                    f"{', '.join(map(repr, LOADS))} (one throw: --model compressor-contact "
                    "or compressor-contact-valves)")  # fmt: skip
        if t.cylinder_angle:
            return (f"{where}: {t.name}.cylinder_angle = 180 deg with crank_joint = "
                    f"{t.crank_joint!r} is not modelled yet; allowed: 0")  # fmt: skip
    return None


@dataclass(frozen=True)
class ContactConfiguration:
    """A machine of contact throws resolved for its values (`assemble_contact`).

    Attributes
    ----------
    machine : Machine
    locals : tuple of dict
        Each throw's values as the one-throw contact model takes them (validated; its
        ``theta1_0`` the shaft's plus its phase).
    layout : Layout
        Each throw's slice of the state (part ``throwK.mechanism``) and of the parameter
        vector (part ``throwK``).
    params : ndarray
    throw_module : module
        The throws' kernels (the one-throw module, template ``contact``).
    """

    machine: Machine
    locals: tuple[dict, ...]
    layout: Layout
    params: np.ndarray
    throw_module: ModuleType

    def bindings(self) -> tuple[str, dict, dict, str, str]:
        """The machine module's template, roles, constants, stem and note."""
        from ..joints.pins import CFG

        st, pv = self.layout.state, self.layout.params
        throws = self.machine.throws

        def arr(values) -> np.ndarray:
            return np.array(list(values), dtype=np.int64)

        parts = [st.parts[f"{t.name}.mechanism"] for t in throws]
        slices = [pv.parts[t.name] for t in throws]
        mod = self.throw_module.__name__
        roles = {f"throw_{r}": (mod, r) for r in ("rhs", "jac", "event", "reset")}
        phased = one_model(throws[0]).tracks_separations(self.locals[0])
        constants = {
            "CFG": _literal(CFG[self.locals[0]["clearance_joints"]]),
            "N_THROWS": len(throws),
            "OWN_EVENT": len(throws) == 1 or phased,
            "THROW_N": arr(s.stop - s.start for s in parts),
            "THROW_NP": arr(s.stop - s.start for s in slices),
            "THROW_PARAMS": arr(s.start for s in slices),
            "THROW_STATE": arr(s.start for s in parts),
        }
        stem = f"{self.locals[0]['clearance_joints']}_{len(throws)}"
        return "contact_throws", roles, constants, stem, ""

    @property
    def kernels(self) -> ModuleType:
        mod = self.__dict__.get("_kernels")
        if mod is None:
            from . import generate

            mod = generate.module(*self.bindings())
            object.__setattr__(self, "_kernels", mod)
        return mod


def _literal(k: int):
    from .generate import Literal

    return Literal(k)


def throw_contact_values(machine: Machine, throw: Throw, local: Mapping[str, Any]
                         ) -> dict[str, Any]:  # fmt: skip
    """A throw's values as the one-throw contact model takes them (validated there, refused
    with the throw's namespace): its own and the shaft's, its pins, its crank angle at ``t =
    0`` the shaft's plus its phase."""
    model = one_model(throw)
    names = set(model.schema.names)
    v = {k: val for k, val in local.items() if k in names}
    v.update(crank_joint=throw.crank_joint, crosshead_joint="ideal", guide="ideal",
             drive="prescribed", theta1_0=float(local["theta1_0"]) + float(local["phase"]))
    if "load" in names:
        v["load"] = throw.load
    try:
        return model.parameters(v)
    except ParameterError as exc:
        raise _prefixed_message(machine.prefix(throw.name), exc) from None


def assemble_contact(machine: Machine, locals_: list[dict]) -> ContactConfiguration:
    """Resolve a machine of contact throws: each throw's one-throw vector and state, one
    after another (module docstring)."""
    from ..components.contact_model import pack

    models = [one_model(t) for t in machine.throws]
    modules = [m.kernels(v) for m, v in zip(models, locals_, strict=True)]
    for t, m in zip(machine.throws[1:], modules[1:], strict=True):
        if m is not modules[0]:
            raise ParameterError(
                f"{t.name}: its pins' laws or load differ from {machine.throws[0].name}'s "
                "(contact_law, friction_law or load): the throws of a machine share one "
                "configuration of the joints today (their values differ freely)"
            )
    pv, sv = SlicesBuilder(), SlicesBuilder()
    chunks = []
    for t, v, model in zip(machine.throws, locals_, models, strict=True):
        vec = pack(v, model.load_part(v))
        chunks.append(vec)
        pv.reserve(t.name, vec.size)
        pre = machine.prefix(t.name)
        sv.add(f"{t.name}.mechanism", ((pre + n, u) for n, u in model.states(v)))
    layout = Layout(sv.build(), pv.build(), SlicesBuilder().build())
    return ContactConfiguration(machine, tuple(locals_), layout, np.concatenate(chunks),
                                modules[0])  # fmt: skip


@lru_cache(maxsize=32)
def _configuration(machine: Machine, items: tuple) -> ContactConfiguration:
    values = dict(items)
    locals_ = [throw_contact_values(machine, t, v) for t, v in
               zip(machine.throws, ContactMachine.throws_of(machine, values), strict=True)]
    return assemble_contact(machine, locals_)


class ContactMachine(MachineModel):
    """A machine whose throws have contact-impact or lubricated crank pins (module
    docstring): `MachineModel` builds one for such a machine."""

    validity_bounds = ()

    def __init__(self, machine: Machine, schema=None) -> None:
        why = refusal(machine)
        if why is not None:
            raise ParameterError(why)
        super().__init__(machine, schema)
        self.description = machine.description or (
            f"{len(machine.throws)} throws on one crankshaft (prescribed drive), contact-impact "
            "crank pins"
        )
        pre = [machine.prefix(t.name) for t in machine.throws]
        self.section_signals = tuple((f"{q}{s}", u) for q in pre for s, u in (
            ("ex", "m"), ("ey", "m"), ("x", "m"), ("v", "m/s"), ("a", "m/s**2")))  # fmt: skip
        self.validity_bounds = ()
        self.summary_verdicts = tuple(f"{q}api618_pin_reversal" for q in pre)
        self.mean_signals = tuple((f"{q}contact", f"{q}contact_fraction", "1") for q in pre)
        self.max_signals = tuple((f"{q}eccentricity_ratio", f"{q}max_eccentricity_ratio", "1")
                                 for q in pre)  # fmt: skip
        self.event_example = {"shaft.omega" if not machine.flat else "omega": 150.0,
                              **{f"{q}load_amplitude": 2e4 for q, t in
                                 zip(pre, machine.throws, strict=True) if t.load == "paper"}}
        if len(machine.throws) > 1:
            self.lyapunov_refusal = (
                "the recorded approach velocities of all but the last throw sit among the "
                "degrees of freedom of a machine of several contact throws (Benettin's method "
                "would count them); one throw: --model compressor-contact"
            )

    @staticmethod
    def throws_of(machine: Machine, values: Mapping[str, Any]) -> list[dict[str, Any]]:
        from .assemble import throw_values

        return [throw_values(machine, values, k) for k in range(len(machine.throws))]

    def contact(self, values: Mapping[str, Any]) -> ContactConfiguration:
        """The machine resolved at validated ``values`` (remembered per values)."""
        items = tuple(sorted(values.items()))
        return _configuration(self.structure(values), items)

    def contact_values(self, values: Mapping[str, Any]) -> list[dict[str, Any]]:
        """Each throw's values as the one-throw contact model takes them."""
        return list(self.contact(values).locals)

    # -- what MachineModel does for the massless link ----------------------------------
    def check(self, values: Mapping[str, Any]) -> None:
        machine = self.structure(values)
        for t, v in zip(machine.throws, self.throws_of(machine, values), strict=True):
            throw_contact_values(machine, t, v)

    def has_dynamics(self, values: Mapping[str, Any]) -> bool:
        return True

    def validity_applies(self, values: Mapping[str, Any]) -> bool:
        return False

    def lyapunov_supported(self, values: Mapping[str, Any]) -> bool:
        machine = self.structure(values)
        if len(machine.throws) > 1:
            return False
        return one_model(machine.throws[0]).lyapunov_supported(self.contact_values(values)[0])

    def states(self, values: Mapping[str, Any]) -> tuple[tuple[str, str], ...]:
        return self.contact(values).layout.state.named()

    def events(self, values: Mapping[str, Any]) -> tuple[Event, ...]:
        from ..base import Event

        c = self.contact(values)
        k = c.kernels
        if len(c.locals) == 1:  # the one-throw model's event, on the machine's module
            (own,) = one_model(c.machine.throws[0]).events(c.locals[0])
            return (Event(own.name, k.event, direction=own.direction, action=own.action,
                          reset=k.reset, description=own.description),)  # fmt: skip
        return (Event("impact", k.event, direction=-1, action="reset", reset=k.reset,
                      description="contact onset or separation at a throw's worn crank pin "
                      "(the smallest of the throws' phased factors falls through 0): at an "
                      "onset the approach velocity is recorded for the damping law"),)  # fmt: skip

    def system(self, values: Mapping[str, Any]) -> AssembledSystem:
        from ..joints.pins import I_WIN, I_WLOSS, RIGID
        from .system import AssembledSystem, Frozen

        c = self.contact(values)
        st = c.layout.state
        passive = []
        for t, v in zip(c.machine.throws, c.locals, strict=True):
            s = st.start(f"{t.name}.mechanism")
            passive += [s + i for i in (*RIGID[v["clearance_joints"]], I_WIN, I_WLOSS)]
        own = one_model(c.machine.throws[0]).system(c.locals[0])  # (its auxiliary states)
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
            aux_states=own.aux_states,
            passive=tuple(sorted(passive)),
            model=self,
            values=Frozen(values),
        )

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        """Each throw's one-throw initial state (the pin along its rod load at its own crank
        angle, `CompressorContact.initial_state`); with several throws each recorded approach
        velocity carries its pin's phase (+ in contact, - in free flight)."""
        c = self.contact(values)
        parts = []
        for t, v in zip(c.machine.throws, c.locals, strict=True):
            model = one_model(t)
            y = model.initial_state(v)
            if len(c.locals) > 1 and not model.tracks_separations(v):
                sign = 1.0 if v["e0_ratio"] >= 1.0 else -1.0
                y[8] = y[9] = sign * v["v_impact_min"]
            parts.append(y)
        return np.concatenate(parts)

    def state_scale(self, values: Mapping[str, Any]) -> np.ndarray:
        """Each throw's one-throw scales (the gas states at their own size)."""
        c = self.contact(values)
        return np.concatenate([one_model(t).state_scale(v)
                               for t, v in zip(c.machine.throws, c.locals, strict=True)])

    def outputs(self, values: Mapping[str, Any], t: np.ndarray, y: np.ndarray
                ) -> dict[str, Signal]:  # fmt: skip
        """Each throw's signals, the one-throw contact model's of its states (its crank angle
        its own: the shaft's plus its phase), under its name; the shaft's crank angle."""
        from ..base import Signal

        c = self.contact(values)
        y = np.asarray(y, dtype=np.float64)
        out: dict[str, Signal] = {}
        for th, v in zip(c.machine.throws, c.locals, strict=True):
            part = c.layout.state.parts[f"{th.name}.mechanism"]
            own = one_model(th).outputs(v, t, np.ascontiguousarray(y[:, part]))
            pre = c.machine.prefix(th.name)
            out.update({pre + k: s for k, s in own.items()})
        if not c.machine.flat:
            w = float(self._shaft(values, "omega"))
            th1 = float(self._shaft(values, "theta1_0")) + w * np.asarray(t, dtype=np.float64)
            out["theta1"] = Signal(th1, "rad", "crank angle of the shaft")
        return out

    def run_summary(self, values: Mapping[str, Any], ds: Any) -> dict[str, Any]:
        """Each throw's figures (`CompressorContact.run_summary` of its signals and of the
        events at which its own pin changed phase), under its name."""
        c = self.contact(values)
        if c.machine.flat:
            return one_model(c.machine.throws[0]).run_summary(c.locals[0], ds)
        out: dict[str, Any] = {}
        for th, v in zip(c.machine.throws, c.locals, strict=True):
            pre = f"{th.name}."
            ev = f"impact_{pre}"
            rename = {"impact_time": "impact_time"} if "impact_time" in ds.data_vars else {}
            for k in map(str, ds.data_vars):
                if k.startswith(pre):
                    rename[k] = k[len(pre) :]
                elif k.startswith(ev):
                    rename[k] = "impact_" + k[len(ev) :]
            view = ds[list(rename)].rename(rename).assign_attrs(ds.attrs)
            if "impact_time" in view:  # its own events: where its reset moved its states
                names = [n for n, _ in one_model(th).states(v)]
                moved = np.column_stack([view[f"impact_{n}"].values
                                         != view[f"impact_{n}_after"].values for n in names])
                view = view.isel(impact_event=np.flatnonzero(moved.any(axis=1)))
            for k, val in one_model(th).run_summary(v, view).items():
                out[pre + k] = val
        return out
