"""Benchmark (issue 30, "no slowdown"): the compressor's time per revolution in this tree
against an earlier revision's, side by side in one run.

The earlier revision (``--before``, default the last commit before the compressor was
assembled from components) is unpacked from git into a temporary folder with its own numba
cache. Each tree runs in a worker process of its own that compiles every case first; then,
round after round, the two workers time every case in turn, alternating, and the best round
of each is kept. The time is the worker's CPU time: a shared machine's waits are left out,
its contention for caches and cores is not, so on a loaded machine one run can err by tens
of percent (run it on an idle one for the target). The cases are the four model names the
earlier tree had, at their defaults, with their own events as a run hands them to the
integrator: the presets of today's `compressor`.

Target (the issue): every case within 1.05x of the earlier tree. Needs git and the
repository (a checkout, not an installed package); without them it says so and measures
nothing.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: The last commit before the component architecture (issue 30).
BEFORE = "05119ec"
CASES = ("compressor", "compressor-contact", "compressor-valves", "compressor-contact-valves")
TARGET = 1.05


def _worker(revs: float, cases: tuple[str, ...]) -> None:
    """In a tree's process: compile the cases, then time each once per line read."""
    from recipdyn.integrate import integrate
    from recipdyn.model.registry import get_model

    setups = {}
    for name in cases:
        model = get_model(name)
        vals = model.parameters({})
        system = model.system(vals)
        kw = dict(rtol=1e-10, atol=1e-12, max_events=10**7)
        events = model.events(vals)
        if events:
            ev = events[0]
            kw.update(event=ev.function, event_direction=ev.direction,
                      event_action=ev.action, reset=ev.reset)  # fmt: skip
        y0 = model.initial_state(vals)
        integrate(system, y0, (0.0, 0.01), **kw)  # compiled, before the timing
        setups[name] = (system, y0, 2.0 * math.pi / float(vals["omega"]), kw)
    print(json.dumps({"ready": True}), flush=True)
    for _ in sys.stdin:
        out = {}
        for name, (system, y0, period, kw) in setups.items():
            t0 = time.process_time()  # CPU time: the waits of a shared machine left out
            run = integrate(system, y0, (0.0, revs * period), **kw)
            out[name] = [(time.process_time() - t0) / revs, run.nsteps / revs]
        print(json.dumps(out), flush=True)


def _unpack(rev: str, into: Path) -> Path | None:
    """The ``src`` folder of revision ``rev`` of the repository this file is in, or None."""
    root = Path(__file__).resolve().parent.parent
    try:
        tar = subprocess.run(["git", "-C", str(root), "archive", rev, "src"], check=True,
                             capture_output=True).stdout  # fmt: skip
        subprocess.run(["tar", "-x", "-C", str(into)], input=tar, check=True)
    except (OSError, subprocess.CalledProcessError):
        return None
    return into / "src"


def _start(src: Path, cache: Path, revs: float, cases: tuple[str, ...]) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(src), "NUMBA_CACHE_DIR": str(cache)}
    proc = subprocess.Popen([sys.executable, __file__, "--worker", "--revs", str(revs),
                             "--cases", *cases],
                            env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            text=True)  # fmt: skip
    return proc


def _ask(proc: subprocess.Popen) -> dict:
    proc.stdin.write("go\n")
    proc.stdin.flush()
    return json.loads(proc.stdout.readline())


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="1 revolution, 3 rounds")
    ap.add_argument("--before", default=BEFORE, help="the earlier revision (a git commit)")
    ap.add_argument("--rounds", type=int, default=None)
    ap.add_argument("--revolutions", type=float, default=None, help="per timing (default 2)")
    ap.add_argument("--cases", nargs="*", default=list(CASES), choices=CASES)
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--revs", type=float, default=2.0, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    cases = tuple(args.cases)
    if args.worker:
        _worker(args.revs, cases)
        return {}
    revs, rounds = (1.0, 3) if args.quick else (args.revolutions or 2.0, args.rounds or 7)
    here_src = Path(__file__).resolve().parent.parent / "src"
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        old_src = _unpack(args.before, tmp)
        if old_src is None:
            print(f"  revision {args.before} could not be unpacked (git and the repository "
                  "are needed): nothing measured")  # fmt: skip
            return {"summary": []}
        workers = {}
        for key, src in (("before", old_src), ("now", here_src)):
            (tmp / f"cache-{key}").mkdir()
            workers[key] = _start(src, tmp / f"cache-{key}", revs, cases)
        for key, proc in workers.items():  # both compiled before any timing
            assert json.loads(proc.stdout.readline())["ready"], key
        best = {k: dict.fromkeys(cases, math.inf) for k in workers}
        steps: dict[str, dict[str, float]] = {k: {} for k in workers}
        for r in range(rounds):
            order = ("before", "now") if r % 2 == 0 else ("now", "before")
            for key in order:
                for name, (s, n) in _ask(workers[key]).items():
                    best[key][name] = min(best[key][name], s)
                    steps[key][name] = n
        for proc in workers.values():
            proc.stdin.close()
            proc.wait()
    print(f"per revolution, best of {rounds} alternating rounds ({revs:g} revolutions), "
          f"{args.before} against this tree:")  # fmt: skip
    rows = []
    for name in cases:
        b, n = best["before"][name], best["now"][name]
        sb, sn = steps["before"][name], steps["now"][name]
        print(f"  {name:28s} {1e3 * b:9.2f} ms {1e3 * n:9.2f} ms  {n / b:5.2f}x  steps a "
              f"revolution {sb:.0f} -> {sn:.0f}")  # fmt: skip
        rows.append(dict(metric=f"{name}: now / {args.before}, per revolution", value=n / b,
                         unit="x", target=TARGET, better="lower"))  # fmt: skip
    return {"before": args.before, "ms_per_revolution": {
        k: {c: 1e3 * v for c, v in best[k].items()} for k in best}, "steps_per_revolution": steps,
        "summary": rows}  # fmt: skip


if __name__ == "__main__":
    main()
