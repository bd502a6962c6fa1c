"""Refused commands: exit status 2, one line, nothing written, and answered before the heavy
modules load (docs/reliability.md, "Bad input").

The fault-injection table runs every command with bad options, values, units and files in a
fresh folder and checks the three promises for each; the import checks run the command line in
a fresh interpreter and look at what it loaded (a test of speed that holds on any machine: no
timing).
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from recipdyn.cli import main

BAD_TOML = "[params\nrc = 1\n"
UNKNOWN_KEY_TOML = '[params]\nrc = "1 mm"\nfoo = 1\n'
UNKNOWN_TABLE_TOML = "[params]\n[solver]\nrtol = 1e-8\n"
BAD_SETTING_TOML = "[simulation]\nrtol = 0\n"
NAN_TOML = '[params]\nrc = "nan mm"\n'

#: (command line, words the one line must contain); run in a folder holding the files of
#: ``_inputs``; every output goes into a folder ``o/`` that does not exist yet.
CASES = [
    # simulate: values, ranges, units, NaN
    (["simulate", "--rc", "-1 mm"], ["rc", "allowed", "[0, r)"]),
    (["simulate", "--rc", "-1 mm", "-o", "o/x.nc"], ["rc", "allowed"]),
    (["simulate", "--rc", "1 parsec", "-o", "o/x.nc"], ["rc", "allowed"]),
    (["simulate", "--rc", "1 kg", "-o", "o/x.nc"], ["rc", "cannot be converted"]),
    (["simulate", "--rc", "1 furlongs_x", "-o", "o/x.nc"], ["rc", "unit"]),
    (["simulate", "--rc", "nan", "-o", "o/x.nc"], ["rc", "NaN"]),
    (["simulate", "--d", "0.5 m", "-o", "o/x.nc"], ["d =", "allowed"]),
    (["simulate", "--omega", "0 rad/s", "-o", "o/x.nc"], ["omega", "allowed"]),
    (["simulate", "--omega", "inf", "-o", "o/x.nc"], ["omega", "finite"]),
    (["simulate", "--set", "m2=-1", "-o", "o/x.nc"], ["m2", "allowed"]),
    (["simulate", "--set", "novalue", "-o", "o/x.nc"], ["NAME=VALUE"]),
    (
        ["simulate", "--set", "discharge_presure=1 bar", "-o", "o/x.nc"],
        ["did you mean 'discharge_pressure'"],
    ),
    (["simulate", "--set", "foo=1", "-o", "o/x.nc"], ["unknown parameter 'foo'"]),
    (
        ["simulate", "--model", "compresor-contact", "-o", "o/x.nc"],
        ["did you mean 'compressor-contact'"],
    ),
    # simulate: settings
    (["simulate", "-n", "0", "-o", "o/x.nc"], ["revolutions", "> 0"]),
    (["simulate", "-n", "-1", "-o", "o/x.nc"], ["revolutions", "> 0"]),
    (["simulate", "-n", "nan", "-o", "o/x.nc"], ["revolutions", "NaN"]),
    (["simulate", "--transient", "-1", "-o", "o/x.nc"], ["transient", ">= 0"]),
    (["simulate", "--fs", "0 Hz", "-o", "o/x.nc"], ["fs", "> 0"]),
    (["simulate", "--fs", "10 kg", "-o", "o/x.nc"], ["fs", "cannot be converted"]),
    (["simulate", "--rtol", "0", "-o", "o/x.nc"], ["rtol", "allowed"]),
    (["simulate", "--rtol", "-1", "-o", "o/x.nc"], ["rtol", "allowed"]),
    (["simulate", "--rtol", "nan", "-o", "o/x.nc"], ["rtol", "allowed"]),
    (["simulate", "--atol", "0", "-o", "o/x.nc"], ["atol", "allowed"]),
    (["simulate", "--atol", "2", "-o", "o/x.nc"], ["atol", "allowed"]),
    (["simulate", "--method", "euler", "-o", "o/x.nc"], ["method", "dop853"]),
    (["simulate", "--method", "rk4", "--h", "-1 s", "-o", "o/x.nc"], ["h =", "allowed"]),
    (["simulate", "--method", "rk4", "--h", "0 s", "-o", "o/x.nc"], ["h =", "allowed"]),
    (["simulate", "--method", "rk4", "--h", "1 s", "-o", "o/x.nc"], ["h =", "one revolution"]),
    (["simulate", "--float32", "-o", "o/x.nc"], ["--stream"]),
    (["simulate", "--max-memory", "0 GB", "-o", "o/x.nc"], ["max_memory", "> 0"]),
    (["simulate", "--max-memory", "4 parsec", "-o", "o/x.nc"], ["max_memory"]),
    (["simulate", "-o", "o/x.txt"], ["unknown extension", ".nc"]),
    # simulate: runs too large for the memory or the disk
    (["simulate", "-n", "1e9", "-o", "o/x.nc"], ["disk"]),
    (["simulate", "-n", "1e9", "--no-stream", "-o", "o/x.nc"], ["memory"]),
    # simulate: config files
    (["simulate", "-c", "bad.toml", "-o", "o/x.nc"], ["malformed TOML"]),
    (["simulate", "-c", "latin1.toml", "-o", "o/x.nc"], ["not UTF-8"]),
    (["simulate", "-c", "unknown_key.toml", "-o", "o/x.nc"], ["unknown parameter 'foo'"]),
    (["simulate", "-c", "unknown_table.toml", "-o", "o/x.nc"], ["solver"]),
    (["simulate", "-c", "bad_setting.toml", "-o", "o/x.nc"], ["rtol", "allowed"]),
    (["simulate", "-c", "nan.toml", "-o", "o/x.nc"], ["rc", "NaN"]),
    (["simulate", "-c", "missing.toml", "-o", "o/x.nc"], ["not found"]),
    (["simulate", "-c", "folder", "-o", "o/x.nc"], ["folder"]),
    # sweep
    (["sweep", "-p", "rc=-1:1:3", "-o", "o/sw"], ["rc", "allowed"]),
    (["sweep", "-p", "rc=1mm:2mm:0", "-o", "o/sw"], ["count"]),
    (["sweep", "-p", "foo=1,2", "-o", "o/sw"], ["unknown parameter 'foo'"]),
    (["sweep", "-p", "rc=1mm,2mm", "--points", "0", "-o", "o/sw"], ["points"]),
    (["sweep", "-p", "rc=1mm,2mm", "--workers", "0", "-o", "o/sw"], ["workers"]),
    (["sweep", "-p", "rc=1mm,2mm", "-m", "bogus", "-o", "o/sw"], ["--measure", "bogus"]),
    (["sweep", "-p", "rc=1mm,2mm", "--fs", "10 kg", "-o", "o/sw"], ["fs"]),
    (["sweep", "-p", "rc=1mm,2mm", "--rtol", "0", "-o", "o/sw"], ["rtol"]),
    (["sweep", "-p", "rc=1mm,2mm", "-c", "bad.toml", "-o", "o/sw"], ["malformed TOML"]),
    # analyze
    (["analyze", "nothere.csv"], ["not found"]),
    (["analyze", "signal.csv", "-o", "o/a", "--quantity", "bogus"], ["quantity"]),
    (["analyze", "signal.csv", "-o", "o/a", "--fs", "-1 kHz"], ["fs", "> 0"]),
    (["analyze", "signal.csv", "-o", "o/a", "--fs", "10 kg"], ["fs"]),
    (["analyze", "signal.csv", "-o", "o/a", "--speed", "10 kg"], ["speed"]),
    (["analyze", "signal.csv", "-o", "o/a", "--section-points", "0"], ["section_points"]),
    (["analyze", "signal.csv", "-o", "o/a", "--tacho", "x", "--speed", "1 Hz"], ["tacho"]),
    (["analyze", "short.csv", "-o", "o/a", "--fs", "1 kHz"], ["samples"]),
    # features
    (["features", "nothere.nc", "-o", "o/f.csv"], ["not found"]),
    (["features", "signal.csv", "-o", "o/f.txt"], [".csv or .parquet"]),
    (["features", "signal.csv", "-o", "o/f.csv", "--fs", "0 Hz"], ["fs"]),
    # compare
    (["compare", "a.nc", "b.nc", "-o", "o/c"], ["not found"]),
    (["compare", "signal.csv", "-o", "o/c"], ["at least 2"]),
    (["compare", "signal.csv", "short.csv", "--labels", "a", "-o", "o/c"], ["labels"]),
    (["compare", "signal.csv", "short.csv", "-o", "o/c"], ["signal.csv"]),
    # reproduce
    (["reproduce", "--jobs", "0", "-o", "o/r"], ["jobs"]),
    # usage errors of the command line itself (click)
    (["simulate", "--bogus-option", "-o", "o/x.nc"], ["--bogus-option"]),
    (["sweep", "-o", "o/sw"], ["--param"]),
]


def _inputs(folder: Path) -> set[str]:
    """The input files of the cases; returns their names (everything else is a leftover)."""
    (folder / "bad.toml").write_text(BAD_TOML)
    (folder / "latin1.toml").write_bytes("[params]\n# Fahrenheit: 100 \u00b0F\n".encode("latin-1"))
    (folder / "unknown_key.toml").write_text(UNKNOWN_KEY_TOML)
    (folder / "unknown_table.toml").write_text(UNKNOWN_TABLE_TOML)
    (folder / "bad_setting.toml").write_text(BAD_SETTING_TOML)
    (folder / "nan.toml").write_text(NAN_TOML)
    (folder / "folder").mkdir()
    rows = "\n".join(f"{i * 1e-3:.4f},{(i * 7919) % 13 - 6}" for i in range(2000))
    (folder / "signal.csv").write_text("time,acc\n" + rows + "\n")
    (folder / "short.csv").write_text("acc\n1\n2\n3\n")
    return {p.name for p in folder.iterdir()}


@pytest.mark.parametrize("args, words", CASES, ids=[" ".join(c[0]) for c in CASES])
def test_refused_command_writes_nothing(tmp_path, monkeypatch, capsys, args, words):
    """Exit 2, one line naming the problem, no traceback, and the folder as it was."""
    monkeypatch.chdir(tmp_path)
    before = _inputs(tmp_path)
    code = main([*args, "--no-progress"] if args[0] in ("simulate", "sweep") else args)
    captured = capsys.readouterr()
    lines = [line for line in captured.err.splitlines() if line.strip()]
    assert code == 2, captured.err
    assert len(lines) == 1, lines
    assert "Traceback" not in captured.err
    for w in words:
        assert w in lines[0], lines[0]
    left = {p.name for p in tmp_path.iterdir()} - before
    assert not left, f"left behind: {left}"


def test_parameter_of_another_model_is_named(tmp_path, monkeypatch, capsys):
    """--set contact_law=hertz on the default model names the selector values that enable it
    (the contact joints), instead of listing the default model's parameters."""
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "--set", "contact_law=hertz", "-o", "o/x.nc"]) == 2
    err = capsys.readouterr().err.strip()
    assert "crank_joint or crosshead_joint = 'contact' | 'lubricated'" in err
    assert "J1" not in err  # not the list of the compressor's parameters
    assert not list(tmp_path.iterdir())


