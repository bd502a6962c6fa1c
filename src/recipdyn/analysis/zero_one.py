r"""The 0-1 test for chaos (Gottwald & Melbourne), correlation method.

For an observable phi(j), j = 1..N, and a random frequency c in (pi/5, 4 pi/5)::

    p_c(n) = sum_{j<=n} phi(j) cos(j c),   q_c(n) = sum_{j<=n} phi(j) sin(j c)
    M_c(n) = mean_j [(p_c(j+n) - p_c(j))^2 + (q_c(j+n) - q_c(j))^2]
    D_c(n) = M_c(n) - (E phi)^2 (1 - cos(n c)) / (1 - cos c)
    K_c    = corr(n, D_c(n)),   n = 1..n_cut (n_cut = N/10)

K = median over c of K_c: ~1 for chaotic dynamics (p, q diffuse like Brownian motion), ~0 for
regular dynamics (p, q bounded). Apply it to a map's orbit or a flow sampled stroboscopically
(oversampled flows give false 0s; Gottwald & Melbourne 2009):
[`zero_one`][recipdyn.analysis.zero_one.zero_one] first thins a signal to about one sample per
decorrelation time (the delay of [`estimate_delay`][recipdyn.analysis.embedding.estimate_delay], one
sample for maps), so the same flow sampled at two rates gives the same K.

M_c(n) for all n at once by the FFT: with z = p + i q,
sum_j |z(j+n) - z(j)|^2 = sum_{j>=n} |z_j|^2 + sum_{j<N-n} |z_j|^2 - 2 Re sum_j conj(z_j) z(j+n),
the last sum an autocorrelation: O(N log N) per c instead of O(N n_cut).

The test cannot tell chaos from noise (white noise gives K = 1): a verdict needs a
determinism check as well ([`recipdyn.analysis.surrogates`][recipdyn.analysis.surrogates]).

References
----------
Gottwald & Melbourne (2004), Proc. R. Soc. A 460, 603; (2009), SIAM J. Appl. Dyn. Syst. 8, 129.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .checks import as_signal

__all__ = ["zero_one_test", "zero_one", "ZeroOne"]

#: Fewest samples the test is run on after thinning (Gottwald & Melbourne use 10^3 to 10^4).
MIN_SAMPLES = 500


def _mean_square_displacement(z: np.ndarray, n_cut: int) -> np.ndarray:
    """M(n) = mean_j |z(j+n) - z(j)|^2 for n = 1..n_cut (FFT autocorrelation)."""
    N = z.size
    f = np.fft.fft(z, 2 * N)
    r = np.fft.ifft(f * np.conj(f))[: n_cut + 1].real  # sum_j z(j+n) conj(z_j), n = 0..n_cut
    sq = np.abs(z) ** 2
    cs = np.concatenate(([0.0], np.cumsum(sq)))  # cs[k] = sum_{j<k} |z_j|^2
    n = np.arange(1, n_cut + 1)
    head = cs[N - n]  # sum_{j < N-n}
    tail = cs[N] - cs[n]  # sum_{j >= n}
    return (head + tail - 2.0 * r[1:]) / (N - n)


def zero_one_test(phi, *, n_c: int = 100, n_cut: int | None = None, seed: int = 0,
                  return_all: bool = False):  # fmt: skip
    """K statistic of the 0-1 test on ``phi`` as given (median over ``n_c`` random c; seeded).
    No thinning: for a map's orbit or a section. For a sampled flow use
    [`zero_one`][recipdyn.analysis.zero_one.zero_one]."""
    phi = as_signal(phi, name="phi", min_samples=100)
    N = phi.size
    n_cut = n_cut or N // 10
    rng = np.random.default_rng(seed)
    cs = rng.uniform(np.pi / 5, 4 * np.pi / 5, n_c)
    j = np.arange(1, N + 1)
    ns = np.arange(1, n_cut + 1)
    Ephi2 = phi.mean() ** 2
    ks = np.empty(n_c)
    for m, c in enumerate(cs):
        z = np.cumsum(phi * np.exp(1j * j * c))
        M = _mean_square_displacement(z, n_cut)
        D = M - Ephi2 * (1 - np.cos(ns * c)) / (1 - np.cos(c))
        ks[m] = 0.0 if np.std(D) == 0 else np.corrcoef(ns, D)[0, 1]
    K = float(np.median(ks))
    return (K, ks) if return_all else K


@dataclass
class ZeroOne:
    """The 0-1 test on a signal, with what was done to it."""

    K: float
    stride: int
    samples: int
    status: str
    reason: str

    def diagnostics(self) -> dict:
        return {"K": None if not np.isfinite(self.K) else self.K, "stride": self.stride,
                "samples": self.samples, "status": self.status, "reason": self.reason}  # fmt: skip


def zero_one(x, *, stride: int | None = None, max_samples: int = 20_000, n_c: int = 100,
             seed: int = 0) -> ZeroOne:  # fmt: skip
    """The 0-1 test of a sampled signal: thinned by ``stride`` (default: the embedding delay,
    about one decorrelation time; 1 for maps and for sections), then at most ``max_samples``
    values. Refused (K NaN) when fewer than ``MIN_SAMPLES`` values remain."""
    from .embedding import estimate_delay

    x = as_signal(x, name="x")
    if stride is None:
        stride = estimate_delay(x[:50_000]) if x.size >= MIN_SAMPLES else 1
    stride = max(1, int(stride))
    y = x[::stride][:max_samples]
    if y.size < MIN_SAMPLES:
        what = "values" if stride == 1 else f"values after thinning by {stride} (one per " \
            "decorrelation time)"  # fmt: skip
        return ZeroOne(float("nan"), stride, int(y.size), "refused",
                       f"{y.size} {what}; at least {MIN_SAMPLES} needed: a longer "
                       "record")  # fmt: skip
    return ZeroOne(zero_one_test(y, n_c=n_c, seed=seed), stride, int(y.size), "ok",
                   f"thinned by {stride} to {y.size} values")  # fmt: skip
