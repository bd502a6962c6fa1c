"""Which classes a record's channels can name: measured on held-out conditions, per channel set.

A diagnoser answers each record with the classifier of the channels the record has
(`AVAILABILITY`: all of them, no pressure, or the acceleration with a
constant speed). Those classifiers are not equally able: with the acceleration and a speed
only, the shipped diagnoser's held-out accuracy is 0.38, and a healthy record was called a worn
guide at p 0.88 with nothing to say that such an answer is right on a third of the records
only. So a class is **named only with the channels that can show it**: for every channel set
and every class the classifier may answer, the held-out conditions' records measure how
often that answer was right (its precision). A healthy answer is right where the
record is healthy or holds a fault milder than that fault's detection limit with those
channels (the diagnoser states it cannot see those, and the answer names them); a fault
answer is right only where the record holds that fault. An answer is given only where that
precision reaches `PRECISION_MIN` on at least `ANSWERS_MIN` held-out answers; otherwise the
record is refused, saying what the answers of that class were on the held-out records and
which channels would tell them apart. Every answer says which channels it used and the
measured precision and recall of its class with them.

**A class named above a confidence threshold** (selective classification: Chow 1970, the
reject option; Geifman & El-Yaniv 2017, a threshold on the top probability chosen for a
target risk). A class whose held-out answers fall short of `PRECISION_MIN` as a whole may
still be right often enough where the classifier was sure: the shipped diagnoser's
``sticking_valve`` answers with every channel were right for 79 % of 42, but for all 27 of
those at p >= 0.957 (the healthy machines and weak springs taken for it had p <= 0.952).
So the table keeps, per class, its held-out answers' top probabilities and whether each was
right, and `selective_threshold` gives the smallest threshold t_c for which the answers
at or above it reach the gate: a one-sided 95 % lower confidence bound on their precision
at least `PRECISION_MIN`, on at least `ANSWERS_MIN` answers. The class is then named for a
record whose top probability is at least t_c, and refused below it, saying which threshold
the class needed and the record's p.

*Why a lower bound and not the precision itself, and why Wilson's.* t_c is chosen on the
same held-out answers that vouch for it, and the precision above a threshold read off them
is biased upwards (the threshold lands where the answers happen to be right): a one-sided
lower bound at 95 % asks for enough answers that the precision is at least `PRECISION_MIN`
with that confidence (27 right answers of 27, 0.909, clears 0.9; 12 of 12, 0.816, does not).
The bound is Wilson's score interval (scipy's ``binomtest(...).proportion_ci``), whose
coverage is close to its nominal level for small counts (Brown, Cai & DasGupta 2001, who
recommend it for n < 40); Clopper-Pearson's exact bound guarantees at least the level but
is conservative there, and would ask for 29 right answers of 29 to clear 0.9, more than a
class gets on the default data set's 350 held-out records (about 40 a class). The
alternative of choosing t_c on half of the held-out conditions and checking it on the
other half leaves some 20 answers a half, too few to check 0.9 on. What the bound does not
correct is the choice among thresholds itself (the smallest that passes): the blind set
(`benchmarks/blind/`) measures what the gate does on records it did not see.

A class whose answers reach the gate as a whole keeps threshold 0 (no threshold is chosen
there, so the precision is read as it is: the gate as it was before). A diagnoser whose
stored table lacks the probabilities (trained before they were kept) keeps that gate for
every class.

References: C. K. Chow, "On optimum recognition error and reject tradeoff", IEEE Trans.
Inf. Theory 16 (1970) 41-46; Y. Geifman, R. El-Yaniv, "Selective classification for deep
neural networks", NeurIPS 2017; L. D. Brown, T. T. Cai, A. DasGupta, "Interval estimation
for a binomial proportion", Statistical Science 16 (2001) 101-133.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .evidence import feature_groups

__all__ = [
    "AVAILABILITY",
    "available",
    "naming_table",
    "gate",
    "selective_threshold",
    "CHANNEL_TEXT",
    "PRECISION_MIN",
    "ANSWERS_MIN",
    "CONFIDENCE",
]

#: Feature subsets by the channels a record has.
AVAILABILITY = {
    "full": ("base", "angle", "pressure", "cycle"),
    "no_pressure": ("base", "angle"),
    "vibration_only": ("base",),
}


def available(row: np.ndarray, names: list[str]) -> str:
    """Which availability subset a feature row has (`AVAILABILITY`)."""
    groups = feature_groups(names)
    idx = {n: i for i, n in enumerate(names)}
    has = {g for g, cols in groups.items() if np.isfinite(row[[idx[c] for c in cols]]).any()}
    for name, keep in AVAILABILITY.items():
        if set(keep) <= has:
            return name
    return "vibration_only"


def _cols(names, subset: str) -> np.ndarray:
    groups = feature_groups(names)
    keep = [n for g in AVAILABILITY[subset] for n in groups[g]]
    return np.array([names.index(n) for n in keep])


#: What each channel set of `recipdyn.diagnosis.train.AVAILABILITY` is, in words.
CHANNEL_TEXT = {
    "full": "the acceleration, the tacho and both chamber pressures",
    "no_pressure": "the acceleration and the tacho (no pressure)",
    "vibration_only": "the acceleration and a constant speed (no tacho, no pressure)",
}
#: What to add to a channel set to tell more classes apart.
ADVICE = {
    "full": "",
    "no_pressure": "record the head- and crank-end chamber pressures",
    "vibration_only": "record a once-per-revolution tacho and the two chamber pressures",
}
#: The share of a class's held-out answers that must be right for a channel set to name it.
PRECISION_MIN = 0.9
#: The fewest held-out answers of a class from which its precision is read.
ANSWERS_MIN = 10
#: The one-sided confidence of the lower bound on the precision above a class's threshold.
CONFIDENCE = 0.95
#: Decimals the answers' top probabilities are kept to (and a record's compared at).
P_DIGITS = 6


def _limit(detection: dict, c: str) -> float:
    """The detection limit's severity of class ``c`` (1 + : never reached; 0: none)."""
    d = detection.get(c)
    if d is None:
        return 0.0
    s = d.get("limit_severity")
    return math.inf if s is None else float(s)


