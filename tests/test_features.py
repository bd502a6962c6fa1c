"""recipdyn features (issue 12, item 5): a labelled feature table from runs, signal files and
sweep stores."""

import numpy as np
import pandas as pd
import pytest

from recipdyn.cli import main
from recipdyn.features import signal_features


def test_features_of_a_known_signal():
    """A 50 Hz sine of amplitude 2 plus 0.5 at 150 Hz (order 3 of a 50 Hz crank): RMS,
    crest factor, dominant frequency and the order amplitudes are the closed-form values."""
    fs = 5000.0
    t = np.arange(50_000) / fs
    x = 2.0 * np.sin(2 * np.pi * 50 * t) + 0.5 * np.sin(2 * np.pi * 150 * t)
    r = signal_features(x, fs, revs=50.0 * t)
    assert r["rms"] == pytest.approx(np.sqrt((4 + 0.25) / 2), rel=1e-9)
    assert r["dominant_hz"] == pytest.approx(50.0)
    assert r["order_1"] == pytest.approx(2.0, rel=1e-3)
    assert r["order_3"] == pytest.approx(0.5, rel=1e-3)
    assert r["order_2"] < 1e-3
    assert r["velocity_rms_2_1000hz"] == pytest.approx(
        np.sqrt((2 / (2 * np.pi * 50)) ** 2 + (0.5 / (2 * np.pi * 150)) ** 2) / np.sqrt(2),
        rel=1e-6)  # fmt: skip


def test_features_command_runs_windows_and_sweeps(tmp_path, capsys):
    """Two simulated runs -> rows labelled with their parameters (rc differs), windows of one
    revolution give one row per whole revolution; a CSV signal with --speed gets order
    features and the chaos indicators with statuses; a sweep store gives one row per point."""
    runs = []
    for rc in ("0.5 mm", "1 mm"):
        p = tmp_path / f"run{rc[:3].strip()}.nc"
        assert main(["simulate", "--rc", rc, "-n", "3", "--fs", "5 kHz", "-o", str(p),
                     "--no-figure", "--no-progress"]) == 0  # fmt: skip
        runs.append(p)
    out = tmp_path / "f.parquet"
    assert main(["features", *map(str, runs), "-o", str(out), "--window", "1 rev"]) == 0
    f = pd.read_parquet(out)
    assert len(f) == 6 and sorted(f["param_rc"].unique()) == [5e-4, 1e-3]
    assert np.all(np.isfinite(f["order_1"])) and np.all(f["window_s"] > 0.3)
    sig = tmp_path / "s.csv"
    fs = 2000.0
    t = np.arange(8000) / fs
    pd.DataFrame({"time": t, "acc": np.sin(2 * np.pi * 10 * t)}).to_csv(sig, index=False)
    out2 = tmp_path / "g.csv"
    assert main(["features", str(sig), "-c", "acc", "--speed", "600 rpm", "--chaos",
                 "-o", str(out2)]) == 0  # fmt: skip
    g = pd.read_csv(out2)
    assert g["order_1"].iloc[0] == pytest.approx(1.0, rel=1e-3)
    assert g["lambda1_status"].iloc[0] in ("flat", "ok") and "k01_status" in g
    store = tmp_path / "sw"
    assert main(["sweep", "-p", "rc=0.5mm:1mm:3", "-m", "peak", "--revolutions", "1",
                 "--transient", "0", "-o", str(store), "--backend", "serial",
                 "--no-progress"]) == 0  # fmt: skip
    out3 = tmp_path / "h.csv"
    assert main(["features", str(store / "sweep.zarr"), "-o", str(out3)]) == 0
    h = pd.read_csv(out3)
    assert len(h) == 3 and "peak_a" in h and "rc" in h
    assert "wrote 3 row(s)" in capsys.readouterr().out


def test_features_bad_window_exit_2(tmp_path, capsys):
    sig = tmp_path / "s.csv"
    pd.DataFrame({"time": np.arange(500) / 100.0, "acc": np.arange(500.0)}).to_csv(sig)
    assert main(["features", str(sig), "-c", "acc", "-w", "10 rev", "-o",
                 str(tmp_path / "x.csv")]) == 2  # fmt: skip
    assert main(["features", str(sig), "-c", "acc", "-w", "1 ms", "-o",
                 str(tmp_path / "x.csv")]) == 2  # fmt: skip
    assert main(["features", str(sig), "-c", "acc", "-o", str(tmp_path / "x.xlsx")]) == 2
    err = capsys.readouterr().err
    assert "needs the speed" in err and "at least 64" in err and "Traceback" not in err
    assert "use .csv or .parquet" in err


