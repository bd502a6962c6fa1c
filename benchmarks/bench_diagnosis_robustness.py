"""Accuracy of the shipped diagnoser against the accelerometer's SNR, on its held-out
operating conditions (docs/diagnosis.md, robustness).

The test records of the default data set's spec are simulated again at each SNR (same
conditions, faults and noise seeds; only the noise level differs) and diagnosed by the shipped
diagnoser, trained at 20 dB:

    python benchmarks/bench_diagnosis_robustness.py --snr 40,20,10 --workers 2
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def main() -> None:
    from recipdyn.diagnosis import default_model_path, load
    from recipdyn.diagnosis.dataset import DatasetSpec, design, make_record
    from recipdyn.errors import deferred_signals
    from recipdyn.parallel import run_unordered

    ap = argparse.ArgumentParser()
    ap.add_argument("--snr", default="40,20,10")
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    diag = load(default_model_path())
    card = diag.card
    base = {k: tuple(v) if isinstance(v, list) else v for k, v in card["spec"].items()}
    classes = diag.classes
    print("| SNR (dB) | records | accuracy | moderate and severe | refused (out of domain) |")
    print("|---|---|---|---|---|")
    for snr in [float(s) for s in args.snr.split(",")]:
        spec = DatasetSpec(**dict(base, snr_db=snr))
        tasks = [t for t in design(spec) if t["split"] == "test"]
        results = []
        t0 = time.perf_counter()
        with deferred_signals() as pending:
            run_unordered(make_record, tasks, args.workers, results.append, pending)
        by = {r["index"]: r for r in results}
        right, right_ms, n_ms, refused = 0, 0, 0, 0
        for t in tasks:
            f = by[t["index"]]["features"]
            x = np.array([[f[n] for n in diag.names]])
            lo, hi = diag.state["ring_range"]
            d, thr, _ = diag.ood(x[0])
            if not (0.9 * lo <= f["acc_ring_hz"] <= 1.1 * hi) or d > thr:
                refused += 1
            ok = classes[int(np.argmax(diag.predict_proba(x)[0]))] == t["label"]
            right += ok
            if t["label"] == "healthy" or t["severity"] >= 0.5:
                right_ms += ok
                n_ms += 1
        print(
            f"| {snr:g} | {len(tasks)} | {right / len(tasks):.3f} | {right_ms / n_ms:.3f} | "
            f"{refused / len(tasks):.3f} |  ({time.perf_counter() - t0:.0f} s)",
            flush=True,
        )


if __name__ == "__main__":
    main()
