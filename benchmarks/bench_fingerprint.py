"""The machine fingerprint's spread on a diagnoser's own data set (issue 42, point 5;
docs/diagnosis.md, "When another machine is the same one"; `recipdyn.diagnosis.fingerprint`).

Every record of the data set (every class, every drawn chain) is read back from its store
(the sensed acceleration and tacho, as ``recipdyn diagnose`` reads them), its crank orders
estimated, and r/l and r (times the accelerometer's gain) compared with its machine's. The
records are the diagnoser's own machine, so every departure is the estimator's error:
the gas force, the joints' impacts, the chain (the AC coupling's high-pass, drift, noise).
Printed: quantiles of ``|lam/lam0 - 1|`` and ``|r/r0 - 1|`` raw and corrected for the AC
coupling, of ``|lam/lam0 - 1|`` over the record's own uncertainty (``lam_z``), by class, by
the drawn coupling's corner, and over the held-out (test) split, from which
`recipdyn.diagnosis.tolerances.FINGERPRINT` is set (``--min-revs``: the records of 2 whole
revolutions, as `recipdyn.diagnosis.fingerprint.check` requires).

    python benchmarks/bench_fingerprint.py [DATASET_FOLDER] [--min-revs] [--limit N] [--csv OUT]

Without a folder: the data set ``make diagnoser`` builds, or with ``--quick`` the small one
of ``_dataset.py`` (it checks that the benchmark runs; too small to set a tolerance).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

#: ``make bench`` runs it on the small data set (the shipped one's takes ~2 min more).
RUN_ALL_ARGV = ["--quick"]


def _one(folder, index, machine):
    from recipdyn.analysis.vibration import tacho_times
    from recipdyn.diagnosis.dataset import dataset_record
    from recipdyn.diagnosis.fingerprint import estimate

    rec = dataset_record(folder, index)
    fs = rec["fs"]
    edges = tacho_times(rec["tacho"], fs)
    # the data set's records hold 2 revolutions from a mark, so 2 leading edges: the crank
    # angle is the line through them (a prescribed, constant speed) over the whole record
    k = np.polyfit(edges, np.arange(edges.size), 1)
    revs = np.polyval(k, np.arange(rec["accel_guide"].size) / fs)
    e = estimate(rec["accel_guide"], fs, revs, machine)
    row = rec["row"]
    e.update(
        record=index,
        label=row["label"],
        split=row["split"],
        hp_hz=row.get("chain.accelerometer.highpass_hz", math.nan),
        hp_order=row.get("chain.accelerometer.highpass_order", math.nan),
        snr=row.get("chain.accelerometer.snr_db", math.nan),
        gain=row.get("chain.accelerometer.gain", 1.0),
        drift=row.get("chain.accelerometer.drift", 0.0),
    )
    return e


def _q(v, qs=(0.5, 0.9, 0.95, 0.99, 1.0)):
    v = np.abs(np.asarray(v, float))
    v = v[np.isfinite(v)]
    return " ".join(f"{q:.2f}:{np.quantile(v, q):.4f}" for q in qs) + f" (n={v.size})"


def main(argv=None):
    import pandas as pd

    from _dataset import dataset_for
    from recipdyn.diagnosis.dataset import read_features

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", nargs="?", default=None)
    ap.add_argument("--quick", action="store_true", help="the small data set of _dataset.py")
    ap.add_argument("--limit", type=int, default=0, help="every k-th record only (0: all)")
    ap.add_argument("--csv", default=None, help="write the per-record estimates here")
    ap.add_argument("--min-revs", action="store_true", help="only records of 2 whole revolutions")
    a = ap.parse_args(argv)
    folder, small = dataset_for(a.folder, a.quick)
    a.folder = str(folder)
    if small:
        print("the quick data set: this checks that the benchmark runs; it measures nothing")
    df, card = read_features(a.folder)
    machine = card["spec"].get("machine") or None
    idx = sorted(df.record.unique())
    if a.limit:
        idx = idx[:: max(1, len(idx) // a.limit)]
    t0 = time.perf_counter()
    rows = []
    for i in idx:
        try:
            rows.append(_one(a.folder, int(i), machine))
        except ValueError as exc:  # a record without whole revolutions or tacho pulses
            print(f"record {i}: {exc}")
    r = pd.DataFrame(rows)
    if a.csv:
        r.to_csv(a.csv, index=False)
    print(f"{len(r)} records in {time.perf_counter() - t0:.0f} s")
    r["lam_err"] = r.lam / r.lam_ref - 1
    r["lam_raw_err"] = r.lam_raw / r.lam_ref - 1
    r["r_err"] = r.r / r.r_ref - 1
    r["r_raw_err"] = r.r_raw / r.r_ref - 1
    # r/l's error in units of the record's own uncertainty (the orders 3-6, the coupling)
    r["lam_z"] = r.lam_err / np.sqrt(r.resid_12**2 + r.resid_2**2 + r.lam_spread**2)
    r["r_err_gain"] = r.r / (r.r_ref * r.gain) - 1  # with the drawn gain known
    if a.min_revs:
        r = r[r.revolutions >= 2].copy()
    print(f"{len(r)} records used ({(r.split == 'test').sum()} of held-out conditions)")
    for col in ("lam_raw_err", "lam_err", "lam_z", "r_err", "r_raw_err", "r_err_gain"):
        print(f"{col:12s} all  {_q(r[col])}")
        print(f"{col:12s} test {_q(r[r.split == 'test'][col])}")
        print(f"{col:12s} signed median {np.nanmedian(r[col]):+.4f}")
    print("by class (|lam_err| 0.95, |r_err| 0.95, lam_err median):")
    for lab, g in r.groupby("label"):
        print(
            f"  {lab:26s} {np.nanquantile(g.lam_err.abs(), 0.95):.4f} "
            f"{np.nanquantile(g.r_err.abs(), 0.95):.4f} {np.nanmedian(g.lam_err):+.4f}"
        )
    print("by the coupling's corner (Hz), order: 0.95 quantiles of |lam_raw_err|, |lam_err|,")
    print("|r_raw_err|, |r_err|")
    bins = pd.cut(r.hp_hz, [0, 0.3, 0.7, 1.2, 2.1])
    for (b, o), g in r.groupby([bins, "hp_order"], observed=True):
        print(
            f"  {b} order {o:.0f}: n={len(g)} raw {np.nanquantile(g.lam_raw_err.abs(), 0.95):.4f}"
            f" corrected {np.nanquantile(g.lam_err.abs(), 0.95):.4f}; r raw "
            f"{np.nanquantile(g.r_raw_err.abs(), 0.95):.4f} corrected "
            f"{np.nanquantile(g.r_err.abs(), 0.95):.4f}; corner read "
            f"{np.nanmedian(g.corner_hz):.2f} Hz"
        )
    summary = [
        {"metric": f"{q} quantile of {name}", "value": float(np.nanquantile(r[col].abs(), q)),
         "unit": "1", "target": None, "better": "lower"}
        for name, col in (("|r/l / r/l0 - 1|", "lam_err"), ("|r/r0 - 1|", "r_err"),
                          ("|r/l / r/l0 - 1| / u", "lam_z"))
        for q in (0.95, 0.99)
    ]  # fmt: skip
    return {"records": len(r), "summary": summary}


if __name__ == "__main__":
    main()
