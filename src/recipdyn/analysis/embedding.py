"""Delay embedding: delay from mutual information, dimension from false nearest neighbours.

References
----------
Fraser & Swinney (1986), Phys. Rev. A 33, 1134 (average mutual information);
Kennel, Brown & Abarbanel (1992), Phys. Rev. A 45, 3403 (false nearest neighbours);
Cao (1997), Physica D 110, 43-50 (E1/E2 dimension and determinism statistics);
Kantz & Schreiber, *Nonlinear Time Series Analysis*, 2nd ed. (2004), sec. 3.3 and 9.2 (delay:
one sample for maps, about the decorrelation time for flows).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..defaults import MIN_SIGNAL_SAMPLES
from .checks import as_signal

__all__ = ["delay_embed", "mutual_information", "autocorrelation", "estimate_delay",
           "false_nearest_neighbours", "cao", "estimate_dimension", "mean_period", "Embedding",
           "choose_embedding"]  # fmt: skip


def delay_embed(x, dim: int, delay: int) -> np.ndarray:
    """Vectors ``(x[i], x[i + delay], ..., x[i + (dim - 1) delay])``.

    Shape ``(N - (dim - 1) delay, dim)``.
    """
    x = as_signal(x, name="x", allow_constant=True)
    if dim < 1 or delay < 1:
        raise ValueError(f"dim = {dim}, delay = {delay}; allowed: >= 1")
    n = x.size - (dim - 1) * delay
    if n < 2:
        raise ValueError(f"signal of {x.size} samples too short for dim={dim}, delay={delay}")
    return np.lib.stride_tricks.sliding_window_view(x, (dim - 1) * delay + 1)[:, ::delay].copy()


def mutual_information(x, max_lag: int, bins: int = 32) -> np.ndarray:
    """Average mutual information I(lag) (nats) for lags 0..max_lag (histogram estimate)."""
    x = as_signal(x, name="x", min_samples=max(2, int(max_lag) + 2))
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


def autocorrelation(x, max_lag: int | None = None) -> np.ndarray:
    """Normalised autocorrelation for lags 0..max_lag (FFT, O(N log N))."""
    x = as_signal(x, name="x")
    x = x - x.mean()
    n = x.size
    max_lag = n - 1 if max_lag is None else min(int(max_lag), n - 1)
    f = np.fft.rfft(x, 2 * n)
    ac = np.fft.irfft(f.real**2 + f.imag**2, 2 * n)[: max_lag + 1]
    return ac / ac[0] if ac[0] > 0 else np.zeros_like(ac)


def estimate_delay(x, max_lag: int | None = None) -> int:
    """The smaller of the first minimum of the average mutual information (smoothed over 5
    lags, and lower than the next 5 lags, so histogram noise does not stop it early) and the
    lag where the autocorrelation first drops below 1/e.

    The autocorrelation bound matters for maps and for noise: their correlations are gone
    after one or two samples, while the mutual information of a chaotic map decays over
    ``log(bins) / lambda_1`` samples (its first minimum is then a lag at which the coordinates
    are already unrelated: a delay of 30 for the Ikeda map)."""
    x = as_signal(x, name="x", min_samples=MIN_SIGNAL_SAMPLES)
    max_lag = max_lag or max(10, min(x.size // 10, 500))
    below = np.nonzero(autocorrelation(x, max_lag) < np.exp(-1))[0]
    tau_ac = int(below[0]) if below.size else max_lag
    ami = np.convolve(mutual_information(x, max_lag + 5), np.ones(5) / 5, mode="same")
    for lag in range(3, min(max_lag, tau_ac)):
        if ami[lag] < ami[lag - 1] and np.all(ami[lag] <= ami[lag + 1 : lag + 6]):
            return lag
    return max(1, tau_ac)


def false_nearest_neighbours(x, delay: int, max_dim: int = 10, rtol: float = 15.0,
                             atol: float = 2.0, theiler: int = 0) -> np.ndarray:  # fmt: skip
    """Fraction of false nearest neighbours for dimensions 1..max_dim (Kennel et al. 1992)."""
    x = as_signal(x, name="x", min_samples=max_dim * delay + 2)
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


def cao(x, delay: int, max_dim: int = 10, theiler: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Cao's (1997) statistics ``E1(d)`` and ``E2(d)`` for d = 1..max_dim.

    ``E1`` stops changing (near 1) once ``d`` is an embedding dimension; ``E2`` is 1 for every
    ``d`` for a random series and differs from 1 for some ``d`` for a deterministic one.
    Maximum norm, nearest neighbours outside a Theiler window, zero distances skipped."""
    x = as_signal(x, name="x", min_samples=(max_dim + 1) * delay + 2)
    E = np.full(max_dim + 1, np.nan)
    Es = np.full(max_dim + 1, np.nan)
    for d in range(1, max_dim + 2):
        X = delay_embed(x, d + 1, delay)  # coordinates 0..d-1: the d-embedding; d: the next
        Y = X[:, :d]
        k = min(2 * theiler + 3, Y.shape[0] - 1)
        dist, j = cKDTree(Y).query(Y, k=k, p=np.inf)
        i = np.arange(Y.shape[0])[:, None]
        ok = (np.abs(j - i) > theiler) & (dist > 0)
        has = ok.any(axis=1)
        first = np.argmax(ok, axis=1)[has]
        rows = np.nonzero(has)[0]
        if rows.size == 0:
            break
        jn, dn = j[rows, first], dist[rows, first]
        d_next = np.maximum(dn, np.abs(X[rows, d] - X[jn, d]))
        E[d - 1] = np.mean(d_next / dn)
        Es[d - 1] = np.mean(np.abs(X[rows, d] - X[jn, d]))
    return E[1:] / E[:-1], Es[1:] / Es[:-1]


