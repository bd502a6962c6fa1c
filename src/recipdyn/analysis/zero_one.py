r"""The 0-1 test for chaos (Gottwald & Melbourne), correlation method.

For an observable phi(j), j = 1..N, and a random frequency c in (pi/5, 4 pi/5)::

    p_c(n) = sum_{j<=n} phi(j) cos(j c),   q_c(n) = sum_{j<=n} phi(j) sin(j c)
    M_c(n) = mean_j [(p_c(j+n) - p_c(j))^2 + (q_c(j+n) - q_c(j))^2]
    D_c(n) = M_c(n) - (E phi)^2 (1 - cos(n c)) / (1 - cos c)
    K_c    = corr(n, D_c(n)),   n = 1..n_cut (n_cut = N/10)

K = median over c of K_c: ~1 for chaotic dynamics (p, q diffuse like Brownian motion), ~0 for
regular dynamics (p, q bounded). Apply it to a map's orbit or a flow sampled stroboscopically
(oversampled flows give false 0s; Gottwald & Melbourne 2009).

References
----------
Gottwald & Melbourne (2004), Proc. R. Soc. A 460, 603; (2009), SIAM J. Appl. Dyn. Syst. 8, 129.
"""

from __future__ import annotations

import numpy as np

__all__ = ["zero_one_test"]


def zero_one_test(phi, *, n_c: int = 100, n_cut: int | None = None, seed: int = 0,
                  return_all: bool = False):  # fmt: skip
    """K statistic of the 0-1 test (median over ``n_c`` random c; seeded)."""
    phi = np.asarray(phi, dtype=float)
    if phi.ndim != 1 or phi.size < 100:
        raise ValueError("need a 1-D series of at least 100 values")
    if not np.all(np.isfinite(phi)):
        raise ValueError("series contains NaN or inf")
    N = phi.size
    n_cut = n_cut or N // 10
    rng = np.random.default_rng(seed)
    cs = rng.uniform(np.pi / 5, 4 * np.pi / 5, n_c)
    j = np.arange(1, N + 1)
    ns = np.arange(1, n_cut + 1)
    Ephi2 = phi.mean() ** 2
    ks = np.empty(n_c)
    for m, c in enumerate(cs):
        p = np.cumsum(phi * np.cos(j * c))
        q = np.cumsum(phi * np.sin(j * c))
        M = np.array([np.mean((p[n:] - p[:-n]) ** 2 + (q[n:] - q[:-n]) ** 2) for n in ns])
        D = M - Ephi2 * (1 - np.cos(ns * c)) / (1 - np.cos(c))
        if np.std(D) == 0:
            ks[m] = 0.0
        else:
            ks[m] = np.corrcoef(ns, D)[0, 1]
    K = float(np.median(ks))
    return (K, ks) if return_all else K
