"""A labelled, physics-generated data set for fault diagnosis (``recipdyn dataset``).

Design: ``n_conditions`` operating conditions (speed, suction and discharge pressure, rod and
crosshead masses, the accelerometer's mounting resonance and the sampling rate), drawn
uniformly from the machine's ranges (`recipdyn.diagnosis.machine.condition_ranges`; the
default machine's are `CONDITIONS`) with a seeded generator; at each condition
every fault class at every severity level (the healthy machine as often as each fault, so the
classes are balanced), or, with ``severity_range``, at severities drawn uniformly (seeded) in
that range; each record sensed at the data set's SNR (`recipdyn.sensors`) with its own noise
seed. The conditions are split whole into train and test sets, so no condition is
shared between them.

Layout of ``OUT``:

``signals.zarr``
    One array per sensed channel (``accel_guide``, ``p_head_sensor``, ``p_crank_sensor``,
    ``tacho``), record by sample (float32, NaN after a record's ``n_samples``), the features
    (``features``, record by feature) and ``done``/``error`` per record.
``features.parquet``
    One row per finished record: labels (class, severity, the fault parameter's value), the
    condition, the sensor settings, the split and every feature.
``datacard.json``, ``datacard.md``
    What each class and severity means physically, the ranges, the class balance, the seeds,
    the recipdyn version and the measured throughput.

The unit of work, `make_record`, is pure and picklable (the same code serially, in a process
pool or on Dask); only the coordinating process writes. A record counts as finished only
after its arrays are written; ``done`` is written last, so an interrupted build resumes
(``resume=True``) with every finished record kept.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
import traceback
import warnings
import zlib
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ParameterError
from .classes import MODEL, class_names, get_class

__all__ = [
    "DatasetSpec",
    "design",
    "make_record",
    "build_dataset",
    "read_features",
    "CHANNELS",
    "split_of",
    "dataset_record",
    "severities",
]

#: The sensed channels stored per record.
CHANNELS = ("accel_guide", "p_head_sensor", "p_crank_sensor", "tacho")
BACKENDS = ("serial", "processes", "dask")
#: How a data set's records are sensed (`DatasetSpec.chain`).
CHAIN_KINDS = ("drawn", "fixed")


@dataclass(frozen=True)
class DatasetSpec:
    """What a data set holds.

    Parameters
    ----------
    n_conditions : int
        Operating conditions drawn (each gets every class at every level).
    levels : tuple of float
        Severity levels in (0, 1] (`FaultClass.value` maps them to the fault parameter).
    snr_db : float
        Accelerometer signal-to-noise ratio, dB.
    revolutions, transient : float
        Crank revolutions recorded after ``transient`` revolutions discarded.
    test_fraction : float
        Share of the conditions held out for testing (at least one condition).
    seed : int
        Seed of the conditions, the split and every record's sensor noise.
    classes : tuple of str
        Class names (default: all of `CLASSES`).
    severity_range : (float, float) or None
        Continuous severities: each fault record's severity drawn uniformly in ``[lo, hi]``
        (``0 <= lo < hi <= 1``) instead of the fixed ``levels``, seeded per condition and
        class (`severity_draws`). None: the fixed levels.
    severity_draws : int or None
        With ``severity_range``: records of each class at each condition (default: as many
        as ``levels``). Ignored without it.
    snr_range : (float, float) or None
        Each record's accelerometer SNR drawn uniformly in ``[lo, hi]`` dB (seeded per
        condition, class and record) instead of ``snr_db`` for all, so that a diagnoser learns
        the machine apart from the sensor's noise floor (docs/diagnosis.md, robustness).
        With the drawn chain it replaces the ranges' accelerometer SNR.
    chain : {"drawn", "fixed"}
        ``drawn`` (default): every record's measurement chain drawn from
        `recipdyn.chain.DEFAULT_RANGES` (seeded per condition, class and record; domain
        randomisation), its resonance and SNR in place of the condition's resonance and
        ``snr_db``. ``fixed``: the one chain every data set used before
        (`recipdyn.chain.legacy_chain`: the condition's resonance, ``snr_db`` or
        ``snr_range``), its records those of earlier versions to the bit.
    chain_spans : tuple of (str, float, float)
        With the drawn chain: ranges that replace `recipdyn.chain.DEFAULT_RANGES`'
        (``(parameter, lo, hi)``, e.g. ``("accelerometer.resonance_hz", 800, 6000)``; applied
        after ``snr_range``), so that a diagnoser can be trained for a chain the default
        ranges do not cover. Empty: the default ranges.
    machine : tuple of (str, value)
        The machine simulated, as its changes from the diagnosis model's defaults
        (`recipdyn.diagnosis.machine.Machine.changes`; a dict is accepted): its operating
        ranges, fault ranges and healthy pins are re-derived from it
        (`recipdyn.diagnosis.machine`). Empty: the default machine.

    Notes
    -----
    A data set's store is identified by `to_json`, which leaves out the continuous-severity
    and SNR-range settings while they are None and the chain while it is ``fixed``, so a
    store built before keeps its identity (and resumes) whatever settings are added here
    later; `from_dict` reads a spec without ``chain`` as the fixed chain it was built with.
    """

    n_conditions: int = 16
    levels: tuple[float, ...] = (0.25, 0.5, 0.75, 1.0)
    snr_db: float = 20.0
    revolutions: float = 2.0
    transient: float = 1.0
    test_fraction: float = 0.25
    seed: int = 0
    classes: tuple[str, ...] = field(default_factory=lambda: tuple(class_names()))
    severity_range: tuple[float, float] | None = None
    severity_draws: int | None = None
    snr_range: tuple[float, float] | None = None
    chain: str = "drawn"
    machine: tuple[tuple[str, Any], ...] = ()
    chain_spans: tuple[tuple[str, float, float], ...] = ()

    def __post_init__(self):
        if not 0 < self.test_fraction < 1:
            raise ParameterError(f"test_fraction = {self.test_fraction!r}; allowed: (0, 1)")
        n, need = self.n_conditions, min_conditions(self.test_fraction)
        if not (isinstance(n, int) and n >= 1):
            raise ParameterError(f"n_conditions = {n!r}; allowed: an integer >= {need}")
        if n - n_test_conditions(n, self.test_fraction) < MIN_TRAIN_CONDITIONS:
            raise ParameterError(
                f"n_conditions = {n} (test_fraction = {self.test_fraction:g}) leaves "
                f"{max(0, n - n_test_conditions(n, self.test_fraction))} training "
                f"condition(s); allowed: n_conditions >= {need} (a diagnoser trains on "
                f"{MIN_TRAIN_CONDITIONS} conditions at least, one to fit and one to calibrate "
                "its severity intervals and out-of-distribution threshold, and tests on 1)"
            )
        if not self.levels or not all(0 < s <= 1 for s in self.levels):
            raise ParameterError(f"levels = {self.levels!r}; allowed: severities in (0, 1]")
        if not -20 <= self.snr_db <= 200:
            raise ParameterError(f"snr_db = {self.snr_db!r}; allowed: [-20, 200] dB")
        if not 1 <= self.revolutions <= 100:
            raise ParameterError(f"revolutions = {self.revolutions!r}; allowed: [1, 100]")
        if not 0 <= self.transient <= 100:
            raise ParameterError(f"transient = {self.transient!r}; allowed: [0, 100]")
        if not (isinstance(self.seed, int) and 0 <= self.seed < 2**63):
            raise ParameterError(f"seed = {self.seed!r}; allowed: an integer >= 0")
        for c in self.classes:
            get_class(c)
        if "healthy" not in self.classes:
            raise ParameterError("classes: must include 'healthy' (the baseline)")
        for name, lo, hi, what in (("severity_range", 0, 1, "severities"),
                                   ("snr_range", -20, 200, "SNRs")):  # fmt: skip
            r = getattr(self, name)
            if r is not None:
                object.__setattr__(self, name, _bounds(r, name, lo, hi, what))
        d = self.severity_draws
        if d is not None and not (isinstance(d, int) and 1 <= d <= 1000):
            raise ParameterError(f"severity_draws = {d!r}; allowed: an integer in [1, 1000]")
        if self.chain not in CHAIN_KINDS:
            raise ParameterError(f"chain = {self.chain!r}; allowed: {', '.join(CHAIN_KINDS)}")
        object.__setattr__(self, "machine", _machine_pairs(self.machine))
        object.__setattr__(self, "chain_spans", _chain_spans(self.chain_spans))
        if self.chain_spans and self.chain != "drawn":
            raise ParameterError("chain_spans: sets the drawn chain's ranges; allowed with "
                                 "chain = drawn")  # fmt: skip
        if self.chain_spans:
            self.chain_ranges  # noqa: B018 - a range the chain cannot hold is refused here

    @property
    def chain_ranges(self):
        """The ranges a drawn chain comes from (`recipdyn.chain.ChainRanges`; ``snr_range``
        replaces the accelerometer's SNR range)."""
        from ..chain import DEFAULT_RANGES, ChainRanges, Span

        ranges = ChainRanges()
        if self.snr_range is not None:
            old = DEFAULT_RANGES["accelerometer.snr_db"]
            lo, hi = self.snr_range
            ranges = ranges.with_spans(
                accelerometer__snr_db=Span(
                    lo, hi, old.unit, old.meaning, "the data set's snr_range"
                )  # fmt: skip
            )
        if self.chain_spans:
            from dataclasses import replace

            ranges = ranges.with_spans(**{
                k.replace(".", "__"): replace(DEFAULT_RANGES[k], lo=lo, hi=hi,
                                              source="the data set's chain_spans")
                for k, lo, hi in self.chain_spans})  # fmt: skip
        return ranges

    @property
    def continuous(self) -> bool:
        """Whether the severities are drawn in `severity_range` (not the fixed levels)."""
        return self.severity_range is not None

    @property
    def per_class(self) -> int:
        """Records of each class at each condition."""
        if self.continuous and self.severity_draws is not None:
            return self.severity_draws
        return len(self.levels)

    def to_json(self) -> str:
        """The spec's identity (a store holds the data set of exactly this string); the
        continuous-severity settings are left out while None (fixed levels)."""
        d = asdict(self)
        for k in ("severity_range", "severity_draws", "snr_range"):
            if d[k] is None:
                del d[k]
        if d["chain"] == "fixed":
            del d["chain"]
        if not d["machine"]:  # the default machine: the store keeps its identity
            del d["machine"]
        if not d["chain_spans"]:
            del d["chain_spans"]
        return json.dumps(d, sort_keys=True)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> DatasetSpec:
        """The spec of a store's ``spec_json`` or a data card's ``spec`` (lists as tuples);
        one without ``chain`` was built with the fixed chain."""
        kw = {k: tuple(v) if isinstance(v, list) else v for k, v in d.items()}
        return cls(**{"chain": "fixed", **kw})


def _machine_pairs(m: Any) -> tuple[tuple[str, Any], ...]:
    """A spec's machine as sorted ``(name, value)`` pairs (a dict, pairs or a JSON list of
    pairs), each name a machine parameter."""
    from .machine import MACHINE_PARAMETERS, NOMINAL, _not_machine

    try:
        pairs = dict(m.items() if hasattr(m, "items") else ((k, v) for k, v in m))
    except (TypeError, ValueError):
        raise ParameterError(f"machine = {m!r}; allowed: pairs (name, value)") from None
    for k in pairs:
        if k not in (*MACHINE_PARAMETERS, *NOMINAL):
            raise ParameterError(_not_machine(k))
    return tuple(sorted(pairs.items()))


def _chain_spans(spans: Any) -> tuple[tuple[str, float, float], ...]:
    """A spec's chain ranges as sorted ``(parameter, lo, hi)``, each parameter a range of
    `recipdyn.chain.DEFAULT_RANGES` (not a choice) and ``lo <= hi``."""
    if not spans:
        return ()
    from ..chain import DEFAULT_RANGES, Span

    out = {}
    for item in spans.items() if hasattr(spans, "items") else spans:
        try:
            k, (lo, hi) = (item[0], item[1]) if len(item) == 2 else (item[0], item[1:])
            lo, hi = float(lo), float(hi)
        except (TypeError, ValueError):
            raise ParameterError(f"chain_spans: {item!r}; allowed: (parameter, lo, hi)") from None
        if not isinstance(DEFAULT_RANGES.get(k), Span):
            spans_ = ", ".join(n for n, r in DEFAULT_RANGES.items() if isinstance(r, Span))
            raise ParameterError(f"chain range {k!r}; allowed: one of {spans_}")
        if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
            raise ParameterError(f"chain range {k} = {lo:g}..{hi:g}; allowed: LO <= HI")
        out[k] = (lo, hi)
    return tuple((k, lo, hi) for k, (lo, hi) in sorted(out.items()))


def spec_machine(spec: DatasetSpec):
    """The `recipdyn.diagnosis.machine.Machine` of ``spec`` (None: the default machine)."""
    if not spec.machine:
        return None
    from .machine import Machine

    return Machine.of(spec.machine, source="the data set's machine")


def _bounds(r: Any, name: str, lo: float, hi: float, what: str) -> tuple[float, float]:
    """``(a, b)`` of a range setting ``r`` with ``lo <= a < b <= hi``, else the refusal naming
    the setting."""
    try:
        a, b = (float(v) for v in r)
    except (TypeError, ValueError):
        a = b = math.nan
    if not lo <= a < b <= hi:
        raise ParameterError(f"{name} = {r!r}; allowed: two {what} {lo} <= lo < hi <= {hi}")
    return a, b


def _conditions(spec: DatasetSpec) -> list[dict[str, float]]:
    from .machine import condition_ranges

    ranges = condition_ranges(spec_machine(spec))
    rng = np.random.default_rng([spec.seed, 0])
    out = []
    for _ in range(spec.n_conditions):
        c = {k: r.draw(rng) for k, r in ranges.items()}
        c["fs"] = round(c["fs"] / 100.0) * 100.0
        out.append(c)
    return out


#: Training conditions a diagnoser needs: one to fit on and one to calibrate on (its
#: severity intervals' conformal quantiles and its out-of-distribution threshold come from
#: whole conditions the fit has not seen: `recipdyn.diagnosis.train`).
MIN_TRAIN_CONDITIONS = 2


def n_test_conditions(n: int, test_fraction: float) -> int:
    """Conditions held out for testing: ``test_fraction`` of ``n``, at least 1 (and at most
    ``n - 1``)."""
    return max(1, min(round(test_fraction * n), n - 1))


def min_conditions(test_fraction: float) -> int:
    """The fewest conditions that leave `MIN_TRAIN_CONDITIONS` for training and one for
    testing at ``test_fraction``."""
    n = MIN_TRAIN_CONDITIONS + 1
    while n - n_test_conditions(n, test_fraction) < MIN_TRAIN_CONDITIONS:
        n += 1
    return n


def split_of(spec: DatasetSpec) -> list[str]:
    """``"train"`` or ``"test"`` per condition (seeded; at least one of each)."""
    n_test = n_test_conditions(spec.n_conditions, spec.test_fraction)
    perm = np.random.default_rng([spec.seed, 1]).permutation(spec.n_conditions)
    test = set(perm[:n_test].tolist())
    return ["test" if i in test else "train" for i in range(spec.n_conditions)]


def severities(spec: DatasetSpec, condition: int, name: str) -> list[float]:
    """The severities of class ``name``'s records at ``condition``: the fixed levels, or
    ``spec.per_class`` draws, uniform in ``spec.severity_range``, from a generator seeded by
    the data set's seed, the condition and the class name (so adding a class or a condition
    leaves the others' draws as they were)."""
    if not spec.continuous:
        return [float(s) for s in spec.levels]
    lo, hi = spec.severity_range
    rng = np.random.default_rng([spec.seed, 3, condition, zlib.crc32(name.encode())])
    return rng.uniform(lo, hi, spec.per_class).tolist()


def snrs(spec: DatasetSpec, condition: int, name: str, n: int) -> list[float]:
    """The accelerometer SNR (dB) of class ``name``'s ``n`` records at ``condition``:
    ``spec.snr_db``, or draws uniform in ``spec.snr_range`` from a generator seeded by the
    data set's seed, the condition and the class name (as `severities`)."""
    if spec.snr_range is None:
        return [float(spec.snr_db)] * n
    lo, hi = spec.snr_range
    rng = np.random.default_rng([spec.seed, 4, condition, zlib.crc32(name.encode())])
    return rng.uniform(lo, hi, n).tolist()


def chain_draw(spec: DatasetSpec, condition: int, name: str, level: int, fs: float):
    """The drawn measurement chain (`recipdyn.chain.Chain`) of record ``level`` of class
    ``name`` at ``condition``: from a generator seeded by the data set's seed, the condition,
    the class name and the record (as `severities`: adding a class, a condition or a record
    leaves the other chains as they were)."""
    rng = np.random.default_rng([spec.seed, 5, condition, zlib.crc32(name.encode()), level])
    return spec.chain_ranges.draw(rng, fs)


def design(spec: DatasetSpec) -> list[dict[str, Any]]:
    """The records of ``spec``: one task per (condition, class, severity), in a fixed order
    (``level`` numbers a class's records at a condition). With the drawn chain each task
    holds its chain (``chain``, `recipdyn.chain.Chain.to_dict`), whose resonance and SNR are
    the task's ``resonance_hz`` and ``snr_db``."""
    from .machine import fault_classes, healthy_parameters

    tasks = []
    splits = split_of(spec)
    machine = spec_machine(spec)
    classes = fault_classes(machine)
    for ci, cond in enumerate(_conditions(spec)):
        for name in spec.classes:
            fc = get_class(name, classes)
            sev = severities(spec, ci, name)
            for li, (s, snr) in enumerate(zip(sev, snrs(spec, ci, name, len(sev)), strict=True)):
                idx = len(tasks)
                params = {} if machine is None else dict(machine.pairs())
                params.update(healthy_parameters(machine))
                params.update(
                    {
                        k: cond[k]
                        for k in ("omega", "suction_pressure", "discharge_pressure", "m2", "m3")
                    }
                )
                params.update(fc.overrides(s))
                tasks.append(
                    {
                        "index": idx,
                        "condition": ci,
                        "split": splits[ci],
                        "label": name,
                        "level": li,
                        "severity": float(s) if fc.parameter else 0.0,
                        "fault_value": fc.value(s) if fc.parameter else math.nan,
                        "params": params,
                        "fs": cond["fs"],
                        "resonance_hz": cond["resonance_hz"],
                        "snr_db": snr,
                        "revolutions": spec.revolutions,
                        "transient": spec.transient,
                        "noise_seed": int(spec.seed * 1_000_003 + idx),
                    }
                )
                if machine is not None:  # the features read the machine's geometry
                    tasks[-1]["machine"] = dict(machine.pairs())
                if spec.chain == "drawn":
                    ch = chain_draw(spec, ci, name, li, cond["fs"])
                    tasks[-1]["chain"] = ch.to_dict()
                    tasks[-1]["resonance_hz"] = ch.accelerometer.resonance_hz
                    tasks[-1]["snr_db"] = ch.accelerometer.snr_db
    return tasks


def snr_text(spec: dict[str, Any]) -> str:
    """The accelerometer SNR (dB) a data set's spec (``asdict``) records at: one value, or
    the range drawn in."""
    r = spec.get("snr_range")
    if r is not None:
        return f"{r[0]:g}..{r[1]:g} (drawn a record)"
    if spec.get("chain", "fixed") == "drawn":
        from ..chain import DEFAULT_RANGES

        a = DEFAULT_RANGES["accelerometer.snr_db"]
        return f"{a.lo:g}..{a.hi:g} (drawn a record)"
    return f"{spec['snr_db']:g}"


def n_samples_max(tasks) -> int:
    return max(
        int(math.ceil(t["revolutions"] * 2 * math.pi / t["params"]["omega"] * t["fs"])) + 2
        for t in tasks
    )


def simulate_record(task: dict[str, Any], *, summary: bool = False):
    """The sensed record (an xarray Dataset) of one task. ``summary``: also compute the
    simulation's run summary into the attrs (the data set reads the signals only; the
    summary is a tenth of a record's time)."""
    from .. import sensors
    from ..simulate import simulate

    with warnings.catch_warnings():  # the healthy pins stretch Hertz's law (docs/diagnosis.md)
        warnings.simplefilter("ignore")
        ds = simulate(
            model=MODEL,
            revolutions=task["revolutions"],
            transient=task["transient"],
            fs=task["fs"],
            summary=summary,
            **task["params"],
        )
    if "chain" in task:  # a drawn chain; a task without one has the fixed chain
        from ..chain import Chain

        return sensors.record(ds, chain=Chain.from_dict(task["chain"]), seed=task["noise_seed"])
    return sensors.record(
        ds,
        accelerometer=sensors.Accelerometer(
            snr_db=task["snr_db"], resonance_hz=task["resonance_hz"]
        ),
        pressure=sensors.PressureTransducer(),
        tacho=sensors.Tacho(),
        seed=task["noise_seed"],
    )


def _revs(channels: dict[str, np.ndarray], fs: float, speed_hz: float) -> np.ndarray:
    """The crank angle a data set's features read: from the tacho's first edge at the
    record's constant crank speed (a short record has too few pulses for the speed to be
    read from them)."""
    from ..analysis.vibration import tacho_times

    edges = tacho_times(channels["tacho"], fs)
    if edges.size == 0:
        raise ValueError("no tacho edge in the record")
    return (np.arange(channels["accel_guide"].size) / fs - edges[0]) * speed_hz


def features_of(
    channels: dict[str, np.ndarray], fs: float, speed_hz: float, machine=None
) -> dict[str, float]:
    """A record's features from its sensed channels (the crank angle: `_revs`);
    ``machine``: the changes of the machine the record's cycle features are read against
    (None: the default machine)."""
    from .evidence import record_features

    revs = _revs(channels, fs, speed_hz)
    return record_features(
        channels["accel_guide"], fs, revs, p_head=channels.get("p_head_sensor"),
        p_crank=channels.get("p_crank_sensor"), machine=machine,
    )  # fmt: skip


def chamber_fits(channels: dict[str, np.ndarray], fs: float, speed_hz: float, machine=None) -> dict:
    """Each chamber's `recipdyn.diagnosis.correction.pressure_phase` on the record's crank
    angle (`_revs`), JSON-able: what the chain correction of a drawn-chain data set reads
    (``machine``: the changes of the machine whose chambers they are; None: the default)."""
    from .correction import pressure_phase

    revs = _revs(channels, fs, speed_hz)
    revs = np.where(revs >= 0, revs, np.nan)
    out = {}
    for ch in ("head", "crank"):
        p = channels.get(f"p_{ch}_sensor")
        if p is not None:
            out[ch] = {k: (float(v) if isinstance(v, (float, np.floating)) else v)
                       for k, v in pressure_phase(p, revs, ch, machine).items()}  # fmt: skip
    return out


def corrected_features(
    channels, fs: float, speed_hz: float, reference, fits, condition=None, machine=None
):
    """``(features or None, correction)``: the record's chain estimated and corrected as
    `recipdyn diagnose` does (`recipdyn.diagnosis.correction.correct_chain`, against
    ``reference``, from its stored ``fits``, its own ``condition`` left out of the
    reference), then its features (``machine``: the changes of the data set's machine);
    None where the correction refuses the record."""
    from .correction import correct_chain
    from .evidence import record_features

    revs = _revs(channels, fs, speed_hz)
    fix = correct_chain(
        revs,
        p_head=channels.get("p_head_sensor"),
        p_crank=channels.get("p_crank_sensor"),
        reference=reference,
        fits=fits,
        exclude_condition=condition,
        machine=machine,
    )
    if fix.refused:
        return None, fix
    feats = record_features(
        channels["accel_guide"], fs, fix.revs, p_head=fix.p_head, p_crank=fix.p_crank,
        machine=machine,
    )  # fmt: skip
    return feats, fix


def make_record(task: dict[str, Any]) -> dict[str, Any]:
    """Simulate, sense and featurise one record (pure: the result depends on ``task`` only).

    Returns ``{"index", "error", "channels", "features", "seconds"}``; a failure is returned
    as ``error`` (the build goes on)."""
    t0 = time.perf_counter()
    out: dict[str, Any] = {"index": task["index"], "error": ""}
    try:
        rec = simulate_record(task)
        ch = {c: np.asarray(rec[c].values, dtype=np.float32) for c in CHANNELS}
        out["channels"] = ch
        speed = task["params"]["omega"] / (2 * math.pi)
        chd = {k: v.astype(float) for k, v in ch.items()}
        out["features"] = features_of(chd, task["fs"], speed, task.get("machine"))
        if "chain" in task:  # a drawn chain: what its correction reads (_correct_records)
            out["fits"] = chamber_fits(chd, task["fs"], speed, task.get("machine"))
    except Exception as exc:  # noqa: BLE001 - recorded; the data set goes on
        out["error"] = f"{type(exc).__name__}: {exc} | {traceback.format_exc(limit=2)}"
    out["seconds"] = time.perf_counter() - t0
    return out


def _make_records(tasks):
    return [make_record(t) for t in tasks]


def feature_names() -> list[str]:
    """The feature columns, in order (from a synthetic record: the names do not depend on
    the values)."""
    from .evidence import record_features

    fs, n = 10_000.0, 8_000
    t = np.arange(n) / fs
    x = np.sin(2 * np.pi * 40 * t) + 0.01 * np.cos(2 * np.pi * 1700 * t)
    return list(record_features(x, fs, 3.0 * t, p_head=2 + x, p_crank=2 - x))


def _open_store(path: Path, spec: DatasetSpec, tasks, resume: bool, force: bool):
    import zarr

    n, m = len(tasks), n_samples_max(tasks)
    names = feature_names()
    if path.exists() and not force:
        g = zarr.open_group(str(path), mode="r+")
        if g.attrs.get("spec_json") != spec.to_json():
            raise ParameterError(
                f"{path.parent}: holds a data set of another spec; use "
                "another --out, or --force to start over"
            )
        if not resume:
            raise ParameterError(
                f"{path.parent}: a data set exists; --resume to continue it, --force to start over"
            )
        if spec.chain == "drawn":
            _chain_arrays(g, len(tasks))
        return g, names
    g = zarr.open_group(str(path), mode="w")
    chunk = (1, m)
    for c in CHANNELS:
        g.create_array(c, shape=(n, m), chunks=chunk, dtype="f4", fill_value=np.nan)
    g.create_array(
        "features", shape=(n, len(names)), chunks=(1, len(names)), dtype="f8", fill_value=np.nan
    )
    g.create_array("n_samples", shape=(n,), chunks=(n,), dtype="i8", fill_value=0)
    g.create_array("done", shape=(n,), chunks=(1,), dtype=bool, fill_value=False)
    g.create_array("error", shape=(n,), chunks=(1,), dtype=str)
    g.create_array("seconds", shape=(n,), chunks=(1,), dtype="f8", fill_value=np.nan)
    if spec.chain == "drawn":  # each record's drawn chain, as JSON
        g.create_array("chain", shape=(n,), chunks=(n,), dtype=str)
        g["chain"][:] = np.array([json.dumps(t["chain"]) for t in tasks])
        _chain_arrays(g, n)
    from .. import __version__

    g.attrs.update(
        {
            "spec_json": spec.to_json(),
            "feature_names": names,
            "recipdyn_version": __version__,
            "channels": list(CHANNELS),
        }
    )
    return g, names


def _chain_arrays(g, n: int) -> None:
    """A drawn-chain store's per-record chain correction (JSON strings): the chambers' fits
    (`chamber_fits`), the estimates and the refusal (`_correct_records`)."""
    for name in ("chain_fits", "chain_estimates", "chain_refused"):
        if name not in g:
            g.create_array(name, shape=(n,), chunks=(n,), dtype=str)


def _write(g, res: dict[str, Any], names: list[str]) -> None:
    i = res["index"]
    if "fits" in res:
        g["chain_fits"][i] = json.dumps(res["fits"])
    if not res["error"]:
        for c, y in res["channels"].items():
            row = np.full(g[c].shape[1], np.nan, np.float32)
            row[: y.size] = y[: row.size]
            g[c][i, :] = row
        g["n_samples"][i] = int(res["channels"]["accel_guide"].size)
        g["features"][i, :] = np.array([res["features"][k] for k in names], float)
    g["error"][i] = res["error"][:2000]
    g["seconds"][i] = res["seconds"]
    g["done"][i] = True  # last: a record is done once its data are written


def build_dataset(
    out: str | Path,
    spec: DatasetSpec = DatasetSpec(),
    *,
    backend: str = "processes",
    workers: int | None = None,
    dask_local: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    force: bool = False,
    progress: bool = True,
    on_record: Callable[[dict[str, Any]], None] | None = None,
) -> Path:
    """Build (or resume) the data set of ``spec`` in the folder ``out``; returns ``out``.

    ``backend``: ``serial``, ``processes`` (``workers``, default all cores) or ``dask``
    (``dask_local`` workers of a local cluster, or ``scheduler``, an existing one).
    ``on_record`` is called in this process after each record is stored (tests use it to
    interrupt a build). Raises `ParameterError` for bad settings or an existing data set
    without ``resume``/``force``; [`Interrupted`][recipdyn.errors.Interrupted] on SIGINT/SIGTERM,
    with every finished record kept."""
    from ..errors import deferred_signals
    from ..locking import RunLock

    if backend not in BACKENDS:
        raise ParameterError(f"backend = {backend!r}; allowed: {', '.join(BACKENDS)}")
    if workers is not None and not (isinstance(workers, int) and workers >= 1):
        raise ParameterError(f"workers = {workers!r}; allowed: an integer >= 1")
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"--out {out}: is a file; expected a folder")
    out.mkdir(parents=True, exist_ok=True)
    tasks = design(spec)
    with RunLock(out, "dataset"):
        g, names = _open_store(out / "signals.zarr", spec, tasks, resume, force)
        done = np.asarray(g["done"][:])
        todo = [t for t in tasks if not done[t["index"]]]
        n_workers = 1 if backend == "serial" else (workers or dask_local or os.cpu_count() or 1)
        t0 = time.perf_counter()
        count = {"n": 0, "failed": 0, "last": t0}

        def accept(res):
            _write(g, res, names)
            count["n"] += 1
            count["failed"] += bool(res["error"])
            now = time.perf_counter()
            if progress and (now - count["last"] > 2.0 or count["n"] == len(todo)):
                rate = count["n"] / (now - t0)
                left = (len(todo) - count["n"]) / rate if rate > 0 else math.nan
                print(
                    f"dataset: {count['n']}/{len(todo)} records ({count['failed']} failed), "
                    f"{rate:.2f} records/s, {left:.0f} s left",
                    file=sys.stderr,
                    flush=True,
                )
                count["last"] = now
            if on_record is not None:
                on_record(res)

        with deferred_signals() as pending:
            if backend == "serial":
                for t in todo:
                    accept(make_record(t))
                    pending.check()
            elif backend == "processes":
                from ..parallel import run_unordered

                run_unordered(make_record, todo, n_workers, accept, pending)
            else:
                n_workers = _run_dask(todo, dask_local, scheduler, workers, accept, pending)
        wall = time.perf_counter() - t0
        throughput = {
            "records": count["n"],
            "failed": count["failed"],
            "wall_s": wall,
            "workers": n_workers,
            "backend": backend,
            "records_per_s_per_core": count["n"] / wall / n_workers
            if wall > 0 and count["n"]
            else math.nan,
            "reused": len(tasks) - len(todo),
        }
        _finish(out, g, spec, tasks, names, throughput)
    if progress:
        print(
            f"dataset: {count['n']} computed ({count['failed']} failed), "
            f"{len(tasks) - len(todo)} reused, {wall:.1f} s -> {out}",
            file=sys.stderr,
        )
    return out


