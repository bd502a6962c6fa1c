"""Plots of analysis results (matplotlib; headless-safe)."""

from __future__ import annotations

import numpy as np

from ..plotting import _mpl

__all__ = ["plot_spectrum", "plot_phase", "plot_lyapunov_history", "plot_divergence"]


def plot_spectrum(spec, peaks=(), ax=None, fmax=None, title=None):
    """Amplitude spectrum with labelled peaks (k x for harmonics, frequency otherwise)."""
    plt = _mpl()
    if ax is None:
        _, ax = plt.subplots(figsize=(8, 4), constrained_layout=True)
    ax.plot(spec.frequency, spec.amplitude, lw=0.7)
    for p in peaks:
        label = f"{p.order}x" if p.order else f"{p.frequency:.4g} Hz"
        ax.annotate(label, (p.frequency, p.amplitude), fontsize=7, xytext=(2, 2),
                    textcoords="offset points")  # fmt: skip
    ax.set_xlim(0, fmax or spec.frequency[-1])
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("amplitude")
    ax.set_title(title or f"spectrum ({spec.window} window, resolution {spec.resolution:.3g} Hz)")
    ax.grid(alpha=0.3)
    return ax.figure


def plot_phase(x, y, xlabel="x", ylabel="y", ax=None, title=None, points=False):
    plt = _mpl()
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 5), constrained_layout=True)
    ax.plot(x, y, "." if points else "-", ms=2, lw=0.4)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.grid(alpha=0.3)
    return ax.figure


def plot_lyapunov_history(res, ax=None, unit="1/s"):
    """Running Benettin estimates against averaging time."""
    plt = _mpl()
    if ax is None:
        _, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    for i in range(res.history.shape[1]):
        ax.plot(res.times, res.history[:, i], label=f"lambda_{i + 1} = {res.exponents[i]:.4g}")
    ax.axhline(0, color="k", lw=0.6)
    ax.set_xlabel("averaging time")
    ax.set_ylabel(f"exponent ({unit})")
    ax.set_title(f"Benettin convergence (sum = {res.sum:.3g})")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    return ax.figure


def plot_divergence(res, ax=None):
    """Divergence curve (Rosenstein/Kantz) with the fitted region, or Wolf's running estimate."""
    plt = _mpl()
    if ax is None:
        _, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    dt = res.params.get("dt", 1.0)
    t = np.asarray(res.steps) * dt
    ax.plot(t, res.curve, lw=0.8)
    if res.fit is not None:
        lo, hi = res.fit
        ax.axvspan(t[lo], t[hi], color="C1", alpha=0.2, label="fitted region")
        ax.plot(t[lo : hi + 1], res.curve[lo] + res.exponent * (t[lo : hi + 1] - t[lo]), "C1--",
                label=f"slope {res.exponent:.4g}")  # fmt: skip
    ax.set_xlabel("time")
    ax.set_ylabel("running estimate" if res.method == "wolf" else "<ln divergence>")
    ax.set_title(f"{res.method}: lambda_1 = {res.exponent:.4g}  (dim {res.params.get('dim')}, "
                 f"delay {res.params.get('delay')})")  # fmt: skip
    ax.legend(fontsize=7) if res.fit is not None else None
    ax.grid(alpha=0.3)
    return ax.figure
