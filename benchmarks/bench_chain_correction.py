"""The measurement chain's errors estimated from the record and corrected (docs/diagnosis.md,
"The measurement chain, read from the record").

Three parts, each on records of the shipped diagnoser's held-out conditions (the healthy
machine and every fault of its data set's design, simulated again over ``--revolutions``):

``coverage`` (default)
    Every record sensed through the data set's chain with errors drawn at random (seeded):
    the tacho's mark +-3 deg, each pressure's offset +-10 kPa and gain +-1 %, both pressures
    0-10 samples late, a causal Butterworth low-pass of order 2-8 at 1.5 kHz-0.4 fs on them,
    the mount's resonance at 2.5 kHz-0.45 fs with damping 0.02-0.2, the tacho's jitter
    0-0.25 deg. Counted: how often each recovered value lies within its reported 95 %
    interval of the imposed one (coverage), and whether the corrected record is answered as
    the clean one is (and as the truth).
``examples``
    The issue's single changes on healthy records, before (``correct=False``: the mark
    trusted, the pressures' zero and alignment trusted, the angle interpolated through every
    pulse) and after.
``held-out``
    Builds ``src/recipdyn/diagnosis/data/default.heldout.json``: what each channel set of the
    shipped diagnoser can name (`recipdyn.diagnosis.channels.naming_table` on its 360
    held-out records, the data set's records to the bit) and its chain's reference
    (`recipdyn.diagnosis.correction.reference_from` on the same records). The shipped
    diagnoser was built before either existed; a diagnoser trained now stores both.

    python benchmarks/bench_chain_correction.py --cases 54
    python benchmarks/bench_chain_correction.py --part examples --conditions 3
    python benchmarks/bench_chain_correction.py --part held-out
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import time
import warnings

import numpy as np

#: The ranges the coverage part draws chain errors from.
RANGES = {
    "mark_deg": (-3.0, 3.0),
    "offset_pa": (-10_000.0, 10_000.0),
    "gain": (0.99, 1.01),
    "delay_samples": (0, 10),
    "lowpass_order": (2, 8),
    "lowpass_hz": (1500.0, None),  # to 0.4 fs
    "resonance_hz": (2500.0, None),  # to 0.45 fs
    "damping": (0.02, 0.2),
    "jitter_deg": (0.0, 0.25),
}


def _shipped():
    from recipdyn.diagnosis.dataset import DatasetSpec, design
    from recipdyn.diagnosis.diagnose import default_model_path
    from recipdyn.diagnosis.train import load

    diag = load(default_model_path())
    spec = DatasetSpec.from_dict(diag.card["spec"])  # its chain: fixed, as it was built
    return diag, [t for t in design(spec) if t["split"] == "test"]


def _run(task, revolutions):
    from recipdyn.simulate import simulate

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(model="compressor-contact-valves", revolutions=revolutions,
                        transient=task["transient"], fs=task["fs"], summary=False,
                        **task["params"])  # fmt: skip


def _lowpass_delay(order, fc, fs) -> float:
    """Group delay (s) of a causal digital Butterworth low-pass at the crank's low orders."""
    from scipy.signal import butter, sosfreqz

    sos = butter(order, fc, fs=fs, output="sos")
    w, h = sosfreqz(sos, worN=np.array([1.0, 3.0]), fs=fs)
    ph = np.unwrap(np.angle(h))
    return float(-(ph[1] - ph[0]) / (2 * np.pi * (w[1] - w[0])))