def recompute_features(folder: str | Path, *, progress: bool = True) -> Path:
    """Recompute every finished record's features from its stored channels (after the
    features changed; the simulation is not repeated) and rewrite the table and card."""
    import zarr

    folder = Path(folder)
    g = zarr.open_group(str(folder / "signals.zarr"), mode="r+")
    spec = DatasetSpec.from_dict(json.loads(g.attrs["spec_json"]))
    tasks = design(spec)
    names = feature_names()
    if g["features"].shape[1] != len(names):
        old = np.asarray(g["features"][:])
        del g["features"]
        g.create_array(
            "features",
            shape=(old.shape[0], len(names)),
            chunks=(1, len(names)),
            dtype="f8",
            fill_value=np.nan,
        )
    done, err = np.asarray(g["done"][:]), np.asarray(g["error"][:])
    for t in tasks:
        i = t["index"]
        if not done[i] or err[i]:
            continue
        n = int(g["n_samples"][i])
        ch = {c: np.asarray(g[c][i, :n], float) for c in CHANNELS}
        f = features_of(ch, t["fs"], t["params"]["omega"] / (2 * math.pi), t.get("machine"))
        g["features"][i, :] = np.array([f[k] for k in names], float)
        if spec.chain == "drawn":  # the fits the correction reads (_finish corrects)
            _chain_arrays(g, len(tasks))
            fit = chamber_fits(ch, t["fs"], t["params"]["omega"] / (2 * math.pi), t.get("machine"))
            g["chain_fits"][i] = json.dumps(fit)
    g.attrs["feature_names"] = names
    card = json.loads((folder / "datacard.json").read_text(encoding="utf-8"))
    _finish(folder, g, spec, tasks, names, card["throughput"])
    return folder


