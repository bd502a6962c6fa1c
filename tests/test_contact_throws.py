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
#: simulate's absolute tolerance per step (its default).
ATOL = 1e-12


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


def test_throws_of_two_families_and_what_a_motor_does_not_take_are_refused_in_one_line():
    """The massless link beside a contact pin, or beside an ideal crank pin with a worn
    crosshead pin (an ideal pin may stand there: tests/test_mixed_throws.py), the link with a
    worn crosshead pin, and contact throws whose
    pins differ (a worn crosshead pin on one only); a flexible shaft under a held rotor with
    contact pins (a flexible shaft on a motor: tests/test_contact_torsion.py; the held rotor
    on a rigid shaft: tests/test_mixed_throws.py), and on a motor a worn crank pin's
    crank without an inertia of its own."""
    worn = Throw("throw2", crank_joint="ideal", crosshead_joint="contact")
    for throws, drive, words in (
        ((_throw("throw1"), Throw("throw2")), "prescribed", "throw2.crank_joint = 'link'"),
        ((Throw("throw1"), worn), "prescribed", "throw1.crank_joint = 'link'"),
        ((Throw("throw1", crosshead_joint="contact"),), "prescribed", "beside crank_joint"),
        ((_throw("throw1"),), "torsion", "[shaft.torsion] under a held rotor"),
    ):
        with pytest.raises(ParameterError) as exc:
            if drive == "torsion":
                _motor_machine(*throws, motor="held", torsion=True)
            else:
                _machine(*throws, drive=drive)
        assert words in str(exc.value) and "\n" not in str(exc.value), str(exc.value)
    m = _machine(_throw("throw1"), Throw("throw2", crosshead_joint="contact",
                                         crank_joint="contact"))  # fmt: skip
    with pytest.raises(ParameterError) as exc:
        m.parameters()
    assert "throw2: its pins, guide" in str(exc.value) and "\n" not in str(exc.value)
    # on a motor with several throws a worn crank pin's crank needs its own inertia
    bare = Throw("throw2", crank_joint="contact", params=(("m1", 0.0), ("J1", 0.0)))
    with pytest.raises(ParameterError) as exc:
        _motor_machine(_throw("throw1"), bare).parameters()
    assert "throw2.J1 + m1 rs**2 = 0" in str(exc.value) and "\n" not in str(exc.value)


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


# ---- on a motor: the throws share the crank's acceleration --------------------------------

#: The motor's synchronous speed above the runs' 150 rad/s (Kloss's curve, breakdown slip 0.15).
SYNC = 160.0


def _motor_machine(*throws, motor="induction", torsion=False, **shaft):
    from recipdyn.model.assembler.model import MachineModel

    params = {"omega": OMEGA, "motor_sync_speed": SYNC, **shaft}
    return MachineModel(Machine("contact-motor-test", shaft=Shaft(
        "motor", motor, params=tuple(params.items()), torsion=torsion), throws=tuple(throws),
        stages=(Stage(),)))  # fmt: skip


def test_one_contact_throw_on_a_motor_is_the_contact_model_on_a_motor_to_the_bit(tmp_path):
    """A machine file of one throw with ``crank_joint = contact`` and ``drive = motor`` is
    ``--model compressor-contact --set drive=motor`` at the same values: the same module (the
    template calls it on the whole vector and adds nothing with one throw), every signal and
    event to the bit, and the same auxiliary and passive states (Lyapunov's tangent space)."""
    f = tmp_path / "one.toml"
    f.write_text(f'[shaft]\ndrive = "motor"\nomega = "{OMEGA} rad/s"\nmotor_sync_speed = '
                 f'"{SYNC} rad/s"\n\n[[throw]]\ncrank_joint = "contact"\nload_amplitude = '
                 f'"{LOAD} N"\n')  # fmt: skip
    machine = get_model(str(f))
    values = machine.parameters()
    c = get_model("compressor-contact")
    ref = c.parameters({"omega": OMEGA, "load_amplitude": LOAD, "drive": "motor",
                        "motor_sync_speed": SYNC})  # fmt: skip
    assert values.pop("phase") == 0.0
    assert values == {k: ref[k] for k in values}
    s, own = machine.system(machine.parameters()), c.system(ref)  # (Lyapunov's tangent space)
    assert (s.passive, s.aux, s.aux_states) == (own.passive, own.aux, own.aux_states)
    kw = dict(revolutions=0.5, fs=4000.0)
    a = _simulate(model=machine, **kw)
    b = _simulate(model=c, params=ref, **kw)
    assert set(a.data_vars) == set(b.data_vars)
    assert a.sizes["impact_event"] == b.sizes["impact_event"] > 3
    for k in b.data_vars:
        assert np.array_equal(a[k].values, b[k].values, equal_nan=True), k


