"""recipdyn analyze on signal files from elsewhere (issue 12): CSV, WAV, MAT, NetCDF,
Parquet and NPY, with the sampling rate read from the file or given with units."""

import json

import numpy as np
import pytest

from recipdyn.cli import main
from recipdyn.io_signal import read_signal
from recipdyn.model.parameters import ParameterError
from recipdyn.model.reference import systems as S

FS = 2000.0


@pytest.fixture(scope="module")
def henon_x():
    return S.iterate(S.henon(), [0.1, 0.1], 4000, 500)[:, 0]


def _write_all(d, x):
    import pandas as pd
    import xarray as xr
    from scipy.io import savemat, wavfile

    t = np.arange(x.size) / FS
    paths = {}
    paths["csv"] = d / "s.csv"
    pd.DataFrame({"time": t, "acc": x, "other": -x}).to_csv(paths["csv"], index=False)
    paths["parquet"] = d / "s.parquet"
    pd.DataFrame({"time": t, "acc": x}).to_parquet(paths["parquet"])
    paths["wav"] = d / "s.wav"
    wavfile.write(paths["wav"], int(FS), np.c_[x, -x].astype(np.float32))
    paths["mat"] = d / "s.mat"
    savemat(paths["mat"], {"acc": x, "fs": FS})
    paths["nc"] = d / "s.nc"
    xr.Dataset({"acc": ("time", x)}, coords={"time": t}).to_netcdf(paths["nc"])
    paths["npy"] = d / "s.npy"
    np.save(paths["npy"], x)
    return paths


def test_every_format_gives_the_same_samples_and_rate(tmp_path, henon_x):
    """Each format returns the written samples (float32 WAV: to 2**-24 relative) and the rate
    from the file (time column, WAV header, fs variable, time coordinate); NPY needs --fs."""
    paths = _write_all(tmp_path, henon_x)
    for kind, p in paths.items():
        kw = {"column": "acc"} if kind in ("csv", "mat", "nc", "parquet") else {}
        if kind == "npy":
            kw["fs"] = "2 kHz"
        s = read_signal(p, **kw)
        tol = 1e-6 if kind == "wav" else 0.0
        assert np.allclose(s.x, henon_x, rtol=tol, atol=tol), kind
        assert s.fs == pytest.approx(FS, rel=1e-9), kind
    assert read_signal(paths["wav"], column=1).x[5] == pytest.approx(-henon_x[5], rel=1e-6)
    assert read_signal(paths["csv"], column=1).name == "other"  # index among the data columns
    for kind, p in paths.items():  # the first rows only: the same samples, name and rate (a
        # rate from a time column: from the first 300 times, equal to rounding)
        kw = {"column": "acc"} if kind in ("csv", "mat", "nc", "parquet") else {}
        if kind == "npy":
            kw["fs"] = "2 kHz"
        whole, head = read_signal(p, **kw), read_signal(p, rows=300, **kw)
        assert head.x.size == 300 and np.array_equal(head.x, whole.x[:300]), kind
        assert head.name == whole.name and head.fs == pytest.approx(whole.fs, rel=1e-9), kind


@pytest.mark.parametrize("kw, word", [
    ({}, "choose one with --column"),
    ({"column": "nope"}, "allowed: acc, other"),
    ({"column": "acc", "fs": "-3 Hz"}, "positive sampling rate"),
    ({"column": "acc", "fs": "3 m"}, "cannot be converted"),
])  # fmt: skip
def test_bad_choices_name_the_option(tmp_path, henon_x, kw, word):
    import pandas as pd

    p = tmp_path / "s.csv"
    pd.DataFrame({"time": np.arange(500) / FS, "acc": henon_x[:500],
                  "other": henon_x[:500]}).to_csv(p, index=False)  # fmt: skip
    with pytest.raises(ParameterError, match=word):
        read_signal(p, **kw)


def test_no_rate_and_nonuniform_time_are_refused(tmp_path, henon_x):
    import pandas as pd

    p = tmp_path / "n.csv"
    pd.DataFrame({"acc": henon_x[:300]}).to_csv(p, index=False)
    with pytest.raises(ParameterError, match="--fs"):
        read_signal(p)
    t = np.cumsum(np.r_[0.0, np.full(299, 1e-3)])
    t[150:] += 5e-4
    pd.DataFrame({"time": t, "acc": henon_x[:300]}).to_csv(p, index=False)
    with pytest.raises(ParameterError, match="not uniformly sampled"):
        read_signal(p)


