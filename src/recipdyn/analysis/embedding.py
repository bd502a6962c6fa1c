"""Delay embedding: delay from mutual information, dimension from false nearest neighbours.

References
----------
Fraser & Swinney (1986), Phys. Rev. A 33, 1134 (average mutual information);
Kennel, Brown & Abarbanel (1992), Phys. Rev. A 45, 3403 (false nearest neighbours).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["delay_embed", "mutual_information", "estimate_delay", "false_nearest_neighbours",
           "estimate_dimension", "mean_period"]  # fmt: skip


def delay_embed(x, dim: int, delay: int) -> np.ndarray:
    """Vectors ``(x[i], x[i + delay], ..., x[i + (dim - 1) delay])``.

    Shape ``(N - (dim - 1) delay, dim)``.
    """
    x = np.asarray(x, dtype=float)
    if dim < 1 or delay < 1:
        raise ValueError(f"dim = {dim}, delay = {delay}; allowed: >= 1")
    n = x.size - (dim - 1) * delay
    if n < 2:
        raise ValueError(f"signal of {x.size} samples too short for dim={dim}, delay={delay}")
    return np.lib.stride_tricks.sliding_window_view(x, (dim - 1) * delay + 1)[:, ::delay].copy()


def mutual_information(x, max_lag: int, bins: int = 32) -> np.ndarray:
    """Average mutual information I(lag) (nats) for lags 0..max_lag (histogram estimate)."""
    x = np.asarray(x, dtype=float)
    edges = np.histogram_bin_edges(x, bins=bins)
    idx = np.clip(np.digitize(x, edges[1:-1]), 0, bins - 1)
    out = np.empty(max_lag + 1)
    for lag in range(max_lag + 1):
        a, b = idx[: x.size - lag], idx[lag:]
        joint = np.bincount(a * bins + b, minlength=bins * bins).reshape(bins, bins) / a.size
        pa, pb = joint.sum(axis=1), joint.sum(axis=0)
        nz = joint > 0
        out[lag] = np.sum(joint[nz] * np.log(joint[nz] / np.outer(pa, pb)[nz]))
    return out


def estimate_delay(x, max_lag: int | None = None) -> int:
    """First minimum of the average mutual information (smoothed over 5 lags, and lower than
    the next 5 lags, so histogram noise does not stop it early); if none, the lag where the
    autocorrelation first drops below 1/e."""
    x = np.asarray(x, dtype=float)
    max_lag = max_lag or max(10, min(x.size // 10, 500))
    ami = np.convolve(mutual_information(x, max_lag + 5), np.ones(5) / 5, mode="same")
    for lag in range(3, max_lag):
        if ami[lag] < ami[lag - 1] and np.all(ami[lag] <= ami[lag + 1 : lag + 6]):
            return lag
    xc = x - x.mean()
    ac = np.correlate(xc, xc, mode="full")[x.size - 1 : x.size - 1 + max_lag + 1]
    below = np.nonzero(ac / ac[0] < np.exp(-1))[0]
    return int(below[0]) if below.size else max_lag


def false_nearest_neighbours(x, delay: int, max_dim: int = 10, rtol: float = 15.0,
                             atol: float = 2.0, theiler: int = 0) -> np.ndarray:  # fmt: skip
    """Fraction of false nearest neighbours for dimensions 1..max_dim (Kennel et al. 1992)."""
    x = np.asarray(x, dtype=float)
    sd = x.std()
    out = np.empty(max_dim)
    for m in range(1, max_dim + 1):
        X = delay_embed(x, m + 1, delay)  # last column: the (m+1)-th coordinate
        Y = X[:, :m]
        tree = cKDTree(Y)
        k = min(2 * theiler + 2, Y.shape[0] - 1) if theiler else 2
        d, j = tree.query(Y, k=k + 1)
        i = np.arange(Y.shape[0])[:, None]
        ok = (np.abs(j - i) > theiler) & (d > 0)
        first = np.argmax(ok, axis=1)
        has = ok[np.arange(ok.shape[0]), first]
        dn = d[np.arange(d.shape[0]), first][has]
        jn = j[np.arange(j.shape[0]), first][has]
        extra = np.abs(X[has, m] - X[jn, m])
        false = (extra / dn > rtol) | (np.sqrt(dn**2 + extra**2) / sd > atol)
        out[m - 1] = false.mean() if false.size else np.nan
    return out


def estimate_dimension(x, delay: int, max_dim: int = 10, threshold: float = 0.01,
                       theiler: int = 0) -> int:  # fmt: skip
    """Smallest dimension whose false-nearest-neighbour fraction is below ``threshold``."""
    f = false_nearest_neighbours(x, delay, max_dim, theiler=theiler)
    if np.all(np.isnan(f)):  # no non-degenerate neighbours at all (an exactly repeating record)
        return 2
    below = np.nonzero(f < threshold)[0]
    return int(below[0] + 1) if below.size else int(np.nanargmin(f) + 1)


def mean_period(x) -> float:
    """Mean period in samples, 1 / (power-weighted mean frequency) -- a Theiler window."""
    x = np.asarray(x, dtype=float) - np.mean(x)
    p = np.abs(np.fft.rfft(x)) ** 2
    f = np.fft.rfftfreq(x.size)
    p[0] = 0.0
    fm = np.sum(f * p) / np.sum(p) if np.sum(p) > 0 else 0.0
    return float(1.0 / fm) if fm > 0 else float(x.size)
