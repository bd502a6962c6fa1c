r"""The assembler: a machine and its parameter values, resolved once into a configuration.

`assemble` takes a `recipdyn.model.machine.Machine` and its validated values (namespaced:
``throw2.rc``; a machine of one throw, the compressor's names) and returns a `Configuration`:
the components each part chose, the named `Layout` of the state, the parameter vector and the
observer's columns, the packed parameter vector, and the compiled kernels (right-hand side,
Jacobian, event, reset, observer) of one module generated from the template of the shaft's
drive (`recipdyn.model.assembler.generate`).

The order of the parameter vector: the shaft's drive and torque law, then per throw its
mechanism (`recipdyn.model.mechanism.link.MECHANISM`), its phase and its load's difference
steps, then the frame's slice (a machine with a ``[frame]``), then per interstage volume its
slice (`recipdyn.model.components.interstage`), then the flexible shaft's (a machine with a
``[shaft.torsion]``, `recipdyn.model.shaft.flexible`), then per throw its load's slice (last:
a table's length varies, and every offset before it stays a constant of the generated
module). The order of the state: per throw its clearance angle and rate; with a motor the
crank's angle and speed (on a flexible shaft the rotor's, then the other nodes' angles and
speeds along the shaft) and the motor's work (and the shaft's dissipation), then per throw
the gas's work on its crosshead; then the frame's states and work integrals (with a frame);
then per throw its load's states; then per interstage its pressure (``interstage1.p``); then
per throw its load's auxiliary states. With one throw this is the order of the compressor's
state before the assembler (``theta_c, thetadot_c[, theta1, omega1, W_motor, W_gas], <the
valves' states>, <their counters>``), so records and configs of one throw keep their
meaning.

The throws of one machine carry one kind of load and one set of equations (the template binds
one set of load roles); their parameters (geometry, masses, phases, cylinders, faults) differ
freely.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np

from ...errors import ParameterError
from ..components.contract import Component, resolve_component, source_digest
from ..machine.description import Machine
from ..mechanism.link import MECHANISM, STATES
from . import generate
from .layout import Layout, SlicesBuilder

__all__ = ["Configuration", "assemble", "bindings", "throw_values", "load_of", "motor_of",
           "frame_values", "KERNELS", "FAMILIES", "family_of"]  # fmt: skip

#: The massless-link throw's compiled functions.
KERNELS = "recipdyn.model.mechanism.link_kernels"

#: A state's kind: a degree of freedom, a work integral (auxiliary and passive: nothing
#: depends on it), a load's counter (auxiliary), the frame's (passive: the throws do not
#: depend on it, `recipdyn.model.frame.body`, one-way coupling).
DOF, WORK, COUNTER, FRAME = "dof", "work", "counter", "frame"
#: The frame's compiled roles.
FRAME_KERNELS = "recipdyn.model.frame.kernels"


#: A throw's mechanism family by its ``crank_joint``: the massless link (an ideal pin is the
#: link with rc = 0: `KERNELS`, template ``prescribed`` or ``motor``) or the contact joints
#: (`recipdyn.model.assembler.contact_throws`, template ``contact_throws``).
FAMILIES = {"link": "link", "ideal": "link", "contact": "contact", "lubricated": "contact"}


def throw_family(t) -> str:
    """A throw's mechanism family: its crank pin's (`FAMILIES`); a worn crosshead pin or
    the guide's clearance make it the contact joints' whatever its crank pin."""
    if (t.crosshead_joint, t.guide) != ("ideal", "ideal"):
        return "contact"
    return FAMILIES[t.crank_joint]


def family_of(machine: Machine) -> str:
    """The family that builds the machine: the massless link's (template ``prescribed`` or
    ``motor``) when every throw is of the link family, else the contact joints'
    (`recipdyn.model.assembler.contact_throws`), which hosts ideal throws beside its own as a
    throw of another kind (each one a one-throw module of the massless link called on its
    slice)."""
    return "contact" if any(throw_family(t) == "contact" for t in machine.throws) else "link"


def frame_values(values: Mapping[str, Any]) -> dict[str, Any]:
    """The frame's values under their names inside ``frame.`` (``mass``, ``mount2.k_x``)."""
    return {n[len("frame.") :]: v for n, v in values.items() if n.startswith("frame.")}


