"""Benchmark (issue 30): the contact-impact joints with each load, per revolution, as
assembled from the load components by generated glue.

Each case integrates one period of ``compressor-contact`` or ``compressor-contact-valves``
(and the massless link with dynamic valves) at the defaults, rtol 1e-10, atol 1e-12, best of
``repeat``. With ``--baseline SRC`` (a checkout's ``src`` folder, e.g. of the main branch) the
same cases run alternately in a subprocess that imports recipdyn from ``SRC``, so the ratio
new / baseline is measured side by side, under the same load of the machine (the issue's
target: within 1.05x).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

CASES = {
    "contact crank, paper (impacts)": ("compressor-contact", {"omega": 150.0,
                                                               "load_amplitude": 2e4}),
    "contact crosshead, paper": ("compressor-contact", {"clearance_joints": "crosshead",
                                                        "omega": 150.0,
                                                        "load_amplitude": 2e4}),
    "contact both, paper": ("compressor-contact", {"clearance_joints": "both", "omega": 150.0,
                                                   "load_amplitude": 2e4}),
    "contact crank, lubricated": ("compressor-contact", {"joint": "lubricated"}),
    "contact crank, cycle": ("compressor-contact", {"load": "cycle"}),
    "contact crank, dynamic valves": ("compressor-contact-valves", {}),
    "link, dynamic valves": ("compressor-valves", {}),
}  # fmt: skip


def measure(name: str, repeat: int) -> tuple[float, int]:
    """Best time of one period (s) and its steps."""
    import numpy as np

    from recipdyn.integrate import integrate
    from recipdyn.model.registry import get_model

    model, kw = CASES[name]
    m = get_model(model)
    v = m.parameters(kw)
    s = m.system(v)
    y0 = m.initial_state(v)
    T = m.period(v)
    integrate(s, y0, (0.0, 0.05 * T), t_eval=np.empty(0))  # compile or load the cache
    best, steps = np.inf, 0
    for _ in range(repeat):
        t0 = time.perf_counter()
        sol = integrate(s, y0, (0.0, T), t_eval=np.empty(0), rtol=1e-10, atol=1e-12)
        best = min(best, time.perf_counter() - t0)
        steps = sol.nsteps
    return best, steps


def _baseline(src: str, name: str, repeat: int) -> tuple[float, int]:
    env = {**os.environ, "PYTHONPATH": src}
    env.pop("NUMBA_CACHE_DIR", None)  # the baseline's sources have their own cache folder
    out = subprocess.run([sys.executable, __file__, "--case", name, "--repeat", str(repeat)],
                         env=env, capture_output=True, text=True, check=True)  # fmt: skip
    return tuple(json.loads(out.stdout.strip().splitlines()[-1]))


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="2 rounds of 2 repeats")
    ap.add_argument("--baseline", help="src folder of the code to compare with")
    ap.add_argument("--case", help=argparse.SUPPRESS)
    ap.add_argument("--repeat", type=int, default=3, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.case:  # one measurement, for a baseline run
        print(json.dumps(measure(args.case, args.repeat)))
        return {}
    rounds, repeat = (2, 2) if args.quick else (3, 3)
    rows = {}
    for name in CASES:
        new, old = [], []
        for _ in range(rounds):  # alternately, so a change of the machine's load hits both
            new.append(measure(name, repeat))
            if args.baseline:
                old.append(_baseline(args.baseline, name, repeat))
        t, n = min(new)
        rows[name] = (t, n, min(old) if old else None)
    print(f"contact joints and loads, one period (best of {rounds} x {repeat}):")
    for name, (t, n, old) in rows.items():
        line = f"  {name:32s} {1e3 * t:9.2f} ms {n:8d} steps"
        if old:
            line += f"   baseline {1e3 * old[0]:9.2f} ms {old[1]:8d} steps   {t / old[0]:5.2f}x"
        print(line)
    summary = []
    if args.baseline:
        ratios = [t / old[0] for t, _, old in rows.values()]
        summary.append(dict(metric="contact/valves glue / baseline, worst case", unit="x",
                            value=max(ratios), target=1.05, better="lower"))  # fmt: skip
    return {"cases_ms": {k: 1e3 * t for k, (t, _, _) in rows.items()}, "summary": summary}


if __name__ == "__main__":
    main()
