r"""The vibration engineer's toolkit for reciprocating machines: crank-angle resampling and
order spectra, spectrogram and Campbell diagram, envelope spectrum, cepstrum, band-limited
velocity RMS with evaluation zones, condition indicators and impact detection.

Generic: every function takes a sampled signal and, where the crank matters, the crank angle
(in revolutions) at each sample -- from a once-per-revolution tacho/keyphasor channel
(:func:`tacho_times`, :func:`crank_angle`) or a constant speed.

References
----------
Randall, *Vibration-based Condition Monitoring*, 2nd ed., Wiley 2021: order tracking by
computed resampling (ch. 3.6), envelope analysis (ch. 3.4, 5.5), cepstrum (ch. 3.5).
Fyfe & Munck (1997), Mech. Syst. Signal Process. 11, 187-205 (computed order tracking).
Bogert, Healy & Tukey (1963) (cepstrum). ISO 20816-8:2018, *Mechanical vibration --
Measurement and evaluation of machine vibration -- Part 8: Reciprocating compressor systems*
(velocity r.m.s. over 2 Hz to 1000 Hz; its zone boundaries are not reproduced here: give them
with ``zones=`` from your copy of the standard).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal as sps
from scipy.stats import kurtosis, skew

from .spectrum import Spectrum, amplitude_spectrum

__all__ = ["tacho_times", "crank_angle", "angle_resample", "order_spectrum_angle",
           "spectrogram", "campbell", "envelope_spectrum", "cepstrum", "band_rms",
           "velocity_rms", "zone", "indicators", "Impact", "detect_impacts",
           "ISO20816_8_BAND_HZ"]  # fmt: skip

#: Frequency band of the ISO 20816-8:2018 velocity evaluation, Hz.
ISO20816_8_BAND_HZ = (2.0, 1000.0)


def tacho_times(tacho, fs: float, *, threshold: float | None = None,
                hysteresis: float = 0.1) -> np.ndarray:  # fmt: skip
    """Times (s) of the rising edges of a pulse channel, interpolated between samples.

    ``threshold`` defaults to halfway between the 5th and 95th percentiles; an edge re-arms
    only after the signal falls ``hysteresis`` (a fraction of that span) below it, so noise
    on a slow edge does not count twice."""
    v = np.asarray(tacho, dtype=float)
    lo, hi = np.percentile(v, [5, 95])
    if hi <= lo:
        raise ValueError("tacho channel is flat: no pulses")
    thr = 0.5 * (lo + hi) if threshold is None else float(threshold)
    rearm = thr - hysteresis * (hi - lo)
    ups = np.flatnonzero((v[1:] >= thr) & (v[:-1] < thr)) + 1
    downs = np.flatnonzero((v[1:] < rearm) & (v[:-1] >= rearm)) + 1
    edges = []
    last = None
    for u in ups:
        if last is not None and np.searchsorted(downs, u) == np.searchsorted(downs, last, "right"):
            continue  # no fall below the re-arm level since the last edge: the same pulse
        frac = (thr - v[u - 1]) / (v[u] - v[u - 1])
        edges.append((u - 1 + frac) / fs)
        last = u
    return np.array(edges)


def crank_angle(n: int, fs: float, *, pulses=None, speed_hz: float | None = None,
                pulses_per_rev: int = 1, zero_rev: float = 0.0) -> np.ndarray:  # fmt: skip
    """Crank angle in revolutions at each of ``n`` samples.

    From pulse times (``pulses``, s; ``pulses_per_rev`` per revolution, the first at angle
    ``zero_rev``): monotone cubic (PCHIP) interpolation of the revolution count over time,
    NaN before the first and after the last pulse. From a constant ``speed_hz``: ``f t``."""
    t = np.arange(n) / fs
    if pulses is None:
        if not speed_hz or speed_hz <= 0:
            raise ValueError("give pulse times or a positive speed_hz")
        return zero_rev + speed_hz * t
    from scipy.interpolate import PchipInterpolator

    p = np.asarray(pulses, dtype=float)
    if p.size < 3:
        raise ValueError(f"{p.size} tacho pulses; at least 3 needed")
    if np.any(np.diff(p) <= 0):
        raise ValueError("pulse times must increase")
    revs = zero_rev + np.arange(p.size) / pulses_per_rev
    out = PchipInterpolator(p, revs, extrapolate=False)(t)
    return out


def angle_resample(x, revs, samples_per_rev: int) -> tuple[np.ndarray, np.ndarray]:
    """``x`` at uniformly spaced crank angles: ``(angle_grid_rev, x_angle)`` over the whole
    revolutions covered (computed order tracking, Fyfe & Munck 1997; linear interpolation,
    so the time signal should be sampled at least ~5x above the highest order of interest)."""
    x = np.asarray(x, dtype=float)
    revs = np.asarray(revs, dtype=float)
    ok = np.isfinite(revs)
    r, y = revs[ok], x[ok]
    if r.size < 2 or np.any(np.diff(r) <= 0):
        raise ValueError("crank angle must increase (a tacho or a positive speed)")
    first, last = np.ceil(r[0]), np.floor(r[-1])
    if last - first < 1:
        raise ValueError("less than one whole revolution covered")
    grid = first + np.arange(int(round((last - first) * samples_per_rev))) / samples_per_rev
    return grid, np.interp(grid, r, y)


def order_spectrum_angle(x_angle, samples_per_rev: int, window: str = "hann") -> Spectrum:
    """Amplitude spectrum of an angle-domain signal: its ``frequency`` axis is in orders
    (cycles per revolution), sharp even when the speed varied."""
    return amplitude_spectrum(x_angle, float(samples_per_rev), window=window)


def spectrogram(x, fs: float, *, nperseg: int | None = None, overlap: float = 0.75):
    """``(frequency_hz, time_s, amplitude)`` of a short-time Fourier transform (Hann window,
    amplitude-scaled like :func:`~recipdyn.analysis.spectrum.amplitude_spectrum`)."""
    x = np.asarray(x, dtype=float)
    nperseg = int(nperseg or min(x.size, max(64, 2 ** int(np.log2(x.size / 16)))))
    f, t, Z = sps.stft(x - x.mean(), fs, window="hann", nperseg=nperseg,
                       noverlap=int(overlap * nperseg), boundary=None, padded=False,
                       scaling="spectrum")  # fmt: skip
    return f, t, 2.0 * np.abs(Z)


def campbell(x, fs: float, revs, *, nperseg: int | None = None, overlap: float = 0.75):
    """Campbell (waterfall) data of a run-up or coast-down: ``(frequency_hz, speed_hz,
    amplitude)`` with one STFT frame per row, its speed the mean crank speed over the frame
    (from the crank angle ``revs``). Orders appear as straight lines through the origin."""
    f, t, A = spectrogram(x, fs, nperseg=nperseg, overlap=overlap)
    revs = np.asarray(revs, dtype=float)
    ts = np.arange(revs.size) / fs
    speed = np.gradient(revs, ts)
    frame_speed = np.interp(t, ts, speed)
    return f, frame_speed, A.T


def envelope_spectrum(x, fs: float, band: tuple[float, float] | None = None,
                      order: int = 4) -> tuple[Spectrum, np.ndarray]:  # fmt: skip
    """Spectrum of the Hilbert envelope of ``x`` band-passed to ``band`` (Hz; default the
    upper half of the spectrum, fs/4 to 0.45 fs, where impact-excited resonances live).
    Returns ``(spectrum, envelope)``: repeated impacts show as lines at their rate."""
    x = np.asarray(x, dtype=float)
    lo, hi = band if band is not None else (fs / 4, 0.45 * fs)
    if not 0 < lo < hi < fs / 2:
        raise ValueError(f"band = ({lo:g}, {hi:g}) Hz; allowed: 0 < low < high < fs/2 = "
                         f"{fs / 2:g} Hz")  # fmt: skip
    sos = sps.butter(order, [lo, hi], btype="bandpass", fs=fs, output="sos")
    env = np.abs(sps.hilbert(sps.sosfiltfilt(sos, x - x.mean())))
    return amplitude_spectrum(env, fs), env


def cepstrum(x, fs: float, window: str = "hann") -> tuple[np.ndarray, np.ndarray]:
    """Real cepstrum ``(quefrency_s, c)``: the inverse FFT of the log amplitude spectrum.
    Families of harmonics or sidebands spaced by ``df`` show as a peak at ``1/df``; an echo
    delayed by ``tau`` as a peak at ``tau``."""
    x = np.asarray(x, dtype=float)
    w = sps.get_window(window, x.size)
    mag = np.abs(np.fft.rfft((x - x.mean()) * w))
    c = np.fft.irfft(np.log(mag + 1e-12 * mag.max()), n=x.size)
    q = np.arange(x.size) / fs
    half = x.size // 2
    return q[:half], c[:half]


def band_rms(x, fs: float, band: tuple[float, float], *, integrate: int = 0) -> float:
    """RMS of ``x`` restricted to ``band`` (Hz), after integrating ``integrate`` times in the
    frequency domain (1: acceleration to velocity, 2: to displacement). Parseval over the
    one-sided FFT; bins outside the band are dropped (an ideal filter)."""
    x = np.asarray(x, dtype=float)
    n = x.size
    X = np.fft.rfft(x - x.mean())
    f = np.fft.rfftfreq(n, 1.0 / fs)
    keep = (f >= band[0]) & (f <= band[1]) & (f > 0)
    Xk = X[keep] / (2j * np.pi * f[keep]) ** integrate
    w = np.where(np.isclose(f[keep], fs / 2) & (n % 2 == 0), 1.0, 2.0)
    return float(np.sqrt(np.sum(w * np.abs(Xk) ** 2)) / n)


def velocity_rms(acceleration, fs: float, band=ISO20816_8_BAND_HZ) -> float:
    """Velocity RMS (in the acceleration's length unit per second) over ``band`` (default
    ISO 20816-8's 2 Hz to 1000 Hz) from an acceleration signal."""
    return band_rms(acceleration, fs, band, integrate=1)


def zone(value: float, boundaries) -> str:
    """Evaluation zone ``A``..``D`` of ``value`` from the three boundaries A/B, B/C, C/D
    (increasing; from the standard for the machine and measurement location)."""
    b = [float(v) for v in boundaries]
    if len(b) != 3 or not b[0] < b[1] < b[2]:
        raise ValueError(f"zone boundaries {boundaries!r}; allowed: three increasing values "
                         "(A/B, B/C, C/D)")  # fmt: skip
    return "ABCD"[int(np.searchsorted(b, value, side="right"))]


def indicators(x) -> dict[str, float]:
    """RMS, peak, peak-to-peak, crest factor (peak / RMS), kurtosis (Pearson: 3 for Gaussian
    noise, 1.5 for a sine, large for impacts) and skewness of the mean-free signal."""
    x = np.asarray(x, dtype=float)
    y = x - x.mean()
    rms = float(np.sqrt(np.mean(y**2)))
    peak = float(np.max(np.abs(y)))
    return {"rms": rms, "peak": peak, "peak_to_peak": float(np.ptp(x)),
            "crest_factor": peak / rms if rms > 0 else float("nan"),
            "kurtosis": float(kurtosis(y, fisher=False)), "skewness": float(skew(y))}  # fmt: skip


@dataclass(frozen=True)
class Impact:
    """One burst: onset and peak time (s), peak envelope, crank angle at the onset (deg, NaN
    without a crank angle) and the revolution it falls in. The onset (first sample over the
    threshold) is the impact's timing: the envelope peaks later, after the resonance it
    excites has built up."""

    start: float
    time: float
    peak: float
    angle_deg: float
    revolution: int


def detect_impacts(x, fs: float, *, revs=None, band: tuple[float, float] | None = None,
                   threshold: float = 8.0,
                   min_gap: float | None = None) -> list[Impact]:  # fmt: skip
    """Impact bursts: where the band-passed envelope exceeds its median by ``threshold``
    robust standard deviations (1.4826 MAD). Bursts closer than ``min_gap`` (s; default 2 %
    of a revolution with ``revs``, else 2 ms) are one impact."""
    _, env = envelope_spectrum(x, fs, band)
    med = np.median(env)
    sigma = 1.4826 * np.median(np.abs(env - med))
    level = med + threshold * max(sigma, 1e-12 * max(env.max(), 1e-300))
    above = env > level
    if not above.any():
        return []
    revs = None if revs is None else np.asarray(revs, dtype=float)
    if min_gap is None:
        if revs is not None and np.isfinite(revs).sum() > 2:
            ok = np.isfinite(revs)
            rate = (revs[ok][-1] - revs[ok][0]) / (ok.sum() / fs)
            min_gap = 0.02 / rate if rate > 0 else 2e-3
        else:
            min_gap = 2e-3
    gap = max(1, int(round(min_gap * fs)))
    idx = np.flatnonzero(above)
    splits = np.flatnonzero(np.diff(idx) > gap) + 1
    out = []
    for run in np.split(idx, splits):
        seg = run[0] + np.argmax(env[run[0] : run[-1] + 1])
        if revs is not None and np.isfinite(revs[run[0]]):
            ang, rev = float((revs[run[0]] % 1.0) * 360.0), int(np.floor(revs[run[0]]))
        else:
            ang, rev = float("nan"), -1
        out.append(Impact(run[0] / fs, seg / fs, float(env[seg]), ang, rev))
    return out
