r"""The contact-impact joints at the pins: the joints' configuration part of a throw.

A throw with a contact or lubricated pin, or the guide's clearance, is one configuration of
these joints: `ContactJoints` holds what its values mean (schema, checks, packing,
states, the generated glue's bindings, outputs, summaries) and `.contact_valves_model`
overrides what the dynamic valves' states change. The one assembler builds the machines from
them: the family's one-throw machine (``compressor-contact``, ``compressor-contact-valves``,
``compressor-guide``: `recipdyn.model.assembler.model.OneContact`) and a machine's contact
throws (`recipdyn.model.assembler.contact_throws`); neither class is a registered model. The
derivations are `recipdyn.model.compressor_contact`, the compiled parts
`recipdyn.model.joints.pins`, the kernels' templates `recipdyn.model.assembler.templates.joints`
(the joints' forces, one module per contact law) and `.contact` (one per configuration).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import lru_cache
from typing import Any

import numpy as np

from ..base import Event, ODESystem, Signal
from ..joints.contact import FRICTION_LAWS, FRICTION_ROLES, LAWS, hertz_stiffness, hysteresis_factor
from ..joints.pins import (
    CFG,
    CLEARANCE,
    G_GAS,
    G_GUIDE,
    GUIDE_JOINTS,
    I_WIN,
    I_WLOSS,
    INPUTS,
    LAW_OPTIONAL,
    LAW_ROLES,
    MECH,
    N_GUIDE,
    N_GUIDE_STATES,
    N_PACKED,
    P_CHI,
    P_MU,
    RIGID,
    STATE_NAMES,
    STATE_UNITS,
)
from ..load import CYCLE_PARAMS
from ..parameters import SCHEMA as LINK_SCHEMA
from ..parameters import check_reach
from ..protocol import Param, Schema
from .guide import GUIDE_PARAMS, GUIDES
from .load import cycle_outputs, cycle_summary

__all__ = ["ContactJoints", "energy", "overlap_half_angle", "pack", "stiffness"]

_INF = math.inf


#: The joint family at each pin: its parameter and the joints it may be (the massless link
#: exists at the crank pin only, and only in the massless-link model).
PIN_CHOICES = {"crank_joint": ("link", "ideal", "contact", "lubricated"),
               "crosshead_joint": ("ideal", "contact", "lubricated")}  # fmt: skip


def joint_types(values: Mapping[str, Any]) -> tuple[str, str]:
    """The joint at the crank pin and at the crosshead pin (``ideal``, ``contact``,
    ``lubricated``): ``crank_joint`` and ``crosshead_joint`` where given, else from
    ``clearance_joints`` (where the clearance is) and ``joint`` (dry or lubricated)."""
    where = values.get("clearance_joints", "crank")
    kind = "lubricated" if values.get("joint", "dry") == "lubricated" else "contact"
    crank = values.get("crank_joint") or ("ideal" if where in ("crosshead", "ideal") else kind)
    cross = values.get("crosshead_joint") or ("ideal" if where in ("crank", "ideal") else kind)
    return crank, cross


def _resolve_joints(values: dict[str, Any]) -> None:
    """Write the joint family of each pin and the clearance configuration it makes into
    ``values``; refuse, in one line, a combination that does not exist here."""
    from ...errors import ParameterError

    crank, cross = joint_types(values)
    if crank == "link":
        raise ParameterError(
            "crank_joint = 'link' is out of range for this model; allowed: 'ideal', 'contact', "
            "'lubricated' (the massless link is the compressor model's: --model compressor)"
        )
    guide = values.get("guide", "ideal") == "clearance"
    if crank == "ideal" and cross == "ideal" and not guide:
        raise ParameterError(
            "crank_joint = crosshead_joint = 'ideal': no clearance joint left; allowed: "
            "'contact' or 'lubricated' at one pin at least, or guide = 'clearance' (the ideal "
            "mechanism: --model compressor with rc = 0)"
        )
    values["crank_joint"], values["crosshead_joint"] = crank, cross
    values["clearance_joints"] = ("ideal" if crank == cross == "ideal" else
                                  "both" if "ideal" not in (crank, cross) else
                                  "crank" if cross == "ideal" else "crosshead")  # fmt: skip


def load_part(values: Mapping[str, Any]):
    """The load component the values choose (`recipdyn.model.components.load`): a table when
    ``load_table`` is given (a measured indicator diagram, or a real gas's cycle tabulated
    from CoolProp), else the ``load`` parameter's, a built-in load or one of a user's file
    (``load = file.py:OBJ``, `load_spec`)."""
    from .load import load_component

    return load_component(values)


def load_spec(values: Mapping[str, Any]) -> str | None:
    """The ``load`` of ``values`` if it names a component of a user's module or file
    (``file.py:OBJ``), else None (a built-in load)."""
    from ..registry import is_spec

    spec = values.get("load")
    return spec if is_spec(spec) else None


#: The roles of a load with states (`recipdyn.model.components.load`).
STATE_ROLES = ("state_force", "state_rhs", "event", "reset")


def user_load(values: Mapping[str, Any]):
    """The load component of a user's file that ``values`` choose, or None. It must be of the
    family ``load`` and provide ``force`` or, with states, the roles `STATE_ROLES` and its
    initial states (``initial``): `ParameterError` in one line otherwise."""
    from ...errors import ParameterError
    from .contract import resolve_component

    spec = load_spec(values)
    if spec is None:
        return None
    load = resolve_component("load", spec, {})
    if load.states or load.aux_states:
        missing = [r for r in STATE_ROLES if r not in load.kernels]
        if load.initial is None:
            missing.append("initial")
        if missing:
            raise ParameterError(f"load = {spec!r} has states but provides no "
                                 f"{' or '.join(missing)}; a load with states provides "
                                 f"{', '.join(STATE_ROLES)} and initial (values -> its states "
                                 "at t = 0)")  # fmt: skip
    elif "force" not in load.kernels:
        raise ParameterError(f"load = {spec!r} provides no 'force' kernel; a load provides "
                             "force(theta1, p, o) and optionally force_sc(sin theta1, cos "
                             "theta1, p, o)")  # fmt: skip
    return load


def stateful_user_load(values: Mapping[str, Any]):
    """The load of a user's file with states that ``values`` choose, or None."""
    load = user_load(values)
    return load if load is not None and (load.states or load.aux_states) else None


def load_offset(values: Mapping[str, Any]) -> int:
    """The offset of the load's slice in the parameter vector: after the joints', a contact
    law's of a user's file, and the guide's or the free crank's and the torque law's."""
    lo = N_PACKED + law_size(values)
    if has_motor(values):
        lo += N_CRANK + motor_size(values)
    elif has_guide(values):
        lo += N_GUIDE
    return lo


def _initial_force(values: Mapping[str, Any]) -> float:
    """The gas force at t = 0 of a load of a user's file with states: its compiled
    ``state_force`` on its initial states."""
    import importlib

    load = stateful_user_load(values)
    g = first_load_state(values)
    y = np.zeros(g + len(load.states) + len(load.aux_states))
    y[g:] = np.asarray(load.initial(values), dtype=np.float64).ravel()
    fn = getattr(importlib.import_module(load.module), load.kernel("state_force"))
    return float(fn(y, g, pack(values), load_offset(values)))


def _load_key(values: Mapping[str, Any], part) -> str:
    """How the glue's cache names the load ``part``: a built-in load by its name, a load of a
    user's file by its absolute spec (`_glue` resolves it again and hashes its file)."""
    from ..registry import absolute_spec
    from .load import LOADS, VALVES

    if part is VALVES or LOADS.get(part.name) is part:
        return part.name
    return absolute_spec(values["load"])


def law_spec(values: Mapping[str, Any]) -> str | None:
    """The ``contact_law`` of ``values`` (or its alias ``law``) if it names a component of a
    user's module or file (``file.py:OBJ``), else None (one of the built-in laws, `LAWS`)."""
    from ..registry import is_spec

    spec = values.get("contact_law", values.get("law"))
    return spec if is_spec(spec) else None


