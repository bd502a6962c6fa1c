"""Run a sweep on a backend, writing each point to a Zarr store as it finishes.

Backends (one code path: :func:`recipdyn.sweep.work.run_point`):

``serial``
    In this process, in grid order.
``processes`` (default)
    ``concurrent.futures.ProcessPoolExecutor`` over all cores.
``dask``
    ``dask.distributed``: ``dask_local=N`` starts a ``LocalCluster`` of N single-threaded
    workers; ``scheduler="tcp://host:8786"`` uses an existing cluster (see docs/sweeps.md).

The store (``OUT/sweep.zarr``) has one small chunk per point, so a point is written
independently of the others; ``done`` is written after the point's data, so an interrupted
sweep (Ctrl-C, kill -9, lost worker) resumes (``resume=True``) without recomputing finished
points or losing them. A failing point gets its message in ``error`` and the sweep goes on.
Only the coordinating process writes, in whatever order points finish; every value depends
only on its point, so results are bit-identical across backends.
"""

from __future__ import annotations

import json
import os
import shutil
import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .. import __version__
from ..model.parameters import ParameterError
from ..simulate import clean_attrs
from .spec import SweepSpec
from .work import N_PEAKS, run_point

__all__ = ["run_sweep", "open_sweep", "BACKENDS"]

BACKENDS = ("serial", "processes", "dask")


def _variables(spec: SweepSpec) -> dict[str, tuple[str, tuple[str, ...], int | None, str]]:
    """name -> (dtype, extra dims, extra size, units) for the requested measures."""
    v: dict[str, tuple[str, tuple[str, ...], int | None, str]] = {}
    n = int(spec.settings["points"])
    if "poincare" in spec.measures or "verdict" in spec.measures:
        for k, u in (("theta_c", "rad"), ("thetadot_c", "rad/s"), ("x", "m"), ("v", "m/s"),
                     ("a", "m/s**2")):  # fmt: skip
            v[f"poincare_{k}"] = ("f8", ("section",), n, u)
        v["poincare_distinct"] = ("i8", (), None, "1")
    if "peak" in spec.measures or "spectrum" in spec.measures:
        v["peak_a"] = ("f8", (), None, "m/s**2")
        v["rms_a"] = ("f8", (), None, "m/s**2")
    if "spectrum" in spec.measures:
        v["peak_freq"] = ("f8", ("peak",), N_PEAKS, "Hz")
        v["peak_amp"] = ("f8", ("peak",), N_PEAKS, "m/s**2")
    if "lyapunov" in spec.measures or "verdict" in spec.measures:
        v["lambda1"] = ("f8", (), None, "1/s")
        v["lambda_sum"] = ("f8", (), None, "1/s")
    if "verdict" in spec.measures:
        v["verdict"] = ("str", (), None, "")
    v["y_final"] = ("f8", ("state",), 2, "")
    return v


def _create_store(path: Path, spec: SweepSpec) -> None:
    import zarr

    g = zarr.open_group(str(path), mode="w")
    dims = tuple(a.name for a in spec.axes)
    for a in spec.axes:
        arr = g.create_array(a.name, shape=(len(a.values),), dtype="f8", dimension_names=[a.name])
        arr[:] = np.asarray(a.values)
        arr.attrs.update({"units": _unit(a.name), "scale": a.scale})
    one = (1,) * len(dims)
    for name, (dtype, extra, size, units) in _variables(spec).items():
        shape = spec.shape + ((size,) if extra else ())
        chunks = one + ((size,) if extra else ())
        kw: dict[str, Any] = dict(shape=shape, chunks=chunks, dimension_names=[*dims, *extra])
        if dtype == "str":
            arr = g.create_array(name, dtype=str, **kw)
        else:
            fill = np.nan if dtype == "f8" else -1
            arr = g.create_array(name, dtype=dtype, fill_value=fill, **kw)
        arr.attrs["units"] = units
    g.create_array("done", shape=spec.shape, chunks=one, dtype=bool, fill_value=False,
                   dimension_names=list(dims))  # fmt: skip
    g.create_array("error", shape=spec.shape, chunks=one, dtype=str, dimension_names=list(dims))
    attrs = dict(spec.base.to_attrs())
    g.attrs.update(clean_attrs({
        "title": "recipdyn sweep", "recipdyn_version": __version__, "spec_digest": spec.digest,
        "spec_json": spec.to_json(), "measures": ",".join(spec.measures),
        "sweep_axes": ",".join(dims), "continuation": int(spec.continuation),
        "mode": "sequential continuation" if spec.continuation else "independent points",
        **{f"setting_{k}": v for k, v in spec.settings.items()},
        **{f"param_{k}": v for k, v in attrs.items()},
    }))  # fmt: skip


