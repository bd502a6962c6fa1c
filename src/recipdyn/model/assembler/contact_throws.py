r"""Throws with contact-impact (or lubricated) pins or the guide's clearance: their family.

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

A throw's ``crosshead_joint`` and ``guide`` (structure keys of the machine's description)
choose the rest of its joints: a worn crosshead pin, the guide's clearance (the family's
whatever the crank pin); the loads ``paper``, ``cycle`` and ``valves``. Not yet (refused in
one line): a motor (the joints' share of a free crank's equation), a load of a user's file or
a table, a frame, an interstage volume, a throw on the other side of the shaft
(``cylinder_angle``), throws whose joints' configurations differ (`same_joints`), and throws
of different families in one machine (`recipdyn.model.assembler.assemble.family_of`).

The model of such a machine is `recipdyn.model.assembler.model.ContactMachine` (each throw's
signals and summary its one-throw model's, under its name); this module holds what it is
built from, and imports no model module (the one-throw models are the parts' classes,
`recipdyn.model.components.contact_model`, `.contact_valves_model`).
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

if TYPE_CHECKING:
    from ..protocol import Param

__all__ = ["ContactConfiguration", "assemble_contact", "contact_configuration",
           "contact_throw_params", "one_model", "refusal", "throw_contact_values", "joints_key",
           "same_joints", "LOADS"]  # fmt: skip

#: The loads a contact throw of a machine takes today.
LOADS = ("paper", "cycle", "valves")
#: The one-throw model's parameters a throw of a machine does not take: the shaft's, the
#: stage's, the structure (the throw's load, pins and guide: keys of its description), the
#: drive's.
_STRUCTURE = ("load", "drive", "motor", "equations", "clearance_joints", "joint", "crank_joint",
              "crosshead_joint", "guide", "rs", "m1", "J1")  # fmt: skip


def one_model(throw: Throw):
    """The one-throw model of a contact throw: ``compressor-contact``'s, or with the dynamic
    valves ``compressor-contact-valves``'s."""
    return _models()[throw.load == "valves"]


@lru_cache(maxsize=1)
def _models():
    """The contact model and the contact model with the dynamic valves (the parts' classes,
    one instance each: no model module imports another's, tests/test_layers.py)."""
    from ..components.contact_model import CompressorContact
    from ..components.contact_valves_model import CompressorContactValves

    return CompressorContact(), CompressorContactValves()


def contact_throw_params(throw: Throw) -> tuple[Param, ...]:
    """A contact throw's parameters under their local names (its one-throw model's,
    without the shaft's, the stage's and the structure's; the cycle's with ``load = cycle``
    or ``valves`` only, the paper load's with ``load = paper`` only), with its ``phase``."""
    from ..components.guide import GUIDE_PARAMS

    skip = {*SHAFT_NAMES, *STAGE_NAMES, *_STRUCTURE}
    if throw.guide != "clearance":
        skip |= {p.name for p in GUIDE_PARAMS}
    schema = one_model(throw).schema
    out = [p for p in schema if p.name not in skip and p.group != "drive"]
    if throw.crank_joint == "ideal":
        out = [p for p in out if p.name not in ("rc", "K", "journal_radius", "e0_angle")]
    if throw.crosshead_joint == "ideal":
        out = [
            p
            for p in out
            if p.name
            not in ("rc_crosshead", "K_crosshead", "crosshead_pin_radius", "e0_angle_crosshead")
        ]
    if throw.crank_joint == "ideal" and throw.crosshead_joint == "ideal":  # (the guide's only)
        out = [p for p in out if p.group != "joint" or p.name == "v_impact_min"]
    if throw.load == "paper":
        out = [p for p in out if p.group != "cycle" and p.name != "gas"]
    if throw.load != "paper":
        out = [p for p in out if p.name not in ("load_amplitude", "load_sign")]
    return (*out, PHASE)


def refusal(machine: Machine) -> str | None:
    """Why a machine of contact throws cannot be assembled yet (one line), or None."""
    where = f"machine {machine.name!r}"
    if machine.shaft.drive != "prescribed":
        return (
            f"{where}: drive = {machine.shaft.drive!r} with contact pins is not "
            "modelled yet (the joints' share of a free crank's equation); allowed: "
            "'prescribed', or one throw: --model compressor-contact --set drive=motor"
        )
    if machine.frame is not None:
        return (f"{where}: a [frame] with contact pins or the guide's clearance is not "
                "modelled yet; allowed: crank_joint = 'link' | 'ideal', ideal crosshead pins "
                "and guides")  # fmt: skip
    if machine.interstages:
        return (f"{where}: an [[interstage]] with contact pins or the guide's clearance is "
                "not modelled yet; allowed: crank_joint = 'link' | 'ideal', ideal crosshead "
                "pins and guides")  # fmt: skip
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
    if throw.crank_joint == "ideal":  # (`throw_values` gives the link's rc = 0 then)
        v.pop("rc", None)
    v.update(
        crank_joint=throw.crank_joint,
        crosshead_joint=throw.crosshead_joint,
        guide=throw.guide,
        drive="prescribed",
        theta1_0=float(local["theta1_0"]) + float(local["phase"]),
    )
    if "load" in names:
        v["load"] = throw.load
    try:
        return model.parameters(v)
    except ParameterError as exc:  # with the throw's namespace: ``throw2.rc = ...``
        raise ParameterError(f"{machine.prefix(throw.name)}{exc}") from None


def joints_key(throw: Throw, local: Mapping[str, Any]) -> tuple:
    """What chooses a contact throw's kernels module (`CompressorContact.kernels`): which
    pins are worn, the load, the guide, the contact law of a user's file, the friction laws;
    throws of one machine share it (`same_joints`)."""
    from ..components import contact_model as cm

    guide = cm.has_guide(local)
    shoes = cm.FRICTION_ROLES[local["guide_friction_law"]] if guide else ""
    part = one_model(throw).load_part(local)
    return (local["clearance_joints"], cm._load_key(local, part), guide, cm.law_spec(local),
            cm.friction_part(local), shoes)  # fmt: skip


def same_joints(machine: Machine, locals_: list[dict]) -> None:
    """Refuse, in one line, throws whose joints' configurations differ (`joints_key`)."""
    first = joints_key(machine.throws[0], locals_[0])
    for t, v in zip(machine.throws[1:], locals_[1:], strict=True):
        if joints_key(t, v) != first:
            raise ParameterError(
                f"{t.name}: its pins, guide, laws or load differ from "
                f"{machine.throws[0].name}'s (which pins are worn, the guide's clearance, "
                "friction_law, a contact law of a file, load): the throws of a machine share "
                "one configuration of the joints today (their values differ freely)"
            )


def assemble_contact(machine: Machine, locals_: list[dict]) -> ContactConfiguration:
    """Resolve a machine of contact throws: each throw's one-throw vector and state, one
    after another (module docstring)."""
    from ..components.contact_model import pack

    models = [one_model(t) for t in machine.throws]
    same_joints(machine, locals_)
    modules = [m.kernels(v) for m, v in zip(models, locals_, strict=True)]
    assert all(m is modules[0] for m in modules), "joints_key misses a choice of the module"
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
def contact_configuration(machine: Machine, items: tuple) -> ContactConfiguration:
    """The machine assembled at the validated values ``items`` (sorted pairs; remembered)."""
    from .assemble import throw_values

    values = dict(items)
    locals_ = [throw_contact_values(machine, t, throw_values(machine, values, k))
               for k, t in enumerate(machine.throws)]  # fmt: skip
    return assemble_contact(machine, locals_)
