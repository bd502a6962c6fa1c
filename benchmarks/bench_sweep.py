"""Benchmark (issue 5): sweep throughput per backend, side by side, and a bifurcation diagram
over omega (100 points, extrapolated to the 200 of issue 5).

The same grid runs on the serial, process-pool (2 workers) and Dask LocalCluster (2 workers)
backends in one run; points per second and ratios are printed. The omega bifurcation
(10-150 rad/s, 300 revolutions per point) is timed on the default backend; ``--points`` and
``--revs`` reduce it (the per-point time is reported so the full size can be extrapolated).
"""

from __future__ import annotations

import argparse
import tempfile
import time

from recipdyn.model import CompressorParams
from recipdyn.sweep import SweepSpec, parse_axis, run_sweep

SETTINGS = dict(revolutions=2.0, transient=20.0, points=60, lyap_revolutions=20.0, fs=10_000.0,
                rtol=1e-9, atol=1e-11)  # fmt: skip


#: ``make bench`` runs the quick mode: the full one (a 100-point grid on three backends and a
#: 100-point, 300-revolution bifurcation) takes tens of minutes; --quick took 64 s on a loaded
#: 2-core machine (2026-12-07).
RUN_ALL_ARGV = ["--quick"]


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--points", type=int, default=100)
    ap.add_argument("--grid", type=int, default=100, help="points of the throughput grid")
    ap.add_argument("--revs", type=int, default=300)
    args, _ = ap.parse_known_args(argv)
    n = 8 if args.quick else args.grid
    spec = SweepSpec(axes=(parse_axis(f"omega=10:150:{n}"),), measures=("poincare", "peak"),
                     base=CompressorParams(theta_c_offset=0.1), settings=SETTINGS)  # fmt: skip
    res: dict = {"grid_points": n}
    with tempfile.TemporaryDirectory() as tmp:
        run_sweep(spec, f"{tmp}/warm", backend="serial", progress=False)  # JIT cache warm-up
        for name, kw in (("serial", dict(backend="serial")),
                         ("processes", dict(backend="processes", workers=2)),
                         ("dask", dict(backend="dask", dask_local=2))):  # fmt: skip
            t0 = time.perf_counter()
            run_sweep(spec, f"{tmp}/{name}", progress=False, **kw)
            res[name] = n / (time.perf_counter() - t0)
        # Dask on an already running cluster (what a user of --scheduler gets): the cluster's
        # start-up (~2-3 s, once per session) is excluded, workers are warm after one sweep
        from dask.distributed import LocalCluster

        with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None) as cl:
            run_sweep(spec, f"{tmp}/dwarm", backend="dask", scheduler=cl.scheduler_address,
                      progress=False)  # fmt: skip
            t0 = time.perf_counter()
            run_sweep(spec, f"{tmp}/dask2", backend="dask", scheduler=cl.scheduler_address,
                      progress=False)  # fmt: skip
            res["dask_running_cluster"] = n / (time.perf_counter() - t0)
        res["speedup_processes"] = res["processes"] / res["serial"]
        res["dask_overhead_vs_processes"] = res["processes"] / res["dask_running_cluster"] - 1
        res["dask_overhead_incl_cluster_start"] = res["processes"] / res["dask"] - 1
        print(f"sweep throughput, {n} points (omega 10-150 rad/s, 80 revolutions each):")
        for name in ("serial", "processes", "dask", "dask_running_cluster"):
            print(f"  {name:21s} {res[name]:6.2f} points/s")
        print(f"  processes vs serial: {res['speedup_processes']:.2f}x; Dask overhead vs "
              f"processes: {100 * res['dask_overhead_vs_processes']:+.1f} % on a running "
              f"cluster, {100 * res['dask_overhead_incl_cluster_start']:+.1f} % including "
              "LocalCluster start-up")  # fmt: skip
        res["summary"] = [
            dict(metric=f"sweep: process pool vs serial, {n} points, 2 workers",
                 value=res["speedup_processes"], unit="x", target=1.8, better="higher"),
            dict(metric="sweep: Dask (running cluster) overhead vs pool",
                 value=res["dask_overhead_vs_processes"], unit="", target=0.15, better="lower"),
        ]  # fmt: skip
        pts = 10 if args.quick else args.points
        revs = 30 if args.quick else args.revs
        bif_settings = dict(SETTINGS, transient=revs // 3, points=revs - revs // 3)
        bif = SweepSpec(
            axes=(parse_axis(f"omega=10:150:{pts}"),), measures=("poincare",),
            base=CompressorParams(theta_c_offset=0.1), settings=bif_settings,
        )  # fmt: skip
        t0 = time.perf_counter()
        run_sweep(bif, f"{tmp}/bif", backend="processes", progress=False)
        wall = time.perf_counter() - t0
        res["bifurcation"] = dict(points=pts, revolutions=revs, seconds=wall,
                                  per_point_s=wall / pts,
                                  extrapolated_200x300_s=wall / pts * 200 * 300 / revs)  # fmt: skip
        print(
            f"bifurcation diagram: {pts} points x {revs} revolutions in {wall:.1f} s "
            f"(extrapolated 200 x 300: {res['bifurcation']['extrapolated_200x300_s']:.0f} s)"
        )
    return res


if __name__ == "__main__":
    main()
