"""The blind set and the issue's examples through a diagnoser (issue 42).

    python benchmarks/blind/run.py                       # the shipped diagnoser, full set
    python benchmarks/blind/run.py --quick               # a reduced set (minutes)
    python benchmarks/blind/run.py --model new.skops --before bench-results/blind/blind.json

Writes ``OUT/blind.json`` and ``OUT/blind.md`` (tables per family and per target group,
every record's answer), and ``OUT/examples.json`` / ``.md`` (the issue's examples; with
``--before``, the BEFORE column next to this run's). ``--cache DIR`` keeps the simulated
physics (``.npz``) so that another diagnoser is judged on the same records without
simulating again. The records are made in memory from ``--seed`` and never written as a
data set: ``OUT`` may not be a data set folder (it is refused).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
if str(HERE.parent) not in sys.path:
    sys.path.insert(0, str(HERE.parent))

from blind import harness as H  # noqa: E402
from blind.examples import examples  # noqa: E402
from blind.sources import blind_set  # noqa: E402


def examples_markdown(result: dict, before: dict | None) -> str:
    prev = {r["id"]: r for r in (before or {}).get("records", [])}
    L = [
        "| # | example | truth | "
        + ("before | " if before else "")
        + "answer | outcome | the issue reported |",
        "|---|---|---|" + ("---|" if before else "") + "---|---|---|",
    ]
    for r in result["records"]:
        truth = r["truth"] or "no compressor"
        if r["severity_true"] is not None:
            truth += f" (s {r['severity_true']:.2f})"
        if r["expect"] == "refuse":
            truth += "; refuse"
        b = prev.get(r["id"])
        bcol = (f"{H.answer_text(b)} | " if b else "– | ") if before else ""
        fam = r["family"].removeprefix("issue: ")
        ans = H.answer_text(r)
        if r.get("unit") and r["label"] != "healthy":
            lo, hi = sorted(r["value_interval"])
            ans += f" = {r['value']:.3g} ({lo:.3g}..{hi:.3g}) {r['unit']}"
        L.append(f"| {r['id']} | {fam} | {truth} | {bcol}{ans} | {r['outcome']} | {r['note']} |")
    return "\n".join(L)


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a reduced set")
    ap.add_argument("--seed", type=int, default=20240)
    ap.add_argument("--model", default=None, help="diagnoser file (default: the shipped one)")
    ap.add_argument("--out", default="bench-results/blind")
    ap.add_argument("--cache", default=None, help="folder for the simulated physics (.npz)")
    ap.add_argument("--workers", type=int, default=1, help="processes for the simulations")
    ap.add_argument("--before", default=None, help="a previous run's folder or blind.json")
    ap.add_argument("--no-examples", action="store_true", help="the blind set only")
    ap.add_argument("--no-blind", action="store_true", help="the issue's examples only")
    args = ap.parse_args(argv)
    out = Path(args.out)
    if (out / "datacard.json").exists() or (out / "signals.zarr").exists():
        print(f"--out {out}: a data set folder; the blind set is never written into one",
              file=sys.stderr)  # fmt: skip
        raise SystemExit(2)
    before = {}
    if args.before:
        b = Path(args.before)
        folder = b if b.is_dir() else b.parent
        for name in ("blind", "examples"):
            f = folder / f"{name}.json"
            if f.exists():
                before[name] = json.loads(f.read_text())

    def say(msg):
        print(f"  {msg}", file=sys.stderr, flush=True)

    results = {}
    cache = Path(args.cache) if args.cache else None
    jobs = []
    if not args.no_examples:
        jobs.append(("examples", examples()))
    if not args.no_blind:
        jobs.append(("blind", blind_set(args.seed, quick=args.quick)))
    for name, recs in jobs:
        t0 = time.perf_counter()
        print(f"{name}: {len(recs)} records", file=sys.stderr, flush=True)
        run = H.run_records(recs, model=args.model, cache=cache, workers=args.workers, say=say)
        res = H.summarise(run, seed=args.seed, quick=args.quick, model=args.model)
        js, md = H.write(res, out, name, before.get(name))
        if name == "examples":
            md.write_text(examples_markdown(res, before.get(name)) + "\n")
            print(md.read_text())
        else:
            print(md.read_text())
        print(f"wrote {js}, {md} ({time.perf_counter() - t0:.0f} s)", file=sys.stderr)
        results[name] = res
    return results


if __name__ == "__main__":
    main()
