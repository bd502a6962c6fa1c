"""The vibration engineer's toolkit (issue 12, item 4) against closed forms: each test builds a
signal whose answer is known exactly and checks the tool recovers it."""

import numpy as np
import pytest

from recipdyn.analysis import vibration as V

FS = 20_000.0


def _runup(seconds=4.0, f0=5.0, f1=15.0):
    """Crank speed ramping linearly f0 -> f1 (Hz): angle in revolutions, and a square
    once-per-revolution tacho (10 % duty) with edges at whole revolutions."""
    t = np.arange(int(seconds * FS)) / FS
    revs = f0 * t + 0.5 * (f1 - f0) / seconds * t**2
    tacho = ((revs % 1.0) < 0.1).astype(float) * 5.0 + 0.01 * np.sin(2 * np.pi * 3e3 * t)
    return t, revs, tacho


def test_tacho_edges_and_angle():
    """Edges at whole revolutions of a ramp to within a tenth of a sample (linear
    interpolation of a step over one sample: error <= 1/fs); the interpolated angle within
    2e-3 revolution (PCHIP through exact pulse times of a smooth speed)."""
    t, revs, tacho = _runup()
    edges = V.tacho_times(tacho, FS)
    true = np.array([
        (-5.0 + np.sqrt(25.0 + 2 * 2.5 * k)) / 2.5 for k in range(1, int(revs[-1]) + 1)
    ])  # fmt: skip
    assert edges.size == true.size
    assert np.max(np.abs(edges - true)) <= 1.0 / FS
    ang = V.crank_angle(t.size, FS, pulses=edges, zero_rev=1.0)
    ok = np.isfinite(ang)
    assert np.max(np.abs(ang[ok] - revs[ok])) < 2e-3
    assert np.isnan(ang[0])  # before the first pulse: unknown


def test_narrow_keyphasor_pulses_are_found():
    """A notch pulse over 2 % of a revolution (narrower than the 5 % percentile band) gives the
    same edges as a wide pulse: the levels fall back to the minimum and maximum."""
    t, revs, _ = _runup()
    narrow = ((revs % 1.0) < 0.02).astype(float)
    wide = ((revs % 1.0) < 0.2).astype(float)
    e_narrow, e_wide = V.tacho_times(narrow, FS), V.tacho_times(wide, FS)
    assert e_narrow.size == e_wide.size == int(revs[-1])
    np.testing.assert_allclose(e_narrow, e_wide, rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match="flat"):
        V.tacho_times(np.ones(1000), FS)


