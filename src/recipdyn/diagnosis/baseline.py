"""The machine's own healthy baseline (``recipdyn baseline``; docs/diagnosis.md).

A diagnoser is built for a machine description; the machine itself differs from it in what
no drawing gives exactly (its masses, its clearance volume, its valve springs and lifts), and
its measurement chain has its own errors (the pressure transducers' offsets, the tacho mark's
angle from outer dead centre, the accelerometer's mounting resonance). Condition monitoring
refers a machine's readings to its own healthy state after an overhaul; this module does it
with the simulator:

1. **The chain, first estimate** (`ChainEstimator`): any callable ``record -> ChainEstimate``
   gives the fit its starting values and priors for the offsets and the mark angle, and the
   mounting resonance. The default, `estimate_chain`, is the record-level estimators of
   `recipdyn.diagnosis.correction` (the polytropes' phase and offsets, the mount's
   spectrum); another estimator plugs in by the ``estimator`` argument.
2. **The fit** (`fit_machine`): the simulator's healthy machine, its `UNCERTAIN` parameters
   free within their ranges, each record's line pressures free, and the chain's offsets and
   mark angle, fitted to the records' chamber pressures over the revolution (one-degree bins)
   by regularised nonlinear least squares (`scipy.optimize.least_squares`, a Gaussian prior
   from each range, a finite-difference Jacobian whose simulations run in a process pool).
   The uncertainty is the Laplace approximation at the optimum, the residuals' scale and
   lag-1 autocorrelation taken into the covariance, so the intervals widen where the
   pressures cannot tell a parameter (the masses, which the pressures barely see).
3. **The referral** (`build_baseline`, `Baseline.refer`): every later record's features,
   after its chain is corrected (offsets removed, crank angle re-phased), are referred to
   the machine's own healthy records: the healthy records' pressure and cycle features less
   what the diagnoser's healthy machine shows at their operating points (its own healthy
   baseline, `recipdyn.diagnosis.train.fit_baseline`, which carries the operating point's
   effect) is the machine's healthy offset, taken off; the diagnoser then reads deviations
   from the machine's own healthy state. The healthy machine with the fitted parameters and
   the diagnoser's nominal one are also simulated and sensed at each record's operating
   point (the model's referral, kept for comparison, and the check of the records against
   the fit). The acceleration's features are not referred: the masses that act on them are
   not fitted, and two simulated records' impacts differ by more than the fitted parameters
   move them.

The baseline is a small JSON file tied to one diagnoser (its data set's spec).
"""

from __future__ import annotations

import hashlib
import json
import math
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from ..errors import ParameterError
from .classes import MODEL

__all__ = [
    "Uncertain",
    "UNCERTAIN",
    "Record",
    "read_record",
    "ChainEstimate",
    "ChainEstimator",
    "estimate_chain",
    "MachineFit",
    "fit_machine",
    "Baseline",
    "build_baseline",
    "load_baseline",
    "simulated_record",
]

#: Layout version of a baseline file.
FORMAT = 1
#: Nominal coverage of the reported intervals (as the severity intervals').
COVERAGE = 0.9
#: Revolutions each fit simulation records after `FIT_TRANSIENT` discarded: the pressure
#: cycle of the healthy machine does not repeat exactly (the valve plates' bounces and the
#: pins' impacts differ from one revolution to the next by ~60-75 Pa RMS in one-degree bins),
#: so a simulated curve is a mean over revolutions as the record's is.
FIT_REVOLUTIONS = 2.0
FIT_TRANSIENT = 1.0
#: Central-difference step of the fit's Jacobian on an uncertain factor (`fit_machine`): a
#: 2 % step of the crosshead mass, which the pressures do not feel, changed the simulated
#: curves by ~100 Pa (over the 720 bins) of numerical noise, while 5 % of the valve lift
#: changes them by ~1 kPa; 10 % on either side keeps that noise a few per cent of the effect.
FD_FACTOR = 0.1
#: Prior standard deviations of the chain: the transducers' offsets (Pa) and the tacho mark's
#: angle (degrees) when the chain estimator gives none (the issue's examples: offsets of
#: +5 / -3 kPa, marks set to a degree or worse).
OFFSET_PRIOR_PA = 10e3
PHASE_PRIOR_DEG = 3.0


@dataclass(frozen=True)
class Uncertain:
    """A machine parameter a baseline fits: its range as factors of the machine file's value
    (uniform within it: the prior), the machine parameters it scales, and whether the
    chamber pressures tell it (``fitted``; if not, its interval is its whole range)."""

    lo: float
    hi: float
    sets: tuple[str, ...]
    meaning: str
    fitted: bool = True


#: The machine's uncertain parameters: what a drawing does not give to better than these
#: ranges (engineering judgement; the masses: the data set's own +-10 %). The masses are not
#: fitted: with the crank's speed prescribed, the chamber pressures follow the crank angle's
#: kinematics and not the pins' motion (the pressures of the machine with ideal pins and with
#: its pins in clearance are the same to 0.1 Pa RMS), so they do not depend on the masses:
#: a 2 % change of the crosshead's mass changes the simulated curves by numerical noise only
#: (its forward and backward differences disagree by 5 times their size).
UNCERTAIN: dict[str, Uncertain] = {
    "m2": Uncertain(0.9, 1.1, ("m2",), "connecting-rod mass", fitted=False),
    "m3": Uncertain(0.9, 1.1, ("m3",), "crosshead and piston mass", fitted=False),
    "clearance_fraction": Uncertain(
        0.8,
        1.2,
        ("clearance_fraction",),
        "clearance volume (pockets, gaskets, the piston's end clearance as set at the overhaul)",
    ),
    "valve_spring": Uncertain(
        0.8,
        1.2,
        ("valve_stiffness", "valve_preload"),
        "every valve's springs (stiffness and preload together)",
        fitted=False,
    ),
    "valve_lift": Uncertain(0.9, 1.1, ("valve_lift",), "every valve plate's lift", fitted=False),
}


# ---- records ----------------------------------------------------------------------------------


@dataclass
class Record:
    """One record's channels (the acceleration, m/s**2; the tacho; the chamber pressures, Pa)
    at ``fs`` Hz."""

    accel: np.ndarray
    fs: float
    tacho: np.ndarray
    p_head: np.ndarray
    p_crank: np.ndarray
    name: str = ""


def read_record(path, *, channel="accel_guide", tacho="tacho", p_head="p_head_sensor",
                p_crank="p_crank_sensor", fs=None) -> Record:  # fmt: skip
    """A `Record` from a signal file (the formats of ``recipdyn analyze``)."""
    from ..io_signal import read_signal

    sig = read_signal(path, column=channel, fs=fs)
    rate = float(sig.fs)

    def ch(name):
        return np.asarray(read_signal(path, column=name, fs=rate).x, float)

    return Record(np.asarray(sig.x, float), rate, ch(tacho), ch(p_head), ch(p_crank),
                  Path(path).name)  # fmt: skip


