"""simulate(): labelled output, recorded inputs, partial results on failure."""

import dataclasses
import math

import numpy as np
import pytest

from recipdyn import CompressorParams, IntegrationError, ParameterError, simulate
from recipdyn.simulate import params_from_attrs


def test_dataset_records_every_input_and_units(tmp_path):
    p = CompressorParams(rc=0.5e-3, d=2e-3, omega=30.0, theta_c_offset=0.05)
    ds = simulate(p, revolutions=0.5, transient=0.5, fs=4000)
    for f in dataclasses.fields(CompressorParams):
        if f.name != "load_table":
            assert f"param_{f.name}" in ds.attrs
    assert params_from_attrs(ds.attrs) == p
    # the default start: the link aligned with the rod at t = 0 (checked from the closure
    # equation, independently of equilibrium_theta_c), plus the offset
    thc_eq = ds.attrs["theta_c_initial"] - p.theta_c_offset
    th2 = math.asin(-(p.d + p.r * math.sin(p.theta1_0) + p.rc * math.sin(thc_eq)) / p.l)
    assert math.sin(thc_eq - th2) == pytest.approx(0.0, abs=1e-12)
    assert math.cos(thc_eq - th2) == pytest.approx(-1.0)  # gas force toward the crank at t = 0
    assert ds.time.values[0] == pytest.approx(0.5 * p.crank_period)
    assert ds.time.attrs["units"] == "s" and ds.x.attrs["units"] == "m"
    np.testing.assert_allclose(np.diff(ds.time.values), 1 / 4000, rtol=1e-9)
    path = tmp_path / "r.nc"
    ds.to_netcdf(path)
    import xarray as xr

    back = xr.open_dataset(path)
    assert params_from_attrs(back.attrs) == p


def test_failure_keeps_what_was_computed():
    """The printed equations with a large initial offset blow up; the samples computed before
    the failure are returned with the error, not lost."""
    p = CompressorParams(equations="paper-printed", load_sign="paper", theta_c_offset=1.0)
    with pytest.raises(IntegrationError) as info:
        simulate(p, revolutions=2, fs=5000, rtol=1e-9)
    ds = info.value.dataset
    assert ds is not None and ds.sizes["time"] > 10
    assert np.all(np.isfinite(ds.a.values))


def test_bad_settings():
    from recipdyn import ParameterError

    with pytest.raises(ParameterError, match="revolutions"):
        simulate(revolutions=0)
    with pytest.raises(ParameterError, match="fs"):
        simulate(fs=-1.0)
    with pytest.raises(ParameterError, match="unknown parameter"):
        simulate(wobble=1.0)


def test_streamed_record_equals_the_in_memory_one(tmp_path):
    """Memory flat in run length (issue 15): a record streamed block by block to NetCDF or
    Zarr holds exactly the samples of the in-memory run (the block boundaries are progress
    stops of the integrator, which add no steps), with the same attributes."""
    import recipdyn

    kw = dict(revolutions=3.0, fs=20_000.0)
    a = recipdyn.simulate(**kw)
    b = recipdyn.simulate(**kw, out=tmp_path / "s.nc")
    c = recipdyn.simulate(**kw, out=tmp_path / "s.zarr", columns=["x", "a"], float32=True)
    assert b.sizes["time"] == a.sizes["time"] == c.sizes["time"]
    assert np.array_equal(a.time.values, b.time.values)
    assert np.array_equal(a.revolution.values, b.revolution.values)
    for k in a.data_vars:
        assert np.array_equal(a[k].values, b[k].values), k
        assert a[k].attrs["units"] == b[k].attrs["units"]
    assert b.attrs["min_contact_force_N"] == a.attrs["min_contact_force_N"]
    assert b.attrs["solver_nsteps"] == a.attrs["solver_nsteps"]
    assert list(c.data_vars) == ["x", "a"] and c.a.dtype == np.float32
    # the order comes from the store's attribute, not from the file system's listing (which
    # differs between machines): rewriting the attribute reorders the opened record
    import zarr

    from recipdyn.io import ORDER_ATTR, open_record

    assert ORDER_ATTR not in c.attrs
    zarr.open_group(str(tmp_path / "s.zarr"), mode="r+").attrs[ORDER_ATTR] = "a x"
    assert list(open_record(tmp_path / "s.zarr").data_vars) == ["a", "x"]
    # single precision: relative rounding 2**-24 ~ 6e-8 of each value
    assert np.allclose(c.a.values, a.a.values, rtol=1.2e-7, atol=0)
    assert not list(tmp_path.glob(".s.*")), "no temporary store left behind"
    with pytest.raises(ParameterError, match="columns"):
        recipdyn.simulate(revolutions=0.1, columns=["x", "bogus"])


