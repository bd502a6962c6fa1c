"""Combine the evidence into a verdict: periodic, quasi-periodic or chaotic.

Rules (each piece of evidence is optional; the verdict says which were used):

* **chaotic** if the largest Lyapunov exponent is positive beyond its uncertainty
  (``lambda1 > max(lyap_tol, 2 * lambda1_err)``) and, when given, the 0-1 test agrees
  (``K > 0.5``); or if K > 0.8 and the section is scattered (no exponent given).
* **periodic** if the Poincaré section has few distinct points (<= ``max_periodic_points``)
  or, without a section, if the spectrum's strong lines are all harmonics of one fundamental
  (the lowest line at least ``MIN_FUNDAMENTAL_TOLS`` tolerances above 0 Hz: a line in the
  first bins, a drift, would make every frequency its harmonic).
* **quasi-periodic** otherwise when the exponent is ~0 and K < 0.5 (a closed curve in the
  section, incommensurate spectral lines).
* **undetermined** when the evidence conflicts (e.g. positive exponent but K ~ 0): the
  evidence dict then shows why; and for a signal that is not stationary (``rms_ratio``: its
  quarters' RMS differ by more than ``MAX_RMS_RATIO``, e.g. the free decay of a hammer test;
  ``speed_ratio``: their mean speeds by more than ``MAX_SPEED_RATIO``, a run-up).

For a measured signal (no equations) two more pieces enter:

* ``determinism``: the surrogate test
  ([`surrogate_test`][recipdyn.analysis.surrogates.surrogate_test]). If it cannot reject linearly
  correlated noise, the verdict is never **chaotic**: it is **periodic** when the spectrum or
  section says so, **periodic**/**quasi-periodic** by the rules above when the exponents are flat
  and K < 0.5 (noise never gives a flat divergence curve; line spectra are where the surrogate test
  is weakest), else **stochastic** (white noise, coloured noise and a noisy periodic signal land
  here).
* ``signal_lyapunov``: estimates from the signal (Wolf, Rosenstein, Kantz); only those with a
  usable status count (refusals are listed, never read as 0). The estimates are compared with
  each other first (the rules of ``assess_signal``, one implementation: ``check_agreement``):
  usable positive ones that disagree are withheld, which makes the verdict **undetermined**;
  a lone positive one is ``unconfirmed``: it votes for a positive sign but gives no number
  (the verdict counts the exponent as positive, with no value). They stand in for
  ``lambda1``
  when no equation-based exponent is given: positive when most usable estimates exceed
  ``signal_tol / time_scale`` (``time_scale``: the embedding delay, about one decorrelation
  time, in the exponents' time unit) and twice their fit error; flat when most do not
  (the dissenting estimator is named); undetermined on a tie. A
  deterministic signal whose estimators all refused is **chaotic** only with K > 0.8.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from ..defaults import LYAP_TOL, MAX_PERIODIC_POINTS, MAX_RMS_RATIO, MAX_SPEED_RATIO
from .checks import as_signal
from .lyapunov_signal import check_agreement
from .poincare import count_distinct_points
from .spectrum import Spectrum, find_spectral_peaks

__all__ = ["Verdict", "classify", "quarter_rms_ratio", "quarter_speed_ratio",
           "is_repeating_section"]  # fmt: skip

#: A section of few distinct points shows a periodic orbit only when each point recurs: at
#: least this many section points per distinct point on average (9 points of a 10-revolution
#: record, all distinct, say nothing; 200 points on 3 say period 3).
MIN_SECTION_REVISITS = 3


def is_repeating_section(n_distinct: int, n_points: int,
                         max_periodic_points: int = MAX_PERIODIC_POINTS) -> bool:  # fmt: skip
    """True when a section of ``n_points`` with ``n_distinct`` distinct points is a periodic
    orbit: few distinct points, each visited ``MIN_SECTION_REVISITS`` times on average."""
    return 0 < n_distinct <= max_periodic_points and n_points >= MIN_SECTION_REVISITS * n_distinct


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


#: A signal counts as deterministic only if its local prediction error (RMS over the signal's
#: standard deviation, one delay ahead) is below this: measured 0.008 (Henon) to 0.38 (a
#: machine signal with impacts) for deterministic signals, 1.06 for GARCH(1, 1) noise, which
#: the surrogate test alone calls nonlinear (and 0.90 for the compressor's chaotic 150 rad/s
#: acceleration at 10 kHz, whose link rings within a few samples: determinism not shown).
MAX_PREDICTION_ERROR = 0.8
#: A line counts as a harmonic within this many frequency bins of a multiple of the fundamental.
HARMONIC_TOL_BINS = 1.5
#: The fundamental must lie at least this many tolerances (3 bins) above 0 Hz. A line in the
#: first two bins is the record's drift or offset leaking through the window, or a component
#: with fewer than 3 periods in the record: taken as the fundamental, it would make every line
#: its harmonic. Such lines stay out of the test and are counted. (Any frequency falls within
#: ``tol`` of a multiple of ``f0`` with probability ``2 tol / f0``: the test is weak for a
#: fundamental of a few bins, e.g. 0.6 per line at 5 bins, a 5-period record.)
MIN_FUNDAMENTAL_TOLS = 2.0


def _line_structure(spec: Spectrum, n: int = 12) -> dict[str, Any]:
    """Are the strong spectral lines harmonics of the lowest resolved one?"""
    peaks = find_spectral_peaks(spec, n=n, min_rel_height=0.02)
    tol = HARMONIC_TOL_BINS * spec.resolution
    resolved = [p for p in peaks if p.frequency >= MIN_FUNDAMENTAL_TOLS * tol]
    out: dict[str, Any] = {"lines": len(resolved)}
    if len(resolved) < len(peaks):
        out["unresolved_lines"] = len(peaks) - len(resolved)
    if not resolved:
        out["harmonic_fraction"] = float("nan")
        return out
    f0 = min(p.frequency for p in resolved)
    harm = [abs(p.frequency / f0 - round(p.frequency / f0)) * f0 <= tol for p in resolved]
    return out | {"fundamental_hz": f0, "harmonic_fraction": float(np.mean(harm))}


def quarter_rms_ratio(x) -> float:
    """Largest over smallest RMS (about the whole record's mean) of the record's four quarters:
    ~1 for a stationary signal, large for a decay, a run-up or a burst (inf if a quarter is
    constant at the mean)."""
    x = as_signal(x, name="x", min_samples=4, allow_constant=True)
    r = np.array([np.sqrt(np.mean(q**2)) for q in np.array_split(x - x.mean(), 4)])
    return float(r.max() / r.min()) if r.min() > 0 else float("inf")


def quarter_speed_ratio(revs, fs: float) -> float:
    """Largest over smallest mean speed of the record's four quarters, from the crank angle
    ``revs`` (revolutions at each sample, NaN where unknown): 1 at constant speed whatever the
    ripple within a revolution, > 1 in a run-up or a coast-down."""
    r = np.asarray(revs, dtype=float)
    idx = np.flatnonzero(np.isfinite(r))
    speeds = []
    for q in np.array_split(idx, 4):
        if q.size > 1 and q[-1] > q[0]:
            speeds.append(abs(r[q[-1]] - r[q[0]]) * fs / (q[-1] - q[0]))
    if len(speeds) < 4 or min(speeds) <= 0:
        return float("nan")
    return float(max(speeds) / min(speeds))


def _grouped(estimates, what: str) -> list[str]:
    """One reason per distinct cause: 'wolf, kantz: refused (cause)'."""
    causes: dict[str, list[str]] = {}
    for e in estimates:
        causes.setdefault(e.reason, []).append(e.method)
    return [f"{', '.join(names)}: {what} ({cause})" for cause, names in causes.items()]


def _signal_exponent(estimates, time_scale, tol, ev, reasons):
    """(lambda1, err, no_number) from signal estimates; records the evidence. The estimates
    are first compared with each other
    ([`check_agreement`][recipdyn.analysis.lyapunov_signal.check_agreement], the rules
    `assess_signal` applies: a list from anywhere gets them too). Estimates withheld as
    ``inconsistent`` are listed with their reason and never used; when they leave no usable
    positive estimate, ``ev['signal_estimates_withheld']`` is set. An ``unconfirmed`` estimate
    (a lone positive one) votes for a positive sign when above the positive limit, and is no
    evidence otherwise; it gives no number: when it carries the vote, lambda1 is None and
    ``ev['signal_exponent_unconfirmed']`` is set (the verdict counts the exponent as positive,
    with no value). ``no_number``: no estimate is evidence either way."""
    estimates = check_agreement(list(estimates))
    usable = [e for e in estimates if e.ok]
    unconfirmed = [e for e in estimates if e.status == "unconfirmed"]
    withheld = [e for e in estimates if e.status == "inconsistent"]
    for e in estimates:
        ev[f"lambda1_{e.method}"] = e.exponent if e.ok else None
        ev[f"lambda1_{e.method}_status"] = e.status
        if e.status in ("inconsistent", "unconfirmed"):
            ev[f"lambda1_{e.method}_withheld"] = e.exponent
    reasons += _grouped([e for e in estimates if e.status == "refused"], "refused")
    reasons += _grouped(withheld, "withheld")
    reasons += _grouped(unconfirmed, "unconfirmed")
    if withheld and not any(e.exponent > 0 for e in usable):
        ev["signal_estimates_withheld"] = True
    lim = tol / time_scale
    # an unconfirmed value votes only for a positive sign: below the positive limit it is no
    # evidence of "no divergence" either (a lone Wolf of 58 1/s beside two refused slopes of
    # a ringing machine signal would make its harmonic lines "periodic")
    voters = usable + [e for e in unconfirmed if e.exponent > max(lim, 2 * e.stderr)]
    if not voters:
        return None, 0.0, not withheld
    pos = [e for e in voters if e.exponent > max(lim, 2 * e.stderr)]
    if usable:
        ev["lambda1_signal_median"] = float(np.median([e.exponent for e in usable]))
    ev["lambda1_signal_tolerance"] = lim
    if len(pos) * 2 > len(voters):  # a majority positive
        confirmed = [e for e in pos if e.ok]
        if not confirmed:
            ev["signal_exponent_unconfirmed"] = True
            names = ", ".join(e.method for e in pos)
            reasons.append(f"{names}: positive, its value unconfirmed (no number is reported)")
            return None, 0.0, False
        lam = float(np.median([e.exponent for e in confirmed]))
        reasons.append(f"{len(pos)} of {len(voters)} signal estimates positive "
                       f"(median {lam:.4g} > {lim:.3g}, the smallest exponent counted as "
                       f"positive: {tol:g} per embedding delay of {time_scale:.3g})")  # fmt: skip
        return lam, 0.0, False
    if pos and len(pos) * 2 == len(voters):  # a tie
        reasons.append(f"signal estimates disagree: {len(pos)} of {len(voters)} positive")
        ev["signal_estimates_conflict"] = True
        return None, 0.0, False
    if pos:
        names = ", ".join(e.method for e in pos)
        reasons.append(f"{len(voters) - len(pos)} of {len(voters)} signal estimates show no "
                       f"divergence ({names} dissents)")  # fmt: skip
    return 0.0, 0.0, False


def classify(*, lambda1: float | None = None, lambda1_err: float = 0.0, k01: float | None = None,
             section=None, spectrum: Spectrum | None = None, lyap_tol: float = LYAP_TOL,
             max_periodic_points: int = MAX_PERIODIC_POINTS, determinism=None,
             signal_lyapunov=None, time_scale: float = 1.0, signal_tol: float = LYAP_TOL,
             section_rtol: float = 1e-6, section_extent: float | None = None,
             section_scale=None, rms_ratio: float | None = None,
             speed_ratio: float | None = None) -> Verdict:  # fmt: skip
    """Verdict from any subset of: largest exponent (with error), 0-1 K, section points
    (array n x d), amplitude spectrum, a surrogate test (``determinism``: a
    [`SurrogateTest`][recipdyn.analysis.surrogates.SurrogateTest] or a bool) and signal estimates
    (``signal_lyapunov``: [`SignalLyapunov`][recipdyn.analysis.lyapunov_signal.SignalLyapunov]
    list). ``lyap_tol`` is in the exponent's units; ``section_rtol`` the relative distance under
    which section points are one (1e-6 for an integration; larger for measured signals),
    ``section_extent`` the widest group that still counts as one point and ``section_scale``
    the scale of both ([`count_distinct_points`][recipdyn.analysis.poincare.count_distinct_points]).
    ``rms_ratio`` ([`quarter_rms_ratio`][recipdyn.analysis.classify.quarter_rms_ratio] of a signal)
    above ``MAX_RMS_RATIO``, or ``speed_ratio``
    ([`quarter_speed_ratio`][recipdyn.analysis.classify.quarter_speed_ratio] of its crank angle)
    above ``MAX_SPEED_RATIO``, makes the verdict undetermined: every estimator here assumes a
    stationary record."""
    ev: dict[str, Any] = {}
    reasons: list[str] = []
    if rms_ratio is not None:
        ev["quarter_rms_ratio"] = float(rms_ratio)
    if speed_ratio is not None and np.isfinite(speed_ratio):
        ev["quarter_speed_ratio"] = float(speed_ratio)
    deterministic = None
    if determinism is not None:
        deterministic = bool(getattr(determinism, "nonlinear", determinism))
        ev["surrogate_nonlinear"] = deterministic
        if hasattr(determinism, "summary"):
            reasons.append("surrogate test: " + determinism.summary)
        error = getattr(determinism, "statistic", None)
        if deterministic and error is not None and not error < MAX_PREDICTION_ERROR:
            # nonlinear is not deterministic: GARCH-like noise (volatility clusters) beats
            # its IAAFT surrogates, yet nothing in it can be predicted; so does a chaotic
            # record sampled too coarsely for its fastest motion. Neither is shown.
            deterministic = None
            ev["surrogate_unpredictable"] = True
            reasons.append(
                f"nonlinear but unpredictable (prediction error {error:.2f} of the spread, "
                f">= {MAX_PREDICTION_ERROR}): determinism not shown"
            )
    all_refused = False
    conflict = withheld = False
    if signal_lyapunov:
        lam_s, _, all_refused = _signal_exponent(signal_lyapunov, time_scale, signal_tol, ev,
                                                 reasons)  # fmt: skip
        conflict = ev.get("signal_estimates_conflict", False)
        withheld = ev.get("signal_estimates_withheld", False)
        if lambda1 is None and lam_s is not None:
            lambda1, lambda1_err = lam_s, 0.0
            lyap_tol = min(lyap_tol, 0.5 * ev["lambda1_signal_tolerance"])
        elif lambda1 is not None:
            conflict = withheld = False  # the equations' exponent decides; the signal's is evidence
            med = ev.get("lambda1_signal_median")
            if med is not None and med > 0 and lambda1 > 0:
                ratio = med / lambda1
                ev["lambda1_signal_over_equations"] = ratio
                if not 1 / 3 < ratio < 3:
                    reasons.append(
                        f"the signal estimates (median {med:.4g}) differ from the equations' "
                        f"exponent ({lambda1:.4g}) by {ratio:.3g}x: they follow the divergence "
                        "on the signal's fastest time scale (embedding delay "
                        f"{time_scale:.3g}), not the attractor's; the equations' value is used"
                    )
    if lambda1 is not None:
        ev["lambda1"] = float(lambda1)
        ev["lambda1_err"] = float(lambda1_err)
    if k01 is not None:
        ev["k01"] = float(k01)
    n_distinct = None
    if section is not None:
        pts = np.atleast_2d(np.asarray(section, dtype=float))
        n_distinct = count_distinct_points(pts, rtol=section_rtol, scale=section_scale,
                                           max_extent=section_extent)  # fmt: skip
        ev["section_points"] = int(pts.shape[0])
        ev["section_distinct"] = int(n_distinct)
        if n_distinct <= max_periodic_points and not is_repeating_section(
            n_distinct, pts.shape[0], max_periodic_points
        ):
            reasons.append(f"section of {pts.shape[0]} point(s), {n_distinct} distinct: too "
                           "few to tell a periodic orbit from scatter (left out)")  # fmt: skip
            ev["section_inconclusive"] = True
            n_distinct = None
    if spectrum is not None:
        ev.update({f"spectrum_{k}": v for k, v in _line_structure(spectrum).items()})
    for key, limit, what, cause in (
        ("quarter_rms_ratio", MAX_RMS_RATIO, "RMS", "a decay, a run-up or a burst"),
        ("quarter_speed_ratio", MAX_SPEED_RATIO, "mean speed", "a run-up or a coast-down"),
    ):
        value = ev.get(key)
        if value is not None and not value <= limit:  # inf (a constant quarter) included
            reasons.insert(
                0,
                f"not stationary: the {what} of the record's quarters differs "
                f"{value:.3g}x (> {limit:g}; {cause}), and the exponents, the 0-1 "
                "test, the surrogates and the section all assume a stationary record",
            )
            return Verdict("undetermined", ev, reasons)
    # a lone positive signal estimate (unconfirmed) counts as a positive sign without a value
    unconfirmed = lambda1 is None and ev.get("signal_exponent_unconfirmed", False)
    pos = unconfirmed or (lambda1 is not None and lambda1 > max(lyap_tol, 2 * lambda1_err))
    flat = lambda1 == 0.0 and (k01 is None or k01 < 0.5)  # no divergence: noise never is
    if deterministic is False and not flat:
        regular = n_distinct is not None and n_distinct <= max_periodic_points
        lines = ev.get("spectrum_harmonic_fraction") == 1 and not pos
        if regular or (lines and lambda1 is not None):
            reasons.append("regular: few section points" if regular
                           else "flat divergence and harmonic spectral lines")  # fmt: skip
            return Verdict("periodic", ev, reasons)
        reasons.insert(0, "consistent with linearly correlated noise: not chaotic whatever the "
                       "exponent estimates say")  # fmt: skip
        return Verdict("stochastic", ev, reasons)
    if conflict:
        return Verdict("undetermined", ev, reasons)
    few = n_distinct is not None and n_distinct <= max_periodic_points
    if withheld and lambda1 is None:
        if few:
            reasons.append(f"{n_distinct} distinct section point(s): period-{n_distinct} orbit")
            return Verdict("periodic", ev, reasons)
        reasons.insert(0, "the exponent estimates from the signal contradict the other "
                       "evidence (below): no exponent, and no verdict of chaos")  # fmt: skip
        return Verdict("undetermined", ev, reasons)
    if pos and few:
        reasons.append(f"a positive exponent but {n_distinct} distinct section point(s): "
                       "conflicting evidence")  # fmt: skip
        return Verdict("undetermined", ev, reasons)
    unconfirmed_low = any(k.endswith("_withheld") and k.startswith("lambda1_") for k in ev)
    if all_refused and lambda1 is None:
        if deterministic and k01 is not None and k01 > 0.8 and not few and unconfirmed_low:
            # an exponent was estimated, below the positive limit and unconfirmed: the 0-1
            # test alone does not make it chaos (a ringing quasi-periodic machine signal
            # reads K ~ 0.9)
            reasons.append(f"0-1 test K = {k01:.2f} > 0.8, but the signal's exponent could "
                           "not be confirmed: no verdict of chaos")  # fmt: skip
            return Verdict("undetermined", ev, reasons)
        if deterministic and k01 is not None and k01 > 0.8 and not few:
            reasons.append(f"deterministic and 0-1 test K = {k01:.2f} > 0.8 (no exponent could "
                           "be estimated)")  # fmt: skip
            return Verdict("chaotic", ev, reasons)
        if not few:
            reasons.append("no exponent could be estimated from the signal")
            return Verdict("undetermined", ev, reasons)
        if k01 is not None and k01 > 0.5:  # the section is a few noisy points: K measures
            reasons.append(f"0-1 test K = {k01:.2f} on a section of {n_distinct} point(s): "
                           "the test sees the noise around them")  # fmt: skip
    if pos and (k01 is None or k01 > 0.5):
        reasons.append("largest Lyapunov exponent positive" + (
            " (the sign of a lone estimate; its value unconfirmed)" if unconfirmed
            else " beyond its uncertainty"))  # fmt: skip
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
        if any(k.endswith("_withheld") and k.startswith("lambda1_") for k in ev):
            # an exponent was estimated but could not be confirmed: the 0-1 test alone does
            # not make it chaos (a ringing quasi-periodic machine signal reads K ~ 0.9)
            reasons.append(f"0-1 test K = {k01:.2f} > 0.8, but the signal's exponent could "
                           "not be confirmed: no verdict of chaos")  # fmt: skip
            return Verdict("undetermined", ev, reasons)
        reasons.append(f"0-1 test K = {k01:.2f} > 0.8")
        return Verdict("chaotic", ev, reasons)
    if n_distinct is not None and n_distinct <= max_periodic_points:
        reasons.append(f"{n_distinct} distinct section point(s): period-{n_distinct} orbit")
        return Verdict("periodic", ev, reasons)
    if n_distinct is None and spectrum is not None and ev.get("spectrum_harmonic_fraction") == 1:
        reasons.append("all strong spectral lines are harmonics of one fundamental")
        if k01 is None or k01 < 0.5:
            return Verdict("periodic", ev, reasons)
    if lambda1 is None and k01 is None and n_distinct is None:
        reasons.append("a spectrum alone cannot tell quasi-periodic motion from chaos or noise "
                       "(its lines are not all harmonics of one fundamental)")  # fmt: skip
        return Verdict("undetermined", ev, reasons)
    if k01 is None or k01 < 0.5:
        if n_distinct is None and ev.get("spectrum_lines") == 0:  # nothing says "lines"
            reasons.append("no spectral line resolved (none above "
                           f"{MIN_FUNDAMENTAL_TOLS * HARMONIC_TOL_BINS:g} bins: a drift, or a "
                           "record shorter than a few periods)")  # fmt: skip
            return Verdict("stochastic" if deterministic is False else "undetermined", ev,
                           reasons)  # fmt: skip
        reasons.append("no positive exponent" if lambda1 is not None else "no exponent given")
        frac = ev.get("spectrum_harmonic_fraction")
        if n_distinct is None and frac is not None and frac < 1:
            reasons.append(f"{frac:.0%} of the strong spectral lines are harmonics of "
                           f"{ev['spectrum_fundamental_hz']:.4g} Hz")  # fmt: skip
        if k01 is not None:
            reasons.append(f"0-1 test K = {k01:.2f} < 0.5")
        return Verdict("quasi-periodic", ev, reasons)
    reasons.append("evidence insufficient or conflicting")
    return Verdict("undetermined", ev, reasons)
