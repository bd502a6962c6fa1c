"""Fault injection: the promises of docs/reliability.md under bad input, signals and faults.

The CLI is driven in-process (``main([...])``, for the many usage-error classes) and as a real
subprocess (``python -m recipdyn``) where signals, process trees and exit statuses matter.
Signals are sent at seeded random moments *after* some work is known to be finished (chunks on
disk), so every run exercises "stop in the middle, keep what is done". Sizes are reduced for
CI; the wider sets are marked ``slow`` (CI runs them too).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import uuid
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from recipdyn.cli import main
from recipdyn.errors import ParameterError

# ---------------------------------------------------------------------------------------------
# helpers


def _env(tag: str) -> dict[str, str]:
    env = dict(os.environ, MPLBACKEND="Agg", RECIPDYN_TEST_TAG=tag)
    env.pop("RECIPDYN_DEBUG", None)
    return env


def spawn(args, cwd, tag="") -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "recipdyn", *args],
        cwd=cwd,
        env=_env(tag or uuid.uuid4().hex),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def run_cli(args, cwd, timeout=300) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "recipdyn", *args],
        cwd=cwd,
        env=_env("x"),
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def tagged_processes(tag: str) -> list[int]:
    """Live processes started with RECIPDYN_TEST_TAG=tag (the CLI and all its workers)."""
    found = []
    needle = f"RECIPDYN_TEST_TAG={tag}".encode()
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            if needle in (d / "environ").read_bytes():
                status = (d / "status").read_text()
                if "\nState:\tZ" not in status:  # zombies have exited
                    found.append(int(d.name))
        except OSError:
            continue
    return found


def wait_for(pred, timeout=120.0, what="condition"):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        if pred():
            return
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def done_chunks(store: Path) -> int:
    d = store / "done" / "c"
    return sum(1 for _ in d.rglob("*") if _.is_file()) if d.exists() else 0


def no_traceback(*texts):
    for t in texts:
        assert "Traceback" not in t, t


needs_proc = pytest.mark.skipif(not Path("/proc/self/environ").exists(), reason="needs /proc")

SWEEP = [
    "sweep",
    "-p",
    "omega=15:25:16",
    "-m",
    "poincare,peak",
    "--points",
    "30",
    "--transient",
    "5",
    "--revolutions",
    "2",
    "--no-progress",
]


def load_store(path: Path) -> dict[str, np.ndarray]:
    with xr.open_zarr(str(path), consolidated=False) as ds:
        return {k: ds[k].values for k in ds.data_vars}


def assert_same_store(a: dict, b: dict):
    assert a.keys() == b.keys()
    assert np.array_equal(a["done"], b["done"]), (a["done"], b["done"])
    assert [str(x) for x in a["error"].ravel()] == [str(x) for x in b["error"].ravel()], (
        a["error"],
        b["error"],
    )
    for k in a:
        if a[k].dtype.kind == "f":
            assert np.array_equal(a[k], b[k], equal_nan=True), k
        else:
            assert np.array_equal(a[k], b[k]), k


# ---------------------------------------------------------------------------------------------
# 1. every usage-error class: exit 2, one clear line, no traceback

USAGE = [
    (["simulate", "--bogus"], "No such option"),
    (["simulate", "--rc"], "requires an argument"),
    (["nocommand"], "No such command"),
    (["sweep"], "Missing option"),
    (["sweep", "-p", "omega=1:2:3", "--points", "x"], "--points"),
    (["simulate", "--rtol", "abc"], "--rtol"),
    (["simulate", "-n", "abc"], "revolutions"),
    (["simulate", "--rc", "1 parsec/s"], "rc"),
    (["simulate", "--rc", "1e-300"], "rc"),
    (["simulate", "--rc", "1e-12"], "rc"),
    (["simulate", "--rc", "1 m"], "rc"),
    (["simulate", "--omega", "-5"], "omega"),
    (["simulate", "--rtol", "0"], "rtol"),
    (["simulate", "--rtol", "-1e-9"], "rtol"),
    (["simulate", "--atol", "-1"], "atol"),
    (["simulate", "--method", "rk4", "--h", "0 s"], "h"),
    (["simulate", "--method", "rk5"], "method"),
    (["simulate", "-n", "1e7", "--no-stream"], "memory"),
    (["simulate", "--fs", "1 THz", "--no-stream"], "memory"),
    (["simulate", "-n", "1e7"], "disk"),  # streamed by default: memory is flat, disk is not
    (["simulate", "--fs", "1 THz"], "disk"),
    (["simulate", "-o", "run.txt"], "extension"),
    (["sweep", "-p", "omega=10:20:1000000000"], "count"),
    (["sweep", "-p", "omega=10:20:100000", "-p", "rc=1mm:2mm:1000"], "split"),
    (["sweep", "-p", "omega=10:20:3", "--rtol", "0"], "rtol"),
    (["sweep", "-p", "omega=10:20:3", "--points", "0"], "points"),
    (["sweep", "-p", "omega=10:20:3", "--workers", "0"], "workers"),
    (["sweep", "-p", "omega=10:20:3", "--dask-local", "0"], "dask_local"),
    (["sweep", "-p", "omega=10:20:3", "--transient", "-1"], "transient"),
    (["sweep", "-p", "omega=10:20:3", "--transient", "2.5", "--continuation"], "whole number"),
    (["sweep", "-p", "omega=10:20:3", "-m", "peak", "--fs", "1 THz"], "memory"),
    (["calibrate", "-j", "0"], "jobs"),
    (["reproduce", "-j", "0"], "jobs"),
    (["analyze", "missing.nc"], "not found"),
    (["plot", "missing.zarr"], "not found"),
]


@pytest.mark.parametrize("args,word", USAGE, ids=[" ".join(a)[:40] for a, _ in USAGE])
def test_usage_errors_exit_2_without_traceback(tmp_path, monkeypatch, capsys, args, word):
    monkeypatch.chdir(tmp_path)
    assert main(args) == 2
    cap = capsys.readouterr()
    no_traceback(cap.out, cap.err)
    assert word in cap.err + cap.out


def test_usage_error_through_the_console_script(tmp_path):
    """The installed entry point (not just main()) exits 2 without a traceback."""
    for args in (["simulate", "--bogus"], ["nocommand"], ["simulate", "--rc", "5 parsec"]):
        r = run_cli(args, tmp_path, timeout=120)
        assert r.returncode == 2, (args, r.stderr)
        no_traceback(r.stdout, r.stderr)


def test_version(capsys):
    from recipdyn import __version__

    assert main(["--version"]) == 0
    assert __version__ in capsys.readouterr().out


# ---------------------------------------------------------------------------------------------
# 2. wrong input files: a clear message naming what is missing, exit 2


def _write_inputs(d: Path) -> dict[str, Path]:
    files = {
        "text": d / "t.txt",
        "empty": d / "e.nc",
        "foreign": d / "foreign.nc",
        "folder": d / "folder",
        "bad_toml": d / "bad.toml",
        "latin1": d / "latin1.toml",
    }
    files["text"].write_text("hello\n")
    files["empty"].write_bytes(b"")
    xr.Dataset({"foo": ("t", np.arange(5.0))}).to_netcdf(files["foreign"])
    files["folder"].mkdir()
    files["bad_toml"].write_text("[params\nrc = ")
    files["latin1"].write_bytes("[params]\nrc = '1 µm'\n".encode("latin-1"))
    return files


@pytest.mark.parametrize(
    "command,kind,word",
    [
        ("analyze", "text", "cannot be read"),
        ("analyze", "empty", "empty"),
        ("analyze", "foreign", "sampling rate"),  # not a recipdyn run: read as a signal
        ("analyze", "folder", "folder"),
        ("plot", "text", "sweep store"),
        ("plot", "foreign", "sweep store"),
        ("plot", "folder", "sweep store"),
        ("simulate -c", "bad_toml", "malformed"),
        ("simulate -c", "latin1", "UTF-8"),
        ("simulate -c", "folder", "folder"),
        ("simulate -c", "empty", ""),
    ],
)
def test_wrong_input_files(tmp_path, monkeypatch, capsys, command, kind, word):
    monkeypatch.chdir(tmp_path)
    files = _write_inputs(tmp_path)
    args = [*command.split(), str(files[kind])]
    code = main([*args, "--no-figure", "-n", "0.05"] if command.startswith("simulate") else args)
    cap = capsys.readouterr()
    if kind == "empty" and command.startswith("simulate"):
        # the empty file is e.nc: a recorded run is a config, and an empty one is not
        assert code == 2 and "empty" in cap.err
        toml = tmp_path / "e.toml"
        toml.write_text("")
        assert main(["simulate", "-c", str(toml), "--no-figure", "-n", "0.05"]) == 0
        return
    assert code == 2, cap.err
    no_traceback(cap.out, cap.err)
    assert word in cap.err


def test_one_sample_run_gives_figure_and_clear_analyze_refusal(tmp_path, capsys):
    run = tmp_path / "one.nc"
    assert main(["simulate", "-n", "1e-9", "-o", str(run), "--no-progress"]) == 0
    assert xr.open_dataset(run).sizes["time"] == 1
    assert run.with_suffix(".png").stat().st_size > 1000
    assert main(["analyze", str(run)]) == 2
    assert "at least" in capsys.readouterr().err


# ---------------------------------------------------------------------------------------------
# 3. outputs: checked before work, written atomically, in the format the extension names


def test_bad_output_path_is_reported_before_any_work(tmp_path, capsys, monkeypatch):
    sim = sys.modules["recipdyn.simulate"]  # the package attribute is the function
    called = []
    monkeypatch.setattr(sim, "integrate", lambda *a, **k: called.append(1))
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["simulate", "-o", str(blocker / "run.nc")]) == 2
    assert (
        main(["sweep", "-p", "omega=10:20:2", "-o", str(blocker / "sw"), "--backend", "serial"])
        == 2
    )
    assert not called
    assert "cannot create folder" in capsys.readouterr().err


@pytest.mark.parametrize("ext", [".nc", ".csv", ".zarr"])
def test_output_format_follows_the_extension(tmp_path, ext):
    out = tmp_path / f"run{ext}"
    assert (
        main(
            [
                "simulate",
                "-n",
                "0.2",
                "--fs",
                "2 kHz",
                "-o",
                str(out),
                "--no-figure",
                "--no-progress",
            ]
        )
        == 0
    )
    if ext == ".nc":
        assert xr.open_dataset(out).a.attrs["units"] == "m/s**2"
    elif ext == ".zarr":
        assert (out / "zarr.json").exists() and "a" in xr.open_zarr(str(out), consolidated=False)
    else:
        lines = out.read_text().splitlines()
        header = next(ln for ln in lines if not ln.startswith("#"))
        assert header.startswith("time [s],") and "a [m/s**2]" in header
        assert any(ln.startswith("# param_rc = ") for ln in lines)
        data = np.loadtxt(out, delimiter=",", comments="#", skiprows=lines.index(header) + 1)
        assert data.shape[0] == 1 + int(0.2 * 2 * np.pi / 20 * 2000)


def test_failed_write_keeps_the_previous_file(tmp_path, monkeypatch, capsys):
    """A write that fails halfway (disk full, simulated) leaves the old file intact, no
    temporary file behind, and exits 2 with the reason."""
    out = tmp_path / "run.nc"
    args = [
        "simulate",
        "-n",
        "0.2",
        "--fs",
        "2 kHz",
        "-o",
        str(out),
        "--no-figure",
        "--no-progress",
    ]
    assert main(args) == 0
    before = out.read_bytes()

    def full_disk(self, path, *a, **k):
        Path(path).write_bytes(b"partial")
        raise OSError(28, "No space left on device", str(path))

    monkeypatch.setattr(xr.Dataset, "to_netcdf", full_disk)
    assert main([*args[:-4], "--rc", "2 mm", "-o", str(out), "--no-figure", "--no-progress"]) == 2
    assert "No space left" in capsys.readouterr().err
    assert out.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc"]


def test_real_full_disk_on_a_small_tmpfs(tmp_path):
    """Where a tmpfs can be mounted (root on Linux), a genuinely full disk: exit 2 (or 1),
    no traceback, no partial file under the final name."""
    mnt = tmp_path / "small"
    mnt.mkdir()
    r = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=256k", "tmpfs", str(mnt)], capture_output=True
    )
    if r.returncode != 0:
        pytest.skip("cannot mount a tmpfs here")
    try:
        out = mnt / "run.nc"
        res = run_cli(
            ["simulate", "-n", "3", "-o", str(out), "--no-figure", "--no-progress"], tmp_path
        )
        assert res.returncode == 2, res.stderr
        no_traceback(res.stderr)
        assert "cannot write" in res.stderr and "MB free" in res.stderr
        assert not out.exists()
        assert list(mnt.iterdir()) == []
    finally:
        subprocess.run(["umount", str(mnt)], capture_output=True)


# ---------------------------------------------------------------------------------------------
# 4. progress observes, never changes


@pytest.mark.parametrize("method,revs", [("dop853", 20), ("rk4", 2)])
def test_progress_does_not_change_results(method, revs):
    """The issue's case: 150 rad/s, offset 0.2 rad (peak |a| differed by 40 % before)."""
    from recipdyn import simulate

    kw = dict(omega=150.0, theta_c_offset=0.2, revolutions=revs, method=method)
    a = simulate(progress=False, **kw)
    b = simulate(progress=True, **kw)
    assert np.array_equal(a.a.values, b.a.values)
    assert a.attrs["solver_nsteps"] == b.attrs["solver_nsteps"]


