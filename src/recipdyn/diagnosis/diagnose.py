"""Diagnose one record (``recipdyn diagnose RECORD``, `recipdyn.diagnose`).

The record is read like ``recipdyn analyze`` reads one (CSV/TSV/WAV/MAT/NetCDF/Parquet,
channels by name); the crank angle comes from a once-per-revolution tacho whose mark is at
outer dead centre, or from a constant speed (then the features that need the angle are left
out and the diagnosis is less sharp). Before any answer, the record must lie in the
diagnoser's training domain: its crank speed and sampling rate inside the training ranges,
its measurement chain as estimated from it (the mount's resonance, the SNR, the pressure
offsets) inside the chain ranges the diagnoser was trained under
(`recipdyn.diagnosis.chainrange`; a diagnoser of one fixed chain: the noise floor and the
frequency at which its impacts ring inside its training records' ranges), its features not
less like the training records than all but a stated share of held-out records
(`recipdyn.diagnosis.domain`: a conformal novelty p-value); and the best-fitting simulated
record of the class named must explain it within its noise
(`recipdyn.diagnosis.consistency`). Otherwise the diagnosis is withheld, with the reason.
First of all, the record's machine (the user's machine file, or the parameters a simulated
record carries) must be the diagnoser's within the tolerances of
`recipdyn.diagnosis.machine`: a record of another machine is refused with the commands that
build a diagnoser for it.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ParameterError
from .channels import _cols, available, gate
from .classes import get_class
from .tolerances import FLOOR_SLACK, RANGE_SLACK, RESONANCE_CHECK_MIN_HZ, RING_SLACK

__all__ = ["diagnose", "Diagnosis", "default_model_path", "diagnose_arrays"]

#: The smallest spread of the healthy training records a deciding feature's z is measured in,
#: as a share of the whole training set's interquartile range (`_deciding`).
HEALTHY_SPREAD_FLOOR = 0.05


def default_model_path() -> Path:
    """The diagnoser shipped with recipdyn (built by ``make diagnoser``)."""
    return Path(__file__).parent / "data" / "default.skops"


@dataclass
class Diagnosis:
    """The answer for one record (``refused``: withheld, with ``reason``)."""

    refused: bool
    reason: str = ""
    probabilities: dict[str, float] = field(default_factory=dict)
    label: str = ""
    severity: float = float("nan")
    severity_interval: tuple[float, float] = (float("nan"), float("nan"))
    value: float = float("nan")
    value_interval: tuple[float, float] = (float("nan"), float("nan"))
    unit: str = ""
    evidence: dict[str, Any] = field(default_factory=dict)
    ood: dict[str, float] = field(default_factory=dict)
    figure: str | None = None
    seconds: float = float("nan")

    def summary(self) -> dict[str, Any]:
        return {k: v for k, v in self.__dict__.items()}

    def text(self) -> str:
        if self.refused:
            return f"refused: {self.reason}"
        probs = ", ".join(
            f"{k} {v:.2f}" for k, v in sorted(self.probabilities.items(), key=lambda kv: -kv[1])[:4]
        )
        lines = [f"diagnosis: {self.label} (p = {self.probabilities[self.label]:.2f}); {probs}"]
        if self.label != "healthy":
            lo, hi = self.value_interval
            lines.append(
                f"severity {self.severity:.2f} (90 % interval {self.severity_interval[0]:.2f}"
                f"..{self.severity_interval[1]:.2f}): {get_class(self.label).parameter} = "
                f"{self.value:.3g} {self.unit} ({min(lo, hi):.3g}..{max(lo, hi):.3g})"
            )
        ev = self.evidence
        ch = ev.get("channels", {})
        if ch:
            line = f"channels used: {ch['channels']}"
            if ch.get("measured"):
                line += (
                    f"; on held-out conditions '{self.label}' from them was right for "
                    f"{ch['precision']:.0%} of its {ch['answers']} answers (recall "
                    f"{ch['recall']:.0%}; all classes {ch['accuracy']:.0%} of {ch['n']} records)"
                )
            lines.append(line)
        if ev.get("windows"):
            w = ev["windows"]
            lines.append(
                f"scored on {w['n']} windows of {w['revolutions']:g} revolutions (the data "
                f"set's records): p of '{self.label}' "
                + ", ".join(f"{v:.2f}" for v in w["p"])
                + "; each window's answer "
                + ", ".join(w["labels"])
            )
        if ev.get("fingerprint"):
            from .fingerprint import Fingerprint

            lines.append(Fingerprint(**ev["fingerprint"]).text())
        for name, e in ev.get("chain", {}).items():
            lines.append(f"chain: {name.replace('_', ' ')} {_estimate_text(e)}")
        lines.append(
            f"impacts: {ev['impacts_per_rev']:.1f} per revolution"
            + (
                f" at crank angles {', '.join(f'{a:.0f}' for a in ev['impact_angles_deg'])} deg"
                if ev.get("impact_angles_deg")
                else ""
            )
        )
        lines.append(
            "deciding features (robust z against the healthy training records): "
            + ", ".join(f"{k} {v:+.1f}" for k, v in ev["deciding"])
        )
        if "noise_floor" in ev:
            nf = ev["noise_floor"]
            lines.append(
                f"accelerometer noise floor: {_db(nf['share']):.0f} dB below the mean "
                f"10-degree stretch (training records {_db(nf['training_range'][1]):.0f}.."
                f"{_db(nf['training_range'][0]):.0f} dB)"
            )
        for c in ev.get("chain_ranges", {}).values():
            from .chainrange import ChainCheck

            lines.append("chain against its declared range: " + ChainCheck(**c).text())
        if "pressure_deviation" in ev:
            pd_ = ev["pressure_deviation"]
            lines.append(
                f"head-end pressure shape: largest deviation from the closest healthy "
                f"simulated record {pd_['max']:.3f} (of its range) at {pd_['angle_deg']:.0f} deg"
            )
        o = self.ood
        lines.append(
            f"in domain: novelty p-value {o['p_value']:.3f} >= {o['alpha']:g} (score "
            f"{o['score']:.2f} against {o['n_calibration']} held-out records, features: "
            f"{o['features']})"
        )
        c = ev.get("consistency") or {}
        if c.get("fit"):
            f, w = c["fit"], c["worst"]
            sev = f" at severity {f['severity']:.2f}" if math.isfinite(f["severity"]) else ""
            lines.append(
                f"physics: the best-fitting simulated {f['label']}{sev} explains the record "
                f"within {c['statistic']:.1f} standard deviations (largest: {w['curve']} at "
                f"{w['angle_deg'][0]}-{w['angle_deg'][1]} deg; p-value {c['p_value']:.2f})"
            )
        elif c.get("reason"):
            lines.append(f"physics: not checked ({c['reason']})")
        if self.figure:
            lines.append(f"closest simulated record overlaid: {self.figure}")
        lines.append(
            "trained on simulation only; not validated on a measured compressor (docs/diagnosis.md)"
        )
        return "\n".join(lines)


def _estimate_text(e: dict[str, Any]) -> str:
    """One chain estimate (`recipdyn.diagnosis.correction.Estimate` as a dict) in words."""
    v, u = e["value"], e["uncertainty"]
    if not math.isfinite(v):
        return e["status"] + (f" ({e['note']})" if e["note"] else "")
    unc = f" +- {u:.2g}" if math.isfinite(u) else ""
    return f"{v:+.3g}{unc} {e['unit']} ({e['status']})"


def _read(path, column, fs):
    from ..io_signal import read_signal

    return read_signal(path, column=column, fs=fs)


def diagnose(
    record: str | Path,
    *,
    channel: str = "accel_guide",
    fs=None,
    speed=None,
    tacho: str | None = None,
    p_head: str | None = None,
    p_crank: str | None = None,
    model=None,
    out: str | Path | None = None,
    correct: bool = True,
    machine=None,
    baseline=None,
) -> Diagnosis:
    """Diagnose the record in the file ``record``.

    Parameters
    ----------
    record : path
        A signal file (the formats of ``recipdyn analyze``).
    channel : str
        The acceleration channel (m/s**2).
    fs : float or str, optional
        Sampling rate, if the file does not give it.
    speed : str or float, optional
        Constant crank speed (e.g. ``"191 rpm"``); or
    tacho : str, optional
        The once-per-revolution pulse channel (mark at outer dead centre).
    p_head, p_crank : str, optional
        Chamber pressure channels (Pa), if recorded.
    model : path or Diagnoser, optional
        Default: the diagnoser shipped with recipdyn.
    out : path, optional
        Folder for the overlay figure (none without it).
    correct : bool
        Estimate the measurement chain's errors from the record and correct them before the
        features (`recipdyn.diagnosis.correction`); False: trust the tacho's mark, the
        pressures' zero and the channels' alignment, and interpolate the crank angle
        through every tacho pulse, as recipdyn did before (for comparison).
    machine : path or Machine, optional
        The machine the record was taken on (a machine file: `recipdyn.diagnosis.machine.
        read_machine`). Without it, a simulated record's own parameters are read, if it has
        them. A machine other than the diagnoser's (`recipdyn.diagnosis.machine.refusal`)
        is refused.
    baseline : path or Baseline, optional
        The machine's own healthy baseline for this diagnoser (``recipdyn baseline``:
        `recipdyn.diagnosis.baseline`): the record's chain is corrected with it and its
        features referred to the machine's own healthy state.

    Returns
    -------
    Diagnosis
        ``refused=True`` with ``reason`` for a record outside the training domain.
    """
    from ..io_signal import check_signal_file, speed_hz
    from .machine import machine_from_file, record_machine

    check_signal_file(record)  # (a file that is not there is said first)
    if (speed is None) == (tacho is None):
        raise ParameterError("speed and tacho: give exactly one (the crank angle is needed)")
    if machine is None:
        machine = record_machine(record)
    elif isinstance(machine, (str, Path)):
        machine = machine_from_file(machine)
    sig = _read(record, channel, fs)
    x, rate = np.asarray(sig.x, float), float(sig.fs)
    tach = _read(record, tacho, rate).x if tacho is not None else None
    ph = _read(record, p_head, rate).x if p_head is not None else None
    pc = _read(record, p_crank, rate).x if p_crank is not None else None
    return diagnose_arrays(
        x,
        rate,
        tacho=tach,
        speed_hz=speed_hz(speed),
        p_head=ph,
        p_crank=pc,
        model=model,
        out=out,
        correct=correct,
        machine=machine,
        baseline=baseline,
    )


def _load(model):
    from .train import Diagnoser, load

    if isinstance(model, Diagnoser):
        return model
    return load(default_model_path() if model is None else model)


def diagnose_arrays(
    x,
    fs: float,
    *,
    tacho=None,
    speed_hz: float | None = None,
    p_head=None,
    p_crank=None,
    model=None,
    out=None,
    correct: bool = True,
    machine=None,
    baseline=None,
) -> Diagnosis:
    """`diagnose` on arrays (the acceleration ``x`` at ``fs`` Hz, a tacho or a speed);
    ``machine``: the `recipdyn.diagnosis.machine.Machine` (or a machine file) the record was
    taken on, if known; ``baseline``: the machine's own healthy baseline (a file or a
    `recipdyn.diagnosis.baseline.Baseline`)."""
    from .train import one_thread

    with one_thread():
        return _diagnose_arrays(x, fs, tacho=tacho, speed_hz=speed_hz, p_head=p_head,
                                p_crank=p_crank, model=model, out=out,
                                correct=correct, machine=machine,
                                baseline=baseline)  # fmt: skip


def _diagnose_arrays(
    x, fs, *, tacho, speed_hz, p_head, p_crank, model, out, correct=True, machine=None,
    baseline=None,
) -> Diagnosis:  # fmt: skip
    from ..analysis.vibration import crank_angle, tacho_times
    from .chainrange import (
        as_evidence,
        check_chain,
        clipping_refusal,
        declared_ranges,
        read_channels,
        snr_estimate,
    )
    from .correction import axis_sd, correct_chain, resonance, tacho_revolutions
    from .evidence import impacts, record_features
    from .machine import machine_from_file, refusal

    t0 = time.perf_counter()
    diag = _load(model)
    if isinstance(machine, (str, Path)):
        machine = machine_from_file(machine)
    why = refusal(diag, machine)
    if why is not None:
        return _refuse(Diagnosis(refused=True), why, t0)
    own_chain = {}  # the machine's own chain, from its baseline
    if baseline is not None:
        from .baseline import baseline_for

        baseline = baseline_for(diag, baseline)
        own_chain = baseline.chain
        if p_head is not None:
            p_head = np.asarray(p_head, float) - own_chain["p_head_offset"]
        if p_crank is not None:
            p_crank = np.asarray(p_crank, float) - own_chain["p_crank_offset"]
    x = np.asarray(x, float)
    jitter = None
    if tacho is not None:
        try:  # a channel that is no pulse train is refused with the tacho's reason
            edges = tacho_times(np.asarray(tacho, float), fs)
        except ValueError as exc:
            raise ParameterError(str(exc)) from None
        if edges.size < 3:
            raise ParameterError(
                f"tacho: {edges.size} pulse(s); at least 3 needed (2 whole revolutions)"
            )
        if correct:  # a fit through the pulses (their jitter averaged), not an interpolation
            revs, jitter = tacho_revolutions(edges, x.size, fs)
        else:
            revs = crank_angle(x.size, fs, pulses=edges)
        # the tacho mark's angle after outer dead centre (a baseline's chain): re-phased
        revs = revs + own_chain.get("phase_deg", 0.0) / 360.0
        keep = np.isfinite(revs)
    else:
        if speed_hz is None:
            raise ParameterError("speed and tacho: give one")
        revs = crank_angle(x.size, fs, speed_hz=speed_hz)
        keep = np.ones(x.size, bool)
    sl = np.flatnonzero(keep)
    sl = slice(sl[0], sl[-1] + 1)
    x, revs = x[sl], revs[sl]
    ph = None if p_head is None else np.asarray(p_head, float)[sl]
    pc = None if p_crank is None else np.asarray(p_crank, float)[sl]
    res = Diagnosis(refused=False)
    # the channels' own samples: a clipped pressure, or an accelerometer clipped outside the
    # converter ranges the diagnoser's data set drew, is refused (chainrange.py)
    signals = read_channels(x, fs, revs, ph, pc, edges.size if tacho is not None else 0)
    why, clip = clipping_refusal(signals, declared_ranges(diag))
    res.evidence.update(clip)
    if why:
        return _refuse(res, why, t0)
    # the measurement chain, estimated from the record and corrected before any feature
    chain: dict[str, Any] = {}
    if jitter is not None:
        chain["tacho_jitter"] = jitter
    machine_pairs = diag.card["spec"].get("machine") or None
    if correct and baseline is None and tacho is not None and (ph is not None or pc is not None):
        # (a baseline's chain, fitted on the machine's own healthy records, replaces it)
        fix = correct_chain(
            revs,
            p_head=ph,
            p_crank=pc,
            reference=chain_reference(diag),
            axis_sd_deg=axis_sd(jitter, edges.size) if jitter is not None else 0.0,
            machine=machine_pairs,
        )
        chain.update(fix.estimates)
        res.evidence["chain"] = _chain_summary(chain)
        if fix.refused:
            return _refuse(res, fix.refused, t0)
        revs, ph, pc = fix.revs, fix.p_head, fix.p_crank
    declared = declared_ranges(diag)  # None: a diagnoser of one chain (learnt ranges)
    if correct or declared is not None:
        # the data set's sensor model: the bilinear resonance of the fixed chain, or a drawn
        # chain's exact (analog) one
        drawn = diag.card["spec"].get("chain", "fixed") == "drawn"
        form = "analog" if drawn else "bilinear"
        low = {} if declared is None else {"min_hz": RESONANCE_CHECK_MIN_HZ}  # (tolerances)
        chain.update(resonance(x, fs, revs if tacho is not None else None, form, **low))
        res.evidence["chain"] = _chain_summary(chain)
    # the record's own machine, from its acceleration's crank orders (fingerprint.py)
    from .fingerprint import check as fingerprint
    from .fingerprint import refusal as other_machine

    fp = fingerprint(x, fs, revs, machine_pairs, tacho=tacho is not None)
    res.evidence["fingerprint"] = fp.to_dict()
    if why := other_machine(fp, diag):
        return _refuse(res, why, t0)
    row = record_features(
        x, fs, revs, angle=tacho is not None, p_head=ph, p_crank=pc, machine=machine_pairs
    )
    names = diag.names
    X = np.array([[row[n] for n in names]], float)
    if baseline is not None:  # the machine's own healthy state (speed and ringing kept)
        X = baseline.refer(X, names)
    st = diag.state
    f_rev = row["speed_hz"]
    lo, hi = st["speed_range"]
    if not lo * (1 - RANGE_SLACK) <= f_rev <= hi * (1 + RANGE_SLACK):
        return _refuse(
            res,
            f"crank speed {f_rev:.3g} Hz ({f_rev * 60:.0f} rpm) is outside "
            f"the training range {lo:.3g}..{hi:.3g} Hz; train a diagnoser on a "
            "data set that covers it",
            t0,
        )
    lo, hi = st["fs_range"]
    if not lo * (1 - RANGE_SLACK) <= fs <= hi * (1 + RANGE_SLACK):
        return _refuse(
            res,
            f"sampling rate {fs:g} Hz is outside the training range "
            f"{lo:g}..{hi:g} Hz (it shapes the spectral features); resample the "
            "record or train on that rate",
            t0,
        )
    if declared is not None:
        # the record's chain, estimated from it, against the ranges the diagnoser was trained
        # under (chainrange.py); the learnt ranges of the statistics are not read. The floor
        # of the record's own features (not referred to a baseline: the sensor's, not the
        # machine's)
        raw = np.array([row[n] for n in names], float)
        floor = noise_floor(diag, raw)
        read = None if floor is None else (floor[0], floor_kind(diag, raw))
        if read is not None:  # the floor's share, and the SNR it gives
            res.evidence["noise_floor"] = {"share": floor[0], "training_range": list(floor[1:]),
                                           "snr_db": list(snr_estimate(*read)[:3])}  # fmt: skip
        # the tacho pulses of the data set's records: a mark at each end of their revolutions
        pulses = int(round(float(diag.card["spec"].get("revolutions", 0)))) + 1
        checks, why = check_chain(declared, chain, read, row["acc_ring_hz"], signals, pulses)
        res.evidence["chain_ranges"] = as_evidence(checks)
        if why:
            return _refuse(res, why, t0)
        floor = None  # (checked)
    else:  # the learnt range of the floor (of the features as the classifiers read them)
        floor = noise_floor(diag, X[0])
    # the noise floor first: a noisier sensor than trained also blurs the ringing frequency
    if floor is not None:
        q, lo, hi = floor
        floor_ev = {"share": q, "training_range": [lo, hi]}
        res.evidence["noise_floor"] = floor_ev
        if not lo / FLOOR_SLACK <= q <= hi * FLOOR_SLACK:
            return _refuse(
                res,
                f"the acceleration's noise floor (its quietest 10-degree stretches of the "
                f"revolution hold {q:.2g} of the mean's energy, about {_db(q):.0f} dB below it) is "
                f"outside the training range {lo:.2g}..{hi:.2g} ({_db(hi):.0f}..{_db(lo):.0f} "
                f"dB): an accelerometer signal-to-noise ratio the diagnoser was not trained "
                f"at (its data set: {_trained_snr(diag.card['spec'])} dB); train on a data set "
                "at this record's SNR (recipdyn dataset --snr or --snr-range)",
                t0,
            )
    lo, hi = st["ring_range"]
    ring = row["acc_ring_hz"]
    if declared is None and not lo * (1 - RING_SLACK) <= ring <= hi * (1 + RING_SLACK):
        return _refuse(
            res,
            f"the impacts ring at {ring:.0f} Hz, outside the training sensor "
            f"band ({lo:.0f}..{hi:.0f} Hz: the mounting resonances of the data "
            "set): another sensor or mounting; train on a data set with its "
            "resonance",
            t0,
        )
    proba = diag.predict_proba(X)[0]
    classes = diag.classes
    # a record longer than the data set's: scored on its windows of the data set's length,
    # the length the confidence thresholds were measured at (windows.py)
    from .windows import scores as window_scores

    win = window_scores(diag, x, fs, revs, p_head=ph, p_crank=pc, angle=tacho is not None,
                        machine=machine_pairs, baseline=baseline)  # fmt: skip
    if win is not None:
        proba = win.mean
    k = int(np.argmax(proba))
    res.probabilities = {c: float(p) for c, p in zip(classes, proba, strict=True)}
    if win is not None:
        res.evidence["windows"] = win.evidence(k)
    # a class is named only with channels whose held-out answers of it were right
    subset = available(X[0], diag.names)
    p_gate = proba[k] if win is None else win.gate_p(k)
    named, why, facts = gate(naming_of(diag), subset, classes[k], p_gate)
    res.evidence["channels"] = facts
    if not named and win is not None and "confidence" in facts:
        w = res.evidence["windows"]
        why += (
            f" (p: the lowest of its {w['n']} windows of {w['revolutions']:g} revolutions, the "
            f"length the threshold was measured at: {', '.join(f'{v:.3f}' for v in w['p'])})"
        )
    if not named:
        return _refuse(res, why, t0)
    # out of the domain (domain.py), then not explained by the physics (consistency.py)
    from .consistency import refusal as inconsistent
    from .domain import refusal as out_of_domain

    res.ood, why = out_of_domain(diag, X[0], classes[k])
    if why:
        return _refuse(res, why, t0)
    s0 = diag.severity(X, classes[k])[0][0] if classes[k] != "healthy" else None
    res.evidence["consistency"], why = inconsistent(
        diag, X[0], classes[k], x, fs, revs, ph, pc, angle=tacho is not None, severity=s0
    )
    if why:
        return _refuse(res, why, t0)
    res.label = classes[k]
    if res.label != "healthy":
        s, slo, shi = diag.severity(X, res.label)
        fc = diag.fault_class(res.label)
        res.severity, res.severity_interval = float(s[0]), (float(slo[0]), float(shi[0]))
        res.value = fc.value(res.severity)
        res.value_interval = (
            fc.value(res.severity_interval[0]),
            fc.value(res.severity_interval[1]),
        )
        res.unit = fc.unit
    imp = impacts(x, fs, revs)
    res.evidence.update(
        {
            "impacts_per_rev": imp["per_rev"],
            "impact_angles_deg": _top_angles(imp) if tacho is not None else [],
            "deciding": _deciding(diag, X[0]),
        }
    )
    if baseline is not None:
        res.evidence["baseline"] = {
            "records": list(baseline.records),
            "chain": dict(own_chain),
            "machine": dict(baseline.fit.machine),
        }
    j = _closest(diag, X[0], res.label)
    if ph is not None and tacho is not None:
        from .train import curve

        healthy = _closest(diag, X[0], "healthy")
        mine = curve(ph, None, fs, f_rev, 64)
        ref = np.asarray(st["library_p_head"][healthy], float)[
            :: st["library_p_head"].shape[1] // 64
        ]
        a = (mine - mine.min()) / np.ptp(mine)
        b = (ref - np.nanmin(ref)) / np.nanmax(ref - np.nanmin(ref))
        dev = np.abs(a - b)
        res.evidence["pressure_deviation"] = {
            "max": float(np.nanmax(dev)),
            "angle_deg": float(np.nanargmax(dev) * 360 / 64),
        }
    res.evidence["closest_record"] = {
        "label": st["train_labels"][j],
        "severity": float(st["train_severity"][j]),
        "record": int(st["train_records"][j]),
    }
    if out is not None:
        res.figure = str(overlay_figure(diag, j, x, tacho, fs, f_rev, Path(out), res))
    res.seconds = time.perf_counter() - t0
    return res


def _trained_snr(spec: dict[str, Any]) -> str:
    from .dataset import snr_text

    return snr_text(spec).split(" ")[0]


def _db(share: float) -> float:
    return -10.0 * math.log10(max(share, 1e-30))


def _chain_summary(chain: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """The chain's estimates as plain dicts (value, uncertainty, unit, status, note)."""
    from dataclasses import asdict

    return {k: asdict(v) for k, v in chain.items()}