@pytest.mark.parametrize(
    ("pins", "signals"),
    [
        ({}, ("ex", "ey", "x")),
        ({"crosshead_joint": "contact"}, ("ex", "ey", "ex_crosshead", "ey_crosshead", "x")),
        ({"guide": "clearance"}, ("ex", "ey", "guide_y", "tilt", "x")),
        ({"crank_joint": "ideal", "crosshead_joint": "contact"},
         ("ex_crosshead", "ey_crosshead", "x")),
        ({"crank_joint": "ideal", "crosshead_joint": "contact", "guide": "clearance"},
         ("ex_crosshead", "ey_crosshead", "guide_y", "tilt", "x")),
        ({"crank_joint": "ideal", "guide": "clearance"}, ("guide_y", "tilt", "x")),
    ],
    ids=["crank-pin", "both-pins", "crank-pin-and-guide", "crosshead-pin",
         "crosshead-pin-and-guide", "guide"],
)  # fmt: skip
def test_two_identical_throws_in_phase_on_a_motor_are_one_throw_with_twice_the_drive(pins, signals):
    """Two identical throws in phase on the motor, with twice the drive's inertia and twice
    the motor's torque (Kloss's curve is proportional to its breakdown torque), turn the crank
    as one throw with the drive once: ``(2 J_d + 2 I) alpha = 2 T + 2 tau``. The machine
    composes the crank's acceleration from each throw's torque on its crank and corrects each
    throw's crank-pin eccentricity to it (template ``contact_throws``, ``_shaft``: the rod's
    big end, and with it the crosshead pin and the crosshead in its guide, do not depend on
    the crank's acceleration); the one-throw model solves the throw's whole Lagrangian with
    the crank's row inside: independent arithmetic. With the worn crank pin alone, with both
    pins worn, and with the guide's clearance (0.2 mm). A light drive (2 kg m^2 with the
    crank's own 0.055) makes the speed swing (5-8 %), so a composition that dropped the
    correction or a throw's share would fail (twice the drive on one throw moves the pin by
    7e-4 m against a bound of ~2e-8 m; 5 % more drive on the one throw moves the crosshead pin
    by 2e-5 m, the crosshead by 2e-4 m, against bounds of ~1e-9 m). With an ideal crank pin (a
    worn crosshead pin, the guide's clearance) the rod turns with the crank: each throw's
    share of the crank's inertia is its mass matrix's Schur complement
    (`recipdyn.model.joints.pins.ideal_share`). Each throw's pins (and guide) and crosshead,
    and the speed, to the integration's error (module docstring), a quarter revolution with
    impacts."""
    J, TB = 2.0, 3000.0
    extra = (("guide_clearance", 2e-4),) if pins.get("guide") == "clearance" else ()
    pins = {"crank_joint": "contact", **pins}
    th = [Throw(f"throw{k}", **pins, params=(("load_amplitude", LOAD), *extra))
          for k in (1, 2)]  # fmt: skip
    m = _motor_machine(*th, J_drive=2 * J, motor_breakdown_torque=2 * TB)
    kw = dict(revolutions=0.25, fs=20000.0)
    a = _simulate(model=m, rtol=RTOL, **kw)
    c = get_model("compressor-contact")
    v = c.parameters({"omega": OMEGA, "load_amplitude": LOAD, "drive": "motor", "J_drive": J,
                      "motor_sync_speed": SYNC, "motor_breakdown_torque": TB, **pins,
                      **dict(extra)})  # fmt: skip
    run = _simulate(model=c, params=v, rtol=RTOL, **kw)
    ref = _simulate(model=c, params=v, rtol=RTOL_REF, atol=1e-14, **kw)
    assert run.sizes["impact_event"] >= 2
    swing = np.ptp(ref["omega1"].values) / OMEGA
    assert swing > 0.01, swing  # (the crank's acceleration matters)
    err = np.abs(a["omega1"].values - ref["omega1"].values).max()
    assert err <= _bound(run, ref, "omega1"), (err, _bound(run, ref, "omega1"))
    for name in ("throw1", "throw2"):
        for k in signals:
            err = np.abs(a[f"{name}.{k}"].values - ref[k].values).max()
            # (at least 10 times the integrator's absolute tolerance per step, 1e-12: the
            # guide's tilt, ~1e-4 rad, agrees to 4e-13 rad, below what a step resolves)
            tol = max(_bound(run, ref, k), 10 * ATOL)
            assert err <= tol, (name, k, err, tol)