def _run_dask(todo, dask_local, scheduler, workers, accept, pending) -> int:
    from dask.distributed import Client, LocalCluster, as_completed

    cluster = None
    if scheduler:
        client = Client(scheduler)
        n = max(1, len(client.scheduler_info().get("workers", {})))
    else:
        n = dask_local or workers or os.cpu_count() or 1
        cluster = LocalCluster(
            n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None
        )
        client = Client(cluster)
    try:
        futures = as_completed([client.submit(_make_records, [t], pure=False) for t in todo])
        for fut in futures:
            for res in fut.result():
                accept(res)
            pending.check()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return n


def _table(g, tasks, names: list[str]):
    import pandas as pd

    done = np.asarray(g["done"][:])
    err = np.asarray(g["error"][:])
    feats = np.asarray(g["features"][:])
    rows = []
    for t in tasks:
        i = t["index"]
        if not done[i] or err[i]:
            continue
        p = t["params"]
        row = {
            "record": i,
            "condition": t["condition"],
            "split": t["split"],
            "label": t["label"],
            "level": t["level"],
            "severity": t["severity"],
            "fault_value": t["fault_value"],
            "omega": p["omega"],
            "suction_pressure": p["suction_pressure"],
            "discharge_pressure": p["discharge_pressure"],
            "m2": p["m2"],
            "m3": p["m3"],
            "fs": t["fs"],
            "resonance_hz": t["resonance_hz"],
            "snr_db": t["snr_db"],
            "noise_seed": t["noise_seed"],
        }
        if "chain" in t:
            from ..chain import Chain

            row.update({f"chain.{k}": v for k, v in Chain.from_dict(t["chain"]).columns().items()})
            if "chain_refused" in g:  # the correction's estimates and refusal (_correct_records)
                row["chain_refused"] = str(g["chain_refused"][i])
                raw = str(g["chain_estimates"][i])
                for k, (v, u, _) in (json.loads(raw) if raw else {}).items():
                    row[f"est.{k}"], row[f"est.{k}.u95"] = v, u
        row.update({f"f_{k}": v for k, v in zip(names, feats[i], strict=True)})
        rows.append(row)
    return pd.DataFrame(rows)


