r"""The vibration engineer's toolkit for reciprocating machines: crank-angle resampling and
order spectra, spectrogram and Campbell diagram, envelope spectrum, cepstrum, band-limited
velocity RMS with evaluation zones, condition indicators and impact detection.

Generic: every function takes a sampled signal and, where the crank matters, the crank angle
(in revolutions) at each sample -- from a once-per-revolution tacho/keyphasor channel
([`tacho_times`][recipdyn.analysis.vibration.tacho_times],
[`crank_angle`][recipdyn.analysis.vibration.crank_angle]) or a constant speed.

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

import math
from dataclasses import dataclass

import numpy as np
from scipy import signal as sps
from scipy.stats import kurtosis, skew

from .checks import as_signal
from .spectrum import Spectrum, amplitude_spectrum, find_spectral_peaks

__all__ = ["tacho_times", "tacho_levels", "TachoLevels", "check_pulse_train", "crank_angle",
           "angle_resample", "crank_orders", "order_spectrum_angle", "spectrogram", "campbell",
           "envelope_spectrum", "cepstrum", "band_rms",
           "velocity_rms", "zone", "indicators", "Impact", "detect_impacts",
           "ISO20816_8_BAND_HZ", "vibration_report", "resonance_band",
           "impact_pattern"]  # fmt: skip

#: Frequency band of the ISO 20816-8:2018 velocity evaluation, Hz.
ISO20816_8_BAND_HZ = (2.0, 1000.0)


#: Smallest pulse height, in standard deviations of the levels' noise, at which a pulse train
#: is read: the trigger sits half a height, six or more standard deviations, from either
#: level, so white Gaussian noise crosses it falsely with probability 1e-9 per sample or
#: less (1e-4 over a record of 1e5 samples); below it the channel is refused.
TACHO_MIN_HEIGHT_SIGMAS = 12.0


@dataclass(frozen=True)
class TachoLevels:
    """A pulse channel's two levels and the thresholds read from them (`tacho_levels`):
    ``baseline`` and ``pulse`` levels, the ``noise``'s standard deviation, ``polarity`` +1
    (the pulse above the baseline) or -1, the trigger ``threshold`` (half-way) and the
    ``rearm`` level the signal must pass back through before the next edge counts."""

    baseline: float
    pulse: float
    noise: float
    polarity: int
    threshold: float
    rearm: float

    @property
    def height(self) -> float:
        return abs(self.pulse - self.baseline)


def _otsu_split(v: np.ndarray, bins: int = 4096) -> float:
    """The value that splits ``v`` into two classes of largest between-class variance (Otsu
    1979), over a histogram of ``bins`` equal bins spanning the samples: the split lands in
    the gap between two levels whenever that gap is wider than a bin, 1/4096 of the span."""
    counts, edges = np.histogram(v, bins=bins)
    mids = 0.5 * (edges[1:] + edges[:-1])
    w = np.cumsum(counts)[:-1].astype(float)  # samples at or below each candidate split
    s = np.cumsum(counts * mids)[:-1]
    n, total = float(v.size), float(np.sum(counts * mids))
    with np.errstate(divide="ignore", invalid="ignore"):
        between = (total * w / n - s) ** 2 / (w * (n - w))
    between[(w == 0) | (w == n)] = -1.0
    return float(edges[int(np.argmax(between)) + 1])


def tacho_levels(tacho, *, polarity: str = "auto", hysteresis: float = 0.1) -> TachoLevels:
    """The two levels of a once-per-revolution pulse channel, robustly.

    The noise's standard deviation comes from the sample-to-sample differences
    (``1.4826 median|diff| / sqrt 2``: a pulse's plateaus do not change from sample to
    sample and its two edges per revolution are a few samples among thousands, so the
    estimate holds for any width); the baseline is the level most samples hold (their
    median), the pulse the median of the samples more than eight noise deviations from it.
    So a pulse 1 degree wide (0.3 % of the samples) is found as well as one 179 degrees wide,
    and the polarity (``"auto"``) is the side the minority level lies on; with ``"positive"``
    or ``"negative"`` the pulse is taken on that side. A channel whose median falls between
    its levels (a pulse of exactly half a revolution) is split by Otsu's criterion instead.
    The trigger is half-way between the levels; an edge re-arms once the signal has passed
    back through ``rearm``, ``max(hysteresis * height, 3 noise)`` short of the trigger.

    Raises ``ValueError`` naming the tacho when the channel is flat or its pulses stand less
    than `TACHO_MIN_HEIGHT_SIGMAS` noise deviations from the baseline.
    """
    v = as_signal(tacho, name="tacho", min_samples=3, allow_constant=True)
    span = float(np.ptp(v))
    if not span > 0:
        raise ValueError("tacho channel is flat: no pulses")
    noise = 1.4826 * float(np.median(np.abs(np.diff(v)))) / math.sqrt(2.0)
    if polarity not in ("auto", "positive", "negative"):
        raise ValueError(f"tacho polarity = {polarity!r}; allowed: auto, positive, negative")
    med = float(np.median(v))
    d = v - med
    far = np.abs(d) > max(8.0 * noise, 1e-9 * span)
    up, down = far & (d > 0), far & (d < 0)
    if polarity == "auto":
        sign = 1 if np.count_nonzero(up) >= np.count_nonzero(down) else -1
    else:
        sign = 1 if polarity == "positive" else -1
    side = up if sign > 0 else down
    other = down if sign > 0 else up
    if np.count_nonzero(other) > 0.1 * max(1, np.count_nonzero(side)) or not side.any():
        split = _otsu_split(v)  # the median lies between the levels: half duty
        hi_side = v >= split
        side = hi_side if sign > 0 else ~hi_side
        base = float(np.median(v[~side]))
    else:
        base = float(np.median(v[~far]))
    pulse = float(np.median(v[side])) if side.any() else base
    height = sign * (pulse - base)
    if not height > 0 or height < TACHO_MIN_HEIGHT_SIGMAS * noise:
        raise ValueError(
            f"tacho: no pulse train stands out of the noise (baseline {base:.4g}, pulses at "
            f"{pulse:.4g}, noise {noise:.3g} standard deviation; the pulses must stand "
            f"{TACHO_MIN_HEIGHT_SIGMAS:g} deviations from the baseline, on the "
            f"{'positive' if sign > 0 else 'negative'} side)"
        )
    thr = 0.5 * (base + pulse)
    back = max(hysteresis * height, 3.0 * noise)
    return TachoLevels(base, pulse, noise, sign, thr, thr - sign * back)


def _leading_edges(v: np.ndarray, lv: TachoLevels, fs: float, offset: int = 0,
                   armed: bool = True) -> tuple[list[float], bool]:  # fmt: skip
    """Leading-edge times (s) of the pulses in ``v`` (its first sample at index ``offset``)
    and whether the detector is armed after its last sample. An edge is the crossing of the
    threshold away from the baseline, interpolated linearly between the two samples; it
    counts only once the signal has passed back through ``rearm`` since the last one."""
    w = lv.polarity * (v - lv.threshold)  # > 0 inside a pulse, whatever its polarity
    r = lv.polarity * (v - lv.rearm)
    ups = np.flatnonzero((w[1:] >= 0) & (w[:-1] < 0)) + 1
    downs = np.flatnonzero((r[1:] < 0) & (r[:-1] >= 0)) + 1
    events = sorted([(int(u), 1) for u in ups] + [(int(d), 0) for d in downs])
    edges = []
    for i, is_up in events:
        if not is_up:
            armed = True
        elif armed:
            frac = -w[i - 1] / (w[i] - w[i - 1])
            edges.append((offset + i - 1 + frac) / fs)
            armed = False
    return edges, armed


def check_pulse_train(edges, *, max_speed_hz: float = 100.0, max_step: float = 1.5) -> None:
    """Refuse (``ValueError``, naming the tacho) edge times that are not a once-per-revolution
    pulse train: two edges closer than ``1 / max_speed_hz`` (a crank faster than that), or a
    revolution's period more than ``max_step`` times its neighbour's or less than its
    inverse (a pulse missed or one too many; a crank does not change its speed by half in a
    revolution)."""
    e = np.asarray(edges, dtype=float)
    if e.size < 2:
        return
    d = np.diff(e)
    if np.min(d) < 1.0 / max_speed_hz:
        i = int(np.argmin(d))
        raise ValueError(
            f"tacho: pulses {d[i] * 1e3:.3g} ms apart at t = {e[i]:.4g} s, a crank speed of "
            f"{1 / d[i]:.4g} Hz, above the {max_speed_hz:g} Hz a reciprocating machine "
            "turns at: not a once-per-revolution pulse train (noise or a multi-tooth wheel?)"
        )
    if d.size >= 2:
        ratio = d[1:] / d[:-1]
        bad = np.flatnonzero((ratio > max_step) | (ratio < 1 / max_step))
        if bad.size:
            i = int(bad[0])
            raise ValueError(
                f"tacho: the revolution after t = {e[i + 1]:.4g} s lasts {d[i + 1] * 1e3:.4g} ms "
                f"against {d[i] * 1e3:.4g} ms before it: a pulse missed or one too many"
            )


def tacho_times(tacho, fs: float, *, threshold: float | None = None,
                hysteresis: float = 0.1, polarity: str = "auto",
                max_speed_hz: float = 100.0) -> np.ndarray:  # fmt: skip
    """Times (s) of the leading edges of a once-per-revolution pulse channel, interpolated
    between samples.

    The levels come from `tacho_levels` (Otsu's split of the samples, each level its side's
    median, the noise their robust spread), so a pulse from about 1 degree wide (as long as
    it spans a sample or two) to 180 degrees, of either polarity (``polarity="auto"``: the
    pulse is the level held by fewer samples), is found with noise up to 1/12 of its height
    (`TACHO_MIN_HEIGHT_SIGMAS`). ``threshold`` replaces the half-way trigger. An edge
    re-arms only after the signal passes back through the re-arm level (hysteresis: a
    fraction ``hysteresis`` of the height, or three noise standard deviations if more), so
    noise on a slow edge does not count twice. The edges must form a pulse train
    (`check_pulse_train`: no two closer than ``1 / max_speed_hz``, no period 1.5 times its
    neighbour's or less than its inverse). Raises ``ValueError`` naming the tacho and the
    reason otherwise.
    """
    lv = tacho_levels(tacho, polarity=polarity, hysteresis=hysteresis)
    if threshold is not None:
        back = lv.threshold - lv.rearm
        lv = TachoLevels(lv.baseline, lv.pulse, lv.noise, lv.polarity, float(threshold),
                         float(threshold) - back)  # fmt: skip
    v = np.asarray(tacho, dtype=float).ravel()
    edges, _ = _leading_edges(v, lv, fs)
    check_pulse_train(edges, max_speed_hz=max_speed_hz)
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
    revolutions covered (computed order tracking, Fyfe & Munck 1997). Cubic-spline
    interpolation: a component with ``p`` time samples per cycle loses about ``(pi/p)^4/ 3``
    of its amplitude (1e-5 at p = 30; linear interpolation loses ``(pi/p)^2 / 6``, 0.2 %)."""
    x = np.asarray(x, dtype=float)
    revs = np.asarray(revs, dtype=float)
    ok = np.isfinite(revs)
    r, y = revs[ok], x[ok]
    if r.size < 2 or np.any(np.diff(r) <= 0):
        raise ValueError("crank angle must increase (a tacho or a positive speed)")
    # the record's last sample ends its interval: a record of exactly N revolutions has its
    # last sample one step short of N, and still covers N
    first, last = np.ceil(r[0] - 1e-9), np.floor(r[-1] + np.median(np.diff(r)) * (1 + 1e-9))
    if last - first < 1:
        raise ValueError("less than one whole revolution covered")
    from scipy.interpolate import CubicSpline

    grid = first + np.arange(int(round((last - first) * samples_per_rev))) / samples_per_rev
    return grid, CubicSpline(r, y)(grid)


#: A window of whole revolutions may lack this share of one (a tacho's jitter of up to 1
#: degree on its last pulse): the least-squares fit of the orders stays orthogonal to
#: ~1e-3 of a revolution's missing content.
ORDER_SPAN_SLACK = 0.005


def crank_orders(x, revs, orders=(1, 2)) -> tuple[np.ndarray, int]:
    """The complex amplitudes of the crank ``orders`` of ``x`` (``x ~ Re(c_k e^{i k
    theta})``, ``theta`` the crank angle after the tacho's mark), over the most whole
    revolutions ``revs`` covers from its first angle, and the number of those revolutions.

    A least-squares fit, on the samples' own crank angles, of the orders 1 to
    ``max(orders)`` together with a straight line in ``theta``: a drift or the AC
    coupling's settling over the record would otherwise leak into the lowest orders (a line
    holds ``1/(pi k)`` of its rise in order ``k``), and a line removed apart would take the
    orders' sine parts' share of it along. Not resampled by angle first: a few hundred
    angle samples per revolution would fold the impacts' kilohertz ringing onto the low
    orders (`angle_resample` has no anti-alias filter; measured on the diagnosis data set:
    ~20 % of the 1st order)."""
    revs = np.asarray(revs, float)
    ok = np.isfinite(revs)
    r, y = revs[ok], np.asarray(x, float)[ok]
    if r.size < 2 or np.any(np.diff(r) <= 0):
        raise ValueError("crank angle must increase (a tacho or a positive speed)")
    # the last sample ends its interval, and the tacho's jitter moves the last pulse: a
    # record whose pulses span N revolutions to within `ORDER_SPAN_SLACK` covers N (the fit
    # below does not need the window filled to the sample)
    n = int(np.floor((r[-1] - r[0]) + np.median(np.diff(r)) + ORDER_SPAN_SLACK))
    if n < 1:
        raise ValueError("less than one whole revolution covered")
    inside = r < r[0] + n
    th, y = 2.0 * np.pi * r[inside], y[inside]
    ks = np.arange(1, int(max(orders)) + 1)
    cols = [np.ones_like(th), th - th.mean()]
    for k in ks:
        cols += [np.cos(k * th), np.sin(k * th)]
    coef = np.linalg.lstsq(np.column_stack(cols), y, rcond=None)[0]
    c = coef[2::2] - 1j * coef[3::2]
    return np.array([c[k - 1] for k in orders]), n


def order_spectrum_angle(x_angle, samples_per_rev: int, window: str = "hann") -> Spectrum:
    """Amplitude spectrum of an angle-domain signal: its ``frequency`` axis is in orders
    (cycles per revolution), sharp even when the speed varied."""
    return amplitude_spectrum(x_angle, float(samples_per_rev), window=window)


def spectrogram(x, fs: float, *, nperseg: int | None = None, overlap: float = 0.75):
    """``(frequency_hz, time_s, amplitude)`` of a short-time Fourier transform (Hann window,
    amplitude-scaled like [`amplitude_spectrum`][recipdyn.analysis.spectrum.amplitude_spectrum])."""
    x = as_signal(x, name="x", min_samples=8, allow_constant=True)
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


def resonance_band(x, fs: float, low: float | None = None) -> tuple[float, float]:
    """A band for envelope analysis: +-30 % around the strongest spectral line above ``low``
    (default 5 % of fs, above the running-speed harmonics), where impacts ring a structural
    resonance (Randall 2021, ch. 5.5, chooses it by spectral kurtosis; the strongest line is
    the simple stand-in). Clipped to (low, 0.45 fs)."""
    spec = amplitude_spectrum(x, fs)
    low = 0.05 * fs if low is None else float(low)
    sel = (spec.frequency > low) & (spec.frequency < 0.45 * fs)
    if not sel.any():
        return (fs / 4, 0.45 * fs)
    fc = float(spec.frequency[sel][np.argmax(spec.amplitude[sel])])
    return (max(low, 0.7 * fc), min(0.45 * fs, 1.3 * fc))


def envelope_spectrum(x, fs: float, band: tuple[float, float] | None = None,
                      order: int = 4) -> tuple[Spectrum, np.ndarray]:  # fmt: skip
    """Spectrum of the Hilbert envelope of ``x`` band-passed to ``band`` (Hz; default the
    upper half of the spectrum, fs/4 to 0.45 fs, where impact-excited resonances live).
    Returns ``(spectrum, envelope)``: repeated impacts show as lines at their rate."""
    x = as_signal(x, name="x", min_samples=16, allow_constant=True)
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
    x = as_signal(x, name="x", min_samples=4)
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
    x = as_signal(x, name="x", allow_constant=True)
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
    x = as_signal(x, name="x", min_samples=1, allow_constant=True)
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
                   threshold: float = 8.0, min_gap: float | None = None,
                   envelope=None) -> list[Impact]:  # fmt: skip
    """Impact bursts: where the band-passed envelope exceeds its median by ``threshold``
    robust standard deviations (1.4826 MAD), and 1 % of its largest value. Bursts closer
    than ``min_gap`` (s; default 2 % of a revolution with ``revs``, else 2 ms) are one
    impact."""
    env = envelope_spectrum(x, fs, band)[1] if envelope is None else np.asarray(envelope)
    # the band-pass filter and the Hilbert transform ring at the record's ends: bursts there
    # are artefacts (a few periods of the band's lower edge)
    lo = band[0] if band is not None else fs / 4
    edge = min(env.size // 4, max(16, int(round(4.0 * fs / lo))))
    env = env.copy()
    env[:edge] = 0.0
    env[env.size - edge :] = 0.0
    med = np.median(env)
    sigma = 1.4826 * np.median(np.abs(env - med))
    # a noise-free record has a floor of rounding dust: never below 1 % of the largest burst
    level = max(med + threshold * sigma, 0.01 * env.max())
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
        # onset: where the envelope first reaches a quarter of the burst's peak (the zero-phase
        # band-pass spreads the start of a burst both ways by about a period of the band's
        # lower edge; the threshold alone would date it by the filter's pre-ringing)
        on = run[0] + int(np.argmax(env[run[0] : seg + 1] >= 0.25 * env[seg]))
        if revs is not None and np.isfinite(revs[on]):
            ang, rev = float((revs[on] % 1.0) * 360.0), int(np.floor(revs[on]))
        else:
            ang, rev = float("nan"), -1
        out.append(Impact(on / fs, seg / fs, float(env[seg]), ang, rev))
    return out


def impact_pattern(hits, revolutions: float, *, tol_deg: float = 10.0,
                   min_share: float = 0.5) -> list[dict]:  # fmt: skip
    """Crank angles at which impacts recur: ``[{"angle_deg", "per_revolution"}]``, by angle.

    The impacts' onset angles (``hits``: `Impact` with a crank angle) are grouped on
    the circle: neighbours closer than ``tol_deg`` are one group (a group may not wrap
    through 360 deg twice). A group counts when it holds impacts in at least ``min_share`` of
    the ``revolutions`` covered: an impact that happens at that angle every revolution has
    ``per_revolution`` ~1. Its angle is the circular mean of its members."""
    ang = np.array([h.angle_deg for h in hits if np.isfinite(h.angle_deg)], dtype=float)
    if ang.size == 0 or not revolutions > 0:
        return []
    ang = np.sort(ang % 360.0)
    gaps = np.diff(np.r_[ang, ang[0] + 360.0])
    if np.all(gaps <= tol_deg):  # impacts at every angle: no pattern
        return []
    start = int(np.argmax(gaps)) + 1  # begin after the widest gap: no group spans it
    ang = np.roll(ang, -start)
    groups, cur = [], [ang[0]]
    for a, b in zip(ang[:-1], ang[1:], strict=True):
        if (b - a) % 360.0 <= tol_deg:
            cur.append(b)
        else:
            groups.append(cur)
            cur = [b]
    groups.append(cur)
    out = []
    for g in groups:
        share = len(g) / revolutions
        if share >= min_share:
            rad = np.deg2rad(g)
            mean = np.rad2deg(np.arctan2(np.sin(rad).mean(), np.cos(rad).mean())) % 360.0
            out.append({"angle_deg": round(float(mean), 1), "per_revolution": round(share, 3)})
    return sorted(out, key=lambda d: d["angle_deg"])


def vibration_report(x, fs: float, *, revs=None, quantity: str = "acceleration", zones=None,
                     band: tuple[float, float] | None = None, samples_per_rev: int = 256,
                     impact_threshold: float = 8.0) -> dict:  # fmt: skip
    """Everything above for one signal: indicators, band velocity RMS (and its zone with
    ``zones``), order spectrum (with a crank angle ``revs``), spectrogram or Campbell data
    (when the speed varies by more than 5 %), envelope spectrum, cepstrum and impacts. The
    result holds the arrays for `plot_vibration` and a
    JSON-ready ``summary``."""
    x = as_signal(x, name="x", min_samples=16)
    rep: dict = {"fs": fs, "quantity": quantity}
    summ: dict = {"indicators": indicators(x)}
    if quantity in ("acceleration", "velocity") and fs > 2 * ISO20816_8_BAND_HZ[1]:
        v = (
            velocity_rms(x, fs)
            if quantity == "acceleration"
            else band_rms(x, fs, ISO20816_8_BAND_HZ)
        )
        summ["velocity_rms_2_1000hz"] = v
        if zones is not None:
            summ["zone"] = zone(v, zones)
            summ["zone_boundaries"] = [float(b) for b in zones]
    if revs is not None:
        revs = np.asarray(revs, dtype=float)
        ok = np.isfinite(revs)
        speed = np.gradient(revs[ok], 1.0 / fs)
        summ["speed_hz"] = {"min": float(speed.min()), "max": float(speed.max()),
                            "mean": float(speed.mean())}  # fmt: skip
        spr = int(min(samples_per_rev, 2 ** int(np.log2(max(8.0, fs / speed.max())))))
        _, xa = angle_resample(x, revs, spr)
        rep["orders"] = order_spectrum_angle(xa, spr)
        summ["order_resolution"] = rep["orders"].resolution
        summ["order_lines"] = [
            {"order": round(p.frequency, 3), "amplitude": p.amplitude}
            for p in find_spectral_peaks(rep["orders"], n=8, min_rel_height=0.02,
                                         min_separation=0.1)
        ]  # fmt: skip
        summ["samples_per_rev"] = spr
        if speed.max() > 1.05 * speed.min():
            rep["campbell"] = campbell(x, fs, np.where(ok, revs, np.interp(
                np.arange(revs.size), np.flatnonzero(ok), revs[ok])))  # fmt: skip
    if "campbell" not in rep:
        rep["spectrogram"] = spectrogram(x, fs)
    lo_hi = band if band is not None else resonance_band(x, fs)
    rep["envelope"], env = envelope_spectrum(x, fs, lo_hi)
    summ["envelope_band_hz"] = list(lo_hi)
    rep["cepstrum"] = cepstrum(x, fs)
    hits = detect_impacts(x, fs, revs=revs, band=lo_hi, threshold=impact_threshold, envelope=env)
    rep["impacts"] = hits
    n_rev = None
    if revs is not None and np.isfinite(revs).any():
        n_rev = float(np.nanmax(revs) - np.nanmin(revs))
    summ["impacts"] = {
        "count": len(hits), "threshold_robust_sd": impact_threshold,
        "per_revolution": len(hits) / n_rev if n_rev else None,
        "angles_deg": [round(h.angle_deg, 2) for h in hits[:200]] if revs is not None else None,
        "times_s": [round(h.start, 6) for h in hits[:200]],
    }  # fmt: skip
    if revs is not None and n_rev:
        summ["impacts"]["pattern"] = impact_pattern(hits, n_rev)
    rep["summary"] = summ
    return rep
