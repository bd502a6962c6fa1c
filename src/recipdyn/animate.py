"""Animation of the mechanism from a record: crank, clearance link, rod, crosshead.

The clearance (a millimetre beside a 120 mm crank) and the subsidence are invisible at true
scale, so both are drawn magnified by ``exaggerate``; the mechanism is then closed with the
magnified values (the same closure as the model, paper Eq. 4-6), so the drawing is the
model's geometry at a larger clearance, not a distorted picture. Below it the crosshead
acceleration runs with a cursor.

GIF needs nothing beyond matplotlib and Pillow; MP4 needs ``ffmpeg`` on the PATH.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import ParameterError
from .io import atomic_path, check_output, write_error
from .plotting import PALETTE, _mpl

__all__ = ["Mechanism", "mechanism_points", "animate_run", "ANIMATION_FORMATS"]

ANIMATION_FORMATS = {".gif": "GIF", ".mp4": "MP4"}


@dataclass(frozen=True)
class Mechanism:
    """Positions (m) over the frames: crank pin ``B``, rod big end ``J`` (the clearance link
    runs B -> J), crosshead ``C``; the crank centre is the origin."""

    B: np.ndarray
    J: np.ndarray
    C: np.ndarray


def mechanism_points(theta1, theta_c, *, r: float, l: float, rc: float, d: float,
                     exaggerate: float = 1.0) -> Mechanism:  # fmt: skip
    """The mechanism's joints for crank angles ``theta1`` and clearance angles ``theta_c``,
    with ``rc`` and ``d`` magnified by ``exaggerate`` and the rod angle from the closure
    ``sin(theta2) = -(d + r sin(theta1) + rc sin(theta_c)) / l``."""
    th1 = np.asarray(theta1, dtype=float)
    thc = np.asarray(theta_c, dtype=float)
    rc_k, d_k = exaggerate * rc, exaggerate * d
    s2 = -(d_k + r * np.sin(th1) + rc_k * np.sin(thc)) / l
    if np.any(np.abs(s2) >= 1):
        raise ParameterError(f"exaggerate: {exaggerate:g} makes the rod too short to close the "
                             "mechanism; allowed: a smaller factor")  # fmt: skip
    c2 = np.sqrt(1 - s2**2)
    B = np.stack([r * np.cos(th1), r * np.sin(th1)], axis=-1)
    J = B + rc_k * np.stack([np.cos(thc), np.sin(thc)], axis=-1)
    C = J + l * np.stack([c2, s2], axis=-1)
    return Mechanism(B, J, C)


def animate_run(ds, out: str | Path, *, exaggerate: float | None = None, revolutions: float = 2.0,
                frames_per_revolution: int = 48, fps: int = 24, progress=None) -> Path:  # fmt: skip
    """Write an animation of the compressor record ``ds`` to ``out`` (.gif or .mp4).

    ``exaggerate`` magnifies the clearance and the subsidence (default: the clearance drawn as
    15 % of the crank radius); the last ``revolutions`` of the record are shown with
    ``frames_per_revolution`` frames each. ``progress(i, n)`` is called per frame.
    """
    out = check_output(out, formats=ANIMATION_FORMATS, what="animation")
    need = {"theta1", "theta_c", "x", "a"}
    if not need <= set(ds.variables) or "param_r" not in ds.attrs:
        missing = ", ".join(sorted(need - set(ds.variables))) or "param_* attributes"
        raise ParameterError(f"input: {missing} missing; animate takes a record of the "
                             "compressor from 'recipdyn simulate'")  # fmt: skip
    if out.suffix.lower() == ".mp4" and shutil.which("ffmpeg") is None:
        raise ParameterError(f"animation {out}: MP4 needs ffmpeg on the PATH (not found); "
                             "allowed: .gif, or install ffmpeg")  # fmt: skip
    for name, val, lo in (("revolutions", revolutions, 0.0), ("fps", fps, 0),
                          ("frames_per_revolution", frames_per_revolution, 1)):  # fmt: skip
        if not val > lo:
            raise ParameterError(f"{name}: {val}; allowed: > {lo}")
    a = ds.attrs
    r, l, rc, d = (float(a[f"param_{k}"]) for k in ("r", "l", "rc", "d"))
    omega = float(a["param_omega"])
    if exaggerate is None:
        exaggerate = 0.15 * r / rc if rc > 0 else 1.0
    if not exaggerate >= 1:
        raise ParameterError(f"exaggerate: {exaggerate:g}; allowed: >= 1")
    t = ds["time"].values
    period = 2 * np.pi / omega
    t0 = max(t[0], t[-1] - revolutions * period)
    n = max(2, int(round((t[-1] - t0) / period * frames_per_revolution)))
    tf = np.linspace(t0, t[-1], n)
    th1 = np.interp(tf, t, ds["theta1"].values)
    thc = np.interp(tf, t, np.unwrap(ds["theta_c"].values))
    mech = mechanism_points(th1, thc, r=r, l=l, rc=rc, d=d, exaggerate=exaggerate)
    return _render(ds, out, tf, mech, r, l, rc, d, exaggerate, fps, progress)


def _render(ds, out, tf, mech, r, l, rc, d, k, fps, progress) -> Path:
    plt = _mpl()
    from matplotlib.animation import FFMpegWriter, PillowWriter

    fig, (ax, axa) = plt.subplots(2, 1, figsize=(8, 6), height_ratios=(3, 1.3),
                                  constrained_layout=True)  # fmt: skip
    ax.set_aspect("equal")
    ax.set_xlim(-1.3 * r, r + l + 0.35 * r)
    ax.set_ylim(-1.35 * r, 1.35 * r)
    ax.axhline(-k * d, color="0.6", lw=0.8, ls="--")
    ax.plot(np.cos(np.linspace(0, 2 * np.pi, 200)) * r, np.sin(np.linspace(0, 2 * np.pi, 200))
            * r, color="0.85", lw=0.8)  # fmt: skip
    ax.plot(0, 0, "o", color="k", ms=6)
    (crank,) = ax.plot([], [], "-", lw=5, color=PALETTE[0], solid_capstyle="round")
    (ring,) = ax.plot([], [], "-", lw=0.8, color=PALETTE[1])
    (link,) = ax.plot([], [], "-", lw=2.5, color=PALETTE[1])
    (rod,) = ax.plot([], [], "-", lw=4, color=PALETTE[2], solid_capstyle="round")
    head = plt.Rectangle((0, 0), 0.16 * r, 0.22 * r, color=PALETTE[3])
    ax.add_patch(head)
    label = ax.text(0.01, 0.97, "", transform=ax.transAxes, va="top", fontsize=8)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"Mechanism, clearance rc = {1e3 * rc:g} mm and subsidence d = {1e3 * d:g} mm "
                 f"drawn x{k:.3g}", fontsize=9)  # fmt: skip
    t = ds["time"].values
    sel = (t >= tf[0]) & (t <= tf[-1])
    axa.plot(t[sel], ds["a"].values[sel], lw=0.6, color=PALETTE[0])
    cursor = axa.axvline(tf[0], color=PALETTE[1], lw=1)
    axa.set_xlabel("time (s)")
    axa.set_ylabel("a (m/s$^2$)")
    axa.grid(alpha=0.3)
    ring_t = np.linspace(0, 2 * np.pi, 60)
    deg = np.degrees

    def draw(i):
        B, J, C = mech.B[i], mech.J[i], mech.C[i]
        crank.set_data([0, B[0]], [0, B[1]])
        ring.set_data(B[0] + k * rc * np.cos(ring_t), B[1] + k * rc * np.sin(ring_t))
        link.set_data([B[0], J[0]], [B[1], J[1]])
        rod.set_data([J[0], C[0]], [J[1], C[1]])
        head.set_xy((C[0] - 0.08 * r, C[1] - 0.11 * r))
        th1 = np.arctan2(B[1], B[0])
        label.set_text(f"t = {tf[i]:.4f} s, crank angle {deg(th1) % 360:5.1f} deg, "
                       f"x3 = {C[0]:.4f} m (drawn)")  # fmt: skip
        cursor.set_xdata([tf[i], tf[i]])

    writer = PillowWriter(fps=fps) if out.suffix.lower() == ".gif" else FFMpegWriter(fps=fps)
    try:
        with atomic_path(out) as tmp:
            with writer.saving(fig, str(tmp), dpi=80):
                for i in range(tf.size):
                    draw(i)
                    writer.grab_frame()
                    if progress is not None:
                        progress(i + 1, tf.size)
    except (OSError, RuntimeError) as exc:
        raise write_error(out, exc) from None
    finally:
        plt.close(fig)
    return out