#: Columns of the feature table that describe the condition (not the fault).
CONDITION_COLUMNS = (
    "omega",
    "suction_pressure",
    "discharge_pressure",
    "m2",
    "m3",
    "fs",
    "resonance_hz",
)


def _correct_records(g, tasks, names) -> dict[str, Any]:
    """A drawn-chain data set's records, put through the chain correction `recipdyn
    diagnose` runs (issue 42): the reference is built from the training records' fits with
    each one's drawn chain taken off (`recipdyn.diagnosis.correction.known_chain`); every
    record is then corrected against it (its own condition left out, as a new record's
    would be) and its features recomputed from the corrected channels, so the training
    features carry the estimator's real errors; a record the correction refuses keeps its
    reason (``chain_refused``) and is left out of training. Each record's estimates are
    stored beside its drawn chain, and their coverage is measured here."""
    from ..chain import Chain
    from .correction import known_chain, reference_from

    done, err = np.asarray(g["done"][:]), np.asarray(g["error"][:])
    ok = [t for t in tasks if done[t["index"]] and not err[t["index"]]]
    t0 = time.perf_counter()

    def channels(i):
        n = int(g["n_samples"][i])
        return {c: np.asarray(g[c][i, :n], float) for c in CHANNELS}

    fits, truth = {}, {}
    for t in ok:
        i, speed = t["index"], t["params"]["omega"] / (2 * math.pi)
        raw = str(g["chain_fits"][i])
        fits[i] = (
            json.loads(raw) if raw else chamber_fits(channels(i), t["fs"], speed, t.get("machine"))
        )
        row = {f"chain.{k}": v for k, v in Chain.from_dict(t["chain"]).columns().items()}
        truth[i] = [known_chain(row, k, speed) for k in (0, 1)]
    ref_fits = []
    for t in ok:
        if t["split"] != "train":
            continue
        i = t["index"]
        f = {"condition": t["condition"]}
        for k, ch in enumerate(("head", "crank")):
            r = dict(fits[i].get(ch, {"ok": False}))
            if r.get("ok"):
                phase, offset, gain = truth[i][k]
                r["phase_deg"] -= phase
                r["offset_pa"] -= offset
                r["p_lo"] = (r["p_lo"] - offset) / gain
                r["p_hi"] = (r["p_hi"] - offset) / gain
            f[ch] = r
        ref_fits.append(f)
    ref = reference_from(ref_fits, source=f"{len(ref_fits)} training records, drawn chains")
    if not ref.rows:
        return {"reference": None, "refused": 0, "records": len(ok),
                "note": "too few training records for a reference: not corrected"}  # fmt: skip
    hits: dict[str, list[int]] = {}
    refused = 0
    for t in ok:
        i, speed = t["index"], t["params"]["omega"] / (2 * math.pi)
        feats, fix = corrected_features(
            channels(i), t["fs"], speed, ref, fits[i], t["condition"], t.get("machine")
        )
        est = {k: [e.value, e.uncertainty, e.status] for k, e in fix.estimates.items()}
        g["chain_estimates"][i] = json.dumps(est)
        g["chain_refused"][i] = fix.refused[:500]
        if feats is None:
            refused += 1
            continue
        g["features"][i, :] = np.array([feats[k] for k in names], float)
        (ph, oh, gh), (pc, oc, gc) = truth[i]
        want = {"phase_head": ph, "phase_crank": pc, "offset_head": oh,
                "offset_crank": oc, "gain_ratio": gh / gc - 1.0}  # fmt: skip
        for k, w in want.items():
            e = fix.estimates.get(k)
            if e is not None and math.isfinite(e.value) and math.isfinite(e.uncertainty):
                h = hits.setdefault(k, [0, 0])
                h[0] += abs(e.value - w) <= e.uncertainty
                h[1] += 1
    return {
        "reference": ref.to_dict(),
        "records": len(ok),
        "refused": refused,
        "coverage": {k: {"within": h[0], "of": h[1]} for k, h in hits.items()},
        "seconds": time.perf_counter() - t0,
    }


