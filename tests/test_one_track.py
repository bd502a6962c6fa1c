"""One track above the model protocol (issue 30, item 4): every model is simulated, streamed,
cut to columns, swept, analysed and re-run from its record the same way, through
`recipdyn.model.protocol.Model` only."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import recipdyn
from recipdyn.cli import main

simulate_module = importlib.import_module("recipdyn.simulate")  # (the package re-exports the
# function under the module's name)

ROOT = Path(__file__).parents[1]
EXAMPLE = f"{ROOT / 'examples' / 'pendulum.py'}:PENDULUM"

#: A flow with a forcing period, one with an acting event (impacts, reset), a model from a
#: user's file, and a compressor model other than the default.
MODELS = {
    "duffing": dict(revolutions=3.0, fs=50.0),
    "impact-oscillator": dict(revolutions=4.0, fs=100.0),
    EXAMPLE: dict(revolutions=3.0, fs=40.0),
    "compressor-contact": dict(revolutions=0.3, fs=4000.0),
}


@pytest.mark.parametrize("model", list(MODELS), ids=["duffing", "impact", "plug-in", "contact"])
def test_streamed_record_equals_the_in_memory_one_for_every_model(tmp_path, model,
                                                                  monkeypatch):  # fmt: skip
    """Streaming, columns and progress are the protocol's, not one model's: a record streamed
    to NetCDF (in blocks of 97 samples, so a run spans several) and to Zarr holds exactly the
    samples, events and attributes of the in-memory run; ``columns`` keeps the named outputs
    only, in the order asked for."""
    monkeypatch.setattr(simulate_module, "STREAM_BLOCK", 97)
    kw = dict(model=model, **MODELS[model])
    a = recipdyn.simulate(**kw)
    assert a.sizes["time"] > 3 * 97  # several blocks
    b = recipdyn.simulate(**kw, out=tmp_path / "s.nc", progress=True)
    names = list(a.data_vars)
    keep = [n for n in names if a[n].dims == ("time",)][1::-1]  # two, in reverse order
    c = recipdyn.simulate(**kw, out=tmp_path / "s.zarr", columns=keep)
    assert b.sizes == a.sizes
    assert np.array_equal(a.time.values, b.time.values)
    for k in names:
        assert np.array_equal(a[k].values, b[k].values), k
        assert a[k].attrs.get("units") == b[k].attrs.get("units"), k
    for k in ("solver_nsteps", "model_spec", "config_toml", "validity"):  # (nfev: +1 a block)
        assert a.attrs[k] == b.attrs[k], k
    assert [k for k in c.data_vars if c[k].dims == ("time",)] == keep
    for k in keep:
        assert np.array_equal(c[k].values, a[k].values), k
    events = [k for k in names if a[k].dims != ("time",)]
    if model == "impact-oscillator":  # the events go to the streamed file too
        assert events and all(k in c for k in events)
        assert all(np.array_equal(a[k].values, c[k].values) for k in events)
    assert not list(tmp_path.glob(".s.*")), "no temporary store left behind"


def test_the_cli_streams_and_cuts_columns_for_any_model(tmp_path, monkeypatch, capsys):
    """``--stream`` and ``--columns`` on a model other than the default; a run longer than
    the automatic threshold is streamed without being asked (it was the default model's
    only), and its summary names the model's own vibration signal."""
    from recipdyn.cli import simulate as cli_sim

    out = tmp_path / "d.nc"
    assert main(["simulate", "--model", "duffing", "-n", "3", "--fs", "50 Hz", "--stream",
                 "--columns", "v,x", "-o", str(out), "--no-progress"]) == 0  # fmt: skip
    with xr.open_dataset(out) as ds:
        assert [k for k in ds.data_vars if ds[k].dims == ("time",)] == ["v", "x"]
        assert ds.attrs["columns"] == "v,x" and ds.attrs["model_name"] == "duffing"
    capsys.readouterr()
    monkeypatch.setattr(cli_sim, "STREAM_AUTO", 100)
    seen = []
    real = simulate_module.simulate

    def spy(*a, **kw):
        seen.append(kw.get("out"))
        return real(*a, **kw)

    monkeypatch.setattr(simulate_module, "simulate", spy)
    assert main(["simulate", "--model", "impact-oscillator", "-n", "4", "--fs", "100 Hz",
                 "-o", str(tmp_path / "i.nc"), "--no-progress", "--no-figure"]) == 0  # fmt: skip
    assert seen == [tmp_path / "i.nc"]  # streamed: more samples than STREAM_AUTO
    assert "wrote" in capsys.readouterr().out


