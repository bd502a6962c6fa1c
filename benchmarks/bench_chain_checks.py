"""The chain checks read from the record's own samples and from the chain corrections (issue
42, point 2; docs/diagnosis.md, "The chain ranges a diagnoser was trained under"): their
coverage on records through chains drawn from `recipdyn.chain.DEFAULT_RANGES`, and the
shipped diagnoser's chain refusals of those records (all of them are inside the ranges, so
every chain refusal is a false one).

``--conditions`` held-out conditions of the shipped diagnoser's data set (its test split:
every class in turn, the data set's own record length), each simulated once and sensed
through ``--chains`` chains drawn afresh (seeded); every record is diagnosed with the shipped
diagnoser, and each check's estimate (its 95 % interval) is compared with the drawn value:

* hum at the site's mains frequency (accelerometer and pressures), where the chain has hum;
* the tacho's jitter; the pressures' relative gain; the mount's damping where read;
* the converter step where read;
* clipping: the chain's clipped samples (``recipdyn.sensors``' count) against the check.

    python benchmarks/bench_chain_checks.py --conditions 8 --chains 8
"""

from __future__ import annotations

import argparse
import time
import warnings
from concurrent.futures import ProcessPoolExecutor

import numpy as np


def _one(job):
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    import bench_chain_ranges as b
    from recipdyn import sensors
    from recipdyn.chain import DEFAULT_RANGES, ChainRanges
    from recipdyn.diagnosis.diagnose import diagnose_arrays

    task, n_chains, seed = job
    diag, _ = b._spec()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = b._simulate(task)
    rng = np.random.default_rng([seed, task["index"]])
    rows = []
    for _ in range(n_chains):
        chain = ChainRanges(DEFAULT_RANGES).draw(rng, task["fs"])
        rec = sensors.record(ds, chain=chain, seed=int(rng.integers(2**31)))
        t0 = time.perf_counter()
        try:
            res = diagnose_arrays(rec["accel_guide"].values, task["fs"],
                                  tacho=rec["tacho"].values, p_head=rec["p_head_sensor"].values,
                                  p_crank=rec["p_crank_sensor"].values, model=diag)  # fmt: skip
            reason = res.reason if res.refused else ""
            checks = res.evidence.get("chain_ranges", {})
        except Exception as exc:  # noqa: BLE001 - a refusal with exit 2 is a refusal
            reason, checks = f"{type(exc).__name__}: {exc}", {}
        a, p, t = chain.accelerometer, chain.pressure, chain.tacho
        clipped = {
            "accelerometer": int(rec["accel_guide"].attrs["sensor_clipped_samples"]),
            "p_head": int(rec["p_head_sensor"].attrs["sensor_clipped_samples"]),
            "p_crank": int(rec["p_crank_sensor"].attrs["sensor_clipped_samples"]),
        }
        truth = {
            "hum_accelerometer_site": a.hum_db,
            "hum_p_head_site": p.hum_db,
            "hum_p_crank_site": p.hum_db,
            "tacho_jitter": t.jitter_deg,
            "gain_ratio": p.gain[0] / p.gain[1] - 1.0,
            "damping": a.damping,
            "step_accelerometer": 2 * a.full_scale / 2**a.bits,
            "step_p_head": float(rec["p_head_sensor"].attrs["sensor_full_scale"]) / 2**p.bits,
            "step_p_crank": float(rec["p_crank_sensor"].attrs["sensor_full_scale"]) / 2**p.bits,
        }
        rows.append({"label": task["label"], "reason": reason, "checks": checks,
                     "truth": truth, "clipped": clipped, "mains": a.mains_hz,
                     "seconds": time.perf_counter() - t0})  # fmt: skip
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--conditions", type=int, default=8)
    ap.add_argument("--chains", type=int, default=8)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--revolutions", type=float, default=4.0)
    ap.add_argument(
        "--quick",
        action="store_true",
        help="2 conditions x 2 chains: checks that it runs, measures little",
    )
    args = ap.parse_args(argv)
    if args.quick:
        args.conditions, args.chains = min(args.conditions, 2), min(args.chains, 2)
    import bench_chain_ranges as b
    from recipdyn.diagnosis.dataset import design

    _, spec = b._spec()
    test = [t for t in design(spec) if t["split"] == "test"]
    rng = np.random.default_rng(args.seed)
    pick = rng.choice(len(test), min(args.conditions, len(test)), replace=False)
    jobs = [(dict(test[i], revolutions=args.revolutions), args.chains, args.seed) for i in pick]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as ex:
        rows = [r for part in ex.map(_one, jobs) for r in part]
    med = np.median([r["seconds"] for r in rows])
    print(
        f"{len(rows)} records ({len(jobs)} conditions x {args.chains} chains), "
        f"{time.perf_counter() - t0:.0f} s; diagnose {med:.1f} s per record (median)\n"
    )
    # coverage: the drawn value inside the estimate's interval
    print("| check | drawn value inside the 95 % interval | not estimated | outside (refused) |")
    print("|---|---|---|---|")
    names = sorted({k for r in rows for k in r["truth"]} | {"phase"})
    for name in names:
        hit = n = ne = out = 0
        for r in rows:
            key = name.replace("site", f"{r['mains']:g}")
            c = r["checks"].get(key)
            if c is None:
                continue
            out += c["status"] == "outside"
            if c["status"] == "not estimated":
                ne += 1
                continue
            v = r["truth"].get(name)
            if v is None:  # (no hum drawn: the level's interval is not compared)
                continue
            n += 1
            hit += c["lo"] <= v <= c["hi"]
        label = name
        cov = f"{hit}/{n} ({hit / n:.0%})" if n else "-"
        print(f"| {label} | {cov} | {ne} | {out} |")
    clip_true = {ch: sum(r["clipped"][ch] > 0 for r in rows) for ch in rows[0]["clipped"]}
    refused_clip = [r for r in rows if "clipped" in r["reason"]]
    print(f"\nchains that clipped (sensors' count > 0): {clip_true}; refused as clipped: "
          f"{len(refused_clip)}")  # fmt: skip
    for r in refused_clip:
        print(f"  {r['label']} clipped samples {r['clipped']}: {r['reason'][:160]}")
    chain = [r for r in rows if "trained under" in r["reason"] or "clipped" in r["reason"]]
    print(f"\nchain refusals of in-range records: {len(chain)} of {len(rows)}")
    for r in chain:
        print(f"  {r['label']}: {r['reason'][:300]}")
    other = [r for r in rows if r["reason"] and r not in chain]
    print(f"other refusals: {len(other)}")
    for r in other:
        print(f"  {r['label']}: {r['reason'][:160]}")


if __name__ == "__main__":
    main()
