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

With a motor (``drive = motor``) each throw is its joints' configuration with the crank free
(``--model compressor-contact --set drive=motor``): its slice of the state ends with its own
crank's angle (the shaft's plus its phase), the crank's speed and a work integral. A machine
of one throw is that model itself. With several, each throw's slice holds its own crank's
inertia and static moment (``J1 + m1 rs^2``, ``m1 rs``: its values ``J_drive`` 0) and the
machine's the drive's (``J_drive``, the torque law's; part ``shaft``): the template's
``_shaft`` turns the crank at ``(T_m + sum_k tau_k) / (J_drive + sum_k I_k)`` from each
throw's torque on its crank, which a worn crank pin's force (a function of the states) gives,
and corrects each throw's crank-pin eccentricity to it (template ``contact_throws``). Each
throw's work integral there (``throwK.W_crank``) is the shaft's work on its crank, and the
motor's is the machine's last state, ``W_motor``. A throw with an ideal crank pin (a worn
crosshead pin or the guide's clearance only) takes a share of the crank's inertia too (its rod
turns with the crank: the Schur complement of its mass matrix,
`recipdyn.model.joints.pins.ideal_share`).

A throw's ``crosshead_joint`` and ``guide`` (structure keys of the machine's description)
choose the rest of its joints: a worn crosshead pin, the guide's clearance (the family's
whatever the crank pin); the loads ``paper``, ``cycle`` and ``valves``. A held rotor
(``motor = held``, a rigid shaft) turns the crank at alpha = 0, each throw's module on a
constant torque of 0 (`throw_law`). A throw on the other side of the shaft (``cylinder_angle``
180 deg) runs in its own axes with its ``g`` negated (`_validated`).

Throws with ideal pins (``crank_joint = ideal``, the massless link's family) join such a
machine as a throw of another kind (`is_contact` false): each one is its one-throw model of the
massless link at rc = 0 (given by the caller, ``link(throw)``: ``--model compressor`` or
``compressor-valves``), its values `throw_link_values`, its slices that model's vector and
state, its kernels that model's generated module, which the template calls on the throw's
views by its kind (``THROW_KIND``; docs/architecture.md, "A throw of another kind").

Interstage volumes (``[[interstage]]``, `recipdyn.model.components.interstage`): each volume's
slice (its volume, cooler's temperature and gas constant) and its pressure (a state,
``interstage1.p``) follow the throws' (and the drive's and the frame's); the template writes
again the load's derivatives of each throw joined to one between the volume's line and its
own slice's other line, and the volume's pressure rate from its stages' counters (template
``contact_throws``). A fed stage's throws take the interstage's values as their suction
line's (`.assemble.throw_values`), which their slices keep (unread by the template).

On a flexible shaft (``[shaft.torsion]``, a motor) each throw's crank is its node: its module
turns it on a torque of 0 (`throw_law`), the rotor's and flywheel's angles and speeds follow
the throws' slices (part ``shaft.nodes``), the sections' slice and the nodes' phases are in
the parameter vector (``shaft.torsion``, ``shaft.phases``), and the template's ``_torsion``
gives each node its sections' torques.

Not yet (refused in one line, `refusal`): a flexible shaft under a held rotor, a load of a
user's file or a table, the guide's clearance on a frame or with an interstage, contact
throws whose joints' configurations differ (`same_joints`), and the massless link (rc > 0)
beside contact throws.

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
from ..machine.description import SHAFT_NAMES, STAGE_NAMES, Machine, Shaft, Throw
from ..mechanism.link import PHASE
from .layout import Layout, SlicesBuilder

if TYPE_CHECKING:
    from ..protocol import Param

__all__ = ["ContactConfiguration", "assemble_contact", "contact_configuration",
           "contact_throw_params", "one_model", "joints_part", "one_throw_configuration",
           "refusal", "throw_contact_values", "joints_key", "same_joints", "LOADS"]  # fmt: skip

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


