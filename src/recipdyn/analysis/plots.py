"""Plots of analysis results (matplotlib; headless-safe)."""

from __future__ import annotations

import numpy as np

from ..mplstyle import _mpl

__all__ = [
    "plot_spectrum",
    "plot_phase",
    "plot_lyapunov_history",
    "plot_divergence",
    "plot_vibration",
]


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
    what = f"lambda_1 = {res.exponent:.4g}" if res.ok else "refused"
    ax.set_title(f"{res.method}: {what}  (dim {res.params.get('dim')}, "
                 f"delay {res.params.get('delay')})")  # fmt: skip
    if not res.ok:
        import textwrap

        ax.text(0.02, 0.95, textwrap.fill(res.reason, 80), transform=ax.transAxes, va="top",
                fontsize=7, bbox=dict(fc="w", ec="0.6"))  # fmt: skip
    ax.legend(fontsize=7) if res.fit is not None else None
    ax.grid(alpha=0.3)
    return ax.figure


def plot_vibration(rep, title: str = "", unit: str = ""):
    """The vibration engineer's page
    ([`vibration_report`][recipdyn.analysis.vibration.vibration_report]): order spectrum, Campbell
    diagram or spectrogram, envelope spectrum, cepstrum, impacts over the crank angle,
    indicators."""
    plt = _mpl()
    fig, axes = plt.subplots(2, 3, figsize=(16, 8.5), constrained_layout=True)
    ax = axes[0, 0]
    if "orders" in rep:
        o = rep["orders"]
        strong = o.frequency[o.amplitude > 0.03 * o.amplitude.max()]
        top = max(10.0, min(200.0, 1.1 * strong.max())) if strong.size else 40.0
        keep = (o.frequency <= top) & (o.frequency > 0)
        ax.semilogy(o.frequency[keep], o.amplitude[keep] + 1e-9 * o.amplitude.max(), lw=0.8)
        ax.set_ylim(1e-5 * o.amplitude.max(), 2 * o.amplitude.max())
        ax.set_xlabel("crank order")
        ax.set_title(f"order spectrum (resolution {o.resolution:.3g} order)")
    else:
        ax.text(0.5, 0.5, "no crank angle: give --tacho or --speed", ha="center",
                transform=ax.transAxes)  # fmt: skip
        ax.set_title("order spectrum")
    ax.set_ylabel(f"amplitude {unit}".strip())
    ax = axes[0, 1]
    if "campbell" in rep:
        f, sp, A = rep["campbell"]
        order = np.argsort(sp)
        mesh = ax.pcolormesh(f, sp[order], 20 * np.log10(A[order] + 1e-12 * A.max()),
                             shading="auto", cmap="viridis")  # fmt: skip
        for k in range(1, 11):
            ax.plot(k * sp[order], sp[order], "w--", lw=0.5)
        ax.set_xlim(0, min(f[-1], 12 * sp.max()))
        ax.set_xlabel("frequency (Hz)")
        ax.set_ylabel("crank speed (Hz)")
        ax.set_title("Campbell diagram (dashed: orders 1-10)")
    else:
        f, t, A = rep["spectrogram"]
        mesh = ax.pcolormesh(t, f, 20 * np.log10(A + 1e-12 * A.max()), shading="auto",
                             cmap="viridis")  # fmt: skip
        ax.set_xlabel("time (s)")
        ax.set_ylabel("frequency (Hz)")
        ax.set_title("spectrogram")
    fig.colorbar(mesh, ax=ax, label="dB")
    ax = axes[0, 2]
    e = rep["envelope"]
    keep = e.frequency <= min(e.frequency[-1], 1000.0)
    ax.plot(e.frequency[keep], e.amplitude[keep], lw=0.8)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("envelope amplitude")
    lo, hi = rep["summary"]["envelope_band_hz"]
    ax.set_title(f"envelope spectrum (band {lo:.0f}-{hi:.0f} Hz)")
    ax = axes[1, 0]
    q, c = rep["cepstrum"]
    keep = (q > 2.0 / rep["fs"]) & (q < 0.5)
    ax.plot(q[keep] * 1e3, c[keep], lw=0.7)
    ax.set_xlabel("quefrency (ms)")
    ax.set_ylabel("real cepstrum")
    ax.set_title("cepstrum (harmonic families and echoes)")
    ax = axes[1, 1]
    hits = rep["impacts"]
    known = [h for h in hits if np.isfinite(h.angle_deg)]
    if known:
        ax.scatter([h.angle_deg for h in known], [h.revolution for h in known],
                   s=12, c=[h.peak for h in known], cmap="viridis")  # fmt: skip
        ax.set_xlim(0, 360)
        ax.set_xticks(range(0, 361, 60))
        ax.set_xlabel("crank angle at onset (deg)")
        ax.set_ylabel("revolution")
    else:
        ax.plot([h.start for h in hits], [h.peak for h in hits], "o", ms=3)
        ax.set_xlabel("onset time (s)")
        ax.set_ylabel("envelope peak")
    ax.set_title(f"impacts: {len(hits)} found")
    ax = axes[1, 2]
    ax.axis("off")
    s = rep["summary"]
    lines = [f"{k:>14s}  {v:.4g}" for k, v in s["indicators"].items()]
    if "velocity_rms_2_1000hz" in s:
        lines.append(f"{'v RMS 2-1000Hz':>14s}  {s['velocity_rms_2_1000hz']:.4g}"
                     + (f"  zone {s['zone']}" if "zone" in s else ""))  # fmt: skip
    if s["impacts"]["per_revolution"] is not None:
        lines.append(f"{'impacts/rev':>14s}  {s['impacts']['per_revolution']:.3g}")
    ax.text(0.0, 1.0, "\n".join(lines), family="monospace", va="top", fontsize=10,
            transform=ax.transAxes)  # fmt: skip
    for a in axes.flat[:5]:
        a.grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    return fig
