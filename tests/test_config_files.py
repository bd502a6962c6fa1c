"""Configs a user can start from and get back (issue 14, item 4): the shipped examples run,
--dump-config writes the whole commented config of a run, and a recorded run is its own
config."""

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from recipdyn.cli import main

EXAMPLES = sorted((Path(__file__).parent.parent / "examples" / "configs").glob("*.toml"))


def test_there_are_examples():
    assert {p.stem for p in EXAMPLES} >= {"base_case", "gas_cycle", "contact_joint"}


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_example_configs_run(tmp_path, path, capsys):
    """Each example runs (a fifth of a revolution) and its record says which parameters it
    set: the values of the file, in SI."""
    import tomllib

    out = tmp_path / "r.nc"
    assert main(["simulate", "-c", str(path), "-n", "0.2", "-o", str(out), "--no-figure",
                 "--no-progress"]) == 0, capsys.readouterr().err  # fmt: skip
    ds = xr.open_dataset(out)
    cfg = tomllib.loads(path.read_text())
    assert ds.attrs["model_name"] == cfg.get("model", "compressor")
    if "rc" in cfg["params"]:
        assert ds.attrs["param_rc"] == pytest.approx(1e-3)


@pytest.mark.parametrize("model, args", [
    ("compressor", ["--rc", "0.5 mm", "--set", "load=cycle", "--set", "acting=head"]),
    ("compressor-contact", ["--set", "rc=0.5 mm", "--set", "friction=0.05"]),
])  # fmt: skip
def test_dump_config_and_rerun_a_record(tmp_path, model, args, capsys):
    """--dump-config writes every schema parameter (commented with unit and range) and every
    setting; running the dump gives the run the options describe; rerunning the record
    (-c RUN.nc) gives the same samples, bit for bit (same machine, same computation)."""
    from recipdyn.model.registry import get_model

    cfg = tmp_path / "c.toml"
    base = ["simulate", "--model", model, *args, "-n", "0.3", "--fs", "4 kHz"]
    assert main([*base, "--dump-config", str(cfg)]) == 0
    text = cfg.read_text()
    for p in get_model(model).schema:
        assert f"{p.name} =" in text, p.name
    assert "[simulation]" in text and "revolutions = 0.3" in text and "# m; " in text
    a, b = tmp_path / "a.nc", tmp_path / "b.nc"
    assert main(["simulate", "-c", str(cfg), "-o", str(a), "--no-figure",
                 "--no-progress"]) == 0  # fmt: skip
    assert main(["simulate", "-c", str(a), "-o", str(b), "--no-figure", "--no-progress"]) == 0
    da, db = xr.open_dataset(a), xr.open_dataset(b)
    assert da.attrs["param_rc"] == pytest.approx(5e-4)
    assert da.sizes == db.sizes
    for k in da.data_vars:
        assert np.array_equal(da[k].values, db[k].values), k
    assert da.attrs["config_toml"] == db.attrs["config_toml"]
    capsys.readouterr()
    assert main([*base, "--dump-config", "-"]) == 0
    assert capsys.readouterr().out.startswith("# recipdyn run configuration")


def test_foreign_netcdf_is_not_a_config(tmp_path, capsys):
    p = tmp_path / "f.nc"
    xr.Dataset({"x": ("t", np.arange(3.0))}).to_netcdf(p)
    assert main(["simulate", "-c", str(p), "--no-figure"]) == 2
    assert "not a recipdyn run" in capsys.readouterr().err
