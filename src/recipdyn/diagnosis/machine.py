"""The machine a diagnoser belongs to (docs/diagnosis.md, "A diagnoser belongs to one machine").

A diagnoser learns one machine: its geometry, masses, cylinder, valves and gas set where the
pins knock, how the pressures rise and fall, what the healthy machine looks like. This module
holds

* the **machine description**: the parameters of the diagnosis model (`MODEL`) that describe
  a machine (`MACHINE_PARAMETERS`) and its nominal operating point (`NOMINAL`), read from a
  machine file by `read_machine` (a config TOML as ``recipdyn simulate --dump-config`` writes
  it, or a recorded run) into a `Machine`;
* what a data set of that machine draws: its operating-condition ranges
  (`condition_ranges`), its fault classes' ranges (`fault_classes`) and its healthy pins
  (`healthy_parameters`), each re-derived from the machine where it depends on it;
* the **tolerances** within which another machine is the same one for a diagnoser
  (`TOLERANCES`, measured by ``benchmarks/bench_machine_tolerances.py``), the comparison
  (`differences`) and the exact commands that build a diagnoser for another machine
  (`build_commands`).

The default machine is the diagnosis model's defaults: a data set without a machine is the
data set it always was, to the bit (`condition_ranges`, `fault_classes` and
`healthy_parameters` return their inputs unchanged for it).
"""

from __future__ import annotations

import math
import shlex
from collections.abc import Mapping
from dataclasses import dataclass, replace
from functools import cache
from pathlib import Path
from typing import Any

from ..errors import ParameterError
from .classes import BASELINE, CLASSES, CONDITIONS, MODEL, FaultClass, Range

__all__ = [
    "MACHINE_PARAMETERS",
    "NOMINAL",
    "CATEGORICAL",
    "Machine",
    "Tolerance",
    "TOLERANCES",
    "read_machine",
    "machine_from_file",
    "condition_ranges",
    "fault_classes",
    "healthy_parameters",
    "differences",
    "build_commands",
]

#: The diagnosis model's parameters that describe a machine: the mechanism's geometry and
#: masses, the pins' and the crosshead's sizes, the cylinder, the valves and the gas. Not
#: here: the operating point (`NOMINAL`, drawn around the machine's nominal one), the fault
#: parameters of `recipdyn.diagnosis.classes.CLASSES` and the healthy pins' clearances
#: (`healthy_parameters`), the contact laws, materials and friction (the model's, the same
#: for every machine a data set simulates), the drive (prescribed) and gravity.
MACHINE_PARAMETERS: tuple[str, ...] = (
    # mechanism
    "r",
    "l",
    "ls",
    "m2",
    "m3",
    "J2",
    # pins and crosshead
    "journal_radius",
    "crosshead_pin_radius",
    "d",
    "crosshead_half_length",
    "crosshead_half_height",
    # cylinder
    "bore",
    "rod_diameter",
    "clearance_fraction",
    "acting",
    "frame_pressure",
    "n_compression",
    "n_expansion",
    "suction_temperature",
    # valves
    "valve_area_fraction",
    "valve_lift",
    "valve_mass",
    "valve_stiffness",
    "valve_preload",
    "valve_damping",
    "valve_force_factor",
    "discharge_coefficient",
    "valve_restitution",
    # gas
    "gas",
    "gas_constant",
    "isentropic_exponent",
)
#: The machine's nominal operating point: the centre of the speed and line-pressure ranges a
#: data set of the machine draws (`condition_ranges`).
NOMINAL: tuple[str, ...] = ("omega", "suction_pressure", "discharge_pressure")
#: Machine parameters that are names: another value is another machine, whatever the rest.
CATEGORICAL: tuple[str, ...] = ("acting", "gas")


def _pairs(values: Mapping[str, Any]) -> tuple[tuple[str, Any], ...]:
    return tuple(sorted((str(k), v) for k, v in values.items()))


