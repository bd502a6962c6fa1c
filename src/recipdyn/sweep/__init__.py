"""Parameter sweeps (bifurcation diagrams, fault maps) on serial, process or Dask backends.

The names below are imported from their modules when first asked for, so that the command
line can check a sweep's options with `recipdyn.sweep.spec` alone, before the machinery
(numba, xarray, zarr, the plots) loads."""

from importlib import import_module
from typing import Any

__all__ = [
    "BACKENDS", "MEASURES", "Axis", "SweepSpec", "parse_axis", "run_point", "run_sweep",
    "open_sweep", "sweep_figures",
]  # fmt: skip

#: Where each public name lives.
_MODULES = {"sweep_figures": "plots", "BACKENDS": "run", "open_sweep": "run",
            "run_sweep": "run", "MEASURES": "spec", "Axis": "spec", "SweepSpec": "spec",
            "parse_axis": "spec", "run_point": "work"}  # fmt: skip


def __getattr__(name: str) -> Any:
    if name in _MODULES:
        value = getattr(import_module(f".{_MODULES[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
