"""Shaking forces and moments of a machine, and its API 618 loads per throw (issue 43, 4-5).

The hypotheses, each against a closed form independent of the record's kinematics
(`recipdyn.model.kinematics`, a chain rule through the clearance link): with ideal crank pins,
no crosshead offset and a prescribed speed, a throw is the textbook slider-crank, whose
crosshead acceleration is, with ``lam = r/l`` and ``D = sqrt(1 - lam^2 sin^2 th)``,

    a3 = -r w^2 (cos th + lam cos 2th / D + lam^3 sin^2 2th / (4 D^3))

(differentiating ``x3 = r cos th + l D`` twice), and whose rod, centroid at ``ls`` from the
crank pin, moves its centroid as ``(1 - ls/l)`` of the crank pin plus ``ls/l`` of the
crosshead. So the throw's force on the frame is

    F_x = m_rot r w^2 cos th - m_rec a3,    F_y = m_rot r w^2 sin th,
    m_rot r = m1 rs + m2 (1 - ls/l) r,      m_rec = m3 + m2 ls/l,

and to second order ``-m_rec a3 = m_rec r w^2 (cos th + lam cos 2th) + O(lam^3)``: the
primary and secondary reciprocating forces (Den Hartog, *Mechanical Vibrations*, 4th ed.,
1956, sections 5.3-5.5; Taylor, *The Internal-Combustion Engine in Theory and Practice*,
vol. 2, ch. 8). Several identical throws with crank phases ``phi_k`` at axial positions
``z_k``: the n-th harmonic of the force is the one throw's times ``sum_k exp(i n phi_k)`` and
that of the moment times ``sum_k z_k exp(i n phi_k)`` (the same sums with the cylinders turned
by 180 deg flip the throw's force). The geometry is none of the examples' (r 90 mm, l 420 mm,
lam = 0.214; masses 11/17/43 kg).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from recipdyn.errors import ModelValidityWarning, ParameterError
from recipdyn.model.machine import Machine, Shaft, Stage, Throw

R, L, RS, LS, M1, M2, M3 = 0.09, 0.42, 0.03, 0.15, 11.0, 17.0, 43.0
LAM = R / L
OMEGA = 30.0  # rad/s
N = 720  # samples per revolution: 0.5 deg, dead centres sampled
F0 = 1000.0  # N, the constant gas force of the table load (along +x)
S = 0.8  # m, the axial spacing of the throws
M_ROT_R = M1 * RS + M2 * (1.0 - LS / L) * R
M_REC = M3 + M2 * LS / L


def _throw(name, phase, cylinder=0.0, z=0.0):
    geo = (("r", R), ("l", L), ("rs", RS), ("ls", LS), ("m1", M1), ("m2", M2), ("m3", M3),
           ("d", 0.0), ("load_table", ((0.0, F0), (180.0, F0))))  # fmt: skip
    return Throw(name, crank_joint="ideal", load="table", params=(("phase", phase), *geo),
                 cylinder_angle=cylinder, axial_position=z)  # fmt: skip


def _run(arrangement, g=None):
    """A machine of identical throws ``(phase, cylinder_angle, axial_position)`` at a
    prescribed speed, one revolution sampled at ``N`` points."""
    import recipdyn
    from recipdyn.model.assembler.model import MachineModel

    throws = tuple(_throw(f"throw{k + 1}", *a) for k, a in enumerate(arrangement))
    shaft = Shaft("prescribed", params=(("omega", OMEGA),))
    m = MachineModel(Machine("shaking-test", shaft=shaft, throws=throws, stages=(Stage(),)))
    params = m.parameters()
    if g is not None:
        params = m.parameters({**params, **{f"{t.name}.g": g for t in throws}})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelValidityWarning)
        return recipdyn.simulate(model=m, params=params, revolutions=1.0,
                                 fs=OMEGA * N / (2.0 * math.pi))  # fmt: skip


def _a3(th):
    d = np.sqrt(1.0 - (LAM * np.sin(th)) ** 2)
    return -R * OMEGA**2 * (np.cos(th) + LAM * np.cos(2 * th) / d
                            + LAM**3 * np.sin(2 * th) ** 2 / (4 * d**3))  # fmt: skip


def _force(th):
    """One throw's force on the frame in its own axes (the module docstring's closed form)."""
    return M_ROT_R * OMEGA**2 * np.cos(th) - M_REC * _a3(th), M_ROT_R * OMEGA**2 * np.sin(th)


def _harmonics(x):
    """Complex amplitudes of harmonics 0..8 of one revolution sampled at N points."""
    return np.fft.rfft(np.asarray(x, dtype=float)[:N])[:9] * (2.0 / N)


@pytest.fixture(scope="module")
def opposed():
    """A balanced-opposed pair: cranks 180 deg apart on the shaft, cylinders on opposite
    sides, planes S apart."""
    return _run(((0.0, 0.0, 0.0), (math.pi, math.pi, S)))


def test_one_throw_against_the_exact_slider_crank_and_its_primary_and_secondary_series(opposed):
    """Throw 1's force on the frame equals the exact closed form at the record's own crank
    angles to rounding: 1e-12 of the peak (the record's kinematics evaluate the same
    geometry by another chain of ~50 operations, each good to eps ~ 1e-16, on forces of ~7 kN).
    The primary + secondary series differs by the truncation: with ``D >= D0 =
    sqrt(1 - lam^2)``, ``|lam cos 2th (1/D - 1)| <= lam^3 / (D0 (1 + D0))`` and the last term
    ``<= lam^3 / (4 D0^3)``, so by at most ``m_rec r w^2 lam^3 (1/(D0 (1 + D0)) + 1/(4 D0^3))``
    (~0.78 lam^3 m_rec r w^2 = 30.7 N here; measured 20.3 N); and by more than a fifth of it
    (at 45 deg the last term alone is lam^3 / 4): the series is a second-order truncation,
    and the record is not."""
    th = opposed["throw1.theta1"].values
    fx, fy = _force(th)
    peak = np.max(np.hypot(fx, fy))
    assert np.max(np.abs(opposed["throw1.shake_x"].values - fx)) < 1e-12 * peak
    assert np.max(np.abs(opposed["throw1.shake_y"].values - fy)) < 1e-12 * peak
    x3 = R * np.cos(th) + L * np.sqrt(1.0 - (LAM * np.sin(th)) ** 2)
    assert np.max(np.abs(opposed["throw1.x"].values - x3)) < 1e-14 * (R + L)
    series = M_ROT_R * OMEGA**2 * np.cos(th) + M_REC * R * OMEGA**2 * (
        np.cos(th) + LAM * np.cos(2 * th)
    )
    d0 = math.sqrt(1.0 - LAM**2)
    bound = M_REC * R * OMEGA**2 * LAM**3 * (1.0 / (d0 * (1.0 + d0)) + 0.25 / d0**3)
    err = np.max(np.abs(opposed["throw1.shake_x"].values - series))
    assert bound / 5.0 < err <= bound, (err, bound)


def test_a_balanced_opposed_pair_cancels_its_force_and_leaves_a_couple(opposed):
    """Cranks 180 deg apart, cylinders opposed: each throw runs the same motion in its own
    axes, turned by 180 deg in the frame, so the primary, secondary (and every) harmonic of
    the force cancels: the sum is zero to rounding (1e-12 of one throw's peak). What is left
    is a couple: the second throw's force at its lever arm S, ``M_y = S F_x,2 = -S F_x,1`` and
    ``M_x = -S F_y,2 = S F_y,1``, to rounding. The frame's combined load (the run summary)
    is then 0 N of force and a moment S times one throw's largest force."""
    th = opposed["throw1.theta1"].values
    fx, fy = _force(th)
    peak = np.max(np.hypot(fx, fy))
    assert np.max(np.abs(opposed["shake_x"].values)) < 1e-12 * peak
    assert np.max(np.abs(opposed["shake_y"].values)) < 1e-12 * peak
    assert np.max(np.abs(opposed["shake_moment_y"].values + S * fx)) < 1e-12 * S * peak
    assert np.max(np.abs(opposed["shake_moment_x"].values - S * fy)) < 1e-12 * S * peak
    assert opposed.attrs["frame_peak_force_N"] < 1e-12 * peak
    assert opposed.attrs["frame_peak_moment_N_m"] == pytest.approx(S * peak, rel=1e-12)
    assert opposed["shake_x"].attrs["units"] == "N"
    assert opposed["shake_moment_y"].attrs["units"] == "N*m"
    assert opposed.attrs["throw2.cylinder_angle_deg"] == 180.0
    assert opposed.attrs["throw2.axial_position_m"] == S


def test_an_inline_pair_at_180_deg_cancels_the_primary_and_doubles_the_secondary():
    """Both cylinders on one side, cranks 180 deg apart: ``sum exp(i n phi) = 1 + (-1)^n``.
    The total force is ``F(th) + F(th + pi)`` exactly (1e-12 of the peak); its first harmonic
    vanishes (1e-12 of one throw's, rounding of an FFT of 720 samples) and its second is twice
    one throw's (to 1e-12 relative). That second harmonic is ``2 m_rec r w^2 A2`` with the
    exact slider-crank's Fourier coefficient ``A2 = lam + lam^3/4 + 15 lam^5/128 + ...``
    (Taylor vol. 2, ch. 8; Den Hartog 5.3): the truncated ``2 m_rec r w^2 lam`` is low by
    ``lam^2/4`` relative (1.15 %; measured 1.17 %), held to ``lam^4/4`` (the next term is
    ``15 lam^4/128``). The couple of the primary forces, ``S`` times one throw's primary,
    remains in ``M_y``."""
    ds = _run(((0.0, 0.0, 0.0), (math.pi, 0.0, S)))
    th = ds["throw1.theta1"].values
    fx, fy = _force(th)
    fx2, fy2 = _force(th + math.pi)
    peak = np.max(np.hypot(fx, fy))
    assert np.max(np.abs(ds["shake_x"].values - (fx + fx2))) < 1e-12 * peak
    assert np.max(np.abs(ds["shake_y"].values - (fy + fy2))) < 1e-12 * peak
    one, total = _harmonics(ds["throw1.shake_x"].values), _harmonics(ds["shake_x"].values)
    assert abs(total[1]) < 1e-12 * abs(one[1])
    assert abs(total[2] - 2.0 * one[2]) < 1e-12 * abs(one[2])
    secondary = 2.0 * M_REC * R * OMEGA**2 * LAM
    assert abs(abs(total[2]) / secondary - (1.0 + LAM**2 / 4.0)) < LAM**4 / 4.0
    moment = _harmonics(ds["shake_moment_y"].values)
    assert abs(moment[1] + S * one[1]) < 1e-12 * S * abs(one[1])  # z2 exp(i pi) = -S


@pytest.mark.parametrize(
    "phases, expect",
    [
        # 0/90/270/180 at 0, S, 2S, 3S: primary and secondary forces vanish; the primary
        # couple is |sum z_k e^{i phi_k}| = S |i + 2(-i) + 3(-1)| = sqrt(10) S; the secondary
        # couple |sum z_k e^{2i phi_k}| = S |-1 - 2 + 3| = 0.
        ((0, 90, 270, 180), {"F1": 0.0, "F2": 0.0, "M1": math.sqrt(10.0), "M2": 0.0}),
        # 0/180/180/0 (mirror-symmetric): the primary force and couple vanish, the secondary
        # force is four times one throw's, its couple |S (1 + 2 + 3)| = 6 S.
        ((0, 180, 180, 0), {"F1": 0.0, "F2": 4.0, "M1": 0.0, "M2": 6.0}),
    ],
)
def test_four_throws_against_the_closed_form_sums_of_primary_and_secondary_forces_and_moments(
    phases, expect
):
    """Four identical throws on one side at ``z_k = (k - 1) S``: the force's and moment's
    harmonics n = 1, 2 (and every n up to 8) are one throw's times ``sum_k exp(i n phi_k)``
    and ``sum_k z_k exp(i n phi_k)`` (to 1e-12 of one throw's peak: rounding of sums and an
    FFT of 720 samples), and those sums are the arrangement's textbook values (parameter
    list); the y force (rotating parts only) follows the same sums."""
    phi = np.radians(phases)
    z = S * np.arange(4)
    ds = _run(tuple((p, 0.0, zk) for p, zk in zip(phi, z, strict=True)))
    fx, fy = _force(ds["throw1.theta1"].values)
    peak = np.max(np.hypot(fx, fy))
    n = np.arange(9)
    sum_f = np.exp(1j * np.outer(n, phi)).sum(axis=1)
    sum_m = (z * np.exp(1j * np.outer(n, phi))).sum(axis=1)
    for out, own, weights in (("shake_x", "throw1.shake_x", sum_f),
                              ("shake_y", "throw1.shake_y", sum_f),
                              ("shake_moment_y", "throw1.shake_x", sum_m),
                              ("shake_moment_x", "throw1.shake_y", -sum_m)):  # fmt: skip
        one, total = _harmonics(ds[own].values), _harmonics(ds[out].values)
        scale = S if out.startswith("shake_moment") else 1.0
        assert np.max(np.abs(total - one * weights)) < 1e-12 * 4 * scale * peak, out
    one = _harmonics(ds["throw1.shake_x"].values)
    force, moment = _harmonics(ds["shake_x"].values), _harmonics(ds["shake_moment_y"].values)
    for h in (1, 2):
        assert abs(force[h]) == pytest.approx(expect[f"F{h}"] * abs(one[h]), abs=1e-9 * peak)
        assert abs(moment[h]) == pytest.approx(expect[f"M{h}"] * S * abs(one[h]),
                                               abs=1e-9 * S * peak)  # fmt: skip


def test_api618_rod_load_and_pin_reversal_per_throw_against_a_hand_computation(opposed):
    """A constant gas force F0 = 1000 N along +x (a table) on each throw: the rod load at the
    crosshead pin is ``m3 a3 - F0`` (> 0 compression). By hand: its tension peak at the outer
    dead centre, ``m3 r w^2 (1 + lam) + F0`` = 5229.6 N, its compression peak at the inner,
    ``m3 r w^2 (1 - lam) - F0`` = 1736.6 N (for lam < 1/4 |a3| peaks there), both sampled
    exactly (to 1e-9 relative); the reverse fraction their ratio; the compression lasts
    ``2 (pi - th*)`` with ``m3 a3(th*) = F0``, which the summary counts in samples of 0.5 deg
    (to one sample per crossing: 1 deg). Each throw has the same figures, API 618 (>= 15 deg,
    >= 3 %) passes."""
    from scipy.optimize import brentq

    th = opposed["throw1.theta1"].values
    assert np.max(np.abs(opposed["throw1.rod_load"].values - (M3 * _a3(th) - F0))) < 1e-9 * F0
    tension = M3 * R * OMEGA**2 * (1.0 + LAM) + F0
    compression = M3 * R * OMEGA**2 * (1.0 - LAM) - F0
    root = brentq(lambda t: M3 * _a3(t) - F0, 0.1, math.pi)
    degrees = math.degrees(2.0 * (math.pi - root))
    a = opposed.attrs
    for t in ("throw1", "throw2"):
        assert a[f"{t}.pin_peak_tension_N"] == pytest.approx(tension, rel=1e-9)
        assert a[f"{t}.pin_peak_compression_N"] == pytest.approx(compression, rel=1e-9)
        assert a[f"{t}.pin_reverse_fraction"] == pytest.approx(compression / tension, rel=1e-9)
        assert abs(a[f"{t}.pin_reversal_deg"] - degrees) <= 1.0 + 1e-9, (degrees, a)
        assert a[f"{t}.api618_pin_reversal"] == "pass"


def test_a_throws_placement_is_read_with_units_and_refused_out_of_range(tmp_path):
    """``cylinder_angle = "180 deg"`` and ``axial_position = "650 mm"`` are read in SI; a
    cylinder at 90 deg (its parts' weight along the stroke is not modelled) and an axial
    position of 1 km are refused in one line naming the key; a throw at 180 deg runs its
    equations at its crank phase less its cylinder angle."""
    from recipdyn.model.machine import read_machine

    f = tmp_path / "m.toml"
    f.write_text('[[throw]]\n[[throw]]\nphase = "180 deg"\ncylinder_angle = "180 deg"\n'
                 'axial_position = "650 mm"\n')  # fmt: skip
    m = read_machine(f)
    assert m.throws[1].cylinder_angle == math.pi and m.throws[1].axial_position == 0.65
    assert m.throws[0].cylinder_angle == 0.0 and m.throws[0].axial_position == 0.0
    from recipdyn.model.assembler.model import MachineModel

    model = MachineModel(m)
    assert model.throws(model.parameters())[1]["phase"] == 0.0
    for text, words in (('cylinder_angle = "90 deg"', "throw2.cylinder_angle = 90 deg"),
                        ('axial_position = "1 km"', "throw2.axial_position = 1000 m")):  # fmt: skip
        f.write_text(f"[[throw]]\n[[throw]]\n{text}\n")
        with pytest.raises(ParameterError) as exc:
            read_machine(f)
        assert words in str(exc.value) and "\n" not in str(exc.value), str(exc.value)


def test_on_a_motor_the_shaking_force_is_minus_the_second_derivative_of_the_mass_moment():
    """With a free crank the speed varies (a small flywheel, J_drive 2 kg m^2, and a constant
    motor torque of 0: the throws' inertia torques swing it, alpha1 up to ~60 rad/s^2), so
    the crank's and rod's accelerations hold ``alpha1`` terms. Independent of the kinematics'
    chain rule: the frame's force is ``-G"`` with ``G = sum m_i p_i`` the mass moment of every
    moving part, from the record's positions (crank angle, rod angle, crosshead position),
    differentiated twice by central differences at h = 0.1 ms: truncation ``h^2/12`` times
    G's fourth derivative ~ 1e-6 of the peak force (harmonics up to the 4th at 20 rad/s),
    rounding ``eps |G| / h^2`` ~ 1e-6 N; held to 1e-4 of the peak (measured 1.3e-6). The
    ``alpha1`` terms weigh more than 10x that (checked), so a force without them fails."""
    import recipdyn
    from recipdyn.model.assembler.model import MachineModel

    throws = (_throw("throw1", 0.0), _throw("throw2", math.pi / 2, math.pi, S))
    shaft = Shaft("motor", "constant",
                  params=(("omega", 20.0), ("J_drive", 2.0), ("motor_torque", 0.0)))  # fmt: skip
    m = MachineModel(Machine("shaking-motor", shaft=shaft, throws=throws, stages=(Stage(),)))
    h = 1e-4
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelValidityWarning)
        ds = recipdyn.simulate(model=m, params=m.parameters(), revolutions=0.5, fs=1.0 / h)
    g = np.zeros((2, ds.sizes["time"]))
    for t, sign in (("throw1", 1.0), ("throw2", -1.0)):  # (throw 2's axes turned by 180 deg)
        th, th2 = ds[f"{t}.theta1"].values, ds[f"{t}.theta2"].values
        x3 = ds[f"{t}.x"].values
        gx = M1 * RS * np.cos(th) + M2 * (R * np.cos(th) + LS * np.cos(th2)) + M3 * x3
        gy = M1 * RS * np.sin(th) + M2 * (R * np.sin(th) + LS * np.sin(th2))
        g += sign * np.array([gx, gy])
    fd = -(g[:, 2:] - 2.0 * g[:, 1:-1] + g[:, :-2]) / h**2
    got = np.array([ds["shake_x"].values, ds["shake_y"].values])[:, 1:-1]
    peak = np.max(np.abs(got))
    assert np.max(np.abs(got - fd)) < 1e-4 * peak
    alpha = ds["alpha1"].values[1:-1]
    assert np.max(np.abs(alpha)) * (M1 * RS + M2 * R) > 10 * 1e-4 * peak  # the alpha terms count


