"""Throws of different kinds on one crankshaft: ideal (link family) throws beside contact ones
(issue 43; template ``contact_throws``, each ideal throw its one-throw module of the massless
link with rc = 0, called on its slice: docs/architecture.md, "A throw of another kind").

* the crank prescribed: the throws do not interact, so the ideal throw is the one-throw
  ideal compressor (`--model compressor`, rc = 0) from its own crank angle, to the bit (its
  motion is its crank's, and the module and the arithmetic are that model's), and the contact
  throw is the one-throw contact model to the integration's error (module docstring of
  tests/test_contact_throws.py: the bound is 10 times the one-throw run's error estimate);
* on a motor they share the crank: the machine's energy balance closes, the ideal throw's own
  balance (its energy against the shaft's and the gas's work on it) closes, and the shaft's
  equation holds at every sample;
* a worn crank pin shows in its own throw's channels: its crosshead's acceleration carries
  the impacts' kHz band, the ideal throw's only what the crank's acceleration brings it.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.signal import butter, sosfiltfilt

from recipdyn.errors import ParameterError
from recipdyn.model.machine import Throw
from recipdyn.model.registry import get_model
from test_contact_throws import (
    LOAD,
    OMEGA,
    RTOL,
    RTOL_REF,
    _bound,
    _machine,
    _motor_machine,
    _one,
    _simulate,
    _throw,
)


def _ideal(name, phase=0.0, **kw):
    return Throw(name, crank_joint="ideal", params=(("load_amplitude", LOAD), ("phase", phase)),
                 **kw)  # fmt: skip


def test_an_ideal_throw_beside_a_contact_throw_is_each_its_one_throw_run():
    """Crank prescribed, a contact throw at 0 deg and an ideal one at 180 deg, a quarter
    revolution (impacts at the contact pin): the ideal throw's every signal is the one-throw
    ideal compressor's from theta1_0 = pi, to the bit; the contact throw's pin and crosshead
    are the one-throw contact model's within 10 times its error estimate."""
    m = _machine(_throw("throw1"), _ideal("throw2", math.pi))
    assert type(m).__name__ == "ContactMachine"
    kw = dict(revolutions=0.25, fs=20000.0)
    a = _simulate(model=m, rtol=RTOL, **kw)
    assert a.sizes["impact_event"] >= 2
    link = get_model("compressor")
    lv = link.parameters({"omega": OMEGA, "load_amplitude": LOAD, "theta1_0": math.pi, "rc": 0.0})
    b = _simulate(model=link, params=lv, rtol=RTOL, **kw)
    for k in b.data_vars:
        if k in ("W_gas",) or str(k).startswith("impact"):
            continue
        np.testing.assert_array_equal(a[f"throw2.{k}"].values, b[k].values, err_msg=str(k))
    _, _, run, ref = _one(0.0, **kw)
    for k in ("ex", "ey", "x"):
        err = np.abs(a[f"throw1.{k}"].values - ref[k].values).max()
        assert err <= _bound(run, ref, k), (k, err, _bound(run, ref, k))
    summary = m.run_summary(m.parameters(), a)
    assert summary["throw1.impacts"] >= 1
    own = {k[len("throw2.") :]: val for k, val in summary.items() if k.startswith("throw2.")}
    assert own == link.run_summary(lv, b)


def test_a_mixed_machine_on_a_motor_balances_its_energy():
    """Invariant (as tests/test_contact_throws.py's): ``W_motor = dE + sum_k (-W_gas,k) +
    W_loss`` over half a revolution on a light drive (30 kg m^2: the speed swings ~3 %), the
    residual under ``n_steps rtol max(|E|, |W|)``; the ideal throw's own energy against the
    shaft's work on its crank and the gas's (``W_crank``, ``W_gas``: its share of the crank
    turned into work at the shaft's acceleration) under the same bound; the shaft's equation
    ``sum_k crank_torque_k = T_m - J_drive alpha1`` to 1e-9 of the motor's torque (rounding of
    a sum of a few terms of that size: ~1e-15)."""
    m = _motor_machine(_ideal("throw1", math.pi), _throw("throw2"))
    v = m.parameters({"shaft.J_drive": 30.0})
    ds = _simulate(model=m, params=v, revolutions=0.5, fs=5000.0, rtol=RTOL)
    assert ds.sizes["impact_event"] >= 2
    w = ds["omega1"].values
    assert w.max() - w.min() > 0.01 * OMEGA  # (the throws do swing the crank)
    E, Wm = ds["energy"].values, ds["W_motor"].values
    Wg = ds["throw1.W_gas"].values + ds["throw2.W_gas"].values
    Wl = ds["throw2.W_loss"].values
    scale = max(np.abs(E).max(), np.abs(Wm).max(), np.abs(Wg).max())
    bound = float(ds.attrs["solver_nsteps"]) * RTOL * scale
    residual = np.abs((Wm - Wm[0]) - (E - E[0]) + (Wg - Wg[0]) - (Wl - Wl[0])).max()
    assert residual < bound, (residual, bound)
    E1, Wc1 = ds["throw1.energy"].values, ds["throw1.W_crank"].values
    Wg1 = ds["throw1.W_gas"].values
    own = np.abs((E1 - E1[0]) - (Wc1 - Wc1[0]) - (Wg1 - Wg1[0])).max()
    assert own < bound and np.abs(Wc1).max() > 1e2, (own, bound)
    shaft = ds["motor_torque"].values - 30.0 * ds["alpha1"].values
    cranks = ds["throw1.crank_torque"].values + ds["throw2.crank_torque"].values
    assert np.abs(cranks - shaft).max() <= 1e-9 * np.abs(ds["motor_torque"].values).max()
    summary = m.run_summary(v, ds)
    assert summary["energy_balance_residual"] < bound / scale