def naming_table(
    labels,
    predicted,
    severities,
    classes: list[str],
    detection: dict[str, dict],
    top=None,
) -> dict[str, Any]:
    """Per class the classifier answered: the held-out records behind those answers, their
    precision and the class's recall, for one channel set.

    Parameters
    ----------
    labels, predicted : arrays of str
        True and predicted class of each held-out record.
    severities : array
        Each record's severity (0 for the healthy machine).
    classes : list of str
    detection : dict
        The channel set's detection limits (`recipdyn.diagnosis.train.detection_limits`):
        a fault below its class's limit answered 'healthy' is set aside from the healthy
        answer's precision (the channels cannot see it; the answer says so).
    top : array, optional
        Each record's top-class probability (that of its predicted class): kept per class
        for its counted answers (``p``, highest first, to `P_DIGITS` decimals, and ``right``,
        1 where that answer was right), from which `selective_threshold` reads the class's
        confidence threshold. Without it the table has neither, and the gate names a class
        on its whole precision only.

    Returns
    -------
    dict
        ``accuracy``, ``n`` and, per class, ``precision`` (NaN without answers), ``recall``,
        ``answers`` (the answers counted), ``records``, ``set_aside`` (faults below their
        limit answered 'healthy') and ``behind`` (the true classes of its answers, most
        frequent first, with their counts), ``limit`` (the class's detection limit) and,
        given ``top``, ``p`` and ``right``."""
    y = np.asarray(labels).astype(str)
    yp = np.asarray(predicted).astype(str)
    s = np.asarray(severities, float)
    below = np.array(
        [c != "healthy" and sev < _limit(detection, c) for c, sev in zip(y, s, strict=True)]
    )
    out: dict[str, Any] = {"accuracy": float(np.mean(y == yp)), "n": int(y.size), "classes": {}}
    for c in classes:
        ans = yp == c
        # a fault below its detection limit answered 'healthy' is one the channels cannot see
        # (the limit says so); answered as another fault, it is a wrong answer like any other
        aside = ans & below & (y != c) & (c == "healthy")
        counted = ans & ~aside
        right = counted & (y == c)
        kinds, counts = np.unique(y[counted], return_counts=True)
        order = np.argsort(-counts)
        lim = _limit(detection, c)
        out["classes"][c] = {
            "precision": float(right.sum() / counted.sum()) if counted.any() else math.nan,
            "recall": float(np.mean(yp[y == c] == c)) if (y == c).any() else math.nan,
            "answers": int(counted.sum()),
            "records": int((y == c).sum()),
            "set_aside": int(aside.sum()),
            "behind": [[str(kinds[i]), int(counts[i])] for i in order],
            "limit": None if not math.isfinite(lim) else lim,
        }
        if top is not None:
            p = np.round(np.asarray(top, float)[counted], P_DIGITS)
            order = np.argsort(-p, kind="stable")
            out["classes"][c]["p"] = [float(v) for v in p[order]]
            out["classes"][c]["right"] = [int(v) for v in (y[counted] == c)[order]]
    return out


