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
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .. import __version__
from ..model.parameters import CompressorParams
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
    rtol: float = 1e-9
    atol: float = 1e-12
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
    """Worker: simulate, measure, write the result file; returns its path."""
    from .measures import measure_run

    ds = measure_run(spec)
    tmp = path + ".part"
    enc = {k: {"zlib": True, "complevel": 4} for k in ds.data_vars}
    ds.to_netcdf(tmp, encoding=enc)
    os.replace(tmp, path)  # atomic: an interrupted run never leaves a half-written result
    return path


def run_all(
    specs: Iterable[RunSpec],
    cache: Path,
    *,
    jobs: int | None = None,
    force: bool = False,
    progress: Callable[[str, bool], None] | None = None,
) -> dict[tuple[str, str], xr.Dataset]:
    """Compute (or load from ``cache``) every run; returns ``{(case_id, variant_id): ds}``.

    ``progress(key, cached)`` is called as each run completes.
    """
    cache.mkdir(parents=True, exist_ok=True)
    specs = list(specs)
    todo = []
    for s in specs:
        path = cache / f"{s.key}.nc"
        if force or not path.exists():
            todo.append((s, str(path)))
        elif progress is not None:
            progress(s.key, True)
    jobs = jobs or os.cpu_count() or 1
    if todo:
        if jobs == 1:
            for s, p in todo:
                _compute(s, p)
                if progress is not None:
                    progress(s.key, False)
        else:
            with ProcessPoolExecutor(max_workers=jobs) as pool:
                futs = {pool.submit(_compute, s, p): s for s, p in todo}
                for fut in as_completed(futs):
                    fut.result()
                    if progress is not None:
                        progress(futs[fut].key, False)
    out: dict[tuple[str, str], xr.Dataset] = {}
    for s in specs:
        with xr.open_dataset(cache / f"{s.key}.nc") as ds:
            out[(s.case.id, s.variant.id)] = ds.load()
    return out


def summary_of(ds: xr.Dataset) -> dict[str, Any]:
    """The scalar measures stored in a run's attributes (``m_*``)."""
    return {k[2:]: v for k, v in ds.attrs.items() if k.startswith("m_")}


def as_float(x: Any) -> float:
    try:
        return float(np.asarray(x).item())
    except (TypeError, ValueError):
        return float("nan")
