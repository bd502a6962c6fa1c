"""Run every benchmark in this folder (``make bench``): one summary table, JSON results, and a
comparison with the previous run so that a regression shows (in the spirit of asv).

Each ``bench_*.py`` module has ``main(argv) -> dict | None`` (``argv``: its command-line
arguments, ``None`` for ``sys.argv``), a docstring whose first paragraph says what it measures,
and a ``--quick`` option (reduced sizes). A benchmark whose full run takes long (tens of
minutes, or a data set to build) says so with ``RUN_ALL_ARGV = ["--quick"]``: this runner
passes it that; ``--quick`` runs every benchmark quick, ``--full`` every one at full size.

A benchmark prints its own details and may put a ``"summary"`` list in its result: rows
``{"metric", "value", "unit", "target", "better"}`` with ``better`` = ``"higher"`` or
``"lower"`` and ``target`` a bound (or ``None``). Every value is a ratio measured side by side
in the same run, or a measurement with its context; nothing here is a timed assertion.

A benchmark that raises, or stops with a nonzero exit status (argparse's usage errors do),
is FAILED: the others still run, the table at the end lists every benchmark as ran or
FAILED with its error, and the runner exits with status 1 (so ``make bench`` fails).

Results go to ``bench-results/results.json`` (the previous file is kept as
``previous.json``); a metric that got more than 10 % worse than in the previous run is flagged
``REGRESSION``.

Usage: ``python benchmarks/run_all.py [--quick | --full] [--only NAME ...] [--list]``.
"""

from __future__ import annotations

import argparse
import datetime as dt
import importlib.util
import json
import os
import platform
import subprocess
import sys
import time
import traceback
from pathlib import Path

#: A metric worse than the previous run by more than this fraction is flagged.
REGRESSION = 0.10
HERE = Path(__file__).parent


def _machine() -> dict:
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                                text=True, cwd=HERE).stdout.strip()  # fmt: skip
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
    """The metrics every benchmark reported, against their targets and the previous run."""
    prev_rows = {}
    for name, res in (previous or {}).get("benchmarks", {}).items():
        for row in res.get("summary", []) if isinstance(res, dict) else []:
            prev_rows[(name, row["metric"])] = row
    w = max([14, *(len(n.removeprefix("bench_")) for n in results)])
    lines = [f"{'benchmark':{w}s} {'metric':52s} {'value':>11s} {'target':>9s} {'':6s} "
             "vs previous"]  # fmt: skip
    lines.append("-" * len(lines[0]))
    for name, res in results.items():
        rows = res.get("summary", []) if isinstance(res, dict) else []
        short = name.removeprefix("bench_")
        if isinstance(res, dict) and "error" in res:
            lines.append(f"{short:{w}s} FAILED: {res['error']}")
        for row in rows:
            v = row.get("value")
            unit = row.get("unit", "")
            val = "n/a" if v is None else f"{v:.3g} {unit}".strip()
            tgt = (
                ""
                if row.get("target") is None
                else (("≥ " if row.get("better") == "higher" else "≤ ") + f"{row['target']:g}")
            )
            lines.append(
                f"{short:{w}s} {row['metric'][:52]:52s} {val:>11s} {tgt:>9s} "
                f"{_ok(row):6s} {_change(row, prev_rows.get((name, row['metric'])))}"
            )
    return "\n".join(lines)


def status_table(results: dict) -> str:
    """One row a benchmark: ran or FAILED, its arguments, its wall time and its error."""
    lines = [f"{'benchmark':28s} {'status':7s} {'arguments':12s} {'wall':>8s}  error"]
    lines.append("-" * 72)
    for name, res in results.items():
        failed = "error" in res
        lines.append(f"{name:28s} {'FAILED' if failed else 'ran':7s} "
                     f"{' '.join(res.get('argv', [])) or '(full)':12s} "
                     f"{res.get('wall_s', 0.0):7.0f}s  {res.get('error', '')}")  # fmt: skip
    n_failed = sum("error" in r for r in results.values())
    lines.append(f"{len(results) - n_failed} ran, {n_failed} failed")
    return "\n".join(lines)


