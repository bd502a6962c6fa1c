"""The interstage volume between two stages (issue 43, points 3 and 4): stage 1's discharge
valves deliver into a volume held at the cooler's temperature, stage 2's suction valves take
in from it, its pressure a state.

* the mean interstage pressure of an ideal two-stage machine (stiff, light valves; a small
  clearance, its volumetric efficiency accounted for) against the closed form of the mass
  balance, within a tolerance from the pressure's ripple, the valves' departure from ideal
  ones and the start-up left over;
* the volume's mass balance: its change over a window equals the mass stage 1 delivered less
  the mass stage 2 took in (an invariant, to rounding);
* a leaking stage-1 discharge valve lowers the interstage pressure;
* a machine without an interstage is the machine it was (its layout, its generated module's
  flags), and the description refuses what the interstage cannot hold, in one line.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.optimize import brentq

from recipdyn.errors import ParameterError
from recipdyn.model.machine import Interstage, Machine, Shaft, Stage, Throw
from recipdyn.simulate import simulate

OMEGA = 20.0
T_SUCTION, T_COOLER = 293.15, 313.15
P_SUCTION, P_DISCHARGE = 1e5, 9e5
CLEARANCE = 0.03
#: Valves 2 times larger in area with plates 4 times lighter than the defaults: toward the
#: ideal limit of tests/test_valves.py (there the volumetric efficiency is within 8.8e-4 of
#: the closed form at this factor, 1.3e-4 at 8, which costs 3.4 times the run time and moved
#: the interstage pressure here by 1e-4 of itself, measured).
IDEAL_VALVES = (("valve_area_fraction", 0.16), ("valve_mass", 0.05 / 4),
                ("valve_preload", 5.0 / 4), ("clearance_fraction", CLEARANCE))  # fmt: skip


def _machine(volume=1.0, p0=3e5, leak=0.0, bore2=0.3, interstage=True, drive="prescribed"
             ) -> Machine:  # fmt: skip
    """Two throws on an ideal crank pin: stage 1 (500 mm bore) at 0 deg, stage 2 (``bore2``)
    at 90 deg, double-acting, the ideal valves above; the interstage starts at ``p0``; the
    crank at a prescribed speed or on the induction motor (``drive``)."""
    leaks = (("leak_area_discharge_head", leak),)
    t1 = Throw("throw1", stage="stage1", crank_joint="ideal", load="valves",
               params=(("phase", 0.0), *IDEAL_VALVES, *leaks))  # fmt: skip
    t2 = Throw("throw2", stage="stage2", crank_joint="ideal", load="valves",
               params=(("phase", math.pi / 2), ("bore", bore2), *IDEAL_VALVES))  # fmt: skip
    s2 = (("discharge_pressure", P_DISCHARGE),)
    if not interstage:
        s2 += (("suction_pressure", p0), ("suction_temperature", T_COOLER))
    stages = (Stage("stage1", (("suction_pressure", P_SUCTION), ("discharge_pressure", p0),
                               ("suction_temperature", T_SUCTION))),
              Stage("stage2", s2))  # fmt: skip
    inter = (Interstage("interstage1", "stage1", "stage2",
                        (("volume", volume), ("cooler_temperature", T_COOLER))),)  # fmt: skip
    return Machine("two-stage", shaft=Shaft(drive, params=(("omega", OMEGA),)),
                   throws=(t1, t2), stages=stages,
                   interstages=inter if interstage else ())  # fmt: skip


def _model(machine: Machine):
    from recipdyn.model.assembler.model import MachineModel

    return MachineModel(machine)


def _run(machine: Machine, revolutions: float, transient: float, fs: float = 2000.0):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (the link's validity: an ideal pin, not the subject)
        return simulate(model=_model(machine), revolutions=revolutions, transient=transient,
                        fs=fs)  # fmt: skip


def _swept(values, throw: str) -> float:
    """A double-acting throw's swept volume per revolution, m^3 (both ends)."""
    from recipdyn.model.cycle import cycle_geometry

    g = cycle_geometry(values[f"{throw}.r"], values[f"{throw}.l"],
                       values[f"{throw}.d"], values[f"{throw}.bore"],
                       values[f"{throw}.rod_diameter"])  # fmt: skip
    return (g.area_head + g.area_crank) * g.stroke


