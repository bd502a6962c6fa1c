"""Benchmark (issue 15, target 7): sweep throughput against the number of Dask workers.

A fault-map-like sweep (rc x omega grid, peak and Poincare measures, 40 revolutions a point) on
a local Dask cluster of 1, 2, ... single-threaded worker processes, each cluster started once
and warmed by one small sweep (the compiled kernels load from the cache), then timed. Also
measured, because they bound what more workers can give:

* the coordinator's store writes (``StoreWriter``: points written, read back, checked, marked
  done), one by one and in batches, on a small and a large grid: the rate no number of workers
  can exceed;
* the scheduler's cost per task (empty tasks through the same cluster).

The machine has as many cores as it has; workers beyond them share cores, so the curve flattens
there — that part shows the overhead of oversubscription, not scaling. ``docs/scaling.md``
turns the per-worker rate and these limits into the time and cost of a 10^6-point map.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

import numpy as np

from recipdyn.model import CompressorParams
from recipdyn.sweep import SweepSpec, parse_axis, run_sweep

SETTINGS = dict(revolutions=10.0, transient=20.0, points=20, fs=10_000.0, rtol=1e-9,
                atol=1e-11)  # fmt: skip


def _spec(n_rc: int, n_omega: int) -> SweepSpec:
    return SweepSpec(axes=(parse_axis(f"rc=0.2mm:2mm:{n_rc}"),
                           parse_axis(f"omega=15:60:{n_omega}")),
                     measures=("poincare", "peak"), base=CompressorParams(theta_c_offset=0.1),
                     settings=SETTINGS)  # fmt: skip


def _write_rate(tmp: str, side: int, n: int = 400) -> dict:
    """Points per second the coordinator can store (write, read back, verify, mark done) into a
    side x side grid's store, point by point (the serial backend) and in batches of 256 (the
    parallel backends). One computed point is stored under ``n`` different indices."""
    from pathlib import Path

    import zarr

    from recipdyn.sweep import run as R
    from recipdyn.sweep.work import run_point

    spec = _spec(side, side)
    R._create_store(Path(f"{tmp}/w{side}.zarr"), spec)
    g = zarr.open_group(f"{tmp}/w{side}.zarr", mode="r+")
    tasks = list(R._tasks(spec, list(spec.grid())[: 2 * n]))
    one = run_point(tasks[0])
    results = [dict(one, index=t["index"]) for t in tasks]
    out = dict(points=spec.n_points, point_block=R.point_block(spec.n_points))
    for label, batch, rs in (("single", 1, results[:n]), ("batched", R.WRITE_BATCH, results[n:])):
        w = R.StoreWriter(g, spec, max_batch=batch, max_wait=1e9)
        t0 = time.perf_counter()
        for r in rs:
            w.add(r)
        w.flush()
        out[label] = len(rs) / (time.perf_counter() - t0)
    return out


def _task_rate(client, n: int = 400) -> float:
    """Empty tasks per second through the scheduler (submit, run, gather)."""
    t0 = time.perf_counter()
    futs = [client.submit(int, i, pure=False) for i in range(n)]
    client.gather(futs)
    return n / (time.perf_counter() - t0)


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="12 points, 1-2 workers")
    ap.add_argument("--workers", default=None, help="comma list (default 1,2,3)")
    args, _ = ap.parse_known_args(argv)
    from dask.distributed import Client, LocalCluster

    counts = [1, 2] if args.quick else [1, 2, 3]
    if args.workers:
        counts = [int(w) for w in args.workers.split(",")]
    n_rc, n_omega = (3, 4) if args.quick else (6, 8)
    spec = _spec(n_rc, n_omega)
    n = n_rc * n_omega
    res: dict = dict(points=n, cores=os.cpu_count(), settings=SETTINGS, curve=[])
    with tempfile.TemporaryDirectory() as tmp:
        run_sweep(_spec(2, 1), f"{tmp}/warm", backend="serial", progress=False)  # JIT cache
        t0 = time.perf_counter()
        run_sweep(spec, f"{tmp}/serial", backend="serial", progress=False)
        serial = n / (time.perf_counter() - t0)
        res["serial_points_per_s"] = serial
        for w in counts:
            t0 = time.perf_counter()
            with LocalCluster(n_workers=w, threads_per_worker=1, dashboard_address=None) as cl:
                start = time.perf_counter() - t0
                addr = cl.scheduler_address
                run_sweep(_spec(1, w), f"{tmp}/warm{w}", backend="dask", scheduler=addr,
                          progress=False)  # fmt: skip  # every worker loads the kernels
                t0 = time.perf_counter()
                run_sweep(spec, f"{tmp}/d{w}", backend="dask", scheduler=addr, progress=False)
                rate = n / (time.perf_counter() - t0)
                with Client(addr) as client:
                    tasks = _task_rate(client)
            row = dict(workers=w, points_per_s=rate, per_worker=rate / w,
                       efficiency=rate / (w * serial), cluster_start_s=start,
                       tasks_per_s=tasks)  # fmt: skip
            res["curve"].append(row)
        res["writes_small"] = _write_rate(tmp, 20, 100 if args.quick else 200)  # 400 points
        res["writes_large"] = _write_rate(tmp, 100, 100 if args.quick else 400)  # 10^4 points
    print(
        f"scaling: {n} points (rc x omega, poincare + peak, "
        f"{SETTINGS['transient'] + SETTINGS['revolutions']:g} revolutions a point), "
        f"{res['cores']} cores"
    )
    print(f"  serial: {serial:.2f} points/s")
    print(
        f"  {'workers':>7s} {'points/s':>9s} {'per worker':>10s} {'efficiency':>10s} "
        f"{'cluster start':>13s} {'empty tasks/s':>13s}"
    )
    for r in res["curve"]:
        print(
            f"  {r['workers']:7d} {r['points_per_s']:9.2f} {r['per_worker']:10.2f} "
            f"{r['efficiency']:10.2f} {r['cluster_start_s']:11.1f} s {r['tasks_per_s']:13.0f}"
        )
    for key in ("writes_small", "writes_large"):
        w = res[key]
        print(
            f"  coordinator store writes, {w['points']} -point grid ({w['point_block']} points "
            f"a chunk): {w['single']:.0f} points/s one by one, {w['batched']:.0f} batched"
        )
    best = max(res["curve"], key=lambda r: r["points_per_s"])
    within = [r for r in res["curve"] if r["workers"] <= (res["cores"] or 1)]
    eff = float(np.min([r["efficiency"] for r in within])) if within else float("nan")
    res["summary"] = [
        dict(metric=f"scaling: Dask points/s, {best['workers']} workers (best)",
             value=best["points_per_s"], unit="pt/s", target=None, better="higher"),
        dict(metric="scaling: parallel efficiency up to the core count", value=eff, unit="",
             target=None, better="higher"),
        dict(metric="scaling: store writes, 10^4-point grid, batched",
             value=res["writes_large"]["batched"], unit="pt/s", target=None, better="higher"),
    ]  # fmt: skip
    return res


if __name__ == "__main__":
    main()