def _unit(name: str) -> str:
    from ..model.parameters import PARAM_UNITS

    return PARAM_UNITS.get(name, "1")


def _write(g, spec: SweepSpec, res: dict[str, Any]) -> None:
    idx = tuple(res["index"])
    for name in _variables(spec):
        if name in res:
            g[name][idx] = res[name]
    g["error"][idx] = res["error"]
    g["done"][idx] = True  # last: a point counts as done only once its data are written


def open_sweep(path: str | Path) -> xr.Dataset:
    """The sweep store as an xarray Dataset (lazy)."""
    path = Path(path)
    if not path.exists():
        raise ParameterError(f"sweep store not found: {path}")
    return xr.open_zarr(str(path), consolidated=False)


def _tasks(spec: SweepSpec, todo: Iterable) -> Iterable[dict[str, Any]]:
    for idx, values in todo:
        yield dict(index=idx, params=spec.point_params(values), measures=spec.measures,
                   settings=spec.settings)  # fmt: skip


def run_sweep(
    spec: SweepSpec,
    out: str | Path,
    *,
    backend: str = "processes",
    workers: int | None = None,
    dask_local: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    force: bool = False,
    progress: bool = True,
    on_point: Callable[[dict[str, Any]], None] | None = None,
) -> Path:
    """Run ``spec``; returns the store path (``OUT/sweep.zarr``)."""
    if backend not in BACKENDS:
        raise ParameterError(f"backend = {backend!r}; allowed: {', '.join(BACKENDS)}")
    if spec.continuation and "poincare" not in spec.measures:
        raise ParameterError("--continuation needs the 'poincare' measure (its final state)")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    store = out / "sweep.zarr"
    import zarr

    if store.exists() and not (resume or force):
        raise ParameterError(f"{store} exists: use --resume to continue it or --force to redo it")
    if store.exists() and resume:
        g = zarr.open_group(str(store), mode="a")
        if g.attrs.get("spec_digest") != spec.digest:
            raise ParameterError(f"{store} was made with a different sweep spec; "
                                 "refusing to resume (use --force to start over)")  # fmt: skip
    else:
        if store.exists():
            shutil.rmtree(store)
        _create_store(store, spec)
        g = zarr.open_group(str(store), mode="a")
    done = np.asarray(g["done"][...])
    todo = [(idx, v) for idx, v in spec.grid() if not done[idx]]
    n_total, n_skip = int(np.prod(spec.shape)), int(done.sum())
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=n_total, initial=n_skip, unit="pt", desc="sweep")
    failed = 0
    t0 = time.perf_counter()

    def accept(res):
        nonlocal failed
        _write(g, spec, res)
        failed += bool(res["error"])
        if on_point is not None:
            on_point(res)
        if bar is not None:
            bar.update(1)
            bar.set_postfix(failed=failed)

    try:
        if spec.continuation or backend == "serial":
            y0 = None
            for task in _tasks(spec, todo):
                if spec.continuation and y0 is not None:
                    task["y0"] = y0
                res = run_point(task)
                accept(res)
                if spec.continuation and not res["error"]:
                    y0 = res["y_final"]
        elif backend == "processes":
            _run_processes(_tasks(spec, todo), workers, accept)
        else:
            _run_dask(_tasks(spec, todo), dask_local, scheduler, workers, accept)
    finally:
        if bar is not None:
            bar.close()
    g.attrs["last_run_seconds"] = time.perf_counter() - t0
    if progress:
        print(f"sweep: {n_total - n_skip} computed ({failed} failed), {n_skip} reused, "
              f"{time.perf_counter() - t0:.1f} s -> {store}")  # fmt: skip
    return store


def _run_processes(tasks, workers, accept) -> None:
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    workers = workers or os.cpu_count() or 1
    tasks = iter(tasks)
    with ProcessPoolExecutor(max_workers=workers) as pool:
        pending = set()
        for task in tasks:  # keep at most 2 tasks per worker queued (bounded memory)
            pending.add(pool.submit(run_point, task))
            if len(pending) >= 2 * workers:
                finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                for f in finished:
                    accept(f.result())
        for f in wait(pending).done:
            accept(f.result())


def _run_dask(tasks, dask_local, scheduler, workers, accept) -> None:
    from dask.distributed import Client, LocalCluster, as_completed

    cluster = None
    if scheduler:
        client = Client(scheduler)
    else:
        n = dask_local or workers or os.cpu_count() or 1
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=None)  # fmt: skip
        client = Client(cluster)
    try:
        futures = [client.submit(run_point, t, pure=False) for t in tasks]
        for fut in as_completed(futures):
            accept(fut.result())
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def spec_from_store(path: str | Path) -> dict[str, Any]:
    """The JSON spec recorded in a store."""
    import zarr

    return json.loads(zarr.open_group(str(path), mode="r").attrs["spec_json"])