def _closed_form(values) -> tuple[float, float]:
    """The steady interstage pressure of the ideal machine and the volume's time constant.

    Per revolution stage 1 takes in (and, periodic, delivers) ``p_s1 eta_1 V_1 / (R T_s1)``
    and stage 2 takes in ``p_i eta_2 V_2 / (R T_c)``, with the volumetric efficiencies of
    ideal valves ``eta = 1 - C ((p_d / p_s)^(1/n) - 1)`` (``n`` the re-expansion exponent,
    ``C`` the clearance fraction): ``eta_1`` at ``p_i / p_s1``, ``eta_2`` at ``p_d2 / p_i``.
    Their balance ``p_s1 eta_1(p_i) V_1 / T_s1 = p_i eta_2(p_i) V_2 / T_c`` gives ``p_i``
    (one root: the left falls and the right rises with ``p_i``). The time constant of a
    departure from it: ``tau = (V / (R T_c)) / (d/dp_i of (intake_2 - delivery_1) per
    second)``."""
    n = values["throw1.n_expansion"]
    v1, v2 = _swept(values, "throw1"), _swept(values, "throw2")

    def eta(ratio):
        return 1.0 - CLEARANCE * (ratio ** (1.0 / n) - 1.0)

    def excess(p):  # stage 2's intake less stage 1's delivery, m^3 K^-1 Pa per revolution
        intake = p * eta(P_DISCHARGE / p) * v2 / T_COOLER
        return intake - P_SUCTION * eta(p / P_SUCTION) * v1 / T_SUCTION

    p_i = brentq(excess, 1.1 * P_SUCTION, 0.9 * P_DISCHARGE, xtol=1e-6)
    slope = (excess(p_i * 1.001) - excess(p_i * 0.999)) / (0.002 * p_i)  # per revolution
    tau = values["interstage1.volume"] / T_COOLER / (slope * OMEGA / (2.0 * math.pi))
    return p_i, tau


def test_the_interstage_pressure_of_an_ideal_two_stage_machine_is_its_closed_form():
    """Hypothesis: the interstage pressure settles where stage 2 takes in what stage 1
    delivers (`_closed_form`: 3.071 bar with these bores and temperatures, 3 % clearance).

    The volume (1 m^3) starts 2 % above it; its time constant (`_closed_form`) is 29
    revolutions, and after 5 of them the start-up left over is 2 % e^-5 ~ 1.3e-4 of the
    pressure (a model with another balance would by then have gone 99 % of the way to its
    own). Tolerance, the sum of three bounds: (a) the ripple: within a revolution each
    stage's mass is the closed form's at some pressure the volume passed through (its intake
    and delivery are monotone in the pressure), so the closed form's pressure lies within the
    revolution's range, as does the mean: |mean - p*| <= ptp, measured 1.05 % of the
    pressure (the error it leaves scales with it: 0.58 % at half the volume, 0.30 % here);
    (b) the valves' departure from ideal ones: 8.8e-4 in each volumetric efficiency
    (`IDEAL_VALVES`), 2e-3 in the pressure; (c) the start-up left over, 1.3e-4, and the
    integration (rtol 1e-10), negligible beside them. Measured error: 0.30 % of the pressure
    (3.080 bar against 3.071).
    A model that took stage 1's suction temperature for the cooler's (7 % off) or lost a
    chamber's flow would fail it."""
    p_star = 3.07e5
    machine = _machine(volume=1.0, p0=1.02 * p_star)
    values = _model(machine).parameters()
    p_star, tau = _closed_form(values)
    revs_tau = tau * OMEGA / (2.0 * math.pi)
    assert 25.0 < revs_tau < 35.0
    assert abs(values["stage1.discharge_pressure"] / p_star - 1.02) < 1e-3
    ds = _run(machine, revolutions=4, transient=math.ceil(5.0 * revs_tau))
    p = ds["interstage1.p"].values
    mean, ripple = p.mean(), np.ptp(p)
    tol = ripple + 2e-3 * p_star + 0.02 * p_star * math.exp(-5.0)
    assert abs(mean - p_star) < tol, (mean, p_star, ripple)
    assert ripple < 0.015 * p_star  # (a bound this small says something)