def naming_of(diag) -> dict | None:
    """What each channel set of ``diag`` can name (`recipdyn.diagnosis.channels`): stored in
    the diagnoser when it was trained, or, for the shipped one trained before that, in the
    file measured on its held-out conditions beside it (`held_out_file`), if it is this
    diagnoser's."""
    t = diag.state.get("naming")
    return t if t else held_out(diag).get("naming")


def chain_reference(diag):
    """The `recipdyn.diagnosis.correction.ChainReference` of ``diag``'s own chain: stored
    in it, or the shipped diagnoser's measured one (`held_out_file`), else the default."""
    from .correction import ChainReference

    d = diag.state.get("chain_reference") or held_out(diag).get("chain_reference")
    return ChainReference.from_dict(d)


def held_out_file() -> Path:
    """Measurements of the shipped diagnoser made on its held-out conditions after it was
    built (``benchmarks/bench_chain_correction.py --held-out``): what each channel set can
    name and its chain's reference. Read only while they belong to the diagnoser loaded
    (its pinned records' fingerprint)."""
    return default_model_path().with_name("default.heldout.json")


def held_out(diag) -> dict[str, Any]:
    import hashlib
    import json

    path = held_out_file()
    if not path.is_file():
        return {}
    d = json.loads(path.read_text(encoding="utf-8"))
    mine = hashlib.sha256(str(diag.state.get("fingerprints_json", "")).encode()).hexdigest()
    return d if d.get("fingerprint") == mine else {}


