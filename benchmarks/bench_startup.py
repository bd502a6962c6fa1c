"""Benchmark (issue 15, target 2): start-up of the command line.

Every command runs in a fresh process, as a user runs it:

* ``recipdyn --help`` (median of 5; target 0.3 s);
* a warm ``recipdyn simulate`` of 10 revolutions without the figure (compiled code in the cache;
  median of 3; target 1.0 s);
* a cold first run: ``recipdyn simulate -n 1`` with an empty cache directory (numba and the
  tableau cache), as on a fresh machine (target 5 s), and the same command warm right after.

Beside them, the floor that no change in recipdyn can remove: the interpreter with numpy and
numba imported and one cached function loaded.
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


def _time(cmd: list[str], env: dict | None = None, repeat: int = 1) -> float:
    walls = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True, env=env)
        walls.append(time.perf_counter() - t0)
    return statistics.median(walls)


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.parse_known_args(argv)
    exe = [sys.executable, "-m", "recipdyn"]
    res: dict = {}
    with tempfile.TemporaryDirectory() as tmp:
        sim = [*exe, "simulate", "--no-figure", "--no-progress", "-o", f"{tmp}/s.nc"]
        res["help_s"] = _time([*exe, "--help"], repeat=5)
        _time([*sim, "-n", "10"])  # fill the user's cache if needed
        res["warm_simulate_10rev_s"] = _time([*sim, "-n", "10"], repeat=3)
        cold = dict(os.environ, XDG_CACHE_HOME=f"{tmp}/cache")
        cold.pop("NUMBA_CACHE_DIR", None)
        res["cold_first_run_s"] = _time([*sim, "-n", "1"], env=cold)
        res["same_run_warm_s"] = _time([*sim, "-n", "1"], env=cold)
        floor_env = dict(os.environ, NUMBA_CACHE_DIR=f"{tmp}/floor")
        floor = os.path.join(tmp, "floor.py")  # a file: numba cannot cache code given by -c
        with open(floor, "w") as fh:
            fh.write(_FLOOR)
        _time([sys.executable, floor], env=floor_env)
        res["floor_numba_numpy_s"] = _time([sys.executable, floor], env=floor_env, repeat=3)
    print("start-up, each in a fresh process:")
    print(f"  recipdyn --help                        {res['help_s']:6.2f} s  (target 0.3 s)")
    print(f"  simulate 10 revolutions, warm cache    {res['warm_simulate_10rev_s']:6.2f} s  "
          "(target 1.0 s)")  # fmt: skip
    print(f"  simulate 1 revolution, empty cache     {res['cold_first_run_s']:6.2f} s  "
          f"(target 5 s; warm right after: {res['same_run_warm_s']:.2f} s)")  # fmt: skip
    print(
        f"  floor: python + numpy + numba + one cached function {res['floor_numba_numpy_s']:.2f} s"
    )
    res["summary"] = [
        dict(metric="recipdyn --help", value=res["help_s"], unit="s", target=0.3,
             better="lower"),
        dict(metric="warm simulate, 10 revolutions", value=res["warm_simulate_10rev_s"],
             unit="s", target=1.0, better="lower"),
        dict(metric="cold first run (empty cache), 1 revolution",
             value=res["cold_first_run_s"], unit="s", target=5.0, better="lower"),
    ]  # fmt: skip
    return res


if __name__ == "__main__":
    main()
