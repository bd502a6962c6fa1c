"""Adding a component is one file (issue 30, item 6): a load and a motor torque law from
``tests/plugin_components.py`` (the test suite's own file, recipdyn untouched) run through
simulate, analyze, a rerun from the record and a sweep. The joints are not components yet
(the contact joint is its own model), so the second component is a torque law."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from recipdyn.cli import main
from recipdyn.errors import ParameterError
from recipdyn.model._generated import clearance_acceleration
from recipdyn.model.registry import get_model

HERE = Path(__file__).parent
FILE = HERE / "plugin_components.py"
HARMONIC = f"{FILE.resolve()}:HARMONIC"
LINEAR = f"{FILE.resolve()}:LINEAR"


def _harmonic(th1, A, k, phi):
    return -A * (1.0 + np.cos(k * th1 + phi))


def test_a_load_from_a_users_file_is_wired_to_its_own_slice(rng, monkeypatch):
    """Hypothesis: the user's load enters the schema with its fragment and the glue calls it
    with its own offset: theta_c'' of the assembled kernel equals the reduced equation with
    the force computed here in numpy (same arithmetic up to the cosine's last ulp: rel
    1e-12). A relative path is stored absolute (records and workers find the file)."""
    m = get_model("compressor")
    monkeypatch.chdir(HERE)
    v = m.parameters(load="plugin_components.py:HARMONIC", harmonic_amplitude=3e4,
                     harmonic_order=2.0, harmonic_phase=0.5, rc=2e-3, omega=31.0,
                     theta1_0=0.4)  # fmt: skip
    assert v["load"] == HARMONIC and v["harmonic_order"] == 2.0
    assert m.schema_for(v)["harmonic_amplitude"].unit == "N"
    assert "harmonic_amplitude" not in m.schema  # the registered schema stays the paper's
    system = m.system(v)
    for _ in range(20):
        t = float(rng.uniform(0.0, 0.5))
        y = np.array([rng.uniform(-math.pi, math.pi), rng.normal(0.0, 50.0)])
        th1 = 0.4 + 31.0 * t
        F = float(_harmonic(th1, 3e4, 2.0, 0.5))
        ref = clearance_acceleration(th1, y[0], y[1], F, 0.12, 0.6, 0.3, 20.0, 30.0, 0.6, 9.81,
                                     2e-3, 1e-3, 31.0)  # fmt: skip
        assert system.f(t, y)[1] == pytest.approx(ref, rel=1e-12, abs=1e-9)
    attrs = m.record_attrs(v)
    assert attrs["param_harmonic_amplitude"] == 3e4 and attrs["param_load"] == HARMONIC
    assert m.values_from_record(attrs) == v


def test_refusals_name_the_family_and_the_reason():
    """A spec that is not a component of the family, or a missing file, is refused in one
    line; a user's load with the constant torque law needs its torque (the default, the mean
    load torque, is computed for recipdyn's own loads only)."""
    m = get_model("compressor")
    with pytest.raises(ParameterError, match="motor component, not a load component"):
        m.parameters(load=LINEAR)
    with pytest.raises(ParameterError, match="is int, not a load component"):
        m.parameters(load=f"{FILE}:NOT_A_COMPONENT")
    with pytest.raises(ParameterError, match="load component .*not found"):
        m.parameters(load="nothere.py:X")
    with pytest.raises(ParameterError, match="motor_torque: needed"):
        m.parameters(load=HARMONIC, drive="motor", motor="constant")
    assert m.parameters(load=HARMONIC, drive="motor", motor="constant", motor_torque=4e3)


def test_a_torque_law_from_a_users_file_drives_the_crank():
    """The user's torque law runs the free crank: the recorded motor torque is its line
    ``c (w_s - w)`` at the recorded speed (rel 1e-9: the torque is recovered as the work
    rate over the speed), and the energy balance E - E0 = W_motor + W_gas closes (the
    massless link dissipates nothing; measured 1e-13..1e-9 of the largest work for the
    built-in laws at rtol 1e-10, bound 1e-7)."""
    import recipdyn

    ds = recipdyn.simulate(drive="motor", motor=LINEAR, linear_slope=3e4,
                           linear_sync_speed=20.5, revolutions=2, fs=2000.0)  # fmt: skip
    assert ds.attrs["param_motor"] == LINEAR and ds.attrs["param_linear_slope"] == 3e4
    w = ds.omega1.values
    assert np.allclose(ds.motor_torque.values, 3e4 * (20.5 - w), rtol=1e-9, atol=1e-6)
    assert np.ptp(w) > 0  # the crank's speed moves under the load
    E, Wm, Wg = ds.energy.values, ds.W_motor.values, ds.W_gas.values
    scale = max(np.abs(Wm).max(), np.abs(Wg).max())
    assert np.abs(E - E[0] - Wm - Wg).max() < 1e-7 * scale


def test_a_users_load_through_simulate_analyze_rerun_and_sweep(tmp_path, monkeypatch, capsys):
    """The load from the test suite's file through the command line: simulate (the record
    stores the component's spec and its parameters with units; its gas force is the
    component's), analyze and ``simulate -c`` from another folder, and a sweep of the
    component's own parameter in worker processes, whose peak at the simulated point is
    the simulated run's (the same samples: chunks never change results)."""
    a, b = tmp_path / "a.nc", tmp_path / "b.nc"
    monkeypatch.chdir(HERE)
    run = ["-n", "2", "--fs", "2 kHz", "--no-progress"]
    assert main(["simulate", "--set", "load=plugin_components.py:HARMONIC",
                 "--set", "harmonic_amplitude=40 kN", *run, "-o", str(a),
                 "--no-figure"]) == 0  # fmt: skip
    da = xr.open_dataset(a)
    assert da.attrs["param_load"] == HARMONIC
    assert da.attrs["param_harmonic_amplitude"] == 4e4
    assert da.attrs["param_harmonic_amplitude_units"] == "N"
    F = _harmonic(da.theta1.values, 4e4, 1.0, 0.3)
    assert np.allclose(da.gas_force.values, F, rtol=1e-12, atol=1e-7)
    monkeypatch.chdir(tmp_path)
    assert main(["analyze", str(a), "-o", str(tmp_path / "an"), "--section-points", "20",
                 "--lyap-revolutions", "5"]) == 0  # fmt: skip
    summary = json.loads((tmp_path / "an" / "summary.json").read_text())
    assert "lyapunov_equations" in summary and summary["poincare"]["points"] == 20
    assert main(["simulate", "-c", str(a), "-o", str(b), "--no-figure", "--no-progress"]) == 0
    db = xr.open_dataset(b)
    for k in da.data_vars:
        assert np.array_equal(da[k].values, db[k].values), k
    capsys.readouterr()
    assert main(["sweep", "--set", f"load={HARMONIC}", "-p", "harmonic_amplitude=20kN,40kN",
                 "-m", "peak", "--revolutions", "2", "--transient", "0", "--fs", "2 kHz",
                 "--workers", "2", "-o", str(tmp_path / "sw"), "--no-progress"]) == 0  # fmt: skip
    from recipdyn.sweep import open_sweep

    sw = open_sweep(tmp_path / "sw" / "sweep.zarr").load()
    assert list(sw["error"].values) == ["", ""]
    assert sw.attrs["param_load"] == HARMONIC
    assert sw["peak_a"].values[1] == pytest.approx(float(np.abs(da.a.values).max()), rel=1e-12)
    assert sw["peak_a"].values[0] != sw["peak_a"].values[1]
