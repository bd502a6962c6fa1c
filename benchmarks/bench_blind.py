"""The diagnoser on records it did not make (issue 42, item 7): the blind set of
``benchmarks/blind`` (an independent measurement chain, other machines, another model's
physics, signals of no compressor) and the issue's examples, through the shipped diagnoser
(or ``--model``), against the issue's targets. docs/diagnosis.md ("The blind set") gives the
families, the chain's ranges and today's table.

    python benchmarks/bench_blind.py [--quick] [--model FILE] [--out DIR] [--cache DIR]

The same run on a new diagnoser, with ``--before`` the previous run's folder, gives the
issue's before/after tables (``benchmarks/blind/run.py`` is the same with more options).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from blind import run as blind_run  # noqa: E402


def _share(res, group, key):
    g = res["groups"].get(group)
    return None if g is None else g[f"share {key}"]


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--model", default=None)
    ap.add_argument("--out", default="bench-results/blind")
    ap.add_argument("--cache", default=None)
    ap.add_argument("--before", default=None)
    args = ap.parse_args(argv)
    rest = ["--out", args.out] + (["--quick"] if args.quick else [])
    for opt in ("model", "cache", "before"):
        if getattr(args, opt):
            rest += [f"--{opt}", getattr(args, opt)]
    res = blind_run.main(rest)
    b, ex = res["blind"], res["examples"]
    t = b["meta"]["timing"]
    n_ex_wrong = sum(r["outcome"] == "confidently wrong" for r in ex["records"])
    print(f"blind set: {t['records']} records from {t['physics_records']} simulations in "
          f"{t['total_s'] / 60:.1f} min")  # fmt: skip
    summary = [
        {"metric": "control (data set's kind of chain): right", "unit": "",
         "value": _share(b, "control", "right"), "target": 0.95, "better": "higher"},
        {"metric": "chains in the ranges, all channels: right", "unit": "",
         "value": _share(b, "chain", "right"), "target": 0.90, "better": "higher"},
        {"metric": "chains in the ranges, all channels: confidently wrong", "unit": "",
         "value": _share(b, "chain", "confidently wrong"), "target": 0.01, "better": "lower"},
        {"metric": "chains in the ranges, fewer channels: confidently wrong", "unit": "",
         "value": _share(b, "chain-reduced", "confidently wrong"), "target": 0.01,
         "better": "lower"},
        {"metric": "installation mistakes: confidently wrong", "unit": "",
         "value": _share(b, "installation", "confidently wrong"), "target": 0.01,
         "better": "lower"},
        {"metric": "other machines: refused", "unit": "", "value": _share(b, "machine", "refused"),
         "target": 1.0, "better": "higher"},
        {"metric": "another model: confidently wrong", "unit": "",
         "value": _share(b, "other-model", "confidently wrong"), "target": 0.01,
         "better": "lower"},
        {"metric": "not a compressor: refused", "unit": "",
         "value": _share(b, "negative", "refused"), "target": 1.0, "better": "higher"},
        {"metric": "issue's examples answered confidently wrong", "unit": "records",
         "value": float(n_ex_wrong), "target": 0.0, "better": "lower"},
        {"metric": "blind set wall time, simulations included", "unit": "min",
         "value": t["total_s"] / 60, "target": None, "better": "lower"},
    ]  # fmt: skip
    return {"summary": summary, "timing": t}


if __name__ == "__main__":
    main()
