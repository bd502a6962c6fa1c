"""Feature tables for machine learning (``recipdyn features``): one row per run or per window
of time-domain statistics, spectral and order features and chaos indicators with their
statuses; or one row per point of a sweep store.

A row carries where it came from (file, column, window start) and, for a recipdyn run, every
model parameter (``param_*``), so a fault-classification data set is labelled by construction.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from .analysis.spectrum import amplitude_spectrum
from .analysis.vibration import angle_resample, indicators, order_spectrum_angle, velocity_rms
from .defaults import MAX_MEMORY_SAMPLES
from .model.parameters import ParameterError

__all__ = ["signal_features", "file_features", "write_table", "N_ORDERS",
           "feature_units", "record_speed_hz", "write_dictionary", "dictionary_path",
           "COLUMN_DESCRIPTIONS"]  # fmt: skip

#: Crank orders whose amplitudes are features (1..N_ORDERS).
N_ORDERS = 10


def signal_features(x, fs: float, *, revs=None, quantity: str = "acceleration",
                    chaos: bool = False) -> dict[str, Any]:  # fmt: skip
    """Features of one window: [`indicators`][recipdyn.analysis.vibration.indicators], the
    ISO 20816-8 band velocity RMS (for an acceleration), dominant frequency, spectral
    centroid, spread and normalised entropy; with a crank angle (``revs``), the amplitudes of
    orders 1..``N_ORDERS``; with ``chaos``, the 0-1 test K and the Rosenstein exponent, each
    with its status."""
    x = np.asarray(x, dtype=float)
    row: dict[str, Any] = dict(indicators(x))
    if quantity == "acceleration":
        row["velocity_rms_2_1000hz"] = velocity_rms(x, fs) if fs > 2000 else math.nan
    spec = amplitude_spectrum(x, fs)
    p = spec.amplitude[1:] ** 2
    f = spec.frequency[1:]
    total = p.sum()
    if total > 0:
        q = p / total
        row["dominant_hz"] = float(f[np.argmax(p)])
        row["centroid_hz"] = float(np.sum(f * q))
        row["spread_hz"] = float(np.sqrt(np.sum((f - row["centroid_hz"]) ** 2 * q)))
        nz = q[q > 0]
        row["spectral_entropy"] = float(-np.sum(nz * np.log(nz)) / np.log(q.size))
    else:
        row.update(dominant_hz=math.nan, centroid_hz=math.nan, spread_hz=math.nan,
                   spectral_entropy=math.nan)  # fmt: skip
    if revs is not None:
        try:
            r = np.asarray(revs, dtype=float)
            _, xa = angle_resample(x, r - r[0], 64)  # orders do not care where it starts
            osp = order_spectrum_angle(xa, 64)
            for k in range(1, N_ORDERS + 1):
                row[f"order_{k}"] = float(osp.amplitude[np.argmin(np.abs(osp.frequency - k))])
        except ValueError:  # less than one revolution in the window
            for k in range(1, N_ORDERS + 1):
                row[f"order_{k}"] = math.nan
    if chaos:
        from .analysis.lyapunov_signal import lyap_rosenstein
        from .analysis.zero_one import zero_one

        try:  # a window too short or constant is refused, as the functions say
            z = zero_one(x)
            row["k01"], row["k01_status"] = z.K, z.status
        except ValueError:
            row["k01"], row["k01_status"] = math.nan, "refused"
        try:
            r = lyap_rosenstein(x, 1.0 / fs)
            row["lambda1_rosenstein"], row["lambda1_status"] = r.exponent, r.status
        except ValueError:
            row["lambda1_rosenstein"], row["lambda1_status"] = math.nan, "refused"
    return row


#: What each feature column means (its unit depends on the signal: `feature_units`).
COLUMN_DESCRIPTIONS: dict[str, str] = {
    "store": "sweep store the row comes from",
    "file": "input file the row comes from",
    "signal": "the signal the features are computed from (a run: its vibration signal)",
    "window_start_s": "start of the window in the record",
    "window_s": "window length",
    "fs_hz": "sampling rate",
    "speed_hz": "crank (forcing) speed: a run's model period, --speed or the tacho; NaN if "
    "unknown",
    "rms": "root mean square of the signal",
    "peak": "largest magnitude",
    "peak_to_peak": "largest minus smallest value",
    "crest_factor": "peak / rms",
    "kurtosis": "kurtosis (3 for a Gaussian signal)",
    "skewness": "skewness",
    "velocity_rms_2_1000hz": "ISO 20816-8 band (2-1000 Hz) RMS of the velocity integrated "
    "from the acceleration",
    "dominant_hz": "frequency of the largest spectral line",
    "centroid_hz": "power-weighted mean frequency",
    "spread_hz": "power-weighted standard deviation of the frequency",
    "spectral_entropy": "normalised spectral entropy (0: one line, 1: white)",
    "k01": "0-1 test for chaos, K (near 0 regular, near 1 chaotic)",
    "k01_status": "status of the 0-1 test (ok or refused with the reason)",
    "lambda1_rosenstein": "largest Lyapunov exponent (Rosenstein) of the signal",
    "lambda1_status": "status of the Rosenstein estimate (ok, flat, refused)",
    **{f"order_{k}": f"amplitude of crank order {k} (angle-domain spectrum)"
       for k in range(1, N_ORDERS + 1)},
}  # fmt: skip


def feature_units(signal_unit: str, *, orders: bool = True,
                  quantity: str = "acceleration") -> dict[str, str]:  # fmt: skip
    """The numeric features of [`signal_features`][recipdyn.features.signal_features] (chaos
    indicators aside) and their units, in its order, for a signal in ``signal_unit``: what a sweep's
    ``features`` measure stores per point."""
    length = signal_unit.split("/")[0] if "/" in signal_unit else signal_unit
    units = {"rms": signal_unit, "peak": signal_unit, "peak_to_peak": signal_unit,
             "crest_factor": "1", "kurtosis": "1", "skewness": "1"}  # fmt: skip
    if quantity == "acceleration":
        units["velocity_rms_2_1000hz"] = f"{length}/s" if length else "1"
    units.update(dominant_hz="Hz", centroid_hz="Hz", spread_hz="Hz", spectral_entropy="1")
    if orders:
        units.update({f"order_{k}": signal_unit for k in range(1, N_ORDERS + 1)})
    return units


def _window_samples(window: str, fs: float, rev_s: float | None) -> int:
    """Samples in a window given as a duration ('2 s', '500 ms') or whole revolutions
    ('10 rev', needs the speed)."""
    text = window.strip().lower()
    if text.endswith("rev"):
        if not rev_s:
            raise ParameterError(f"window: {window!r} in revolutions needs the speed "
                                 "(--speed, --tacho, or a recipdyn run)")  # fmt: skip
        try:
            seconds = float(text[:-3]) * rev_s
        except ValueError:
            raise ParameterError(f"window: {window!r}; allowed: e.g. '10 rev', '2 s'") from None
    else:
        from .units import to_si

        seconds = to_si("window", window, "s")
    m = int(round(seconds * fs))
    if m < 64:
        raise ParameterError(f"window: {window!r} is {m} samples; allowed: at least 64")
    return m


def _windows(n: int, fs: float, window: str | None, rev_s: float | None):
    """(start, stop) sample ranges: the whole record, or consecutive whole windows."""
    if not window:
        return [(0, n)]
    m = _window_samples(window, fs, rev_s)
    if m > n:
        raise ParameterError(f"window: {window!r} is {m} samples, longer than the record ({n})")
    return [(a, a + m) for a in range(0, n - m + 1, m)]


def file_features(path: str | Path, *, column=None, fs=None, window: str | None = None,
                  speed=None, tacho=None, chaos: bool = False, progress: bool = False,
                  max_memory_samples: int = MAX_MEMORY_SAMPLES, meta: dict | None = None,
                  ) -> list[dict[str, Any]]:  # fmt: skip
    """Rows for one file: a recipdyn run (its vibration signal, speed and parameters) or a
    measured signal (``column``/``fs`` as for analyze; ``speed`` or a ``tacho`` column for
    the orders).

    With ``window``, a signal file is read block by block, whatever its length. Without, its
    one row needs the whole signal in memory: a file longer than ``max_memory_samples`` is
    refused (a `ParameterError` that says to give a window) before anything is read.

    Every run of a model with a forcing period (the compressor models) gets its speed
    (`record_speed_hz`) and so the same numeric columns, orders included. ``meta``, a
    dict, receives each column's unit, description and note (the parameters' assumption
    notes) for the data dictionary (`write_dictionary`); the table itself holds no
    notes or units."""
    from .analysis.vibration import crank_angle
    from .analyze import is_record
    from .io_signal import crank_revs, read_signal, record_length, speed_hz

    path = Path(path)
    labels: dict[str, Any] = {}
    unit = ""
    revs = None
    if column is None and fs is None and is_record(path):
        from .io import read_dataset

        ds = read_dataset(path)
        vib = str(ds.attrs.get("vibration_signal", ""))  # the model's, named by the record
        if vib not in ds:
            vib = "a" if "a" in ds else next(iter(ds.data_vars))
        t = ds[ds[vib].dims[0]].values
        x, rate = ds[vib].values.astype(float), 1.0 / float(np.median(np.diff(t)))
        labels = _record_labels(ds.attrs, meta)
        f_rev = record_speed_hz(ds.attrs)
        name, unit = vib, str(ds[vib].attrs.get("units", ""))
        turning = ds.attrs.get("section_angle")  # a crank of its own speed (a motor drive)
        if turning in ds.variables and ds[turning].dims == ds[vib].dims and t.size > 1:
            # its recorded angle, not the nominal speed, places the orders and the bins
            revs = (ds[turning].values - float(ds[turning].values[0])) / (2 * math.pi)
            f_rev = float(revs[-1] / (t[-1] - t[0]))
    else:
        if window:  # window by window: files longer than memory are fine
            rows = _streamed_rows(path, column, fs, window, speed, chaos, progress, tacho)
            if meta is not None:
                _feature_meta(meta, "")
            return rows
        n_est = record_length(path, column=column)
        if n_est is not None and n_est > max_memory_samples:
            raise ParameterError(
                f"{path.name}: about {n_est} samples, more than max_memory_samples = "
                f"{max_memory_samples} for one row of the whole file; give --window (e.g. "
                "'10 s' or '20 rev': read block by block, one row per window) or raise "
                "--max-memory-samples"
            )
        sig = read_signal(path, column=column, fs=fs)
        x, rate, name = sig.x, sig.fs, sig.name
        f_rev = None
        unit = sig.units
    if tacho is not None:
        revs = crank_revs(path, x.size, rate, tacho=tacho)
        ok = np.isfinite(revs)
        f_rev = (revs[ok][-1] - revs[ok][0]) / (ok.sum() / rate)
    elif speed is not None:
        f_rev = speed_hz(speed)
    if revs is None and f_rev:
        revs = crank_angle(x.size, rate, speed_hz=f_rev)
    rows = []
    for a, b in _windows(x.size, rate, window, 1.0 / f_rev if f_rev else None):
        row = {"file": path.name, "signal": name, "window_start_s": a / rate,
               "window_s": (b - a) / rate, "fs_hz": rate,
               "speed_hz": f_rev if f_rev else math.nan}  # fmt: skip
        row.update(signal_features(x[a:b], rate, revs=None if revs is None else revs[a:b],
                                   chaos=chaos))  # fmt: skip
        row.update(labels)
        rows.append(row)
    if meta is not None:
        _feature_meta(meta, unit)
    return rows


def record_speed_hz(attrs) -> float | None:
    """The forcing (crank) frequency of a recipdyn run from its attributes, through the model
    protocol: ``1 / model.period(values)`` of the recorded model and parameters; None for an
    autonomous system, a map, or a record whose model cannot be rebuilt."""
    from .model.registry import get_model

    spec = attrs.get("model_spec", attrs.get("model_name"))
    try:
        m = get_model(spec)
        period = m.period(m.values_from_record(attrs)) if m.kind == "ode" else None
    except (ParameterError, ImportError, AttributeError, KeyError, TypeError, ValueError):
        period = None
    if not period:  # a record of an older recipdyn: its compressor said its speed
        f = float(attrs.get("crank_frequency_hz", 0.0))
        return f or None
    return 1.0 / float(period)


def _record_labels(attrs, meta: dict | None) -> dict[str, Any]:
    """The parameter columns (``param_*``) of a run; their units and assumption notes go to
    ``meta`` (the data dictionary), not into the table. A value the model derives (recorded
    as ``"default"``) of a numeric parameter is NaN, so a column stays numeric."""
    from .model.registry import get_model

    try:
        schema = get_model(attrs.get("model_spec", attrs.get("model_name"))).schema
    except (ParameterError, ImportError, AttributeError):
        schema = None
    labels: dict[str, Any] = {"model": str(attrs.get("model_name", ""))}
    if meta is not None:
        meta.setdefault("model", {"unit": "", "note": "", "description": "the recipdyn model "
                                  "of the run (recipdyn models NAME)"})  # fmt: skip
    for k, v in attrs.items():
        if not k.startswith("param_") or k.endswith(("_note", "_units")):
            continue
        if not isinstance(v, (int, float, str, np.number)):
            continue
        name = k.removeprefix("param_")
        p = schema[name] if schema is not None and name in schema else None
        if p is None and schema is not None and isinstance(v, str):
            if meta is not None:  # a text the model records beside its parameters: a note
                entry = meta["model"]
                if f"{name}: {v}" not in entry["note"]:
                    entry["note"] = "; ".join(n for n in (entry["note"], f"{name}: {v}") if n)
            continue
        note = str(attrs.get(f"{k}_note", ""))
        if v == "default" and (p is None or p.kind == "number"):
            v = math.nan
            note = "; ".join(n for n in (note, "NaN: derived by the model (not set)") if n)
        labels[k] = v
        if meta is not None:
            entry = meta.setdefault(k, {"unit": "", "description": "", "note": ""})
            entry["unit"] = entry["unit"] or str(attrs.get(f"{k}_units", p.unit if p else ""))
            entry["description"] = entry["description"] or (
                f"model parameter: {p.description}" if p else "model parameter")  # fmt: skip
            if note and note not in entry["note"]:
                entry["note"] = "; ".join(n for n in (entry["note"], note) if n)
    return labels


def _feature_meta(meta: dict, signal_unit: str) -> None:
    """Units and descriptions of the feature columns of a signal in ``signal_unit``."""
    units = {"file": "", "signal": "", "window_start_s": "s", "window_s": "s", "fs_hz": "Hz",
             "speed_hz": "Hz", **feature_units(signal_unit), "k01": "1", "k01_status": "",
             "lambda1_rosenstein": "1/s", "lambda1_status": ""}  # fmt: skip
    for col, unit in units.items():
        entry = meta.setdefault(col, {"unit": unit, "description": "", "note": ""})
        entry["description"] = entry["description"] or COLUMN_DESCRIPTIONS.get(col, "")
        if entry["unit"] != unit and unit not in entry["unit"].split(" or "):
            entry["unit"] = f"{entry['unit']} or {unit}"  # rows of signals in other units


def dictionary_path(table: str | Path) -> Path:
    """The data dictionary beside a table: ``f.csv`` -> ``f.dictionary.csv``."""
    table = Path(table)
    return table.with_name(table.stem + ".dictionary.csv")


def write_dictionary(meta: dict, rows: list[dict[str, Any]], table: str | Path) -> Path:
    """The data dictionary of a feature table, beside it (`dictionary_path`): one row per
    column of the table, in its order: ``column, unit, description, note``."""
    import pandas as pd

    from .io import atomic_path, write_error

    cols: list[str] = []
    for r in rows:
        cols += [k for k in r if k not in cols]
    empty = {"unit": "", "description": "", "note": ""}
    frame = pd.DataFrame([{"column": c, **{**empty, **meta.get(c, {})}} for c in cols],
                         columns=["column", "unit", "description", "note"])  # fmt: skip
    path = dictionary_path(table)
    try:
        with atomic_path(path) as tmp:
            frame.to_csv(tmp, index=False)
    except Exception as exc:
        raise write_error(path, exc) from None
    return path


def _tacho_pulses(path, tacho, fs, progress) -> np.ndarray:
    """Pulse times of the ``tacho`` column of a file, read block by block."""
    from .analysis.streaming import TachoEdges
    from .io_signal import signal_blocks

    label = f"tacho {path.name}" if progress else None
    rate, _, _, blocks = signal_blocks(path, column=tacho, fs=fs, progress=label)
    edges = TachoEdges(rate)
    for block in blocks:
        try:
            edges.feed(block)
        except ValueError as exc:  # a flat first block, or no pulses standing out of it
            raise ParameterError(f"tacho {tacho!r}: {exc}") from None
    try:
        pulses = edges.times()
    except ValueError as exc:  # not a once-per-revolution train
        raise ParameterError(f"tacho {tacho!r}: {exc}") from None
    if pulses.size < 3:
        raise ParameterError(f"tacho {tacho!r}: {pulses.size} pulses; at least 3 needed")
    return pulses


def _streamed_rows(path, column, fs, window, speed, chaos, progress,
                   tacho=None) -> list[dict[str, Any]]:  # fmt: skip
    """Feature rows of consecutive windows of a signal file read block by block (memory: a
    block of 10^6 samples and one window, whatever the file's length). With a ``tacho``
    column, its pulses are found in a first pass (block by block; a few numbers per
    revolution are kept) and each window's crank angle interpolated from them (PCHIP, as
    [`crank_angle`][recipdyn.analysis.vibration.crank_angle]: NaN outside the pulses)."""
    from .analysis.vibration import crank_angle
    from .io_signal import signal_blocks, speed_hz

    rate, name, total, blocks = signal_blocks(
        path, column=column, fs=fs, progress=f"features {path.name}" if progress else None
    )
    f_rev = speed_hz(speed)
    angle = None
    if tacho is not None:
        from scipy.interpolate import PchipInterpolator

        pulses = _tacho_pulses(path, tacho, fs if fs is not None else rate, progress)
        angle = PchipInterpolator(pulses, np.arange(pulses.size, dtype=float),
                                  extrapolate=False)  # fmt: skip
        f_rev = (pulses.size - 1) / (pulses[-1] - pulses[0])
    m = _window_samples(window, rate, 1.0 / f_rev if f_rev else None)
    if total is not None and m > total:
        raise ParameterError(f"window: {window!r} is {m} samples, longer than the record "
                             f"({total})")  # fmt: skip
    rows, buf, start = [], np.empty(0), 0
    for block in blocks:
        buf = np.concatenate([buf, block])
        while buf.size >= m:
            w, buf = buf[:m], buf[m:]
            revs = None
            if angle is not None:
                revs = angle((start + np.arange(m)) / rate)
            elif f_rev:
                revs = crank_angle(m, rate, speed_hz=f_rev, zero_rev=start / rate * f_rev)
            row = {"file": path.name, "signal": name, "window_start_s": start / rate,
                   "window_s": m / rate, "fs_hz": rate,
                   "speed_hz": f_rev if f_rev else math.nan}  # fmt: skip
            row.update(signal_features(w, rate, revs=revs, chaos=chaos))
            rows.append(row)
            start += m
    if not rows:
        raise ParameterError(f"window: {window!r} is {m} samples, longer than the record "
                             f"({start + buf.size})")  # fmt: skip
    return rows


def write_table(rows: list[dict[str, Any]], path: str | Path) -> Path:
    """CSV or Parquet (by suffix), written atomically; columns in first-seen order."""
    import pandas as pd

    from .io import atomic_path, write_error

    path = Path(path)
    if path.suffix.lower() not in (".csv", ".parquet"):
        raise ParameterError(f"output {path}: use .csv or .parquet")
    cols: list[str] = []
    for r in rows:
        cols += [k for k in r if k not in cols]
    frame = pd.DataFrame(rows, columns=cols)
    try:
        with atomic_path(path) as tmp:
            if path.suffix.lower() == ".csv":
                frame.to_csv(tmp, index=False)
            else:
                frame.to_parquet(tmp, index=False)
    except Exception as exc:
        raise write_error(path, exc) from None
    return path
