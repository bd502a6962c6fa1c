"""CLI: simulate writes a dataset and a figure; bad input exits with status 2 and names the
parameter and its allowed range."""

import math

import pytest
import xarray as xr

from recipdyn.cli import main
from recipdyn.model import CompressorParams, ParameterError


def test_simulate_writes_dataset_and_figure(tmp_path, capsys):
    out = tmp_path / "run.nc"
    code = main(["simulate", "--rc", "0.5 mm", "--omega", "191 rpm", "-n", "1", "--fs", "2 kHz",
                 "-o", str(out), "--no-progress"])  # fmt: skip
    assert code == 0
    ds = xr.open_dataset(out)
    assert ds.attrs["param_rc"] == pytest.approx(5e-4)
    assert ds.attrs["param_omega"] == pytest.approx(191 * 2 * math.pi / 60)
    assert ds.a.attrs["units"] == "m/s**2"
    assert "assumed" in ds.attrs["param_m2_note"]
    assert ds.attrs["recipdyn_version"]
    assert out.with_suffix(".png").stat().st_size > 10_000
    assert "peak |a|" in capsys.readouterr().out


def test_config_file(tmp_path):
    cfg = tmp_path / "case.toml"
    cfg.write_text('[params]\nclearance = "0.2 mm"\nd = 0\n[simulation]\nrevolutions = 0.5\n'
                   'fs = "1 kHz"\n')  # fmt: skip
    out = tmp_path / "c.nc"
    assert main(["simulate", "-c", str(cfg), "-o", str(out), "--no-figure", "--no-progress"]) == 0
    ds = xr.open_dataset(out)
    assert ds.attrs["param_rc"] == pytest.approx(2e-4)
    assert ds.sizes["time"] == 1 + int(0.5 * 2 * math.pi / 20 * 1000)