def law_part(values: Mapping[str, Any]):
    """The contact-law component a user's file gives (``contact_law = file.py:OBJ``), or None
    for a built-in law. It must be of the family ``contact_law`` and provide the roles
    `LAW_ROLES` (module ``recipdyn.model.components.contact``, docs/components.md);
    [`ParameterError`][recipdyn.errors.ParameterError] in one line otherwise."""
    from ...errors import ParameterError
    from .contract import resolve_component

    spec = law_spec(values)
    if spec is None:
        return None
    law = resolve_component("contact_law", spec, {})
    missing = [r for r in LAW_ROLES if r not in law.kernels]
    if missing:
        raise ParameterError(f"contact_law = {spec!r} provides no {' or '.join(missing)} "
                             f"kernel; a contact law provides {', '.join(LAW_ROLES)} and "
                             f"optionally {', '.join(LAW_OPTIONAL)}")  # fmt: skip
    return law


def law_size(values: Mapping[str, Any]) -> int:
    """The length of the contact law's slice (0 for a built-in law: its ``chi`` is in the
    joints' part, `P_CHI`). The slice follows the joints' part; the guide's and the load's
    follow it."""
    law = law_part(values)
    return 0 if law is None else int(np.asarray(law.pack(values)).size)


GUIDE_REFUSAL = (
    "Benettin's method is not offered with guide = 'clearance' or a load of your own with "
    "states: the tangent integration across the impacts (the saltation matrices of the "
    "guide's four corners' event, or of the load's events) has not been checked against "
    "differences of the flow, as the pins' has (with the crank prescribed or free); set "
    "guide = 'ideal' and a load without states for exponents of worn pins"
)


#: The drive's parameters (inert with the prescribed drive: left out of a sweep store's
#: identity then).
_DRIVE_NAMES = ("drive", "motor", "J_drive", "motor_torque", "motor_sync_speed",
                "motor_breakdown_torque", "motor_breakdown_slip", "rs", "m1", "J1")  # fmt: skip


def has_motor(values: Mapping[str, Any]) -> bool:
    """Whether a motor turns the crank (``drive = motor``: the crank angle and speed are
    states)."""
    return values.get("drive", "prescribed") == "motor"


def _crank_slice(values: Mapping[str, Any]) -> np.ndarray:
    """The free crank's slice: its inertia about the main bearing with the drive's,
    ``J1 + m1 rs^2 + J_drive``, and its static moment ``m1 rs``."""
    m1, rs = float(values["m1"]), float(values["rs"])
    return np.array([float(values["J1"]) + m1 * rs * rs + float(values["J_drive"]), m1 * rs])


def _motor_parts(values: Mapping[str, Any]):
    """The free crank's slice (the drive) and the torque law's component."""
    from .contract import Component
    from .drive import KERNELS, MOTORS

    crank = Component("drive", "motor", "the free crank with the drive's inertia",
                      module=KERNELS, kernels={}, pack=_crank_slice)  # fmt: skip
    return crank, MOTORS[values["motor"]]


#: The free crank's slice length (`_crank_slice`).
N_CRANK = 2
#: The crank's states with a motor, after every other state.
MOTOR_STATES = (("theta1", "rad"), ("omega1", "rad/s"), ("W_motor", "J"))


def motor_size(values: Mapping[str, Any]) -> int:
    """The length of the torque law's slice."""
    return int(np.asarray(_motor_parts(values)[1].pack(_motor_values(values))).size)


def _motor_values(values: Mapping[str, Any]) -> dict[str, Any]:
    """``values`` as the torque laws read them: a constant torque's default, the mean load
    torque of the ideal mechanism, is the paper's load's, the table's or the ideal-valve
    cycle's (for the dynamic valves)."""
    if values.get("load") in (None, "valves"):
        return {**values, "load": "cycle", "gas": "ideal", "load_table": None}
    return dict(values)


def has_guide(values: Mapping[str, Any]) -> bool:
    """Whether the crosshead's guide has clearance (``guide = clearance``)."""
    return values.get("guide", "ideal") == "clearance"


def first_load_state(values: Mapping[str, Any]) -> int:
    """The index of a load's first state: after the joints' twelve and the guide's eight."""
    return G_GAS + (N_GUIDE_STATES if has_guide(values) else 0)


def friction_part(values: Mapping[str, Any]) -> tuple[str, str, int]:
    """The friction law at the pins, as the glue imports it: ``(module, function, offset of
    its slice)``. A contact law of a user's file with a ``friction`` role: that function, its
    slice after the joints' part; else the built-in law ``friction_law`` names
    (`recipdyn.model.joints.contact.FRICTION_ROLES`), reading ``(mu, v0, v1)`` at `P_MU`."""
    law = law_part(values)
    if law is not None and "friction" in law.kernels:
        return law.module, law.kernel("friction"), N_PACKED
    return "recipdyn.model.joints.contact", FRICTION_ROLES[values["friction_law"]], P_MU


def joints_bindings(law: str | None, friction: tuple[str, str, int], guide_friction: str
                    ) -> tuple[dict, dict, str, str]:  # fmt: skip
    """The joints' forces for one contact law and one friction law at the pins and at the
    guide's shoes: the roles and constants of the template ``joints``
    (`recipdyn.model.assembler.templates.joints`), its stem and note. ``law``: a contact law of
    a user's file (its absolute spec; its slice after the joints' part), or None for the
    built-in law (its hysteresis factor at `P_CHI`)."""
    from .contract import resolve_component, source_digest

    builtin = "recipdyn.model.joints.contact"
    roles = {"friction": friction[:2], "guide_friction": (builtin, guide_friction)}
    note, stem = "", f"{friction[1]}_{guide_friction}"
    if law is None:
        roles.update(law_normal=(builtin, "power_law_normal"),
                     law_elastic=(builtin, "power_law_elastic"))  # fmt: skip
        lo = P_CHI
    else:
        law_c = resolve_component("contact_law", law, {})
        roles.update(law_normal=(law_c.module, law_c.kernel("normal")),
                     law_elastic=(law_c.module, law_c.kernel("elastic")))  # fmt: skip
        lo = N_PACKED
        # its edits give a new module, never stale machine code
        note = f"contact_law = {law_c.module}: {source_digest(law_c.module)}"
        stem = f"{law_c.name}_{stem}".replace("-", "_")
    return roles, {"FO": friction[2], "LO": lo}, stem, note


@lru_cache(maxsize=16)
def _joints_module(law: str | None, friction: tuple[str, str, int], guide_friction: str):
    """The module of the joints' forces (`joints_bindings`), compiled once for every
    configuration of the joints that holds those laws."""
    from ..assembler import generate

    return generate.module("joints", *joints_bindings(law, friction, guide_friction))


def contact_bindings(joints_module: str, joints: str, load, guide: bool, n_law: int,
                     motor: str | None, n_motor: int) -> tuple[dict, dict, str]:  # fmt: skip
    """The roles, constants and stem of the template ``contact``
    (`recipdyn.model.assembler.templates.contact`) for one configuration of the joints: the
    joints' forces from ``joints_module``, the load component ``load``'s roles, the motor's
    torque law, and the offsets of the layout (the joints' part, the law's slice of
    ``n_law``, the guide's, with a motor the crank's and the torque law's of ``n_motor``, the
    load's; the states: the joints', the guide's, the load's, the crank's)."""
    from ..assembler import generate

    absent = ("recipdyn.model.assembler.generate", "absent")
    roles = {name: (joints_module, name) for name in (
        "joints", "joints_at", "joints_guide", "joints_guide_at", "guide_forces",
        "guide_corner")}  # fmt: skip
    roles.update(dict.fromkeys(("load_force", "load_force_sc", "load_state_force", "load_rhs",
                                "load_event", "load_reset", "torque"), absent))  # fmt: skip
    stateful = bool(load.states)
    if stateful:
        for role, kernel in (
            ("load_state_force", "state_force"),
            ("load_rhs", "state_rhs"),
            ("load_event", "event"),
            ("load_reset", "reset"),
        ):
            roles[role] = (load.module, load.kernel(kernel))
    elif "force_sc" in load.kernels:
        roles["load_force_sc"] = (load.module, load.kernel("force_sc"))
    else:
        roles["load_force"] = (load.module, load.kernel("force"))
    n_guide, first = (N_GUIDE, G_GAS + N_GUIDE_STATES) if guide else (0, G_GAS)
    n_drive = N_CRANK + n_motor if motor is not None else 0
    constants = dict(
        A=first + len(load.states), CFG=generate.Literal(CFG[joints]),
        CO=N_PACKED + n_law + n_guide, G=first, GO=N_PACKED + n_law, GY=G_GUIDE,
        HAS_GUIDE=guide, LO=N_PACKED + n_law + n_guide + n_drive,
        LOAD_SC="force_sc" in load.kernels, LOAD_STATES=stateful,
        M=first + len(load.states) + len(load.aux_states),
        MO=N_PACKED + n_law + n_guide + N_CRANK, MOTOR=motor is not None,
        N_OBS=(30 if guide else 21) + (3 if motor is not None else 0),
    )  # fmt: skip
    stem = f"{joints}_{load.name}" + ("_guide" if guide else "")
    if motor is not None:
        from .drive import MOTORS

        roles["torque"] = (MOTORS[motor].module, MOTORS[motor].kernel("torque"))
        stem += f"_motor_{motor}"
    return roles, constants, stem.replace("-", "_")


