"""Parameter sweeps (bifurcation diagrams, fault maps) on serial, process or Dask backends."""

from .plots import sweep_figures
from .run import BACKENDS, open_sweep, run_sweep
from .spec import MEASURES, Axis, SweepSpec, parse_axis
from .work import run_point

__all__ = [
    "BACKENDS", "MEASURES", "Axis", "SweepSpec", "parse_axis", "run_point", "run_sweep",
    "open_sweep", "sweep_figures",
]  # fmt: skip
