"""Benchmark (issue 32): the cost of a revolution with each valve or ring fault, against the same
configuration healthy, measured side by side in one run (rtol 1e-10, atol 1e-12; the issue asks
at most 1.5x).

Both joint models with dynamic valves: the massless link on the ideal mechanism (rc = 0,
``compressor-valves``) and the contact joint (rc = 1 mm, ``compressor-contact-valves``). Each
case integrates from the same initial state for the same span after one warm-up run (the
compilation); the cases are interleaved within each repeat and the best of the repeats is
kept.
"""

from __future__ import annotations

import argparse
import math
import time

from recipdyn.integrate import integrate
from recipdyn.model.registry import get_model

FAULTS = {
    "healthy": {},
    "suction leak (head, 3 cm2)": {"leak_area_suction_head": 3e-4},
    "discharge leak (crank, 3 cm2)": {"leak_area_discharge_crank": 3e-4},
    "broken spring (suction head)": {"spring_factor_suction_head": 0.0},
    "weak spring 0.3 (discharge crank)": {"spring_factor_discharge_crank": 0.3},
    "sticking plate 100 N (suction head)": {"adhesion_force_suction_head": 100.0},
    "ring leak (1 cm2)": {"ring_leak_area": 1e-4},
}
MODELS = (("compressor-valves", {"rc": 0.0}), ("compressor-contact-valves", {"rc": 1e-3}))


def _setup(name: str, over: dict):
    model = get_model(name)
    vals = model.parameters(over)
    system, ev = model.system(vals), model.events(vals)[0]
    kw = dict(rtol=1e-10, atol=1e-12, event=ev.function, event_direction=ev.direction,
              event_action=ev.action, reset=ev.reset, max_events=10**7)  # fmt: skip
    y0 = model.initial_state(vals)
    integrate(system, y0, (0.0, 0.01), **kw)  # compiled, before the timing
    return system, y0, 2.0 * math.pi / float(vals["omega"]), kw


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="2 revolutions, 3 repeats")
    args = ap.parse_args(argv)
    revs, repeat = (2.0, 3) if args.quick else (4.0, 5)
    summary, cases = [], {}
    for name, base in MODELS:
        setups = {k: _setup(name, base | f) for k, f in FAULTS.items()}
        best = dict.fromkeys(FAULTS, math.inf)
        steps = {}
        # interleaved: every repeat runs every case, so a change of the machine's load during
        # the benchmark (shared cores) affects all cases alike; the best of the repeats is kept
        for _ in range(repeat):
            for k, (system, y0, period, kw) in setups.items():
                t0 = time.perf_counter()
                run = integrate(system, y0, (0.0, revs * period), **kw)
                best[k] = min(best[k], (time.perf_counter() - t0) / revs)
                steps[k] = run.nsteps / revs
        t0, n0 = best["healthy"], steps["healthy"]
        print(f"{name} {base}, per revolution (best of {repeat}, {revs:g} revolutions):")
        for k, t in best.items():
            print(f"  {k:36s} {1e3 * t:8.2f} ms  {steps[k]:7.0f} steps  {t / t0:5.2f}x healthy"
                  f"  ({steps[k] / n0:4.2f}x its steps)")  # fmt: skip
            cases[f"{name}: {k}"] = 1e3 * t
        worst = max(t for k, t in best.items() if k != "healthy") / t0
        summary.append(dict(metric=f"{name}: worst fault / healthy, per revolution", unit="x",
                            value=worst, target=1.5, better="lower"))  # fmt: skip
    return {"cases_ms_per_revolution": cases, "summary": summary}


if __name__ == "__main__":
    main()
