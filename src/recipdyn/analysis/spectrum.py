"""Amplitude spectra with correct scaling, and labelled spectral peaks.

A sine of amplitude A at a bin-centred frequency shows a peak of height A whatever the window:
the one-sided FFT magnitude is divided by the window's coherent gain (its mean). Peaks are found
with `scipy.signal.find_peaks` and labelled as harmonics of a given fundamental (the crank
frequency) when they fall within ``tol_bins`` bins of an integer multiple of it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.fft import rfft, rfftfreq
from scipy.signal import find_peaks, get_window

from .checks import as_signal, check_rate

__all__ = [
    "Spectrum",
    "Peak",
    "amplitude_spectrum",
    "find_spectral_peaks",
    "order_spectrum",
    "nonharmonic_peak",
    "display_band",
]


@dataclass(frozen=True)
class Spectrum:
    """One-sided amplitude spectrum.

    Attributes
    ----------
    frequency : ndarray
        Hz.
    amplitude : ndarray
        Same units as the signal (peak amplitude of a sinusoid).
    resolution : float
        Bin width ``fs / n``, Hz.
    window : str
    fs : float
        Sampling rate, Hz.
    """

    frequency: np.ndarray
    amplitude: np.ndarray
    resolution: float
    window: str
    fs: float


@dataclass(frozen=True)
class Peak:
    """A spectral peak; ``order`` is the harmonic number of the fundamental (0 = not one)."""

    frequency: float
    amplitude: float
    order: int


def amplitude_spectrum(x, fs: float, window: str = "hann", detrend: bool = True) -> Spectrum:
    """One-sided amplitude spectrum of a real signal.

    Parameters
    ----------
    x : array_like
        Uniformly sampled signal.
    fs : float
        Sampling rate, Hz (> 0).
    window : str
        Any `scipy.signal.get_window` name ("hann", "hamming", "blackmanharris",
        "flattop" for accurate amplitudes between bins, "boxcar" for none).
    detrend : bool
        Remove the mean first (the DC bin is then ~0).

    Notes
    -----
    ``amplitude = 2 |X_k| / (n * mean(w))`` for ``0 < k < n/2``, half that at DC and Nyquist.
    Frequency resolution ``fs / n``: a 10-revolution record at 20 rad/s resolves 0.32 Hz.
    """
    # a constant signal has an exact spectrum (zero): a stalled channel's window keeps its row
    x = as_signal(x, name="x", min_samples=2, allow_constant=True)
    fs = check_rate(fs)
    n = x.size
    if detrend:
        x = x - x.mean()
    w = get_window(window, n, fftbins=True)
    amp = np.abs(rfft(x * w)) * 2.0 / (n * w.mean())
    amp[0] /= 2.0
    if n % 2 == 0:
        amp[-1] /= 2.0
    return Spectrum(rfftfreq(n, 1.0 / fs), amp, fs / n, window, float(fs))


def find_spectral_peaks(
    spec: Spectrum,
    n: int = 10,
    *,
    fundamental: float | None = None,
    tol_bins: float = 1.5,
    min_rel_height: float = 1e-3,
    min_separation: float = 0.0,
) -> list[Peak]:
    """The ``n`` largest local maxima, largest first, labelled as harmonics of ``fundamental``.

    ``min_rel_height`` drops peaks below that fraction of the largest (numerical noise).
    ``min_separation`` (relative, e.g. 0.1): list humps, not bins. The spectrum is averaged
    over +-``min_separation * f`` around each frequency ``f`` (a window that widens with
    frequency, as an analyst's fractional-octave bands do); each maximum of that envelope which
    stands out from its surroundings (prominence at least a quarter of its height) is one
    entry, reported at the largest line of the raw spectrum between its bases. The comb of
    harmonics under a structural ring excited once a revolution, or the ripples of one broad
    line, is then one entry, while low harmonics (further apart than the window) stay
    separate. 0: every local maximum of the raw spectrum.

    A peak is harmonic ``k`` of ``fundamental`` (``order = k``) when it lies within
    ``tol_bins`` frequency bins of ``k * fundamental``: the largest bin of a windowed line is
    within half a bin of the line's frequency, and one more bin allows for the leakage of a
    neighbouring line shifting that maximum. Any other peak has ``order = 0``: not an order.
    """
    amp = spec.amplitude
    if amp.size < 3 or amp.max() <= 0:
        return []
    if min_separation > 0:
        idx = _hump_peaks(spec, min_separation, min_rel_height)
    else:
        idx, _ = find_peaks(amp, height=min_rel_height * amp.max())
    idx = idx[np.argsort(amp[idx])[::-1][:n]]
    peaks = []
    for i in idx:
        f = float(spec.frequency[i])
        order = 0
        if fundamental:
            k = round(f / fundamental)
            if k >= 1 and abs(f - k * fundamental) <= tol_bins * spec.resolution:
                order = int(k)
        peaks.append(Peak(f, float(amp[i]), order))
    return peaks


def _hump_peaks(spec: Spectrum, rel: float, min_rel_height: float) -> np.ndarray:
    """Indices of the largest raw line under each prominent maximum of the spectrum averaged
    over +-``rel * f`` (see `find_spectral_peaks`)."""
    amp = spec.amplitude
    k = np.arange(amp.size)
    half = np.maximum(1, np.round(rel * spec.frequency / spec.resolution)).astype(int)
    lo, hi = np.maximum(0, k - half), np.minimum(amp.size - 1, k + half)
    cs = np.concatenate(([0.0], np.cumsum(amp)))
    env = (cs[hi + 1] - cs[lo]) / (hi - lo + 1)
    cand, props = find_peaks(env, prominence=0.0)
    keep = props["prominences"] >= 0.25 * env[cand]
    out = []
    for i, left, right in zip(cand[keep], props["left_bases"][keep],
                              props["right_bases"][keep], strict=True):  # fmt: skip
        a, b = max(left, i - half[i]), min(right, i + half[i])
        j = a + int(np.argmax(amp[a : b + 1]))
        if amp[j] >= min_rel_height * amp.max():
            out.append(j)
    return np.unique(np.array(out, dtype=int))


def order_spectrum(spec: Spectrum, fundamental: float) -> tuple[np.ndarray, np.ndarray]:
    """The spectrum over orders of ``fundamental`` (crank orders): ``(orders, amplitude)``."""
    return spec.frequency / fundamental, spec.amplitude


def _harmonic_mask(freq: np.ndarray, fundamental: float, resolution: float, tol_bins: float):
    """Bins within ``tol_bins`` bins of a harmonic, at most a quarter of the fundamental on
    each side (a record of a few periods has bins so wide that the tolerance would otherwise
    cover every frequency)."""
    order = freq / fundamental
    width = min(tol_bins * resolution, fundamental / 4)
    return np.abs(order - np.round(order)) * fundamental < width


def nonharmonic_peak(
    freq, amp, fundamental: float, *, min_order: float = 8.0, tol_bins: float = 1.5,
    min_rel_height: float = 1e-9,
) -> float:  # fmt: skip
    """Frequency of the largest spectral line above ``min_order`` orders of ``fundamental``
    that is not one of its harmonics (in the compressor: the link's or the joint's own
    oscillation); NaN when there is none above ``min_rel_height`` of the largest line."""
    freq = np.asarray(freq, dtype=float)
    amp = np.asarray(amp, dtype=float).copy()
    if freq.size < 3 or not np.any(amp > 0):
        return float("nan")
    top = amp.max()
    df = freq[1] - freq[0]
    amp[(freq < min_order * fundamental) | _harmonic_mask(freq, fundamental, df, tol_bins)] = 0
    if amp.max() <= min_rel_height * top:
        return float("nan")
    return float(freq[np.argmax(amp)])


def display_band(
    spec: Spectrum, fundamental: float | None = None, *, min_orders: float = 30.0,
    min_rel_height: float = 1e-3, margin: float = 1.3, min_hz: float = 50.0,
) -> float:  # fmt: skip
    """Upper frequency limit that shows every line of ``spec`` above ``min_rel_height`` of the
    largest one (``margin`` times the highest such line), at least ``min_orders`` orders of
    ``fundamental`` (or ``min_hz``), at most the Nyquist frequency.

    A fixed band (say 60 crank orders) hides what a clearance fault adds: the link's own
    oscillation lies at hundreds of orders (kHz at 20 rad/s).
    """
    nyquist = spec.fs / 2.0
    low = max(min_hz, min_orders * fundamental if fundamental else 0.0)
    amp = spec.amplitude
    if amp.size < 3 or not np.any(amp > 0):
        return min(nyquist, low)
    idx, _ = find_peaks(amp, height=min_rel_height * amp.max())
    highest = float(spec.frequency[idx].max()) if idx.size else 0.0
    return float(min(nyquist, max(low, margin * highest)))
