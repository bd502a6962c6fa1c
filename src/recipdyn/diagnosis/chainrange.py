"""The record's measurement chain against the chain ranges its diagnoser was trained under.

A diagnoser of a data set of drawn chains (`recipdyn.chain.DEFAULT_RANGES`, or the ranges
its ``recipdyn dataset`` was given) has learnt records sensed through any chain inside those
ranges, and only those. So before an answer, the chain parameters that can be read from the
record itself are estimated -- the accelerometer's mounting resonance
(`recipdyn.diagnosis.correction.resonance`), its signal-to-noise ratio (from the noise floor,
`snr_estimate`), each pressure transducer's offset (`recipdyn.diagnosis.correction.
correct_chain`) -- each with its 95 % interval, and compared with the *declared* ranges the
diagnoser's data card lists (`declared_ranges`). A parameter whose whole interval lies
outside its declared range is refused, naming the channel, the parameter, the estimate and
the range; a parameter that cannot be estimated on this record (no resonance peak a mount's
response fits, a noise floor that the signal itself fills) is reported as not estimated and
is not refused on.

A diagnoser whose data card lists no drawn ranges (the fixed chain, or a file made before
the chains were drawn) keeps the earlier checks: the noise floor and the impacts' ringing
against the ranges of those statistics over its training records
(`recipdyn.diagnosis.diagnose`).

The SNR calibration
-------------------
The noise floor is the share ``q`` of the mean crank-angle bin's high-passed (500 Hz) energy
that the quietest 10-degree bin holds (``noise_floor``; without a tacho: the quietest windows
of a bin's length, ``acc_quiet_share``). Where that bin holds only the sensor's white noise,
``q = N / (N + S)`` with ``S`` the signal's mean high-passed energy per bin and ``N`` the
noise's, so ``x = 10 log10(1/q - 1)`` is the signal-to-noise ratio of the high-passed signal
and the chain's SNR (on the whole band-limited signal) is ``x`` plus the record's ratio of
whole to high-passed signal energy, in dB: a constant plus a scatter that depends on the
machine, its state and the mount. Both were measured, not assumed
(``python benchmarks/bench_chain_ranges.py --part calibrate``; numbers in `SNR_CALIBRATION`
and docs/diagnosis.md). Where the signal itself fills the quietest bin (a quiet sensor: high
SNR) ``x`` stops rising with the SNR: above `SNR_CALIBRATION`'s ``x_max`` only a lower bound
of the SNR is read.
"""

from __future__ import annotations

import math
import re
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from ..sensors import G0
from .correction import _lowpass_delay, axis_sd, dataclass_replace
from .tolerances import RESONANCE_CHECK_REL, RING_AGREEMENT, SNR_CALIBRATION

#: The mains frequencies whose hum is read (both grids: the hum at the one that is not the
#: site's is held to the same bound) and the harmonics read on the accelerometer (the drawn
#: chains put hum at the first three; the pressures' at the fundamental only).
MAINS = (50.0, 60.0)
HUM_HARMONICS = 3
#: Largest pressure transducer range over the recorded peak pressure: `pressure.range_margin`
#: rounded up to the 1-2-5 series can double it (`recipdyn.sensors`), so the converter step
#: is at most ``2 * margin * peak / 2**bits``.
RANGE_ROUNDING = 2.0
#: Relative half-width given to a converter step read from the record (`level_spacing`: the
#: mean of the spacings one step apart, exact to rounding).
STEP_REL = 0.01

__all__ = ["ChainCheck", "declared_ranges", "snr_estimate", "check_chain", "SNR_CALIBRATION"]

