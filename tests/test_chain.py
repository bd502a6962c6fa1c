"""The measurement chain's description (`recipdyn.chain`): ranges with sources, seeded draws
inside them, the default and the earlier chains as points of them, and one set of defaults
for ``recipdyn sense`` and ``recipdyn dataset`` (issue 44, item 5)."""

import inspect
import math

import numpy as np
import pytest
import xarray as xr

from recipdyn.chain import (
    DEFAULT_RANGES,
    SENSE_DEFAULT,
    SOURCES,
    Chain,
    ChainRanges,
    Choice,
    Span,
    legacy_chain,
)
from recipdyn.errors import ParameterError
from recipdyn.sensors import record


def test_every_range_states_its_source():
    """Each range names a source the data card lists, or says it is engineering judgement."""
    for k, r in DEFAULT_RANGES.items():
        cited = [s for s in SOURCES if s in r.source]
        assert cited or "engineering judgement" in r.source or "diagnoser" in r.source, k
        assert r.meaning and r.text(), k
    rows = ChainRanges().describe()
    assert [r["parameter"] for r in rows] == list(DEFAULT_RANGES)


def test_draws_are_seeded_inside_the_ranges_and_fill_them():
    """400 draws: every one inside the ranges (`contains` is empty); the same seed gives the
    same chain; a uniform span's draws reach within 3 % of both ends of its width (the chance
    that 400 uniform draws miss a 3 % end is 0.97^400 = 5e-6; for a log-uniform span on the
    log scale, for a span absent with p = 0.5 about 200 draws: 2e-3 at worst, over ~40 spans
    the whole test fails by chance with p < 0.1 %), and each choice's every value occurs."""
    r, fs = ChainRanges(), 11_000.0
    rng = np.random.default_rng(2024)
    chains = [r.draw(rng, fs) for _ in range(400)]
    assert all(r.contains(c, fs) == [] for c in chains)
    assert r.draw(np.random.default_rng(5), fs) == r.draw(np.random.default_rng(5), fs)
    assert r.draw(np.random.default_rng(5), fs) != r.draw(np.random.default_rng(6), fs)
    from recipdyn.chain import _coordinates

    coords = [_coordinates(c, fs) for c in chains]
    for k, span in DEFAULT_RANGES.items():
        vals = []
        for c in coords:
            v = c[k]
            vals.extend(v if isinstance(v, tuple) else (v,))
        vals = [v for v in vals if v is not None]
        if isinstance(span, Choice):
            assert set(vals) == set(span.values), k
            continue
        if span.hi == span.lo:
            continue
        f = np.log if span.log else np.asarray
        lo, hi = f(span.lo), f(span.hi)
        x = f(np.asarray(vals, float))
        assert x.min() - lo < 0.03 * (hi - lo) and hi - x.max() < 0.03 * (hi - lo), k


def test_the_sense_default_and_the_earlier_chain_lie_inside_the_data_sets_ranges():
    """One set of defaults: `recipdyn sense`'s default chain, at simulate's default sampling
    rate (inside the data set's sampling range), lies inside the default data set's chain
    ranges; so does the chain of earlier data sets at every condition's resonance and SNR
    they drew."""
    from recipdyn.diagnosis.classes import CONDITIONS
    from recipdyn.diagnosis.dataset import DatasetSpec
    from recipdyn.simulate import simulate

    fs = inspect.signature(simulate).parameters["fs"].default
    assert CONDITIONS["fs"].lo <= fs <= CONDITIONS["fs"].hi
    spec = DatasetSpec()
    assert spec.chain == "drawn"
    assert spec.chain_ranges.contains(SENSE_DEFAULT, fs) == []
    for res in (CONDITIONS["resonance_hz"].lo, CONDITIONS["resonance_hz"].hi):
        for snr in (10.0, 20.0, 40.0):
            assert ChainRanges().contains(legacy_chain(res, snr), 12_000.0) == []
    outside = ChainRanges().contains(legacy_chain(1200.0, 5.0), fs)
    assert len(outside) == 2 and "resonance_hz" in outside[0] and "snr_db" in outside[1]


