"""The signature of each valve and ring fault next to the healthy machine (docs/faults.md).

Runs ``compressor-valves`` on the ideal mechanism (rc = 0), air 1 → 3 bar at 20 rad/s, one
revolution after two, healthy and with each fault, and writes one small figure per fault:
the p–V diagram and the pressure over crank angle of the affected chamber, and the lift of the
affected valve. Usage: ``python examples/valve_faults_figures.py [OUTDIR]`` (default
``docs/img``).
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from recipdyn.simulate import simulate  # noqa: E402

#: file stem: (title, parameters, chamber, valve)
FAULTS = {
    "fault_leak_suction": ("leaking suction valve, head end (3 cm²)",
                           {"leak_area_suction_head": 3e-4}, "head", "suction"),
    "fault_leak_discharge": ("leaking discharge valve, head end (0.3 cm²)",
                             {"leak_area_discharge_head": 3e-5}, "head", "discharge"),
    "fault_broken_spring": ("broken suction-valve spring, head end (factor 0)",
                            {"spring_factor_suction_head": 0.0}, "head", "suction"),
    "fault_sticking_plate": ("sticking suction plate, head end (300 N adhesion)",
                             {"adhesion_force_suction_head": 300.0}, "head", "suction"),
    "fault_ring_leak": ("piston-ring leak (1 cm²)", {"ring_leak_area": 1e-4}, "head", "suction"),
}  # fmt: skip


def _run(**kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the massless link's validity note (rod-load reversal)
        return simulate(model="compressor-valves", revolutions=1, transient=2, fs=20000,
                        rc=0.0, **kw)  # fmt: skip


def _panel(axes, ds, end, kind, style, label):
    th = np.degrees(np.asarray(ds["theta1"].values)) % 360.0
    order = np.argsort(th)
    p = np.asarray(ds[f"p_{end}"].values) / 1e5
    axes[0].plot(np.asarray(ds[f"V_{end}"].values) * 1e3, p, style, lw=1, label=label)
    axes[1].plot(th[order], p[order], style, lw=1, label=label)
    axes[2].plot(th[order], np.asarray(ds[f"y_{kind}_{end}"].values)[order] * 1e3, style, lw=1,
                 label=label)  # fmt: skip


def main(outdir: str = "docs/img") -> None:
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    healthy = _run()
    for stem, (title, kw, end, kind) in FAULTS.items():
        ds = _run(**kw)
        fig, axes = plt.subplots(1, 3, figsize=(9.0, 2.6), dpi=90, constrained_layout=True)
        _panel(axes, healthy, end, kind, "k--", "healthy")
        _panel(axes, ds, end, kind, "C3-", "fault")
        axes[0].set(xlabel=f"V_{end} [L]", ylabel=f"p_{end} [bar]", title="p–V")
        axes[1].set(xlabel="crank angle θ1 [deg]", ylabel=f"p_{end} [bar]", title="p–θ")
        axes[2].set(xlabel="crank angle θ1 [deg]", ylabel="lift [mm]",
                    title=f"{kind} valve, {end} end")  # fmt: skip
        axes[0].legend(fontsize=7)
        fig.suptitle(title, fontsize=9)
        fig.savefig(out / f"{stem}.png")
        plt.close(fig)
        print(out / f"{stem}.png")


if __name__ == "__main__":
    main(*sys.argv[1:])