def noise_floor(diag, row: np.ndarray) -> tuple[float, float, float] | None:
    """``(share, lo, hi)``: the acceleration's noise floor, as the share of the mean crank-angle
    bin's high-passed energy that its quietest 10-degree bin holds (``BINS`` times the least
    ``ang_`` feature), and the range of the same over the diagnoser's training records.
    Without a tacho (no angle features): the quietest windows of a 10-degree bin's duration
    (``acc_quiet_share``, a statistic of its own with its own training range); None if the
    diagnoser has neither.

    A machine's impacts and valve events fill some bins and leave others quiet, so the
    quietest bin is the sensor's noise: at 20 dB it holds about 1e-2 of the mean bin
    (0.007-0.016), at 10 dB 0.05-0.11, at 40 dB 1e-4-1.4e-3 (the shipped data set draws the
    SNR in 10-40 dB: its training range is 1e-4-0.11). The angle features are shares of that
    energy, so the noise moves them all at once: a diagnoser trained at 20 dB alone called
    12 of 12 healthy records at 10 dB a crosshead knocking in its guide. A record outside the
    training range is refused, not answered."""
    names = diag.names
    cols = [i for i, n in enumerate(names) if n.startswith("ang_")]
    a = np.asarray(row, float)[cols]
    st = diag.state
    if not cols or not np.isfinite(a).all():
        # no crank angle: the quietest 10-degree-long windows (evidence.quiet_share)
        rng = st.get("quiet_range")
        if rng is None or "acc_quiet_share" not in names:
            return None
        q = float(np.asarray(row, float)[names.index("acc_quiet_share")])
        return (q, float(rng[0]), float(rng[1])) if math.isfinite(q) else None
    if st.get("noise_floor_range") is not None:  # stored exactly at training
        lo, hi = st["noise_floor_range"]
        return len(cols) * float(a.min()), float(lo), float(hi)
    # an older file: from the float16 training features (3 digits: enough at one SNR)
    train = st["Z_train"].astype(float)[:, cols] * st["scale"][cols] + st["center"][cols]
    q_train = len(cols) * np.nanmin(train, axis=1)
    return len(cols) * float(a.min()), float(np.nanmin(q_train)), float(np.nanmax(q_train))


