"""Run a sweep on a backend, writing each point to a Zarr store as it finishes.

Backends (one code path: `recipdyn.sweep.work.run_point`):

``serial``
    In this process, in grid order.
``processes`` (default)
    ``concurrent.futures.ProcessPoolExecutor`` over all cores.
``dask``
    ``dask.distributed``: ``dask_local=N`` starts a ``LocalCluster`` of N single-threaded
    workers; ``scheduler="tcp://host:8786"`` uses an existing cluster (see docs/sweeps.md).

The store (``OUT/sweep.zarr``) has one small chunk per point (blocks of points along the last
axis for grids above `BLOCK_ABOVE` points), written in batches
([`StoreWriter`][recipdyn.sweep.run.StoreWriter]). A point counts as done only after its data are
written, read back and match their checksum (``checksum``, CRC-32 of every value of the point);
``done`` is written last. On ``resume=True`` every done point is verified again (a torn or corrupted
chunk after ``kill -9`` or a disk fault is found and its points recomputed, never counted as done),
and with ``continuation`` every point after the first missing one is recomputed from its
predecessor's recorded final state, so a resumed sweep equals an uninterrupted one. A failing point
gets its message in ``error`` and the sweep goes on. Only the coordinating process writes; every
value depends only on its point, so results are bit-identical across backends.

One sweep at a time per output folder (`RunLock`). SIGINT/SIGTERM
stop the sweep after the points already finished are written; the workers are ended and the
[`Interrupted`][recipdyn.errors.Interrupted] raised says how many points are kept.
"""

from __future__ import annotations

import os
import shutil
import sys
import time
import warnings
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

__all__ = ["run_sweep", "open_sweep", "sweep_features", "BACKENDS"]

BACKENDS = ("serial", "processes", "dask")


def _variables(spec: SweepSpec) -> dict[str, tuple[str, tuple[str, ...], int | None, str]]:
    """name -> (dtype, extra dims, extra size, units) for the requested measures."""
    v: dict[str, tuple[str, tuple[str, ...], int | None, str]] = {}
    m = spec.get_model().configured(spec.base)
    n = int(spec.settings["points"])
    per_time = "Hz" if m.time_unit == "s" else f"1/{m.time_unit}"
    if "poincare" in spec.measures or "verdict" in spec.measures:
        for k, u in m.sections():
            v[f"poincare_{k}"] = ("f8", ("section",), n, u)
        v["poincare_distinct"] = ("i8", (), None, "1")
    sig, sig_unit = m.vibration()
    if "features" in spec.measures:  # the vibration signal's features (recipdyn features)
        from ..features import feature_units

        for name, unit in feature_units(sig_unit, orders=m.kind == "ode" and bool(
                m.period(m.parameters()))).items():  # fmt: skip
            v[f"feat_{name}"] = ("f8", (), None, unit)
    if "peak" in spec.measures or "spectrum" in spec.measures:
        v[f"peak_{sig}"] = ("f8", (), None, sig_unit)
        v[f"rms_{sig}"] = ("f8", (), None, sig_unit)
        for name, unit, *_ in m.validity_bounds:  # where the model holds (e.g. contact >= 0)
            v[f"min_{name}"] = ("f8", (), None, unit)
        for _out, name, unit in (*m.mean_signals, *m.max_signals):  # e.g. the contact fraction
            v[name] = ("f8", (), None, unit)
    if "spectrum" in spec.measures:
        v["peak_freq"] = ("f8", ("peak",), N_PEAKS, per_time)
        v["peak_amp"] = ("f8", ("peak",), N_PEAKS, sig_unit)
        v["forcing_hz"] = ("f8", (), None, per_time)  # the crank (forcing) frequency: orders
    if "lyapunov" in spec.measures or "verdict" in spec.measures:
        lam_unit = "1" if m.kind == "map" else ("1/s" if m.time_unit == "s" else per_time)
        v["lambda1"] = ("f8", (), None, lam_unit)
        v["lambda_sum"] = ("f8", (), None, lam_unit)
    if "verdict" in spec.measures:
        v["verdict"] = ("str", (), None, "")
    v["y_final"] = ("f8", ("state",), len(m.states(spec.base)), "")
    return v


