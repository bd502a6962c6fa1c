"""Immutable, validated parameters of the compressor model (SI units throughout).

One frozen dataclass, [`CompressorParams`][recipdyn.model.parameters.CompressorParams], holds
geometry, inertia, faults, operation and the initial condition; vary it with `dataclasses.replace`
(validation runs again). [`paper_2d12`][recipdyn.model.parameters.paper_2d12] is the preset for the
2D12 compressor of Xiao et al. (2017).

What the reference paper gives and what it does not
----------------------------------------------------
Table 1 of the paper (masses and moments of inertia of the 2D12 compressor) is garbled in the
only copy we have and no other source was found. The crank radius (0.12 m) and the rod length
(0.6 m) follow from the text ("480.6 mm at the low dead point" = l - r, and the table's "0.12");
the centroids at mid-length are stated in Section 3. **Every other value is an assumption**,
listed in `ASSUMED` and recorded as such in every output file. They are plausible for a
mid-size process compressor, not fitted to anything.

Only ``m2``, ``m3``, ``J2`` (and ``g`` with ``m2``) enter the clearance-angle dynamics: the crank
turns at a prescribed uniform speed, so ``m1``, ``J1`` and ``rs`` affect only the crank torque.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields
from typing import Any, Literal

from ..defaults import RC_MIN
from ..errors import ParameterError
from .components.contract import resolve_component
from .components.drive import CONSTANT_TORQUE, DRIVES, INDUCTION, MOTOR, MOTORS
from .gases import GASES
from .protocol import Derived, Param, Schema, derive_value
from .registry import is_spec

__all__ = [
    "CompressorParams",
    "params_from_attrs",
    "ParameterError",
    "ASSUMED",
    "ASSUMED_CYCLE",
    "PARAM_UNITS",
    "PARAM_ALIASES",
    "paper_2d12",
    "resolve_name",
    "SCHEMA",
    "SELECTORS",
    "configures",
    "pin_joints",
]


#: Parameters whose values are assumptions (the paper's Table 1 is illegible for them).
ASSUMED: dict[str, str] = {
    "m1": "assumed: Table 1 illegible (does not affect the clearance dynamics)",
    "m2": "assumed: Table 1 illegible",
    "m3": "assumed: Table 1 illegible",
    "J1": "partly legible in Table 1 (0.0012); does not affect the clearance dynamics",
    "J2": "assumed: slender uniform rod, m2*l**2/12",
    "theta_c0": "not given in the paper: default = link aligned with the rod load, at rest",
    "thetadot_c0": "not given in the paper: default 0",
}

#: Assumed values of the compression-cycle load (load = "cycle"): the paper gives no cylinder
#: data. A first stage of a two-stage air compressor (8 bar final): suction 1 bar, discharge
#: 3 bar, double-acting, 10 % clearance, polytropic exponent 1.3 (air, cooled cylinder).
ASSUMED_CYCLE: dict[str, str] = {
    k: "assumed: the paper gives no cylinder data (used only with load = 'cycle')"
    for k in (
        "bore",
        "rod_diameter",
        "clearance_fraction",
        "suction_pressure",
        "discharge_pressure",
        "n_compression",
        "n_expansion",
        "acting",
        "suction_temperature",
    )
}

_INF = math.inf

#: The compressor's parameter schema: units, static ranges, groups, assumptions. Ranges that
#: depend on other parameters (rs <= r, ls <= l, rc < r, |d| < l - r - rc) are checked in
#: `CompressorParams.__post_init__`.
SCHEMA = Schema((
    Param("r", "m", 0.12, "crank radius A-B (paper)", 0.0, _INF, True, True, group="mechanism"),
    Param("rs", "m", 0.06, "main bearing to crank centroid (default: mid-length, r / 2)",
          0.0, _INF, high_ref="r", group="mechanism", derive="r / 2"),
    Param("l", "m", 0.6, "connecting-rod length (paper)", 0.0, _INF, True, True,
          group="mechanism"),
    Param("ls", "m", 0.3, "crank-pin end of the rod to its centroid (default: mid-length, "
          "l / 2)", 0.0, _INF, high_ref="l", group="mechanism", derive="l / 2"),
    Param("m1", "kg", 15.0, "crank mass", 0.0, _INF, high_open=True, assumed=ASSUMED["m1"],
          group="mechanism"),
    Param("m2", "kg", 20.0, "connecting-rod mass", 0.0, _INF, high_open=True,
          assumed=ASSUMED["m2"], group="mechanism"),
    Param("m3", "kg", 30.0, "crosshead + piston mass", 0.0, _INF, high_open=True,
          assumed=ASSUMED["m3"], group="mechanism"),
    Param("J1", "kg*m**2", 0.0012, "crank moment of inertia about its centroid", 0.0, _INF,
          high_open=True, assumed=ASSUMED["J1"], group="mechanism"),
    Param("J2", "kg*m**2", 0.6, "rod moment of inertia about its centroid (default: a "
          "slender uniform rod, m2 l^2 / 12)", 0.0, _INF, high_open=True, assumed=ASSUMED["J2"],
          group="mechanism", derive="m2 * l**2 / 12"),
    Param("g", "m/s**2", 9.81, "gravitational acceleration (along -y)", 0.0, 100.0,
          group="mechanism"),
    Param("rc", "m", 1.0e-3, "radial clearance of the crank-pin joint (massless link length); "
          "0 = ideal joint", 0.0, _INF, high_open=True, high_ref="r", group="joint"),
    Param("d", "m", 1.0e-3, "crosshead subsidence (crosshead runs at y = -d)", -_INF, _INF,
          True, True, low_ref="-(l - r - rc)", high_ref="l - r - rc", group="joint"),
    Param("omega", "rad/s", 20.0, "crank speed", 0.0, 1.0e4, low_open=True, group="operation"),
    Param("theta1_0", "rad", 0.0, "crank angle at t = 0 (0 = outer dead centre)", -1e6, 1e6,
          group="operation"),
    Param("theta_c0", "rad", None, "initial clearance angle (default: link aligned with the "
          "rod load)", -1e6, 1e6, assumed=ASSUMED["theta_c0"], group="initial", optional=True),
    Param("theta_c_offset", "rad", 0.0, "offset added to the initial clearance angle",
          -math.pi, math.pi, group="initial"),
    Param("thetadot_c0", "rad/s", 0.0, "initial clearance angular velocity", -1e7, 1e7,
          assumed=ASSUMED["thetadot_c0"], group="initial"),
    Param("load_amplitude", "N", 200000.0, "peak cylinder force (paper Eq. 1: P = 200000 mu)",
          0.0, 1e9, group="load"),
    Param("load_sign", "", "physical", "direction of the gas force: 'physical' (toward the "
          "crank) or 'paper' (as in Eq. 46)", choices=("physical", "paper"), group="load"),
    Param("equations", "", "exact", "'exact' derivation or the paper's printed Eq. 43-47",
          choices=("exact", "paper-printed"), group="joint"),
    Param("load", "", "paper", "cylinder load: 'paper' (Eq. 1-2, load_amplitude) or 'cycle' "
          "(the compression cycle, ideal valves)", choices=("paper", "cycle"), group="load"),
    Param("bore", "m", 0.5, "cylinder bore (load = cycle)", 0.0, 10.0, low_open=True,
          assumed=ASSUMED_CYCLE["bore"], group="cycle"),
    Param("rod_diameter", "m", 0.1, "piston-rod diameter (load = cycle; < bore)", 0.0, 10.0,
          high_open=True, high_ref="bore", assumed=ASSUMED_CYCLE["rod_diameter"], group="cycle"),
    Param("clearance_fraction", "", 0.1, "clearance volume / swept volume of each chamber "
          "(load = cycle)", 0.0, 10.0, low_open=True, assumed=ASSUMED_CYCLE["clearance_fraction"],
          group="cycle"),
    Param("suction_pressure", "Pa", 1.0e5, "suction line pressure, absolute (load = cycle)",
          0.0, 1e9, low_open=True, assumed=ASSUMED_CYCLE["suction_pressure"], group="cycle"),
    Param("discharge_pressure", "Pa", 3.0e5, "discharge line pressure, absolute (load = cycle; "
          ">= suction_pressure)", 0.0, 1e9, low_open=True,
          assumed=ASSUMED_CYCLE["discharge_pressure"], group="cycle"),
    Param("n_compression", "", 1.3, "polytropic exponent of compression (load = cycle)", 1.0,
          2.0, assumed=ASSUMED_CYCLE["n_compression"], group="cycle"),
    Param("n_expansion", "", 1.3, "polytropic exponent of re-expansion (load = cycle)", 1.0,
          2.0, assumed=ASSUMED_CYCLE["n_expansion"], group="cycle"),
    Param("acting", "", "double", "compressing chambers: 'head', 'crank' or 'double' (load = "
          "cycle)", choices=("head", "crank", "double"), assumed=ASSUMED_CYCLE["acting"],
          group="cycle"),
    Param("frame_pressure", "Pa", 101325.0, "pressure in the frame / distance piece, on the rod "
          "section and in an inactive chamber (load = cycle)", 0.0, 1e9, group="cycle"),
    Param("gas", "", "ideal", "gas of the cycle: 'ideal' (polytropes with n_compression, "
          "n_expansion) or a CoolProp fluid (real-gas isentropes; load = cycle)",
          choices=GASES, group="cycle"),
    Param("suction_temperature", "K", 293.15, "suction temperature (load = cycle with a real "
          "gas)", 0.0, 5000.0, low_open=True, assumed=ASSUMED_CYCLE["suction_temperature"],
          group="cycle"),
    # the drive (components.drive): the family's choice, then each component's fragment
    Param("drive", "", "prescribed", "what turns the crank: 'prescribed' (constant omega) or "
          "'motor' (crank angle and speed as states; omega is the initial speed)",
          choices=tuple(DRIVES), group="drive"),
    Param("motor", "", "induction", "the motor's torque law (drive = motor): 'induction' "
          "(Kloss's curve), 'constant', or 'held' (the rotor turns at omega: an ideal "
          "speed-controlled drive)", choices=tuple(MOTORS), group="drive"),
    *MOTOR.params, *CONSTANT_TORQUE.params, *INDUCTION.params,
), extras=("load_table",), aliases={
    "clearance": "rc", "subsidence": "d", "speed": "omega", "crank_speed": "omega",
    "crank_radius": "r", "rod_length": "l",
})  # fmt: skip

PARAM_UNITS: dict[str, str] = {p.name: p.unit for p in SCHEMA if p.unit}

JOINTS = ("link", "ideal", "contact", "lubricated")
#: The selectors of the compressor (`recipdyn.model.family`): each a parameter whose value
#: chooses a part, and so the implementation that runs.
SELECTORS = Schema((
    Param("crank_joint", "", "link", "the crank-pin joint: 'link' (the paper's massless link "
          "of length rc), 'ideal', 'contact' (dry contact-impact) or 'lubricated' (oil film + "
          "contact)", choices=JOINTS, group="joint"),
    Param("crosshead_joint", "", "ideal", "the crosshead-pin joint: 'ideal', 'contact' or "
          "'lubricated'", choices=JOINTS[1:], group="joint"),
    Param("load", "", "paper", "cylinder load: 'paper' (Eq. 1-2), 'table' (load_table or "
          "pressure_table), 'cycle' (ideal valves), 'valves' (dynamic plate valves, the gas as "
          "states) or file.py:OBJ", choices=("paper", "table", "cycle", "valves"),
          group="load"),
    Param("drive", "", "prescribed", "what turns the crank: 'prescribed' (constant omega) or "
          "'motor'", choices=("prescribed", "motor"), group="drive"),
    Param("guide", "", "ideal", "the crosshead guide: 'ideal' (the crosshead runs at y = -d) "
          "or 'clearance' (it moves and tilts between the shoes: crosshead knock)",
          choices=("ideal", "clearance"), group="guide"),
))  # fmt: skip

#: The contact joints' older way to name the pins (``clearance_joints``: where, ``joint``: dry
#: or lubricated), which the selectors read too.
PIN_SPELLINGS = ("clearance_joints", "joint")
#: The older spelling's ``clearance_joints``: which pins (crank, crosshead) have clearance.
_WHERE = {"crank": (True, False), "crosshead": (False, True), "both": (True, True),
          "ideal": (False, False)}  # fmt: skip


def pin_joints(values: Mapping[str, Any]) -> tuple[str | None, str | None]:
    """The joints at the crank pin and at the crosshead pin that ``values`` (names, raw or
    validated) ask for, None for a pin they say nothing of: ``crank_joint`` and
    ``crosshead_joint`` where given, else the older spelling's where it is given
    (``clearance_joints``: where the clearance is, default the crank pin; ``joint``: 'dry'
    contact or 'lubricated' at those pins; the other pins ideal).

    Where the two spellings contradict each other (``clearance_joints = 'crosshead'`` with
    ``crank_joint = 'contact'``, or ``joint = 'lubricated'`` where no pin is lubricated), one
    of the user's values would not be run as asked: [`ParameterError`][recipdyn.errors.
    ParameterError] names both."""
    crank, cross = values.get("crank_joint"), values.get("crosshead_joint")
    where, joint = values.get("clearance_joints"), values.get("joint")
    if where is None and joint is None:
        return crank, cross
    if where is not None and where not in _WHERE:
        raise ParameterError(f"clearance_joints = {where!r}; allowed: {', '.join(_WHERE)}")
    if joint is not None and joint not in ("dry", "lubricated"):
        raise ParameterError(f"joint = {joint!r}; allowed: dry, lubricated")
    kind = "lubricated" if joint == "lubricated" else "contact"
    has = _WHERE[where or "crank"]
    spelled = tuple(kind if h else "ideal" for h in has)
    pins = []
    for name, given, old, h in zip(("crank_joint", "crosshead_joint"), (crank, cross),
                                   spelled, has, strict=True):  # fmt: skip
        if given is not None and where is not None and (given != "ideal") != h:
            pin = name.split("_")[0]
            raise ParameterError(
                f"{name} = {given!r} and clearance_joints = {where!r} contradict each other: "
                f"clearance_joints = {where!r} makes the {pin} pin "
                f"{'a clearance joint' if h else 'ideal'}; give one of them (crank_joint and "
                "crosshead_joint name each pin)"
            )
        pins.append(old if given is None else given)
    if joint == "lubricated" and "lubricated" not in pins:
        raise ParameterError(
            f"joint = 'lubricated' acts on no pin here (crank_joint = {pins[0]!r}, "
            f"crosshead_joint = {pins[1]!r}): set crank_joint or crosshead_joint = "
            "'lubricated' instead"
        )
    return pins[0], pins[1]


def configures(values: Mapping[str, Any]) -> bool:
    """Whether ``values`` (names, raw) choose a configuration of the compressor other than
    the massless link's by a selector it does not have (``crank_joint = contact``, ``load =
    valves``...): then the model, not this module's `SCHEMA`, validates them."""
    for k, v in values.items():
        if k in PIN_SPELLINGS or (k in SELECTORS.names and k not in SCHEMA.names):
            return True
        if k in SELECTORS.names and v not in SCHEMA[k].choices and not is_spec(v):
            return True
    return False