def test_integrate_sink_gets_every_sample_once_in_order():
    """With a sink the outputs arrive in blocks (a window too narrow for the last step is
    redone wider from the saved state): the concatenated blocks equal the stored run, steps
    and all, and no block is larger than needed."""
    from recipdyn.integrate import integrate
    from recipdyn.integrate.solve import UniformGrid
    from recipdyn.model import compressor_model

    m = compressor_model(CompressorParams(omega=40.0))
    T = 2 * np.pi / 40.0
    te = np.linspace(0.0, 5 * T, 20001)
    ref = integrate(m, m.initial_state(), (0.0, te[-1]), t_eval=te)
    for t_eval, block in ((te, 1), (te, 997), (te[::50], 3)):
        blocks = []
        sol = integrate(m, m.initial_state(), (0.0, te[-1]), t_eval=t_eval, block=block,
                        sink=lambda t, y, out=blocks: out.append((t, y.copy())))  # fmt: skip
        t = np.concatenate([b[0] for b in blocks])
        y = np.concatenate([b[1] for b in blocks])
        sel = slice(None) if t_eval is te else slice(None, None, 50)
        assert np.array_equal(t, ref.t[sel]) and np.array_equal(y, ref.y[sel])
        assert sol.nsteps == ref.nsteps and sol.y.shape == (0, 2)
    grid = UniformGrid(0.0, 20001 / te[-1], 3)
    assert np.array_equal(grid[0:3], 0.0 + np.arange(3) / grid.rate)


def test_no_link_no_link_bound(tmp_path):
    """Without clearance (rc = 0) the crank pin is an ideal two-way joint: the massless
    link's bound (it can only push) does not apply, so a reversing pin load (the cycle's
    rod-load reversal with dynamic valves; the paper's load at 1 kN) is not flagged and a
    sweep stores no minimum for it (NaN, so its figure marks nothing); with clearance the same
    reversal is flagged and stored."""
    import warnings

    import recipdyn
    from recipdyn.errors import ModelValidityWarning
    from recipdyn.model.parameters import CompressorParams
    from recipdyn.sweep.run import open_sweep, run_sweep
    from recipdyn.sweep.spec import SweepSpec, parse_axis

    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelValidityWarning)
        for kw in (dict(model="compressor-valves", params={"rc": 0.0}),
                   dict(params=CompressorParams(rc=0.0, load_amplitude=1000.0))):  # fmt: skip
            ds = recipdyn.simulate(revolutions=1.0, fs=5000.0, **kw)
            assert ds.attrs["validity"] == "ok"
            assert float(ds["contact_force"].min()) < 0  # the reversal itself is recorded
    with pytest.warns(ModelValidityWarning):
        recipdyn.simulate(model="compressor-valves", params={"rc": 1e-3}, revolutions=1.0,
                          fs=5000.0)  # fmt: skip
    spec = SweepSpec(axes=(parse_axis("rc=0mm:1mm:2"),), measures=("peak",),
                     base=CompressorParams(load_amplitude=1000.0),
                     settings=dict(revolutions=1, transient=0, fs=5000.0))  # fmt: skip
    sw = open_sweep(run_sweep(spec, tmp_path, backend="serial", progress=False))
    mins = sw["min_contact_force"].values
    assert np.isnan(mins[0]) and mins[1] < 0