def _create_store(path: Path, spec: SweepSpec) -> None:
    import zarr

    g = zarr.open_group(str(path), mode="w")
    dims = tuple(a.name for a in spec.axes)
    for a in spec.axes:
        arr = g.create_array(a.name, shape=(len(a.values),), dtype="f8", dimension_names=[a.name])
        arr[:] = np.asarray(a.values)
        arr.attrs.update({"units": spec.get_model().schema_for(spec.base)[a.name].unit or "1",
                          "scale": a.scale})  # fmt: skip
    one = (1,) * (len(dims) - 1) + (min(point_block(spec.n_points), spec.shape[-1]),)
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

#: Grids larger than this store blocks of [`POINT_BLOCK`][recipdyn.sweep.run.POINT_BLOCK] points
#: (along the last axis) per chunk instead of one point per chunk: Zarr spends ~0.5 ms on every
#: chunk it writes or reads and a file-system block of disk, so a 10^6-point map would otherwise
#: take 15 million files and cap the coordinator at ~60 points/s (benchmarks/bench_scaling.py).
BLOCK_ABOVE = 4096
POINT_BLOCK = 64


def point_block(n_points: int) -> int:
    """Points per chunk along the last grid axis (1 keeps every point in its own chunk, so a
    torn write can never touch a neighbour; with blocks, verification on resume finds the
    neighbours a torn chunk damaged and recomputes them)."""
    return POINT_BLOCK if n_points > BLOCK_ABOVE else 1


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


