"""Benchmark (issue 15, target 3): memory flat in run length.

Peak RSS of ``recipdyn.simulate`` at 10 kHz, each run in a fresh process, for growing run
lengths: in memory (the Dataset returned whole) and streamed to NetCDF block by block
(``out=...``). Target: 10^4 revolutions streamed under 300 MB (the quick mode stops at 10^3
and reports the slope per revolution, from which 10^4 follows).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile

_CHILD = r"""
import json, resource, sys, time, os
import recipdyn
revs, mode, out = float(sys.argv[1]), sys.argv[2], sys.argv[3]
t0 = time.perf_counter()
kw = dict(out=out) if mode == "streamed" else {}
ds = recipdyn.simulate(revolutions=revs, transient=0, fs=10_000.0, **kw)
if mode == "memory":
    ds.to_netcdf(out)
n = ds.sizes["time"]
size = os.path.getsize(out)
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps(dict(samples=n, rss_mb=peak, file_mb=size / 1e6, wall_s=time.perf_counter() - t0)))
"""


def _child(revs: float, mode: str, out: str) -> dict:
    r = subprocess.run([sys.executable, "-c", _CHILD, str(revs), mode, out], capture_output=True,
                       text=True, timeout=7200)  # fmt: skip
    if r.returncode != 0:
        return {"error": (r.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(r.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args, _ = ap.parse_known_args(argv)
    lengths = (100, 1000) if args.quick else (100, 1000, 10_000)
    res: dict = {"rows": []}
    with tempfile.TemporaryDirectory() as tmp:
        # a first run fills numba's cache (a new one after any change of the sources): the
        # rows then measure a run, not the compilation (725 MB peak in every row of a run
        # whose cache was cold, 306-383 MB warm, 2026-11-25)
        _child(1, "streamed", f"{tmp}/warm.nc")
        for revs in lengths:
            for mode in ("memory", "streamed"):
                if mode == "memory" and revs > 1000:
                    continue  # 10^4 revolutions in memory would need ~15 GB
                r = _child(revs, mode, f"{tmp}/{mode}{revs}.nc")
                r.update(revolutions=revs, mode=mode)
                res["rows"].append(r)
    print(f"{'revolutions':>12} {'mode':>9} {'samples':>10} {'peak RSS MB':>12} {'file MB':>8}"
          f" {'wall s':>7}")  # fmt: skip
    for r in res["rows"]:
        if "error" in r:
            print(f"{r['revolutions']:>12} {r['mode']:>9} failed: {r['error']}")
            continue
        print(f"{r['revolutions']:>12} {r['mode']:>9} {r['samples']:>10} {r['rss_mb']:>12.0f} "
              f"{r['file_mb']:>8.0f} {r['wall_s']:>7.1f}")  # fmt: skip
    ok = [r for r in res["rows"] if "error" not in r]
    st = {r["revolutions"]: r["rss_mb"] for r in ok if r["mode"] == "streamed"}
    mem = {r["revolutions"]: r["rss_mb"] for r in ok if r["mode"] == "memory"}
    res["summary"] = []
    if 100 in st and 1000 in st:
        slope = (st[1000] - st[100]) / 900
        res["streamed_mb_per_revolution"] = slope
        res["streamed_10k_mb"] = st.get(10_000, st[1000] + slope * 9000)
        res["summary"].append(dict(
            metric="peak RSS, 10^4 revolutions at 10 kHz, streamed" +
            ("" if 10_000 in st else " (extrapolated)"), value=res["streamed_10k_mb"],
            unit="MB", target=300.0, better="lower"))  # fmt: skip
    if 1000 in mem and 1000 in st:
        res["summary"].append(dict(metric="peak RSS at 10^3 revolutions: in memory / streamed",
                                   value=mem[1000] / st[1000], unit="x", target=None,
                                   better="higher"))  # fmt: skip
    return res


if __name__ == "__main__":
    main()
