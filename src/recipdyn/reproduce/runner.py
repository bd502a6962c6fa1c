"""Compute the paper's cases, in parallel, with an on-disk cache.

A *run* is one case (a parameter set of the paper) under one *variant* (which equations, which
load sign, which initial clearance angle). Its result is a compressed NetCDF file in
``OUT/cache/`` named by a hash of every input and the recipdyn version, so re-running reuses
finished runs unless ``force``. Runs are independent and go to a process pool.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import xarray as xr

from .. import __version__
from ..defaults import ATOL, RTOL
from ..errors import Interrupted, deferred_signals
from ..io import remove_orphans
from ..model.parameters import CompressorParams
from ..parallel import run_unordered
from .cases import Case

__all__ = ["Variant", "VARIANTS", "RunSpec", "run_all", "Settings"]


@dataclass(frozen=True)
class Variant:
    """How a case is run: equations, load sign and initial clearance-angle offset (rad)."""

    id: str
    equations: str
    load_sign: str
    theta_c_offset: float
    label: str


VARIANTS: tuple[Variant, ...] = (
    Variant("natural", "exact", "physical", 0.0,
            "exact equations, physical load sign, link at its static equilibrium (natural start)"),
    Variant("offset", "exact", "physical", 0.2,
            "exact equations, physical load sign, initial link offset 0.2 rad"),
    Variant("printed", "paper-printed", "paper", 0.2,
            "paper's printed Eq. (43)-(47), paper's load sign, initial link offset 0.2 rad"),
)  # fmt: skip


@dataclass(frozen=True)
class Settings:
    """Simulation and analysis settings shared by all runs (recorded in the report)."""

    revolutions: float = 10.0
    fs: float = 10_000.0
    rtol: float = RTOL
    atol: float = ATOL
    poincare_points: int = 200
    lyap_revolutions: float = 100.0
    wolf_samples: int = 20_000

    def quick(self) -> Settings:
        """Reduced lengths for tests and smoke runs."""
        return dataclasses.replace(
            self, revolutions=3.0, fs=5000.0, poincare_points=30, lyap_revolutions=10.0,
            wolf_samples=3000,
        )  # fmt: skip


@dataclass(frozen=True)
class RunSpec:
    case: Case
    variant: Variant
    settings: Settings

    @property
    def params(self) -> CompressorParams:
        return CompressorParams(
            rc=self.case.rc, d=self.case.d, omega=self.case.omega,
            equations=self.variant.equations, load_sign=self.variant.load_sign,
            theta_c_offset=self.variant.theta_c_offset,
        )  # fmt: skip

    @property
    def key(self) -> str:
        blob = json.dumps(
            [dataclasses.asdict(self.params), dataclasses.asdict(self.settings), __version__],
            sort_keys=True, default=str,
        )  # fmt: skip
        digest = hashlib.sha256(blob.encode()).hexdigest()[:16]
        return f"{self.case.id}__{self.variant.id}__{digest}"


def _compute(spec: RunSpec, path: str) -> str:
    """Worker: simulate, measure, write the result file atomically; returns its path."""
    from ..io import atomic_path
    from .measures import measure_run

    ds = measure_run(spec)
    enc = {k: {"zlib": True, "complevel": 4} for k in ds.data_vars}
    with atomic_path(path) as tmp:  # an interrupted run never leaves a half-written result
        ds.to_netcdf(tmp, encoding=enc)
    return path


def _compute_task(task: tuple[RunSpec, str]) -> str:
    """Pool entry point: compute one run; returns its key."""
    spec, path = task
    _compute(spec, path)
    return spec.key


def _load(path: Path) -> xr.Dataset | None:
    """A cached run, fully read; ``None`` if the file is unreadable (truncated, corrupted)."""
    try:
        with xr.open_dataset(path) as ds:
            out = ds.load()
    except Exception:
        return None
    return out


def run_all(
    specs: Iterable[RunSpec],
    cache: Path,
    *,
    jobs: int | None = None,
    force: bool = False,
    progress: Callable[[str, bool], None] | None = None,
) -> dict[tuple[str, str], xr.Dataset]:
    """Compute (or load from ``cache``) every run; returns ``{(case_id, variant_id): ds}``.

    ``progress(key, cached)`` is called as each run completes. A cache file that cannot be read
    back (truncated by a crash, corrupted) is recomputed, never used. On SIGINT/SIGTERM the runs
    finished so far stay in the cache and [`Interrupted`][recipdyn.errors.Interrupted] says so.
    """
    cache.mkdir(parents=True, exist_ok=True)
    remove_orphans(cache)  # left by a run killed outright (kill -9, power loss)
    specs = list(specs)
    todo = []
    out: dict[tuple[str, str], xr.Dataset] = {}
    for s in specs:
        path = cache / f"{s.key}.nc"
        ds = None if (force or not path.exists()) else _load(path)
        if ds is None:
            todo.append((s, str(path)))
        else:
            out[(s.case.id, s.variant.id)] = ds
            if progress is not None:
                progress(s.key, True)
    jobs = jobs or os.cpu_count() or 1
    done = 0

    def finished(key: str) -> None:
        nonlocal done
        done += 1
        if progress is not None:
            progress(key, False)

    try:
        with deferred_signals() as pending:
            if jobs == 1:
                for task in todo:
                    pending.check()
                    finished(_compute_task(task))
                pending.check()
            elif todo:
                run_unordered(_compute_task, todo, jobs, finished, pending)
    except (KeyboardInterrupt, Interrupted) as exc:
        remove_orphans(cache)  # results the terminated workers were writing
        intr = Interrupted.wrap(exc)
        intr.kept.append(f"{len(specs) - len(todo) + done} of {len(specs)} runs in {cache} "
                         "(rerun the same command: cached runs are reused)")  # fmt: skip
        raise intr from None
    for s, p in todo:
        ds = _load(Path(p))
        if ds is None:
            raise OSError(f"run {s.key} did not read back from {p}")
        out[(s.case.id, s.variant.id)] = ds
    return {(s.case.id, s.variant.id): out[(s.case.id, s.variant.id)] for s in specs}
