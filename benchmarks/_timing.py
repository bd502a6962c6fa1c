"""Timing shared by the per-revolution benchmarks: set a model's case up (compiled before the
timing) and time the cases interleaved, keeping the best of the rounds.

Interleaving matters on shared cores: every round runs every case, so a change of the
machine's load during the benchmark affects all cases alike, and the ratios between them stay
meaningful although the absolute times do not. Imported by the ``bench_*.py`` next to it (this
folder is on ``sys.path`` whether a benchmark runs alone or from ``run_all.py``).
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from typing import Any

from recipdyn.integrate import integrate
from recipdyn.model.registry import get_model


def setup(
    name: str,
    over: Mapping[str, Any],
    *,
    with_event: bool = False,
    rtol: float = 1e-10,
    atol: float = 1e-12,
) -> tuple:
    """``(system, y0, period, integrate keywords)`` of model ``name`` with ``over``, after one
    short warm-up run (the compilation). ``with_event``: hand the model's first event (its
    contact or valve events) to the integrator, as a run does."""
    model = get_model(name)
    vals = model.parameters(dict(over))
    system = model.system(vals)
    kw: dict[str, Any] = dict(rtol=rtol, atol=atol, max_events=10**7)
    if with_event:
        ev = model.events(vals)[0]
        kw.update(event=ev.function, event_direction=ev.direction, event_action=ev.action,
                  reset=ev.reset)  # fmt: skip
    y0 = model.initial_state(vals)
    integrate(system, y0, (0.0, 0.01), **kw)  # compiled, before the timing
    return system, y0, 2.0 * math.pi / float(vals["omega"]), kw


def best_per_revolution(
    setups: Mapping[str, tuple], revs: float, repeat: int
) -> tuple[dict[str, float], dict[str, float]]:
    """Seconds and steps per revolution of each case (``setups``: name -> `setup`'s tuple),
    the cases interleaved within each of ``repeat`` rounds, the best round kept."""
    best = dict.fromkeys(setups, math.inf)
    steps: dict[str, float] = {}
    for _ in range(repeat):
        for k, (system, y0, period, kw) in setups.items():
            t0 = time.perf_counter()
            run = integrate(system, y0, (0.0, revs * period), **kw)
            best[k] = min(best[k], (time.perf_counter() - t0) / revs)
            steps[k] = run.nsteps / revs
    return best, steps
