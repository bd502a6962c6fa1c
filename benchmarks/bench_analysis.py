"""Benchmark (issue 3): signal Lyapunov estimators vs nolds, and Benettin on the compressor.

Side by side in one run on the same Lorenz x-series (dt = 0.01, 20 000 points): recipdyn's
Rosenstein and Wolf vs ``nolds.lyap_r`` (which builds an N x N distance matrix). Each estimator
runs in a fresh subprocess so its peak memory (max RSS) is measured alone. Then the Benettin
spectrum of the compressor base case over 1000 crank revolutions, side by side with the
reference port (``reference_port.py``) at the same tolerances.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

LAMBDA = 0.9056

_CHILD = r"""
import json, resource, sys, time
import numpy as np
from recipdyn.model.reference import systems as S
from recipdyn.integrate import integrate
n = int(sys.argv[2]); dt = 0.01
sol = integrate(S.lorenz(), [1.0, 1.0, 1.0], (0, 50 + n * dt), t_eval=50 + np.arange(n) * dt,
                rtol=1e-10)
x = sol.y[:, 0]
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
which = sys.argv[1]
t0 = time.perf_counter()
if which == "nolds":
    import nolds
    lam = nolds.lyap_r(x, emb_dim=3, lag=16, min_tsep=155, trajectory_len=300) / dt
else:
    from recipdyn.analysis import lyap_rosenstein, lyap_wolf
    if which == "rosenstein":
        lyap_rosenstein(x[:2000], dt)  # JIT-free, but warm imports (200 samples: too short
        # for the embedding Cao's method picks on the Lorenz x-signal, which is refused)
        t0 = time.perf_counter()
        lam = lyap_rosenstein(x, dt).exponent
    else:
        t0 = time.perf_counter()
        lam = lyap_wolf(x, dt).exponent
wall = time.perf_counter() - t0
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
out = dict(lam=float(lam), wall=wall, rss_mb=peak / 1024, rss_delta_mb=(peak - base) / 1024)
print(json.dumps(out))
"""


def _child(which: str, n: int) -> dict:
    r = subprocess.run([sys.executable, "-c", _CHILD, which, str(n)], capture_output=True,
                       text=True, timeout=3600)  # fmt: skip
    if r.returncode != 0:
        return {"error": (r.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(r.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="5000 points, 100 revolutions")
    args, _ = ap.parse_known_args(argv)
    n = 5000 if args.quick else 20_000
    res: dict = {"n": n}
    for which in ("rosenstein", "wolf", "nolds"):
        res[which] = _child(which, n)
    print(f"signal Lyapunov, Lorenz x, N = {n} (reference {LAMBDA})")
    for which in ("rosenstein", "wolf", "nolds"):
        r = res[which]
        if "error" in r:
            print(f"  {which:11s} unavailable: {r['error']}")
            continue
        err = 100 * (r["lam"] / LAMBDA - 1)
        print(f"  {which:11s} lambda1 {r['lam']:.4f} ({err:+.1f} %)  {r['wall']:7.2f} s  "
              f"peak RSS {r['rss_mb']:.0f} MB (+{r['rss_delta_mb']:.0f} MB)")  # fmt: skip
    if "error" not in res["nolds"] and "error" not in res["rosenstein"]:
        res["speedup_rosenstein_vs_nolds"] = res["nolds"]["wall"] / res["rosenstein"]["wall"]
        res["memory_ratio_nolds_vs_rosenstein"] = max(res["nolds"]["rss_delta_mb"], 1) / max(
            res["rosenstein"]["rss_delta_mb"], 1
        )
        print(f"  speed-up Rosenstein vs nolds.lyap_r: {res['speedup_rosenstein_vs_nolds']:.1f}x,"
              f" extra memory ratio {res['memory_ratio_nolds_vs_rosenstein']:.1f}x")  # fmt: skip
    from recipdyn.analysis import lyapunov_spectrum
    from recipdyn.model import CompressorParams, compressor_model

    revs = 100 if args.quick else 1000
    m = compressor_model(CompressorParams())
    y0 = m.initial_state()
    lyapunov_spectrum(m, y0, m.period, rtol=1e-8, atol=1e-9)  # warm-up
    t0 = time.perf_counter()
    r = lyapunov_spectrum(m, y0, revs * m.period, rtol=1e-8, atol=1e-9)
    t_ours = time.perf_counter() - t0
    # the reference port (reference_port.py): the same equations, a minimal numba DOP853 with
    # the right-hand side inlined, QR once per revolution; same tolerances, same start
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import reference_port as port

    A, B, C, E3, E5 = port.tableau()
    P = port.params(m.cparams)
    counts = np.zeros(2, dtype=np.int64)
    port.benettin(0.0, y0, m.period, 1, 1, P, A, B, C, E3, E5, 1e-8, 1e-9, counts)  # compile
    counts[:] = 0
    t0 = time.perf_counter()
    ex_port = port.benettin(0.0, y0, m.period, revs, 1, P, A, B, C, E3, E5, 1e-8, 1e-9, counts)
    t_port = time.perf_counter() - t0
    res["benettin_compressor"] = dict(
        revolutions=revs, seconds=t_ours, exponents=r.exponents.tolist(), sum=r.sum,
        qr_interval=float(r.settings["dt_final"]), port_seconds=t_port,
        port_exponents=ex_port.tolist(), ratio_vs_port=t_ours / t_port,
        exponent_difference_vs_port=float(np.max(np.abs(r.exponents - ex_port))),
    )  # fmt: skip
    b = res["benettin_compressor"]
    print(
        f"Benettin, compressor base case, {revs} revolutions (rtol 1e-8): {t_ours:.2f} s "
        f"(QR every {b['qr_interval']:.4g} s), exponents {b['exponents']}, sum {b['sum']:.2e}"
    )
    print(f"  reference port: {t_port:.2f} s, exponents {b['port_exponents']}; ratio "
          f"{b['ratio_vs_port']:.2f} (target <= 1.1), exponents differ by "
          f"{b['exponent_difference_vs_port']:.1e} 1/s")  # fmt: skip
    res["summary"] = [
        dict(metric=f"Benettin, compressor, {revs} revolutions", value=t_ours, unit="s",
             target=8.0 if revs == 1000 else None, better="lower"),
        dict(metric="Benettin time / reference port time", value=b["ratio_vs_port"], unit="x",
             target=1.1, better="lower"),
    ]  # fmt: skip
    if "speedup_rosenstein_vs_nolds" in res:
        res["summary"].append(dict(metric="Rosenstein vs nolds.lyap_r",
                                   value=res["speedup_rosenstein_vs_nolds"], unit="x",
                                   target=None, better="higher"))  # fmt: skip
    return res


if __name__ == "__main__":
    main()