def joints_part(valves: bool = False):
    """The joints' configuration part of a contact throw (its schema, checks, packing,
    states, kernels module, signals and summary): with the dynamic valves or without."""
    return _models()[bool(valves)]


@lru_cache(maxsize=1)
def _models():
    """The contact model and the contact model with the dynamic valves (the parts' classes,
    one instance each: no model module imports another's, tests/test_layers.py)."""
    from ..components.contact_model import ContactJoints
    from ..components.contact_valves_model import ContactJointsValves

    return ContactJoints(), ContactJointsValves()


#: A free crank's own parameters (its mass, centroid and inertia), a throw's with a motor.
_CRANK = ("rs", "m1", "J1")


def contact_throw_params(throw: Throw, shaft: Shaft | None = None, frame: bool = False
                         ) -> tuple[Param, ...]:  # fmt: skip
    """A contact throw's parameters under their local names (its one-throw model's,
    without the shaft's, the stage's and the structure's; the cycle's with ``load = cycle``
    or ``valves`` only, the paper load's with ``load = paper`` only; with a motor its
    crank's ``rs``, ``m1``, ``J1``; on a ``frame`` its crank's ``rs``, ``m1``: its rotating
    unbalance shakes the frame), with its ``phase``."""
    from ..components.guide import GUIDE_PARAMS

    motor = shaft is not None and shaft.drive == "motor"
    crank = _CRANK if motor else (("rs", "m1") if frame else ())
    skip = {*SHAFT_NAMES, *STAGE_NAMES, *(n for n in _STRUCTURE if n not in crank)}
    if throw.guide != "clearance":
        skip |= {p.name for p in GUIDE_PARAMS}
    schema = one_model(throw).schema
    out = [p for p in schema if p.name not in skip and (p.group != "drive" or p.name in crank)]
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
    if shaft is not None and shaft.torsion:  # the crankshaft section that ends at its crank
        from ..shaft.flexible import THROW_PARAMS

        out += THROW_PARAMS
    return (*out, PHASE)


def is_contact(throw: Throw) -> bool:
    """Whether a throw is one of the contact joints' (a worn pin or the guide's clearance),
    not an ideal throw of the massless link's family (`.assemble.throw_family`)."""
    from .assemble import throw_family

    return throw_family(throw) == "contact"


