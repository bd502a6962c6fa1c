"""A measurement chain for the blind set, written from physics, datasheets and practice,
independently of `recipdyn.sensors` (not read while writing this).

A record's physics arrives sampled at `FS_PHYS` (61 440 Hz, 5-6 times the acquisition rates
used here): that stands for the continuous signals at the sensors. Each channel then goes
through its transducer and conditioning at that rate (the "analogue" part, IIR filters
discretised by the bilinear transform, prewarped at the frequency that matters), is sampled
by the acquisition card (its anti-alias filter, then every k-th sample from a random phase),
and is quantised with clipping at the card's range:

* **accelerometer** (`Accelerometer`): sensitivity error; mounting resonance as the
  transmissibility of a base-excited mount, ``(2 z w s + w^2) / (s^2 + 2 z w s + w^2)``;
  IEPE coupling (first-order high-pass); structural background (band-limited noise from the
  rest of the machine) and broadband electronic noise, each at an SNR on the conditioned
  signal's RMS; mains hum (fundamental and odd harmonics); slow baseline wander;
* **pressure transducer** (`PressureTransducer`, one per chamber): the indicator passage
  (a Helmholtz / quarter-wave resonance, second-order low-pass); sensitivity error; zero
  offset; thermal drift (a ramp over the record); the conditioner's low-pass (Bessel or
  Butterworth, causal or zero-phase), noise, hum, an extra delay (channel skew);
* **tacho** (`Tacho`): a once-per-revolution mark at ``mark_deg`` from outer dead centre
  (positive: after it), a pulse ``width_deg`` wide of either polarity on a DC level, edges
  with a first-order rise time, timing jitter, noise; sampled through the card's
  anti-alias filter like the analogue channels (``through_adc``) or by a digital input
  that bypasses it (then the card's filter delay is a skew between tacho and signals);
* **acquisition** (`Acquisition`): the anti-alias filter (a delta-sigma converter's
  linear-phase FIR decimator, or an analogue Butterworth, elliptic or Bessel of a given
  order and corner), the sampling rate, the converter's resolution.

Every effect is switchable (a ``None`` or 0 turns it off); `RANGES` gives the range of each
that the blind set draws from and where it comes from; `draw_chain` draws a whole chain,
`NEUTRAL` is a chain close to what the data set's documentation (docs/sensors.md) describes,
so that one effect can be changed at a time.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace

import numpy as np
from scipy import signal

__all__ = [
    "FS_PHYS",
    "Accelerometer",
    "PressureTransducer",
    "Tacho",
    "Acquisition",
    "Chain",
    "Range",
    "RANGES",
    "NEUTRAL",
    "draw_chain",
    "apply_chain",
]

#: Rate of the physics records, Hz: 6 x 10 240 and 5 x 12 288, two acquisition rates of
#: delta-sigma cards (a 13.1072 MHz timebase / 256 / 5; 49.152 kHz / 4).
FS_PHYS = 61_440.0

G = 9.80665


@dataclass(frozen=True)
class Accelerometer:
    gain_error: float = 0.0  # relative sensitivity error
    resonance_hz: float | None = 3750.0  # mounted resonance (None: a rigid mount)
    damping: float = 0.05
    mount: str = "seismic"  # "seismic": w^2/(s^2 + 2 z w s + w^2); or "transmissibility"
    highpass_hz: float | None = 1.0  # IEPE coupling (sensor + card)
    highpass_order: int = 2
    background_snr_db: float | None = None  # band-limited structural background
    background_band: tuple[float, float] = (100.0, 2500.0)
    noise_snr_db: float | None = None  # broadband analogue noise (before the anti-alias)
    adc_noise_snr_db: float | None = 25.0  # the converter's noise (white to Nyquist)
    hum_amplitude: float = 0.0  # m/s**2 at the mains frequency
    hum_hz: float = 50.0
    hum_harmonics: tuple[float, ...] = (1.0, 0.3)  # amplitudes of 1x, 3x, 5x, ... mains
    wander_amplitude: float = 0.0  # m/s**2, RMS of a slow baseline wander
    wander_hz: float = 0.3
    full_scale: float = 500 * G  # +- m/s**2 at the converter


@dataclass(frozen=True)
class PressureTransducer:
    passage_hz: float | None = None  # indicator passage resonance (None: flush mounted)
    passage_damping: float = 0.1
    gain_error: float = 0.0
    offset_pa: float = 0.0
    drift_pa: float = 0.0  # change of the zero over the record (thermal), Pa
    lowpass_hz: float | None = None  # conditioner's low-pass
    lowpass_order: int = 4
    lowpass_kind: str = "butterworth"  # or "bessel"
    zero_phase: bool = False  # filtered forward and backward (offline), no delay
    noise_pa: float = 150.0  # RMS, broadband
    hum_pa: float = 0.0
    delay_s: float = 0.0  # extra delay of this channel (skew), s
    full_scale_pa: float = 5e5  # 0..FS absolute


@dataclass(frozen=True)
class Tacho:
    mark_deg: float = 0.0  # where the leading edge fires, degrees after outer dead centre
    width_deg: float = 10.0
    polarity: int = 1  # +1: pulse above the baseline, -1: below (a notch under a proximity probe)
    baseline_v: float = 0.0
    amplitude_v: float = 5.0
    rise_s: float = 0.0  # first-order time constant of the edges
    jitter_deg: float = 0.0  # RMS timing jitter of each pulse, crank degrees
    noise_v: float = 0.0
    through_adc: bool = True  # sampled through the card's anti-alias filter
    full_scale_v: float = 10.0


@dataclass(frozen=True)
class Acquisition:
    fs: float = FS_PHYS / 6  # 10 240 Hz
    antialias: str = "butterworth"  # "delta-sigma", "butterworth", "elliptic", "bessel", "none"
    order: int = 4
    corner: float = 0.4  # of fs (IIR); the delta-sigma FIR passes 0.45 fs, stops 0.55 fs
    bits: int | None = 16


@dataclass(frozen=True)
class Chain:
    accel: Accelerometer = field(default_factory=Accelerometer)
    p_head: PressureTransducer = field(default_factory=PressureTransducer)
    p_crank: PressureTransducer = field(default_factory=PressureTransducer)
    tacho: Tacho = field(default_factory=Tacho)
    acq: Acquisition = field(default_factory=Acquisition)

    def describe(self) -> dict:
        return asdict(self)


#: Close to the data set's chain as docs/sensors.md describes it (a 4th-order Butterworth at
#: 0.4 fs, a lightly damped mount in 3-4.5 kHz, white noise, 16 bits, a 5 V tacho pulse 10 deg
#: wide at outer dead centre, pressures with ~60 dB of noise): the base that one effect at a
#: time is changed from, and a control (records through it should be answered as through
#: recipdyn's own chain).
NEUTRAL = Chain()


@dataclass(frozen=True)
class Range:
    lo: float
    hi: float
    unit: str
    source: str
    choices: tuple = ()

    def draw(self, rng):
        if self.choices:
            return self.choices[int(rng.integers(len(self.choices)))]
        return float(rng.uniform(self.lo, self.hi))


#: What the blind set draws, with where each range comes from. "Assumed" marks a range chosen
#: from practice without a single citable number.
RANGES: dict[str, Range] = {
    "accel.gain_error": Range(-0.05, 0.05, "1",
        "sensitivity tolerance of industrial IEPE accelerometers, +-5 % (+-10 % uncalibrated "
        "on datasheets; a calibrated sensor +-2 %)"),
    "accel.resonance_hz": Range(2500.0, 7000.0, "Hz",
        "magnet mounts: ~7 kHz on a flat clean surface down to 2-3 kHz on a curved or painted "
        "one (Serridge & Licht 1987, ch. 5)"),
    "accel.damping": Range(0.03, 0.15, "1",
        "assumed: Q of 3 to 17 for a magnet or adhesive mount (a stud mount is lighter "
        "damped but resonates far above these bands)"),
    "accel.mount": Range(0, 0, "",
        "the mounted sensor's own resonance (w^2/(s^2 + 2 z w s + w^2), the handbook "
        "form) or a rigid sensor riding on a compliant mount (its base-excitation "
        "transmissibility)", choices=("seismic", "transmissibility")),
    "accel.highpass_hz": Range(0.1, 1.0, "Hz",
        "IEPE sensors' discharge time constants 0.5-2 s and cards' AC coupling (~0.5 Hz on "
        "delta-sigma sound-and-vibration cards)"),
    "accel.background_snr_db": Range(15.0, 40.0, "dB",
        "assumed: other sources of the machine (other throws, piping, the driver) in "
        "100-2500 Hz"),
    "accel.noise_snr_db": Range(25.0, 50.0, "dB", "assumed: sensor and amplifier noise"),
    "accel.adc_noise_snr_db": Range(40.0, 70.0, "dB", "assumed: the converter's own noise"),
    "accel.hum_amplitude": Range(0.0, 0.5, "m/s**2",
        "assumed: a ground loop of up to ~5 mV at 10 mV/g"),
    "accel.hum_hz": Range(0, 0, "Hz", "mains frequency", choices=(50.0, 60.0)),
    "accel.wander_amplitude": Range(0.0, 0.5, "m/s**2", "assumed: thermal / settling wander"),
    "accel.full_scale": Range(0, 0, "m/s**2",
        "a 10 mV/g or 20 mV/g sensor into a +-5 V input", choices=(500 * G, 250 * G)),
    "p.passage_hz": Range(500.0, 2500.0, "Hz",
        "quarter-wave frequency c/4L of an indicator passage of ~35-200 mm (c ~ 350 m/s); "
        "flush-mounted transducers have none (drawn in half the installations)"),
    "p.passage_damping": Range(0.05, 0.3, "1", "assumed"),
    "p.gain_error": Range(-0.02, 0.02, "1",
        "assumed: calibration and thermal sensitivity shift of piezoresistive transducers"),
    "p.offset_pa": Range(-5000.0, 5000.0, "Pa",
        "zero offset and thermal zero shift of ~0.5 % of a 10 bar range (piezoresistive), or "
        "the referencing (pegging) error of a piezoelectric transducer"),
    "p.drift_pa": Range(-1000.0, 1000.0, "Pa", "assumed: thermal zero drift over the record"),
    "p.lowpass_hz": Range(1500.0, 5000.0, "Hz",
        "assumed: the conditioner's low-pass of portable analysers' pressure channels"),
    "p.lowpass_order": Range(0, 0, "1", "2nd to 6th order", choices=(2, 4, 6)),
    "p.lowpass_kind": Range(0, 0, "", "", choices=("butterworth", "bessel")),
    "p.noise_pa": Range(50.0, 300.0, "Pa", "assumed: 50-300 Pa RMS (~60 dB on 3 bar)"),
    "p.hum_pa": Range(0.0, 100.0, "Pa", "assumed"),
    "p.delay_s": Range(0.0, 1.0e-4, "s",
        "assumed: skew between channels of a multiplexed card (up to one sample at 10 kHz)"),
    "p.full_scale_pa": Range(0, 0, "Pa", "0-5, 0-10 bar transducers", choices=(5e5, 10e5)),
    "tacho.mark_deg": Range(-1.0, 1.0, "deg",
        "assumed: a once-per-revolution mark set to outer dead centre by eye or dial gauge, "
        "to within a degree"),
    "tacho.width_deg": Range(2.0, 30.0, "deg",
        "reflective tape (a few degrees) to a keyway or notch under a proximity probe"),
    "tacho.polarity": Range(0, 0, "1",
        "a notch under a proximity probe gives a pulse of negative sense", choices=(1, -1)),
    "tacho.baseline_v": Range(-10.0, 0.0, "V",
        "0 V for an optical or TTL pickup, ~-10 V gap voltage of a proximity probe"),
    "tacho.amplitude_v": Range(2.0, 10.0, "V", "assumed"),
    "tacho.rise_s": Range(5e-6, 1e-4, "s", "assumed: pickup and driver bandwidth 2-30 kHz"),
    "tacho.jitter_deg": Range(0.0, 0.5, "deg",
        "assumed: edge timing noise and torsional motion of the shaft"),
    "tacho.noise_v": Range(0.0, 0.05, "V", "assumed"),
    "acq.fs": Range(0, 0, "Hz", "delta-sigma card rates inside the training range",
                    choices=(FS_PHYS / 6, FS_PHYS / 5)),
    "acq.antialias": Range(0, 0, "",
        "delta-sigma cards (linear-phase FIR, pass 0.45 fs, stop 0.55 fs) or analogue "
        "filters before a successive-approximation converter",
        choices=("delta-sigma", "butterworth", "elliptic", "bessel")),
    "acq.order": Range(0, 0, "1", "analogue anti-alias orders", choices=(4, 6, 8)),
    "acq.corner": Range(0.3, 0.45, "fs", "assumed: the analogue corner's share of fs"),
    "acq.bits": Range(0, 0, "bit", "", choices=(16, 24)),
}  # fmt: skip


def _d(rng, key):
    return RANGES[key].draw(rng)


def draw_chain(rng, *, channels_differ: bool = True) -> Chain:
    """A whole chain drawn from `RANGES` (every effect on). The two pressure transducers are
    two instruments (their own errors) when ``channels_differ``."""
    acc = Accelerometer(
        gain_error=_d(rng, "accel.gain_error"),
        resonance_hz=_d(rng, "accel.resonance_hz"),
        damping=_d(rng, "accel.damping"),
        mount=_d(rng, "accel.mount"),
        highpass_hz=_d(rng, "accel.highpass_hz"),
        highpass_order=1,
        background_snr_db=_d(rng, "accel.background_snr_db"),
        noise_snr_db=_d(rng, "accel.noise_snr_db"),
        adc_noise_snr_db=_d(rng, "accel.adc_noise_snr_db"),
        hum_amplitude=_d(rng, "accel.hum_amplitude"),
        hum_hz=_d(rng, "accel.hum_hz"),
        hum_harmonics=(1.0, float(rng.uniform(0.1, 0.5)), float(rng.uniform(0.0, 0.2))),
        wander_amplitude=_d(rng, "accel.wander_amplitude"),
        full_scale=_d(rng, "accel.full_scale"),
    )
    passage = bool(rng.random() < 0.5)
    fs_p = _d(rng, "p.full_scale_pa")
    lp = (_d(rng, "p.lowpass_hz"), _d(rng, "p.lowpass_order"), _d(rng, "p.lowpass_kind"))

    def pt():
        return PressureTransducer(
            passage_hz=_d(rng, "p.passage_hz") if passage else None,
            passage_damping=_d(rng, "p.passage_damping"),
            gain_error=_d(rng, "p.gain_error"),
            offset_pa=_d(rng, "p.offset_pa"),
            drift_pa=_d(rng, "p.drift_pa"),
            lowpass_hz=lp[0],
            lowpass_order=lp[1],
            lowpass_kind=lp[2],
            noise_pa=_d(rng, "p.noise_pa"),
            hum_pa=_d(rng, "p.hum_pa"),
            delay_s=_d(rng, "p.delay_s"),
            full_scale_pa=fs_p,
        )

    ph = pt()
    pc = pt() if channels_differ else ph
    tach = Tacho(
        mark_deg=_d(rng, "tacho.mark_deg"),
        width_deg=_d(rng, "tacho.width_deg"),
        polarity=_d(rng, "tacho.polarity"),
        baseline_v=_d(rng, "tacho.baseline_v"),
        amplitude_v=_d(rng, "tacho.amplitude_v"),
        rise_s=_d(rng, "tacho.rise_s"),
        jitter_deg=_d(rng, "tacho.jitter_deg"),
        noise_v=_d(rng, "tacho.noise_v"),
        through_adc=True,
        full_scale_v=20.0,
    )
    acq = Acquisition(
        fs=_d(rng, "acq.fs"),
        antialias=_d(rng, "acq.antialias"),
        order=_d(rng, "acq.order"),
        corner=_d(rng, "acq.corner"),
        bits=_d(rng, "acq.bits"),
    )
    return Chain(accel=acc, p_head=ph, p_crank=pc, tacho=tach, acq=acq)


# ---------------------------------------------------------------------------------- blocks


def _bilinear_sos(b, a, fs, f_warp):
    """Analogue (b, a) in s to digital second-order sections, by the bilinear transform
    prewarped so that the response at ``f_warp`` Hz is exact."""
    w = 2 * math.pi * f_warp
    k = w / math.tan(w / (2 * fs))  # the prewarped 2 fs
    bz, az = signal.bilinear(b, a, fs=k / 2)
    return signal.tf2sos(bz, az)


def mounting_sos(f_n: float, zeta: float, fs: float):
    """Transmissibility of a base-excited mount: the sensor's acceleration over the
    surface's, ``(2 z w s + w^2) / (s^2 + 2 z w s + w^2)`` (peak ~ 1/(2 z) at w)."""
    w = 2 * math.pi * f_n
    return _bilinear_sos([2 * zeta * w, w * w], [1.0, 2 * zeta * w, w * w], fs, f_n)


