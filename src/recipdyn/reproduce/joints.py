"""Both joint models side by side: the paper's massless link and the contact-impact joint.

The same mechanism (the paper's geometry, the assumed masses) is run with the massless virtual
link of the paper and with the contact-impact clearance joint
(`recipdyn.model.compressor_contact`), under the paper's load and under a light one (20 kN)
where inertia can pull the pin off the bearing wall. The massless link is only valid while its
contact force is positive; the contact model shows what happens where it is not: free flight
and impacts.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from ..errors import ModelValidityWarning
from ..model.parameters import CompressorParams
from ..model.registry import get_model
from ..plotting import PALETTE, _mpl, plot_signal
from ..simulate import simulate

__all__ = ["JOINT_CASES", "joint_comparison"]

#: (clearance m, crank speed rad/s, load amplitude N) of the comparison.
JOINT_CASES = (
    (0.1e-3, 20.0, 2e5), (0.1e-3, 150.0, 2e5), (1e-3, 20.0, 2e5), (1e-3, 150.0, 2e5),
    (0.1e-3, 70.0, 2e4), (1e-3, 70.0, 2e4), (1e-3, 150.0, 2e4),
)  # fmt: skip
QUICK_CASES = ((1e-3, 20.0, 2e5), (1e-3, 70.0, 2e4))
#: The case drawn in the figure (a light load: the link model loses validity).
FIGURE_CASE = (1e-3, 70.0, 2e4)


def _pair(rc: float, omega: float, load: float, revolutions: float, transient: float):
    with warnings.catch_warnings():  # the link's loss of validity is a column of the table
        warnings.simplefilter("ignore", ModelValidityWarning)
        link = simulate(CompressorParams(rc=rc, omega=omega, load_amplitude=load),
                        revolutions=revolutions, transient=transient, fs=10_000.0)  # fmt: skip
        contact = simulate(model="compressor-contact",
                           params=dict(rc=rc, omega=omega, load_amplitude=load),
                           revolutions=revolutions, transient=transient, fs=10_000.0)  # fmt: skip
    return link, contact


def joint_comparison(quick: bool = False) -> tuple[list[dict[str, Any]], Any]:
    """Run each case with both joint models; returns the table rows and a figure of the
    light-load case (crosshead acceleration and joint force of both models)."""
    revolutions, transient = (1.0, 2.0) if quick else (5.0, 5.0)
    m = get_model("compressor-contact")
    rows, shown = [], None
    for rc, omega, load in QUICK_CASES if quick else JOINT_CASES:
        link, contact = _pair(rc, omega, load, revolutions, transient)
        s = m.run_summary(m.schema.from_attrs(contact.attrs), contact)
        a_link = float(np.abs(link["a"].values).max())
        a_contact = float(np.abs(contact["a"].values).max())
        rows.append(dict(
            rc_mm=1e3 * rc, omega=omega, load_kN=load / 1e3,
            impacts_per_rev=float(s["impacts_per_revolution"]),
            contact_peak_a=a_contact, contact_peak_force_N=float(s["peak_joint_force_N"]),
            contact_fraction=float(s["contact_fraction"]),
            link_peak_a=a_link,
            link_peak_force_N=float(np.abs(link["joint_force"].values).max()),
            link_valid_fraction=float(np.mean(link["contact_force"].values > 0)),
            peak_a_contact_vs_link=a_contact / a_link - 1.0,
        ))  # fmt: skip
        if (rc, omega, load) == FIGURE_CASE:
            shown = (link, contact)
    return rows, _figure(*shown) if shown else None


def _figure(link, contact):
    plt = _mpl()
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.4), constrained_layout=True)
    t0 = float(link.time.values[0])
    for ds, name, color in ((link, "massless link (paper)", PALETTE[0]),
                            (contact, "contact-impact joint", PALETTE[1])):  # fmt: skip
        plot_signal(axes[0], ds.time.values - t0, ds["a"].values, color=color, label=name,
                    zoom=False)  # fmt: skip
        deg = np.degrees(np.mod(ds["theta1"].values, 2 * np.pi))
        axes[1].plot(deg, np.abs(ds["joint_force"].values) / 1e3, ".", ms=1.2, color=color,
                     label=name)  # fmt: skip
    valid = link["contact_force"].values > 0
    if not valid.all():
        deg = np.degrees(np.mod(link["theta1"].values, 2 * np.pi))
        bad = np.abs(link["joint_force"].values[~valid]) / 1e3
        axes[1].plot(deg[~valid], bad, "x", ms=3, color="tab:red",
                     label="link force < 0: outside the link model")  # fmt: skip
    axes[0].set_xlabel("time (s)")
    axes[0].set_ylabel("crosshead acceleration (m/s$^2$)")
    axes[1].set_xlabel("crank angle (deg)")
    axes[1].set_ylabel("joint force magnitude (kN)")
    axes[1].set_xlim(0, 360)
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    rc, om, load = FIGURE_CASE
    fig.suptitle(f"Both joint models, rc = {1e3 * rc:g} mm, {om:g} rad/s, load {load / 1e3:g} kN")
    return fig