def throw_values(machine: Machine, values: Mapping[str, Any], k: int) -> dict[str, Any]:
    """Throw ``k``'s values under the compressor's names: its own, its stage's and the
    shaft's, with its structure (``load``, ``equations``, ``drive``, ``motor``) and its
    ``phase`` in its own axes (the crank's lead less its ``cylinder_angle``). In a machine of
    one throw: ``values`` themselves (and ``phase`` 0)."""
    t = machine.throws[k]
    if machine.flat:
        out = {"phase": 0.0, **values}
    else:
        pre, spre = f"{t.name}.", f"{t.stage}."
        out = {n[len(pre) :]: v for n, v in values.items() if n.startswith(pre)}
        out.update({n[len(spre) :]: v for n, v in values.items() if n.startswith(spre)})
        out.update({n[len("shaft.") :]: v for n, v in values.items() if n.startswith("shaft.")})
        fed = machine.interstage_into(t.stage)
        if fed is not None:  # its suction line: the interstage's (the initial and set values)
            out["suction_pressure"] = values[f"{fed.upstream}.discharge_pressure"]
            out["suction_temperature"] = values[f"{fed.name}.cooler_temperature"]
    for key, value in (
        ("load", t.load),
        ("equations", t.equations),
        ("drive", machine.shaft.drive),
        ("motor", machine.shaft.motor),
    ):
        out.setdefault(key, value)  # (the compressor of one throw holds them as values)
    if t.crank_joint == "ideal":
        out["rc"] = 0.0
    if t.cylinder_angle:  # its equations run in its own axes, turned with its cylinder
        out["phase"] = float(out["phase"]) - t.cylinder_angle
        if "g" in out:  # ... where the weight (down in the frame) lies along cos(angle) * -y
            out["g"] = float(out["g"]) * round(math.cos(t.cylinder_angle))
    return out


def load_of(local: Mapping[str, Any]) -> Component:
    """The load component a throw's values choose (a table when one is given or for a real
    gas's cycle, the dynamic valves, or a user's component)."""
    from ..components.load import LOADS, VALVES, load_component

    if local.get("load") == "valves":
        return VALVES
    if ":" in str(local.get("load", "")):
        return resolve_component("load", local["load"], LOADS)
    return load_component(local)


def motor_of(machine: Machine) -> Component | None:
    """The motor's torque law (None with a prescribed speed)."""
    from ..components.drive import MOTORS

    if machine.shaft.drive != "motor":
        return None
    return resolve_component("motor", machine.shaft.motor, MOTORS)


def _torque_values(machine: Machine, locals_: list[dict], motor: Component) -> dict[str, Any]:
    """The values the torque law packs: a constant torque's default is the mean load torque
    of every throw (each throw's own over a revolution of its ideal mechanism; the dynamic
    valves' as of the ideal-valve cycle of the same cylinder)."""
    from ..components.drive import mean_load_torque

    local = dict(locals_[0])
    if motor.name == "constant" and local.get("motor_torque") is None:
        total = 0.0
        for v in locals_:
            if v.get("load") == "valves":
                v = {**v, "load": "cycle", "gas": "ideal", "load_table": None}
            total += mean_load_torque(v)
        local["motor_torque"] = total
    return local


