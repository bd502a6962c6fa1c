"""The paper's figures, regenerated (same cases, same layout, units on every axis).

Each ``fig_*`` function returns ``{file_stem: Figure}``; the runner saves them as PNG. Figures
that depend on the initial condition are drawn once per variant (``natural``, ``offset``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.ticker import MaxNLocator

from ..io import save_figure
from ..model.load import mu_paper
from ..plotting import PALETTE, _mpl, centred, is_dense, plot_orbit, plot_signal, unit_tex
from .cases import case_by_id

__all__ = ["FIGURES", "make_all_figures"]

PANEL = "abcd"
TIME_VARS = (("x", "displacement x3 (m)"), ("v", "velocity (m/s)"),
             ("a", "acceleration (m/s$^2$)"))  # fmt: skip


def _grid(plt, title):
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5), constrained_layout=True)
    fig.suptitle(title)
    return fig, axes.ravel()


def fig02_load(runs, variant):
    plt = _mpl()
    th = np.linspace(0, 2 * np.pi, 2001)
    fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    ax.plot(np.rad2deg(th), 200000 * mu_paper(th) / 1e3)
    for b in (7 / 16, 1, 23 / 16):
        ax.axvline(180 * b, color="0.7", lw=0.8, ls="--")
    for x, name in ((20, "expansion"), (120, "suction"), (210, "compression"), (300, "exhaust")):
        ax.text(x, 205, name, fontsize=8)
    ax.set_xlabel("crank angle $\\theta_1$ (deg)")
    ax.set_ylabel("cylinder load P = 200000 $\\mu$ (kN)")
    ax.set_title("Fig. 2: cylinder load over a cycle (Eq. 1-2)")
    ax.set_ylim(0, 220)
    ax.grid(alpha=0.3)
    return {"fig02_load": fig}


def _response(ds, title, fmax):
    plt = _mpl()
    fig, axes = _grid(plt, title)
    t = ds.time.values
    for ax, (name, label), pl in zip(axes[:3], TIME_VARS, PANEL, strict=False):
        plot_signal(ax, t, ds[name].values, lw=0.6)
        ax.set_xlabel("time (s)")
        ax.set_ylabel(f"{pl}) {label}")
        ax.grid(alpha=0.3)
    ax = axes[3]
    ax.plot(ds.frequency, ds.spectrum_a, lw=0.7)
    ax.set_xlim(0, fmax)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("d) amplitude of a (m/s$^2$)")
    ax.grid(alpha=0.3)
    return fig


def _responses(runs, variant, spec):
    out = {}
    for num, cid in spec:
        ds = runs[(cid, variant)]
        c = case_by_id(cid)
        from .report import _nonharmonic_fundamental

        f_link = _nonharmonic_fundamental(ds)  # show the link oscillation when there is one
        f_top = 30 * ds.attrs["crank_frequency_hz"] if not np.isfinite(f_link) else 1.6 * f_link
        f_top = min(float(ds.frequency.max()), max(f_top, 50.0))
        out[f"fig{num:02d}_{variant}"] = _response(
            ds, f"Fig. {num}: crosshead response, {c.label} [{variant}]", f_top
        )
    return out


def figs04_07(runs, variant):
    return _responses(runs, variant, [(4, "rc0_d0_w20"), (5, "rc0.1_d0_w20"),
                                      (6, "rc0.5_d0_w20"), (7, "rc5_d0_w20")])  # fmt: skip


def figs14_16(runs, variant):
    return _responses(runs, variant, [(14, "rc1_d1_w10"), (15, "rc1_d1_w70"),
                                      (16, "rc1_d1_w150")])  # fmt: skip


def _overlay(runs, variant, num, var, label, cids, what):
    """The paper's overlay of one signal over several cases, readable: when the signals are
    smooth, the overlay and below it each case's difference from the first (reference) case,
    which the overlay hides when the curves nearly coincide; when a case carries a fast
    oscillation (the offset start's link ringing), one row per case on shared axes, each drawn
    by [`plot_signal`][recipdyn.plotting.plot_signal] (envelope and zoom) instead of an overplot."""
    plt = _mpl()
    sets = [runs[(cid, variant)] for cid in cids]
    names = [case_by_id(cid).label for cid in cids]
    unit = label[label.rfind("(") :]
    if any(is_dense(ds[var].values, 700) for ds in sets):
        fig, axes = plt.subplots(len(cids), 1, figsize=(9, 1.7 * len(cids) + 1.0),
                                 sharex=True, sharey=True, constrained_layout=True)  # fmt: skip
        for ax, ds, name, color in zip(axes, sets, names, PALETTE, strict=False):
            plot_signal(ax, ds.time.values, ds[var].values, color=color, lw=0.6)
            ax.set_title(name, fontsize=8, loc="left", pad=2)
            ax.grid(alpha=0.3)
        axes[-1].set_xlabel("time (s)")
        fig.supylabel(label)
        fig.suptitle(f"Fig. {num}: crosshead {what} [{variant}], one row per case")
        return fig
    fig, (ax, axd) = plt.subplots(2, 1, figsize=(9, 6.4), sharex=True, height_ratios=(3, 2),
                                  constrained_layout=True)  # fmt: skip
    ref = sets[0]
    for ds, name, color in zip(sets, names, PALETTE, strict=False):
        ax.plot(ds.time, ds[var], lw=0.8, label=name, color=color)
        n = min(ds.sizes["time"], ref.sizes["time"])
        if ds is not ref:
            axd.plot(ds.time[:n], ds[var].values[:n] - ref[var].values[:n], lw=0.8, color=color)
    ax.set_ylabel(label)
    ax.set_title(f"Fig. {num}: comparison of crosshead {what} [{variant}]")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    axd.set_xlabel("time (s)")
    axd.set_ylabel(f"difference from the\nfirst case {unit}")
    axd.axhline(0, color="k", lw=0.5)
    axd.grid(alpha=0.3)
    return fig


def figs08_13(runs, variant):
    out = {}
    rc_cases = ["rc0_d0_w20", "rc0.1_d0_w20", "rc0.5_d0_w20", "rc1_d0_w20", "rc5_d0_w20"]
    d_cases = ["rc1_d0_w20", "rc1_d0.1_w20", "rc1_d1_w20", "rc1_d5_w20"]
    for k, (var, label) in enumerate(TIME_VARS):
        what = ("displacement", "velocity", "acceleration")[k]
        out[f"fig{8 + k:02d}_{variant}"] = _overlay(
            runs, variant, 8 + k, var, label, rc_cases, f"{what}, clearance sweep"
        )
        out[f"fig{11 + k:02d}_{variant}"] = _overlay(
            runs, variant, 11 + k, var, label, d_cases, f"{what}, subsidence sweep"
        )
    return out


PHASE_SETS = {
    17: ("rc0_d0_w20",),
    18: ("rc0.1_d1_w20", "rc0.5_d1_w20", "rc1_d1_w20", "rc5_d1_w20"),
    20: ("rc1_d0_w20", "rc1_d0.1_w20", "rc1_d1_w20", "rc1_d5_w20"),
    22: ("rc5_d1_w10", "rc5_d1_w20", "rc5_d1_w70", "rc5_d1_w150"),
}


def figs17_23(runs, variant):
    plt = _mpl()
    out = {}
    for num, cids in PHASE_SETS.items():
        pairs = [("x", "v", "x-v")] if num == 17 else [("x", "v", "x-v"), ("v", "a", "v-a")]
        if num == 17:
            fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), constrained_layout=True)
            ds = runs[(cids[0], variant)]
            for ax, (a, b) in zip(axes, (("x", "v"), ("v", "a")), strict=True):
                plot_orbit(ax, ds[a].values, ds[b].values)
                ax.set_xlabel(f"{a} ({unit_tex(ds[a].attrs['units'])})")
                ax.set_ylabel(f"{b} ({unit_tex(ds[b].attrs['units'])})")
                ax.grid(alpha=0.3)
            fig.suptitle(f"Fig. 17: phase trajectories, no clearance, no subsidence [{variant}]")
            out[f"fig17_{variant}"] = fig
            continue
        for j, (a, b, kind) in enumerate(pairs):
            fig, axes = _grid(plt, f"Fig. {num + j}: phase trajectories {kind} [{variant}]")
            for ax, cid, pl in zip(axes, cids, PANEL, strict=True):
                ds = runs[(cid, variant)]
                plot_orbit(ax, ds[a].values, ds[b].values, lw=0.4)
                ax.set_title(f"{pl}) {case_by_id(cid).label}", fontsize=9)
                ax.set_xlabel(f"{a} ({unit_tex(ds[a].attrs['units'])})")
                ax.set_ylabel(f"{b} ({unit_tex(ds[b].attrs['units'])})")
                ax.grid(alpha=0.3)
            out[f"fig{num + j:02d}_{variant}"] = fig
    return out


def figs25_28(runs, variant):
    plt = _mpl()
    out = {}
    for num, src in ((25, 17), (26, 18), (27, 20), (28, 22)):
        cids = PHASE_SETS[src]
        if len(cids) == 1:
            fig, axes = plt.subplots(1, 1, figsize=(6, 4.5), constrained_layout=True)
            axes = [axes]
        else:
            fig, axes = _grid(plt, "")
        fig.suptitle(f"Fig. {num}: Poincaré sections (v, a), once per crank revolution "
                     f"[{variant}]")  # fmt: skip
        for ax, cid, pl in zip(axes, cids, PANEL, strict=False):
            ds = runs[(cid, variant)]
            xv, xlab = centred(ds.poincare_v.values, "v", "m/s")
            ya, ylab = centred(ds.poincare_a.values, "a", "m/s^2")
            ax.plot(xv, ya, ".", ms=3)
            n_pts = ds.attrs["m_poincare_distinct"]
            what = f"{n_pts} distinct points" if n_pts >= 0 else "run failed"
            ax.set_title(f"{pl}) {case_by_id(cid).label}: {what}", fontsize=9)
            ax.set_xlabel(xlab)
            ax.set_ylabel(ylab)
            ax.xaxis.set_major_locator(MaxNLocator(5))
            ax.grid(alpha=0.3)
        out[f"fig{num:02d}_{variant}"] = fig
    return out


LYAP_SETS = {
    "a": ("clearance (mm)", [("rc0.1_d1_w20", 0.1), ("rc0.5_d1_w20", 0.5), ("rc1_d1_w20", 1),
                             ("rc5_d1_w20", 5)], [1.57, 0.68, 0.62, 0.59]),
    "b": ("subsidence (mm)", [("rc1_d0_w20", 0), ("rc1_d0.1_w20", 0.1), ("rc1_d1_w20", 1),
                              ("rc1_d5_w20", 5)], [0.51, 0.53, 0.62, 0.52]),
    "c": ("crank speed (rad/s)", [("rc5_d1_w10", 10), ("rc5_d1_w20", 20), ("rc5_d1_w70", 70),
                                  ("rc5_d1_w150", 150)], [0.97, 0.59, 0.23, 1.5]),
}  # fmt: skip


def fig24_lyapunov(runs, variant):
    plt = _mpl()
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.5), constrained_layout=True)
    for ax, (pl, (xlabel, pts, paper)) in zip(axes, LYAP_SETS.items(), strict=True):
        idx = np.arange(len(pts))
        wolf = [runs[(c, variant)].attrs["m_lyap_wolf"] for c, _ in pts]
        ben = [runs[(c, variant)].attrs["m_lyap_benettin"] for c, _ in pts]
        ax.bar(idx - 0.27, paper, 0.27, label="paper (Wolf, units not stated)")
        ax.bar(idx, wolf, 0.27, label="ours: Wolf on a (1/s)")
        ax.bar(idx + 0.27, ben, 0.27, label="ours: Benettin, equations (1/s)")
        ax.set_xticks(idx, [f"{v:g}" for _, v in pts])
        ax.set_xlabel(xlabel)
        ax.set_ylabel("largest Lyapunov exponent")
        ax.set_title(f"{pl})")
        ax.axhline(0, color="k", lw=0.6)
        ax.grid(alpha=0.3, axis="y")
    axes[0].legend(fontsize=7)
    fig.suptitle(f"Fig. 24: largest Lyapunov exponents per sweep [{variant}]")
    return {f"fig24_{variant}": fig}


FIGURES = (figs04_07, figs08_13, figs14_16, figs17_23, fig24_lyapunov, figs25_28)


def save_figures(figs: dict, folder: Path, dpi: int = 100) -> dict[str, Path]:
    """Save and close figures; returns ``{stem: path}``."""
    plt = _mpl()
    paths = {}
    for stem, fig in figs.items():
        paths[stem] = folder / f"{stem}.png"
        save_figure(fig, paths[stem], dpi=dpi)
        plt.close(fig)
    return paths


def make_all_figures(runs, variants, folder: Path, progress: bool = False) -> dict[str, Path]:
    """Every figure for every variant, plus Fig. 2 once, saved as PNG in ``folder`` (with a
    progress bar over the figure groups when ``progress``)."""
    out = save_figures(fig02_load(runs, None), folder)
    jobs = [(f, v) for v in variants for f in FIGURES]
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(jobs), desc="reproduce: figures", unit="group")
    for f, v in jobs:
        out.update(save_figures(f(runs, v), folder))
        if bar is not None:
            bar.set_postfix_str(f"{f.__name__} [{v}]")
            bar.update(1)
    if bar is not None:
        bar.close()
    return out
