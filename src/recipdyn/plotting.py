"""Figures of simulation results (matplotlib, headless-safe).

Every figure carries, in a footer, the parameters that produced it and a mark on assumed
values, so it can be traced back to its inputs.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

__all__ = [
    "response_figure",
    "provenance_footer",
    "model_figure",
    "axis_label",
    "contact_figure",
    "plot_signal",
    "plot_orbit",
    "centred",
    "unit_tex",
    "is_dense",
    "mark_invalid",
    "PALETTE",
]

from .mplstyle import PALETTE, _mpl  # noqa: F401  (the style lives on the floor)


def _columns(ax) -> int:
    """Width of the axes in pixels at the figure's dpi (before layout: an estimate)."""
    fig = ax.get_figure()
    return max(100, int(ax.get_position().width * fig.get_figwidth() * fig.dpi))


def is_dense(y, columns: int, per_column: float = 1 / 3) -> bool:
    """True when ``y`` has more than ``per_column * columns`` clear oscillations (prominence
    above 1 % of its range): drawn as a line it fills the axes as a solid block."""
    from scipy.signal import find_peaks

    y = np.asarray(y, dtype=float)
    span = float(np.ptp(y)) if y.size else 0.0
    if y.size < 3 * columns or not span > 0:
        return False
    peaks, _ = find_peaks(y, prominence=0.01 * span)
    return peaks.size > per_column * columns


_PREFIX = ((1e-9, "n"), (1e-6, "\u00b5"), (1e-3, "m"), (1.0, ""))


def unit_tex(unit: str) -> str:
    """A unit string for an axis label: ``m/s**2`` / ``m/s^2`` -> ``m/s$^2$``."""
    import re

    return re.sub(r"(\*\*|\^)(-?\d+)", r"$^{\2}$", unit)


def centred(values, name: str, unit: str) -> tuple[np.ndarray, str]:
    """Values and axis label for a quantity whose spread is tiny beside its mean (a Poincaré
    section of a nearly periodic orbit: v = -4.0101 mm/s +- 5 um/s), which plain tick labels
    print as unreadable 8-digit numbers. Returns the deviation from the median in a prefixed
    unit with the median in the label; unchanged when the spread is above 1 % of the mean."""
    v = np.asarray(values, dtype=float)
    fin = v[np.isfinite(v)]
    label = f"{name} ({unit_tex(unit)})" if unit not in ("", "1") else name
    if fin.size < 2:
        return v, label
    mid = float(np.median(fin))
    span = float(np.ptp(fin))
    if not (span > 0 and span < 0.01 * abs(mid)):
        return v, label
    scale, prefix = next(((k, p) for k, p in _PREFIX if span / k < 1000), (1.0, ""))
    if unit in ("", "1"):
        scale, prefix = 1.0, ""
    shift = f"{name} {'+' if mid < 0 else chr(0x2212)} {abs(mid):.6g}"
    return (v - mid) / scale, (f"{shift} ({prefix}{unit_tex(unit)})"
                               if unit not in ("", "1") else shift)  # fmt: skip


def plot_orbit(ax, x, y, *, color=None, lw: float = 0.5):
    """A phase portrait. A dense orbit (more turns than twice the axes' pixel columns) is
    drawn as its occupation density (a 2-D histogram of the samples, i.e. the time spent per
    cell, on a log colour scale): a line would fill the axes as one block."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    cols = _columns(ax)
    if not (is_dense(x, cols, 2.0) or is_dense(y, cols, 2.0)):  # a 2-D line takes more
        return ax.plot(x, y, lw=lw, color=color)
    from matplotlib.colors import LogNorm

    ok = np.isfinite(x) & np.isfinite(y)
    h, xe, ye = np.histogram2d(x[ok], y[ok], bins=(cols // 5, cols // 6))
    h = np.where(h > 0, h / h.sum(), np.nan)
    return ax.pcolormesh(xe, ye, h.T, cmap="Blues", norm=LogNorm(vmin=np.nanmax(h) * 1e-3),
                         shading="flat", rasterized=True)  # fmt: skip


def plot_signal(ax, t, y, *, color=None, label=None, lw: float = 0.7, zoom: bool = True):
    """Draw ``y(t)``. A signal denser than the axes' pixel columns (e.g. a kHz link oscillation
    over seconds) is drawn as its envelope, the minimum and maximum over each pixel column
    (what a line would show as a block, at a fraction of the size), with an inset zoom on six
    periods of the fast oscillation around the largest value, so its waveform stays visible.
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    cols = _columns(ax)
    if not is_dense(y, cols):
        return ax.plot(t, y, lw=lw, color=color, label=label)
    edges = np.linspace(0, y.size, cols + 1).astype(int)
    lo = np.minimum.reduceat(y, edges[:-1])
    hi = np.maximum.reduceat(y, edges[:-1])
    tc = t[edges[:-1]]
    art = ax.fill_between(tc, lo, hi, color=color, lw=0, alpha=0.85,
                          label=None if label is None else f"{label} (envelope)")  # fmt: skip
    if zoom:
        from scipy.signal import find_peaks

        peaks, _ = find_peaks(y, prominence=0.01 * float(np.ptp(y)))
        period = float(np.median(np.diff(t[peaks]))) if peaks.size > 1 else (t[-1] - t[0]) / 50
        i = int(np.argmax(np.abs(y - np.median(y))))
        sel = (t >= t[i] - 3 * period) & (t <= t[i] + 3 * period)
        ins = ax.inset_axes([0.66, 0.64, 0.32, 0.33])
        ins.plot(t[sel], y[sel], lw=0.8, color=color)
        ins.set_title(f"zoom: t = {t[i]:.4g} s", fontsize=6.5, pad=2)
        ins.tick_params(labelsize=6)
        ins.patch.set_alpha(0.92)
        ins.grid(alpha=0.3)
    return art


