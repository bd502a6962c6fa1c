"""Benchmark (issue 15, target 2; issue 31, finding 5): start-up of the command line.

Every command runs in a fresh process, as a user runs it, interleaved with its references so
that a loaded machine slows both alike:

* ``recipdyn --help`` (target 0.3 s);
* a warm ``recipdyn simulate -n 10`` (compiled code in the cache), without the figure (the
  record only; target 1.0 s) and with it (the default);
* a cold first run: ``recipdyn simulate -n 1`` with an empty cache directory (numba and the
  tableau cache), as on a fresh machine, and the same command warm right after.

The references, measured in the same rounds: ``python -c "import numpy"`` (the interpreter and
numpy) and the floor no change in recipdyn can remove: numpy and numba imported and one cached
function loaded (numba then imports SciPy's linear algebra and sets up its compiler). Each
command is timed as wall time and as CPU time (user + system of the process): on a machine
whose cores are shared the CPU time stands for an idle machine's wall time. The ratios (to
``import numpy`` and to the floor) compare machines.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

_FLOOR = (
    "import numba, numpy as np\n"
    "@numba.njit(cache=True)\n"
    "def f(x):\n    return x + 1.0\n"
    "f(np.ones(1))\n"
)


def _run(cmd: list[str], env: dict | None = None) -> tuple[float, float]:
    """(wall, CPU) seconds of one fresh process."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    err = proc.stderr.read().decode(errors="replace")
    proc.stderr.close()
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited {proc.returncode}: {err[-500:]}")
    return wall, usage.ru_utime + usage.ru_stime


def _rounds(cmds: dict[str, tuple[list[str], dict | None]], repeat: int) -> dict:
    """Each command once per round, ``repeat`` rounds; the median wall and CPU per command."""
    walls: dict[str, list[float]] = {k: [] for k in cmds}
    cpus: dict[str, list[float]] = {k: [] for k in cmds}
    for _ in range(repeat):
        for k, (cmd, env) in cmds.items():
            w, c = _run(cmd, env)
            walls[k].append(w)
            cpus[k].append(c)
    return {k: (statistics.median(walls[k]), statistics.median(cpus[k])) for k in cmds}


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args, _ = ap.parse_known_args(argv)
    repeat = 3 if args.quick else 5
    exe = [sys.executable, "-m", "recipdyn"]
    res: dict = {}
    with tempfile.TemporaryDirectory() as tmp:
        sim = [*exe, "simulate", "--no-progress", "-n", "10", "-o", f"{tmp}/s.nc"]
        floor_env = dict(os.environ, NUMBA_CACHE_DIR=f"{tmp}/floor")
        floor = os.path.join(tmp, "floor.py")  # a file: numba cannot cache code given by -c
        with open(floor, "w") as fh:
            fh.write(_FLOOR)
        _run([*sim, "--no-figure"])  # fill the user's cache if needed
        _run([sys.executable, floor], floor_env)
        cmds = {
            "numpy": ([sys.executable, "-c", "import numpy"], None),
            "floor": ([sys.executable, floor], floor_env),
            "help": ([*exe, "--help"], None),
            "record": ([*sim, "--no-figure"], None),
            "figure": (sim, None),
        }
        times = _rounds(cmds, repeat)
        cold = dict(os.environ, XDG_CACHE_HOME=f"{tmp}/cache")
        cold.pop("NUMBA_CACHE_DIR", None)
        one = [*exe, "simulate", "--no-figure", "--no-progress", "-n", "1", "-o", f"{tmp}/c.nc"]
        times["cold"] = _run(one, cold)
        times["cold_again"] = _run(one, cold)
    for k, (w, c) in times.items():
        res[f"{k}_wall_s"], res[f"{k}_cpu_s"] = w, c
    np_cpu, floor_cpu = times["numpy"][1], times["floor"][1]
    print(f"start-up, each in a fresh process (median of {repeat} interleaved rounds):")
    print(f"  {'':44s} {'wall':>7s} {'CPU':>7s} {'/ numpy':>8s} {'/ floor':>8s}")
    names = {
        "numpy": 'python -c "import numpy"',
        "floor": "floor: numpy + numba + one cached function",
        "help": "recipdyn --help (target 0.3 s)",
        "record": "simulate -n 10 --no-figure, warm (target 1 s)",
        "figure": "simulate -n 10 with its figure, warm",
        "cold": "simulate -n 1, empty cache (compiles)",
        "cold_again": "the same right after (warm)",
    }
    for k, label in names.items():
        w, c = times[k]
        print(f"  {label:44s} {w:6.2f}s {c:6.2f}s {c / np_cpu:7.1f}x {c / floor_cpu:7.2f}x")
    res["summary"] = [
        dict(metric="recipdyn --help", value=times["help"][0], unit="s", target=0.3,
             better="lower"),
        dict(metric="warm simulate, 10 revolutions, no figure", value=times["record"][0],
             unit="s", target=1.0, better="lower"),
        dict(metric="the same, CPU time", value=times["record"][1], unit="s", target=1.0,
             better="lower"),
        dict(metric="the same / floor (CPU time)", value=times["record"][1] / floor_cpu,
             unit="x", target=None, better="lower"),
        dict(metric="the same / import numpy (CPU time)", value=times["record"][1] / np_cpu,
             unit="x", target=None, better="lower"),
        dict(metric="warm simulate with the figure / floor (CPU time)",
             value=times["figure"][1] / floor_cpu, unit="x", target=None, better="lower"),
        dict(metric="cold first run (empty cache), 1 revolution", value=times["cold"][0],
             unit="s", target=None, better="lower"),
    ]  # fmt: skip
    return res


if __name__ == "__main__":
    main()
