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


@pytest.mark.parametrize("start", [0.0, -0.37, 0.004])
def test_windows_are_whole_revolutions_of_the_data_sets_length(start):
    """6 revolutions after a record's first whole one: 3 windows of 2, each read by the
    features as exactly 2 whole revolutions (evidence._whole_revs), starting at a whole
    revolution, back to back (each ends at the sample nearest its last revolution's end,
    which is the next window's first)."""
    r = _revs(start, np.ceil(start) + 6.0)
    sl = window_slices(r, 2)
    assert len(sl) == 3
    first = np.ceil(start - 2 * F_REV / FS)
    for i, s in enumerate(sl):
        w = r[s]
        _, n_revs, w0 = _whole_revs(w)
        assert n_revs == 2 and w0 == first + 2 * i
        assert abs(w[0] - w0) <= 0.5 * F_REV / FS + 1e-12
    for a, b in zip(sl, sl[1:], strict=False):
        assert b.start == a.stop - 1


def test_a_record_of_fewer_than_two_windows_is_scored_whole():
    """3.5 revolutions hold one window of 2: the record is scored whole (no windows); so is a
    window length that is not a whole number of revolutions."""
    assert WINDOWS_MIN == 2
    assert window_slices(_revs(0.0, 3.5), 2) == []
    assert window_slices(_revs(0.0, 4.0), 2) != []
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