@cache
def _model():
    from ..model.registry import get_model

    return get_model(MODEL)


@cache
def _default_values() -> tuple[tuple[str, Any], ...]:
    v = _model().parameters(dict(BASELINE))
    return _pairs({k: v[k] for k in (*MACHINE_PARAMETERS, *NOMINAL)})


@dataclass(frozen=True)
class Machine:
    """A machine description: every parameter of `MACHINE_PARAMETERS` and `NOMINAL`, in SI
    units, validated by the diagnosis model's schema.

    Parameters
    ----------
    values : tuple of (str, value)
        The parameters (sorted pairs; build with `Machine.of`, `Machine.default` or
        `read_machine`).
    source : str
        Where the description came from (a file name, or the model's defaults).
    nominal : bool
        Whether its `NOMINAL` values are the machine's nominal operating point (a machine
        file), not the operating point of one record (a record's own attributes: its speed
        and pressures are then the record's, which `recipdyn diagnose` checks as such).
    """

    values: tuple[tuple[str, Any], ...]
    source: str = "the diagnosis model's defaults"
    nominal: bool = True

    @classmethod
    def default(cls) -> Machine:
        """The diagnosis model's machine (the one every data set simulated before machines
        could be chosen)."""
        return cls(_default_values())

    @classmethod
    def of(cls, changes: Mapping[str, Any] | tuple = (), source: str | None = None) -> Machine:
        """The default machine with ``changes`` (names of `MACHINE_PARAMETERS` or `NOMINAL`,
        numbers in SI or quantity strings), validated by the diagnosis model's schema."""
        from ..config import model_values

        changes = dict(changes)
        bad = [k for k in changes if k not in (*MACHINE_PARAMETERS, *NOMINAL)]
        if bad:
            raise ParameterError(_not_machine(bad[0]))
        if not changes:
            return cls.default() if source is None else replace(cls.default(), source=source)
        values = model_values(_model(), {**dict(BASELINE), **changes})
        merged = dict(_default_values())
        merged.update({k: values[k] for k in merged})
        return cls(_pairs(merged), source or "the diagnosis model's defaults with changes")

    @property
    def as_dict(self) -> dict[str, Any]:
        return dict(self.values)

    def __getitem__(self, name: str) -> Any:
        return self.as_dict[name]

    def changes(self) -> tuple[tuple[str, Any], ...]:
        """The parameters that differ from the default machine (sorted pairs)."""
        base = dict(_default_values())
        return tuple((k, v) for k, v in self.values if base.get(k) != v)

    def pairs(self) -> tuple[tuple[str, Any], ...]:
        """What a data set's spec stores (`recipdyn.diagnosis.dataset.DatasetSpec.machine`):
        every parameter of a machine other than the default one (a parameter the model
        derives from others, the rod's centroid and inertia from its length, keeps the
        machine's own value), nothing for the default machine."""
        return () if self.is_default else self.values

    @property
    def is_default(self) -> bool:
        return not self.changes()

    def text(self, names=None) -> str:
        """``name = value`` of ``names`` (default: the parameters changed from the default)."""
        d = self.as_dict
        keys = list(names) if names is not None else [k for k, _ in self.changes()]
        return ", ".join(f"{k} = {_fmt(d[k])}" for k in keys) or "the default machine"


def _fmt(v: Any) -> str:
    return f"{v:.4g}" if isinstance(v, float) else str(v)


def _not_machine(name: str) -> str:
    from .classes import CLASSES as _C

    faults = {c.parameter for c in _C if c.parameter} | set(BASELINE)
    if name in faults:
        why = "a fault (or the healthy pins') parameter: the data set sets it for each class"
    elif name in ("theta1_0", "g"):
        why = "not a machine parameter"
    else:
        why = "not a machine parameter of the diagnosis model"
    return (
        f"{name}: {why}; allowed: the machine's {', '.join(MACHINE_PARAMETERS)} and its "
        f"nominal operating point {', '.join(NOMINAL)}"
    )


