"""Benchmark: the joints with friction (the pins and the guide's shoes), per revolution, per law.

The friction law (``friction_law``: Ambrósio's dynamic correction or tanh) is a function the
generated glue imports by name; this times one period of the contact joints with friction on
(``friction`` = 0.1, and ``v0``, ``v1`` of the order of the sliding velocities, so that each
law's own branch runs, not only its saturated Coulomb value) at rtol 1e-10, atol 1e-12, best
of ``repeat`` per round. With ``--baseline SRC`` (a checkout's ``src`` folder) each round runs
the same case in a subprocess that imports recipdyn from ``SRC``, alternately with this
checkout, so the ratio new / baseline is measured under the same load of the machine.

    python benchmarks/bench_friction_laws.py --baseline ../main/src --rounds 5
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

#: The guide's shoes with friction, v0 and v1 of the order of the crosshead's speed.
_SHOES = {"guide_clearance": 2e-4, "load_amplitude": 2e4, "guide_friction": 0.2,
          "guide_v0": 0.5, "guide_v1": 2.0}  # fmt: skip
_IMPACTS = {"omega": 150.0, "load_amplitude": 2e4, "friction": 0.1, "v0": 5.0, "v1": 10.0}
CASES = {
    "crank pin, ambrosio": ("compressor-contact", {**_IMPACTS, "friction_law": "ambrosio"}),
    "crank pin, tanh": ("compressor-contact", {**_IMPACTS, "friction_law": "tanh"}),
    "oil film + dry crosshead pin, tanh": ("compressor-contact", {
        "crank_joint": "lubricated", "crosshead_joint": "contact", "rc_crosshead": 2e-4,
        "friction": 0.1, "friction_law": "tanh", "v0": 0.01, "v1": 0.02}),
    "crank pin with a motor, tanh": ("compressor-contact", {
        **_IMPACTS, "friction_law": "tanh", "drive": "motor", "motor": "constant"}),
    "compressor-guide kernel, ambrosio": ("compressor-guide-reference", {**_SHOES}),
    "compressor-guide kernel, tanh": ("compressor-guide-reference",
                                      {**_SHOES, "guide_friction_law": "tanh"}),
    "glue's guide (ideal pins), tanh": ("compressor", {
        **_SHOES, "guide": "clearance", "crank_joint": "ideal", "guide_friction_law": "tanh"}),
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


def _run(src: str | None, name: str, repeat: int) -> tuple[float, int]:
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = src
        env.pop("NUMBA_CACHE_DIR", None)  # the baseline's sources have their own cache folder
    out = subprocess.run([sys.executable, __file__, "--case", name, "--repeat", str(repeat)],
                         env=env, capture_output=True, text=True, check=True)  # fmt: skip
    return tuple(json.loads(out.stdout.strip().splitlines()[-1]))


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", help="src folder of the code to compare with")
    ap.add_argument("--rounds", type=int, default=5, help="alternations (default 5)")
    ap.add_argument("--repeat", type=int, default=3, help="periods per measurement")
    ap.add_argument("--match", default="", help="only the cases whose name holds this")
    ap.add_argument("--case", help=argparse.SUPPRESS)
    ap.add_argument("--quick", action="store_true", help="2 rounds of 1 period")
    args = ap.parse_args(argv)
    if args.quick:
        args.rounds, args.repeat = 2, 1
    if args.case:  # one measurement, in its own process
        print(json.dumps(measure(args.case, args.repeat)))
        return {}
    rows = {}
    for name in [k for k in CASES if args.match in k]:
        new, old = [], []
        for _ in range(args.rounds):  # alternately, so a change of the machine's load hits both
            new.append(_run(None, name, args.repeat))
            if args.baseline:
                old.append(_run(args.baseline, name, args.repeat))
        rows[name] = (min(new), min(old) if old else None)
    print(f"joints with friction, one period (best of {args.rounds} x {args.repeat}):")
    for name, ((t, n), old) in rows.items():
        line = f"  {name:36s} {1e3 * t:9.2f} ms {n:8d} steps"
        if old:
            line += f"   baseline {1e3 * old[0]:9.2f} ms {old[1]:8d} steps   {t / old[0]:5.2f}x"
        print(line)
    summary = []
    if args.baseline:
        ratios = [t / old[0] for (t, _), old in rows.values()]
        summary.append(dict(metric="friction laws by name / baseline, worst case", unit="x",
                            value=max(ratios), target=1.05, better="lower"))  # fmt: skip
    return {"cases_ms": {k: 1e3 * t for k, ((t, _), _) in rows.items()}, "summary": summary}


if __name__ == "__main__":
    main()
