"""Accuracy of the shipped diagnoser when the record departs from what it was trained on:
the accelerometer's SNR, its mounting resonance, the machine's masses (docs/diagnosis.md,
robustness).

Records of the held-out conditions of the diagnoser's data set (``--conditions`` of them,
the healthy machine and every fault at the severity levels >= 0.5: the issue's targets) are
simulated again, each variant changing one thing and keeping the condition, the fault and
the noise seed:

* ``as trained``: the held-out records as the data set drew them (its SNR or SNR range);
* ``snr=40``, ``snr=20``, ``snr=10``, ``snr=5``: the accelerometer's SNR set (the shipped
  diagnoser is trained on SNRs drawn in 10-40 dB, so 5 dB lies outside and must be refused);
* ``resonance*0.8``, ``resonance*1.2``: the condition's mounting resonance moved by -20 %
  or +20 % (the training band is 3-4.5 kHz; a resonance at or above 0.45 fs is not
  simulated: the sensor model's limit);
* ``mass*0.9``, ``mass*1.1``: the rod and crosshead masses of the condition times 0.9 or
  1.1, so the machine departs up to 10 % beyond the training range (18-22 kg, 27-33 kg)
  while the diagnoser's load-reversal features assume the nominal 30 kg crosshead.

The sensed channels are cached in ``--cache`` (one ``.npz`` a record), so the features can be
recomputed and another diagnoser evaluated without simulating again:

    python benchmarks/bench_diagnosis_robustness.py --workers 2 --cache out/robustness
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

VARIANTS = {
    "as trained": {},
    "snr=40": {"snr_db": 40.0},
    "snr=20": {"snr_db": 20.0},
    "snr=10": {"snr_db": 10.0},
    "snr=5": {"snr_db": 5.0},
    "resonance*0.8": {"resonance": 0.8},
    "resonance*1.2": {"resonance": 1.2},
    "mass*0.9": {"mass": 0.9},
    "mass*1.1": {"mass": 1.1},
}


def _task(t, change):
    t = dict(t, params=dict(t["params"]))
    if "snr_db" in change:
        t["snr_db"] = change["snr_db"]
    if "resonance" in change:
        t["resonance_hz"] = t["resonance_hz"] * change["resonance"]
    if "mass" in change:
        for k in ("m2", "m3"):
            t["params"][k] = t["params"][k] * change["mass"]
    return t


def simulate_channels(job):
    """Sensed channels of one task (picklable unit of work)."""
    from recipdyn.diagnosis.dataset import CHANNELS, simulate_record

    key, task = job
    rec = simulate_record(task)
    return key, {c: np.asarray(rec[c].values, np.float32) for c in CHANNELS}


def main() -> None:
    from recipdyn.diagnosis import default_model_path, load
    from recipdyn.diagnosis.dataset import DatasetSpec, design, features_of
    from recipdyn.diagnosis.diagnose import FLOOR_SLACK, RING_SLACK, noise_floor
    from recipdyn.errors import deferred_signals
    from recipdyn.parallel import run_unordered

    ap = argparse.ArgumentParser()
    ap.add_argument("--variants", default=",".join(VARIANTS))
    ap.add_argument("--conditions", type=int, default=5, help="held-out conditions used")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--cache", default="out/robustness")
    ap.add_argument("--model", default=None)
    ap.add_argument(
        "--simulate-only",
        default=None,
        metavar="DATASET",
        help="only simulate (into the cache) the variants of this data set's spec",
    )
    ap.add_argument(
        "--cached-only",
        action="store_true",
        help="diagnose the cached records only (simulate nothing)",
    )
    args = ap.parse_args()
    if args.simulate_only:
        import json

        card = json.loads((Path(args.simulate_only) / "datacard.json").read_text())
        spec_dict = card["spec"]
    else:
        diag = load(args.model or default_model_path())
        spec_dict = diag.card["spec"]
    spec = DatasetSpec.from_dict(spec_dict)  # a card without a chain: the fixed one
    test = [t for t in design(spec) if t["split"] == "test"]
    conds = sorted({t["condition"] for t in test})[: args.conditions]
    tasks = [
        t
        for t in test
        if t["condition"] in conds and (t["label"] == "healthy" or t["severity"] >= 0.5)
    ]
    cache = Path(args.cache)
    cache.mkdir(parents=True, exist_ok=True)
    print(
        f"{len(tasks)} records a variant ({len(conds)} held-out conditions, healthy and s >= 0.5)\n"
    )
    print("| variant | records | accuracy (s >= 0.5) | healthy recall | refused (out of domain) |")
    print("|---|---|---|---|---|")
    for name in args.variants.split(","):
        change = VARIANTS[name]
        jobs, skipped = [], 0
        for t in tasks:
            tt = _task(t, change)
            if tt["resonance_hz"] >= 0.45 * tt["fs"]:
                skipped += 1
                continue
            key = f"{name.replace('*', 'x').replace(' ', '_')}-{t['index']}"
            if not (cache / f"{key}.npz").exists() and not args.cached_only:
                jobs.append((key, tt))
        t0 = time.perf_counter()

        def store(res):
            key, ch = res
            np.savez(cache / f"{key}.npz", **ch)

        with deferred_signals() as pending:
            run_unordered(simulate_channels, jobs, args.workers, store, pending)
        if args.simulate_only:
            print(f"{name}: {len(jobs)} simulated", flush=True)
            continue
        classes = diag.classes
        right = refused = n = healthy_right = n_healthy = 0
        if not any(
            (cache / f"{name.replace('*', 'x').replace(' ', '_')}-{t['index']}.npz").exists()
            for t in tasks
        ):
            print(f"| {name} | not simulated | | | |")
            continue
        for t in tasks:
            tt = _task(t, change)
            key = f"{name.replace('*', 'x').replace(' ', '_')}-{t['index']}"
            if not (cache / f"{key}.npz").exists():
                continue
            with np.load(cache / f"{key}.npz") as z:
                ch = {k: z[k].astype(float) for k in z.files}
            f = features_of(ch, tt["fs"], tt["params"]["omega"] / (2 * math.pi))
            x = np.array([[f[k] for k in diag.names]])
            lo, hi = diag.state["ring_range"]
            d, thr, _ = diag.ood(x[0])
            ring_ok = lo * (1 - RING_SLACK) <= f["acc_ring_hz"] <= hi * (1 + RING_SLACK)
            floor = noise_floor(diag, x[0])
            floor_ok = floor is None or floor[1] / FLOOR_SLACK <= floor[0] <= floor[2] * FLOOR_SLACK
            refused += (not ring_ok) or (not floor_ok) or d > thr
            ok = classes[int(np.argmax(diag.predict_proba(x)[0]))] == t["label"]
            right += ok
            n += 1
            if t["label"] == "healthy":
                healthy_right += ok
                n_healthy += 1
        print(
            f"| {name} | {n}{f' ({skipped} above 0.45 fs: not simulated)' if skipped else ''} | "
            f"{right / n:.3f} | {healthy_right / max(n_healthy, 1):.2f} | {refused / n:.3f} |"
            f"  ({time.perf_counter() - t0:.0f} s)",
            flush=True,
        )


if __name__ == "__main__":
    main()