def read_machine(path: str | Path) -> tuple[Any, dict[str, Any]]:
    """(model, values) of a machine file: a config TOML as ``recipdyn simulate --dump-config``
    writes it (``model`` and ``[params]``; the ``[simulation]`` table is not the machine's and
    is ignored), or a recorded run (``.nc``: the parameters it was made with).

    The one entry for machine files: a machine description of another layout (the
    multi-throw machine files of the model redesign) plugs in here. ``values`` are the
    model's validated values in SI units; `machine_from_file` takes the machine out of them.
    """
    from ..config import model_values, read_config
    from ..model.registry import get_model

    path = Path(path)
    if path.suffix.lower() not in (".toml", ".nc"):
        raise ParameterError(
            f"machine {path}: unknown format {path.suffix!r}; allowed: a config .toml "
            "('recipdyn simulate --dump-config FILE') or a recorded run (.nc)"
        )
    if not path.is_file():
        raise ParameterError(f"machine {path}: file not found")
    cfg = read_config(path)
    model = get_model(cfg.model or MODEL)
    return model, model_values(model, dict(cfg.params))


def machine_from_file(path: str | Path, sets: Mapping[str, Any] | None = None) -> Machine:
    """The `Machine` of a machine file (`read_machine`), with ``sets`` (``NAME: VALUE``)
    applied on top. The file's model may be any of the compressor family: its values of
    `MACHINE_PARAMETERS` and `NOMINAL` are taken (a parameter its model lacks keeps the
    diagnosis model's default); the rest of the file (fault parameters, pins, solver) is not
    the machine's and is not read."""
    model, values = read_machine(path)
    mine = {k: values[k] for k in (*MACHINE_PARAMETERS, *NOMINAL) if values.get(k) is not None}
    if not {"r", "l"} <= set(mine):
        raise ParameterError(
            f"machine {path}: model {model.name!r} is not a reciprocating compressor (no "
            "crank radius r and rod length l); allowed: a config of the compressor family"
        )
    mine.update(sets or {})
    return Machine.of(mine, source=str(path))


# ---- what a data set of a machine draws ------------------------------------------------------

#: The condition ranges that scale with the machine: each is the default range times the
#: machine's nominal value of the named parameter over the default machine's (so the same
#: relative spread: speed +-20 %, line pressures and masses +-10 %). The sensor settings
#: (mounting resonance, sampling rate) are the sensor's, not the machine's, and stay.
SCALED_CONDITIONS = {
    "omega": "omega",
    "suction_pressure": "suction_pressure",
    "discharge_pressure": "discharge_pressure",
    "m2": "m2",
    "m3": "m3",
}


def condition_ranges(machine: Machine | None) -> dict[str, Range]:
    """`CONDITIONS` re-derived for ``machine`` (`SCALED_CONDITIONS`); the default machine's are
    `CONDITIONS` itself."""
    if machine is None or machine.is_default:
        return CONDITIONS
    base, mine = dict(_default_values()), machine.as_dict
    out = {}
    for k, r in CONDITIONS.items():
        p = SCALED_CONDITIONS.get(k)
        f = mine[p] / base[p] if p else 1.0
        if f == 1.0:
            out[k] = r
        else:
            m = r.meaning.split(" (")[0]
            out[k] = Range(r.lo * f, r.hi * f, r.unit, f"{m} (x{f:.3g} of the default machine's)")
    return out