def _lower_bound(right: int, n: int) -> float:
    """One-sided `CONFIDENCE` lower bound on a precision of ``right`` of ``n`` (Wilson)."""
    from scipy.stats import binomtest

    return float(binomtest(right, n, alternative="greater").proportion_ci(CONFIDENCE, "wilson").low)


def selective_threshold(entry: dict[str, Any]) -> dict[str, Any] | None:
    """The confidence threshold of one class of a naming table (`naming_table`'s entry).

    Returns ``None`` when the entry holds no probabilities (a table of an older diagnoser);
    otherwise a dict: ``threshold`` (0 where the class's answers reach the gate as a whole:
    `PRECISION_MIN` on `ANSWERS_MIN` answers; else the smallest top probability t of its
    held-out answers for which those at or above t have a one-sided `CONFIDENCE` Wilson
    lower bound on their precision of at least `PRECISION_MIN` on at least `ANSWERS_MIN`
    answers; ``None`` if no threshold does), ``answers`` and ``right`` (the held-out
    answers at or above it), ``precision`` and ``lower`` (its lower bound; for threshold 0,
    the whole precision's, for information). Where no threshold passes, the numbers are
    those of the threshold whose lower bound came closest.

    Notes
    -----
    Only the answers' own probabilities are tried as thresholds (the precision above t
    changes only there); "at or above" (``p >= t``) for the held-out answers and a record
    alike, both to `P_DIGITS` decimals.
    """
    if "p" not in entry or "right" not in entry:
        return None
    p = np.asarray(entry["p"], float)
    ok = np.asarray(entry["right"], int)
    order = np.argsort(-p, kind="stable")
    p, ok = p[order], ok[order]
    n = int(p.size)
    k = int(ok.sum())
    if n >= ANSWERS_MIN and k / n >= PRECISION_MIN:
        lo = _lower_bound(k, n)
        return {"threshold": 0.0, "answers": n, "right": k, "precision": k / n, "lower": lo}
    cum = np.cumsum(ok)
    best: dict[str, Any] | None = None
    # from the lowest threshold up: the first that passes is the smallest
    for i in range(n - 1, ANSWERS_MIN - 2, -1):
        if i + 1 < n and p[i + 1] == p[i]:
            continue  # ties: a threshold takes every answer at its p
        m, r = i + 1, int(cum[i])
        if r / m < PRECISION_MIN:
            continue  # the bound lies below the precision itself
        lo = _lower_bound(r, m)
        cand = {"threshold": float(p[i]), "answers": m, "right": r, "precision": r / m,
                "lower": lo}  # fmt: skip
        if lo >= PRECISION_MIN:
            return cand
        if best is None or lo > best["lower"]:
            best = cand
    if best is None:  # no threshold reaches even the point precision
        return {"threshold": None, "answers": n, "right": k,
                "precision": k / n if n else math.nan, "lower": math.nan}  # fmt: skip
    return {**best, "threshold": None, "closest": best["threshold"]}


