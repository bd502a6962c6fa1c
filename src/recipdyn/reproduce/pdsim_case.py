r"""The dynamic-valve model against PDSim's reciprocating compressor with reed valves.

PDSim (Bell, Ziviani et al., *PDSim: A general quasi-steady modeling approach for
positive displacement compressors and expanders*, Int. J. Refrig.,
doi:10.1016/j.ijrefrig.2019.09.002; MIT-licensed code at github.com/ibell/pdsim) ships a
reciprocating-compressor example (``examples/recip_compressor.py``): R410A, 60 Hz, a 20 mm
bore and stroke, reed valves modelled as one-degree-of-freedom masses. One converged cycle of
that example, computed with PDSim, is stored with the package (``data/pdsim_valve_case/``,
provenance in its README). [`run`][recipdyn.reproduce.pdsim_case.run] integrates the same case
with ``compressor-valves`` and puts both side by side.

The reed becomes a plate valve with PDSim's own equivalent stiffness and mass (the formulas of
the example, a cantilever loaded at ``a`` from its root, stiffness from its tip deflection, and a
third of the reed's mass)::

    I = d h^3 / 12,  k = 6 E I / (a^2 (3 l - a)) = 309.8 N/m,  m = rho l d h / 3 = 51.5 mg

The parameters without a counterpart are set as follows (`params`), never fitted:

* force area ``A_F = pi d_valve^2 / 4`` (PDSim's pressure term), so ``valve_force_factor =
  (d_valve / d_port)^2``; flow area at full lift ``A_port`` (PDSim's area above its transition
  lift); discharge coefficient 1 (PDSim's isentropic nozzle has none); no damping and no
  preload (PDSim has neither);
* restitution 0: PDSim sets lift and velocity to 0 at the seat and the stop (a plastic stop),
  which is ``e = 0`` in recipdyn (a plate arriving at a stop rests on it);
* the mechanism is the 2D12 slider-crank with PDSim's crank radius and rod length, the 2D12's
  masses, the ideal joint (``rc = 0``) and the crank speed imposed: the comparison is about the
  gas and the valves.

What PDSim models that ``compressor-valves`` does not (the causes of the differences, see
``docs/valve_benchmark.md``): heat transfer between gas and cylinder wall, a suction tube heated
by the shell, leakage past the piston (an isentropic nozzle of area ``delta_gap pi D`` to the
shell, whose gas returns to the suction), the reed's drag force ``C_D rho V^2 A_valve / 2`` and
its flux-dominated regime above the transition lift, and a flow area ``pi d_valve x`` that
reaches the port area at the transition lift (recipdyn's grows linearly to the stop).
"""

from __future__ import annotations

import csv
import math
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "REED", "PDSIM_REPORTED", "params", "reed_equivalent", "reference", "valve_events",
    "pdsim_leakage", "compare", "run", "figure",
]  # fmt: skip

_DATA = "data/pdsim_valve_case"
#: Stop (guard) lift of both reeds, m.
STOP = 0.0018
#: Lift above which a valve counts as open, m (the reference file's threshold).
OPEN_LIFT = 1e-7

#: PDSim's reed (``examples/recip_compressor.py``): Young's modulus E (Pa), thickness h, total
#: length l, anchor-to-force distance a, width (tip diameter) d_valve, port diameter d_port
#: (m), density (kg/m^3).
REED = dict(E=1.93e11, h=1.532e-4, l=0.018, a=0.0140, d_valve=0.007, d_port=0.0059,
            rho=8000.0)  # fmt: skip

#: Figures PDSim's solver reported for the stored cycle (its own definitions: mass flow into
#: the inlet tube; volumetric efficiency against the inlet density; ``Wdot = mdot (h2 - h1) -
#: Qamb``, an energy balance across the whole machine, not the p-V work).
PDSIM_REPORTED = dict(mass_flow_g_s=8.3279, volumetric_efficiency=0.66737, wdot_W=253.40)

#: PDSim's suction state (R410A, 289.15 K, 33.1 kg/m^3) and pressure ratio.
SUCTION_T, SUCTION_RHO, RATIO = 289.15, 33.1, 2.5
#: Piston-to-cylinder gap (m) of PDSim's leakage path, area ``delta_gap pi D``.
DELTA_GAP = 10e-6