#: The chain parameters checked: estimate name -> (declared parameter, channel, words).
CHECKED = {
    "resonance_hz": ("accelerometer.resonance_hz", "accelerometer",
                     "mounting resonance (the sensor band the impacts ring in)"),
    "snr_db": ("accelerometer.snr_db", "accelerometer",
               "signal-to-noise ratio (read from the acceleration's noise floor)"),
    "offset_head": ("pressure.offset", "p_head", "transducer offset"),
    "offset_crank": ("pressure.offset", "p_crank", "transducer offset"),
    "damping": ("accelerometer.damping", "accelerometer",
                "mounting resonance's damping ratio"),
    "tacho_jitter": ("tacho.jitter_deg", "tacho", "mark's jitter (RMS over the pulses)"),
    "tacho_axis": ("tacho.jitter_deg", "tacho", "crank-angle error the mark's jitter leaves in "
                   "the fitted crank angle"),
    "phase": ("tacho.angle_deg", "tacho", "mark's angle from outer dead centre (read from the "
              "pressures' polytropes, with the pressure channels' delay behind it)"),
    "gain_ratio": ("pressure.gain", "p_head/p_crank", "relative gain (head over crank, less "
                   "1)"),
    "step_accelerometer": ("accelerometer.bits", "accelerometer", "converter step"),
    "step_p_head": ("pressure.bits", "p_head", "converter step"),
    "step_p_crank": ("pressure.bits", "p_crank", "converter step"),
}  # fmt: skip
#: Estimated and reported, never refused on: the mount's damping (its intervals held the
#: drawn value 80-86 % of the time on in-range records, and a 10-revolution record of
#: ``recipdyn sense``'s own chain, damping 0.05, read 0.0085: the fit's interval is not a
#: 95 % one), and the tacho's jitter itself (what the features feel is the crank-angle error
#: it leaves in the least-squares fit through the pulses, ``tacho_axis``, checked instead: a
#: record of more pulses than the data set's averages the jitter down).
REPORTED_ONLY = ("damping", "tacho_jitter")
#: The mains harmonic each hum check reads (1: the fundamental).
HARMONIC: dict[str, int] = {}
for _ch, _p in (("accelerometer", "accelerometer.hum_db"), ("p_head", "pressure.hum_db"),
                ("p_crank", "pressure.hum_db")):  # fmt: skip
    for _f in MAINS:
        for _k in range(1, HUM_HARMONICS + 1):
            if _k == 1 or _ch == "accelerometer":
                CHECKED[f"hum_{_ch}_{_k * _f:g}"] = (
                    _p,
                    _ch,
                    f"mains hum at {_k * _f:g} Hz (harmonic {_k} of {_f:g} Hz)",
                )
                HARMONIC[f"hum_{_ch}_{_k * _f:g}"] = _k

_RANGE = re.compile(r"^\s*([-+0-9.eE]+)\s*\.\.\s*([-+0-9.eE]+)\s*([^\s;(]*)")
_CHOICE = re.compile(r"^\s*([-+0-9.eE]+(?:\s*,\s*[-+0-9.eE]+)*)\s*([^\s;(,]*)\s*$")


def declared_ranges(diag) -> dict[str, tuple[float, float, str]] | None:
    """``{parameter: (lo, hi, unit)}``: the chain ranges ``diag``'s data set drew its records'
    chains from, as its data card lists them (``card["chain"]["ranges"]``); None for a
    diagnoser of the fixed chain or one whose card lists none (it keeps the learnt-range
    checks)."""
    chain = (getattr(diag, "card", None) or {}).get("chain") or {}
    if chain.get("kind") != "drawn" or not chain.get("ranges"):
        return None
    out = {}
    for row in chain["ranges"]:
        text = str(row.get("range", ""))
        m = _RANGE.match(text)
        try:
            if m:
                out[row["parameter"]] = (float(m.group(1)), float(m.group(2)), m.group(3))
            elif (c := _CHOICE.match(text)) is not None:  # a few values: their span
                v = [float(w) for w in c.group(1).split(",")]
                out[row["parameter"]] = (min(v), max(v), c.group(2))
        except ValueError:
            continue
    return out or None


@dataclass(frozen=True)
class ChainCheck:
    """One chain parameter estimated from the record against its declared range: the
    estimate ``value`` and its 95 % interval ``[lo, hi]`` (``hi`` may be inf: a lower bound
    only), the declared ``range``, and ``status``: ``inside``, ``outside`` (the whole interval
    beyond the range: refused), ``not estimated`` (with ``note`` why)."""

    name: str
    parameter: str
    channel: str
    value: float
    lo: float
    hi: float
    unit: str
    range: tuple[float, float]
    status: str
    note: str = ""

    def text(self) -> str:
        a, b = self.range
        dec = f"declared {self.parameter} {a:g}..{b:g} {self.unit}"
        if self.status == "not estimated":
            return f"{self.channel} {self.name}: not estimated ({self.note}); {dec}"
        return f"{self.channel} {self.name}: {_value_text(self)} ({self.status}; {dec})"


def _value_text(c: ChainCheck) -> str:
    if not math.isfinite(c.hi):
        return f"{c.value:.3g} {c.unit} (at least {c.lo:.3g})"
    if not math.isfinite(c.lo):
        return f"{c.value:.3g} {c.unit} (at most {c.hi:.3g})"
    half = 0.5 * (c.hi - c.lo)
    if abs(c.value - (c.lo + half)) <= 1e-6 * max(1.0, abs(c.value)):
        return f"{c.value:.3g} +- {half:.2g} {c.unit}"
    return f"{c.value:.3g} {c.unit} (95 % interval {c.lo:.3g}..{c.hi:.3g})"


