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
"""

from __future__ import annotations

import math
import zlib
from dataclasses import asdict, dataclass

import numpy as np

from .errors import ParameterError

__all__ = ["Accelerometer", "PressureTransducer", "Tacho", "record", "adc", "snr_db",
           "resonance_filter", "flank_error", "band_filters", "G0"]  # fmt: skip

#: Standard gravity, m/s^2 (ISO 80000-3).
G0 = 9.80665
#: Default low-pass corner as a fraction of the sampling rate (an anti-alias filter at 80 % of
#: the Nyquist frequency, where data-acquisition cards put theirs).
LOWPASS_FRACTION = 0.4


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

    def __post_init__(self):
        _check("resonance", self.resonance_hz, 0, math.inf, low_open=True, high_open=True,
               none=True)  # fmt: skip
        _check("damping", self.damping, 0, 1, low_open=True)
        _filter_checks(self, "")
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
        at least 1.25 times the largest recorded pressure (a transducer chosen for the
        machine's discharge pressure).
    """

    sources: tuple[str, ...] = ("p_head", "p_crank")
    highpass_hz: float | None = None
    highpass_order: int = 2
    lowpass_hz: float | None = None
    lowpass_order: int = 4
    snr_db: float | None = 60.0
    full_scale: float | None = None
    bits: int | None = 16

    def __post_init__(self):
        _filter_checks(self, "pressure_")
        _check("pressure_snr", self.snr_db, -40, 200, none=True)
        _check("pressure_full_scale", self.full_scale, 0, math.inf, low_open=True,
               high_open=True, none=True)  # fmt: skip
        _check("pressure_bits", self.bits, 2, 32, none=True, integer=True)

    @property
    def units(self) -> str:
        return "Pa"


@dataclass(frozen=True)
class Tacho:
    """A once-per-revolution pulse (a keyphasor): ``high`` volts while the crank angle, less
    ``angle``, lies within ``width_deg`` after a multiple of 2 pi; 0 V otherwise."""

    source: str = "theta1"
    name: str = "tacho"
    angle: float = 0.0
    width_deg: float = 10.0
    high: float = 5.0

    def __post_init__(self):
        _check("tacho_angle", self.angle, -2 * math.pi, 2 * math.pi)
        _check("tacho_width", self.width_deg, 0, 180, low_open=True, high_open=True)
        _check("tacho_high", self.high, 0, 1e3, low_open=True)


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


def _condition(x, fs, s, lo, hi, rng, *, resonance=None):
    """The chain resonance -> band filters -> noise -> ADC on one channel; returns
    ``(output, settings)`` with the noise's standard deviation and the clipped count."""
    from scipy.signal import lfilter, lfilter_zi, sosfilt, sosfilt_zi

    y = np.asarray(x, dtype=float)
    if resonance is not None:  # steady state for a constant input equal to the first sample
        b, a = resonance_filter(*resonance, fs)
        y, _ = lfilter(b, a, y, zi=lfilter_zi(b, a) * y[0])
    lowpass = s.lowpass_hz if s.lowpass_hz is not None else LOWPASS_FRACTION * fs
    sos = band_filters(s.highpass_hz, s.highpass_order, lowpass, s.lowpass_order, fs)
    if sos is not None:
        y, _ = sosfilt(sos, y, zi=sosfilt_zi(sos) * y[0])
    sigma = 0.0
    if s.snr_db is not None:
        sigma = float(np.sqrt(np.mean(y**2))) * 10.0 ** (-s.snr_db / 20.0)
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


def _pressure_range(x) -> float:
    top = 1.25 * float(np.max(x))
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
           seed: int = 0):  # fmt: skip
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
        _below_nyquist("resonance", s.resonance_hz, fs)
        _below_nyquist("highpass", s.highpass_hz, fs)
        _below_nyquist("lowpass", s.lowpass_hz, fs)
        res = None if s.resonance_hz is None else (s.resonance_hz, s.damping)
        y, extra = _condition(src, fs, s, -s.full_scale, s.full_scale, _rng(seed, s.name),
                              resonance=res)  # fmt: skip
        settings = {k: v for k, v in asdict(s).items() if k != "name"}
        if res is not None:
            settings["resonance_flank_error"] = flank_error(*res, fs)
        put(
            s.name,
            y,
            s.units,
            f"accelerometer on the {s.location} (from {s.source})",
            settings | extra | {"adc_range": f"-{s.full_scale:g}..{s.full_scale:g} m/s**2"},
        )
    if pressure is not None:
        s = pressure
        _below_nyquist("pressure_highpass", s.highpass_hz, fs)
        _below_nyquist("pressure_lowpass", s.lowpass_hz, fs)
        found = [n for n in s.sources if n in ds.data_vars]
        if not found:
            raise ParameterError(
                f"pressure: the record has none of {', '.join(s.sources)} "
                "(simulate with --set load=cycle for chamber pressures)"
            )
        for n in found:
            src = _source(ds, n, ("Pa",), "pressure source")
            top = s.full_scale if s.full_scale is not None else _pressure_range(src)
            name = f"{n}_sensor"
            y, extra = _condition(src, fs, s, 0.0, top, _rng(seed, name))
            settings = {k: v for k, v in asdict(s).items() if k != "sources"}
            settings |= extra | {"source": n, "full_scale": top,
                                 "adc_range": f"0..{top:g} Pa"}  # fmt: skip
            put(name, y, s.units, f"dynamic pressure transducer ({n})", settings)
    if tacho is not None:
        s = tacho
        th = _source(ds, s.source, ("rad",), "tacho source")
        phase = np.mod(th - s.angle, 2 * np.pi)
        y = np.where(phase < np.deg2rad(s.width_deg), s.high, 0.0)
        put(s.name, y, "V", "once-per-revolution tacho pulse", asdict(s) | {"pulses": _runs(y)})
    attrs["sensor_channels"] = ",".join(channels)
    out.attrs.update(attrs)
    return out


def _runs(y) -> int:
    """Pulses in a 0/high channel: runs of high samples (one already high at the start
    counts)."""
    high = y > 0
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
