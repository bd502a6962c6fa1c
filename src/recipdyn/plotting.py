"""Figures of simulation results (matplotlib, headless-safe).

Every figure carries, in a footer, the parameters that produced it and a mark on assumed
values, so it can be traced back to its inputs.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

__all__ = ["response_figure", "provenance_footer", "model_figure", "axis_label"]


def _mpl():
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "pdf", "svg", "cairo"):
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def axis_label(name: str, da) -> str:
    """``name (units)`` from a DataArray's ``units`` attribute (no unit for dimensionless)."""
    u = da.attrs.get("units", "")
    return f"{name} ({u})" if u not in ("", "1") else name


def provenance_footer(ds: xr.Dataset) -> str:
    """One line: the case's key parameters, solver and version (assumed values marked *)."""
    a = ds.attrs
    return (
        f"rc={1e3 * a['param_rc']:g} mm, d={1e3 * a['param_d']:g} mm, "
        f"omega={a['param_omega']:g} rad/s, load sign={a['param_load_sign']}, "
        f"equations={a['param_equations']}, theta_c0={a['theta_c_initial']:.4f} rad, "
        f"m2*={a['param_m2']:g} kg, m3*={a['param_m3']:g} kg, J2*={a['param_J2']:g} kg m^2 "
        f"(* assumed) | {a['solver_method']} rtol={a['solver_rtol']:g} | "
        f"recipdyn {a['recipdyn_version']}"
    )


def response_figure(ds: xr.Dataset, *, title: str | None = None, fmax: float | None = None):
    """Crosshead x, v, a over time and the amplitude spectrum of a (the paper's Fig. 4 layout).

    Returns the matplotlib Figure.
    """
    from scipy.signal import periodogram

    plt = _mpl()
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5), constrained_layout=True)
    t = ds.time.values
    for ax, name, label in (
        (axes[0, 0], "x", "a) displacement x3 (m)"),
        (axes[0, 1], "v", "b) velocity (m/s)"),
        (axes[1, 0], "a", "c) acceleration (m/s$^2$)"),
    ):
        ax.plot(t, ds[name].values, lw=0.7)
        ax.set_xlabel("time (s)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    ax = axes[1, 1]
    if t.size < 4:  # too short for a spectrum: say so instead of failing
        ax.text(0.5, 0.5, f"{t.size} sample(s): too short for a spectrum", ha="center",
                va="center", transform=ax.transAxes)  # fmt: skip
        ax.set_axis_off()
        fig.suptitle(title or "Crosshead response")
        fig.text(0.01, 0.002, provenance_footer(ds), fontsize=6.5, color="0.35")
        return fig
    fs = 1.0 / float(np.median(np.diff(t)))
    # 'spectrum' scaling corrects for the window's coherent gain: sqrt(2 P) is the amplitude
    freq, pxx = periodogram(ds["a"].values, fs, window="hann", scaling="spectrum")
    ax.plot(freq, np.sqrt(2.0 * pxx), lw=0.7)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("d) amplitude of a (m/s$^2$)")
    f_top = (
        fmax if fmax is not None else min(fs / 2, max(60.0 * ds.attrs["crank_frequency_hz"], 50))
    )
    ax.set_xlim(0, f_top)
    ax.grid(alpha=0.3)
    fig.suptitle(title or "Crosshead response")
    fig.text(0.01, 0.002, provenance_footer(ds), fontsize=6.5, color="0.35")
    return fig


def model_figure(ds: xr.Dataset, *, title: str | None = None):
    """Any model's record: up to three signals over time (or iteration) and a phase portrait
    of the first two (points for a map)."""
    plt = _mpl()
    dim = "iteration" if "iteration" in ds.dims else "time"
    names = [k for k in ds.data_vars if ds[k].dims == (dim,)][:3]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    t = ds[dim].values
    is_map = dim == "iteration"
    for k in names:
        u = ds[k].attrs.get("units", "")
        label = f"{k} ({u})" if u not in ("", "1") else k
        if is_map:
            axes[0].plot(t, ds[k].values, ".", ms=2, label=label)
        else:
            axes[0].plot(t, ds[k].values, lw=0.7, label=label)
    tu = ds[dim].attrs.get("units", "")
    axes[0].set_xlabel(f"{dim} ({tu})" if tu not in ("", "1") else dim)
    axes[0].legend(fontsize=8, loc="upper right")
    axes[0].grid(alpha=0.3)
    if len(names) >= 2:
        a, b = ds[names[0]], ds[names[1]]
        style = dict(ls="none", marker=".", ms=1.5) if is_map else dict(lw=0.5)
        axes[1].plot(a.values, b.values, **style)
        axes[1].set_xlabel(f"{names[0]} ({a.attrs.get('units', '')})")
        axes[1].set_ylabel(f"{names[1]} ({b.attrs.get('units', '')})")
        axes[1].set_title("phase portrait")
        axes[1].grid(alpha=0.3)
    else:
        axes[1].set_axis_off()
    fig.suptitle(title or f"{ds.attrs.get('model', 'model')}: {ds.attrs.get('title', '')}")
    return fig