def seismic_sos(f_n: float, zeta: float, fs: float):
    """The mounted sensor's own resonance, ``w^2 / (s^2 + 2 z w s + w^2)`` (peak 1/(2 z))."""
    w = 2 * math.pi * f_n
    return _bilinear_sos([w * w], [1.0, 2 * zeta * w, w * w], fs, f_n)


def passage_sos(f_p: float, zeta: float, fs: float):
    """Helmholtz resonance of an indicator passage: ``w^2 / (s^2 + 2 z w s + w^2)``."""
    w = 2 * math.pi * f_p
    return _bilinear_sos([w * w], [1.0, 2 * zeta * w, w * w], fs, f_p)


def _filt(sos, x):
    """Causal filtering, started in the steady state of a constant input equal to x[0]."""
    zi = signal.sosfilt_zi(sos) * x[0]
    return signal.sosfilt(sos, x, zi=zi)[0]


def _lowpass_sos(kind: str, order: int, f_c: float, fs: float):
    if kind == "bessel":
        return signal.bessel(order, f_c, fs=fs, output="sos", norm="mag")
    if kind == "elliptic":
        return signal.ellip(order, 0.1, 80.0, f_c, fs=fs, output="sos")
    return signal.butter(order, f_c, fs=fs, output="sos")


def _fir_decimator(fs_out: float, fs_in: float) -> np.ndarray:
    """Linear-phase FIR of a delta-sigma card's decimator: flat to 0.45 fs_out, >= 90 dB
    down from 0.55 fs_out (Parks-McClellan)."""
    trans = 0.1 * fs_out / fs_in  # transition width over fs_in
    n = int(math.ceil(90.0 / (22.0 * trans))) | 1  # Bellanger's estimate, odd length
    return signal.remez(n, [0, 0.45 * fs_out, 0.55 * fs_out, fs_in / 2], [1, 0], weight=[1, 30],
                        fs=fs_in)  # fmt: skip


