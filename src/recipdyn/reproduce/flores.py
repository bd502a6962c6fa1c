r"""The slider-crank benchmark with a revolute clearance joint at the slider pin.

The benchmark the clearance-joint literature uses to compare joint models: Flores, Ambrósio,
Claro & Lankarani, *Kinematics and Dynamics of Multibody Systems with Imperfect Joints*
(Springer 2008), Ch. 4, and Flores & Ambrósio (2004), "Revolute joints with clearance in
multibody systems", Computers & Structures 82, 1359-1369. Crank 0.05 m driven at 5000 rpm,
rod 0.12 m, a dry clearance joint of 0.5 mm radial clearance between the rod and the slider,
steel (E = 207 GPa, nu = 0.3), Lankarani-Nikravesh contact with e = 0.9, no friction,
gravity; the journal starts at the bearing centre. In recipdyn this is the compressor-contact
model with ``clearance_joints = "crosshead"``, the slider as the crosshead (``d = 0``, no gas
load).

[`ideal`][recipdyn.reproduce.flores.ideal] gives the ideal joint's slider acceleration and pin force
in closed form (Newton-Euler for the rod about the crank pin), so every run carries its ideal
reference. The published curves were not available where this module was written: the comparison in
``docs/flores_benchmark.md`` is with the qualitative findings the papers state, and the
numbers are ours.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import xarray as xr

from ..model.kinematics import ideal_mechanism

__all__ = ["PARAMS", "ideal", "run", "figure", "findings"]

#: The benchmark's parameters (masses 0.30 / 0.21 / 0.14 kg and inertias 1e-4 / 2.5e-4 /
#: 1e-4 kg m^2 of crank, rod and slider; the crank's do not enter, its speed is imposed).
PARAMS: dict[str, Any] = dict(
    r=0.05, l=0.12, ls=0.06, m2=0.21, J2=0.00025, m3=0.14, d=0.0, g=9.81,
    omega=5000 * 2 * math.pi / 60, load_amplitude=0.0, clearance_joints="crosshead",
    rc_crosshead=0.5e-3, crosshead_pin_radius=0.01, restitution=0.9,
    contact_law="lankarani-nikravesh", friction=0.0, e0_ratio=0.0,
)  # fmt: skip


def ideal(values: dict[str, Any], t: np.ndarray) -> dict[str, np.ndarray]:
    """Slider position, acceleration and the pin force on the rod (x, y) of the ideal
    slider-crank (rigid joints) with the same bodies, in closed form."""
    th1 = float(values["theta1_0"]) + float(values["omega"]) * np.asarray(t, dtype=float)
    m = ideal_mechanism(values, th1)  # no gas: the pin force on the rod is -m3 a along x
    fx, fy = m["force_x"], m["force_y"]
    return {"x": m["x"], "a": m["a"], "force_x": fx, "force_y": fy, "force": np.hypot(fx, fy)}


def run(revolutions: float = 5.0, transient: float = 0.0, fs: float | None = None,
        **overrides: Any) -> xr.Dataset:  # fmt: skip
    """The benchmark simulated (default: its first 5 crank revolutions, 2000 samples each),
    with the ideal joint's acceleration and force added as ``a_ideal``, ``joint_force_ideal``."""
    from ..simulate import simulate

    params = {**PARAMS, **overrides}
    w = float(params["omega"])
    fs = fs if fs is not None else 2000 * w / (2 * math.pi)
    ds = simulate(params=params, model="compressor-contact", revolutions=revolutions,
                  transient=transient, fs=fs)  # fmt: skip
    from ..model.registry import get_model

    values = get_model("compressor-contact").parameters(params)
    ref = ideal(values, ds.time.values)
    ds["a_ideal"] = (
        "time",
        ref["a"],
        {"units": "m/s**2", "long_name": "slider acceleration, ideal joints"},
    )
    ds["joint_force_ideal"] = ("time", ref["force"], {"units": "N",
                               "long_name": "slider-pin force, ideal joints"})  # fmt: skip
    ds.attrs["benchmark"] = (
        "slider-crank with a revolute clearance joint at the slider pin "
        "(Flores et al. 2008, Ch. 4; Flores & Ambrosio 2004)"
    )
    return ds