def snr_estimate(share: float, kind: str = "angle") -> tuple[float, float, float, str]:
    """``(snr_db, lo, hi, note)`` from a noise-floor share ``q`` (`SNR_CALIBRATION`
    ``kind``): the SNR and its 95 % interval; ``hi`` is inf where the signal fills the
    quietest bin (``x > x_max``: a lower bound only); NaN if ``q`` is not in (0, 1)."""
    cal = SNR_CALIBRATION[kind]
    if not (math.isfinite(share) and 0.0 < share < 1.0):
        return math.nan, math.nan, math.nan, "no noise floor read"
    x = 10.0 * math.log10(1.0 / share - 1.0)
    v = x + cal["offset"]
    if x > cal["x_max"]:  # (above, the residuals' lower end was no lower: a lower bound)
        return v, v + cal["lo"], math.inf, "the signal fills the quietest bin: a lower bound"
    return v, v + cal["lo"], v + cal["hi"], ""


def _check(name, value, lo, hi, declared, note="", span=None) -> ChainCheck | None:
    """``span``: ``(lo, hi, unit)`` the range the estimate is compared with, where it is
    derived from the declared parameter's (a hum harmonic's level, a converter step)."""
    parameter, channel, _ = CHECKED[name]
    if parameter not in declared:
        return None
    a, b, unit = declared[parameter] if span is None else span
    if math.isnan(value) or math.isnan(lo) or math.isnan(hi):  # (-inf / inf: a bound only)
        status = "not estimated"
    elif hi < a or lo > b:
        status = "outside"
    else:
        status = "inside"
    return ChainCheck(name, parameter, channel, value, lo, hi, unit, (a, b), status, note)


def check_chain(
    declared: dict[str, tuple[float, float, str]],
    estimates: dict[str, Any],
    floor: tuple[float, str] | None,
    ring_hz: float = math.nan,
    signals: dict[str, Any] | None = None,
    train_pulses: int = 0,
) -> tuple[list[ChainCheck], str | None]:
    """The record's chain against ``declared`` (`declared_ranges`): ``estimates`` the
    record's chain estimates (`recipdyn.diagnosis.correction.Estimate` by name: the
    resonance, the offsets), ``floor`` its noise floor ``(share, kind)``, ``ring_hz`` the
    frequency its impacts ring at (`recipdyn.diagnosis.evidence.ringing_hz`: the resonance is
    read only where the two agree within `RING_AGREEMENT`; its damping with it),
    ``signals`` what `read_channels` read of the channels' own samples (hum, converter
    step, the tacho's pulses), ``train_pulses`` the tacho pulses of the data set's records
    (the crank-angle error their jitter could leave; 0: not checked). Returns every check
    and the refusal (None if every estimated parameter is inside its range)."""
    checks = []
    r = estimates.get("resonance_hz")
    if r is not None:
        ok = r.status == "measured" and math.isfinite(r.uncertainty)
        note = "" if ok else r.note or r.status
        if ok and not abs(ring_hz - r.value) <= RING_AGREEMENT * r.value:
            ok, note = False, (f"the mount's fitted resonance ({r.value:.0f} Hz) is not where "
                               f"the impacts ring ({ring_hz:.0f} Hz): no resonance read with "
                               "confidence")  # fmt: skip
        u = math.hypot(r.uncertainty, RESONANCE_CHECK_REL * r.value) if ok else math.nan
        checks.append(_check("resonance_hz", r.value if ok else math.nan, r.value - u,
                             r.value + u, declared, note))  # fmt: skip
    if floor is not None:
        v, lo, hi, note = snr_estimate(*floor)
        checks.append(_check("snr_db", v, lo, hi, declared, note))
    for name in ("offset_head", "offset_crank"):
        e = estimates.get(name)
        if e is not None:
            ok = math.isfinite(e.value) and math.isfinite(e.uncertainty)
            checks.append(_check(name, e.value, e.value - e.uncertainty if ok else math.nan,
                                 e.value + e.uncertainty if ok else math.nan, declared,
                                 "" if ok else e.note))  # fmt: skip
    if r is not None and estimates.get("damping") is not None:  # read where the resonance is
        d = estimates["damping"]
        ok = checks[0] is not None and checks[0].status != "not estimated"
        ok = ok and math.isfinite(d.uncertainty)
        checks.append(_check("damping", d.value if ok else math.nan, d.value - d.uncertainty,
                             d.value + d.uncertainty, declared,
                             "" if ok else "the resonance is not read"))  # fmt: skip
    checks += _tacho_checks(declared, estimates, signals or {}, train_pulses)
    g = estimates.get("gain_ratio")
    if g is not None and "pressure.gain" in declared:
        a, b, _ = declared["pressure.gain"]
        ok = math.isfinite(g.value) and math.isfinite(g.uncertainty)
        checks.append(_check("gain_ratio", g.value, g.value - g.uncertainty if ok else math.nan,
                             g.value + g.uncertainty, declared, "" if ok else g.note,
                             span=(a / b - 1.0, b / a - 1.0, "1")))  # fmt: skip
    checks += _signal_checks(declared, signals or {})
    checks = [c for c in checks if c is not None]
    out = [c for c in checks if c.status == "outside" and c.name not in REPORTED_ONLY]
    if not out:
        return checks, None
    return checks, refusal_text(out)