def _references(values: Mapping[str, Any]) -> dict[str, float]:
    """The machine quantity each fault's size is relative to (docs/diagnosis.md): a pin's
    clearance to its journal radius (a bearing's clearance is about a thousandth of its
    diameter, new); the guide's to the crosshead's height; a valve leak to the valve's flow
    area (``valve_area_fraction`` of the piston area); the plate's stiction to the spring's
    preload (the classes' meanings: 4 to 60 times it); the rings' leak to the bore (a ring's
    end gap grows with its circumference: engineering judgement); the spring factor is
    relative already."""
    flow = float(values["valve_area_fraction"]) * float(values["bore"]) ** 2
    return {
        "rc": float(values["journal_radius"]),
        "rc_crosshead": float(values["crosshead_pin_radius"]),
        "guide_clearance": float(values["crosshead_half_height"]),
        "leak_area_suction_head": flow,
        "leak_area_discharge_head": flow,
        "adhesion_force_suction_head": float(values["valve_preload"]),
        "ring_leak_area": float(values["bore"]),
    }


def _scale(machine: Machine, parameter: str) -> float:
    base = _references(dict(_default_values())).get(parameter)
    if base is None:
        return 1.0
    mine = _references(machine.as_dict)[parameter]
    return mine / base if base > 0 else 1.0


def fault_classes(machine: Machine | None, classes=CLASSES) -> tuple[FaultClass, ...]:
    """The fault classes of ``machine``: each fault's mild and severe values scaled with the
    machine quantity it is relative to (`_references`); the default machine's are ``classes``
    themselves."""
    if machine is None or machine.is_default:
        return tuple(classes)
    out = []
    for c in classes:
        f = _scale(machine, c.parameter) if c.parameter else 1.0
        out.append(c if f == 1.0 else replace(c, mild=c.mild * f, severe=c.severe * f))
    return tuple(out)


def healthy_parameters(machine: Machine | None) -> dict[str, Any]:
    """The healthy machine's settings (`recipdyn.diagnosis.classes.BASELINE`) for
    ``machine``: its pins' clearances scaled with their journal radii."""
    if machine is None or machine.is_default:
        return dict(BASELINE)
    out = dict(BASELINE)
    for k in ("rc", "rc_crosshead"):
        out[k] = BASELINE[k] * _scale(machine, k)
    return out


# ---- tolerances ------------------------------------------------------------------------------


@dataclass(frozen=True)
class Tolerance:
    """How far a machine parameter may differ before the diagnoser's machine is another one.

    Parameters
    ----------
    relative : float
        The relative change allowed (beyond the range the data set drew, for the masses).
    shift : float
        The measured feature shift of a 10 % change, in healthy residual spreads (the
        largest over the features the classifier reads, averaged over conditions and signs).
    feature : str
        The feature that moved most.
    """

    relative: float
    shift: float
    feature: str


#: The change that moves a feature by this many of the healthy machine's own residual spreads
#: at a fixed operating point (`recipdyn.diagnosis.train.fit_baseline`'s units) is another
#: machine: within it, the record looks like the trained machine's healthy scatter.
SHIFT_LIMIT = 1.0
#: The largest relative change measured; a parameter that moves no feature by `SHIFT_LIMIT`
#: at this change is given this tolerance (no claim beyond what was measured).
TOLERANCE_CAP = 0.3

