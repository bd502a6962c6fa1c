"""Parity (issue 43): the same runs in this tree and in an earlier revision, compared.

Each case is a ``recipdyn.simulate`` run (a quarter revolution at 2 kHz by default, the
default tolerances) of ``--model NAME --set ...``, made in a worker process of each tree (the
earlier one unpacked from git into a temporary folder, with a numba cache of its own). For
every variable both records hold, the script prints whether the two are equal to the bit and
otherwise the largest difference relative to the variable's largest magnitude, and the two
runs' numbers of right-hand-side calls. Needs git and the repository.

    python benchmarks/parity_revisions.py --before e2fe659 [--cases NAME ...] [--revolutions R]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

PLUGIN = str(Path(__file__).resolve().parents[1] / "tests" / "plugin_components.py")
MACHINES = Path(__file__).resolve().parents[1] / "examples" / "machines"
#: name -> (model, values)
CASES = {
    "default": ("compressor", {}),
    "rc2": ("compressor", {"rc": 2e-3}),
    "cycle": ("compressor", {"load": "cycle"}),
    "table": ("compressor", {"load_table": [[0.0, -1e4], [90.0, -5e4], [180.0, 2e4],
                                            [270.0, -3e4]]}),
    "printed": ("compressor", {"equations": "paper-printed"}),
    "ideal-pin": ("compressor", {"rc": 0.0}),
    "plugin-load": ("compressor", {"load": f"{PLUGIN}:HARMONIC"}),
    "motor": ("compressor", {"drive": "motor"}),
    "motor-constant-cycle": ("compressor", {"drive": "motor", "motor": "constant",
                                            "load": "cycle"}),
    "motor-ideal-pin": ("compressor", {"drive": "motor", "rc": 0.0}),
    "valves": ("compressor-valves", {}),
    "valves-fault": ("compressor-valves", {"leak_area_discharge_head": 2e-5}),
    "valves-motor": ("compressor-valves", {"drive": "motor"}),
    "contact": ("compressor-contact", {}),
    "contact-cycle": ("compressor-contact", {"load": "cycle"}),
    "lubricated-contact": ("compressor-contact", {"crank_joint": "lubricated",
                                                  "crosshead_joint": "contact", "omega": 150.0,
                                                  "load_amplitude": 2e4}),
    "contact-both-tanh": ("compressor-contact", {"crosshead_joint": "contact",
                                                 "friction_law": "tanh", "friction": 0.1}),
    "contact-law-file": ("compressor-contact", {"contact_law": f"{PLUGIN}:KELVIN_VOIGT"}),
    "contact-load-file": ("compressor-contact", {"load": f"{PLUGIN}:HARMONIC"}),
    "contact-motor": ("compressor-contact", {"drive": "motor", "motor": "constant",
                                             "omega": 150.0, "load_amplitude": 2e4}),
    "contact-valves": ("compressor-contact-valves", {}),
    "contact-valves-motor": ("compressor-contact-valves", {"drive": "motor"}),
    "guide-ideal-pins": ("compressor-contact", {"guide": "clearance", "crank_joint": "ideal",
                                                "guide_clearance": 2e-4}),
    "guide-contact": ("compressor-contact", {"guide": "clearance", "guide_clearance": 2e-4}),
    "guide-motor": ("compressor-contact", {"guide": "clearance", "crank_joint": "ideal",
                                           "guide_clearance": 2e-4, "drive": "motor",
                                           "motor": "constant"}),
    "guide-valves": ("compressor-contact-valves", {"guide": "clearance",
                                                   "guide_clearance": 2e-4}),
    "machine-two-throw": (str(MACHINES / "two_throw.toml"), {}),
    "machine-balanced-opposed": (str(MACHINES / "balanced_opposed.toml"), {}),
}  # fmt: skip


def _worker(cases: list[str], revolutions: float, out: str) -> None:
    import warnings

    import recipdyn

    warnings.simplefilter("ignore")
    for name in cases:
        model, values = CASES[name]
        values = {k: tuple(map(tuple, v)) if isinstance(v, list) else v
                  for k, v in values.items()}  # fmt: skip
        ds = recipdyn.simulate(model=model, params=values, revolutions=revolutions, fs=2000.0)
        arrays = {k: np.asarray(ds[k].values) for k in ds.data_vars}
        arrays["__nfev"] = np.array([ds.attrs["solver_nfev"]])
        np.savez(os.path.join(out, f"{name}.npz"), **arrays)


def _unpack(rev: str, into: Path) -> Path:
    root = Path(__file__).resolve().parent.parent
    tar = subprocess.run(["git", "-C", str(root), "archive", rev, "src"], check=True,
                         capture_output=True).stdout  # fmt: skip
    subprocess.run(["tar", "-x", "-C", str(into)], input=tar, check=True)
    return into / "src"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", required=True, help="the earlier revision (a git commit)")
    ap.add_argument("--cases", nargs="*", default=list(CASES), choices=list(CASES))
    ap.add_argument("--revolutions", type=float, default=0.25)
    ap.add_argument(
        "--before-cache",
        help="the earlier tree's numba cache folder (kept between runs; default: a temporary one)",
    )
    ap.add_argument("--before-records", help="a folder for the earlier tree's records, kept "
                    "between runs (a case found there is not run again)")  # fmt: skip
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--out", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        _worker(args.cases, args.revolutions, args.out)
        return
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        old_src = _unpack(args.before, tmp)
        new_src = Path(__file__).resolve().parents[1] / "src"
        outs = {}
        for label, src in (("before", old_src), ("now", new_src)):
            out = tmp / label
            if label == "before" and args.before_records:
                out = Path(args.before_records)
            out.mkdir(parents=True, exist_ok=True)
            cases = [c for c in args.cases if not (out / f"{c}.npz").exists()]
            if not cases:
                outs[label] = out
                continue
            env = {**os.environ, "PYTHONPATH": str(src),
                   "NUMBA_CACHE_DIR": str(tmp / f"cache_{label}")}  # fmt: skip
            if label == "now" and "NUMBA_CACHE_DIR" in os.environ:
                env["NUMBA_CACHE_DIR"] = os.environ["NUMBA_CACHE_DIR"]
            if label == "before" and args.before_cache:
                env["NUMBA_CACHE_DIR"] = args.before_cache
            subprocess.run([sys.executable, __file__, "--worker", "--before", args.before,
                            "--revolutions", str(args.revolutions), "--out", str(out),
                            "--cases", *cases], env=env, check=True)  # fmt: skip
            outs[label] = out
        report = {}
        for name in args.cases:
            a = np.load(outs["before"] / f"{name}.npz")
            b = np.load(outs["now"] / f"{name}.npz")
            rows = {}
            for k in sorted(set(a.files) & set(b.files) - {"__nfev"}):
                x, y = a[k], b[k]
                if x.shape != y.shape:
                    rows[k] = f"shapes {x.shape} {y.shape}"
                elif np.array_equal(x, y, equal_nan=True):
                    rows[k] = "bit-identical"
                else:
                    scale = max(float(np.nanmax(np.abs(x))), 1e-300)
                    rows[k] = f"{float(np.nanmax(np.abs(x - y))) / scale:.2e}"
            nfev = (int(a["__nfev"][0]), int(b["__nfev"][0]))
            only = sorted(set(a.files) ^ set(b.files))
            report[name] = {"nfev": nfev, "vars": rows, "only_in_one": only}
            same = all(v == "bit-identical" for v in rows.values()) and nfev[0] == nfev[1]
            worst = max((float(v) for v in rows.values() if v[0].isdigit() or v[0] == "."),
                        default=0.0)  # fmt: skip
            print(f"{name:22s} {'bit-identical' if same else f'max rel. diff {worst:.2e}'}"
                  f"  nfev {nfev[0]} / {nfev[1]}"
                  + (f"  only in one: {only}" if only else ""))  # fmt: skip
        print(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