#: Modules that take seconds to import (pint imports SciPy's top-level package, ~50 ms; its
#: submodules are the heavy part).
HEAVY = ("numba", "xarray", "matplotlib", "dask", "pandas", "scipy.signal", "scipy.linalg",
         "scipy.integrate", "recipdyn.integrate", "recipdyn.model.base")  # fmt: skip


def _fresh(args: list[str], tmp_path: Path) -> dict:
    """Run the command line in a new interpreter; its exit status, stderr and whether it
    loaded the heavy modules."""
    probe = (
        "import sys, json\n"
        "from recipdyn.cli import main\n"
        f"code = main({args!r})\n"
        f"heavy = sorted(m for m in {HEAVY!r} if m in sys.modules)\n"
        "print(json.dumps(dict(code=code, heavy=heavy)))\n"
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run([sys.executable, "-c", probe], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)  # fmt: skip
    return {**json.loads(done.stdout.strip().splitlines()[-1]), "err": done.stderr}


@pytest.mark.parametrize(
    "args",
    [
        ["simulate", "--rc", "-1 mm", "-o", "o/x.nc"],
        ["simulate", "--rc", "1 kg"],
        ["simulate", "--set", "discharge_presure=2 bar"],
        ["simulate", "--model", "compresor-contact"],
        ["simulate", "--method", "rk4", "--h", "-1 s"],
        ["simulate", "--rtol", "0"],
        ["analyze", "nothere.csv"],
        ["analyze", "x.csv", "--fs", "10 kg"],
        ["features", "nothere.nc", "-o", "f.csv"],
        ["compare", "a.nc", "b.nc"],
        ["reproduce", "--jobs", "0"],
        ["sweep", "-p", "rc=1mm,2mm", "--points", "0"],
        ["sweep", "-p", "rc=1mm:2mm:0"],  # (issue 44, item 9: after numba, xarray, SciPy)
        ["sweep", "-p", "rc=1mm,2mm", "-o", "x.csv/sweep"],  # an output it cannot make
    ],
    ids=lambda a: " ".join(a),
)
def test_refused_before_heavy_imports(tmp_path, args):
    """A usage or value error is answered before numba, xarray, SciPy, matplotlib, dask or the
    model kernels are imported (they take seconds; the answer must take well under one)."""
    (tmp_path / "x.csv").write_text("acc\n1\n2\n")
    res = _fresh(args, tmp_path)
    assert res["code"] == 2, res["err"]
    assert res["heavy"] == [], res["heavy"]
    assert not (tmp_path / "o").exists()


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0,
                    reason="root writes into a read-only folder")  # fmt: skip
