"""Plots of analysis results (matplotlib; headless-safe)."""

from __future__ import annotations

import numpy as np

from ..mplstyle import _mpl, dense_orbit, orbit_density

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
    ax.set_xlim(0, fmax or spec.frequency[-1])
    ax.set_ylim(0, 1.12 * max(float(np.max(spec.amplitude, initial=0.0)), 1e-300))
    # strongest first; a label that would cover one already placed is left out (a cluster of
    # lines a few bins apart gets the label of its strongest)
    placed: list[tuple[float, float]] = []
    lo, hi = ax.get_xlim()
    top = ax.get_ylim()[1]
    for p in sorted(peaks, key=lambda p: -p.amplitude):
        u, v = (p.frequency - lo) / (hi - lo), p.amplitude / top
        if not 0 <= u <= 1 or any(abs(u - a) < 0.07 and abs(v - b) < 0.06 for a, b in placed):
            continue
        placed.append((u, v))
        label = f"{p.order}x" if p.order else f"{p.frequency:.4g} Hz"
        ax.annotate(label, (p.frequency, p.amplitude), fontsize=7, xytext=(2, 2),
                    textcoords="offset points", ha="right" if u > 0.93 else "left")  # fmt: skip
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("amplitude")
    ax.set_title(title or f"spectrum ({spec.window} window, resolution {spec.resolution:.3g} Hz)")
    ax.grid(alpha=0.3)
    return ax.figure


def plot_phase(x, y, xlabel="x", ylabel="y", ax=None, title=None, points=False):
    """A phase portrait of ``(x, y)``: a line, or points (``points``: a section). An orbit
    that turns more than twice per pixel column (a chaotic or quasi-periodic orbit over many
    periods, which a line draws as a solid blob) is drawn as its occupation density, the
    fraction of the time spent in each cell on a log colour scale
    (`recipdyn.mplstyle.orbit_density`): it shows where the motion dwells and the
    attractor's structure; its Poincaré section is the complementary view."""
    plt = _mpl()
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 5), constrained_layout=True)
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if not points and dense_orbit(ax, x, y):
        mesh = orbit_density(ax, x, y)
        ax.figure.colorbar(mesh, ax=ax, label="fraction of time per cell", pad=0.01)
        title = f"{title}: occupation density" if title else "occupation density"
    else:
        ax.plot(x, y, "." if points else "-", ms=2, lw=0.4)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.grid(alpha=0.3)
    return ax.figure


def _time_unit(unit: str) -> str:
    """The time unit of an exponent's unit: ``1/s`` or ``per s`` -> ``s``; ``per iteration``
    or ``1/iteration`` -> ``iterations``."""
    u = unit.removeprefix("1/").removeprefix("per ").strip() or "s"
    return "iterations" if u in ("iteration", "iterations") else u


def plot_lyapunov_history(res, ax=None, unit="1/s"):
    """Running Benettin estimates against averaging time; ``unit`` is the exponents' unit
    (``1/s``; ``per iteration`` for a map), the averaging time's unit follows from it."""
    plt = _mpl()
    if ax is None:
        _, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    for i in range(res.history.shape[1]):
        ax.plot(res.times, res.history[:, i], label=f"lambda_{i + 1} = {res.exponents[i]:.4g}")
    ax.axhline(0, color="k", lw=0.6)
    ax.set_xlabel(f"averaging time ({_time_unit(unit)})")
    ax.set_ylabel(f"exponent ({unit})")
    ax.set_title(f"Benettin convergence (sum = {res.sum:.3g})")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    return ax.figure


def plot_divergence(res, ax=None, time_unit: str = "s"):
    """Divergence curve (Rosenstein/Kantz) with the fitted region, or Wolf's running estimate,
    against time in ``time_unit``, the unit of the sampling step ``dt`` the estimate was given
    (``"samples"`` when it was given none)."""
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
    ax.set_xlabel(f"{'time' if res.method == 'wolf' else 'divergence time'} ({time_unit})")
    per = "sample" if time_unit == "samples" else time_unit
    ax.set_ylabel(f"running estimate (1/{per})" if res.method == "wolf" else "<ln divergence>")
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
