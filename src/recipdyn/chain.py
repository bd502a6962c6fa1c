"""The measurement chain as part of the model: what each channel's chain is, the ranges real
installations span, draws from them, and the chains recipdyn uses by default.

A diagnoser trained through one chain has learnt that chain (issue 42: a 0.3 degree keyphasor
error or a 1 kPa transducer offset turned a healthy machine into a confident fault). So a data
set draws every record's chain -- transducer dynamics, gain, offset, delay, filters, ADC, hum,
drift, the tacho's mark, width, polarity, jitter and noise -- from `ChainRanges` (domain
randomisation, Tobin et al. 2017), and every range says where it comes from: a datasheet, a
standard, a paper, or "engineering judgement" with the reason.

`Chain` holds one chain (the three sensors of `recipdyn.sensors`), `ChainRanges.draw` gives
one, `recipdyn.sensors.record(ds, chain=...)` applies it. `SENSE_DEFAULT` is what
``recipdyn sense`` records by default; it lies inside `DEFAULT_RANGES`, as does the chain the
data sets used before the ranges existed (`legacy_chain`), which `recipdyn.sensors` still
records to the bit.

References
----------
J. Tobin et al., "Domain randomization for transferring deep neural networks from simulation
to the real world", IROS 2017.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields
from types import MappingProxyType
from typing import Any

from .errors import ParameterError
from .sensors import G0, Accelerometer, PressureTransducer, Tacho

__all__ = ["Span", "Choice", "Chain", "ChainRanges", "DEFAULT_RANGES", "SENSE_DEFAULT",
           "legacy_chain", "SOURCES"]  # fmt: skip

#: The sources the ranges cite (key -> full reference), listed in the data card.
SOURCES: dict[str, str] = {
    "serridge1987": "M. Serridge, T. R. Licht, Piezoelectric Accelerometers and Vibration "
    "Preamplifiers, Bruel & Kjaer, 1987, ch. 5 (mounting methods and their mounted "
    "resonances: ~30 kHz stud, ~7 kHz magnet on a flat surface, 1-2 kHz hand-held)",
    "endaq": "enDAQ, 'Accelerometer mounting best practices for vibration measurement' "
    "(blog.endaq.com): the mounting method sets the resonance and its amplification",
    "prognost2025": "Prognost Systems, 'Impact versus impact: comparison of different filter "
    "modes for vibration measurement' (2025): crosshead-guide acceleration of reciprocating "
    "compressors analysed over 0-7 kHz",
    "api670": "API 670, 5th ed. (2014), Machinery Protection Systems: crosshead acceleration "
    "as a shutdown parameter of reciprocating compressors; a once-per-turn keyphasor reference",
    "pcb_pressure": "PCB Piezotronics, 'Introduction to dynamic pressure sensors' (pcb.com): "
    "piezoelectric pressure sensors measure dynamic pressure, not static; a piezoresistive "
    "(DC) transducer is assumed for absolute cylinder pressure",
    "bergh1965": "H. Bergh, H. Tijdeman, 'Theoretical and experimental results for the dynamic "
    "response of pressure measuring systems', NLR-TR F.238, 1965 (the tube-cavity "
    "resonance of a transducer behind a passage: quarter wave f = c / 4L)",
    "pipitone2007": "E. Pipitone, A. Beccari, S. Beccari, 'The experimental validation of a new "
    "thermodynamic method for TDC determination', SAE technical paper (no. 2007-24-0052), "
    "2007 (a 1 degree error of the dead-centre reference gives up to 10 % error in indicated "
    "mean pressure)",
    "ni9234": "National Instruments, NI USB-9234 User Guide and Specifications: a delta-sigma "
    "acquisition module whose digital anti-alias filter is linear-phase with a passband to "
    "~0.45 fs and a group delay of many samples; IEPE inputs AC-coupled",
    "issue42": "recipdyn issue 42: offsets of +5/-3 kPa, a 1 % gain error, a 0.27 ms delay, "
    "a 2 kHz causal low-pass on the pressures, 0.1-0.25 degree tacho jitter and a mark "
    "0.3-1 degree off dead centre, each seen on real installations, each enough to mislead",
}

_JUDGEMENT = "engineering judgement"


@dataclass(frozen=True)
class Span:
    """A range a chain parameter is drawn from: uniform in ``[lo, hi]`` (log-uniform with
    ``log``); with probability ``p_none`` the block is absent (None, a point of the range);
    ``per_source``: one draw per pressure chamber (a tuple)."""

    lo: float
    hi: float
    unit: str
    meaning: str
    source: str
    log: bool = False
    p_none: float = 0.0
    per_source: bool = False

    def draw(self, rng, n_sources: int = 2):
        def one():
            if self.p_none and rng.uniform() < self.p_none:
                return None
            if self.log:
                return float(math.exp(rng.uniform(math.log(self.lo), math.log(self.hi))))
            return float(rng.uniform(self.lo, self.hi))

        return tuple(one() for _ in range(n_sources)) if self.per_source else one()

    def contains(self, value) -> bool:
        values = value if isinstance(value, tuple) else (value,)
        return all(
            (v is None and self.p_none > 0) or (v is not None and self.lo <= v <= self.hi)
            for v in values
        )

    def text(self) -> str:
        unit = "" if self.unit == "1" else self.unit
        r = f"{self.lo:g} .. {self.hi:g} {unit}".strip()
        r += " (log-uniform)" if self.log else ""
        r += f"; absent with p = {self.p_none:g}" if self.p_none else ""
        return r + ("; one draw per chamber" if self.per_source else "")


@dataclass(frozen=True)
class Choice:
    """A parameter drawn from a few values (equally likely)."""

    values: tuple
    unit: str
    meaning: str
    source: str

    def draw(self, rng, n_sources: int = 2):
        return self.values[int(rng.integers(len(self.values)))]

    def contains(self, value) -> bool:
        return value in self.values

    def text(self) -> str:
        return ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in self.values) + (
            f" {self.unit}" if self.unit else ""
        )


def _s(lo, hi, unit, meaning, source, **kw) -> Span:
    return Span(lo, hi, unit, meaning, source, **kw)


#: The ranges a data set draws its chains from: ``<channel>.<parameter>``, in draw order.
#: Parameters named ``*_fraction`` are fractions of the record's sampling rate (or of the
#: tacho pulse's height), ``full_scale_g`` in g, ``angle_deg`` in degrees; every other is
#: the `recipdyn.sensors` field of that name.
DEFAULT_RANGES: Mapping[str, Span | Choice] = MappingProxyType({
    "site.mains_hz": Choice((50.0, 60.0), "Hz", "mains frequency of the site", _JUDGEMENT
                            + ": the two grids"),
    # -- the accelerometer on the crosshead guide
    "accelerometer.resonance_hz": _s(
        2500.0, 6000.0, "Hz", "dominant resonance of the path crosshead -> guide -> sensor "
        "(mounting and guide structure)", "serridge1987, endaq, prognost2025; "
        + _JUDGEMENT + ": the structure between crosshead and sensor is not modelled, so this "
        "one resonance stands for mount and guide together, in or near the record's band "
        "(above its Nyquist frequency only the flank shows)",
        log=True),
    "accelerometer.damping": _s(0.02, 0.15, "1", "damping ratio of that resonance (Q 3 to 25)",
                                "serridge1987 (lightly damped mounted resonances); issue42 "
                                "(0.12 on a real chain)"),
    "accelerometer.gain": _s(0.95, 1.05, "1", "sensitivity error", _JUDGEMENT + ": industrial "
                             "accelerometers' sensitivity is stated to +-5 % (or +-10 %) of "
                             "nominal; a chain not calibrated end to end keeps that error"),
    "accelerometer.offset": _s(-2.0, 2.0, "m/s**2", "amplifier and ADC zero offset",
                               _JUDGEMENT + ": a few mV at 10 mV/g, 0.2 g"),
    "accelerometer.delay_s": _s(0.0, 3e-4, "s", "delay against the tacho (skew)", _JUDGEMENT
                                + "; ni9234 (delta-sigma filters delay analog inputs by "
                                "many samples, a counter-timed tacho not); issue42 (0.27 ms)"),
    "accelerometer.highpass_hz": _s(0.1, 2.0, "Hz", "AC coupling corner (sensor and input)",
                                    "ni9234 (AC-coupled IEPE inputs); " + _JUDGEMENT
                                    + ": below the crank's first order", log=True),
    "accelerometer.highpass_order": Choice((1, 2), "", "order of the AC coupling", _JUDGEMENT),
    "accelerometer.lowpass_fraction": _s(0.3, 0.45, "fs", "anti-alias corner",
                                         "ni9234 (passband to ~0.45 fs); " + _JUDGEMENT
                                         + ": analog anti-alias filters sit lower"),
    "accelerometer.lowpass_order": Choice((2, 4, 6, 8), "", "anti-alias filter order",
                                          _JUDGEMENT),
    "accelerometer.lowpass_phase": Choice(("causal", "zero"), "", "anti-alias phase: analog "
                                          "(causal) or linear-phase digital, compensated "
                                          "(zero)", "ni9234; issue42 (causal filters mislead)"),
    "accelerometer.snr_db": _s(10.0, 40.0, "dB", "signal to white noise, on the band-limited "
                               "signal's RMS", "the range the shipped diagnoser was trained on "
                               "(docs/diagnosis.md)"),
    "accelerometer.full_scale_g": _s(250.0, 1000.0, "g", "ADC range +-", _JUDGEMENT
                                     + ": 5 to 20 mV/g sensors into a +-5 V input, so that "
                                     "this model's healthy machine (peaks ~150 g) never clips "
                                     "and its worn pins (~450 g) sometimes do", log=True),
    "accelerometer.bits": Choice((16, 24), "bit", "ADC resolution", "ni9234 (24 bit); "
                                 + _JUDGEMENT),
    "accelerometer.hum_db": _s(-60.0, -20.0, "dB", "mains hum's fundamental against the "
                               "signal's RMS", _JUDGEMENT + ": ground loops on long cables; "
                               "absent on a clean installation", p_none=0.3),
    "accelerometer.hum_h2": _s(0.0, 0.2, "1", "hum's 2nd harmonic / fundamental", _JUDGEMENT),
    "accelerometer.hum_h3": _s(0.0, 0.5, "1", "hum's 3rd harmonic / fundamental", _JUDGEMENT
                               + ": odd harmonics dominate (rectifier loads)"),
    "accelerometer.drift": _s(0.0, 2.0, "m/s**2", "baseline drift before the high-pass",
                              _JUDGEMENT + ": thermal transients of the sensor"),
    "accelerometer.drift_hz": _s(0.02, 0.5, "Hz", "drift's frequency", _JUDGEMENT, log=True),
    # -- the pressure transducers (one per chamber)
    "pressure.resonance_hz": _s(800.0, 4000.0, "Hz", "indicator passage's acoustic resonance",
                                "bergh1965: c / 4L with c = 350-400 m/s and passages 25-120 mm "
                                "(" + _JUDGEMENT + "); absent for a flush-mounted transducer",
                                log=True, p_none=0.5),
    "pressure.damping": _s(0.03, 0.2, "1", "passage resonance's damping ratio", _JUDGEMENT),
    "pressure.gain": _s(0.99, 1.01, "1", "sensitivity error", "issue42 (+-1 %); "
                        + _JUDGEMENT + ": accuracy classes of piezoresistive transducers",
                        per_source=True),
    "pressure.offset": _s(-5000.0, 5000.0, "Pa", "zero offset", "issue42 (+5 / -3 kPa); "
                          + _JUDGEMENT + ": +-1 % of a 5 bar range", per_source=True),
    "pressure.delay_s": _s(0.0, 3e-4, "s", "delay against the tacho (skew)",
                           "issue42 (pressures 0.27 ms late); ni9234", per_source=True),
    "pressure.lowpass_fraction": _s(0.2, 0.45, "fs", "anti-alias / conditioning low-pass",
                                    "issue42 (a 2 kHz causal low-pass at 11 kHz, 0.18 fs); "
                                    "ni9234"),
    "pressure.lowpass_order": Choice((2, 4, 6, 8), "", "its order", _JUDGEMENT),
    "pressure.lowpass_phase": Choice(("causal", "zero"), "", "its phase", "ni9234; "
                                     "issue42 (a causal low-pass misleads, zero-phase not)"),
    "pressure.snr_db": _s(40.0, 70.0, "dB", "signal (absolute pressure RMS) to white noise",
                          _JUDGEMENT + ": 0.03-1 % of the pressure"),
    "pressure.range_margin": _s(1.1, 2.5, "1", "transducer range above the peak pressure "
                                "(rounded up to 1-2-5)", _JUDGEMENT),
    "pressure.bits": Choice((16, 24), "bit", "ADC resolution", "ni9234 (24 bit); "
                           + _JUDGEMENT),
    "pressure.hum_db": _s(-80.0, -40.0, "dB", "mains hum against the pressure's RMS",
                          _JUDGEMENT, p_none=0.3),
    "pressure.drift": _s(0.0, 1000.0, "Pa", "baseline drift (thermal)", "pcb_pressure; "
                         + _JUDGEMENT + ": thermal drift of the zero", per_source=True),
    "pressure.drift_hz": _s(0.02, 0.5, "Hz", "drift's frequency", _JUDGEMENT, log=True),
    # -- the tacho (keyphasor)
    "tacho.angle_deg": _s(-2.0, 2.0, "deg", "mark's angle from outer dead centre",
                          "issue42 (real keyphasors are set to a degree or worse); "
                          "pipitone2007 (why a degree matters)"),
    "tacho.width_deg": _s(2.0, 45.0, "deg", "pulse width", "api670; " + _JUDGEMENT
                          + ": a notch or a tape a few probe diameters wide", log=True),
    "tacho.high": _s(2.0, 15.0, "V", "pulse height", _JUDGEMENT + ": 5 V logic to a "
                     "proximity probe's notch (several volts per mm of depth)"),
    "tacho.baseline": _s(-12.0, 1.0, "V", "baseline level", _JUDGEMENT + ": 0 V logic to a "
                         "proximity probe's gap voltage (about -10 V)"),
    "tacho.polarity": Choice(("positive", "negative"), "", "pulse direction (projection or "
                             "tape; a notch under a proximity probe goes negative)", "api670"),
    "tacho.jitter_deg": _s(0.0, 0.25, "deg", "mark angle's scatter per revolution",
                           "issue42 (0.1-0.25 degree)"),
    "tacho.noise_fraction": _s(0.0, 0.02, "1", "noise standard deviation / pulse height",
                               _JUDGEMENT),
    "tacho.lowpass_fraction": _s(0.3, 0.45, "fs", "the acquisition's low-pass when the tacho "
                                 "is an analog input", _JUDGEMENT + "; absent on a counter "
                                 "input", p_none=0.5),
})  # fmt: skip


@dataclass(frozen=True)
class Chain:
    """One measurement chain: the three sensors of `recipdyn.sensors` (any may be None)."""

    accelerometer: Accelerometer | None = field(default_factory=Accelerometer)
    pressure: PressureTransducer | None = field(default_factory=PressureTransducer)
    tacho: Tacho | None = field(default_factory=Tacho)

    def to_dict(self) -> dict[str, Any]:
        """Flat and JSON-able: ``{"<channel>.<field>": value}`` (tuples as lists)."""
        out: dict[str, Any] = {}
        for f in fields(self):
            s = getattr(self, f.name)
            if s is None:
                out[f.name] = None
                continue
            for k, v in asdict(s).items():
                out[f"{f.name}.{k}"] = list(v) if isinstance(v, tuple) else v
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Chain:
        """The chain of `to_dict`."""
        kinds = {"accelerometer": Accelerometer, "pressure": PressureTransducer, "tacho": Tacho}
        parts: dict[str, Any] = {}
        for name, kind in kinds.items():
            if name in d and d[name] is None:
                parts[name] = None
                continue
            kw = {k.split(".", 1)[1]: tuple(v) if isinstance(v, list) else v
                  for k, v in d.items() if k.startswith(name + ".")}  # fmt: skip
            parts[name] = kind(**kw)
        return cls(**parts)

    def columns(self) -> dict[str, Any]:
        """`to_dict` with lists spread into ``<key>.<i>``: the feature table's columns
        (``chain.`` prefixed by the data set)."""
        out = {}
        for k, v in self.to_dict().items():
            if isinstance(v, list):
                out.update({f"{k}.{i}": x for i, x in enumerate(v)})
            else:
                out[k] = v
        return out


def _coordinates(chain: Chain, fs: float) -> dict[str, Any]:
    """The chain's value of every parameter `DEFAULT_RANGES` names (None where the chain has
    no such channel)."""
    a, p, t = chain.accelerometer, chain.pressure, chain.tacho
    out: dict[str, Any] = {}
    if a is not None:
        h = a.hum_harmonics + (0.0, 0.0)
        out |= {f"accelerometer.{k}": getattr(a, k) for k in (
            "resonance_hz", "damping", "gain", "offset", "delay_s", "highpass_hz",
            "highpass_order", "lowpass_order", "lowpass_phase", "snr_db", "bits", "hum_db",
            "drift", "drift_hz")}  # fmt: skip
        out["accelerometer.lowpass_fraction"] = (a.lowpass_hz or 0.4 * fs) / fs
        out["accelerometer.full_scale_g"] = a.full_scale / G0
        out["accelerometer.hum_h2"], out["accelerometer.hum_h3"] = h[1], h[2]
        out["site.mains_hz"] = a.mains_hz
    if p is not None:
        n = len(p.sources)

        def each(v):
            return v if isinstance(v, tuple) else (v,) * n

        out |= {f"pressure.{k}": getattr(p, k) for k in (
            "resonance_hz", "damping", "lowpass_order", "lowpass_phase", "snr_db",
            "range_margin", "bits", "hum_db", "drift_hz")}  # fmt: skip
        out |= {f"pressure.{k}": each(getattr(p, k)) for k in ("gain", "offset", "delay_s",
                                                                "drift")}  # fmt: skip
        out["pressure.lowpass_fraction"] = (p.lowpass_hz or 0.4 * fs) / fs
    if t is not None:
        out |= {f"tacho.{k}": getattr(t, k) for k in (
            "width_deg", "high", "baseline", "polarity", "jitter_deg")}  # fmt: skip
        out["tacho.angle_deg"] = math.degrees(t.angle)
        out["tacho.noise_fraction"] = t.noise_std / t.high
        out["tacho.lowpass_fraction"] = None if t.lowpass_hz is None else t.lowpass_hz / fs
    return out


@dataclass(frozen=True)
class ChainRanges:
    """The ranges chains are drawn from (default `DEFAULT_RANGES`).

    ``draw(rng, fs)`` gives one `Chain` for a record sampled at ``fs`` Hz, applied with the
    exact response (`recipdyn.sensors.RESPONSES`); ``contains(chain, fs)`` names every
    parameter of a chain outside the ranges; ``with_spans`` replaces some ranges (e.g. the
    accelerometer's SNR); ``describe()`` lists them with their sources (the data card)."""

    spans: Mapping[str, Span | Choice] = field(default_factory=lambda: DEFAULT_RANGES)

    def __post_init__(self):
        unknown = sorted(set(self.spans) ^ set(DEFAULT_RANGES))
        if unknown:
            raise ParameterError(f"chain ranges: {', '.join(unknown)} unknown or missing; "
                                 f"allowed: exactly {', '.join(DEFAULT_RANGES)}")  # fmt: skip
        for k, r in self.spans.items():
            if isinstance(r, Span) and not (r.lo <= r.hi and (not r.log or r.lo > 0)):
                raise ParameterError(f"chain ranges: {k} = {r.lo:g}..{r.hi:g}; allowed: lo <= "
                                     "hi (and lo > 0 for a log-uniform range)")  # fmt: skip

    def with_spans(self, **changes: Span | Choice) -> ChainRanges:
        """These ranges with some replaced (keys with ``__`` for ``.``)."""
        new = dict(self.spans)
        new.update({k.replace("__", "."): v for k, v in changes.items()})
        return ChainRanges(MappingProxyType(new))

    def draw(self, rng, fs: float) -> Chain:
        g = {k: r.draw(rng) for k, r in self.spans.items()}
        mains = g["site.mains_hz"]
        acc = Accelerometer(
            resonance_hz=g["accelerometer.resonance_hz"],
            damping=g["accelerometer.damping"],
            gain=g["accelerometer.gain"],
            offset=g["accelerometer.offset"],
            delay_s=g["accelerometer.delay_s"],
            highpass_hz=g["accelerometer.highpass_hz"],
            highpass_order=int(g["accelerometer.highpass_order"]),
            lowpass_hz=g["accelerometer.lowpass_fraction"] * fs,
            lowpass_order=int(g["accelerometer.lowpass_order"]),
            lowpass_phase=g["accelerometer.lowpass_phase"],
            snr_db=g["accelerometer.snr_db"],
            full_scale=g["accelerometer.full_scale_g"] * G0,
            bits=int(g["accelerometer.bits"]),
            hum_db=g["accelerometer.hum_db"],
            hum_harmonics=(1.0, g["accelerometer.hum_h2"], g["accelerometer.hum_h3"]),
            mains_hz=mains,
            drift=g["accelerometer.drift"],
            drift_hz=g["accelerometer.drift_hz"],
            response="exact",
        )
        pres = PressureTransducer(
            resonance_hz=g["pressure.resonance_hz"],
            damping=g["pressure.damping"],
            gain=g["pressure.gain"],
            offset=g["pressure.offset"],
            delay_s=g["pressure.delay_s"],
            lowpass_hz=g["pressure.lowpass_fraction"] * fs,
            lowpass_order=int(g["pressure.lowpass_order"]),
            lowpass_phase=g["pressure.lowpass_phase"],
            snr_db=g["pressure.snr_db"],
            range_margin=g["pressure.range_margin"],
            bits=int(g["pressure.bits"]),
            hum_db=g["pressure.hum_db"],
            mains_hz=mains,
            drift=g["pressure.drift"],
            drift_hz=g["pressure.drift_hz"],
            response="exact",
        )
        lp = g["tacho.lowpass_fraction"]
        tach = Tacho(
            angle=math.radians(g["tacho.angle_deg"]),
            width_deg=g["tacho.width_deg"],
            high=g["tacho.high"],
            baseline=g["tacho.baseline"],
            polarity=g["tacho.polarity"],
            jitter_deg=g["tacho.jitter_deg"],
            noise_std=g["tacho.noise_fraction"] * g["tacho.high"],
            lowpass_hz=None if lp is None else lp * fs,
        )
        return Chain(acc, pres, tach)

    def contains(self, chain: Chain, fs: float) -> list[str]:
        """The parameters of ``chain`` (recorded at ``fs`` Hz) outside these ranges, each as
        ``"name = value (range)"``; empty when the chain lies inside."""
        bad = []
        for k, v in _coordinates(chain, fs).items():
            r = self.spans[k]
            if not r.contains(v):
                bad.append(f"{k} = {v!r} ({r.text()})")
        return bad

    def describe(self) -> list[dict[str, str]]:
        """One row per parameter: name, range, unit, meaning, source."""
        return [{"parameter": k, "range": r.text(), "meaning": r.meaning, "source": r.source}
                for k, r in self.spans.items()]  # fmt: skip


#: The chain ``recipdyn sense`` records by default: the accelerometer's 4 kHz resonance
#: (damping 0.05) applied exactly (no warping near the Nyquist frequency, so no note at
#: simulate's default 10 kHz), 30 dB (the middle of the data set's 10-40 dB), the rest as
#: `recipdyn.sensors`' defaults; the pressure transducers and the tacho as always. Inside
#: `DEFAULT_RANGES` (tested).
SENSE_DEFAULT = Chain(
    Accelerometer(response="exact", snr_db=30.0),
    PressureTransducer(response="exact"),
    Tacho(),
)


def legacy_chain(resonance_hz: float = 4000.0, snr_db: float | None = 20.0) -> Chain:
    """The chain every data set used before the ranges (and ``recipdyn dataset --chain
    fixed`` still uses): the accelerometer with the condition's resonance at the data set's
    SNR, recipdyn's bilinear chain and defaults otherwise; inside `DEFAULT_RANGES` but for
    its numerical method (tested)."""
    return Chain(Accelerometer(snr_db=snr_db, resonance_hz=resonance_hz), PressureTransducer(),
                 Tacho())  # fmt: skip
