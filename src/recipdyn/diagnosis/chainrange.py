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

from .tolerances import RESONANCE_CHECK_REL, RING_AGREEMENT, SNR_CALIBRATION

__all__ = ["ChainCheck", "declared_ranges", "snr_estimate", "check_chain", "SNR_CALIBRATION"]

#: The chain parameters checked: estimate name -> (declared parameter, channel, words).
CHECKED = {
    "resonance_hz": ("accelerometer.resonance_hz", "accelerometer",
                     "mounting resonance (the sensor band the impacts ring in)"),
    "snr_db": ("accelerometer.snr_db", "accelerometer",
               "signal-to-noise ratio (read from the acceleration's noise floor)"),
    "offset_head": ("pressure.offset", "p_head", "transducer offset"),
    "offset_crank": ("pressure.offset", "p_crank", "transducer offset"),
}  # fmt: skip

_RANGE = re.compile(r"^\s*([-+0-9.eE]+)\s*\.\.\s*([-+0-9.eE]+)\s*([^\s;(]*)")


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
        m = _RANGE.match(str(row.get("range", "")))
        if m:
            try:
                out[row["parameter"]] = (float(m.group(1)), float(m.group(2)), m.group(3))
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


def _check(name, value, lo, hi, declared, note="") -> ChainCheck | None:
    parameter, channel, _ = CHECKED[name]
    if parameter not in declared:
        return None
    a, b, unit = declared[parameter]
    if not (math.isfinite(value) and math.isfinite(lo)):
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
) -> tuple[list[ChainCheck], str | None]:
    """The record's chain against ``declared`` (`declared_ranges`): ``estimates`` the
    record's chain estimates (`recipdyn.diagnosis.correction.Estimate` by name: the
    resonance, the offsets), ``floor`` its noise floor ``(share, kind)``, ``ring_hz`` the
    frequency its impacts ring at (`recipdyn.diagnosis.evidence.ringing_hz`: the resonance is
    read only where the two agree within `RING_AGREEMENT`). Returns every check
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
    checks = [c for c in checks if c is not None]
    out = [c for c in checks if c.status == "outside"]
    if not out:
        return checks, None
    return checks, refusal_text(out)


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
        parts.append(f"{head}, outside the declared {c.parameter} range {a:g}..{b:g} {c.unit} "
                     "the diagnoser was trained under")  # fmt: skip
    how = []
    if any(c.name == "snr_db" for c in out):
        how.append("--snr-range LO,HI")
    if any(c.name != "snr_db" for c in out):
        how.append("--chain-range NAME=LO,HI")
    return (
        "; ".join(parts)
        + "; train a diagnoser on a data set whose chain ranges cover it (recipdyn dataset "
        + " / ".join(how)
        + ")"
    )


def as_evidence(checks: list[ChainCheck]) -> dict[str, dict[str, Any]]:
    """The checks as plain dicts (JSON-able but for inf), by name."""
    return {c.name: asdict(c) for c in checks}