#: The parameters that choose a component and may name one from a user's module or file
#: (``module:object``, ``file.py:OBJ``; `recipdyn.model.components.contract.resolve_component`).
PLUGGABLE = ("load", "motor")

#: Friendly names accepted by the CLI, configs and sweeps.
PARAM_ALIASES: dict[str, str] = dict(SCHEMA.aliases)


def resolve_name(name: str) -> str:
    """Map an alias (``clearance``) to the field name (``rc``); raise on unknown names (with
    the closest names, `recipdyn.model.protocol.UnknownParameterError`)."""
    return name if name == "load_table" else SCHEMA.resolve(name)  # (a table: no schema row)


def _check(name: str, value: float, lo: float, hi: float, lo_open=False, hi_open=False):
    if not isinstance(value, (int, float)) or isinstance(value, bool):
        raise ParameterError(f"{name} must be a number, got {value!r}")
    if not math.isfinite(value):
        raise ParameterError(f"{name} must be finite, got {value!r}")
    bad_lo = value <= lo if lo_open else value < lo
    bad_hi = value >= hi if hi_open else value > hi
    if bad_lo or bad_hi:
        lb = "(" if lo_open else "["
        rb = ")" if hi_open else "]"
        unit = PARAM_UNITS.get(name, "")
        raise ParameterError(
            f"{name} = {value!r} {unit} is out of range; allowed: {lb}{lo:g}, {hi:g}{rb} {unit}"
        )


