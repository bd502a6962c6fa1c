"""Records longer than memory: block-by-block statistics equal the whole-array ones, and analyze
reads a long file in blocks (whole-record numbers, detailed analyses on an excerpt)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.signal import welch

from recipdyn.analysis.streaming import RunningMoments, StreamingWelch
from recipdyn.analysis.vibration import indicators
from recipdyn.analyze import analyze_signal
from recipdyn.cli import main
from recipdyn.model.parameters import ParameterError


def _signal(n, fs, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    x = 3.0 * np.sin(2 * np.pi * 50.0 * t) + 0.5 * rng.standard_normal(n) + 7.0
    x[n // 2 :] += 40.0 * (rng.random(n - n // 2) < 1e-3)  # sparse spikes: kurtosis, crest
    return x


@pytest.mark.parametrize("block", [1000, 4097, 77_777, 10**6])
def test_block_statistics_equal_the_whole_array(block):
    """Any split into blocks (shorter or longer than a Welch segment) gives the whole array's
    indicators and scipy's Welch PSD. The merges are exact in arithmetic, so the difference
    is rounding: the central sums carry ~n eps relative error (n = 3e5: ~1e-10), the Welch
    segments are the same numbers in another order (~1e-15)."""
    fs, n = 5000.0, 300_001
    x = _signal(n, fs)
    rm, sw = RunningMoments(), StreamingWelch(fs, 8192)
    for a in range(0, n, block):
        rm.feed(x[a : a + block])
        sw.feed(x[a : a + block])
    want, got = indicators(x), rm.indicators()
    assert got.keys() == want.keys()
    for k in want:
        assert got[k] == pytest.approx(want[k], rel=1e-9, abs=1e-12), k
    f, p = welch(x, fs, nperseg=8192)
    f2, p2 = sw.psd()
    np.testing.assert_array_equal(f, f2)
    np.testing.assert_allclose(p2, p, rtol=1e-12, atol=1e-14 * p.max())
    assert sw.segments == (n - 8192) // 4096 + 1


def test_welch_amplitude_and_band_rms_closed_forms():
    """A sinusoid of amplitude 3 at 50 Hz, centred on a bin: the amplitude spectrum peaks at 3
    (Hann on a bin centre) and the velocity RMS in 2-1000 Hz is 3 / (2 pi 50) / sqrt 2 (the
    Hann main lobe spans +-2 bins of 1 Hz, over which 1/f^2 changes by +-8 %; the lobe is
    symmetric, so the first order cancels and the second is ~(2/50)^2 / 2: below 1e-3)."""
    fs, nper = 8192.0, 8192
    f0 = 50 * fs / nper  # bin 50: 50 Hz
    t = np.arange(40 * nper) / fs
    sw = StreamingWelch(fs, nper)
    sw.feed(3.0 * np.sin(2 * np.pi * f0 * t))
    f, amp = sw.amplitude()
    assert f[np.argmax(amp)] == pytest.approx(f0)
    assert amp.max() == pytest.approx(3.0, rel=1e-6)
    assert sw.band_rms((2.0, 1000.0), integrate=1) == pytest.approx(
        3.0 / (2 * np.pi * f0) / np.sqrt(2), rel=1e-3
    )
    with pytest.raises(ValueError, match="shorter than one segment"):
        StreamingWelch(fs, nper).psd()


def test_analyze_a_long_record_in_blocks(tmp_path):
    """A record twice the memory limit (NPY and CSV): read in blocks; the summary's whole-record
    indicators equal those of the whole array (the spikes are in the second half, outside the
    excerpt, so the excerpt's own kurtosis is ~1.5 and the whole record's is larger); the
    spectrum peak is the 50 Hz line; the notes say what covers what; the sample count is the
    record's."""
    import pandas as pd

    fs, n = 5000.0, 240_000
    x = _signal(n, fs, seed=3)
    np.save(tmp_path / "long.npy", x)
    pd.DataFrame({"time": np.arange(n) / fs, "acc": x}).to_csv(tmp_path / "long.csv",
                                                                 index=False)  # fmt: skip
    want = indicators(x)
    for name, kw in (("long.npy", dict(fs=fs)), ("long.csv", dict(column="acc"))):
        out = tmp_path / f"an_{name}"
        s = analyze_signal(tmp_path / name, out, max_memory_samples=120_000,
                           excerpt_samples=50_000, **kw)  # fmt: skip
        whole = s["vibration"]["whole_record"]
        assert s["samples"] == n and whole["samples"] == n
        assert s["vibration"]["excerpt_samples"] == 50_000
        for k in want:
            assert whole["indicators"][k] == pytest.approx(want[k], rel=1e-9), (name, k)
        assert s["vibration"]["indicators"]["kurtosis"] < 2.0 < whole["indicators"]["kurtosis"]
        assert any("long record" in note for note in s["notes"])
        assert s["spectrum"]["peaks"][0]["frequency_hz"] == pytest.approx(50.0, abs=0.1)
        assert "Whole record" in (out / "summary.md").read_text()
        # a short record takes the in-memory path: no whole-record section
    s = analyze_signal(tmp_path / "long.npy", tmp_path / "short", fs=fs)
    assert "whole_record" not in s["vibration"]


