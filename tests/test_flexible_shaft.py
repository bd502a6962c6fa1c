"""The torsionally flexible shaft in the time integration (issue 43, point 3;
`recipdyn.model.shaft.flexible`).

* a small free oscillation of the train turns at the linear train's lowest natural frequency
  (`recipdyn.model.shaft.train_of`, itself checked against openTorsion in test_torsion.py);
* stiff limit: as every stiffness grows by 4, the crank angles' departure from the rigid
  machine's shrinks by 4 (1/k, the derivation below);
* energy: the mechanisms', the drive's nodes' and the springs' energy change by the motor's
  and the gas's work less the sections' dissipation; each throw's crank torque is the net
  torque of the sections at its node;
* resonance: the first mode tuned to the 2nd order of the running speed against detuned by
  20 %: the ratio of the twists the one-degree-of-freedom coupling mode predicts from its
  damping;
* each throw's crank angle is its node's plus its phase, the nodes in axial order;
* refusals in one line (a prescribed drive, a rotor heavier than the drive, a section's
  parameter without ``[shaft.torsion]``).

Machines without a flexible shaft keep main's results to the bit (measured for the commit on
the machines of test_models.py with a motor and ``compressor --set drive=motor``; the template's
branches on ``TORSION`` are pruned, `tests/test_assembler.py` checks the template's binding).
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from recipdyn.errors import ModelValidityWarning, ParameterError
from recipdyn.model.machine import Machine, Shaft, Stage, Throw, read_machine

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "machines" / "two_throw_torsion.toml"
OMEGA = 20.0
J_MOTOR, J_DRIVE = 400.0, 3000.0


def _machine(k_coupling, k_shaft, c_coupling=0.0, c_shaft=0.0, torsion=True, extra=(),
             positions=(0.0, 0.3), motor="constant", joint="ideal"):  # fmt: skip
    """Two throws of the paper's compressor at 0 and 180 deg with ideal crank pins (no
    clearance dynamics: the shaft's alone), a constant motor torque (the mean load torque:
    no damping from a torque-speed slope), the drive 3000 kg m² of which 400 the rotor."""
    throws = tuple(
        Throw(f"throw{i + 1}", crank_joint=joint, axial_position=z,
              params=(("phase", ph), *((("k_shaft", k_shaft), ("c_shaft", c_shaft))
                                       if torsion else ()), *extra))
        for i, (ph, z) in enumerate(zip((0.0, math.pi), positions, strict=True))
    )  # fmt: skip
    params = (("omega", OMEGA), ("J_drive", J_DRIVE))
    if torsion:
        params += (("J_motor", J_MOTOR), ("k_coupling", k_coupling), ("c_coupling", c_coupling))
    return Machine("torsion-test", shaft=Shaft("motor", motor, params, torsion=torsion),
                   throws=throws, stages=(Stage(),))  # fmt: skip


def _model(machine):
    from recipdyn.model.assembler.model import MachineModel

    return MachineModel(machine)


def _simulate(**kw):
    import recipdyn

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelValidityWarning)
        return recipdyn.simulate(summary=False, **kw)


def _inertia_range(local) -> tuple[float, float]:
    """The smallest and largest of a throw's inertia about the shaft over a revolution (ideal
    pin): twice its kinetic energy at unit crank speed, ``J1 + m1 rs² + m2 |v_G|² + J2
    theta2'² + m3 x3'²``, the velocities by differences of the closed-form slider-crank on a
    fine grid (the test's own kinematics)."""
    r, l, ls, d, rs = (float(local[k]) for k in ("r", "l", "ls", "d", "rs"))
    m1, m2, m3, j1, j2 = (float(local[k]) for k in ("m1", "m2", "m3", "J1", "J2"))
    th = np.linspace(0.0, 2.0 * math.pi, 20001)
    s = r * np.sin(th) + d
    x3 = r * np.cos(th) + np.sqrt(l * l - s * s)
    gx = r * np.cos(th) + ls / l * (x3 - r * np.cos(th))
    gy = r * np.sin(th) + ls / l * (-d - r * np.sin(th))
    th2 = np.arcsin(-s / l)
    dv = [np.gradient(q, th) for q in (x3, gx, gy, th2)]
    inertia = j1 + m1 * rs**2 + m2 * (dv[1] ** 2 + dv[2] ** 2) + j2 * dv[3] ** 2 + m3 * dv[0] ** 2
    return float(inertia.min()), float(inertia.max())


def _ring(model, kicked: str, fs: float = 2000.0, duration: float = 2.5):
    """``model`` at its defaults with the state ``kicked`` 0.01 rad ahead, integrated for
    ``duration`` s at rtol 1e-10 and sampled at ``fs``: ``(solution, state layout, the
    coupling twist's dominant frequency, half a bin)`` (the largest bin of its Hann-windowed
    FFT, 0 Hz left out)."""
    from recipdyn.integrate import integrate

    v = model.parameters()
    st = model.configuration(v).layout.state
    y0 = model.initial_state(v)
    y0[st[kicked]] += 0.01
    t = np.arange(int(duration * fs)) / fs
    sol = integrate(model.system(v), y0, (0.0, t[-1]), t_eval=t, rtol=1e-10, atol=1e-12)
    twist = sol.y[:, st["theta1"]] - sol.y[:, st["shaft.theta_flywheel"]]
    spectrum = np.abs(np.fft.rfft((twist - twist.mean()) * np.hanning(t.size)))
    freqs = np.fft.rfftfreq(t.size, 1.0 / fs)
    return sol, st, freqs[1 + np.argmax(spectrum[1:])], 0.5 * fs / t.size


def test_a_free_oscillation_turns_at_the_linear_trains_lowest_natural_frequency():
    """The rotor started 0.01 rad ahead of its static twist, no damping, a weak gas load (1 %
    of the paper's): the coupling's twist oscillates at the train's lowest natural frequency
    (`train_of`, each throw its mean inertia; ~20 Hz here). Tolerance, two parts: the spectral
    resolution, half a bin of the Hann-windowed record's FFT (a single tone's largest sample
    is the nearest bin; 2.5 s: 0.2 Hz, 1 %), and the throws' inertia varying over the
    revolution: more inertia lowers every eigenvalue (Courant-Fischer), so the train with each
    throw at its smallest and at its largest inertia brackets the frequency (a width of ~1e-4
    of it here: the throws hold 0.03 % of the train's inertia)."""
    from recipdyn.model.shaft import TorsionalTrain, train_of

    kc, ks = 5.5e6, 2.5e6
    model = _model(_machine(kc, ks, extra=(("load_amplitude", 2000.0),)))
    v = model.parameters()
    _, _, f_sim, half_bin = _ring(model, "theta1")

    f_lin = train_of(model.machine, v, (kc, ks, ks), J_motor=J_MOTOR).natural_frequencies()[0]
    lo, hi = _inertia_range(model.throws(v)[0])  # (the two throws are alike)

    def f_at(j):
        names = ("motor", "flywheel", "throw1", "throw2")
        return TorsionalTrain(names, (J_MOTOR, J_DRIVE - J_MOTOR, j, j),
                              (kc, ks, ks)).natural_frequencies()[0]  # fmt: skip

    band = (f_at(hi), f_at(lo))
    assert band[0] <= f_lin <= band[1]
    assert band[0] - half_bin <= f_sim <= band[1] + half_bin, (f_sim, f_lin, band, half_bin)
    assert abs(f_sim - f_lin) < 0.02 * f_lin  # (and it is the ~20 Hz mode, not another)


def test_the_stiff_limit_is_the_rigid_crank():
    """Every stiffness times 1, 4, 16 (no damping; ideal pins, half a revolution): the throws'
    crank angles and the rotor's speed depart from the rigid machine's (the same values, one
    crank) by ``C / k``. Derivation: the sections' twists are the quasi-static ``T(t) / k``
    plus a free oscillation; the run starts at the quasi-static twists of its first instant
    (`recipdyn.model.shaft.flexible.twisted_start`), so what starts the oscillation is the
    twists' rates, ``T' / k``: an oscillation of angle ``T' / (k w_n)`` and of speed ``T' /
    k``; the corrections are ``O(1 / k^2)``. So each 4x stiffer shaft divides the largest
    departure of the angles by 4 within 10 % (measured 4.04 and 4.01) and of the speed within
    20 % (measured 4.29 and 4.28: a larger ``1 / k^2`` part, the oscillation's frequency
    ``w_n ~ k^(1/2)`` beside the load's orders)."""
    kw = dict(revolutions=0.5, fs=4000.0)
    rigid_model = _model(_machine(0.0, 0.0, torsion=False))
    rigid = _simulate(model=rigid_model, params=rigid_model.parameters(), **kw)
    angles, speeds = [], []
    for s in (1.0, 4.0, 16.0):
        model = _model(_machine(3e6 * s, 2.5e6 * s))
        ds = _simulate(model=model, params=model.parameters(), **kw)
        angles.append(max(float(np.max(np.abs(ds[f"throw{k}.theta1"].values
                                              - rigid[f"throw{k}.theta1"].values)))
                          for k in (1, 2)))  # fmt: skip
        speeds.append(float(np.max(np.abs(ds["omega1"].values - rigid["omega1"].values))))
    ratios = [angles[i] / angles[i + 1] for i in range(2)]
    assert all(3.6 < r < 4.4 for r in ratios), (angles, ratios)
    ratios = [speeds[i] / speeds[i + 1] for i in range(2)]
    assert all(3.2 < r < 4.8 for r in ratios), (speeds, ratios)


def test_the_energy_balance_and_each_nodes_torques():
    """The example machine (massless links, induction motor, damped sections), half a
    revolution: ``E(t) - E(0) = W_motor + sum W_gas - W_shaft_damping`` to 1e-7 of the motor's
    work (the integration's tolerance; measured 1e-12), with the damping's work > 0. At every
    sample each throw's crank torque (the theta1 row of its own equations at its node's
    acceleration) equals the net torque of the sections at its node (the springs and dampers,
    a separate path), to 1e-9 of the largest (rounding of ~1e4 N m terms)."""
    from recipdyn.model.shaft.flexible import order

    model = _model(read_machine(EXAMPLE))
    v = model.parameters()
    ds = _simulate(model=model, params=v, revolutions=0.5, fs=4000.0)
    total = ds["energy"].values - ds["energy"].values[0]
    damping = ds["shaft.W_shaft_damping"].values
    work = ds["W_motor"].values + ds["throw1.W_gas"].values + ds["throw2.W_gas"].values
    assert damping[-1] > 0.0
    assert np.max(np.abs(total - (work - damping))) < 1e-7 * np.max(np.abs(ds["W_motor"].values))
    m = model.machine
    names = [f"{m.throws[k].name}.shaft_torque" for k in order(m)]
    for j, k in enumerate(order(m)):
        into = ds[names[j]].values
        out = ds[names[j + 1]].values if j + 1 < len(names) else 0.0
        torque = ds[f"{m.throws[k].name}.crank_torque"].values
        scale = np.max(np.abs(torque))
        assert np.max(np.abs(torque - (into - out))) < 1e-9 * scale


def test_a_mode_tuned_to_an_order_of_the_running_speed_resonates():
    """The coupling's mode on the 2nd order of the running speed (the two throws at 180 deg
    cancel the odd orders), 5 % damped, against the same train with the coupling 1.44 x
    stiffer (the mode 20 % higher). The coupling's twist ``q`` of the rotor against the
    flywheel (the throws stiffly on it: their modes ~370 Hz against 6.4 Hz) is one degree of
    freedom, ``J_eff q'' + c q' + k q = -T_n J_motor / J`` at the order's frequency ``W``
    (the rigid turning separated out), so the ratio of its order-2 amplitudes is ``|k_2 -
    J_eff W^2 + i c W| / |k_1 - J_eff W^2 + i c W|``, evaluated at each run's mean speed
    (4.43; at the nominal speed ``sqrt(0.44^2 + 4 zeta^2) / (2 zeta)`` = 4.51). Tolerance 3 %:
    after 8 revolutions (5 time constants ``1 / (zeta w_n)``) the start's transient is down
    to e^-5 = 0.7 % of the forced amplitude in each run; the speed's ripple at resonance
    (+-1.1 rad/s) modulates the order's phase by ~0.06 rad, 0.1 % of the amplitude; the
    throws' elasticity and varying inertia, ~3e-4."""
    from recipdyn.model.shaft import train_of

    n, zeta, ks = 2, 0.05, 2.5e6
    target = n * OMEGA

    def omega_1(kc):
        model = _model(_machine(kc, ks))
        train = train_of(model.machine, model.parameters(), (kc, ks, ks), J_motor=J_MOTOR)
        return 2.0 * math.pi * train.natural_frequencies()[0]

    k1 = 5.5e5
    for _ in range(3):  # (w_1 ~ sqrt(k): converges at once)
        k1 *= (target / omega_1(k1)) ** 2
    j_eff = k1 / target**2
    c = 2.0 * zeta * j_eff * target
    amps, predicted = [], []
    for k in (k1, 1.44 * k1):
        model = _model(_machine(k, ks, c_coupling=c, c_shaft=40.0))
        ds = _simulate(model=model, params=model.parameters(), revolutions=4.0, transient=8.0,
                       fs=2000.0)  # fmt: skip
        th, twist = ds["theta1"].values, ds["shaft.coupling_twist"].values
        amps.append(2.0 * abs(np.mean(twist * np.exp(-1j * n * th))))
        w = n * float(np.mean(ds["omega1"].values))
        predicted.append(1.0 / abs(k - j_eff * w * w + 1j * c * w))
    ratio, want = amps[0] / amps[1], predicted[0] / predicted[1]
    assert want > 4.0
    assert ratio == pytest.approx(want, rel=0.03), (ratio, want, amps)


def test_each_throws_crank_turns_with_its_node_and_its_phase():
    """Throw 2 nearer the flywheel than throw 1 (axial 0 and 0.6 m) and turned by 180 deg: the
    nodes follow the axial order (flywheel, throw2, throw1), and each throw's crank angle is
    its node's angle plus its phase less its cylinder angle, to the bit (one addition)."""
    throws = (
        Throw("throw1", crank_joint="ideal", axial_position=0.6, params=(("phase", 0.3),)),
        Throw("throw2", crank_joint="ideal", axial_position=0.0, cylinder_angle=math.pi,
              params=(("phase", 2.0),)),
    )  # fmt: skip
    machine = Machine("phases", shaft=Shaft("motor", "induction", (("omega", OMEGA),),
                                            torsion=True),
                      throws=throws, stages=(Stage(),))  # fmt: skip
    model = _model(machine)
    v = model.parameters()
    st = model.configuration(v).layout.state
    assert st.names[st.start("shaft.nodes") : st.parts["shaft.nodes"].stop] == (
        "shaft.theta_flywheel", "shaft.omega_flywheel", "throw2.theta_shaft",
        "throw2.omega_shaft", "throw1.theta_shaft", "throw1.omega_shaft")  # fmt: skip
    ds = _simulate(model=model, params=v, revolutions=0.1, fs=4000.0)
    for name, phase in (("throw1", 0.3), ("throw2", 2.0 - math.pi)):
        got = ds[f"{name}.theta1"].values
        assert np.array_equal(got, ds[f"{name}.theta_shaft"].values + phase), name
    # throw2's section carries both throws' torque, throw1's its own only
    assert np.max(np.abs(ds["throw2.shaft_torque"].values)) > 0.0
    assert not np.array_equal(ds["throw1.shaft_twist"].values, ds["throw2.shaft_twist"].values)


def test_the_run_summary_holds_the_api618_torsional_check():
    """The summary's natural frequencies are the linear train's, and its smallest separation
    the smallest ``|f - n f_run| / (n f_run)`` over the modes and orders 1-10, at the run's
    mean speed; a train tuned onto an order fails."""
    from recipdyn.model.shaft import train_of
    from recipdyn.model.shaft.torsion import torsion_summary

    model = _model(read_machine(EXAMPLE))
    v = model.parameters()
    s = torsion_summary(model.machine, v, OMEGA / (2 * math.pi))
    f = train_of(model.machine, v, (3e5, 2.5e6, 2.5e6), J_motor=400.0).natural_frequencies()
    assert [s[f"torsion_f{i}_hz"] for i in (1, 2, 3)] == pytest.approx(f, rel=1e-12)
    f_run = OMEGA / (2 * math.pi)
    sep = min(abs(x - n * f_run) / (n * f_run) for x in f for n in range(1, 11))
    assert s["torsion_min_separation"] == pytest.approx(sep, rel=1e-12)
    for i, x in enumerate(f, 1):  # each mode's nearest order and its margin
        n = s[f"torsion_f{i}_order"]
        assert s[f"torsion_f{i}_separation"] == pytest.approx(abs(x - n * f_run) / (n * f_run))
        assert all(abs(x - m * f_run) / (m * f_run) >= s[f"torsion_f{i}_separation"]
                   for m in range(1, 11))  # fmt: skip
    assert s["api618_torsional"] == ("pass" if sep >= 0.1 else "FAIL")
    hit = torsion_summary(model.machine, v, f[0] / 3.02)  # the first mode at 3.02 x the speed
    assert hit["api618_torsional"] == "FAIL" and hit["torsion_min_separation_order"] == 3


@pytest.mark.parametrize(
    "text, words",
    [
        ('[shaft]\ndrive = "prescribed"\n[shaft.torsion]\n', "needs drive = 'motor'"),
        ('[shaft]\ndrive = "motor"\nJ_motor = 300\n', "(in [shaft.torsion])"),
        ('[shaft]\ndrive = "motor"\n[shaft.torsion]\nk_shaft = 1e6\n', "in its [[throw]]"),
    ],
)
def test_a_flexible_shaft_is_refused_where_it_cannot_hold(tmp_path, text, words):
    """One line naming the key and what is allowed: a prescribed drive (every crank at omega:
    nothing to twist against), a torsion parameter outside ``[shaft.torsion]``, a throw's
    parameter in it."""
    f = tmp_path / "m.toml"
    f.write_text(text + '[[throw]]\nload = "paper"\n[[throw]]\nload = "paper"\n')
    with pytest.raises(ParameterError) as exc:
        read_machine(f)
    assert words in str(exc.value) and "\n" not in str(exc.value), str(exc.value)


def test_a_flexible_shafts_values_are_checked_in_one_line():
    """``shaft.J_motor`` at least ``J_drive``, and a throw's ``k_shaft`` without a flexible
    shaft, are refused naming the parameter."""
    model = _model(read_machine(EXAMPLE))
    with pytest.raises(ParameterError, match=r"^shaft\.J_motor = 3000 kg\*m\*\*2 is out of"):
        model.parameters({"shaft.J_motor": 3000.0})
    with pytest.raises(ParameterError, match=r"^shaft\.k_coupling"):
        model.parameters({"shaft.k_coupling": 0.0})
    rigid = Machine(
        "r",
        shaft=Shaft("motor"),
        throws=(Throw("throw1", params=(("k_shaft", 1e6),)), Throw("throw2")),
        stages=(Stage(),),
    )
    with pytest.raises(ParameterError, match=r"throw1\.k_shaft .*\[shaft\.torsion\]"):
        _model(rigid)


def test_a_bad_flexible_shaft_is_refused_before_the_compiled_code_loads(tmp_path):
    """``--set shaft.J_motor=4000`` (above ``J_drive``) on the example: one line, exit status
    2, before numba, xarray, SciPy or the kernels load (a fresh interpreter)."""
    from test_cli_refusals import _fresh

    args = ["simulate", "--machine", str(EXAMPLE), "--set", "shaft.J_motor=4000 kg*m**2"]
    res = _fresh([*args, "-o", "o/x.nc"], tmp_path)
    assert res["code"] == 2, res["err"]
    assert res["heavy"] == [], res["heavy"]
    assert len(res["err"].strip().splitlines()) == 1, res["err"]
    assert "shaft.J_motor" in res["err"] and "J_drive" in res["err"]


@pytest.mark.parametrize("name", ["two_throw_frame", "two_stage_4_throw"])
def test_the_flexible_shaft_composes_with_the_other_parts(name):
    """The example machines with a frame, and with dynamic valves between two stages and an
    interstage volume (load states, events and resets), given a flexible shaft: they run, and
    the energy balance with the sections' dissipation holds to 1e-7 of the motor's work over a
    quarter revolution (the integration's tolerance; measured ~3e-13)."""
    from dataclasses import replace

    m = read_machine(ROOT / "examples" / "machines" / f"{name}.toml")
    model = _model(replace(m, shaft=replace(m.shaft, torsion=True)))
    v = model.parameters()
    ds = _simulate(model=model, params=v, revolutions=0.25, fs=2000.0)
    work = ds["W_motor"].values - ds["shaft.W_shaft_damping"].values
    work = work + sum(ds[f"{t.name}.W_gas"].values for t in m.throws)
    total = ds["energy"].values - ds["energy"].values[0]
    assert np.max(np.abs(total - work)) < 1e-7 * np.max(np.abs(ds["W_motor"].values))


def test_a_held_rotor_on_a_rigid_shaft_turns_the_crank_at_the_prescribed_speed():
    """``motor = 'held'`` on a rigid shaft: the crank's acceleration is 0 exactly (the torque
    is the throws' shares' with the sign turned: ``x + (-x)`` is 0 in floating point), so its
    speed stays ``omega`` to the bit, the motor's torque is the sum of the throws' crank
    torques (to rounding: 1e-9 of the largest), and the throws move as with ``drive =
    'prescribed'`` (massless links with the default clearance, half a revolution). The two
    runs solve the same equations by two paths (a free crank's share at ``alpha = 0``, the
    prescribed crank's own equation) through the same integrator at rtol 1e-10: each clearance
    angle agrees to 1e-6 rad (a few thousand steps of local error ~1e-10 relative; the impacts
    of the link's clearance make the error grow, not the equations differ: measured ~1e-11)."""
    held = _model(_machine(0.0, 0.0, torsion=False, motor="held", joint="link"))
    prescribed = Machine(
        "torsion-test", shaft=Shaft("prescribed", params=(("omega", OMEGA),)),
        throws=tuple(Throw(f"throw{i + 1}", crank_joint="link", params=(("phase", ph),))
                     for i, ph in enumerate((0.0, math.pi))),
        stages=(Stage(),),
    )  # fmt: skip
    kw = dict(revolutions=0.5, fs=4000.0, rtol=1e-10, atol=1e-12)
    a = _simulate(model=held, params=held.parameters(), **kw)
    b = _simulate(model=_model(prescribed), params=_model(prescribed).parameters(), **kw)
    assert np.all(a["omega1"].values == OMEGA)
    torque = a["throw1.crank_torque"].values + a["throw2.crank_torque"].values
    assert np.max(np.abs(a["motor_torque"].values - torque)) < 1e-9 * np.max(np.abs(torque))
    for k in (1, 2):
        thc_a, thc_b = a[f"throw{k}.theta_c"].values, b[f"throw{k}.theta_c"].values
        assert np.max(np.abs(thc_a - thc_b)) < 1e-6, np.max(np.abs(thc_a - thc_b))
        assert np.ptp(thc_b) > 0.1  # (the clearance angle moves: not a trivial agreement)


def test_a_grounded_train_is_the_limit_of_a_heavy_rotor():
    """A train whose first node is held (``grounded``) has the natural frequencies of the same
    train with that node's inertia 1e9 times larger (a separate path: the full eigenproblem
    with one rigid mode left out); the difference is O(1e-9) relatively (the heavy node's
    motion ~ J_others / J_heavy), bound 1e-6."""
    from recipdyn.model.shaft import TorsionalTrain

    names = ("motor", "flywheel", "throw1", "throw2")
    inertias, ks = (400.0, 2600.0, 55.0, 70.0), (3e5, 2.5e6, 1.8e6)
    held = TorsionalTrain(names, inertias, ks, grounded=True).natural_frequencies()
    heavy = TorsionalTrain(names, (4e11, *inertias[1:]), ks).natural_frequencies()
    assert held.size == 3
    assert held == pytest.approx(heavy, rel=1e-6)
    assert held[0] < TorsionalTrain(names, inertias, ks).natural_frequencies()[0]


def test_a_held_rotors_shaft_twists_at_the_grounded_trains_frequency_and_balances_energy():
    """A held rotor (``motor = 'held'``) on the flexible shaft, the flywheel started 0.01 rad
    ahead of its quasi-static twist, no damping, 1 % of the paper's load: the rotor turns at
    ``omega`` to the bit, and the coupling's twist oscillates at the lowest natural frequency
    of the train with the rotor grounded (`train_of(..., held=True)`; a different mode from
    the free train's, ~7 Hz against ~20 Hz here), within the half bin of the record's FFT and
    the band of the throws' inertia over a revolution (as the free train's test). Then with
    damped sections and the full load, half a revolution: ``E(t) - E(0) = W_motor + sum W_gas
    - W_shaft_damping`` to 1e-7 of the motor's work (the integration's tolerance), the motor's
    work being the coupling's torque times ``omega``."""
    from recipdyn.model.shaft import TorsionalTrain, train_of

    kc, ks = 5.5e6, 2.5e6
    model = _model(_machine(kc, ks, extra=(("load_amplitude", 2000.0),), motor="held"))
    v = model.parameters()
    sol, st, f_sim, half_bin = _ring(model, "shaft.theta_flywheel")
    assert np.all(sol.y[:, st["omega1"]] == OMEGA)
    f_held = train_of(model.machine, v, (kc, ks, ks), J_motor=J_MOTOR,
                      held=True).natural_frequencies()[0]  # fmt: skip
    f_free = train_of(model.machine, v, (kc, ks, ks), J_motor=J_MOTOR).natural_frequencies()[0]
    lo, hi = _inertia_range(model.throws(v)[0])

    def f_at(j):
        names = ("motor", "flywheel", "throw1", "throw2")
        return TorsionalTrain(names, (J_MOTOR, J_DRIVE - J_MOTOR, j, j), (kc, ks, ks),
                              grounded=True).natural_frequencies()[0]  # fmt: skip

    band = (f_at(hi), f_at(lo))
    assert band[0] - half_bin <= f_sim <= band[1] + half_bin, (f_sim, f_held, band)
    assert abs(f_free - f_held) > 10 * half_bin  # (the grounded mode, not the free one)

    damped = _model(_machine(3e5, 2.5e6, c_coupling=1e3, c_shaft=40.0, motor="held"))
    ds = _simulate(model=damped, params=damped.parameters(), revolutions=0.5, fs=4000.0)
    total = ds["energy"].values - ds["energy"].values[0]
    loss = ds["shaft.W_shaft_damping"].values
    work = ds["W_motor"].values + ds["throw1.W_gas"].values + ds["throw2.W_gas"].values
    assert loss[-1] > 0.0 and np.all(ds["omega1"].values == OMEGA)
    assert np.max(np.abs(total - (work - loss))) < 1e-7 * np.max(np.abs(ds["W_motor"].values))
    coupling = ds["shaft.coupling_torque"].values
    err = np.max(np.abs(ds["motor_torque"].values - coupling))
    assert err < 1e-9 * np.max(np.abs(coupling)), err


def test_a_held_rotor_with_the_contact_joints_is_refused_in_one_line():
    """``--model compressor-contact --set drive=motor --set motor=held``: not modelled yet,
    one line naming what is allowed."""
    from recipdyn.model.registry import get_model

    with pytest.raises(ParameterError, match=r"^motor = 'held' with the contact joints") as e:
        get_model("compressor-contact").parameters({"drive": "motor", "motor": "held"})
    assert "\n" not in str(e.value)
