"""Matplotlib, headless-safe, with recipdyn's colour cycle: the floor every figure uses.

Kept apart from [`recipdyn.plotting`][recipdyn.plotting] so that the generic analysis layer can draw
without importing the compressor's figures.
"""

from __future__ import annotations

__all__ = ["PALETTE", "_mpl", "is_dense", "orbit_density", "dense_orbit"]

#: Okabe & Ito (2008) colour-blind-safe palette, black last; the default colour cycle of
#: every recipdyn figure.
PALETTE = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442",
           "#000000")  # fmt: skip


def _mpl():
    """pyplot on a file backend (Agg unless a file backend is set), with
    [`PALETTE`][recipdyn.mplstyle.PALETTE]."""
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "pdf", "svg", "cairo"):
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from cycler import cycler

    matplotlib.rcParams["axes.prop_cycle"] = cycler(color=PALETTE)
    return plt


def _columns(ax) -> int:
    """Width of the axes in pixels at the figure's dpi (before layout: an estimate)."""
    fig = ax.get_figure()
    return max(100, int(ax.get_position().width * fig.get_figwidth() * fig.dpi))


def is_dense(y, columns: int, per_column: float = 1 / 3) -> bool:
    """True when ``y`` has more than ``per_column * columns`` clear oscillations (prominence
    above 1 % of its range): drawn as a line it fills the axes as a solid block."""
    import numpy as np

    y = np.asarray(y, dtype=float)
    span = float(np.ptp(y)) if y.size else 0.0
    if y.size < 3 * columns or not span > 0:
        return False
    # every peak find_peaks reports is a rise followed by a fall or a plateau: when there are
    # too few of those, the answer is known without SciPy's signal module (~0.8 s to import)
    dy = np.diff(y)
    if np.count_nonzero((dy[:-1] > 0) & (dy[1:] <= 0)) <= per_column * columns:
        return False
    from scipy.signal import find_peaks

    peaks, _ = find_peaks(y, prominence=0.01 * span)
    return peaks.size > per_column * columns


def orbit_density(ax, x, y):
    """Draw the orbit ``(x, y)`` as its occupation density: a 2-D histogram of the samples
    (uniform in time, so each cell's value is the fraction of the time spent there) on a log
    colour scale over three decades. Where a line would fill the axes as one block (a chaotic
    or quasi-periodic orbit over many turns), this shows where the motion dwells and the
    structure of the attractor. Returns the mesh (for a colour bar)."""
    import numpy as np
    from matplotlib.colors import LogNorm

    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    cols = _columns(ax)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    bins = (cols // 5, cols // 6)
    # a short record has fewer samples than cells: the path between samples, linearly
    # interpolated (uniform in time, as the samples are), fills about ten points per cell
    k = int(min(20, np.ceil(10 * bins[0] * bins[1] / max(x.size, 1))))
    if k > 1 and x.size > 1:
        s = np.arange((x.size - 1) * k + 1) / k
        x, y = np.interp(s, np.arange(x.size), x), np.interp(s, np.arange(y.size), y)
    h, xe, ye = np.histogram2d(x, y, bins=bins)
    h = np.where(h > 0, h / h.sum(), np.nan)
    return ax.pcolormesh(xe, ye, h.T, cmap="Blues", norm=LogNorm(vmin=np.nanmax(h) * 1e-3),
                         shading="flat", rasterized=True)  # fmt: skip


def dense_orbit(ax, x, y) -> bool:
    """True when the orbit ``(x, y)`` drawn as a line would be a solid blob: either it turns
    more than twice per pixel column of ``ax`` (a 2-D line takes more room than a signal's),
    or its path is longer than twice the axes' area in pixels (a 1-pixel line would ink it
    twice over) while it visits more than 15 % of a 40 x 40 grid over its range (a periodic
    orbit retraced many times visits few cells and stays a line)."""
    import numpy as np

    cols = _columns(ax)
    if is_dense(x, cols, 2.0) or is_dense(y, cols, 2.0):
        return True
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    if x.size < 3 or not (np.ptp(x) > 0 and np.ptp(y) > 0):
        return False
    fig = ax.get_figure()
    rows = max(80, int(ax.get_position().height * fig.get_figheight() * fig.dpi))
    u = (x - x.min()) / np.ptp(x)
    v = (y - y.min()) / np.ptp(y)
    length = float(np.sum(np.hypot(np.diff(u) * cols, np.diff(v) * rows)))
    if length < 2.0 * cols * rows:
        return False
    cells = np.unique(
        np.minimum((u * 40).astype(int), 39) * 40 + np.minimum((v * 40).astype(int), 39)
    )
    return cells.size > 0.15 * 1600