@lru_cache(maxsize=32)
def _glue(joints: str, load: str, guide: bool = False, law: str | None = None,
          n_law: int = 0, friction: tuple[str, str, int] = (), guide_friction: str = "",
          motor: str | None = None, n_motor: int = 0):  # fmt: skip
    """The kernels of one configuration of the joints: a module generated from the template
    ``contact`` (`contact_bindings`), calling the joints' module of its laws
    (`_joints_module`)."""
    from ..assembler import generate
    from .contract import resolve_component, source_digest
    from .load import LOADS, VALVES

    part = VALVES if load == VALVES.name else resolve_component("load", load, LOADS)
    jm = _joints_module(law, friction, guide_friction or "ambrosio_friction").__name__
    roles, constants, stem = contact_bindings(jm, joints, part, guide, n_law, motor, n_motor)
    # a load of a user's file (``load`` its absolute spec): its edits give a new module
    note = "" if load in LOADS or part is VALVES else (
        f"load = {part.module}: {source_digest(part.module)}")  # fmt: skip
    return generate.module("contact", roles, constants, stem, note)


def kernels(values: Mapping[str, Any], load=None):
    """The generated kernels of the joints, the guide, the load ``values`` choose (or
    ``load``) and the contact law of a user's file if one is chosen: a module with ``rhs``,
    ``jac``, ``rhs_jac``, ``event``, ``reset``, ``observe``, ``fd_jac`` and ``cs_jac``
    (`recipdyn.model.assembler.templates.contact`)."""
    part = load_part(values) if load is None else load
    name = _load_key(values, part)
    spec = law_spec(values)
    friction = friction_part(values)
    guide = has_guide(values)
    shoes = FRICTION_ROLES[values["guide_friction_law"]] if guide else ""
    if has_motor(values):
        from ..registry import absolute_spec

        law = None if spec is None else absolute_spec(spec)
        return _glue(values["clearance_joints"], name, guide, law, law_size(values),
                     friction, shoes, values["motor"], motor_size(values))  # fmt: skip
    if spec is not None:
        from ..registry import absolute_spec

        return _glue(values["clearance_joints"], name, guide, absolute_spec(spec),
                     law_size(values), friction, shoes)  # fmt: skip
    return _glue(values["clearance_joints"], name, guide, None, 0, friction, shoes)


def _link(name: str, **changes) -> Param:
    from dataclasses import replace

    return replace(LINK_SCHEMA[name], **changes)


