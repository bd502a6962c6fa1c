"""Sweeps: identical results on every backend, resume, failures recorded, bad specs."""

import numpy as np
import pytest

from recipdyn.cli import main
from recipdyn.errors import Interrupted
from recipdyn.model import CompressorParams, ParameterError
from recipdyn.sweep import SweepSpec, open_sweep, parse_axis, run_sweep

SETTINGS = dict(revolutions=1.0, transient=2.0, points=8, lyap_revolutions=3.0, fs=5000.0,
                rtol=1e-8, atol=1e-10)  # fmt: skip


def _spec(**kw):
    axes = kw.pop("axes", (parse_axis("rc=0.5mm,1mm"), parse_axis("omega=15,20,25")))
    return SweepSpec(axes=axes, measures=kw.pop("measures", ("poincare", "peak", "lyapunov")),
                     base=kw.pop("base", CompressorParams(theta_c_offset=0.1)),
                     settings=SETTINGS, **kw)  # fmt: skip


def _values(path):
    ds = open_sweep(path).load()
    return {k: ds[k].values for k in ds.data_vars if k != "error"}


@pytest.mark.slow
def test_backends_give_identical_results(tmp_path):
    """Serial, process pool and Dask LocalCluster: bit-for-bit equal stores."""
    spec = _spec()
    ref = _values(run_sweep(spec, tmp_path / "s", backend="serial", progress=False))
    for name, kw in (("p", dict(backend="processes", workers=2)),
                     ("d", dict(backend="dask", dask_local=2))):  # fmt: skip
        got = _values(run_sweep(spec, tmp_path / name, progress=False, **kw))
        for k in ref:
            assert np.array_equal(ref[k], got[k], equal_nan=True), (name, k)
    assert ref["done"].all()


def _plain_open(path):
    """``xr.open_zarr`` as a user calls it, with every warning an error: the store's metadata
    is consolidated (else xarray warns that it fell back to reading array by array), and the
    points written after the consolidation are read all the same."""
    import warnings

    import xarray as xr

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return xr.open_zarr(str(path)).load()


def test_resume_does_not_recompute(tmp_path):
    """Interrupt after 2 of 6 points, resume: exactly the 4 missing points are computed and
    the result equals an uninterrupted run. The store opens without a warning throughout (its
    metadata consolidated when created and when a run ends)."""
    spec = _spec(measures=("poincare",))
    seen = []

    def interrupt(res):
        seen.append(res["index"])
        if len(seen) == 2:
            raise KeyboardInterrupt

    with pytest.raises(Interrupted) as info:  # a KeyboardInterrupt comes out as Interrupted
        run_sweep(spec, tmp_path / "r", backend="serial", progress=False, on_point=interrupt)
    assert info.value.exit_code == 130 and "2 of 6 sweep points" in info.value.kept[0]
    assert _plain_open(tmp_path / "r" / "sweep.zarr").done.values.sum() == 2
    second = []
    run_sweep(spec, tmp_path / "r", backend="serial", resume=True, progress=False,
              on_point=lambda r: second.append(r["index"]))  # fmt: skip
    assert len(second) == 4 and not set(second) & set(seen)
    assert _plain_open(tmp_path / "r" / "sweep.zarr").done.values.all()
    full = run_sweep(spec, tmp_path / "f", backend="serial", progress=False)
    a, b = _values(tmp_path / "r" / "sweep.zarr"), _values(full)
    assert all(np.array_equal(a[k], b[k], equal_nan=True) for k in a)
    with pytest.raises(ParameterError, match="exists"):
        run_sweep(spec, tmp_path / "r", backend="serial", progress=False)
    with pytest.raises(ParameterError, match="different sweep spec"):
        run_sweep(_spec(measures=("peak",)), tmp_path / "r", resume=True, progress=False)


def test_failing_point_is_recorded(tmp_path):
    """The printed equations blow up at a large initial offset: that point records its error,
    the others complete."""
    base = CompressorParams(equations="paper-printed", load_sign="paper")
    spec = _spec(axes=(parse_axis("theta_c_offset=0,1.0,0.05"),), measures=("poincare",),
                 base=base)  # fmt: skip
    ds = open_sweep(run_sweep(spec, tmp_path / "e", backend="serial", progress=False)).load()
    assert ds.done.values.all()
    err = ds.error.values
    assert "IntegrationError" in err[1] and err[0] == "" and err[2] == ""
    assert np.isfinite(ds.poincare_v.values[0]).all()


