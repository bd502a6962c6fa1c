"""Run every benchmark in this folder (``make bench``); each prints its own ratios."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path


def main() -> None:
    here = Path(__file__).parent
    results = {}
    for path in sorted(here.glob("bench_*.py")):
        spec = importlib.util.spec_from_file_location(path.stem, path)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        print(f"\n=== {path.stem} ===", flush=True)
        results[path.stem] = mod.main(sys.argv[1:])
    out = Path("bench-results")
    out.mkdir(exist_ok=True)
    (out / "results.json").write_text(json.dumps(results, indent=2, default=float))
    print(f"\nwrote {out / 'results.json'}")


# The guard matters: Dask and 'spawn' process pools re-import the main module in every worker,
# which without it re-ran the whole suite in each worker (make bench never finished).
if __name__ == "__main__":
    main()