def load(path: Path):
    """The benchmark module at ``path``, under its own name in ``sys.modules`` and with its
    folder on ``sys.path`` (for ``_timing``), so that a function of it sent to a process
    pool pickles by name (bench_diagnosis_robustness's did not: "it's not the same object")."""
    if str(path.parent) not in sys.path:
        sys.path.insert(0, str(path.parent))
    spec = importlib.util.spec_from_file_location(path.stem, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[path.stem] = mod
    try:
        spec.loader.exec_module(mod)
    except BaseException:
        sys.modules.pop(path.stem, None)
        raise
    return mod


def describe(mod) -> str:
    """What a benchmark measures: the first paragraph of its docstring, on one line."""
    first = (mod.__doc__ or "").strip().split("\n\n")[0]
    return " ".join(first.split()) or "(no description)"


def run_one(path: Path, mode: str) -> dict:
    """Run one benchmark in this process; its result with ``argv``, ``wall_s`` and, if it
    failed, ``error``. ``mode``: ``"default"`` (its ``RUN_ALL_ARGV``), ``"quick"`` or
    ``"full"``."""
    t0 = time.perf_counter()
    argv: list[str] = []
    try:
        mod = load(path)
        if mode == "quick":
            argv = ["--quick"]
        elif mode == "default":
            argv = list(getattr(mod, "RUN_ALL_ARGV", []))
        print(f"\n=== {path.stem} {' '.join(argv)}: {describe(mod)} ===", flush=True)
        res = mod.main(argv)
        res = dict(res) if isinstance(res, dict) else {}
    except SystemExit as exc:  # argparse's usage errors, sys.exit(n) of a script
        code = exc.code
        res = {} if code in (0, None) else {"error": f"exit status {code}"}
    except Exception as exc:  # one failing benchmark must not lose the others' results
        traceback.print_exc()
        res = {"error": f"{type(exc).__name__}: {exc}"}
    if "error" in res:
        print(f"  FAILED: {res['error']}", flush=True)
    res["argv"] = argv
    res["wall_s"] = time.perf_counter() - t0
    return res


def main(argv: list[str] | None = None) -> int:
    """Run the benchmarks; 0 when every one ran, 1 when any failed."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    size = ap.add_mutually_exclusive_group()
    size.add_argument("--quick", action="store_true", help="every benchmark at reduced size")
    size.add_argument("--full", action="store_true",
                      help="every benchmark at full size (hours)")  # fmt: skip
    ap.add_argument("--only", nargs="*", default=None, help="benchmark names, e.g. engine")
    ap.add_argument("--list", action="store_true", help="say what each benchmark measures")
    ap.add_argument("--out", default="bench-results")
    ap.add_argument("--dir", default=str(HERE), help=argparse.SUPPRESS)  # (the tests' folder)
    args = ap.parse_args(argv)
    paths = []
    for path in sorted(Path(args.dir).glob("bench_*.py")):
        short = path.stem.removeprefix("bench_")
        if not args.only or short in args.only or path.stem in args.only:
            paths.append(path)
    if args.only and not paths:
        print(f"no benchmark named {', '.join(args.only)}", file=sys.stderr)
        return 2
    if args.list:
        for path in paths:
            mod = load(path)
            quick = " [run quick]" if getattr(mod, "RUN_ALL_ARGV", []) else ""
            print(f"{path.stem.removeprefix('bench_')}{quick}: {describe(mod)}\n")
        return 0
    mode = "quick" if args.quick else "full" if args.full else "default"
    results: dict = {}
    t_all = time.perf_counter()
    for path in paths:
        results[path.stem] = run_one(path, mode)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    cur = out / "results.json"
    previous = None
    if cur.exists():
        try:
            previous = json.loads(cur.read_text())
            (out / "previous.json").write_text(cur.read_text())
        except (OSError, ValueError):
            previous = None
    doc = dict(machine=_machine(), mode=mode, total_s=time.perf_counter() - t_all,
               benchmarks=results)  # fmt: skip
    cur.write_text(json.dumps(doc, indent=2, default=float))
    print(f"\n=== summary ({doc['total_s'] / 60:.1f} min; {doc['machine']['cpus']} cores; "
          f"commit {doc['machine']['commit'] or '?'}) ===")  # fmt: skip
    comparable = previous is not None and previous.get("mode") == mode
    if previous:
        m = previous.get("machine", {})
        print(f"previous run: commit {m.get('commit', '?')}, {m.get('date', '?')}"
              + ("" if comparable else " (other sizes: not compared)"))  # fmt: skip
    print(summary_table(results, previous if comparable else None))
    print()
    print(status_table(results))
    print(f"\nwrote {cur}")
    return 1 if any("error" in r for r in results.values()) else 0


# The guard matters: Dask and 'spawn' process pools re-import the main module in every worker,
# which without it re-ran the whole suite in each worker (make bench never finished).
if __name__ == "__main__":
    sys.exit(main())