def read_channels(x, fs: float, revs, p_head=None, p_crank=None, n_pulses: int = 0) -> dict:
    """What the channels' own samples say of their chain (`recipdyn.analysis.channel`):
    each channel's clipping and converter step, the hum at both mains frequencies (and the
    accelerometer's at their 2nd and 3rd harmonics) against the channel's RMS as the chain
    ranges state it (the accelerometer's about its mean, the pressures' absolute), read
    against the crank-synchronous signal
    (``revs``: the crank angle in revolutions, finite), the record's speed and the tacho's
    pulse count (``n_pulses``)."""
    from ..analysis.channel import clipping, level_spacing, mains_hums

    revs = np.asarray(revs, float)
    out: dict[str, Any] = {
        "fs": fs,
        "n_pulses": int(n_pulses),
        "speed_hz": float(revs[-1] - revs[0]) * fs / max(revs.size - 1, 1),
    }
    for ch, y in (("accelerometer", x), ("p_head", p_head), ("p_crank", p_crank)):
        if y is None:
            continue
        y = np.asarray(y, float)
        out[f"clip_{ch}"] = clipping(y)
        out[f"step_{ch}"] = level_spacing(y)
        out[f"peak_{ch}"] = float(np.max(np.abs(y)))
        orders = HUM_HARMONICS if ch == "accelerometer" else 1
        lines = [k * f for f in MAINS for k in range(1, orders + 1)]
        hums = mains_hums(y, fs, lines, revs=revs, about_mean=ch == "accelerometer")
        out.update({f"hum_{ch}_{f:g}": h for f, h in zip(lines, hums, strict=True)})
    return out


def clipping_refusal(
    signals: dict[str, Any], declared: dict[str, tuple[float, float, str]] | None = None
) -> tuple[str | None, dict[str, Any]]:
    """``(refusal, evidence)`` of the record's clipped channels (`read_channels`).

    A clipped **pressure** is refused: no data set's chain lets one clip (its transducer's
    range is at least ``pressure.range_margin`` >= 1.1 times the peak pressure, and the
    waveform beyond it is lost). A clipped **accelerometer** is a chain parameter like the
    others: its flat tops sit at the converter's full scale, so the record gives
    ``full_scale_g`` (the larger extreme over g, to a converter step), and a diagnoser whose
    data set drew ``accelerometer.full_scale_g`` has learnt records clipped anywhere in that
    range (the default ranges let the worn pins' impacts clip: `recipdyn.chain`). It is
    refused when the full scale lies outside the declared range, or when the diagnoser
    declares none (it cannot say it has seen such records); otherwise the evidence says the
    record clipped where its data set's records clip."""
    from ..sensors import G0

    evidence: dict[str, Any] = {}
    bad = []
    for ch in ("accelerometer", "p_head", "p_crank"):
        c = signals.get(f"clip_{ch}")
        if c is None or not c.clipped:
            continue
        if ch != "accelerometer":
            bad.append(f"{ch} clipped: {c.text()} ({c.samples} samples); no data set's "
                       "pressure transducer range lets the pressure clip")  # fmt: skip
            continue
        full = max(c.top, -c.bottom) / G0
        half = max(c.step, 0.0) / G0
        entry = {"clipped_samples": c.samples, "full_scale_g": full, "interval_g": half}
        span = (declared or {}).get("accelerometer.full_scale_g")
        if span is None:
            bad.append(f"accelerometer clipped: {c.text()} ({c.samples} samples), a full "
                       f"scale of {full:.4g} g; this diagnoser declares no converter range "
                       "its records were drawn with, so it cannot vouch for a clipped "
                       "record")  # fmt: skip
        elif full + half < span[0] or full - half > span[1]:
            bad.append(f"accelerometer clipped at a full scale of {full:.4g} g ({c.text()}, "
                       f"{c.samples} samples), outside the declared accelerometer.full_scale_g "
                       f"{span[0]:g}..{span[1]:g} g")  # fmt: skip
        else:
            entry["status"] = (f"clipped at {full:.4g} g, inside the declared full scale "
                               f"{span[0]:g}..{span[1]:g} g (its data set's records clip "
                               "there too)")  # fmt: skip
        evidence["accelerometer_clipping"] = entry
    if not bad:
        return None, evidence
    return ("; ".join(bad) + "; re-record with the channel's range set so that the signal "
            "does not clip (a larger converter range or a less sensitive transducer), or "
            "build a data set with that range (recipdyn dataset --chain-range "
            "accelerometer.full_scale_g=LO,HI)"), evidence  # fmt: skip


