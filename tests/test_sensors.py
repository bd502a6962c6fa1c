"""Sensors (`recipdyn.sensors`): each block of the conditioning chain against its closed
form, the noise's SNR against its statistical error, the ADC, the tacho against the crank
angle's crossings, determinism, and `analyze` on a sensed record."""

import math

import numpy as np
import pytest
import xarray as xr
from scipy.optimize import brentq
from scipy.signal import freqz

from recipdyn.analysis.vibration import tacho_times
from recipdyn.errors import ParameterError
from recipdyn.sensors import (
    Accelerometer,
    PressureTransducer,
    Tacho,
    adc,
    flank_error,
    record,
    resonance_filter,
    snr_db,
)


def _record(fs, n, **signals):
    t = np.arange(n) / fs
    units = {"a": "m/s**2", "theta1": "rad", "p_head": "Pa", "p_crank": "Pa"}
    data = {k: ("time", f(t), {"units": units[k]}) for k, f in signals.items()}
    return xr.Dataset(data, coords={"time": t})


def _amplitude(y, fs, f, last):
    """Amplitude of the sine at ``f`` in the last ``last`` samples (least squares; a whole
    number of periods, so exact for a pure sine)."""
    t = np.arange(y.size)[-last:] / fs
    m = np.c_[np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t), np.ones_like(t)]
    c = np.linalg.lstsq(m, y[-last:], rcond=None)[0]
    return math.hypot(c[0], c[1])


def _butter_gain(f, fc, n, fs, kind):
    """The digital Butterworth's closed form: bilinear, prewarped at the corner."""
    r = math.tan(math.pi * f / fs) / math.tan(math.pi * fc / fs)
    return 1 / math.sqrt(1 + (r if kind == "low" else 1 / r) ** (2 * n))


CLEAN = dict(resonance_hz=None, highpass_hz=None, snr_db=None, bits=None)


@pytest.mark.parametrize("fn, zeta, fs", [(2000.0, 0.05, 10e3), (4000.0, 0.02, 10e3),
                                          (300.0, 0.3, 48e3)])  # fmt: skip
