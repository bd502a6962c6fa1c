"""Benchmark (issues 30 and 32): the cost per revolution of the guide's clearance as a component
of the contact joints' glue, against `compressor-guide` (the same mechanics, its own kernel)
and against the rigid guide, measured side by side in one run (rtol 1e-10, atol 1e-12).

Each case integrates from its initial state for the same span after one warm-up run (the
compilation); the cases alternate within each round and the best of the rounds is kept.
"""

from __future__ import annotations

import argparse

from _timing import best_per_revolution, setup

_IDEAL = {"guide": "clearance", "crank_joint": "ideal", "crosshead_joint": "ideal"}
CASES = {
    "compressor-guide, c = 0.2 mm": ("compressor-guide-reference", {"guide_clearance": 2e-4}),
    "glue, ideal pins, c = 0.2 mm": ("compressor-contact", {**_IDEAL, "guide_clearance": 2e-4}),
    "compressor-guide, c = 0.2 mm, cycle": ("compressor-guide-reference",
                                            {"guide_clearance": 2e-4, "load": "cycle"}),
    "glue, ideal pins, c = 0.2 mm, cycle": ("compressor-contact",
                                            {**_IDEAL, "guide_clearance": 2e-4,
                                             "load": "cycle"}),
    "crank pin worn, rigid guide": ("compressor-contact", {}),
    "crank pin worn, healthy guide (c = 0)": ("compressor-contact", {"guide": "clearance"}),
    "crank pin worn, guide c = 0.2 mm": ("compressor-contact",
                                         {"guide": "clearance", "guide_clearance": 2e-4}),
    "crank pin worn, valves, rigid guide": ("compressor-contact-valves", {}),
    "crank pin worn, valves, guide c = 0.2 mm": ("compressor-contact-valves",
                                                 {"guide": "clearance",
                                                  "guide_clearance": 2e-4}),
}  # fmt: skip


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="half a revolution, 2 rounds")
    args = ap.parse_args(argv)
    revs, repeat = (0.5, 2) if args.quick else (1.0, 3)
    setups = {k: setup(*c) for k, c in CASES.items()}
    best, steps = best_per_revolution(setups, revs, repeat)
    print(f"per revolution (best of {repeat}, {revs:g} revolutions):")
    for k, t in best.items():
        print(f"  {k:42s} {1e3 * t:9.2f} ms  {steps[k]:8.0f} steps")
    ratios = {
        "glue / compressor-guide (paper)": best["glue, ideal pins, c = 0.2 mm"]
        / best["compressor-guide, c = 0.2 mm"],
        "glue / compressor-guide (cycle)": best["glue, ideal pins, c = 0.2 mm, cycle"]
        / best["compressor-guide, c = 0.2 mm, cycle"],
        "worn guide / rigid guide (crank pin worn)": best["crank pin worn, guide c = 0.2 mm"]
        / best["crank pin worn, rigid guide"],
        "worn guide / healthy guide (crank pin worn)": best["crank pin worn, guide c = 0.2 mm"]
        / best["crank pin worn, healthy guide (c = 0)"],
        "worn guide / rigid guide (crank pin worn, valves)": best[
            "crank pin worn, valves, guide c = 0.2 mm"]
        / best["crank pin worn, valves, rigid guide"],
    }  # fmt: skip
    for k, r in ratios.items():
        print(f"  {k:52s} {r:6.3f}x")
    return {"cases_ms_per_revolution": {k: 1e3 * t for k, t in best.items()},
            "summary": [dict(metric=k, unit="x", value=r, better="lower")
                        for k, r in ratios.items()]}  # fmt: skip


if __name__ == "__main__":
    main()