def _tacho_checks(declared, estimates, signals, n_train: int) -> list[ChainCheck | None]:
    out = []
    j = estimates.get("tacho_jitter")
    dof = signals.get("n_pulses", 0) - 3  # (the fit's parabola: `correction._degree`)
    if j is not None and "tacho.jitter_deg" in declared:
        ok = j.status == "corrected" and math.isfinite(j.value) and dof > 0
        lo = hi = math.nan
        if ok:  # the chi-square interval of a standard deviation
            from scipy.stats import chi2

            if signals["n_pulses"] < 10:  # (a line through fewer pulses)
                dof += 1
            lo = j.value * math.sqrt(dof / chi2.ppf(0.975, dof))
            hi = j.value * math.sqrt(dof / chi2.ppf(0.025, dof))
        out.append(_check("tacho_jitter", j.value if ok else math.nan, lo, hi, declared,
                          "" if ok else j.note or j.status))  # fmt: skip
        # the crank angle's error the jitter leaves (correction.axis_sd) against the largest
        # the data set's records could hold: its widest jitter over their pulses
        n = signals.get("n_pulses", 0)
        if ok and n_train >= 2:
            a, b, unit = declared["tacho.jitter_deg"]
            f, f_train = (
                axis_sd(dataclass_replace(j, value=1.0), n),
                math.sqrt((1 + 1) / n_train),
            )  # (a line through the data set's few pulses)
            out.append(_check("tacho_axis", j.value * f, lo * f, hi * f, declared,
                              span=(0.0, b * f_train, unit)))  # fmt: skip
    ph = estimates.get("phase")
    if ph is not None and "tacho.angle_deg" in declared:
        a, b, unit = declared["tacho.angle_deg"]
        # the pressures' own delay lies behind the phase: the declared delay, the slowest
        # causal low-pass and the lowest passage resonance's, as crank angle
        delay = declared.get("pressure.delay_s", (0.0, 0.0, "s"))[1]
        fc = declared.get("pressure.lowpass_fraction", (0.0, 0.0, ""))[0] * signals.get(
            "fs", math.nan
        )
        order = declared.get("pressure.lowpass_order", (0.0, 0.0, ""))[1]
        delay += _lowpass_delay(fc, order, "causal") if fc > 0 and order else 0.0
        fr, zeta = (declared.get("pressure.resonance_hz", (math.inf,) * 3)[0],
                    declared.get("pressure.damping", (0.0, 0.0, ""))[1])  # fmt: skip
        delay += 2 * zeta / (2 * math.pi * fr) if math.isfinite(fr) and fr > 0 else 0.0
        wide = 360.0 * signals.get("speed_hz", math.nan) * delay
        ok = math.isfinite(ph.value) and math.isfinite(ph.uncertainty) and math.isfinite(wide)
        out.append(_check("phase", ph.value, ph.value - ph.uncertainty if ok else math.nan,
                          ph.value + ph.uncertainty, declared, "" if ok else ph.note,
                          span=(a - wide, b + wide, unit)))  # fmt: skip
    return out


