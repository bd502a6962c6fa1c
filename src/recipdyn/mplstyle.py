"""Matplotlib, headless-safe, with recipdyn's colour cycle: the floor every figure uses.

Kept apart from [`recipdyn.plotting`][recipdyn.plotting] so that the generic analysis layer can draw
without importing the compressor's figures.
"""

from __future__ import annotations

__all__ = ["PALETTE", "_mpl"]

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