def axis_label(name: str, da) -> str:
    """``name (units)`` from a DataArray's ``units`` attribute (no unit for dimensionless)."""
    u = da.attrs.get("units", "")
    return f"{name} ({unit_tex(u)})" if u not in ("", "1") else name


def provenance_footer(ds: xr.Dataset) -> str:
    """One line: the case's key parameters, solver and version (assumed values marked *);
    parameters a model does not have are left out."""
    a = ds.attrs
    parts = [f"rc={1e3 * a['param_rc']:g} mm, d={1e3 * a['param_d']:g} mm, "
             f"omega={a['param_omega']:g} rad/s"]  # fmt: skip
    if "param_load_sign" in a:
        parts.append(f"load sign={a['param_load_sign']}")
    if "param_equations" in a:
        parts.append(f"equations={a['param_equations']}")
    if "theta_c_initial" in a:
        parts.append(f"theta_c0={a['theta_c_initial']:.4f} rad")
    parts.append(f"m2*={a['param_m2']:g} kg, m3*={a['param_m3']:g} kg, "
                 f"J2*={a['param_J2']:g} kg m^2 (* assumed)")  # fmt: skip
    return (
        ", ".join(parts) + f" | {a['solver_method']} rtol={a['solver_rtol']:g} | "
        f"recipdyn {a['recipdyn_version']}"
    )


def response_figure(ds: xr.Dataset, *, title: str | None = None, fmax: float | None = None):
    """Crosshead x, v, a over time and the amplitude spectrum of a (the paper's Fig. 4 layout).

    Returns the matplotlib Figure.
    """

    plt = _mpl()
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5), constrained_layout=True)
    t = ds.time.values
    for ax, name, label in (
        (axes[0, 0], "x", "a) displacement x3 (m)"),
        (axes[0, 1], "v", "b) velocity (m/s)"),
        (axes[1, 0], "a", "c) acceleration (m/s$^2$)"),
    ):
        plot_signal(ax, t, ds[name].values)
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
    from .analysis.spectrum import amplitude_spectrum, display_band, nonharmonic_peak

    fs = 1.0 / float(np.median(np.diff(t)))
    from .io import forcing_frequency

    fc = forcing_frequency(ds.attrs) or float(ds.attrs["param_omega"]) / (2 * np.pi)
    spec = amplitude_spectrum(ds["a"].values, fs, window="hann")
    f_top = fmax if fmax is not None else display_band(spec, fc)
    ax.semilogy(spec.frequency, np.maximum(spec.amplitude, 1e-300), lw=0.7)
    top = float(spec.amplitude.max()) if spec.amplitude.size else 1.0
    ax.set_ylim(max(top, 1e-300) * 1e-6, max(top, 1e-300) * 3)  # 120 dB below the largest line
    f_link = nonharmonic_peak(spec.frequency, spec.amplitude, fc, min_rel_height=1e-4)
    if np.isfinite(f_link) and f_link <= f_top:
        amp = float(np.interp(f_link, spec.frequency, spec.amplitude))
        ax.annotate(f"{f_link:.4g} Hz = {f_link / fc:.1f} crank orders\n(not a crank harmonic)",
                    (f_link, amp), xytext=(-10, 12), textcoords="offset points", ha="right",
                    fontsize=8, arrowprops=dict(arrowstyle="->", lw=0.6))  # fmt: skip
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("d) amplitude of a (m/s$^2$), log scale")
    ax.set_xlim(0, f_top)
    ax.grid(alpha=0.3)
    fig.suptitle(title or "Crosshead response")
    fig.text(0.01, 0.002, provenance_footer(ds), fontsize=6.5, color="0.35")
    return fig