def crank_revs(rec: Record, phase_deg: float = 0.0) -> np.ndarray:
    """The crank angle of each sample in revolutions after outer dead centre: the tacho's
    count (its mark at 0) plus the mark's angle ``phase_deg`` after outer dead centre (NaN
    outside the pulses)."""
    from ..analysis.vibration import crank_angle, tacho_times

    edges = tacho_times(rec.tacho, rec.fs)
    if edges.size < 3:
        raise ParameterError(
            f"{rec.name or 'record'}: tacho: {edges.size} pulse(s); at least 3 needed"
        )
    return crank_angle(rec.accel.size, rec.fs, pulses=edges) + phase_deg / 360.0


def pressure_curves(rec: Record, phase_deg: float = 0.0):
    """``(curves, speed_hz, per_rev)``: the two chamber pressures' means in the 360 one-degree
    bins of the crank angle (`crank_revs`), shape (2, 360), the record's mean crank speed, and
    the same curves of each whole revolution, shape (revolutions, 2, 360)."""
    from .evidence import _angle_bins, _whole_revs

    r = crank_revs(rec, phase_deg)
    ok = np.isfinite(r)
    r = r[ok]
    mask, n_revs, start = _whole_revs(r)
    if n_revs < 1:
        raise ParameterError(f"{rec.name or 'record'}: less than one whole revolution")
    speed = (r[-1] - r[0]) / ((r.size - 1) / rec.fs)
    ps = [np.asarray(p, float)[ok] for p in (rec.p_head, rec.p_crank)]
    curves = np.array([_angle_bins(p, r, mask, n_revs, start, 360) for p in ps])
    per_rev = []
    for k in range(n_revs):
        m = (r >= start + k) & (r < start + k + 1)
        per_rev.append([_angle_bins(p, r, m, 1, start, 360) for p in ps])
    return curves, float(speed), np.array(per_rev)


# ---- the chain ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class ChainEstimate:
    """A measurement chain's errors: each name's value and standard uncertainty.

    Names: ``p_head_offset``, ``p_crank_offset`` (Pa, added by the transducer to the true
    pressure), ``phase_deg`` (the tacho mark's crank angle after outer dead centre, degrees),
    ``resonance_hz`` (the accelerometer's mounting resonance)."""

    values: dict[str, float]
    sigma: dict[str, float]
    method: str = ""


class ChainEstimator(Protocol):
    """Anything that estimates a record's chain: ``estimator(record) -> ChainEstimate``
    (`estimate_chain`, which also takes the machine's changes as ``machine=``, or any other
    estimator of the same signature)."""

    def __call__(self, record: Record) -> ChainEstimate: ...


#: The impacts' ringing lies within this fraction of the mounting resonance on 95 % of the
#: data set's records (`recipdyn.diagnosis.evidence.ringing_hz`): the resonance's 95 %
#: half-width when the mount's response cannot be fitted.
RINGING_ACCURACY = 0.07
#: What the polytropes' phase and offset (`recipdyn.diagnosis.correction.pressure_phase`)
#: may be off by beyond their own statistics when read without the diagnoser's chain
#: reference (a healthy chamber's are within ~0.3 degree and a few kPa of the truth:
#: `recipdyn.diagnosis.correction.ChainReference`): added to their uncertainty as priors.
PHASE_PRIOR_FLOOR_DEG = 0.5
OFFSET_PRIOR_FLOOR_PA = 2e3


def estimate_chain(record: Record, machine=None) -> ChainEstimate:
    """The chain as one record shows it, by the record-level estimators of
    `recipdyn.diagnosis.correction` (the first estimate and the prior of the baseline's fit):
    the tacho mark's angle and each transducer's offset from the chambers' polytropes
    (`pressure_phase`, the two chambers' phases combined by their weights; uncertainties
    widened by `PHASE_PRIOR_FLOOR_DEG`, `OFFSET_PRIOR_FLOOR_PA`, or the priors
    `PHASE_PRIOR_DEG`, `OFFSET_PRIOR_PA` where a chamber gives none), and the mounting
    resonance from the acceleration's spectrum (`resonance`; the impacts' ringing,
    `RINGING_ACCURACY`, where the mount's response cannot be fitted). ``machine``: its
    changes (`recipdyn.diagnosis.machine.Machine.pairs`), whose chambers' volumes the
    polytropes are read against."""
    from .correction import K95, pressure_phase, resonance
    from .evidence import ringing_hz

    revs = crank_revs(record)
    values = {"p_head_offset": 0.0, "p_crank_offset": 0.0, "phase_deg": 0.0}
    sigma = {"p_head_offset": OFFSET_PRIOR_PA, "p_crank_offset": OFFSET_PRIOR_PA,
             "phase_deg": PHASE_PRIOR_DEG}  # fmt: skip
    phases = []
    for ch, p in (("head", record.p_head), ("crank", record.p_crank)):
        r = pressure_phase(p, revs, ch, machine)
        if not r.get("ok"):
            continue
        values[f"p_{ch}_offset"] = float(r["offset_pa"])
        sigma[f"p_{ch}_offset"] = math.hypot(float(r["offset_sd"]), OFFSET_PRIOR_FLOOR_PA)
        phases.append((float(r["phase_deg"]), math.hypot(float(r["phase_sd"]),
                                                         PHASE_PRIOR_FLOOR_DEG)))  # fmt: skip
    if phases:
        w = [1.0 / sd**2 for _, sd in phases]
        values["phase_deg"] = sum(v * wi for (v, _), wi in zip(phases, w, strict=True)) / sum(w)
        sigma["phase_deg"] = max(1.0 / math.sqrt(sum(w)), PHASE_PRIOR_FLOOR_DEG)
    est = resonance(record.accel, record.fs, revs).get("resonance_hz")
    if est is not None and math.isfinite(est.value) and math.isfinite(est.uncertainty):
        values["resonance_hz"], sigma["resonance_hz"] = est.value, est.uncertainty / K95
    else:
        hz = ringing_hz(record.accel, record.fs)
        values["resonance_hz"], sigma["resonance_hz"] = hz, RINGING_ACCURACY / 1.96 * hz
    return ChainEstimate(values, sigma, "recipdyn.diagnosis.correction (polytropes, spectrum)")


def _estimate(estimator, rec: Record, machine) -> ChainEstimate:
    """``estimator(rec)``, given the machine's changes when it takes them (`estimate_chain`)."""
    import inspect

    if "machine" in inspect.signature(estimator).parameters:
        return estimator(rec, machine=machine.pairs() or None)
    return estimator(rec)


