"""The record's chain against the diagnoser's declared chain ranges (issue 42, points 1, 2, 4;
docs/diagnosis.md, "The chain ranges a diagnoser was trained under").

``calibrate``
    The noise floor's calibration to the accelerometer's SNR, and the resonance estimate's
    errors, measured on records made with known chains: ``--machines`` records of the
    shipped diagnoser's *training* conditions (every class in turn, ``--revolutions``
    revolutions), each sensed through ``--chains`` chains drawn from
    `recipdyn.chain.DEFAULT_RANGES` with the accelerometer's SNR widened to 0-50 dB and its
    resonance to 0.7-7 kHz (log-uniform), so the calibration spans the declared ranges and
    beyond. Printed: the offset and the 2.5/97.5 % residuals of ``snr - x`` (``x = 10
    log10(1/q - 1)``) for the crank-angle floor and the quiet windows, by band of ``x``; the
    resonance estimate's coverage and how often it is not identified, in and out of the
    declared band.
``refusals``
    The shipped diagnoser on the in-domain held-out records (its data set's test split, as
    drawn, ``--per-condition`` records of each held-out condition) and on records outside the
    ranges (``--outside`` records each: SNR 3-8 dB, resonance 0.8-2 kHz, otherwise as drawn),
    refused by the chain checks before (the learnt ranges) and after (the declared ranges).

    python benchmarks/bench_chain_ranges.py --part calibrate --machines 36 --chains 8
    python benchmarks/bench_chain_ranges.py --part refusals
"""

from __future__ import annotations

import argparse
import math
import time
import warnings
from concurrent.futures import ProcessPoolExecutor

import numpy as np


def _spec():
    from recipdyn.diagnosis.dataset import DatasetSpec
    from recipdyn.diagnosis.diagnose import default_model_path
    from recipdyn.diagnosis.train import load

    diag = load(default_model_path())
    return diag, DatasetSpec.from_dict(diag.card["spec"])


def _simulate(task):
    from recipdyn.diagnosis.classes import MODEL
    from recipdyn.simulate import simulate

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(model=MODEL, revolutions=task["revolutions"], transient=task["transient"],
                        fs=task["fs"], **task["params"])  # fmt: skip


def _statistics(rec, fs):
    """What `recipdyn diagnose` reads of the accelerometer's chain: the crank-angle noise
    floor (its tacho fit), the quiet windows' share, the resonance estimate."""
    from recipdyn.analysis.vibration import tacho_times
    from recipdyn.diagnosis.correction import resonance, tacho_revolutions
    from recipdyn.diagnosis.evidence import BINS, record_features

    x = np.asarray(rec["accel_guide"].values, float)
    edges = tacho_times(np.asarray(rec["tacho"].values, float), fs)
    revs, _ = tacho_revolutions(edges, x.size, fs)
    keep = np.flatnonzero(np.isfinite(revs))
    x, revs = x[keep[0] : keep[-1] + 1], revs[keep[0] : keep[-1] + 1]
    row = record_features(x, fs, revs)
    ang = np.array([v for k, v in row.items() if k.startswith("ang_")], float)
    est = resonance(x, fs, revs, "analog")
    r = est["resonance_hz"]
    low = resonance(x, fs, revs, "analog", min_hz=600.0)["resonance_hz"]
    return {
        "low_value": low.value,
        "low_u": low.uncertainty,
        "low_status": low.status,
        "impacts": float(row["acc_impacts_per_rev"]),
        "damp_value": est["damping"].value,
        "damp_u": est["damping"].uncertainty,
        "q_angle": float(BINS * np.nanmin(ang)),
        "q_quiet": float(row["acc_quiet_share"]),
        "ring_hz": float(row["acc_ring_hz"]),
        "res_value": r.value,
        "res_u": r.uncertainty,
        "res_status": r.status,
    }


