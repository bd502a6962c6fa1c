"""One assessment of a sampled signal: embedding, exponents, 0-1 test, surrogates, spectrum and
the verdict that combines them ([`classify`][recipdyn.analysis.classify.classify]).

This is what ``recipdyn analyze`` runs on any signal, simulated or measured: every estimate
carries its status and diagnostics, and the verdict lists which evidence agrees.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..defaults import MAX_RMS_RATIO, MAX_SPEED_RATIO, MIN_SIGNAL_SAMPLES
from .checks import as_signal, check_rate
from .classify import (
    Verdict,
    classify,
    is_repeating_section,
    quarter_rms_ratio,
    quarter_speed_ratio,
)
from .embedding import Embedding, choose_embedding
from .lyapunov_signal import (
    SignalLyapunov,
    _gate,
    check_agreement,
    lyap_kantz,
    lyap_rosenstein,
    lyap_wolf,
)
from .poincare import count_distinct_points
from .spectrum import amplitude_spectrum
from .surrogates import SurrogateTest, surrogate_test
from .zero_one import ZeroOne, zero_one

__all__ = ["SignalAssessment", "assess_signal", "ESTIMATORS"]

ESTIMATORS = {"wolf": lyap_wolf, "rosenstein": lyap_rosenstein, "kantz": lyap_kantz}


@dataclass
class SignalAssessment:
    """Everything [`assess_signal`][recipdyn.analysis.signal.assess_signal] found (``verdict``
    first)."""

    verdict: Verdict
    embedding: Embedding
    lyapunov: dict[str, SignalLyapunov]
    zero_one: ZeroOne
    surrogates: SurrogateTest | None
    fs: float
    samples: int
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {
            "verdict": self.verdict.to_dict(),
            "samples": self.samples,
            "fs_hz": self.fs,
            "embedding": self.embedding.diagnostics(),
            "lyapunov": {k: v.diagnostics() for k, v in self.lyapunov.items()},
            "zero_one": self.zero_one.diagnostics(),
            "surrogates": None if self.surrogates is None else self.surrogates.diagnostics(),
            "notes": self.notes,
        }

    def evidence_table(self) -> list[tuple[str, str, str]]:
        """(evidence, value, status) rows, as printed by the CLI."""
        rows = []
        ratio = self.verdict.evidence.get("quarter_rms_ratio")
        if ratio is not None:
            rows.append(("stationarity", f"quarters' RMS ratio {ratio:.3g}",
                         "ok" if ratio <= MAX_RMS_RATIO else
                         f"not stationary (> {MAX_RMS_RATIO:g})"))  # fmt: skip
        speed = self.verdict.evidence.get("quarter_speed_ratio")
        if speed is not None:
            rows.append(("steady speed", f"quarters' speed ratio {speed:.4g}",
                         "ok" if speed <= MAX_SPEED_RATIO else
                         f"not stationary (> {MAX_SPEED_RATIO:g})"))  # fmt: skip
        rows.append(("embedding", f"delay {self.embedding.delay}, dimension {self.embedding.dim}",
                     self.embedding.status))  # fmt: skip
        for k, r in self.lyapunov.items():
            val = (f"{r.exponent:.4g} /s" if r.ok else f"({r.exponent:.4g} /s)"
                   if r.status in ("inconsistent", "unconfirmed") else "-")  # fmt: skip
            rows.append((f"lambda1 ({k})", val, r.status + (f": {r.reason}" if r.reason else "")))
        z = self.zero_one
        rows.append(("0-1 test K", "-" if not np.isfinite(z.K) else f"{z.K:.3f}",
                     f"{z.status}: {z.reason}"))  # fmt: skip
        if self.surrogates is not None:
            s = self.surrogates
            what = "nonlinear" if s.nonlinear else "consistent with linear noise"
            rows.append(("surrogates (IAAFT)", f"z = {s.z:.1f}", what))
        return rows


#: Largest section tolerance (relative to its scale) at which the section is still evidence.
MAX_SECTION_RTOL = 0.05
#: Kantz's plateau: the Rosenstein and Kantz slopes are recomputed with the embedding
#: dimension raised by PLATEAU_STEP; a slope that changes by more than PLATEAU_TOL is not an
#: exponent of the attractor. Calibration study (benchmarks/bench_lyap_calibration.py): with
#: the other rules, 0.10 and 0.15 leave no ok estimate outside 25 % (0.15 keeps 4 % more),
#: 0.20 three (Chua, Thomas: slopes 20-30 % low that change 16-20 %); the ring-dominated
#: acceleration of a compressor with clearance changes by 17-19 % (0.057 /s from the
#: equations; the slopes 310 and 270 /s).
PLATEAU_STEP = 2
PLATEAU_TOL = 0.15


def _fast_scale(spec, emb, dt) -> str:
    """What the embedding window sees, in periods of the strongest spectral line."""
    f = float(spec.frequency[1:][np.argmax(spec.amplitude[1:])]) if spec.amplitude.size > 2 else 0
    window = (emb.dim - 1) * emb.delay * dt
    if not f > 0:
        return f"embedding window {window:.3g} s"
    return (f"the embedding window, {window:.3g} s, spans {window * f:.2g} period(s) of the "
            f"strongest line, {f:.4g} Hz")  # fmt: skip


def _reconcile(lyap, x, dt, emb, spec, section_periodic: str | None):
    """Withhold every positive estimate that contradicts the other evidence (status
    ``inconsistent``) or that nothing confirms (``unconfirmed``): (1) a Rosenstein or Kantz
    slope is not on a plateau across embedding dimensions (Kantz 1994; the divergence then
    follows what the short embedding window sees, a fast ring, not the attractor); (2) the
    positive estimates disagree, or one stands alone (`check_agreement`); (3) the section says
    the orbit is periodic (``section_periodic``: the reason, or None)."""
    out = dict(lyap)
    fast = _fast_scale(spec, emb, dt)
    for name in ("rosenstein", "kantz"):
        r = out.get(name)
        if r is None or r.status != "ok" or not r.exponent > 0:
            continue
        hi = ESTIMATORS[name](x, dt, delay=emb.delay, theiler=emb.theiler,
                              dim=emb.dim + PLATEAU_STEP)  # fmt: skip
        # a slope refused only for its curve's small rise is still a slope to compare (the
        # plateau test asks whether the slope follows the dimension, not whether it is right)
        slope = hi.exponent if hi.status == "ok" else hi.params.get("slope", float("nan"))
        r.params[f"exponent_dim_{emb.dim + PLATEAU_STEP}"] = slope
        if hi.status == "refused" and not np.isfinite(slope):  # too few samples: not checked
            r.params["plateau"] = f"not checked at d = {emb.dim + PLATEAU_STEP}: {hi.reason}"
            continue
        change = slope / r.exponent - 1 if hi.status != "flat" else float("nan")
        if not abs(change) <= PLATEAU_TOL:
            what = (f"changes {change:+.0%}" if np.isfinite(change)
                    else f"is {hi.status}")  # fmt: skip
            out[name] = r.withheld(
                f"no plateau across embedding dimensions: the slope {what} from d = "
                f"{emb.dim} to {emb.dim + PLATEAU_STEP} (tolerance {PLATEAU_TOL:.0%}); it "
                f"follows the signal's fast time scale ({fast}), not the attractor"
            )
    out = check_agreement(out)
    if section_periodic:
        for k, r in out.items():
            if r.status == "ok" and r.exponent > 0:
                out[k] = r.withheld(f"{section_periodic}: a periodic orbit has no positive "
                                    f"exponent; this one follows the divergence within a "
                                    f"revolution ({fast})")  # fmt: skip
    return out


def noise_level(x) -> float:
    """Standard deviation of white measurement noise on ``x``, from its 4th differences:
    ``1.4826 MAD(diff4) / sqrt(70)`` (a 4th difference of white noise has variance
    ``C(8, 4) sigma^2 = 70 sigma^2``; the median makes it blind to sparse impacts). A smooth
    signal sampled at ``fs`` adds ``(2 pi f / fs)^4`` of its amplitude at frequency ``f``
    (1e-6 at 20 samples a period): the estimate is the noise for an oversampled signal, and
    too high for content near the Nyquist frequency."""
    d = np.diff(as_signal(x, name="x", min_samples=5, allow_constant=True), 4)
    return float(1.4826 * np.median(np.abs(d - np.median(d))) / np.sqrt(70.0))


def _once_per_revolution(x, revs) -> np.ndarray:
    """(x at angle 0, x 0.382 turn later) at every whole revolution covered (the second angle
    an irrational fraction of a turn, unlikely to sit on an impact)."""
    r = np.asarray(revs, dtype=float)
    ok = np.isfinite(r)
    r, y = r[ok], np.asarray(x, dtype=float)[ok]
    whole = np.arange(np.ceil(r[0]), np.floor(r[-1] - 0.382) + 1)
    return np.c_[np.interp(whole, r, y), np.interp(whole + 0.382, r, y)]


def assess_signal(x, fs: float, *, methods=("wolf", "rosenstein", "kantz"),
                  max_samples: int = 40_000, surrogates: bool | SurrogateTest = True,
                  section=None, revs=None, seed: int = 0) -> SignalAssessment:  # fmt: skip
    """Assess a uniformly sampled signal ``x`` (sampling rate ``fs`` in Hz).

    ``surrogates``: True runs the surrogate test, False leaves it out, and a
    [`SurrogateTest`][recipdyn.analysis.surrogates.SurrogateTest] of this record (from an
    earlier assessment: it depends on the record and its embedding only) is used as given.

    At most ``max_samples`` samples (the first) enter the neighbour-based estimators; the 0-1
    test thins the whole record. ``section`` (points of a Poincaré section, if the caller has
    one) joins the evidence. With the crank angle ``revs`` (revolutions at each sample) of a
    machine driven at that speed, the section is the signal once per revolution (at angle 0
    and 0.382 turn later) and the 0-1 test runs on it: the stroboscopic map of a forced
    system (a periodic signal thinned at an arbitrary stride looks quasi-periodic, and the
    0-1 test is unreliable on it)."""
    x = as_signal(x, name="x", min_samples=MIN_SIGNAL_SAMPLES)
    dt = 1.0 / check_rate(fs)
    head = x[:max_samples]
    emb = choose_embedding(head)
    notes = []
    if head.size < x.size:
        notes.append(f"neighbour-based estimators used the first {head.size} of {x.size} samples")
    lyap = {}
    for name in methods:
        if emb.status == "ok":
            lyap[name] = ESTIMATORS[name](head, dt, delay=emb.delay, theiler=emb.theiler,
                                          dim=emb.dim)  # fmt: skip
        else:
            prm = {"dim": emb.dim, "delay": emb.delay, "theiler": emb.theiler, "dt": dt,
                   "embedding": emb.status, "embedding_reason": emb.reason}  # fmt: skip
            lyap[name] = _gate(name, prm)
    if revs is not None and section is None:
        section = _once_per_revolution(x, revs)
        notes.append(f"section: the signal once per revolution ({section.shape[0]} points)")
    if section is not None and revs is not None:
        z01 = zero_one(section[:, 0], stride=1, seed=seed)
    else:
        z01 = zero_one(x, stride=emb.delay, seed=seed)
    sur = surrogates if isinstance(surrogates, SurrogateTest) else None
    if surrogates is True:
        sur = surrogate_test(head, dim=emb.dim, delay=emb.delay, seed=seed)
    # A section from a measured signal repeats only to the accuracy of the crank angle (tacho
    # edges to a fraction of a sample) and to the measurement noise: points within 1e-3 of the
    # signal's range, or within 4 noise deviations, are one, if the group stays compact (a
    # noisy point's cloud of N points spans ~2 sqrt(2 ln N) sigma: 6.5 sigma for 200; a chain
    # along a chaotic or quasi-periodic section is wider than 3 tolerances). A tolerance above
    # MAX_SECTION_RTOL resolves no structure: the section is then left out, with a note.
    rtol, extent, scale = 1e-6, None, None
    if revs is not None and section is not None:
        sigma = noise_level(x)
        # one scale for both axes, the signal's range (a section point near a zero crossing
        # of the signal would make the section's own magnitude a poor scale)
        scale = float(np.ptp(x)) or 1.0
        rtol = max(1e-3, 4.0 * sigma / scale)
        extent = 3.0 * rtol
        if rtol > MAX_SECTION_RTOL:
            notes.append(f"section left out of the verdict: the noise (estimate {sigma:.3g} "
                         f"from the 4th differences) blurs its points by {rtol:.2g} of the "
                         f"signal's range (resolvable up to {MAX_SECTION_RTOL:g})")  # fmt: skip
            section, extent = None, None
        else:
            notes.append(f"section tolerance {rtol:.3g} of the signal's range (noise estimate "
                         f"{sigma:.3g} from the 4th differences)")  # fmt: skip
    spec = amplitude_spectrum(x, fs)
    periodic = None
    if section is not None:
        n_pts = int(np.atleast_2d(section).shape[0])
        n_dist = count_distinct_points(np.atleast_2d(section), rtol=rtol, scale=scale,
                                       max_extent=extent)  # fmt: skip
        if is_repeating_section(n_dist, n_pts):
            periodic = (f"the section once per revolution is {n_dist} point(s) over "
                        f"{n_pts} revolutions")  # fmt: skip
    lyap = _reconcile(lyap, head, dt, emb, spec, periodic)
    speed_ratio = None if revs is None else quarter_speed_ratio(revs, fs)
    verdict = classify(k01=z01.K if z01.status == "ok" else None, spectrum=spec,
                       section=section, determinism=sur, signal_lyapunov=list(lyap.values()),
                       time_scale=emb.delay * dt, section_rtol=rtol,
                       section_extent=extent, section_scale=scale,
                       rms_ratio=quarter_rms_ratio(x),
                       speed_ratio=speed_ratio)  # fmt: skip
    if extent is not None:
        verdict.evidence["section_tolerance"] = rtol
    verdict.evidence["embedding_delay"] = emb.delay
    verdict.evidence["embedding_dim"] = emb.dim
    return SignalAssessment(verdict, emb, lyap, z01, sur, float(fs), int(x.size), notes)
