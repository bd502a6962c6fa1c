"""Contact throws on a torsionally flexible shaft (issue 43, point 3 (f)): each throw's crank
is its node of the shaft's chain (`recipdyn.model.shaft.flexible`), its module turning its
crank on a torque of 0 and the template adding its node's section torques (template
``contact_throws``, branch ``TORSION``).

* the coupling's free oscillation with two contact throws at a tiny clearance rings at the
  link machine's frequency, within half an FFT bin;
* the whole machine's energy balance (the mechanisms', the rotor's and flywheel's, the
  sections' elastic energy against the motor's and the gas's work less the sections' and the
  joints' dissipation), with impacts, two contact throws and an ideal one beside a contact
  one; each throw's crank torque is its node's net section torque;
* a flexible shaft under a held rotor is refused in one line.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from recipdyn.errors import ParameterError
from test_flexible_shaft import _machine, _model, _simulate

KC, KS = 5.5e6, 2.5e6


def _ring(model, layout, fs: float = 2000.0, duration: float = 2.5):
    """`test_flexible_shaft._ring` on the state ``layout`` (a contact machine's own,
    ``model.contact(values).layout.state``): the rotor 0.01 rad ahead of its static twist,
    rtol 1e-10; the coupling twist's dominant frequency (its Hann-windowed FFT's largest bin,
    0 Hz left out) and half a bin."""
    from recipdyn.integrate import integrate

    v = model.parameters()
    st = layout.state
    y0 = model.initial_state(v)
    y0[st["theta1"]] += 0.01
    t = np.arange(int(duration * fs)) / fs
    sol = integrate(model.system(v), y0, (0.0, t[-1]), t_eval=t, rtol=1e-10, atol=1e-12)
    twist = sol.y[:, st["theta1"]] - sol.y[:, st["shaft.theta_flywheel"]]
    spectrum = np.abs(np.fft.rfft((twist - twist.mean()) * np.hanning(t.size)))
    freqs = np.fft.rfftfreq(t.size, 1.0 / fs)
    return freqs[1 + np.argmax(spectrum[1:])], 0.5 * fs / t.size


def test_the_coupling_rings_at_the_link_machines_frequency_with_contact_throws():
    """Two throws at 0 and 180 deg with a weak gas load (1 % of the paper's), no damping, the
    rotor kicked 0.01 rad (tests/test_flexible_shaft.py): with contact crank pins at 10 um the
    rod and crosshead ride on the crank through the pin in permanent contact, so the train is
    the link machine's but for the pin's compliance, far above this ~20 Hz mode (the throws
    hold 0.03 % of the train's inertia): the coupling twist's frequency is the link
    machine's within half a bin (0.2 Hz; measured: equal, 20.0 Hz). A node equation that
    left out the throws' share, or a section's phase, would move it by bins (a throw's node
    without its section's torque: the flywheel's and throws' inertia part, 6.4 Hz
    measured while the layout was wrong)."""
    ideal = _model(_machine(KC, KS, extra=(("load_amplitude", 2000.0),)))
    f_link, half_bin = _ring(ideal, ideal.configuration(ideal.parameters()).layout)
    worn = _model(_machine(KC, KS, extra=(("load_amplitude", 2000.0), ("rc", 1e-5)),
                           joint="contact"))  # fmt: skip
    f_contact, _ = _ring(worn, worn.contact(worn.parameters()).layout)
    assert 15.0 < f_link < 25.0  # (the coupling's mode)
    assert abs(f_contact - f_link) <= half_bin, (f_contact, f_link, half_bin)


def _mixed(machine):
    """``machine`` with throw 1's crank pin ideal (an ideal throw beside the contact one)."""
    t1 = dataclasses.replace(machine.throws[0], crank_joint="ideal",
                             params=tuple(p for p in machine.throws[0].params
                                          if p[0] != "rc"))  # fmt: skip
    return dataclasses.replace(machine, throws=(t1, *machine.throws[1:]))


@pytest.mark.parametrize("kinds", ["contact", "mixed"])
def test_the_whole_machines_energy_balances_on_a_flexible_shaft(kinds):
    """Induction motor, damped sections (coupling 1e3, crank 40 N m s/rad), crank pins at
    0.1 mm (impacts), half a revolution: ``E(t) - E(0) = W_motor + sum W_gas -
    W_shaft_damping - sum W_loss`` (the joints' losses) to 1e-7 of the motor's work, the
    integration's tolerance (rtol 1e-10 over ~1e3 steps; measured 9e-13 with two contact
    throws), with both dissipations > 0 for a contact throw. Each throw's crank torque (the
    shaft's work on its crank over its speed) is its node's net section torque (the springs
    and dampers of `_torsion_crank`, another path) to 1e-9 of the largest (rounding)."""
    from recipdyn.model.shaft.flexible import order

    machine = _machine(3e6, KS, c_coupling=1e3, c_shaft=40.0, motor="induction",
                       joint="contact", extra=(("rc", 1e-4),))  # fmt: skip
    if kinds == "mixed":
        machine = _mixed(machine)
    model = _model(machine)
    ds = _simulate(model=model, params=model.parameters(), revolutions=0.5, fs=4000.0)
    pre = [f"{t.name}." for t in machine.throws]
    energy, motor = ds["energy"].values, ds["W_motor"].values
    damping = ds["shaft.W_shaft_damping"].values
    gas = sum(ds[q + "W_gas"].values for q in pre)
    loss = sum(ds[q + "W_loss"].values for q in pre if q + "W_loss" in ds)
    balance = (energy - energy[0]) - (motor + gas - damping - loss)
    assert damping[-1] > 0.0 and ds["throw2.W_loss"].values[-1] > 0.0
    assert np.abs(balance).max() < 1e-7 * np.abs(motor).max(), np.abs(balance).max()
    names = [f"{machine.throws[k].name}.shaft_torque" for k in order(machine)]
    for j, k in enumerate(order(machine)):
        into = ds[names[j]].values
        out = ds[names[j + 1]].values if j + 1 < len(names) else 0.0
        torque = ds[f"{machine.throws[k].name}.crank_torque"].values
        assert np.abs(torque - (into - out)).max() < 1e-9 * np.abs(torque).max()


def test_a_flexible_shaft_under_a_held_rotor_with_contact_throws_is_refused_in_one_line():
    machine = _machine(KC, KS, motor="held", joint="contact")
    with pytest.raises(ParameterError, match=r"\[shaft.torsion\] under a held rotor") as e:
        _model(machine)
    assert "\n" not in str(e.value)