def sense(ds, task, chain: dict, seed_extra: int = 0) -> dict:
    """The record through the data set's chain (`recipdyn.sensors`, as
    `recipdyn.diagnosis.dataset.simulate_record`) with ``chain``'s changes: ``mark_deg``,
    ``offset_pa`` and ``gain`` (per chamber), ``delay_samples``, ``lowpass`` ((order, Hz)
    causal, replacing the 0.4 fs anti-alias filter; ``lowpass_zero_phase``: applied forward
    and backward instead), ``resonance_hz``/``damping``, ``jitter_deg``."""
    from scipy.signal import butter, sosfiltfilt

    from recipdyn import sensors

    fs = task["fs"]
    lp = chain.get("lowpass")
    zero = chain.get("lowpass_zero_phase", False)
    pt = sensors.PressureTransducer()
    if lp is not None and not zero:
        pt = sensors.PressureTransducer(lowpass_hz=lp[1], lowpass_order=lp[0])
    acc = sensors.Accelerometer(
        snr_db=task["snr_db"],
        resonance_hz=chain.get("resonance_hz", task["resonance_hz"]),
        damping=chain.get("damping", 0.05),
    )
    mark = chain.get("mark_deg", 0.0)
    rec = sensors.record(ds, accelerometer=acc, pressure=pt,
                         tacho=sensors.Tacho(angle=math.radians(mark)),
                         seed=task["noise_seed"])  # fmt: skip
    out = {"fs": fs, "x": rec["accel_guide"].values, "tacho": rec["tacho"].values}
    d = int(chain.get("delay_samples", 0))
    for k, name in enumerate(("p_head_sensor", "p_crank_sensor")):
        p = rec[name].values
        if lp is not None and zero:
            p = sosfiltfilt(butter(lp[0], lp[1], fs=fs, output="sos"), p)
        if d:
            p = np.concatenate([np.full(d, p[0]), p[:-d]])
        out[name] = chain.get("gain", (1.0, 1.0))[k] * p + chain.get("offset_pa", (0.0, 0.0))[k]
    jit = chain.get("jitter_deg", 0.0)
    if jit:  # each pulse at its own mark angle, scattered by the jitter
        rng = np.random.default_rng([task["noise_seed"], 77, seed_extra])
        th = ds["theta1"].values - math.radians(mark)
        k = np.round(th / (2 * np.pi)).astype(int)
        scatter = rng.normal(0, math.radians(jit), k.max() - k.min() + 2)
        ph = th - 2 * np.pi * k - scatter[k - k.min()]
        out["tacho"] = np.where((ph >= 0) & (ph < math.radians(10.0)), 5.0, 0.0)
    return out


def axis_mark(ds, s) -> float:
    """The crank angle (deg) at which the crank angle `diagnose` reads from the record's
    tacho (a fit through its pulses, `tacho_revolutions`) is 0: the mark as that axis has
    it, its jitter's mean over the pulses included."""
    from recipdyn.analysis.vibration import tacho_times
    from recipdyn.diagnosis.correction import tacho_revolutions

    edges = tacho_times(s["tacho"], s["fs"])
    revs, _ = tacho_revolutions(edges, s["tacho"].size, s["fs"])
    ok = np.isfinite(revs)
    d = np.degrees(ds["theta1"].values[ok]) - 360.0 * revs[ok]
    return float(np.median((d + 180.0) % 360.0 - 180.0))


def truth(chain: dict, task, mark: float | None = None) -> dict:
    """The errors ``chain`` imposes, against the data set's own chain: the phase the
    pressures show (the mark as the tacho's fitted axis has it, ``mark`` (`axis_mark`), or
    the chain's, less the pressures' delay and the low-pass's group delay beyond the data
    set's own 4th-order one at 0.4 fs, as crank angle), the offsets, the gain ratio minus 1,
    the jitter (with the tacho's own sampling: an edge read to a sample, 1/sqrt(12) of a
    sample's crank angle RMS), the mount's frequency and damping."""
    fs, omega = task["fs"], task["params"]["omega"]
    tau = chain.get("delay_samples", 0) / fs
    lp = chain.get("lowpass")
    if lp is not None and not chain.get("lowpass_zero_phase", False):
        tau += _lowpass_delay(lp[0], lp[1], fs)
    if lp is not None:  # the data set's own anti-alias filter is replaced
        tau -= _lowpass_delay(4, 0.4 * fs, fs)
    g = chain.get("gain", (1.0, 1.0))
    o = chain.get("offset_pa", (0.0, 0.0))
    step = 360.0 * omega / (2 * math.pi) / fs / math.sqrt(12.0)
    return {
        "phase": (chain.get("mark_deg", 0.0) if mark is None else mark) - math.degrees(omega * tau),
        "offset_head": o[0],
        "offset_crank": o[1],
        "gain_ratio": g[0] / g[1] - 1.0,
        "tacho_jitter": math.hypot(chain.get("jitter_deg", 0.0), step),
        "resonance_hz": chain.get("resonance_hz", task["resonance_hz"]),
        "damping": chain.get("damping", 0.05),
    }