@dataclass(frozen=True)
class Configuration:
    """A machine resolved once for its values: what `assemble` returns.

    Attributes
    ----------
    machine : Machine
    layout : Layout
        Where each part's values live: ``layout.state["throw2.theta_c"]``,
        ``layout.params["throw1.load"]``, ``layout.outputs["throw2.gas_force"]`` (the
        observer's column).
    params : ndarray
        The packed parameter vector.
    kernels : module
        The generated module: ``rhs``, ``jac``, ``rhs_jac`` (a prescribed crank, loads without
        states), ``event`` and ``reset`` (loads with states), ``observe(t, y, p)``; written
        and imported when first asked for (the layout and the parameters need no numba).
    loads : tuple of Component
        Each throw's load.
    motor : Component or None
        The motor's torque law.
    kinds : tuple of str
        Each state's kind (``dof``, ``work``, ``counter``).
    """

    machine: Machine
    layout: Layout
    params: np.ndarray
    loads: tuple[Component, ...]
    motor: Component | None
    kinds: tuple[str, ...]
    drive: Component

    def bindings(self) -> tuple[str, dict, dict, str, str]:
        """The generated module's template, roles, constants, stem and note
        (`bindings`)."""
        return bindings(self.machine, self.layout, self.loads[0], self.motor, self.drive)

    @property
    def kernels(self) -> ModuleType:
        mod = self.__dict__.get("_kernels")
        if mod is None:
            mod = _kernels(self.machine, self.layout, self.loads[0], self.motor, self.drive)
            object.__setattr__(self, "_kernels", mod)
        return mod

    @property
    def has_states(self) -> bool:
        """Whether the loads have states (and so an event and a reset)."""
        return bool(self.loads[0].states)

    @property
    def aux_states(self) -> int:
        """The trailing auxiliary states (not degrees of freedom)."""
        n = 0
        for kind in reversed(self.kinds):
            if kind == DOF:
                break
            n += 1
        return n

    def passive(self, values_of_throws: list[Mapping[str, Any]]) -> tuple[int, ...]:
        """The states left out of the tangent space: the work integrals, the frame's states
        (nothing depends on them), and with a motor the clearance angle and rate of a throw
        with an ideal pin (rc = 0: they never move)."""
        out = [i for i, kind in enumerate(self.kinds) if kind in (WORK, FRAME)]
        if self.motor is not None:
            for t, local in zip(self.machine.throws, values_of_throws, strict=True):
                if float(local["rc"]) == 0.0:
                    s = self.layout.state.start(f"{t.name}.mechanism")
                    out += [s, s + 1]
        return tuple(sorted(out))


def _steps(load: Component, local: Mapping[str, Any]) -> np.ndarray:
    """A load's central-difference steps per state, ``(rel, abs)`` pairs: ``h = 1e-7 (|y| (1
    + rel) + abs)`` (the load's ``steps``, else relative to 1)."""
    n = len(load.states)
    if load.steps is not None:
        out = np.asarray(load.steps(local), dtype=np.float64).ravel()
        if out.size != 2 * n:
            raise ValueError(f"load {load.name!r}: steps gives {out.size} values, not {2 * n}")
        return out
    return np.tile([0.0, 1.0], n)