def _finish(out: Path, g, spec: DatasetSpec, tasks, names, throughput) -> None:
    from .. import __version__
    from ..io import atomic_path

    correction = _correct_records(g, tasks, names) if spec.chain == "drawn" else None
    df = _table(g, tasks, names)
    with atomic_path(out / "features.parquet") as tmp:
        df.to_parquet(tmp, index=False)
    card = datacard(spec, df, throughput, __version__)
    if correction is not None:
        card["chain_correction"] = correction
    with atomic_path(out / "datacard.json") as tmp:
        Path(tmp).write_text(json.dumps(card, indent=1, default=float), encoding="utf-8")
    with atomic_path(out / "datacard.md") as tmp:
        Path(tmp).write_text(datacard_markdown(card), encoding="utf-8")


def datacard(spec: DatasetSpec, df, throughput: dict, version: str) -> dict[str, Any]:
    """The data card: what the data set holds and how it was made."""
    from .machine import condition_ranges, fault_classes, healthy_parameters

    machine = spec_machine(spec)
    known = fault_classes(machine)
    classes = []
    for name in spec.classes:
        fc = get_class(name, known)
        classes.append(
            {
                "name": fc.name,
                "parameter": fc.parameter,
                "meaning": fc.meaning,
                "unit": fc.unit,
                "scale": fc.scale,
                "mild": fc.mild,
                "severe": fc.severe,
                "values": [fc.value(s) for s in spec.levels]
                if fc.parameter and not spec.continuous
                else [],
                "value_range": [fc.value(s) for s in spec.severity_range]
                if fc.parameter and spec.continuous
                else [],
            }
        )
    balance = {}
    if len(df):
        for split in ("train", "test"):
            sub = df[df.split == split]
            balance[split] = {k: int(v) for k, v in sub.label.value_counts().sort_index().items()}
    return {
        "recipdyn_version": version,
        "model": MODEL,
        "baseline": healthy_parameters(machine),
        "machine": machine.as_dict if machine is not None else {},
        "spec": asdict(spec),
        "classes": classes,
        "conditions": {
            k: {"lo": r.lo, "hi": r.hi, "unit": r.unit, "meaning": r.meaning}
            for k, r in condition_ranges(machine).items()
            if not (spec.chain == "drawn" and k == "resonance_hz")  # the chain's, below
        },
        "sensors": _sensors_card(spec),
        "chain": _chain_card(spec),
        "seeds": {
            "conditions": [spec.seed, 0],
            "split": [spec.seed, 1],
            "noise": f"{spec.seed} * 1000003 + record index",
        },
        "severities": {
            "kind": "uniform",
            "range": list(spec.severity_range),
            "per_class": spec.per_class,
            "seed": f"[{spec.seed}, 3, condition, crc32(class name)]",
        }
        if spec.continuous
        else {"kind": "levels", "levels": list(spec.levels), "per_class": spec.per_class},
        "split": "by operating condition: no condition has records in both train and test",
        "records": int(len(df)),
        "balance": balance,
        "throughput": throughput,
    }


