"""Figures of simulation results (matplotlib, headless-safe).

Every figure carries, in a footer, the parameters that produced it and a mark on assumed
values, so it can be traced back to its inputs.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

__all__ = ["response_figure", "provenance_footer", "model_figure", "axis_label", "contact_figure"]


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
    of the first two (points for a map). The contact-impact compressor gets
    :func:`contact_figure`."""
    if ds.attrs.get("model_name") == "compressor-contact":
        return contact_figure(ds, title=title)
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


def _impacts(ds: xr.Dataset, key: str) -> np.ndarray:
    """Indices into ``impact_event`` of the contact onsets at one joint (``key`` "" or
    "_crosshead"): with clearance at both pins the event also fires at separations, and its
    joint is the one on its surface."""
    if "impact_time" not in ds:
        return np.empty(0, dtype=int)
    ex, ey = ds["impact_ex" + key].values, ds["impact_ey" + key].values
    u, v = ds[f"impact_ex{key}_dot"].values, ds[f"impact_ey{key}_dot"].values
    rho = np.hypot(ex, ey)
    onset = (ex * u + ey * v) > 0
    if ds.attrs.get("param_clearance_joints") == "both":
        other = "_crosshead" if key == "" else ""
        rc, rc_o = ds.attrs["param_rc" + key], ds.attrs["param_rc" + other]
        rho_o = np.hypot(ds["impact_ex" + other].values, ds["impact_ey" + other].values)
        onset &= np.abs(rho / rc - 1) <= np.abs(rho_o / rc_o - 1)
    return np.flatnonzero(onset)


