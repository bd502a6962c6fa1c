"""Where one data-set record's time goes (`recipdyn dataset`): simulate (the model's set-up
and the integration), sense, featurise, store.

    python benchmarks/bench_dataset_record.py [--records 3] [--profile]
    python benchmarks/bench_dataset_record.py --compare [--rounds 4]

Runs, in one process, one record of each of a few classes at the first condition of the
default design once to warm up (the first call loads or compiles the model's kernels, and the
time of that is printed apart), then ``--records`` rounds over the same records, timing each
phase with `time.perf_counter`, and prints the mean of each phase per record and its share.
``--profile`` adds cProfile's 25 largest cumulative entries of one warm record. Times are of
the machine it runs on (on a shared machine, compare the shares, not the seconds).

``--compare`` times the records as the data set makes them now (no run summary; the event
records built as one Dataset) against the way it made them before (the run summary computed
and dropped; the event records added to the Dataset one variable at a time, the function
`events_one_by_one` below), alternating the two arms round by round on the same records, and
checks that both give the same stored channels and features to the bit.
"""

from __future__ import annotations

import argparse
import cProfile
import math
import pstats
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from recipdyn import sensors
from recipdyn.diagnosis.classes import MODEL
from recipdyn.diagnosis.dataset import (
    CHANNELS,
    DatasetSpec,
    _open_store,
    _write,
    design,
    features_of,
)
from recipdyn.simulate import simulate

CLASSES = ("healthy", "crank_pin_clearance", "ring_leak", "sticking_valve")


def events_one_by_one(m, values, e, sol, t_start, t_last):
    """The event records as `recipdyn.simulate` built them before: one variable at a time."""
    import xarray as xr

    keep = (sol.t_events >= t_start) & (sol.t_events <= t_last)
    dim = f"{e.name}_event"
    ds = xr.Dataset()
    ds[f"{e.name}_time"] = (dim, sol.t_events[keep], {"units": m.time_unit,
                            "long_name": f"time of {e.name}: {e.description}"})  # fmt: skip
    for i, (s, u) in enumerate(m.states(values)):
        ds[f"{e.name}_{s}"] = (dim, sol.y_events[keep, i], {"units": u,
                               "long_name": f"{s} at {e.name}"})  # fmt: skip
        if e.action == "reset":
            ds[f"{e.name}_{s}_after"] = (dim, sol.y_events_after[keep, i], {"units": u,
                                         "long_name": f"{s} after {e.name}"})  # fmt: skip
    ds.attrs[f"events_{e.name}"] = f"{e.description} (direction {e.direction}, {e.action})"
    return ds


def phases(task, g, names, summary: bool = False) -> dict[str, float]:
    t = {}
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = simulate(
            model=MODEL,
            revolutions=task["revolutions"],
            transient=task["transient"],
            fs=task["fs"],
            summary=summary,
            **task["params"],
        )
    t["simulate"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    rec = sensors.record(
        ds,
        accelerometer=sensors.Accelerometer(
            snr_db=task["snr_db"], resonance_hz=task["resonance_hz"]
        ),
        pressure=sensors.PressureTransducer(),
        tacho=sensors.Tacho(),
        seed=task["noise_seed"],
    )
    ch = {c: np.asarray(rec[c].values, dtype=np.float32) for c in CHANNELS}
    t["sense"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    speed = task["params"]["omega"] / (2 * math.pi)
    f = features_of({k: v.astype(float) for k, v in ch.items()}, task["fs"], speed)
    t["features"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    _write(
        g,
        {"index": task["index"], "error": "", "channels": ch, "features": f, "seconds": 0.0},
        names,
    )
    t["store"] = time.perf_counter() - t0
    t["integrate (of simulate)"] = float(ds.attrs.get("solver_wall_time_s", math.nan))
    t["_out"] = (ch, f)
    return t


def compare(tasks, g, names, rounds: int) -> None:
    import importlib
    import sys

    importlib.import_module("recipdyn.simulate")
    sim = sys.modules["recipdyn.simulate"]
    new_events = sim._events
    total = {"before": 0.0, "after": 0.0}
    n = {"before": 0, "after": 0}
    outs: dict[str, dict] = {"before": {}, "after": {}}
    for r in range(rounds):
        for arm in ("before", "after") if r % 2 == 0 else ("after", "before"):
            sim._events = events_one_by_one if arm == "before" else new_events
            for t in tasks:
                p = phases(t, g, names, summary=arm == "before")
                total[arm] += sum(p[k] for k in ("simulate", "sense", "features", "store"))
                n[arm] += 1
                outs[arm][t["index"]] = p["_out"]
    sim._events = new_events
    for i, (ch, f) in outs["before"].items():
        ch2, f2 = outs["after"][i]
        assert all(np.array_equal(ch[c], ch2[c], equal_nan=True) for c in ch), i
        assert all(f[k] == f2[k] or (math.isnan(f[k]) and math.isnan(f2[k])) for k in f), i
    rate = {a: n[a] / total[a] for a in total}
    print(f"{rounds} alternating rounds of {len(tasks)} records per arm (one process, one core):")
    for a in ("before", "after"):
        print(f"  {a:7s} {total[a] / n[a]:.3f} s/record  {rate[a]:.3f} records/s/core")
    print(f"  after/before throughput: {rate['after'] / rate['before']:.3f}")
    print("  stored channels and features identical to the bit: yes")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--records", type=int, default=3, help="rounds over the classes")
    ap.add_argument("--profile", action="store_true")
    ap.add_argument("--compare", action="store_true", help="before/after, alternating")
    ap.add_argument("--rounds", type=int, default=4, help="rounds of --compare")
    a = ap.parse_args()
    spec = DatasetSpec(n_conditions=3, classes=("healthy",) + CLASSES[1:])
    tasks = [t for t in design(spec) if t["condition"] == 0 and t["level"] == 3]
    with tempfile.TemporaryDirectory() as tmp:
        g, names = _open_store(Path(tmp) / "s.zarr", spec, design(spec), False, True)
        t0 = time.perf_counter()
        phases(tasks[0], g, names)
        print(f"first record (loads or compiles the kernels): {time.perf_counter() - t0:.1f} s")
        for t in tasks[1:]:
            phases(t, g, names)
        if a.compare:
            compare(tasks, g, names, a.rounds)
            return
        acc: dict[str, list[float]] = {}
        for _ in range(a.records):
            for t in tasks:
                for k, v in phases(t, g, names).items():
                    if k != "_out":
                        acc.setdefault(k, []).append(v)
        total = sum(np.mean(acc[k]) for k in ("simulate", "sense", "features", "store"))
        print(f"{len(acc['simulate'])} warm records ({', '.join(CLASSES)}), mean per record:")
        for k, v in acc.items():
            print(f"  {k:24s} {np.mean(v):7.3f} s  {100 * np.mean(v) / total:5.1f} %")
        print(f"  {'total':24s} {total:7.3f} s  -> {1 / total:.2f} records/s/core")
        if a.profile:
            pr = cProfile.Profile()
            pr.enable()
            phases(tasks[1], g, names)
            pr.disable()
            pstats.Stats(pr).sort_stats("cumulative").print_stats(25)


if __name__ == "__main__":
    main()
