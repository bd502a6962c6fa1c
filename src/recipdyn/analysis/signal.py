"""One assessment of a sampled signal: embedding, exponents, 0-1 test, surrogates, spectrum and
the verdict that combines them ([`classify`][recipdyn.analysis.classify.classify]).

This is what ``recipdyn analyze`` runs on any signal, simulated or measured: every estimate
carries its status and diagnostics, and the verdict lists which evidence agrees.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..defaults import MAX_RMS_RATIO, MAX_SPEED_RATIO
from .classify import Verdict, classify, quarter_rms_ratio, quarter_speed_ratio
from .embedding import Embedding, choose_embedding
from .lyapunov_signal import SignalLyapunov, _gate, lyap_kantz, lyap_rosenstein, lyap_wolf
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
            val = f"{r.exponent:.4g} /s" if r.ok else "-"
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


def noise_level(x) -> float:
    """Standard deviation of white measurement noise on ``x``, from its 4th differences:
    ``1.4826 MAD(diff4) / sqrt(70)`` (a 4th difference of white noise has variance
    ``C(8, 4) sigma^2 = 70 sigma^2``; the median makes it blind to sparse impacts). A smooth
    signal sampled at ``fs`` adds ``(2 pi f / fs)^4`` of its amplitude at frequency ``f``
    (1e-6 at 20 samples a period): the estimate is the noise for an oversampled signal, and
    too high for content near the Nyquist frequency."""
    d = np.diff(np.asarray(x, dtype=float), 4)
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
                  max_samples: int = 40_000, surrogates: bool = True, section=None,
                  revs=None, seed: int = 0) -> SignalAssessment:  # fmt: skip
    """Assess a uniformly sampled signal ``x`` (sampling rate ``fs`` in Hz).

    At most ``max_samples`` samples (the first) enter the neighbour-based estimators; the 0-1
    test thins the whole record. ``section`` (points of a Poincaré section, if the caller has
    one) joins the evidence. With the crank angle ``revs`` (revolutions at each sample) of a
    machine driven at that speed, the section is the signal once per revolution (at angle 0
    and 0.382 turn later) and the 0-1 test runs on it: the stroboscopic map of a forced
    system (a periodic signal thinned at an arbitrary stride looks quasi-periodic, and the
    0-1 test is unreliable on it)."""
    x = np.asarray(x, dtype=float)
    if x.ndim != 1:
        raise ValueError("need a 1-D signal")
    if not np.all(np.isfinite(x)):
        raise ValueError("signal contains NaN or inf")
    if x.size < 200:
        raise ValueError(f"{x.size} samples; assessing a signal needs at least 200")
    if np.ptp(x) == 0:
        raise ValueError("signal is constant")
    dt = 1.0 / float(fs)
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
    sur = None
    if surrogates:
        sur = surrogate_test(head, dim=emb.dim, delay=emb.delay, seed=seed)
    spec = amplitude_spectrum(x, fs)
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