def test_negative_contact_force_is_flagged(tmp_path, capsys):
    """A light gas load (1 kN amplitude) lets inertia pull the massless link (min contact
    force about -1.8 kN): simulate warns (ModelValidityWarning, the record's 'validity'
    attribute, one CLI line naming the contact-impact model); the default load does not. A
    sweep over the load amplitude records min_contact_force per point and marks the points
    that cross on its figure."""
    import warnings

    import recipdyn
    from recipdyn.cli import main
    from recipdyn.errors import ModelValidityWarning

    with pytest.warns(ModelValidityWarning, match="compressor-contact"):
        ds = recipdyn.simulate(revolutions=1.0, fs=5000.0, load_amplitude=1000.0)
    assert ds.attrs["min_contact_force_N"] < 0 and "contact_force reaches" in ds.attrs["validity"]
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelValidityWarning)
        assert recipdyn.simulate(revolutions=1.0, fs=5000.0).attrs["validity"] == "ok"
    out = tmp_path / "r.nc"
    assert main(["simulate", "-n", "1", "--set", "load_amplitude=1 kN", "-o", str(out),
                 "--no-figure", "--no-progress"]) == 0  # fmt: skip
    err = capsys.readouterr().err
    assert err.count("warning: contact_force reaches") == 1
    store = tmp_path / "sw"
    assert main(["sweep", "-p", "load_amplitude=1kN,100kN", "-m", "peak", "--revolutions", "1",
                 "--transient", "0", "--backend", "serial", "-o", str(store),
                 "--no-progress"]) == 0  # fmt: skip
    from recipdyn.sweep.run import open_sweep

    sw = open_sweep(store / "sweep.zarr")
    low = sw["min_contact_force"].values
    assert low[0] < 0 < low[1] and sw["min_contact_force"].attrs["units"] == "N"


def test_verdicts_are_withheld_outside_the_models_validity(tmp_path, capsys):
    """Issue 31, item 2: the double-acting compression cycle reverses the rod load, so the
    massless link (rc = 1 mm) is asked to pull (validity crossed). Every verdict computed from
    that run is withheld: the API 618 pin-reversal verdict is 'invalid' with the reason and
    the model to use, in the attributes, the CLI print (no 'pass'/'FAIL' line) and the
    figures (a red title naming the model to use; the rod-load panel says the verdict is
    withheld). The numbers stay (they are what the equations give). With rc = 0 the pin is an
    ideal two-way joint, the bound does not apply, and the same cycle keeps its verdict."""
    import warnings

    import matplotlib.text

    import recipdyn
    from recipdyn.cli import main
    from recipdyn.errors import ModelValidityWarning
    from recipdyn.plotting import cycle_figure, mark_invalid, response_figure

    with pytest.warns(ModelValidityWarning, match="compressor-contact"):
        bad = recipdyn.simulate(load="cycle", revolutions=1.2, fs=5000.0)
    a = bad.attrs
    assert a["validity"] != "ok" and a["api618_pin_reversal"] == "invalid"
    assert "compressor-contact" in a["api618_pin_reversal_reason"]
    assert a["pin_reversal_deg"] > 0.0  # the numbers are kept, only the verdict is withheld
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelValidityWarning)
        good = recipdyn.simulate(load="cycle", rc=0.0, revolutions=1.2, fs=5000.0)
    assert good.attrs["validity"] == "ok" and good.attrs["api618_pin_reversal"] in ("pass", "FAIL")
    assert "api618_pin_reversal_reason" not in good.attrs

    out = tmp_path / "c.nc"
    assert main(["simulate", "--set", "load=cycle", "-n", "1.2", "--fs", "5 kHz", "-o",
                 str(out), "--no-progress"]) == 0  # fmt: skip
    text = capsys.readouterr().out
    assert "api618_pin_reversal = invalid" in text and "compressor-contact" in text
    assert "= pass" not in text and "= FAIL" not in text
    assert out.with_suffix(".png").exists() and out.with_name("c.cycle.png").exists()

    def texts(fig):
        return [t.get_text() for t in fig.findobj(matplotlib.text.Text)]

    for fig in (mark_invalid(cycle_figure(bad), a), mark_invalid(response_figure(bad), a)):
        assert any("INVALID" in t and "compressor-contact" in t for t in texts(fig))
        assert "OUTSIDE THE MODEL'S VALIDITY" in texts(fig)
        assert not any("PASS" in t or "FAIL" in t for t in texts(fig))
    fig = cycle_figure(good)
    before = texts(fig)
    assert any("PASS" in t or "FAIL" in t for t in before)  # a valid run keeps its verdict
    assert texts(mark_invalid(fig, good.attrs)) == before  # and no banner