@dataclass(frozen=True)
class CompressorParams:
    """Parameters of the single-cylinder compressor with a clearance at the crank pin.

    Attributes (SI units)
    ---------------------
    r : float
        Crank radius A-B, m (paper: 0.12).
    rs : float
        Distance from the main bearing A to the crank's centroid, m (mid-length).
    l : float
        Connecting-rod length, m (paper: 0.6).
    ls : float
        Distance from the crank-pin end of the rod to its centroid, m (mid-length).
    m1, m2, m3 : float
        Masses of crank, rod and crosshead (with piston), kg. **Assumed** (see module doc).
    J1, J2 : float
        Moments of inertia of crank and rod about their centroids, kg m^2. **Assumed**.
    g : float
        Gravitational acceleration (acts along -y), m/s^2.
    rc : float
        Radial clearance of the crank-pin joint, m; the length of the massless virtual link.
        ``0 <= rc < r``; ``rc = 0`` is the ideal mechanism.
    d : float
        Crosshead subsidence, m: the crosshead runs at ``y3 = -d``.
    omega : float
        Crank speed, rad/s (> 0); the crank angle is ``theta1 = theta1_0 + omega t``.
    theta1_0 : float
        Crank angle at t = 0, rad (0 = outer dead centre, crosshead at ``x = r + l``).
    theta_c0 : float or None
        Initial clearance angle, rad. ``None`` (default) = the link aligned with the force the
        rod transmits at t = 0, i.e. the static equilibrium of the link under the gas load
        (`recipdyn.model.mechanism.link.equilibrium_theta_c`), plus ``theta_c_offset``.
    theta_c_offset : float
        Offset added to the default initial clearance angle, rad. The motion is very sensitive
        to it: offsets of ~0.2 rad and more excite large free oscillations of the link.
    thetadot_c0 : float
        Initial clearance angular velocity, rad/s (default 0).
    load_amplitude : float
        Peak cylinder force, N (the paper's ``P = 200000 mu``, Eq. 1).
    load_sign : {"physical", "paper"}
        Direction of the gas force on the crosshead. ``"physical"``: the gas pushes the piston
        toward the crank, ``F_x = -P`` (the cylinder is on the +x side, beyond the outer dead
        centre). ``"paper"``: ``F_x = +P``, the sign with which P enters the paper's Eq. (46)
        (``d1 = P r_c`` multiplying ``dx3/dtheta_c``).
    equations : {"exact", "paper-printed"}
        ``"exact"``: our exact derivation. ``"paper-printed"``: Eq. (43)-(47) exactly as printed
        (with their errata), for comparison only.
    load : {"paper", "cycle"}
        ``"paper"``: the piecewise load of Eq. (1)-(2). ``"cycle"``: the gas force of the
        compression cycle with ideal valves ([`recipdyn.model.cycle`][recipdyn.model.cycle]), from
        ``bore``, ``rod_diameter``, ``clearance_fraction``, ``suction_pressure``,
        ``discharge_pressure`` (absolute, Pa), ``n_compression``, ``n_expansion``, ``acting`` and
        ``frame_pressure``; ``load_amplitude`` and ``load_sign`` do not apply to it.
    drive : {"prescribed", "motor"}
        ``"prescribed"``: ``theta1 = theta1_0 + omega t``. ``"motor"``: the crank angle and
        speed are states driven by the torque law ``motor`` (``"induction"``: Kloss's curve
        with ``motor_sync_speed``, ``motor_breakdown_torque``, ``motor_breakdown_slip``;
        ``"constant"``: ``motor_torque``) on the inertia ``J_drive``; ``omega`` is then the
        initial speed (``recipdyn.model.components.drive``).
    """

    r: float = 0.12
    rs: float = Derived(0.06)  # (r / 2 unless set: `SCHEMA`'s rules, derived again on replace)
    l: float = 0.6
    ls: float = Derived(0.3)  # (l / 2)
    m1: float = 15.0
    m2: float = 20.0
    m3: float = 30.0
    J1: float = 0.0012
    J2: float = Derived(0.6)  # (m2 l^2 / 12)
    g: float = 9.81
    rc: float = 1.0e-3
    d: float = 1.0e-3
    omega: float = 20.0
    theta1_0: float = 0.0
    theta_c0: float | None = None
    theta_c_offset: float = 0.0
    thetadot_c0: float = 0.0
    load_amplitude: float = 200000.0
    load_sign: Literal["physical", "paper"] = "physical"
    equations: Literal["exact", "paper-printed"] = "exact"
    load: Literal["paper", "cycle"] = "paper"
    bore: float = 0.5
    rod_diameter: float = 0.1
    clearance_fraction: float = 0.1
    suction_pressure: float = 1.0e5
    discharge_pressure: float = 3.0e5
    n_compression: float = 1.3
    n_expansion: float = 1.3
    acting: Literal["head", "crank", "double"] = "double"
    frame_pressure: float = 101325.0
    gas: str = "ideal"
    suction_temperature: float = 293.15
    drive: Literal["prescribed", "motor"] = "prescribed"
    motor: Literal["induction", "constant"] = "induction"
    J_drive: float = 3000.0
    motor_torque: float | None = None
    motor_sync_speed: float = 21.0
    motor_breakdown_torque: float = 11000.0
    motor_breakdown_slip: float = 0.15
    load_table: tuple[tuple[float, float], ...] | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        rules = [p for p in SCHEMA if p.derive]
        for p in SCHEMA:  # the static ranges, declared once in the schema
            if p.name in PLUGGABLE and is_spec(getattr(self, p.name)):
                continue  # a component from a user's file (checked when it is loaded)
            if p not in rules or not isinstance(getattr(self, p.name), Derived):
                p.check(getattr(self, p.name))
        given = {k: getattr(self, k) for k in SCHEMA.names if k not in PLUGGABLE}
        for p in rules:  # a default derived from the values it follows (unless set)
            if isinstance(given[p.name], Derived) or given[p.name] is None:
                object.__setattr__(self, p.name, derive_value(p, given))
        _check("rs", self.rs, 0.0, self.r)
        _check("ls", self.ls, 0.0, self.l)
        _check("rc", self.rc, 0.0, self.r, hi_open=True)
        if 0.0 < self.rc < RC_MIN:
            raise ParameterError(
                f"rc = {self.rc!r} m is out of range; allowed: 0 (ideal joint) or "
                f"[{RC_MIN:g}, {self.r:g}) m (below {RC_MIN:g} m the free link oscillation "
                "needs millions of steps per revolution)"
            )
        # |d + r sin(theta1) + rc sin(theta_c)| < l must hold for every crank and link angle.
        check_reach(self.l, self.r, self.rc, "rc")
        dmax = self.l - self.r - self.rc
        _check("d", self.d, -dmax, dmax, lo_open=True, hi_open=True)
        if self.m2 + self.m3 + self.J2 <= 0 and self.rc > 0:
            raise ParameterError("m2, m3, J2: at least one must be > 0 when rc > 0")
        if self.load_table is not None:
            _validate_table(self.load_table)
            if self.load == "cycle":
                raise ParameterError("load = 'cycle' and a load table exclude each other: "
                                     "drop the table or set load = 'paper'")  # fmt: skip
        _check("rod_diameter", self.rod_diameter, 0.0, self.bore, hi_open=True)
        if self.drive == "motor":
            if self.equations != "exact":
                raise ParameterError(
                    "equations = 'paper-printed' exists for a prescribed crank "
                    "only; allowed with drive = 'motor': equations = 'exact'"
                )
            check = resolve_component("motor", self.motor, MOTORS).check
            if check is not None:
                check(asdict(self))
            if self.motor == "constant" and self.motor_torque is None and is_spec(self.load):
                raise ParameterError(
                    f"motor_torque: needed with motor = 'constant' and load = {self.load!r} "
                    "(its default, the mean load torque, is known for recipdyn's own loads)"
                )
        if self.discharge_pressure < self.suction_pressure:
            raise ParameterError(
                f"discharge_pressure = {self.discharge_pressure!r} Pa is out of range; allowed: "
                f">= suction_pressure ({self.suction_pressure:g} Pa)"
            )

    @property
    def crank_period(self) -> float:
        """Duration of one crank revolution, s."""
        return 2.0 * math.pi / self.omega

    @property
    def crank_frequency(self) -> float:
        """Crank rotation frequency, Hz."""
        return self.omega / (2.0 * math.pi)

    def to_attrs(self) -> dict[str, Any]:
        """Flat attributes for result files: every value, its unit and whether it is assumed."""
        out: dict[str, Any] = {}
        for k, v in asdict(self).items():
            if k == "load_table":
                out["load_model"] = (
                    "table"
                    if v is not None
                    else "compression cycle, ideal valves"
                    if self.load == "cycle"
                    else "paper Eq. (1)-(2)"
                )
                if v is not None:
                    out["load_table_deg_N"] = [x for row in v for x in row]
                continue
            out[k] = "default" if v is None else v
            if k in PARAM_UNITS:
                out[f"{k}_units"] = PARAM_UNITS[k]
        out["assumed_parameters"] = ", ".join(sorted(ASSUMED))
        for k, why in ASSUMED.items():
            out[f"{k}_note"] = why
        return out