def _antialias(x, acq: Acquisition, fs_in: float):
    if acq.antialias == "none":
        return x
    if acq.antialias == "delta-sigma":
        h = _fir_decimator(acq.fs, fs_in)
        return signal.lfilter(h, 1.0, np.concatenate([np.full(h.size, x[0]), x]))[h.size :]
    sos = _lowpass_sos(acq.antialias, acq.order, acq.corner * acq.fs, fs_in)
    return _filt(sos, x)


def _quantise(x, lo, hi, bits):
    """Mid-tread rounding to 2**bits levels over [lo, hi), clipped to the end codes."""
    if bits is None:
        return np.clip(x, lo, hi)
    lsb = (hi - lo) / 2**bits
    q = lo + np.round((x - lo) / lsb) * lsb
    return np.clip(q, lo, hi - lsb)


def _delay(x, seconds, fs):
    """Delay by a whole number of samples at the physics rate (1/61 440 s resolution)."""
    n = int(round(seconds * fs))
    if n <= 0:
        return x
    return np.concatenate([np.full(n, x[0]), x[:-n]])


def _band_noise(rng, n, band, fs):
    sos = signal.butter(4, band, btype="bandpass", fs=fs, output="sos")
    w = rng.standard_normal(n + 4096)
    return signal.sosfilt(sos, w)[4096:]