def test_a_huge_flywheel_holds_the_speed_and_the_throws_move_as_with_the_crank_prescribed():
    """Two contact throws at 0 and 180 deg on a drive a million times the default (3e9 kg
    m^2): the speed departs from its initial value by at most ``t (max|T_m| + sum_k max|tau_k|)
    / J``, each throw's torque on its crank bounded by its pin's force, ``|tau_k| <= (r + mu
    R_j) max|F_k| + g m1 rs`` (the force's moment about the main bearing, the dry friction's
    about the journal, the crank's weight); and each throw's pin and crosshead are the
    prescribed machine's to the integration's error (module docstring: 10 times each
    machine's own estimate, rtol 1e-10 against 1e-12) plus the crank angle's departure
    ``d theta1`` (~1e-9 rad here), which moves the crank pin by ``r |d theta1|`` (a free
    journal's eccentricity by as much, one in contact by less) and the crosshead by at most
    ``r (1 + tan theta2_max) |d theta1|``; the integration's error of both machines."""
    th = (_throw("throw1"), _throw("throw2", math.pi))
    mm = _motor_machine(*th, J_drive=3e9)
    kw = dict(revolutions=0.25, fs=20000.0)
    a = _simulate(model=mm, rtol=RTOL, **kw)
    a_ref = _simulate(model=mm, rtol=RTOL_REF, atol=1e-14, **kw)
    mp = _machine(*th)
    run = _simulate(model=mp, rtol=RTOL, **kw)
    ref = _simulate(model=mp, rtol=RTOL_REF, atol=1e-14, **kw)
    v = mm.parameters()
    r, mu, rj, g = (float(v[f"throw1.{k}"]) for k in ("r", "friction", "journal_radius", "g"))
    m1, rs = float(v["throw1.m1"]), float(v["throw1.rs"])
    tau = sum((r + mu * rj) * np.abs(a[f"{q}.joint_force"].values).max() + g * m1 * rs
              for q in ("throw1", "throw2"))  # fmt: skip
    t = a.time.values - a.time.values[0]
    total = 3e9 + 2 * (float(v["throw1.J1"]) + m1 * rs**2)
    bound = t * (np.abs(a["motor_torque"].values).max() + tau) / total
    dw = np.abs(a["omega1"].values - OMEGA)
    assert np.all(dw <= bound * (1 + 1e-9) + 1e-12 * OMEGA), (dw.max(), bound.max())
    assert dw.max() > 0.0
    dth = np.abs(a["theta1"].values - run["theta1"].values).max()
    p = mp.parameters()
    l, d = float(p["throw1.l"]), float(p["throw1.d"])
    s2 = (r + 1.5e-3 + abs(d)) / l
    tan2 = s2 / math.sqrt(1 - s2**2)
    for q in ("throw1", "throw2"):
        for k, extra in (("ex", r * dth), ("ey", r * dth), ("x", r * (1 + tan2) * dth)):
            err = np.abs(a[f"{q}.{k}"].values - ref[f"{q}.{k}"].values).max()
            tol = _bound(run, ref, f"{q}.{k}") + _bound(a, a_ref, f"{q}.{k}") + extra
            assert err <= tol, (q, k, err, tol, dth)