def test_a_sweep_into_a_read_only_folder_is_refused_before_heavy_imports(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        res = _fresh(["sweep", "-p", "rc=1mm,2mm", "-o", "ro/sweep"], tmp_path)
    finally:
        ro.chmod(0o755)
    assert res["code"] == 2 and ("not writable" in res["err"] or "cannot create" in res["err"])
    assert res["heavy"] == [], res["heavy"]


def test_light_lists_match_the_library():
    """The command line checks methods and measures without loading the modules that define
    them; its lists must be theirs."""
    from recipdyn.cli.simulate import METHOD_NAMES
    from recipdyn.cli.sweep import _MEASURES
    from recipdyn.integrate import METHODS
    from recipdyn.sweep import MEASURES

    assert tuple(METHODS) == METHOD_NAMES
    assert tuple(MEASURES) == _MEASURES


def test_close_matches_suggest_the_misspelt_name_only():
    """The hint names the parameter meant, not every name that shares a suffix."""
    from recipdyn.model.parameters import SCHEMA
    from recipdyn.model.protocol import close_matches

    names = {*SCHEMA.names, *SCHEMA.aliases}
    assert close_matches("discharge_presure", names) == ["discharge_pressure"]
    assert close_matches("RC", names) == ["rc"]
    assert close_matches("subsidance", names) == ["subsidence"]
    assert close_matches("contact_law", names) == []


def test_models_table_shows_cross_field_bounds(capsys):
    """rc's allowed range is [0, r), not [0, inf]: the bound that depends on another parameter
    is shown, for the compressor and for the contact model's own subsidence limit."""
    from recipdyn.model.parameters import SCHEMA

    assert SCHEMA["rc"].range_text() == "[0, r) m"
    assert SCHEMA["d"].range_text() == "(-(l - r - rc), l - r - rc) m"
    assert main(["models", "compressor"]) == 0
    assert "[0, r) m" in capsys.readouterr().out
    assert main(["models", "compressor-contact"]) == 0
    assert "l - r - 1.5 (rc + rc_crosshead)" in capsys.readouterr().out


@pytest.mark.parametrize("d_mm, warned", [(5.0, False), (12.0, False), (13.0, True),
                                          (300.0, True), (-300.0, True)])  # fmt: skip
def test_implausible_subsidence_is_warned_with_the_reason(capsys, d_mm, warned):
    """A subsidence beyond 0.1 r (12 mm for the 2D12; the paper goes to 5 mm) is warned about,
    with the bound and why; the paper's values are not."""
    code = main(["simulate", "--d", f"{d_mm} mm", "--dump-config", "-"])
    err = capsys.readouterr().err
    assert code == 0
    assert ("warning:" in err) == warned
    if warned:
        assert "0.1 r = 12 mm" in err and "offset slider-crank" in err


def test_compile_note_names_the_configuration_and_its_measured_time():
    """The line said before compiling names the model and the configuration, says it happens
    once per configuration, and gives the CPU time measured for those kernels (the issue 44
    first run: "first run only, ~70 s" for variants that compile 80-500 s); the parts of a
    contact glue's configuration add up; another model's time is not claimed."""
    from recipdyn.cli.simulate import compile_note, compile_seconds

    glue = "recipdyn_assembled_contact_crank_valves_ambrosio_friction_28991f9c736b10ec.rhs"
    loop = "recipdyn.integrate.kernels.dop853_kernel"
    assert compile_seconds([glue]) == 13.0 + 115.0
    assert compile_seconds([glue, loop, "recipdyn.model.joints.pins.onset_crank"]) == 137.0
    assert compile_seconds(["recipdyn.model.compressor_valves.rhs_valves",
                            "recipdyn.model.compressor_valves.valve_impact"]) == 55.0  # fmt: skip
    assert compile_seconds(["recipdyn.model.reference.systems._lorenz"]) is None
    note = compile_note("compressor", "load = valves", [glue])
    assert note.startswith("compiling the kernels of compressor (load = valves): ~2 min of CPU")
    assert "once per configuration" in note and "first run only" not in note
    assert "a few seconds to a few minutes" in compile_note("my-model", "", ["m.rhs"])


def test_the_cache_index_says_before_whether_a_kernel_compiles(tmp_path):
    """`cache_holds` reads numba's cache index: a kernel with no machine code on disk for its
    signature compiles (False), the same in a new process after it was compiled loads
    (True); a dispatcher without a disk cache cannot tell (None)."""
    (tmp_path / "tiny_kernel.py").write_text(
        "import numba\n\n@numba.njit(cache=True)\ndef f(x):\n    return x + 1.0\n"
    )
    probe = ("import json, numba\nfrom recipdyn.model.base import cache_holds\n"
             "from tiny_kernel import f\nsig = (numba.float64,)\nbefore = cache_holds(f, sig)\n"
             "f.compile(sig)\n"
             "print(json.dumps([before, cache_holds(f, sig), "
             "cache_holds(numba.njit(lambda x: x), sig)]))\n")  # fmt: skip
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), *sys.path]),
           "NUMBA_CACHE_DIR": str(tmp_path / "cache")}  # fmt: skip
    runs = [subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True,
                           text=True, timeout=300) for _ in range(2)]  # fmt: skip
    first, second = (json.loads(r.stdout.strip().splitlines()[-1]) for r in runs)
    assert first == [False, True, None], runs[0].stderr
    assert second[0] is True