def refusal(machine: Machine) -> str | None:
    """Why a machine of contact throws cannot be assembled yet (one line), or None."""
    where = f"machine {machine.name!r}"
    if machine.shaft.torsion and machine.shaft.motor == "held":
        return (f"{where}: a [shaft.torsion] under a held rotor (motor = 'held') with contact "
                "pins or the guide's clearance is not modelled yet; allowed: a motor with a "
                "torque law ('induction', ...), or a rigid shaft")  # fmt: skip
    if machine.frame is not None:
        for t in machine.throws:
            if t.guide == "clearance":
                return (f"{where}: a [frame] with {t.name}.guide = 'clearance' is not modelled "
                        "yet; allowed on a frame: ideal guides (guide = 'ideal')")  # fmt: skip
    if machine.interstages:
        for t in machine.throws:
            if t.guide == "clearance":
                return (f"{where}: an [[interstage]] with {t.name}.guide = 'clearance' is not "
                        "modelled yet; allowed with an interstage: ideal guides (guide = "
                        "'ideal')")  # fmt: skip
    for t in machine.throws:
        if not is_contact(t) and t.crank_joint != "ideal":
            return (f"{where}: {t.name}.crank_joint = {t.crank_joint!r} (the massless link) "
                    "beside throws with contact pins or the guide's clearance is not modelled "
                    "yet; allowed there: 'ideal', 'contact', 'lubricated'")  # fmt: skip
        if t.load not in LOADS:
            return (f"{where}: {t.name}.load = {t.load!r} with crank_joint = "
                    f"{t.crank_joint!r} is not modelled yet on a machine; allowed: "
                    f"{', '.join(map(repr, LOADS))} (one throw: --model compressor-contact "
                    "or compressor-contact-valves)")  # fmt: skip
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
        The contact throws' kernels (the one-throw module, template ``contact``).
    link_module : module or None
        The ideal throws' kernels (the one-throw module of the massless link with rc = 0,
        template ``prescribed`` or ``motor``), None without ideal throws.
    """

    machine: Machine
    locals: tuple[dict, ...]
    layout: Layout
    params: np.ndarray
    throw_module: ModuleType
    link_module: ModuleType | None = None
    link_events: bool = False

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
        absent = ("recipdyn.model.assembler.generate", "absent")
        roles["torque"] = absent
        motor = self.machine.shaft.drive == "motor"
        if motor:  # (a held rotor: its throws' modules turn on a torque of 0, `throw_law`)
            law = throw_law(self.machine)
            roles["torque"] = (law.module, law.kernel("torque"))
        link = self.link_module
        frame = self.machine.frame is not None
        stages = bool(self.machine.interstages)
        for r in ("rhs", "jac", "event", "reset", "share", "crank"):
            on = link is not None and (r != "share" or shared(self.machine))
            if r == "crank":  # (an ideal throw's crank angle on a frame or an interstage's
                # line, the crank prescribed)
                on = link is not None and (frame or stages) and not motor
            roles[f"link_{r}"] = (link.__name__, r) if on else absent
        roles.update(_interstage_roles(self.machine))
        torsion = bool(self.machine.shaft.torsion)
        roles["motor_torque"] = absent
        if torsion:  # the rotor's torque law (each throw's module turns on a torque of 0)
            from .assemble import motor_of

            law = motor_of(self.machine)
            roles["motor_torque"] = (law.module, law.kernel("torque"))
        kinds = [0 if is_contact(t) else 1 for t in throws]
        first = kinds.index(0)  # (a contact throw: the machine's family)
        phased = one_model(throws[first]).tracks_separations(self.locals[first])
        m = self.throw_module
        crank = {0: int(m.M), 1: int(getattr(link, "CRANK", 0))}
        torque_at = {0: int(m.MO), 1: int(getattr(link, "MOTOR", 0))}
        end = slices[-1].stop
        names = [i.name for i in self.machine.interstages]

        def index(found) -> int:
            return -1 if found is None else names.index(found.name)

        def arr1(values) -> np.ndarray:  # (an empty array holds one unused -1)
            return np.array(list(values) or [-1], dtype=np.int64)

        def load_at(mod, g, a, o) -> np.ndarray:
            return arr([int(g), int(a), int(o)]) if mod is not None else arr([0, 0, 0])

        constants = {
            "CFG": _literal(CFG[self.locals[first]["clearance_joints"]]),
            "CONTACT_LOAD": load_at(m, getattr(m, "G", 0), getattr(m, "A", 0), getattr(m, "LO", 0)),
            "INTERSTAGE": stages,
            "IS_PARAM": arr1(pv.start(n) for n in names),
            "IS_STATE": arr1(st[f"{n}.p"] for n in names),
            "LINK_LOAD": load_at(
                link, *(getattr(link, k, [0])[0] for k in ("LOAD_STATE", "LOAD_AUX", "THROW_LOAD"))
            ),
            "N_INTERSTAGES": len(names),
            **_torsion_constants(self.machine, self.layout, crank, kinds),
            "THROW_IN": arr1(index(self.machine.interstage_into(t.stage)) for t in throws),
            "THROW_OUT": arr1(index(self.machine.interstage_from(t.stage)) for t in throws),
            "FRAME": frame,
            "FRAME_CRANKS": pv.start("frame.cranks") if frame else 0,
            "FRAME_PARAMS": pv.start("frame") if frame else 0,
            "FRAME_STATE": st.start("frame") if frame else 0,
            "FRAME_WORK": st.start("frame.work") if frame else 0,
            "HAS_GUIDE": self.locals[first].get("guide", "ideal") == "clearance",
            "HAS_LINK": link is not None,
            "HELD": held(self.machine),
            "LINK_EVENTS": self.link_events,
            "LINK_MECH": int(link.THROW_MECH[0]) if link is not None else 0,
            "LINK_PHASE": int(link.THROW_PHASE[0]) if link is not None else 0,
            "LINK_SHAFT": int(getattr(link, "SHAFT", 0)),
            "MOTOR": motor,
            "N_THROWS": len(throws),
            "OWN_EVENT": len(throws) == 1 or phased,
            "SCALE": pv.start("jacobian") if "jacobian" in pv.parts else end,
            "SHAFT": end,
            "SHARED": shared(self.machine),
            "THROW_CO": int(m.CO),
            "THROW_CRANK": arr(crank[k] for k in kinds),
            "THROW_KIND": arr(kinds),
            "THROW_N": arr(s.stop - s.start for s in parts),
            "THROW_NP": arr(s.stop - s.start for s in slices),
            "THROW_PARAMS": arr(s.start for s in slices),
            "THROW_STATE": arr(s.start for s in parts),
            "THROW_TORQUE": arr(torque_at[k] for k in kinds),
            "W_MOTOR": st.start("shaft.work") if "shaft.work" in st.parts else parts[-1].stop,
        }
        stem = f"{self.locals[first]['clearance_joints']}_{len(throws)}"
        if link is not None:
            stem += f"_ideal{kinds.count(1)}"
        if motor:
            stem += f"_motor_{self.machine.shaft.motor}".replace("-", "_")
        if frame:
            stem += "_frame"
        if stages:
            stem += f"_is{len(names)}"
        if torsion:
            stem += "_torsion"
        return "contact_throws", roles, constants, stem, ""

    @property
    def kernels(self) -> ModuleType:
        mod = self.__dict__.get("_kernels")
        if mod is None:
            from . import generate

            mod = generate.module(*self.bindings())
            object.__setattr__(self, "_kernels", mod)
        return mod


def _torsion_constants(machine: Machine, layout: Layout, crank: Mapping[int, int],
                       kinds: list[int]) -> dict[str, Any]:  # fmt: skip
    """``TORSION``, the nodes' angles' states (the rotor's and flywheel's in the shaft's part,
    then each throw's crank along the shaft, `recipdyn.model.shaft.flexible.order`), the
    throw at each node, the slices of the sections and of the nodes' phases, the state of the
    sections' dissipation (template ``contact_throws``)."""
    st, pv = layout.state, layout.params
    if not machine.shaft.torsion:
        return {"TORSION": False, "N_NODES": 1, "NODE_ANGLE": np.zeros(1, dtype=np.int64),
                "NODE_PHASES": 0, "NODE_THROW": np.full(1, -1, dtype=np.int64),
                "SHAFT_DAMPING": 0, "TORSION_PARAMS": 0}  # fmt: skip
    from ..shaft.flexible import order

    along = order(machine)
    nodes = st.start("shaft.nodes")
    angles = [nodes, nodes + 2, *(st.start(f"{machine.throws[k].name}.mechanism")
                                  + crank[kinds[k]] for k in along)]  # fmt: skip
    return {"TORSION": True, "N_NODES": len(angles),
            "NODE_ANGLE": np.array(angles, dtype=np.int64),
            "NODE_PHASES": pv.start("shaft.phases"),
            "NODE_THROW": np.array([-1, -1, *along], dtype=np.int64),
            "SHAFT_DAMPING": st.start("shaft.work") + 1,
            "TORSION_PARAMS": pv.start("shaft.torsion")}  # fmt: skip


def _interstage_roles(machine: Machine) -> dict[str, tuple[str, str]]:
    """The roles of the interstage volumes and of the loads between their lines (the dynamic
    valves': `.assemble.load_of`), absent without an interstage."""
    from ..components.interstage import INTERSTAGE
    from ..components.load import VALVES

    names = ("load_rhs_lines", "load_lines", "load_flows", "interstage_line", "interstage_rate")
    if not machine.interstages:
        return dict.fromkeys(names, ("recipdyn.model.assembler.generate", "absent"))
    return {"load_rhs_lines": (VALVES.module, VALVES.kernel("state_rhs_lines")),
            "load_lines": (VALVES.module, VALVES.kernel("lines")),
            "load_flows": (VALVES.module, VALVES.kernel("flows")),
            "interstage_line": (INTERSTAGE.module, INTERSTAGE.kernel("line")),
            "interstage_rate": (INTERSTAGE.module, INTERSTAGE.kernel("rate"))}  # fmt: skip


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
        drive=machine.shaft.drive,
        theta1_0=float(local["theta1_0"]) + float(local["phase"]),
    )
    if machine.shaft.drive == "motor":
        v["motor"] = machine.shaft.motor
        if shared(machine):  # its own crank; the drive's inertia is the machine's
            v["J_drive"] = 0.0
        if held(machine) or machine.shaft.torsion:  # (its node's torques: the template's)
            v.update(motor=throw_law(machine).name, motor_torque=0.0)
    if "load" in names:
        v["load"] = throw.load
    out = _validated(machine, throw, model, v)
    worn = throw.crank_joint != "ideal"  # (an ideal crank pin's rod turns with its crank)
    if shared(machine) and worn and not out["J1"] + out["m1"] * out["rs"] ** 2 > 0.0:
        raise ParameterError(
            f"{machine.prefix(throw.name)}J1 + m1 rs**2 = 0 kg*m**2 is out of range with "
            "drive = 'motor' and several throws; allowed: > 0 (a worn crank pin's crank turns "
            "apart from its rod: its own inertia)"
        )
    return out


