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
    "add_footer",
    "model_figure",
    "throws_figure",
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

from .mplstyle import PALETTE, _columns, _mpl, dense_orbit, is_dense, orbit_density  # noqa: F401

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
    drawn as its occupation density (`recipdyn.mplstyle.orbit_density`: the time spent
    per cell, on a log colour scale): a line would fill the axes as one block."""
    if not dense_orbit(ax, x, y):
        return ax.plot(x, y, lw=lw, color=color)
    return orbit_density(ax, x, y)


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
        ins = ax.inset_axes([0.66, 0.6, 0.32, 0.32])  # its title inside the axes
        ins.plot(t[sel], y[sel], lw=0.8, color=color)
        ins.set_title(f"zoom: t = {t[i]:.4g} s", fontsize=6.5, pad=2)
        ins.tick_params(labelsize=6)
        from matplotlib.ticker import MaxNLocator

        ins.xaxis.set_major_locator(MaxNLocator(3))  # a small inset: few labels that fit
        ins.yaxis.set_major_locator(MaxNLocator(4))
        ins.patch.set_alpha(0.92)
        ins.grid(alpha=0.3)
    return art


def section_times(ds: xr.Dataset, period: float | None) -> tuple[np.ndarray, str]:
    """The instants at which a record's section samples it, and what they are: once per turn
    of the state its record names as ``section_angle`` (a crank driven by a motor, whose turns
    do not keep time: `angle_times` at the record's first angle), else once per forcing
    ``period`` (`strobe_times`); none without either."""
    from .analysis.poincare import angle_times, strobe_times

    t = ds["time"].values
    name = ds.attrs.get("section_angle")
    if name and name in ds.variables and t.size >= 2:
        th = np.asarray(ds[name].values, dtype=float)
        return angle_times(t, th, phase=float(th[0]) % (2 * np.pi)), f"once per turn of {name}"
    if period:
        return strobe_times(t[0], t[-1], period), "once per period"
    return np.empty(0), "none"


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


#: Font size of the provenance footer (points).
FOOTER_SIZE = 6.5


def add_footer(fig, text: str):
    """Put the provenance line ``text`` under the panels as the figure's ``supxlabel``: the
    layout engine (constrained or compressed) reserves its room, so it never covers an axis
    label; left-aligned, wrapped to the figure's width (a character of the footer's font is
    taken as 0.6 of its size, wider than DejaVu Sans' mean)."""
    import textwrap

    width = max(40, int(fig.get_figwidth() * 72 / (0.6 * FOOTER_SIZE)))
    return fig.supxlabel(textwrap.fill(text, width), x=0.01, ha="left", fontsize=FOOTER_SIZE,
                         color="0.35")  # fmt: skip


def _annotate_line(ax, f, amp, text: str) -> None:
    """Label the spectral line at ``(f, amp)`` with ``text`` inside the axes: the note sits in
    the top band kept free of data (see the y limits of `response_figure`), on the side
    away from the line, with an arrow down to it."""
    lo, hi = ax.get_xlim()
    frac = (f - lo) / (hi - lo) if hi > lo else 0.5
    right = frac < 0.5  # the line on the left: the note on the right, and the other way round
    ax.annotate(text, (f, amp), xytext=(0.98 if right else 0.02, 0.97),
                textcoords="axes fraction", ha="right" if right else "left", va="top",
                fontsize=7.5, bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="0.7", alpha=0.9),
                arrowprops=dict(arrowstyle="->", lw=0.6, color="0.2"))  # fmt: skip


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
        add_footer(fig, provenance_footer(ds))
        return fig
    from .analysis.spectrum import amplitude_spectrum, display_band, nonharmonic_peak

    fs = 1.0 / float(np.median(np.diff(t)))
    from .io import forcing_frequency

    fc = forcing_frequency(ds.attrs) or float(ds.attrs["param_omega"]) / (2 * np.pi)
    spec = amplitude_spectrum(ds["a"].values, fs, window="hann")
    f_top = fmax if fmax is not None else display_band(spec, fc)
    ax.semilogy(spec.frequency, np.maximum(spec.amplitude, 1e-300), lw=0.7)
    top = max(float(spec.amplitude.max()) if spec.amplitude.size else 1.0, 1e-300)
    # 120 dB below the largest line; the 1.5 decades above it are kept free for the note
    ax.set_ylim(top * 1e-6, top * 30)
    ax.set_xlim(0, f_top)
    f_link = nonharmonic_peak(spec.frequency, spec.amplitude, fc, min_rel_height=1e-4)
    if np.isfinite(f_link) and f_link <= f_top:
        amp = float(np.interp(f_link, spec.frequency, spec.amplitude))
        _annotate_line(ax, f_link, amp, f"{f_link:.4g} Hz = {f_link / fc:.1f} crank orders\n"
                                        "(not a crank harmonic)")  # fmt: skip
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("d) amplitude of a (m/s$^2$), log scale")
    ax.grid(alpha=0.3)
    fig.suptitle(title or "Crosshead response")
    add_footer(fig, provenance_footer(ds))
    return fig