def correct(record: Record, chain: Mapping[str, float]) -> tuple[Record, float]:
    """``(record, phase_deg)``: the record with the transducers' offsets taken off, and the mark
    angle the crank angle is to be re-phased by (`crank_revs`)."""
    out = Record(record.accel, record.fs, record.tacho,
                 record.p_head - chain.get("p_head_offset", 0.0),
                 record.p_crank - chain.get("p_crank_offset", 0.0), record.name)  # fmt: skip
    return out, float(chain.get("phase_deg", 0.0))


# ---- the fit -----------------------------------------------------------------------------------


def _sim_curves(job):
    """(key, (2, 360) chamber-pressure curves by crank angle: the mean over the simulation's
    `FIT_REVOLUTIONS` revolutions) of one healthy simulation (picklable unit of work), sampled
    at the record's rate and through the data set's pressure transducers without their noise
    (`recipdyn.sensors.PressureTransducer`: their causal anti-alias filter delays the
    pressures by ~0.1 degree, which the mark angle would otherwise take up)."""
    from .. import sensors
    from ..simulate import simulate

    key, params, fs = job
    with warnings.catch_warnings():  # the healthy pins stretch Hertz's law (docs/diagnosis.md)
        warnings.simplefilter("ignore")
        ds = simulate(model=MODEL, revolutions=FIT_REVOLUTIONS, transient=FIT_TRANSIENT,
                      fs=fs, summary=False, **params)  # fmt: skip
        clean = sensors.PressureTransducer(snr_db=None, bits=None)
        ds = sensors.record(ds, accelerometer=None, pressure=clean)
    th = np.mod(np.asarray(ds["theta1"].values, float), 2 * np.pi)
    b = np.minimum((th / (2 * np.pi) * 360).astype(int), 359)
    n = np.bincount(b, minlength=360)
    out = np.array(
        [np.bincount(b, weights=np.asarray(ds[v].values, float), minlength=360) / n
         for v in ("p_head_sensor", "p_crank_sensor")]
    )  # fmt: skip
    return key, out


def _shift(curves: np.ndarray, phase_deg: float) -> np.ndarray:
    """Periodic curves (last axis: 360 one-degree bins) read at ``angle + phase_deg``
    (band-limited: Fourier shift)."""
    F = np.fft.rfft(curves, axis=-1)
    m = np.arange(F.shape[-1])
    return np.fft.irfft(F * np.exp(2j * np.pi * m * phase_deg / 360.0), n=360, axis=-1)


@dataclass
class MachineFit:
    """The fitted baseline: each parameter's value, standard uncertainty and `COVERAGE`
    interval (``names``: the `UNCERTAIN` factors, the chain's ``p_head_offset``,
    ``p_crank_offset`` (Pa) and ``phase_deg``, each record's ``suction_pressure_<i>`` and
    ``discharge_pressure_<i>`` (Pa)), the machine parameters they give, and the fit's
    diagnostics."""

    names: list[str]
    value: list[float]
    sigma: list[float]
    machine: dict[str, float]
    machine_interval: dict[str, list[float]]
    resonance_hz: tuple[float, float]
    operating: list[dict[str, float]]
    residual_rms_pa: float
    autocorrelation: float
    simulations: int
    seconds: float
    chain_method: str = ""
    dof: int = 0
    quantile: float = 1.645
    unseen: list[str] = field(default_factory=list)

    def interval(self, name: str) -> tuple[float, float]:
        z = self.quantile
        i = self.names.index(name)
        return self.value[i] - z * self.sigma[i], self.value[i] + z * self.sigma[i]

    @property
    def chain(self) -> dict[str, float]:
        d = dict(zip(self.names, self.value, strict=True))
        return {"p_head_offset": d["p_head_offset"], "p_crank_offset": d["p_crank_offset"],
                "phase_deg": d["phase_deg"], "resonance_hz": self.resonance_hz[0]}  # fmt: skip