SCHEMA = Schema((
    *(_link(k) for k in ("r", "l", "ls", "m2", "m3", "J2", "g")),
    Param("clearance_joints", "", "crank", "where the clearance is: the crank pin, the crosshead "
          "pin, or both (the other joints are ideal); 'ideal': neither (with guide = "
          "'clearance')", choices=GUIDE_JOINTS, group="joint"),
    _link("rc", description="radial clearance of the crank-pin joint, c = R_b - R_j",
          low=0.0, low_open=True),
    Param("rc_crosshead", "m", 1e-4, "radial clearance of the crosshead-pin joint "
          "(clearance_joints = crosshead or both)", 0.0, 0.05, low_open=True,
          assumed="assumed: a worn crosshead bush", group="joint"),
    _link("d", low_ref="-(l - r - 1.5 (rc + rc_crosshead))",
          high_ref="l - r - 1.5 (rc + rc_crosshead)"),
    Param("joint", "", "dry", "'dry' contact-impact or 'lubricated' (oil film + dry contact "
          "beyond eps_dry) at each clearance joint (crank_joint, crosshead_joint set one pin)",
          choices=("dry", "lubricated"), group="joint"),
    Param("crank_joint", "", None, "the crank-pin joint: 'ideal', 'contact' (dry) or "
          "'lubricated' (default: from clearance_joints and joint; 'link', the massless link, "
          "is the compressor model's)", choices=PIN_CHOICES["crank_joint"], optional=True,
          group="joint"),
    Param("crosshead_joint", "", None, "the crosshead-pin joint: 'ideal', 'contact' (dry) or "
          "'lubricated' (default: from clearance_joints and joint)",
          choices=PIN_CHOICES["crosshead_joint"], optional=True, group="joint"),
    Param("contact_law", "", "lankarani-nikravesh", "normal force law (hysteresis damping)",
          choices=LAWS, group="joint"),
    Param("restitution", "", 0.9, "nominal coefficient of restitution of the law", 0.0, 1.0,
          low_open=True, group="joint"),
    Param("K", "N/m**1.5", None, "contact stiffness of the crank-pin joint (default: Hertz "
          "pin-in-hole from the radii and materials)", 0.0, _INF, low_open=True, group="joint",
          optional=True),
    Param("K_crosshead", "N/m**1.5", None, "contact stiffness of the crosshead-pin joint "
          "(default: Hertz pin-in-hole)", 0.0, _INF, low_open=True, group="joint",
          optional=True),
    Param("journal_radius", "m", 0.05, "crank-pin (journal) radius R_j", 0.0, _INF,
          low_open=True, assumed="assumed: not given in the paper", group="joint"),
    Param("crosshead_pin_radius", "m", 0.03, "crosshead-pin (journal) radius", 0.0, _INF,
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
    Param("guide", "", "ideal", "the crosshead guide: 'ideal' (rigid: the crosshead on y = -d) "
          "or 'clearance' (the crosshead moves sideways and tilts between the shoes and knocks on "
          "them: guide_clearance and the guide_* parameters)", choices=GUIDES, group="guide"),
    *GUIDE_PARAMS,
    _link("omega"), _link("theta1_0"),
    *(_link(k) for k in ("drive", "motor", "J_drive", "motor_torque", "motor_sync_speed",
                         "motor_breakdown_torque", "motor_breakdown_slip")),
    # the crank's own mass and inertia act on a free crank only (drive = motor)
    *(_link(k, group="drive") for k in ("rs", "m1", "J1")),
    _link("load_amplitude"), _link("load_sign"), _link("load"),
    *(_link(k) for k in (*CYCLE_PARAMS, "gas", "suction_temperature")),
    Param("e0_angle", "rad", None, "initial direction of e (default: aligned with the rod "
          "load, as the massless link's default)", -1e6, 1e6, group="initial", optional=True),
    Param("e0_angle_crosshead", "rad", None, "initial direction of the crosshead pin's e "
          "(default: the crank pin's + pi)", -1e6, 1e6, group="initial", optional=True),
    Param("e0_ratio", "", 1.0, "initial |e| / rc of each clearance joint", 0.0, 1.5,
          group="initial"),
    Param("edot0_x", "m/s", 0.0, "initial ex'", -1e3, 1e3, group="initial"),
    Param("edot0_y", "m/s", 0.0, "initial ey'", -1e3, 1e3, group="initial"),
), aliases={"clearance": "rc", "subsidence": "d", "speed": "omega", "crank_speed": "omega",
            "c": "rc", "law": "contact_law"})  # fmt: skip


def stiffness(values: Mapping[str, Any], joint: str = "crank") -> float:
    """K (N/m^1.5) of a clearance joint: the value given, or Hertz's pin-in-hole formula."""
    key, rc, rj = (("K", "rc", "journal_radius") if joint == "crank" else
                   ("K_crosshead", "rc_crosshead", "crosshead_pin_radius"))  # fmt: skip
    if values.get(key) is not None:
        return float(values[key])
    rj = float(values[rj])
    return hertz_stiffness(rj, rj + float(values[rc]), values["E_journal"],
                           values["nu_journal"], values["E_bearing"],
                           values["nu_bearing"])  # fmt: skip


#: The widest overlap half-angle (degrees) at which the point-contact law is taken to hold:
#: Hertz's theory needs a contact small against the radii (Johnson 1985, Contact Mechanics,
#: sec. 4.1) and must not be used when the contact arc is of the order of the radius
#: (Mostofi & Gohar, summarised in Lubricants 10 (2022) 233,
#: doi:10.3390/lubricants10100233). "Of the order" is taken here as an arc 2 phi R_j as long
#: as the radius R_j: phi = 0.5 rad = 28.6 deg (the paper's
#: base case, c = 1 mm, reaches 23 deg; c = 0.1 mm under the same load 45 deg).
HERTZ_ARC_LIMIT_DEG = math.degrees(0.5)


def overlap_half_angle(R_j: float, c: float, delta: float) -> float:
    """Half-angle (degrees) of the arc over which a journal of radius ``R_j`` overlaps its
    bearing (radius ``R_j + c``) at penetration ``delta``, seen from the bearing centre: from
    the two circles' intersection, ``cos phi = (R_b^2 + |e|^2 - R_j^2) / (2 R_b |e|)`` with
    ``|e| = c + delta``; ``1 - cos phi ~ delta / (c + delta)`` for ``R_j >> c``. 0 without
    contact. Hertz's law (and the damping laws built on it) assume a contact small against the
    radii: an arc of tens of degrees means the real, conformal contact is far from it."""
    if delta <= 0.0:
        return 0.0
    rb, e = R_j + c, c + delta
    cos_phi = (rb * rb + e * e - R_j * R_j) / (2.0 * rb * e)
    return math.degrees(math.acos(min(1.0, max(-1.0, cos_phi))))


def pack(values: Mapping[str, Any], load=None) -> np.ndarray:
    """The joints' parameters (layout: the ``P_*`` constants), then the slice of the load
    component (``load``, default: the one the values choose, `load_part`)."""
    from .contract import Assembly

    v = values
    pins = joint_types(v)
    head = [v[k] for k in MECH] + [0.0] * len(INPUTS)
    head += [v["rc"], stiffness(v, "crank"), v["journal_radius"],
             v["rc_crosshead"], stiffness(v, "crosshead"), v["crosshead_pin_radius"],
             0.0 if law_spec(v) else hysteresis_factor(v["contact_law"], v["restitution"]),
             v["friction"], v["v0"], v["v1"],
             v["oil_viscosity"] if pins[0] == "lubricated" else 0.0, v["bearing_length"],
             v["eps_dry"], v["v_impact_min"],
             v["oil_viscosity"] if pins[1] == "lubricated" else 0.0]  # fmt: skip
    part = load_part(v) if load is None else load
    law = law_part(v)  # a contact law of a user's file: its slice first
    first = () if law is None else (law,)
    n_law = law_size(v)
    if has_motor(v):  # (the guide's,) the crank's and the torque law's slices, then the load's
        crank, motor = _motor_parts(v)
        guide = (CLEARANCE,) if has_guide(v) else ()
        n_g = N_GUIDE if guide else 0
        vec, offsets = Assembly(N_PACKED, (*first, *guide, crank, motor, part)).pack(
            np.asarray(head, dtype=np.float64), _motor_values(v))  # fmt: skip
        assert offsets["drive"] == N_PACKED + n_law + n_g  # literals in the glue
        assert offsets["load"] == N_PACKED + n_law + n_g + N_CRANK + motor_size(v)
        assert not guide or offsets["guide"] == N_PACKED + n_law
        return vec
    if has_guide(v):
        vec, offsets = Assembly(N_PACKED, (*first, CLEARANCE, part)).pack(
            np.asarray(head, dtype=np.float64), v)  # fmt: skip
        assert offsets["guide"] == N_PACKED + n_law  # literals in the glue
        assert offsets["load"] == N_PACKED + n_law + N_GUIDE
        return vec
    vec, offsets = Assembly(N_PACKED, (*first, part)).pack(np.asarray(head, dtype=np.float64),
                                                           v)  # fmt: skip
    assert offsets["load"] == N_PACKED + n_law  # a literal in the glue
    return vec


def _law_energy(values: Mapping[str, Any], delta: np.ndarray, joint: str) -> np.ndarray:
    """The elastic energy stored at penetrations ``delta`` (>= 0) by the contact law of a
    user's file: its ``potential(delta, K, p, o)`` if it has one, else the integral of its
    ``elastic`` force from 0 to ``delta`` (adaptive quadrature, relative error 1e-12)."""
    import importlib

    from scipy.integrate import quad

    law = law_part(values)
    mod = importlib.import_module(law.module)
    p, o, K = pack(values), N_PACKED, stiffness(values, joint)
    out = np.zeros_like(delta)
    if "potential" in law.kernels:
        fun = getattr(mod, law.kernel("potential"))
        for i in np.flatnonzero(delta > 0.0):
            out[i] = fun(float(delta[i]), K, p, o)
        return out
    fun = getattr(mod, law.kernel("elastic"))
    for i in np.flatnonzero(delta > 0.0):
        out[i] = quad(fun, 0.0, float(delta[i]), args=(K, p, o), epsabs=0.0, epsrel=1e-12)[0]
    return out


def energy(values: Mapping[str, Any], t: np.ndarray, y: np.ndarray, theta1=None,
           omega1=None) -> dict[str, np.ndarray]:  # fmt: skip
    """Kinetic + gravity energy of rod and crosshead and the contacts' elastic energy (J);
    ``theta1``, ``omega1``: a free crank's angle and speed (default: the prescribed
    ``theta1_0 + omega t`` and ``omega``)."""
    r, l, ls, m2, m3, J2, g, d, w, th10 = (float(values[k]) for k in MECH)
    th1 = th10 + w * t if theta1 is None else theta1
    w = w if omega1 is None else omega1
    y = np.atleast_2d(y)
    e1x, e1y, e2x, e2y, u1, v1, u2, v2 = (y[:, i] for i in range(8))
    ys, vs = e2y, v2  # the small end's lateral position and velocity, from y = -d
    if has_guide(values):  # it follows the crosshead pin's lateral position
        ys, vs = e2y + y[:, G_GUIDE], v2 + y[:, G_GUIDE + 2]
    s2 = (ys - d - r * np.sin(th1) - e1y) / l
    c2 = np.sqrt(1.0 - s2**2)
    vbx, vby = -r * w * np.sin(th1) + u1, r * w * np.cos(th1) + v1
    th2d = (vs - vby) / (l * c2)
    vgx, vgy = vbx - ls * s2 * th2d, vby + ls * c2 * th2d
    v3 = vbx - l * s2 * th2d - u2
    kin = 0.5 * (m2 * (vgx**2 + vgy**2) + J2 * th2d**2 + m3 * v3**2)
    pot = m2 * g * (r * np.sin(th1) + e1y + ls * s2)
    d1 = np.maximum(np.hypot(e1x, e1y) - float(values["rc"]), 0.0)
    d2 = np.maximum(np.hypot(e2x, e2y) - float(values["rc_crosshead"]), 0.0)
    if law_spec(values) is not None:
        elastic = _law_energy(values, d1, "crank") + _law_energy(values, d2, "crosshead")
    else:
        elastic = stiffness(values, "crank") * d1**2.5 / 2.5
        elastic = elastic + stiffness(values, "crosshead") * d2**2.5 / 2.5
    if has_guide(values):  # the crosshead's lateral motion, tilt and weight
        from .guide import tilt_inertia

        yg, ygd, phid = y[:, G_GUIDE], y[:, G_GUIDE + 2], y[:, G_GUIDE + 3]
        kin = kin + 0.5 * (m3 * ygd**2 + tilt_inertia(values) * phid**2)
        pot = pot + m3 * g * yg
    return {"mechanical": kin + pot, "elastic": elastic}


_PLUGGED_SCHEMAS: dict[tuple[int, str | None, str | None], tuple[Schema, Schema]] = {}


def _plugged_schema(schema: Schema, law: str | None, load: str | None) -> Schema:
    """``schema`` with the contact law ``law`` and the load ``load`` of users' files (specs, or
    None; remembered per schema and specs): each spec one more choice of its parameter
    (``contact_law``, ``load``), each component's fragment appended (a name that ``schema`` or
    the other component already has is refused in one line)."""
    from dataclasses import replace

    from ...errors import ParameterError
    from .contract import check_fragments

    key = (id(schema), law, load)
    hit = _PLUGGED_SCHEMAS.get(key)
    if hit is None or hit[0] is not schema:
        specs, parts = {}, []
        if law is not None:
            specs["contact_law"] = law
            parts.append(law_part({"contact_law": law}))
        if load is not None:
            specs["load"] = load
            parts.append(user_load({"load": load}))
        try:
            check_fragments(parts, base=schema.params)
        except ValueError as exc:
            which = " and ".join(f"{k} = {v!r}" for k, v in specs.items())
            raise ParameterError(f"{which}: {exc}") from None
        params = tuple(replace(p, choices=(*p.choices, specs[p.name])) if p.name in specs
                       else p for p in schema)  # fmt: skip
        hit = _PLUGGED_SCHEMAS[key] = schema, Schema(
            (*params, *(q for c in parts for q in c.params)), schema.aliases,
            schema.extras)  # fmt: skip
    return hit[1]


class ContactJoints:
    """The joints' configuration part of a throw with contact-impact (dry or lubricated)
    clearance joints at the crank pin, the crosshead pin, or both, or the guide's clearance:
    what its values mean (schema, checks, packing, states, the generated glue's kernels,
    events, signals, summary of one throw's slice). Not a model: the one-throw machine
    (`recipdyn.model.assembler.model.OneContact`) and a machine's contact throws
    (`recipdyn.model.assembler.contact_throws`) take it as a part."""

    #: (a contact throw's bounds are its machine's: none of its own)
    validity_bounds: tuple = ()

    mean_signals = (
        ("contact", "contact_fraction", "1"),
        ("contact_crosshead", "contact_fraction_crosshead", "1"),
    )
    max_signals = (
        ("eccentricity_ratio", "max_eccentricity_ratio", "1"),
        ("eccentricity_ratio_crosshead", "max_eccentricity_ratio_crosshead", "1"),
    )
    name = "compressor-contact"
    description = ("compressor with contact-impact clearance joints at the crank pin, the "
                   "crosshead pin or both (free flight, impacts, friction, oil film; Flores et "
                   "al. 2008)")  # fmt: skip
    state_names = STATE_NAMES
    state_units = STATE_UNITS
    schema = SCHEMA
    section_signals = (("ex", "m"), ("ey", "m"), ("x", "m"), ("v", "m/s"), ("a", "m/s**2"))
    vibration_signal = ("a", "m/s**2")
    section_pair = ("v", "a")
    summary_verdicts = ("api618_pin_reversal",)
    #: The paper's load never reverses (the journal stays on the wall); at 150 rad/s with a
    #: tenth of it, inertia separates the journal and it impacts several times a revolution.
    event_example = {"omega": 150.0, "load_amplitude": 2e4}

    def check(self, values: Mapping[str, Any]) -> None:
        from ...errors import ParameterError

        if values["rc"] >= values["r"]:
            raise ParameterError(f"rc = {values['rc']!r} m is out of range; allowed: "
                                 f"(0, r = {values['r']!r}) m")  # fmt: skip
        margin = 1.5 * (values["rc"] + values["rc_crosshead"])
        check_reach(values["l"], values["r"], margin, "1.5 (rc + rc_crosshead)")
        dmax = values["l"] - values["r"] - margin
        if not abs(values["d"]) < dmax:
            raise ParameterError(
                f"d = {values['d']!r} m is out of range; allowed: "
                f"(-{dmax:g}, {dmax:g}) m (l - r - 1.5 (rc + rc_crosshead))"
            )
        if values["v1"] <= values["v0"]:
            raise ParameterError(f"v1 = {values['v1']!r} m/s must exceed v0 = "
                                 f"{values['v0']!r} m/s")  # fmt: skip
        if has_motor(values):
            if values.get("motor") == "held":
                raise ParameterError(
                    "motor = 'held' with the contact joints is not modelled yet; allowed: "
                    "'induction' or 'constant', or drive = 'prescribed' (a held rotor on a "
                    "rigid shaft turns the crank as a prescribed speed does)"
                )
            check = _motor_parts(values)[1].check
            if check is not None:
                check(values)
        load = user_load(values)
        if load is not None and load.check is not None:
            load.check(values)
        law = law_part(values)
        if law is not None:
            if values.get("clearance_joints") == "ideal":
                raise ParameterError(
                    f"contact_law = {values['contact_law']!r}: no pin joint has contact in "
                    "this configuration (both pins ideal); a contact law belongs to "
                    "crank_joint or crosshead_joint = 'contact' | 'lubricated'"
                )
            if law.check is not None:
                law.check(values)

    def schema_for(self, values: Mapping[str, Any]) -> Schema:
        """The schema; with a contact law or a load of a user's file (``contact_law =
        file.py:OBJ``, ``load = file.py:OBJ``) each spec one more choice of its parameter and
        the component's fragment appended (its parameters validated, recorded and swept like
        the built-in ones)."""
        from ..registry import absolute_spec

        law, load = law_spec(values), load_spec(values)
        if law is None and load is None:
            return self.schema
        return _plugged_schema(self.schema, None if law is None else absolute_spec(law),
                               None if load is None else absolute_spec(load))  # fmt: skip

    def parameters(self, values: Mapping[str, Any] | None = None, **kw: Any) -> dict[str, Any]:
        """Validated values; besides the schema's, a force table as the massless link takes
        it: ``load_table`` (rows of crank angle in deg and force in N, or a CSV file of them,
        `recipdyn.model.load.read_load_table`) or ``pressure_table`` (a measured indicator
        diagram, a CSV file, `recipdyn.model.load.read_pressure_table`, with this run's bore,
        rod diameter and frame pressure). The table replaces the ``load`` (the table load
        component)."""
        from ...errors import ParameterError
        from ..registry import absolute_spec, is_spec

        v = {**(values or {}), **kw}
        table, ptab = v.pop("load_table", None), v.pop("pressure_table", None)
        for k in ("contact_law", "law", "load"):  # a user's file: found from any folder
            if is_spec(v.get(k)):
                v[k] = absolute_spec(v[k])
        if load_spec(v) is not None and (table is not None or ptab is not None):
            raise ParameterError(f"{'load_table' if table is not None else 'pressure_table'}: "
                                 f"not with load = {v['load']!r}, a load of your own (it "
                                 "gives its own force); allowed: load = 'table'")  # fmt: skip
        out = self.schema_for(v).validate(v)
        _resolve_joints(out)
        self.check(out)
        tab = self._table(out, table, ptab)
        if tab is not None:
            out["load_table"] = tab
        return out

    @staticmethod
    def _table(values: Mapping[str, Any], table: Any, ptab: Any) -> Any:
        from ...errors import ParameterError
        from ..load import read_load_table, read_pressure_table
        from ..parameters import _validate_table

        if table is not None and ptab is not None:
            raise ParameterError("pressure_table and load_table: give one of them")
        if ptab is not None:
            return read_pressure_table(ptab, bore=values["bore"],
                                       rod_diameter=values["rod_diameter"],
                                       frame_pressure=values["frame_pressure"])  # fmt: skip
        if table is None:
            return None
        if not isinstance(table, (list, tuple)):
            return read_load_table(table)
        rows = tuple(tuple(float(x) for x in row) for row in table)
        _validate_table(rows)
        return rows

    def load_part(self, values: Mapping[str, Any]):
        """The load component of this model for ``values`` (`load_part`)."""
        return load_part(values)

    def kernels(self, values: Mapping[str, Any]):
        """The generated glue of the joints and the load (`kernels`)."""
        return kernels(values, self.load_part(values))

    def events(self, values: Mapping[str, Any]) -> tuple[Event, ...]:
        joints = values["clearance_joints"]
        k = self.kernels(values)
        onset, record = k.event, k.reset
        if has_guide(values):
            return (Event("impact", onset, direction=-1, action="reset", reset=record,
                          description="contact onset or separation of a crosshead corner on "
                          "a guide shoe or at a worn pin (the smallest phased factor falls "
                          "through 0): at an onset the approach velocity is recorded for the "
                          "damping law"),)  # fmt: skip
        if stateful_user_load(values) is not None:
            return (Event("impact", onset, direction=-1, action="reset", reset=record,
                          description="contact onset or separation at a worn pin, or an event "
                          "of the load (one event function: the smallest of the factors falls "
                          "through 0): at an onset the approach velocity is recorded for the "
                          "damping law, the load's event resets its states"),)  # fmt: skip
        if joints == "both":
            return (Event("impact", onset, direction=-1, action="reset", reset=record,
                          description="contact onset or separation at either joint (the "
                          "smaller phased factor falls through 0): at an onset the approach "
                          "velocity is recorded for the damping law"),)  # fmt: skip
        where = "|e| = rc" if joints == "crank" else "|e_crosshead| = rc_crosshead"
        return (Event("impact", onset, direction=1, action="reset", reset=record,
                      description=f"contact onset ({where}, approaching): the approach "
                      "velocity is recorded for the damping law"),)  # fmt: skip

    def states(self, values: Mapping[str, Any]) -> tuple[tuple[str, str], ...]:
        """The joints' twelve states; with the guide's clearance, its eight after them; with a
        motor, the crank's three last (`MOTOR_STATES`)."""
        own = tuple(zip(STATE_NAMES, STATE_UNITS, strict=True))
        if has_guide(values):
            own = own + CLEARANCE.states + CLEARANCE.aux_states
        return own + self._load_states(values) + (MOTOR_STATES if has_motor(values) else ())

    def _load_states(self, values: Mapping[str, Any]) -> tuple[tuple[str, str], ...]:
        """A load's states: a load of a user's file, its states then its auxiliary ones (the
        dynamic valves' model adds its own)."""
        load = stateful_user_load(values)
        return () if load is None else (*load.states, *load.aux_states)

    #: Why Benettin's method is refused with the guide's clearance (a subclass that refuses it
    #: always says its own reason).
    lyapunov_refusal = GUIDE_REFUSAL

    def state_scale(self, values: Mapping[str, Any]) -> np.ndarray:
        """The default (``max(1, |y0|)``); with the guide's clearance, its lateral position
        0.02 m and tilt 0.01 rad (perturbations of a few percent put the crosshead ~1 mm into
        a shoe, as `compressor-guide`'s), the corners' approach velocities 1 mm/s."""
        s = np.maximum(1.0, np.abs(self.initial_state(values)))
        if has_guide(values):
            g = G_GUIDE
            s[g], s[g + 1] = 0.02, 0.01
            s[g + 4 : g + 8] = 1e-3
        return s

    def identity_values(self, values: Mapping[str, Any]) -> dict[str, Any]:
        """Without the guide's parameters while the guide is ideal (they have no effect then),
        so a sweep store of the contact joints keeps its digest."""
        inert = set() if has_motor(values) else set(_DRIVE_NAMES)
        if not has_guide(values):
            inert |= {"guide", *(p.name for p in GUIDE_PARAMS)}
        return {k: v for k, v in values.items() if k not in inert}

    def lyapunov_supported(self, values: Mapping[str, Any]) -> bool:
        """Not with the guide's clearance: its corners' saltation matrices have not been
        checked against differences of the flow (as the pins' have, with the crank
        prescribed and with a motor: tests/test_contact.py, tests/test_motor_lyapunov.py);
        nor with a load of a user's file that has states (nor for its events)."""
        return (self.lyapunov_refusal == GUIDE_REFUSAL and not has_guide(values)
                and stateful_user_load(values) is None)  # fmt: skip

    def tangent(self, values: Mapping[str, Any]) -> dict[str, Any]:
        """What the system says of its states beyond their names (`system`; the family's
        assembled one-throw machine takes it from here too): ``rhs_jac`` (whether the
        kernels' fused right-hand side and Jacobian is used), ``period`` (None with a motor:
        autonomous), ``aux_states`` (the last auxiliary states), ``aux`` and ``passive``.

        With a motor the approach velocities (8, 9) are auxiliary, not passive: the damping
        law reads them, so their tangent components must follow the flow through each
        onset's saltation matrix (held at 0, the tangent flow missed that dependence: off by
        several times its size after twelve impacts, tests/test_motor_lyapunov.py). The work
        integrals, the motor's included, are passive: nothing depends on them, and a
        component that acts on nothing but is rescaled with the vectors each interval grows
        without bound along a contracting one (the motor's work overflowed Benettin's vectors
        within a revolution)."""
        rigid = RIGID[values["clearance_joints"]]
        if has_motor(values):  # the crank's states last; the guide's corners' phases (not
            # its lateral position and tilt) and a load's states passive
            n = len(self.states(values))
            corners = range(G_GUIDE + 4, G_GUIDE + N_GUIDE_STATES) if has_guide(values) else ()
            return {"rhs_jac": True, "period": None, "aux_states": 1,
                    "aux": tuple(i for i in (8, 9) if i not in rigid),
                    "passive": (*rigid, I_WIN, I_WLOSS, *corners,
                                *range(first_load_state(values), n - 3), n - 1)}  # fmt: skip
        load = stateful_user_load(values)
        if load is not None or has_guide(values):  # a load's states after the joints' (and
            # the guide's)
            return {"rhs_jac": True, "period": self.period(values),
                    "aux_states": 4 if load is None else len(load.aux_states), "aux": (),
                    "passive": (*rigid, 8, 9, I_WIN, I_WLOSS)}  # fmt: skip
        return {"rhs_jac": True, "period": self.period(values), "aux_states": 4, "aux": (),
                "passive": (*rigid, I_WIN, I_WLOSS)}  # fmt: skip

    def system(self, values: Mapping[str, Any]) -> ODESystem:
        """The joints' kernels on their packed values (`tangent`: what the system says of
        its states)."""
        k = self.kernels(values)
        own = self.tangent(values)
        names, units = zip(*self.states(values), strict=True)
        return ODESystem(rhs=k.rhs, jac=k.jac, rhs_jac=k.rhs_jac if own["rhs_jac"] else None,
                         params=pack(values, self.load_part(values)), state_names=names,
                         state_units=units, period=own["period"], name=self.name,
                         events=self.events(values), aux_states=own["aux_states"],
                         aux=own["aux"], passive=own["passive"])  # fmt: skip

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        """Both eccentricities along the rod load as the massless link's equilibrium (rod in
        compression: the crank pin's e points from the crosshead to the crank, the crosshead
        pin's the other way), at rest relative to the journals; a rigid joint's are 0."""
        ang = values["e0_angle"]
        if ang is None:
            from ..mechanism.link import equilibrium_theta_c
            from ..parameters import CompressorParams

            keys = (
                *MECH,
                "rc",
                "load_amplitude",
                "load_sign",
                "load",
                *CYCLE_PARAMS,
                "gas",
                "suction_temperature",
            )
            cp = CompressorParams(rs=0.0, load_table=values.get("load_table"),
                                  **{k: values[k] for k in keys})  # fmt: skip
            load = user_load(values)  # a load of a user's file: its own values too
            extra = {} if load is None else {q.name: values[q.name] for q in load.params}
            force = None if stateful_user_load(values) is None else _initial_force(values)
            ang = equilibrium_theta_c(cp, extra=extra, force=force)
        ang2 = values["e0_angle_crosshead"]
        ang2 = ang + math.pi if ang2 is None else ang2
        y = np.zeros(len(STATE_NAMES))
        joints = values["clearance_joints"]
        if joints not in ("crosshead", "ideal"):
            e = values["e0_ratio"] * values["rc"]
            y[[0, 1, 4, 5]] = (e * math.cos(ang), e * math.sin(ang), values["edot0_x"],
                               values["edot0_y"])  # fmt: skip
        if joints not in ("crank", "ideal"):
            e = values["e0_ratio"] * values["rc_crosshead"]
            y[[2, 3]] = e * math.cos(ang2), e * math.sin(ang2)
        y[8] = y[9] = values["v_impact_min"]
        if self.tracks_separations(values):  # the phase: + in contact, - in free flight
            sign = 1.0 if values["e0_ratio"] >= 1.0 else -1.0
            y[8] = y[9] = sign * values["v_impact_min"]
        if has_guide(values):
            # the crosshead centred in its guide, level, moving along it; with no clearance
            # its corners touch the shoes already (in contact)
            sign = 1.0 if values["guide_clearance"] == 0 else -1.0
            g = np.zeros(N_GUIDE_STATES)
            g[4:] = sign * values["v_impact_min"]
            y = np.concatenate([y, g])
        load = stateful_user_load(values)
        if load is not None:  # a load of a user's file: its states at t = 0
            y0 = np.asarray(load.initial(values), dtype=np.float64).ravel()
            n = len(load.states) + len(load.aux_states)
            if y0.size != n:
                from ...errors import ParameterError

                raise ParameterError(f"load = {values['load']!r}: its initial gives {y0.size} "
                                     f"values for its {n} states")  # fmt: skip
            y = np.concatenate([y, y0])
        if has_motor(values):  # the crank at theta1_0 turning at omega, no work done yet
            y = np.concatenate([y, [float(values["theta1_0"]), float(values["omega"]), 0.0]])
        return y

    def tracks_separations(self, values: Mapping[str, Any]) -> bool:
        """Whether the event also locates separations (the phase is then the sign of
        ``v_impact``; [`phased_factor`][recipdyn.model.joints.pins.phased_factor]): with
        clearance at both pins, with the guide's clearance, or with a load of a user's file
        that has states (its events share the event function)."""
        return (values["clearance_joints"] == "both" or has_guide(values)
                or stateful_user_load(values) is not None)  # fmt: skip

    def period(self, values: Mapping[str, Any]) -> float:
        return 2.0 * math.pi / float(values["omega"])

    def outputs(self, values: Mapping[str, Any], t: np.ndarray, y: np.ndarray
                ) -> dict[str, Signal]:  # fmt: skip
        s = self.system(values)
        t = np.ascontiguousarray(t, dtype=float)
        y = np.ascontiguousarray(y, dtype=float)
        j = self.kernels(values).observe(t, y, s.params)
        r, l, d, w = (float(values[k]) for k in ("r", "l", "d", "omega"))
        th1 = float(values["theta1_0"]) + w * t
        motor = has_motor(values)
        alpha = 0.0
        guide = has_guide(values)
        if motor:  # the crank's angle, speed and acceleration: the observer's (after the guide's)
            mc = 30 if guide else 21
            th1, w, alpha = j[:, mc], j[:, mc + 1], j[:, mc + 2]
        e1x, e1y, e2x, e2y = (y[:, i] for i in range(4))
        e2ydd = j[:, 17]
        if guide:  # the small end follows the crosshead pin's lateral position
            e2y, e2ydd = e2y + y[:, G_GUIDE], e2ydd + j[:, 21]
        s2 = (e2y - d - r * np.sin(th1) - e1y) / l
        c2 = np.sqrt(1.0 - s2**2)
        th2d = j[:, 18]
        # theta2'' from sin(theta2)'' = (e2y'' - By'') / l, By'' = -r w^2 sin(theta1) + e1y''
        # (with a free crank By'' has r alpha cos(theta1) too, and x3'' -r alpha sin(theta1))
        s2dd = (e2ydd + r * w**2 * np.sin(th1) - r * alpha * np.cos(th1) - j[:, 15]) / l
        th2dd = (s2dd + s2 * th2d**2) / c2
        x3 = r * np.cos(th1) + e1x + l * c2 - e2x
        a3 = (-r * w**2 * np.cos(th1) - r * alpha * np.sin(th1) + j[:, 14]
              - l * (c2 * th2d**2 + s2 * th2dd) - j[:, 16])  # fmt: skip
        if not motor:
            en = energy(values, t, y)
        else:  # the crank and the drive: I_crank w^2 / 2 + g S_crank sin(theta1)
            en = energy(values, t, y, th1, w)
            ic, sc = _crank_slice(values)
            en["mechanical"] = (en["mechanical"] + 0.5 * ic * w**2
                                + float(values["g"]) * sc * np.sin(th1))  # fmt: skip
        sig = {
            "x": Signal(x3, "m", "crosshead displacement x3"),
            "v": Signal(j[:, 19], "m/s", "crosshead velocity"),
            "a": Signal(a3, "m/s**2", "crosshead acceleration"),
            "theta1": Signal(th1, "rad", "crank angle"),
            "theta2": Signal(np.arcsin(s2), "rad", "connecting-rod angle"),
            "gas_force": Signal(j[:, 20], "N", "gas force on the crosshead along +x"),
            "energy": Signal(en["mechanical"] + en["elastic"], "J",
                             "kinetic + gravity energy of rod and crosshead + contact elastic"),
            **cycle_outputs(values, th1),
        }  # fmt: skip
        if guide:
            en_g = j[:, 28]
            sig["energy"] = Signal(en["mechanical"] + en["elastic"] + en_g, "J",
                                   "kinetic + gravity energy of rod and crosshead + contact "
                                   "elastic (pins and guide shoes)")  # fmt: skip
            sig.update(_guide_outputs(y, j))
        joints = values["clearance_joints"]
        for key, where, row, (ix, iy), rc in (
            ("", "crank-pin", 0, (0, 1), "rc"),
            ("_crosshead", "crosshead-pin", 1, (2, 3), "rc_crosshead"),
        ):  # fmt: skip
            if joints not in ("both", where.split("-")[0]):
                continue
            ex, ey = y[:, ix], y[:, iy]
            rho = np.hypot(ex, ey)
            c = float(values[rc])
            delta = rho - c
            f = j[:, 7 * row : 7 * row + 7]
            sig.update({
                "ex" + key: Signal(ex, "m", f"{where} eccentricity x (bearing centre - journal "
                                   "centre)"),
                "ey" + key: Signal(ey, "m", f"{where} eccentricity y"),
                "eccentricity_ratio" + key: Signal(rho / c, "", f"{where} |e| / {rc}"),
                "delta" + key: Signal(delta, "m", f"{where} penetration |e| - {rc} (> 0: in "
                                      "contact)"),
                "contact" + key: Signal((delta > 0).astype(float), "", f"{where} contact: 1 in "
                                        "contact, 0 in free flight"),
                "normal_force" + key: Signal(f[:, 4], "N", f"{where} normal force on the "
                                             "bearing (contact + film)"),
                "tangential_force" + key: Signal(f[:, 5], "N", f"{where} tangential force on "
                                                 "the bearing"),
                "joint_force_x" + key: Signal(f[:, 0], "N", f"{where} joint force on the rod, "
                                              "x"),
                "joint_force_y" + key: Signal(f[:, 1], "N", f"{where} joint force on the rod, "
                                              "y"),
                "joint_force" + key: Signal(np.hypot(f[:, 0], f[:, 1]), "N", f"{where} joint "
                                            "force magnitude"),
            })  # fmt: skip
        if motor:
            m = len(y[0]) - 3
            d = self.system(values)
            from ..base import rhs_series

            tm = rhs_series(d.rhs, d.params, t, y)[:, m + 2] / w
            sig.update({
                "omega1": Signal(w, "rad/s", "crank speed"),
                "alpha1": Signal(alpha, "rad/s**2", "crank angular acceleration"),
                "motor_torque": Signal(tm, "N*m", "motor torque at the crank"),
                "W_motor": Signal(y[:, m + 2], "J", "work done by the motor since t = 0"),
                "W_gas": Signal(y[:, I_WIN] - y[:, m + 2], "J",
                                "work done by the gas on the crosshead since t = 0"),
            })  # fmt: skip
            sig["energy"] = Signal(sig["energy"].values, "J", "kinetic + gravity energy of "
                                   "crank (with the drive), rod and crosshead + contact "
                                   "elastic")  # fmt: skip
        if "ex" not in sig:  # an ideal crank pin: no eccentricity (the section signals name it)
            zero = np.zeros_like(t)
            sig["ex"] = Signal(zero, "m", "crank-pin eccentricity x (ideal pin: 0)")
            sig["ey"] = Signal(zero.copy(), "m", "crank-pin eccentricity y (ideal pin: 0)")
        return sig

    def law_range(self, values: Mapping[str, Any], ds: Any) -> str:
        """The point-contact law beyond its range: at a joint whose deepest penetration gives
        an overlap arc (`overlap_half_angle`) wider than `HERTZ_ARC_LIMIT_DEG`."""
        out = []
        for key, rc, rj, where in (("", "rc", "journal_radius", "crank pin"),
                                   ("_crosshead", "rc_crosshead", "crosshead_pin_radius",
                                    "crosshead pin")):  # fmt: skip
            if "delta" + key not in ds:
                continue
            pen = float(max(np.nanmax(ds["delta" + key].values), 0.0))
            c = float(values[rc])
            arc = overlap_half_angle(float(values[rj]), c, pen)
            if arc > HERTZ_ARC_LIMIT_DEG:
                out.append(f"the {where} (+-{arc:.3g} deg)")
        if not out:
            return ""
        # (one short line: the why, with its sources, is docs/contact.md's "contact arc")
        return (f"the point-contact law {values['contact_law']!r} is out of its range (contact "
                f"arc > +-{HERTZ_ARC_LIMIT_DEG:.3g} deg, Johnson 1985 sec. 4.1) at "
                f"{' and '.join(out)}: forces are the model's, not a real bearing's "
                "(docs/contact.md)")  # fmt: skip

    def run_summary(self, values: Mapping[str, Any], ds: Any) -> dict[str, float]:
        """Per clearance joint (suffix ``_crosshead`` for the crosshead pin): impacts (count,
        per revolution, approach velocities), maximum penetration (in m and as a fraction of
        the clearance) with the half-angle of the overlap arc there
        ([`overlap_half_angle`][recipdyn.model.components.contact_model.overlap_half_angle]:
        how far the contact is from the small contact the point-contact law assumes), contact
        fraction (free flight is the rest), peak and RMS joint force; the energy lost in the
        joints and the energy-balance residual over the recorded interval; the peak crosshead
        acceleration."""
        out: dict[str, float] = {}
        t = ds["time"].values
        revs = (t[-1] - t[0]) / self.period(values) if t.size > 1 else float("nan")
        if has_guide(values):
            ds, guide_summary = _guide_summary(values, ds, revs)
            out.update(guide_summary)
        joints = values["clearance_joints"]
        active = [("", 0, 1, 4, 5, "rc")] if joints not in ("crosshead", "ideal") else []
        if joints not in ("crank", "ideal"):
            active.append(("_crosshead", 2, 3, 6, 7, "rc_crosshead"))
        if "impact_time" in ds and stateful_user_load(values) is not None:
            # a load's event (its reset) leaves the joints' phases, v_impact, as they were
            moved = np.column_stack([ds[f"impact_{k}"].values != ds[f"impact_{k}_after"].values
                                     for k in STATE_NAMES[8:10]]).any(axis=1)  # fmt: skip
            out["load_events"] = float((~moved).sum())
            ds = ds.isel(impact_event=np.flatnonzero(moved))
        has_ev = "impact_time" in ds
        if has_ev:
            ev = np.column_stack([ds[f"impact_{k}"].values for k in STATE_NAMES[:8]])
            rel = np.column_stack([np.abs(np.hypot(ev[:, 0], ev[:, 1]) / values["rc"] - 1.0),
                                   np.abs(np.hypot(ev[:, 2], ev[:, 3])
                                          / values["rc_crosshead"] - 1.0)])  # fmt: skip
            owner = np.argmin(rel, axis=1) if joints == "both" else np.full(
                len(ev), 0 if joints == "crank" else 1)  # fmt: skip
        for key, ix, iy, iu, iv, rc in active:
            if has_ev:
                mine = owner == (0 if key == "" else 1)
                vr = (ev[mine, ix] * ev[mine, iu] + ev[mine, iy] * ev[mine, iv]) / np.hypot(
                    ev[mine, ix], ev[mine, iy])  # fmt: skip
                vr = vr[vr > 0]  # onsets (with both joints the separations are events too)
            else:
                vr = np.empty(0)
            force = ds["joint_force" + key].values
            pen = float(max(ds["delta" + key].values.max(), 0.0))
            c = float(values[rc])
            rj = float(values["journal_radius" if key == "" else "crosshead_pin_radius"])
            out.update({
                f"impacts{key}": float(vr.size),
                f"impacts_per_revolution{key}": vr.size / revs if revs > 0 else float("nan"),
                f"impact_velocity_mean{key}_m_s": float(vr.mean()) if vr.size else 0.0,
                f"impact_velocity_max{key}_m_s": float(vr.max()) if vr.size else 0.0,
                f"max_penetration{key}_m": pen,
                f"max_penetration_ratio{key}": pen / c,
                f"contact_arc{key}_deg": overlap_half_angle(rj, c, pen),
                f"contact_fraction{key}": float(ds["contact" + key].values.mean()),
                f"peak_joint_force{key}_N": float(force.max()),
                f"rms_joint_force{key}_N": float(np.sqrt(np.mean(force**2))),
            })  # fmt: skip
        E = ds["energy"].values
        w_in, w_loss = ds["W_in"].values, ds["W_loss"].values
        bal = E - E[0] - ((w_in - w_in[0]) - (w_loss - w_loss[0]))
        out.update({
            "energy_lost_in_joints_J": float(w_loss[-1] - w_loss[0]),
            "energy_balance_residual": float(np.abs(bal).max() / max(np.abs(E).max(), 1e-300)),
            "peak_abs_a_m_s2": float(np.abs(ds["a"].values).max()),
        })  # fmt: skip
        out.update(cycle_summary(values, ds))
        return out


def _guide_outputs(y: np.ndarray, j: np.ndarray) -> dict[str, Signal]:
    """The guide's outputs from its states and the observer's columns (21-29)."""
    g = G_GUIDE
    return {
        "guide_y": Signal(y[:, g], "m", "crosshead lateral position from the guide's "
                          "centreline (+ up)"),
        "guide_v": Signal(y[:, g + 2], "m/s", "crosshead lateral velocity"),
        "guide_acc": Signal(j[:, 21], "m/s**2", "crosshead lateral acceleration (what an "
                            "accelerometer on the guide sees of the knock)"),
        "tilt": Signal(y[:, g + 1], "rad", "crosshead tilt in the guide"),
        "shoe_force_upper": Signal(j[:, 25], "N", "normal force of the upper shoe"),
        "shoe_force_lower": Signal(j[:, 26], "N", "normal force of the lower shoe"),
        "side_force": Signal(j[:, 23], "N", "net side force of the guide on the crosshead "
                             "(+ up)"),
        "guide_friction_force": Signal(j[:, 22], "N", "friction force of the shoes on the "
                                       "crosshead along +x"),
        "guide_contact": Signal((j[:, 27] > 0).astype(float), "", "1 while a corner touches "
                                "a shoe"),
    }  # fmt: skip


def _guide_summary(values: Mapping[str, Any], ds: Any, revs: float) -> tuple[Any, dict]:
    """The record without the guide's events (an event whose corners changed phase), and
    the guide's figures: shoe impacts (count, per revolution, largest approach velocity),
    the peak lateral acceleration, the largest lateral excursion, the contact fraction."""
    out: dict[str, float] = {}
    if "impact_time" in ds:
        names = [f"v_impact_guide_{k}" for k in range(1, 5)]
        before = np.column_stack([ds[f"impact_{k}"].values for k in names])
        after = np.column_stack([ds[f"impact_{k}_after"].values for k in names])
        mine = (before != after).any(axis=1)
        onset = (after > 0) & (before <= 0)
        vel = after[onset]
        out.update({
            "impacts_guide": float(onset.sum()),
            "impacts_per_revolution_guide": onset.sum() / revs if revs > 0 else float("nan"),
            "impact_velocity_max_guide_m_s": float(vel.max()) if vel.size else 0.0,
        })  # fmt: skip
        ds = ds.isel(impact_event=np.flatnonzero(~mine))
    c = float(values["guide_clearance"])
    excursion = float(np.abs(ds["guide_y"].values).max())
    out.update({
        "peak_abs_guide_acc_m_s2": float(np.abs(ds["guide_acc"].values).max()),
        "max_lateral_excursion_m": excursion,
        "max_lateral_excursion_ratio": excursion / c if c > 0 else float("nan"),
        "guide_contact_fraction": float(ds["guide_contact"].values.mean()),
    })  # fmt: skip
    return ds, out