def test_the_balanced_opposed_example_places_its_throws():
    """``examples/machines/balanced_opposed.toml``: cranks 180 deg apart, cylinders opposed,
    650 mm apart; in their own axes the two throws run at the same crank angle, so the
    example's frame force cancels as the pair's above."""
    from pathlib import Path

    from recipdyn.model.assembler.model import MachineModel
    from recipdyn.model.machine import read_machine

    m = read_machine(Path(__file__).parents[1] / "examples" / "machines" / "balanced_opposed.toml")
    assert [(t.cylinder_angle, t.axial_position) for t in m.throws] == [(0.0, 0.0), (math.pi, 0.65)]
    model = MachineModel(m)
    v = model.parameters()
    assert v["throw2.phase"] == pytest.approx(math.pi)
    assert [local["phase"] for local in model.throws(v)] == [0.0, 0.0]


def test_the_weight_acts_down_in_the_frame_on_a_throw_at_180_deg():
    """A throw whose cylinder is turned by 180 deg runs its equations in its own axes, where
    the weight (down in the frame) points along +y. With ideal pins and a prescribed speed
    its forces are linear in g: the guide's normal force is ``N(th) = N0(th) + g G(th)``. A
    throw at cylinder 0 and one at 180 deg with the same angle in its own axes (crank phase
    180 deg) then have ``N_1 + N_2 = 2 N0``, the force of the same throws without weight,
    to rounding (1e-9 of the peak); with the weight along its own -y on both (the sign this
    replaces) ``N_2 = N_1`` and the sum misses ``2 N0`` by twice the weight's share, about
    (m2 (1 - ls/l) ... + m3) g ~ 500 N here."""
    with_g = _run(((0.0, 0.0, 0.0), (math.pi, math.pi, S)))
    n1, n2 = (with_g[f"throw{k}.guide_force"].values for k in (1, 2))
    weightless = _run(((0.0, 0.0, 0.0), (math.pi, math.pi, S)), g=0.0)
    n0 = weightless["throw1.guide_force"].values
    assert np.max(np.abs(weightless["throw2.guide_force"].values - n0)) <= 1e-9 * np.max(np.abs(n0))
    assert np.max(np.abs(n1 + n2 - 2.0 * n0)) <= 1e-9 * np.max(np.abs(n0))
    assert np.max(np.abs(n1 - n0)) > 0.5 * M3 * 9.81  # the weight is felt (not a no-op)