def fit_machine(
    records: Sequence[Record],
    machine=None,
    *,
    uncertain: Mapping[str, Uncertain] | None = None,
    estimator: ChainEstimator | Callable[[Record], ChainEstimate] = estimate_chain,
    workers: int = 2,
    max_nfev: int = 25,
    progress: Callable[[str], None] | None = None,
) -> MachineFit:
    """Fit the healthy machine and the chain to ``records`` (module docstring, step 2).

    Parameters
    ----------
    records : sequence of Record
        Records of the healthy machine (tacho and both chamber pressures needed).
    machine : Machine, optional
        The machine's description (`recipdyn.diagnosis.machine`; default: the default one).
    uncertain : mapping, optional
        The parameters fitted (default `UNCERTAIN`).
    estimator : ChainEstimator
        The chain's first estimate (and its prior), per record; the records' estimates are
        averaged (one chain for all).
    workers : int
        Processes that run the simulations.
    max_nfev : int
        Largest number of residual evaluations of each of the two least-squares stages.

    Notes
    -----
    Parameters (scaled to order one): each uncertain factor ``u`` (the value is the machine's
    times ``u``), with a Gaussian prior of the uniform range's mean and standard deviation and
    the range as bounds; the two offsets (kPa) and the mark angle (degrees), prior from the
    estimator; each record's suction and discharge line pressures (bar), prior: the record's
    own plateaus +-10 %. The residuals: the simulated chamber pressures read at the crank
    angle plus the mark angle, plus the offsets, minus the records' one-degree means, each
    bin over its own error's standard deviation (`_bin_sigma`: the cycle-to-cycle variation
    the records themselves show); the Jacobian is a central difference for the factors
    (`FD_FACTOR`) and a forward one elsewhere (0.2 kPa, 0.05 degree, 0.5 % of a line
    pressure), its simulations run in one batch. The uncertainty is the sandwich covariance
    of `_covariance` and the intervals are
    Student's t at the degrees of freedom of the variation's estimate (the revolutions less
    one per record). Uncertain parameters that the pressures do not tell (``fitted=False``:
    the masses) keep their nominal values with their whole range as the interval.
    """
    from scipy.ndimage import maximum_filter1d
    from scipy.optimize import least_squares

    from ..errors import deferred_signals
    from ..parallel import process_pool, stop_pool
    from .machine import Machine, healthy_parameters

    t0 = time.perf_counter()
    machine = machine or Machine.default()
    uncertain = dict(UNCERTAIN if uncertain is None else uncertain)
    unseen = {n: u for n, u in uncertain.items() if not u.fitted}
    uncertain = {n: u for n, u in uncertain.items() if u.fitted}
    if not records:
        raise ParameterError("records: none given; allowed: one or more healthy records")
    base = {**machine.as_dict, **healthy_parameters(machine if not machine.is_default else None)}
    meas, speeds, chains = [], [], []
    per_rev = []
    for rec in records:
        c, sp, pr = pressure_curves(rec)
        if not np.isfinite(c).all():
            raise ParameterError(f"{rec.name or 'record'}: a pressure channel is not finite "
                                 "over a whole revolution")  # fmt: skip
        meas.append(c)
        speeds.append(sp)
        per_rev.append(pr[np.isfinite(pr).all(axis=(1, 2))])
        chains.append(_estimate(estimator, rec, machine))
    chain0 = {k: float(np.mean([c.values[k] for c in chains])) for k in chains[0].values}
    chain_sd = {k: float(np.mean([c.sigma[k] for c in chains])) for k in chains[0].sigma}
    res_hz = (chain0["resonance_hz"], chain_sd["resonance_hz"])
    scale, dof = _bin_sigma(per_rev)
    # the parameter vector: names, start, prior mean and sd, bounds (all scaled)
    names, x0, mu, sd, lo, hi = [], [], [], [], [], []

    def add(n, start, m, s, a, b):
        names.append(n)
        x0.append(start)
        mu.append(m)
        sd.append(s)
        lo.append(a)
        hi.append(b)

    for n, u in uncertain.items():
        add(n, 0.5 * (u.lo + u.hi), 0.5 * (u.lo + u.hi), (u.hi - u.lo) / math.sqrt(12), u.lo, u.hi)
    for n in ("p_head_offset", "p_crank_offset"):
        add(n, chain0[n] / 1e3, chain0[n] / 1e3, chain_sd[n] / 1e3, -500.0, 500.0)  # kPa
    add("phase_deg", chain0["phase_deg"], chain0["phase_deg"], chain_sd["phase_deg"], -30, 30)
    for i, c in enumerate(meas):
        ps0, pd0 = (v / 1e5 for v in _levels(c, machine))  # the record's plateaus, bar
        add(f"suction_pressure_{i}", ps0, ps0, 0.1 * ps0, 0.2 * ps0, 5 * ps0)
        add(f"discharge_pressure_{i}", pd0, pd0, 0.1 * pd0, 0.2 * pd0, 5 * pd0)
    x0, mu, sd = np.array(x0), np.array(mu), np.array(sd)
    lo, hi = np.array(lo), np.array(hi)
    x0 = np.clip(x0, lo + 1e-6 * (hi - lo), hi - 1e-6 * (hi - lo))
    n_unc = len(uncertain)
    # difference steps: `FD_FACTOR` of a factor (central), 0.2 kPa, 0.05 degree, 0.5 % of a
    # line pressure (forward)
    steps = np.array([FD_FACTOR if i < n_unc else 0.2 if n.endswith("_offset") else
                      0.05 if n == "phase_deg" else 0.005 * x0[i]
                      for i, n in enumerate(names)])  # fmt: skip
    idx = {n: i for i, n in enumerate(names)}

    def params_of(x, i):
        p = dict(base)
        for n, u in uncertain.items():
            for k in u.sets:
                p[k] = base[k] * x[idx[n]]
        p["omega"] = 2 * math.pi * speeds[i]
        p["suction_pressure"] = x[idx[f"suction_pressure_{i}"]] * 1e5
        p["discharge_pressure"] = x[idx[f"discharge_pressure_{i}"]] * 1e5
        return p

    count = {"sims": 0}
    cache: dict[tuple, np.ndarray] = {}

    def simulate_all(jobs):
        todo = list({j[0]: j for j in jobs if j[0] not in cache}.values())
        if todo:
            run = pool.map if workers > 1 and len(todo) > 1 else map
            for k, c in run(_sim_curves, todo):
                cache[k] = c
            count["sims"] += len(todo)
            pending.check()
        return [cache[j[0]] for j in jobs]

    def job(x, i):
        return sim_key(x, i), params_of(x, i), float(records[i].fs)

    def nuisance(x):
        """Each draw's curves (of every record) less the draws' mean: (draws, records, 2,
        360), the unfitted factors drawn over their ranges (a seeded Latin hypercube)."""
        from scipy.stats import qmc

        u = qmc.LatinHypercube(d=len(unseen), seed=NUISANCE_SEED).random(NUISANCE_DRAWS)
        jobs = []
        for k, row in enumerate(u):
            for i in range(len(meas)):
                p = params_of(x, i)
                for un, q in zip(unseen.values(), row, strict=True):
                    for name in un.sets:
                        p[name] = base[name] * (un.lo + (un.hi - un.lo) * q)
                jobs.append((("nuisance", k, i), p, float(records[i].fs)))
        c = np.array(simulate_all(jobs)).reshape(NUISANCE_DRAWS, len(meas), 2, 360)
        return NUISANCE_SCALE * (c - c.mean(axis=0))

    def sim_key(x, i):
        sub = [x[idx[n]] for n in uncertain] + [x[idx[f"suction_pressure_{i}"]],
                                                x[idx[f"discharge_pressure_{i}"]]]  # fmt: skip
        return (i, *np.round(sub, 12).tolist())

    def model_curves(x, sims):
        out = []
        for s in sims:
            y = _shift(s, x[idx["phase_deg"]])
            y[0] += x[idx["p_head_offset"]] * 1e3
            y[1] += x[idx["p_crank_offset"]] * 1e3
            out.append(y)
        return out

    def residuals(x, scale):
        sims = simulate_all([job(x, i) for i in range(len(meas))])
        data = np.concatenate([((y - m) / sc).ravel() for y, m, sc in
                               zip(model_curves(x, sims), meas, scale, strict=True)])  # fmt: skip
        return np.concatenate([data, (x - mu) / sd])

    def jacobian(x, scale, cols=None):
        # central differences for the uncertain factors (a valve's bounces differ from one
        # simulation to the next by an amount that does not shrink with the step: a wide,
        # two-sided step keeps it small against the effect), forward ones elsewhere
        cols = range(x.size) if cols is None else cols
        h = steps * np.where(x + steps < hi, 1, -1)
        h[:n_unc] = steps[:n_unc]
        jobs = [job(x, i) for i in range(len(meas))]
        for j, n in enumerate(names):
            if j not in cols:
                continue
            if j < n_unc or n.startswith(("suction_pressure_", "discharge_pressure_")):
                rows = range(len(meas)) if j < n_unc else [int(n.rsplit("_", 1)[1])]
                for sign in (1, -1) if j < n_unc else (1,):
                    xj = x.copy()
                    xj[j] += sign * h[j]
                    jobs += [job(xj, i) for i in rows]
        simulate_all(jobs)  # one batch: every simulation the columns need
        r0 = residuals(x, scale)
        J = np.zeros((r0.size, x.size))
        for j in cols:
            xj = x.copy()
            xj[j] += h[j]
            if j < n_unc:
                xm = x.copy()
                xm[j] -= h[j]
                J[:, j] = (residuals(xj, scale) - residuals(xm, scale)) / (2 * h[j])
            else:
                J[:, j] = (residuals(xj, scale) - r0) / h[j]
        return J

    with deferred_signals() as pending:
        pool = process_pool(workers) if workers > 1 else None
        try:
            # the unfitted parameters drawn over their ranges: how much the curves depend on
            # them, bin by bin, is error the fit cannot take off (their marginal, in the
            # weights and the covariance)
            nuis = None
            if unseen:
                nuis = nuisance(x0)
                var = maximum_filter1d(np.sum(nuis**2, axis=0) / (len(nuis) - 1), SPREAD_BINS,
                                       axis=-1, mode="wrap")  # fmt: skip
                scale = np.sqrt(scale**2 + var)
            # first the chain and the line pressures with the machine as described (a
            # simulation per record and column), then everything from there
            rest = np.arange(n_unc, x0.size)

            def sub(z):
                x = x0.copy()
                x[rest] = z
                return x

            first = least_squares(
                lambda z: residuals(sub(z), scale), x0[rest],
                jac=lambda z: jacobian(sub(z), scale, rest)[:, rest], bounds=(lo[rest], hi[rest]),
                method="trf", x_scale=sd[rest], max_nfev=max_nfev,
            )  # fmt: skip
            sol = least_squares(residuals, sub(first.x), jac=jacobian, bounds=(lo, hi),
                                args=(scale,), method="trf", x_scale=sd,
                                max_nfev=max_nfev)  # fmt: skip
            J = jacobian(sol.x, scale)
        finally:
            if pool is not None:
                stop_pool(pool)
    n_data = sum(m.size for m in meas)
    data = (sol.fun[:n_data].reshape(len(meas), 2, 360) * scale).ravel()
    rms = float(np.sqrt(np.mean(data**2)))
    rho = _lag1(data, [m.size for m in meas])
    if progress is not None:
        progress(f"baseline fit: residual RMS {rms:.0f} Pa, {count['sims']} simulations, "
                 f"{sol.nfev} evaluations ({sol.message})")  # fmt: skip
    cov = _covariance(J[:n_data], J[n_data:], per_rev, scale, nuis)
    sig = np.sqrt(np.maximum(np.diag(cov), 0.0))
    x = sol.x
    if nuis is not None:  # the unfitted parameters' spread: estimated from its draws
        dof = min(dof, NUISANCE_DRAWS - 1)
    z = _quantile(COVERAGE, dof)
    fitted, intervals = {}, {}
    for u in unseen.values():  # not told by the pressures: the nominal value, the whole range
        for k in u.sets:
            fitted[k] = base[k]
            intervals[k] = [base[k] * u.lo, base[k] * u.hi]
    for n, u in uncertain.items():
        i = idx[n]
        for k in u.sets:
            fitted[k] = base[k] * x[i]
            intervals[k] = [base[k] * max(x[i] - z * sig[i], u.lo),
                            base[k] * min(x[i] + z * sig[i], u.hi)]  # fmt: skip
    value = x.copy()
    sigma = sig.copy()
    for n in ("p_head_offset", "p_crank_offset"):
        value[idx[n]] *= 1e3
        sigma[idx[n]] *= 1e3
    for i in range(len(meas)):
        for n in (f"suction_pressure_{i}", f"discharge_pressure_{i}"):
            value[idx[n]] *= 1e5
            sigma[idx[n]] *= 1e5
    ops = [{"omega": 2 * math.pi * speeds[i],
            "suction_pressure": float(x[idx[f"suction_pressure_{i}"]] * 1e5),
            "discharge_pressure": float(x[idx[f"discharge_pressure_{i}"]] * 1e5)}
           for i in range(len(meas))]  # fmt: skip
    return MachineFit(names, value.tolist(), sigma.tolist(), fitted, intervals, res_hz, ops, rms,
                      rho, count["sims"], time.perf_counter() - t0, chains[0].method,
                      dof, z, sorted(unseen))  # fmt: skip