def assemble(machine: Machine, values: Mapping[str, Any]) -> Configuration:
    """Resolve ``machine`` at its validated ``values`` (module docstring)."""
    from ..components.drive import DRIVES

    n = len(machine.throws)
    locals_ = [throw_values(machine, values, k) for k in range(n)]
    loads = tuple(load_of(v) for v in locals_)
    for t, load in zip(machine.throws[1:], loads[1:], strict=True):
        if load is not loads[0] or t.equations != machine.throws[0].equations:
            raise ParameterError(
                f"{t.name}: load {load.name!r} ({t.equations}) beside {machine.throws[0].name}'s "
                f"{loads[0].name!r} ({machine.throws[0].equations}): the throws of a machine "
                "carry one kind of load and one set of equations today (their parameters "
                "differ freely)"
            )
    drive = DRIVES[machine.shaft.drive]
    motor = motor_of(machine)
    load = loads[0]

    # the parameter vector
    pv = SlicesBuilder()
    chunks: list[np.ndarray] = []

    def put(part: str, values_: np.ndarray, names=None) -> slice:
        arr = np.asarray(values_, dtype=np.float64).ravel()
        chunks.append(arr)
        return pv.add(part, names) if names is not None else pv.reserve(part, arr.size)

    shaft_local = locals_[0]
    put("shaft.drive", drive.pack(shaft_local))
    if motor is not None:
        put("shaft.motor", motor.pack(_torque_values(machine, locals_, motor)))
    for t, local in zip(machine.throws, locals_, strict=True):
        pre = machine.prefix(t.name)
        put(f"{t.name}.mechanism", [local[k] for k in MECHANISM],
            [(pre + k, "") for k in MECHANISM])  # fmt: skip
        put(f"{t.name}.phase", [local["phase"]], [(pre + "phase", "rad")])
        put(f"{t.name}.steps", _steps(load, local) if load.states else np.zeros(0))
    if machine.frame is not None:
        from ..frame.body import pack as frame_pack

        put("frame", frame_pack(machine, frame_values(values)))
    for i in machine.interstages:
        from ..components.interstage import INTERSTAGE

        upstream = next(v for t, v in zip(machine.throws, locals_, strict=True)
                        if t.stage == i.upstream)  # fmt: skip
        own = {k[len(i.name) + 1 :]: v for k, v in values.items() if k.startswith(f"{i.name}.")}
        put(i.name, INTERSTAGE.pack({**own, "gas_constant": upstream["gas_constant"]}),
            [(f"{i.name}.{k}", u) for k, u in (("volume", "m**3"), ("cooler_temperature", "K"),
                                               ("gas_constant", "J/(kg*K)"))])  # fmt: skip
    if machine.shaft.torsion:
        from ..shaft.flexible import pack as torsion_pack

        arr, names = torsion_pack(machine, values)
        put("shaft.torsion", arr, names)
    for t, local in zip(machine.throws, locals_, strict=True):
        put(f"{t.name}.load", load.pack(local))
    params = pv.build()

    # the state
    sv = SlicesBuilder()
    kinds: list[str] = []

    def place(part: str, entries, kind: str) -> slice:
        entries = tuple(entries)
        kinds.extend([kind] * len(entries))
        return sv.add(part, entries)

    for t in machine.throws:
        pre = machine.prefix(t.name)
        place(f"{t.name}.mechanism", ((pre + s, u) for s, u in STATES), DOF)
    if motor is not None:
        place("shaft", (("theta1", "rad"), ("omega1", "rad/s")), DOF)
        work = [("W_motor", "J")]
        if machine.shaft.torsion:
            from ..shaft.flexible import state_entries

            place("shaft.nodes", state_entries(machine), DOF)
            work.append((machine.prefix("shaft") + "W_shaft_damping", "J"))
        place("shaft.work", work, WORK)
        for t in machine.throws:
            place(f"{t.name}.work", ((machine.prefix(t.name) + "W_gas", "J"),), WORK)
    if machine.frame is not None:
        from ..frame.body import STATES as FRAME_STATES
        from ..frame.body import WORK as FRAME_WORK

        place("frame", ((f"frame.{s}", u) for s, u in FRAME_STATES), FRAME)
        place("frame.work", ((f"frame.{s}", u) for s, u in FRAME_WORK), WORK)
    for t in machine.throws:
        pre = machine.prefix(t.name)
        place(f"{t.name}.load", ((pre + s, u) for s, u in load.states), DOF)
    for i in machine.interstages:
        place(i.name, ((f"{i.name}.p", "Pa"),), DOF)
    for t in machine.throws:
        pre = machine.prefix(t.name)
        place(f"{t.name}.load_aux", ((pre + s, u) for s, u in load.aux_states), COUNTER)
    state = sv.build()

    # the observer's columns
    ov = SlicesBuilder()
    ov.add("shaft", (("theta1", "rad"), ("omega1", "rad/s")))
    for t in machine.throws:
        ov.add(t.name, ((f"{t.name}.theta1", "rad"), (f"{t.name}.gas_force", "N"),
                        (f"{t.name}.crank_torque", "N*m")))  # fmt: skip
    if machine.shaft.torsion:
        from ..shaft.flexible import section_names

        ov.add("shaft.sections", ((f"{q}{x}", u) for q in section_names(machine)
                                  for x, u in (("twist", "rad"), ("torque", "N*m"))))  # fmt: skip
    outputs = ov.build()
    layout = Layout(state, params, outputs)

    return Configuration(machine, layout, np.concatenate(chunks) if chunks else np.zeros(0),
                         loads, motor, tuple(kinds), drive)  # fmt: skip


def _load_roles(load: Component) -> dict[str, tuple[str, str]]:
    absent = ("recipdyn.model.assembler.generate", "absent")
    if load.states:
        return {"load_force": absent,
                "load_state_force": (load.module, load.kernel("state_force")),
                "load_rhs": (load.module, load.kernel("state_rhs")),
                "load_event": (load.module, load.kernel("event")),
                "load_reset": (load.module, load.kernel("reset"))}  # fmt: skip
    return {"load_force": (load.module, load.kernel("force")), "load_state_force": absent,
            "load_rhs": absent, "load_event": absent, "load_reset": absent}  # fmt: skip


def _frame_roles(frame: bool) -> dict[str, tuple[str, str]]:
    if not frame:
        absent = ("recipdyn.model.assembler.generate", "absent")
        return {"shaking": absent, "frame_load": absent, "frame_rhs": absent}
    return {"shaking": (KERNELS, "shaking"), "frame_load": (FRAME_KERNELS, "throw_load"),
            "frame_rhs": (FRAME_KERNELS, "frame_rhs")}  # fmt: skip