def test_order_spectrum_is_sharp_during_a_runup():
    """Order 3 and order 7.5 components (amplitudes 1 and 0.4) during a 5 -> 15 Hz run-up: in
    the angle domain each is one line of its amplitude (within 2 %, Hann window on whole
    revolutions), while the time-domain spectrum spreads order 3 over 15-45 Hz (its highest
    bin below 0.2)."""
    t, revs, _ = _runup()
    x = np.sin(2 * np.pi * 3 * revs) + 0.4 * np.sin(2 * np.pi * 7.5 * revs)
    grid, xa = V.angle_resample(x, revs, 128)
    xa = xa[: xa.size // 256 * 256]  # an even number of revolutions: order 7.5 on a bin
    spec = V.order_spectrum_angle(xa, 128)
    for order, amp in ((3.0, 1.0), (7.5, 0.4)):
        k = np.argmin(np.abs(spec.frequency - order))
        assert spec.amplitude[k] == pytest.approx(amp, rel=0.02)
    from recipdyn.analysis import amplitude_spectrum

    s = amplitude_spectrum(x, FS)
    band = (s.frequency > 10) & (s.frequency < 50)
    assert s.amplitude[band].max() < 0.2


def test_campbell_ridge_follows_the_order():
    """The strongest frequency of each STFT frame of the order-3 run-up lies within two bins
    of 3 x the frame's speed."""
    t, revs, _ = _runup()
    x = np.sin(2 * np.pi * 3 * revs)
    f, speed, A = V.campbell(x, FS, revs, nperseg=8192)
    df = f[1] - f[0]
    peak = f[np.argmax(A, axis=1)]
    assert np.all(np.abs(peak - 3 * speed) <= 2 * df)


def test_envelope_spectrum_finds_the_impact_rate():
    """Bursts of a 4 kHz resonance (decay 2 ms) repeated at 37 Hz, buried in noise of the
    same RMS: the envelope spectrum's largest line below 200 Hz is at 37 Hz (within one bin);
    the plain spectrum has nothing there."""
    rng = np.random.default_rng(0)
    t = np.arange(int(2.0 * FS)) / FS
    phase = (t * 37.0) % 1.0 / 37.0
    x = np.exp(-phase / 2e-3) * np.sin(2 * np.pi * 4000 * t)
    x += rng.standard_normal(t.size) * x.std()
    spec, env = V.envelope_spectrum(x, FS, band=(2500, 6000))
    low = (spec.frequency > 5) & (spec.frequency < 200)
    found = spec.frequency[low][np.argmax(spec.amplitude[low])]
    assert found == pytest.approx(37.0, abs=spec.resolution)


def test_cepstrum_finds_an_echo():
    """x(t) + 0.5 x(t - 7.3 ms) of white noise: the cepstrum's peak (beyond 1 ms) is at the
    echo delay, to one sample."""
    rng = np.random.default_rng(1)
    s = rng.standard_normal(40_000)
    d = int(round(7.3e-3 * FS))
    x = s.copy()
    x[d:] += 0.5 * s[:-d]
    q, c = V.cepstrum(x, FS, window="boxcar")
    far = q > 1e-3
    assert q[far][np.argmax(c[far])] == pytest.approx(d / FS, abs=1.0 / FS)


def test_velocity_rms_closed_form():
    """An acceleration A sin(2 pi f t) has velocity RMS A / (2 pi f sqrt 2); a 0.5 Hz and a
    3 kHz component outside ISO 20816-8's 2-1000 Hz band do not count (whole periods in the
    record, so no leakage: agreement to 1e-9)."""
    t = np.arange(int(10 * FS)) / FS
    a = 3.0 * np.sin(2 * np.pi * 50 * t) + 7.0 * np.sin(2 * np.pi * 0.5 * t)
    a += 2.0 * np.sin(2 * np.pi * 3000 * t)
    expected = 3.0 / (2 * np.pi * 50 * np.sqrt(2))
    assert V.velocity_rms(a, FS) == pytest.approx(expected, rel=1e-9)
    assert V.band_rms(a, FS, (1000, 5000)) == pytest.approx(2.0 / np.sqrt(2), rel=1e-9)


def test_zones_and_indicators():
    assert [V.zone(v, (1.0, 2.0, 4.0)) for v in (0.5, 1.0, 3.0, 9.0)] == ["A", "B", "C", "D"]
    with pytest.raises(ValueError, match="increasing"):
        V.zone(1.0, (2.0, 1.0, 3.0))
    t = np.arange(100_000) / FS
    ind = V.indicators(np.sin(2 * np.pi * 50 * t))
    assert ind["crest_factor"] == pytest.approx(np.sqrt(2), rel=1e-6)
    assert ind["kurtosis"] == pytest.approx(1.5, rel=1e-6)
    g = V.indicators(np.random.default_rng(2).standard_normal(400_000))
    assert g["kurtosis"] == pytest.approx(3.0, abs=0.05)  # sd of the estimate ~ sqrt(24/N)


def test_impacts_per_revolution_at_their_crank_angles():
    """Two impacts per revolution at 40 deg and 220 deg of the crank, 10 Hz, 3 s, noise 10 %
    of the burst peak: 2 x 29-30 impacts found, each within 1 deg of its angle, none
    spurious."""
    rng = np.random.default_rng(3)
    t = np.arange(int(3.0 * FS)) / FS
    revs = 10.0 * t
    x = 0.1 * rng.standard_normal(t.size)
    for deg in (40.0, 220.0):
        tau = ((revs - deg / 360.0) % 1.0) / 10.0  # time since the impact, s
        x += np.exp(-tau / 1e-3) * np.sin(2 * np.pi * 5000 * tau) * (revs >= deg / 360.0)
    hits = V.detect_impacts(x, FS, revs=revs, band=(3000, 8000))
    angles = np.array([h.angle_deg for h in hits])
    near40 = np.abs(angles - 40.0) < 1.0
    near220 = np.abs(angles - 220.0) < 1.0
    assert np.all(near40 | near220)
    assert 29 <= near40.sum() <= 30 and 29 <= near220.sum() <= 30


# ---- the tacho edge detector over widths, polarities, noise, jitter and speeds ---------------


def _pulse_train(fs, speed_hz, width_deg, polarity, noise, jitter_deg, seed, revs=3.4):
    """An independent pulse train (not recipdyn.sensors'): a crank at ``speed_hz`` with a 5 %
    speed ripple, a pulse of ``width_deg`` from each mark ``2 pi k + delta_k`` (``delta_k``
    Gaussian, ``jitter_deg``), a baseline and a height drawn from the seed, white noise of
    ``noise`` times the height. Returns the channel and the true mark times in the record."""
    from scipy.optimize import brentq

    rng = np.random.default_rng(seed)
    n = int(revs / speed_hz * fs)
    t = np.arange(n) / fs
    w, phi0 = 2 * np.pi * speed_hz, rng.uniform(0, 2 * np.pi)

    def th(x):
        return phi0 + w * x + 0.05 * np.sin(w * x)

    ks = np.arange(-1, int(th(t[-1]) // (2 * np.pi)) + 2)
    delta = np.deg2rad(jitter_deg) * rng.standard_normal(ks.size)
    starts = 2 * np.pi * ks + delta
    theta = th(t)
    inside = np.zeros(n, bool)
    for s in starts:
        inside |= (theta >= s) & (theta < s + np.deg2rad(width_deg))
    base, height = rng.uniform(-10, 2), rng.uniform(2, 15)
    sign = 1 if polarity == "positive" else -1
    y = base + sign * height * inside + noise * height * rng.standard_normal(n)
    marks = [brentq(lambda x, s=s: th(x) - s, 0, t[-1]) for s in starts
             if th(t[1]) < s < th(t[-1])]  # an edge needs a sample before it  # fmt: skip
    return y, np.array(marks)


def test_tacho_edges_over_a_grid_of_widths_polarities_noise_jitter_and_speeds():
    """Property over a seeded grid: for every pulse width from 1 to 179 degrees (each spanning
    at least two samples), either polarity, white noise up to 1/15 of the pulse's height,
    jitter up to 0.25 degree and crank speeds of 2-30 Hz at 10 kHz, the detector finds every
    pulse whose leading edge lies in the record, and each edge within one sample of its true
    mark (a step's crossing is interpolated between the two samples around it; noise below
    the trigger's 7.5 standard deviations never moves it to another sample). Up to 120 degrees
    the pulse is found as the minority level (polarity "auto"); wider, a record of a few
    revolutions may hold more pulse than baseline, so the polarity is given. 2 speeds x 7
    widths x 2 polarities x 3 noises x 2 jitters, fewer where a pulse would span under two
    samples."""
    fs = 10_000.0
    failures, cases = [], 0
    for speed in (2.0, 30.0):
        for width in (1.0, 3.0, 10.0, 45.0, 120.0, 160.0, 179.0):
            if width / 360 * fs / speed < 2:
                continue
            for pol in ("positive", "negative"):
                for noise in (0.0, 0.02, 1 / 15):
                    for jitter in (0.0, 0.25):
                        cases += 1
                        y, marks = _pulse_train(fs, speed, width, pol, noise, jitter, cases)
                        given = pol if width > 120 else "auto"
                        try:
                            e = V.tacho_times(y, fs, polarity=given)
                        except ValueError as exc:
                            failures.append((speed, width, pol, noise, jitter, str(exc)))
                            continue
                        if e.size != marks.size or np.max(np.abs(e - marks)) > 1 / fs:
                            failures.append((speed, width, pol, noise, jitter, e.size, marks.size))
    assert cases >= 80
    assert not failures, failures[:5]


def test_a_narrow_noisy_pulse_is_read_not_refused_with_a_wrong_speed():
    """Issue 42: a 10-degree pulse of 5 V with 0.02 V noise was refused as a crank speed of
    2.24e3 Hz (the percentile threshold lay inside the baseline's noise). Now every pulse is
    found within a sample of its mark."""
    fs = 11_000.0
    rng = np.random.default_rng(7)
    t = np.arange(int(2.2 / 3.2 * fs * 1.0) * 3) / fs
    revs = 3.2 * t + 0.3
    y = 5.0 * ((revs % 1.0) < 10 / 360) + 0.02 * rng.standard_normal(t.size)
    e = V.tacho_times(y, fs)
    true = (np.arange(1, int(revs[-1]) + 1) - 0.3) / 3.2
    assert e.size == true.size
    assert np.max(np.abs(e - true)) <= 1 / fs


@pytest.mark.parametrize("case, word", [
    ("noise", "stands out"), ("missing", "pulse missed"), ("fast", "above the 100 Hz"),
    ("flat", "flat"),
])  # fmt: skip
def test_a_channel_that_is_no_pulse_train_is_refused_with_a_reason_about_the_tacho(case, word):
    """Noise of 1/8 of the pulse's height (under the 12 standard deviations the detector
    needs), a pulse missing, a train at 300 Hz (a toothed wheel, not a keyphasor), a flat
    channel: each refused with a reason naming the tacho, never turned into a speed."""
    fs = 10_000.0
    rng = np.random.default_rng(3)
    t = np.arange(20_000) / fs
    revs = 5.0 * t + 0.2
    y = 5.0 * ((revs % 1.0) < 0.05)
    if case == "noise":
        y = y + 5.0 / 8 * rng.standard_normal(t.size)
    elif case == "missing":
        y[(revs > 3.9) & (revs < 4.5)] = 0.0
    elif case == "fast":
        y = 5.0 * (((300.0 * t) % 1.0) < 0.3)
    else:
        y = np.full(t.size, 2.0)
    with pytest.raises(ValueError, match=word) as info:
        V.tacho_times(y, fs)
    assert "tacho" in str(info.value)