#: Draws of the unfitted parameters (`Uncertain.fitted` False) over their ranges whose
#: curves' spread enters the fit's weights and covariance (`fit_machine`), and their seed.
NUISANCE_DRAWS = 10
NUISANCE_SEED = 42
#: The draws' deviations are scaled by this factor: a uniform draw's standard deviation is
#: the range's half-width over sqrt(3), while the machine may sit at an edge of the range
#: (with 6 draws unscaled, the clearance volume's 90 % intervals held the truth in 8 of 11
#: benchmark machines, the three misses those with springs and lifts near the top of their
#: ranges, 1.3-1.9 half-widths off): the error is taken as the range's half-width.
NUISANCE_SCALE = math.sqrt(3.0)
#: Crank-angle bins (degrees) over which a bin's cycle-to-cycle variance is spread
#: (`_bin_sigma`: a valve event's angle moves from one revolution to the next).
SPREAD_BINS = 7


def _bin_sigma(per_rev) -> tuple[np.ndarray, int]:
    """``(sigma, dof)``: each record's curve error's standard deviation in each bin (Pa, shape
    (records, 2, 360)) and the degrees of freedom of its estimate.

    The error of a record's mean curve against a simulated one is the cycle-to-cycle
    variation (the valve plates' bounces differ from one revolution to the next: ~90 Pa RMS
    over the bins, ~300 Pa at the valve events, ~4 Pa elsewhere), the sensor's noise and the
    tacho's timing: estimated from the records themselves, the deviations of each whole
    revolution's curves from its record's mean, pooled over the records (degrees of freedom:
    the revolutions less one per record), spread by a running maximum over `SPREAD_BINS`,
    floored at each channel's median, and times ``1/R + 1/K`` for a record of ``R``
    revolutions against a simulated mean of ``K`` = `FIT_REVOLUTIONS`."""
    from scipy.ndimage import maximum_filter1d

    devs = [pr - pr.mean(axis=0) for pr in per_rev if pr.shape[0] >= 2]
    dof = sum(d.shape[0] - 1 for d in devs)
    if dof < 2:
        n = sum(pr.shape[0] for pr in per_rev)
        raise ParameterError(
            f"records: {n} whole revolution(s) in {len(per_rev)} record(s); at least 3 "
            "(2 in one record) are needed to measure the cycle-to-cycle variation"
        )
    var = sum(np.sum(d**2, axis=0) for d in devs) / dof
    var = maximum_filter1d(var, SPREAD_BINS, axis=-1, mode="wrap")
    var = np.maximum(var, np.median(var, axis=-1, keepdims=True))
    return np.array([np.sqrt(var * (1.0 / pr.shape[0] + 1.0 / FIT_REVOLUTIONS))
                     for pr in per_rev]), dof  # fmt: skip


