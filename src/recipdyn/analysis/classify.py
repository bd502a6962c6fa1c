"""Combine the evidence into a verdict: periodic, quasi-periodic or chaotic.

Rules (each piece of evidence is optional; the verdict says which were used):

* **chaotic** if the largest Lyapunov exponent is positive beyond its uncertainty
  (``lambda1 > max(lyap_tol, 2 * lambda1_err)``) and, when given, the 0-1 test agrees
  (``K > 0.5``); or if K > 0.8 and the section is scattered (no exponent given).
* **periodic** if the Poincaré section has few distinct points (<= ``max_periodic_points``)
  or, without a section, if the spectrum's strong lines are all harmonics of one fundamental.
* **quasi-periodic** otherwise when the exponent is ~0 and K < 0.5 (a closed curve in the
  section, incommensurate spectral lines).
* **undetermined** when the evidence conflicts (e.g. positive exponent but K ~ 0): the
  evidence dict then shows why.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from ..defaults import LYAP_TOL, MAX_PERIODIC_POINTS
from .poincare import count_distinct_points
from .spectrum import Spectrum, find_spectral_peaks

__all__ = ["Verdict", "classify"]


@dataclass
class Verdict:
    verdict: str
    evidence: dict[str, Any] = field(default_factory=dict)
    reasons: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        def conv(v):
            if isinstance(v, np.generic):
                return v.item()
            if isinstance(v, np.ndarray):
                return v.tolist()
            return v

        d = asdict(self)
        d["evidence"] = {k: conv(v) for k, v in d["evidence"].items()}
        return d


def _line_structure(spec: Spectrum, n: int = 12) -> dict[str, Any]:
    """Are the strong spectral lines harmonics of the strongest low line?"""
    peaks = find_spectral_peaks(spec, n=n, min_rel_height=0.02)
    if not peaks:
        return {"lines": 0, "harmonic_fraction": float("nan")}
    f0 = min(p.frequency for p in peaks if p.frequency > 0) if peaks else 0.0
    tol = 1.5 * spec.resolution
    harm = [abs(p.frequency / f0 - round(p.frequency / f0)) * f0 <= tol for p in peaks]
    return {"lines": len(peaks), "fundamental_hz": f0, "harmonic_fraction": float(np.mean(harm))}


def classify(*, lambda1: float | None = None, lambda1_err: float = 0.0, k01: float | None = None,
             section=None, spectrum: Spectrum | None = None, lyap_tol: float = LYAP_TOL,
             max_periodic_points: int = MAX_PERIODIC_POINTS) -> Verdict:  # fmt: skip
    """Verdict from any subset of: largest exponent (with error), 0-1 K, section points
    (array n x d), amplitude spectrum. ``lyap_tol`` is in the exponent's units."""
    ev: dict[str, Any] = {}
    reasons: list[str] = []
    if lambda1 is not None:
        ev["lambda1"] = float(lambda1)
        ev["lambda1_err"] = float(lambda1_err)
    if k01 is not None:
        ev["k01"] = float(k01)
    n_distinct = None
    if section is not None:
        pts = np.atleast_2d(np.asarray(section, dtype=float))
        n_distinct = count_distinct_points(pts)
        ev["section_points"] = int(pts.shape[0])
        ev["section_distinct"] = int(n_distinct)
    if spectrum is not None:
        ev.update({f"spectrum_{k}": v for k, v in _line_structure(spectrum).items()})
    pos = lambda1 is not None and lambda1 > max(lyap_tol, 2 * lambda1_err)
    if pos and (k01 is None or k01 > 0.5):
        reasons.append("largest Lyapunov exponent positive beyond its uncertainty")
        if k01 is not None:
            reasons.append(f"0-1 test K = {k01:.2f} > 0.5")
        return Verdict("chaotic", ev, reasons)
    if pos and k01 is not None:
        reasons.append(f"positive exponent but 0-1 test K = {k01:.2f}: conflicting evidence")
        return Verdict("undetermined", ev, reasons)
    if (
        lambda1 is None
        and k01 is not None
        and k01 > 0.8
        and (n_distinct is None or n_distinct > max_periodic_points)
    ):
        reasons.append(f"0-1 test K = {k01:.2f} > 0.8")
        return Verdict("chaotic", ev, reasons)
    if n_distinct is not None and n_distinct <= max_periodic_points:
        reasons.append(f"{n_distinct} distinct section point(s): period-{n_distinct} orbit")
        return Verdict("periodic", ev, reasons)
    if n_distinct is None and spectrum is not None and ev.get("spectrum_harmonic_fraction") == 1:
        reasons.append("all strong spectral lines are harmonics of one fundamental")
        if k01 is None or k01 < 0.5:
            return Verdict("periodic", ev, reasons)
    if k01 is None or k01 < 0.5:
        reasons.append("no positive exponent" if lambda1 is not None else "no exponent given")
        if k01 is not None:
            reasons.append(f"0-1 test K = {k01:.2f} < 0.5")
        return Verdict("quasi-periodic", ev, reasons)
    reasons.append("evidence insufficient or conflicting")
    return Verdict("undetermined", ev, reasons)