@pytest.mark.parametrize("drive", ["prescribed", "motor"])
def test_the_interstage_mass_changes_by_what_stage_1_delivers_less_what_stage_2_takes_in(
    drive,
):
    """Both templates (a prescribed crank, a motor). The volume's mass ``p V / (R T_c)``
    and the cylinders' mass counters integrate one balance: ``m_i - (mass stage 1
    delivered) + (mass stage 2 took in)`` is a linear
    invariant of the right-hand side, which every Runge-Kutta step keeps to rounding (the
    valves' impacts reset plates only). Over a window of 3 revolutions from the start (the
    largest swings) the mass (0.83 kg) changes by 0.064 kg; rounding over ~1e4 steps on 1 kg
    is ~1e-12 kg (measured: 1.4e-14 kg), so 1e-9 of the volume's mass leaves a wide margin
    and still catches a flow counted twice or a counter left out (0.01 to 1 of the
    change)."""
    machine = _machine(volume=0.3, p0=2.5e5, drive=drive)
    ds = _run(machine, revolutions=3, transient=0, fs=4000.0)
    m = ds["interstage1.mass"].values
    delivered = sum(ds[f"throw1.mass_out_{end}"].values for end in ("head", "crank"))
    taken = sum(ds[f"throw2.mass_in_{end}"].values for end in ("head", "crank"))
    balance = (m - m[0]) - (delivered - delivered[0]) + (taken - taken[0])
    assert np.abs(m - m[0]).max() > 0.02  # (the window moves the mass)
    assert np.abs(balance).max() < 1e-9 * m[0], np.abs(balance).max()
    # the recorded flows are the counters' rates: their integral over the window is the same
    # balance to the trapezoid rule's error (1e-2 of the change, measured 1.8e-3: 4 kHz, ~200
    # samples a stroke, the flow's sharp edges at the valves' openings)
    t = ds["time"].values
    net = ds["interstage1.mdot_in"].values - ds["interstage1.mdot_out"].values
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (net[1:] + net[:-1]) * np.diff(t))])
    assert np.abs(integral - (m - m[0])).max() < 1e-2 * np.abs(m - m[0]).max()


def test_a_leaking_stage_1_discharge_valve_lowers_the_interstage_pressure():
    """A leak in stage 1's head-end discharge valve lets gas the cylinder delivered flow back
    from the interstage volume while the head end re-expands and takes in: stage 1 delivers
    less per revolution, stage 2 still takes in in proportion to the pressure, so the balance
    settles at a lower interstage pressure (the field rule: a low interstage pressure points
    to stage 1's valves, a high one to stage 2's). Both runs start from the same state and
    run 40 revolutions of a 0.3 m^3 volume (time constant ~9 revolutions); the leak (4 cm^2,
    a broken plate's piece) lowers the mean of the last 4 revolutions by 20 % (3.10 to 2.48
    bar, measured), which is asked to exceed the healthy run's ripple (3.5 %) so that no
    phase of the ripple can make it."""
    runs = {}
    for leak in (0.0, 4e-4):
        ds = _run(_machine(volume=0.3, p0=2.9e5, leak=leak), revolutions=4, transient=36)
        runs[leak] = ds["interstage1.p"].values
    healthy, leaking = runs[0.0], runs[4e-4]
    assert healthy.mean() - leaking.mean() > np.ptp(healthy), (healthy.mean(), leaking.mean())


