"""Benchmark (issue 15 target 3, issue 44 item 11): the peak memory of each run, its own.

Every measurement runs in a fresh process, which reports its own peak resident set at the
end: ``VmHWM`` of ``/proc/self/status`` on Linux (the high-water mark of the process's own
address space, which starts anew at ``exec``). Not ``ru_maxrss``: Linux carries that over a
``fork`` and ``exec``, so a child of a large parent reports the parent's peak when it is
larger (this benchmark reported 1 433 MB for every run length when ``run_all.py`` had grown
to 1.4 GB before it). Where there is no ``/proc``, the parent samples the child's resident
set with psutil every 10 ms (a lower bound of the peak). MB here are 2^20 bytes.

Rows, each after one warm-up run that fills numba's cache (so that a row measures a run, not
the compilation):

* ``recipdyn simulate -n N --fs "10 kHz"`` as a user runs it (the record and its figure; in
  memory up to 10^6 samples, streamed to the file above): N = 1, 100, 2000, 10^4 (quick: up
  to 2000), and ``-n 1 --no-figure``: the command's baseline, what every run of it holds
  whatever its length (the interpreter, the libraries, the compiled kernels);
* ``recipdyn.simulate(revolutions=N, fs=10 kHz)`` in Python: in memory (the Dataset returned
  whole; N = 100, 1000) and streamed to NetCDF block by block (``out=...``; N = 100, 1000,
  10^4, quick: up to 1000, from which the slope per revolution gives 10^4).

Targets: the command's baseline under 300 MB; 10^4 revolutions streamed under 300 MB.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: The default model's crank period (s): 20 rad/s.
PERIOD = 2 * 3.141592653589793 / 20.0

#: Run in the child: its own peak resident set in MB (None without /proc).
_PEAK = r"""
def _own_peak_mb():
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    return None
"""

#: ``recipdyn simulate ARGS`` in a fresh interpreter; writes its exit status and peak.
_CLI = (
    _PEAK
    + r"""
import json, sys
from recipdyn.cli import main
report, args = sys.argv[1], sys.argv[2:]
code = main(args)
with open(report, "w") as f:
    json.dump(dict(code=code, peak_mb=_own_peak_mb()), f)
"""
)

#: ``recipdyn.simulate`` in Python: in memory, then written, or streamed to the file.
_LIBRARY = (
    _PEAK
    + r"""
import json, os, sys
import recipdyn
report, revs, mode, out = sys.argv[1], float(sys.argv[2]), sys.argv[3], sys.argv[4]
kw = dict(out=out) if mode == "streamed" else {}
ds = recipdyn.simulate(revolutions=revs, transient=0, fs=10_000.0, progress=False, **kw)
if mode == "memory":
    ds.to_netcdf(out)
with open(report, "w") as f:
    json.dump(dict(code=0, samples=ds.sizes["time"], file_mb=os.path.getsize(out) / 1e6,
                   peak_mb=_own_peak_mb()), f)