def _torsion_roles(torsion: bool) -> dict[str, tuple[str, str]]:
    if not torsion:
        absent = ("recipdyn.model.assembler.generate", "absent")
        return {"shaft_nodes": absent, "shaft_section": absent}
    kernels = "recipdyn.model.shaft.kernels"
    return {"shaft_nodes": (kernels, "nodes_rhs"), "shaft_section": (kernels, "section")}


def _torsion_constants(machine: Machine, layout: Layout) -> dict[str, Any]:
    """``TORSION``, ``N_NODES``, the shaft's slice, its dissipation's state, each throw's
    node (its angle's state; the crank's on a rigid shaft) and the sections' first observer
    column."""
    st = layout.state
    if not machine.shaft.torsion:
        return {"TORSION": False, "N_NODES": 1, "TORSION_PARAMS": 0, "SHAFT_DAMPING": 0,
                "THROW_NODE": np.full(len(machine.throws), st["theta1"], dtype=np.int64),
                "OBS_SECTION": 0}  # fmt: skip
    # the role reads node j at CRANK + 2 j: the other nodes follow the rotor's states
    assert st.start("shaft.nodes") == st["theta1"] + 2, "the nodes are contiguous"
    node = np.array([st[machine.prefix(t.name) + "theta_shaft"] for t in machine.throws],
                    dtype=np.int64)  # fmt: skip
    return {"TORSION": True, "N_NODES": 2 + len(machine.throws),
            "TORSION_PARAMS": layout.params.start("shaft.torsion"),
            "SHAFT_DAMPING": st[machine.prefix("shaft") + "W_shaft_damping"],
            "THROW_NODE": node, "OBS_SECTION": layout.outputs.start("shaft.sections")}  # fmt: skip


def _interstage_roles(machine: Machine, load: Component) -> dict[str, tuple[str, str]]:
    """The roles of the interstage volumes and of the loads between their lines (absent
    without an interstage)."""
    from ..components.interstage import INTERSTAGE

    names = ("load_rhs_lines", "load_lines", "load_flows", "interstage_line", "interstage_rate")
    if not machine.interstages:
        return dict.fromkeys(names, ("recipdyn.model.assembler.generate", "absent"))
    return {"load_rhs_lines": (load.module, load.kernel("state_rhs_lines")),
            "load_lines": (load.module, load.kernel("lines")),
            "load_flows": (load.module, load.kernel("flows")),
            "interstage_line": (INTERSTAGE.module, INTERSTAGE.kernel("line")),
            "interstage_rate": (INTERSTAGE.module, INTERSTAGE.kernel("rate"))}  # fmt: skip


def _interstage_constants(machine: Machine, layout: Layout) -> dict[str, Any]:
    """``INTERSTAGE``, ``N_INTERSTAGES``, each interstage's state and slice, each throw's
    interstage in and out (``-1``: a set line; an empty array holds one unused ``-1``)."""
    names = [i.name for i in machine.interstages]

    def index(found) -> int:
        return -1 if found is None else names.index(found.name)

    def arr(values) -> np.ndarray:
        return np.array(list(values) or [-1], dtype=np.int64)

    return {
        "INTERSTAGE": bool(names),
        "N_INTERSTAGES": len(names),
        "IS_STATE": arr(layout.state[f"{n}.p"] for n in names),
        "IS_PARAM": arr(layout.params.start(n) for n in names),
        "THROW_IN": arr(index(machine.interstage_into(t.stage)) for t in machine.throws),
        "THROW_OUT": arr(index(machine.interstage_from(t.stage)) for t in machine.throws),
    }


def _kernels(machine: Machine, layout: Layout, load: Component, motor: Component | None,
             drive: Component) -> ModuleType:  # fmt: skip
    """The generated module of the configuration (`bindings`)."""
    return generate.module(*bindings(machine, layout, load, motor, drive))