@pytest.mark.parametrize(
    "args, words",
    [
        (["--rc", "-1 mm"], ["rc", "allowed"]),
        (["--rc", "0.2 m"], ["rc", "0.12"]),
        (["--d", "0.5 m"], ["d =", "allowed"]),
        (["--omega", "0 rad/s"], ["omega", "allowed"]),
        (["--omega", "nan rad/s"], ["omega"]),
        (["--rc", "1 furlongs_x"], ["rc", "unit"]),
        (["--rc", "1 s"], ["rc", "cannot be converted"]),
        (["--set", "l=-0.6"], ["l", "allowed"]),
        (["--set", "bogus=1"], ["unknown parameter"]),
        (["--method", "euler"], ["method"]),
    ],
)
def test_bad_input_exit_2(tmp_path, capsys, args, words):
    code = main(["simulate", *args, "-o", str(tmp_path / "x.nc"), "--no-figure", "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2
    assert "Traceback" not in err
    for w in words:
        assert w in err


def test_malformed_config_exit_2(tmp_path, capsys):
    cfg = tmp_path / "bad.toml"
    cfg.write_text("[params\nrc = ")
    assert main(["simulate", "-c", str(cfg), "--no-figure"]) == 2
    assert "malformed" in capsys.readouterr().err
    cfg.write_text("[simulation]\nwhatever = 1\n")
    assert main(["simulate", "-c", str(cfg), "--no-figure"]) == 2


def test_parameter_validation_messages():
    for kw in (dict(r=0.0), dict(m2=-1.0), dict(omega=math.inf), dict(rc=math.nan),
               dict(load_sign="up"), dict(equations="mine")):  # fmt: skip
        with pytest.raises(ParameterError, match=next(iter(kw))):
            CompressorParams(**kw)


def test_load_table_from_csv(tmp_path):
    """A user load table (crank angle deg, force N) is used and recorded in the result."""
    csv = tmp_path / "load.csv"
    csv.write_text("angle_deg,force_N\n0,-150000\n90,-40000\n180,-40000\n270,-150000\n")
    out = tmp_path / "t.nc"
    code = main(["simulate", "--set", f"load_table={csv}", "-n", "0.5", "--fs", "1 kHz",
                 "-o", str(out), "--no-figure", "--no-progress"])  # fmt: skip
    assert code == 0
    ds = xr.open_dataset(out)
    assert ds.attrs["param_load_model"] == "table"
    assert float(ds.gas_force[0]) == pytest.approx(-150000.0)
    from recipdyn.simulate import params_from_attrs

    assert params_from_attrs(ds.attrs).load_table[1] == (90.0, -40000.0)


def test_help_and_import_load_no_heavy_library():
    """Start-up (issue 15): 'import recipdyn' and the command-line help must not import numba,
    SciPy, xarray, pint or dask (they cost ~2 s together); the public names still resolve, and
    'recipdyn.simulate' stays the function even after its submodule was imported."""
    import subprocess
    import sys

    code = (
        "import sys, recipdyn, recipdyn.cli\n"
        "recipdyn.cli._register()\n"
        "from recipdyn.cli import main\n"
        "try:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
        "heavy = [m for m in ('numba', 'scipy', 'xarray', 'pint', 'dask', 'pandas') "
        "if m in sys.modules]\n"
        "print('HEAVY', heavy)\n"
        "import recipdyn.simulate\n"
        "print('FUNC', callable(recipdyn.simulate) and recipdyn.simulate.__name__)\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "HEAVY []" in r.stdout, r.stdout[-500:]
    assert "FUNC simulate" in r.stdout


def test_exports_and_json_summary(tmp_path, capsys):
    """Issue 14, exports: the same run as NetCDF and MAT holds the same samples (MAT read back
    with scipy, as MATLAB/Octave users would), with units and attributes; ``--json`` prints
    one JSON object on stdout (everything else on stderr) whose numbers are the record's."""
    import json

    import numpy as np
    import scipy.io as sio
    import xarray as xr

    args = ["simulate", "-n", "0.5", "--fs", "2 kHz", "--no-figure", "--no-progress"]
    assert main([*args, "-o", str(tmp_path / "r.nc")]) == 0
    capsys.readouterr()
    assert main([*args, "-o", str(tmp_path / "r.mat"), "--json"]) == 0
    io = capsys.readouterr()
    summary = json.loads(io.out)  # stdout is exactly one JSON document
    assert "wrote" in io.err and "wrote" not in io.out
    with xr.open_dataset(tmp_path / "r.nc") as ds:
        mat = sio.loadmat(tmp_path / "r.mat", squeeze_me=True)
        np.testing.assert_array_equal(mat["a"], ds["a"].values)
        np.testing.assert_array_equal(mat["time"], ds["time"].values)
        assert str(mat["units"]["a"]) == ds["a"].attrs["units"]
        assert float(mat["attrs"]["param_rc"]) == ds.attrs["param_rc"]
        assert summary["peak_a"] == float(np.abs(ds["a"].values).max())
        assert summary["parameters"]["rc"] == ds.attrs["param_rc"]
    assert summary["samples"] == {"time": int(mat["time"].size)}
    assert summary["validity"] == "ok"


def test_analyze_json(tmp_path, capsys):
    import json

    run = tmp_path / "ideal.nc"
    assert main(["simulate", "--rc", "0 mm", "-n", "2", "--fs", "2 kHz", "-o", str(run),
                 "--no-figure", "--no-progress"]) == 0  # fmt: skip
    capsys.readouterr()
    assert main(["analyze", str(run), "-o", str(tmp_path / "an"), "--section-points", "20",
                 "--json"]) == 0  # fmt: skip
    s = json.loads(capsys.readouterr().out)
    assert s["verdict"]["verdict"] == "periodic"
    saved = json.loads((tmp_path / "an" / "summary.json").read_text(encoding="utf-8"))
    assert s["verdict"] == saved["verdict"] and s["spectrum"] == saved["spectrum"]
    assert s["output"] == str(tmp_path / "an")


def test_jsonable_gives_strict_json():
    """One helper for every JSON output: numpy scalars (NaN included: np.float64(nan).item()
    is a float NaN, which json.dumps would write as the invalid token NaN), arrays, paths."""
    import json
    from pathlib import Path

    import numpy as np

    from recipdyn.io import jsonable

    obj = {"a": np.float64("nan"), "b": np.arange(3), 1: [np.int64(2), float("inf")],
           "p": Path("x") / "y", "ok": 1.5}  # fmt: skip
    text = json.dumps(jsonable(obj), allow_nan=False)
    assert json.loads(text) == {"a": None, "b": [0, 1, 2], "1": [2, None], "p": "x/y", "ok": 1.5}


def test_crank_options_apply_to_every_model_that_has_them(tmp_path, capsys):
    """--rc/--d/--omega set the parameters of whichever model has them (the contact joint's
    rc, the valve model's omega), and name the model that has no such parameter."""
    import tomllib

    cfg = tmp_path / "c.toml"
    assert main(["simulate", "--model", "compressor-valves", "--rc", "0.5 mm", "--omega",
                 "300 rpm", "--dump-config", str(cfg)]) == 0  # fmt: skip
    params = tomllib.loads(cfg.read_text())["params"]
    assert params["rc"] == pytest.approx(0.5e-3) and params["omega"] == pytest.approx(
        10 * 3.14159265, rel=1e-6
    )
    assert main(["simulate", "--model", "duffing", "--rc", "1 mm", "-o",
                 str(tmp_path / "x.nc")]) == 2  # fmt: skip
    err = capsys.readouterr().err
    assert "--rc" in err and "'duffing' has no such parameter" in err
    assert not (tmp_path / "x.nc").exists()


def test_a_plug_in_models_record_is_analysed_from_anywhere(tmp_path, monkeypatch):
    """A record stores the spec its model was loaded from (an absolute file path for a user's
    file), so analyze finds the model again from another folder."""
    from pathlib import Path

    example = Path(__file__).parents[1] / "examples" / "pendulum.py"
    run = tmp_path / "runs" / "p.nc"
    run.parent.mkdir()
    monkeypatch.chdir(example.parent)
    assert main(["simulate", "--model", "pendulum.py:PENDULUM", "-n", "20", "--fs", "20 Hz",
                 "-o", str(run), "--no-figure", "--no-progress"]) == 0  # fmt: skip
    spec = xr.open_dataset(run).attrs["model_spec"]
    assert spec == f"{example.resolve()}:PENDULUM"
    monkeypatch.chdir(tmp_path)
    assert main(["analyze", str(run), "-o", str(tmp_path / "an"), "--section-points", "20",
                 "--lyap-revolutions", "20"]) == 0  # fmt: skip