def reed_equivalent(reed: dict[str, float] | None = None) -> tuple[float, float]:
    """PDSim's equivalent stiffness (N/m) and moving mass (kg) of a cantilever reed.

    ``k = 6 E I / (a^2 (3 l - a))`` with ``I = d h^3 / 12`` (the tip deflection of a cantilever
    of length ``l`` under a force at ``a`` from its root), ``m = rho l d h / 3`` (a third of the
    reed), as in PDSim's ``examples/recip_compressor.py``."""
    r = dict(REED if reed is None else reed)
    inertia = r["d_valve"] * r["h"] ** 3 / 12.0
    k = 6.0 * r["E"] * inertia / (r["a"] ** 2 * (3.0 * r["l"] - r["a"]))
    m = r["rho"] * r["l"] * r["d_valve"] * r["h"] / 3.0
    return k, m


def _suction_pressure() -> float:
    import CoolProp.CoolProp as CP

    return float(CP.PropsSI("P", "T", SUCTION_T, "D", SUCTION_RHO, "R410A"))


def params(restitution: float = 0.0) -> dict[str, Any]:
    """The case's parameters for ``compressor-valves`` (see the module's docstring)."""
    k, m = reed_equivalent()
    ps = _suction_pressure()
    return dict(
        r=0.01, rs=0.005, l=0.04, ls=0.02, rc=0.0, d=0.0, omega=377.0, theta1_0=0.0,
        bore=0.02, rod_diameter=0.0, clearance_fraction=0.003 / 0.02, acting="head",
        suction_pressure=ps, discharge_pressure=RATIO * ps, suction_temperature=SUCTION_T,
        gas="R410A", valve_area_fraction=(REED["d_port"] / 0.02) ** 2, valve_lift=STOP,
        valve_mass=m, valve_stiffness=k, valve_preload=0.0, valve_damping=0.0,
        valve_force_factor=(REED["d_valve"] / REED["d_port"]) ** 2,
        discharge_coefficient=1.0, valve_restitution=float(restitution),
    )  # fmt: skip


def reference() -> dict[str, np.ndarray]:
    """PDSim's converged cycle: ``theta_deg`` (0 at TDC), ``V`` (m^3), ``p`` (Pa), ``T`` (K),
    the lifts ``y_suction``, ``y_discharge`` clipped to the seat and stop as PDSim uses them
    (m), and the raw velocities (m/s)."""
    text = resources.files("recipdyn.reproduce").joinpath(
        _DATA, "pdsim_recip_run_output.csv").read_text()  # fmt: skip
    rows = [r for r in csv.reader(line for line in text.splitlines() if not line.startswith("#"))]
    a = np.array(rows[1:], dtype=float)
    return {
        "theta_deg": np.degrees(a[:, 0]), "V": a[:, 1], "p": a[:, 2] * 1e3, "T": a[:, 3],
        "y_suction": np.clip(a[:, 4], 0.0, STOP), "u_suction": a[:, 5],
        "y_discharge": np.clip(a[:, 6], 0.0, STOP), "u_discharge": a[:, 7],
    }  # fmt: skip


def valve_events(theta_deg: np.ndarray, lift: np.ndarray, start: float) -> dict[str, float]:
    """Opening and closing angles (deg) of a valve over one cycle and its time on the stop.

    ``theta_deg`` increasing over one revolution; the cycle is read from ``start`` (a crank
    angle where the valve is closed), so a valve that closes after TDC gets a closing angle
    beyond 360. Opening: the first sample above `OPEN_LIFT`; closing: the last one
    (interpolated linearly between samples); time on the stop: the crank angle spent within
    0.1 % of the stop lift (the trapezoid of the indicator)."""
    th = (np.asarray(theta_deg, dtype=float) - start) % 360.0
    order = np.argsort(th, kind="stable")
    th, y = th[order], np.asarray(lift, dtype=float)[order]
    is_open = y > OPEN_LIFT
    idx = np.flatnonzero(is_open)
    if idx.size == 0:
        return {"open_deg": math.nan, "close_deg": math.nan, "on_stop_deg": 0.0, "openings": 0}
    i0, i1 = idx[0], idx[-1]
    t_open = np.interp(OPEN_LIFT, [y[i0 - 1], y[i0]], [th[i0 - 1], th[i0]]) if i0 else th[0]
    t_close = th[i1] if i1 + 1 >= th.size else np.interp(
        -OPEN_LIFT, [-y[i1], -y[i1 + 1]], [th[i1], th[i1 + 1]])  # fmt: skip
    on = (y >= STOP * (1.0 - 1e-3)).astype(float)
    on_stop = float(np.sum(0.5 * (on[1:] + on[:-1]) * np.diff(th)))
    starts = np.count_nonzero(is_open[1:] & ~is_open[:-1]) + int(is_open[0])
    return {"open_deg": float(t_open + start), "close_deg": float(t_close + start),
            "on_stop_deg": on_stop, "openings": int(starts)}  # fmt: skip


