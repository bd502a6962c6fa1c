"""The machine's own healthy baseline (``recipdyn baseline``): does the fit recover what it
does not know, and do later diagnoses improve? (docs/diagnosis.md, issue 42 item 6).

Each case is a machine the shipped diagnoser was not built for exactly, at one of its
held-out operating conditions:

* ``perturbed``: its clearance volume x U(0.8, 1.2), its valve springs x U(0.8, 1.2) and
  plate lifts x U(0.9, 1.1) (the baseline's `UNCERTAIN` ranges: the clearance volume is
  fitted, the springs and lifts are not, their spread taken into the fit's error), its masses
  those the condition drew; a chain with pressure offsets U(-8, 8) kPa on each transducer and
  the tacho mark U(-2, 2) degrees after outer dead centre;
* ``nominal``: the diagnoser's own machine and chain (does a baseline cost anything?).

For each case, ``--records`` healthy records (``--revolutions`` each, the speed and the line
pressures moved by up to 3 %) make the baseline; the fit's 90 % intervals are checked against
the truth (coverage over the cases); then ``--faults`` records of every fault class (severity
U(0.25, 1)) and as many healthy ones, through the same machine and chain, are diagnosed with
and without the baseline: the healthy recall (healthy records called healthy, refusals not),
the faults' recall (their own class) and detection (not called healthy, not refused).

    python benchmarks/bench_diagnosis_baseline.py --cases 6 --nominal 3 --workers 2 \\
        --out out/baseline_bench.json
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import pickle
import time
from pathlib import Path

import numpy as np


def record_job(job):
    """(key, Record) of one simulated record (picklable unit of work)."""
    from recipdyn.diagnosis.baseline import simulated_record

    key, params, kw = job
    return key, simulated_record(params, **kw)


def _case(rng, kind: str, cond_task: dict, machine_defaults: dict) -> dict:
    p = {**machine_defaults, **cond_task["params"]}
    truth = {"clearance_fraction": 1.0, "valve_spring": 1.0, "valve_lift": 1.0}
    chain = {"p_head_offset": 0.0, "p_crank_offset": 0.0, "phase_deg": 0.0}
    if kind == "perturbed":
        truth = {
            "clearance_fraction": float(rng.uniform(0.8, 1.2)),
            "valve_spring": float(rng.uniform(0.8, 1.2)),
            "valve_lift": float(rng.uniform(0.9, 1.1)),
        }
        chain = {
            "p_head_offset": float(rng.uniform(-8e3, 8e3)),
            "p_crank_offset": float(rng.uniform(-8e3, 8e3)),
            "phase_deg": float(rng.uniform(-2.0, 2.0)),
        }
    p["clearance_fraction"] *= truth["clearance_fraction"]
    p["valve_stiffness"] *= truth["valve_spring"]
    p["valve_preload"] *= truth["valve_spring"]
    p["valve_lift"] *= truth["valve_lift"]
    return {"params": p, "truth": truth, "chain": chain}


def main(argv: list[str] | None = None) -> None:
    from recipdyn.diagnosis import default_model_path, load
    from recipdyn.diagnosis.baseline import build_baseline, load_baseline
    from recipdyn.diagnosis.classes import CLASSES
    from recipdyn.diagnosis.dataset import DatasetSpec, design
    from recipdyn.diagnosis.diagnose import diagnose_arrays
    from recipdyn.diagnosis.machine import Machine
    from recipdyn.errors import ParameterError
    from recipdyn.parallel import process_pool, stop_pool

    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", type=int, default=6, help="perturbed machines")
    ap.add_argument("--nominal", type=int, default=3, help="cases of the nominal machine")
    ap.add_argument("--records", type=int, default=3, help="healthy records of a baseline")
    ap.add_argument("--revolutions", type=float, default=6.0)
    ap.add_argument("--faults", type=int, default=2, help="records of each fault class a case")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="out/baseline_bench.json")
    ap.add_argument(
        "--cache",
        default=None,
        help="folder keeping each case's records and baseline (re-diagnosed, not "
        "rebuilt, when the run is repeated with another --out)",
    )
    ap.add_argument(
        "--task-offset",
        type=int,
        default=0,
        help="case c takes the (c + this)-th held-out healthy record's condition "
        "and chain (evaluate on conditions not developed on)",
    )
    ap.add_argument(
        "--variants",
        default="without,with,with records referral,with sim referral",
        help="which diagnoses to run (comma-separated)",
    )
    ap.add_argument(
        "--rerefer", action="store_true", help="a cached baseline's fit kept, its referral rebuilt"
    )
    ap.add_argument("--quick", action="store_true", help="1 perturbed and 1 nominal case")
    args = ap.parse_args(argv)
    if args.quick:
        args.cases, args.nominal, args.faults = 1, 1, 1

    diag = load(default_model_path())
    # held-out healthy conditions whose drawn mounting resonance `recipdyn.sensors` can sense
    # (below 0.45 fs: its accelerometer refuses one above the Nyquist frequency, which the
    # drawn chains of a data set allow, their flank in band)
    tasks = [t for t in design(DatasetSpec.from_dict(diag.card["spec"]))
             if t["split"] == "test" and t["label"] == "healthy" and t["level"] == 0
             and t["resonance_hz"] < 0.45 * t["fs"]]  # fmt: skip
    defaults = Machine.default().as_dict
    out = Path(args.out)
    done = json.loads(out.read_text()) if out.exists() else {"cases": []}
    kinds = ["perturbed"] * args.cases + ["nominal"] * args.nominal
    pool = process_pool(args.workers)
    try:
        for c, kind in enumerate(kinds):
            if c < len(done["cases"]):
                continue
            rng = np.random.default_rng([args.seed, c])
            cond = tasks[(c + args.task_offset) % len(tasks)]
            case = _case(rng, kind, cond, defaults)
            t0 = time.perf_counter()
            base_kw = {"fs": cond["fs"], "revolutions": args.revolutions,
                       "resonance_hz": cond["resonance_hz"], "snr_db": cond["snr_db"],
                       "chain": case["chain"]}  # fmt: skip
            jobs = []
            for i in range(args.records):
                p = dict(case["params"])
                p["omega"] *= rng.uniform(0.97, 1.03)
                p["suction_pressure"] *= rng.uniform(0.98, 1.02)
                p["discharge_pressure"] *= rng.uniform(0.97, 1.03)
                jobs.append((("baseline", i), p, {**base_kw, "seed": 1000 * c + i,
                                                 "name": f"h{i}"}))  # fmt: skip
            test = []
            for fc in CLASSES:
                n = args.faults if fc.parameter else args.faults * 2
                for k in range(n):
                    s = float(rng.uniform(0.25, 1.0)) if fc.parameter else 0.0
                    p = {**case["params"], **fc.overrides(s)}
                    test.append((fc.name, s))
                    kw = {**base_kw, "revolutions": 4.0, "seed": 1000 * c + 100 + len(test)}
                    jobs.append(((fc.name, k), p, kw))
            tag = f"seed{args.seed}-off{args.task_offset}-{kind}-case{c}"
            stem = None if args.cache is None else Path(args.cache) / tag
            if stem is not None and stem.with_suffix(".pkl").exists():
                recs = pickle.loads(stem.with_suffix(".pkl").read_bytes())
            else:
                recs = dict(pool.map(record_job, jobs))
                if stem is not None:
                    stem.parent.mkdir(parents=True, exist_ok=True)
                    stem.with_suffix(".pkl").write_bytes(pickle.dumps(recs))
            t_sim = time.perf_counter() - t0
            healthy = [recs[("baseline", i)] for i in range(args.records)]
            t0 = time.perf_counter()
            if stem is not None and stem.with_suffix(".json").exists():
                b = load_baseline(stem.with_suffix(".json"))
                if args.rerefer:  # the fit kept, the referral of today's code
                    b = build_baseline(healthy, diag, workers=args.workers, fit=b.fit)
                    b.save(stem.with_suffix(".json"))
            else:
                b = build_baseline(healthy, diag, workers=args.workers)
                if stem is not None:
                    b.save(stem.with_suffix(".json"))
            t_fit = time.perf_counter() - t0
            f = b.fit
            cover = {}
            for n, v in case["truth"].items():
                if n not in f.names:  # not fitted: its interval is its range (f.unseen)
                    continue
                lo, hi = f.interval(n)
                cover[n] = {"truth": v, "value": f.value[f.names.index(n)], "lo": lo, "hi": hi,
                            "in": bool(lo <= v <= hi)}  # fmt: skip
            for n, v in case["chain"].items():
                lo, hi = f.interval(n)
                cover[n] = {"truth": v, "value": f.value[f.names.index(n)], "lo": lo, "hi": hi,
                            "in": bool(lo <= v <= hi)}  # fmt: skip
            z = 1.6448536269514722
            r0, rs = f.resonance_hz
            hz = cond["resonance_hz"]
            cover["resonance_hz"] = {
                "truth": hz,
                "value": r0,
                "lo": r0 - z * rs,
                "hi": r0 + z * rs,
                "in": bool(abs(r0 - hz) <= z * rs),
            }
            answers = []
            counts = {}
            for name, s in test:
                k = counts[name] = counts.get(name, -1) + 1
                r = recs[(name, k)]
                kw = {"tacho": r.tacho, "p_head": r.p_head, "p_crank": r.p_crank, "model": diag}
                row = {"truth": name, "severity": s}
                rec_b = dataclasses.replace(b, delta=b.delta_records, referral="records")
                sim_b = dataclasses.replace(b, delta=b.delta_sim, referral="sim")
                for tag, extra in (("without", {}), ("with", {"baseline": b}),
                                   ("with records referral", {"baseline": rec_b}),
                                   ("with sim referral", {"baseline": sim_b})):  # fmt: skip
                    if tag not in args.variants.split(","):
                        continue
                    try:
                        a = diagnose_arrays(r.accel, r.fs, **kw, **extra)
                        row[tag] = "refused" if a.refused else a.label
                        row[f"{tag}: why"] = _why(a)
                    except ParameterError as exc:  # the command's one-line refusal (exit 2)
                        row[tag] = "refused"
                        row[f"{tag}: why"] = {"gate": "input", "reason": str(exc)}
                answers.append(row)
            done["cases"].append({
                "kind": kind, "condition": cond["condition"], "truth": case["truth"],
                "chain": case["chain"], "coverage": cover, "answers": answers,
                "fit": {"residual_rms_pa": f.residual_rms_pa, "dof": f.dof,
                        "simulations": f.simulations, "seconds": f.seconds,
                        "check": b.check},
                "seconds": {"records": t_sim, "baseline": t_fit},
            })  # fmt: skip
            out.parent.mkdir(parents=True, exist_ok=True)
            out.write_text(json.dumps(done, indent=1))
            inside = sum(v["in"] for v in cover.values())
            print(f"case {c} ({kind}, condition {cond['condition']}): {inside}/{len(cover)} "
                  f"inside their intervals; baseline {t_fit:.0f} s ({f.simulations} "
                  f"simulations)", flush=True)  # fmt: skip
    finally:
        stop_pool(pool)
    report(done)


#: The gate a refusal came from, by the words of its reason (`diagnose_arrays`).
GATES = (
    ("no simulated", "consistency"),
    ("another machine", "fingerprint"),
    ("r/l", "fingerprint"),
    ("noise floor", "noise floor"),
    ("novelty p-value", "ood"),
    ("no simulated", "consistency"),
    ("channels", "channel gate"),
    ("held-out", "channel gate"),
    ("offset", "chain range"),
    ("resonance", "chain range"),
    ("tacho", "chain range"),
    ("clipp", "clipping"),
)


def _why(a) -> dict:
    """Which gate answered the record and the numbers behind it: the refusal's gate (by its
    reason's words) or ``classifier``, the top probabilities, the novelty p-value and the
    consistency check's p-value and worst residual, the features farthest from the healthy
    training records."""
    gate = "classifier"
    if a.refused:
        gate = next((g for w, g in GATES if w in a.reason), "other")
    top = sorted(a.probabilities.items(), key=lambda kv: -kv[1])[:3]
    c = a.evidence.get("consistency") or {}
    w = c.get("worst") or {}
    return {"gate": gate, "reason": a.reason[:300], "top": [[k, round(v, 3)] for k, v in top],
            "ood_p": a.ood.get("p_value"), "cons_p": c.get("p_value"),
            "cons_worst": [w.get("curve"), w.get("angle_deg"), w.get("z")] if w else None,
            "deciding": a.evidence.get("deciding")}  # fmt: skip


def report(done: dict) -> None:
    for kind in ("perturbed", "nominal"):
        cases = [c for c in done["cases"] if c["kind"] == kind]
        if not cases:
            continue
        print(f"\n## {kind} machines: {len(cases)} case(s)")
        names = list(cases[0]["coverage"])
        print("| parameter | inside the 90 % interval | median |error| / half-width |")
        print("|---|---|---|")
        for n in names:
            rows = [c["coverage"][n] for c in cases]
            ins = sum(r["in"] for r in rows)
            ratio = [abs(r["value"] - r["truth"]) / max((r["hi"] - r["lo"]) / 2, 1e-300)
                     for r in rows]  # fmt: skip
            print(f"| {n} | {ins}/{len(rows)} | {np.median(ratio):.2f} |")
        for tag in ("without", "with", "with records referral", "with sim referral"):
            ans = [a for c in cases for a in c["answers"] if tag in a]
            if not ans:
                continue
            h = [a for a in ans if a["truth"] == "healthy"]
            f = [a for a in ans if a["truth"] != "healthy"]
            hr = sum(a[tag] == "healthy" for a in h) / len(h)
            fr = sum(a[tag] == a["truth"] for a in f) / len(f)
            det = sum(a[tag] not in ("healthy", "refused") for a in f) / len(f)
            ref = sum(a[tag] == "refused" for a in ans) / len(ans)
            print(f"{tag} baseline: healthy recall {hr:.3f} ({len(h)}), fault recall {fr:.3f}, "
                  f"faults detected {det:.3f} ({len(f)}), refused {ref:.3f}")  # fmt: skip
        secs = [c["seconds"]["baseline"] for c in cases]
        sims = [c["fit"]["simulations"] for c in cases]
        print(f"baseline: {np.median(secs):.0f} s median ({min(secs):.0f}-{max(secs):.0f}), "
              f"{np.median(sims):.0f} simulations")  # fmt: skip


if __name__ == "__main__":
    main()