def test_chunking_is_invisible():
    """Any number of chunks (progress stops) gives the same steps and samples, bit for bit."""
    from recipdyn.integrate import integrate
    from recipdyn.model import CompressorParams, compressor_model

    m = compressor_model(CompressorParams(theta_c_offset=0.3))
    te = np.linspace(0, 5 * m.period, 4001)
    ref = integrate(m, m.initial_state(), (0, te[-1]), t_eval=te)
    for chunks in (2, 7, 333):
        got = integrate(m, m.initial_state(), (0, te[-1]), t_eval=te, chunks=chunks)
        assert np.array_equal(ref.y, got.y) and ref.nsteps == got.nsteps


def test_cli_progress_flag_same_file_content(tmp_path):
    outs = []
    for flag in ("--progress", "--no-progress"):
        out = tmp_path / f"r{flag}.nc"
        assert (
            main(
                [
                    "simulate",
                    "--omega",
                    "150",
                    "--set",
                    "theta_c_offset=0.2",
                    "-n",
                    "5",
                    "-o",
                    str(out),
                    "--no-figure",
                    flag,
                ]
            )
            == 0
        )
        outs.append(xr.open_dataset(out))
    for k in ("a", "theta_c", "contact_force"):
        assert np.array_equal(outs[0][k].values, outs[1][k].values)


