"""A record longer than the data set's is scored on windows of its length
(recipdyn.diagnosis.windows)."""

from __future__ import annotations

import numpy as np
import pytest

from recipdyn.diagnosis.evidence import _whole_revs
from recipdyn.diagnosis.windows import WINDOWS_MIN, WindowScores, window_slices

FS = 10240.0
F_REV = 3.2  # Hz


def _revs(start: float, stop: float) -> np.ndarray:
    """The crank angle (revolutions) of samples at `FS` from ``start`` to ``stop``."""
    n = int((stop - start) / F_REV * FS) + 1
    return start + np.arange(n) * F_REV / FS


@pytest.mark.parametrize(("start", "whole"), [(0.0, 6), (-0.37, 5), (0.004, 5)])
def test_windows_are_whole_revolutions_of_the_data_sets_length(start, whole):
    """A record of 6 revolutions holds ``whole`` whole ones, and whole - 1 windows of 2, one
    revolution apart, each read by the features as exactly 2 whole revolutions
    (evidence._whole_revs) starting at its own whole revolution, its first sample within half
    a sample of it. A record starting 0.004 revolutions (1.4 degrees, as a crank-angle
    correction moves it) after a whole one holds one whole revolution fewer, and keeps its
    windows."""
    r = _revs(start, start + 6.0)
    sl = window_slices(r, 2)
    first = np.ceil(start - 2 * F_REV / FS)
    assert len(sl) == whole - 1
    for i, s in enumerate(sl):
        w = r[s]
        _, n_revs, w0 = _whole_revs(w)
        assert n_revs == 2 and w0 == first + i
        assert abs(w[0] - w0) <= 0.5 * F_REV / FS + 1e-12


def test_a_record_of_fewer_than_two_windows_is_scored_whole():
    """2.9 whole revolutions hold one window of 2: the record is scored whole (no windows);
    3 hold two; a window length that is not a whole number of revolutions gives none."""
    assert WINDOWS_MIN == 2
    assert window_slices(_revs(0.0, 2.9), 2) == []
    assert len(window_slices(_revs(0.0, 3.0), 2)) == 2
    assert window_slices(_revs(0.0, 8.0), 2.5) == []
    assert window_slices(_revs(0.0, 8.0), 0) == []


def test_the_gate_reads_the_lowest_window_and_the_answer_their_mean():
    """Each window is a record of the length the class's threshold was measured at: the class
    is named only where every window clears it, so the gate's p is the lowest window's."""
    proba = np.array([[0.1, 0.9], [0.4, 0.6], [0.02, 0.98]])
    w = WindowScores(proba, 2.0, ["healthy", "sticking_valve"])
    assert w.mean == pytest.approx([0.52 / 3, 2.48 / 3])
    assert w.gate_p(1) == pytest.approx(0.6)
    ev = w.evidence(1)
    assert ev["n"] == 3 and ev["labels"] == ["sticking_valve"] * 3
    assert ev["p"] == pytest.approx([0.9, 0.6, 0.98])
