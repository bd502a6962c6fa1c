"""The crosshead guide's clearance as a component of the contact joints' glue
(`compressor-contact` and `compressor-contact-valves` with ``guide = clearance``): the rigid
guide untouched, agreement with `compressor-guide-reference` (an independent implementation:
the preset compressor-guide's kernel before the assembler), the stiff
zero-clearance limit, the energy balance with every worn part at once, and the knock's timing.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import recipdyn
from recipdyn.errors import ParameterError
from recipdyn.model.assembler.model import one_throw
from recipdyn.model.components.contact_model import pack
from recipdyn.model.components.load import PAPER
from recipdyn.model.joints.contact import FRICTION_LAWS, FRICTION_ROLES
from recipdyn.model.joints.pins import N_PACKED
from recipdyn.model.reference.compressor_guide import KERNELS, ideal_crosshead

#: The contact joints' machine of one throw (``compressor-contact``'s, the one assembler's).
CC = one_throw("contact")

#: Both pins ideal, the guide worn: the configuration `compressor-guide` integrates.
IDEAL_PINS = {"guide": "clearance", "crank_joint": "ideal", "crosshead_joint": "ideal"}


def test_a_rigid_guide_leaves_the_contact_model_as_it_was():
    """With ``guide = ideal`` (the default) the guide's parameters are inert: the parameter
    vector is the joints' and the load's only, the generated kernels bind no guide, and a
    run with every guide parameter changed is the default run to the bit (same trajectory,
    same steps). A guide parameter leaking into the rigid kernel would change one of them."""
    v = CC.parameters({})
    odd = {"guide_clearance": 3e-3, "guide_stiffness": 1e8, "guide_friction": 0.7,
           "crosshead_half_length": 0.9, "crosshead_tilt_inertia": 5.0}  # fmt: skip
    w = CC.parameters(odd)
    assert pack(v).size == N_PACKED + PAPER.pack(v).size
    np.testing.assert_array_equal(pack(v), pack(w))
    src = Path(CC.kernels(v).__file__).read_text()
    assert "HAS_GUIDE = False" in src  # the guide's branches removed before typing
    a = recipdyn.simulate(model=CC, params=v, revolutions=0.25, fs=2000.0)
    b = recipdyn.simulate(model=CC, params=w, revolutions=0.25, fs=2000.0)
    for k in ("ex", "ey", "a", "joint_force", "W_in", "W_loss"):
        np.testing.assert_array_equal(a[k].values, b[k].values)
    assert a.attrs["solver_nsteps"] == b.attrs["solver_nsteps"]
    assert "guide_y" not in a


def test_every_pin_joint_takes_the_guide_and_two_ideal_pins_need_it():
    """The guide combines with any pin joint (the clearance configuration follows); two ideal
    pins are refused without it, in one line that names the way out."""
    for crank, cross, where in (("contact", "ideal", "crank"), ("ideal", "lubricated",
                                "crosshead"), ("contact", "contact", "both"),
                                ("ideal", "ideal", "ideal")):  # fmt: skip
        v = CC.parameters({"guide": "clearance", "crank_joint": crank,
                           "crosshead_joint": cross})  # fmt: skip
        assert v["clearance_joints"] == where
        assert len(CC.initial_state(v)) == 20
    with pytest.raises(ParameterError, match="guide = 'clearance'"):
        CC.parameters({"crank_joint": "ideal", "crosshead_joint": "ideal"})


def _pair(c: float, load: dict, revolutions: float):
    params = {"guide_clearance": c, **load}
    new = recipdyn.simulate(model="compressor-contact", params={**IDEAL_PINS, **params},
                            revolutions=revolutions, transient=0.0, fs=4000.0)  # fmt: skip
    ref = recipdyn.simulate(model="compressor-guide-reference", params=params,
                            revolutions=revolutions, transient=0.0, fs=4000.0)  # fmt: skip
    return new, ref


@pytest.mark.parametrize("c", [1e-4, 2e-4, 5e-4])
@pytest.mark.parametrize("load", [{"load_amplitude": 2e4}, {"load": "cycle"}],
                         ids=["paper-20kN", "cycle"])  # fmt: skip
def test_with_ideal_pins_the_glue_s_guide_is_compressor_guide(c, load):
    """Hypothesis: the guide in the contact glue (coordinates: the crosshead pin's lateral
    position and the pins' eccentricities, equations from the contact model's Lagrangian) is
    the same mechanics as `compressor-guide` (coordinates: the rod angle, equations from the
    Flores-Leine-Glocker derivation), over the first revolution (from the same start: the
    crosshead centred; one revolution holds two to six knocks and no divergence).

    Tolerance: both integrate to rtol 1e-10; their difference is the two global errors,
    which the shoe impacts amplify (an impact located a little earlier or later shifts the
    contact force's spike). Each signal is compared to 1e4 rtol = 1e-6 of its own scale: the
    lateral position to the clearance c, the tilt to c / a (where a corner touches its shoe),
    the axial position to the stroke, the forces and the lateral acceleration to 1e-4 of their
    peaks (the spikes). A wrong mass, moment arm or sign would give percents. Measured (paper
    load 20 and 200 kN, cycle; c = 0.1, 0.2, 0.5 mm): lateral position 2.5e-13 - 4.2e-11 m,
    tilt 1.2e-12 - 1.1e-10 rad, side force and lateral acceleration 3e-8 - 6e-6 of their
    peaks, the same count of impacts; docs/faults.md has the table."""
    new, ref = _pair(c, load, 1.0)
    v = CC.parameters({**IDEAL_PINS, "guide_clearance": c, **load})
    scale = {"guide_y": 1e-6 * c, "tilt": 1e-6 * c / v["crosshead_half_length"],
             "x": 1e-6 * 2 * v["r"], "theta2": 1e-6 * c / v["l"]}  # fmt: skip
    for k in ("side_force", "shoe_force_lower", "shoe_force_upper", "guide_acc"):
        scale[k] = 1e-4 * np.abs(ref[k].values).max()
    for k, tol in scale.items():
        assert np.abs(new[k].values - ref[k].values).max() <= tol, k
    assert new.attrs["impacts_guide"] == ref.attrs["impacts"]
    assert new.attrs["energy_balance_residual"] < 1e-8


def test_no_clearance_and_stiff_shoes_give_the_rigid_guide():
    """The limit c -> 0 with stiff shoes (K = 1e12 N/m^1.5) and no friction at them (the
    rigid guide has none; the shoes' friction, 0.05 of a ~40 kN side force, would change the
    rod load by ~2 kN): with the crank pin worn
    (contact, c = 1 mm, the paper's load keeps the journal on the wall), the crosshead's
    acceleration and the crank pin's force are the rigid guide's to 1e-3 of their peaks and
    the eccentricity to 1e-3 of the clearance (the shoes' contact vibration, ~1 um of lateral
    motion at this stiffness, reaches them through the rod angle; measured in the docs); with
    both pins ideal, the net side force is the ideal mechanism's in closed form (Newton-Euler,
    `ideal_crosshead`) to 3 % of its peak, as for `compressor-guide`."""
    kw = dict(revolutions=0.5, transient=0.0, fs=2000.0)
    worn = recipdyn.simulate(model="compressor-contact", params={"guide": "clearance",
                             "guide_clearance": 0.0, "guide_friction": 0.0}, **kw)  # fmt: skip
    rigid = recipdyn.simulate(model="compressor-contact", params={}, **kw)
    for k, scale in (("a", None), ("joint_force", None), ("ex", 1e-3), ("ey", 1e-3)):
        scale = scale or np.abs(rigid[k].values).max()
        assert np.abs(worn[k].values - rigid[k].values).max() < 1e-3 * scale, k
    assert np.abs(worn.guide_y.values).max() < 1e-5
    v = CC.parameters({**IDEAL_PINS, "guide_clearance": 0.0})
    # after half a revolution: the crosshead starts centred, its shoes unloaded, and settles
    ideal = recipdyn.simulate(model=CC, params=v, **{**kw, "transient": 0.5})
    side = ideal_crosshead(v, ideal.theta1.values)["side_force"]
    assert np.abs(ideal.side_force.values - side).max() < 0.03 * np.abs(side).max()


def test_energy_balances_with_a_worn_guide_a_worn_crank_pin_and_the_dynamic_valves():
    """Every part worn at once (the crank pin's dry contact, the guide's clearance, the
    cylinder gas with dynamic valves): the mechanism's energy (rod, crosshead with its lateral
    motion and tilt, the contacts' elastic energy) changes by the work of the crank and the
    gas less what the pins and shoes dissipate. The crank's power is the crank pin's force
    times the journal's velocity; the residual is bounded by the integration's (rtol 1e-10
    over ~1e4 steps: 1e-8 of the energy's peak)."""
    ds = recipdyn.simulate(model="compressor-contact-valves",
                           params={"guide": "clearance", "guide_clearance": 2e-4,
                                   "crank_joint": "contact"},
                           revolutions=0.5, transient=0.0, fs=2000.0)  # fmt: skip
    assert ds.attrs["energy_balance_residual"] < 1e-8
    assert ds.attrs["impacts_guide"] >= 1
    assert ds.attrs["impacts"] >= 1  # the crank pin's


def _knocks(ds, values):
    """Crank angles (deg) of the impacts that end a crossing of the guide's clearance: the
    first onset on the other shoe (corners 1-2 upper, 3-4 lower)."""
    names = [f"impact_v_impact_guide_{k}" for k in range(1, 5)]
    before = np.column_stack([ds[k].values for k in names])
    after = np.column_stack([ds[k + "_after"].values for k in names])
    out, side = [], 0
    for t, row_b, row_a in zip(ds.impact_time.values, before, after, strict=True):
        for k in range(4):
            if row_a[k] > 0 >= row_b[k]:
                s = 1 if k < 2 else -1
                if s != side:
                    out.append(math.degrees(values["theta1_0"] + values["omega"] * t))
                    side = s
    return np.array(out)


def test_with_a_worn_crank_pin_the_crosshead_knocks_after_each_side_force_reversal():
    """With the crank pin worn too (dry contact, rc = 1 mm), the crosshead still rests on one
    shoe while the side force presses it there and knocks on the other after the side force
    reverses (docs/faults.md): one knock after each reversal of the ideal mechanism's side
    force, no other, within twice the flight time across the play after it (the estimate
    (12 m omega^2 c / k)^(1/3) of `tests/test_compressor_guide.py`). The crank pin's
    eccentricity (1 mm, on the wall under the paper's load) moves the rod angle by
    rc / l ~ 2e-3 rad, far less than the knock's lag."""
    v = CC.parameters({"guide": "clearance", "guide_clearance": 2e-4})
    ds = recipdyn.simulate(model="compressor-contact", params=v, revolutions=1, transient=1,
                           fs=4000.0)  # fmt: skip
    assert ds.attrs["energy_balance_residual"] < 1e-8
    th = np.radians(np.linspace(0, 720, 72001))
    side = ideal_crosshead(v, th)["side_force"]
    reversals = np.degrees(th[np.nonzero(np.diff(np.sign(side)))[0]])
    assert reversals.size == 4
    m = v["m3"] + (v["J2"] + v["m2"] * v["ls"] ** 2) / v["l"] ** 2
    knocks = _knocks(ds, v)
    knocks = knocks[knocks >= 360 + 1e-9]
    assert knocks.size == 2
    for th_k in knocks:
        th_r = reversals[reversals < th_k].max()
        j = np.argmin(np.abs(np.degrees(th) - th_r))
        k = abs(np.gradient(side, th)[j])
        lag = math.degrees((12 * m * v["omega"] ** 2 * v["guide_clearance"] / k) ** (1 / 3))
        assert 0 < th_k - th_r < 2 * lag, (th_r, th_k, lag)
    assert ds.attrs["peak_abs_guide_acc_m_s2"] > 50.0


#: The shoes' friction on, with v0 and v1 of the order of the crosshead's speed along the
#: guide (up to 2.4 m/s at the default omega), so that each law runs its own, unsaturated
#: branch (at 150 rad/s both saturate to Coulomb's value nearly everywhere).
SHOES = {**IDEAL_PINS, "guide_clearance": 2e-4, "load_amplitude": 2e4, "guide_friction": 0.2,
         "guide_v0": 0.5, "guide_v1": 2.0}  # fmt: skip


@pytest.mark.parametrize("law", FRICTION_LAWS)
def test_the_shoes_friction_law_is_chosen_by_name(law):
    """The guide's friction law is a function chosen when the kernels are built: the joints'
    module binds the one ``guide_friction_law`` names and reads no law code (its slice holds
    none), and `compressor-guide-reference` runs the compiled kernel of that law."""
    v = CC.parameters({**SHOES, "guide_friction_law": law})
    k = CC.kernels(v)
    src = Path(sys.modules[k.joints.py_func.__module__].__file__).read_text(encoding="utf-8")
    assert f"import {FRICTION_ROLES[law]} as guide_friction" in src
    assert "FLAW" not in src and "int(p[" not in src
    g = recipdyn.get_model("compressor-guide-reference")
    gv = g.parameters(guide_friction_law=law)
    assert g.system(gv).rhs is KERNELS[law][0] and g.system(gv).jac is KERNELS[law][1]


@pytest.mark.filterwarnings("ignore::recipdyn.errors.LawRangeWarning")
def test_a_change_of_the_shoes_friction_law_changes_the_run():
    """A run with the shoes' other friction law is another run (the selector is not
    ignored): the recorded friction of the shoes differs by a large part of its size, while
    without friction both laws give the same run to the bit."""
    runs = {}
    for mu in (0.2, 0.0):
        for law in FRICTION_LAWS:
            runs[mu, law] = recipdyn.simulate(model=CC, revolutions=0.25, fs=4000.0,
                                              params={**SHOES, "guide_friction": mu,
                                                      "guide_friction_law": law})  # fmt: skip
    a, b = (runs[0.2, law]["guide_friction_force"].values for law in FRICTION_LAWS)
    assert np.abs(a - b).max() > 0.1 * np.abs(a).max() > 0.0
    for k in runs[0.0, "tanh"].data_vars:
        assert np.array_equal(runs[0.0, "ambrosio"][k].values, runs[0.0, "tanh"][k].values), k
