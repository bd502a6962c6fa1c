"""Sensors as a monitoring system records them: signal conditioning of a record's outputs.

A run of `recipdyn simulate` records the machine's exact outputs. A monitoring system
records what its sensors make of them: an accelerometer on the crosshead guide (or the frame)
with its mounting resonance, band-limiting filters, noise and an ADC; a dynamic pressure
transducer per chamber; a once-per-revolution tacho. [`record`][recipdyn.sensors.record]
adds these channels to a record, with their units and every setting in the attributes
(``sensor_*``), so that ``recipdyn analyze RUN.nc -c accel_guide --tacho tacho`` reads them
like any measured record.

No physics is added here: the input of each sensor is an output the record already holds
(the accelerometer reads a recorded acceleration, by default the crosshead's ``a``; the
structural path from crosshead to guide is not modelled). Everything is seeded: the same
seed gives the same channels to the bit. See docs/sensors.md for the model of each sensor,
its defaults and their sources.

The chain of each channel is a frozen dataclass whose defaults are the chain recipdyn has
always used (a resonance discretised by the bilinear transform, causal band filters, no gain
error, offset, delay, hum or drift), so records made with the defaults are those of earlier
versions to the bit. The further blocks -- a gain error, an offset, a delay (the skew between
channels), mains hum, baseline drift, zero-phase filters, a pressure passage's resonance, the
tacho's polarity, jitter, noise and filter -- and the frequency response applied exactly
(``response="exact"``) are off by default; `recipdyn.chain` draws them from stated ranges.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import asdict, dataclass
from types import SimpleNamespace

import numpy as np

from .errors import ParameterError

__all__ = ["Accelerometer", "PressureTransducer", "Tacho", "record", "adc", "snr_db",
           "resonance_filter", "flank_error", "band_filters", "analog_response",
           "apply_response", "G0", "RESPONSES", "PHASES", "POLARITIES"]  # fmt: skip

#: Standard gravity, m/s^2 (ISO 80000-3).
G0 = 9.80665
#: Default low-pass corner as a fraction of the sampling rate (an anti-alias filter at 80 % of
#: the Nyquist frequency, where data-acquisition cards put theirs).
LOWPASS_FRACTION = 0.4
#: How a channel's linear dynamics (resonance, low-pass, delay) are applied: ``bilinear``, the
#: resonance discretised by the prewarped bilinear transform and causal digital Butterworth
#: filters (recipdyn's chain until 0.x; the resonance's flank is warped near the Nyquist
#: frequency), or ``exact``, the continuous-time response evaluated at every frequency of the
#: record's discrete Fourier transform (no warping; a resonance may lie above the Nyquist
#: frequency, where only its flank reaches the record's band).
RESPONSES = ("bilinear", "exact")
#: The low-pass (anti-alias) filter's phase: ``causal`` (an analog filter: it delays and shifts
#: phase) or ``zero`` (its magnitude alone: a linear-phase digital filter whose group delay
#: the acquisition compensates). ``zero`` needs ``response = "exact"``.
PHASES = ("causal", "zero")
#: Which way a tacho pulse goes from its baseline.
POLARITIES = ("positive", "negative")


def _check(name: str, value, lo: float, hi: float, *, low_open=False, high_open=False,
           none=False, integer=False) -> None:  # fmt: skip
    """Refuse ``value`` outside ``lo..hi`` with one line naming ``name`` and the range."""
    if value is None and none:
        return
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    ok = ok and math.isfinite(float(value)) and (not integer or float(value).is_integer())
    if ok:
        v = float(value)
        ok = (v > lo if low_open else v >= lo) and (v < hi if high_open else v <= hi)
    if not ok:
        left, right = "(" if low_open else "[", ")" if high_open else "]"
        kind = "an integer in " if integer else ""
        extra = " or none" if none else ""
        raise ParameterError(f"{name} = {value!r} out of range; allowed: {kind}{left}{lo:g}, "
                             f"{hi:g}{right}{extra}")  # fmt: skip


def _one_of(name: str, value, allowed: tuple) -> None:
    if value not in allowed:
        raise ParameterError(f"{name} = {value!r}; allowed: {', '.join(map(str, allowed))}")


def _harmonics(name: str, value) -> None:
    ok = isinstance(value, tuple) and len(value) <= 10
    if ok:
        for v in value:
            _check(name, v, 0, 10)
    else:
        raise ParameterError(f"{name} = {value!r}; allowed: a tuple of up to 10 relative "
                             "amplitudes in [0, 10]")  # fmt: skip


def _chain_checks(s, prefix: str, *, per_source: int = 0) -> None:
    """The blocks every analog channel shares (gain, offset, delay, hum, drift, response)."""
    _one_of(f"{prefix}response", s.response, RESPONSES)
    _one_of(f"{prefix}lowpass_phase", s.lowpass_phase, PHASES)
    if s.lowpass_phase == "zero" and s.response != "exact":
        raise ParameterError(f"{prefix}lowpass_phase = 'zero'; allowed with "
                             f"{prefix}response = 'exact' only (the bilinear chain's filters "
                             "are causal)")  # fmt: skip
    for field_name, lo, hi, low_open in (
        ("gain", 0, 100, True),
        ("offset", -1e12, 1e12, False),
        ("delay_s", 0, 1, False),
        ("drift", 0, 1e12, False),
    ):
        v = getattr(s, field_name)
        values = v if isinstance(v, tuple) and per_source else (v,)
        if per_source and isinstance(v, tuple) and len(v) != per_source:
            raise ParameterError(f"{prefix}{field_name} = {v!r}; allowed: one value, or one per "
                                 f"source ({per_source})")  # fmt: skip
        for x in values:
            _check(f"{prefix}{field_name}", x, lo, hi, low_open=low_open)
    _check(f"{prefix}hum_db", s.hum_db, -200, 0, none=True)
    _harmonics(f"{prefix}hum_harmonics", s.hum_harmonics)
    _check(f"{prefix}mains_hz", s.mains_hz, 40, 70)
    _check(f"{prefix}drift_hz", s.drift_hz, 0, 10, low_open=True)


@dataclass(frozen=True)
class Accelerometer:
    """A piezoelectric accelerometer and its conditioning chain.

    Parameters
    ----------
    source : str
        The recorded acceleration the sensor is mounted on (units m/s**2; default ``a``, the
        crosshead's acceleration along the cylinder axis).
    name : str
        The channel's name in the record.
    location : str
        Where it is mounted (recorded as a label only: no structural path is modelled).
    resonance_hz : float or None
        Mounting resonance f_n, Hz (None: an ideal mount, flat response). Must lie below the
        record's Nyquist frequency.
    damping : float
        Damping ratio zeta of the mounting resonance (peak gain 1/(2 zeta) at f_n).
    highpass_hz, highpass_order : float or None, int
        High-pass corner (Hz; None: DC-coupled) and order of its Butterworth filter.
    lowpass_hz, lowpass_order : float or None, int
        Low-pass (anti-alias) corner (Hz; None: 0.4 times the record's sampling rate) and
        order of its Butterworth filter.
    snr_db : float or None
        Signal-to-noise ratio of the added white Gaussian noise, dB, defined on the RMS of
        the band-limited signal (None: no noise).
    full_scale : float
        ADC range +/- full_scale, m/s**2 (default 500 g: a 10 mV/g sensor into a +-5 V
        input).
    bits : int or None
        ADC resolution (None: no quantisation and no clipping).
    response : {"bilinear", "exact"}
        How the resonance, the low-pass and the delay are applied (`RESPONSES`; default the
        bilinear chain recipdyn has always used). With ``exact`` the resonance may lie above
        the Nyquist frequency.
    lowpass_phase : {"causal", "zero"}
        The low-pass's phase (`PHASES`).
    gain : float
        Sensitivity error: the indicated acceleration is ``gain`` times the true one.
    offset : float
        Zero offset of the amplifier and ADC, m/s**2 (added after the filters).
    delay_s : float
        Delay of this channel, s (the skew between channels; applied as a band-limited
        fractional delay).
    hum_db, hum_harmonics, mains_hz
        Mains hum: harmonics ``k = 1, 2, ...`` of ``mains_hz`` with amplitudes
        ``hum_harmonics[k-1]`` times ``rms * 10**(hum_db/20)`` (``rms`` that of the
        band-limited signal, as for the SNR), phases drawn from the seed (None: no hum).
    drift, drift_hz
        Baseline drift: ``drift * sin(2 pi drift_hz t + phi)`` (m/s**2, before the filters, so
        the high-pass acts on it; phase drawn from the seed).
    """

    source: str = "a"
    name: str = "accel_guide"
    location: str = "crosshead guide"
    resonance_hz: float | None = 4000.0
    damping: float = 0.05
    highpass_hz: float | None = 1.0
    highpass_order: int = 2
    lowpass_hz: float | None = None
    lowpass_order: int = 4
    snr_db: float | None = 40.0
    full_scale: float = 500 * G0
    bits: int | None = 16
    response: str = "bilinear"
    lowpass_phase: str = "causal"
    gain: float = 1.0
    offset: float = 0.0
    delay_s: float = 0.0
    hum_db: float | None = None
    hum_harmonics: tuple[float, ...] = (1.0,)
    mains_hz: float = 50.0
    drift: float = 0.0
    drift_hz: float = 0.1

    def __post_init__(self):
        _check("resonance", self.resonance_hz, 0, math.inf, low_open=True, high_open=True,
               none=True)  # fmt: skip
        _check("damping", self.damping, 0, 1, low_open=True)
        _filter_checks(self, "")
        _chain_checks(self, "")
        _check("snr", self.snr_db, -40, 200, none=True)
        _check("full_scale", self.full_scale, 0, math.inf, low_open=True, high_open=True)
        _check("bits", self.bits, 2, 32, none=True, integer=True)

    @property
    def units(self) -> str:
        return "m/s**2"


@dataclass(frozen=True)
class PressureTransducer:
    """A dynamic pressure transducer on each chamber the record has (``p_head``, ``p_crank``).

    Parameters
    ----------
    sources : tuple of str
        The recorded pressures (Pa); those absent from a record are skipped.
    highpass_hz, highpass_order, lowpass_hz, lowpass_order, snr_db, bits
        As for [`Accelerometer`][recipdyn.sensors.Accelerometer] (default: DC-coupled, a
        4th-order low-pass at 0.4 fs, 60 dB, 16 bits).
    full_scale : float or None
        ADC range 0..full_scale, Pa (absolute); None: the smallest value of the 1-2-5 series
        at least ``range_margin`` times the largest recorded pressure (a transducer chosen
        for the machine's discharge pressure).
    range_margin : float
        See ``full_scale`` (default 1.25).
    resonance_hz, damping : float or None, float
        The pressure passage's (indicator channel's) acoustic resonance between the chamber
        and the diaphragm, as a second-order system (None: a flush-mounted transducer, whose
        own resonance lies far above the band).
    response, lowpass_phase, gain, offset, delay_s, hum_db, hum_harmonics, mains_hz, drift,
    drift_hz
        As for [`Accelerometer`][recipdyn.sensors.Accelerometer] (``offset`` and ``drift`` in
        Pa); ``gain``, ``offset``, ``delay_s`` and ``drift`` may be one value per source.
    """

    sources: tuple[str, ...] = ("p_head", "p_crank")
    highpass_hz: float | None = None
    highpass_order: int = 2
    lowpass_hz: float | None = None
    lowpass_order: int = 4
    snr_db: float | None = 60.0
    full_scale: float | None = None
    bits: int | None = 16
    range_margin: float = 1.25
    resonance_hz: float | None = None
    damping: float = 0.1
    response: str = "bilinear"
    lowpass_phase: str = "causal"
    gain: float | tuple[float, ...] = 1.0
    offset: float | tuple[float, ...] = 0.0
    delay_s: float | tuple[float, ...] = 0.0
    hum_db: float | None = None
    hum_harmonics: tuple[float, ...] = (1.0,)
    mains_hz: float = 50.0
    drift: float | tuple[float, ...] = 0.0
    drift_hz: float = 0.1

    def __post_init__(self):
        _filter_checks(self, "pressure_")
        _chain_checks(self, "pressure_", per_source=len(self.sources))
        _check("pressure_range_margin", self.range_margin, 1, 100, low_open=True)
        _check("pressure_resonance", self.resonance_hz, 0, math.inf, low_open=True,
               high_open=True, none=True)  # fmt: skip
        _check("pressure_damping", self.damping, 0, 1, low_open=True)
        _check("pressure_snr", self.snr_db, -40, 200, none=True)
        _check("pressure_full_scale", self.full_scale, 0, math.inf, low_open=True,
               high_open=True, none=True)  # fmt: skip
        _check("pressure_bits", self.bits, 2, 32, none=True, integer=True)

    @property
    def units(self) -> str:
        return "Pa"

    def for_source(self, i: int) -> dict:
        """The settings of the ``i``-th source's channel (per-source values picked)."""
        d = asdict(self)
        for k in ("gain", "offset", "delay_s", "drift"):
            v = d[k]
            d[k] = v[i] if isinstance(v, tuple) else v
        return d


@dataclass(frozen=True)
class Tacho:
    """A once-per-revolution pulse (a keyphasor).

    The pulse lies ``high`` volts from the ``baseline`` (above it with ``polarity``
    ``positive``, below it with ``negative``: a notch seen by a proximity probe) while the
    crank angle, less the mark's angle ``angle`` (rad; 0: outer dead centre) and this
    revolution's jitter, lies within ``width_deg`` after a multiple of 2 pi.

    Parameters
    ----------
    angle : float
        Angle of the mark (the pulse's leading edge) from outer dead centre, rad.
    width_deg : float
        Pulse width, degrees of crank angle, in (0, 180).
    high, baseline : float
        Pulse height (V, > 0) and baseline level (V).
    polarity : {"positive", "negative"}
        Direction of the pulse from the baseline.
    jitter_deg : float
        Standard deviation of each revolution's mark angle about ``angle``, degrees (uneven
        notch edges, the shaft's radial motion at the probe, trigger timing), drawn per
        revolution from the seed.
    noise_std : float
        Standard deviation of white noise on the channel, V.
    lowpass_hz, lowpass_order : float or None, int
        A causal Butterworth low-pass on the channel (the acquisition's analog input; None: a
        digital or counter input, no filter), applied exactly.
    delay_s : float
        Delay of the channel, s.
    """

    source: str = "theta1"
    name: str = "tacho"
    angle: float = 0.0
    width_deg: float = 10.0
    high: float = 5.0
    baseline: float = 0.0
    polarity: str = "positive"
    jitter_deg: float = 0.0
    noise_std: float = 0.0
    lowpass_hz: float | None = None
    lowpass_order: int = 4
    delay_s: float = 0.0

    def __post_init__(self):
        _check("tacho_angle", self.angle, -2 * math.pi, 2 * math.pi)
        _check("tacho_width", self.width_deg, 0, 180, low_open=True, high_open=True)
        _check("tacho_high", self.high, 0, 1e3, low_open=True)
        _check("tacho_baseline", self.baseline, -1e3, 1e3)
        _one_of("tacho_polarity", self.polarity, POLARITIES)
        _check("tacho_jitter", self.jitter_deg, 0, 10)
        _check("tacho_noise", self.noise_std, 0, 1e3)
        _check("tacho_lowpass", self.lowpass_hz, 0, math.inf, low_open=True, high_open=True,
               none=True)  # fmt: skip
        _check("tacho_lowpass_order", self.lowpass_order, 1, 8, integer=True)
        _check("tacho_delay", self.delay_s, 0, 1)


def _filter_checks(s, prefix: str) -> None:
    _check(f"{prefix}highpass", s.highpass_hz, 0, math.inf, low_open=True, high_open=True,
           none=True)  # fmt: skip
    _check(f"{prefix}lowpass", s.lowpass_hz, 0, math.inf, low_open=True, high_open=True,
           none=True)  # fmt: skip
    for kind in ("highpass", "lowpass"):
        _check(f"{prefix}{kind}_order", getattr(s, f"{kind}_order"), 1, 8, integer=True)
    if s.highpass_hz is not None and s.lowpass_hz is not None and s.highpass_hz >= s.lowpass_hz:
        raise ParameterError(f"{prefix}highpass = {s.highpass_hz:g} Hz; allowed: below "
                             f"{prefix}lowpass ({s.lowpass_hz:g} Hz)")  # fmt: skip


# -- the blocks of a conditioning chain (each usable alone) -----------------------------------


def resonance_filter(fn: float, zeta: float, fs: float):
    """``(b, a)`` of the mounting resonance ``H(s) = wn^2 / (s^2 + 2 zeta wn s + wn^2)``
    discretised by the bilinear transform prewarped at ``wn``.

    Notes
    -----
    ``H`` maps the base's acceleration to the acceleration the sensor indicates (a
    base-excited single-degree-of-freedom system: the seismic mass's relative displacement
    times wn^2). The bilinear transform maps the analog frequency axis onto the digital
    one by ``w_a = c tan(w T / 2)``; with ``c = wn / tan(wn T / 2)`` (prewarping) the
    digital response at f_n equals ``H(j wn)`` exactly, ``1 / (2 zeta)`` at -90 degrees, and at
    any other frequency f it equals the closed form at the warped frequency
    ``f_w = f_n tan(pi f / fs) / tan(pi f_n / fs)``: that is the whole discretisation error,
    zero at 0 and f_n and largest near the Nyquist frequency. The transform is stable for
    any ``f_n < fs / 2`` and does not alias. A zero-order-hold (exact) discretisation would be
    exact for a staircase input, which a sampled smooth signal is not, and shifts the peak.
    """
    from scipy.signal import bilinear

    c = 2 * fs
    wn = 2 * np.pi * fn
    wp = c * math.tan(wn / c)  # the analog prototype's frequency that maps onto wn
    return bilinear([wp**2], [1.0, 2 * zeta * wp, wp**2], fs=fs)


def flank_error(fn: float, zeta: float, fs: float, points: int = 2001) -> float:
    """Largest relative error of the discrete resonance's magnitude against the closed form
    over ``0 < f <= f_n / 2`` (the band below the resonance), from the warping of
    [`resonance_filter`][recipdyn.sensors.resonance_filter]: ``|H(j f_w)| / |H(j f)| - 1``.

    About 2e-1 at f_n = 0.4 fs, 1.6e-2 at 0.1 fs, 4e-3 at 0.05 fs (damping 0.05): sample at
    ten times the resonance or more for a flank right to 2 %."""
    f = np.linspace(fn / 2 / points, fn / 2, points)
    fw = fn * np.tan(np.pi * f / fs) / math.tan(np.pi * fn / fs)

    def mag(x):
        return fn**2 / np.abs(fn**2 - x**2 + 2j * zeta * fn * x)

    return float(np.max(np.abs(mag(fw) / mag(f) - 1)))


def band_filters(highpass_hz, highpass_order, lowpass_hz, lowpass_order, fs):
    """Second-order sections of the Butterworth high-pass and low-pass (either may be None),
    designed by ``scipy.signal.butter`` (bilinear, prewarped at the corner: the digital
    response is ``1 / sqrt(1 + (tan(pi f / fs) / tan(pi f_c / fs))^(+-2n))``)."""
    from scipy.signal import butter

    sos = []
    if highpass_hz is not None:
        sos.append(butter(highpass_order, highpass_hz, "highpass", fs=fs, output="sos"))
    if lowpass_hz is not None:
        sos.append(butter(lowpass_order, lowpass_hz, "lowpass", fs=fs, output="sos"))
    return np.concatenate(sos) if sos else None


def adc(x, lo: float, hi: float, bits: int | None):
    """``(codes * LSB + lo, clipped)``: mid-tread rounding to ``2^bits`` levels spanning
    ``[lo, hi)``, LSB = (hi - lo) / 2^bits; values beyond the range clip to the end codes
    (``clipped`` counts them). Quantisation error of a busy signal: uniform in +-LSB/2,
    RMS LSB / sqrt(12)."""
    x = np.asarray(x, dtype=float)
    if bits is None:
        return x.copy(), 0
    lsb = (hi - lo) / 2.0**bits
    code = np.round((x - lo) / lsb)
    top = 2.0**bits - 1
    clipped = int(np.count_nonzero((code < 0) | (code > top)))
    return np.clip(code, 0, top) * lsb + lo, clipped


def snr_db(signal, noise) -> float:
    """``20 log10(rms(signal) / rms(noise))``, dB."""
    rms = lambda v: float(np.sqrt(np.mean(np.square(v))))  # noqa: E731
    return 20 * math.log10(rms(signal) / rms(noise))


def _rng(seed: int, channel: str):
    """A generator for one channel: the same seed and channel name give the same noise,
    whichever other channels are recorded."""
    return np.random.default_rng([int(seed), zlib.crc32(channel.encode())])


def analog_response(f, *, resonance=None, lowpass=None, lowpass_order: int = 4,
                    zero_phase: bool = False, delay_s: float = 0.0):  # fmt: skip
    """The continuous-time frequency response at the frequencies ``f`` (Hz) of the blocks
    ``response = "exact"`` applies: the second-order resonance ``resonance = (f_n, zeta)``
    (``wn^2 / (s^2 + 2 zeta wn s + wn^2)``), the analog Butterworth low-pass of order
    ``lowpass_order`` at ``lowpass`` Hz (``scipy.signal.butter(..., analog=True)``; its
    magnitude alone with ``zero_phase``) and the delay ``exp(-s delay_s)``."""
    from scipy.signal import butter, freqs

    s = 2j * np.pi * np.asarray(f, dtype=float)
    h = np.ones_like(s)
    if resonance is not None:
        wn = 2 * np.pi * resonance[0]
        h = h * wn**2 / (s**2 + 2 * resonance[1] * wn * s + wn**2)
    if lowpass is not None:
        b, a = butter(lowpass_order, 2 * np.pi * lowpass, "lowpass", analog=True)
        g = freqs(b, a, worN=s.imag)[1]
        h = h * (np.abs(g) if zero_phase else g)
    if delay_s:
        h = h * np.exp(-s * delay_s)
    return h


def _settling(resonance, lowpass, lowpass_order, delay_s) -> float:
    """The longest time constant (s) of the exact blocks, plus the delay: the padding's
    scale."""
    tau = [0.0]
    if resonance is not None:
        tau.append(1.0 / (resonance[1] * 2 * np.pi * resonance[0]))
    if lowpass is not None:  # the Butterworth's least damped pole: wc sin(pi / 2n)
        tau.append(1.0 / (2 * np.pi * lowpass * math.sin(math.pi / (2 * lowpass_order))))
    return max(tau) + delay_s


def apply_response(x, fs: float, *, resonance=None, lowpass=None, lowpass_order: int = 4,
                   zero_phase: bool = False, delay_s: float = 0.0):  # fmt: skip
    """``x`` through `analog_response`, exactly at every frequency of its discrete Fourier
    transform (the samples read as a band-limited signal).

    Notes
    -----
    The record is extended before the transform: ``P`` samples of its first value in front
    (the steady state of a constant input, as the bilinear chain's filters start), then
    ``P`` of its last value and a raised-cosine return to the first, so that the circular
    convolution wraps onto a smooth join whose response has decayed, ``P`` being twelve of
    the slowest time constant plus the delay (residual ``e^-12``, 6e-6, of the join's
    step). Frequencies at and above the Nyquist frequency do not exist in the record: a
    resonance above it shows only its flank (its ringing would need a record sampled
    faster). The Nyquist bin keeps the real part of the response (a real signal's bin).
    """
    from scipy.fft import irfft, next_fast_len, rfft, rfftfreq

    x = np.asarray(x, dtype=float)
    pad = max(64, int(math.ceil(12 * _settling(resonance, lowpass, lowpass_order, 0.0) * fs)))
    pad += int(math.ceil(delay_s * fs))
    ramp = 0.5 * (1 - np.cos(np.pi * (np.arange(pad) + 0.5) / pad))
    ext = np.concatenate([np.full(pad, x[0]), x, np.full(pad, x[-1]),
                          x[-1] + (x[0] - x[-1]) * ramp])  # fmt: skip
    n = next_fast_len(ext.size, real=True)
    ext = np.concatenate([ext, np.full(n - ext.size, x[0])])
    h = analog_response(
        rfftfreq(n, 1.0 / fs),
        resonance=resonance,
        lowpass=lowpass,
        lowpass_order=lowpass_order,
        zero_phase=zero_phase,
        delay_s=delay_s,
    )
    if n % 2 == 0:
        h[-1] = h[-1].real
    return irfft(rfft(ext) * h, n=n)[pad : pad + x.size]


def _hum(n: int, fs: float, rms: float, s, rng):
    """Mains hum of the settings ``s`` (zero-length phases when off)."""
    t = np.arange(n) / fs
    a1 = rms * 10.0 ** (s.hum_db / 20.0)
    phases = rng.uniform(0, 2 * np.pi, len(s.hum_harmonics))
    out = np.zeros(n)
    for k, (rel, ph) in enumerate(zip(s.hum_harmonics, phases, strict=True), start=1):
        if rel and k * s.mains_hz < fs / 2:
            out += a1 * rel * np.sin(2 * np.pi * k * s.mains_hz * t + ph)
    return out


def _condition(x, fs, s, lo, hi, rng, *, resonance=None, extra_rng=None):
    """The chain (gain, drift) -> resonance -> band filters (-> delay) -> noise (+ hum,
    offset) -> ADC on one channel; returns ``(output, settings)`` with the noise's standard
    deviation and the clipped count. With every further block at its neutral value and
    ``response = "bilinear"`` these are the operations of recipdyn's chain as it always
    was, in the same order (the same record to the bit)."""
    from scipy.signal import lfilter, lfilter_zi, sosfilt, sosfilt_zi

    y = np.asarray(x, dtype=float)
    if s.gain != 1.0:
        y = s.gain * y
    if s.drift:
        t = np.arange(y.size) / fs
        phi = extra_rng("drift").uniform(0, 2 * np.pi)
        y = y + s.drift * np.sin(2 * np.pi * s.drift_hz * t + phi)
    lowpass = s.lowpass_hz if s.lowpass_hz is not None else LOWPASS_FRACTION * fs
    if s.response == "exact":
        y = apply_response(y, fs, resonance=resonance, lowpass=lowpass,
                           lowpass_order=s.lowpass_order, zero_phase=s.lowpass_phase == "zero",
                           delay_s=s.delay_s)  # fmt: skip
        sos = band_filters(s.highpass_hz, s.highpass_order, None, s.lowpass_order, fs)
    else:
        if resonance is not None:  # steady state for a constant input equal to the first sample
            b, a = resonance_filter(*resonance, fs)
            y, _ = lfilter(b, a, y, zi=lfilter_zi(b, a) * y[0])
        sos = band_filters(s.highpass_hz, s.highpass_order, lowpass, s.lowpass_order, fs)
    if sos is not None:
        y, _ = sosfilt(sos, y, zi=sosfilt_zi(sos) * y[0])
    if s.response != "exact" and s.delay_s:
        y = apply_response(y, fs, delay_s=s.delay_s)
    sigma = 0.0
    rms = float(np.sqrt(np.mean(y**2)))
    if s.snr_db is not None:
        sigma = rms * 10.0 ** (-s.snr_db / 20.0)
    if s.hum_db is not None:
        y = y + _hum(y.size, fs, rms, s, extra_rng("hum"))
    if s.offset:
        y = y + s.offset
    if s.snr_db is not None:
        y = y + sigma * rng.standard_normal(y.size)
    span = (float(np.min(y)), float(np.max(y)))  # what reaches the ADC
    y, clipped = adc(y, lo, hi, s.bits)
    return y, {"lowpass_hz": lowpass, "noise_std": sigma, "clipped_samples": clipped,
               "adc_input_min": span[0], "adc_input_max": span[1]}  # fmt: skip


def _attr(v):
    """A setting as a NetCDF attribute (None -> 'none')."""
    if v is None:
        return "none"
    if isinstance(v, tuple):
        return ",".join(map(str, v))
    return v


def _pressure_range(x, margin: float = 1.25) -> float:
    top = margin * float(np.max(x))
    if not top > 0:
        raise ParameterError(
            "pressure_full_scale: the recorded pressure is never positive; "
            "allowed: give the range (e.g. --pressure-full-scale '10 bar')"
        )
    e = 10.0 ** math.floor(math.log10(top))
    return next(m * e for m in (1, 2, 5, 10) if m * e >= top)


def _sampling(ds):
    if "time" not in ds.dims or ds.sizes["time"] < 3:
        raise ParameterError("input: a record over 'time' with at least 3 samples is needed "
                             "(a run of 'recipdyn simulate')")  # fmt: skip
    t = np.asarray(ds["time"].values, dtype=float)
    dt = np.diff(t)
    if not (np.all(dt > 0) and np.ptp(dt) <= 1e-6 * np.median(dt)):
        raise ParameterError("input: time samples must be uniformly spaced and increasing")
    return 1.0 / float(np.median(dt))


def _below_nyquist(name: str, f, fs: float) -> None:
    if f is not None and not f < fs / 2:
        raise ParameterError(f"{name} = {f:g} Hz out of range for a record sampled at {fs:g} Hz; "
                             f"allowed: below the Nyquist frequency {fs / 2:g} Hz (or simulate "
                             "at a higher --fs)")  # fmt: skip


def record(ds, *, accelerometer: Accelerometer | None = Accelerometer(),
           pressure: PressureTransducer | None = None, tacho: Tacho | None = None,
           seed: int = 0, chain=None):  # fmt: skip
    """The record ``ds`` with sensor channels added, as a monitoring system records them.

    Parameters
    ----------
    ds : xarray.Dataset
        A run of `recipdyn.simulate` (uniform ``time``), or any Dataset with the sources.
    accelerometer, pressure, tacho : settings or None
        The sensors to add (None: not added). ``pressure`` adds one channel per chamber the
        record has (``<source>_sensor``); ``tacho`` needs the crank angle ``theta1``.
    seed : int
        Seed of the noise (numpy ``default_rng``; each channel draws from its own stream,
        seeded by ``seed`` and the channel's name).
    chain : recipdyn.chain.Chain, optional
        The three sensors at once (its ``accelerometer``, ``pressure`` and ``tacho``, any of
        them None); given, it replaces the three arguments.

    Returns
    -------
    xarray.Dataset
        A copy of ``ds`` with the channels (units in their attributes, every setting in the
        channel's attributes and as ``sensor_<channel>_<setting>`` in the record's) and
        ``sensor_channels``, ``sensor_seed``.

    Examples
    --------
    >>> import numpy as np, xarray as xr
    >>> t = np.arange(2000) / 10e3
    >>> ds = xr.Dataset({"a": ("time", np.sin(2 * np.pi * 50 * t), {"units": "m/s**2"})},
    ...                 coords={"time": t})
    >>> out = record(ds, accelerometer=Accelerometer(), seed=1)
    >>> out["accel_guide"].attrs["units"]
    'm/s**2'
    """
    _check("seed", seed, 0, 2**63 - 1, integer=True)
    if chain is not None:
        accelerometer, pressure, tacho = chain.accelerometer, chain.pressure, chain.tacho
    if accelerometer is None and pressure is None and tacho is None:
        raise ParameterError("sensors: none given; allowed: an accelerometer, pressure "
                             "transducers, a tacho, or several")  # fmt: skip
    fs = _sampling(ds)
    out = ds.copy()
    channels = []
    attrs: dict = {"sensor_seed": int(seed), "sensor_fs_hz": fs}

    def put(name, y, units, desc, settings):
        var = {"units": units, "long_name": desc}
        for k, v in settings.items():
            var[f"sensor_{k}"] = _attr(v)
            attrs[f"sensor_{name}_{k}"] = _attr(v)
        out[name] = ("time", y, var)
        channels.append(name)

    if accelerometer is not None:
        s = accelerometer
        src = _source(ds, s.source, ("m/s**2", "m/s^2", "m s-2"), "accelerometer source")
        if s.response != "exact":  # the exact response holds a resonance above it too
            _below_nyquist("resonance", s.resonance_hz, fs)
        _below_nyquist("highpass", s.highpass_hz, fs)
        _below_nyquist("lowpass", s.lowpass_hz, fs)
        res = None if s.resonance_hz is None else (s.resonance_hz, s.damping)
        y, extra = _condition(src, fs, s, -s.full_scale, s.full_scale, _rng(seed, s.name),
                              resonance=res, extra_rng=_streams(seed, s.name))  # fmt: skip
        settings = {k: v for k, v in asdict(s).items() if k != "name"}
        if res is not None:  # the exact response has no warping
            settings["resonance_flank_error"] = (
                flank_error(*res, fs) if s.response != "exact" else 0.0
            )
        put(
            s.name,
            y,
            s.units,
            f"accelerometer on the {s.location} (from {s.source})",
            settings | extra | {"adc_range": f"-{s.full_scale:g}..{s.full_scale:g} m/s**2"},
        )
    if pressure is not None:
        s = pressure
        if s.response != "exact":
            _below_nyquist("pressure_resonance", s.resonance_hz, fs)
        _below_nyquist("pressure_highpass", s.highpass_hz, fs)
        _below_nyquist("pressure_lowpass", s.lowpass_hz, fs)
        found = [n for n in s.sources if n in ds.data_vars]
        if not found:
            raise ParameterError(
                f"pressure: the record has none of {', '.join(s.sources)} "
                "(simulate with --set load=cycle for chamber pressures)"
            )
        res = None if s.resonance_hz is None else (s.resonance_hz, s.damping)
        for n in found:
            src = _source(ds, n, ("Pa",), "pressure source")
            one = s.for_source(s.sources.index(n))
            top = s.full_scale if s.full_scale is not None else _pressure_range(src, s.range_margin)
            name = f"{n}_sensor"
            y, extra = _condition(src, fs, SimpleNamespace(**one), 0.0, top, _rng(seed, name),
                                  resonance=res, extra_rng=_streams(seed, name))  # fmt: skip
            settings = {k: v for k, v in one.items() if k != "sources"}
            settings |= extra | {"source": n, "full_scale": top,
                                 "adc_range": f"0..{top:g} Pa"}  # fmt: skip
            put(name, y, s.units, f"dynamic pressure transducer ({n})", settings)
    if tacho is not None:
        s = tacho
        th = _source(ds, s.source, ("rad",), "tacho source")
        _below_nyquist("tacho_lowpass", s.lowpass_hz, fs)
        inside = _pulse(th, s, _streams(seed, s.name))
        level = s.baseline + (s.high if s.polarity == "positive" else -s.high)
        y = np.where(inside, level, s.baseline)
        if s.lowpass_hz is not None or s.delay_s:
            y = apply_response(y, fs, lowpass=s.lowpass_hz, lowpass_order=s.lowpass_order,
                               delay_s=s.delay_s)  # fmt: skip
        if s.noise_std:
            y = y + s.noise_std * _rng(seed, s.name).standard_normal(y.size)
        put(s.name, y, "V", "once-per-revolution tacho pulse",
            asdict(s) | {"pulses": _runs(inside)})  # fmt: skip
    attrs["sensor_channels"] = ",".join(channels)
    out.attrs.update(attrs)
    return out


def _streams(seed: int, channel: str):
    """Generators of a channel's further random blocks (hum phases, drift phase, tacho
    jitter), each its own stream, so that the noise of a chain without them is the one it
    always was."""
    return lambda what: _rng(seed, f"{channel}/{what}")


def _pulse(th, s: Tacho, streams):
    """Whether each sample lies inside a pulse: the crank angle less the mark's angle within
    ``width_deg`` after ``2 pi k`` plus revolution ``k``'s jitter."""
    width = np.deg2rad(s.width_deg)
    if not s.jitter_deg:
        return np.mod(th - s.angle, 2 * np.pi) < width
    phase = th - s.angle
    k = np.floor(phase / (2 * np.pi)).astype(np.int64)
    k0 = int(k.min())
    jit = np.deg2rad(s.jitter_deg) * streams("jitter").standard_normal(int(k.max()) - k0 + 2)
    own = phase - 2 * np.pi * k - jit[k - k0]
    nxt = phase - 2 * np.pi * (k + 1) - jit[k - k0 + 1]  # the next pulse, if it starts early
    return ((own >= 0) & (own < width)) | ((nxt >= 0) & (nxt < width))


def _runs(y) -> int:
    """Pulses in a 0/high channel: runs of high samples (one already high at the start
    counts)."""
    high = np.asarray(y) > 0
    return int(np.count_nonzero(high[1:] & ~high[:-1]) + bool(high[0]))


def _source(ds, name: str, units: tuple[str, ...], what: str):
    if name not in ds.data_vars or ds[name].dims != ("time",):
        have = [k for k, v in ds.data_vars.items() if v.dims == ("time",)
                and str(v.attrs.get("units", "")) in units]  # fmt: skip
        raise ParameterError(
            f"{what} = {name!r} is not in the record; allowed: "
            f"{', '.join(have) or '(none with units ' + units[0] + ')'}"
        )
    u = str(ds[name].attrs.get("units", ""))
    if u not in units:
        raise ParameterError(f"{what} = {name!r} has units {u!r}; allowed: a variable in "
                             f"{units[0]}")  # fmt: skip
    x = np.asarray(ds[name].values, dtype=float)
    if not np.all(np.isfinite(x)):
        raise ParameterError(f"{what} = {name!r} has non-finite values")
    return x