def _covariance(Jd, Jp, per_rev, scale, nuisance=None):
    """The fitted parameters' covariance (scaled units).

    The estimate is the regularised, weighted least-squares solution, ``x - x_true ~ H^-1
    (Jd^T e + Jp^T Jp (mu - x_true))`` with ``H = Jd^T Jd + Jp^T Jp`` (linearised at the
    optimum; the data rows divided by `_bin_sigma`), so for a machine drawn from the prior and
    a weighted curve error ``e`` of covariance ``S``: ``cov = H^-1 (Jd^T S Jd + Jp^T Jp)
    H^-1`` (the sandwich; ``H^-1`` when the bins' errors are independent). ``S`` is the
    records' own revolutions' deviations (whatever their correlation along the crank angle),
    pooled, times ``1/R + 1/K`` as in `_bin_sigma`; and, with ``nuisance`` (each draw of the
    unfitted parameters' curves less their mean, shape (draws, records, 2, 360)), the error
    their unknown values leave, the same in every record (one machine): each draw's
    deviations over all records projected together."""
    H = Jd.T @ Jd + Jp.T @ Jp
    Hi = np.linalg.pinv(H)
    n = Jd.shape[0] // len(per_rev)
    dof = sum(pr.shape[0] - 1 for pr in per_rev if pr.shape[0] >= 2)
    G = np.zeros_like(H)
    for i, pr_i in enumerate(per_rev):
        Ji = Jd[i * n : (i + 1) * n]
        f = 1.0 / pr_i.shape[0] + 1.0 / FIT_REVOLUTIONS
        for pr in per_rev:  # every record's revolutions, in record i's weights
            if pr.shape[0] < 2:
                continue
            D = (pr - pr.mean(axis=0)) / scale[i] * math.sqrt(f)
            P = D.reshape(pr.shape[0], -1) @ Ji
            G += P.T @ P / dof
    if nuisance is not None and len(nuisance) > 1:
        P = np.array([sum((d[i] / scale[i]).ravel() @ Jd[i * n : (i + 1) * n]
                          for i in range(len(per_rev))) for d in nuisance])  # fmt: skip
        G += P.T @ P / (len(nuisance) - 1)
    return Hi @ (G + Jp.T @ Jp) @ Hi


def _quantile(coverage: float, dof: int) -> float:
    """The two-sided ``coverage`` quantile: Student's t at ``dof`` degrees of freedom (the
    covariance estimated from that many revolutions), the normal's without them."""
    from scipy.stats import norm, t

    q = 0.5 + coverage / 2
    return float(t.ppf(q, dof)) if dof >= 1 else float(norm.ppf(q))


def _levels(curves: np.ndarray, machine) -> tuple[float, float]:
    """The suction and discharge levels (Pa) a record's two chamber curves show (each
    chamber's plateaus over its own strokes, `recipdyn.diagnosis.evidence`, averaged): where a
    fit starts the line pressures."""
    from .evidence import _chamber_cycle, geometry

    g = geometry(machine.pairs() or None)
    lo, hi = [], []
    for c, v, vs in ((curves[0], g["V_head"], g["Vs_head"]), (curves[1], g["V_crank"],
                                                                g["Vs_crank"])):  # fmt: skip
        out = _chamber_cycle(c, v, vs, g["clearance"])
        lo.append(out["p_lo"])
        hi.append(out["p_hi"])
    ps, pd = float(np.nanmean(lo)), float(np.nanmean(hi))
    if not (ps > 0 and pd > ps):
        ps, pd = float(np.min(curves)), float(np.max(curves))
    return ps, pd


def _lag1(r: np.ndarray, sizes: Sequence[int]) -> float:
    """The residuals' lag-1 autocorrelation within each curve (360 bins), pooled; clipped to
    [0, 0.95] (a negative one is not taken as extra information)."""
    num = den = 0.0
    start = 0
    for n in sizes:
        y = r[start : start + n].reshape(-1, 360)
        start += n
        y = y - y.mean(axis=1, keepdims=True)
        num += float(np.sum(y * np.roll(y, 1, axis=1)))
        den += float(np.sum(y * y))
    rho = num / den if den > 0 else 0.0
    return float(min(max(rho, 0.0), 0.95))


# ---- the referral ------------------------------------------------------------------------------


def diagnoser_id(diag) -> str:
    """A diagnoser's identity (its data card: the data set it was trained on, built once):
    a baseline refers features to one diagnoser's machine and features."""
    text = diag.state["datacard_json"] + "|" + ",".join(diag.names)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


#: How a baseline refers later records (`Baseline`, `build_baseline`).
REFERRALS = ("model", "records", "sim")
#: The accelerometer SNR (dB) of the referral's simulated records: the feature difference of
#: two records sensed with the same noise is the machine's, at any SNR inside the training
#: range.
REFERRAL_SNR_DB = 30.0


def _features_job(task):
    from .dataset import make_record

    res = make_record(task)
    if res["error"]:
        raise RuntimeError(f"baseline referral record: {res['error'].splitlines()[0]}")
    return task["index"], res["features"]


