"""Amplitude spectrum scaling and peak labelling."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from recipdyn.analysis import amplitude_spectrum, find_spectral_peaks, order_spectrum


@pytest.mark.parametrize("window", ["hann", "hamming", "blackmanharris", "boxcar"])
def test_sum_of_sines_amplitudes_and_frequencies(window):
    """Bin-centred sines of amplitudes 3, 1.5, 0.25 show peaks of those heights (to 1e-6 rel)
    at their frequencies (exactly, on the bin grid)."""
    fs, n = 1000.0, 10_000
    t = np.arange(n) / fs
    comps = [(3.0, 3.2), (1.5, 6.4), (0.25, 113.5)]
    x = sum(a * np.sin(2 * np.pi * f * t + 0.3) for a, f in comps) + 7.0
    spec = amplitude_spectrum(x, fs, window=window)
    assert spec.resolution == pytest.approx(0.1)
    for a, f in comps:
        i = int(round(f / spec.resolution))
        assert spec.frequency[i] == pytest.approx(f)
        assert spec.amplitude[i] == pytest.approx(a, rel=1e-6)


@settings(max_examples=25, deadline=None)
@given(amp=st.floats(0.01, 100.0), k=st.integers(5, 400))
def test_scaling_property(amp, k):
    """Any bin-centred sine's peak equals its amplitude (Hann window)."""
    fs, n = 2000.0, 4000
    f = k * fs / n
    x = amp * np.cos(2 * np.pi * f * np.arange(n) / fs)
    spec = amplitude_spectrum(x, fs)
    assert spec.amplitude.max() == pytest.approx(amp, rel=1e-9)
    assert spec.frequency[np.argmax(spec.amplitude)] == pytest.approx(f)


def test_flattop_between_bins():
    """Off-bin: the flat-top window keeps the amplitude error below 0.1 %."""
    fs, n = 1000.0, 5000
    x = 2.0 * np.sin(2 * np.pi * 50.07 * np.arange(n) / fs)
    assert amplitude_spectrum(x, fs, window="flattop").amplitude.max() == pytest.approx(
        2.0, rel=1e-3
    )


def test_peaks_are_labelled_as_crank_harmonics():
    fs, n = 2000.0, 20_000
    t = np.arange(n) / fs
    fc = 20 / (2 * np.pi)
    x = (
        50 * np.cos(2 * np.pi * fc * t)
        + 10 * np.cos(4 * np.pi * fc * t)
        + 3 * np.sin(2 * np.pi * 113.5 * t)
    )
    peaks = find_spectral_peaks(amplitude_spectrum(x, fs), n=3, fundamental=fc)
    assert [p.order for p in peaks] == [1, 2, 0]
    assert peaks[2].frequency == pytest.approx(113.5, abs=0.1)
    orders, _ = order_spectrum(amplitude_spectrum(x, fs), fc)
    assert orders[1] == pytest.approx(0.1 / fc)


def test_bad_input():
    with pytest.raises(ValueError, match="fs"):
        amplitude_spectrum(np.ones(10), 0.0)
    with pytest.raises(ValueError, match="1-D"):
        amplitude_spectrum(np.ones((3, 3)), 1.0)
