"""0-1 test for chaos and the verdict helper."""

import numpy as np
import pytest

from recipdyn.analysis import amplitude_spectrum, classify, zero_one_test
from recipdyn.model.reference.systems import iterate, logistic_map


@pytest.mark.parametrize("r, chaotic", [(3.97, True), (4.0, True), (3.5, False), (3.83, False)])
def test_logistic_map(r, chaotic):
    """K ~ 1 for chaotic logistic maps, K ~ 0 for periodic windows (period 4, period 3)."""
    x = iterate(logistic_map(r), [0.3], 2000, 500)[:, 0]
    K = zero_one_test(x)
    assert (K > 0.9) if chaotic else (abs(K) < 0.1)


def test_classify():
    """Chaotic (positive exponent + K), periodic (one section point / harmonic lines),
    quasi-periodic (zero exponent, closed curve)."""
    assert classify(lambda1=0.9, lambda1_err=0.05, k01=0.99).verdict == "chaotic"
    v = classify(lambda1=0.0, k01=0.01, section=np.ones((50, 2)))
    assert v.verdict == "periodic" and v.evidence["section_distinct"] == 1
    th = np.linspace(0, 2 * np.pi, 200, endpoint=False) * np.sqrt(2) * 37 % (2 * np.pi)
    circle = np.c_[np.cos(th), np.sin(th)]
    assert classify(lambda1=0.001, k01=0.05, section=circle).verdict == "quasi-periodic"
    t = np.arange(8000) / 100.0
    spec = amplitude_spectrum(np.sin(2 * np.pi * t) + 0.3 * np.sin(4 * np.pi * t), 100.0)
    assert classify(spectrum=spec).verdict == "periodic"
    assert classify(lambda1=0.5, k01=0.02).verdict == "undetermined"
    assert "verdict" in classify(lambda1=0.9, k01=0.99).to_dict()


def test_spectrum_alone_does_not_make_noise_quasi_periodic():
    """A broadband spectrum is no evidence of quasi-periodic motion (the old spectrum-only
    rule called every broadband signal quasi-periodic): undetermined, with the reason; a
    harmonic line spectrum alone still says periodic."""
    x = np.random.default_rng(0).standard_normal(8000)
    v = classify(spectrum=amplitude_spectrum(x, 100.0))
    assert v.verdict == "undetermined" and "spectrum alone" in v.reasons[-1]