# ---------------------------------------------------------------------------------------------
# 5. signals: prompt stop, keep what is finished, exit 128+N, no process left behind


@needs_proc
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_simulate_interrupted_keeps_partial_record(tmp_path, sig):
    import re
    import threading

    tag = uuid.uuid4().hex
    out = tmp_path / "long.nc"
    p = spawn(
        [
            "simulate",
            "--set",
            "theta_c_offset=0.3",
            "-n",
            "2000",
            "-o",
            str(out),
            "--no-figure",
            "--progress",
        ],
        tmp_path,
        tag,
    )
    chunks: list[str] = []
    reader = threading.Thread(target=lambda: chunks.extend(iter(lambda: p.stderr.read(64), "")))
    reader.start()

    def integrating():  # the progress bar has advanced: compiled code loaded, samples exist
        m = re.findall(r"(\d+)%\|", "".join(chunks))
        return (m and int(m[-1]) >= 1) or p.poll() is not None

    wait_for(integrating, timeout=180, what="the integration to advance")
    p.send_signal(sig)
    p.wait(timeout=60)
    reader.join(timeout=10)
    err = "".join(chunks)
    assert p.returncode == 128 + sig, err
    no_traceback(err)
    assert "kept:" in err and "partial record" in err
    part = tmp_path / "long.partial.nc"
    ds = xr.open_dataset(part)
    assert ds.attrs["solver_status"] == "interrupted"
    assert 0 < ds.sizes["time"] < 2000 * 2 * np.pi / 20 * 1e4
    assert np.all(np.isfinite(ds.a.values))
    assert not out.exists()
    assert tagged_processes(tag) == []


