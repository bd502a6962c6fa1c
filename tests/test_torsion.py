"""The crankshaft train's torsional natural frequencies (issue 43, point 4): against the closed
form of two inertias, against openTorsion's independent lumped model, the throws' equivalent
inertia against its series in lam = r/l, API 618's separation check, and the train built from
a machine description."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from recipdyn.errors import ParameterError
from recipdyn.model.shaft import TorsionalTrain, throw_inertia, train_of

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "machines"


def test_two_inertias_against_the_closed_form():
    """``f = sqrt(k (J1 + J2) / (J1 J2)) / 2 pi``, to rounding (an eigensolver's 1e-12)."""
    j1, j2, k = 3000.0, 45.0, 2.5e7
    f = TorsionalTrain(("flywheel", "throw1"), (j1, j2), (k,)).natural_frequencies()
    assert f.shape == (1,)
    assert f[0] == pytest.approx(math.sqrt(k * (j1 + j2) / (j1 * j2)) / (2 * math.pi), rel=1e-12)


def test_a_six_node_train_against_opentorsion():
    """Motor, flywheel and four throws of unequal inertias and shaft stiffnesses: the five
    natural frequencies equal openTorsion's (``Assembly.undamped_modal_analysis``, its own
    assembly of K and M and its own eigensolver), to 1e-9 relative (both solve the same
    6x6 generalised eigenproblem in double precision; the spread of the inertias, 2e3,
    costs a few digits at most)."""
    ot = pytest.importorskip("opentorsion")
    inertias = (120.0, 2880.0, 31.0, 29.5, 18.0, 17.2)
    springs = (4.1e6, 3.3e7, 5.2e7, 4.8e7, 5.0e7)
    ours = TorsionalTrain(tuple(f"n{i}" for i in range(6)), inertias, springs)
    shafts = [ot.Shaft(i, i + 1, k=k, I=0.0) for i, k in enumerate(springs)]
    disks = [ot.Disk(i, I=j) for i, j in enumerate(inertias)]
    lam, _ = ot.Assembly(shafts, disk_elements=disks).undamped_modal_analysis()
    theirs = np.sort(np.sqrt(np.abs(lam.real)))[1:] / (2 * math.pi)  # the rigid mode first
    assert np.allclose(ours.natural_frequencies(), theirs, rtol=1e-9, atol=0.0)
    # the mode shapes: mass-normalised, and the first mode's nodes turn the motor against the
    # flywheel (the softest spring: the coupling)
    f, phi = ours.modes()
    m, k = ours.matrices()
    assert np.allclose(phi.T @ m @ phi, np.eye(5), atol=1e-12)
    assert np.allclose(phi.T @ k @ phi, np.diag((2 * math.pi * f) ** 2), rtol=1e-9, atol=1e-6)
    assert phi[0, 0] * phi[1, 0] < 0.0


def test_a_throws_equivalent_inertia_against_its_series():
    """With the rod dynamically equivalent to two masses (``J2 = m2 ls (l - ls)``) and no
    offset, the mean kinetic energy at unit crank speed is ``J1 + m1 rs^2 + m_rot r^2 +
    m_rec r^2 <(x3'/r)^2>`` with ``m_rot = m2 (1 - ls/l)``, ``m_rec = m3 + m2 ls/l`` and
    ``<(x3'/r)^2> = 1/2 + lam^2/8 + lam^4/16 + c lam^6``, c = 0.039-0.042 for lam <= 0.3
    (measured by quadrature; the series of ``x3' = -r (sin th + lam sin 2th / (2 D))``). At
    lam = 0.25 the remainder is bounded by 0.05 lam^6 m_rec r^2 (1.2e-5 of it), while the
    lam^4 term (2.4e-4) and the rod's share are each far larger: a wrong weight of any of
    them fails."""
    r, l, ls, m1, m2, m3, rs, j1 = 0.1, 0.4, 0.15, 20.0, 15.0, 40.0, 0.03, 0.4
    lam = r / l
    local = dict(r=r, l=l, ls=ls, rs=rs, m1=m1, m2=m2, m3=m3, J1=j1, J2=m2 * ls * (l - ls), d=0.0)
    m_rec = m3 + m2 * ls / l
    series = j1 + m1 * rs**2 + m2 * (1 - ls / l) * r**2
    series += m_rec * r**2 * (0.5 + lam**2 / 8 + lam**4 / 16)
    assert abs(throw_inertia(local) - series) <= 0.05 * lam**6 * m_rec * r**2
    # the crosshead's offset d moves the mean energy (the crank pin's height is r sin th + d)
    assert throw_inertia({**local, "d": 0.02}) != pytest.approx(throw_inertia(local), rel=1e-6)
    with pytest.raises(ParameterError, match=r"^l = "):
        throw_inertia({**local, "l": 0.09})


def test_api618_separation_from_the_orders_of_the_running_speed():
    """A natural frequency at 3.05 x the running speed lies 1.7 % from the 3rd order (inside
    API 618's 10 %); at 3.5 x it is 16.7 % and 12.5 % from the 3rd and 4th: clear."""
    j1, j2, speed = 3000.0, 45.0, 10.0

    def train(ratio):
        w = 2 * math.pi * ratio * speed
        k = w**2 * j1 * j2 / (j1 + j2)
        return TorsionalTrain(("flywheel", "throw1"), (j1, j2), (k,))

    hits = train(3.05).interference(speed)
    assert [(h["mode"], h["order"]) for h in hits] == [(1, 3)]
    assert hits[0]["separation"] == pytest.approx(0.05 / 3, rel=1e-9)
    assert train(3.5).interference(speed) == []
    with pytest.raises(ParameterError, match="speed_hz"):
        train(3.5).interference(0.0)


def test_the_train_of_a_machine_description():
    """The two-stage, four-throw example: motor, flywheel and its throws in the order of their
    axial positions; each throw's inertia its equivalent inertia; a wrong number of springs,
    a negative one, or a rotor heavier than the drive refused in one line naming it."""
    from recipdyn.model.machine import read_machine

    machine = read_machine(EXAMPLES / "two_stage_4_throw.toml")
    from recipdyn.model.assembler.model import MachineModel

    values = MachineModel(machine).parameters()
    springs = (5e6, 8e7, 9e7, 9e7, 9e7)
    train = train_of(machine, values, springs, J_motor=400.0)
    by_axis = sorted(machine.throws, key=lambda t: t.axial_position)
    assert train.names == ("motor", "flywheel", *(t.name for t in by_axis))
    assert train.inertias[:2] == (400.0, pytest.approx(float(values["shaft.J_drive"]) - 400.0))
    assert all(j > 0 for j in train.inertias[2:])
    f = train.natural_frequencies()
    assert f.shape == (5,) and np.all(np.diff(f) > 0)
    with pytest.raises(ParameterError, match=r"^stiffness: 4 values for 6 nodes"):
        train_of(machine, values, springs[:4], J_motor=400.0)
    with pytest.raises(ParameterError, match=r"^stiffness\[1\]"):
        train_of(machine, values, (5e6, -1.0, 9e7, 9e7, 9e7), J_motor=400.0)
    with pytest.raises(ParameterError, match=r"^J_motor"):
        train_of(machine, values, springs, J_motor=1e9)