def model_figure(ds: xr.Dataset, *, title: str | None = None):
    """Any model's record: up to three signals over time (or iteration) and a phase portrait
    of the first two (points for a map). The contact-impact compressor gets
    [`contact_figure`][recipdyn.plotting.contact_figure]."""
    names = set(ds.data_vars)
    if {"ex", "delta", "x", "v", "a"} <= names or {"ex_crosshead", "delta_crosshead"} <= names:
        return contact_figure(ds, title=title)  # the contact-impact joint, any load
    if {"theta_c", "contact_force", "gas_force", "x", "v", "a"} <= names:
        return response_figure(ds, title=title)  # the massless link, any load
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
    fig.suptitle(title or ds.attrs.get("title", ds.attrs.get("model", "model")))
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
    if "impact_y_suction_head" in ds:  # the event also carries the valve impacts: keep the
        # events located on this joint's surface (to the root finder's precision)
        onset &= np.abs(rho / ds.attrs["param_rc" + key] - 1) < 1e-6
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
    from .analysis.poincare import strobe_times

    ts = strobe_times(t[0], t[-1], T)
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
    combined (the crosshead-pin load, compression > 0), with the API 618 reversal verdict;
    with dynamic valves (model ``compressor-valves``) d) the valve lifts over crank angle.
    """
    from .model.cycle import last_revolution, rod_load_reversal

    plt = _mpl()
    last = last_revolution(ds, float(ds.attrs["param_omega"]), extra=1)
    deg = np.degrees(np.mod(last["theta1"].values, 2.0 * np.pi))
    order = np.argsort(deg)
    ps = float(ds.attrs["param_suction_pressure"])
    pdis = float(ds.attrs["param_discharge_pressure"])
    valves = "y_suction_head" in ds
    fig, axes = plt.subplots(1, 4 if valves else 3, figsize=(20 if valves else 15, 4.6),
                             constrained_layout=True)  # fmt: skip
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
    if ds.attrs.get("validity", "ok") != "ok":  # no verdict from an invalid model
        verdict = verdict.rsplit(":", 1)[0] + ":\nAPI 618 verdict WITHHELD (outside the model)"
    ax.text(0.02, 0.02, verdict, transform=ax.transAxes, fontsize=8, va="bottom",
            bbox=dict(boxstyle="round", fc="white", ec="0.6", alpha=0.9))  # fmt: skip
    ax.set_xlabel("crank angle (deg)")
    ax.set_ylabel("load (kN)")
    ax.set_xlim(0, 360)
    ax.set_xticks(range(0, 361, 60))
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(alpha=0.3)
    if valves:
        ax = axes[3]
        for end in ends:
            for kind, ls in (("suction", "-"), ("discharge", "--")):
                ax.plot(deg[order], last[f"y_{kind}_{end}"].values[order] * 1e3, lw=1.0, ls=ls,
                        color=colors[end], label=f"{end} {kind}")  # fmt: skip
        ax.axhline(float(ds.attrs["param_valve_lift"]) * 1e3, lw=0.7, color="0.4", ls=":")
        ax.set_xlabel("crank angle (deg)")
        ax.set_ylabel("valve lift (mm)")
        ax.set_title("d) valve plate lift (guard dotted)")
        ax.set_xlim(0, 360)
        ax.set_xticks(range(0, 361, 60))
        ax.legend(fontsize=8, loc="upper right")
        ax.grid(alpha=0.3)
    kind = "dynamic valves" if valves else "ideal valves"
    fig.suptitle(title or f"Compression cycle ({kind}) and rod loads, last revolution")
    fig.get_layout_engine().set(rect=(0, 0.04, 1, 0.96))  # room for the footer
    fig.text(0.01, 0.005, provenance_footer(ds), fontsize=6.5, color="0.35")
    return fig


def mark_invalid(fig, attrs):
    """Say on ``fig``, where nobody can miss it, that its run left the model's validity
    (``attrs["validity"]`` is not ``"ok"``): the reason and the model to use in red above the
    title, and "OUTSIDE THE MODEL'S VALIDITY" across the figure. Returns ``fig`` (unchanged
    for a valid run)."""
    import textwrap

    why = str(attrs.get("validity", "ok"))
    if why == "ok":
        return fig
    old = fig.get_suptitle()
    head = "INVALID RUN: outside the model's validity, verdicts withheld"
    text = "\n".join([head, *textwrap.wrap(why, 150), *([old] if old else [])])
    fig.suptitle(text, color="#B00020", fontsize=9)
    fig.text(0.5, 0.5, "OUTSIDE THE MODEL'S VALIDITY", ha="center", va="center", rotation=20,
             fontsize=44, color="#B00020", alpha=0.15, zorder=10)  # fmt: skip
    return fig