@needs_proc
@pytest.mark.parametrize("seed", [0, 1])
def test_sweep_interrupted_at_random_moment_then_resumed_equals_uninterrupted(tmp_path, seed):
    """SIGINT/SIGTERM at a random moment after 1-4 points are stored: exit 130/143, kept points
    reported, workers gone; --resume finishes and equals an uninterrupted sweep bit for bit."""
    rng = np.random.default_rng(seed)
    sig = (signal.SIGINT, signal.SIGTERM)[seed % 2]
    tag = uuid.uuid4().hex
    out = tmp_path / "a"
    p = spawn([*SWEEP, "-o", str(out), "--workers", "2"], tmp_path, tag)
    k = int(rng.integers(1, 5))
    wait_for(
        lambda: done_chunks(out / "sweep.zarr") >= k or p.poll() is not None,
        what="first stored points",
    )
    time.sleep(float(rng.uniform(0, 0.3)))
    p.send_signal(sig)
    _, err = p.communicate(timeout=60)
    if p.returncode == 0:
        pytest.skip("the sweep finished before the signal arrived")
    assert p.returncode == 128 + sig, err
    no_traceback(err)
    assert "kept:" in err and "--resume" in err
    wait_for(lambda: tagged_processes(tag) == [], timeout=10, what="workers to exit")
    r = run_cli([*SWEEP, "-o", str(out), "--workers", "2", "--resume"], tmp_path)
    assert r.returncode == 0, r.stderr
    ref = tmp_path / "ref"
    assert main([*SWEEP, "-o", str(ref), "--backend", "serial"]) == 0
    assert_same_store(load_store(ref / "sweep.zarr"), load_store(out / "sweep.zarr"))


