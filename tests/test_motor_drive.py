"""The motor drive with the compressor's other components (issue 30, item 7): the crank angle
and speed as states under a motor torque, with the dynamic valves (rigid pins).

* the flywheel limit: as ``J_drive`` grows the run approaches the prescribed-speed model, the
  speed ripple and every difference falling like ``1 / J_drive``, with bounds derived from the
  ripple where the kinematics give one;
* the energy balance: the motor's work is the mechanism's and the drive's energy change plus
  the work done on the gas (no dissipation in rigid pins);
* the command line: simulate, rerun from the record, analyze.
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

import recipdyn
from recipdyn.cli import main
from recipdyn.errors import LawRangeWarning, ModelValidityWarning
from recipdyn.model.registry import get_model

VALVES = {"load": "valves"}
MOTOR_VALVES = {"load": "valves", "drive": "motor"}


def _simulate(params, **kw):
    with warnings.catch_warnings():  # (the massless link under the valves' reversing load)
        warnings.simplefilter("ignore", ModelValidityWarning)
        warnings.simplefilter("ignore", LawRangeWarning)
        return recipdyn.simulate(model=get_model("compressor"), params=params, **kw)


def test_motor_with_valves_routes_to_the_valves_model_with_the_crank_as_a_state():
    m = get_model("compressor")
    values = m.parameters(MOTOR_VALVES)
    assert m.route(values)[0] == "link-valves"
    names = [k for k, _ in m.states(values)]
    assert names[:6] == ["theta_c", "thetadot_c", "theta1", "omega1", "W_motor", "W_gas"]
    assert len(names) == 6 + 12 + 4  # the gas states and the four mass counters follow
    assert m.system(values).period is None  # the crank is free: autonomous
    # the prescribed configuration is untouched: its own states, its period
    prescribed = m.parameters(VALVES)
    assert [k for k, _ in m.states(prescribed)][:3] == ["theta_c", "thetadot_c", "p_head"]
    assert m.system(prescribed).period == pytest.approx(2 * math.pi / 20.0)


def test_huge_flywheel_approaches_the_prescribed_valves_model():
    """Limit J_drive -> inf: the motor-driven crank with the dynamic valves turns at its
    initial speed, and the run is the prescribed-speed one (`compressor-valves`).

    A constant torque equal to the ideal cycle's mean keeps the mean speed at omega; the speed
    then deviates by the load's energy swing over J omega, so the relative ripple delta =
    max|omega1 - omega| / omega falls like 1 / J (x0.1 a decade, to O(1/J^2)). Derived bounds,
    a quarter revolution (theta_run = pi / 2), first order in the deviations:

    * crank angle: |theta1 - omega t| = |int (omega1 - omega) dt| <= delta theta_run;
    * crosshead: x3 = r cos theta1 + rc cos theta_c + l cos theta2, so
      |dx3| <= (1 + tan theta2_max) (r |d theta1| + rc |d theta_c|), tan theta2_max from
      |sin theta2| <= (r + rc + |d|) / l;
    * the rest (theta_c, the chambers' pressures, the crosshead acceleration) has no simple
      sensitivity to the speed (the link's fast oscillation, the valves): their differences
      must fall by 0.05-0.2 per decade of J, i.e. converge like 1/J.

    The integration error (rtol 1e-11) is below 1e-6 of the smallest difference compared."""
    kw = dict(revolutions=0.25, fs=20_000.0, rtol=1e-11, atol=1e-13)
    ref = _simulate(VALVES, **kw)
    p = get_model("compressor").parameters(VALVES)
    r, rc, l, d, w = (float(p[k]) for k in ("r", "rc", "l", "d", "omega"))
    s2 = (r + rc + abs(d)) / l
    tan2 = s2 / math.sqrt(1.0 - s2 * s2)
    theta_run = w * float(ref.time.values[-1] - ref.time.values[0])
    rows = []
    for J in (3e4, 3e5, 3e6):
        ds = _simulate({**MOTOR_VALVES, "motor": "constant", "J_drive": J}, **kw)
        assert np.array_equal(ds.time.values, ref.time.values)
        err = {k: float(np.max(np.abs(ds[k].values - ref[k].values)))
               for k in ("theta1", "theta_c", "x", "a", "p_head", "p_crank")}  # fmt: skip
        delta = float(np.max(np.abs(ds.omega1.values - w))) / w
        assert err["theta1"] <= delta * theta_run * (1 + 1e-6), (J, err, delta)
        bound_x = (1 + tan2) * (r * err["theta1"] + rc * err["theta_c"])
        assert err["x"] <= 1.01 * bound_x, (J, err["x"], bound_x)
        rows.append((delta, err))
    for (d0, e0), (d1, e1) in zip(rows, rows[1:]):  # noqa: B905 (pairs)
        assert 0.08 < d1 / d0 < 0.12, (d0, d1)
        for k in e0:
            assert 0.05 < e1[k] / e0[k] < 0.2, (k, e0[k], e1[k])


@pytest.mark.parametrize("kw", [{}, {"motor": "constant", "crank_joint": "ideal"}],
                         ids=["induction,rc=1mm", "constant,ideal-pin"])  # fmt: skip
def test_energy_balance_with_the_valves_closes(kw):
    """Invariant: rigid pins dissipate nothing, so the motor's work is the change of the
    energy of crank, drive, rod and crosshead plus the work done on the gas through the
    piston: W_motor = dE - W_gas (W_gas, the gas's work on the crosshead, is negative while
    it is compressed). The valves' losses are inside the gas (its states), not in the
    mechanism. The residual is the integrator's global error in that combination: at most
    the sum of the steps' local errors, n_steps rtol max(|E|, |W|) (E holds J_drive omega^2
    / 2); the bound is that estimate."""
    ds = _simulate({**MOTOR_VALVES, **kw}, revolutions=2, fs=2000.0)
    E, Wm, Wg = ds.energy.values, ds.W_motor.values, ds.W_gas.values
    assert np.max(np.abs(Wm)) > 1e4 and np.max(np.abs(Wg)) > 1e4  # work is done
    residual = np.max(np.abs((Wm - Wm[0]) - (E - E[0]) - (-(Wg - Wg[0]))))
    scale = max(np.max(np.abs(E)), np.max(np.abs(Wm)), np.max(np.abs(Wg)))
    bound = float(ds.attrs["solver_nsteps"]) * float(ds.attrs["solver_rtol"]) * scale
    assert residual < bound, (residual, bound)
    # the recorded motor torque is the law's at the recorded speed (one observation path)
    p = ds.attrs
    if kw.get("motor") == "constant":
        assert np.allclose(ds.motor_torque.values, ds.motor_torque.values[0], rtol=1e-12)
    else:
        ws, tb, sb = (float(p[f"param_motor_{k}"]) for k in ("sync_speed", "breakdown_torque",
                                                              "breakdown_slip"))  # fmt: skip
        s = (ws - ds.omega1.values) / ws
        kloss = 2 * tb * s * sb / (s * s + sb * sb)
        assert np.allclose(ds.motor_torque.values, kloss, rtol=1e-12)


def test_the_command_line_runs_and_analyses_a_motor_with_valves(tmp_path, capsys):
    """``recipdyn simulate --model compressor --set drive=motor --set load=valves``: the
    record holds the selectors, reruns to the bit from itself (``simulate -c``), and
    ``analyze`` reads it (Benettin's exponents refused for the valves, with the reason; the
    section once per turn of the free crank, not once per nominal period)."""
    import xarray as xr

    rec = tmp_path / "r.nc"
    args = ["-n", "1.1", "--fs", "2 kHz", "--no-progress", "--no-figure"]
    assert main(["simulate", "--model", "compressor", "--set", "drive=motor", "--set",
                 "load=valves", "-o", str(rec), *args]) == 0  # fmt: skip
    ds = xr.open_dataset(rec).load()
    assert ds.attrs["param_drive"] == "motor" and ds.attrs["param_load"] == "valves"
    for k in ("omega1", "motor_torque", "W_motor", "W_gas", "energy", "p_head"):
        assert k in ds and np.all(np.isfinite(ds[k].values)), k
    again = tmp_path / "again.nc"
    assert main(["simulate", "-c", str(rec), "-o", str(again), *args]) == 0
    ds2 = xr.open_dataset(again).load()
    for k in ("theta1", "omega1", "a", "p_head"):
        assert np.array_equal(ds[k].values, ds2[k].values), k
    capsys.readouterr()
    out = tmp_path / "an"
    assert main(["analyze", str(rec), "-o", str(out), "--section-points", "3",
                 "--lyap-revolutions", "1"]) == 0  # fmt: skip
    summary = json.loads((out / "summary.json").read_text())
    assert "valve plates" in summary["lyapunov_equations"]["refused"]
    assert summary["poincare"] == {"points": 3, "kind": "angle", "angle": "theta1"}
    # the record's section (app, compare, figures): where the recorded crank angle passes its
    # first value modulo 2 pi, to the linear interpolation's error (628 samples a turn:
    # h^2 theta'' / 8 theta' ~ 1e-9 rad); the nominal period's instants miss it by the slip
    from recipdyn.plotting import section_times

    assert ds.attrs["section_angle"] == "theta1"
    ts, what = section_times(ds, 2 * math.pi / 20.0)
    t, th = ds["time"].values, ds["theta1"].values
    assert what == "once per turn of theta1" and ts.size == 2
    np.testing.assert_allclose(np.interp(ts, t, th) - th[0], [0.0, 2 * math.pi], atol=1e-6)
    nominal = np.interp(2 * math.pi / 20.0, t, th) - th[0] - 2 * math.pi
    assert abs(nominal) > 1e-4, nominal  # the slip: why the nominal period is not a section
    # the features place the orders by the recorded angle: the mean speed, not omega's
    from recipdyn.features import file_features

    (row,) = file_features(rec)
    measured = (th[-1] - th[0]) / (t[-1] - t[0]) / (2 * math.pi)
    assert row["speed_hz"] == pytest.approx(measured, rel=1e-12)
    assert abs(row["speed_hz"] * 2 * math.pi / 20.0 - 1.0) > 1e-5  # not the nominal speed


# ---------------------------------------------------------------------------------------------
# The motor with the contact joints (free-crank contact Lagrangian, _compressor_contact_drive)

#: Impacts at the crank pin: at 150 rad/s with a tenth of the paper's load, inertia separates
#: the journal (the contact model's event example); a quarter revolution holds 8 impacts.
IMPACTS = {"crank_joint": "contact", "omega": 150.0, "load_amplitude": 2e4}


@pytest.mark.parametrize("joints", ["crank", "crosshead", "both"])
def test_free_crank_contact_equations_reduce_to_the_prescribed_ones(joints):
    """Two derivations: the free-crank Lagrangian (coordinates theta1, e...) with the crank
    torque that holds theta1'' = 0 gives the eccentricities' accelerations of the
    prescribed-crank Lagrangian (`compressor_contact.lagrangian`, a separate derivation with
    theta1 = theta1_0 + omega t) at the same crank angle and speed: 30 random states, joint
    forces, torques and geometries, to 1e-8 relative (rounding of M^-1 b with condition
    numbers up to ~1e5)."""
    from recipdyn.model import _compressor_contact as pres
    from recipdyn.model import _compressor_contact_drive as free
    from recipdyn.model.joints.pins import NHEAD

    rng = np.random.default_rng(30)
    n_e = 4 if joints == "both" else 2
    f_free = getattr(free, f"{joints}_free_accelerations")
    f_pres = getattr(pres, f"{joints}_accelerations")
    for _ in range(30):
        r, l = rng.uniform(0.05, 0.2), rng.uniform(0.6, 1.5)
        p = np.zeros(NHEAD)
        p[:10] = (r, l, rng.uniform(0.2, 0.5) * l, rng.uniform(5, 50), rng.uniform(5, 50),
                  rng.uniform(0.1, 2.0), 9.81, rng.uniform(-1e-3, 1e-3), 0.0, 0.0)  # fmt: skip
        th1, w, t = rng.uniform(-np.pi, np.pi), rng.uniform(5, 50), rng.uniform(0, 0.1)
        p[8], p[9] = w, th1 - w * t  # the prescribed crank passes theta1 at t with omega
        e = rng.uniform(-1e-3, 1e-3, n_e)
        ed = rng.uniform(-0.1, 0.1, n_e)
        forces = tuple(rng.uniform(-1e4, 1e4, 6))
        s1, c1 = math.sin(th1), math.cos(th1)
        ic, sc = rng.uniform(1, 1e3), rng.uniform(0, 5)

        state = (th1, *e, w, *ed)
        a0 = f_free(0.0, state, p, (*forces, 0.0, ic, sc, s1, c1))[0]
        a1 = f_free(0.0, state, p, (*forces, 1e4, ic, sc, s1, c1))[0]
        held = f_free(0.0, state, p, (*forces, -a0 * 1e4 / (a1 - a0), ic, sc, s1, c1))
        assert abs(held[0]) <= 1e-8 * max(1.0, abs(a0))
        ref = f_pres(t, (*e, *ed), p, (*forces, s1, c1))
        for k in range(n_e):
            assert held[1 + k] == pytest.approx(ref[k], rel=1e-8, abs=1e-8 * max(map(abs, ref)))


@pytest.mark.slow
def test_generated_free_crank_contact_mechanism_is_up_to_date():
    """``_compressor_contact_drive.py`` is what ``python -m recipdyn.model.compressor_contact``
    writes (sympy, ~1 min)."""
    from pathlib import Path

    from recipdyn.model import compressor_contact

    committed = Path(compressor_contact.__file__).with_name("_compressor_contact_drive.py")
    assert committed.read_text() == compressor_contact.generate_drive()


def test_huge_flywheel_approaches_the_prescribed_contact_model():
    """Limit J_drive -> inf with contact at the crank pin, over a quarter revolution with 8
    impacts (contact is non-smooth: the impacts' times shift with the speed, so a long
    trajectory is not compared). The speed ripple delta falls like 1 / J (x0.1 a decade);
    bounds derived from it, first order:

    * crank angle: |theta1 - omega t| <= delta theta_run;
    * crosshead: x3 = B_x + l cos theta2, l cos theta2 = sqrt(l^2 - (d + B_y)^2), so
      |dx3| <= |dB_x| + tan theta2_max |dB_y| <= r (1 + tan theta2_max) |d theta1| + |d e_x|
      + tan theta2_max |d e_y|;
    * the eccentricity, the crosshead acceleration and the gas force: their differences fall
      by 0.05-0.2 per decade of J (the impacts shift by ~delta of their time: the same
      order).

    The integration error (rtol 1e-11) is below 1e-4 of the smallest difference compared."""
    kw = dict(revolutions=0.25, fs=20_000.0, rtol=1e-11, atol=1e-13)
    ref = _simulate(IMPACTS, **kw)
    assert ref.sizes["impact_event"] >= 4  # the check crosses impacts
    p = get_model("compressor").parameters(IMPACTS)
    r, rc, l, d, w = (float(p[k]) for k in ("r", "rc", "l", "d", "omega"))
    s2 = (r + 1.5 * rc + abs(d)) / l
    tan2 = s2 / math.sqrt(1.0 - s2 * s2)
    theta_run = w * float(ref.time.values[-1] - ref.time.values[0])
    rows = []
    for J in (3e4, 3e5, 3e6):
        ds = _simulate({**IMPACTS, "drive": "motor", "motor": "constant", "J_drive": J}, **kw)
        assert ds.sizes["impact_event"] == ref.sizes["impact_event"]
        err = {k: float(np.max(np.abs(ds[k].values - ref[k].values)))
               for k in ("theta1", "ex", "ey", "x", "a", "gas_force")}  # fmt: skip
        delta = float(np.max(np.abs(ds.omega1.values - w))) / w
        assert err["theta1"] <= delta * theta_run * (1 + 1e-6), (J, err, delta)
        bound_x = r * (1 + tan2) * err["theta1"] + err["ex"] + tan2 * err["ey"]
        assert err["x"] <= 1.01 * bound_x, (J, err["x"], bound_x)
        rows.append((delta, err))
    for (d0, e0), (d1, e1) in zip(rows, rows[1:]):  # noqa: B905 (pairs)
        assert 0.08 < d1 / d0 < 0.12, (d0, d1)
        for k in e0:
            assert 0.05 < e1[k] / e0[k] < 0.2, (k, e0[k], e1[k])


@pytest.mark.parametrize("kw", [
    {**IMPACTS, "friction": 0.1, "motor_sync_speed": 160.0},
    {"crank_joint": "lubricated", "crosshead_joint": "contact", "load": "cycle"},
    {"crank_joint": "contact", "load": "valves"},
], ids=["crank-impacts-friction", "oil-and-contact-cycle", "contact-valves"])  # fmt: skip
def test_energy_balance_with_contact_joints_closes(kw):
    """Invariant: the motor's work is the change of the energy of crank, drive, rod and
    crosshead (with the contacts' elastic energy) plus the work done on the gas plus the
    energy lost in the joints (contact damping, friction, the oil film): W_motor = dE - W_gas
    + W_loss. The residual is the integrator's global error: at most the sum of the steps'
    local errors, n_steps rtol max(|E|, |W|); the bound is that estimate. The dissipation is
    real (W_loss > 0) and the journal's friction torque acts on the free crank."""
    ds = _simulate({**kw, "drive": "motor"}, revolutions=0.5, fs=5000.0)
    E, Wm, Wg, Wl = (ds[k].values for k in ("energy", "W_motor", "W_gas", "W_loss"))
    assert np.max(np.abs(Wm)) > 1e3 and Wl[-1] - Wl[0] > 0.0
    residual = np.max(np.abs((Wm - Wm[0]) - (E - E[0]) + (Wg - Wg[0]) - (Wl - Wl[0])))
    scale = max(np.max(np.abs(E)), np.max(np.abs(Wm)), np.max(np.abs(Wg)))
    bound = float(ds.attrs["solver_nsteps"]) * float(ds.attrs["solver_rtol"]) * scale
    assert residual < bound, (residual, bound)


def test_the_command_line_runs_and_analyses_a_motor_with_a_contact_joint(tmp_path, capsys):
    """``recipdyn simulate --set crank_joint=contact --set drive=motor``: the record reruns
    to the bit from itself and ``analyze`` reads it: Benettin's exponents of the six degrees
    of freedom (the eccentricity and its rate, the crank's angle and speed), over
    ``--lyap-revolutions`` revolutions of the nominal speed (the system is autonomous: no
    forcing period; 0.2 of one, 2 pi / omega each, not 0.2 s), per second and per nominal
    revolution."""
    import xarray as xr

    rec = tmp_path / "r.nc"
    args = ["-n", "1.1", "--fs", "2 kHz", "--no-progress", "--no-figure"]
    assert main(["simulate", "--set", "crank_joint=contact", "--set", "drive=motor", "-o",
                 str(rec), *args]) == 0  # fmt: skip
    ds = xr.open_dataset(rec).load()
    assert ds.attrs["param_drive"] == "motor" and ds.attrs["param_crank_joint"] == "contact"
    for k in ("omega1", "motor_torque", "W_motor", "W_gas", "W_loss", "ex", "a"):
        assert k in ds and np.all(np.isfinite(ds[k].values)), k
    again = tmp_path / "again.nc"
    assert main(["simulate", "-c", str(rec), "-o", str(again), *args]) == 0
    ds2 = xr.open_dataset(again).load()
    for k in ("theta1", "omega1", "ex", "a"):
        assert np.array_equal(ds[k].values, ds2[k].values), k
    capsys.readouterr()
    out = tmp_path / "an"
    assert main(["analyze", str(rec), "-o", str(out), "--section-points", "3",
                 "--lyap-revolutions", "0.2"]) == 0  # fmt: skip
    lyap = json.loads((out / "summary.json").read_text())["lyapunov_equations"]
    assert "refused" not in lyap and len(lyap["exponents_per_s"]) == 6
    period = 2.0 * math.pi / float(ds.attrs["param_omega"])
    assert lyap["duration"] == pytest.approx(0.2 * period, rel=1e-12)
    assert lyap["exponents_per_revolution"] == pytest.approx(
        [x * period for x in lyap["exponents_per_s"]], rel=1e-12)  # fmt: skip
    assert (out / "lyapunov_benettin.png").exists()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["poincare"]["kind"] == "angle"  # once per turn, through the impacts' resets


def test_the_last_revolution_of_a_slower_crank_is_a_whole_revolution():
    """The summaries (indicated power, valve impacts a revolution, the pin reversal) read
    the record's last revolution. A motor turns slower than ``omega`` by its slip: a window
    sized by ``omega`` would cover only 90 % of a revolution of a crank at 0.9 omega, and
    the power would be ``omega`` times the work. Synthetic record, theta1 = 0.9 omega t:
    the window covers a whole turn, and the mean speed is 0.9 omega (to rounding) with a
    motor, ``omega`` with the prescribed drive."""
    import xarray as xr

    from recipdyn.model.cycle import last_revolution, mean_speed

    omega, fs = 20.0, 5000.0
    t = np.arange(int(3 * 2 * math.pi / (0.9 * omega) * fs)) / fs
    ds = xr.Dataset({"theta1": ("time", 0.9 * omega * t)}, coords={"time": t})
    part = last_revolution(ds, omega)
    th = part["theta1"].values
    assert th[-1] - th[0] >= 2 * math.pi
    assert th[-1] - th[0] < 2 * (2 * math.pi)  # a window, not the whole record
    values = {"omega": omega, "drive": "motor"}
    assert mean_speed(values, ds) == pytest.approx(0.9 * omega, rel=1e-9)
    assert mean_speed({**values, "drive": "prescribed"}, ds) == omega


@pytest.mark.slow
def test_generated_share_of_an_ideal_crank_pin_is_up_to_date():
    """``_compressor_contact_share.py`` (the rod's and crosshead's mass matrix with an ideal
    crank pin, for a machine of several throws on a motor) is what ``python -m
    recipdyn.model.compressor_contact`` writes (sympy, ~15 s)."""
    from pathlib import Path

    from recipdyn.model import compressor_contact

    committed = Path(compressor_contact.__file__).with_name("_compressor_contact_share.py")
    assert committed.read_text() == compressor_contact.generate_share()