class StoreWriter:
    """Writes finished points to the store in batches: each run of consecutive points of a
    batch in one Zarr call per variable (Zarr writes the run's chunks concurrently), then the
    batch is read back and each point's checksum compared, and only then are the points marked
    done.

    Every Zarr call costs ~0.7 ms of synchronisation whatever it carries, and a point has ~15
    variables, so point by point the coordinator stored only ~30 points/s (measured:
    ``benchmarks/bench_scaling.py``): a ceiling on any cluster. A batch is flushed when
    ``max_batch`` points wait or ``max_wait`` seconds have passed since the last flush, and on
    every interruption, so at most that much finished work sits in memory; ``on_stored`` is
    called for each point once it is stored and verified.
    """

    def __init__(self, g, spec: SweepSpec, *, max_batch: int = 1, max_wait: float = 0.5,
                 on_stored: Callable[[dict[str, Any]], None] | None = None) -> None:  # fmt: skip
        self.spec = spec
        self.vars = _variables(spec)
        self.arrays = {name: g[name] for name in (*self.vars, "error", "checksum", "done")}
        self.max_batch, self.max_wait = max(1, int(max_batch)), float(max_wait)
        self.on_stored = on_stored
        self.buffer: list[dict[str, Any]] = []
        self.clobbered: list[tuple] = []
        self.last = time.monotonic()

    def add(self, res: dict[str, Any]) -> None:
        self.buffer.append(res)
        if len(self.buffer) >= self.max_batch or time.monotonic() - self.last >= self.max_wait:
            self.flush()

    def _runs(self, batch: list[dict[str, Any]]) -> list[tuple[tuple, int, int, list]]:
        """The batch as runs of consecutive points along the last axis: ``(lead, start,
        stop, results)``. Points finish roughly in grid order, so a batch makes few runs, and a
        run is written with one Zarr call per variable (its chunks concurrently)."""
        runs: list[tuple[tuple, int, int, list]] = []
        for r in sorted(batch, key=lambda r: tuple(r["index"])):
            idx = tuple(r["index"])
            lead, k = idx[:-1], idx[-1]
            if runs and runs[-1][0] == lead and runs[-1][2] == k:
                lead0, start, _stop, rs = runs[-1]
                runs[-1] = (lead0, start, k + 1, [*rs, r])
            else:
                runs.append((lead, k, k + 1, [r]))
        return runs

    def _put(self, name: str, lead: tuple, start: int, stop: int, vals: np.ndarray) -> None:
        arr = self.arrays[name]
        try:
            arr[(*lead, slice(start, stop))] = vals
        except Exception:  # a chunk the write must merge into is unreadable: rewrite it whole
            cb = arr.chunks[len(lead)]
            lo, hi = start // cb * cb, min(-(-stop // cb) * cb, arr.shape[len(lead)])
            fill = {"error": "", "checksum": -1, "done": False}.get(name)
            fill = _FILL[self.vars[name][0]] if fill is None else fill
            full = np.full((hi - lo, *vals.shape[1:]), fill, dtype=vals.dtype)
            full[start - lo : stop - lo] = vals
            arr[(*lead, slice(lo, hi))] = full
            for k in (*range(lo, start), *range(stop, hi)):  # neighbours lost with the chunk
                self.clobbered.append((*lead, k))

    def flush(self) -> None:
        # emptied first: a callback that raises cannot make a second flush write it again
        batch, self.buffer = self.buffer, []
        self.last = time.monotonic()
        if not batch:
            return
        runs = self._runs(batch)
        for lead, start, stop, rs in runs:
            for name, (dtype, extra, size, _u) in self.vars.items():
                shape = (size,) if extra else ()
                kind = str if dtype == "str" else dtype
                vals = np.stack(
                    [
                        np.broadcast_to(np.asarray(r.get(name, _FILL[dtype]), dtype=kind), shape)
                        for r in rs
                    ]
                )
                self._put(name, lead, start, stop, vals)
            self._put("error", lead, start, stop, np.array([r["error"] for r in rs], dtype=str))
            crc = np.array([_checksum(self.spec, r) for r in rs], dtype=np.int64)
            self._put("checksum", lead, start, stop, crc)
        for lead, start, stop, rs in runs:  # read back and verify
            region = (*lead, slice(start, stop))
            back = {name: self.arrays[name][region] for name in (*self.vars, "error")}
            for j, r in enumerate(rs):
                if _checksum(self.spec, {k: v[j] for k, v in back.items()}) != _checksum(
                    self.spec, r
                ):  # pragma: no cover - disk fault
                    raise OSError(f"sweep point {tuple(r['index'])} did not read back as written")
        # last: a point counts as done only once its data verify
        for lead, start, stop, _rs in runs:
            self._put("done", lead, start, stop, np.ones(stop - start, dtype=bool))
        for idx in self.clobbered:  # pragma: no cover - needs a chunk corrupted mid-run
            self.arrays["done"][idx] = False
        self.clobbered = []
        if self.on_stored is not None:
            for r in batch:
                self.on_stored(r)