@needs_proc
def test_workers_exit_when_the_parent_is_killed(tmp_path):
    tag = uuid.uuid4().hex
    out = tmp_path / "k"
    p = spawn([*SWEEP, "-o", str(out), "--workers", "2"], tmp_path, tag)
    wait_for(
        lambda: len(tagged_processes(tag)) >= 3 or p.poll() is not None, what="workers to start"
    )
    if p.poll() is not None:
        pytest.skip("the sweep finished before it could be killed")
    p.kill()
    p.wait(timeout=10)
    wait_for(lambda: tagged_processes(tag) == [], timeout=15, what="orphaned workers to exit")


@needs_proc
def test_continuation_resume_after_kill9_equals_uninterrupted(tmp_path):
    """kill -9 in the middle of a continuation sweep; --resume restarts from the recorded
    final state of the last stored point and recomputes everything after it."""
    args = [
        "sweep",
        "-p",
        "omega=18:22:8",
        "-m",
        "poincare",
        "--points",
        "40",
        "--transient",
        "3",
        "--continuation",
        "--set",
        "theta_c_offset=0.2",
        "--no-progress",
    ]
    out = tmp_path / "c"
    tag = uuid.uuid4().hex
    p = spawn([*args, "-o", str(out)], tmp_path, tag)
    wait_for(
        lambda: done_chunks(out / "sweep.zarr") >= 2 or p.poll() is not None,
        what="two stored points",
    )
    if p.poll() is not None:
        pytest.skip("the sweep finished before it could be killed")
    p.kill()
    p.wait(timeout=10)
    r = run_cli([*args, "-o", str(out), "--resume"], tmp_path)
    assert r.returncode == 0, r.stderr
    ref = tmp_path / "ref"
    assert main([*args, "-o", str(ref)]) == 0
    assert_same_store(load_store(ref / "sweep.zarr"), load_store(out / "sweep.zarr"))


