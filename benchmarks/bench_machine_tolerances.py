"""How far each machine parameter may move before the shipped diagnoser's machine is another
one: the measured basis of `recipdyn.diagnosis.machine.TOLERANCES` (docs/diagnosis.md, "A
diagnoser belongs to one machine").

For every numerical parameter of `MACHINE_PARAMETERS`, the healthy records of
``--conditions`` held-out conditions of the shipped diagnoser's data set are simulated again
with that parameter times 1 -+ 0.1 and 1 -+ 0.3, keeping the condition and the sensor noise
seed (paired records: the difference is the parameter's), and their features computed as the
diagnoser computes them (with its own machine's geometry). Each feature's change is measured
in units of the healthy machine's own scatter at a fixed operating point
(`healthy_spreads`).

Many features do not move smoothly with a parameter: the pressure events' angles are whole
degrees, the ringing frequency is a spectral peak picked among others, the impacts' energy
per 10-degree bin jumps when a knock crosses a bin's edge. A small change of any parameter
(or of the noise) makes some such feature jump by several spreads in either direction, so
the largest single change is no measure of a parameter's effect (it is 3-6 spreads for
parameters that change nothing systematic, and between two noise seeds). The sensitivity of
a feature to a parameter is therefore the slope of its change against the relative change
(least squares through the origin over the conditions and the four changes), taken at its
lower 2-standard-error bound (`slope_lower`: a jump that comes with either sign leaves no
slope), and a parameter's sensitivity is the largest over the features. The tolerance is the
change at which that slope moves a feature by `SHIFT_LIMIT` (one spread), capped at
`TOLERANCE_CAP` (the largest change measured). The table it prints is pasted into
machine.py:

    python benchmarks/bench_machine_tolerances.py --conditions 3 --workers 2 --out out/tol.json
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

DELTAS = (0.1, 0.3)


def features_job(job):
    """(key, features or error) of one task (picklable unit of work)."""
    from recipdyn.diagnosis.dataset import make_record

    key, task = job
    res = make_record(task)
    return key, res["error"] or res["features"]


def _valid(name, value) -> bool:
    from recipdyn.diagnosis.machine import Machine
    from recipdyn.errors import ParameterError

    try:
        Machine.of({name: value})
    except (ParameterError, ValueError):
        return False
    return True


def slope_lower(x, y) -> tuple[float, float]:
    """``(slope, lower)``: the least-squares slope of ``y`` on ``x`` through the origin and its
    magnitude's lower 2-standard-error bound (0 if the slope is not told from 0)."""
    import numpy as np

    x, y = np.asarray(x, float), np.asarray(y, float)
    sxx = float(np.sum(x * x))
    b = float(np.sum(x * y) / sxx)
    dof = max(x.size - 1, 1)
    se = math.sqrt(float(np.sum((y - b * x) ** 2)) / dof / sxx)
    return b, max(abs(b) - 2 * se, 0.0)