def _sensors_card(spec: DatasetSpec) -> dict[str, str]:
    if spec.chain == "drawn":
        return {"all": "recipdyn.chain.ChainRanges().draw(rng, fs) per record (chain, below), "
                "applied by recipdyn.sensors.record(..., chain=...)"}  # fmt: skip
    snr = (
        f"{spec.snr_db}"
        if spec.snr_range is None
        else f"<drawn uniformly in [{spec.snr_range[0]}, {spec.snr_range[1]}] a record>"
    )
    return {
        "accelerometer": f"recipdyn.sensors.Accelerometer(snr_db={snr}, "
        "resonance_hz=<condition>), other settings default",
        "pressure": "recipdyn.sensors.PressureTransducer() (60 dB)",
        "tacho": "recipdyn.sensors.Tacho() (mark at outer dead centre)",
    }


def _chain_card(spec: DatasetSpec) -> dict[str, Any]:
    """The data card's measurement chain: fixed, or the ranges drawn from with their
    sources."""
    if spec.chain == "fixed":
        return {"kind": "fixed", "chain": "recipdyn.chain.legacy_chain(<condition's "
                "resonance>, <snr>): the one chain of every record"}  # fmt: skip
    from ..chain import SOURCES

    return {
        "kind": "drawn",
        "seed": f"[{spec.seed}, 5, condition, crc32(class name), record]",
        "response": "exact (the continuous-time response at every frequency of the record)",
        "ranges": spec.chain_ranges.describe(),
        "sources": SOURCES,
        "per_record": "features.parquet columns chain.*; signals.zarr array chain (JSON)",
    }