@needs_proc
def test_reproduce_interrupted_keeps_cache(tmp_path):
    tag = uuid.uuid4().hex
    out = tmp_path / "rep"
    p = spawn(["reproduce", "--quick", "-o", str(out), "-j", "2", "--no-progress"], tmp_path, tag)
    cache = out / "cache"
    wait_for(
        lambda: (cache.exists() and any(cache.glob("*.nc"))) or p.poll() is not None,
        timeout=180,
        what="a cached run",
    )
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=60)
    if p.returncode == 0:
        pytest.skip("reproduce finished before the signal")
    assert p.returncode == 130, err
    no_traceback(err)
    assert "kept:" in err and "runs in" in err
    wait_for(lambda: tagged_processes(tag) == [], timeout=10, what="workers to exit")
    kept = sorted(cache.glob("*.nc"))
    assert kept and not list(cache.glob(".*tmp*"))
    for f in kept:  # every kept entry is complete
        xr.open_dataset(f).load()


# ---------------------------------------------------------------------------------------------
# 6. resume verifies what it reuses


def _small_sweep(out, **kw):
    from recipdyn.sweep import SweepSpec, parse_axis, run_sweep

    spec = SweepSpec(
        axes=(parse_axis("omega=15:25:4"),),
        measures=("poincare", "peak"),
        settings=dict(
            revolutions=1.0,
            transient=2.0,
            points=10,
            lyap_revolutions=5.0,
            fs=2000.0,
            rtol=1e-9,
            atol=1e-11,
        ),
    )
    return run_sweep(spec, out, backend="serial", progress=False, **kw)


def test_corrupted_and_truncated_chunks_are_recomputed(tmp_path, capsys):
    store = _small_sweep(tmp_path / "s")
    ref = load_store(store)
    (store / "poincare_v" / "c" / "1" / "0").write_bytes(b"\x00garbage")  # corrupted
    f = store / "peak_a" / "c" / "2"
    f.write_bytes(f.read_bytes()[:3])  # truncated
    (store / "done" / "c" / "3").write_bytes(b"\xff")  # torn 'done' chunk
    seen = []
    _small_sweep(tmp_path / "s", resume=True, on_point=lambda r: seen.append(r["index"]))
    assert sorted(seen) == [(1,), (2,), (3,)]
    assert_same_store(ref, load_store(store))


def test_block_store_torn_chunk_recomputes_its_points(tmp_path, monkeypatch):
    """Large grids keep several points in one chunk (here forced: 3 a chunk on a 7-point axis,
    chunks [0-2], [3-5], [6]); a corrupted chunk damages every point in it, and a resume
    recomputes exactly those, ending equal to the uninterrupted store. The parallel writer's
    batches (written run by run, one Zarr call per variable) give the same store as the
    serial one."""
    from recipdyn.sweep import SweepSpec, parse_axis, run_sweep
    from recipdyn.sweep import run as R

    monkeypatch.setattr(R, "BLOCK_ABOVE", 2)
    monkeypatch.setattr(R, "POINT_BLOCK", 3)
    spec = SweepSpec(axes=(parse_axis("omega=15:25:7"),), measures=("poincare", "peak"),
                     settings=dict(revolutions=1.0, transient=2.0, points=10, fs=2000.0,
                                   rtol=1e-9, atol=1e-11))  # fmt: skip
    store = run_sweep(spec, tmp_path / "s", backend="serial", progress=False)
    import zarr

    assert zarr.open_array(str(store / "peak_a"), mode="r").chunks == (3,)
    ref = load_store(store)
    batched = run_sweep(spec, tmp_path / "p", backend="processes", workers=2, progress=False)
    assert_same_store(ref, load_store(batched))
    (store / "peak_a" / "c" / "1").write_bytes(b"\x00garbage")  # points 3, 4, 5
    seen = []
    run_sweep(spec, tmp_path / "s", backend="serial", resume=True, progress=False,
              on_point=lambda r: seen.append(r["index"]))  # fmt: skip
    assert sorted(seen) == [(3,), (4,), (5,)]
    assert_same_store(ref, load_store(store))


def test_missing_data_chunk_is_not_counted_as_done(tmp_path):
    store = _small_sweep(tmp_path / "s")
    ref = load_store(store)
    (store / "poincare_a" / "c" / "0" / "0").unlink()  # lost (reads back as fill values)
    seen = []
    _small_sweep(tmp_path / "s", resume=True, on_point=lambda r: seen.append(r["index"]))
    assert seen == [(0,)]
    assert_same_store(ref, load_store(store))