def draw(rng, fs) -> dict:
    r = RANGES
    return {
        "mark_deg": float(rng.uniform(*r["mark_deg"])),
        "offset_pa": tuple(float(v) for v in rng.uniform(*r["offset_pa"], 2)),
        "gain": tuple(float(v) for v in rng.uniform(*r["gain"], 2)),
        "delay_samples": int(rng.integers(r["delay_samples"][0], r["delay_samples"][1] + 1)),
        "lowpass": (
            int(rng.choice([2, 4, 6, 8])),
            float(rng.uniform(r["lowpass_hz"][0], 0.4 * fs)),
        ),
        "resonance_hz": float(rng.uniform(r["resonance_hz"][0], 0.45 * fs)),
        "damping": float(math.exp(rng.uniform(math.log(0.02), math.log(0.2)))),
        "jitter_deg": float(rng.uniform(*r["jitter_deg"])),
    }


def _diagnose(s, diag, correct=True, **kw):
    from recipdyn.diagnosis.diagnose import diagnose_arrays

    return diagnose_arrays(s["x"], s["fs"], tacho=s["tacho"], p_head=s["p_head_sensor"],
                           p_crank=s["p_crank_sensor"], model=diag, correct=correct,
                           **kw)  # fmt: skip


def _answer(res) -> str:
    """The classifier's answer (even where the record was refused after it), or '-'."""
    if not res.probabilities:
        return "-"
    return max(res.probabilities, key=res.probabilities.get)


def part_coverage(args) -> dict:
    diag, test = _shipped()
    conds = sorted({t["condition"] for t in test})[: args.conditions]
    tasks = [t for t in test if t["condition"] in conds and t["level"] == 0]
    rng = np.random.default_rng(args.seed)
    per_record = max(1, math.ceil(args.cases / len(tasks)))
    names = ("phase", "offset_head", "offset_crank", "gain_ratio", "tacho_jitter",
             "resonance_hz", "damping")  # fmt: skip
    hits = {n: [0, 0] for n in names}
    same = right = right_clean = refused = n = 0
    t0 = time.perf_counter()
    rows, misses, rel = [], [], {}
    for task in tasks:
        ds = _run(task, args.revolutions)
        clean = _diagnose(sense(ds, task, {}), diag, correct=False)
        right_clean += _answer(clean) == task["label"]
        for j in range(per_record):
            if n >= args.cases:
                break
            chain = draw(rng, task["fs"])
            if args.keep_mount:  # the data set's accelerometer: the pressures' chain alone
                chain.pop("resonance_hz")
                chain.pop("damping")
            s = sense(ds, task, chain, seed_extra=j)
            res = _diagnose(s, diag)
            want = truth(chain, task)
            ev = res.evidence.get("chain", {})
            for name in names:
                e = ev.get(name)
                if (
                    e is None
                    or not math.isfinite(e["value"])
                    or not math.isfinite(e["uncertainty"])
                ):
                    continue
                hits[name][1] += 1
                inside = abs(e["value"] - want[name]) <= e["uncertainty"]
                hits[name][0] += inside
                rel.setdefault(name, []).append(
                    (e["value"] - want[name]) / want[name] if want[name] else math.nan
                )
                if not inside:
                    misses.append(f"{n + 1} {name}: {e['value']:.4g} +- {e['uncertainty']:.2g}"
                                  f" for {want[name]:.4g}")  # fmt: skip
            n += 1
            refused += res.refused
            same += (not res.refused) and res.label == _answer(clean)
            right += (not res.refused) and res.label == task["label"]
            rows.append((task["label"], round(task["severity"], 2), res.refused,
                         _answer(res), res.reason[:70]))  # fmt: skip
            said = "refused: " + res.reason[:60] if res.refused else res.label
            print(f"{n:3d} {task['label']:26s} {said}", flush=True)
    print(f"\n{n} cases ({len(tasks)} records of {len(conds)} held-out conditions, "
          f"{args.revolutions:g} revolutions), {time.perf_counter() - t0:.0f} s\n")  # fmt: skip
    print("outside their intervals:\n  " + "\n  ".join(misses) + "\n")
    for name in ("resonance_hz", "damping"):
        r = np.abs(np.array(rel.get(name, [np.nan])))
        print(
            f"{name}: relative error median {np.nanmedian(r):.3f}, 90th percentile "
            f"{np.nanpercentile(r, 90):.3f}, largest {np.nanmax(r):.3f}"
        )
    print("| estimate | cases | within its 95 % interval |")
    print("|---|---|---|")
    for name, (h, m) in hits.items():
        print(f"| {name} | {m} | {h / max(m, 1):.2f} |")
    print(
        f"\nanswered as the clean record (uncorrected) is: {same}/{n}; right: {right}/{n} "
        f"(clean records right: {right_clean}/{len(tasks)}); refused: {refused}/{n}"
    )
    summary = [
        {"metric": f"chain coverage {k}", "value": h / max(m, 1), "unit": "", "target": 0.9,
         "better": "higher"}
        for k, (h, m) in hits.items() if m
    ]  # fmt: skip
    summary.append({"metric": "chain: answered as clean", "value": same / max(n, 1), "unit": "",
                    "target": None, "better": "higher"})  # fmt: skip
    return {"cases": n, "coverage": hits, "same": same, "right": right, "refused": refused,
            "rows": rows, "summary": summary}  # fmt: skip