@pytest.mark.slow
def test_issue31_valves_command_gives_no_api618_verdict(tmp_path, capsys):
    """Issue 31's exact command: air, 20 rad/s, rc = 0.1 mm, dynamic valves. The massless
    link is asked to pull under the reversing rod load (-272 N measured): the run printed
    'api618_pin_reversal = pass'; now the verdict is withheld and the contact-impact model with
    dynamic valves is named."""
    from recipdyn.cli import main

    out = tmp_path / "v.nc"
    assert main(["simulate", "--model", "compressor-valves", "--set", "gas=Air", "--set",
                 "omega=20", "--set", "rc=0.1mm", "-n", "2", "--transient", "2", "-o",
                 str(out), "--no-progress"]) == 0  # fmt: skip
    io = capsys.readouterr()
    assert "api618_pin_reversal = invalid" in io.out and "= pass" not in io.out
    assert "--model compressor-contact-valves" in io.out
    assert io.err.count("warning: contact_force reaches") == 1


def test_a_record_alone_loads_no_plotting_or_distributed_stack(tmp_path):
    """A warm 'simulate --no-figure' writes its record without importing what it does not
    use: dask.array, distributed and pint (xarray's duck-array and scheduler checks, about a
    second of the command; io.lazy_duck_arrays), SciPy's signal and statistics modules, or
    matplotlib. Checked in a fresh interpreter by what it loaded, not by time."""
    import json
    import os
    import subprocess
    import sys

    out = tmp_path / "r.nc"
    probe = (
        "import sys, json\n"
        "from recipdyn.cli import main\n"
        f"code = main(['simulate', '-n', '0.5', '--fs', '2000', '--no-figure', '--no-progress',"
        f" '-o', {str(out)!r}])\n"
        "mods = ('dask.array', 'distributed', 'pint', 'scipy.signal', 'scipy.stats', "
        "'matplotlib')\n"
        "print(json.dumps(dict(code=code, loaded=[m for m in mods if m in sys.modules])))\n"
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run([sys.executable, "-c", probe], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=1200)  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    assert json.loads(done.stdout.strip().splitlines()[-1]) == {"code": 0, "loaded": []}
    assert out.exists()


def test_simulate_without_the_run_summary_records_the_same_signals():
    """``summary=False`` (a data set's records) leaves the run summary out of the attrs and
    nothing else: the signals and the event records, with their units, are those of the
    default run (the summary is computed after the integration, from the recorded
    samples). On a model with reset events, so that the event records are compared too."""
    from recipdyn.simulate import simulate

    a = simulate(model="impact-oscillator", revolutions=3, fs=2000.0)
    b = simulate(model="impact-oscillator", revolutions=3, fs=2000.0, summary=False)
    assert "impact_time" in a and a.sizes["impact_event"] > 0
    assert "summary_interval" in a.attrs and "summary_interval" not in b.attrs
    assert a.drop_attrs(deep=False).identical(b.drop_attrs(deep=False))


def test_a_last_sample_a_rounding_error_past_the_end_is_recorded():
    """Revolutions x period x rate a hair below a whole number of samples (within the 1e-9 of
    a sample that counts it as whole): the last sample lies a rounding error past
    ``revolutions x period``, and the run ends at it rather than refusing its own output
    times as outside the span (met at a crank speed read from a tacho)."""
    fs = 10_000.0
    omega = 4 * math.pi * fs / (6100 - 1e-11)  # 2 revolutions: 6100 - 1e-11 sample intervals
    ds = simulate(model="compressor", omega=omega, revolutions=2, transient=0, fs=fs,
                  summary=False)  # fmt: skip
    assert ds.time.size == 6101
    assert float(ds.time[-1]) == pytest.approx(0.61, abs=1e-12)