def pdsim_leakage(
    ref: dict[str, np.ndarray] | None = None, shell_pressure: float | None = None
) -> float:
    """Net mass (kg) leaving PDSim's cylinder past the piston per revolution, estimated on the
    stored cycle.

    PDSim's path (``Recip.PistonLeakage``): an isentropic nozzle of area ``delta_gap pi D``
    between the cylinder and the shell. The cylinder's state is the trace's; the shell (not
    in the trace) is taken at the suction state, or at ``shell_pressure`` and the suction
    density: its gas returns to the suction through a 10 mm nozzle, so its pressure is within
    the suction's pressure drop of it. Flow function of
    the upstream gas's isentropic exponent ``cp/cv`` (CoolProp), ``p/rho`` from CoolProp."""
    import CoolProp.CoolProp as CP

    ref = reference() if ref is None else ref
    ps = _suction_pressure() if shell_pressure is None else float(shell_pressure)
    area = DELTA_GAP * math.pi * 0.02
    p, T = ref["p"], ref["T"]
    rho = CP.PropsSI("D", "P", p, "T", T, "R410A")
    kap = CP.PropsSI("CPMASS", "P", p, "T", T, "R410A") / CP.PropsSI(
        "CVMASS", "P", p, "T", T, "R410A")  # fmt: skip
    kap_s = CP.PropsSI("CPMASS", "T", SUCTION_T, "D", SUCTION_RHO, "R410A") / CP.PropsSI(
        "CVMASS", "T", SUCTION_T, "D", SUCTION_RHO, "R410A")  # fmt: skip
    out = p >= ps
    k = np.where(out, kap, kap_s)
    pu = np.where(out, p, ps)
    rho_u = np.where(out, rho, SUCTION_RHO)
    r = np.where(out, ps / p, p / ps)
    crit = (2.0 / (k + 1.0)) ** (k / (k - 1.0))
    r = np.maximum(r, crit)
    psi = np.sqrt(2.0 * k / (k - 1.0) * (r ** (2.0 / k) - r ** ((k + 1.0) / k)))
    mdot = np.where(out, 1.0, -1.0) * area * np.sqrt(pu * rho_u) * psi
    t = np.radians(ref["theta_deg"]) / 377.0
    return float(np.sum(0.5 * (mdot[1:] + mdot[:-1]) * np.diff(t)))


def _pdsim_intake(ref: dict[str, np.ndarray]) -> float:
    """The mass (kg) through PDSim's suction valve in a cycle, from its trace: the cylinder's
    mass (CoolProp density at the trace's p and T, times V) gained between the valve's
    opening and closing, less what leaks in past the piston then (`pdsim_leakage` on that
    interval)."""
    import CoolProp.CoolProp as CP

    ev = valve_events(ref["theta_deg"], ref["y_suction"], 0.0)
    m = CP.PropsSI("D", "P", ref["p"], "T", ref["T"], "R410A") * ref["V"]
    th = ref["theta_deg"]
    gained = np.interp(ev["close_deg"], th, m) - np.interp(ev["open_deg"], th, m)
    sel = (th >= ev["open_deg"]) & (th <= ev["close_deg"])
    return float(gained + pdsim_leakage({k: v[sel] for k, v in ref.items()}))


def _indicated_power(p: np.ndarray, V: np.ndarray, omega: float) -> float:
    """``omega / (2 pi)`` times the p-V work of one closed cycle (trapezoid)."""
    work = -float(np.sum(0.5 * (p[1:] + p[:-1]) * np.diff(V)))
    work -= 0.5 * (p[-1] + p[0]) * (V[0] - V[-1])  # close the loop
    return work * omega / (2.0 * math.pi)


