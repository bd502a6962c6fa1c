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
    ``analyze`` reads it (Benettin's exponents refused for the valves, with the reason; no
    stroboscopic section for a free crank)."""
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
    assert "poincare" not in summary