def test_ideal_mechanism_bifurcation_is_period_one(tmp_path):
    spec = _spec(axes=(parse_axis("omega=10:150:4"),), measures=("poincare",),
                 base=CompressorParams(rc=0.0))  # fmt: skip
    ds = open_sweep(run_sweep(spec, tmp_path / "i", backend="serial", progress=False)).load()
    assert (ds.poincare_distinct.values == 1).all()


def test_continuation_is_sequential_and_recorded(tmp_path):
    spec = _spec(axes=(parse_axis("omega=18,20,22"),), measures=("poincare",), continuation=True)
    ds = open_sweep(run_sweep(spec, tmp_path / "c", progress=False)).load()
    assert ds.attrs["mode"] == "sequential continuation"
    # the second point started where the first ended: its first section point differs from a
    # cold start's
    cold = open_sweep(run_sweep(_spec(axes=(parse_axis("omega=20"),), measures=("poincare",)),
                                tmp_path / "cold", progress=False)).load()  # fmt: skip
    assert not np.array_equal(ds.poincare_v.values[1], cold.poincare_v.values[0])


@pytest.mark.parametrize(
    "param, words",
    [
        ("bogus=1:2:3", ["unknown parameter"]),
        ("omega=10:150", ["start:stop:count"]),
        ("omega=10:150:0", ["count = 0"]),
        ("rc=0:1mm:5:log", ["log range", "> 0"]),
        ("rc=0.1mm:200mm:3", ["rc", "allowed"]),
        ("omega=10:150:x", ["not an integer"]),
    ],
)
def test_bad_specs_exit_2(tmp_path, capsys, param, words):
    code = main(["sweep", "-p", param, "-o", str(tmp_path / "x"), "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    for w in words:
        assert w in err


def test_cli_sweep_and_plot(tmp_path):
    out = tmp_path / "cli"
    args = ["sweep", "-p", "rc=0.5mm,1mm", "-p", "d=0,1mm", "-m", "peak", "--revolutions", "1",
            "--transient", "0", "--backend", "serial", "-o", str(out), "--no-progress"]  # fmt: skip
    assert main(args) == 0
    assert (out / "map_peak_a.png").exists()
    (out / "map_peak_a.png").unlink()
    assert main(["plot", str(out / "sweep.zarr")]) == 0
    assert (out / "map_peak_a.png").exists()


def test_campbell_diagram_of_a_speed_sweep_and_old_stores_refused(tmp_path):
    """A 1-D sweep over the crank speed with --measure spectrum stores each point's forcing
    frequency (omega / 2 pi, exactly: it is computed from the parameters) and its strongest
    lines, and draws the Campbell diagram. At rc = 0 the motion is the ideal slider-crank's,
    periodic at the crank frequency, so every stored line is an order of it to within the
    record's frequency bin (fs / n = 1 / (revolutions T) = forcing_hz / revolutions). A store
    that lacks a variable this version writes (made by an older version) is refused on
    --resume, not crashed into."""
    import zarr

    from recipdyn.sweep.plots import campbell_figure

    revs = 4.0
    spec = SweepSpec(
        axes=(parse_axis("omega=15,25,35"),),
        measures=("spectrum",),
        base=CompressorParams(rc=0.0),
        settings={**SETTINGS, "revolutions": revs},
    )
    path = run_sweep(spec, tmp_path / "c", backend="serial", progress=False)
    ds = open_sweep(path).load()
    fc = ds.forcing_hz.values
    assert np.allclose(fc, ds.omega.values / (2 * np.pi), rtol=1e-12, atol=0)
    f = ds.peak_freq.values
    ok = np.isfinite(f)
    assert ok.sum(axis=1).min() >= 2  # the crank frequency and at least one harmonic
    fcs = np.broadcast_to(fc[:, None], f.shape)
    off = np.abs(f / fcs - np.round(f / fcs)) * fcs  # Hz from the nearest order
    assert np.all(off[ok] <= fcs[ok] / revs)  # within one frequency bin
    p = campbell_figure(ds, tmp_path / "fig")
    assert p.name == "campbell_omega.png" and p.stat().st_size > 0
    zarr.open_group(str(path), mode="a").__delitem__("forcing_hz")
    with pytest.raises(ParameterError, match="older version"):
        run_sweep(spec, tmp_path / "c", resume=True, progress=False)