@dataclass
class Baseline:
    """A machine's own healthy baseline for one diagnoser (module docstring).

    ``fit``: the fitted parameters and chain (`MachineFit`); ``delta``: each pressure and
    cycle feature's healthy offset of this machine from the diagnoser's, the one `refer`
    takes off, by ``referral``:

    * ``"records"`` (the default; ``delta_records``): the healthy records' own features,
      chain corrected, less what the diagnoser's healthy machine shows at their operating
      points (its affine healthy baseline, `recipdyn.diagnosis.train.fit_baseline`, for the
      features it models; the nominal machine's simulated record for the rest), averaged: a
      later record is then read as its departure from the machine's own healthy records,
      the operating point's effect carried by the diagnoser's baseline, as condition
      monitoring refers a reading to the machine's own healthy state at the same load. It
      holds what the fit does not: the valve springs' and lifts' effect, which the model's
      referral leaves in (docs/diagnosis.md: the perturbed machines' healthy records called
      a sticking plate, their weak springs healthy, with the model's referral);
    * ``"model"`` (``delta_model``): the fitted machine's simulated features less the
      nominal one's, averaged over the records' operating points (``delta_spread`` its
      spread over them): only the fitted parameters' effect;
    * ``"sim"`` (``delta_sim``): the healthy records' features less the nominal machine's
      simulated record at the same operating point (a two-revolution simulation's own
      cycle-to-cycle noise enters the offset; measured worse than ``"records"``).

    ``check``: the largest departure of the (chain-corrected) healthy records' features
    from the fitted machine's, in the healthy machine's own spreads
    (`recipdyn.diagnosis.machine.healthy_spreads`), and the feature; ``diagnoser``:
    `diagnoser_id`."""

    fit: MachineFit
    delta: dict[str, float]
    delta_spread: dict[str, float]
    check: dict[str, Any]
    diagnoser: str
    records: list[str] = field(default_factory=list)
    recipdyn_version: str = ""
    referral: str = "records"
    delta_model: dict[str, float] = field(default_factory=dict)
    delta_records: dict[str, float] = field(default_factory=dict)
    delta_sim: dict[str, float] = field(default_factory=dict)

    @property
    def chain(self) -> dict[str, float]:
        return self.fit.chain

    def refer(self, X: np.ndarray, names: Sequence[str]) -> np.ndarray:
        """Feature rows (columns ``names``) referred to the machine's own healthy state: the
        machine's healthy offset `delta` taken off."""
        X = np.array(X, float, copy=True, ndmin=2)
        for j, n in enumerate(names):
            d = self.delta.get(n)
            if d is not None and math.isfinite(d):
                X[:, j] -= d
        return X

    def to_json(self) -> str:
        d = asdict(self)
        d["format"] = FORMAT
        return json.dumps(d, indent=1, default=float)

    def save(self, path: str | Path) -> Path:
        from ..io import atomic_path

        path = Path(path)
        with atomic_path(path) as tmp:
            Path(tmp).write_text(self.to_json(), encoding="utf-8")
        return path

    def summary(self) -> str:
        f = self.fit
        lines = [f"baseline of {len(self.records)} healthy record(s) "
                 f"({f.simulations} simulations, {f.seconds:.0f} s)"]  # fmt: skip
        for k, v in f.machine.items():
            lo, hi = f.machine_interval[k]
            lines.append(f"  {k} = {v:.4g} ({100 * COVERAGE:.0f} % interval {lo:.4g}..{hi:.4g})")
        for n in ("p_head_offset", "p_crank_offset", "phase_deg"):
            lo, hi = f.interval(n)
            v = f.value[f.names.index(n)]
            unit = " deg" if n == "phase_deg" else " Pa"
            lines.append(f"  {n} = {v:.4g}{unit} ({lo:.4g}..{hi:.4g})")
        lines.append(f"  resonance_hz = {f.resonance_hz[0]:.0f} +- {f.resonance_hz[1]:.0f} Hz")
        lines.append(f"  pressure residual RMS {f.residual_rms_pa:.0f} Pa (lag-1 "
                     f"autocorrelation {f.autocorrelation:.2f}); the healthy records' largest "
                     f"departure from the fitted machine: {self.check['shift']:.1f} healthy "
                     f"spreads ({self.check['feature']})")  # fmt: skip
        return "\n".join(lines)


def load_baseline(path: str | Path) -> Baseline:
    """Read a baseline file (`Baseline.save`)."""
    path = Path(path)
    if not path.is_file():
        raise ParameterError(f"baseline {path}: file not found; build one with "
                             "'recipdyn baseline RECORD... -o FILE'")  # fmt: skip
    try:
        d = json.loads(path.read_text(encoding="utf-8"))
        if d.pop("format") != FORMAT:
            raise ValueError("format")
        d["fit"] = MachineFit(**{**d["fit"], "resonance_hz": tuple(d["fit"]["resonance_hz"])})
        return Baseline(**d)
    except (ValueError, KeyError, TypeError, UnicodeDecodeError):
        raise ParameterError(f"baseline {path}: not a recipdyn baseline file") from None


def baseline_for(diag, baseline) -> Baseline:
    """``baseline`` (a `Baseline` or its file), checked to belong to diagnoser ``diag``."""
    if isinstance(baseline, (str, Path)):
        baseline = load_baseline(baseline)
    if baseline.diagnoser != diagnoser_id(diag):
        raise ParameterError(
            "baseline: built for another diagnoser (its features are referred to that one's "
            "machine); rebuild it with 'recipdyn baseline RECORD... -m DIAGNOSER -o FILE'"
        )
    return baseline


def build_baseline(
    records: Sequence[Record],
    diag,
    *,
    machine=None,
    uncertain: Mapping[str, Uncertain] | None = None,
    estimator: ChainEstimator | Callable[[Record], ChainEstimate] = estimate_chain,
    workers: int = 2,
    max_nfev: int = 25,
    progress: Callable[[str], None] | None = None,
    referral: str = "records",
    fit: MachineFit | None = None,
) -> Baseline:
    """The machine's own healthy baseline for diagnoser ``diag`` from healthy ``records``
    (module docstring): the fit (`fit_machine`), then the healthy machine with the fitted
    parameters and the diagnoser's nominal one simulated and sensed at each record's
    operating point, with the same noise, and their features' difference
    (`Baseline.delta_model`); the healthy records' own departure from the diagnoser's healthy
    machine (`Baseline.delta_records`), and against the nominal machine's simulated records
    (`Baseline.delta_sim`); ``referral`` chooses which `Baseline.refer` takes off (`REFERRALS`;
    default ``"records"``). ``fit``: a `MachineFit` already made from these records (the fit
    is then not run again: the referral alone is rebuilt)."""
    from .. import __version__
    from ..parallel import process_pool, stop_pool
    from .machine import feature_shift, healthy_parameters, healthy_spreads

    if referral not in REFERRALS:
        raise ParameterError(f"referral = {referral!r}; allowed: {', '.join(REFERRALS)}")
    machine = machine or diag.machine
    if fit is None:
        fit = fit_machine(records, machine, uncertain=uncertain, estimator=estimator,
                          workers=workers, max_nfev=max_nfev, progress=progress)  # fmt: skip
    changes = diag.card["spec"].get("machine") or None
    nominal = {**machine.as_dict, **healthy_parameters(None if machine.is_default else machine)}
    fitted = {**nominal, **fit.machine}
    hz = float(fit.resonance_hz[0])
    tasks = []
    for i, (rec, op) in enumerate(zip(records, fit.operating, strict=True)):
        fs = round(rec.fs / 100.0) * 100.0
        res = min(hz, 0.44 * fs) if math.isfinite(hz) else 4000.0
        for k, params in enumerate((fitted, nominal)):
            tasks.append({"index": 2 * i + k, "params": {**params, **op}, "fs": fs,
                          "resonance_hz": res, "snr_db": REFERRAL_SNR_DB, "revolutions": 2.0,
                          "transient": 1.0, "noise_seed": 7_000_003 + i,
                          **({"machine": dict(changes)} if changes else {})})  # fmt: skip
    pool = process_pool(workers) if workers > 1 else None
    try:
        feats = dict(pool.map(_features_job, tasks) if pool else map(_features_job, tasks))
    finally:
        if pool is not None:
            stop_pool(pool)
    from .evidence import feature_groups

    groups = feature_groups(diag.names)
    fixed = constant_in_health(diag)
    measured = [record_features_of(rec, fit.chain, changes) for rec in records]
    expected = [_expected(diag, m, feats[2 * i + 1]) for i, m in enumerate(measured)]
    delta_model, delta_records, delta_sim, spread = {}, {}, {}, {}
    for n in groups["pressure"] + groups["cycle"]:
        d = [feats[2 * i][n] - feats[2 * i + 1][n] for i in range(len(records))]
        d = [v for v in d if math.isfinite(v)]
        if d:
            delta_model[n] = float(np.mean(d))
            spread[n] = float(np.std(d))
        e = [m[n] - x[n] for m, x in zip(measured, expected, strict=True)]
        e = [v for v in e if math.isfinite(v)]
        if e:
            delta_records[n] = float(np.mean(e))
        e = [m[n] - feats[2 * i + 1][n] for i, m in enumerate(measured)]
        e = [v for v in e if math.isfinite(v)]
        if e:
            delta_sim[n] = float(np.mean(e))
            if n in fixed:  # at its bound: the nominal machine's own value, not a mean's
                delta_records[n] = delta_sim[n]
    spreads = healthy_spreads(diag)
    worst, which = 0.0, ""
    for i, got in enumerate(measured):
        s, n = feature_shift(got, feats[2 * i], spreads)
        if s > worst:
            worst, which = s, n
    check = {"shift": worst, "feature": which}
    if progress is not None:
        progress(f"baseline: referral simulated ({len(tasks)} records)")
    delta = {"records": delta_records, "model": delta_model, "sim": delta_sim}[referral]
    return Baseline(fit, delta, spread, check, diagnoser_id(diag),
                    [r.name for r in records], __version__, referral, delta_model,
                    delta_records, delta_sim)  # fmt: skip


