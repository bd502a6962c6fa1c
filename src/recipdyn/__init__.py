"""recipdyn: nonlinear dynamics of reciprocating compressors with joint faults.

Quick start::

    import recipdyn
    ds = recipdyn.simulate(rc=1e-3, d=1e-3, omega=20.0, revolutions=5)
    ds.a.plot()

The names below are imported on first use (PEP 562), so ``import recipdyn`` and the command
line start without loading numba, SciPy or xarray until a command needs them.
"""

from __future__ import annotations

import importlib
import os
import sys
import types

from .resources import cache_dir as _cache_dir


def _source_fingerprint(root: str | None = None) -> str:
    """A hash of every module's path, size and modification time (of this package, or of the
    package folder ``root``). numba invalidates a cached function when its own file changes,
    but not when a function it calls (and inlined) from another file does, which let stale
    machine code run after an edit or an upgrade; one cache folder per state of the sources
    rules that out (~1 ms at import)."""
    import hashlib

    h = hashlib.sha1()
    root = root or os.path.dirname(os.path.abspath(__file__))
    for dirpath, dirnames, files in os.walk(root):
        dirnames[:] = sorted(d for d in dirnames if d != "__pycache__")
        for f in sorted(files):
            if f.endswith(".py"):
                st = os.stat(os.path.join(dirpath, f))
                h.update(f"{dirpath}/{f}:{st.st_size}:{st.st_mtime_ns};".encode())
    return h.hexdigest()[:16]


# numba keeps compiled code in the user's cache directory, not the package folder, one folder
# per state of the sources. It reads NUMBA_CACHE_DIR when it is first imported; an explicit
# setting wins.
os.environ.setdefault("NUMBA_CACHE_DIR",
                      os.path.join(_cache_dir(), "numba", _source_fingerprint()))  # fmt: skip
if "numba.core.config" in sys.modules:  # numba came first (a script, a test module): it reads
    sys.modules["numba.core.config"].reload_config()  # the variable again only when compiling

_LAZY = {
    "simulate": "simulate",
    "integrate": "integrate",
    "propagate": "integrate",
    "IntegrationError": "integrate",
    "CompressorParams": "model",
    "paper_2d12": "model",
    "compressor_model": "model",
    "ODESystem": "model",
    "DiscreteMap": "model",
    "ParameterError": "model",
    "ASSUMED": "model",
    # the rest of the public API, as the tutorials (examples/notebooks) use it
    "get_model": "model.registry",
    "model_names": "model.registry",
    "analyze_signal": "analyze",
    "diagnose": "diagnosis",
    "diagnose_arrays": "diagnosis",
    "DatasetSpec": "diagnosis",
    "build_dataset": "diagnosis",
    "dataset_record": "diagnosis",
    "train_diagnoser": "diagnosis",
    "load_diagnoser": "diagnosis",
    "SweepSpec": "sweep",
    "parse_axis": "sweep",
    "run_sweep": "sweep",
    "open_sweep": "sweep",
    "sweep_figures": "sweep",
    "amplitude_spectrum": "analysis",
    "lyapunov_spectrum": "analysis",
    "model_figure": "plotting",
    "response_figure": "plotting",
    "cycle_figure": "plotting",
    "PAPER_VALUES": "reproduce",
}

__all__ = ["__version__", *_LAZY]


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("recipdyn")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        return "0+unknown"


def __getattr__(name: str):
    if name == "__version__":  # importlib.metadata costs ~40 ms: only when asked for
        globals()[name] = value = _version()
        return value
    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value  # later lookups skip this hook
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


class _Package(types.ModuleType):
    """``recipdyn.simulate`` and ``recipdyn.integrate`` are the functions, as before lazy
    loading: the import system would otherwise bind the submodules of the same names here when
    they are first imported (the submodules stay importable by name)."""

    def __setattr__(self, name: str, value) -> None:
        if name in ("simulate", "integrate") and isinstance(value, types.ModuleType):
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