@pytest.mark.slow
def test_first_run_says_it_compiles_before_compiling(tmp_path):
    """With an empty numba cache, simulate says it is compiling before it starts (the line
    comes first on standard error) and names its phase "compiling" (it said "loading compiled
    kernels" for a 225.7 s compile); with the cache filled it says nothing of compiling.
    (The Lorenz system with the RK4 loop: the smallest compile, 4 s of CPU against 13 s for
    the DOP853 loop, which every other test compiles into the shared cache anyway.)"""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path),
           "NUMBA_CACHE_DIR": str(tmp_path / "cache")}  # fmt: skip
    cmd = [sys.executable, "-m", "recipdyn", "simulate", "--model", "lorenz", "--method", "rk4",
           "-n", "1", "--no-figure", "--no-progress", "-o", str(tmp_path / "d.nc")]  # fmt: skip
    first = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=1200)
    assert first.returncode == 0, first.stderr
    assert first.stderr.startswith("compiling the kernels of lorenz: "), first.stderr
    assert "loading compiled kernels" not in first.stderr
    again = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    assert again.returncode == 0 and "compiling" not in again.stderr, again.stderr


def test_a_record_too_short_for_the_signal_estimators_is_refused(tmp_path, monkeypatch, capsys):
    """A record of 64-199 samples passed analyze's length check and then stopped inside the
    signal's exponent estimators (which need MIN_SIGNAL_SAMPLES): "internal error", exit 1.
    It is refused up front now: exit 2, one line naming the length and the remedy."""
    from recipdyn.defaults import MIN_SIGNAL_SAMPLES

    monkeypatch.chdir(tmp_path)
    # one forcing period of the Duffing oscillator (5.24 time units) at 30 samples a unit
    assert main(["simulate", "--model", "duffing", "--revolutions", "1", "--fs", "30", "-o",
                 "short.nc", "--no-progress"]) == 0  # fmt: skip
    capsys.readouterr()
    code = main(["analyze", "short.nc"])
    err = [x for x in capsys.readouterr().err.splitlines() if x.strip()]
    assert code == 2 and len(err) == 1, err
    assert f"analyze needs at least {MIN_SIGNAL_SAMPLES}" in err[0] and "Traceback" not in err[0]