def floor_kind(diag, row: np.ndarray) -> str:
    """Which noise floor `noise_floor` read for ``row``: ``"angle"`` (the crank-angle bins,
    with a tacho) or ``"quiet"`` (the quiet windows, without)."""
    cols = [i for i, n in enumerate(diag.names) if n.startswith("ang_")]
    a = np.asarray(row, float)[cols]
    return "angle" if cols and np.isfinite(a).all() else "quiet"


def _refuse(res: Diagnosis, reason: str, t0: float) -> Diagnosis:
    res.refused, res.reason = True, reason
    res.seconds = time.perf_counter() - t0
    return res


def _top_angles(imp, n: int = 6, apart_deg: float = 5.0) -> list[float]:
    """The crank angles of the ``n`` largest impacts at distinct places of the revolution: an
    impact within ``apart_deg`` of a larger one kept already (the same knock in another
    revolution) is passed over, so the list names places, not repeats."""
    kept: list[float] = []
    for i in np.argsort(imp["sizes"])[::-1]:
        a = float(imp["angles_deg"][i])
        if all(abs((a - b + 180.0) % 360.0 - 180.0) > apart_deg for b in kept):
            kept.append(a)
            if len(kept) == n:
                break
    return sorted(round(a, 1) for a in kept)


def _deciding(diag, row, n: int = 5) -> list[tuple[str, float]]:
    """The features farthest (robust z) from the healthy training records, among those the
    classifier of the record's channel subset reads. The healthy records' spread (their
    interquartile range) is floored at `HEALTHY_SPREAD_FLOOR` of the whole training set's: a
    feature the healthy records hold nearly constant (a count of pin-load reversals) would
    otherwise give a z of 1e14 for an ordinary departure."""
    st = diag.state
    cols = _cols(diag.names, available(row, diag.names))
    healthy = np.array([lab == "healthy" for lab in st["train_labels"]])
    Z = st["Z_train"].astype(float)[healthy][:, cols]
    z = ((row - st["center"]) / st["scale"])[cols]
    med = np.nanmedian(Z, axis=0)
    spread = np.nanpercentile(Z, 75, axis=0) - np.nanpercentile(Z, 25, axis=0)
    dz = (z - med) / np.maximum(np.nan_to_num(spread), HEALTHY_SPREAD_FLOOR)
    ok = np.isfinite(dz)
    order = np.argsort(-np.abs(np.where(ok, dz, 0)))[:n]
    return [(diag.names[cols[i]], float(dz[i])) for i in order if ok[i]]


