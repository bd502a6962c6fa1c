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
independently of the others. A point counts as done only after its data are written, read
back and match their checksum (``checksum``, CRC-32 of every value of the point); ``done`` is
written last. On ``resume=True`` every done point is verified again (a torn or corrupted chunk
after ``kill -9`` or a disk fault is found and the point recomputed, never counted as done),
and with ``continuation`` every point after the first missing one is recomputed from its
predecessor's recorded final state, so a resumed sweep equals an uninterrupted one. A failing
point gets its message in ``error`` and the sweep goes on. Only the coordinating process
writes; every value depends only on its point, so results are bit-identical across backends.

One sweep at a time per output folder (:class:`~recipdyn.locking.RunLock`). SIGINT/SIGTERM
stop the sweep after the points already finished are written; the workers are ended and the
:class:`~recipdyn.errors.Interrupted` raised says how many points are kept.
"""

from __future__ import annotations

import os
import shutil
import time
import zlib
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .. import __version__
from ..errors import Interrupted, ParameterError, deferred_signals
from ..locking import RunLock
from ..parallel import run_unordered
from ..simulate import clean_attrs
from .spec import SweepSpec
from .work import N_PEAKS, run_point

__all__ = ["run_sweep", "open_sweep", "BACKENDS"]

BACKENDS = ("serial", "processes", "dask")


def _variables(spec: SweepSpec) -> dict[str, tuple[str, tuple[str, ...], int | None, str]]:
    """name -> (dtype, extra dims, extra size, units) for the requested measures."""
    v: dict[str, tuple[str, tuple[str, ...], int | None, str]] = {}
    m = spec.get_model()
    n = int(spec.settings["points"])
    per_time = "Hz" if m.time_unit == "s" else f"1/{m.time_unit}"
    if "poincare" in spec.measures or "verdict" in spec.measures:
        for k, u in m.sections():
            v[f"poincare_{k}"] = ("f8", ("section",), n, u)
        v["poincare_distinct"] = ("i8", (), None, "1")
    sig, sig_unit = m.vibration()
    if "peak" in spec.measures or "spectrum" in spec.measures:
        v[f"peak_{sig}"] = ("f8", (), None, sig_unit)
        v[f"rms_{sig}"] = ("f8", (), None, sig_unit)
    if "spectrum" in spec.measures:
        v["peak_freq"] = ("f8", ("peak",), N_PEAKS, per_time)
        v["peak_amp"] = ("f8", ("peak",), N_PEAKS, sig_unit)
    if "lyapunov" in spec.measures or "verdict" in spec.measures:
        lam_unit = "1" if m.kind == "map" else ("1/s" if m.time_unit == "s" else per_time)
        v["lambda1"] = ("f8", (), None, lam_unit)
        v["lambda_sum"] = ("f8", (), None, lam_unit)
    if "verdict" in spec.measures:
        v["verdict"] = ("str", (), None, "")
    v["y_final"] = ("f8", ("state",), m.dim, "")
    return v


def _create_store(path: Path, spec: SweepSpec) -> None:
    import zarr

    g = zarr.open_group(str(path), mode="w")
    dims = tuple(a.name for a in spec.axes)
    for a in spec.axes:
        arr = g.create_array(a.name, shape=(len(a.values),), dtype="f8", dimension_names=[a.name])
        arr[:] = np.asarray(a.values)
        arr.attrs.update({"units": spec.get_model().schema[a.name].unit or "1",
                          "scale": a.scale})  # fmt: skip
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
    g.create_array("checksum", shape=spec.shape, chunks=one, dtype="i8", fill_value=-1,
                   dimension_names=list(dims))  # fmt: skip
    attrs = spec.base_attrs()
    g.attrs.update(clean_attrs({
        "title": "recipdyn sweep", "recipdyn_version": __version__, "spec_digest": spec.digest,
        "model": spec.get_model().name, "model_spec": spec.model,
        "spec_json": spec.to_json(), "measures": ",".join(spec.measures),
        "sweep_axes": ",".join(dims), "continuation": int(spec.continuation),
        "mode": "sequential continuation" if spec.continuation else "independent points",
        **{f"setting_{k}": v for k, v in spec.settings.items()},
        **{f"param_{k}": v for k, v in attrs.items()},
    }))  # fmt: skip


_FILL = {"f8": np.nan, "i8": -1, "str": ""}


def _canonical(name: str, dtype: str, shape: tuple[int, ...], value) -> bytes:
    if dtype == "str":
        return f"{name}={value}".encode()
    a = np.broadcast_to(np.asarray(value, dtype=dtype), shape)  # a fill scalar fills it all
    if dtype == "f8":
        a = np.where(np.isnan(a), np.nan, a)  # one NaN bit pattern
    return name.encode() + np.ascontiguousarray(a).tobytes()


def _checksum(spec: SweepSpec, values: dict[str, Any]) -> int:
    """CRC-32 of a point's values as the store holds them (fill values where absent)."""
    crc = 0
    for name, (dtype, extra, size, _u) in _variables(spec).items():
        shape = (size,) if extra else ()
        crc = zlib.crc32(_canonical(name, dtype, shape, values.get(name, _FILL[dtype])), crc)
    return zlib.crc32(f"error={values.get('error', '')}".encode(), crc)