def test_a_plug_in_models_record_reruns_from_another_folder(tmp_path, monkeypatch):
    """A record stores its model's spec (the absolute path of a user's file): ``simulate -c
    RUN.nc`` from another folder rebuilds the same model and gives the same samples, and its
    config names the spec, not the bare name."""
    example = ROOT / "examples" / "pendulum.py"
    a, b = tmp_path / "runs" / "a.nc", tmp_path / "b.nc"
    a.parent.mkdir()
    monkeypatch.chdir(example.parent)
    assert main(["simulate", "--model", "pendulum.py:PENDULUM", "-n", "3", "--fs", "40 Hz",
                 "-o", str(a), "--no-figure", "--no-progress"]) == 0  # fmt: skip
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "-c", str(a), "-o", str(b), "--no-figure", "--no-progress"]) == 0
    da, db = xr.open_dataset(a), xr.open_dataset(b)
    assert db.attrs["model_spec"] == da.attrs["model_spec"] == f"{example.resolve()}:PENDULUM"
    assert f'model = "{example.resolve()}:PENDULUM"' in da.attrs["config_toml"]
    for k in da.data_vars:
        assert np.array_equal(da[k].values, db[k].values), k


def test_a_compressor_record_keeps_its_load_table_and_reruns(tmp_path):
    """The compressor's load table (a value beside its schema) goes into the record and its
    config: rerunning the record (``-c RUN.nc``) gives the same samples."""
    table = tmp_path / "load.csv"
    table.write_text("angle_deg,force_N\n0,0\n90,-40000\n180,-80000\n270,-20000\n")
    a, b = tmp_path / "a.nc", tmp_path / "b.nc"
    assert main(["simulate", "--set", f"load_table={table}", "-n", "0.5", "--fs", "2 kHz",
                 "-o", str(a), "--no-figure", "--no-progress"]) == 0  # fmt: skip
    assert main(["simulate", "-c", str(a), "-o", str(b), "--no-figure", "--no-progress"]) == 0
    da, db = xr.open_dataset(a), xr.open_dataset(b)
    assert "load_table = [[0.0, 0.0], [90.0, -40000.0]" in da.attrs["config_toml"]
    assert da.attrs["param_load_model"] == db.attrs["param_load_model"] == "table"
    for k in da.data_vars:
        assert np.array_equal(da[k].values, db[k].values), k


def test_sweep_specs_take_any_models_values_and_keep_old_digests():
    """A sweep's base case is the model's validated values, whatever the model; for the
    default model a `CompressorParams` base and the same values as a mapping give one spec,
    and the digest of a default-model sweep is the one stores written before this layout
    carry (pinned), so ``--resume`` still finds them."""
    from recipdyn.model.parameters import CompressorParams
    from recipdyn.sweep import SweepSpec, parse_axis

    axis = (parse_axis("rc=0.5mm,1mm"),)
    assert SweepSpec(axes=axis, measures=("peak",)).digest == "dd153c3f23fc3560"
    kw = dict(axes=(parse_axis("omega=10:20:3"),), measures=("poincare", "peak"),
              settings=dict(revolutions=2))  # fmt: skip
    p = CompressorParams(d=0.5e-3, load="cycle")
    a = SweepSpec(base=p, **kw)
    b = SweepSpec(base={"d": 0.5e-3, "load": "cycle"}, **kw)
    assert a.digest == b.digest == "bb24d9f22eb73ca0"
    assert isinstance(a.base, dict)
    point = a.point_params({"omega": 15.0})
    assert point["omega"] == 15.0 and point["d"] == 0.5e-3 and point["load"] == "cycle"
    d = SweepSpec(axes=(parse_axis("w=0.5:1.5:3", "duffing"),), measures=("peak",),
                  model="duffing", base={"gamma": 0.3})  # fmt: skip
    assert d.point_params({"w": 1.0})["gamma"] == 0.3
    with pytest.raises(recipdyn.ParameterError, match="gamma"):
        SweepSpec(axes=d.axes, measures=("peak",), model="duffing", base={"gamma": "x"})


#: Above the model layer a model is reached through its protocol only. These patterns are
#: branches on a model's name or parameter class; `reproduce/` (the paper's cases, by
#: nature about its compressor) is not searched.
BRANCHES = re.compile(
    r"""(==|!=)\s*["']compressor|name\s*(==|!=)\s*DEFAULT_MODEL|isinstance\([^)]*Params"""
    r"""|compressor_model\(|["']param_rc["']\s+in\b|hasattr\([^)]*crank_period"""
)


def test_no_branch_on_a_models_name_above_the_model_layer():
    """simulate, sweep, analyze, features, compare, the app and the command line reach every
    model through the protocol (issue 30, item 4): none branches on a model's name or
    parameter class."""
    src = ROOT / "src" / "recipdyn"
    files = [src / f for f in ("simulate.py", "analyze.py", "features.py", "compare.py",
                               "config.py", "plotting.py", "animate.py")]  # fmt: skip
    for folder in ("sweep", "app", "cli"):
        files += sorted((src / folder).glob("*.py"))
    hits = [f"{f.relative_to(src)}:{i}: {line.strip()}" for f in files
            for i, line in enumerate(f.read_text().splitlines(), 1)
            if BRANCHES.search(line) and not line.lstrip().startswith("#")]  # fmt: skip
    assert hits == []
