r"""Surrogate data: is a signal more than linearly correlated noise?

A positive exponent from a signal means chaos only if the signal is deterministic: white noise,
coloured (linear) noise and a noisy periodic signal all give divergence curves that rise. The
surrogate test asks whether the signal can be told apart from its IAAFT surrogates -- series
with the same amplitude distribution and (nearly) the same power spectrum, otherwise random,
i.e. realisations of the null hypothesis "a linear Gaussian process seen through a static
monotone transform".

* **IAAFT** (Schreiber & Schmitz 1996): alternately impose the data's Fourier amplitudes and
  its sorted values, starting from a random shuffle, until the ranks stop changing.
* **End matching** (Schreiber & Schmitz 2000): the discrete Fourier transform treats the record
  as periodic; a jump between its last and first sample adds a broadband tail that the
  surrogates inherit as fake nonlinearity. The test runs on the sub-record (at most 10 % cut at
  each end) whose ends match best in value and slope.
* **Statistic**: the error of a local-constant nonlinear predictor (Farmer & Sidorowich 1987;
  Sugihara & May 1990) ``horizon`` samples ahead in a delay embedding, normalised by the
  standard deviation: determinism makes it small.
* **Rank test**: with ``M`` surrogates, the probability that the data's error is the smallest
  of the ``M + 1`` values under the null hypothesis is ``1 / (M + 1)``; M = 19 gives a
  one-sided test at 5 % (Theiler et al. 1992; Schreiber & Schmitz 2000). We also ask for a
  separation of 3 surrogate standard deviations, which only lowers the false-rejection rate.

References
----------
Theiler, Eubank, Longtin, Galdrikian & Farmer (1992), Physica D 58, 77-94.
Schreiber & Schmitz (1996), Phys. Rev. Lett. 77, 635-638.
Schreiber & Schmitz (2000), Physica D 142, 346-382.
Farmer & Sidorowich (1987), Phys. Rev. Lett. 59, 845; Sugihara & May (1990), Nature 344, 734.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..defaults import MIN_SIGNAL_SAMPLES
from .checks import as_signal
from .embedding import delay_embed

__all__ = ["iaaft", "match_ends", "prediction_error", "SurrogateTest", "surrogate_test"]


def iaaft(x, n_surrogates: int = 19, *, seed: int = 0, max_iter: int = 200,
          rank_tol: float = 0.01) -> np.ndarray:  # fmt: skip
    """``n_surrogates`` IAAFT surrogates of ``x`` (array ``(n_surrogates, N)``), seeded.

    Each has exactly the values of ``x`` (rearranged) and Fourier amplitudes close to those
    of ``x``: the iteration stops when fewer than ``rank_tol`` of the ranks change in a round
    (the spectrum then matches to better than 1e-3 relative; it stalls there, Schreiber & Schmitz
    1996), or after ``max_iter`` rounds."""
    x = as_signal(x, name="x", min_samples=4)
    rng = np.random.default_rng(seed)
    amp = np.abs(np.fft.rfft(x))
    ordered = np.sort(x)
    s = np.array([rng.permutation(x) for _ in range(n_surrogates)])
    rows = np.arange(n_surrogates)[:, None]
    order = np.argsort(s, axis=1)
    for _ in range(max_iter):
        spec = np.fft.rfft(s, axis=1)
        s = np.fft.irfft(amp * np.exp(1j * np.angle(spec)), n=x.size, axis=1)
        new = np.argsort(s, axis=1)
        s[rows, new] = ordered  # the k-th smallest value goes where the k-th smallest is
        changed = np.mean(new != order)
        order = new
        if changed < rank_tol:
            break
    return s


def match_ends(x, max_cut: float = 0.1) -> tuple[int, int]:
    """``(start, stop)`` of the sub-record, cutting at most ``max_cut`` of the length at each
    end, whose first and last samples agree best in value and in slope (both relative to the
    signal's spread)."""
    x = as_signal(x, name="x", min_samples=4, allow_constant=True)
    n = x.size
    m = max(2, int(max_cut * n))
    sd = np.std(x) or 1.0
    d = np.diff(x)
    heads = np.arange(0, m)
    tails = np.arange(n - m, n - 1)  # stop index (exclusive) = tail + 1
    jump = (x[heads][:, None] - x[tails][None, :]) ** 2
    slope = (d[heads][:, None] - d[tails - 1][None, :]) ** 2
    cost = (jump + slope) / sd**2
    i, j = np.unravel_index(np.argmin(cost), cost.shape)
    return int(heads[i]), int(tails[j] + 1)


def prediction_error(x, dim: int, delay: int, horizon: int = 1, k: int = 5) -> float:
    """Normalised error of a local-constant predictor: each point of the record's second half
    is predicted ``horizon`` samples ahead as the mean of what followed its ``k`` nearest
    neighbours (delay embedding) in the first half. RMS error / standard deviation of ``x``:
    about 1.4 for white noise, far below 1 for low-dimensional determinism."""
    x = as_signal(x, name="x", min_samples=4)
    X = delay_embed(x, dim, delay)
    target = np.arange(X.shape[0]) + (dim - 1) * delay + horizon  # index into x
    usable = target < x.size
    X, target = X[usable], target[usable]
    half = X.shape[0] // 2
    tree = cKDTree(X[:half])
    _, j = tree.query(X[half:], k=k)
    pred = x[target[:half]][j].mean(axis=1)
    err = pred - x[target[half:]]
    sd = np.std(x)
    return float(np.sqrt(np.mean(err**2)) / sd) if sd > 0 else 0.0


@dataclass
class SurrogateTest:
    """Result of [`surrogate_test`][recipdyn.analysis.surrogates.surrogate_test]: ``nonlinear`` is
    True when the null hypothesis (linear Gaussian process, static transform) is rejected at
    ``significance``."""

    nonlinear: bool
    statistic: float
    surrogates: np.ndarray
    rank: int
    significance: float
    z: float
    segment: tuple[int, int]
    params: dict

    def diagnostics(self) -> dict:
        return {"nonlinear": self.nonlinear, "prediction_error": self.statistic,
                "surrogate_errors_min": float(self.surrogates.min()),
                "surrogate_errors_mean": float(self.surrogates.mean()),
                "rank": self.rank, "n_surrogates": int(self.surrogates.size),
                "significance": self.significance, "z": self.z,
                "segment": list(self.segment), **self.params}  # fmt: skip

    @property
    def summary(self) -> str:
        verb = "rejected" if self.nonlinear else "not rejected"
        return (
            f"linear-noise hypothesis {verb} at {100 * self.significance:.0f} % "
            f"(prediction error {self.statistic:.3f}, surrogates "
            f"{self.surrogates.min():.3f}..{self.surrogates.max():.3f}, z = {self.z:.1f})"
        )


def surrogate_test(x, *, dim: int, delay: int, horizon: int | None = None,
                   n_surrogates: int = 19, max_samples: int = 8192,
                   min_z: float = 3.0, seed: int = 0) -> SurrogateTest:  # fmt: skip
    """Rank test of the prediction error of ``x`` against ``n_surrogates`` IAAFT surrogates.

    ``horizon`` defaults to ``delay`` (one sample for maps). At most ``max_samples`` samples
    (the first ones) are used. Rejection needs the data's error to be the smallest of all
    (significance ``1 / (n_surrogates + 1)``) and at least ``min_z`` standard deviations of
    the surrogates' errors below their mean: a bare rank test rejects for one noise record
    in twenty, and a verdict of chaos should not rest on that."""
    x = as_signal(x, name="x", min_samples=MIN_SIGNAL_SAMPLES)[:max_samples]
    a, b = match_ends(x)
    x = x[a:b]
    dim = int(min(max(dim, 2), 8))
    horizon = int(delay if horizon is None else horizon)
    stat = prediction_error(x, dim, delay, horizon)
    surr = np.array([prediction_error(s, dim, delay, horizon)
                     for s in iaaft(x, n_surrogates, seed=seed)])  # fmt: skip
    rank = int(np.sum(surr <= stat))  # 0: the data's error is the smallest
    sd = surr.std(ddof=1)
    z = float((surr.mean() - stat) / sd) if sd > 0 else float("inf")
    alpha = 1.0 / (n_surrogates + 1)
    return SurrogateTest(rank == 0 and z >= min_z, stat, surr, rank, alpha, z, (a, b),
                         {"dim": dim, "delay": int(delay), "horizon": horizon,
                          "samples": int(x.size), "min_z": min_z})  # fmt: skip