EXAMPLES = {
    "clean": {},
    "+1 kPa on both pressures": {"offset_pa": (1000.0, 1000.0)},
    "+0.3 kPa on the head end": {"offset_pa": (300.0, 0.0)},
    "pressures 3 samples late": {"delay_samples": 3},
    "causal 4th-order 2 kHz low-pass": {"lowpass": (4, 2000.0)},
    "zero-phase 4th-order 2 kHz low-pass": {"lowpass": (4, 2000.0), "lowpass_zero_phase": True},
    "mark 0.3 deg before ODC": {"mark_deg": -0.3},
    "mark 1 deg after ODC": {"mark_deg": 1.0},
    "jitter 0.1 deg": {"jitter_deg": 0.1},
    "jitter 0.25 deg (seed 1)": {"jitter_deg": 0.25, "seed": 1},
    "jitter 0.25 deg (seed 2)": {"jitter_deg": 0.25, "seed": 2},
    "gains +3 % / -3 %": {"gain": (1.03, 0.97)},
    "resonance 3.8 kHz at damping 0.12": {"resonance_hz": 3800.0, "damping": 0.12},
}


def part_examples(args) -> dict:
    diag, test = _shipped()
    conds = sorted({t["condition"] for t in test})[: args.conditions]
    labels = args.labels.split(",")
    out = {}
    print("| record | change | before | after | chain estimates (after) |")
    print("|---|---|---|---|---|")
    for task in [t for t in test if t["condition"] in conds and t["label"] in labels
                 and t["level"] == 0]:  # fmt: skip
        ds = _run(task, args.revolutions)
        for name, chain in EXAMPLES.items():
            s = sense(ds, task, chain, seed_extra=chain.get("seed", 0))
            cells = []
            for correct in (False, True):
                r = _diagnose(s, diag, correct=correct)
                a = _answer(r)
                p = r.probabilities.get(a, math.nan)
                gated = r.refused and r.evidence.get("channels") and a != "-"
                if r.refused and not gated:
                    cells.append(f"refused ({r.reason[:50]})")
                else:
                    mark = "right" if a == task["label"] else "WRONG"
                    cells.append(f"{a} p {p:.2f} ({mark}{', refused after' if gated else ''})")
            ev = r.evidence.get("chain", {})
            est = ", ".join(
                f"{k} {v['value']:+.3g}" for k, v in ev.items()
                if k in ("phase", "offset_head", "offset_crank", "gain_ratio")
                and v["status"] == "corrected"
            )  # fmt: skip
            print(f"| {task['label']} (condition {task['condition']}) | {name} | {cells[0]} | "
                  f"{cells[1]} | {est} |", flush=True)  # fmt: skip
            out[f"{task['index']}:{name}"] = cells
    return {"examples": out, "summary": []}


