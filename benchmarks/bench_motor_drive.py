"""Benchmark: the motor drive against the prescribed crank speed, per revolution, for each
configuration the motor runs with.

Each configuration runs ``recipdyn.simulate`` (fs 2 kHz, default tolerances) with
``--set drive=prescribed`` and with ``--set drive=motor`` (the default induction motor), in
alternating rounds in one process (so both see the same load of the machine); the best CPU
time of each side per revolution and their ratio are printed. The motor adds the crank's
states (two degrees of freedom more) and changes the step count with the ripple, so the ratio
is the cost of the free crank, not a routing overhead.

    python benchmarks/bench_motor_drive.py [--rounds 5] [--revolutions 1] [--only guide]

``--quick`` (``make bench``): the massless link and the contact crank pin with the paper's
load, 2 rounds of half a revolution (each other configuration compiles a motor variant of
its own: minutes each on a cold cache).
"""

from __future__ import annotations

import argparse
import time
import warnings

CONFIGS = {
    "massless link, paper load": {},
    "link + dynamic valves": {"load": "valves"},
    "contact crank pin, paper load": {"crank_joint": "contact"},
    "oil crank + contact crosshead, cycle": {"crank_joint": "lubricated",
                                             "crosshead_joint": "contact", "load": "cycle"},
    "contact crank pin + valves": {"crank_joint": "contact", "load": "valves"},
    "ideal pins, worn guide (0.2 mm), paper": {"guide": "clearance", "crank_joint": "ideal",
                                               "guide_clearance": 2e-4},
}  # fmt: skip


#: ``make bench`` runs the quick mode (the full one compiles six motor configurations).
RUN_ALL_ARGV = ["--quick"]
#: The configurations of the quick mode.
QUICK = ("massless link, paper load", "contact crank pin, paper load")


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--revolutions", type=float, default=1.0)
    ap.add_argument("--only", default="", help="run the configurations whose label holds this")
    ap.add_argument("--quick", action="store_true", help="2 configurations, 2 rounds of 0.5")
    args = ap.parse_args(argv)
    if args.quick:
        args.rounds, args.revolutions = 2, 0.5

    import recipdyn
    from recipdyn.errors import LawRangeWarning, ModelValidityWarning
    from recipdyn.model.registry import get_model

    warnings.simplefilter("ignore", ModelValidityWarning)
    warnings.simplefilter("ignore", LawRangeWarning)
    model = get_model("compressor")
    kw = dict(revolutions=args.revolutions, fs=2000.0)
    print(f"{'configuration':38s} {'prescribed (s/rev)':>18s} {'motor (s/rev)':>14s} "
          f"{'ratio':>7s} {'nfev ratio':>10s}")  # fmt: skip
    rows = []
    for label, selectors in CONFIGS.items():
        if args.only not in label or (args.quick and label not in QUICK):
            continue
        sides = {"prescribed": selectors, "motor": {**selectors, "drive": "motor"}}
        for p in sides.values():  # compile or load the cache
            recipdyn.simulate(model=model, params=p, revolutions=0.05, fs=2000.0)
        best = {k: float("inf") for k in sides}
        nfev = {}
        for r in range(args.rounds):
            order = list(sides) if r % 2 == 0 else list(sides)[::-1]
            for k in order:
                t0 = time.process_time()
                ds = recipdyn.simulate(model=model, params=sides[k], **kw)
                best[k] = min(best[k], (time.process_time() - t0) / args.revolutions)
                nfev[k] = int(ds.attrs["solver_nfev"])
        print(f"{label:38s} {best['prescribed']:18.4f} {best['motor']:14.4f} "
              f"{best['motor'] / best['prescribed']:7.2f} "
              f"{nfev['motor'] / nfev['prescribed']:10.2f}")  # fmt: skip
        rows.append(dict(metric=f"motor / prescribed CPU time: {label}",
                         value=best["motor"] / best["prescribed"], unit="x", target=None,
                         better="lower"))  # fmt: skip
    return {"summary": rows}


if __name__ == "__main__":
    main()
