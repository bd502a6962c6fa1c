"""The frame on its elastic mounts (issue 43, point 3; `recipdyn.model.frame`).

The hypotheses, each against something written independently of the code under test:

* the frame's rigid-body modes: the compiled right-hand side's linear operator on the frame's
  states against the hand closed form of a symmetric frame and against ``scipy.linalg.eigh``
  of a mass and a stiffness matrix written here from the mounts' potential energy;
* a harmonic force: one throw's primary shaking force gives the frame's translation the
  steady amplitude of the one-degree-of-freedom closed form ``F / |k - m w^2 + i c w|``;
* a balanced-opposed pair of identical throws leaves the frame's translation at rest and
  turns it by the couple's closed-form response;
* a fault on throw 2 shows in throw 2's accelerometer most, and in throw 1's through the frame
  only (a prescribed crank: without the frame throw 1's channel does not change at all);
* the compiled frame force (``M q'' + C q' + K q`` of the record) equals the record's shaking
  force and moment computed in numpy from the hand-derived kinematics (a motor: the crank's
  acceleration too); the frame's energy balance; its Jacobian rows;
* without a frame a machine binds none of it, and the throws do not feel the frame (one-way
  coupling): their signals agree with and without it to the integration's tolerance.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import recipdyn
from recipdyn.errors import ModelValidityWarning, ParameterError
from recipdyn.model.machine import Frame, Machine, Mount, Shaft, Stage, Throw, read_machine

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "machines" / "two_throw_frame.toml"
OPPOSED = ROOT / "examples" / "machines" / "balanced_opposed.toml"

# one throw: the geometry of tests/test_shaking.py (none of the examples'), no offset
R, L, RS, LS, M1, M2, M3 = 0.09, 0.42, 0.03, 0.15, 11.0, 17.0, 43.0
OMEGA = 30.0  # rad/s
N = 360  # samples per revolution


def _model(machine):
    from recipdyn.model.assembler.model import MachineModel

    return MachineModel(machine)


def _mounts(places, k_x, k_z, c_x=0.0, c_z=0.0):
    return tuple(Mount(f"mount{i + 1}", x, z, (("k_x", k_x), ("k_z", k_z), ("c_x", c_x),
                                                ("c_z", c_z)))
                 for i, (x, z) in enumerate(places))  # fmt: skip


def _one_throw(frame: Frame, z: float = 0.0) -> Machine:
    geo = (("r", R), ("l", L), ("rs", RS), ("ls", LS), ("m1", M1), ("m2", M2), ("m3", M3),
           ("d", 0.0), ("load_table", ((0.0, 1000.0), (180.0, 1000.0))))  # fmt: skip
    throw = Throw("throw1", crank_joint="ideal", load="table", params=geo, axial_position=z)
    return Machine("frame-test", shaft=Shaft("prescribed", params=(("omega", OMEGA),)),
                   throws=(throw,), stages=(Stage(),), frame=frame)  # fmt: skip


def _run(model, values, revolutions, transient=0.0, n=N, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelValidityWarning)
        return recipdyn.simulate(model=model, params=values, revolutions=revolutions,
                                 transient=transient,
                                 fs=float(model.period(values)) ** -1 * n, **kw)  # fmt: skip


def _harmonic(x, n=1, per=N):
    """The n-th harmonic's complex amplitude of ``x`` over whole revolutions of ``per``
    samples (a periodic signal sampled evenly: the DFT is exact up to aliasing)."""
    x = np.asarray(x, dtype=float)
    x = x[len(x) % per :]
    k = np.arange(x.size)
    return 2.0 * np.sum(x * np.exp(-2j * np.pi * n * k / per)) / x.size


def _frame_block(model, values):
    """``-M^-1 K`` of the compiled right-hand side: the frame's accelerations per unit
    displacement of each of its coordinates (exactly linear: a difference from q = 0)."""
    c = model.configuration(values)
    s = c.layout.state.start("frame")
    y0 = model.initial_state(values)
    f0 = np.empty_like(y0)
    c.kernels.rhs(0.0, y0, c.params, f0)
    out = np.empty((3, 3))
    for j in range(3):
        y = y0.copy()
        y[s + j] = 1e-3
        f = np.empty_like(y)
        c.kernels.rhs(0.0, y, c.params, f)
        out[:, j] = (f[s + 3 : s + 6] - f0[s + 3 : s + 6]) / 1e-3
    return out


def _independent_matrices(mass, inertia, xc, zc, mounts):
    """M and K of a rigid body in the x-z plane from its mounts' potential energy
    ``V = 1/2 sum k_x (x + psi dz)^2 + k_z (z - psi dx)^2`` (``dx, dz``: a mount's place from
    the centre of mass), its Hessian written out term by term."""
    K = np.zeros((3, 3))
    for m in mounts:
        v = m.values
        dx, dz = m.x - xc, m.z - zc
        K[0, 0] += v["k_x"]
        K[1, 1] += v["k_z"]
        K[0, 2] += v["k_x"] * dz
        K[1, 2] -= v["k_z"] * dx
        K[2, 2] += v["k_x"] * dz * dz + v["k_z"] * dx * dx
    K[2, 0], K[2, 1] = K[0, 2], K[1, 2]
    return np.diag([mass, mass, inertia]), K


def test_the_rigid_body_modes_against_a_hand_closed_form_and_scipy_eigh():
    """Natural frequencies of the frame's three rigid-body modes from the compiled right-hand
    side (the eigenvalues of its ``M^-1 K``) against (a) a symmetric frame's closed form: four
    equal mounts at ``(+-a, +-b)`` from the centre of mass give ``w_x = w_z = sqrt(4 k / m)``
    and ``w_psi = sqrt(4 k (a^2 + b^2) / J)``; (b) an asymmetric frame (three unequal mounts,
    the centre of mass off the middle, x, z and psi coupled) against
    ``scipy.linalg.eigh(K, M)`` of matrices written here. Tolerance 1e-9 relative: the
    operator is exactly linear, read from differences of the right-hand side at displacements
    of 1e-3 (rounding ~1e-16 |f| / 1e-3 of entries ~|K| / m)."""
    from scipy.linalg import eigh

    m, J, a, b, k = 8000.0, 8700.0, 1.0, 0.8, 5e7
    sym = Frame((("mass", m), ("inertia", J), ("x_cm", 0.5), ("z_cm", 0.3)),
                _mounts([(0.5 + sx * a, 0.3 + sz * b) for sx in (-1, 1) for sz in (-1, 1)],
                        k, k))  # fmt: skip
    model = _model(_one_throw(sym))
    w2 = np.sort(np.linalg.eigvals(-_frame_block(model, model.parameters())).real)
    want = np.sort([4 * k / m, 4 * k / m, 4 * k * (a * a + b * b) / J])
    np.testing.assert_allclose(w2, want, rtol=1e-9)

    mounts = (Mount("front", -0.4, -0.9, (("k_x", 3e7), ("k_z", 1e7))),
              Mount("back", 1.7, 0.2, (("k_x", 6e7), ("k_z", 4e7))),
              Mount("side", 0.3, 1.6, (("k_x", 2e7), ("k_z", 9e7))))  # fmt: skip
    frame = Frame((("mass", 5000.0), ("inertia", 4100.0), ("x_cm", 0.35), ("z_cm", 0.45)),
                  mounts)  # fmt: skip
    model = _model(_one_throw(frame))
    A = -_frame_block(model, model.parameters())
    Mt, Kt = _independent_matrices(5000.0, 4100.0, 0.35, 0.45, mounts)
    assert abs(Kt[0, 2]) > 1e6 and abs(Kt[1, 2]) > 1e6  # the modes are coupled
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(A).real), eigh(Kt, Mt, eigvals_only=True),
                               rtol=1e-9)  # fmt: skip
    np.testing.assert_allclose(A, np.linalg.solve(Mt, Kt), rtol=1e-9, atol=1e-9 * np.abs(A).max())


def _sdof_frame(zc=0.3):
    """A frame whose translation along x is one degree of freedom: four equal mounts
    symmetric about the centre of mass (no coupling to psi or z), the throw at ``z_cm``
    (no moment); m 1000 kg, k 8.1e6 N/m (w_n = 90 rad/s = 3 x the crank's), zeta 0.2."""
    m, wn, zeta = 1000.0, 90.0, 0.2
    k, c = m * wn * wn, 2 * zeta * m * wn
    frame = Frame((("mass", m), ("inertia", 900.0), ("x_cm", 0.0), ("z_cm", zc)),
                  _mounts([(sx * 0.7, zc + sz * 0.6) for sx in (-1, 1) for sz in (-1, 1)],
                          k / 4, k / 4, c / 4, c / 4))  # fmt: skip
    return frame, m, k, c


def test_a_harmonic_force_gives_the_one_degree_of_freedom_steady_amplitude():
    """One throw (ideal pin, no offset, prescribed speed) on the one-degree-of-freedom frame
    of `_sdof_frame`. Its shaking force's first harmonic is exactly the primary force
    ``F1 = (m1 rs + (m2 + m3) r) w^2`` (every term of the crosshead's acceleration beyond
    ``-r w^2 cos th`` has period pi: even harmonics only), so the frame's first harmonic is
    ``|X1| = F1 / sqrt((k - m w^2)^2 + (c w)^2)``, read by the DFT of two whole revolutions
    after a transient of 4. Errors: the start's transient decays as ``exp(-zeta w_n t)`` =
    exp(-18 x 0.84 s) = 3e-7 of the static deflection; the integration's (atol 1e-16 m beside
    an amplitude ~7e-4 m, rtol 1e-10) and the DFT's aliasing (the response's n-th harmonic
    falls as lam^(n-1) / n^2) far below; bound 1e-6 relative (measured 1.9e-8)."""
    frame, m, k, c = _sdof_frame()
    model = _model(_one_throw(frame, z=0.3))
    v = model.parameters()
    ds = _run(model, v, 2.0, transient=4.0, atol=1e-16)
    x1 = abs(_harmonic(ds["frame.x"].values))
    F1 = (M1 * RS + (M2 + M3) * R) * OMEGA**2
    want = F1 / math.hypot(k - m * OMEGA**2, c * OMEGA)
    assert x1 == pytest.approx(want, rel=1e-6)
    assert np.max(np.abs(ds["frame.psi"].values)) < 1e-9 * x1  # decoupled: no moment
    # the accelerometer's channel: the crosshead's + the frame's at its guide
    np.testing.assert_array_equal(ds["accel"].values, ds["a"].values + ds["frame_a"].values)


def test_a_balanced_opposed_pair_leaves_the_frame_still_in_translation_and_turns_it_by_the_couple():
    """examples/machines/balanced_opposed.toml on a frame symmetric about its centre of mass
    at mid-span (z_cm = 325 mm, the throws 650 mm apart). The pair's forces cancel at every
    harmonic (the two throws' motions in their own axes are identical, the cylinders opposed:
    ``F_x,2 = -F_x,1`` to the bit), so the translation has no source but the couple through a
    mount coupling ``K_x,psi``, zero here up to the rounding of the mounts' places: bound
    1e-9 of one throw's translation on the same frame (``F1 / |k - m w^2 + i c w|``, F1 the
    first harmonic of the record's ``throw1.shake_x``). The couple ``S F_x,1`` turns the frame:
    its first harmonic against the one-degree-of-freedom closed form in psi with ``k_psi =
    sum k_x dz^2 + k_z dx^2``, ``c_psi`` alike and the inertia J, at 2e-6 (as the translation
    test: transient exp(-zeta_psi w_psi t) ~ 1e-9, integration far below)."""
    base = read_machine(OPPOSED)
    m, J, k1, c1, zc = 6000.0, 5000.0, 1.5e7, 3e4, 0.325
    places = [(sx * 0.8, zc + sz * 1.0) for sx in (-1, 1) for sz in (-1, 1)]
    frame = Frame((("mass", m), ("inertia", J), ("x_cm", 0.0), ("z_cm", zc)),
                  _mounts(places, k1, k1, c1, c1))  # fmt: skip
    model = _model(replace(base, frame=frame))
    v = model.parameters()
    w = float(v["shaft.omega"])
    ds = _run(model, v, 2.0, transient=4.0, atol=1e-16)
    fx1 = _harmonic(ds["throw1.shake_x"].values)
    single = abs(fx1) / math.hypot(4 * k1 - m * w * w, 4 * c1 * w)
    assert np.max(np.abs(ds["frame.x"].values)) < 1e-9 * single
    kpsi = sum(k1 * ((z - zc) ** 2 + x * x) for x, z in places)
    cpsi = sum(c1 * ((z - zc) ** 2 + x * x) for x, z in places)
    moment1 = abs(_harmonic(ds["shake_moment_y"].values - zc * ds["shake_x"].values))
    assert moment1 == pytest.approx(0.65 * abs(fx1), rel=1e-9)
    psi1 = abs(_harmonic(ds["frame.psi"].values))
    assert psi1 == pytest.approx(moment1 / math.hypot(kpsi - J * w * w, cpsi * w), rel=2e-6)


def _example(drive="prescribed"):
    m = read_machine(EXAMPLE)
    if drive == "prescribed":
        m = replace(m, shaft=Shaft("prescribed", params=(("omega", "20 rad/s"),)))
    return m


def test_a_fault_on_throw_2_shows_most_in_its_own_channel_and_in_its_neighbours_through_the_frame():
    """The example machine at a prescribed speed (so the throws share nothing but the frame):
    throw 2's link wears from 1 to 2 mm. The change of throw 2's accelerometer channel
    (``throw2.accel``) is the largest; throw 1's channel changes too, by the frame only, and
    less; without the frame throw 1's changes only by the integration's error (the throws
    share the step sizes): bound 1e-6 of its largest value (rtol 1e-10 over two revolutions
    of a clearance link; measured 1e-8 m/s^2 of 60), where the frame moves it by ~1e-2."""
    out = {}
    for frame in (True, False):
        m = _example()
        model = _model(m if frame else replace(m, frame=None))
        runs = [_run(model, model.parameters({"throw2.rc": rc}), 1.0, transient=1.0)
                for rc in (1e-3, 2e-3)]  # fmt: skip
        sig = "accel" if frame else "a"
        out[frame] = [np.max(np.abs(runs[1][f"throw{k}.{sig}"].values
                                    - runs[0][f"throw{k}.{sig}"].values))
                      for k in (1, 2)]  # fmt: skip
        top = np.max(np.abs(runs[0]["throw1.a"].values))
    d1, d2 = out[True]
    assert 1e-4 * top < d1 < 0.1 * d2, (d1, d2)
    assert out[False][0] < 1e-6 * top and out[False][1] > 0.1 * d2


def test_the_compiled_frame_force_is_the_records_shaking_force_and_its_energy_balances():
    """The example machine (a motor: the crank accelerates, so the shaking force holds
    ``alpha1`` terms). (1) ``M q'' + C q' + K q`` of the record (``q''`` from the compiled
    right-hand side that was integrated) against the record's ``shake_x`` and its moment about
    the centre of mass ``shake_moment_y - z_cm shake_x``, both in numpy from the hand-derived
    kinematics (`recipdyn.model.kinematics`): the compiled role `link_kernels.shaking` is an
    implementation of its own; bound 1e-9 of the peak (rounding of both, the mounts' forces
    cancelling the inertia of 8 t). (2) The frame's energy change equals the throws' work on it
    less the mounts' dissipation, ``E(t) - E(0) = W_throws - W_damping``: all three integrated
    together, so to the integration's tolerance; bound 1e-6 of the largest work (the frame's
    states at atol 1e-12 beside displacements ~1e-5 m)."""
    from recipdyn.model.frame.body import matrices

    model = _model(_example("motor"))
    v = model.parameters()
    ds = _run(model, v, 1.0)
    M, K, C = matrices(model.machine.frame, {k[6:]: x for k, x in v.items()
                                             if k.startswith("frame.")})  # fmt: skip
    q = np.stack([ds[f"frame.{s}"].values for s in ("x", "z", "psi")], axis=1)
    qd = np.stack([ds[f"frame.{s}"].values for s in ("xdot", "zdot", "psidot")], axis=1)
    c = model.configuration(v)
    from recipdyn.model.base import rhs_series

    y = np.stack([ds[n].values for n in c.layout.state.names], axis=1)
    dy = rhs_series(c.kernels.rhs, c.params, np.array(ds["time"].values), y)
    s = c.layout.state.start("frame")
    Q = dy[:, s + 3 : s + 6] @ M.T + qd @ C.T + q @ K.T
    zc = float(v["frame.z_cm"])
    fx, my = ds["shake_x"].values, ds["shake_moment_y"].values - zc * ds["shake_x"].values
    top = np.max(np.abs(fx))
    assert top > 500.0 and np.max(np.abs(my)) > 50.0
    np.testing.assert_allclose(Q[:, 0], fx, atol=1e-9 * top)
    np.testing.assert_allclose(Q[:, 1], 0.0, atol=1e-9 * top)
    np.testing.assert_allclose(Q[:, 2], my, atol=1e-9 * np.max(np.abs(my)))
    e = ds["frame_energy"].values
    w = ds["frame.W_throws"].values - ds["frame.W_damping"].values
    scale = max(np.max(np.abs(ds["frame.W_throws"].values)), np.max(ds["frame.W_damping"].values))
    assert np.max(ds["frame.W_damping"].values) > 0.0
    np.testing.assert_allclose(e - e[0], w, atol=1e-6 * scale)
    summary = model.run_summary(v, ds)
    assert 0.0 < summary["frame_feedback_ratio"] < 1e-2
    assert ds.attrs["validity"] == "ok"


def test_a_frame_at_resonance_leaves_the_one_way_coupling_and_is_flagged():
    """A light frame (300 kg beside the throw's 71 kg of moving parts) tuned to the crank's
    speed, 5 % damped: within a revolution the frame's acceleration at the guide, times the
    throw's moving mass, exceeds `FEEDBACK_LIMIT` of the throw's shaking force (the resonant
    response grows by ``F t / (2 m)`` in velocity: ~0.2 m/s, ~6 m/s^2 at 30 rad/s, against
    the limit's 0.05 x 5.2 kN / 71 kg = 3.6 m/s^2), so the run is flagged outside the model's
    validity (warning naming the frame's margin, the record's ``validity``), its verdicts
    withheld like any invalid run's."""
    from recipdyn.model.frame.body import FEEDBACK_LIMIT

    m, wn, zeta = 300.0, OMEGA, 0.05
    k, c = m * wn * wn, 2 * zeta * m * wn
    frame = Frame((("mass", m), ("inertia", 300.0), ("x_cm", 0.0), ("z_cm", 0.0)),
                  _mounts([(sx * 0.7, sz * 0.6) for sx in (-1, 1) for sz in (-1, 1)],
                          k / 4, k / 4, c / 4, c / 4))  # fmt: skip
    model = _model(_one_throw(frame))
    v = model.parameters()
    with pytest.warns(ModelValidityWarning, match="frame_coupling_margin"):
        ds = recipdyn.simulate(model=model, params=v, revolutions=1.5,
                               fs=float(model.period(v)) ** -1 * N)  # fmt: skip
    assert "frame_coupling_margin" in ds.attrs["validity"]
    assert np.max(ds["frame_feedback"].values) > FEEDBACK_LIMIT
    assert np.min(ds["frame_coupling_margin"].values) < 0.0


def test_the_jacobians_frame_rows_against_central_differences():
    """The prescribed crank's Jacobian (``jac``: the throws' rows exact, the frame's by its
    own central differences) at a state of a run against central differences of the
    right-hand side written here, steps 1e-5 (|y| + 1): truncation ~1e-10 of an entry,
    rounding ~1e-11; bound 1e-6 of the row's largest. A frame's system has no combined
    ``rhs_jac`` (not written for the frame's rows)."""
    model = _model(_example())
    v = model.parameters()
    system = model.system(v)
    assert system.rhs_jac is None
    ds = _run(model, v, 0.3, n=60)
    c = model.configuration(v)
    y = np.array([ds[n].values[-1] for n in c.layout.state.names])
    t = float(ds["time"].values[-1])
    n = y.size
    J = np.zeros((n, n))
    system.jac(t, y, c.params, J)
    D = np.zeros((n, n))
    for j in range(n):
        h = 1e-5 * (abs(y[j]) + 1.0)
        fp, fm = np.empty(n), np.empty(n)
        yp, ym = y.copy(), y.copy()
        yp[j] += h
        ym[j] -= h
        system.rhs(t, yp, c.params, fp)
        system.rhs(t, ym, c.params, fm)
        D[:, j] = (fp - fm) / (2 * h)
    s = c.layout.state.start("frame")
    rows = slice(s, s + 8)
    for i in range(s, s + 8):
        np.testing.assert_allclose(J[i], D[i], atol=1e-6 * max(np.max(np.abs(D[i])), 1e-30))
    assert np.max(np.abs(J[rows, :4])) > 0.0  # the throws' states move the frame


def test_without_a_frame_nothing_is_bound_and_the_throws_do_not_feel_it():
    """A machine without a frame binds no frame role (``absent``) and ``FRAME = False`` (the
    generated code is the code before the frame, its branches removed), and holds no frame
    state. With the frame the throws' own signals are those without it to the integration's
    tolerance (one-way coupling; the step sizes differ, since the frame's states enter the
    error norm): bound 1e-7 of each signal's largest (rtol 1e-10 over a revolution of a
    clearance link)."""
    m = _example()
    bare = _model(replace(m, frame=None))
    vb = bare.parameters()
    template, roles, constants, _, _ = bare.configuration(vb).bindings()
    assert constants["FRAME"] is False
    assert {roles[r][1] for r in ("shaking", "frame_load", "frame_rhs")} == {"absent"}
    assert not any(n.startswith("frame.") for n in bare.state_names)
    model = _model(m)
    a = _run(bare, vb, 1.0)
    b = _run(model, model.parameters(), 1.0)
    for name in ("throw1.theta_c", "throw2.theta_c", "throw1.a", "throw2.a", "throw2.gas_force"):
        x, z = a[name].values, b[name].values
        np.testing.assert_allclose(z, x, atol=1e-7 * np.max(np.abs(x)), err_msg=name)


def test_a_frame_is_read_with_units_and_refused_in_one_line(tmp_path):
    """The example's ``[frame]``: its parameters with units under ``frame.``, its mounts'
    places as structure (in the record's attributes); refused, each in one line naming it: one
    mount, an unknown key, a mount's unknown key, mounts that leave the frame free (the value
    check, before the compiled code)."""
    m = read_machine(EXAMPLE)
    assert [mo.name for mo in m.frame.mounts] == ["mount1", "mount2", "mount3", "mount4"]
    assert m.frame.mounts[0].x == pytest.approx(-0.5) and m.frame.mounts[0].z == -0.675
    model = _model(m)
    v = model.parameters()
    assert v["frame.z_cm"] == pytest.approx(0.325) and v["frame.mount2.k_x"] == 5e7
    assert model.vibration() == ("throw1.accel", "m/s**2")
    assert model.record_attrs(v)["frame.mount4.z_m"] == pytest.approx(1.325)
    mount = "[[frame.mount]]\nk_x = 1e6\n"
    for text, words in (
        ("[frame]\nmass = 1\n" + mount + "[[throw]]\n", "needs at least 2 [[frame.mount]]"),
        ("[frame]\nheight = 1\n" + 2 * mount + "[[throw]]\n", "frame.height: not a parameter"),
        ("[frame]\n" + 2 * mount + "k_y = 1\n[[throw]]\n", "mount2.k_y: not a parameter"),
    ):
        f = tmp_path / "m.toml"
        f.write_text(text)
        with pytest.raises(ParameterError) as exc:
            read_machine(f)
        assert words in str(exc.value) and "\n" not in str(exc.value), str(exc.value)
    with pytest.raises(ParameterError, match="frame: its mounts leave it free") as exc:
        model.parameters({f"frame.mount{i}.k_z": 0.0 for i in range(1, 5)})
    assert "\n" not in str(exc.value)
    with pytest.raises(ParameterError, match="frame.mass"):
        model.parameters({"frame.mass": -1.0})


def test_a_frame_refused_by_the_command_line_before_the_compiled_code_loads(tmp_path):
    """``--set frame.mount1.k_x=-1`` is answered in one line, exit status 2, before numba,
    xarray, SciPy or the kernels load."""
    from test_cli_refusals import _fresh

    res = _fresh(["simulate", "--machine", str(EXAMPLE), "--set", "frame.mount1.k_x=-1",
                  "-o", "o/x.nc"], tmp_path)  # fmt: skip
    assert res["code"] == 2, res["err"]
    assert res["heavy"] == [], res["heavy"]
    assert len(res["err"].strip().splitlines()) == 1 and "frame.mount1.k_x" in res["err"]