def model_figure(ds: xr.Dataset, *, title: str | None = None):
    """Any model's record: up to three signals over time (or iteration) and a phase portrait
    of the first two (points for a map). The contact-impact compressor gets
    [`contact_figure`][recipdyn.plotting.contact_figure]."""
    names = set(ds.data_vars)
    if "theta1" in names and len(throw_names(ds)) > 1:
        return throws_figure(ds, title=title)  # a machine of several throws
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


def throw_names(ds: xr.Dataset) -> list[str]:
    """The throws of a machine's record: the namespaces of its signals ``throwK.a``."""
    return sorted({str(k).rpartition(".")[0] for k in ds.data_vars
                   if str(k).endswith(".a") and f"{str(k)[:-2]}.x" in ds},
                  key=lambda n: (len(n), n))  # fmt: skip


def throws_figure(ds: xr.Dataset, *, title: str | None = None, max_throws: int = 6):
    """A machine of several throws: each throw's crosshead displacement, velocity,
    acceleration and gas force (rows) by the shaft's crank angle over the last recorded
    revolution, one line per throw (its phase shows as a shift along the angle)."""
    plt = _mpl()
    throws = throw_names(ds)[:max_throws]
    th = np.asarray(ds["theta1"].values, dtype=float)
    last = th >= th[-1] - 2.0 * np.pi
    deg = np.degrees(np.mod(th[last], 2.0 * np.pi))
    order = np.argsort(deg, kind="stable")
    rows = [
        ("x", "crosshead displacement"),
        ("v", "crosshead velocity"),
        ("a", "crosshead acceleration"),
        ("gas_force", "gas force on the crosshead"),
    ]
    fig, axes = plt.subplots(len(rows), 1, figsize=(10, 9), sharex=True, constrained_layout=True)
    for ax, (name, what) in zip(axes, rows, strict=True):
        unit = ""
        for t in throws:
            da = ds.get(f"{t}.{name}")
            if da is None:
                continue
            unit = da.attrs.get("units", "")
            ax.plot(deg[order], np.asarray(da.values)[last][order], lw=0.8, label=t)
        ax.set_ylabel(f"{what} ({unit})" if unit else what)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, loc="upper right", ncols=min(len(throws), 3))
    axes[-1].set_xlabel("crank angle of the shaft (deg), last revolution")
    axes[-1].set_xlim(0, 360)
    fig.suptitle(title or f"{ds.attrs.get('model', 'machine')}: each throw by crank angle")
    a = ds.attrs
    rcs = ", ".join(f"{t}.rc={1e3 * a[f'param_{t}.rc']:g} mm" for t in throws
                    if f"param_{t}.rc" in a)  # fmt: skip
    add_footer(fig, f"{len(throws)} throws{'; ' + rcs if rcs else ''} | {a['solver_method']} rtol="
                    f"{a['solver_rtol']:g} | recipdyn {a['recipdyn_version']}")  # fmt: skip
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


def _startup_end(ds: xr.Dataset) -> float | None:
    """End of the start-up that the contact figure shows apart: the first crank revolution of
    a record that begins with the run (no revolution discarded as transient) and holds at
    least one more. The journal is released at rest in the clearance, so its first fall onto
    the bearing is an impact far harder than the steady ones; scaled to it, the steady motion
    would be a flat line. ``None`` when there is no such start-up in the record."""
    if float(ds.attrs.get("transient_revolutions", 0.0)) > 0:
        return None
    t = ds["time"].values
    period = 2 * np.pi / float(ds.attrs["param_omega"])
    if t.size < 2 or t[-1] - t[0] < 1.5 * period:
        return None
    return float(t[0] + period)


def _steady_ylim(ax, y, steady, margin: float = 0.05) -> bool:
    """Scale ``ax``'s y axis to ``y[steady]`` (with a margin); True when the other samples (the
    start-up) reach outside it, i.e. are partly off scale."""
    ys = y[steady & np.isfinite(y)]
    if ys.size == 0:
        return False
    lo, hi = float(ys.min()), float(ys.max())
    pad = margin * ((hi - lo) or abs(hi) or 1.0)
    ax.set_ylim(lo - pad, hi + pad)
    rest = y[~steady & np.isfinite(y)]
    return bool(rest.size and (rest.min() < lo - pad or rest.max() > hi + pad))