def shared(machine: Machine) -> bool:
    """Whether the throws share a free crank's acceleration (a motor and several throws, or
    a held rotor: the template turns the crank, each throw's module its own crank alone)."""
    return machine.shaft.drive == "motor" and (len(machine.throws) > 1 or held(machine)
                                               or bool(machine.shaft.torsion))  # fmt: skip


def held(machine: Machine) -> bool:
    """Whether the motor is a held rotor (on a rigid shaft: its torque holds the speed)."""
    return machine.shaft.drive == "motor" and machine.shaft.motor == "held"


def throw_law(machine: Machine):
    """The torque law of each throw's module on a motor: the motor's, or under a held rotor
    (which has no torque law: its torque is the one that holds the speed) the constant
    torque's, at 0 (`throw_contact_values`): each module then gives its crank's acceleration
    under its own joint's and load's torque alone, which is what the template needs."""
    from ..components.drive import CONSTANT_TORQUE
    from .assemble import motor_of

    return CONSTANT_TORQUE if held(machine) or machine.shaft.torsion else motor_of(machine)


#: A free crank's state names in a throw's one-throw state, then in its slice of a machine's
#: of several throws (its crank angle, the crank's speed, the shaft's work on its crank).
_CRANK_STATES = {"theta1": "theta1", "omega1": "omega1", "W_motor": "W_crank"}


