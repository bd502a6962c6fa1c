"""Sweep figures: bifurcation diagram, lambda1 vs parameter, Campbell diagram, fault-map
heatmaps."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from ..io import save_figure
from ..plotting import _mpl, axis_label, unit_tex

__all__ = ["sweep_figures", "campbell_figure", "cell_edges", "wrap_around_mean", "thin_labels"]

_LABELS = {"rc": ("clearance rc", 1e3, "mm"), "d": ("subsidence d", 1e3, "mm"),
           "omega": ("crank speed omega", 1.0, "rad/s")}  # fmt: skip


def _axis(ds, name):
    label, k, unit = _LABELS.get(name, (name, 1.0, ds[name].attrs.get("units", "")))
    return ds[name].values * k, f"{label} ({unit})"


def cell_edges(centres, log: bool = False) -> np.ndarray:
    """Edges of the cells around grid values: midpoints between neighbours, geometric on a
    log axis (where arithmetic midpoints, as ``shading="nearest"`` takes, put each cell off
    its value and make the cells of a regular log grid unequal); the outer edges mirror the
    inner ones."""
    c = np.asarray(centres, dtype=float)
    if c.size == 1:
        return c * np.array([0.9, 1.1]) if log else c + np.array([-0.5, 0.5])
    u = np.log(c) if log else c
    mid = (u[1:] + u[:-1]) / 2
    edges = np.concatenate([[2 * u[0] - mid[0]], mid, [2 * u[-1] - mid[-1]]])
    return np.exp(edges) if log else edges


def _label_grid(axis, values) -> None:
    """Ticks at the grid values of a short log axis (a log axis spanning less than two decades
    otherwise shows one or two labelled ticks)."""
    if len(values) <= 12:
        from matplotlib.ticker import FixedLocator, NullLocator

        axis.set_major_locator(FixedLocator(values))
        axis.set_major_formatter(lambda v, _pos: f"{v:.3g}")
        axis.set_minor_locator(NullLocator())


def wrap_around_mean(angle) -> tuple[np.ndarray, float]:
    """Angles wrapped to one turn centred on their circular mean: a link that hangs near
    +-pi then shows as one band instead of two halves at the top and bottom of (-pi, pi]."""
    a = np.asarray(angle, dtype=float)
    fin = a[np.isfinite(a)]
    centre = float(np.angle(np.mean(np.exp(1j * fin)))) if fin.size else 0.0
    return centre + np.angle(np.exp(1j * (a - centre))), centre


def _store_model(ds):
    """The model a sweep store was made with (its spec: a plug-in model's file too), or None
    for one that is not available here."""
    from ..model.registry import DEFAULT_MODEL, configured_for_record, get_model

    try:
        return configured_for_record(get_model(str(ds.attrs.get("model_spec")
                                                   or ds.attrs.get("model") or DEFAULT_MODEL)),
                                     ds.attrs)  # fmt: skip
    except Exception:  # a store from a model that is not installed here
        return None


def _mark_invalid(ax, ds, x, y, done) -> None:
    """Mark the points where the model left its validity region (``min_<output>`` below the
    bound the model declares, e.g. a negative joint contact force): red crosses on a map, red
    bands on a curve, with a legend entry."""
    m = _store_model(ds)
    if m is None:
        return
    bounds = m.validity_bounds
    for name, unit, bound, *_ in bounds:
        var = f"min_{name}"
        if var not in ds:
            continue
        bad = done & (ds[var].values < bound)
        if not bad.any():
            continue
        label = f"{name} < {bound:g} {unit}: outside the model"
        if y is None:
            step = np.min(np.diff(x)) / 2 if x.size > 1 else 0.5
            for i, xi in enumerate(x[bad]):
                ax.axvspan(xi - step, xi + step, color="tab:red", alpha=0.15,
                           label=label if i == 0 else None)  # fmt: skip
        else:
            yy, xx = np.meshgrid(y, x, indexing="ij")
            ax.plot(xx[bad], yy[bad], "x", color="tab:red", ms=6, label=label)
        ax.legend(fontsize=7, loc="best")


def _run_signals(ds) -> list[tuple[str, str]]:
    """(variable, label) of the model's run means and maxima stored in ``ds`` (e.g. the time
    fraction in contact, the largest eccentricity ratio), skipping variables that are NaN
    everywhere (a joint that is not modelled)."""
    m = _store_model(ds)
    if m is None:
        return []
    out = []
    for _o, name, unit in (*m.mean_signals, *m.max_signals):
        if name in ds and np.isfinite(ds[name].values).any():
            label = name.replace("_", " ")
            out.append((name, f"{label} ({unit})" if unit not in ("", "1") else label))
    return out


def thin_labels(positions, gap: float) -> list[int]:
    """Indices of the ascending ``positions`` to label so that labelled neighbours are at least
    ``gap`` apart: the first is kept, then each next one that clears the last kept."""
    kept: list[int] = []
    for i, y in enumerate(positions):
        if not kept or y - positions[kept[-1]] >= gap:
            kept.append(i)
    return kept


def _label_gap(fig, ax, fontsize: float) -> float:
    """The data distance along ``ax``'s y axis that one line of text of ``fontsize`` points
    takes, with 20 % spacing; the axes' height is taken as 85 % of its position before the
    layout engine runs (the colour bar and labels take room from it)."""
    lo, hi = ax.get_ylim()
    height_pt = 0.85 * ax.get_position().height * fig.get_figheight() * 72
    return 1.2 * fontsize * (hi - lo) / max(height_pt, 1.0)


#: Orders of the forcing frequency drawn in the Campbell diagram (1x ... this).
MAX_ORDER_LINES = 10


def campbell_figure(ds: xr.Dataset, out: Path, plt=None) -> Path:
    """Campbell diagram of a 1-D sweep with ``--measure spectrum``: the strongest spectral lines
    of the vibration signal at each point over the swept parameter (marker colour and area by
    amplitude) and, for a forced model, the orders ``k * forcing_hz`` (dashed). Over the crank
    speed the orders are lines through the origin; a line that stays put while they fan out is
    a resonance, and lines between the orders are sub- or non-harmonic response."""
    plt = plt or _mpl()
    dim = ds.attrs["sweep_axes"].split(",")[0]
    x, xlabel = _axis(ds, dim)
    done = ds.done.values.astype(bool)
    f, a = ds.peak_freq.values[done], ds.peak_amp.values[done]
    xs = np.repeat(x[done][:, None], f.shape[1], axis=1)
    ok = np.isfinite(f) & np.isfinite(a) & (a > 0)
    fig, ax = plt.subplots(figsize=(8, 5), constrained_layout=True)
    if ok.any():
        big = a[ok].max()
        sc = ax.scatter(xs[ok], f[ok], c=np.log10(a[ok]), s=12 + 60 * a[ok] / big,
                        cmap="viridis", edgecolors="k", linewidths=0.3, zorder=3)  # fmt: skip
        unit = unit_tex(ds.peak_amp.attrs.get("units", ""))
        fig.colorbar(sc, ax=ax, label=f"log10 amplitude ({unit})" if unit else "log10 amplitude")
    fc = ds.forcing_hz.values[done] if "forcing_hz" in ds else np.full(done.sum(), np.nan)
    if np.isfinite(fc).any() and ok.any():
        top = np.nanmax(f[ok])
        ax.set_ylim(0, 1.05 * top)
        orders = range(1, min(MAX_ORDER_LINES, int(np.ceil(top / np.nanmin(fc)))) + 1)
        for k in orders:
            ax.plot(x[done], k * fc, "--", color="0.55", lw=0.7, zorder=1)
        # the labels beside the right edge (clear of the last point's markers), thinned so
        # that none covers the next (orders of a few hertz under a kHz line are a pixel apart)
        gap = _label_gap(fig, ax, fontsize=7)
        ends = [k * fc[-1] for k in orders if k * fc[-1] <= ax.get_ylim()[1]]  # in view
        for k in thin_labels(ends, gap):
            ax.annotate(f"{k + 1}\u00d7", (1.0, (k + 1) * fc[-1]), xycoords=("axes fraction",
                        "data"), fontsize=7, color="0.4", xytext=(3, 0),
                        textcoords="offset points", va="center", annotation_clip=False)  # fmt: skip
    ax.set_xlabel(xlabel)
    ax.set_ylabel(f"frequency ({unit_tex(ds.peak_freq.attrs.get('units', 'Hz'))})")
    ax.set_title(f"Campbell diagram ({f.shape[1]} strongest lines per point"
                 + ("; dashed: orders" if np.isfinite(fc).any() else "") + ")")  # fmt: skip
    ax.grid(alpha=0.3)
    p = out / f"campbell_{dim}.png"
    save_figure(fig, p, dpi=130)
    plt.close(fig)
    return p


def sweep_figures(ds: xr.Dataset, out: Path) -> list[Path]:
    """Write every figure the store supports; returns their paths."""
    plt = _mpl()
    out.mkdir(parents=True, exist_ok=True)
    dims = ds.attrs["sweep_axes"].split(",")
    done = ds.done.values.astype(bool)
    paths = []
    if len(dims) == 1:
        x, xlabel = _axis(ds, dims[0])
        if "poincare_v" in ds and "poincare_theta_c" in ds:  # the compressor
            pairs = (("poincare_v", "crosshead velocity v (m/s)"),
                     ("poincare_theta_c", "clearance angle theta_c (rad)"))  # fmt: skip
        else:  # any other model: every recorded section signal
            pairs = tuple((k, axis_label(k.removeprefix("poincare_"), ds[k]))
                          for k in ds.data_vars if k.startswith("poincare_")
                          and k != "poincare_distinct")  # fmt: skip
        if pairs:
            for var, ylab in pairs:
                fig, ax = plt.subplots(figsize=(9, 5), constrained_layout=True)
                y = ds[var].values
                wrapped = ""
                if var == "poincare_theta_c":  # an angle: one turn centred on its mean
                    y, centre = wrap_around_mean(y)
                    wrapped = f"; angle wrapped to {centre:+.2f} \u00b1 \u03c0 rad"
                xs = np.repeat(x[:, None], y.shape[1], axis=1)
                ax.plot(xs[done].ravel(), y[done].ravel(), ",k", alpha=0.6)
                ax.plot(xs[done].ravel(), y[done].ravel(), ".k", ms=1.0, alpha=0.5)
                ax.set_xlabel(xlabel)
                m = _store_model(ds)  # sampled once per forcing period, or at a map's points
                periodic = m is not None and m.kind == "ode" and bool(m.period(m.parameters()))
                ax.set_ylabel(f"{ylab}, " + ("once per period" if periodic else
                                             "at the section points"))  # fmt: skip
                ax.set_title(f"Bifurcation diagram ({y.shape[1]} section points per value"
                             f"{wrapped})")  # fmt: skip
                ax.grid(alpha=0.3)
                p = out / f"bifurcation_{var.split('_', 1)[1]}.png"
                save_figure(fig, p, dpi=130)
                plt.close(fig)
                paths.append(p)
        if "peak_freq" in ds:
            paths.append(campbell_figure(ds, out, plt))
        peaks = [(k, f"peak |{k.removeprefix('peak_')}| ({unit_tex(ds[k].attrs.get('units', ''))})")
                 for k in ds.data_vars if k.startswith("peak_") and ds[k].ndim == 1]  # fmt: skip
        lam = ("lambda1", f"largest Lyapunov exponent ({ds['lambda1'].attrs.get('units', '1/s')})"
               if "lambda1" in ds else "")  # fmt: skip
        for var, ylab in (lam, *peaks, *_run_signals(ds)):
            if var in ds:
                fig, ax = plt.subplots(figsize=(8, 4.5), constrained_layout=True)
                ax.plot(x[done], ds[var].values[done], "o-", ms=3)
                _mark_invalid(ax, ds, x, None, done)
                ax.set_xlabel(xlabel)
                ax.set_ylabel(ylab)
                ax.axhline(0, color="k", lw=0.5)
                ax.grid(alpha=0.3)
                p = out / f"{var}_vs_{dims[0]}.png"
                save_figure(fig, p, dpi=130)
                plt.close(fig)
                paths.append(p)
    else:
        x, xlabel = _axis(ds, dims[1])
        y, ylabel = _axis(ds, dims[0])
        maps = [("lambda1", "lambda1 (1/s)")]
        for k in ds.data_vars:
            if (k.startswith("peak_") or k.startswith("rms_")) and ds[k].ndim == 2:
                what, sig = k.split("_", 1)
                maps.append((k, f"{'peak |' + sig + '|' if what == 'peak' else 'RMS ' + sig} "
                                f"({unit_tex(ds[k].attrs.get('units', ''))})"))  # fmt: skip
        maps += _run_signals(ds)
        maps.append(("poincare_distinct", "distinct section points"))
        for var, clabel in maps:
            if var not in ds:
                continue
            z = np.where(done, ds[var].values.astype(float), np.nan)
            fig, ax = plt.subplots(figsize=(8, 6), constrained_layout=True)
            log_x = ds[dims[1]].attrs.get("scale") == "log"
            log_y = ds[dims[0]].attrs.get("scale") == "log"
            m = ax.pcolormesh(cell_edges(x, log_x), cell_edges(y, log_y), z, shading="flat",
                              cmap="viridis")  # fmt: skip
            fig.colorbar(m, ax=ax, label=clabel)
            ax.set_xlabel(xlabel)
            ax.set_ylabel(ylabel)
            if log_x:
                ax.set_xscale("log")
                _label_grid(ax.xaxis, x)
            if log_y:
                ax.set_yscale("log")
                _label_grid(ax.yaxis, y)
            _mark_invalid(ax, ds, x, y, done)
            ax.set_title(f"Fault map: {clabel}")
            p = out / f"map_{var}.png"
            save_figure(fig, p, dpi=130)
            plt.close(fig)
            paths.append(p)
    return paths