def _emptiest_direction(angle) -> float:
    """Centre (deg) of the 30-degree sector holding the fewest of ``angle`` (rad): where a
    polar plot's radial labels cover the least data."""
    counts, edges = np.histogram(np.mod(angle, 2 * np.pi), bins=12, range=(0, 2 * np.pi))
    k = int(np.argmin(counts))
    return float(np.degrees(edges[k] + np.pi / 12))


def contact_figure(ds: xr.Dataset, *, title: str | None = None):
    """The contact-impact joint's record, per clearance joint: crosshead acceleration and
    joint force over crank angle with the impacts marked, the journal's orbit inside the
    clearance circle, the joint force in polar form over the crank angle, and the impact map
    (states at impacts) beside the stroboscopic section (once a revolution).

    A record that begins with the run shows its first revolution (the start-up: the journal's
    first fall onto the bearing) in grey and apart: every panel is scaled to the steady part
    after it, and a start-up reaching outside that scale is said so in the legend."""
    from matplotlib.ticker import MaxNLocator

    plt = _mpl()
    joints = ds.attrs.get("param_clearance_joints", "crank")
    keys = {"crank": [""], "crosshead": ["_crosshead"], "both": ["", "_crosshead"]}[joints]
    deg = np.degrees(np.mod(ds["theta1"].values, 2 * np.pi))
    t = ds["time"].values
    t_up = _startup_end(ds)
    steady = t >= t_up if t_up is not None else np.ones(t.size, dtype=bool)
    grey = "0.65"
    omega, th0 = float(ds.attrs["param_omega"]), float(ds.attrs["param_theta1_0"])
    fig = plt.figure(figsize=(13, 4.0 * (1 + len(keys))), layout="constrained")
    grid = fig.add_gridspec(1 + len(keys), 3)
    colors = {"": "C3", "_crosshead": "C2"}

    def startup_note(ax, y) -> str:
        """The start-up's legend entry; its extreme when it reaches outside the steady scale."""
        off = _steady_ylim(ax, y, steady)
        peak = float(np.nanmax(np.abs(y[~steady]))) if (~steady).any() else 0.0
        return "start-up (1st revolution)" + (f": off scale, |peak| {peak:.3g}" if off else "")

    # row 0: the vibration signal with impacts, the stroboscopic section, impact map
    ax = fig.add_subplot(grid[0, 0])
    a = ds["a"].values
    ax.plot(t[steady], a[steady], lw=0.5, color="C0")
    if t_up is not None:
        up = t <= t_up
        ax.plot(t[up], a[up], lw=0.5, color=grey)
        ax.axvspan(t[0], t_up, color="0.92", zorder=0, label=startup_note(ax, a))
    for key in keys:
        i = _impacts(ds, key)
        if i.size:
            ti = ds["impact_time"].values[i]
            ax.plot(ti, np.interp(ti, t, a), "v", ms=3, color=colors[key],
                    label=f"impacts, {'crank' if key == '' else 'crosshead'} pin")  # fmt: skip
    ax.set_xlabel("time (s)")
    ax.set_ylabel(axis_label("crosshead acceleration", ds["a"]))
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, loc="upper right")
    ax = fig.add_subplot(grid[0, 1])
    ts, _ = section_times(ds, 2 * np.pi / omega)  # (once per turn of a motor-driven crank)
    if t_up is not None:
        ts = ts[ts >= t_up - 1e-9 * (t[1] - t[0])]  # the steady part's revolutions
    vu, au = ds["v"].attrs.get("units", "m/s"), ds["a"].attrs.get("units", "m/s**2")
    sv, xlab = centred(np.interp(ts, t, ds["v"].values), "crosshead velocity", vu)
    sa, ylab = centred(np.interp(ts, t, a), "crosshead acceleration", au)
    if ts.size:
        ax.plot(sv, sa, "o", ms=3, color="C0")
    ax.xaxis.set_major_locator(MaxNLocator(5))
    ax.set_xlabel(xlab)
    ax.set_ylabel(ylab)
    after = " after the start-up" if t_up is not None else ""
    revs = f"{ts.size} revolution{'' if ts.size == 1 else 's'}"
    ax.set_title(f"stroboscopic section ({revs}{after})", fontsize=9)
    ax.grid(alpha=0.3)
    ax = fig.add_subplot(grid[0, 2])
    for key in keys:
        i = _impacts(ds, key)
        if i.size:
            ti = ds["impact_time"].values[i]
            th = np.degrees(np.mod(omega * ti + th0, 2 * np.pi))
            v_after = ds[f"impact_v_impact{key}_after"].values[i]
            late = ti >= t_up if t_up is not None else np.ones(ti.size, dtype=bool)
            ax.plot(th[late], v_after[late], ".", ms=4, color=colors[key],
                    label="crank pin" if key == "" else "crosshead pin")  # fmt: skip
            if (~late).any():
                ax.plot(th[~late], v_after[~late], "o", ms=4, mfc="none", color=grey,
                        label=f"{'crank' if key == '' else 'crosshead'} pin, start-up")  # fmt: skip
    ax.set_xlim(0, 360)
    ax.set_xticks(range(0, 361, 60))
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
        force = ds["joint_force" + key].values / 1e3
        if t_up is not None:
            ax.plot(deg[~steady], force[~steady], ".", ms=1, color=grey,
                    label=startup_note(ax, force))  # fmt: skip
        ax.plot(deg[steady], force[steady], ".", ms=1, color="C0")
        i = _impacts(ds, key)
        if i.size:
            ti = ds["impact_time"].values[i]
            thi = np.degrees(np.mod(omega * ti + th0, 2 * np.pi))
            ax.plot(thi, np.interp(ti, t, force), "v", ms=3, color=colors[key], label="impacts")
        if ax.get_legend_handles_labels()[0]:
            for handle in ax.legend(fontsize=7, loc="upper right").legend_handles:
                handle.set_markersize(4)  # the 1-point dots, readable in the legend
        ax.set_xlim(0, 360)
        ax.set_xticks(range(0, 361, 60))
        ax.set_xlabel("crank angle (deg)")
        ax.set_ylabel(f"{where} joint force (kN)")
        ax.grid(alpha=0.3)
        ax = fig.add_subplot(grid[row, 1])
        ring = np.linspace(0, 2 * np.pi, 361)
        ax.plot(np.cos(ring), np.sin(ring), color="0.4", lw=1)
        ex, ey = ds["ex" + key].values / rc, ds["ey" + key].values / rc
        if t_up is not None:
            ax.plot(ex[~steady], ey[~steady], lw=0.5, color=grey, label="start-up")
        ax.plot(ex[steady], ey[steady], lw=0.5, color="C0")
        ax.set_aspect("equal")
        lim = max(1.1, float(np.nanmax(np.hypot(ex[steady], ey[steady]))) * 1.05)
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_xlabel("e_x / c")
        ax.set_ylabel("e_y / c")
        ax.set_title(f"{where}: journal orbit in the clearance circle (c = {1e3 * rc:g} mm)",
                     fontsize=9)  # fmt: skip
        ax.grid(alpha=0.3)
        if t_up is not None:
            ax.legend(fontsize=7, loc="upper right")
        ax = fig.add_subplot(grid[row, 2], projection="polar")
        fx, fy = ds["joint_force_x" + key].values / 1e3, ds["joint_force_y" + key].values / 1e3
        ang, mag = np.arctan2(fy, fx), np.hypot(fx, fy)
        if t_up is not None:
            ax.plot(ang[~steady], mag[~steady], ".", ms=1, color=grey)
        ax.plot(ang[steady], mag[steady], ".", ms=1, color="C0")
        top = float(np.nanmax(mag[steady])) if np.isfinite(mag[steady]).any() else 1.0
        ax.set_rmax(1.08 * top if top > 0 else 1.0)
        ax.yaxis.set_major_locator(MaxNLocator(4))
        ax.set_rlabel_position(_emptiest_direction(ang[steady]))  # over the fewest points
        ax.tick_params(labelsize=7)
        ax.set_title(f"{where}: joint force on the rod, polar (kN)", fontsize=9, pad=12)
    footer = (
        f"compressor-contact, clearance at {joints}, law {ds.attrs.get('param_contact_law')}"
        f" e={ds.attrs.get('param_restitution')}, friction {ds.attrs.get('param_friction')}"
        f", omega={ds.attrs['param_omega']:g} rad/s | {ds.attrs.get('solver_method')} "
        f"rtol={ds.attrs.get('solver_rtol')} | recipdyn {ds.attrs.get('recipdyn_version')}"
    )
    add_footer(fig, footer)
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
    add_footer(fig, provenance_footer(ds))
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