def datacard_markdown(card: dict[str, Any]) -> str:
    s = card["spec"]
    sev = card.get("severities", {"kind": "levels"})
    if sev["kind"] == "uniform":
        lo, hi = sev["range"]
        how = (
            f"{sev['per_class']} records of each class with severities drawn uniformly in "
            f"[{lo:g}, {hi:g}]"
        )
        head = "values over the severity range"
    else:
        how = f"{len(s['levels'])} severity levels {s['levels']}"
        head = "values at the levels"
    lines = [
        f"# Data card (recipdyn {card['recipdyn_version']})",
        "",
        f"Model `{card['model']}`, healthy baseline {card['baseline']}; "
        f"{s['n_conditions']} operating conditions x {len(s['classes'])} classes x "
        f"{how}; {s['revolutions']} "
        f"revolutions after {s['transient']}; accelerometer SNR "
        f"{snr_text(s)} dB; "
        f"seed {s['seed']}. {card['split']}.",
        "",
        "Machine: "
        + (
            ", ".join(
                f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                for k, v in s.get("machine") or ()
            )
            + " (changed from the diagnosis model's defaults; ranges and fault values "
            "re-derived for it: recipdyn.diagnosis.machine)"
            if s.get("machine")
            else "the diagnosis model's defaults"
        ),
        "",
        f"| class | parameter | {head} | meaning |",
        "|---|---|---|---|",
    ]
    for c in card["classes"]:
        v = c.get("value_range") or c["values"]
        sep = " .. " if c.get("value_range") else ", "
        vals = sep.join(f"{x:.3g}" for x in v) + f" {c['unit']}" if v else ""
        lines.append(f"| {c['name']} | {c['parameter'] or ''} | {vals} | {c['meaning']} |")
    lines += ["", "| condition | range | meaning |", "|---|---|---|"]
    for k, r in card["conditions"].items():
        lines.append(f"| {k} | {r['lo']:g} .. {r['hi']:g} {r['unit']} | {r['meaning']} |")
    chain = card.get("chain", {"kind": "fixed"})
    if chain["kind"] == "drawn":
        lines += ["", f"Measurement chain: drawn per record (seed {chain['seed']}), applied "
                  "with the exact response.", "", "| parameter | range | meaning | source |",
                  "|---|---|---|---|"]  # fmt: skip
        for r in chain["ranges"]:
            lines.append(f"| {r['parameter']} | {r['range']} | {r['meaning']} | {r['source']} |")
        lines += ["", "Sources:", ""]
        lines += [f"- `{k}`: {v}" for k, v in chain["sources"].items()]
    else:
        lines += ["", "Measurement chain: fixed (recipdyn.chain.legacy_chain)."]
    cc = card.get("chain_correction")
    if cc:
        cov = ", ".join(
            f"{k} {v['within']}/{v['of']}" for k, v in (cc.get("coverage") or {}).items()
        )
        lines += [
            "",
            f"Chain correction (as `recipdyn diagnose` runs it, before the features): "
            f"{cc['refused']} of {cc['records']} records refused (left out of training); "
            f"estimates within their 95 % intervals of the drawn chain: {cov or 'none'}"
            + (f"; {cc['note']}" if cc.get("note") else "")
            + ".",
        ]
    lines += [
        "",
        "Class balance (records): " + json.dumps(card["balance"]),
        "",
        "Throughput: " + json.dumps(card["throughput"], default=float),
        "",
    ]
    return "\n".join(lines)