def _read_point(g, spec: SweepSpec, idx: tuple) -> dict[str, Any]:
    out = {name: g[name][idx] for name in _variables(spec)}
    out["error"] = g["error"][idx]
    return out


def _write(g, spec: SweepSpec, res: dict[str, Any]) -> None:
    """Write one point, read it back, check it, then mark it done."""
    idx = tuple(res["index"])
    for name, (dtype, _e, _s, _u) in _variables(spec).items():
        g[name][idx] = res.get(name, _FILL[dtype])
    g["error"][idx] = res["error"]
    crc = _checksum(spec, res)
    g["checksum"][idx] = crc
    if _checksum(spec, _read_point(g, spec, idx)) != crc:  # pragma: no cover - disk fault
        raise OSError(f"sweep point {idx} did not read back as written")
    g["done"][idx] = True  # last: a point counts as done only once its data verify


def _verified_done(g, spec: SweepSpec) -> tuple[np.ndarray, int]:
    """``done`` after re-checking every point marked done; returns (done, n_rejected)."""
    done = np.zeros(spec.shape, dtype=bool)
    rejected = 0
    try:
        marked = np.asarray(g["done"][...], dtype=bool)
    except Exception:  # a torn 'done' chunk: look at every point
        marked = None
    for idx, _ in spec.grid():
        if marked is not None and not marked[idx]:
            continue
        try:  # point by point: one torn chunk must not hide the others
            if not bool(g["done"][idx]):
                continue
            ok = _checksum(spec, _read_point(g, spec, idx)) == int(g["checksum"][idx])
        except Exception:  # unreadable (truncated, corrupted) chunk
            ok = False
        done[idx] = ok
        if not ok:
            rejected += 1
            try:
                g["done"][idx] = False
            except Exception:  # pragma: no cover - unwritable chunk: recomputing rewrites it
                pass
    return done, rejected


def open_sweep(path: str | Path) -> xr.Dataset:
    """The sweep store as an xarray Dataset (lazy)."""
    path = Path(path)
    if not path.exists():
        raise ParameterError(f"sweep store not found: {path}")
    expected = "a sweep store (OUT/sweep.zarr written by 'recipdyn sweep')"
    if not path.is_dir():
        raise ParameterError(f"{path}: is a file; expected {expected}")
    try:
        ds = xr.open_zarr(str(path), consolidated=False)
    except Exception as exc:
        raise ParameterError(f"{path}: cannot be read as Zarr ({type(exc).__name__}); "
                             f"expected {expected}") from None  # fmt: skip
    if "spec_json" not in ds.attrs or "done" not in ds:
        raise ParameterError(f"{path}: not a recipdyn sweep store; expected {expected}")
    return ds


