"""The crosshead knock's signature next to the healthy machine (docs/faults.md).

Runs ``compressor-guide-reference`` (the guide's kernel of its own) at 20 rad/s under the
paper's load, one revolution after one: the healthy guide (no clearance) and a worn one
(0.2 mm radial clearance), and draws over crank angle the crosshead's lateral acceleration
(what an accelerometer on the guide sees), its lateral position in the clearance, and the
side force of the shoes with the ideal mechanism's side-force reversals marked. Usage:
``python examples/crosshead_knock_figure.py [OUTDIR]`` (default ``docs/img``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from recipdyn.model.reference.compressor_guide import COMPRESSOR_GUIDE, ideal_crosshead  # noqa: E402
from recipdyn.simulate import simulate  # noqa: E402

CLEARANCE = 2e-4


def main(out: Path) -> dict[str, float]:
    runs = {}
    for c in (0.0, CLEARANCE):
        runs[c] = simulate(model="compressor-guide-reference", params={"guide_clearance": c},
                           revolutions=1, transient=1, fs=40000.0)  # fmt: skip
    v = COMPRESSOR_GUIDE.parameters({"guide_clearance": CLEARANCE})
    fig, ax = plt.subplots(3, 1, figsize=(9, 8.5), sharex=True, constrained_layout=True)
    for c, ds in runs.items():
        deg = np.degrees(ds.theta1.values) - 360.0
        style = dict(color="0.3", ls="--", lw=1.0) if c == 0 else dict(color="C3", lw=0.7)
        label = "healthy guide (no clearance)" if c == 0 else f"worn guide, c = {c * 1e3:g} mm"
        ax[0].plot(deg, ds.guide_acc.values, label=label, **style)
        ax[1].plot(deg, ds.guide_y.values * 1e3, **style)
        ax[2].plot(deg, ds.side_force.values / 1e3, **style)
    th = np.radians(np.linspace(360, 720, 36001))
    side = ideal_crosshead(v, th)["side_force"]
    rev = np.degrees(th[np.nonzero(np.diff(np.sign(side)))[0]]) - 360.0
    ax[2].plot(np.degrees(th) - 360.0, side / 1e3, color="C0", lw=0.8,
               label="ideal mechanism (Newton-Euler)")  # fmt: skip
    for a in ax:
        for r in rev:
            a.axvline(r, color="C0", lw=0.6, ls=":")
        a.grid(alpha=0.3)
    ax[1].axhline(CLEARANCE * 1e3, color="0.5", lw=0.6)
    ax[1].axhline(-CLEARANCE * 1e3, color="0.5", lw=0.6)
    ax[0].set_ylabel("lateral acceleration (m/s²)")
    ax[1].set_ylabel("lateral position (mm)")
    ax[2].set_ylabel("side force of the shoes (kN)")
    ax[2].set_xlabel("crank angle (deg)")
    ax[2].set_xlim(0, 360)
    ax[2].set_xticks(np.arange(0, 361, 45))
    ax[0].legend(fontsize=8)
    ax[2].legend(fontsize=8)
    fig.suptitle("Crosshead knock: 20 rad/s, the paper's load; dotted: side-force reversals")
    fig.savefig(out / "fault_crosshead_knock.png", dpi=100)
    worn = runs[CLEARANCE].attrs
    healthy = runs[0.0].attrs
    return {
        "reversals_deg": [round(float(r), 1) for r in rev],
        "peak_guide_acc_healthy": healthy["peak_abs_guide_acc_m_s2"],
        "peak_guide_acc_worn": worn["peak_abs_guide_acc_m_s2"],
        "impacts_per_revolution_worn": worn["impacts_per_revolution"],
        "impact_velocity_max_worn": worn["impact_velocity_max_m_s"],
        "peak_a_healthy": healthy["peak_abs_a_m_s2"],
        "peak_a_worn": worn["peak_abs_a_m_s2"],
        "energy_lost_worn": worn["energy_lost_in_guide_J"],
        "energy_lost_healthy": healthy["energy_lost_in_guide_J"],
    }


if __name__ == "__main__":
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "docs/img")
    print(main(out))
