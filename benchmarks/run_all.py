"""Run every benchmark in this folder (``make bench``): one summary table, JSON results, and a
comparison with the previous run so that a regression shows (in the spirit of asv).

Each ``bench_*.py`` module has ``main(argv) -> dict``; it prints its own details and may put a
``"summary"`` list in its result: rows ``{"metric", "value", "unit", "target", "better"}`` with
``better`` = ``"higher"`` or ``"lower"`` and ``target`` a bound (or ``None``). Every value is a
ratio measured side by side in the same run, or a measurement with its context; nothing here is
a timed assertion.

Results go to ``bench-results/results.json`` (the previous file is kept as
``previous.json``); a metric that got more than 10 % worse than in the previous run is flagged
``REGRESSION``.

Usage: ``python benchmarks/run_all.py [--quick] [--only NAME ...]``.
"""

from __future__ import annotations

import argparse
import datetime as dt
import importlib.util
import json
import os
import platform
import subprocess
import time
from pathlib import Path

#: A metric worse than the previous run by more than this fraction is flagged.
REGRESSION = 0.10


def _machine() -> dict:
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                                text=True, cwd=Path(__file__).parent).stdout.strip()  # fmt: skip
    except OSError:
        commit = ""
    import numba
    import numpy

    return dict(python=platform.python_version(), machine=platform.machine(),
                processor=platform.processor(), cpus=os.cpu_count(), numpy=numpy.__version__,
                numba=numba.__version__, commit=commit,
                date=dt.datetime.now(dt.UTC).isoformat(timespec="seconds"))  # fmt: skip


def _ok(row: dict) -> str:
    t, v = row.get("target"), row.get("value")
    if t is None or v is None:
        return ""
    good = v >= t if row.get("better") == "higher" else v <= t
    return "met" if good else "MISSED"


def _change(row: dict, prev: dict | None) -> str:
    if not prev or prev.get("value") in (None, 0) or row.get("value") is None:
        return ""
    ratio = row["value"] / prev["value"]
    worse = ratio < 1 - REGRESSION if row.get("better") == "higher" else ratio > 1 + REGRESSION
    return f"{ratio:.2f}x" + ("  REGRESSION" if worse else "")


def summary_table(results: dict, previous: dict | None) -> str:
    prev_rows = {}
    for name, res in (previous or {}).get("benchmarks", {}).items():
        for row in res.get("summary", []) if isinstance(res, dict) else []:
            prev_rows[(name, row["metric"])] = row
    lines = [f"{'benchmark':14s} {'metric':52s} {'value':>11s} {'target':>9s} {'':6s} "
             "vs previous"]  # fmt: skip
    lines.append("-" * len(lines[0]))
    for name, res in results.items():
        rows = res.get("summary", []) if isinstance(res, dict) else []
        if isinstance(res, dict) and "error" in res:
            lines.append(f"{name:14s} FAILED: {res['error']}")
        for row in rows:
            v = row.get("value")
            unit = row.get("unit", "")
            val = "n/a" if v is None else f"{v:.3g} {unit}".strip()
            tgt = (
                ""
                if row.get("target") is None
                else (("≥ " if row.get("better") == "higher" else "≤ ") + f"{row['target']:g}")
            )
            short = name.removeprefix("bench_")
            lines.append(
                f"{short:14s} {row['metric'][:52]:52s} {val:>11s} {tgt:>9s} "
                f"{_ok(row):6s} {_change(row, prev_rows.get((name, row['metric'])))}"
            )
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="reduced sizes (minutes, not 15)")
    ap.add_argument("--only", nargs="*", default=None, help="benchmark names, e.g. engine")
    ap.add_argument("--out", default="bench-results")
    args = ap.parse_args()
    here = Path(__file__).parent
    results: dict = {}
    t_all = time.perf_counter()
    for path in sorted(here.glob("bench_*.py")):
        short = path.stem.removeprefix("bench_")
        if args.only and short not in args.only and path.stem not in args.only:
            continue
        spec = importlib.util.spec_from_file_location(path.stem, path)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        print(f"\n=== {path.stem} ===", flush=True)
        t0 = time.perf_counter()
        try:
            results[path.stem] = mod.main(["--quick"] if args.quick else [])
        except Exception as exc:  # one failing benchmark must not lose the others' results
            results[path.stem] = {"error": f"{type(exc).__name__}: {exc}"}
            print(f"  failed: {exc}", flush=True)
        results[path.stem]["wall_s"] = time.perf_counter() - t0
    out = Path(args.out)
    out.mkdir(exist_ok=True)
    cur = out / "results.json"
    previous = None
    if cur.exists():
        try:
            previous = json.loads(cur.read_text())
            (out / "previous.json").write_text(cur.read_text())
        except (OSError, ValueError):
            previous = None
    doc = dict(machine=_machine(), quick=args.quick, total_s=time.perf_counter() - t_all,
               benchmarks=results)  # fmt: skip
    cur.write_text(json.dumps(doc, indent=2, default=float))
    print(f"\n=== summary ({doc['total_s'] / 60:.1f} min; {doc['machine']['cpus']} cores; "
          f"commit {doc['machine']['commit'] or '?'}) ===")  # fmt: skip
    if previous:
        m = previous.get("machine", {})
        print(
            f"previous run: commit {m.get('commit', '?')}, {m.get('date', '?')}"
            + ("" if previous.get("quick") == args.quick else " (other size: not comparable)")
        )
    print(summary_table(results, previous if previous and previous.get("quick") == args.quick
                        else None))  # fmt: skip
    print(f"\nwrote {cur}")


# The guard matters: Dask and 'spawn' process pools re-import the main module in every worker,
# which without it re-ran the whole suite in each worker (make bench never finished).
if __name__ == "__main__":
    main()