def _rms(x):
    return float(np.sqrt(np.mean((x - np.mean(x)) ** 2)))


def _hum(t, amplitude, f, harmonics, rng):
    out = np.zeros_like(t)
    for k, h in enumerate(harmonics):
        if h:
            phase = rng.uniform(0, 2 * math.pi)
            out += amplitude * h * np.sin(2 * math.pi * (2 * k + 1) * f * t + phase)
    return out


def _wander(rng, n, fs, f_c, rms):
    if rms <= 0:
        return np.zeros(n)
    sos = signal.butter(2, f_c, fs=fs, output="sos")
    w = signal.sosfilt(sos, rng.standard_normal(n + int(4 * fs / f_c)))[-n:]
    return w / _rms(w) * rms


def accelerometer_analogue(a, t, c: Accelerometer, fs, rng):
    x = a * (1.0 + c.gain_error)
    if c.resonance_hz is not None and c.resonance_hz < 0.45 * fs:
        make = mounting_sos if c.mount == "transmissibility" else seismic_sos
        x = _filt(make(c.resonance_hz, c.damping, fs), x)
    if c.highpass_hz:
        sos = signal.butter(c.highpass_order, c.highpass_hz, "highpass", fs=fs, output="sos")
        x = signal.sosfilt(sos, x - np.mean(x))  # in its steady state: a periodic signal
    s = _rms(x)
    if c.background_snr_db is not None:
        b = _band_noise(rng, x.size, c.background_band, fs)
        x = x + b / _rms(b) * s * 10 ** (-c.background_snr_db / 20)
    if c.noise_snr_db is not None:
        x = x + rng.standard_normal(x.size) * s * 10 ** (-c.noise_snr_db / 20)
    if c.hum_amplitude:
        x = x + _hum(t, c.hum_amplitude, c.hum_hz, c.hum_harmonics, rng)
    if c.wander_amplitude:
        x = x + _wander(rng, x.size, fs, c.wander_hz, c.wander_amplitude)
    return x