#: Each numerical machine parameter's tolerance, measured against the shipped diagnoser by
#: ``python benchmarks/bench_machine_tolerances.py --conditions 3`` (345 paired healthy
#: records: 3 held-out conditions, each parameter times 1 -+ 0.1 and 1 -+ 0.3 with the
#: condition and the sensor noise kept): ``Tolerance(relative, sensitivity, feature)``, the
#: sensitivity being the largest slope (lower 2-standard-error bound) of a feature the
#: full-channel classifier reads, in healthy spreads per unit relative change, and the
#: tolerance `SHIFT_LIMIT` over it, at most `TOLERANCE_CAP`. The geometry of the cycle (crank
#: radius, rod, clearance volume) and the gas's polytropic exponents are read directly by the
#: cycle features (each chamber against its ideal cycle of the machine's geometry): 0.5-3.4 %
#: (measured against the drawn-chain diagnoser, whose healthy spreads hold the chains' scatter;
#: against the fixed-chain one before it, 0.06-0.3 %); the valves' own parameters 13-30 %; what
#: the healthy records do not feel at all (the guide's size: only the worn guide's records have
#: a guide that moves) the cap.
TOLERANCES: dict[str, Tolerance] = {
    "r": Tolerance(0.03, 32.9, "cy_diff_do"),
    "l": Tolerance(0.034, 29.6, "cy_diff_do"),
    "ls": Tolerance(0.3, 1.32, "acc_spectral_entropy"),
    "m2": Tolerance(0.3, 0.621, "acc_order_3"),
    "m3": Tolerance(0.3, 2.58, "acc_peak_to_peak"),
    "J2": Tolerance(0.3, 0.000689, "ph_250"),
    "journal_radius": Tolerance(0.3, 0.278, "ang_090"),
    "crosshead_pin_radius": Tolerance(0.3, 0.609, "acc_centroid_hz"),
    "d": Tolerance(0.3, 0.484, "cy_crank_so"),
    "crosshead_half_length": Tolerance(0.3, 0, ""),
    "crosshead_half_height": Tolerance(0.3, 0, ""),
    "bore": Tolerance(0.16, 6.12, "cy_head_do_peak"),
    "rod_diameter": Tolerance(0.3, 0.51, "pc_170"),
    "clearance_fraction": Tolerance(0.0082, 121, "cy_crank_n_exp"),
    "frame_pressure": Tolerance(0.3, 0.0657, "pc_220"),
    "n_compression": Tolerance(0.0051, 198, "cy_crank_n_comp"),
    "n_expansion": Tolerance(0.0051, 195, "cy_crank_n_exp"),
    "suction_temperature": Tolerance(0.26, 3.89, "ph_350"),
    "valve_area_fraction": Tolerance(0.14, 7.27, "ph_350"),
    "valve_lift": Tolerance(0.3, 2.66, "cy_crank_do_peak"),
    "valve_mass": Tolerance(0.3, 3.06, "cy_head_do_peak"),
    "valve_stiffness": Tolerance(0.3, 1.56, "ph_150"),
    "valve_preload": Tolerance(0.3, 0.968, "ph_150"),
    "valve_damping": Tolerance(0.3, 0.165, "ph_140"),
    "valve_force_factor": Tolerance(0.3, 2.54, "cy_head_do_peak"),
    "discharge_coefficient": Tolerance(0.13, 7.71, "ph_350"),
    "valve_restitution": Tolerance(0.3, 0.778, "pc_270"),
    "gas_constant": Tolerance(0.26, 3.89, "ph_350"),
    "isentropic_exponent": Tolerance(0.26, 3.85, "ang_250"),
}


def healthy_spreads(diag) -> dict[str, float]:
    """The healthy machine's own scatter of each feature the full-channel classifier reads, at
    a fixed operating point: the residual standard deviation of an affine fit of the
    diagnoser's healthy training records on the operating point they show (the crank speed,
    the suction and discharge levels: `recipdyn.diagnosis.train.OPERATING`), floored at
    `recipdyn.diagnosis.tolerances.BASELINE_SPREAD_FLOOR` of the feature's spread over every
    training record (as the healthy baseline's, `recipdyn.diagnosis.train.fit_baseline`, for
    the pressure and cycle features; here for every feature). The unit of the tolerances."""
    import numpy as np

    from .channels import _cols
    from .tolerances import BASELINE_SPREAD_FLOOR, OPERATING

    st = diag.state
    names = diag.names
    Z = np.asarray(st["Z_train"], float) * st["scale"] + st["center"]
    healthy = np.array([lab == "healthy" for lab in st["train_labels"]])
    ops = [names.index(o) for o in OPERATING]
    H = Z[healthy]
    ok = np.isfinite(H[:, ops]).all(axis=1)
    H = H[ok]
    A = np.column_stack([np.ones(len(H)), H[:, ops]])
    out = {}
    for j in _cols(names, "full"):
        n = names[j]
        if n in OPERATING:
            continue
        y = H[:, j]
        m = np.isfinite(y)
        if m.sum() <= A.shape[1] + 1:
            continue
        coef, *_ = np.linalg.lstsq(A[m], y[m], rcond=None)
        r = y[m] - A[m] @ coef
        spread = float(np.std(r, ddof=A.shape[1]))
        spread = max(spread, BASELINE_SPREAD_FLOOR * float(np.nanstd(Z[:, j])))
        if spread > 0:
            out[n] = spread
    return out


