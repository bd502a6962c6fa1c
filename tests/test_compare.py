"""recipdyn compare: the inputs that differ and the measures, checked against the records."""

import json

import numpy as np
import pytest
import xarray as xr

from recipdyn.analysis.spectrum import amplitude_spectrum
from recipdyn.cli import main


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("cmp")
    base = ["simulate", "-n", "4", "--fs", "10 kHz", "--no-figure", "--no-progress"]
    assert main([*base, "-o", str(d / "natural.nc")]) == 0
    assert main([*base, "--rc", "0.5 mm", "--set", "theta_c_offset=0.2",
                 "-o", str(d / "ringing.nc")]) == 0  # fmt: skip
    return d


def test_compare_two_runs(two_runs, capsys):
    d = two_runs
    out = d / "cmp"
    assert main(["compare", str(d / "natural.nc"), str(d / "ringing.nc"), "-o", str(out),
                 "--json"]) == 0  # fmt: skip
    s = json.loads(capsys.readouterr().out)
    # exactly the two parameters changed (and the initial angle they imply)
    assert set(s["differing_inputs"]) == {"param_rc", "param_theta_c_offset", "theta_c_initial"}
    assert s["differing_inputs"]["param_rc"] == [1e-3, 0.5e-3]
    rows = {r["run"]: r for r in s["measures"]}
    with xr.open_dataset(d / "ringing.nc") as ds:
        a = ds["a"].values
        assert rows["ringing"]["peak"] == float(np.abs(a).max())
        spec = amplitude_spectrum(a, 10_000.0)
        f_top = float(spec.frequency[1:][np.argmax(spec.amplitude[1:])])
        fc = float(ds.attrs["crank_frequency_hz"])
    # the ringing link: its own line is the dominant one, hundreds of crank orders up
    assert rows["ringing"]["dominant_hz"] == pytest.approx(f_top)
    # the own-line search skips bins within 1.5 bins of a crank harmonic: the same line to
    # within two bins
    assert rows["ringing"]["own_line_hz"] == pytest.approx(f_top, abs=2 * spec.resolution)
    assert f_top > 100 * fc
    ref = rows["natural"]
    assert rows["ringing"]["peak_diff"] == pytest.approx(rows["ringing"]["peak"] - ref["peak"])
    assert ref["peak_diff"] == 0.0
    for f in ("compare.png", "compare.md", "compare.json"):
        assert (out / f).stat().st_size > 200
    assert "param_rc" in (out / "compare.md").read_text(encoding="utf-8")


def test_compare_same_run_has_no_differences(two_runs, capsys):
    d = two_runs
    assert main(["compare", str(d / "natural.nc"), str(d / "natural.nc"), "-o",
                 str(d / "same"), "--json", "--labels", "A,B"]) == 0  # fmt: skip
    s = json.loads(capsys.readouterr().out)
    assert s["differing_inputs"] == {}
    assert all(s["measures"][1][f"{k}_diff"] in (0.0, None) for k in ("peak", "rms"))


@pytest.mark.parametrize("args,word", [
    (["compare", "ONE"], "at least 2"),
    (["compare", "ONE", "ONE", "--signal", "nope"], "signal"),
    (["compare", "ONE", "ONE", "--labels", "a,b,c"], "labels"),
])  # fmt: skip
def test_compare_bad_input(two_runs, capsys, args, word):
    args = [str(two_runs / "natural.nc") if a == "ONE" else a for a in args]
    assert main([*args, "-o", str(two_runs / "bad")]) == 2
    err = capsys.readouterr().err
    assert word in err and "Traceback" not in err