def gate(
    table: dict[str, Any] | None, subset: str, label: str, p: float | None = None
) -> tuple[bool, str, dict]:
    """Whether the channel set ``subset`` may name ``label``: ``(named, reason, facts)``.

    ``p``: the record's probability of ``label`` (its top class). Where the table keeps the
    held-out answers' probabilities, a class whose answers fall short of `PRECISION_MIN` as
    a whole is named for a record at or above its `selective_threshold`, and refused below
    it, saying which threshold it needed and the record's p; without ``p`` or those
    probabilities, a class is named on its whole precision only.

    ``facts`` (for the evidence): the channels, the channel set's held-out accuracy and the
    class's precision, recall and answers; with a threshold (``confidence``): the threshold,
    the precision of the held-out answers at or above it, their number, its lower bound and
    the record's p. A diagnoser without a table (trained before it was stored) names classes
    with all channels only: the per-class accuracy of its other channel sets was not kept."""
    facts: dict[str, Any] = {"channels": CHANNEL_TEXT.get(subset, subset), "subset": subset}
    if not table or subset not in table:
        if subset == "full":
            facts["measured"] = False
            return True, "", facts
        return (
            False,
            f"this diagnoser holds no per-class evaluation of records with {facts['channels']}, "
            f"so it cannot say which classes they tell apart; retrain it ('recipdyn train') "
            f"or {ADVICE.get(subset, 'record more channels')}",
            facts,
        )
    t = table[subset]
    e = dict(t["classes"].get(label, {}))
    for k in ("precision", "recall"):  # NaN (no answers, no records) is null in JSON
        e[k] = math.nan if e.get(k) is None else e[k]
    facts.update(
        measured=True,
        accuracy=t["accuracy"],
        n=t["n"],
        precision=e.get("precision", math.nan),
        recall=e.get("recall", math.nan),
        answers=e.get("answers", 0),
        set_aside=e.get("set_aside", 0),
    )
    prec = e.get("precision", math.nan)
    if e.get("answers", 0) >= ANSWERS_MIN and prec >= PRECISION_MIN:
        return True, "", facts
    sel = selective_threshold(e) if p is not None else None
    thr = None if sel is None else sel["threshold"]
    if thr is not None:
        p_rec = round(float(p), P_DIGITS)
        facts["confidence"] = {
            "threshold": thr,
            "p": float(p),
            "precision": sel["precision"],
            "answers": sel["answers"],
            "lower": sel["lower"],
            "confidence": CONFIDENCE,
        }
        if p_rec >= thr:
            return True, "", facts
    behind = ", ".join(
        f"{c} {k}" for c, k in e.get("behind", []) if c != label
    )  # what else those answers were
    what = (
        f"on the held-out conditions, '{label}' from {facts['channels']} was right for "
        f"{0 if math.isnan(prec) else prec:.0%} of its {e.get('answers', 0)} answers"
        + (f" (the others: {behind})" if behind else "")
    )
    if thr is not None:  # sure enough above a threshold, and this record is below it
        return (
            False,
            f"{what}, and for {sel['precision']:.0%} of the {sel['answers']} at p >= "
            f"{thr:.3f} ({CONFIDENCE:.0%} lower bound {sel['lower']:.2f}); this record's "
            f"p {float(p):.3f} is below that threshold: not sure enough to name it with "
            f"{facts['channels']}",
            facts,
        )
    if e.get("answers", 0) < ANSWERS_MIN and not math.isnan(prec):
        what += f", too few answers to vouch for it (at least {ANSWERS_MIN})"
    elif math.isnan(prec):
        what = (
            f"'{label}' was never the answer from {facts['channels']} on the held-out conditions, "
            "so how often it is right is not measured"
        )
    elif sel is not None:  # no threshold vouches for it either
        what += (
            f", at no confidence threshold {PRECISION_MIN:.0%} with {CONFIDENCE:.0%} "
            f"confidence on {ANSWERS_MIN} answers or more"
        )
        if sel.get("closest") is not None:
            what += (
                f" (closest: {sel['right']} of {sel['answers']} at p >= {sel['closest']:.3f}, "
                f"lower bound {sel['lower']:.2f})"
            )
    advice = ADVICE.get(subset) or "these channels do not tell them apart"
    return (
        False,
        f"{what}: a fault the available channels cannot tell apart; {advice}",
        facts,
    )
