"""The motor-driven crank: speed ripple and its effect on the order spectrum.

Draws ``motor_drive.png`` (into the folder given as the first argument, default: here): the
crank speed over the crank angle for three drive inertias, and the crosshead acceleration's
crank-order spectrum against the prescribed speed, for the compression-cycle load on the
ideal crank pin (rc = 0: the massless link cannot carry the cycle's reversing rod load).
Runs in about a minute.
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import recipdyn  # noqa: E402
from recipdyn.model import CompressorParams  # noqa: E402


def order_spectrum(theta1: np.ndarray, a: np.ndarray, per_rev: int = 256):
    """Amplitude per crank order of ``a`` resampled uniformly in the crank angle."""
    n = int((theta1[-1] - theta1[0]) // (2 * np.pi))
    grid = theta1[0] + np.arange(n * per_rev) * (2 * np.pi / per_rev)
    spec = 2 * np.abs(np.fft.rfft(np.interp(grid, theta1, a))) / (n * per_rev)
    return np.arange(spec.size) / n, spec


def main(out: Path) -> None:
    base = dict(rc=0.0, load="cycle")
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4), layout="constrained")
    rows = []
    for J in (300.0, 1000.0, 3000.0):
        ds = recipdyn.simulate(CompressorParams(drive="motor", J_drive=J, **base),
                               revolutions=6, transient=10, fs=4000.0)  # fmt: skip
        th, w = ds.theta1.values, ds.omega1.values
        last = th >= th[-1] - 2 * np.pi
        ax1.plot(np.degrees(th[last] - th[last][0]), w[last], label=f"J = {J:g} kg m²")
        o, s = order_spectrum(th, ds.a.values)
        rows.append((J, w.mean(), (w.max() - w.min()) / w.mean(), o, s))
    J, wm, ripple, o, s = rows[1]
    ref = recipdyn.simulate(CompressorParams(omega=float(wm), **base), revolutions=6,
                            transient=10, fs=4000.0)  # fmt: skip
    o_ref, s_ref = order_spectrum(ref.theta1.values, ref.a.values)
    keep = o <= 12
    ax2.semilogy(o[keep], s[keep] + 1e-6, "o-", ms=3, label=f"motor, J = {J:g} kg m²")
    keep = o_ref <= 12
    ax2.semilogy(o_ref[keep], s_ref[keep] + 1e-6, "s--", ms=3, label="prescribed speed")
    ax1.set(xlabel="crank angle over the last revolution (deg)", ylabel="crank speed (rad/s)",
            title="speed ripple, induction motor, cycle load")  # fmt: skip
    ax1.legend()
    ax2.set(xlabel="crank order", ylabel="crosshead acceleration (m/s²)",
            title="order spectrum", ylim=(1e-3, None))  # fmt: skip
    ax2.legend()
    fig.savefig(out / "motor_drive.png", dpi=90)
    for J, wm, ripple, o, s in rows:
        print(
            f"J = {J:6g} kg m2: mean speed {wm:.3f} rad/s, ripple {100 * ripple:.2f} %, "
            "orders 1-4: " + ", ".join(f"{s[np.argmin(abs(o - k))]:.3f}" for k in (1, 2, 3, 4))
        )
    print(
        "prescribed: orders 1-4: "
        + ", ".join(f"{s_ref[np.argmin(abs(o_ref - k))]:.3f}" for k in (1, 2, 3, 4))
    )


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent)