@pytest.mark.parametrize("suffix", [".csv", ".npy", ".wav", ".parquet", ".nc"])
def test_windows_read_block_by_block_equal_the_whole_file(tmp_path, suffix):
    """Windowed features read the file in blocks (here 1000 samples, windows of 730: every
    window but the first straddles a block boundary): rows identical to windows cut from the
    whole signal (float32 WAV: to its rounding)."""
    import xarray as xr
    from scipy.io import wavfile

    from recipdyn.features import _streamed_rows
    from recipdyn.io_signal import signal_blocks

    fs = 1000.0
    x = np.sin(2 * np.pi * 7 * np.arange(5000) / fs) + 0.1 * np.cos(np.arange(5000) ** 1.3)
    p = tmp_path / f"s{suffix}"
    if suffix == ".csv":
        pd.DataFrame({"time": np.arange(x.size) / fs, "acc": x}).to_csv(p, index=False)
    elif suffix == ".parquet":
        pd.DataFrame({"time": np.arange(x.size) / fs, "acc": x}).to_parquet(p)
    elif suffix == ".npy":
        np.save(p, x)
    elif suffix == ".wav":
        x = x.astype(np.float32).astype(float)
        wavfile.write(p, int(fs), x.astype(np.float32))
    else:
        xr.Dataset({"acc": ("time", x)}, coords={"time": np.arange(x.size) / fs}).to_netcdf(p)
    kw = {"column": "acc"} if suffix in (".csv", ".parquet", ".nc") else {}
    if suffix == ".npy":
        kw["fs"] = "1 kHz"
    rate, name, total, blocks = signal_blocks(p, block=1000, **kw)
    assert rate == pytest.approx(fs) and np.array_equal(np.concatenate(list(blocks)), x)
    import recipdyn.io_signal as io_signal

    orig = io_signal.signal_blocks
    io_signal.signal_blocks = lambda *a, **k: orig(*a, **{**k, "block": 1000})
    try:
        rows = _streamed_rows(p, kw.get("column"), kw.get("fs"), "0.73 s", "420 rpm", False,
                              False)  # fmt: skip
    finally:
        io_signal.signal_blocks = orig
    assert len(rows) == 5000 // 730
    for i, r in enumerate(rows):
        ref = signal_features(x[i * 730 : (i + 1) * 730], fs,
                              revs=7.0 * np.arange(i * 730, (i + 1) * 730) / fs)  # fmt: skip
        for k in ("rms", "kurtosis", "order_1", "dominant_hz"):
            assert r[k] == pytest.approx(ref[k], rel=1e-12, abs=1e-12), (k, i)


def test_sweep_features_measure_equals_the_run_features(tmp_path):
    """The sweep measure ``features`` stores, per point, the features of the point's vibration
    signal: equal to :func:`signal_features` of the same run made by ``simulate`` (the same
    integration, so to rounding: 1e-9 relative), orders from the exact crank angle; and
    ``recipdyn features`` on the store writes them as columns after the parameters."""
    import recipdyn
    from recipdyn.features import signal_features

    store = tmp_path / "sw"
    assert main(["sweep", "-p", "rc=0.5mm,1mm", "-m", "features", "--revolutions", "2",
                 "--transient", "1", "--fs", "5 kHz", "-o", str(store), "--backend",
                 "serial", "--no-progress"]) == 0  # fmt: skip
    out = tmp_path / "f.csv"
    assert main(["features", str(store / "sweep.zarr"), "-o", str(out)]) == 0
    f = pd.read_csv(out)
    assert list(f.columns[:2]) == ["store", "rc"] and len(f) == 2
    for rc in (5e-4, 1e-3):
        ds = recipdyn.simulate(rc=rc, revolutions=2, transient=1, fs=5000)
        a = ds["a"].values
        ref = signal_features(a, 5000.0, revs=(ds["time"].values - ds["time"].values[0])
                              * float(ds.attrs["crank_frequency_hz"]))  # fmt: skip
        row = f[np.isclose(f["rc"], rc)].iloc[0]
        for k in ("rms", "kurtosis", "crest_factor", "centroid_hz", "order_1", "order_2"):
            assert row[f"feat_{k}"] == pytest.approx(ref[k], rel=1e-9), k


def test_every_compressor_model_gives_the_same_numeric_columns(tmp_path, capsys):
    """Issue 31, item 4: runs of the four compressor models give a feature table fit for
    learning: every row has its speed (from the model's period: omega / 2 pi, checked
    against the recorded omega) and finite order amplitudes; no text note or unit column;
    the units, descriptions and assumption notes are in the data dictionary beside the table
    (one row per column of the table, in its order)."""
    runs = []
    for model in ("compressor", "compressor-contact", "compressor-valves",
                  "compressor-contact-valves"):  # fmt: skip
        p = tmp_path / f"{model}.nc"
        assert main(["simulate", "--model", model, "-n", "1", "--fs", "5 kHz", "-o", str(p),
                     "--no-figure", "--no-progress"]) == 0  # fmt: skip
        runs.append(p)
    out = tmp_path / "f.csv"
    assert main(["features", *map(str, runs), "-o", str(out), "--no-progress"]) == 0
    assert "f.dictionary.csv" in capsys.readouterr().out
    f = pd.read_csv(out)
    features = ["speed_hz", *[f"order_{k}" for k in range(1, 11)], "rms", "peak",
                "velocity_rms_2_1000hz", "dominant_hz", "spectral_entropy"]  # fmt: skip
    assert len(f) == 4 and np.all(np.isfinite(f[features].to_numpy(dtype=float)))
    np.testing.assert_allclose(f["speed_hz"], f["param_omega"] / (2 * np.pi), rtol=1e-12)
    assert not [c for c in f.columns if c.endswith(("_note", "_units"))]
    # the only text columns: where a row comes from and the models' choices (categories)
    from recipdyn.model.registry import get_model

    choices = {f"param_{p.name}" for m in f["model"] for p in get_model(m).schema
               if p.choices is not None}  # fmt: skip
    text = {c for c in f.columns if not pd.api.types.is_numeric_dtype(f[c])}
    assert text <= {"file", "signal", "model", *choices}, text - choices
    assert sorted(f["model"]) == sorted(p.stem for p in runs)
    guide = pd.read_csv(tmp_path / "f.dictionary.csv", keep_default_na=False)
    assert list(guide["column"]) == list(f.columns)
    unit = dict(zip(guide["column"], guide["unit"], strict=True))
    assert unit["speed_hz"] == "Hz" and unit["order_1"] == "m/s**2" and unit["param_m3"] == "kg"
    note = dict(zip(guide["column"], guide["note"], strict=True))
    assert note["param_m3"]  # an assumed value says why
    assert "load_model: " in note["model"]  # a text a model records is a note, not a column
    assert all(guide["description"].str.len() > 0)