"""
)


#: ``make bench`` runs the quick mode (330 s on a loaded 2-core machine, 2026-12-07); the
#: 10^4-revolution rows add two runs of 6-8 minutes each and 8.6 GB of files (``--full``).
RUN_ALL_ARGV = ["--quick"]


def measure(code: str, args: list[str], cwd: str) -> dict:
    """Run ``code`` with ``args`` in a fresh interpreter in ``cwd``; its own peak (MB), wall
    time and exit status (``error`` when it failed)."""
    import psutil

    report = Path(cwd) / "report.json"
    report.unlink(missing_ok=True)
    t0 = time.perf_counter()
    cmd = [sys.executable, "-c", code, str(report), *args]
    proc = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)  # fmt: skip
    sampled = 0.0  # psutil's view from outside, for a system without /proc
    try:
        ps = psutil.Process(proc.pid)
        while proc.poll() is None:
            try:
                sampled = max(sampled, ps.memory_info().rss / 2**20)
            except psutil.Error:
                break
            time.sleep(0.01)
    except psutil.Error:
        pass
    err = proc.communicate()[1]
    wall = time.perf_counter() - t0
    if proc.returncode != 0 or not report.exists():
        last = (err.strip().splitlines() or [f"exit status {proc.returncode}"])[-1]
        return {"error": last, "wall_s": wall}
    res = json.loads(report.read_text())
    if res.get("code"):
        return {"error": f"exit status {res['code']}: {err.strip()[-300:]}", "wall_s": wall}
    res["how"] = "VmHWM" if res.get("peak_mb") is not None else "psutil, sampled"
    res["peak_mb"] = res["peak_mb"] if res.get("peak_mb") is not None else sampled
    res["wall_s"] = wall
    return res


def cli(args: list[str], cwd: str) -> dict:
    return measure(_CLI, ["simulate", *args, "--no-progress"], cwd)


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true",
                    help="command up to -n 2000, library up to 1000 revolutions")  # fmt: skip
    args = ap.parse_args(argv)
    from recipdyn.cli.simulate import STREAM_AUTO  # (light: no numerical library)

    big = () if args.quick else (10_000,)
    rows: list[dict] = []
    with tempfile.TemporaryDirectory() as tmp:
        # the first run fills numba's cache (a new one after any change of the sources): the
        # rows then measure a run, not the compilation (725 MB peak in every row of a run
        # whose cache was cold, 2026-11-25)
        warm = cli(["-n", "1", "--fs", "10 kHz", "-o", "warm.nc"], tmp)
        if "error" in warm:
            raise RuntimeError(f"warm-up run failed: {warm['error']}")
        cases = [("command", n, ["-n", str(n), "--fs", "10 kHz", "-o", f"c{n}.nc"])
                 for n in (1, 100, 2000, *big)]  # fmt: skip
        cases.insert(0, ("command, --no-figure", 1,
                         ["-n", "1", "--fs", "10 kHz", "--no-figure", "-o", "b.nc"]))  # fmt: skip
        for what, n, cmd in cases:
            r = cli(cmd, tmp)
            streamed = n * PERIOD * 10_000 > STREAM_AUTO  # as the command decides
            r.update(what=what, revolutions=n, mode="streamed" if streamed else "memory")
            rows.append(r)
        for mode, lengths in (("memory", (100, 1000)), ("streamed", (100, 1000, *big))):
            for n in lengths:
                r = measure(_LIBRARY, [str(n), mode, f"{mode}{n}.nc"], tmp)
                r.update(what="recipdyn.simulate", revolutions=n, mode=mode)
                rows.append(r)
    print(f"{'run':22s} {'revolutions':>11} {'mode':>9} {'peak MB':>8} {'wall s':>7}  how")
    for r in rows:
        head = f"{r['what']:22s} {r['revolutions']:>11} {r['mode']:>9}"
        if "error" in r:
            print(f"{head} failed: {r['error']}")
            continue
        print(f"{head} {r['peak_mb']:>8.0f} {r['wall_s']:>7.1f}  {r['how']}")
    ok = [r for r in rows if "error" not in r]
    peak = {(r["what"], r["mode"], r["revolutions"]): r["peak_mb"] for r in ok}
    res: dict = {"rows": rows, "summary": []}
    base = peak.get(("command, --no-figure", "memory", 1))
    if base is not None:
        res["summary"].append(dict(metric="recipdyn simulate -n 1 --no-figure: the baseline",
                                   value=base, unit="MB", target=300.0,
                                   better="lower"))  # fmt: skip
    for n in (1, 100, 2000, 10_000):
        for mode in ("memory", "streamed"):
            v = peak.get(("command", mode, n))
            if v is not None:
                what = f"recipdyn simulate -n {n} (figure; {mode})"
                res["summary"].append(dict(metric=what, value=v, unit="MB", target=None,
                                           better="lower"))  # fmt: skip
    st = {n: v for (w, mode, n), v in peak.items() if w == "recipdyn.simulate"
          and mode == "streamed"}  # fmt: skip
    if 100 in st and 1000 in st:
        slope = (st[1000] - st[100]) / 900
        res["streamed_mb_per_revolution"] = slope
        res["streamed_10k_mb"] = st.get(10_000, st[1000] + slope * 9000)
        res["summary"].append(dict(
            metric="simulate(out=...), 10^4 revolutions at 10 kHz, streamed" +
            ("" if 10_000 in st else " (extrapolated)"), value=res["streamed_10k_mb"],
            unit="MB", target=300.0, better="lower"))  # fmt: skip
    res["machine_memory_mb"] = _total_mb()
    return res


def _total_mb() -> float | None:
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**20
    except (ValueError, OSError, AttributeError):
        return None


if __name__ == "__main__":
    main()