def estimate_dimension(x, delay: int, max_dim: int = 10, threshold: float = 0.01,
                       theiler: int = 0) -> int:  # fmt: skip
    """Smallest dimension whose false-nearest-neighbour fraction is below ``threshold``."""
    f = false_nearest_neighbours(x, delay, max_dim, theiler=theiler)
    if np.all(np.isnan(f)):  # no non-degenerate neighbours at all (an exactly repeating record)
        return 2
    below = np.nonzero(f < threshold)[0]
    return int(below[0] + 1) if below.size else int(np.nanargmin(f) + 1)


@dataclass
class Embedding:
    """A delay embedding chosen from the data, with the evidence for it.

    ``status`` is ``"ok"``, or ``"not_saturated"`` when Cao's E1 was still changing at
    ``max_dim`` (or the largest dimension the record embeds) and the false-nearest-neighbour
    fraction never fell below 1 % (the attractor, if any, needs more dimensions than the record
    supports: the estimators refuse), ``"too_short"`` when the record at its delay embeds fewer
    than 4 dimensions (the estimators refuse), or ``"degenerate"`` for an exactly repeating
    record."""

    delay: int
    dim: int
    theiler: int
    status: str
    reason: str
    e1: np.ndarray
    e2: np.ndarray
    fnn: np.ndarray | None = None

    def diagnostics(self) -> dict:
        out = {"delay": self.delay, "dim": self.dim, "theiler": self.theiler,
               "status": self.status, "reason": self.reason,
               "cao_E1": np.round(self.e1, 4).tolist(),
               "cao_E2": np.round(self.e2, 4).tolist()}  # fmt: skip
        if self.fnn is not None:
            out["false_neighbours"] = np.round(self.fnn, 4).tolist()
        return out


def choose_embedding(x, *, delay: int | None = None, dim: int | None = None,
                     theiler: int | None = None, max_dim: int = 10,
                     e1_tol: float = 0.05, max_points: int = 10_000) -> Embedding:  # fmt: skip
    """Delay ([`estimate_delay`][recipdyn.analysis.embedding.estimate_delay]), Theiler window (the
    mean period, at most N/10) and dimension: the first ``d`` with ``E1(d) > 1 - 2 e1_tol`` and
    ``|E1(d+1) - E1(d)| < e1_tol`` (Cao 1997), from the first ``max_points`` samples (Cao's
    statistics are averages: 10^4 points fix them to about 1 %, and the neighbour search in 10
    dimensions grows faster than N). Given values are kept."""
    x = as_signal(x, name="x", min_samples=MIN_SIGNAL_SAMPLES)
    tau = estimate_delay(x) if delay is None else int(delay)
    th = int(round(mean_period(x))) if theiler is None else int(theiler)
    th = min(th, x.size // 10)
    if dim is not None:
        return Embedding(tau, int(dim), th, "ok", "dimension given", np.empty(0), np.empty(0))
    # Cao's test of dimension d needs the record embedded in d + 1: at most `fits`
    n = min(x.size, max_points)
    fits = (n - 2) // tau - 1
    if fits < 3:  # not even d = 1, 2 and 3 to compare: the dimension cannot be found
        return Embedding(tau, 2, th, "too_short",
                         f"{n} samples at delay {tau} embed up to d = {max(fits, 0)} only (a "
                         "longer record, or a higher rate, is needed to find the embedding "
                         "dimension)", np.empty(0), np.empty(0))  # fmt: skip
    max_dim = min(max_dim, fits)
    e1, e2 = cao(x[:max_points], tau, max_dim=max_dim)
    if np.all(np.isnan(e1)):
        return Embedding(tau, 2, th, "degenerate", "no two distinct embedded points", e1, e2)
    for d in range(1, max_dim - 1):
        if e1[d - 1] > 1 - 2 * e1_tol and abs(e1[d] - e1[d - 1]) < e1_tol:
            return Embedding(tau, max(d, 2), th, "ok", f"Cao's E1 saturates at d = {d}",
                             e1, e2)  # fmt: skip
    # Cao's ratios are erratic on a clean periodic record (its neighbours are near-repeats
    # one period apart): the false-nearest-neighbour fraction (Kennel et al. 1992, which also
    # marks noise neighbours false) is the second criterion
    fnn = false_nearest_neighbours(x[:max_points], tau, max_dim=max_dim, theiler=th)
    below = np.nonzero(fnn < 0.01)[0]
    if below.size:
        d = max(int(below[0]) + 1, 2)
        return Embedding(tau, d, th, "ok", f"Cao's E1 does not saturate; false nearest "
                         f"neighbours below 1 % at d = {below[0] + 1}", e1, e2)  # fmt: skip
    # the statistics themselves are in diagnostics() (cao_E1, fnn): the reason stays one line
    return Embedding(tau, max_dim, th, "not_saturated",
                     f"neither Cao's E1 saturates nor the false-nearest-neighbour fraction "
                     f"drops below 1 % up to d = {max_dim} (lowest "
                     f"{100 * float(np.nanmin(fnn)):.0f} %): more dimensions than this record "
                     "supports, or noise", e1, e2, fnn)  # fmt: skip


def mean_period(x) -> float:
    """Mean period in samples, 1 / (power-weighted mean frequency) -- a Theiler window."""
    x = as_signal(x, name="x")
    x = x - np.mean(x)
    p = np.abs(np.fft.rfft(x)) ** 2
    f = np.fft.rfftfreq(x.size)
    p[0] = 0.0
    fm = np.sum(f * p) / np.sum(p) if np.sum(p) > 0 else 0.0
    return float(1.0 / fm) if fm > 0 else float(x.size)
