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
    "CHANNEL_TEXT",
    "PRECISION_MIN",
    "ANSWERS_MIN",
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


def _limit(detection: dict, c: str) -> float:
    """The detection limit's severity of class ``c`` (1 + : never reached; 0: none)."""
    d = detection.get(c)
    if d is None:
        return 0.0
    s = d.get("limit_severity")
    return math.inf if s is None else float(s)


def naming_table(
    labels, predicted, severities, classes: list[str], detection: dict[str, dict]
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

    Returns
    -------
    dict
        ``accuracy``, ``n`` and, per class, ``precision`` (NaN without answers), ``recall``,
        ``answers`` (the answers counted), ``records``, ``set_aside`` (faults below their
        limit answered 'healthy') and ``behind`` (the true classes of its answers, most
        frequent first, with their counts), ``limit`` (the class's detection limit)."""
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
    return out


def gate(table: dict[str, Any] | None, subset: str, label: str) -> tuple[bool, str, dict]:
    """Whether the channel set ``subset`` may name ``label``: ``(named, reason, facts)``.

    ``facts`` (for the evidence): the channels, the channel set's held-out accuracy and the
    class's precision, recall and answers. A diagnoser without a table (trained before it
    was stored) names classes with all channels only: the per-class accuracy of its other
    channel sets was not kept."""
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
    behind = ", ".join(
        f"{c} {k}" for c, k in e.get("behind", []) if c != label
    )  # what else those answers were
    what = (
        f"on the held-out conditions, '{label}' from {facts['channels']} was right for "
        f"{0 if math.isnan(prec) else prec:.0%} of its {e.get('answers', 0)} answers"
        + (f" (the others: {behind})" if behind else "")
    )
    if e.get("answers", 0) < ANSWERS_MIN and not math.isnan(prec):
        what += f", too few answers to vouch for it (at least {ANSWERS_MIN})"
    elif math.isnan(prec):
        what = (
            f"'{label}' was never the answer from {facts['channels']} on the held-out conditions, "
            "so how often it is right is not measured"
        )
    advice = ADVICE.get(subset) or "these channels do not tell them apart"
    return (
        False,
        f"{what}: a fault the available channels cannot tell apart; {advice}",
        facts,
    )