def test_recipdyn_sense_at_its_defaults_prints_no_note_and_records_the_default_chain(tmp_path):
    """`recipdyn sense` on a run at simulate's default sampling rate (10 kHz) with every
    default: no note and no warning (before: the 4 kHz resonance at 0.4 fs was discretised
    with a 20 % flank error and noted on every run), and the record's settings are those of
    `SENSE_DEFAULT` (30 dB, the exact response)."""
    from recipdyn.cli import main
    from recipdyn.simulate import simulate

    fs = inspect.signature(simulate).parameters["fs"].default
    t = np.arange(int(0.8 * fs)) / fs
    a = 30 * np.sin(2 * np.pi * 3.2 * t) + 900 * (np.sin(2 * np.pi * 3.2 * t) > 0.999)
    ds = xr.Dataset(
        {"a": ("time", a, {"units": "m/s**2"}), "theta1": ("time", 20.0 * t, {"units": "rad"})},
        coords={"time": t},
        attrs={"title": "recipdyn simulation: test record"},  # sense reads simulated runs only
    )
    run, out = tmp_path / "run.nc", tmp_path / "sensed.nc"
    ds.to_netcdf(run)
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
        assert main(["sense", str(run), "-o", str(out)]) == 0
    text = buf.getvalue()
    assert "note" not in text and "warning" not in text, text
    got = xr.open_dataset(out)
    acc = SENSE_DEFAULT.accelerometer
    assert got.attrs["sensor_accel_guide_snr_db"] == acc.snr_db == 30.0
    assert got.attrs["sensor_accel_guide_response"] == "exact"
    assert got.attrs["sensor_accel_guide_resonance_hz"] == acc.resonance_hz
    assert got.attrs["sensor_accel_guide_damping"] == acc.damping


def test_a_chain_round_trips_and_is_applied_by_record():
    """`to_dict`/`from_dict` give the same chain (JSON-able); `record(ds, chain=...)` records
    every channel finite with its settings."""
    import json

    fs = 11_000.0
    c = ChainRanges().draw(np.random.default_rng(8), fs)
    assert Chain.from_dict(json.loads(json.dumps(c.to_dict()))) == c
    t = np.arange(8000) / fs
    ds = xr.Dataset({"a": ("time", np.sin(2 * np.pi * 40 * t), {"units": "m/s**2"}),
                     "theta1": ("time", 20.0 * t, {"units": "rad"}),
                     "p_head": ("time", 2e5 + 1e5 * np.sin(20 * t), {"units": "Pa"}),
                     "p_crank": ("time", 2e5 - 1e5 * np.sin(20 * t), {"units": "Pa"})},
                    coords={"time": t})  # fmt: skip
    out = record(ds, chain=c, seed=1)
    for ch in ("accel_guide", "p_head_sensor", "p_crank_sensor", "tacho"):
        assert np.isfinite(out[ch].values).all(), ch
    assert out["p_head_sensor"].attrs["sensor_offset"] == c.pressure.offset[0]
    assert out["tacho"].attrs["sensor_polarity"] == c.tacho.polarity
    assert out.attrs["sensor_accel_guide_gain"] == c.accelerometer.gain


@pytest.mark.parametrize("change, word", [
    (dict(extra=Span(0, 1, "", "", "")), "unknown or missing"),
    (dict(accelerometer__snr_db=Span(40.0, 10.0, "dB", "", "")), "lo <= hi"),
])  # fmt: skip
def test_bad_ranges_are_refused_naming_them(change, word):
    with pytest.raises(ParameterError, match=word):
        ChainRanges().with_spans(**change)


def test_a_span_can_be_narrowed_and_a_block_absent():
    """``with_spans`` narrows one range (the data set's --snr-range does so); a span absent
    with probability p_none draws None about that often (binomial: 400 draws at p = 0.5,
    within 4 standard deviations, 40)."""
    r = ChainRanges().with_spans(accelerometer__snr_db=Span(25.0, 26.0, "dB", "x", "test"))
    rng = np.random.default_rng(3)
    draws = [r.draw(rng, 10e3) for _ in range(400)]
    assert all(25.0 <= c.accelerometer.snr_db <= 26.0 for c in draws)
    none = sum(c.pressure.resonance_hz is None for c in draws)
    assert abs(none - 200) <= 40
    assert math.isfinite(draws[0].accelerometer.lowpass_hz)