def part_held_out(args) -> dict:
    """The shipped diagnoser's held-out records: naming tables and chain reference."""
    from recipdyn.analysis.vibration import tacho_times
    from recipdyn.diagnosis.channels import naming_table
    from recipdyn.diagnosis.correction import pressure_phase, reference_from
    from recipdyn.diagnosis.dataset import make_record
    from recipdyn.diagnosis.diagnose import held_out_file
    from recipdyn.diagnosis.train import AVAILABILITY, _augment, detection_limits, severity_bins
    from recipdyn.parallel import run_unordered

    diag, test = _shipped()
    done: dict[int, dict] = {}
    t0 = time.perf_counter()

    def keep(res):
        done[res["index"]] = res
        if len(done) % 20 == 0:
            print(f"{len(done)}/{len(test)} records, {time.perf_counter() - t0:.0f} s", flush=True)

    from recipdyn.errors import deferred_signals

    with deferred_signals() as pending:
        run_unordered(make_record, test, args.workers, keep, pending)
    rows, labels, sev, fits = [], [], [], []
    for t in test:
        r = done[t["index"]]
        if r["error"]:
            raise RuntimeError(r["error"])
        rows.append([r["features"][k] for k in diag.names])
        labels.append(t["label"])
        sev.append(t["severity"])
        ch = {k: np.asarray(v, float) for k, v in r["channels"].items()}
        n = int(np.isfinite(ch["tacho"]).sum())
        e = tacho_times(ch["tacho"][:n], t["fs"])
        revs = (np.arange(n) / t["fs"] - e[0]) * t["params"]["omega"] / (2 * np.pi)
        revs = np.where(revs >= 0, revs, np.nan)
        fits.append({"condition": t["condition"],
                     "head": pressure_phase(ch["p_head_sensor"][:n], revs, "head"),
                     "crank": pressure_phase(ch["p_crank_sensor"][:n], revs, "crank")})  # fmt: skip
    X, labels, sev = np.array(rows, float), np.array(labels), np.array(sev)
    Xa, _ = _augment(X, diag.names)
    naming = {}
    for j, k in enumerate(AVAILABILITY):
        proba = diag.predict_proba(Xa[j * len(X) : (j + 1) * len(X)])
        pred = np.array(diag.classes)[proba.argmax(axis=1)]
        det = detection_limits(labels, None, sev, pred, diag.classes,
                               bins=severity_bins(diag.card))  # fmt: skip
        naming[k] = naming_table(labels, pred, sev, diag.classes, det)
        print(f"{k}: accuracy {naming[k]['accuracy']:.3f}; named: "
              + ", ".join(c for c, e in naming[k]["classes"].items()
                          if e["answers"] >= 10 and e["precision"] >= 0.9))  # fmt: skip
    ref = reference_from(fits, source=f"the shipped diagnoser's {len(test)} held-out records "
                         "(its data set's own chain)")  # fmt: skip
    fp = hashlib.sha256(str(diag.state["fingerprints_json"]).encode()).hexdigest()
    doc = {
        "about": "measured on the shipped diagnoser's held-out conditions by "
        "benchmarks/bench_chain_correction.py --part held-out",
        "fingerprint": fp,
        "naming": naming,
        "chain_reference": ref.to_dict(),
    }
    path = held_out_file()
    path.write_text(json.dumps(_rounded(doc)), encoding="utf-8")
    print(
        f"wrote {path} ({path.stat().st_size / 1024:.0f} KiB) in {time.perf_counter() - t0:.0f} s"
    )
    return {"summary": []}


def _rounded(x):
    """Floats to 6 significant digits (the file stays small; the estimates' own errors are
    far larger)."""
    if isinstance(x, float):
        return float(f"{x:.6g}") if math.isfinite(x) else None
    if isinstance(x, dict):
        return {k: _rounded(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_rounded(v) for v in x]
    return x


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--part", choices=("coverage", "examples", "held-out"), default="coverage")
    ap.add_argument("--cases", type=int, default=54)
    ap.add_argument("--conditions", type=int, default=3, help="held-out conditions used")
    ap.add_argument("--revolutions", type=float, default=6.0)
    ap.add_argument("--labels", default="healthy", help="classes of the examples")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="9 cases of one condition")
    ap.add_argument(
        "--keep-mount",
        action="store_true",
        help="keep the data set's accelerometer mount (draw the pressures' and tacho's chain)",
    )
    args = ap.parse_args(argv)
    if args.quick:
        args.cases, args.conditions = 9, 1
    return {"coverage": part_coverage, "examples": part_examples,
            "held-out": part_held_out}[args.part](args)  # fmt: skip


if __name__ == "__main__":
    main()
