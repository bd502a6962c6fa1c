"""Benchmark: the one ``compressor`` model (its selectors describe the machine of one throw
the assembler builds) against that machine itself (`recipdyn.model.family.machine`: the
one-throw machine of the route), per revolution.

Each route runs ``recipdyn.simulate`` for one revolution (fs 2 kHz, default tolerances) with
``--model compressor --set SELECTORS`` and with that class directly, in alternating
rounds in one process (so both see the same load of the machine); the best time of each side
and their ratio are printed. The model adds only the routing of each call (a few dict
operations): the ratio should be 1 within the machine's noise.

    python benchmarks/bench_family.py [--rounds 5] [--quick]

``--quick``: 2 rounds of half a revolution.
"""

from __future__ import annotations

import argparse
import time
import warnings

ROUTES = {
    "massless link (default)": ({}, "link"),
    "contact crank pin": ({"crank_joint": "contact"}, "contact"),
    "link + dynamic valves": ({"load": "valves"}, "link-valves"),
    "contact + dynamic valves": ({"crank_joint": "contact", "load": "valves"}, "contact-valves"),
}


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--revolutions", type=float, default=1.0)
    ap.add_argument("--quick", action="store_true", help="2 rounds of half a revolution")
    args = ap.parse_args(argv)
    if args.quick:
        args.rounds, args.revolutions = 2, 0.5

    import recipdyn
    from recipdyn.errors import ModelValidityWarning
    from recipdyn.model import family
    from recipdyn.model.registry import get_model

    warnings.simplefilter("ignore", ModelValidityWarning)
    model = get_model("compressor")
    kw = dict(revolutions=args.revolutions, fs=2000.0)
    print(f"{'route':28s} {'model (s/rev)':>14s} {'implementation':>15s} {'ratio':>7s}")
    rows = []
    for label, (selectors, route) in ROUTES.items():
        impl = family.machine(route)
        sides = {"model": (model, selectors), "impl": (impl, {})}
        for m, p in sides.values():  # compile or load the cache
            recipdyn.simulate(model=m, params=p, revolutions=0.05, fs=2000.0)
        best = {k: float("inf") for k in sides}
        for r in range(args.rounds):
            order = list(sides) if r % 2 == 0 else list(sides)[::-1]
            for k in order:
                m, p = sides[k]
                t0 = time.perf_counter()
                recipdyn.simulate(model=m, params=p, **kw)
                best[k] = min(best[k], (time.perf_counter() - t0) / args.revolutions)
        print(f"{label:28s} {best['model']:14.4f} {best['impl']:15.4f} "
              f"{best['model'] / best['impl']:7.3f}")  # fmt: skip
        # the routing is a few dict operations: 1 within the noise of a shared machine
        rows.append(dict(metric=f"compressor model / implementation: {label}",
                         value=best["model"] / best["impl"], unit="x", target=1.1,
                         better="lower"))  # fmt: skip
    return {"summary": rows}


if __name__ == "__main__":
    main()
