"""The declarative machine: frozen Python objects and the TOML file that holds them.

A machine file::

    name = "two-throw"
    description = "two throws at 180 deg on one crankshaft"

    [shaft]                  # the crankshaft and what turns it
    drive = "motor"          # prescribed | motor
    motor = "induction"      # the motor's torque law: induction | constant | file.py:OBJ
    omega = "20 rad/s"       # the shaft's parameters: omega, theta1_0, J_drive, motor_*
    J_drive = "3000 kg*m**2"

    [shaft.torsion]          # optional (drive = "motor"): a torsionally flexible shaft, the
    J_motor = "400 kg*m**2"  # rotor, the flywheel (J_drive less J_motor) and each throw a
    k_coupling = "3e6 N*m/rad"  # node with its own angle; the coupling between rotor and
    c_coupling = "1e3 N*m*s/rad" # flywheel, each throw's k_shaft, c_shaft in its [[throw]]

    [[stage]]                # a compression stage: its line pressures and temperature
    name = "stage1"
    suction_pressure = "1 bar"
    discharge_pressure = "3 bar"

    [[interstage]]           # optional: stage 1's discharge into a cooled volume that is
    name = "interstage1"     # stage 2's suction (its pressure a state; load = "valves")
    from = "stage1"
    to = "stage2"
    volume = "0.8 m**3"
    cooler_temperature = "313 K"

    [[throw]]                # one crank of the shaft, at its phase angle
    stage = "stage1"
    load = "cycle"           # paper | table | cycle | valves | file.py:OBJ
    crank_joint = "link"     # link (the massless link of length rc) | ideal | contact | lubricated
    # crosshead_joint = "ideal"  # ideal | contact | lubricated (with contact crank pins' family)
    # guide = "ideal"        # ideal | clearance (the crosshead between the guide's shoes)
    phase = "0 deg"
    rc = "1 mm"              # any parameter of the throw: its mechanism, its cylinder

    [[throw]]
    stage = "stage1"
    load = "cycle"
    phase = "180 deg"

    [frame]                  # optional: the frame on its elastic mounts (a planar rigid
    mass = "8 t"             # body in the horizontal plane x-z that the throws shake)
    inertia = "6000 kg*m**2" # about the vertical axis through its centre of mass
    z_cm = "325 mm"          # its centre of mass (x_cm, z_cm) in the frame's axes

    [[frame.mount]]          # an elastic mount: its place (x, z; structure) and its
    x = "-1 m"               # stiffness and damping along x and z (parameters)
    z = "-0.5 m"
    k_x = "5e7 N/m"
    c_x = "2e4 N*s/m"

    [[sensor]]               # what a monitoring system records: the model's vibration
    name = "accel_throw2"    # signal is the first accelerometer's
    kind = "accelerometer"
    signal = "throw2.a"      # (with a frame, "throw2.accel": the crosshead's + the frame's)

The keys that choose a part (a throw's ``load``, ``crank_joint``, ``equations``, ``stage``,
``name``, and its placement on the frame, ``cylinder_angle``: 0 or 180 deg, and
``axial_position`` along the crankshaft, with units; the shaft's ``drive`` and ``motor``; a
stage's and a sensor's keys) are the machine's structure; every other key is a parameter
value, with its unit (a number in SI or a quantity such as ``"1 mm"``), checked against its
range when the machine becomes a model. A machine of several throws names its parameters by
part: ``throw2.rc``, ``shaft.J_drive``, ``stage1.suction_pressure``; a machine of one throw
keeps the compressor's names (``rc``, ``omega``), so a one-throw machine and ``--model
compressor`` take the same values. The frame's parameters are always under ``frame.``
(``frame.mass``, ``frame.mount2.k_x``); a mount's place (``x``, ``z``) is structure.

A ``[shaft.torsion]`` table (needs ``drive = "motor"``) makes the crankshaft torsionally
flexible (`recipdyn.model.shaft.flexible`): the motor's rotor (``J_motor``), the flywheel
(``J_drive`` less ``J_motor``) and each throw's crank are nodes with their own angle and
speed, joined by the coupling (``k_coupling``, ``c_coupling``, rotor to flywheel) and the
crankshaft's sections (a throw's ``k_shaft``, ``c_shaft``: between it and its neighbour toward
the flywheel, the throws in the order of their ``axial_position`` from the flywheel's end).
Its parameters are the shaft's (``shaft.J_motor``) and the throws' (``throw2.k_shaft``).

An ``[[interstage]]`` joins two stages: the stage ``from``'s discharge valves deliver into a
volume (``volume``, m^3) whose gas a cooler holds at ``cooler_temperature``, and the stage
``to``'s suction valves take in from it; its pressure is a state of the machine (its initial
value the ``from`` stage's ``discharge_pressure``), so the ``to`` stage has no
``suction_pressure`` or ``suction_temperature`` of its own. Without an interstage every stage
works between its set line pressures.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from ...errors import ParameterError

__all__ = [
    "Machine", "Shaft", "Throw", "Stage", "Interstage", "Sensor", "Frame", "Mount",
    "read_machine", "SHAFT_NAMES", "STAGE_NAMES", "TORSION_NAMES", "THROW_TORSION_NAMES",
    "INTERSTAGE_NAMES", "FED_NAMES", "FRAME_NAMES",
    "MOUNT_NAMES", "LOADS", "JOINTS", "DRIVES",
    "SENSOR_KINDS", "CYLINDER_ANGLES",
]  # fmt: skip

#: The parameters of the shaft (its speed, angle and drive) and of a stage (its line
#: pressures and suction temperature): every other parameter of a throw's configuration is
#: the throw's own.
SHAFT_NAMES = ("omega", "theta1_0", "J_drive", "motor_torque", "motor_sync_speed",
               "motor_breakdown_torque", "motor_breakdown_slip")  # fmt: skip
STAGE_NAMES = ("suction_pressure", "discharge_pressure", "suction_temperature")
#: The parameters of a torsionally flexible shaft (`recipdyn.model.shaft.flexible`): the
#: shaft's (in ``[shaft.torsion]``) and each throw's (its crankshaft section's).
TORSION_NAMES = ("J_motor", "k_coupling", "c_coupling")
THROW_TORSION_NAMES = ("k_shaft", "c_shaft")
#: The parameters of the frame (`recipdyn.model.frame`) and of each of its mounts.
FRAME_NAMES = ("mass", "inertia", "x_cm", "z_cm")
MOUNT_NAMES = ("k_x", "k_z", "c_x", "c_z")


#: The parameters of an interstage volume, and a stage's that an interstage feeding it sets.
INTERSTAGE_NAMES = ("volume", "cooler_temperature")
FED_NAMES = ("suction_pressure", "suction_temperature")
#: The parts a throw may hold on the assembler (the crosshead pin's and the guide's clearance
#: run on one throw through ``--model compressor``; the contact and lubricated crank pins on a
#: machine take a prescribed crank and the paper's load or the cycle,
#: `recipdyn.model.assembler.contact_throws`).
LOADS = ("paper", "table", "cycle", "valves")
JOINTS = ("link", "ideal", "contact", "lubricated")
CROSSHEAD_JOINTS = ("ideal", "contact", "lubricated")
GUIDES = ("ideal", "clearance")
DRIVES = ("prescribed", "motor")
SENSOR_KINDS = ("accelerometer", "pressure", "tacho")
#: A throw's line of stroke in the frame, rad: horizontal, on either side of the shaft.
CYLINDER_ANGLES = (0.0, math.pi)
#: The largest distance of a throw's plane from the datum along the crankshaft, m.
AXIAL_MAX = 100.0

_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


def _pairs(values: Mapping[str, Any]) -> tuple[tuple[str, Any], ...]:
    return tuple((k, tuple(map(tuple, v)) if isinstance(v, list) else v)
                 for k, v in values.items())  # fmt: skip


@dataclass(frozen=True)
class Throw:
    """One crank of the shaft with its rod, crosshead and cylinder.

    Attributes
    ----------
    name : str
        Its namespace (``throw2``): its parameters are ``throw2.rc`` and its signals
        ``throw2.a`` in a machine of several throws.
    stage : str
        The stage it compresses for (its cylinder's line pressures are the stage's).
    crank_joint : {"link", "ideal", "contact", "lubricated"}
        The crank pin: the paper's massless link of length ``rc``, ideal (rc = 0), or a
        contact-impact joint of radial clearance ``rc``, dry or lubricated (the family of
        `recipdyn.model.assembler.contact_throws`; every throw of a machine of one family).
    crosshead_joint : {"ideal", "contact", "lubricated"}
        The crosshead pin: ideal, or a contact-impact joint of radial clearance
        ``rc_crosshead`` (the contact joints' family, as the guide's clearance).
    guide : {"ideal", "clearance"}
        The crosshead's guide: rigid, or with clearance (the crosshead moves sideways and
        tilts between the shoes, ``guide_clearance``).
    load : str
        The gas force on its crosshead: ``paper``, ``table``, ``cycle``, ``valves`` or a load
        component of a user's file (``file.py:OBJ``).
    equations : {"exact", "paper-printed"}
        The massless link's equation (the paper's printed one with a prescribed crank only).
    params : tuple of (name, value)
        Its parameter values by local name (``rc``, ``phase``: the angle its crank leads the
        shaft's by), raw (numbers in SI or quantities); the rest take their defaults.
    cylinder_angle : float
        The direction of its line of stroke in the frame, rad: 0 (the frame's +x, every
        throw's before this key) or pi (the opposite side: a balanced-opposed pair). Its
        equations run in its own axes turned by this angle, so its crank angle there is the
        shaft's plus ``phase`` minus ``cylinder_angle``.
    axial_position : float
        Where its plane sits along the crankshaft, m (the shaking moments' lever arm).
    """

    name: str = "throw1"
    stage: str = "stage1"
    crank_joint: str = "link"
    load: str = "paper"
    crosshead_joint: str = "ideal"
    guide: str = "ideal"
    equations: str = "exact"
    params: tuple[tuple[str, Any], ...] = ()
    cylinder_angle: float = 0.0
    axial_position: float = 0.0

    @property
    def values(self) -> dict[str, Any]:
        return dict(self.params)


@dataclass(frozen=True)
class Shaft:
    """The crankshaft and its drive: ``prescribed`` (it turns at ``omega``) or ``motor`` (its
    angle and speed are states, driven by the torque law ``motor`` on ``J_drive``);
    ``torsion``: torsionally flexible (a motor only; its parameters ``J_motor``,
    ``k_coupling``, ``c_coupling`` among ``params``, each throw's ``k_shaft``, ``c_shaft``
    among the throw's), else one rigid body."""

    drive: str = "prescribed"
    motor: str = "induction"
    params: tuple[tuple[str, Any], ...] = ()
    torsion: bool = False

    @property
    def values(self) -> dict[str, Any]:
        return dict(self.params)


@dataclass(frozen=True)
class Stage:
    """A compression stage: the line pressures and suction temperature its throws' cylinders
    work between."""

    name: str = "stage1"
    params: tuple[tuple[str, Any], ...] = ()

    @property
    def values(self) -> dict[str, Any]:
        return dict(self.params)


@dataclass(frozen=True)
class Interstage:
    """A volume between two stages: the stage ``upstream``'s discharge valves deliver into it,
    the stage ``downstream``'s suction valves take in from it, and a cooler holds its gas at
    ``cooler_temperature``; its pressure is a state (``name.p``). Parameters: ``volume``
    (m^3) and ``cooler_temperature`` (K)."""

    name: str = "interstage1"
    upstream: str = "stage1"
    downstream: str = "stage2"
    params: tuple[tuple[str, Any], ...] = ()

    @property
    def values(self) -> dict[str, Any]:
        return dict(self.params)


@dataclass(frozen=True)
class Sensor:
    """A sensor of the machine: ``kind`` (accelerometer, pressure, tacho) reading the
    recorded ``signal`` (``throw2.a``). The model's vibration signal (peak, RMS and
    spectrum in sweeps and features) is its first accelerometer's."""

    name: str
    kind: str
    signal: str


@dataclass(frozen=True)
class Mount:
    """An elastic mount of the frame: its name (``mount2``: its parameters are
    ``frame.mount2.k_x``), its place in the frame's axes (``x``, ``z``, m: structure) and its
    parameter values (stiffness ``k_x``, ``k_z`` and damping ``c_x``, ``c_z`` along x and z,
    raw)."""

    name: str = "mount1"
    x: float = 0.0
    z: float = 0.0
    params: tuple[tuple[str, Any], ...] = ()

    @property
    def values(self) -> dict[str, Any]:
        return dict(self.params)


@dataclass(frozen=True)
class Frame:
    """The frame on its elastic mounts (`recipdyn.model.frame`): a rigid body moving in the
    horizontal plane x-z (the plane of the cylinder axes and the crankshaft), shaken by every
    throw. ``params``: its parameter values (``mass``, ``inertia`` about the vertical axis
    through its centre of mass, ``x_cm``, ``z_cm``), raw; ``mounts``: its mounts."""

    params: tuple[tuple[str, Any], ...] = ()
    mounts: tuple[Mount, ...] = ()

    @property
    def values(self) -> dict[str, Any]:
        return dict(self.params)


@dataclass(frozen=True)
class Machine:
    """A machine: its shaft, its throws (in the order of their namespaces), stages, sensors
    and, optionally, its frame on its mounts (None: the frame is rigid and fixed, as
    before the frame existed)."""

    name: str = "machine"
    description: str = ""
    shaft: Shaft = field(default_factory=Shaft)
    throws: tuple[Throw, ...] = (Throw(),)
    stages: tuple[Stage, ...] = (Stage(),)
    sensors: tuple[Sensor, ...] = ()
    frame: Frame | None = None
    interstages: tuple[Interstage, ...] = ()
    #: Where it was read from (an absolute path: a record and a sweep's workers find it again).
    source: str = ""

    def __post_init__(self) -> None:
        if not self.throws:
            raise ParameterError(f"machine {self.name!r}: needs at least one [[throw]]")
        names = [t.name for t in self.throws]
        for t in self.throws:
            where = f"machine {self.name!r}: {t.name}"
            if not _NAME.match(t.name) or t.name in ("shaft", *[s.name for s in self.stages]):
                raise ParameterError(f"{where}: a throw's name is a letter then letters, digits "
                                     "or _, unlike the shaft's and the stages'")  # fmt: skip
            if t.crank_joint not in JOINTS:
                raise ParameterError(f"{where}.crank_joint = {t.crank_joint!r}; allowed: "
                                     f"{', '.join(map(repr, JOINTS))}")  # fmt: skip
            if t.crosshead_joint not in CROSSHEAD_JOINTS:
                raise ParameterError(f"{where}.crosshead_joint = {t.crosshead_joint!r}; allowed: "
                                     f"{', '.join(map(repr, CROSSHEAD_JOINTS))}")  # fmt: skip
            if t.guide not in GUIDES:
                raise ParameterError(f"{where}.guide = {t.guide!r}; allowed: "
                                     f"{', '.join(map(repr, GUIDES))}")  # fmt: skip
            if t.crank_joint == "link" and (t.crosshead_joint, t.guide) != ("ideal", "ideal"):
                raise ParameterError(f"{where}: crosshead_joint = {t.crosshead_joint!r}, guide = "
                                     f"{t.guide!r} beside crank_joint = 'link': the massless "
                                     "link runs with an ideal crosshead pin and guide; "
                                     "allowed: crank_joint = 'ideal' | 'contact' | "
                                     "'lubricated'")  # fmt: skip
            if t.load not in LOADS and ":" not in t.load:
                raise ParameterError(f"{where}.load = {t.load!r}; allowed: "
                                     f"{', '.join(map(repr, LOADS))} or file.py:OBJ")  # fmt: skip
            if t.equations not in ("exact", "paper-printed"):
                raise ParameterError(f"{where}.equations = {t.equations!r}; allowed: 'exact', "
                                     "'paper-printed'")  # fmt: skip
            if t.equations != "exact" and self.shaft.drive != "prescribed":
                raise ParameterError(f"{where}.equations = 'paper-printed' exists for a "
                                     "prescribed crank only; allowed with drive = 'motor': "
                                     "'exact'")  # fmt: skip
            if t.cylinder_angle not in CYLINDER_ANGLES:
                raise ParameterError(f"{where}.cylinder_angle = {math.degrees(t.cylinder_angle):g} "
                                     "deg; allowed: 0 or 180 deg (horizontal cylinders; the "
                                     "weight of a vertical or V cylinder's parts along their "
                                     "stroke is not modelled)")  # fmt: skip
            if not (math.isfinite(t.axial_position) and abs(t.axial_position) <= AXIAL_MAX):
                raise ParameterError(f"{where}.axial_position = {t.axial_position:g} m; allowed: "
                                     f"[-{AXIAL_MAX:g}, {AXIAL_MAX:g}] m")  # fmt: skip
            if t.stage not in [s.name for s in self.stages]:
                raise ParameterError(f"{where}.stage = {t.stage!r}; the machine's stages: "
                                     f"{', '.join(s.name for s in self.stages)}")  # fmt: skip
        first = self.throws[0]
        for t in self.throws[1:]:
            if (t.load, t.equations) != (first.load, first.equations):
                raise ParameterError(
                    f"machine {self.name!r}: {t.name}.load = {t.load!r} ({t.equations}) beside "
                    f"{first.name}.load = {first.load!r} ({first.equations}): the throws of a "
                    "machine carry one kind of load and one set of equations today (their "
                    "parameters differ freely)"
                )
        if len(set(names)) != len(names):
            raise ParameterError(f"machine {self.name!r}: two throws named alike: {names}")
        if len({s.name for s in self.stages}) != len(self.stages):
            raise ParameterError(f"machine {self.name!r}: two stages named alike")
        self._check_interstages()
        if self.shaft.drive not in DRIVES:
            raise ParameterError(f"machine {self.name!r}: shaft.drive = {self.shaft.drive!r}; "
                                 f"allowed: {', '.join(map(repr, DRIVES))}")  # fmt: skip
        if self.shaft.torsion and self.shaft.drive != "motor":
            raise ParameterError(f"machine {self.name!r}: [shaft.torsion] needs drive = 'motor' "
                                 f"(got {self.shaft.drive!r}: a prescribed speed turns every "
                                 "crank at omega, leaving the shaft nothing to twist); allowed: "
                                 "drive = 'motor' (with motor = 'held' the rotor turns at "
                                 "omega and the shaft twists behind it), or no "
                                 "[shaft.torsion]")  # fmt: skip
        if self.frame is not None:
            self._check_frame(self.frame)
        for s in self.sensors:
            if s.kind not in SENSOR_KINDS:
                raise ParameterError(f"machine {self.name!r}: sensor {s.name!r}: kind = "
                                     f"{s.kind!r}; allowed: {', '.join(SENSOR_KINDS)}")  # fmt: skip

    def _check_frame(self, frame: Frame) -> None:
        where = f"machine {self.name!r}: frame"
        if len(frame.mounts) < 2:
            raise ParameterError(f"{where}: needs at least 2 [[frame.mount]] (one mount leaves "
                                 "it free to turn about the vertical axis); got "
                                 f"{len(frame.mounts)}")  # fmt: skip
        names = [m.name for m in frame.mounts]
        if len(set(names)) != len(names):
            raise ParameterError(f"{where}: two mounts named alike: {names}")
        for m in frame.mounts:
            if not _NAME.match(m.name):
                raise ParameterError(f"{where}: mount name {m.name!r}: a letter then letters, "
                                     "digits or _")  # fmt: skip
            for k, v in (("x", m.x), ("z", m.z)):
                if not (math.isfinite(v) and abs(v) <= AXIAL_MAX):
                    raise ParameterError(f"{where}.{m.name}.{k} = {v:g} m; allowed: "
                                         f"[-{AXIAL_MAX:g}, {AXIAL_MAX:g}] m")  # fmt: skip
            for k in m.values:
                if k not in MOUNT_NAMES:
                    raise ParameterError(f"{where}.{m.name}.{k}: not a parameter of a "
                                         f"mount; allowed: name, x, z, "
                                         f"{', '.join(MOUNT_NAMES)}")  # fmt: skip
        for k in frame.values:
            if k not in FRAME_NAMES:
                raise ParameterError(f"{where}.{k}: not a parameter of the frame; allowed: "
                                     f"{', '.join(FRAME_NAMES)} and [[frame.mount]]")  # fmt: skip

    def _check_interstages(self) -> None:
        stages = [s.name for s in self.stages]
        taken = {*stages, "shaft", *(t.name for t in self.throws)}
        fed, feeding = set(), set()
        for i in self.interstages:
            where = f"machine {self.name!r}: interstage {i.name!r}"
            if not _NAME.match(i.name) or i.name in taken:
                raise ParameterError(f"{where}: its name is a letter then letters, digits or _, "
                                     "unlike the shaft's, the stages' and the throws'")  # fmt: skip
            taken.add(i.name)
            for key, st in (("from", i.upstream), ("to", i.downstream)):
                if st not in stages:
                    raise ParameterError(f"{where}: {key} = {st!r}; the machine's stages: "
                                         f"{', '.join(stages)}")  # fmt: skip
                if not any(t.stage == st for t in self.throws):
                    raise ParameterError(f"{where}: {key} = {st!r} has no throw")
            if i.upstream == i.downstream or i.upstream in feeding or i.downstream in fed:
                raise ParameterError(f"{where}: from = {i.upstream!r}, to = {i.downstream!r}: "
                                     "an interstage joins two different stages, and a stage "
                                     "feeds at most one interstage and is fed by at most "
                                     "one")  # fmt: skip
            feeding.add(i.upstream)
            fed.add(i.downstream)
            given = [
                k
                for k in FED_NAMES
                if k in next(s for s in self.stages if s.name == i.downstream).values
            ]
            if given:
                raise ParameterError(f"{where}: {i.downstream}.{given[0]} is set by the "
                                     "interstage (its pressure is a state, its gas at "
                                     "cooler_temperature): remove it")  # fmt: skip
            if self.throws[0].load != "valves":
                raise ParameterError(f"{where}: the throws' load = {self.throws[0].load!r}; an "
                                     "interstage needs the mass flows of the cylinders' valves: "
                                     "load = 'valves'")  # fmt: skip

    def interstage_into(self, stage: str) -> Interstage | None:
        """The interstage that feeds stage ``stage``'s suction (None: its set line)."""
        return next((i for i in self.interstages if i.downstream == stage), None)

    def interstage_from(self, stage: str) -> Interstage | None:
        """The interstage stage ``stage`` delivers into (None: its set line)."""
        return next((i for i in self.interstages if i.upstream == stage), None)

    @property
    def flat(self) -> bool:
        """One throw: the compressor's names, without namespaces."""
        return len(self.throws) == 1

    def prefix(self, part: str) -> str:
        """The namespace of part ``part`` (a throw's or a stage's name, or ``shaft``) in the
        machine's names: ``"throw2."``, or ``""`` in a machine of one throw."""
        return "" if self.flat else f"{part}."

    def stage_of(self, throw: Throw) -> Stage:
        return next(s for s in self.stages if s.name == throw.stage)

    def with_throws(self, throws) -> Machine:
        return replace(self, throws=tuple(throws))


_TOP = ("name", "description", "shaft", "throw", "stage", "sensor", "interstage", "frame")
_THROW_KEYS = ("name", "stage", "crank_joint", "crosshead_joint", "guide", "load", "equations")
#: A throw's placement on the frame: structure keys with units (not parameters to sweep).
_PLACEMENT = (("cylinder_angle", "rad"), ("axial_position", "m"))


def _placement(raw: dict, where: str) -> dict[str, float]:
    """A throw's ``cylinder_angle`` (rad; a file gives ``"180 deg"``; within 1e-9 rad of 0 or
    pi it is that angle) and ``axial_position`` (m), from its table."""
    from ...quantity import to_unit

    out = {k: to_unit(f"{where}.{k}", raw.pop(k), u) for k, u in _PLACEMENT if k in raw}
    if "cylinder_angle" in out:
        a = out["cylinder_angle"] % (2.0 * math.pi)
        out["cylinder_angle"] = next(
            (c for c in (*CYLINDER_ANGLES, 2.0 * math.pi) if abs(a - c) < 1e-9), a
        ) % (2.0 * math.pi)
    return out


def _table(raw: Any, where: str) -> dict[str, Any]:
    if not isinstance(raw, dict):
        raise ParameterError(f"{where}: expected a table, got {type(raw).__name__}")
    return raw


def _split(raw: dict, keys: tuple[str, ...]) -> tuple[dict, dict]:
    return ({k: v for k, v in raw.items() if k in keys},
            {k: v for k, v in raw.items() if k not in keys})  # fmt: skip


def machine_from_dict(raw: Mapping[str, Any], where: str = "machine",
                      source: str = "") -> Machine:  # fmt: skip
    """The `Machine` of a parsed machine file (module docstring); one-line
    [`ParameterError`][recipdyn.errors.ParameterError] naming the key."""
    for k in raw:
        if k not in _TOP:
            raise ParameterError(f"{where}: unknown key {k!r}; allowed: {', '.join(_TOP)}")
    shaft_raw = dict(_table(raw.get("shaft", {}), f"{where}: [shaft]"))
    torsion = shaft_raw.pop("torsion", None)
    shaft_keys, shaft_params = _split(shaft_raw, ("drive", "motor"))
    for k in shaft_params:
        if k not in SHAFT_NAMES:
            hint = " (in [shaft.torsion])" if k in TORSION_NAMES else ""
            raise ParameterError(f"{where}: [shaft] {k!r} is not a parameter of the shaft"
                                 f"{hint}; allowed: drive, motor, {', '.join(SHAFT_NAMES)}, "
                                 "and a [shaft.torsion] table")  # fmt: skip
    if torsion is not None:
        torsion = _table(torsion, f"{where}: [shaft.torsion]")
        for k in torsion:
            if k not in TORSION_NAMES:
                raise ParameterError(f"{where}: [shaft.torsion] {k!r} is not a parameter of "
                                     "the flexible shaft; allowed: "
                                     f"{', '.join(TORSION_NAMES)} (each throw's k_shaft, "
                                     "c_shaft in its [[throw]])")  # fmt: skip
        shaft_params = {**shaft_params, **torsion}
    shaft = Shaft(
        **{k: str(v) for k, v in shaft_keys.items()},
        params=_pairs(shaft_params),
        torsion=torsion is not None,
    )
    stages = []
    for i, st in enumerate(raw.get("stage", []), 1):
        st = _table(st, f"{where}: stage {i}")
        keys, params = _split(st, ("name",))
        for k in params:
            if k not in STAGE_NAMES:
                raise ParameterError(f"{where}: stage {i}: {k!r} is not a parameter of a stage; "
                                     f"allowed: name, {', '.join(STAGE_NAMES)}")  # fmt: skip
        stages.append(Stage(name=str(keys.get("name", f"stage{i}")), params=_pairs(params)))
    stages = stages or [Stage()]
    interstages = []
    for i, raw_i in enumerate(raw.get("interstage", []), 1):
        raw_i = _table(raw_i, f"{where}: interstage {i}")
        keys, params = _split(raw_i, ("name", "from", "to"))
        name = str(keys.get("name", f"interstage{i}"))
        if {"from", "to"} - set(keys):
            raise ParameterError(f"{where}: interstage {name!r}: needs from and to (the stage "
                                 "whose discharge feeds it, the stage whose suction it "
                                 "is)")  # fmt: skip
        for k in params:
            if k not in INTERSTAGE_NAMES:
                raise ParameterError(f"{where}: interstage {name!r}: {k!r} is not a parameter of "
                                     "an interstage; allowed: name, from, to, "
                                     f"{', '.join(INTERSTAGE_NAMES)}")  # fmt: skip
        interstages.append(Interstage(name, str(keys["from"]), str(keys["to"]), _pairs(params)))
    throws = []
    for i, th in enumerate(raw.get("throw", []), 1):
        th = _table(th, f"{where}: throw {i}")
        keys, params = _split(th, _THROW_KEYS)
        keys = {k: str(v) for k, v in keys.items()}
        keys.setdefault("name", f"throw{i}")
        place = _placement(params, f"{where}: {keys['name']}")
        keys.setdefault("stage", stages[0].name)
        for k in params:
            if k in SHAFT_NAMES or k in STAGE_NAMES:
                part = "[shaft]" if k in SHAFT_NAMES else f"its [[stage]] ({keys['stage']})"
                raise ParameterError(f"{where}: {keys['name']}.{k}: a parameter of {part}, not "
                                     "of a throw")  # fmt: skip
        throws.append(Throw(**keys, params=_pairs(params), **place))
    sensors = []
    for i, se in enumerate(raw.get("sensor", []), 1):
        se = _table(se, f"{where}: sensor {i}")
        missing = {"kind", "signal"} - set(se)
        extra = set(se) - {"name", "kind", "signal"}
        if missing or extra:
            raise ParameterError(
                f"{where}: sensor {i}: needs kind and signal (and a name); "
                f"{'missing ' + ', '.join(sorted(missing)) if missing else ''}"
                f"{'unknown ' + ', '.join(sorted(extra)) if extra else ''}"
            )
        sensors.append(Sensor(str(se.get("name", f"sensor{i}")), str(se["kind"]),
                              str(se["signal"])))  # fmt: skip
    frame = _frame(raw["frame"], where) if "frame" in raw else None
    return Machine(name=str(raw.get("name", Path(source).stem if source else "machine")),
                   description=str(raw.get("description", "")), shaft=shaft,
                   throws=tuple(throws), stages=tuple(stages), sensors=tuple(sensors),
                   interstages=tuple(interstages), frame=frame, source=source)  # fmt: skip


def _frame(raw: Any, where: str) -> Frame:
    """The `Frame` of a file's ``[frame]`` table: its parameters and its ``[[frame.mount]]``
    tables (each a ``name``, its place ``x``, ``z`` with units, and its parameters)."""
    from ...quantity import to_unit

    raw = dict(_table(raw, f"{where}: [frame]"))
    mounts = []
    for i, mo in enumerate(raw.pop("mount", []), 1):
        mo = dict(_table(mo, f"{where}: frame mount {i}"))
        name = str(mo.pop("name", f"mount{i}"))
        place = {k: to_unit(f"{where}: frame.{name}.{k}", mo.pop(k), "m")
                 for k in ("x", "z") if k in mo}  # fmt: skip
        mounts.append(Mount(name, params=_pairs(mo), **place))
    return Frame(params=_pairs(raw), mounts=tuple(mounts))


def read_machine(path: str | Path) -> Machine:
    """The `Machine` of a TOML machine file (module docstring)."""
    import tomllib

    path = Path(path)
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ParameterError(f"machine: file not found: {path}") from None
    except (IsADirectoryError, PermissionError, UnicodeDecodeError) as exc:
        raise ParameterError(f"machine {path}: cannot read it ({type(exc).__name__})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"machine {path}: malformed TOML ({exc})") from None
    if not raw.get("throw"):
        raise ParameterError(f"machine {path}: needs at least one [[throw]]")
    return machine_from_dict(raw, f"machine {path.name}", str(path.resolve()))