def fd_scales(local: Mapping[str, Any], n: int) -> np.ndarray:
    """A throw's difference-step scales, its one-throw module's (template ``contact``,
    ``_fd_columns``): its clearance for the eccentricities, the clearance times the speed for
    the rates, 1 J for the work integrals, 0.1 for the guide's lateral position, tilt and
    corners, 1e-3 for the rest (``n`` states)."""
    from ..components.contact_model import has_guide
    from ..joints.pins import G_GUIDE

    guide = has_guide(local)
    joints = local["clearance_joints"]
    rc, rc2 = float(local["rc"]), float(local["rc_crosshead"])
    c = min(rc, rc2) if guide or joints == "both" else (rc if joints == "crank" else rc2)
    out = np.full(n, 1e-3)
    out[:4] = c
    out[4:10] = c * float(local["omega"])
    out[10:12] = 1.0
    if guide:
        g = G_GUIDE
        out[g : g + 2] = 0.1
        out[g + 4 : g + 8] = 0.1
    return out


def joints_key(throw: Throw, local: Mapping[str, Any]) -> tuple:
    """What chooses a contact throw's kernels module (`ContactJoints.kernels`): which
    pins are worn, the load, the guide, the contact law of a user's file, the friction laws;
    throws of one machine share it (`same_joints`)."""
    from ..components import contact_model as cm

    guide = cm.has_guide(local)
    shoes = cm.FRICTION_ROLES[local["guide_friction_law"]] if guide else ""
    part = one_model(throw).load_part(local)
    return (local["clearance_joints"], cm._load_key(local, part), guide, cm.law_spec(local),
            cm.friction_part(local), shoes)  # fmt: skip