def test_analyze_a_signal_file_end_to_end(tmp_path, capsys, henon_x):
    """CLI on a CSV of the Henon map's x (per sample: lambda1 = 0.419 at FS samples/s, i.e.
    838 1/s): a chaotic verdict with the evidence table printed, exponents within 25 %, the
    figures and summary written; the same data as WAV gives the same verdict."""
    paths = _write_all(tmp_path, henon_x)
    out = tmp_path / "an"
    assert main(["analyze", str(paths["csv"]), "-c", "acc", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "verdict: chaotic" in printed and "surrogates (IAAFT)" in printed
    s = json.loads((out / "summary.json").read_text())
    usable = [r["exponent"] for r in s["lyapunov_signal"].values() if r["status"] == "ok"]
    assert len(usable) >= 2
    assert np.median(usable) == pytest.approx(0.41922 * FS, rel=0.25)
    for f in ("signal.png", "spectrum.png", "summary.md"):
        assert (out / f).stat().st_size > 100
    assert "## Evidence" in (out / "summary.md").read_text()
    out2 = tmp_path / "an2"
    assert main(["analyze", str(paths["wav"]), "-o", str(out2)]) == 0
    assert json.loads((out2 / "summary.json").read_text())["verdict"]["verdict"] == "chaotic"


def test_analyze_signal_bad_input_exit_2(tmp_path, capsys, henon_x):
    paths = _write_all(tmp_path, henon_x)
    assert main(["analyze", str(paths["csv"]), "-c", "bogus"]) == 2
    assert main(["analyze", str(paths["npy"])]) == 2  # no rate
    err = capsys.readouterr().err
    assert "Traceback" not in err and "column" in err and "--fs" in err


def test_analyze_with_a_tacho_finds_orders_and_impacts(tmp_path, capsys):
    """A measured-like record: 12 Hz crank with a once-per-revolution tacho column, orders 1
    and 2 in the acceleration, and an impact (5 kHz ring-down) at 90 deg every revolution:
    analyze reports one impact per revolution at 90 deg (within 2 deg), the velocity RMS in
    the ISO 20816-8 band (closed form of the two orders) with the zone from --zones, and
    draws vibration.png. Bad --zones exit 2 with the allowed form."""
    import pandas as pd

    fs = 25_000.0
    t = np.arange(int(4 * fs)) / fs
    revs = 12.0 * t
    acc = 3.0 * np.sin(2 * np.pi * revs) + 1.0 * np.sin(4 * np.pi * revs)
    tau = ((revs - 0.25) % 1.0) / 12.0
    acc += 20.0 * np.exp(-tau / 4e-4) * np.sin(2 * np.pi * 5000 * tau) * (revs >= 0.25)
    tacho = 5.0 * ((revs % 1.0) < 0.05)
    p = tmp_path / "m.csv"
    pd.DataFrame({"time": t, "acc": acc, "key": tacho}).to_csv(p, index=False)
    out = tmp_path / "an"
    code = main(["analyze", str(p), "-c", "acc", "--tacho", "key", "--zones", "10,20,40 mm/s",
                 "-o", str(out)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    s = json.loads((out / "summary.json").read_text())
    v = s["vibration"]
    assert v["impacts"]["per_revolution"] == pytest.approx(1.0, abs=0.15)
    known = [a for a in v["impacts"]["angles_deg"] if a is not None]
    assert (
        len(v["impacts"]["angles_deg"]) - len(known) <= 2
    )  # before the first, after the last pulse
    assert np.all(np.abs(np.array(known) - 90.0) < 2.0)
    v_rms = np.hypot(3.0 / (2 * np.pi * 12), 1.0 / (2 * np.pi * 24)) / np.sqrt(2)
    assert v["velocity_rms_2_1000hz"] == pytest.approx(v_rms, rel=0.05)  # + the impacts' share
    assert v["zone"] == "C"  # 28.5 mm/s between the B/C (20) and C/D (40 mm/s) boundaries
    assert s["verdict"]["verdict"] == "periodic"  # one section point per revolution
    assert (out / "vibration.png").stat().st_size > 10_000
    assert main(["analyze", str(p), "-c", "acc", "--zones", "3,2,1 mm/s", "-o",
                 str(tmp_path / "b")]) == 2  # fmt: skip
    assert "three increasing" in capsys.readouterr().err