def test_resume_refuses_a_different_spec_and_a_broken_store(tmp_path, capsys):
    _small_sweep(tmp_path / "s")
    assert (
        main(
            [
                "sweep",
                "-p",
                "omega=15:25:5",
                "-o",
                str(tmp_path / "s"),
                "--resume",
                "--backend",
                "serial",
                "--no-progress",
            ]
        )
        == 2
    )
    assert "different sweep spec" in capsys.readouterr().err
    (tmp_path / "s" / "sweep.zarr" / "zarr.json").write_text("{not json")
    with pytest.raises(ParameterError, match="cannot be opened"):
        _small_sweep(tmp_path / "s", resume=True)


def test_truncated_reproduce_cache_entry_is_recomputed(tmp_path):
    from recipdyn.reproduce import CASES, VARIANTS
    from recipdyn.reproduce.runner import RunSpec, Settings, run_all

    s = Settings().quick()
    specs = [RunSpec(CASES[0], VARIANTS[0], s)]
    first = run_all(specs, tmp_path, jobs=1)
    f = next(tmp_path.glob("*.nc"))
    f.write_bytes(f.read_bytes()[:500])
    seen = []
    again = run_all(specs, tmp_path, jobs=1, progress=lambda k, cached: seen.append(cached))
    assert seen == [False]  # recomputed, not used
    key = (CASES[0].id, VARIANTS[0].id)
    np.testing.assert_array_equal(first[key].a.values, again[key].a.values)


# ---------------------------------------------------------------------------------------------
# 7. one run per output folder


@needs_proc
def test_second_sweep_on_the_same_folder_refuses(tmp_path):
    out = tmp_path / "busy"
    p = spawn([*SWEEP, "-o", str(out), "--workers", "1"], tmp_path)
    try:
        wait_for(
            lambda: (
                (out / ".recipdyn.lock").exists()
                and (out / ".recipdyn.lock").read_text().startswith("{")
                or p.poll() is not None
            ),
            what="the lock",
        )
        r = run_cli([*SWEEP, "-o", str(out), "--force"], tmp_path, timeout=120)
        if p.poll() is None:
            assert r.returncode == 2, r.stderr
            assert "in use by another recipdyn run" in r.stderr
            assert f"pid {p.pid}" in r.stderr
            no_traceback(r.stderr)
    finally:
        p.kill()
        p.wait()


def test_stale_lock_from_a_killed_run_is_taken_over(tmp_path):
    out = tmp_path / "stale"
    out.mkdir()
    (out / ".recipdyn.lock").write_text(json.dumps({"pid": 999999, "host": "gone"}))
    store = _small_sweep(out)
    assert load_store(store)["done"].all()


# ---------------------------------------------------------------------------------------------
# 8. failures keep the partial record; extreme valid inputs finish or refuse


def test_integrator_failure_keeps_partial_record_and_exits_1(tmp_path, capsys):
    out = tmp_path / "blow.nc"
    code = main(
        [
            "simulate",
            "--set",
            "equations=paper-printed",
            "--set",
            "load_sign=paper",
            "--set",
            "theta_c_offset=1.0",
            "-n",
            "2",
            "--fs",
            "5 kHz",
            "-o",
            str(out),
            "--no-figure",
            "--no-progress",
        ]
    )
    err = capsys.readouterr().err
    assert code == 1 and "integration failed" in err and "kept:" in err
    ds = xr.open_dataset(tmp_path / "blow.partial.nc")
    assert ds.sizes["time"] > 10 and np.all(np.isfinite(ds.a.values))
    assert ds.attrs["solver_status"] != "reached the end of the interval"
    assert not out.exists()


def test_smallest_clearance_finishes(tmp_path):
    """rc at its lower bound (0.1 um) integrates a revolution in bounded time (~0.4-0.8 million
    steps) and stays at the ideal mechanism's peak from the natural start."""
    from recipdyn import simulate
    from recipdyn.defaults import RC_MIN

    ds = simulate(rc=RC_MIN, revolutions=0.5, fs=2000)
    assert ds.attrs["solver_nsteps"] < 2_000_000
    assert float(abs(ds.a).max()) == pytest.approx(57.6, rel=2e-3)