def same_joints(machine: Machine, locals_: list[dict]) -> None:
    """Refuse, in one line, contact throws whose joints' configurations differ
    (`joints_key`); the ideal throws beside them are of one configuration by construction
    (their load, `refusal`)."""
    pairs = [(t, v) for t, v in zip(machine.throws, locals_, strict=True) if is_contact(t)]
    first = joints_key(*pairs[0])
    for t, v in pairs[1:]:
        if joints_key(t, v) != first:
            raise ParameterError(
                f"{t.name}: its pins, guide, laws or load differ from "
                f"{pairs[0][0].name}'s (which pins are worn, the guide's clearance, "
                "friction_law, a contact law of a file, load): the contact throws of a machine "
                "share one configuration of the joints today (their values differ freely)"
            )


def throw_link_values(machine: Machine, throw: Throw, local: Mapping[str, Any], model
                      ) -> dict[str, Any]:  # fmt: skip
    """An ideal throw's values as its one-throw model of the massless link (``model``:
    ``--model compressor``, or ``compressor-valves``) takes them, rc = 0 (validated there,
    refused with the throw's namespace): its crank angle at ``t = 0`` the shaft's plus its
    phase, and with a motor and several throws the drive's inertia 0 (the machine's)."""
    names = set(model.schema.names)
    v = {k: val for k, val in local.items() if k in names}
    v.update(rc=0.0, theta1_0=float(local["theta1_0"]) + float(local["phase"]))
    if "load" in names:
        v["load"] = throw.load
    if shared(machine):
        v["J_drive"] = 0.0
    if held(machine) or machine.shaft.torsion:
        v.update(motor=throw_law(machine).name, motor_torque=0.0)
    return _validated(machine, throw, model, v)


def _validated(machine: Machine, throw: Throw, model, v: dict[str, Any]) -> dict[str, Any]:
    """``v`` validated by the throw's one-throw ``model``, refused with the throw's namespace
    (``throw2.rc = ...``). A throw on the other side of the shaft (``cylinder_angle`` 180
    deg) has its weight along its own +y: its ``g`` negated (`.assemble.throw_values`),
    checked as the user gave it and kept negated."""
    g = float(v.get("g", 0.0))
    try:
        out = model.parameters({**v, "g": -g} if g < 0.0 else v)
    except ParameterError as exc:
        part = "shaft" if str(exc).split(" ")[0] in SHAFT_NAMES else throw.name
        raise ParameterError(f"{machine.prefix(part)}{exc}") from None
    if g < 0.0:
        out["g"] = g
    return out


