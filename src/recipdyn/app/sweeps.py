"""The sweep browser: a store's fault map (2-D) or bifurcation diagram (1-D), its axes in the
form's display units, and the sweep point under a click."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..model.registry import DEFAULT_MODEL, configured_for_record, get_model
from .figures import below_toolbar
from .form import _factor, display_unit

__all__ = ["sweep_figure", "point_from_click", "log_ticks"]


def _open(store: str | Path):
    from ..sweep.run import open_sweep

    path = Path(store)
    if path.is_dir() and (path / "sweep.zarr").is_dir():
        path = path / "sweep.zarr"
    if not path.is_dir():
        raise ParameterError(f"store {store}: not found (a sweep folder or its sweep.zarr)")
    return open_sweep(path)


def _model(ds):
    m = get_model(str(ds.attrs.get("model_spec") or ds.attrs.get("model") or DEFAULT_MODEL))
    return configured_for_record(m, ds.attrs)


def _axis_unit(ds, dim: str) -> tuple[str, float]:
    """(display unit, SI value of one display unit) of a swept parameter."""
    m = _model(ds)
    si = ds[dim].attrs.get("units", "")
    si = "" if si == "1" else si
    if dim in m.schema:
        unit = display_unit(m.schema[dim])
        return unit, _factor(unit, si)
    return si, 1.0


def log_ticks(lo: float, hi: float) -> list[float]:
    """Tick values for a log axis over ``[lo, hi]`` (> 0): 1-2-5 per decade when the range
    spans less than three decades, powers of ten otherwise; always at least the two ends.
    Plotly's own log ticks over one decade label the minor ticks with single digits in a
    small font (``2``, ``5``) between full labels, which cannot be read as values."""
    lo, hi = min(lo, hi), max(lo, hi)
    if not (lo > 0 and math.isfinite(hi)):
        return []
    steps = (1.0, 2.0, 5.0) if math.log10(hi / lo) < 3 else (1.0,)
    ticks = [m * 10.0**e for e in range(math.floor(math.log10(lo)), math.ceil(math.log10(hi))
             + 1) for m in steps]  # fmt: skip
    ticks = [t for t in ticks if lo * (1 - 1e-9) <= t <= hi * (1 + 1e-9)]
    if len(ticks) < 2:
        ticks = sorted({lo, *ticks, hi})
    return ticks


def _axis(ds, dim: str) -> tuple[np.ndarray, dict]:
    """The grid of ``dim`` in its display unit and the Plotly axis settings."""
    unit, f = _axis_unit(ds, dim)
    x = ds[dim].values / f
    axis: dict[str, Any] = dict(title=f"{dim} ({unit})" if unit else dim)
    if ds[dim].attrs.get("scale") == "log" and np.all(x > 0):
        ticks = log_ticks(float(x.min()), float(x.max()))
        axis.update(type="log", tickmode="array", tickvals=ticks,
                    ticktext=[f"{t:g}" for t in ticks], minor=dict(showgrid=False))  # fmt: skip
    return x, axis


def sweep_figure(store: str | Path, variable: str | None = None) -> tuple[Any, list[str], str]:
    """The sweep's map (2-D: a heat map of ``variable``) or bifurcation diagram (1-D); returns
    ``(figure, variables that can be shown, the variable shown)``."""
    import plotly.graph_objects as go

    ds = _open(store)
    dims = ds.attrs["sweep_axes"].split(",")
    done = ds["done"].values.astype(bool)
    if len(dims) == 2:
        skip = ("done", "checksum", "error")
        options = [
            k for k in ds.data_vars
            if ds[k].dims == tuple(dims) and k not in skip and ds[k].dtype.kind == "f"
        ]  # fmt: skip
        if not options:
            raise ParameterError(f"store {store}: no map variable")
        # a stable order whatever the store lists first: exponent, peaks, RMS, the rest
        rank = ("lambda1", "peak_", "rms_", "min_")
        options.sort(key=lambda k: (next((i for i, r in enumerate(rank) if k.startswith(r)),
                                         len(rank)), k))  # fmt: skip
        variable = variable if variable in options else options[0]
        z = np.where(done, ds[variable].values, np.nan)
        (x, xaxis), (y, yaxis) = _axis(ds, dims[1]), _axis(ds, dims[0])
        units = ds[variable].attrs.get("units", "")
        fig = go.Figure(go.Heatmap(x=x, y=y, z=z, colorbar=dict(
            title=f"{variable} ({units})" if units not in ("", "1") else variable)))  # fmt: skip
        fig.update_layout(xaxis=xaxis, yaxis=yaxis,
                          title=f"fault map: {variable} (click a cell to simulate it)")  # fmt: skip
        return below_toolbar(fig), options, variable
    dim = dims[0]
    options = [k for k in ds.data_vars if k.startswith("poincare_") and ds[k].ndim == 2]
    if not options:
        raise ParameterError(f"store {store}: a 1-D sweep without a Poincaré section")
    variable = variable if variable in options else options[0]
    grid, xaxis = _axis(ds, dim)
    x = np.repeat(grid[:, None], ds[variable].shape[1], axis=1)[done].ravel()
    y = ds[variable].values[done].ravel()
    fig = go.Figure(go.Scattergl(x=x, y=y, mode="markers", marker=dict(size=2, color="black")))
    fig.update_layout(title=f"bifurcation diagram: {variable} (click a value to simulate it)",
                      xaxis=xaxis, yaxis_title=variable)  # fmt: skip
    return below_toolbar(fig), options, variable


def point_from_click(store: str | Path, click: dict) -> tuple[str, dict[str, Any]]:
    """``(model name, parameter values in SI)`` of the sweep point under a Plotly click: the
    store's base case with the swept parameters at the nearest grid values (the click is in
    the figure's display units)."""
    ds = _open(store)
    m = _model(ds)
    dims = ds.attrs["sweep_axes"].split(",")
    pt = (click or {}).get("points", [{}])[0]
    if "x" not in pt:
        raise ParameterError("click: no point")
    coords = {dims[-1]: pt["x"]} if len(dims) == 1 else {dims[1]: pt["x"], dims[0]: pt["y"]}
    base = m.values_from_record(ds.attrs)
    for dim, val in coords.items():
        grid = ds[dim].values
        shown = grid / _axis_unit(ds, dim)[1]
        base[dim] = float(grid[np.argmin(np.abs(shown - float(val)))])
    return m.name, base