def contact_figure(ds: xr.Dataset, *, title: str | None = None):
    """The contact-impact joint's record, per clearance joint: crosshead acceleration and
    joint force over crank angle with the impacts marked, the journal's orbit inside the
    clearance circle, the joint force in polar form over the crank angle, and the impact map
    (states at impacts) beside the stroboscopic section (once a revolution)."""
    plt = _mpl()
    joints = ds.attrs.get("param_clearance_joints", "crank")
    keys = {"crank": [""], "crosshead": ["_crosshead"], "both": ["", "_crosshead"]}[joints]
    deg = np.degrees(np.mod(ds["theta1"].values, 2 * np.pi))
    t = ds["time"].values
    fig = plt.figure(figsize=(13, 4.0 * (1 + len(keys))), constrained_layout=True)
    grid = fig.add_gridspec(1 + len(keys), 3)
    # row 0: the vibration signal with impacts, the stroboscopic section, impact map
    ax = fig.add_subplot(grid[0, 0])
    ax.plot(t, ds["a"].values, lw=0.5, color="C0")
    colors = {"": "C3", "_crosshead": "C2"}
    for key in keys:
        i = _impacts(ds, key)
        if i.size:
            ti = ds["impact_time"].values[i]
            ax.plot(ti, np.interp(ti, t, ds["a"].values), "v", ms=3, color=colors[key],
                    label=f"impacts, {'crank' if key == '' else 'crosshead'} pin")  # fmt: skip
    ax.set_xlabel("time (s)")
    ax.set_ylabel(axis_label("crosshead acceleration", ds["a"]))
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, loc="upper right")
    ax = fig.add_subplot(grid[0, 1])
    T = 2 * np.pi / ds.attrs["param_omega"]
    ts = np.arange(np.ceil(t[0] / T - 1e-9), np.floor(t[-1] / T + 1e-9) + 1) * T
    if ts.size:
        ax.plot(np.interp(ts, t, ds["v"].values), np.interp(ts, t, ds["a"].values), "o",
                ms=3, color="C0")  # fmt: skip
    ax.set_xlabel(axis_label("crosshead velocity", ds["v"]))
    ax.set_ylabel(axis_label("crosshead acceleration", ds["a"]))
    ax.set_title(f"stroboscopic section ({ts.size} revolutions)", fontsize=9)
    ax.grid(alpha=0.3)
    ax = fig.add_subplot(grid[0, 2])
    for key in keys:
        i = _impacts(ds, key)
        if i.size:
            th = np.degrees(np.mod(ds.attrs["param_omega"] * ds["impact_time"].values[i]
                                   + ds.attrs["param_theta1_0"], 2 * np.pi))  # fmt: skip
            ax.plot(
                th,
                ds[f"impact_v_impact{key}_after"].values[i],
                ".",
                ms=4,
                color=colors[key],
                label="crank pin" if key == "" else "crosshead pin",
            )
    ax.set_xlim(0, 360)
    ax.set_xlabel("crank angle at impact (deg)")
    ax.set_ylabel("approach velocity (m/s)")
    ax.set_title("impact map (state at each impact)", fontsize=9)
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7)
    for row, key in enumerate(keys, start=1):
        where = "crank pin" if key == "" else "crosshead pin"
        rc = ds.attrs["param_rc" + key]
        ax = fig.add_subplot(grid[row, 0])
        ax.plot(deg, ds["joint_force" + key].values, ".", ms=1, color="C0")
        i = _impacts(ds, key)
        if i.size:
            ti = ds["impact_time"].values[i]
            thi = np.degrees(np.mod(ds.attrs["param_omega"] * ti + ds.attrs["param_theta1_0"],
                                    2 * np.pi))  # fmt: skip
            ax.plot(thi, np.interp(ti, t, ds["joint_force" + key].values), "v", ms=3,
                    color=colors[key], label="impacts")  # fmt: skip
            ax.legend(fontsize=7, loc="upper right")
        ax.set_xlim(0, 360)
        ax.set_xlabel("crank angle (deg)")
        ax.set_ylabel(f"{where} joint force (N)")
        ax.grid(alpha=0.3)
        ax = fig.add_subplot(grid[row, 1])
        ring = np.linspace(0, 2 * np.pi, 361)
        ax.plot(np.cos(ring), np.sin(ring), color="0.4", lw=1)
        ex, ey = ds["ex" + key].values / rc, ds["ey" + key].values / rc
        ax.plot(ex, ey, lw=0.5, color="C0")
        ax.set_aspect("equal")
        lim = max(1.1, float(np.nanmax(np.hypot(ex, ey))) * 1.05)
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_xlabel("e_x / c")
        ax.set_ylabel("e_y / c")
        ax.set_title(f"{where}: journal orbit in the clearance circle (c = {1e3 * rc:g} mm)",
                     fontsize=9)  # fmt: skip
        ax.grid(alpha=0.3)
        ax = fig.add_subplot(grid[row, 2], projection="polar")
        fx, fy = ds["joint_force_x" + key].values, ds["joint_force_y" + key].values
        ax.plot(np.arctan2(fy, fx), np.hypot(fx, fy), ".", ms=1, color="C0")
        ax.set_title(f"{where}: joint force on the rod, polar (N)", fontsize=9)
    footer = (
        f"compressor-contact, clearance at {joints}, law {ds.attrs.get('param_contact_law')}"
        f" e={ds.attrs.get('param_restitution')}, friction {ds.attrs.get('param_friction')}"
        f", omega={ds.attrs['param_omega']:g} rad/s | {ds.attrs.get('solver_method')} "
        f"rtol={ds.attrs.get('solver_rtol')} | recipdyn {ds.attrs.get('recipdyn_version')}"
    )
    fig.text(0.01, 0.002, footer, fontsize=6.5, color="0.35")
    fig.suptitle(title or "Contact-impact clearance joint")
    return fig