def _calibrate_one(job):
    from recipdyn import sensors
    from recipdyn.chain import DEFAULT_RANGES, ChainRanges, Span

    task, n_chains, seed = job
    ds = _simulate(task)
    old_s = DEFAULT_RANGES["accelerometer.snr_db"]
    old_r = DEFAULT_RANGES["accelerometer.resonance_hz"]
    wide = ChainRanges().with_spans(
        accelerometer__snr_db=Span(0.0, 50.0, "dB", old_s.meaning, "calibration"),
        accelerometer__resonance_hz=Span(700.0, 7000.0, "Hz", old_r.meaning, "calibration",
                                         log=True),
    )  # fmt: skip
    rng = np.random.default_rng([seed, task["index"]])
    rows = []
    for _ in range(n_chains):
        ch = wide.draw(rng, task["fs"])
        rec = sensors.record(ds, chain=ch, seed=int(rng.integers(2**31)))
        try:
            st = _statistics(rec, task["fs"])
        except Exception as exc:  # noqa: BLE001 - counted, not hidden
            st = {"error": f"{type(exc).__name__}: {exc}"}
        st.update(label=task["label"], index=task["index"], snr=ch.accelerometer.snr_db,
                  resonance=ch.accelerometer.resonance_hz, fs=task["fs"],
                  damping=ch.accelerometer.damping,
                  lowpass=ch.accelerometer.lowpass_hz)  # fmt: skip
        rows.append(st)
    return rows


