"""Contact-impact crank pins on a machine of several throws (issue 43; the family
`recipdyn.model.assembler.contact_throws`, template ``contact_throws``).

* a machine of one throw with ``crank_joint = contact`` is ``--model compressor-contact``: the
  same values, the same module, the same record to the bit (every signal and event);
* with the crank prescribed the throws do not interact: two identical throws at 0 and 180 deg
  are each a one-throw run with its own crank angle at t = 0 (the second: the first's half a
  revolution later), and two throws of different clearances have each the impacts and the
  peak joint force of a one-throw run with its clearance; each throw's energy balance holds;
* the template's own block binds its reference configuration (one throw of the contact
  model's defaults); throws of two families, or contact throws on a motor, are refused in one
  line.

Tolerances: the machine and a one-throw run integrate the same equations with different step
sequences (the machine's error norm spans every throw, and it locates the pins' separations as
events too), so they agree to the integrator's error, not to the bit. That error is estimated
by the one-throw run at ``rtol = 1e-10`` against one at ``1e-12`` (or, where that estimate is
smaller, by ``rtol`` times the signal's size); the machine's is asserted within 10 times it
(the margin for its other step sequence). The windows are a quarter and half a revolution: a
pin impacting 14 times a revolution amplifies a difference at each impact (the runs part after
~0.3 revolution at 1e-6), so no longer trajectory is compared.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import recipdyn
from recipdyn.errors import LawRangeWarning, ModelValidityWarning, ParameterError
from recipdyn.model.machine import Machine, Shaft, Stage, Throw
from recipdyn.model.registry import get_model

#: 150 rad/s with a tenth of the paper's load: inertia lifts the journal off the bearing wall
#: and it impacts several times a revolution (the contact model's own example).
OMEGA, LOAD = 150.0, 2e4
RTOL, RTOL_REF = 1e-10, 1e-12


def _simulate(**kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelValidityWarning)
        warnings.simplefilter("ignore", LawRangeWarning)  # (this load's deepest contacts)
        return recipdyn.simulate(**kw)


def _machine(*throws, drive="prescribed", omega=OMEGA):
    from recipdyn.model.assembler.model import MachineModel

    return MachineModel(Machine("contact-test", shaft=Shaft(drive, params=(("omega", omega),)),
                                throws=tuple(throws), stages=(Stage(),)))  # fmt: skip


def _throw(name, phase=0.0, rc=1e-3, joint="contact"):
    return Throw(name, crank_joint=joint,
                 params=(("load_amplitude", LOAD), ("phase", phase), ("rc", rc)))  # fmt: skip


def _one(theta1_0, rc=1e-3, joint="contact", **kw):
    """A one-throw run of the contact model at ``rtol`` and at ``RTOL_REF`` (its error
    estimate)."""
    c = get_model("compressor-contact")
    v = c.parameters({"omega": OMEGA, "load_amplitude": LOAD, "theta1_0": theta1_0, "rc": rc,
                      "crank_joint": joint})  # fmt: skip
    return (c, v, _simulate(model=c, params=v, rtol=RTOL, **kw),
            _simulate(model=c, params=v, rtol=RTOL_REF, atol=1e-14, **kw))  # fmt: skip


def _bound(run, ref, name):
    """10 times the integrator's error estimate of ``run``'s signal ``name``."""
    est = np.abs(run[name].values - ref[name].values).max()
    return 10.0 * max(est, RTOL * np.abs(ref[name].values).max())


def test_one_contact_throw_is_the_contact_model_to_the_bit(tmp_path):
    """A machine file of one throw with ``crank_joint = contact`` takes the contact model's
    names and values and runs its module (called on the whole vector, its event the model's
    own): every signal, event and summary figure to the bit."""
    f = tmp_path / "one.toml"
    f.write_text(f'[shaft]\nomega = "{OMEGA} rad/s"\n\n[[throw]]\ncrank_joint = "contact"\n'
                 f'load_amplitude = "{LOAD} N"\n')  # fmt: skip
    machine = get_model(str(f))
    values = machine.parameters()
    c = get_model("compressor-contact")
    ref = c.parameters({"omega": OMEGA, "load_amplitude": LOAD})
    assert values.pop("phase") == 0.0
    assert values == {k: ref[k] for k in values}
    kw = dict(revolutions=1.0, fs=4000.0)
    a = _simulate(model=machine, **kw)
    b = _simulate(model=c, params=ref, **kw)
    assert set(a.data_vars) == set(b.data_vars)
    assert a.sizes["impact_event"] == b.sizes["impact_event"] > 10
    for k in b.data_vars:
        assert np.array_equal(a[k].values, b[k].values, equal_nan=True), k
    assert machine.run_summary(machine.parameters(), a) == c.run_summary(ref, b)


@pytest.mark.parametrize(("joint", "phase"), [("contact", math.pi), ("lubricated", math.pi),
                                              ("contact", 0.0)])  # fmt: skip
def test_two_throws_at_0_and_180_deg_are_one_throw_and_the_same_half_a_revolution_later(
    joint, phase
):
    """Two identical throws, phases 0 and 180 deg, the crank prescribed (the throws do not
    interact), dry or lubricated pins (the oil film's forces beside the contact's): throw 1 is
    a one-throw run from theta1_0 = 0, throw 2 one from theta1_0 = pi
    (the first's half a revolution later), to the integration's error (module docstring), in
    the pins' eccentricities and the crosshead's position over a quarter revolution with
    impacts at throw 1. (Not the work integrals: their error adds up over every step, and the
    machine takes more steps than either one-throw run, for both throws' impacts.) Both at
    0 deg, the throws' events coincide: each is reset at once (reset one by one, the other's
    factor stayed below 0 and no event was found after the first: 25966 steps a revolution
    with the damping of the first impact's approach velocity ever after, against 1424)."""
    m = _machine(_throw("throw1", joint=joint), _throw("throw2", phase, joint=joint))
    kw = dict(revolutions=0.25, fs=20000.0)
    a = _simulate(model=m, rtol=RTOL, **kw)
    assert a.sizes["impact_event"] >= 2  # (onsets and separations: the film cushions some)
    for name, th in (("throw1", 0.0), ("throw2", phase)):
        _, _, run, ref = _one(th, joint=joint, **kw)
        np.testing.assert_allclose(a[f"{name}.theta1"].values, run["theta1"].values,
                                   rtol=0, atol=1e-12)  # fmt: skip
        for k in ("ex", "ey", "x"):
            err = np.abs(a[f"{name}.{k}"].values - ref[k].values).max()
            assert err <= _bound(run, ref, k), (name, k, err, _bound(run, ref, k))


def test_each_throws_impacts_and_peak_force_are_a_one_throw_runs_with_its_clearance():
    """Two throws of clearances 1 and 0.5 mm (at 0 and 180 deg): over half a revolution each
    throw's impacts (the onsets at its own pin) are a one-throw run's with its clearance, its
    peak joint force and deepest penetration agree to the integration's error, and each
    throw's energy balance (its energy against the work of the gas and the crank less the
    joint's losses) closes to 1e-8 of its energy (the work integrals at rtol 1e-10 over ~1e3
    steps)."""
    m = _machine(_throw("throw1"), _throw("throw2", math.pi, rc=0.5e-3))
    kw = dict(revolutions=0.5, fs=20000.0)
    a = _simulate(model=m, rtol=RTOL, **kw)
    got = m.run_summary(m.parameters(), a)
    for name, th, rc in (("throw1", 0.0, 1e-3), ("throw2", math.pi, 0.5e-3)):
        c, v, run, ref = _one(th, rc=rc, **kw)
        s, s_ref = c.run_summary(v, run), c.run_summary(v, ref)
        assert got[f"{name}.impacts"] == s["impacts"] == s_ref["impacts"] >= 1, name
        for k in ("peak_joint_force_N", "max_penetration_m"):
            tol = 10.0 * max(abs(s[k] - s_ref[k]), RTOL * s_ref[k])
            assert abs(got[f"{name}.{k}"] - s_ref[k]) <= tol, (name, k)
        assert got[f"{name}.energy_balance_residual"] < 1e-8, name
    assert got["throw1.impacts"] != got["throw2.impacts"]  # (the clearances matter)


def test_the_contact_throws_template_binds_its_reference_configuration():
    """The template's own block is what the assembler binds for one throw of the contact
    model's defaults (its roles the same functions of that configuration's module, which is
    the template ``contact``'s own reference)."""
    from test_assembler import _block, _same_constants

    m = _machine(_throw("throw1"))
    c = m.contact(m.parameters())
    _, roles, constants, _, _ = c.bindings()
    got_roles, got_consts = _block("contact_throws")
    assert {r: f for r, (_, f) in roles.items()} == {r: f for r, (_, f) in got_roles.items()}
    _same_constants(got_consts, constants)


def test_throws_of_two_families_and_contact_throws_on_a_motor_are_refused_in_one_line():
    """Throws of two families (the link beside a contact pin, or beside an ideal crank pin
    with a worn crosshead pin), the link with a worn crosshead pin, contact throws on a
    motor, and contact throws whose pins differ (a worn crosshead pin on one only)."""
    worn = Throw("throw2", crank_joint="ideal", crosshead_joint="contact")
    for throws, drive, words in (
        ((_throw("throw1"), Throw("throw2")), "prescribed", "throw2.crank_joint = 'link'"),
        ((Throw("throw1"), worn), "prescribed", "crosshead_joint = 'contact'"),
        ((Throw("throw1", crosshead_joint="contact"),), "prescribed", "beside crank_joint"),
        ((_throw("throw1"), _throw("throw2")), "motor", "drive = 'motor'"),
    ):
        with pytest.raises(ParameterError) as exc:
            _machine(*throws, drive=drive)
        assert words in str(exc.value) and "\n" not in str(exc.value), str(exc.value)
    m = _machine(_throw("throw1"), Throw("throw2", crosshead_joint="contact",
                                         crank_joint="contact"))  # fmt: skip
    with pytest.raises(ParameterError) as exc:
        m.parameters()
    assert "throw2: its pins, guide" in str(exc.value) and "\n" not in str(exc.value)


@pytest.mark.parametrize("load", ["valves", "cycle"])
def test_throws_with_the_cycle_or_the_dynamic_valves_are_each_a_one_throw_run(load):
    """Two throws with contact crank pins and the compression cycle (ideal valves) or the
    dynamic valves (their pressures and plates states of each throw's slice), at 0 and 90 deg
    with clearances 1 and 0.5 mm: each throw's pin, crosshead (and with the valves its chamber
    pressures) are a one-throw ``compressor-contact`` (``-valves``) run's with its crank angle
    at t = 0 and its clearance, to the integration's error (module docstring), over a quarter
    revolution at 20 rad/s (the rod load reverses: impacts); each throw's events are its own
    (the same count of onsets)."""
    m = _machine(Throw("throw1", crank_joint="contact", load=load),
                 Throw("throw2", crank_joint="contact", load=load,
                       params=(("phase", math.pi / 2), ("rc", 0.5e-3))), omega=20.0)  # fmt: skip
    kw = dict(revolutions=0.25, fs=4000.0)
    a = _simulate(model=m, rtol=RTOL, **kw)
    got = m.run_summary(m.parameters(), a)
    if load == "valves":
        c, own, names = get_model("compressor-contact-valves"), {}, ("p_head", "p_crank")
    else:
        c, own, names = get_model("compressor-contact"), {"load": "cycle"}, ()
    for name, th, rc in (("throw1", 0.0, 1e-3), ("throw2", math.pi / 2, 0.5e-3)):
        v = c.parameters({"omega": 20.0, "theta1_0": th, "rc": rc, **own})
        run = _simulate(model=c, params=v, rtol=RTOL, **kw)
        ref = _simulate(model=c, params=v, rtol=RTOL_REF, atol=1e-14, **kw)
        for k in ("ex", "ey", "x", *names):
            err = np.abs(a[f"{name}.{k}"].values - ref[k].values).max()
            assert err <= _bound(run, ref, k), (name, k, err, _bound(run, ref, k))
        assert got[f"{name}.impacts"] == c.run_summary(v, run)["impacts"], name


@pytest.mark.parametrize(
    ("pins", "signals"),
    [
        ({"crank_joint": "ideal", "crosshead_joint": "contact"},
         ("ex_crosshead", "ey_crosshead", "x")),
        ({"crank_joint": "ideal", "guide": "clearance"}, ("guide_y", "tilt", "x")),
    ],
    ids=["crosshead-pin", "guide"],
)  # fmt: skip
def test_throws_with_a_worn_crosshead_pin_or_the_guides_clearance_are_each_a_one_throw_run(
    pins, signals
):
    """Two throws with a worn crosshead pin, or with the crosshead in its guide's clearance
    (0.2 mm), at 0 and 90 deg: each throw's crosshead pin or lateral position and tilt, and
    its crosshead's travel, are a one-throw ``compressor-contact`` run's with the same pins
    and its crank angle at t = 0, to the integration's error (module docstring), over a
    quarter revolution; the same impacts at the crosshead pin, each throw's energy balance."""
    extra = (("guide_clearance", 2e-4),) if pins.get("guide") == "clearance" else ()
    m = _machine(*(Throw(f"throw{k + 1}", **pins, params=(("load_amplitude", LOAD),
                                                          ("phase", k * math.pi / 2), *extra))
                   for k in range(2)))  # fmt: skip
    kw = dict(revolutions=0.25, fs=20000.0)
    a = _simulate(model=m, rtol=RTOL, **kw)
    got = m.run_summary(m.parameters(), a)
    c = get_model("compressor-contact")
    for k, name in enumerate(("throw1", "throw2")):
        v = c.parameters({"omega": OMEGA, "load_amplitude": LOAD, "theta1_0": k * math.pi / 2,
                          **pins, **dict(extra)})  # fmt: skip
        run = _simulate(model=c, params=v, rtol=RTOL, **kw)
        ref = _simulate(model=c, params=v, rtol=RTOL_REF, atol=1e-14, **kw)
        for s in signals:
            err = np.abs(a[f"{name}.{s}"].values - ref[s].values).max()
            assert err <= _bound(run, ref, s), (name, s, err, _bound(run, ref, s))
        own = c.run_summary(v, run)
        if "impacts_crosshead" in own:
            assert got[f"{name}.impacts_crosshead"] == own["impacts_crosshead"], name
        assert got[f"{name}.energy_balance_residual"] < 1e-8, name