def cycle_figure(ds: xr.Dataset, *, title: str | None = None):
    """The compression cycle of a run with ``load = "cycle"``, over its last revolution:
    a) p-V diagram of each chamber (line pressures dashed), b) pressures over crank angle,
    c) rod loads over crank angle: gas, inertia of the crosshead and piston (``-m3 a``) and
    combined (the crosshead-pin load, compression > 0), with the API 618 reversal verdict.
    """
    from .model.cycle import last_revolution, rod_load_reversal

    plt = _mpl()
    last = last_revolution(ds, float(ds.attrs["param_omega"]), extra=1)
    deg = np.degrees(np.mod(last["theta1"].values, 2.0 * np.pi))
    order = np.argsort(deg)
    ps = float(ds.attrs["param_suction_pressure"])
    pdis = float(ds.attrs["param_discharge_pressure"])
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), constrained_layout=True)
    ax = axes[0]
    colors = {"head": "#0072B2", "crank": "#D55E00"}  # Okabe-Ito: colour-blind safe
    acting = str(ds.attrs.get("param_acting", "double"))
    ends = [e for e in ("head", "crank") if acting in (e, "double")]
    for end in ends:
        ax.plot(last[f"V_{end}"].values * 1e3, last[f"p_{end}"].values / 1e5, lw=1.2,
                color=colors[end], label=f"{end} end")  # fmt: skip
    for p_line, name in ((ps, "suction"), (pdis, "discharge")):
        ax.axhline(p_line / 1e5, ls="--", lw=0.7, color="0.4")
        ax.annotate(name, (0.99, p_line / 1e5), xycoords=("axes fraction", "data"), ha="right",
                    va="bottom", fontsize=8, color="0.3")  # fmt: skip
    ax.set_xlabel("cylinder volume (L)")
    ax.set_ylabel("pressure, absolute (bar)")
    ax.set_title("a) p-V diagram")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax = axes[1]
    for end in ends:
        ax.plot(deg[order], last[f"p_{end}"].values[order] / 1e5, lw=1.2, color=colors[end],
                label=f"{end} end")  # fmt: skip
    ax.set_xlabel("crank angle (deg, 0 = outer dead centre)")
    ax.set_ylabel("pressure, absolute (bar)")
    ax.set_title("b) cylinder pressure")
    ax.set_xlim(0, 360)
    ax.set_xticks(range(0, 361, 60))
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax = axes[2]
    # on the crosshead along x: m3 a = F_gas + F_rod, so the rod's load on the pin is
    # m3 a - F_gas = gas load (-F_gas) + inertia load (m3 a); compression > 0
    gas = -last["gas_force"].values
    inertia = float(ds.attrs["param_m3"]) * last["a"].values
    pin = gas + inertia
    for y, lab, c in ((gas, "gas (-F_gas)", "#009E73"), (inertia, "inertia (m3 a)", "#CC79A7"),
                      (pin, "combined (crosshead pin)", "black")):  # fmt: skip
        ax.plot(deg[order], y[order] / 1e3, lw=1.0, label=lab, color=c)
    ax.axhline(0.0, lw=0.7, color="0.4")
    rev = rod_load_reversal(last["theta1"].values, pin)
    ax.set_title("c) rod load at the crosshead pin, compression > 0")
    verdict = rev.describe().replace(" (API", "\n(API").replace(", reverse", ",\nreverse")
    ax.text(0.02, 0.02, verdict, transform=ax.transAxes, fontsize=8, va="bottom",
            bbox=dict(boxstyle="round", fc="white", ec="0.6", alpha=0.9))  # fmt: skip
    ax.set_xlabel("crank angle (deg)")
    ax.set_ylabel("load (kN)")
    ax.set_xlim(0, 360)
    ax.set_xticks(range(0, 361, 60))
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(alpha=0.3)
    fig.suptitle(title or "Compression cycle (ideal valves) and rod loads, last revolution")
    fig.get_layout_engine().set(rect=(0, 0.04, 1, 0.96))  # room for the footer
    fig.text(0.01, 0.005, provenance_footer(ds), fontsize=6.5, color="0.35")
    return fig