def calibrate(args) -> list[dict]:
    diag, spec = _spec()
    from recipdyn.diagnosis.dataset import design

    train = [t for t in design(spec) if t["split"] == "train"]
    conds = sorted({t["condition"] for t in train})
    labels = list(spec.classes)
    tasks = []
    for i in range(args.machines):  # a new condition and the next class each time
        c, lab = conds[(7 * i) % len(conds)], labels[i % len(labels)]
        t = next(t for t in train if t["condition"] == c and t["label"] == lab)
        tasks.append(dict(t, revolutions=args.revolutions))
    t0 = time.perf_counter()
    rows = []
    jobs = [(t, args.chains, args.seed) for t in tasks]
    with ProcessPoolExecutor(args.workers) as ex:
        for r in ex.map(_calibrate_one, jobs):
            rows.extend(r)
    print(f"\n{len(rows)} records ({len(tasks)} simulated x {args.chains} chains), "
          f"{args.revolutions:g} revolutions, {time.perf_counter() - t0:.0f} s")  # fmt: skip
    bad = [r for r in rows if "error" in r]
    rows = [r for r in rows if "error" not in r]
    if bad:
        print(f"{len(bad)} records failed: {bad[0]['error']}")
    if args.out:
        import json

        with open(args.out, "w", encoding="utf-8") as f:
            json.dump(rows, f)
    out = []
    snr = np.array([r["snr"] for r in rows])
    for kind in ("angle", "quiet"):
        q = np.array([r[f"q_{kind}"] for r in rows])
        ok = np.isfinite(q) & (q > 0) & (q < 1)
        x = np.full(q.size, np.nan)
        x[ok] = 10 * np.log10(1 / q[ok] - 1)
        d = snr - x
        print(f"\n{kind}: snr - x by band of x ({ok.sum()} records)")
        print("| x (dB) | records | median | p2.5 | p97.5 | snr range |")
        print("|---|---|---|---|---|---|")
        for a, b in ((-10, 0), (0, 5), (5, 10), (10, 15), (15, 20), (20, 25), (25, 30),
                     (30, 35), (35, 60)):  # fmt: skip
            m = ok & (x >= a) & (x < b)
            if m.sum():
                p = np.percentile(d[m], [2.5, 50, 97.5])
                print(f"| {a}..{b} | {m.sum()} | {p[1]:+.2f} | {p[0]:+.2f} | {p[2]:+.2f} | "
                      f"{snr[m].min():.1f}..{snr[m].max():.1f} |")  # fmt: skip
        for xmax in (20.0, 25.0, 30.0):
            m = ok & (x <= xmax)
            p = np.percentile(d[m], [2.5, 50, 97.5])
            print(f"x <= {xmax:g}: {m.sum()} records, offset {p[1]:+.2f}, residuals "
                  f"{p[0] - p[1]:+.2f}..{p[2] - p[1]:+.2f} dB")  # fmt: skip
            if xmax == 25.0:
                out.append({"metric": f"SNR from the {kind} noise floor: 95 % residual width",
                            "value": float(p[2] - p[0]), "unit": "dB", "target": None,
                            "better": "lower"})  # fmt: skip
    # the resonance estimate, read as the check reads it (chainrange.check_chain)
    from recipdyn.diagnosis.tolerances import RESONANCE_CHECK_REL, RING_AGREEMENT

    res = np.array([r["resonance"] for r in rows])
    fs = np.array([r["fs"] for r in rows])
    ring = np.array([r["ring_hz"] for r in rows])
    inb = (res >= 2500) & (res <= 6000)
    low = (res >= 800) & (res <= 2000)
    print("\nresonance, read where the fit is 'measured' and the impacts ring within "
          f"{RING_AGREEMENT:.0%} of it, +-{RESONANCE_CHECK_REL:.0%} added:")  # fmt: skip
    print("| lowest peak tried | in band (2.5-6 kHz) | read | covered (below 0.45 fs) | read "
          "outside the band | 0.8-2 kHz | read below the band |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    for tag, name in (("res", "1000 Hz"), ("low", "600 Hz")):
        v = np.array([r[f"{tag}_value"] for r in rows])
        u0 = np.array([r[f"{tag}_u"] for r in rows])
        st = np.array([r[f"{tag}_status"] for r in rows])
        read = (st == "measured") & np.isfinite(u0) & (np.abs(ring - v) <= RING_AGREEMENT * v)
        u = np.hypot(u0, RESONANCE_CHECK_REL * v)
        out_ = read & ((v + u < 2500) | (v - u > 6000))
        cov = read & inb & (res < 0.45 * fs)
        covered = np.mean(np.abs(v[cov] - res[cov]) <= u[cov]) if cov.sum() else math.nan
        print(
            f"| {name} | {inb.sum()} | {(read & inb).sum()} | {covered:.3f} ({cov.sum()}) | "
            f"{(out_ & inb).sum()} | {low.sum()} | {(out_ & low & (v + u < 2500)).sum()} |"
        )
        for i in np.flatnonzero(out_ & inb):
            print(f"    {rows[i]['label']}: true {res[i]:.0f} Hz, read {v[i]:.0f} +- {u[i]:.0f}")
        if tag == "low":
            out.append({"metric": "in-band resonances read outside the band (false refusals)",
                        "value": float((out_ & inb).sum() / max(inb.sum(), 1)), "unit": "1",
                        "target": None, "better": "lower"})  # fmt: skip
            out.append({"metric": "0.8-2 kHz resonances read below the band (refused)",
                        "value": float((out_ & low & (v + u < 2500)).sum() / max(low.sum(), 1)),
                        "unit": "1", "target": None, "better": "higher"})  # fmt: skip
    return out


# -- refusals before / after -------------------------------------------------------------------


def _legacy(diag):
    """``diag`` with its card's chain ranges taken away: the learnt-range checks."""
    import copy
    import json

    from recipdyn.diagnosis.train import Diagnoser

    state = dict(diag.state)
    card = json.loads(state["datacard_json"])
    card["chain"] = {k: v for k, v in card["chain"].items() if k != "ranges"}
    state["datacard_json"] = json.dumps(card)
    return Diagnoser(copy.copy(state))


def _diagnose_one(job):
    from recipdyn import sensors
    from recipdyn.chain import Chain
    from recipdyn.diagnosis.diagnose import diagnose_arrays

    key, task, change = job
    diag, _ = _spec()
    ds = _simulate(task)
    d = dict(task["chain"])
    d.update(change)
    rec = sensors.record(ds, chain=Chain.from_dict(d), seed=task["noise_seed"])
    out = {"key": key, "label": task["label"], **change}
    for name, model in (("after", diag), ("before", _legacy(diag))):
        try:
            res = diagnose_arrays(rec["accel_guide"].values, task["fs"],
                                  tacho=rec["tacho"].values, p_head=rec["p_head_sensor"].values,
                                  p_crank=rec["p_crank_sensor"].values, model=model)  # fmt: skip
            out[name] = res.reason if res.refused else ""
            out[name + "_label"] = res.label
        except Exception as exc:  # noqa: BLE001 - a refusal with exit 2 is a refusal
            out[name] = f"{type(exc).__name__}: {exc}"
            out[name + "_label"] = ""
    return out


def _chain_refusal(reason: str) -> bool:
    r = reason or ""
    return any(w in r for w in ("noise floor", "sensor band", "trained under", "impacts ring"))


def refusals(args) -> list[dict]:
    diag, spec = _spec()
    from recipdyn.diagnosis.dataset import design

    test = [t for t in design(spec) if t["split"] == "test"]
    conds = sorted({t["condition"] for t in test})
    rng = np.random.default_rng(args.seed)
    jobs = []
    for c in conds:  # in domain: as drawn
        mine = [t for t in test if t["condition"] == c]
        for i in rng.choice(len(mine), min(args.per_condition, len(mine)), replace=False):
            jobs.append(("in domain", dict(mine[i], revolutions=args.revolutions), {}))
    healthy_like = [t for t in test if t["label"] == "healthy" or t["severity"] >= 0.5]
    for _ in range(args.outside):
        t = healthy_like[int(rng.integers(len(healthy_like)))]
        jobs.append(("SNR 3-8 dB", dict(t, revolutions=args.revolutions),
                     {"accelerometer.snr_db": float(rng.uniform(3, 8))}))  # fmt: skip
        t = healthy_like[int(rng.integers(len(healthy_like)))]
        jobs.append(
            (
                "resonance 0.8-2 kHz",
                dict(t, revolutions=args.revolutions),
                {
                    "accelerometer.resonance_hz": float(
                        np.exp(rng.uniform(np.log(800), np.log(2000)))
                    )
                },
            )
        )
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as ex:
        rows = list(ex.map(_diagnose_one, jobs))
    print(f"\n{len(rows)} records, {args.revolutions:g} revolutions, "
          f"{time.perf_counter() - t0:.0f} s\n")  # fmt: skip
    print("| records | n | refused by the chain checks, before | after | refused at all, before "
          "| after | right, before | after |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    out = []
    for key in ("in domain", "SNR 3-8 dB", "resonance 0.8-2 kHz"):
        g = [r for r in rows if r["key"] == key]
        if not g:
            continue
        cb = sum(_chain_refusal(r["before"]) for r in g)
        ca = sum(_chain_refusal(r["after"]) for r in g)
        ab = sum(bool(r["before"]) for r in g)
        aa = sum(bool(r["after"]) for r in g)
        rb = sum(r["before_label"] == r["label"] and not r["before"] for r in g)
        ra = sum(r["after_label"] == r["label"] and not r["after"] for r in g)
        print(f"| {key} | {len(g)} | {cb} | {ca} | {ab} | {aa} | {rb} | {ra} |")
        out.append({"metric": f"{key}: refused by the chain checks, after / before",
                    "value": ca / max(cb, 1), "unit": "x", "target": None,
                    "better": "lower" if key == "in domain" else "higher"})  # fmt: skip
    print("\nrecords outside the ranges the chain checks let through (after):")
    for r in rows:
        if r["key"] != "in domain" and not _chain_refusal(r["after"]):
            ch = {k: round(v, 1) for k, v in r.items() if k.startswith("accelerometer")}
            print(f"  {r['key']} {r['label']} {ch}: {r['after'][:160] or r['after_label']}")
    print("\nchain refusals, with their reasons (before | after):")
    for r in rows:
        if _chain_refusal(r["before"]) or _chain_refusal(r["after"]):
            ch = {k: v for k, v in r.items() if k.startswith("accelerometer")}
            print(f"  {r['key']} {r['label']} {ch}:\n    before: {r['before'][:160]}\n"
                  f"    after: {r['after'][:200]}")  # fmt: skip
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--part", default="calibrate", choices=("calibrate", "refusals"))
    ap.add_argument("--machines", type=int, default=36)
    ap.add_argument("--chains", type=int, default=8)
    ap.add_argument("--revolutions", type=float, default=4.0)
    ap.add_argument("--per-condition", type=int, default=10)
    ap.add_argument("--outside", type=int, default=10)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=None, help="calibrate: write the records' rows (JSON)")
    ap.add_argument("--quick", action="store_true", help="calibrate on 6 x 4 records")
    args = ap.parse_args(argv)
    if args.quick:
        args.machines, args.chains, args.per_condition, args.outside = 6, 4, 1, 2
    return {"summary": calibrate(args) if args.part == "calibrate" else refusals(args)}


#: ``make bench`` runs the quick calibration (the full one simulates 45 machines, ~2 min).
RUN_ALL_ARGV = ["--quick"]


if __name__ == "__main__":
    main()