def feature_shift(a: Mapping[str, float], b: Mapping[str, float], spreads: Mapping[str, float]):
    """``(shift, feature)``: the largest ``|a - b|`` over the features of ``spreads``, in units
    of each feature's spread, and that feature (a feature NaN in one record and not the other
    counts as infinitely far)."""
    best, which = 0.0, ""
    for n, s in spreads.items():
        x, y = a.get(n, math.nan), b.get(n, math.nan)
        if math.isnan(x) and math.isnan(y):
            continue
        d = math.inf if math.isnan(x) or math.isnan(y) else abs(x - y) / s
        if d > best:
            best, which = d, n
    return best, which


def differences(trained: Machine, other: Machine, drawn: Mapping[str, tuple[float, float]]
                ) -> list[str]:  # fmt: skip
    """The parameters of ``other`` beyond the tolerances of ``trained`` (one text each, naming
    the value, the trained one and the tolerance; empty: the same machine).

    ``drawn``: the ranges the diagnoser's data set drew for a machine parameter (the masses,
    `condition_ranges`); such a parameter may lie anywhere in its range widened by its
    tolerance. A categorical parameter (`CATEGORICAL`) must be equal. The machine's nominal
    operating point (`NOMINAL`) must lie in the ranges the data set drew for it, with the
    slack `recipdyn.diagnosis.tolerances.RANGE_SLACK` of the crank speed's refusal (a machine
    read from a record's attributes has no nominal operating point: `Machine.nominal`)."""
    from .tolerances import RANGE_SLACK

    a, b = trained.as_dict, other.as_dict
    out = []
    for k in NOMINAL if other.nominal else ():
        if k in drawn and k in b:
            lo, hi = drawn[k]
            if not lo * (1 - RANGE_SLACK) <= b[k] <= hi * (1 + RANGE_SLACK):
                out.append(
                    f"{k} = {_fmt(b[k])} (nominal; the diagnoser's range: {_fmt(lo)}..{_fmt(hi)})"
                )
    for k in MACHINE_PARAMETERS:
        va, vb = a.get(k), b.get(k)
        if k in CATEGORICAL or not isinstance(va, (int, float)):
            if va != vb:
                out.append(f"{k} = {vb} (the diagnoser's: {va})")
            continue
        tol = TOLERANCES[k].relative
        lo, hi = drawn.get(k, (va, va))
        lo, hi = min(lo, hi), max(lo, hi)
        if not lo - tol * abs(lo) <= vb <= hi + tol * abs(hi):
            where = f"{_fmt(va)}" if lo == hi else f"{_fmt(lo)}..{_fmt(hi)}"
            out.append(
                f"{k} = {_fmt(vb)} (the diagnoser's: {where}, tolerance +-{100 * tol:.2g} %)"
            )
    return out


def drawn_ranges(machine: Machine) -> dict[str, tuple[float, float]]:
    """The machine parameters and the operating point a data set of ``machine`` draws, and
    their ranges."""
    r = condition_ranges(machine)
    return {k: (r[k].lo, r[k].hi) for k in r if k in (*MACHINE_PARAMETERS, *NOMINAL)}