def bindings(machine: Machine, layout: Layout, load: Component, motor: Component | None,
             drive: Component) -> tuple[str, dict, dict, str, str]:  # fmt: skip
    """``(template, roles, constants, stem, note)`` of a configuration: its template's roles
    bound to the chosen components' functions, its constants from the layout."""
    st, pv = layout.state, layout.params
    throws = machine.throws

    def starts(slices, suffix: str) -> np.ndarray:
        return np.array([slices.start(f"{t.name}.{suffix}") for t in throws], dtype=np.int64)

    has_states = bool(load.states)
    frame = machine.frame is not None
    constants: dict[str, Any] = {
        "FRAME": frame,
        "FRAME_PARAMS": pv.start("frame") if frame else 0,
        "FRAME_STATE": st.start("frame") if frame else 0,
        "FRAME_WORK": st.start("frame.work") if frame else 0,
        "LOAD_STATES": has_states,
        "N_THROWS": len(throws),
        "SHAFT": pv.start("shaft.drive"),
        "THROW_STATE": starts(st, "mechanism"),
        "THROW_MECH": starts(pv, "mechanism"),
        "THROW_PHASE": starts(pv, "phase"),
        "THROW_LOAD": starts(pv, "load"),
        "LOAD_STATE": starts(st, "load"),
        "LOAD_AUX": starts(st, "load_aux"),
        "N_OBS": layout.outputs.size,
        "OBS_THROW": np.array([layout.outputs.start(t.name) for t in throws], dtype=np.int64),
        **_interstage_constants(machine, layout),
    }
    roles = {
        "crosshead": (KERNELS, "crosshead"),
        "crank_torque": (KERNELS, "crank_torque"),
        **_load_roles(load),
        **_frame_roles(frame),
        **_interstage_roles(machine, load),
    }
    equations = throws[0].equations
    if motor is None:
        template = "prescribed"
        roles["crank"] = (drive.module, drive.kernel("crank"))
        acc = "printed_acceleration" if equations == "paper-printed" else "acceleration"
        roles.update(throw_acc=(KERNELS, acc), throw_acc_jac=(KERNELS, f"{acc}_jac"))
        constants.update(
            LOAD_N=np.full(len(throws), len(load.states), dtype=np.int64),
            LOAD_NAUX=np.full(len(throws), len(load.aux_states), dtype=np.int64),
            LOAD_STEPS=starts(pv, "steps"),
        )
    else:
        template = "motor"
        held = motor.name == "held"  # (no torque law: the template finds the torque)
        roles["torque"] = (("recipdyn.model.assembler.generate", "absent") if held
                           else (motor.module, motor.kernel("torque")))  # fmt: skip
        roles["free_contribution"] = (KERNELS, "free_contribution")
        roles.update(_torsion_roles(machine.shaft.torsion))
        kinds = []
        nodes = st.parts.get("shaft.nodes", slice(0, 0))
        node_angles = set(range(nodes.start, nodes.stop, 2))  # (a flexible shaft's nodes)
        for i, name in enumerate(st.names):
            if i in range(*st.parts["shaft.work"].indices(st.size)) or any(
                    i in range(*st.parts[f"{t.name}.{part}"].indices(st.size))
                    for t in throws for part in ("work", "load_aux")) or (
                    frame and i in range(*st.parts["frame.work"].indices(st.size))):  # fmt: skip
                kinds.append(3)  # nothing depends on it: its column is 0
            elif any(i in range(*st.parts[f"{t.name}.load"].indices(st.size)) for t in throws) or (
                    any(i == st[f"{s.name}.p"] for s in machine.interstages)):  # fmt: skip
                kinds.append(2)
            elif name == "theta1" or name.endswith("theta_c") or i in node_angles:
                kinds.append(0)
            else:
                kinds.append(1)
        step_at = np.full(st.size, -1, dtype=np.int64)  # a load's state: its (rel, abs) step
        if has_states:
            for t in throws:
                g, o = st.start(f"{t.name}.load"), pv.start(f"{t.name}.steps")
                step_at[g : g + len(load.states)] = o + 2 * np.arange(len(load.states))
        constants.update(
            CRANK=st["theta1"],
            MOTOR=pv.start("shaft.motor"),
            MOTOR_WORK=st["W_motor"],
            HELD=held,
            **_torsion_constants(machine, layout),
            THROW_WORK=starts(st, "work"),
            STEP_KIND=np.array(kinds, dtype=np.int64),
            STEP_AT=step_at,
        )
    note = ""
    for c in (load, motor):  # a user's file: its edits give a new module, never stale code
        if c is not None and not c.module.startswith("recipdyn"):
            note += f"{c.family} = {c.module}: {source_digest(c.module)}; "
    stem = (f"{load.name}_{equations}_{len(throws)}"
            + ("" if motor is None else f"_{motor.name}")
            + ("_frame" if frame else "")
            + ("_torsion" if machine.shaft.torsion else "")
            + (f"_is{len(machine.interstages)}" if machine.interstages else "")
            ).replace("-", "_")  # fmt: skip
    return template, roles, constants, stem, note