def compare(ds: Any, ref: dict[str, np.ndarray] | None = None) -> list[dict[str, Any]]:
    """The table: one row per quantity with PDSim's and recipdyn's values.

    ``ds``: a ``compressor-valves`` record of at least one revolution of the case; its last
    revolution is compared. Angles in degrees after TDC (the suction valve's events read
    from TDC, the discharge valve's from BDC, so a discharge valve closing after TDC gets an
    angle > 360)."""
    from ..model.cycle import last_revolution

    ref = reference() if ref is None else ref
    omega = 377.0
    part = last_revolution(ds, omega)
    th = np.degrees(np.asarray(part["theta1"].values, dtype=float)) % 360.0
    vdisp = math.pi * 0.02**2 / 4.0 * 0.02
    rate = omega / (2.0 * math.pi)
    m_in = np.asarray(part["mass_in_head"].values, dtype=float)
    m_out = np.asarray(part["mass_out_head"].values, dtype=float)
    ours_in, ours_out = m_in[-1] - m_in[0], m_out[-1] - m_out[0]
    leak = pdsim_leakage(ref)
    rows: list[dict[str, Any]] = []
    for kind, start in (("suction", 0.0), ("discharge", 180.0)):
        a = valve_events(ref["theta_deg"], ref[f"y_{kind}"], start)
        b = valve_events(th, np.asarray(part[f"y_{kind}_head"].values, dtype=float), start)
        for key, label in (("open_deg", "opens at (deg after TDC)"),
                           ("close_deg", "closes at (deg after TDC)"),
                           ("on_stop_deg", "time on the stop (deg of crank angle)"),
                           ("openings", "separate openings")):  # fmt: skip
            rows.append({"quantity": f"{kind} valve {label}", "key": f"{kind}_{key}",
                         "pdsim": a[key], "recipdyn": b[key]})  # fmt: skip
    # PDSim's mass through the suction valve, by two routes: its delivered mass (solver) plus
    # the net leak, and its trace alone (`_pdsim_intake`); they differ by the leak estimate's
    # error (the shell's state is not in the trace)
    pd_mdot = PDSIM_REPORTED["mass_flow_g_s"]
    rows += [
        {"quantity": "mass flow delivered (g/s)", "key": "mass_flow_g_s", "pdsim": pd_mdot,
         "recipdyn": 1e3 * ours_out * rate},
        {"quantity": "volumetric efficiency (delivered)", "key": "volumetric_efficiency",
         "pdsim": PDSIM_REPORTED["volumetric_efficiency"],
         "recipdyn": ours_out / (SUCTION_RHO * vdisp)},
        {"quantity": "piston leakage, net, per rev / (rho_s V_disp) (estimated on PDSim's cycle)",
         "key": "leakage_fraction", "pdsim": leak / (SUCTION_RHO * vdisp), "recipdyn": 0.0},
        {"quantity": "mass through the suction valve / (rho_s V_disp): PDSim's delivered + leak",
         "key": "intake_efficiency",
         "pdsim": PDSIM_REPORTED["volumetric_efficiency"] + leak / (SUCTION_RHO * vdisp),
         "recipdyn": ours_in / (SUCTION_RHO * vdisp)},
        {"quantity": "mass through the suction valve / (rho_s V_disp): PDSim's cylinder gain "
                     "while it is open, less the leak in",
         "key": "intake_trace", "pdsim": _pdsim_intake(ref) / (SUCTION_RHO * vdisp),
         "recipdyn": ours_in / (SUCTION_RHO * vdisp)},
        {"quantity": "indicated power, p-V work x f (W)", "key": "indicated_power_W",
         "pdsim": _indicated_power(ref["p"], ref["V"], omega),
         "recipdyn": _indicated_power(np.asarray(part["p_head"].values, dtype=float),
                                      np.asarray(part["V_head"].values, dtype=float), omega)},
        {"quantity": "peak cylinder pressure (kPa)", "key": "p_max_kPa",
         "pdsim": float(ref["p"].max()) / 1e3,
         "recipdyn": float(np.max(part["p_head"].values)) / 1e3},
        {"quantity": "lowest cylinder pressure (kPa)", "key": "p_min_kPa",
         "pdsim": float(ref["p"].min()) / 1e3,
         "recipdyn": float(np.min(part["p_head"].values)) / 1e3},
        {"quantity": "valve impacts per revolution (PDSim: plastic stops, none)",
         "key": "impacts", "pdsim": math.nan,
         "recipdyn": int(ds.attrs.get("valve_impacts_per_rev", -1))},
        {"quantity": "mass balance of the cycle (in - out) / in", "key": "mass_balance",
         "pdsim": math.nan, "recipdyn": (ours_in - ours_out) / ours_in},
    ]  # fmt: skip
    return rows