def check_reach(l: float, r: float, rc: float, rc_text: str) -> None:
    """Refuse a connecting rod that cannot reach past the crank: the slider-crank exists for
    ``l > r + rc`` (``rc_text``: what the clearance term is, e.g. ``"1.5 (rc + rc_crosshead)"``),
    named by the lengths the user gives, not by a parameter whose range they make empty."""
    if not l > r + rc:
        raise ParameterError(
            f"l = {l:g} m and r = {r:g} m: the connecting rod must be longer than the crank "
            f"radius plus the clearance, l > r + {rc_text} = {r + rc:g} m"
        )


def _validate_table(table) -> None:
    if len(table) < 2:
        raise ParameterError("load_table needs at least 2 rows of (crank angle deg, force N)")
    prev = -math.inf
    for i, row in enumerate(table):
        if len(row) != 2:
            raise ParameterError(f"load_table row {i} must be (angle_deg, force_N), got {row!r}")
        a, f = row
        for name, v in (("angle", a), ("force", f)):
            if not math.isfinite(v):
                raise ParameterError(f"load_table row {i}: {name} must be finite, got {v!r}")
        if not (0.0 <= a < 360.0):
            raise ParameterError(f"load_table row {i}: angle {a} deg out of range [0, 360)")
        if a <= prev:
            raise ParameterError(f"load_table row {i}: angles must increase strictly")
        prev = a


