"""Benchmark (issue 30): the cost of each component combination of the assembled compressor,
measured side by side in one run, per revolution at rtol 1e-10, atol 1e-12.

* every load with the prescribed drive, against the paper's load (the hand-written kernels
  these replaced did the same arithmetic, to the bit: the glue adds no call overhead, so a
  ratio far from the load's own cost would show a wiring problem);
* the motor drive (induction and constant torque) against the prescribed drive on the same
  load: it integrates two more degrees of freedom and two work integrals, and solves a 2 x 2
  mass matrix each call (no target: a new model, reported).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from recipdyn.integrate import integrate
from recipdyn.model import CompressorParams, compressor_model

TABLE = ((0.0, -1.0e4), (90.0, -5.0e4), (180.0, 2.0e4), (270.0, -3.0e4))
CASES = {
    "prescribed, paper": {},
    "prescribed, cycle": {"load": "cycle"},
    "prescribed, table": {"load_table": TABLE},
    "prescribed, paper-printed": {"equations": "paper-printed"},
    "motor induction, paper": {"drive": "motor"},
    "motor constant, paper": {"drive": "motor", "motor": "constant"},
    "motor induction, cycle, rc = 0": {"drive": "motor", "load": "cycle", "rc": 0.0},
    "prescribed, cycle, rc = 0": {"load": "cycle", "rc": 0.0},
}


def _per_revolution(kw: dict, revs: float, repeat: int) -> tuple[float, int]:
    p = CompressorParams(**kw)
    m = compressor_model(p)
    y0 = m.initial_state()
    span = (0.0, revs * p.crank_period)
    integrate(m, y0, (0.0, p.crank_period), t_eval=np.empty(0), rtol=1e-10, atol=1e-12)
    best, steps = np.inf, 0
    for _ in range(repeat):
        t0 = time.perf_counter()
        sol = integrate(m, y0, span, t_eval=np.empty(0), rtol=1e-10, atol=1e-12)
        best = min(best, time.perf_counter() - t0)
        steps = sol.nsteps
    return best / revs, steps


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="2 revolutions, 3 repeats")
    args = ap.parse_args(argv)
    revs, repeat = (2.0, 3) if args.quick else (10.0, 7)
    res = {k: _per_revolution(kw, revs, repeat) for k, kw in CASES.items()}
    base = res["prescribed, paper"][0]
    print(f"assembled compressor, per revolution (best of {repeat}, {revs:g} revolutions):")
    for k, (t, n) in res.items():
        print(f"  {k:34s} {1e3 * t:8.2f} ms  {n / revs:8.0f} steps  {t / base:6.2f}x paper")
    motor = res["motor induction, paper"][0] / base
    ideal = res["motor induction, cycle, rc = 0"][0] / res["prescribed, cycle, rc = 0"][0]
    print(f"  motor / prescribed: {motor:.2f}x (paper load, rc = 1 mm), {ideal:.2f}x (cycle, "
          "rc = 0)")  # fmt: skip
    return {
        "cases_ms_per_revolution": {k: 1e3 * t for k, (t, _) in res.items()},
        "summary": [
            dict(metric="motor drive / prescribed, per revolution (rc = 1 mm)", value=motor,
                 unit="x", target=None, better="lower"),
            dict(metric="table load / paper load, per revolution", unit="x", target=None,
                 value=res["prescribed, table"][0] / base, better="lower"),
        ],
    }  # fmt: skip


if __name__ == "__main__":
    main()
