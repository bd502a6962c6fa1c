"""Benchmark (issue 43, "cheap configurations"): how long a configuration never run before
takes to be ready, in this tree and in an earlier revision.

For each tree, one numba cache folder starts empty; the configurations then run one after
another, each in a fresh process that builds the model, integrates a hundredth of a
revolution and exits: the first pays for every component it holds, each later one only for
what it adds. The time is the process's (wall and CPU, imports included; the import alone,
measured the same way, is printed for reference). Target: a configuration never run before
ready in 20 s at most on 2 cores, its components compiled once for every configuration that
holds them.

    python benchmarks/bench_cold_config.py [--before REV] [--cases NAME ...]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: name -> (model, values); in the order they run (each after the ones before it)
CASES = {
    "compressor": ("compressor", {}),
    "cycle": ("compressor", {"load": "cycle"}),
    "motor": ("compressor", {"drive": "motor"}),
    "motor-constant-cycle": ("compressor", {"drive": "motor", "motor": "constant",
                                            "load": "cycle"}),
    "valves": ("compressor-valves", {}),
    "valves-motor": ("compressor-valves", {"drive": "motor"}),
    "contact": ("compressor-contact", {}),
    "contact-cycle": ("compressor-contact", {"load": "cycle"}),
    "contact-both-lubricated": ("compressor-contact", {"crank_joint": "lubricated",
                                                       "crosshead_joint": "lubricated"}),
    "contact-motor": ("compressor-contact", {"drive": "motor"}),
    "contact-valves": ("compressor-contact-valves", {}),
    "guide-ideal-pins": ("compressor-contact", {"guide": "clearance", "crank_joint": "ideal"}),
    "guide-contact-motor": ("compressor-contact", {"guide": "clearance", "drive": "motor"}),
    "two-throw (machine file)": (str(ROOT / "examples" / "machines" / "two_throw.toml"), {}),
    "two-stage four-throw (machine file)": (
        str(ROOT / "examples" / "machines" / "two_stage_4_throw.toml"), {}),
    # after contact-motor, whose joints' module (the crank free) its throws share: only the
    # machine's own module is new
    "two contact throws, motor (file)": (
        str(ROOT / "examples" / "machines" / "two_throw_contact_motor.toml"), {}),
    # after motor and contact-motor, whose modules its ideal and its contact throw are: only
    # the machine's own module is new
    "ideal + contact throw, motor (file)": (
        str(ROOT / "tests" / "machines" / "mixed_throws_motor.toml"), {}),
}  # fmt: skip

_RUN = """
import sys, time, json, warnings
warnings.simplefilter("ignore")
t0, c0 = time.perf_counter(), time.process_time()
import recipdyn
from recipdyn.integrate import integrate
from recipdyn.model.registry import get_model
model, values = json.loads(sys.argv[1])
if model != "--import-only":
    m = get_model(model)
    v = m.parameters(values)
    s = m.system(v)
    integrate(s, m.initial_state(v), (0.0, 0.01 * m.period(v)))
print(json.dumps([time.perf_counter() - t0, time.process_time() - c0]))
"""


def _time(src: Path, cache: Path, model: str, values: dict) -> tuple[float, float]:
    env = {**os.environ, "PYTHONPATH": str(src), "NUMBA_CACHE_DIR": str(cache)}
    res = subprocess.run([sys.executable, "-c", _RUN, json.dumps([model, values])], env=env,
                         capture_output=True, text=True, check=False)  # fmt: skip
    if res.returncode:
        raise RuntimeError(res.stderr[-2000:])
    wall, cpu = json.loads(res.stdout.strip().splitlines()[-1])
    return wall, cpu


def _unpack(rev: str, into: Path) -> Path:
    tar = subprocess.run(["git", "-C", str(ROOT), "archive", rev, "src"], check=True,
                         capture_output=True).stdout  # fmt: skip
    subprocess.run(["tar", "-x", "-C", str(into)], input=tar, check=True)
    return into / "src"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default=None, help="an earlier revision to time too")
    ap.add_argument("--cases", nargs="*", default=list(CASES), choices=list(CASES))
    ap.add_argument(
        "--quick",
        action="store_true",
        help="two cases only (the paper's compressor and the contact pins with valves)",
    )
    args = ap.parse_args(argv)
    if args.quick:
        pair = [c for c in CASES if "valves" in c and "contact" in c][:1]
        args.cases = ["compressor", *pair]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        trees = {"now": ROOT / "src"}
        if args.before:
            trees["before"] = _unpack(args.before, tmp)
        for label, src in trees.items():
            cache = tmp / f"cache_{label}"
            wall, cpu = _time(src, cache, "--import-only", {})
            print(f"[{label}] import alone: {wall:.1f} s wall, {cpu:.1f} s CPU")
            total = 0.0
            for name in args.cases:
                model, values = CASES[name]
                if model.endswith(".toml") and label == "before":
                    continue  # (no machine files before the assembler)
                t0 = time.perf_counter()
                try:
                    wall, cpu = _time(src, cache, model, values)
                except RuntimeError as exc:
                    print(f"[{label}] {name:28s} failed: {str(exc).splitlines()[-1]}")
                    continue
                total += time.perf_counter() - t0
                print(f"[{label}] {name:28s} {wall:6.1f} s wall {cpu:6.1f} s CPU")
            print(f"[{label}] all in sequence: {total:.0f} s wall")


if __name__ == "__main__":
    main()