def params_from_attrs(attrs: Mapping[str, Any]) -> CompressorParams:
    """The [`CompressorParams`][recipdyn.model.parameters.CompressorParams] a record's
    attributes (``param_*``, written from `CompressorParams.to_attrs`) hold, the load table
    included."""
    import numpy as np

    kw: dict[str, Any] = {}
    for f in fields(CompressorParams):
        if f.name == "load_table":
            flat = attrs.get("param_load_table_deg_N")
            if flat is not None:
                arr = np.asarray(flat, dtype=float).reshape(-1, 2)
                kw["load_table"] = tuple((float(a), float(b)) for a, b in arr)
            continue
        key = f"param_{f.name}"
        if key in attrs:
            v = attrs[key]
            if isinstance(v, np.generic):
                v = v.item()
            kw[f.name] = None if v == "default" else v
    if kw.get("load") == "table" and "load_table" in kw:
        kw["load"] = "paper"  # records name the selector 'table'; the table itself is the load
    return CompressorParams(**kw)


def paper_2d12(**overrides: Any) -> CompressorParams:
    """The 2D12 compressor of Xiao et al. (2017), base case rc = d = 1 mm, omega = 20 rad/s.

    Lengths are the paper's; masses and rod inertia are assumptions (`ASSUMED`). Any
    field can be overridden, e.g. ``paper_2d12(rc=0.5e-3, d=0.0)``.
    """
    names = {resolve_name(k): v for k, v in overrides.items()}
    return CompressorParams(**names)