def findings(ds: xr.Dataset) -> dict[str, float]:
    """The quantities the benchmark's findings are about, per run."""
    revs = ds.attrs["revolutions"]
    return {
        "revolutions": float(revs),
        "impacts_per_revolution": float(ds.attrs["impacts_per_revolution_crosshead"]),
        "peak_abs_a": float(np.abs(ds["a"].values).max()),
        "peak_abs_a_ideal": float(np.abs(ds["a_ideal"].values).max()),
        "peak_force": float(ds["joint_force_crosshead"].values.max()),
        "peak_force_ideal": float(ds["joint_force_ideal"].values.max()),
        "contact_fraction": float(ds["contact_crosshead"].values.mean()),
        "max_penetration_m": float(ds.attrs["max_penetration_crosshead_m"]),
        "max_eccentricity_ratio": float(ds["eccentricity_ratio_crosshead"].values.max()),
        "impact_velocity_max": float(ds.attrs["impact_velocity_max_crosshead_m_s"]),
    }


def figure(ds: xr.Dataset, *, title: str | None = None):
    """Slider acceleration and pin force over crank angle, clearance joint against the ideal
    one, and the journal's orbit in the clearance circle."""
    from ..plotting import _mpl

    plt = _mpl()
    fig, ax = plt.subplots(1, 3, figsize=(14, 4.2), constrained_layout=True)
    deg = np.degrees(ds["theta1"].values - ds["theta1"].values[0])
    ax[0].plot(deg, ds["a"].values / 1e3, lw=0.6, color="C0", label="clearance joint")
    ax[0].plot(deg, ds["a_ideal"].values / 1e3, lw=1.2, color="k", ls="--", label="ideal joint")
    ax[0].set_ylabel("slider acceleration (10$^3$ m/s$^2$)")
    ax[1].plot(deg, ds["joint_force_crosshead"].values, lw=0.6, color="C0",
               label="clearance joint")  # fmt: skip
    ax[1].plot(deg, ds["joint_force_ideal"].values, lw=1.2, color="k", ls="--",
               label="ideal joint")  # fmt: skip
    ax[1].set_ylabel("slider-pin force (N)")
    for a in ax[:2]:
        a.set_xlabel("crank angle (deg)")
        a.set_xlim(deg[0], deg[-1])
        a.set_xticks(np.arange(0, deg[-1] + 1, 360))
        a.grid(alpha=0.3)
        a.legend(fontsize=8, loc="upper right")
    c = ds.attrs["param_rc_crosshead"]
    ring = np.linspace(0, 2 * np.pi, 361)
    ax[2].plot(np.cos(ring), np.sin(ring), color="0.4", lw=1)
    ax[2].plot(ds["ex_crosshead"].values / c, ds["ey_crosshead"].values / c, lw=0.5)
    ax[2].set_aspect("equal")
    ax[2].set_xlabel("e_x / c")
    ax[2].set_ylabel("e_y / c")
    ax[2].set_title("journal orbit in the clearance circle", fontsize=9)
    ax[2].grid(alpha=0.3)
    fig.suptitle(title or "Slider-crank with a clearance joint at the slider pin: c = 0.5 mm, "
                 "5000 rpm, e = 0.9, no friction")  # fmt: skip
    return fig


if __name__ == "__main__":  # pragma: no cover - writes the doc page's figure and numbers
    import json
    import sys
    from pathlib import Path

    out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    ds = run(revolutions=5.0)
    fig = figure(ds)
    fig.savefig(out / "flores_benchmark.png", dpi=110)
    print(json.dumps(findings(ds), indent=1))