def figure(ds: Any, ref: dict[str, np.ndarray] | None = None, path: str | Path | None = None):
    """Lifts and cylinder pressure over crank angle, recipdyn against PDSim."""
    from ..model.cycle import last_revolution
    from ..plotting import _mpl

    plt = _mpl()
    ref = reference() if ref is None else ref
    part = last_revolution(ds, 377.0)
    th = np.degrees(np.asarray(part["theta1"].values, dtype=float)) % 360.0
    o = np.argsort(th)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.0, 5.6), sharex=True)
    ax1.plot(ref["theta_deg"], ref["p"] / 1e3, "k-", lw=1.6, label="PDSim")
    ax1.plot(th[o], np.asarray(part["p_head"].values)[o] / 1e3, "C3--", lw=1.2,
             label="recipdyn")  # fmt: skip
    ax1.set_ylabel("cylinder pressure (kPa)")
    ax1.legend(loc="upper left")
    for kind, col in (("suction", "C0"), ("discharge", "C1")):
        ax2.plot(ref["theta_deg"], ref[f"y_{kind}"] * 1e3, "-", color=col, lw=1.6,
                 label=f"{kind}, PDSim")  # fmt: skip
        ax2.plot(th[o], np.asarray(part[f"y_{kind}_head"].values)[o] * 1e3, "--", color=col,
                 lw=1.2, label=f"{kind}, recipdyn")  # fmt: skip
    ax2.set_xlabel("crank angle after TDC (deg)")
    ax2.set_ylabel("valve lift (mm)")
    ax2.set_xlim(0, 360)
    ax2.legend(loc="center", bbox_to_anchor=(0.68, 0.5), fontsize=8)
    fig.tight_layout()
    if path is not None:
        fig.savefig(path, dpi=90)
        plt.close(fig)
    return fig


def _fmt(v: Any) -> str:
    if isinstance(v, int):
        return str(v)
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "–"
    return f"{v:.4g}"


def run(out: str | Path | None = None, *, transient: float = 4.0, revolutions: float = 1.0,
        restitution: float = 0.0, rtol: float = 1e-8, atol: float = 1e-10,
        **overrides: Any) -> dict[str, Any]:  # fmt: skip
    """Run the PDSim case with ``compressor-valves`` and compare it with PDSim's cycle.

    Parameters
    ----------
    out : path, optional
        Folder to write ``pdsim_comparison.csv``, ``pdsim_comparison.md`` and
        ``pdsim_comparison.png`` (lifts and pressure over crank angle) into.
    transient, revolutions : float
        Revolutions integrated first and discarded, and recorded (the last one is compared).
        From the ideal cycle's start the cycle figures settle to < 1e-4 within 3 revolutions.
    restitution : float
        The plates' coefficient of restitution; 0 is PDSim's plastic stop.
    rtol, atol : float
        Integrator tolerances.
    **overrides
        Parameters replaced in the case (sensitivity studies; the case itself is PDSim's
        mapping, `params`).

    Returns
    -------
    dict
        ``rows`` (the table, see [`compare`][recipdyn.reproduce.pdsim_case.compare]),
        ``dataset`` (the record), ``params``.

    Example
    -------
    >>> from recipdyn.reproduce import pdsim_case
    >>> res = pdsim_case.run("pdsim_out")  # doctest: +SKIP
    """
    from ..simulate import simulate

    p = params(restitution) | overrides
    ds = simulate(model="compressor-valves", revolutions=revolutions, transient=transient,
                  fs=377.0 / (2.0 * math.pi) * 3600.0, rtol=rtol, atol=atol, **p)  # fmt: skip
    rows = compare(ds)
    if out is not None:
        d = Path(out)
        d.mkdir(parents=True, exist_ok=True)
        with open(d / "pdsim_comparison.csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=["key", "quantity", "pdsim", "recipdyn"])
            w.writeheader()
            w.writerows(rows)
        lines = ["| quantity | PDSim | recipdyn |", "|---|---|---|"]
        lines += [f"| {r['quantity']} | {_fmt(r['pdsim'])} | {_fmt(r['recipdyn'])} |"
                  for r in rows]  # fmt: skip
        (d / "pdsim_comparison.md").write_text("\n".join(lines) + "\n")
        figure(ds, path=d / "pdsim_comparison.png")
    return {"rows": rows, "dataset": ds, "params": p}


if __name__ == "__main__":  # python -m recipdyn.reproduce.pdsim_case OUT_DIR
    import sys

    res = run(sys.argv[1] if len(sys.argv) > 1 else "pdsim_case")
    print(Path(sys.argv[1] if len(sys.argv) > 1 else "pdsim_case") / "pdsim_comparison.md")