def assemble_contact(machine: Machine, locals_: list[dict], J_drive: float = 0.0, link=None,
                     frame: Mapping[str, Any] | None = None,
                     stages: Mapping[str, Mapping[str, Any]] | None = None,
                     torsion: Mapping[str, Any] | None = None
                     ) -> ContactConfiguration:  # fmt: skip
    """Resolve a machine of contact throws (and ideal ones): each throw's one-throw vector and
    state, one after another (module docstring); with a motor and several throws then the
    drive's slice (its inertia ``J_drive`` and the torque law's) and the machine's work of
    the motor. ``link(throw)``: an ideal throw's one-throw model of the massless link (its
    values ``locals_``' entry, `throw_link_values`). On a ``[frame]`` (its values ``frame``,
    names inside ``frame.``) then the frame's slice (`recipdyn.model.frame.body.pack`), each
    throw's crank's static moment ``m1 rs`` (part ``frame.cranks``) and the difference steps'
    scales, and the frame's states and work integrals; then per interstage volume its slice
    (its values ``stages[name]``: ``volume``, ``cooler_temperature``; the gas constant its
    upstream stage's) and its pressure (``interstage1.p``). On a flexible shaft (its values
    ``torsion``: the machine's namespaced ones, `recipdyn.model.shaft.flexible.pack`) the
    rotor's and flywheel's angles and speeds (part ``shaft.nodes``) before the motor's work,
    the sections' dissipation after it, the sections' slice and the nodes' phases."""
    from ..components.contact_model import pack

    if len(locals_) > 1:  # (one throw: nothing to compare)
        same_joints(machine, locals_)
    pv, sv = SlicesBuilder(), SlicesBuilder()
    chunks, scales, modules, links = [], [], [], []
    crank = _CRANK_STATES if shared(machine) else {}
    link_events = False
    for t, v in zip(machine.throws, locals_, strict=True):
        pre = machine.prefix(t.name)
        if is_contact(t):
            model = one_model(t)
            modules.append(model.kernels(v))
            vec = pack(v, model.load_part(v))
            names = model.states(v)
            scales.append(fd_scales(v, len(names)))
        else:  # an ideal throw: its one-throw configuration of the massless link
            cfg = link(t).configuration(v)
            links.append(cfg.kernels)
            link_events = cfg.has_states
            vec = cfg.params
            names = cfg.layout.state.named()
            assert cfg.layout.state.start("throw1.mechanism") == 0  # (theta_c, thetadot_c first)
            scales.append(np.full(len(names), 1e-3))  # (as a contact module's other states)
        chunks.append(vec)
        pv.reserve(t.name, vec.size)
        sv.add(f"{t.name}.mechanism", ((pre + crank.get(n, n), u) for n, u in names))
    assert all(m is modules[0] for m in modules), "joints_key misses a choice of the module"
    assert all(m is links[0] for m in links), "the ideal throws' modules differ"
    if shared(machine):  # the drive's inertia and torque law; the difference steps' scales
        from ..components.drive import MOTOR
        from .assemble import _torque_values, motor_of

        law = motor_of(machine)
        drive = np.concatenate([MOTOR.pack({"J_drive": J_drive}),
                                law.pack(_torque_values(machine, locals_, law))])  # fmt: skip
        chunks.append(drive)
        pv.reserve("shaft", drive.size)
        if machine.shaft.torsion:  # the rotor's and flywheel's angles and speeds; the
            # sections' slice and the nodes' phases (a throw's: its crank's angle less its
            # node's); the sections' dissipation after the motor's work
            from ..shaft.flexible import order
            from ..shaft.flexible import pack as torsion_pack

            pre = machine.prefix("shaft")
            sv.add("shaft.nodes", (("theta1", "rad"), ("omega1", "rad/s"),
                                   (pre + "theta_flywheel", "rad"),
                                   (pre + "omega_flywheel", "rad/s")))  # fmt: skip
            scales.append(np.ones(4))
            chunks.append(torsion_pack(machine, torsion or {})[0])
            pv.reserve("shaft.torsion", chunks[-1].size)
            theta0 = float(torsion["theta1_0"]) if torsion else 0.0
            chunks.append(np.array([0.0, 0.0, *(float(locals_[k]["theta1_0"]) - theta0
                                                for k in order(machine))]))  # fmt: skip
            pv.reserve("shaft.phases", chunks[-1].size)
        work = (("W_motor", "J"),)
        if machine.shaft.torsion:
            work += ((machine.prefix("shaft") + "W_shaft_damping", "J"),)
        sv.add("shaft.work", work)
        scales.append(np.ones(len(work)))
    if machine.frame is not None:  # (one-way: nothing before it reads it)
        from ..frame.body import STATES as FRAME_STATES
        from ..frame.body import WORK as FRAME_WORK
        from ..frame.body import pack as frame_pack

        chunks.append(frame_pack(machine, frame or {}))
        pv.reserve("frame", chunks[-1].size)
        chunks.append(np.array([float(v["m1"]) * float(v["rs"]) for v in locals_]))
        pv.reserve("frame.cranks", chunks[-1].size)
        sv.add("frame", ((f"frame.{s}", u) for s, u in FRAME_STATES))
        sv.add("frame.work", ((f"frame.{s}", u) for s, u in FRAME_WORK))
        # the frame's displacements, rates and work integrals: linear in them, any step
        scales.append(np.array([1e-6] * 3 + [1e-4] * 3 + [1.0] * 2))
    for i in machine.interstages:  # its volume, cooler's temperature, gas constant; its p
        from ..components.interstage import INTERSTAGE

        upstream = next(v for t, v in zip(machine.throws, locals_, strict=True)
                        if t.stage == i.upstream)  # fmt: skip
        own = dict(stages or {}).get(i.name, {})
        chunks.append(INTERSTAGE.pack({**own, "gas_constant": upstream["gas_constant"]}))
        pv.reserve(i.name, chunks[-1].size)
        sv.add(i.name, ((f"{i.name}.p", "Pa"),))
        scales.append(np.array([1e3]))  # (a pressure: 1 kPa, at least, scales its step)
    if shared(machine) or machine.frame is not None or machine.interstages:
        chunks.append(np.concatenate(scales))
        pv.reserve("jacobian", chunks[-1].size)
    layout = Layout(sv.build(), pv.build(), SlicesBuilder().build())
    return ContactConfiguration(machine, tuple(locals_), layout,
                                np.concatenate(chunks).astype(np.float64), modules[0],
                                links[0] if links else None, link_events)  # fmt: skip