def _band(x, fs):
    """Mean square of ``x`` in the 1-5 kHz band (the impacts' ringing; the crank's harmonics
    at 24 Hz x n lie far below it), zero-phase 4th-order Butterworth."""
    sos = butter(4, [1000.0, 5000.0], btype="band", fs=fs, output="sos")
    return float(np.mean(sosfiltfilt(sos, x) ** 2))


def test_a_worn_crank_pin_shows_in_its_own_throws_channels():
    """Throw 2's worn crank pin beside an ideal throw 1, one revolution on a light drive (30 kg
    m^2): throw 2's crosshead acceleration carries the impacts' 1-5 kHz band, more than 1000
    times throw 1's (measured 1.3e4); throw 1's band holds no more than the crank's
    acceleration brings it: an ideal throw's crosshead accelerates at ``-r w^2 f(theta) -
    r alpha1 g(theta)``, ``|g| <= 1 + lambda``, the first term as smooth as the speed (its
    band ~1e-6 of the second's: w is alpha1's integral, /(2 pi 1 kHz / 150 rad/s)^2), so its
    band is at most ``(r (1 + lambda))^2`` times alpha1's (measured 0.27 of it), beside the
    healthy machine's (both throws ideal: 3e-4 (m/s^2)^2, a million times below)."""
    fs = 20000.0
    m = _motor_machine(_ideal("throw1", math.pi), _throw("throw2"))
    v = m.parameters({"shaft.J_drive": 30.0})
    ds = _simulate(model=m, params=v, revolutions=1.0, fs=fs, rtol=1e-9)
    healthy = _motor_machine(_ideal("throw1", math.pi), _ideal("throw2"))
    hv = healthy.parameters({"shaft.J_drive": 30.0})
    dh = _simulate(model=healthy, params=hv, revolutions=1.0, fs=fs, rtol=1e-9)
    e1, e2 = _band(ds["throw1.a"].values, fs), _band(ds["throw2.a"].values, fs)
    assert e2 > 1e3 * e1, (e1, e2)
    r, lam = v["throw1.r"], v["throw1.r"] / v["throw1.l"]
    carried = (r * (1.0 + lam)) ** 2 * _band(ds["alpha1"].values, fs)
    assert e1 <= carried + _band(dh["throw1.a"].values, fs), (e1, carried)
    assert e2 > 1e6 * _band(dh["throw2.a"].values, fs)


@pytest.mark.parametrize("kinds", ["ideal+contact", "contact+contact"])
def test_a_held_rotor_turns_contact_throws_as_the_prescribed_speed_does(kinds):
    """A held rotor on a rigid shaft (``motor = held``): the crank's acceleration is 0 by
    construction, so its speed stays ``omega`` exactly (to the bit) and every throw moves as
    on the prescribed crank: the pins, the crossheads within 10 times the prescribed
    machine's own error estimate (at ``rtol`` 1e-10 against 1e-12), a quarter revolution
    with impacts; the motor's torque is the throws' (``sum_k crank_torque_k = T_m``, the
    shaft's equation at alpha 0) to 1e-9 of its peak (rounding ~1e-16)."""
    second = (_throw("throw2") if kinds == "ideal+contact"
              else _throw("throw2", math.pi, rc=0.5e-3))  # fmt: skip
    first = _ideal("throw1", math.pi) if kinds == "ideal+contact" else _throw("throw1")
    m = _motor_machine(first, second, motor="held")
    kw = dict(revolutions=0.25, fs=20000.0)
    ds = _simulate(model=m, params=m.parameters(), rtol=RTOL, **kw)
    assert ds.sizes["impact_event"] >= 2
    assert np.all(ds["omega1"].values == OMEGA) and np.all(ds["alpha1"].values == 0.0)
    p = _machine(first, second)
    run, ref = _simulate(model=p, rtol=RTOL, **kw), _simulate(model=p, rtol=RTOL_REF, atol=1e-14,
                                                               **kw)  # fmt: skip
    names = ["throw1.x", "throw2.x", "throw2.ex", "throw2.ey"]
    if kinds == "contact+contact":
        names += ["throw1.ex", "throw1.ey"]
    for k in names:
        err = np.abs(ds[k].values - ref[k].values).max()
        assert err <= _bound(run, ref, k), (k, err, _bound(run, ref, k))
    tm = ds["motor_torque"].values
    cranks = ds["throw1.crank_torque"].values + ds["throw2.crank_torque"].values
    assert np.abs(cranks - tm).max() <= 1e-9 * np.abs(tm).max()