@pytest.mark.parametrize("pins", ["example", "crosshead-pin-and-guide"])
def test_the_energy_of_a_machine_of_contact_throws_on_a_motor_balances(pins):
    """Invariant: the motor's work is the change of the machine's energy (the drive's, each
    throw's crank, rod and crosshead, the contacts' elastic energy) plus the work done on the
    gas plus the energy lost in the joints, ``W_motor = dE + sum_k (-W_gas,k + W_loss,k)``
    (``W_gas`` the gas's work on the crosshead, negative while it is compressed); the
    residual is the integrator's global error, at most the sum of the steps' local errors,
    ``n_steps rtol max(|E|, |W|)``: the bound (as the one-throw model's test). The example
    machine (dry and lubricated pins, 0 and 180 deg) with a light drive (30 kg m^2), half a
    revolution; and two throws with ideal crank pins, worn crosshead pins and the guide's
    clearance (each one's rod turning with the crank: its share of the crank's inertia the
    Schur complement of its mass matrix), a quarter. Each throw's own balance (its energy
    against the gas's and the shaft's work on its crank less its losses) closes alike, and the
    shaft's equation holds at every sample: ``sum_k crank_torque_k = T_m - J_drive alpha1``
    (to rounding)."""
    from pathlib import Path

    revolutions = 0.5
    if pins == "example":
        model = get_model(str(Path(__file__).parents[1] / "examples" / "machines"
                              / "two_throw_contact_motor.toml"))  # fmt: skip
    else:
        worn = {"crank_joint": "ideal", "crosshead_joint": "contact", "guide": "clearance"}
        model = _motor_machine(*(Throw(f"throw{k + 1}", **worn, params=(
            ("load_amplitude", LOAD), ("guide_clearance", 2e-4), ("phase", k * math.pi)))
            for k in range(2)), motor_breakdown_torque=5e3)  # fmt: skip
        revolutions = 0.25
    v = model.parameters({"shaft.J_drive": 30.0})
    ds = _simulate(model=model, params=v, revolutions=revolutions, fs=5000.0, rtol=RTOL)
    E, Wm = ds["energy"].values, ds["W_motor"].values
    Wg = sum(ds[f"throw{k}.W_gas"].values for k in (1, 2))
    Wl = sum(ds[f"throw{k}.W_loss"].values for k in (1, 2))
    assert np.abs(Wm).max() > 1e3 and Wl[-1] - Wl[0] > 0.0
    residual = np.abs((Wm - Wm[0]) - (E - E[0]) + (Wg - Wg[0]) - (Wl - Wl[0])).max()
    scale = max(np.abs(E).max(), np.abs(Wm).max(), np.abs(Wg).max())
    bound = float(ds.attrs["solver_nsteps"]) * RTOL * scale
    assert residual < bound, (residual, bound)
    summary = model.run_summary(v, ds)
    for q in ("throw1", "throw2"):
        assert summary[f"{q}.energy_balance_residual"] < 1e-8, q
    own = residual / max(np.abs(E).max(), np.abs(Wm).max())  # (the summary's, summed apart)
    assert summary["energy_balance_residual"] == pytest.approx(own, rel=1e-3, abs=1e-16)
    shaft = ds["motor_torque"].values - 30.0 * ds["alpha1"].values
    cranks = ds["throw1.crank_torque"].values + ds["throw2.crank_torque"].values
    assert np.abs(cranks - shaft).max() <= 1e-9 * np.abs(ds["motor_torque"].values).max()


def _orders(ds):
    """The 1x and 2x amplitudes of the crank speed over the record's last two revolutions of
    the crank (two, so that a half-order component is apart from them), after the straight
    line between its ends (the mean speed's drift: exact for a periodic signal) is taken out."""
    th1, w = ds["theta1"].values, ds["omega1"].values
    sel = th1 >= th1[-1] - 4 * math.pi
    x, y = th1[sel], w[sel]
    y = y - (y[0] + (y[-1] - y[0]) * (x - x[0]) / (x[-1] - x[0]))
    return [abs(np.trapezoid(y * np.exp(-1j * k * x), x)) / (2 * math.pi) for k in (1, 2)]


def test_two_identical_throws_at_180_deg_swing_the_speed_at_twice_the_crank_frequency():
    """Two identical throws 180 deg apart: the machine is symmetric under (swap the throws,
    turn the crank half a revolution), so on its symmetric periodic motion the crank's speed
    repeats every half revolution and has no component at the crank's frequency (1x); one
    throw's speed has a clear one. Lubricated pins at the paper's load (no impacts), 20 rad/s,
    30 kg m^2, 8 revolutions, the last two analysed: the 1x is below 1e-3 of one throw's.
    What remains (measured 1.2e-4 rad/s against one throw's 0.53 rad/s) is not the
    integration's error (rtol 1e-9: ~1e-7 rad/s) but the journals' own asymmetry: each throw
    starts at its own crank angle from its quasi-static eccentricity, and the difference
    decays slowly in the oil film (the revolutions' mean speeds alternate by 1e-3 rad/s, 4 %
    less every two revolutions); the bound stands 4 times above it, while a throw's torque
    composed wrongly would leave a 1x of one throw's size."""
    shaft = dict(omega=20.0, J_drive=30.0, motor_sync_speed=21.0, motor_breakdown_torque=2.4e4)

    def th(name, phase):
        return Throw(name, crank_joint="lubricated",
                     params=(("load_amplitude", 1e5), ("phase", phase)))  # fmt: skip

    kw = dict(revolutions=8.0, fs=400 * 20.0 / (2 * math.pi), rtol=1e-9)
    one = _simulate(model=_motor_machine(th("throw1", 0.0), **shaft), **kw)
    two = _simulate(model=_motor_machine(th("throw1", 0.0), th("throw2", math.pi), **shaft),
                    **kw)  # fmt: skip
    assert one.sizes.get("impact_event", 0) == two.sizes.get("impact_event", 0) == 0
    a1, a2 = _orders(one)
    b1, b2 = _orders(two)
    assert a1 > 0.5 * a2 > 0.0, (a1, a2)
    assert b2 > 0.5 * a2, (b2, a2)  # (the 2x: both throws' swings add)
    assert b1 < 1e-3 * a1, (b1, a1)