def test_resonance_matches_the_second_order_closed_form(fn, zeta, fs):
    """At f_n the prewarped bilinear transform is exact: |H| = 1/(2 zeta), phase -90 degrees
    (only rounding, 1e-12). Elsewhere the discrete response equals the closed form
    wn^2/(wn^2 - w^2 + 2j zeta wn w) at the warped frequency f_w = f_n tan(pi f/fs) /
    tan(pi f_n/fs): that mapping is the whole discretisation error (it would fail with a
    transform not prewarped, or an exact ZOH discretisation, by up to tens of %)."""
    b, a = resonance_filter(fn, zeta, fs)
    _, h = freqz(b, a, worN=[fn], fs=fs)
    assert abs(abs(h[0]) - 1 / (2 * zeta)) < 1e-12 / zeta
    assert abs(np.angle(h[0]) + np.pi / 2) < 1e-9
    f = np.linspace(1.0, 0.45 * fs, 200)
    _, h = freqz(b, a, worN=f, fs=fs)
    fw = fn * np.tan(np.pi * f / fs) / np.tan(np.pi * fn / fs)
    closed = fn**2 / (fn**2 - fw**2 + 2j * zeta * fn * fw)
    np.testing.assert_allclose(h, closed, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("fn, want", [(4000.0, 0.20), (1000.0, 0.016), (500.0, 0.0041)])
def test_the_recorded_flank_error_is_the_filters_own_error(fn, want):
    """The error the record states (`sensor_resonance_flank_error`, from the warp's closed
    form) equals the largest magnitude error of the filter's own response (freqz on a dense
    grid) against the continuous closed form below f_n/2: it is the discretisation error.
    Both are evaluated on grids of ~2000 points: they agree to the grid's resolution (1e-3
    relative)."""
    fs, zeta = 10e3, 0.05
    b, a = resonance_filter(fn, zeta, fs)
    f = np.linspace(fn / 4000, fn / 2, 2000)
    _, h = freqz(b, a, worN=f, fs=fs)
    closed = fn**2 / np.abs(fn**2 - f**2 + 2j * zeta * fn * f)
    measured = float(np.max(np.abs(np.abs(h) / closed - 1)))
    assert flank_error(fn, zeta, fs) == pytest.approx(measured, rel=1e-3)
    assert measured == pytest.approx(want, rel=0.05)


def test_a_sine_at_the_resonance_is_recorded_with_gain_one_over_two_zeta():
    """Through the chain: the steady amplitude of a sine at f_n is 1/(2 zeta) times the
    low-pass's closed-form gain there. The transients decay as exp(-zeta wn t) (e^-75 after
    the 0.2 s skipped), so the bound is rounding (1e-9)."""
    fs, fn, zeta = 50e3, 3000.0, 0.04
    ds = _record(fs, 15000, a=lambda t: np.sin(2 * np.pi * fn * t))
    s = Accelerometer(**(CLEAN | dict(resonance_hz=fn, damping=zeta)))
    y = record(ds, accelerometer=s)["accel_guide"].values
    want = _butter_gain(fn, 0.4 * fs, 4, fs, "low") / (2 * zeta)
    assert _amplitude(y, fs, fn, 5000) == pytest.approx(want, rel=1e-9)


@pytest.mark.parametrize("order", [2, 4, 6])
def test_band_filters_pass_the_band_and_attenuate_as_their_order_says(order):
    """A sine at 100 Hz between a 1 Hz high-pass and a 1 kHz low-pass passes with gain 1
    (closed form 1 - 4e-5 or closer); one at 2 kHz is attenuated by the Butterworth closed
    form 1/sqrt(1 + (tan(pi f/fs)/tan(pi fc/fs))^(2n)), 0.196 / 0.040 / 0.008 for
    n = 2 / 4 / 6 (so a wrong order fails). The high-pass transient, at most (1 Hz / 100 Hz) of the
    amplitude, has decayed by exp(-2 pi 0.38 2 s) ~ 1e-2 at least before the last second is
    fitted: bound 1e-4."""
    fs, n = 10e3, 30000
    s = Accelerometer(**(CLEAN | dict(highpass_hz=1.0, highpass_order=order,
                                      lowpass_hz=1000.0, lowpass_order=order)))  # fmt: skip
    for f, tol in ((100.0, 1e-4), (2000.0, 1e-4)):
        ds = _record(fs, n, a=lambda t, f=f: np.sin(2 * np.pi * f * t))
        y = record(ds, accelerometer=s)["accel_guide"].values
        want = _butter_gain(f, 1000.0, order, fs, "low") * _butter_gain(f, 1.0, order, fs, "high")
        assert _amplitude(y, fs, f, 10000) == pytest.approx(want, abs=tol)
        if f == 100.0:
            assert want == pytest.approx(1.0, abs=1e-4)


def test_noise_gives_the_requested_snr_within_the_rms_estimate_error():
    """SNR is defined on the band-limited signal's RMS: the noise is white, sigma =
    rms * 10^(-SNR/20). The noise's sample RMS over N independent Gaussian samples has
    relative standard deviation 1/sqrt(2N), i.e. 20/ln(10)/sqrt(2N) dB = 0.024 dB at
    N = 2^16; five of them bound the difference (a sigma off by 2 % would fail). The input
    carries a DC offset and a 9.5 kHz line that the band removes (RMS 51.8 in, 22.0 in
    the band): an SNR taken on the unfiltered input is off by 7.4 dB (tried: it fails)."""
    fs, n = 20e3, 1 << 16

    def a(t):
        return (30 * np.sin(2 * np.pi * 50 * t) + 8 * np.sin(2 * np.pi * 730 * t) + 20
                + 60 * np.sin(2 * np.pi * 9500 * t))  # fmt: skip

    ds = _record(fs, n, a=a)
    clean = record(ds, accelerometer=Accelerometer(bits=None, snr_db=None))["accel_guide"].values
    sigma_db = 20 / math.log(10) / math.sqrt(2 * n)
    for want in (0.0, 20.0, 46.0):
        noisy = record(ds, accelerometer=Accelerometer(bits=None, snr_db=want), seed=7)
        got = snr_db(clean, noisy["accel_guide"].values - clean)
        assert abs(got - want) < 5 * sigma_db, (want, got)


def test_quantisation_error_is_uniform_with_rms_lsb_over_sqrt12_and_clips_at_full_scale():
    """A dithered signal (Gaussian noise of 20 LSB): the error lies within +-LSB/2, its RMS is
    LSB/sqrt(12) within five standard deviations of the estimate (0.447/sqrt(N) relative:
    var(e^2) = LSB^4/180), and a 10-bin histogram is flat within five binomial standard
    deviations. Beyond the range the codes stop at -FS and FS - LSB, and are counted."""
    rng = np.random.default_rng(3)
    n, fs_, bits = 1 << 16, 500.0, 12
    lsb = 2 * fs_ / 2**bits
    x = 100 * np.sin(np.linspace(0, 40 * np.pi, n)) + 20 * lsb * rng.standard_normal(n)
    q, clipped = adc(x, -fs_, fs_, bits)
    e = q - x
    assert clipped == 0
    assert np.max(np.abs(e)) <= lsb / 2 * (1 + 1e-9)
    assert np.sqrt(np.mean(e**2)) == pytest.approx(
        lsb / math.sqrt(12), rel=5 * 0.447 / math.sqrt(n)
    )
    counts, _ = np.histogram(e, bins=10, range=(-lsb / 2, lsb / 2))
    assert np.max(np.abs(counts - n / 10)) < 5 * math.sqrt(n * 0.1 * 0.9)
    y = 600 * np.sin(np.linspace(0, 4 * np.pi, 4001))
    q, clipped = adc(y, -fs_, fs_, bits)
    assert q.max() == pytest.approx(fs_ - lsb) and q.min() == pytest.approx(-fs_)
    assert clipped == np.count_nonzero((y >= fs_ - lsb / 2) | (y < -fs_ - lsb / 2))
    assert clipped > 0
    ds = _record(10e3, 4001, a=lambda t: 600 * np.sin(2 * np.pi * 5 * t))
    out = record(ds, accelerometer=Accelerometer(resonance_hz=None, highpass_hz=None, snr_db=None,
                                                 full_scale=fs_, bits=bits))  # fmt: skip
    assert out["accel_guide"].attrs["sensor_clipped_samples"] > 0
    assert out["accel_guide"].values.max() == pytest.approx(fs_ - lsb)


def test_tacho_pulses_count_revolutions_and_sit_on_the_crossings_of_2pi_k():
    """A crank angle with a 10 % speed ripple: one pulse per crossing of theta1 = 2 pi k, and
    the rising edges (read by analyze's `tacho_times`) within one sample of the crossing
    times found by root-finding on theta1(t)."""
    fs, n, w = 2000.0, 4200, 2 * np.pi * 5.0

    def th(t):
        return 0.3 + w * t + 0.1 * np.sin(w * t)

    ds = _record(fs, n, theta1=th, a=lambda t: np.sin(w * t))
    out = record(ds, accelerometer=None, tacho=Tacho())
    pulse = out["tacho"].values
    assert set(np.unique(pulse)) == {0.0, 5.0} and out["tacho"].attrs["units"] == "V"
    t_end = (n - 1) / fs
    ks = range(1, int(th(t_end) // (2 * np.pi)) + 1)
    crossings = np.array([brentq(lambda t, k=k: th(t) - 2 * np.pi * k, 0, t_end) for k in ks])
    assert out["tacho"].attrs["sensor_pulses"] == len(crossings) == 10
    edges = tacho_times(pulse, fs)
    assert edges.size == crossings.size
    assert np.max(np.abs(edges - crossings)) <= 1 / fs


def test_same_seed_same_channels_other_seed_other_noise():
    """Every channel is a function of (record, settings, seed); noise streams of two seeds
    are uncorrelated (|rho| < 5/sqrt(N))."""
    fs, n = 10e3, 8192
    ds = _record(fs, n, a=lambda t: np.sin(2 * np.pi * 30 * t), theta1=lambda t: 20 * t,
                 p_head=lambda t: 2e5 + 1e5 * np.sin(20 * t),
                 p_crank=lambda t: 2e5 - 1e5 * np.sin(20 * t))  # fmt: skip
    kw = dict(accelerometer=Accelerometer(), pressure=PressureTransducer(), tacho=Tacho())
    one, two, other = (record(ds, seed=s, **kw) for s in (5, 5, 6))
    chans = one.attrs["sensor_channels"].split(",")
    assert chans == ["accel_guide", "p_head_sensor", "p_crank_sensor", "tacho"]
    for c in chans:
        np.testing.assert_array_equal(one[c].values, two[c].values)
    clean = record(ds, accelerometer=Accelerometer(snr_db=None, bits=None))["accel_guide"].values
    n1 = record(ds, accelerometer=Accelerometer(bits=None), seed=5)["accel_guide"].values - clean
    n2 = record(ds, accelerometer=Accelerometer(bits=None), seed=6)["accel_guide"].values - clean
    assert abs(np.corrcoef(n1, n2)[0, 1]) < 5 / math.sqrt(n)
    assert not np.array_equal(one["accel_guide"].values, other["accel_guide"].values)


def test_pressure_channels_carry_units_settings_and_a_range_for_the_machine():
    """One channel per chamber, in Pa; the default range is the 1-2-5 value above 1.25 x
    the peak (3e5 Pa -> 5e5 Pa), so the quantisation step is 5e5/2^16 Pa."""
    fs, n = 10e3, 4096
    ds = _record(fs, n, p_head=lambda t: 2e5 + 1e5 * np.sin(20 * t), a=lambda t: 0 * t + 1.0)
    out = record(ds, accelerometer=None, pressure=PressureTransducer(snr_db=None))
    assert "p_crank_sensor" not in out
    v = out["p_head_sensor"]
    assert v.attrs["units"] == "Pa" and v.attrs["sensor_full_scale"] == 5e5
    assert out.attrs["sensor_p_head_sensor_bits"] == 16
    steps = np.unique(np.round(v.values / (5e5 / 2**16), 6) % 1)
    assert np.all(steps == 0)  # every value is a whole number of LSBs
    assert np.max(np.abs(v.values[n // 2 :] - ds.p_head.values[n // 2 :])) < 0.01 * 1e5


@pytest.mark.parametrize("kw, name", [
    (dict(damping=0.0), "damping"), (dict(resonance_hz=-1.0), "resonance"),
    (dict(bits=1), "bits"), (dict(bits=16.5), "bits"), (dict(lowpass_order=9), "lowpass_order"),
    (dict(highpass_hz=500.0, lowpass_hz=100.0), "highpass"), (dict(full_scale=0.0), "full_scale"),
])  # fmt: skip
def test_bad_settings_are_named(kw, name):
    with pytest.raises(ParameterError, match=rf"^{name}"):
        Accelerometer(**kw)


def test_a_resonance_above_the_nyquist_frequency_is_refused():
    ds = _record(5000.0, 100, a=lambda t: t)
    with pytest.raises(ParameterError, match=r"^resonance = 4000 Hz .*Nyquist frequency 2500"):
        record(ds, accelerometer=Accelerometer())


@pytest.fixture(scope="module")
def sensed(tmp_path_factory):
    """A short compressor run (5 revolutions at 4 kHz) and its sensed copy, by the CLI."""
    from recipdyn.cli import main

    d = tmp_path_factory.mktemp("sense")
    run, out = d / "run.nc", d / "sensed.nc"
    assert main(["simulate", "-n", "5", "--fs", "4kHz", "-o", str(run), "--no-figure",
                 "--no-progress"]) == 0  # fmt: skip
    assert main(["sense", str(run), "-o", str(out), "--resonance", "1.5kHz", "--snr", "30dB",
                 "--seed", "2"]) == 0  # fmt: skip
    return run, out


def test_sense_records_channels_with_units_and_settings(sensed):
    run, out = sensed
    ds = xr.open_dataset(out)
    assert ds.attrs["sensor_channels"] == "accel_guide,tacho"  # the paper's load: no chambers
    assert ds["accel_guide"].attrs["units"] == "m/s**2"
    assert ds.attrs["sensor_accel_guide_resonance_hz"] == 1500.0
    assert ds.attrs["sensor_accel_guide_snr_db"] == 30.0 and ds.attrs["sensor_seed"] == 2
    assert ds.attrs["sensor_tacho_pulses"] == 5  # revolutions 0..4 start in the record
    assert set(xr.open_dataset(run).data_vars) < set(ds.data_vars)  # the run is kept whole


def test_analyze_reads_a_sensed_record_and_takes_its_orders_from_the_tacho(sensed, tmp_path):
    """`analyze -c accel_guide --tacho tacho`: the crank speed comes from the tacho's pulses,
    so the spectrum's peak labelled order 1 sits at the run's crank frequency (within the
    spectrum's resolution) and order 1 is the order spectrum's strongest line."""
    import json

    from recipdyn.cli import main

    _, out = sensed
    folder = tmp_path / "an"
    assert main(["analyze", str(out), "-c", "accel_guide", "--tacho", "tacho", "-o",
                 str(folder)]) == 0  # fmt: skip
    s = json.loads((folder / "summary.json").read_text())
    f_crank = 20.0 / (2 * np.pi)
    first = [p for p in s["spectrum"]["peaks"] if p["crank_order"] == 1]
    assert first and abs(first[0]["frequency_hz"] - f_crank) <= s["spectrum"]["resolution_hz"]
    lines = s["vibration"]["order_lines"]
    assert lines[0]["order"] == pytest.approx(1.0, abs=s["vibration"]["order_resolution"] / 2)
    assert s["units"] == "m/s**2"


@pytest.mark.parametrize("args, name", [
    (["--snr", "loud"], "snr"), (["--damping", "0"], "damping"), (["--bits", "1"], "bits"),
    (["--resonance", "3kHz", "--response", "bilinear"], "resonance"),
    (["--response", "zoh"], "response"), (["--source", "theta1"], "accelerometer source"),
    (["--no-accel", "--no-pressure", "--no-tacho"], "sensors"),
])  # fmt: skip
def test_sense_refuses_bad_values_in_one_line_and_writes_nothing(sensed, tmp_path, capsys,
                                                                 args, name):  # fmt: skip
    from recipdyn.cli import main

    run, _ = sensed
    out = tmp_path / "new" / "x.nc"
    assert main(["sense", str(run), "-o", str(out), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: {name}") and "\n" not in err, err
    assert not out.parent.exists()


@pytest.mark.parametrize("args", [["--damping", "2"], ["--snr", "x"], ["--bits", "40"],
                                  ["--resonance", "-1"]])  # fmt: skip
def test_sense_refuses_a_bad_value_before_heavy_imports(tmp_path, args):
    """Option values are checked before xarray, SciPy or the record are loaded (a fresh
    interpreter reports what it imported)."""
    import json
    import os
    import subprocess
    import sys

    (tmp_path / "run.nc").write_bytes(b"not read")
    heavy = ("xarray", "scipy.signal", "numba", "matplotlib", "pandas")
    probe = ("import sys, json\nfrom recipdyn.cli import main\n"
             f"code = main({['sense', 'run.nc', '-o', 'o/x.nc', *args]!r})\n"
             f"print(json.dumps([code, [m for m in {heavy!r} if m in sys.modules]]))\n"
             )  # fmt: skip
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run([sys.executable, "-c", probe], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)  # fmt: skip
    code, loaded = json.loads(done.stdout.strip().splitlines()[-1])
    assert code == 2 and loaded == [], (done.stderr, loaded)
    assert not (tmp_path / "o").exists()


def test_a_sensed_record_writes_as_mat_with_every_setting(sensed, tmp_path):
    """MAT files keep the settings too: their struct fields take names up to 63 characters
    (``sensor_accel_guide_resonance_flank_error`` has 40; MAT's default limit is 31)."""
    from scipy.io import loadmat

    from recipdyn.cli import main

    run, _ = sensed
    out = tmp_path / "s.mat"
    assert main(["sense", str(run), "-o", str(out), "--resonance", "1.5kHz", "--response",
                 "bilinear"]) == 0  # the bilinear chain states its flank error  # fmt: skip
    mat = loadmat(out, squeeze_me=True)
    assert mat["attrs"]["sensor_accel_guide_resonance_flank_error"].item() > 0
    assert mat["units"]["accel_guide"].item() == "m/s**2" and mat["tacho"].size > 0


# ---- the chain's further blocks (recipdyn.chain draws them) ----------------------------------


def _old_chain(x, fs, *, resonance, highpass, hp_order, lowpass, lp_order, snr, lo, hi, bits,
               rng):  # fmt: skip
    """The conditioning chain as recipdyn recorded it before the chain's further blocks
    (commit e2fe659, recipdyn/sensors.py: resonance_filter, band_filters, adc, _condition),
    copied here so that the test compares against the old code, not against itself."""
    from scipy.signal import bilinear, butter, lfilter, lfilter_zi, sosfilt, sosfilt_zi

    y = np.asarray(x, dtype=float)
    if resonance is not None:
        c, wn = 2 * fs, 2 * np.pi * resonance[0]
        wp = c * math.tan(wn / c)
        b, a = bilinear([wp**2], [1.0, 2 * resonance[1] * wp, wp**2], fs=fs)
        y, _ = lfilter(b, a, y, zi=lfilter_zi(b, a) * y[0])
    sos = []
    if highpass is not None:
        sos.append(butter(hp_order, highpass, "highpass", fs=fs, output="sos"))
    sos.append(butter(lp_order, lowpass, "lowpass", fs=fs, output="sos"))
    sos = np.concatenate(sos)
    y, _ = sosfilt(sos, y, zi=sosfilt_zi(sos) * y[0])
    if snr is not None:
        sigma = float(np.sqrt(np.mean(y**2))) * 10.0 ** (-snr / 20.0)
        y = y + sigma * rng.standard_normal(y.size)
    lsb = (hi - lo) / 2.0**bits
    code = np.clip(np.round((y - lo) / lsb), 0, 2.0**bits - 1)
    return code * lsb + lo


@pytest.mark.parametrize("resonance_hz, snr", [(4000.0, 40.0), (3100.0, 20.0), (4450.0, 10.0)])
def test_the_chain_of_earlier_versions_records_to_the_bit(resonance_hz, snr):
    """Keep the old chain as one point of the new: the sensors' defaults (the data set's fixed
    chain: a condition's resonance at its SNR, the pressure transducers, the tacho) give the
    channels of the code before the chain's further blocks, equal to the bit (same
    operations in the same order; the noise from the same streams)."""
    import zlib

    fs, n = 11_000.0, 12_000
    ds = _record(fs, n, a=lambda t: 300 * np.sin(2 * np.pi * 37 * t) + 2e3 * (np.sin(
        2 * np.pi * 3.1 * t) > 0.995), theta1=lambda t: 0.3 + 20.0 * t,
        p_head=lambda t: 2e5 + 1e5 * np.sin(20 * t), p_crank=lambda t: 2e5 - 1e5 * np.cos(20 * t),
    )  # fmt: skip
    seed = 123
    out = record(ds, accelerometer=Accelerometer(snr_db=snr, resonance_hz=resonance_hz),
                 pressure=PressureTransducer(), tacho=Tacho(), seed=seed)  # fmt: skip

    def rng(name):
        return np.random.default_rng([seed, zlib.crc32(name.encode())])

    want = _old_chain(ds.a.values, fs, resonance=(resonance_hz, 0.05), highpass=1.0, hp_order=2,
                      lowpass=0.4 * fs, lp_order=4, snr=snr, lo=-500 * 9.80665,
                      hi=500 * 9.80665, bits=16, rng=rng("accel_guide"))  # fmt: skip
    np.testing.assert_array_equal(out["accel_guide"].values, want)
    for src in ("p_head", "p_crank"):
        x = ds[src].values
        top = 1.25 * float(np.max(x))
        e = 10.0 ** math.floor(math.log10(top))
        top = next(m * e for m in (1, 2, 5, 10) if m * e >= top)
        want = _old_chain(x, fs, resonance=None, highpass=None, hp_order=2, lowpass=0.4 * fs,
                          lp_order=4, snr=60.0, lo=0.0, hi=top, bits=16,
                          rng=rng(f"{src}_sensor"))  # fmt: skip
        np.testing.assert_array_equal(out[f"{src}_sensor"].values, want)
    tach = np.where(np.mod(ds.theta1.values, 2 * np.pi) < np.deg2rad(10.0), 5.0, 0.0)
    np.testing.assert_array_equal(out["tacho"].values, tach)


def _fit(y, fs, f, sl, *, mean=False):
    """Amplitude and phase (rad) of the sine at ``f`` in ``y[sl]`` (least squares; with
    ``mean``, also the constant)."""
    t = np.arange(y.size)[sl] / fs
    m = np.c_[np.cos(2 * np.pi * f * t), np.sin(2 * np.pi * f * t), np.ones_like(t)]
    c = np.linalg.lstsq(m, y[sl], rcond=None)[0]
    out = math.hypot(c[0], c[1]), math.atan2(-c[1], c[0])
    return (*out, c[2]) if mean else out


@pytest.mark.parametrize("fn, f", [(4000.0, 1234.5), (4000.0, 3987.0), (25_000.0, 3000.0)])
def test_the_exact_response_is_the_closed_form_at_any_frequency(fn, f):
    """``response="exact"``: a sine's steady amplitude and phase equal the continuous-time
    closed form, resonance times the analog Butterworth low-pass, at any frequency -- near
    the resonance at 0.4 fs, where the bilinear flank is 20 % off, and for a stud mount's
    resonance at 25 kHz, above the record's Nyquist frequency (its flank only). The record
    is read as band-limited and padded with twelve decay times (residual e^-12); the sine
    does not fit the record's length, so the bound is the fit over a window of whole
    periods in the record's middle: 1e-6."""
    from scipy.signal import butter, freqs

    fs, n, zeta, fc = 10e3, 20_000, 0.05, 4500.0
    ds = _record(fs, n, a=lambda t: np.cos(2 * np.pi * f * t))
    s = Accelerometer(**(CLEAN | dict(resonance_hz=fn, damping=zeta, lowpass_hz=fc,
                                      response="exact")))  # fmt: skip
    y = record(ds, accelerometer=s)["accel_guide"].values
    w, wn = 2 * np.pi * f, 2 * np.pi * fn
    h = wn**2 / (wn**2 - w**2 + 2j * zeta * wn * w)
    b, a = butter(4, 2 * np.pi * fc, analog=True)
    h *= freqs(b, a, worN=[w])[1][0]
    periods = int(8000 * f / fs)
    sl = slice(6000, 6000 + int(round(periods * fs / f)))
    amp, ph = _fit(y, fs, f, sl)
    assert amp == pytest.approx(abs(h), rel=1e-6)
    assert math.remainder(ph - np.angle(h), 2 * np.pi) == pytest.approx(0.0, abs=1e-6)


def test_delay_gain_offset_and_zero_phase_are_their_closed_forms():
    """A band-limited fractional delay of 2.37 samples gives cos(w (t - d)) (1e-6 in the
    middle); gain and offset give g x + o; a zero-phase low-pass keeps the phase (0 to 1e-6)
    and applies the Butterworth magnitude 1/sqrt(1 + (f/fc)^8)."""
    fs, n, f = 10e3, 20_000, 777.0
    ds = _record(fs, n, a=lambda t: np.cos(2 * np.pi * f * t))
    sl = slice(6000, 6000 + int(round(int(8000 * f / fs) * fs / f)))
    d = 2.37 / fs
    s = Accelerometer(**(CLEAN | dict(lowpass_hz=None, response="exact", delay_s=d)))
    y = record(ds, accelerometer=s)["accel_guide"].values
    lp = 1 / math.sqrt(1 + (f / (0.4 * fs)) ** 8)  # the default 4th-order low-pass at 0.4 fs
    amp, ph = _fit(y, fs, f, sl)
    from scipy.signal import butter, freqs

    b, a = butter(4, 2 * np.pi * 0.4 * fs, analog=True)
    h = freqs(b, a, worN=[2 * np.pi * f])[1][0]
    assert amp == pytest.approx(lp, rel=1e-6)
    assert math.remainder(ph - (np.angle(h) - 2 * np.pi * f * d), 2 * np.pi) == pytest.approx(
        0.0, abs=1e-6)  # fmt: skip
    z = Accelerometer(**(CLEAN | dict(response="exact", lowpass_phase="zero", gain=1.03,
                                      offset=0.25)))  # fmt: skip
    y = record(ds, accelerometer=z)["accel_guide"].values
    amp, ph, c = _fit(y, fs, f, sl, mean=True)
    assert amp == pytest.approx(1.03 * lp, rel=1e-6) and ph == pytest.approx(0.0, abs=1e-6)
    assert c == pytest.approx(0.25, abs=1e-6)


def test_hum_and_drift_add_their_lines():
    """Hum at -30 dB with harmonics (1, 0.2, 0.5) of 60 Hz: least-squares lines at 60, 120,
    180 Hz of 10^(-30/20) (1, 0.2, 0.5) times the band-limited signal's RMS (the pure 37 Hz
    sine's 1/sqrt 2), to 1e-9; a drift of 0.4 at 0.1 Hz (no high-pass) is the record minus
    the same record without it, a sine of that amplitude and frequency (1e-9)."""
    fs, n = 6000.0, 60_000
    ds = _record(fs, n, a=lambda t: np.sin(2 * np.pi * 37 * t))
    base = dict(CLEAN, response="exact", lowpass_hz=2500.0)
    hum = Accelerometer(**(base | dict(hum_db=-30.0, hum_harmonics=(1.0, 0.2, 0.5),
                                       mains_hz=60.0)))  # fmt: skip
    y = record(ds, accelerometer=hum, seed=4)["accel_guide"].values
    clean = record(ds, accelerometer=Accelerometer(**base))["accel_guide"].values
    rms = float(np.sqrt(np.mean(clean**2)))
    for k, rel in ((1, 1.0), (2, 0.2), (3, 0.5)):
        amp, _ = _fit(y - clean, fs, 60.0 * k, slice(0, n))
        assert amp == pytest.approx(rms * 10 ** (-1.5) * rel, rel=1e-9)
    drift = Accelerometer(**(base | dict(drift=0.4, drift_hz=0.1)))
    y = record(ds, accelerometer=drift, seed=4)["accel_guide"].values
    amp, _ = _fit(y - clean, fs, 0.1, slice(0, n))
    assert amp == pytest.approx(0.4, rel=1e-6)
    assert np.max(np.abs(y - clean)) <= 0.4 * (1 + 1e-6)


def test_pressure_offsets_gains_and_passage_resonance_per_chamber():
    """Per-chamber gain and offset: each channel is g_i p_i + o_i (clean chain, exact, no
    low-pass effect at 3 Hz: 1e-9 relative); a passage resonance at 1.5 kHz (damping 0.1)
    multiplies a 1.5 kHz pressure ripple by 1/(2 zeta) = 5 at -90 degrees (closed form of the
    exact response, times the low-pass's gain)."""
    fs, n = 10e3, 20_000
    ds = _record(fs, n, p_head=lambda t: 2e5 + 1e5 * np.sin(20 * t),
                 p_crank=lambda t: 2e5 - 1e5 * np.sin(20 * t))  # fmt: skip
    s = PressureTransducer(snr_db=None, bits=None, response="exact", gain=(1.01, 0.99),
                           offset=(5e3, -3e3), lowpass_hz=4000.0, lowpass_phase="zero")  # fmt: skip
    out = record(ds, accelerometer=None, pressure=s)
    for src, g, o in (("p_head", 1.01, 5e3), ("p_crank", 0.99, -3e3)):
        np.testing.assert_allclose(out[f"{src}_sensor"].values[2000:-2000],
                                   g * ds[src].values[2000:-2000] + o, rtol=1e-7)  # fmt: skip
        assert out[f"{src}_sensor"].attrs["sensor_offset"] == o
    ripple = _record(fs, n, p_head=lambda t: 2e5 + 1e3 * np.cos(2 * np.pi * 1500 * t))
    r = PressureTransducer(snr_db=None, bits=None, response="exact", resonance_hz=1500.0,
                           damping=0.1, lowpass_hz=None)  # fmt: skip
    y = record(ripple, accelerometer=None, pressure=r)["p_head_sensor"].values
    lp = 1 / math.sqrt(1 + (1500 / 4000) ** 8)
    sl = slice(6000, 6000 + 8 * 500 * 2)
    amp, ph = _fit(y, fs, 1500.0, sl)
    assert amp == pytest.approx(1e3 * 5 * lp, rel=1e-4)


@pytest.mark.parametrize("polarity", ["positive", "negative"])
def test_tacho_polarity_baseline_jitter_and_noise(polarity):
    """The tacho's further settings: the pulse lies ``high`` from the baseline on its side;
    each mark moves by its revolution's jitter (the edges read by tacho_times within one
    sample of the crossings of 2 pi k + delta_k, whose scatter has the jitter's standard
    deviation within its sampling error); white noise of the given deviation (its robust
    estimate within 5 %)."""
    fs, n, w = 10e3, 100_000, 2 * np.pi * 5.0
    ds = _record(fs, n, theta1=lambda t: 0.3 + w * t, a=lambda t: 0 * t)
    s = Tacho(baseline=-8.0, high=4.0, polarity=polarity, jitter_deg=2.0, width_deg=20.0)
    out = record(ds, accelerometer=None, tacho=s, seed=9)
    y = out["tacho"].values
    level = -4.0 if polarity == "positive" else -12.0
    assert set(np.unique(y)) == {-8.0, level}
    e = tacho_times(y, fs)
    ideal = (2 * np.pi * np.arange(1, e.size + 1) - 0.3) / w
    dev = (e - ideal) * w  # the jitter, rad (each within a sample)
    assert np.std(np.rad2deg(dev)) == pytest.approx(2.0, rel=3 / math.sqrt(2 * e.size))
    noisy = record(ds, accelerometer=None, tacho=Tacho(noise_std=0.05), seed=9)["tacho"].values
    quiet = noisy[np.mod(ds.theta1.values, 2 * np.pi) > 0.5]
    assert 1.4826 * np.median(np.abs(quiet - np.median(quiet))) == pytest.approx(0.05, rel=0.05)


def test_sense_refuses_what_is_not_a_simulated_run(tmp_path, capsys):
    """Issue 44, item 4 (its class of defect in `sense`): a NetCDF file that no simulation
    wrote was refused naming the accelerometer's source, a CSV file as unreadable NetCDF;
    both now say what sense reads and what to do with a measured signal."""
    from recipdyn.cli import main

    foreign, csv = tmp_path / "measured.nc", tmp_path / "measured.csv"
    xr.Dataset({"a": ("time", np.zeros(8))}, coords={"time": np.arange(8) / 1e3}).to_netcdf(foreign)
    csv.write_text("time,a\n0,1\n0.001,2\n")
    for path, words in ((foreign, "not a run of 'recipdyn simulate'"),
                        (csv, "sense reads a run of 'recipdyn simulate' (.nc)")):  # fmt: skip
        out = tmp_path / "o" / "x.nc"
        assert main(["sense", str(path), "-o", str(out)]) == 2
        err = capsys.readouterr().err.strip()
        assert words in err and f"recipdyn analyze {path}" in err and "\n" not in err, err
        assert not out.parent.exists()