def test_one_contact_throw_on_a_held_rotor_is_the_prescribed_throw():
    """A machine of one contact throw on a held rotor (flat names, as ``--model
    compressor-contact``'s): the speed constant to the bit, the pin and the crosshead the
    prescribed throw's within 10 times its error estimate, a quarter revolution; the motor's
    torque is the throw's crank torque (the shaft's equation at alpha 0, one term)."""
    m = _motor_machine(_throw("throw1"), motor="held")
    kw = dict(revolutions=0.25, fs=20000.0)
    ds = _simulate(model=m, params=m.parameters(), rtol=RTOL, **kw)
    assert np.all(ds["omega1"].values == OMEGA) and ds.sizes["impact_event"] >= 2
    _, _, run, ref = _one(0.0, **kw)
    for k in ("ex", "ey", "x"):
        err = np.abs(ds[k].values - ref[k].values).max()
        assert err <= _bound(run, ref, k), (k, err, _bound(run, ref, k))
    np.testing.assert_array_equal(ds["motor_torque"].values, ds["crank_torque"].values)


def _placed(name, joint, phase, cylinder, g=None):
    params = (("load_amplitude", LOAD), ("phase", phase), *((("g", g),) if g is not None else ()))
    return Throw(name, crank_joint=joint, cylinder_angle=cylinder, params=params)


def test_a_throw_on_the_other_side_of_the_shaft_runs_in_its_own_axes():
    """``cylinder_angle = 180 deg`` with contact and ideal throws: a throw's equations run in
    its own axes (its crank angle there the shaft's plus phase minus 180 deg), its weight along
    its own +y (``g`` negated, as the link family's: tests/test_shaking.py checks the mirror).
    Without weight a contact throw at phase 180 deg turned 180 deg is the unturned one at
    phase 0, to the bit (the same values in its own axes); with weight its packed ``g`` is
    negated; an ideal throw turned beside a contact throw is the link family's turned throw
    (both throws ideal, `MachineModel`) to the bit, its joint forces (where the weight acts)
    included. A quarter revolution, crank prescribed."""
    from recipdyn.model.assembler.model import MachineModel

    kw = dict(revolutions=0.25, fs=20000.0, rtol=RTOL)
    first = _placed("throw1", "contact", 0.0, 0.0, g=0.0)
    a = _simulate(model=_machine(first, _placed("throw2", "contact", math.pi, math.pi, g=0.0)),
                  **kw)  # fmt: skip
    b = _simulate(model=_machine(first, _placed("throw2", "contact", 0.0, 0.0, g=0.0)), **kw)
    for k in ("ex", "ey", "x", "joint_force_x", "joint_force_y"):
        np.testing.assert_array_equal(a[f"throw2.{k}"].values, b[f"throw2.{k}"].values, k)
    m = _machine(_placed("throw1", "contact", 0.0, 0.0),
                 _placed("throw2", "contact", math.pi, math.pi))  # fmt: skip
    assert [v["g"] for v in m.contact(m.parameters()).locals] == [9.81, -9.81]
    turned = _placed("throw2", "ideal", math.pi, math.pi)
    m = _machine(_placed("throw1", "contact", 0.0, 0.0), turned)
    link = MachineModel(replace(m.machine, name="link",
                                throws=(_placed("throw1", "ideal", 0.0, 0.0), turned)))  # fmt: skip
    assert type(link).__name__ == "MachineModel"
    c, d = _simulate(model=m, **kw), _simulate(model=link, **kw)
    assert np.abs(d["throw2.joint_force_y"].values).max() > 1e3
    for k in ("theta1", "x", "a", "joint_force_x", "joint_force_y", "crank_torque"):
        np.testing.assert_array_equal(c[f"throw2.{k}"].values, d[f"throw2.{k}"].values, k)


def test_the_massless_link_beside_a_contact_throw_is_refused_in_one_line():
    """An ideal pin joins contact throws; the massless link (rc > 0, its validity bound of a
    link that can only push) does not yet."""
    with pytest.raises(ParameterError) as exc:
        _machine(_throw("throw1"), Throw("throw2", params=(("load_amplitude", LOAD),)))
    msg = str(exc.value)
    assert "throw2.crank_joint = 'link'" in msg and "'ideal'" in msg and "\n" not in msg