def _signal_checks(declared, signals) -> list[ChainCheck | None]:
    out = []
    for name, (parameter, _ch, _) in CHECKED.items():
        if name.startswith("hum_") and name in signals and parameter in declared:
            h = signals[name]
            # only the top of the range bounds a hum (no hum at all is in every range)
            b, unit = declared[parameter][1:]
            k = HARMONIC[name]
            rel = declared.get(f"accelerometer.hum_h{k}", (0.0, 1.0, ""))[1] if k > 1 else 1.0
            top = b + 20 * math.log10(rel) if rel > 0 else -math.inf
            note = h.note
            lo = h.db_lo if math.isfinite(h.db) else math.nan
            out.append(_check(name, h.db, lo, h.db_hi, declared, note,
                              span=(-math.inf, top, unit)))  # fmt: skip
    for ch in ("accelerometer", "p_head", "p_crank"):
        q = signals.get(f"step_{ch}")
        name = f"step_{ch}"
        parameter = CHECKED[name][0]
        if q is None or parameter not in declared:
            continue
        bits = declared[parameter][0]  # the coarsest converter drawn
        if ch == "accelerometer":
            if "accelerometer.full_scale_g" not in declared:
                continue
            top = 2 * declared["accelerometer.full_scale_g"][1] * G0 / 2**bits
            unit = "m/s**2"
        else:
            if "pressure.range_margin" not in declared:
                continue
            top = (RANGE_ROUNDING * declared["pressure.range_margin"][1]
                   * signals[f"peak_{ch}"] / 2**bits)  # fmt: skip
            unit = "Pa"
        ok = math.isfinite(q)
        out.append(_check(name, q, q * (1 - STEP_REL) if ok else math.nan, q * (1 + STEP_REL),
                          declared, "" if ok else "the signal visits too few adjacent "
                          "converter codes (a fine converter, or no quantisation)",
                          span=(0.0, top, unit)))  # fmt: skip
    return out


def refusal_text(out: list[ChainCheck]) -> str:
    """The refusal for the parameters ``out`` outside their declared ranges."""
    parts = []
    for c in out:
        words = CHECKED[c.name][2]
        a, b = c.range
        if c.name == "snr_db":
            head = f"{c.channel}: its noise floor gives an SNR of {_value_text(c)}"
        elif c.name == "resonance_hz":
            head = (f"{c.channel}: the {words.split(' (')[0]} is {_value_text(c)}, outside the "
                    "sensor band")  # fmt: skip
        else:
            head = f"{c.channel}: {words} {_value_text(c)}"
        if c.name.startswith(("hum_", "step_", "gain_ratio", "phase", "tacho_axis")):  # derived
            where = (f"outside {a:g}..{b:g} {c.unit}, what the declared {c.parameter} range "
                     "the diagnoser was trained under allows")  # fmt: skip
        else:
            where = (f"outside the declared {c.parameter} range {a:g}..{b:g} {c.unit} the "
                     "diagnoser was trained under")  # fmt: skip
        parts.append(f"{head}, {where}")
    fixes = []
    for c in out:
        key = next((k for k in ADVICE if c.name.startswith(k)), None)
        if key and ADVICE[key] not in fixes:
            fixes.append(ADVICE[key])
    how = []
    if any(c.name == "snr_db" for c in out):
        how.append("--snr-range LO,HI")
    if any(c.name != "snr_db" for c in out):
        how.append("--chain-range NAME=LO,HI")
    return (
        "; ".join(parts)
        + "; "
        + "".join(f + ", or " for f in fixes)
        + "train a diagnoser on a data set whose chain ranges cover it (recipdyn dataset "
        + " / ".join(how)
        + ")"
    )


#: What to do about a parameter outside its range, besides a diagnoser trained for it.
ADVICE = {
    "hum_": "remove the mains hum at its source (a ground loop, an unshielded cable) and re-record",
    "step_": "re-record with a finer converter (the declared bits over the declared range)",
    "tacho_jitter": "re-record with a clean once-per-turn mark (a firm keyphasor target, the "
    "probe's gap set)",
    "tacho_axis": "re-record with a clean once-per-turn mark (a firm keyphasor target, the "
    "probe's gap set) or over more revolutions (the fit through more pulses averages the "
    "jitter down)",
    "phase": "set the tacho mark to outer dead centre (within the declared angle) and re-record",
    "gain_ratio": "calibrate the two pressure transducers against each other and re-record",
    "damping": "mount the accelerometer as the data set's sensors are (a stud or a flat "
    "magnet on the crosshead guide)",
}


def as_evidence(checks: list[ChainCheck]) -> dict[str, dict[str, Any]]:
    """The checks as plain dicts (JSON-able but for inf), by name."""
    return {c.name: asdict(c) for c in checks}