@lru_cache(maxsize=32)
def contact_configuration(machine: Machine, items: tuple, link=None) -> ContactConfiguration:
    """The machine assembled at the validated values ``items`` (sorted pairs; remembered);
    ``link``: as `assemble_contact`'s."""
    from .assemble import throw_values

    values = dict(items)
    own = [throw_values(machine, values, k) for k in range(len(machine.throws))]
    locals_ = [throw_contact_values(machine, t, v) if is_contact(t)
               else throw_link_values(machine, t, v, link(t))
               for t, v in zip(machine.throws, own, strict=True)]  # fmt: skip
    frame = None
    if machine.frame is not None:
        from .assemble import frame_values

        frame = frame_values(values)
    stages = {i.name: {k[len(i.name) + 1 :]: v for k, v in values.items()
                       if k.startswith(f"{i.name}.")} for i in machine.interstages}  # fmt: skip
    torsion = None
    if machine.shaft.torsion:
        torsion = {**values, "theta1_0": float(own[0]["theta1_0"])}
    return assemble_contact(machine, locals_, float(own[0].get("J_drive", 0.0)), link, frame,
                            stages, torsion)  # fmt: skip


def one_throw_configuration(machine: Machine, local: Mapping[str, Any]) -> ContactConfiguration:
    """A machine of one contact throw at its validated one-throw values ``local`` (the
    compressor's names: the family's routes ``contact`` and ``contact-valves``), assembled
    without validating them again (remembered per values)."""
    items = tuple(sorted(local.items()))
    try:
        return _one_throw_configuration(machine, items)
    except TypeError:  # an unhashable value (a table as lists): assembled each time
        return assemble_contact(machine, [dict(local)])


@lru_cache(maxsize=32)
def _one_throw_configuration(machine: Machine, items: tuple) -> ContactConfiguration:
    return assemble_contact(machine, [dict(items)])
