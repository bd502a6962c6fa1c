"""A record longer than the data set's, scored on windows of the data set's length.

The confidence thresholds of `recipdyn.diagnosis.channels` are measured on held-out records
of the data set's length (2 revolutions for the shipped diagnoser): the precision of a
class's answers at ``p >= t`` holds for records of that length. A longer record makes the
classifier surer of its answer, wrong answers included: its features are averaged over more
revolutions, so they lie further inside whichever class's region they fall in. A held-out
healthy record answered ``sticking_valve`` at p 0.60 over 2 revolutions gave 0.96 over 4,
above that class's threshold 0.957: the threshold does not transfer to a record that is not
of the length it was measured on (a user's record of 10 revolutions, say).

So a record holding at least two windows of the data set's length is scored **on its
windows**: stretches of that many whole revolutions, one revolution apart (a record of W
whole revolutions holds W - L + 1 windows of L), each read and classified as a record of
the data set. The answer is the class of the windows' mean probabilities (`scores`), and
the class is named only where **every** window's probability of it reaches the class's
threshold: the gate reads the lowest of them (`WindowScores.gate_p`). Why the lowest: each
window is a record of the length the threshold was measured on, so the probability that a
wrong class clears it in every window is at most the probability that it clears it in one,
which is what the held-out table measured (the windows of one record are not independent,
and they overlap, so no more than that is claimed). Averaging the windows alone would not
bound it: a class whose wrong answers have a mean probability above the threshold would
clear it more often on average.

A record of fewer than two windows (fewer than L + 1 whole revolutions) is scored whole:
it is of the data set's length. Everything else the diagnosis reads (the chain, the
domain, the physics consistency, the severity) is read on the whole record.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["window_slices", "WindowScores", "scores", "WINDOWS_MIN"]

#: The fewest windows of the data set's length a record must hold to be scored by windows
#: (one window is the record itself).
WINDOWS_MIN = 2


def window_slices(revs, revolutions: float) -> list[slice]:
    """Sample ranges of ``revolutions`` whole revolutions each, one revolution apart.

    ``revs``: the crank angle in revolutions at each sample (finite, increasing). The whole
    revolutions are those the features count (`recipdyn.diagnosis.evidence._whole_revs`:
    from the first whole revolution, a sample or two short still covering one); a record of
    W of them holds W - ``revolutions`` + 1 windows, the i-th starting at the i-th whole
    revolution (so a record that the crank-angle correction moved by a degree, and that
    holds one whole revolution fewer than its tacho pulses, keeps its windows). Each runs
    from the sample nearest its first revolution's start to the sample nearest its last
    one's end. Empty if fewer than `WINDOWS_MIN` windows fit, or ``revolutions`` is not a
    positive whole number.
    """
    r = np.asarray(revs, float)
    L = float(revolutions)
    if r.size < 2 or not (L >= 1 and L == math.floor(L)) or not np.isfinite(r).all():
        return []
    from .evidence import _whole_revs

    _, whole, start = _whole_revs(r)  # the whole revolutions the features count
    step = abs(r[1] - r[0])
    k = int(whole - L) + 1
    if k < WINDOWS_MIN:
        return []
    out = []
    for i in range(k):
        a, b = start + i, start + i + L
        # from the sample nearest the window's first revolution to the one nearest its end
        i0 = int(np.searchsorted(r, a - step / 2))
        i1 = min(int(np.searchsorted(r, b - step / 2)) + 1, r.size)
        out.append(slice(i0, i1))
    return out


@dataclass
class WindowScores:
    """The class probabilities of a record's windows (rows: windows; columns: classes)."""

    proba: np.ndarray
    revolutions: float
    classes: list[str]

    @property
    def mean(self) -> np.ndarray:
        """The windows' mean probabilities: the record's answer is their largest."""
        return self.proba.mean(axis=0)

    def gate_p(self, k: int) -> float:
        """The probability of class ``k`` the confidence gate reads: its lowest window's."""
        return float(self.proba[:, k].min())

    def evidence(self, k: int) -> dict:
        """The windows in the answer's evidence: their length, number, each window's
        probability of the class named and each window's own top class."""
        top = np.argmax(self.proba, axis=1)
        return {
            "revolutions": self.revolutions,
            "n": int(self.proba.shape[0]),
            "p": [float(v) for v in self.proba[:, k]],
            "labels": [self.classes[int(j)] for j in top],
        }


def scores(diag, x, fs: float, revs, *, p_head=None, p_crank=None, angle: bool = True,
           machine=None, baseline=None) -> WindowScores | None:  # fmt: skip
    """Score the record on its windows of the data set's length (`window_slices`).

    ``diag``: the diagnoser (its data card's ``revolutions`` is the window's length);
    ``x``, ``revs``, ``p_head``, ``p_crank``: the record as the diagnosis reads it (cut to
    its whole crank angle, its chain corrected); ``machine``: the changes of the machine the
    cycle features are read against; ``baseline``: the machine's own healthy baseline, whose
    reference the windows' features are referred to as the record's are. None for a record
    of fewer than `WINDOWS_MIN` windows (it is scored whole)."""
    from .evidence import record_features

    L = float(diag.card["spec"].get("revolutions", 0) or 0)
    sl = window_slices(revs, L)
    if not sl:
        return None
    rows = []
    for s in sl:
        row = record_features(
            x[s],
            fs,
            revs[s],
            angle=angle,
            p_head=None if p_head is None else p_head[s],
            p_crank=None if p_crank is None else p_crank[s],
            machine=machine,
        )
        rows.append([row[n] for n in diag.names])
    X = np.array(rows, float)
    if baseline is not None:
        X = baseline.refer(X, diag.names)
    return WindowScores(np.asarray(diag.predict_proba(X), float), L, list(diag.classes))