def pressure_analogue(p, t, c: PressureTransducer, fs, rng, hum_hz=50.0):
    x = np.asarray(p, float)
    if c.passage_hz is not None:
        x = _filt(passage_sos(c.passage_hz, c.passage_damping, fs), x)
    x = x * (1.0 + c.gain_error) + c.offset_pa
    if c.drift_pa:
        x = x + c.drift_pa * (t - t[0]) / (t[-1] - t[0])
    if c.noise_pa:
        x = x + rng.standard_normal(x.size) * c.noise_pa
    if c.hum_pa:
        x = x + _hum(t, c.hum_pa, hum_hz, (1.0, 0.3), rng)
    if c.lowpass_hz is not None:
        sos = _lowpass_sos(c.lowpass_kind, c.lowpass_order, c.lowpass_hz, fs)
        x = signal.sosfiltfilt(sos, x) if c.zero_phase else _filt(sos, x)
    return _delay(x, c.delay_s, fs)


def _time_at(th, theta, t, omega):
    """When the crank angle passes ``th`` (extrapolated at ``omega`` before the record)."""
    return float(np.interp(th, theta, t, left=t[0] - (theta[0] - th) / omega))


def tacho_analogue(theta, t, c: Tacho, fs, rng):
    """The pickup's voltage: a pulse from each crossing of ``theta = mark + 2 pi k`` (its
    time interpolated, then jittered) for ``width_deg`` of crank angle."""
    mark = math.radians(c.mark_deg)
    k0 = math.ceil((theta[0] - mark) / (2 * math.pi))
    k1 = math.floor((theta[-1] - mark) / (2 * math.pi))
    level = np.zeros_like(t)
    # a pulse already under way at the start
    crossings = [mark + 2 * math.pi * k for k in range(k0 - 1, k1 + 1)]
    omega = (theta[-1] - theta[0]) / (t[-1] - t[0])
    for th_k in crossings:
        t_on = _time_at(th_k, theta, t, omega)
        t_off = _time_at(th_k + math.radians(c.width_deg), theta, t, omega)
        if c.jitter_deg:
            dt = rng.normal(0.0, math.radians(c.jitter_deg) / omega)
            t_on, t_off = t_on + dt, t_off + dt
        level[(t >= t_on) & (t < t_off)] = 1.0
    if c.rise_s:
        a = math.exp(-1.0 / (fs * c.rise_s))
        zi = signal.lfilter_zi([1 - a], [1, -a]) * level[0]
        level = signal.lfilter([1 - a], [1, -a], level, zi=zi)[0]
    v = c.baseline_v + c.polarity * c.amplitude_v * level
    if c.noise_v:
        v = v + rng.standard_normal(v.size) * c.noise_v
    return v