def constant_in_health(diag) -> set[str]:
    """The features the diagnoser's healthy training records hold at one value (their
    interquartile range zero): a pressure-shape bin at the cycle's peak is 1 by construction
    (``pc_100`` of the shipped diagnoser: 1 from its healthy records' 25th percentile up).
    Their healthy value at an operating point is that bound, which the diagnoser's affine
    healthy baseline (a mean over records some of which peak in the next bin) misses: referred
    to it, a perturbed machine's healthy 1 became 0.984, below every healthy simulated record,
    and the consistency check refused all 4 of its healthy records at 11 standard deviations
    there; left unreferred, another perturbed machine's own peak in the next bin (0.98) was
    refused the same way. `build_baseline` refers them to the nominal machine's simulated
    records at the healthy records' operating points (``delta_sim``), which hold the bound
    exactly."""
    st = diag.state
    healthy = np.array([lab == "healthy" for lab in st["train_labels"]])
    Z = st["Z_train"].astype(float)[healthy]
    iqr = np.nanpercentile(Z, 75, axis=0) - np.nanpercentile(Z, 25, axis=0)
    return {n for n, q in zip(diag.names, iqr, strict=True) if q == 0}


def _expected(diag, row: Mapping[str, float], nominal: Mapping[str, float]) -> dict:
    """What the diagnoser's healthy machine shows at the operating point of feature ``row``:
    its healthy baseline's prediction (`recipdyn.diagnosis.train.fit_baseline`) for the
    features it models, the nominal machine's simulated record (``nominal``) for the rest."""
    out = dict(nominal)
    b = diag.baseline
    if b:
        ops = np.array([row[o] for o in b["operating"]], float)
        a = np.concatenate([[1.0], (ops - np.asarray(b["mean"])) / np.asarray(b["scale"])])
        pred = np.asarray(b["coef"]) @ a
        out.update(zip(b["targets"], pred.tolist(), strict=True))
    return out


def record_features_of(rec: Record, chain: Mapping[str, float], machine=None) -> dict[str, float]:
    """A record's features (`recipdyn.diagnosis.evidence.record_features`) after its chain is
    corrected (`correct`); ``machine``: the changes of the machine whose geometry they are
    read against (a diagnoser's)."""
    from .evidence import record_features

    fixed, phase = correct(rec, chain)
    r = crank_revs(fixed, phase)
    ok = np.flatnonzero(np.isfinite(r))
    sl = slice(ok[0], ok[-1] + 1)
    return record_features(fixed.accel[sl], fixed.fs, r[sl], p_head=fixed.p_head[sl],
                           p_crank=fixed.p_crank[sl], machine=machine)  # fmt: skip


def simulated_record(
    params: Mapping[str, Any],
    *,
    fs: float = 10_000.0,
    revolutions: float = 6.0,
    transient: float = 1.0,
    resonance_hz: float = 4000.0,
    snr_db: float = 30.0,
    chain: Mapping[str, float] | None = None,
    seed: int = 0,
    name: str = "",
) -> Record:
    """A sensed `Record` of the diagnosis model at ``params`` (the data set's sensors,
    `recipdyn.sensors`), through a chain with the errors ``chain`` (``p_head_offset``,
    ``p_crank_offset``, Pa, added to the transducers' output; ``phase_deg``, the tacho mark's
    angle after outer dead centre): a record to try a baseline on, whose truth is known."""
    from .. import sensors
    from ..simulate import simulate

    chain = dict(chain or {})
    with warnings.catch_warnings():  # the healthy pins stretch Hertz's law (docs/diagnosis.md)
        warnings.simplefilter("ignore")
        ds = simulate(model=MODEL, revolutions=revolutions, transient=transient, fs=fs,
                      summary=False, **params)  # fmt: skip
    rec = sensors.record(
        ds,
        # the mount's exact (analog) response, as a real mount's and the drawn chains' of the
        # data set: the bilinear one of `recipdyn.sensors`' fixed chain moves the resonance
        # `estimate_chain` reads (an analog fit) by up to 5 % near 0.4 fs
        accelerometer=sensors.Accelerometer(
            snr_db=snr_db, resonance_hz=resonance_hz, response="exact"
        ),  # fmt: skip
        pressure=sensors.PressureTransducer(),
        tacho=sensors.Tacho(angle=math.radians(chain.get("phase_deg", 0.0))),
        seed=seed,
    )
    return Record(
        np.asarray(rec["accel_guide"].values, float),
        float(fs),
        np.asarray(rec["tacho"].values, float),
        np.asarray(rec["p_head_sensor"].values, float) + chain.get("p_head_offset", 0.0),
        np.asarray(rec["p_crank_sensor"].values, float) + chain.get("p_crank_offset", 0.0),
        name,
    )
