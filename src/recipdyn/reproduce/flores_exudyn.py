r"""The slider-crank clearance benchmark rebuilt in Exudyn, an open multibody code, for a
numerical comparison with recipdyn's ``compressor-contact`` model.

Exudyn (Gerstmayr 2023, "EXUDYN – a C++-based Python package for flexible multibody systems",
*Multibody System Dynamics* 60, 533-561; BSD licence) formulates the mechanism differently from
recipdyn: each body has its own absolute coordinates (the rod's centroid and angle, the slider's
position, the crank's), the ideal joints are algebraic constraints with Lagrange multipliers,
the crank's rotation is a prescribed coordinate constraint, and the equations are integrated
by an implicit generalised-alpha (here Newmark's trapezoidal rule, spectral radius 1: second
order, no numerical damping) with Newton iterations, at a fixed step. recipdyn uses two
minimal coordinates (the eccentricity), equations from its Lagrange generator, DOP853 and
located contact-onset events. The only thing the two share is the benchmark's definition:
the bodies, the joints and the contact law, whose force is written here again from its formula
(only the stiffness value K is taken from the model's parameters).

The clearance joint is a Cartesian connector between the slider pin and the rod's small end
whose force is a Python function of their relative position and velocity
(``e = S - P``, ``delta = |e| - c``, ``F = K delta^1.5 (1 + chi delta'/delta'^-)`` along
``e/|e|``). The approach velocity ``delta'^-`` of Lankarani-Nikravesh's law is recorded by a
pre-step function at the first step that starts in contact, interpolated to the crossing
between the last two step starts; within the step where contact begins, the current
``delta'`` stands for it (there the force is ~0: its impulse over that step is ~1e-5 of the
impact's at the steps used here).

Used by ``tests/test_flores.py`` and ``docs/flores_benchmark.md``; needs ``exudyn`` (a
development dependency).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["HYSTERESIS", "simulate_exudyn", "compare", "figure"]

#: The hysteresis factor chi of the laws this rebuild supports, from the restitution e.
HYSTERESIS = {
    "hertz": lambda e: 0.0,
    "lankarani-nikravesh": lambda e: 3.0 * (1.0 - e * e) / 4.0,  # Lankarani & Nikravesh 1990
}


def simulate_exudyn(values: dict[str, Any], t_end: float, step: float,
                    sample: float = 1e-5) -> dict[str, np.ndarray]:  # fmt: skip
    """The benchmark (``clearance_joints = "crosshead"``, parameters as resolved by the
    ``compressor-contact`` model, journal starting at the bearing centre, the mechanism in its
    ideal motion) integrated by Exudyn's generalised-alpha at the fixed ``step`` (s).

    Returns ``t`` (every ``sample`` s from 0 to ``t_end``), the eccentricity ``ex``, ``ey``
    (small end minus slider pin, m), the slider position ``x`` (m) and ``seconds`` (wall time).
    """
    import time

    import exudyn as exu
    from exudyn import itemInterface as ii

    law = str(values["contact_law"])
    if law not in HYSTERESIS:
        raise ValueError(f"contact_law: the Exudyn rebuild supports {sorted(HYSTERESIS)}")
    if values["clearance_joints"] != "crosshead" or float(values["e0_ratio"]) != 0.0:
        raise ValueError("the Exudyn rebuild is the benchmark: clearance at the crosshead pin, "
                         "journal starting at the bearing centre")  # fmt: skip
    if (float(values["friction"]) != 0.0 or float(values["load_amplitude"]) != 0.0
            or values["joint"] != "dry"):  # fmt: skip
        raise ValueError("the Exudyn rebuild has no friction, no oil film and no gas load")
    r, l, ls, m2, J2, m3, g, w, d, th1 = (float(values[k]) for k in (
        "r", "l", "ls", "m2", "J2", "m3", "g", "omega", "d", "theta1_0"))  # fmt: skip
    c = float(values["rc_crosshead"])
    from ..model.components.contact_model import stiffness

    K = stiffness(values, "crosshead")
    chi = HYSTERESIS[law](float(values["restitution"]))
    v_min = float(values["v_impact_min"])

    # the ideal slider-crank at t = 0: crank pin A, rod angle th2 and rate w2, slider on y = -d
    s1, c1 = math.sin(th1), math.cos(th1)
    s2 = -(d + r * s1) / l
    c2 = math.sqrt(1.0 - s2 * s2)
    w2 = -r * w * c1 / (l * c2)
    ax, ay = r * c1, r * s1
    vax, vay = -r * w * s1, r * w * c1
    gx, gy = ax + ls * c2, ay + ls * s2
    vgx, vgy = vax - ls * w2 * s2, vay + ls * w2 * c2
    x3, vx3 = ax + l * c2, vax - l * w2 * s2

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()

    def at(body, x=0.0):  # a point of a body (local x along it)
        return mbs.AddMarker(ii.MarkerBodyPosition(bodyNumber=body, localPosition=[x, 0.0, 0.0]))

    def coordinate(node, i):  # a node's coordinate (its displacement from the reference)
        return mbs.AddMarker(ii.MarkerNodeCoordinate(nodeNumber=node, coordinate=i))

    ground = mbs.AddObject(ii.ObjectGround())
    zero = coordinate(mbs.AddNode(ii.NodePointGround()), 0)
    # crank: turns about the origin, its angle prescribed (its mass does not enter)
    n_crank = mbs.AddNode(ii.NodeRigidBody2D(referenceCoordinates=[0.0, 0.0, th1],
                                             initialVelocities=[0.0, 0.0, w]))  # fmt: skip
    crank = mbs.AddObject(ii.ObjectRigidBody2D(mass=0.3, inertia=1e-4, nodeNumber=n_crank))
    mbs.AddObject(ii.RevoluteJoint2D(markerNumbers=[at(ground), at(crank)]))
    mbs.AddObject(ii.ObjectConnectorCoordinate(
        markerNumbers=[zero, coordinate(n_crank, 2)],
        offsetUserFunction=lambda mbs, t, item, offset: w * t,
        offsetUserFunction_t=lambda mbs, t, item, offset: w))  # fmt: skip
    # rod: node at its centroid, joined to the crank pin, with gravity
    n_rod = mbs.AddNode(ii.NodeRigidBody2D(referenceCoordinates=[gx, gy, math.atan2(s2, c2)],
                                           initialVelocities=[vgx, vgy, w2]))  # fmt: skip
    rod = mbs.AddObject(ii.ObjectRigidBody2D(mass=m2, inertia=J2, nodeNumber=n_rod))
    mbs.AddObject(ii.RevoluteJoint2D(markerNumbers=[at(crank, r), at(rod, -ls)]))
    mbs.AddLoad(
        ii.LoadMassProportional(
            markerNumber=mbs.AddMarker(ii.MarkerBodyMass(bodyNumber=rod)), loadVector=[0.0, -g, 0.0]
        )
    )
    # slider: a point mass on the guide y = -d
    n_slider = mbs.AddNode(ii.NodePoint2D(referenceCoordinates=[x3, -d],
                                          initialVelocities=[vx3, 0.0]))  # fmt: skip
    slider = mbs.AddObject(ii.ObjectMassPoint2D(mass=m3, nodeNumber=n_slider))
    mbs.AddObject(ii.ObjectConnectorCoordinate(markerNumbers=[zero, coordinate(n_slider, 1)]))
    # the clearance joint: the force on the small end S is -F n, n = e/|e|, e = S - P
    m_pin, m_end = at(slider), at(rod, l - ls)
    memory = {"v_minus": None, "previous": (0.0, 0.0)}

    def contact(e, ed):
        rho = math.hypot(e[0], e[1])
        delta = rho - c
        if delta <= 0.0:
            return 0.0, 0.0, rho, delta, 0.0
        nx, ny = e[0] / rho, e[1] / rho
        rate = ed[0] * nx + ed[1] * ny
        return nx, ny, rho, delta, rate

    def force(mbs, t, item, u, v, k, dmp, offset):
        nx, ny, rho, delta, rate = contact(u, v)
        if delta <= 0.0:
            return [0.0, 0.0, 0.0]
        v_minus = memory["v_minus"] if memory["v_minus"] is not None else max(rate, v_min)
        fn = max(0.0, K * delta**1.5 * (1.0 + chi * rate / v_minus))
        return [fn * nx, fn * ny, 0.0]  # the connector pulls the markers together by +f

    connector = mbs.AddObject(ii.ObjectConnectorCartesianSpringDamper(
        markerNumbers=[m_pin, m_end], springForceUserFunction=force))  # fmt: skip

    def pre_step(mbs, t):
        e = mbs.GetObjectOutput(connector, exu.OutputVariableType.Displacement)
        ed = mbs.GetObjectOutput(connector, exu.OutputVariableType.Velocity)
        _, _, rho, delta, rate = contact(e, ed)
        if delta <= 0.0:
            memory["v_minus"] = None
        elif memory["v_minus"] is None:  # the first step start in contact: the approach
            # velocity at the crossing, interpolated between the last two step starts
            # (linear in delta: O(step^2), the integrator's order; the mechanism accelerates
            # the approach by ~1e-4 of itself within one step, so the rate at the step start
            # is not enough)
            d0, r0 = memory["previous"]
            frac = d0 / (d0 - delta)
            memory["v_minus"] = max(r0 + frac * (rate - r0), v_min)
        if delta <= 0.0:  # the normal rate in free flight, for the interpolation above
            memory["previous"] = (delta, (e[0] * ed[0] + e[1] * ed[1]) / max(rho, 1e-300))
        return True

    mbs.SetPreStepUserFunction(pre_step)
    s_end = mbs.AddSensor(ii.SensorMarker(markerNumber=m_end, storeInternal=True,
                          outputVariableType=exu.OutputVariableType.Position))  # fmt: skip
    s_pin = mbs.AddSensor(ii.SensorMarker(markerNumber=m_pin, storeInternal=True,
                          outputVariableType=exu.OutputVariableType.Position))  # fmt: skip
    mbs.Assemble()

    ss = exu.SimulationSettings()
    ss.timeIntegration.endTime = t_end
    ss.timeIntegration.numberOfSteps = int(round(t_end / step))
    ss.timeIntegration.verboseMode = 0
    ss.timeIntegration.generalizedAlpha.spectralRadius = 1.0
    ss.timeIntegration.generalizedAlpha.useNewmark = True
    ss.timeIntegration.generalizedAlpha.useIndex2Constraints = True
    ss.timeIntegration.newton.relativeTolerance = 1e-12
    ss.timeIntegration.newton.absoluteTolerance = 1e-14
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = sample
    t0 = time.perf_counter()
    mbs.SolveDynamic(ss)
    seconds = time.perf_counter() - t0
    end = mbs.GetSensorStoredData(s_end)
    pin = mbs.GetSensorStoredData(s_pin)
    return {"t": end[:, 0], "ex": end[:, 1] - pin[:, 1], "ey": end[:, 2] - pin[:, 2],
            "x": pin[:, 1], "seconds": np.array(seconds)}  # fmt: skip


def compare(overrides: dict[str, Any] | None = None, revolutions: float = 0.25,
            steps: tuple[float, float] = (1e-7, 5e-8), sample: float = 1e-5,
            rtol: float = 1e-12) -> dict[str, Any]:  # fmt: skip
    """recipdyn against Exudyn on the benchmark over its first ``revolutions``.

    Exudyn runs at two steps ``h`` and ``h/2``; its error at ``h/2`` is estimated from their
    difference (second order: ``(x_h - x_{h/2})/3``), and Richardson's extrapolation
    ``x_{h/2} + (x_{h/2} - x_h)/3`` removes it to leading order. Returned (lengths relative
    to the clearance ``c``, the largest over the window): ``diff`` = |recipdyn - Exudyn| at
    each step, ``order`` (the observed order of Exudyn's convergence to recipdyn),
    ``estimate`` = Exudyn's estimated error at ``h/2``, ``extrapolated`` = |recipdyn -
    Richardson|, ``slider`` (the same for the slider position), ``impacts`` (recipdyn's in
    the window), ``seconds`` (Exudyn's wall time per run) and the samples (``t``, ``ours``,
    ``exudyn``: eccentricity ``(ex, ey)``).
    """
    from ..integrate import integrate
    from ..model.registry import get_model
    from .flores import PARAMS

    model = get_model("compressor-contact")
    values = model.parameters({**PARAMS, **(overrides or {})})
    t_end = revolutions * model.period(values)
    coarse, fine = (simulate_exudyn(values, t_end, h, sample=sample) for h in steps)
    t = fine["t"]
    sol = integrate(model.system(values), model.initial_state(values), (0.0, t_end), t_eval=t,
                    rtol=rtol, atol=rtol * 1e-4)  # fmt: skip
    ours = {"ex": sol.y[:, 2], "ey": sol.y[:, 3],
            "x": np.asarray(model.outputs(values, t, sol.y)["x"].values)}  # fmt: skip
    c = float(values["rc_crosshead"])

    def dist(a, b):
        return float(np.max(np.hypot(a["ex"] - b["ex"], a["ey"] - b["ey"]))) / c

    rich = {k: fine[k] + (fine[k] - coarse[k]) / 3.0 for k in ("ex", "ey", "x")}
    d_coarse, d_fine = dist(ours, coarse), dist(ours, fine)
    return {
        "diff": (d_coarse, d_fine),
        "order": math.log2(d_coarse / d_fine),
        "estimate": dist(coarse, fine) / 3.0,
        "extrapolated": dist(ours, rich),
        "slider": (float(np.max(np.abs(ours["x"] - fine["x"]))) / c,
                   float(np.max(np.abs(ours["x"] - rich["x"]))) / c),  # fmt: skip
        "impacts": int(sol.t_events.size),
        "seconds": (float(coarse["seconds"]), float(fine["seconds"])),
        "t": t, "ours": np.column_stack([ours["ex"], ours["ey"]]),
        "exudyn": np.column_stack([fine["ex"], fine["ey"]]),
    }  # fmt: skip


def figure(results: dict[str, dict[str, Any]]):
    """The journal's eccentricity from both codes over the window, and their distance, per
    contact law (``results``: law -> [`compare`][recipdyn.reproduce.flores_exudyn.compare]'s
    result)."""
    from ..plotting import _mpl

    plt = _mpl()
    fig, ax = plt.subplots(1, 2, figsize=(12, 4), constrained_layout=True)
    for i, (law, r) in enumerate(results.items()):
        t_ms = r["t"] * 1e3
        rho_o = np.hypot(*r["ours"].T)
        rho_x = np.hypot(*r["exudyn"].T)
        ax[0].plot(t_ms, rho_o * 1e3 + i * 0.7, color=f"C{i}", lw=1.2,
                   label=f"recipdyn, {law} (+{0.7 * i:.1f} mm)")  # fmt: skip
        ax[0].plot(t_ms, rho_x * 1e3 + i * 0.7, color="k", ls=":", lw=1.2,
                   label="Exudyn" if i == 0 else None)  # fmt: skip
        dist = np.hypot(*(r["ours"] - r["exudyn"]).T)
        ax[1].semilogy(t_ms, np.maximum(dist, 1e-16), color=f"C{i}", lw=0.8,
                       label=f"{law}: max {r['diff'][1]:.1e} c; Richardson "
                             f"{r['extrapolated']:.1e} c")  # fmt: skip
    ax[0].set_xlabel("time (ms)")
    ax[0].set_ylabel("|e| (mm)")
    ax[0].set_title("journal eccentricity (clearance 0.5 mm)", fontsize=9)
    ax[1].set_xlabel("time (ms)")
    ax[1].set_ylabel("|e_recipdyn - e_Exudyn| (m), Exudyn at h/2")
    ax[1].set_title("distance between the codes", fontsize=9)
    ax[0].set_ylim(-0.05, 2.3)
    for a in ax:
        a.grid(alpha=0.3)
        a.legend(fontsize=7, loc="upper left")
    fig.suptitle("Slider-crank clearance benchmark, first quarter revolution: recipdyn against "
                 "Exudyn")  # fmt: skip
    return fig


if __name__ == "__main__":  # pragma: no cover - writes the doc page's figure and table
    import sys
    from pathlib import Path

    out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    results = {law: compare({"contact_law": law}) for law in HYSTERESIS}
    for law, r in results.items():
        print(
            f"| {law} | {r['impacts']} | {r['diff'][0]:.2e} | {r['diff'][1]:.2e} | "
            f"{r['order']:.2f} | {r['estimate']:.2e} | {r['extrapolated']:.2e} | "
            f"{r['slider'][1]:.2e} | {r['seconds'][0]:.1f} / {r['seconds'][1]:.1f} s |"
        )
    figure(results).savefig(out / "flores_exudyn.png", dpi=110)