def _tasks(spec: SweepSpec, todo: Iterable) -> Iterable[dict[str, Any]]:
    for idx, values in todo:
        yield dict(index=idx, params=spec.point_params(values), measures=spec.measures,
                   settings=spec.settings, model=spec.model)  # fmt: skip


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
    max_memory: float | None = None,
) -> Path:
    """Run ``spec``; returns the store path (``OUT/sweep.zarr``).

    Raises :class:`~recipdyn.errors.ParameterError` for bad settings, an existing store
    without ``resume``/``force``, a store made by a different spec, or an output folder in use
    by another run; :class:`~recipdyn.errors.Interrupted` on SIGINT/SIGTERM (points finished
    so far are kept).
    """
    if backend not in BACKENDS:
        raise ParameterError(f"backend = {backend!r}; allowed: {', '.join(BACKENDS)}")
    if spec.continuation and "poincare" not in spec.measures:
        raise ParameterError("--continuation needs the 'poincare' measure (its final state)")
    if workers is not None and not (isinstance(workers, int) and workers >= 1):
        raise ParameterError(f"workers = {workers!r}; allowed: an integer >= 1")
    if dask_local is not None and not (isinstance(dask_local, int) and dask_local >= 1):
        raise ParameterError(f"dask_local = {dask_local!r}; allowed: an integer >= 1")
    from ..io import check_output

    out = check_output(out, formats=None, what="sweep folder")
    _check_resources(spec, out, backend, workers, dask_local, max_memory)
    with RunLock(out, "sweep"):
        return _run_locked(spec, out, backend, workers, dask_local, scheduler, resume, force,
                           progress, on_point)  # fmt: skip


#: Disk used per point and variable: one chunk file (small, but one file-system block).
_BYTES_PER_CHUNK = 4096


def _check_resources(spec: SweepSpec, out: Path, backend, workers, dask_local,
                     max_memory) -> None:  # fmt: skip
    """Refuse a sweep whose points cannot fit in memory together, or whose store cannot fit."""
    from ..resources import check_memory
    from ..simulate import estimate_memory

    s = spec.settings
    if "peak" in spec.measures or "spectrum" in spec.measures:
        m = spec.get_model()
        periods = []
        for _, p in _corners(spec):
            pp = spec.point_params(p)
            periods.append(pp.crank_period if hasattr(pp, "crank_period") else m.period(pp) or 1.0)
        samples = s.get("revolutions", 5.0) * max(periods) * s.get("fs", 1e4)
        n_par = 1 if backend == "serial" or spec.continuation else (
            dask_local or workers or os.cpu_count() or 1)  # fmt: skip
        check_memory(n_par * estimate_memory(samples),
                     f"sweep ({n_par} point(s) at once, {samples:.3g} samples each)",
                     "reduce --revolutions, --fs or --workers", max_memory)  # fmt: skip
    need = spec.n_points * (len(_variables(spec)) + 3) * _BYTES_PER_CHUNK
    free = shutil.disk_usage(out).free
    if need > free:
        from ..resources import format_bytes

        raise ParameterError(f"a sweep of {spec.n_points} points needs about "
                             f"{format_bytes(need)} on disk, {out} has {format_bytes(free)} free: "
                             "fewer points or another --out")  # fmt: skip


def _corners(spec: SweepSpec):
    """The grid's extreme points (the slowest crank speed is at one of them)."""
    import itertools

    ends = [(0, len(a.values) - 1) for a in spec.axes]
    for idx in itertools.product(*ends):
        yield idx, {a.name: a.values[i] for a, i in zip(spec.axes, idx, strict=True)}