def test_run_command(tmp_path, capsys):
    assert main(["run", "-o", str(tmp_path)]) == 0
    ds = xr.open_dataset(tmp_path / "base_case.nc")
    assert ds.attrs["revolutions"] == 10 and float(ds.attrs["param_rc"]) == 1e-3
    assert (tmp_path / "base_case.png").stat().st_size > 10_000


# ---------------------------------------------------------------------------------------------
# 9. property-based: parsing never fails with anything but a clear ParameterError


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.text(max_size=40))
def test_axis_parsing_fuzz(text):
    from recipdyn.sweep import parse_axis

    try:
        axis = parse_axis(text)
    except ParameterError as exc:
        assert str(exc)
    else:
        assert len(axis.values) >= 1 and all(np.isfinite(axis.values))


@settings(max_examples=150, deadline=None)
@given(
    st.sampled_from(["rc", "omega", "d", "m3", "fs", "revolutions"]),
    st.one_of(st.text(max_size=20), st.floats(allow_nan=True, allow_infinity=True)),
)
def test_quantity_parsing_fuzz(name, value):
    from recipdyn.units import to_si

    try:
        v = to_si(name, value)
    except ParameterError as exc:
        assert name in str(exc)
    else:
        assert isinstance(v, float) and not np.isnan(v)


@settings(max_examples=200, deadline=None)
@given(
    st.dictionaries(
        st.sampled_from(
            [
                "r",
                "l",
                "rc",
                "d",
                "omega",
                "m2",
                "m3",
                "J2",
                "theta_c_offset",
                "load_amplitude",
                "g",
            ]
        ),
        st.floats(allow_nan=True, allow_infinity=True, width=64),
        max_size=4,
    )
)
def test_parameters_fuzz(values):
    """Any combination of values either builds valid parameters or raises a ParameterError
    that names one of the given parameters."""
    from recipdyn.model import CompressorParams

    try:
        CompressorParams(**values)
    except ParameterError as exc:
        assert any(k in str(exc) for k in (*values, "m2, m3, J2"))


# ---------------------------------------------------------------------------------------------
# 10. one place for defaults


def test_every_layer_uses_the_shared_defaults():
    import inspect

    from recipdyn import defaults
    from recipdyn.analysis import classify, lyapunov_spectrum
    from recipdyn.analyze import analyze_run
    from recipdyn.cli.sweep import DEFAULTS as SWEEP_DEFAULTS
    from recipdyn.config import SimulationConfig
    from recipdyn.integrate import integrate
    from recipdyn.simulate import DEFAULT_SETTINGS

    def default(fn, name):
        return inspect.signature(fn).parameters[name].default

    for fn in (integrate, lyapunov_spectrum, analyze_run):
        assert default(fn, "rtol") == defaults.RTOL and default(fn, "atol") == defaults.ATOL
    assert DEFAULT_SETTINGS["rtol"] == SimulationConfig().rtol == SWEEP_DEFAULTS["rtol"]
    assert default(classify, "lyap_tol") == defaults.LYAP_TOL


def test_orphaned_temporary_results_are_removed(tmp_path):
    """A worker terminated inside atomic_path leaves its temporary folder; remove_orphans
    removes the ones whose process is gone and keeps a live process's and every result."""
    import subprocess
    import sys

    from recipdyn.io import atomic_path, remove_orphans

    done = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)  # fmt: skip
    dead = int(done.stdout)
    orphan = tmp_path / f".run.nc.tmp-{dead}-abc"
    orphan.mkdir()
    (orphan / "run.nc").write_bytes(b"half")
    (tmp_path / "kept.nc").write_bytes(b"result")
    with atomic_path(tmp_path / "live.nc") as tmp:  # this process's: alive
        tmp.write_bytes(b"x")
        assert remove_orphans(tmp_path) == 1
        assert tmp.exists() and not orphan.exists()
    assert (tmp_path / "kept.nc").read_bytes() == b"result"
    assert (tmp_path / "live.nc").read_bytes() == b"x"