def read_features(folder: str | Path):
    """The feature table and the data card of a data set folder."""
    import pandas as pd

    folder = Path(folder)
    table, card = folder / "features.parquet", folder / "datacard.json"
    if not folder.is_dir():
        raise ParameterError(f"{folder}: no such folder; build a data set there with "
                             f"'recipdyn dataset -o {folder}'")  # fmt: skip
    if (folder / "signals.zarr").is_dir() and not table.exists():
        try:
            done = records_done(folder)
            count = f" ({int(done.sum())} of {done.size} records)"
        except Exception:  # noqa: BLE001 - a store too damaged to count: said without
            count = ""
        raise ParameterError(
            f"{folder}: an unfinished data set{count}: finish it with 'recipdyn dataset -o "
            f"{folder} --resume' and the options that started it"
        )
    if not table.exists() or not card.exists():
        raise ParameterError(
            f"{folder}: not a data set (no features.parquet/datacard.json); "
            "build one with 'recipdyn dataset'"
        )
    return pd.read_parquet(table), json.loads(card.read_text(encoding="utf-8"))


def dataset_record(folder: str | Path, index: int) -> dict[str, Any]:
    """One stored record of a data set: its sensed channels (``CHANNELS``, float arrays),
    ``fs`` and its row of the feature table (labels, condition, split)."""
    import zarr

    df, _ = read_features(folder)
    rows = df[df.record == index]
    if rows.empty:
        raise ParameterError(
            f"index = {index!r}; allowed: a finished record of {folder} "
            f"({', '.join(str(i) for i in df.record.head(5))}, ...)"
        )
    g = zarr.open_group(str(Path(folder) / "signals.zarr"), mode="r")
    n = int(g["n_samples"][index])
    out: dict[str, Any] = {c: np.asarray(g[c][index, :n], float) for c in CHANNELS}
    out["fs"] = float(rows.fs.iloc[0])
    out["row"] = rows.iloc[0].to_dict()
    return out


def records_done(folder: str | Path) -> np.ndarray:
    import zarr

    return np.asarray(zarr.open_group(str(Path(folder) / "signals.zarr"), mode="r")["done"][:])


def classes_of(card) -> list:
    from .machine import fault_classes

    known = fault_classes(spec_machine(DatasetSpec.from_dict(card["spec"])))
    return [get_class(n, known) for n in card["spec"]["classes"]]
