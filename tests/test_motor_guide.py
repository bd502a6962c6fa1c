"""The motor drive with the guide's clearance (issue 30): the crank angle and speed as states
of the contact joints' glue with the crosshead moving between the guide's shoes.

* two derivations: the free-crank equations with the guide (`free_crank_lagrangian(...,
  guide=True)`) held at theta1'' = 0 are the prescribed-crank guide equations;
* the flywheel limit: as ``J_drive`` grows the run approaches the prescribed-speed run with
  the same guide, the speed ripple and every difference falling like ``1 / J_drive``;
* the energy balance: the motor's work is the mechanism's and the drive's energy change plus
  the work done on the gas plus the losses in the joints and at the guide's shoes;
* the command line: simulate, rerun from the record, analyze (Benettin refused).
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

#: Both pins ideal, the crosshead in its guide (the default: no clearance, its corners on the
#: shoes; the side force moves it by the shoes' compliance).
IDEAL_GUIDE = {"guide": "clearance", "crank_joint": "ideal"}
#: A worn crank pin whose journal separates and impacts (150 rad/s, a tenth of the paper's
#: load: the contact model's event example) and a worn guide (0.2 mm) the crosshead crosses.
CRANK_GUIDE = {"guide": "clearance", "crank_joint": "contact", "guide_clearance": 2e-4,
               "omega": 150.0, "load_amplitude": 2e4}  # fmt: skip


def _simulate(params, **kw):
    with warnings.catch_warnings():  # (deep contacts of a cold start)
        warnings.simplefilter("ignore", ModelValidityWarning)
        warnings.simplefilter("ignore", LawRangeWarning)
        return recipdyn.simulate(model=get_model("compressor"), params=params, **kw)


@pytest.mark.parametrize("joints", ["crank", "crosshead", "both", "ideal"])
def test_free_crank_guide_equations_reduce_to_the_prescribed_ones(joints):
    """Two derivations: the free-crank Lagrangian with the guide (coordinates theta1, e...,
    yg) with the crank torque that holds theta1'' = 0 gives the eccentricities' and the
    crosshead's lateral accelerations of the prescribed-crank guide Lagrangian
    (`compressor_contact.lagrangian(joints, guide=True)`, theta1 = theta1_0 + omega t) at the
    same crank angle and speed: 30 random states, joint and guide forces, torques and
    geometries, to 1e-8 relative (rounding of M^-1 b with condition numbers up to ~1e5)."""
    from recipdyn.model import _compressor_contact as pres
    from recipdyn.model import _compressor_contact_drive as free
    from recipdyn.model.joints.pins import NHEAD

    rng = np.random.default_rng(31)
    n_q = {"crank": 2, "crosshead": 2, "both": 4, "ideal": 0}[joints] + 1
    f_free = getattr(free, f"{joints}_guide_free_accelerations")
    f_pres = getattr(pres, f"{joints}_guide_accelerations")
    for _ in range(30):
        r, l = rng.uniform(0.05, 0.2), rng.uniform(0.6, 1.5)
        p = np.zeros(NHEAD)
        p[:10] = (r, l, rng.uniform(0.2, 0.5) * l, rng.uniform(5, 50), rng.uniform(5, 50),
                  rng.uniform(0.1, 2.0), 9.81, rng.uniform(-1e-3, 1e-3), 0.0, 0.0)  # fmt: skip
        th1, w, t = rng.uniform(-np.pi, np.pi), rng.uniform(5, 50), rng.uniform(0, 0.1)
        p[8], p[9] = w, th1 - w * t  # the prescribed crank passes theta1 at t with omega
        q = rng.uniform(-1e-3, 1e-3, n_q)
        qd = rng.uniform(-0.1, 0.1, n_q)
        forces = tuple(rng.uniform(-1e4, 1e4, 6))
        f3y = rng.uniform(-1e4, 1e4)
        s1, c1 = math.sin(th1), math.cos(th1)
        ic, sc = rng.uniform(1, 1e3), rng.uniform(0, 5)

        def accel(tc, state=(th1, *q, w, *qd), u=(*forces,), rest=(ic, sc, f3y, s1, c1), p=p):
            return f_free(0.0, state, p, (*u, tc, *rest))

        a0, a1 = accel(0.0)[0], accel(1e4)[0]
        held = accel(-a0 * 1e4 / (a1 - a0))
        assert abs(held[0]) <= 1e-8 * max(1.0, abs(a0))
        ref = f_pres(t, (*q, *qd), p, (*forces, f3y, s1, c1))
        for k in range(n_q):
            assert held[1 + k] == pytest.approx(ref[k], rel=1e-8, abs=1e-8 * max(map(abs, ref)))


def _flywheel_limit(base, keys):
    """The runs of ``base`` with a motor of constant torque and J_drive = 3e4, 3e5, 3e6 kg m^2
    against the prescribed-speed run, over a quarter revolution (the impacts' and the
    knocks' times shift with the speed: a long trajectory is not compared). Checks what
    tests/test_motor_drive.py checks for the pins, with the guide in the bounds:

    * the speed ripple delta = max|omega1 - omega| / omega falls like 1 / J (x0.1 a decade);
    * crank angle: |theta1 - omega t| <= delta theta_run;
    * crosshead: x3 = B_x + l cos theta2 - e2_x with l sin theta2 = yg + e2_y - d - B_y, so
      to first order |dx3| <= r (1 + tan theta2_max) |d theta1| + |d e_x| + tan theta2_max
      (|d e_y| + |d yg|) (a rigid crank pin: e = 0), tan theta2_max from the largest |sin
      theta2| of the run;
    * every difference in ``keys`` (the guide's lateral position and tilt among them; a
      rigid pin's eccentricity is 0 in both runs) falls by 0.05-0.2 per decade of J.

    The integration error (rtol 1e-11) is below 1e-4 of the smallest difference compared.
    Returns the rows (delta, differences) for the report."""
    kw = dict(revolutions=0.25, fs=20_000.0, rtol=1e-11, atol=1e-13)
    ref = _simulate(base, **kw)
    p = get_model("compressor").parameters(base)
    r, w = float(p["r"]), float(p["omega"])
    s2 = float(np.max(np.abs(np.sin(ref.theta2.values))))
    tan2 = s2 / math.sqrt(1.0 - s2 * s2)
    theta_run = w * float(ref.time.values[-1] - ref.time.values[0])
    rows = []
    for J in (3e4, 3e5, 3e6):
        ds = _simulate({**base, "drive": "motor", "motor": "constant", "J_drive": J}, **kw)
        assert np.array_equal(ds.time.values, ref.time.values)
        assert ds.sizes.get("impact_event", 0) == ref.sizes.get("impact_event", 0)
        err = {k: float(np.max(np.abs(ds[k].values - ref[k].values)))
               for k in {*keys, "theta1", "x", "ex", "ey", "guide_y"}}  # fmt: skip
        delta = float(np.max(np.abs(ds.omega1.values - w))) / w
        assert err["theta1"] <= delta * theta_run * (1 + 1e-6), (J, err, delta)
        bound_x = (r * (1 + tan2) * err["theta1"] + err["ex"] + tan2 * (err["ey"]
                   + err["guide_y"]))  # fmt: skip
        assert err["x"] <= 1.01 * bound_x, (J, err["x"], bound_x)
        rows.append((delta, err))
    for (d0, e0), (d1, e1) in zip(rows, rows[1:]):  # noqa: B905 (pairs)
        assert 0.08 < d1 / d0 < 0.12, (d0, d1)
        for k in keys:
            assert 0.05 < e1[k] / e0[k] < 0.2, (k, e0[k], e1[k])
    return rows


def test_huge_flywheel_approaches_the_prescribed_run_with_ideal_pins_in_the_guide():
    """`_flywheel_limit` with both pins ideal and the paper's load: the crosshead pressed on
    its shoes by the side force, its lateral position and tilt the shoes' compliance."""
    _flywheel_limit(IDEAL_GUIDE, ("theta1", "x", "a", "gas_force", "guide_y", "tilt"))


def test_huge_flywheel_approaches_the_prescribed_run_with_a_worn_pin_in_a_worn_guide():
    """`_flywheel_limit` with the crank pin's journal impacting in its bearing and the
    crosshead crossing a 0.2 mm guide clearance."""
    ref = _simulate(CRANK_GUIDE, revolutions=0.25, fs=20_000.0, rtol=1e-11, atol=1e-13)
    assert ref.sizes["impact_event"] >= 4  # the check crosses impacts
    _flywheel_limit(CRANK_GUIDE, ("theta1", "x", "a", "gas_force", "guide_y", "tilt", "ex",
                                  "ey"))  # fmt: skip


@pytest.mark.parametrize("kw", [
    {**IDEAL_GUIDE, "motor": "constant", "guide_clearance": 2e-4, "guide_friction": 0.2},
    {**CRANK_GUIDE, "motor": "constant", "friction": 0.1, "guide_friction": 0.2},
    # (the matrix's CI cell with the motor and the guide: the same glue)
    pytest.param({"guide": "clearance", "crank_joint": "contact", "load": "valves",
                  "guide_clearance": 2e-4}, marks=pytest.mark.slow),
], ids=["ideal-pins-worn-guide", "crank-impacts-friction", "contact-valves"])  # fmt: skip
def test_energy_balance_with_the_guide_closes(kw):
    """Invariant: the motor's work is the change of the energy of crank, drive, rod and
    crosshead (its lateral motion and tilt too, with the pins' and the shoes' elastic
    energy) plus the work done on the gas plus the energy lost in the joints and at the
    shoes (contact damping, friction, the oil film): W_motor = dE - W_gas + W_loss. The
    residual is the integrator's global error: at most the sum of the steps' local errors,
    n_steps rtol max(|E|, |W|); the bound is that estimate. The shoes' losses are real (the
    lost work exceeds the pins' alone, which the record gives where a pin is worn)."""
    ds = _simulate({**kw, "drive": "motor"}, revolutions=0.5, fs=5000.0)
    E, Wm, Wg, Wl = (ds[k].values for k in ("energy", "W_motor", "W_gas", "W_loss"))
    assert np.max(np.abs(Wm)) > 1e3 and Wl[-1] - Wl[0] > 0.0
    assert ds.guide_contact.values.max() == 1.0  # the crosshead touches its shoes
    residual = np.max(np.abs((Wm - Wm[0]) - (E - E[0]) + (Wg - Wg[0]) - (Wl - Wl[0])))
    scale = max(np.max(np.abs(E)), np.max(np.abs(Wm)), np.max(np.abs(Wg)))
    bound = float(ds.attrs["solver_nsteps"]) * float(ds.attrs["solver_rtol"]) * scale
    assert residual < bound, (residual, bound)


def test_the_command_line_runs_and_analyses_a_motor_with_the_guide(tmp_path, capsys):
    """``recipdyn simulate --set guide=clearance --set crank_joint=ideal --set drive=motor``:
    the record holds the selectors and the guide's and the crank's signals, reruns to the
    bit from itself (``simulate -c``) and ``analyze`` reads it (Benettin's exponents refused
    with the reason)."""
    import xarray as xr

    rec = tmp_path / "r.nc"
    # (2.2 revolutions: on 1.1 the signal analysis of the shoes' ringing acceleration asks
    # for more samples than the record has, with a prescribed crank as well)
    args = ["-n", "2.2", "--fs", "2 kHz", "--no-progress", "--no-figure"]
    assert main(["simulate", "--set", "guide=clearance", "--set", "crank_joint=ideal",
                 "--set", "drive=motor", "--set", "motor=constant", "-o", str(rec),
                 *args]) == 0  # fmt: skip
    ds = xr.open_dataset(rec).load()
    assert ds.attrs["param_drive"] == "motor" and ds.attrs["param_guide"] == "clearance"
    for k in ("omega1", "motor_torque", "W_motor", "W_gas", "W_loss", "guide_y", "tilt",
              "shoe_force_upper", "a"):  # fmt: skip
        assert k in ds and np.all(np.isfinite(ds[k].values)), k
    again = tmp_path / "again.nc"
    assert main(["simulate", "-c", str(rec), "-o", str(again), *args]) == 0
    ds2 = xr.open_dataset(again).load()
    for k in ("theta1", "omega1", "guide_y", "a"):
        assert np.array_equal(ds[k].values, ds2[k].values), k
    capsys.readouterr()
    out = tmp_path / "an"
    assert main(["analyze", str(rec), "-o", str(out), "--section-points", "3",
                 "--lyap-revolutions", "1"]) == 0  # fmt: skip
    summary = json.loads((out / "summary.json").read_text())
    assert "guide = 'clearance'" in summary["lyapunov_equations"]["refused"]


def test_the_compressor_guide_preset_with_a_motor_runs_on_the_contact_joints_glue():
    """`compressor-guide` (ideal pins in a worn guide) runs on the contact joints' kernels
    with the crank prescribed and with ``drive = motor`` (the crank free) alike (routing and
    states only: the runs are above; its former kernel of its own is the reference model
    ``compressor-guide-reference``)."""
    m = get_model("compressor-guide")
    assert m.route(m.parameters())[0] == "contact"
    values = m.parameters({"drive": "motor"})
    assert m.route(values)[0] == "contact"
    assert (values["guide"], values["drive"]) == ("clearance", "motor")
    names = [k for k, _ in m.states(values)]
    assert names[-3:] == ["theta1", "omega1", "W_motor"] and len(names) == 12 + 8 + 3