def main(argv: list[str] | None = None) -> None:
    from recipdyn.diagnosis import default_model_path, load
    from recipdyn.diagnosis.dataset import DatasetSpec, design
    from recipdyn.diagnosis.machine import (
        CATEGORICAL,
        MACHINE_PARAMETERS,
        SHIFT_LIMIT,
        TOLERANCE_CAP,
        Machine,
        feature_shift,
        healthy_spreads,
    )
    from recipdyn.errors import deferred_signals
    from recipdyn.parallel import run_unordered

    ap = argparse.ArgumentParser()
    ap.add_argument("--conditions", type=int, default=3, help="held-out conditions used")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--params", default=None, help="comma list (default: all numerical)")
    ap.add_argument("--out", default="out/machine_tolerances.json")
    ap.add_argument("--cache", default=None, help="JSON of the records' features (reused)")
    ap.add_argument("--quick", action="store_true", help="1 condition, 3 parameters")
    args = ap.parse_args(argv)
    if args.quick:
        args.conditions, args.params = 1, args.params or "r,clearance_fraction,m3"

    diag = load(default_model_path())
    spreads = healthy_spreads(diag)
    spec = DatasetSpec.from_dict(diag.card["spec"])
    tasks = [t for t in design(spec) if t["split"] == "test" and t["label"] == "healthy"]
    conds = sorted({t["condition"] for t in tasks})[: args.conditions]
    base = [next(t for t in tasks if t["condition"] == c) for c in conds]
    names = (
        args.params.split(",")
        if args.params
        else [p for p in MACHINE_PARAMETERS if p not in CATEGORICAL]
    )
    default = Machine.default()
    jobs = []
    for i, t in enumerate(base):
        jobs.append(((i, "nominal", 0.0), t))
        jobs.append(((i, "null", 0.0), dict(t, noise_seed=t["noise_seed"] + 7919)))
        for p in names:
            v0 = t["params"].get(p, default[p])
            for d in DELTAS:
                for sign in (-1, 1):
                    v = v0 * (1 + sign * d)
                    if _valid(p, v):
                        jobs.append(((i, p, sign * d), dict(t, params={**t["params"], p: v})))
    cache = Path(args.cache) if args.cache else None
    got = {}
    if cache is not None and cache.exists():
        got = {tuple(json.loads(k)): v for k, v in json.loads(cache.read_text()).items()}
    todo = [j for j in jobs if j[0] not in got]
    print(f"{len(jobs)} records ({len(base)} conditions x {len(names)} parameters), "
          f"{len(todo)} to simulate", flush=True)  # fmt: skip
    t0 = time.perf_counter()
    with deferred_signals() as pending:
        run_unordered(features_job, todo, args.workers, lambda r: got.__setitem__(*r), pending)
    wall = time.perf_counter() - t0
    if cache is not None:
        cache.parent.mkdir(parents=True, exist_ok=True)
        cache.write_text(json.dumps({json.dumps(list(k)): v for k, v in got.items()}))
    null = [feature_shift(got[(i, "nominal", 0.0)], got[(i, "null", 0.0)], spreads)
            for i in range(len(base))]  # fmt: skip
    rows = {}
    for p in names:
        x, ys, largest = [], {n: [] for n in spreads}, 0.0
        for i in range(len(base)):
            nom = got[(i, "nominal", 0.0)]
            for d in DELTAS:
                for sign in (-1, 1):
                    f = got.get((i, p, sign * d))
                    if f is None or isinstance(f, str):
                        continue
                    x.append(sign * d)
                    largest = max(largest, feature_shift(nom, f, spreads)[0])
                    for n, s in spreads.items():
                        ys[n].append((f[n] - nom[n]) / s)
        best, which, slope = 0.0, "", 0.0
        for n, y in ys.items():
            y = [0.0 if math.isnan(v) else v for v in y]
            b, low = slope_lower(x, y)
            if low > best:
                best, which, slope = low, n, b
        tol = min(SHIFT_LIMIT / best, TOLERANCE_CAP) if best > 0 else TOLERANCE_CAP
        rows[p] = {"sensitivity": best, "slope": slope, "feature": which, "tolerance": tol,
                   "largest_single_shift": largest, "points": len(x)}  # fmt: skip
    print(f"{len(todo)} records simulated in {wall:.0f} s ({args.workers} workers)")
    print("largest single-feature shift between two noise seeds (same machine): "
          + ", ".join(f"{s:.2f} ({n})" for s, n in null))  # fmt: skip
    print("| parameter | sensitivity (spreads per unit change) | feature | largest single "
          "shift | tolerance |")  # fmt: skip
    print("|---|---|---|---|---|")
    for p, r in rows.items():
        print(f"| {p} | {r['sensitivity']:.3g} | {r['feature'] or '-'} | "
              f"{r['largest_single_shift']:.1f} | {100 * r['tolerance']:.2g} % |")  # fmt: skip
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(
        json.dumps({"rows": rows, "null": null, "wall_s": wall, "conditions": conds}, indent=1)
    )


if __name__ == "__main__":
    main()