def apply_chain(phys: dict, chain: Chain, seed: int) -> dict:
    """The channels a card records of ``phys`` (``t``, ``theta1``, ``a``, optionally
    ``p_head``, ``p_crank``, all at ``phys['fs']``) through ``chain``.

    Returns ``fs`` (Hz), ``accel`` (m/s**2), ``tacho`` (V), ``p_head``, ``p_crank`` (Pa, when
    the physics has them) and ``speed_hz`` (the mean crank speed, rev/s, for records given a
    speed instead of a tacho).
    """
    fs = float(phys["fs"])
    acq = chain.acq
    k = int(round(fs / acq.fs))
    if abs(fs / k - acq.fs) > 1e-6 * acq.fs:
        raise ValueError(f"acquisition rate {acq.fs} Hz is not the physics rate {fs} Hz / k")
    rng = np.random.default_rng(seed)
    t = np.asarray(phys["t"], float)
    start = int(rng.integers(k))  # the card's clock is not aligned with the physics' samples
    chans = {}
    a = accelerometer_analogue(np.asarray(phys["a"], float), t, chain.accel, fs, rng)
    fa = chain.accel.full_scale
    a = _antialias(a, acq, fs)[start::k]
    if chain.accel.adc_noise_snr_db is not None:
        a = a + rng.standard_normal(a.size) * _rms(a) * 10 ** (-chain.accel.adc_noise_snr_db / 20)
    chans["accel"] = _quantise(a, -fa, fa, acq.bits)
    for name, c in (("p_head", chain.p_head), ("p_crank", chain.p_crank)):
        if name in phys and phys[name] is not None:
            p = pressure_analogue(phys[name], t, c, fs, rng, chain.accel.hum_hz)
            chans[name] = _quantise(_antialias(p, acq, fs)[start::k], 0.0, c.full_scale_pa,
                                    acq.bits)  # fmt: skip
    v = tacho_analogue(np.asarray(phys["theta1"], float), t, chain.tacho, fs, rng)
    if chain.tacho.through_adc:
        v = _antialias(v, acq, fs)
    fv = chain.tacho.full_scale_v
    chans["tacho"] = _quantise(v[start::k], -fv, fv, acq.bits)
    th = np.asarray(phys["theta1"], float)
    chans["speed_hz"] = float((th[-1] - th[0]) / (t[-1] - t[0]) / (2 * math.pi))
    chans["fs"] = fs / k
    return chans


def with_(chain: Chain, **changes) -> Chain:
    """``chain`` with some blocks' fields changed: ``with_(c, accel={"damping": 0.1})``."""
    new = {blk: replace(getattr(chain, blk), **kw) for blk, kw in changes.items()}
    return replace(chain, **new)
