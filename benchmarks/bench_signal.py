"""Benchmark (issue 12): chaos estimates from a signal at 10^5 samples, side by side.

On one Lorenz x-series (dt = 0.01): the FFT 0-1 test against the direct sums it replaced
(O(N n_cut) per frequency, the previous implementation), at 2 x 10^4 values where the direct
sums still finish; ``nolds.lyap_r`` against recipdyn's Rosenstein at 10^4 samples (nolds builds
an N x N distance matrix: 10^5 samples would need 80 GB); and the whole assessment
(embedding, three estimators, 0-1 test, 19 IAAFT surrogates, verdict) at 10^5 samples.
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def _lorenz(n, dt=0.01):
    from recipdyn.integrate import integrate
    from recipdyn.model.reference import systems as S

    t = 50 + np.arange(n) * dt
    return integrate(S.lorenz(), [1.0, 1.0, 1.0], (0, t[-1]), t_eval=t, rtol=1e-10).y[:, 0]


def _direct_zero_one(phi, n_c, seed=0):
    """The previous implementation: the mean-square displacement by direct sums."""
    N = phi.size
    rng = np.random.default_rng(seed)
    cs = rng.uniform(np.pi / 5, 4 * np.pi / 5, n_c)
    j = np.arange(1, N + 1)
    ns = np.arange(1, N // 10 + 1)
    ks = []
    for c in cs:
        p, q = np.cumsum(phi * np.cos(j * c)), np.cumsum(phi * np.sin(j * c))
        M = np.array([np.mean((p[n:] - p[:-n]) ** 2 + (q[n:] - q[:-n]) ** 2) for n in ns])
        D = M - phi.mean() ** 2 * (1 - np.cos(ns * c)) / (1 - np.cos(c))
        ks.append(np.corrcoef(ns, D)[0, 1])
    return float(np.median(ks))


def _timed(f, *a, **k):
    t0 = time.perf_counter()
    out = f(*a, **k)
    return out, time.perf_counter() - t0


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    from recipdyn.analysis import lyap_rosenstein
    from recipdyn.analysis.signal import assess_signal
    from recipdyn.analysis.zero_one import zero_one_test

    n_big = 20_000 if args.quick else 100_000
    x = _lorenz(n_big)
    phi = x[::8][: 20_000 if not args.quick else 5000]
    n_c = 10
    k_fft, t_fft = _timed(zero_one_test, phi, n_c=n_c)
    k_dir, t_dir = _timed(_direct_zero_one, phi, n_c)
    print(f"0-1 test, {phi.size} values, {n_c} frequencies: FFT {t_fft:.3f} s (K {k_fft:.4f}), "
          f"direct sums {t_dir:.2f} s (K {k_dir:.4f})")  # fmt: skip
    rows = [dict(metric=f"0-1 test FFT vs direct sums ({phi.size} values), speed-up",
                 value=t_dir / t_fft, unit="x", target=10.0, better="higher")]  # fmt: skip
    n_small = 5000 if args.quick else 10_000
    try:
        import nolds

        lam_n, t_n = _timed(nolds.lyap_r, x[:n_small], emb_dim=3, lag=16, min_tsep=155,
                            trajectory_len=300)  # fmt: skip
        r, t_r = _timed(lyap_rosenstein, x[:n_small], 0.01)
        print(f"Rosenstein, {n_small} samples: recipdyn {t_r:.2f} s (lambda1 {r.exponent:.3f}, "
              f"{r.status}), nolds.lyap_r {t_n:.2f} s (lambda1 {lam_n / 0.01:.3f})")  # fmt: skip
        rows.append(dict(metric=f"Rosenstein vs nolds.lyap_r ({n_small} samples), speed-up",
                         value=t_n / t_r, unit="x", target=1.0, better="higher"))  # fmt: skip
    except ImportError:
        print("nolds not installed (pip install -e '.[bench]'): comparison skipped")
    a, t_a = _timed(assess_signal, x, 100.0)
    print(
        f"assess_signal, {x.size} samples: {t_a:.1f} s, verdict {a.verdict.verdict}, "
        + ", ".join(f"{k} {r.exponent:.3f} ({r.status})" for k, r in a.lyapunov.items())
        + f", K {a.zero_one.K:.3f}, surrogate z {a.surrogates.z:.1f}"
    )
    rows.append(dict(metric=f"whole signal assessment, {x.size} samples", value=t_a, unit="s",
                     target=None, better="lower"))  # fmt: skip
    return {"summary": rows, "zero_one_K": [k_fft, k_dir]}


if __name__ == "__main__":
    main()
