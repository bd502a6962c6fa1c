"""recipdyn analyze on a run from recipdyn simulate."""

import json

from recipdyn.cli import main


def test_analyze_a_simulated_run(tmp_path, capsys):
    run = tmp_path / "run.nc"
    args = ["simulate", "--rc", "1 mm", "--set", "theta_c_offset=0.3", "-n", "3", "--fs", "10 kHz"]
    assert main([*args, "-o", str(run), "--no-figure", "--no-progress"]) == 0
    out = tmp_path / "an"
    assert main(["analyze", str(run), "-o", str(out), "--section-points", "100",
                 "--lyap-revolutions", "20"]) == 0  # fmt: skip
    s = json.loads((out / "summary.json").read_text())
    assert s["verdict"]["verdict"] in ("chaotic", "quasi-periodic", "periodic", "undetermined")
    le = s["lyapunov_equations"]
    assert abs(le["sum_per_s"]) < 0.05 * abs(le["exponents_per_s"][0]) + 1e-3
    for f in ("spectrum.png", "phase_portraits.png", "poincare.png", "lyapunov_benettin.png",
              "lyapunov_wolf.png", "summary.md"):  # fmt: skip
        assert (out / f).stat().st_size > 100
    assert "verdict" in capsys.readouterr().out


def test_ideal_run_is_periodic(tmp_path):
    run = tmp_path / "ideal.nc"
    assert main(["simulate", "--rc", "0 mm", "-n", "2", "--fs", "2 kHz", "-o", str(run),
                 "--no-figure", "--no-progress"]) == 0  # fmt: skip
    out = tmp_path / "an"
    assert main(["analyze", str(run), "-o", str(out), "--section-points", "20"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["verdict"]["verdict"] == "periodic"


def test_analyze_bad_input(tmp_path, capsys):
    assert main(["analyze", str(tmp_path / "missing.nc")]) == 2
    bad = tmp_path / "bad.nc"
    bad.write_text("not netcdf")
    assert main(["analyze", str(bad)]) == 2
    assert "Traceback" not in capsys.readouterr().err
