"""The measurement chain drawn per record (issue 42, item 1): what the draws look like, what a
drawn chain costs a record, and how the shipped diagnoser does on records sensed through
drawn chains -- the 'before' of a diagnoser trained on them.

* ``draws``: ``--draws`` chains from `recipdyn.chain.DEFAULT_RANGES` at 11 kHz: each
  parameter's 5th, 50th and 95th percentiles, extremes and the share drawn absent.
* ``cost``: one simulated record (the healthy machine, 2 revolutions) sensed through the
  earlier fixed chain and through ``--draws-cost`` drawn chains, side by side; the ratio of
  their times, and the sensing's share of the record's simulation time.
* ``shipped``: the shipped diagnoser on records of its held-out conditions (the healthy machine
  and every fault at severity >= 0.5, ``--revolutions`` revolutions, so that the tacho gives
  the three pulses diagnose needs), each simulated once and sensed through the fixed chain
  it was trained with and through ``--chains`` drawn chains: right, refused, wrong at
  p >= 0.5 and wrong at p < 0.5. The exact outputs are cached in ``--cache`` (one ``.npz``
  a record), so the sensing and the diagnosis can be repeated without simulating.

    python benchmarks/bench_chain.py --parts draws,cost,shipped --cache out/bench-chain
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np


def _draws(n: int) -> list[dict]:
    from recipdyn.chain import DEFAULT_RANGES, ChainRanges, Choice, _coordinates

    fs = 11_000.0
    rng = np.random.default_rng(20240)
    r = ChainRanges()
    coords = [_coordinates(r.draw(rng, fs), fs) for _ in range(n)]
    rows = []
    print(f"\n{n} drawn chains at fs = {fs:g} Hz\n")
    print("| parameter | p5 | median | p95 | min | max | absent |")
    print("|---|---|---|---|---|---|---|")
    for k, span in DEFAULT_RANGES.items():
        vals = []
        for c in coords:
            v = c[k]
            vals.extend(v if isinstance(v, tuple) else (v,))
        absent = sum(v is None for v in vals) / len(vals)
        vals = [v for v in vals if v is not None]
        if isinstance(span, Choice):
            counts = {str(x): sum(v == x for v in vals) / len(vals) for x in span.values}
            print(f"| {k} | " + ", ".join(f"{a}: {b:.2f}" for a, b in counts.items())
                  + " | | | | | |")  # fmt: skip
            continue
        q = np.percentile(vals, [5, 50, 95])
        print(f"| {k} | {q[0]:.4g} | {q[1]:.4g} | {q[2]:.4g} | {min(vals):.4g} | "
              f"{max(vals):.4g} | {absent:.2f} |")  # fmt: skip
        rows.append({"parameter": k, "p50": float(q[1])})
    return rows


def _simulate(task):
    import warnings

    from recipdyn.diagnosis.classes import MODEL
    from recipdyn.simulate import simulate

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = simulate(model=MODEL, revolutions=task["revolutions"], transient=task["transient"],
                      fs=task["fs"], **task["params"])  # fmt: skip
    return ds[["a", "theta1", "p_head", "p_crank"]]


def _cost(n: int) -> list[dict]:
    from recipdyn import sensors
    from recipdyn.chain import ChainRanges, legacy_chain
    from recipdyn.diagnosis.dataset import DatasetSpec, design

    task = next(t for t in design(DatasetSpec(n_conditions=2, levels=(1.0,), chain="fixed"))
                if t["label"] == "healthy")  # fmt: skip
    _simulate(task)  # loads the kernels
    t0 = time.perf_counter()
    ds = _simulate(task)
    sim = time.perf_counter() - t0
    fixed = legacy_chain(task["resonance_hz"], task["snr_db"])
    rng = np.random.default_rng(1)
    drawn = [ChainRanges().draw(rng, task["fs"]) for _ in range(n)]
    tf, td = [], []
    for i, ch in enumerate(drawn):  # interleaved: the same load on both
        t0 = time.perf_counter()
        sensors.record(ds, chain=fixed, seed=i)
        tf.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        sensors.record(ds, chain=ch, seed=i)
        td.append(time.perf_counter() - t0)
    t0 = time.perf_counter()
    ChainRanges().draw(rng, task["fs"])
    tdraw = time.perf_counter() - t0
    f, d = float(np.median(tf)), float(np.median(td))
    print(f"\nsensing one record ({ds.sizes['time']} samples, 4 channels): fixed chain "
          f"{f * 1e3:.1f} ms, drawn chain {d * 1e3:.1f} ms (median of {n}), ratio {d / f:.2f}; "
          f"a draw {tdraw * 1e3:.2f} ms; the record's simulation {sim:.2f} s: sensing is "
          f"{d / sim:.1%} of it\n")  # fmt: skip
    return [
        {"metric": "chain: drawn / fixed sensing time", "value": d / f, "unit": "x",
         "target": None, "better": "lower"},
        {"metric": "chain: drawn sensing / simulation", "value": d / sim, "unit": "1",
         "target": None, "better": "lower"},
    ]  # fmt: skip


def _shipped(args) -> list[dict]:
    from recipdyn import sensors
    from recipdyn.chain import Chain, legacy_chain
    from recipdyn.diagnosis.dataset import DatasetSpec, chain_draw, design
    from recipdyn.diagnosis.diagnose import default_model_path, diagnose_arrays
    from recipdyn.diagnosis.train import load

    diag = load(args.model or default_model_path())
    spec = DatasetSpec.from_dict(diag.card["spec"])  # fixed: as it was built
    test = [t for t in design(spec) if t["split"] == "test"]
    conds = sorted({t["condition"] for t in test})[: args.conditions]
    tasks = [t for t in test if t["condition"] in conds and t["level"] < args.per_class
             and (t["label"] == "healthy" or t["severity"] >= 0.5)]  # fmt: skip
    drawn_spec = DatasetSpec.from_dict({**diag.card["spec"], "chain": "drawn"})
    cache = Path(args.cache)
    cache.mkdir(parents=True, exist_ok=True)
    tally: dict[str, dict[str, int]] = {}
    wrong_rows = []
    reasons: dict[str, dict[str, int]] = {}
    t_start = time.perf_counter()
    for t in tasks:
        t = dict(t, revolutions=args.revolutions)
        path = cache / f"rec-{t['index']}-{args.revolutions:g}.nc"
        if not path.exists():
            _simulate(t).to_netcdf(path)
        import xarray as xr

        ds = xr.load_dataset(path)
        chains = [("fixed", legacy_chain(t["resonance_hz"], t["snr_db"]))]
        for k in range(args.chains):
            c = chain_draw(drawn_spec, t["condition"], t["label"], 100 + k, t["fs"])
            chains.append(("drawn", c))
        for i, (kind, ch) in enumerate(chains):  # the fixed chain: the training record's noise
            rec = sensors.record(ds, chain=ch, seed=t["noise_seed"] + i)
            try:
                res = diagnose_arrays(rec["accel_guide"].values, t["fs"],
                                      tacho=rec["tacho"].values,
                                      p_head=rec["p_head_sensor"].values,
                                      p_crank=rec["p_crank_sensor"].values, model=diag)  # fmt: skip
                refused, label, p = res.refused, res.label, max(res.probabilities.values() or [0])
            except Exception as exc:  # noqa: BLE001 - a refusal with exit 2 is a refusal
                refused, label, p = True, None, 0.0
                res = type("R", (), {"reason": f"{type(exc).__name__}: {exc}"})()
            c = tally.setdefault(kind, {"n": 0, "right": 0, "refused": 0, "wrong_hi": 0,
                                        "wrong_lo": 0})  # fmt: skip
            c["n"] += 1
            if refused:
                c["refused"] += 1
                why = str(res.reason).split(";")[0].split("(")[0][:70]
                reasons.setdefault(kind, {}).setdefault(why, 0)
                reasons[kind][why] += 1
            elif label == t["label"]:
                c["right"] += 1
            elif p >= 0.5:
                c["wrong_hi"] += 1
                if kind == "drawn":
                    wrong_rows.append((t["label"], label, p, Chain.to_dict(ch)))
            else:
                c["wrong_lo"] += 1
    print(f"\nthe shipped diagnoser on {len(tasks)} records of {len(conds)} held-out conditions "
          f"(healthy and severity >= 0.5), {args.revolutions:g} revolutions, each sensed "
          f"through the fixed chain and {args.chains} drawn chains "
          f"({time.perf_counter() - t_start:.0f} s)\n")  # fmt: skip
    print("| chain | records | right | refused | wrong, p >= 0.5 | wrong, p < 0.5 |")
    print("|---|---|---|---|---|---|")
    out = []
    for kind, c in tally.items():
        n = c["n"]
        print(f"| {kind} | {n} | {c['right'] / n:.2f} | {c['refused'] / n:.2f} | "
              f"{c['wrong_hi'] / n:.2f} | {c['wrong_lo'] / n:.2f} |")  # fmt: skip
        out.append({"metric": f"shipped diagnoser, {kind} chain: wrong at p >= 0.5",
                    "value": c["wrong_hi"] / n, "unit": "1", "target": 0.01,
                    "better": "lower"})  # fmt: skip
    for kind, rs in reasons.items():
        print(f"\nrefusals, {kind} chain:")
        for why, k in sorted(rs.items(), key=lambda x: -x[1]):
            print(f"  {k} x {why}")
    if wrong_rows:
        print("\nconfidently wrong through drawn chains (truth -> answer, p; chain extremes):")
        for truth, label, p, ch in wrong_rows[:40]:
            print(
                f"  {truth} -> {label} p {p:.2f}; tacho angle "
                f"{math.degrees(ch['tacho.angle']):+.2f} deg, jitter {ch['tacho.jitter_deg']:.2f}"
                f", p offsets {[round(v) for v in ch['pressure.offset']]} Pa, delays "
                f"{ch['accelerometer.delay_s'] * 1e3:.2f}/"
                f"{[round(v * 1e3, 2) for v in ch['pressure.delay_s']]} ms, "
                f"{ch['accelerometer.lowpass_phase']}/{ch['pressure.lowpass_phase']}"
            )
    return out


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--parts", default="draws,cost,shipped")
    ap.add_argument("--draws", type=int, default=2000)
    ap.add_argument("--draws-cost", type=int, default=20)
    ap.add_argument("--conditions", type=int, default=2)
    ap.add_argument("--chains", type=int, default=3)
    ap.add_argument("--per-class", type=int, default=1, help="records a class a condition")
    ap.add_argument("--revolutions", type=float, default=4.0)
    ap.add_argument("--model", default=None)
    ap.add_argument("--cache", default="bench-results/chain")
    ap.add_argument("--quick", action="store_true", help="draws and cost only")
    args = ap.parse_args(argv)
    parts = ["draws", "cost"] if args.quick else args.parts.split(",")
    summary = []
    if "draws" in parts:
        _draws(args.draws)
    if "cost" in parts:
        summary += _cost(args.draws_cost)
    if "shipped" in parts:
        summary += _shipped(args)
    return {"summary": summary}


if __name__ == "__main__":
    main()