def test_long_record_bad_values_and_limits_exit_2(tmp_path, capsys):
    """A NaN far beyond the excerpt is still found (every block is checked), with the sample
    where it was found; a memory limit below 1000 names the option."""
    fs, n = 5000.0, 30_000
    x = _signal(n, fs)
    x[25_000] = np.nan
    p = tmp_path / "bad.npy"
    np.save(p, x)
    code = main(["analyze", str(p), "--fs", "5kHz", "--max-memory-samples", "10000",
                 "-o", str(tmp_path / "o")])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and "non-finite" in err and "Traceback" not in err
    with pytest.raises(ParameterError, match="max_memory_samples"):
        analyze_signal(p, tmp_path / "o2", fs=fs, max_memory_samples=10)


def test_long_record_with_a_tacho_reads_only_the_excerpt_of_it(tmp_path, capsys):
    """CLI on a long CSV with a tacho column: the orders and impacts come from the excerpt
    (its own tacho pulses), one impact per revolution, exit 0."""
    import pandas as pd

    fs = 10_000.0
    t = np.arange(int(12 * fs)) / fs
    revs = 10.0 * t
    acc = 3.0 * np.sin(2 * np.pi * revs)
    tau = ((revs - 0.25) % 1.0) / 10.0
    acc += 20.0 * np.exp(-tau / 4e-4) * np.sin(2 * np.pi * 2000 * tau) * (revs >= 0.25)
    p = tmp_path / "m.csv"
    pd.DataFrame({"time": t, "acc": acc, "key": 5.0 * ((revs % 1.0) < 0.05)}).to_csv(
        p, index=False)  # fmt: skip
    out = tmp_path / "an"
    code = main(["analyze", str(p), "-c", "acc", "--tacho", "key", "--max-memory-samples",
                 "60000", "-o", str(out)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    s = json.loads((out / "summary.json").read_text())
    assert s["samples"] == t.size and s["vibration"]["excerpt_samples"] == 60_000
    assert s["vibration"]["impacts"]["per_revolution"] == pytest.approx(1.0, abs=0.15)
    assert s["vibration"]["whole_record"]["samples"] == t.size


@pytest.mark.parametrize("block", [997, 2500, 10**6])
def test_tacho_edges_block_by_block_equal_the_whole_channel(block):
    """Pulse edges found block by block (blocks of 997 samples cut through pulses and edges)
    equal tacho_times on the whole channel with the same threshold (to rounding: the same
    interpolation between the same samples). The default threshold comes from the first
    block's percentiles, which the 0.01 V ripple shifts by < 0.02 V from the whole channel's;
    at an edge of 5 V per sample that moves an edge by < 0.02 / 5 / fs = 8e-7 s."""
    from recipdyn.analysis.streaming import TachoEdges
    from recipdyn.analysis.vibration import tacho_times

    fs = 5000.0
    revs = 11.3 * np.arange(30_000) / fs + 0.37
    key = 5.0 * ((revs % 1.0) < 0.1) + 0.01 * np.sin(np.arange(revs.size))
    te = TachoEdges(fs)
    for a in range(0, key.size, block):
        te.feed(key[a : a + block])
    want = tacho_times(key, fs)
    assert want.size == int(revs[-1]) - int(revs[0])
    np.testing.assert_allclose(te.times(), want, rtol=0, atol=1e-6)
    same = tacho_times(key, fs, threshold=te.threshold)
    np.testing.assert_allclose(te.times(), same, rtol=0, atol=1e-12)


def test_features_windows_with_a_tacho_are_read_block_by_block(tmp_path, monkeypatch):
    """features --window with --tacho streams both columns (blocks of 1000 samples, windows of
    730): each row equals the features of the same window of the whole signal with the crank
    angle from tacho_times + crank_angle on the whole tacho column (to 1e-9: the same PCHIP
    through the same pulses); the speed is the tacho's."""
    import pandas as pd

    import recipdyn.io_signal as io_signal
    from recipdyn.analysis.vibration import crank_angle, tacho_times
    from recipdyn.features import file_features, signal_features

    fs = 2000.0
    n = 8000
    revs_true = 11.3 * np.arange(n) / fs + 0.37
    x = np.sin(2 * np.pi * revs_true) + 0.3 * np.sin(6 * np.pi * revs_true)
    key = 5.0 * ((revs_true % 1.0) < 0.1)
    p = tmp_path / "m.csv"
    pd.DataFrame({"time": np.arange(n) / fs, "acc": x, "key": key}).to_csv(p, index=False)
    orig = io_signal.signal_blocks
    monkeypatch.setattr(io_signal, "signal_blocks",
                        lambda *a, **k: orig(*a, **{**k, "block": 1000}))  # fmt: skip
    rows = file_features(p, column="acc", window="0.365 s", tacho="key")
    revs = crank_angle(n, fs, pulses=tacho_times(key, fs))
    assert len(rows) == n // 730
    for i, r in enumerate(rows):
        a, b = i * 730, (i + 1) * 730
        ref = signal_features(x[a:b], fs, revs=revs[a:b])
        # a square pulse's edge is located to within a sample (1/fs = 0.5 ms) over ~1.3 s
        # between the first and the last pulse: the mean speed to ~4e-4
        assert r["speed_hz"] == pytest.approx(11.3, rel=5e-4)
        for k in ("rms", "order_1", "order_3"):
            if np.isfinite(ref[k]):
                assert r[k] == pytest.approx(ref[k], rel=1e-9, abs=1e-12), (k, i)
    assert np.isfinite(rows[3]["order_1"]) and rows[3]["order_1"] == pytest.approx(1.0, rel=0.02)


def test_features_of_a_whole_file_longer_than_memory_is_refused_with_the_remedy(tmp_path, capsys):
    """features without --window makes one row from the whole signal: a file longer than
    --max-memory-samples is refused before it is read (exit 2, the limit and --window named,
    no traceback); the same file with a higher limit, or with a window, gives its rows."""
    fs, n = 5000.0, 30_000
    p = tmp_path / "long.npy"
    np.save(p, _signal(n, fs))
    out = tmp_path / "t.csv"
    code = main(["features", str(p), "--fs", "5kHz", "--max-memory-samples", "20000",
                 "-o", str(out), "--no-progress"])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and "max_memory_samples = 20000" in err and "--window" in err, err
    assert "Traceback" not in err and not out.exists()
    code = main(["features", str(p), "--fs", "5kHz", "--max-memory-samples", "40000",
                 "-o", str(out), "--no-progress"])  # fmt: skip
    assert code == 0 and len(out.read_text().strip().splitlines()) == 2
    code = main(["features", str(p), "--fs", "5kHz", "--max-memory-samples", "20000",
                 "--window", "2 s", "-o", str(out), "--no-progress"])  # fmt: skip
    assert code == 0 and len(out.read_text().strip().splitlines()) == 1 + n // 10_000


def test_a_tacho_column_that_is_no_pulse_train_is_refused_naming_it(tmp_path):
    """features --window with --tacho: a pulse missing from the tacho column is refused with
    the column's name and the reason (read block by block, checked as tacho_times checks)."""
    import pandas as pd

    from recipdyn.errors import ParameterError
    from recipdyn.features import file_features

    fs, n = 2000.0, 8000
    revs = 11.3 * np.arange(n) / fs + 0.37
    key = 5.0 * ((revs % 1.0) < 0.1)
    key[(revs > 20.5) & (revs < 21.5)] = 0.0
    p = tmp_path / "m.csv"
    acc = np.sin(2 * np.pi * revs)
    pd.DataFrame({"time": np.arange(n) / fs, "acc": acc, "key": key}).to_csv(p, index=False)
    with pytest.raises(ParameterError, match=r"tacho 'key': .*pulse missed"):
        file_features(p, column="acc", window="0.365 s", tacho="key")