#: The options of ``recipdyn dataset`` that a data set's spec holds, as a data card writes
#: them (`build_commands` repeats a diagnoser's own, so the new one is built as it was).
def _dataset_options(spec: Mapping[str, Any]) -> list[str]:
    opts = ["--conditions", str(spec.get("n_conditions", 16))]
    if spec.get("severity_range") is not None:
        lo, hi = spec["severity_range"]
        opts += ["--severity-range", f"{lo:g},{hi:g}"]
        if spec.get("severity_draws") is not None:
            opts += ["--draws", str(spec["severity_draws"])]
    else:
        opts += ["--levels", ",".join(f"{v:g}" for v in spec.get("levels", (0.25, 0.5, 0.75, 1)))]
    fixed = spec.get("chain", "fixed") == "fixed"  # a spec without one: the fixed chain
    if spec.get("snr_range") is not None:
        lo, hi = spec["snr_range"]
        opts += ["--snr-range", f"{lo:g},{hi:g}"]
    elif fixed:
        opts += ["--snr", f"{spec.get('snr_db', 20.0):g}"]
    if fixed:
        opts += ["--chain", "fixed"]
    for k, flag in (("revolutions", "--revolutions"), ("transient", "--transient"),
                    ("test_fraction", "--test-fraction"), ("seed", "--seed")):  # fmt: skip
        if k in spec:
            opts += [flag, f"{spec[k]:g}" if isinstance(spec[k], float) else str(spec[k])]
    return opts


def build_commands(machine_file: str | Path, spec: Mapping[str, Any], sets=()) -> str:
    """The commands that build a diagnoser for the machine of ``machine_file`` as the
    diagnoser of data-set spec ``spec`` was built (its size, severities, SNRs and seed), and
    diagnose with it."""
    p = Path(machine_file)
    stem = p.stem or "machine"
    ds, model = f"out/{stem}-dataset", f"out/{stem}.skops"
    extra = [a for k, v in sets for a in ("--set", f"{k}={v}")]
    build = ["recipdyn", "dataset", "--machine", str(p), *extra, "-o", ds, *_dataset_options(spec)]
    train = ["recipdyn", "train", ds, "-o", model]
    use = f"recipdyn diagnose RECORD --machine {shlex.quote(str(p))} -m {model}"
    return f"{shlex.join(build)} && {shlex.join(train)}, then {use}"


def record_machine(path: str | Path) -> Machine | None:
    """The machine a record's own attributes reveal: a run of ``recipdyn simulate`` (or a
    sensed copy of one) carries its model and parameters; None for any other record."""
    path = Path(path)
    if path.suffix.lower() != ".nc":
        return None
    from ..io import read_dataset

    try:
        attrs = read_dataset(path, what="record", expected="a NetCDF record").attrs
    except (ParameterError, OSError, ValueError):
        return None
    if not (attrs.get("model_spec") or attrs.get("model_name")) or "param_r" not in attrs:
        return None
    return replace(machine_from_file(path), nominal=False)


def how_to_build(source: str | None, spec: Mapping[str, Any]) -> str:
    """The commands that build a diagnoser for the machine of ``source`` (its machine file,
    or a record of it), or how to describe it first when there is no file."""
    if source and Path(source).suffix in (".toml", ".nc"):
        return build_commands(source, spec)
    return (
        "describe it in a machine file (recipdyn simulate --set NAME=VALUE ... --dump-config "
        "machine.toml) and build one: recipdyn dataset --machine machine.toml -o DS && "
        "recipdyn train DS -o machine.skops"
    )


def refusal(diag, machine: Machine | None) -> str | None:
    """Why ``diag`` must not diagnose a record of ``machine`` (None: it may, or no machine
    is known): the parameters beyond the tolerances and the commands that build a diagnoser
    for that machine."""
    if machine is None:
        return None
    mine = diag.machine
    diffs = differences(mine, machine, drawn_ranges(mine))
    if not diffs:
        return None
    src = machine.source
    how = how_to_build(src, diag.card["spec"])
    return (
        f"another machine ({src}): {'; '.join(diffs)}: this diagnoser was built for "
        f"{mine.text() if not mine.is_default else 'the default machine'} and would answer "
        f"for that one; build a diagnoser for this machine: {how}"
    )