def test_a_machine_without_an_interstage_is_the_machine_it_was():
    """Without ``[[interstage]]`` the layout holds no interstage part, stage 2 keeps its set
    suction line among its parameters, and the generated module's interstage flags are off
    (its roles bound to nothing, pruned before typing): the arithmetic is the one of before
    the interstage (measured when this was built: every array of five machines and presets,
    two with dynamic valves, identical to the bit to the tree before it)."""
    m = _model(_machine(interstage=False))
    v = m.parameters()
    c = m.configuration(v)
    assert not any("interstage" in k for k in (*c.layout.state.parts, *c.layout.params.parts))
    assert "stage2.suction_pressure" in v and not any(k.startswith("interstage") for k in v)
    _, roles, constants, _, _ = c.bindings()
    assert constants["INTERSTAGE"] is False and constants["N_INTERSTAGES"] == 0
    assert roles["load_rhs_lines"] == ("recipdyn.model.assembler.generate", "absent")
    # with one: the volume's state sits after the loads' states, before their counters
    c2 = _model(_machine()).configuration(_model(_machine()).parameters())
    st = c2.layout.state
    assert st["interstage1.p"] == st.start("throw1.load_aux") - 1
    assert c2.bindings()[2]["THROW_IN"].tolist() == [-1, 0]
    assert c2.bindings()[2]["THROW_OUT"].tolist() == [0, -1]


@pytest.mark.parametrize(
    "change, match",
    [
        ({"load": "cycle"}, "needs the mass flows"),
        ({"to": "stage1"}, "two different stages"),
        ({"to": "stage3"}, "the machine's stages"),
        ({"fed": (("suction_pressure", 3e5),)}, "stage2.suction_pressure is set by"),
    ],
)
def test_the_description_refuses_what_an_interstage_cannot_hold(change, match):
    t1 = Throw("throw1", stage="stage1", load=change.get("load", "valves"))
    t2 = Throw("throw2", stage="stage2", load=change.get("load", "valves"))
    stages = (Stage("stage1"), Stage("stage2", change.get("fed", ())))
    inter = Interstage("interstage1", "stage1", change.get("to", "stage2"))
    with pytest.raises(ParameterError, match=match):
        Machine("m", throws=(t1, t2), stages=stages, interstages=(inter,))


def test_an_interstage_in_a_file_and_its_refusals_before_numba(tmp_path):
    """A machine file's ``[[interstage]]``: its parameters with units under its name, range
    checked; a real gas through it, or two gases, is refused in one line (a real gas's line
    states are tabulated at set pressures), and so is a key it does not have."""
    from recipdyn.model.machine import read_machine

    text = """
[[stage]]
name = "stage1"
[[stage]]
name = "stage2"
[[interstage]]
from = "stage1"
to = "stage2"
volume = "800 L"
cooler_temperature = "313.15 K"
[[throw]]
stage = "stage1"
load = "valves"
[[throw]]
stage = "stage2"
load = "valves"
"""
    path = tmp_path / "m.toml"
    path.write_text(text)
    m = _model(read_machine(path))
    v = m.parameters()
    assert v["interstage1.volume"] == pytest.approx(0.8)
    assert v["interstage1.cooler_temperature"] == pytest.approx(313.15)
    with pytest.raises(ParameterError, match="interstage1.volume"):
        m.parameters({"interstage1.volume": -1.0})
    with pytest.raises(ParameterError, match="throw2.gas = 'Argon': interstage 'interstage1'"):
        m.parameters({"throw2.gas": "Argon"})
    with pytest.raises(ParameterError, match="one gas flows through it"):
        m.parameters({"throw2.gas_constant": 260.0})
    path.write_text(text.replace('volume = "800 L"', 'volume = "800 L"\npressure = 1'))
    with pytest.raises(ParameterError, match="not a parameter of an interstage"):
        read_machine(path)