def _run_locked(spec, out, backend, workers, dask_local, scheduler, resume, force, progress,
                on_point) -> Path:  # fmt: skip
    store = out / "sweep.zarr"
    import zarr

    if store.exists() and not (resume or force):
        raise ParameterError(f"{store} exists: use --resume to continue it or --force to redo it")
    rejected = 0
    if store.exists() and resume:
        try:
            g = zarr.open_group(str(store), mode="a")
            digest = g.attrs.get("spec_digest")
        except Exception as exc:
            raise ParameterError(f"{store} cannot be opened as a sweep store ({exc}); "
                                 "use --force to start over") from None  # fmt: skip
        if digest != spec.digest:
            raise ParameterError(f"{store} was made with a different sweep spec; "
                                 "refusing to resume (use --force to start over)")  # fmt: skip
        done, rejected = _verified_done(g, spec)
    else:
        if store.exists():
            shutil.rmtree(store)
        _create_store(store, spec)
        g = zarr.open_group(str(store), mode="a")
        done = np.zeros(spec.shape, dtype=bool)
    grid = list(spec.grid())
    y0 = None
    if spec.continuation:  # points after the first missing one depend on it: redo them all
        first = next((k for k, (idx, _) in enumerate(grid) if not done[idx]), len(grid))
        for idx, _ in grid[first:]:
            done[idx] = False
        if 0 < first < len(grid):
            prev = grid[first - 1][0]
            if not g["error"][prev]:
                y0 = np.asarray(g["y_final"][prev], dtype=float)
    todo = [(idx, v) for idx, v in grid if not done[idx]]
    n_total, n_skip = spec.n_points, int(done.sum())
    if rejected and progress:
        print(f"sweep: {rejected} stored point(s) failed verification and are recomputed")
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=n_total, initial=n_skip, unit="pt", desc="sweep")
    failed = written = 0
    t0 = time.perf_counter()

    def accept(res):
        nonlocal failed, written
        _write(g, spec, res)
        written += 1
        failed += bool(res["error"])
        if on_point is not None:
            on_point(res)
        if bar is not None:
            bar.update(1)
            bar.set_postfix(failed=failed)

    try:
        with deferred_signals() as pending:
            if spec.continuation or backend == "serial":
                for task in _tasks(spec, todo):
                    pending.check()
                    if spec.continuation and y0 is not None:
                        task["y0"] = y0
                    res = run_point(task)
                    accept(res)
                    if spec.continuation:
                        y0 = None if res["error"] else res["y_final"]
                pending.check()
            elif backend == "processes":
                _run_processes(_tasks(spec, todo), workers, accept, pending)
            else:
                _run_dask(_tasks(spec, todo), dask_local, scheduler, workers, accept, pending)
    except (KeyboardInterrupt, Interrupted) as exc:
        intr = Interrupted.wrap(exc)
        intr.kept.append(f"{n_skip + written} of {n_total} sweep points ({written} new) in "
                         f"{store}; rerun the same command with --resume to finish")  # fmt: skip
        raise intr from None
    finally:
        if bar is not None:
            bar.close()
    g.attrs["last_run_seconds"] = time.perf_counter() - t0
    if progress:
        print(f"sweep: {n_total - n_skip} computed ({failed} failed), {n_skip} reused, "
              f"{time.perf_counter() - t0:.1f} s -> {store}")  # fmt: skip
    return store


def _run_processes(tasks, workers, accept, pending) -> None:
    run_unordered(run_point, tasks, workers or os.cpu_count() or 1, accept, pending)


def _run_dask(tasks, dask_local, scheduler, workers, accept, pending) -> None:
    from dask.distributed import Client, LocalCluster, as_completed

    cluster = None
    if scheduler:
        client = Client(scheduler)
    else:
        n = dask_local or workers or os.cpu_count() or 1
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=None)  # fmt: skip
        client = Client(cluster)
    futures = []
    try:
        futures = [client.submit(run_point, t, pure=False) for t in tasks]
        ac = as_completed(futures)
        while not ac.is_empty():
            batch = ac.next_batch(block=False)
            for fut in batch:
                accept(fut.result())
            if not batch:
                time.sleep(0.05)
            pending.check()
    finally:
        if futures:
            client.cancel(futures)
        client.close()
        if cluster is not None:
            cluster.close()