def _verified_done(g, spec: SweepSpec) -> tuple[np.ndarray, int]:
    """``done`` after re-checking every point marked done; returns (done, n_rejected).

    Read slab by slab (rows of the first axis, ~4096 points at a time: one Zarr call per
    variable, not per point); a slab with an unreadable chunk is re-checked point by point, so
    one torn chunk does not hide the others."""
    done = np.zeros(spec.shape, dtype=bool)
    try:
        marked = np.asarray(g["done"][...], dtype=bool)
    except Exception:  # a torn 'done' chunk: look at every point
        marked = None
    names = (*_variables(spec), "error", "checksum")
    arrays = {name: g[name] for name in names}
    row = int(np.prod(spec.shape[1:], dtype=np.int64))
    slab = max(1, 4096 // max(1, row))
    bad: list[tuple] = []
    for i0 in range(0, spec.shape[0], slab):
        rows = slice(i0, min(i0 + slab, spec.shape[0]))
        idxs = [i for i in np.ndindex(*spec.shape) if rows.start <= i[0] < rows.stop]
        if marked is not None:
            idxs = [i for i in idxs if marked[i]]
        if not idxs:
            continue
        try:
            data = {name: a[rows] for name, a in arrays.items()}
        except Exception:  # an unreadable chunk in this slab: point by point
            data = None
        for idx in idxs:
            local = (idx[0] - i0, *idx[1:])
            try:
                if data is None:
                    point = _read_point(g, spec, idx)
                    crc = int(arrays["checksum"][idx])
                else:
                    point = {name: data[name][local] for name in names if name != "checksum"}
                    crc = int(data["checksum"][local])
                ok = _checksum(spec, point) == crc
                if ok and marked is None:
                    ok = bool(g["done"][idx])
            except Exception:  # unreadable (truncated, corrupted) chunk
                ok = False
            done[idx] = ok
            if not ok and (marked is None or marked[idx]):
                bad.append(idx)
    rejected = 0
    for idx in bad:
        try:
            if marked is None and not bool(g["done"][idx]):
                continue  # never finished: not a rejection
        except Exception:
            pass
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
        with warnings.catch_warnings():  # a store of an older version has no consolidated
            warnings.filterwarnings(
                "ignore", "Failed to open Zarr store with consolidated", RuntimeWarning
            )  # metadata: read it array by array
            ds = xr.open_zarr(str(path))
    except Exception as exc:
        raise ParameterError(f"{path}: cannot be read as Zarr ({type(exc).__name__}); "
                             f"expected {expected}") from None  # fmt: skip
    if "spec_json" not in ds.attrs or "done" not in ds:
        raise ParameterError(f"{path}: not a recipdyn sweep store; expected {expected}")
    return ds


def sweep_features(path: str | Path, meta: dict | None = None) -> list[dict[str, Any]]:
    """One row per computed point of a sweep store: its parameter values and every scalar
    measure (vector measures such as section points are left out); with the sweep measure
    ``features``, the vibration signal's features of each point (``feat_*``). Columns: the
    parameters, then the measures by name."""
    from ..features import COLUMN_DESCRIPTIONS

    ds = open_sweep(path)
    grid = [d for d in ds["done"].dims]
    scalar = sorted(k for k, v in ds.data_vars.items()
                    if tuple(v.dims) == tuple(grid) and k != "done")  # fmt: skip
    if meta is not None:
        meta.setdefault("store", {"unit": "", "description": COLUMN_DESCRIPTIONS["store"],
                                  "note": ""})  # fmt: skip
        for k in grid + scalar:
            a = ds[k].attrs
            entry = {"unit": str(a.get("units", "")), "note": "",
                     "description": str(a.get("long_name", ""))}  # fmt: skip
            meta.setdefault(k, entry)
    frame = ds[scalar + ["done"]].to_dataframe().reset_index()
    frame = frame[frame["done"].astype(bool)].drop(columns=["done"])
    return frame[grid + scalar].to_dict("records")


def consolidate(store: str | Path) -> None:
    """Write the store's consolidated metadata (every array's metadata in the group's own
    file), so that ``xr.open_zarr`` opens it in one read and without a warning. Done when the
    store is created and when a run ends; the chunks are not part of it, so points written in
    between are read as usual, and a resumed run reads each array's own metadata."""
    import zarr

    with warnings.catch_warnings():  # zarr: consolidated metadata is not in the v3 spec yet
        warnings.simplefilter("ignore")
        zarr.consolidate_metadata(str(store))


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

    Raises [`ParameterError`][recipdyn.errors.ParameterError] for bad settings, an existing store
    without ``resume``/``force``, a store made by a different spec, or an output folder in use
    by another run; [`Interrupted`][recipdyn.errors.Interrupted] on SIGINT/SIGTERM (points finished
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


#: Disk used by one chunk file at least (one file-system block).
_BYTES_PER_CHUNK = 4096


def _check_resources(spec: SweepSpec, out: Path, backend, workers, dask_local,
                     max_memory) -> None:  # fmt: skip
    """Refuse a sweep whose points cannot fit in memory together, or whose store cannot fit."""
    from ..resources import check_memory
    from ..simulate import estimate_memory

    s = spec.settings
    if {"peak", "spectrum", "features"} & set(spec.measures):
        m = spec.get_model()
        periods = []
        for _, p in _corners(spec):
            pp = spec.point_params(p)
            periods.append(m.period(pp) or 1.0)
        samples = s.get("revolutions", 5.0) * max(periods) * s.get("fs", 1e4)
        n_par = 1 if backend == "serial" or spec.continuation else (
            dask_local or workers or os.cpu_count() or 1)  # fmt: skip
        check_memory(n_par * estimate_memory(samples),
                     f"sweep ({n_par} point(s) at once, {samples:.3g} samples each)",
                     "reduce --revolutions, --fs or --workers", max_memory)  # fmt: skip
    variables = _variables(spec)
    n_chunks = -(-spec.n_points // min(point_block(spec.n_points), spec.shape[-1]))
    data = spec.n_points * sum(8 * (size or 1) for _d, _e, size, _u in variables.values())
    need = n_chunks * (len(variables) + 3) * _BYTES_PER_CHUNK + data
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
        try:  # each array's own metadata, not the consolidated copy
            g = zarr.open_group(str(store), mode="a", use_consolidated=False)
            digest = g.attrs.get("spec_digest")
        except Exception as exc:
            raise ParameterError(f"{store} cannot be opened as a sweep store ({exc}); "
                                 "use --force to start over") from None  # fmt: skip
        if digest != spec.digest:
            raise ParameterError(f"{store} was made with a different sweep spec; "
                                 "refusing to resume (use --force to start over)")  # fmt: skip
        stored = set(g.array_keys())
        differ = sorted(name for name, (_d, extra, size, _u) in _variables(spec).items()
                        if name not in stored
                        or g[name].shape != spec.shape + ((size,) if extra else ()))  # fmt: skip
        if differ:
            raise ParameterError(f"{store} lacks the variable(s) {', '.join(differ)} in the "
                                 "layout this version of recipdyn stores for the same spec (it "
                                 "was made by an older version); refusing to resume (use "
                                 "--force to start over)")  # fmt: skip
        done, rejected = _verified_done(g, spec)
    else:
        if store.exists():
            shutil.rmtree(store)
        _create_store(store, spec)
        consolidate(store)
        g = zarr.open_group(str(store), mode="a", use_consolidated=False)
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

    def stored(res):
        nonlocal failed, written
        written += 1
        failed += bool(res["error"])
        if on_point is not None:
            on_point(res)
        if bar is not None:
            bar.update(1)
            bar.set_postfix(failed=failed)

    sequential = spec.continuation or backend == "serial"
    writer = StoreWriter(g, spec, max_batch=1 if sequential else WRITE_BATCH, on_stored=stored)
    accept = writer.add
    try:
        with deferred_signals() as signals:
            pending = _Ticking(signals, writer)
            if sequential:
                for task in _tasks(spec, todo):
                    pending.check()
                    if spec.continuation and y0 is not None:
                        task["y0"] = y0
                    res = run_point(task)
                    accept(res)
                    if spec.continuation:
                        y0 = None if res["error"] else res["y_final"]
            elif backend == "processes":
                _run_processes(_tasks(spec, todo), workers, accept, pending)
            else:
                _run_dask(_tasks(spec, todo), len(todo), dask_local, scheduler, workers, accept,
                          pending, progress)  # fmt: skip
            writer.flush()
            pending.check()
    except (KeyboardInterrupt, Interrupted) as exc:
        try:  # the finished points waiting in the batch are kept too
            writer.flush()
        except KeyboardInterrupt:  # pragma: no cover - a second Ctrl-C while writing
            pass
        intr = Interrupted.wrap(exc)
        intr.kept.append(f"{n_skip + written} of {n_total} sweep points ({written} new) in "
                         f"{store}; rerun the same command with --resume to finish")  # fmt: skip
        raise intr from None
    finally:
        if bar is not None:
            bar.close()
    g.attrs["last_run_seconds"] = time.perf_counter() - t0
    consolidate(store)
    if progress:
        print(f"sweep: {n_total - n_skip} computed ({failed} failed), {n_skip} reused, "
              f"{time.perf_counter() - t0:.1f} s -> {store}")  # fmt: skip
    return store


#: Most finished points written in one batch by the parallel backends (see StoreWriter).
WRITE_BATCH = 256


class _Ticking:
    """``pending.check()`` that also writes a waiting batch once it is old enough, so finished
    points never wait in memory for the next result to arrive."""

    def __init__(self, pending, writer: StoreWriter) -> None:
        self.pending, self.writer = pending, writer

    def check(self) -> None:
        w = self.writer
        if w.buffer and time.monotonic() - w.last >= w.max_wait:
            w.flush()
        self.pending.check()


def _run_processes(tasks, workers, accept, pending) -> None:
    run_unordered(run_point, tasks, workers or os.cpu_count() or 1, accept, pending)


#: Dask tasks in flight per worker: enough to keep every worker busy while results travel,
#: few enough that a 10^6-point map never sits in the scheduler's memory at once.
DASK_IN_FLIGHT = 2
#: Most points one Dask task carries (see [`dask_batch_size`][recipdyn.sweep.run.dask_batch_size]).
DASK_MAX_BATCH = 32


def dask_batch_size(n_points: int, n_workers: int) -> int:
    """Points per Dask task: ~8 tasks a worker over the sweep (so the last wave is short), at
    most `DASK_MAX_BATCH`. The scheduler costs ~1 ms a task; a point costs 0.1-10 s, so
    batching matters only for very many short points, where it divides that cost."""
    return max(1, min(DASK_MAX_BATCH, n_points // (8 * max(1, n_workers))))


def _run_dask(tasks, n_tasks, dask_local, scheduler, workers, accept, pending,
              progress=False) -> None:  # fmt: skip
    import itertools

    from dask.distributed import Client, LocalCluster, as_completed

    from .work import run_points

    cluster = None
    if scheduler:
        client = Client(scheduler)
        n_workers = max(1, len(client.scheduler_info().get("workers", {})))
    else:
        n_workers = dask_local or workers or os.cpu_count() or 1
        t0 = time.perf_counter()
        cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)  # fmt: skip
        client = Client(cluster)
        if progress:  # ~2 s a run: say so (a running cluster, --scheduler, does not pay it)
            print(f"sweep: Dask LocalCluster of {n_workers} workers started in "
                  f"{time.perf_counter() - t0:.1f} s", file=sys.stderr)  # fmt: skip
    size = dask_batch_size(n_tasks, n_workers)
    batches = iter(lambda: list(itertools.islice(tasks, size)), [])
    running = as_completed()
    n_running = 0
    try:
        while True:
            while n_running < DASK_IN_FLIGHT * n_workers:
                batch = next(batches, None)
                if batch is None:
                    break
                running.add(client.submit(run_points, batch, pure=False))
                n_running += 1
            if n_running == 0:
                break
            done = running.next_batch(block=False)
            for fut in done:
                n_running -= 1
                for res in fut.result():
                    accept(res)
            if not done:
                time.sleep(0.02)
            pending.check()
    finally:
        if n_running:
            client.cancel(list(running.futures))
        client.close()
        if cluster is not None:
            cluster.close()