def _closest(diag, row, label: str) -> int:
    st = diag.state
    idx = np.array([i for i, lab in enumerate(st["train_labels"]) if lab == label])
    cols = _cols(diag.names, available(row, diag.names))
    z = (row - st["center"]) / st["scale"]
    Z = st["Z_train"].astype(float)[idx][:, cols]
    d = np.sqrt(np.mean((Z - z[cols]) ** 2, axis=1))
    return int(idx[np.argmin(d)])


def overlay_figure(diag, j: int, x, tacho, fs: float, f_rev: float, out: Path, res) -> Path:
    """The record's first whole revolution and the closest simulated record's, against the
    crank angle (from the tacho's mark; with a speed only, from the record's start)."""
    from ..mplstyle import _mpl
    from .train import curve

    plt = _mpl()
    out.mkdir(parents=True, exist_ok=True)
    sim = np.asarray(diag.state["library_accel"][j], float)
    n = sim.size  # the library's own resolution (a file of another CURVE_POINTS reads too)
    ang = np.arange(n) * 360.0 / n
    mine = curve(x, None, fs, f_rev, n)  # x is already cut to start at the tacho's first edge
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(ang, mine, lw=0.8, label="record")
    ev = res.evidence["closest_record"]
    ax.plot(
        ang,
        sim,
        lw=0.8,
        alpha=0.8,
        label=f"closest simulated: {ev['label']}, severity {ev['severity']:.2f}",
    )
    ax.set_xlabel(
        "crank angle after the tacho mark (deg)"
        if tacho is not None
        else "crank angle after the record's start (deg)"
    )
    ax.set_ylabel("acceleration (m/s²)")
    ax.set_xlim(0, 360)
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(f"diagnosis: {res.label} (p = {res.probabilities[res.label]:.2f})")
    path = out / "diagnosis_overlay.png"
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path
