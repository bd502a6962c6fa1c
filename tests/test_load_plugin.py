"""A load of the user's own file at the contact and lubricated pins and in the worn guide
(issue 30): the loads of ``tests/plugin_components.py`` (the test suite's own file, recipdyn
untouched), chosen by ``load = file.py:OBJ``, run by the contact joints' generated glue with
their own slice of the parameter vector, with the prescribed crank and with a motor, through
the model, simulate, analyze, a rerun from the record and a sweep.

The massless link's runs of the same file are ``tests/test_plugin_components.py``'s."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import recipdyn
from recipdyn.cli import main
from recipdyn.errors import ParameterError
from recipdyn.integrate import integrate
from recipdyn.model.components.contact_model import N_CRANK
from recipdyn.model.joints.pins import N_PACKED
from recipdyn.model.registry import get_model

HERE = Path(__file__).parent
FILE = HERE / "plugin_components.py"
HARMONIC = f"{FILE.resolve()}:HARMONIC"
SPRING = f"{FILE.resolve()}:SPRING"
PAPER_AGAIN = f"{FILE.resolve()}:PAPER_AGAIN"
CHAMBER = f"{FILE.resolve()}:CHAMBER"
M = get_model("compressor")


def _harmonic(th1, A=5.0e4, k=1.0, phi=0.3):
    return -A * (1.0 + np.cos(k * th1 + phi))


def _spring(th1, p0=2.0e4, k=1.5):
    return -p0 * (1.0 + k * (1.0 - np.cos(th1)))


#: Where a load of one's own runs beyond the massless link: the configuration, the load, its
#: values, and the law in numpy. 150 rad/s with a few tens of kN: the journal leaves the
#: wall and impacts (the joints are exercised, not only held on the wall).
CASES = {
    "contact crank pin": (dict(crank_joint="contact", omega=150.0), HARMONIC,
                          dict(harmonic_amplitude=2e4, harmonic_order=2.0),
                          lambda th: _harmonic(th, 2e4, 2.0)),
    "lubricated crosshead pin": (dict(crank_joint="ideal", crosshead_joint="lubricated",
                                      omega=150.0), SPRING, {}, _spring),
    "contact crank pin, motor": (dict(crank_joint="contact", drive="motor", omega=20.0),
                                 HARMONIC, {}, _harmonic),
    "guide clearance": (dict(guide="clearance", crank_joint="ideal", omega=150.0), SPRING,
                        dict(spring_rate=0.5), lambda th: _spring(th, 2e4, 0.5)),
}  # fmt: skip
#: ... and with the motor in the worn guide (ideal pins; not in CI: one more glue to compile)
MORE = {
    "guide clearance, motor": (dict(guide="clearance", crank_joint="ideal", drive="motor",
                                    motor="constant", motor_torque=1000.0, omega=20.0),
                               HARMONIC, {}, _harmonic),
}  # fmt: skip


@pytest.mark.filterwarnings("ignore::recipdyn.errors.LawRangeWarning")
@pytest.mark.parametrize("case", [*CASES, *(pytest.param(k, marks=pytest.mark.exhaustive)
                                            for k in MORE)])  # fmt: skip
def test_a_users_load_runs_at_every_joint_and_in_the_worn_guide(case):
    """Hypothesis: the glue calls the user's compiled force at its own slice, on the crank
    angle the run integrates (with a motor, the crank's state, not omega t). The recorded gas
    force, from the compiled observer, equals the law written here in numpy on the recorded
    crank angle to rounding (the same operations; numpy's cosine and the compiled one may
    differ in the last ulp: rel 1e-12 of the force's scale). The record holds the load's spec,
    absolute, and its parameters with units; the energy balance closes (test_contact's bound,
    1e-7 of the energy: the load's work enters W_in through the same force)."""
    pins, spec, own, law = {**CASES, **MORE}[case]
    kw = {**pins, "load": spec, **own}
    v = M.parameters(kw)
    assert M.route(v)[0] == "contact" and v["load"] == spec
    ds = recipdyn.simulate(**kw, revolutions=0.5 if pins["omega"] > 100 else 0.1,
                           fs=20_000.0)  # fmt: skip
    th, F = ds["theta1"].values, ds["gas_force"].values
    ref = law(th)
    scale = np.abs(ref).max()
    np.testing.assert_allclose(F, ref, rtol=0.0, atol=1e-12 * scale)
    assert np.ptp(F) > 0.1 * scale  # the force moves with the crank
    assert ds.attrs["param_load"] == spec
    name = next(q for q in ("harmonic_amplitude", "spring_preload") if f"param_{q}" in ds.attrs)
    assert ds.attrs[f"param_{name}_units"] == "N"
    assert ds.attrs["energy_balance_residual"] < 1e-7
    if pins.get("drive") == "motor":  # the crank's own angle: its speed moves under the load
        assert np.ptp(ds["omega1"].values) > 1e-4 * pins["omega"]
    if pins.get("guide") == "clearance":  # the crosshead knocks in its guide
        assert np.abs(ds["guide_y"].values).max() > 0.0


def _run(values, t_end, n=201):
    s = M.system(values)
    return s, integrate(s, M.initial_state(values), (0.0, t_end),
                        t_eval=np.linspace(0.0, t_end, n))  # fmt: skip


@pytest.mark.parametrize("drive", ["prescribed", "motor"])
def test_the_paper_load_from_a_file_gives_the_builtins_trajectory_to_the_bit(drive):
    """Hypothesis: a load of a user's file enters the glue exactly where a built-in one does.
    The file's ``PAPER_AGAIN`` is recipdyn's paper load under another name (the same compiled
    functions, the same slice): its glue differs from ``load = paper``'s only in the module
    it is named from and a comment holding the file's hash, so numba compiles the same
    operations and half a revolution with impacts at a contact crank pin (150 rad/s, a tenth
    of the paper's load) gives the same states, event times and step count to the bit, with
    the prescribed crank and with a motor (a tenth of a revolution at 20 rad/s: the crank's
    state free)."""
    base = dict(crank_joint="contact", omega=150.0, load_amplitude=2e4, drive=drive)
    if drive == "motor":
        base.update(omega=20.0, load_amplitude=2e5)
    v0 = M.parameters(base)
    v1 = M.parameters({**base, "load": PAPER_AGAIN})
    assert v1["load"] == PAPER_AGAIN
    assert np.array_equal(M.system(v0).params, M.system(v1).params)
    T = M.period(v0)
    _, a = _run(v0, (0.5 if drive == "prescribed" else 0.1) * T)
    _, b = _run(v1, (0.5 if drive == "prescribed" else 0.1) * T)
    if drive == "prescribed":
        assert a.t_events.size >= 3  # impacts happen
    assert np.array_equal(a.y, b.y) and np.array_equal(a.t_events, b.t_events)
    assert a.nfev == b.nfev
    o0, o1 = M.outputs(v0, a.t, a.y), M.outputs(v1, b.t, b.y)
    for k in ("gas_force", "normal_force", "a"):
        assert np.array_equal(o0[k].values, o1[k].values), k


def test_a_constant_torques_default_is_the_users_loads_mean_torque():
    """With ``motor = constant`` and no ``motor_torque`` the contact joints' crank gets the
    mean load torque of the ideal mechanism under the user's load (its compiled force on its
    slice): against the mean of ``-F dx3/dtheta1`` over a revolution computed here in numpy
    from the law (a periodic integrand: the mean of 4096 equal steps is exact to rounding;
    the model's 7200 steps likewise: rel 1e-9)."""
    v = M.parameters(crank_joint="contact", drive="motor", motor="constant", load=HARMONIC)
    T = M.system(v).params[N_PACKED + N_CRANK]  # the torque law's slice, after the crank's
    th = np.linspace(0.0, 2.0 * math.pi, 4096, endpoint=False)
    r, l, d = v["r"], v["l"], v["d"]
    u = d + r * np.sin(th)
    dx3 = -r * np.sin(th) - u * r * np.cos(th) / np.sqrt(l * l - u * u)
    ref = float(-np.mean(_harmonic(th) * dx3))
    # (~ A r sin(phi) / 2 = 890 N m: the phase makes the force do net work on the crank)
    assert T == pytest.approx(ref, rel=1e-9) and abs(ref) > 500.0


def test_a_users_load_is_refused_where_it_cannot_run():
    """One line each: a load with states but no initial states, one with states on the
    massless link (whose model holds no load states but the valves'), a load table beside a
    load of one's own, an object that is not a load, and a parameter of the load's out of its
    range. (The guide's clearance with a motor runs: `MORE`.)"""
    for kw, words in (
        (dict(crank_joint="contact", load=f"{FILE}:WITH_STATES"),
         "has states but provides no initial"),
        (dict(load=CHAMBER), "with states runs at a contact or lubricated pin"),
        (dict(load=CHAMBER, drive="motor"), "with states runs at a contact or lubricated pin"),
        (dict(crank_joint="contact", load=SPRING, load_table=((0, 1.0), (180, 2.0))),
         "load_table: not with load"),
        (dict(crank_joint="contact", load=f"{FILE}:KELVIN_VOIGT"),
         "is a contact_law component, not a load component"),
        (dict(crank_joint="lubricated", load=SPRING, spring_rate=-1.0), "spring_rate"),
    ):  # fmt: skip
        with pytest.raises(ParameterError) as exc:
            M.parameters(kw)
        assert words in str(exc.value) and "\n" not in str(exc.value), str(exc.value)


def test_a_users_load_at_a_contact_pin_through_simulate_analyze_rerun_and_sweep(
        tmp_path, monkeypatch, capsys):  # fmt: skip
    """The load from the test suite's file at a contact crank pin through the command line:
    simulate (the record stores the spec, absolute, and the load's parameters with units),
    analyze from another folder (Benettin's exponents on the glue with the file's load),
    ``simulate -c`` from the record (the same samples), and a 2-point sweep of the load's own
    parameter in worker processes whose peak at the simulated point is the simulated run's
    (the same samples: chunks never change results) and differs at the other."""
    a, b = tmp_path / "a.nc", tmp_path / "b.nc"
    monkeypatch.chdir(HERE)
    run = ["-n", "1", "--fs", "20 kHz", "--no-progress"]
    assert main(["simulate", "--set", "crank_joint=contact", "--set",
                 "load=plugin_components.py:HARMONIC", "--set", "harmonic_amplitude=20 kN",
                 "--set", "harmonic_order=2", "--set", "omega=150", *run, "-o", str(a),
                 "--no-figure"]) == 0  # fmt: skip
    da = xr.open_dataset(a)
    assert da.attrs["param_load"] == HARMONIC
    assert da.attrs["param_harmonic_amplitude"] == 2e4
    assert da.attrs["param_harmonic_amplitude_units"] == "N"
    ref = _harmonic(da.theta1.values, 2e4, 2.0)
    np.testing.assert_allclose(da.gas_force.values, ref, rtol=0, atol=1e-12 * 4e4)
    monkeypatch.chdir(tmp_path)
    assert main(["analyze", str(a), "-o", str(tmp_path / "an"), "--section-points", "3",
                 "--lyap-revolutions", "0.2"]) == 0  # fmt: skip
    summary = json.loads((tmp_path / "an" / "summary.json").read_text())
    assert summary["poincare"]["points"] == 3 and "lyapunov_equations" in summary
    assert main(["simulate", "-c", str(a), "-o", str(b), "--no-figure", "--no-progress"]) == 0
    db = xr.open_dataset(b)
    for k in da.data_vars:
        assert np.array_equal(da[k].values, db[k].values), k
    capsys.readouterr()
    assert main(["sweep", "--set", "crank_joint=contact", "--set", f"load={HARMONIC}",
                 "--set", "harmonic_order=2", "--set", "omega=150",
                 "-p", "harmonic_amplitude=20kN,30kN", "-m", "peak", "--revolutions", "1",
                 "--transient", "0", "--fs", "20 kHz", "--workers", "2",
                 "-o", str(tmp_path / "sw"), "--no-progress"]) == 0  # fmt: skip
    from recipdyn.sweep import open_sweep

    sw = open_sweep(tmp_path / "sw" / "sweep.zarr").load()
    assert list(sw["error"].values) == ["", ""]
    assert sw.attrs["param_load"] == HARMONIC
    assert sw["peak_a"].values[0] == pytest.approx(float(np.abs(da.a.values).max()), rel=1e-12)
    assert sw["peak_a"].values[0] != sw["peak_a"].values[1]


@pytest.mark.filterwarnings("ignore::recipdyn.errors.LawRangeWarning")
@pytest.mark.parametrize("case", list(CASES))
def test_a_users_load_with_states_runs_at_every_joint_and_in_the_worn_guide(case):
    """A load with a state of the file's own (`CHAMBER`: a closed gas chamber over the
    crosshead, compressed polytropically, with a relief valve, an event of the load that
    vents it) at the same configurations, started at inner dead centre. Hypotheses: its
    state follows the crosshead of the joints' own state, and its event and reset share the
    event function with the joints. Checked on the record:

    * the invariant of the polytrope, ``p (x_top - x3)^n``, is constant between the load's
      events, on the recorded crosshead position (relative spread below 1e-7, a thousand
      times the solver's rtol: the accumulated local errors; measured 2.7e-10 at most);
    * the relief valve acts once in the revolution, at its set pressure (event location:
      rel 1e-8) and vents to the vent pressure exactly; the summary counts it as the load's
      event, not as an impact;
    * the recorded gas force is ``-(p - p_frame) A`` of the recorded pressure, to the bit
      (the same operations on the same state);
    * the energy balance closes (1e-7 of the energy)."""
    pins, *_ = CASES[case]
    kw = {**pins, "load": CHAMBER, "theta1_0": math.pi}
    v = M.parameters(kw)
    assert M.route(v)[0] == "contact" and not M.lyapunov_supported(v)
    assert ("p_chamber", "Pa") in M.states(v)
    ds = recipdyn.simulate(**kw, revolutions=1.0, fs=20_000.0)
    p, x, t = ds["p_chamber"].values, ds["x"].values, ds["time"].values
    A, top, n = v["chamber_area"], v["chamber_top"], v["chamber_n"]
    before, after = ds["impact_p_chamber"].values, ds["impact_p_chamber_after"].values
    mine = before != after
    assert mine.sum() == 1 and ds.attrs["load_events"] == 1.0
    assert before[mine][0] == pytest.approx(v["chamber_relief"], rel=1e-8)
    assert after[mine][0] == v["chamber_vent"]
    te = ds["impact_time"].values[mine][0]
    C = p * (top - x) ** n
    for seg in (t < te, t > te):
        assert np.ptp(C[seg]) < 1e-7 * C[seg].mean()
    vent = v["chamber_vent"] / v["chamber_relief"]
    assert C[t > te].mean() == pytest.approx(vent * C[t < te].mean(), rel=1e-7)
    assert np.array_equal(ds["gas_force"].values, -(p - v["frame_pressure"]) * A)
    assert ds.attrs["energy_balance_residual"] < 1e-7
