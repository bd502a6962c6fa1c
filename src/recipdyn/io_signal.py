"""Read a measured signal: one channel and its sampling rate from CSV, WAV, MAT, NetCDF,
Parquet or NumPy files (``recipdyn analyze`` on data from elsewhere).

Every failure is a [`ParameterError`][recipdyn.errors.ParameterError] that names the file,
the option and what is allowed (the columns the file has, the rates it implies).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .model.parameters import ParameterError
from .units import to_si

__all__ = [
    "MeasuredSignal",
    "read_signal",
    "record_length",
    "SIGNAL_SUFFIXES",
    "signal_blocks",
    "speed_hz",
    "crank_revs",
]

SIGNAL_SUFFIXES = (".csv", ".txt", ".tsv", ".wav", ".mat", ".nc", ".parquet", ".npy")
TIME_NAMES = ("time", "t", "time_s", "time (s)", "t (s)", "seconds")
FS_NAMES = ("fs", "Fs", "FS", "sampling_rate", "sample_rate", "sr", "SampleRate")


def _is_rate_name(name: str) -> bool:
    """A scalar holding the sampling rate: one of ``FS_NAMES``, or a name that ends in
    sample rate / sampling rate / sampling frequency whatever its case and separators (data
    loggers write e.g. ``Time_Sample_Rate``)."""
    flat = "".join(ch for ch in name.lower() if ch.isalpha())
    return name in FS_NAMES or flat.endswith(("samplerate", "samplingrate", "samplingfrequency"))


@dataclass
class MeasuredSignal:
    """One uniformly sampled channel: values, sampling rate (Hz), and where they came from."""

    x: np.ndarray
    fs: float
    name: str
    source: str
    units: str = ""
    notes: list[str] = field(default_factory=list)


def _csv_sep(suffix: str) -> str:
    return {".csv": ",", ".tsv": "\t"}.get(suffix, r"[\s,;]+")


def _csv_options(path: Path) -> tuple[dict, bool]:
    """``pandas.read_csv`` options for a text table, and whether its first line is data.

    A first line (after ``#`` comments and blank lines) whose fields all read as numbers is
    data, not a header: the columns are then named by position (``column 0``, ``column 1``,
    ...), so the first sample is kept and no signal is named after a number."""
    import re

    sep = _csv_sep(path.suffix.lower())
    first = ""
    with open(path, encoding="utf-8", errors="replace") as fh:
        for line in fh:
            body = line.split("#", 1)[0].strip()
            if body:
                first = body
                break
    fields = [f for f in re.split(sep, first) if f.strip()]
    try:
        [float(f) for f in fields]
        headerless = bool(fields)
    except ValueError:
        headerless = False
    opts = dict(sep=sep, engine="python", comment="#")
    if headerless:
        opts.update(header=None, names=[f"column {i}" for i in range(len(fields))])
    return opts, headerless


def _fs_option(fs) -> float | None:
    if fs is None:
        return None
    out = to_si("fs", fs, "Hz")
    if not out > 0:
        raise ParameterError(f"fs: {fs!r}; allowed: a positive sampling rate (e.g. 10kHz)")
    return out


def _fs_from_time(t, path, name) -> float:
    t = np.asarray(t, dtype=float)
    dt = np.diff(t)
    if t.size < 2 or not np.all(dt > 0):
        raise ParameterError(f"{path}: time column {name!r} must increase")
    if np.ptp(dt) > 1e-3 * np.median(dt):
        raise ParameterError(f"{path}: time column {name!r} is not uniformly sampled (steps "
                             f"{dt.min():.3g} to {dt.max():.3g} s); resample first")  # fmt: skip
    return 1.0 / float(np.median(dt))


#: The most names a refusal lists (then: the closest ones, the first ones and the count).
_LISTED = 12


def _pick(names, column, path, kind="column"):
    """The chosen column name among ``names`` (by name or index)."""
    names = list(names)
    if column is None:
        if len(names) == 1:
            return names[0]
        raise ParameterError(f"{path}: {len(names)} {kind}s ({', '.join(map(str, names))}); "
                             f"choose one with --column")  # fmt: skip
    if str(column) in map(str, names):
        return names[[str(n) for n in names].index(str(column))]
    try:
        i = int(column)
    except (TypeError, ValueError):
        i = None
    if i is not None and 0 <= i < len(names):
        return names[i]
    allowed = ", ".join(map(str, names))
    if len(names) > _LISTED:  # (a record's hundred outputs: the closest and the first ones)
        from .model.protocol import close_matches

        close = close_matches(str(column), map(str, names))
        first = [str(n) for n in names if str(n) not in close][: _LISTED - len(close)]
        allowed = (f"{', '.join(close)} (the closest), " if close else "") + \
            f"{', '.join(first)}, ... ({len(names)} {kind}s in all)"  # fmt: skip
    raise ParameterError(f"column: {column!r} not in {path}; allowed: {allowed} or an index "
                         f"0..{len(names) - 1}")  # fmt: skip


def _table(frame, path, column, fs):
    """A pandas table: a time column gives the rate, the chosen numeric column the values."""
    cols = [c for c in frame.columns if np.issubdtype(frame[c].dtype, np.number)]
    tcol = next((c for c in cols if str(c).strip().lower() in TIME_NAMES), None)
    data = [c for c in cols if c != tcol]
    if not data:
        raise ParameterError(f"{path}: cannot be read as a signal: no numeric column besides "
                             f"time (columns: {', '.join(map(str, frame.columns))})")  # fmt: skip
    name = _pick(data, column, path)
    notes = []
    if fs is None:
        if tcol is None:
            raise ParameterError(f"{path}: no time column ({', '.join(TIME_NAMES[:3])}); give "
                                 "the sampling rate with --fs (e.g. --fs 10kHz)")  # fmt: skip
        fs = _fs_from_time(frame[tcol].to_numpy(), path, tcol)
        notes.append(f"sampling rate {fs:.6g} Hz from column {tcol!r}")
    return frame[name].to_numpy(dtype=float), fs, str(name), notes


def check_signal_file(path: str | Path) -> Path:
    """``path`` if it can be a signal file (it exists, is a file, is not empty, has a known
    extension); else [`ParameterError`][recipdyn.errors.ParameterError] in one line. Cheap:
    commands check their input file with it before anything else about it."""
    path = Path(path)
    if not path.exists():
        raise ParameterError(f"input {path}: file not found")
    if path.is_dir():
        raise ParameterError(f"input {path}: is a folder; expected a signal file "
                             f"({', '.join(SIGNAL_SUFFIXES)})")  # fmt: skip
    if path.stat().st_size == 0:
        raise ParameterError(f"input {path}: file is empty")
    suffix = path.suffix.lower()
    if suffix not in SIGNAL_SUFFIXES:
        raise ParameterError(f"input {path}: unknown format {suffix!r}; allowed: "
                             f"{', '.join(SIGNAL_SUFFIXES)}")  # fmt: skip
    return path


def _unsensed(ds, path: Path, column) -> None:
    """Refuse a column a simulated record (the model's outputs, ``recipdyn simulate``) does
    not hold, pointing at what makes the sensors' channels from it (``recipdyn sense``)."""
    simulated = str(ds.attrs.get("title", "")).startswith("recipdyn simulation")
    if column is None or not simulated or "sensor_channels" in ds.attrs:
        return
    names = [str(k) for k, v in ds.data_vars.items() if v.ndim == 1]
    if str(column) in names:
        return
    from .model.protocol import close_matches

    close = close_matches(str(column), names)
    hint = f" (or one of its outputs: {', '.join(close)} ...)" if close else ""
    raise ParameterError(
        f"{path}: a simulated record (model {ds.attrs.get('model', '?')!r}) holds the "
        f"model's {len(names)} outputs, not the sensor channel {column!r}: run 'recipdyn "
        f"sense {path} -o SENSED.nc' first and read SENSED.nc{hint}"
    )


def read_signal(
    path: str | Path, *, column=None, fs=None, rows: int | None = None
) -> MeasuredSignal:
    """Read one channel of ``path`` (its first ``rows`` samples only, if given: CSV/TSV/TXT
    parse only those lines, Parquet its first batch, WAV and NPY are memory-mapped, NetCDF
    sliced lazily; MAT files are read whole and cut).

    ``column``: column name or index (CSV, Parquet), variable name (MAT, NetCDF), channel
    index (WAV). ``fs``: sampling rate (number in Hz or text with units); needed unless the
    file gives it (a time column, the WAV header, an ``fs`` variable in a MAT file, the time
    coordinate of a NetCDF variable); a given ``fs`` overrides the file's."""
    path = check_signal_file(path)
    suffix = path.suffix.lower()
    fs = _fs_option(fs)
    notes: list[str] = []
    units = ""
    try:
        if suffix in (".csv", ".txt", ".tsv"):
            import pandas as pd

            opts, headerless = _csv_options(path)
            frame = pd.read_csv(path, nrows=rows, **opts)
            x, fs, name, notes = _table(frame, path, column, fs)
            if headerless:
                notes.insert(0, "no header line: the first line is data, the columns are "
                             "named by position")  # fmt: skip
        elif suffix == ".parquet":
            import pandas as pd

            if rows is None:
                frame = pd.read_parquet(path)
            else:
                import pyarrow.parquet as pq

                frame = next(pq.ParquetFile(path).iter_batches(batch_size=rows)).to_pandas()
            x, fs, name, notes = _table(frame, path, column, fs)
        elif suffix == ".wav":
            from scipy.io import wavfile

            rate, data = wavfile.read(path, mmap=rows is not None)
            data = data.reshape(len(data), -1)
            ch = _pick(list(range(data.shape[1])), 0 if column is None else column, path,
                       "channel")  # fmt: skip
            x, name = np.asarray(data[:rows, ch], dtype=float), f"channel {ch}"
            if np.issubdtype(data.dtype, np.integer):
                notes.append(f"integer samples ({data.dtype}), not scaled to physical units")
            if fs is None:
                fs = float(rate)
                notes.append(f"sampling rate {fs:g} Hz from the WAV header")
        elif suffix == ".mat":
            from scipy.io import loadmat

            mat = loadmat(path, squeeze_me=True)
            scalars = [k for k in mat if not k.startswith("__") and np.size(mat[k]) == 1]
            fs_var = next((k for k in FS_NAMES if k in scalars), None)
            fs_var = fs_var or next((k for k in scalars if _is_rate_name(k)), None)
            arrays = [k for k, v in mat.items() if not k.startswith("__")
                      and isinstance(v, np.ndarray) and v.ndim == 1 and v.size > 1
                      and np.issubdtype(v.dtype, np.number)]  # fmt: skip
            tvar = next((k for k in arrays if k.lower() in TIME_NAMES), None)
            name = _pick([k for k in arrays if k != tvar], column, path, "variable")
            x = np.asarray(mat[name], dtype=float)[:rows]
            if fs is None and fs_var is not None:
                fs = float(mat[fs_var])
                notes.append(f"sampling rate {fs:g} Hz from variable {fs_var!r}")
            elif fs is None and tvar is not None:
                fs = _fs_from_time(mat[tvar], path, tvar)
                notes.append(f"sampling rate {fs:.6g} Hz from variable {tvar!r}")
        elif suffix == ".nc":
            import contextlib

            import xarray as xr

            from .io import read_dataset

            with contextlib.ExitStack() as stack:
                if rows is None:
                    ds = read_dataset(path, expected="a NetCDF file with a 1-D signal")
                else:  # lazily: only the first rows are read from disk
                    ds = stack.enter_context(xr.open_dataset(path))
                _unsensed(ds, path, column)
                names = [k for k, v in ds.data_vars.items() if v.ndim == 1]
                name = _pick(names, column, path, "variable")
                da = ds[name]
                x = np.asarray(da[:rows].values, dtype=float)
                units = str(da.attrs.get("units", ""))
                if fs is None and da.dims[0] in ds.coords:
                    fs = _fs_from_time(ds[da.dims[0]][:rows].values, path, da.dims[0])
                    notes.append(f"sampling rate {fs:.6g} Hz from coordinate {da.dims[0]!r}")
        else:  # .npy: a plain array, one channel per column
            data = np.load(path, allow_pickle=False, mmap_mode="r" if rows else None)
            data = data.reshape(len(data), -1)
            ch = _pick(list(range(data.shape[1])), 0 if data.shape[1] == 1 else column, path)
            x, name = np.asarray(data[:rows, ch], dtype=float), f"column {ch}"
    except ParameterError:
        raise
    except Exception as exc:  # parsers raise assorted errors on malformed files
        raise ParameterError(f"input {path}: cannot be read as {suffix[1:].upper()} "
                             f"({type(exc).__name__}: {exc})") from None  # fmt: skip
    if fs is None:
        raise ParameterError(f"{path}: the file does not give a sampling rate; pass --fs "
                             "(e.g. --fs 10kHz)")  # fmt: skip
    bad = ~np.isfinite(x)
    if bad.any():
        raise ParameterError(f"{path}: column {name!r} has {int(bad.sum())} missing or "
                             "non-finite value(s); fill or cut them first")  # fmt: skip
    return MeasuredSignal(x, float(fs), str(name), path.name, units, notes)


def signal_blocks(path: str | Path, *, column=None, fs=None, block: int = 1_000_000,
                  progress: str | None = None):  # fmt: skip
    """``(fs, name, total_or_None, blocks)`` for a file too long to hold in memory: ``blocks``
    yields consecutive arrays of at most ``block`` samples of the chosen channel.

    CSV/TSV/TXT are read in chunks (pandas), Parquet by row groups (pyarrow), WAV and NPY
    memory-mapped, NetCDF lazily; MAT files are read whole (scipy cannot stream them). A
    time column must stay uniform across chunks, and every block free of missing values
    (both checked block by block, as [`read_signal`][recipdyn.io_signal.read_signal] checks a whole
    file). ``progress``: the label of a progress bar over the samples (none without)."""
    path = Path(path)
    rate, name, total, raw = _raw_blocks(path, column, fs, block)
    return rate, name, total, _checked(raw, path, name, total, progress)


def _checked(blocks, path: Path, name: str, total, progress: str | None):
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=total, unit="sample", desc=progress, leave=False)
    n = 0
    try:
        for b in blocks:
            if not np.all(np.isfinite(b)):
                raise ParameterError(
                    f"{path}: column {name!r} has missing or non-finite "
                    f"values after sample {n}; fill or cut them first"
                )
            n += b.size
            if bar is not None:
                bar.update(b.size)
            yield b
    finally:
        if bar is not None:
            bar.close()


def _raw_blocks(path: Path, column, fs, block: int):
    suffix = path.suffix.lower()
    head = read_signal(path, column=column, fs=fs, rows=1000)
    name, rate = head.name, head.fs
    if suffix in (".csv", ".txt", ".tsv"):
        import pandas as pd

        opts, _ = _csv_options(path)

        def gen():
            last_t = None
            for frame in pd.read_csv(path, chunksize=block, **opts):
                tcol = next((c for c in frame.columns if str(c).strip().lower() in TIME_NAMES),
                            None)  # fmt: skip
                if tcol is not None and fs is None:
                    t = frame[tcol].to_numpy(dtype=float)
                    if last_t is not None:
                        t = np.r_[last_t, t]
                    if t.size > 1 and np.ptp(np.diff(t)) > 1e-3 / rate:
                        raise ParameterError(f"{path}: time column {tcol!r} is not uniformly "
                                             "sampled; resample first")  # fmt: skip
                    last_t = t[-1]
                yield frame[name].to_numpy(dtype=float)

        return rate, name, None, gen()
    if suffix == ".parquet":
        import pyarrow.parquet as pq

        pf = pq.ParquetFile(path)

        def gen():
            for batch in pf.iter_batches(batch_size=block, columns=[name]):
                yield batch.column(0).to_numpy(zero_copy_only=False).astype(float)

        return rate, name, pf.metadata.num_rows, gen()
    if suffix in (".wav", ".npy"):
        if suffix == ".wav":
            from scipy.io import wavfile

            _, data = wavfile.read(path, mmap=True)
        else:
            data = np.load(path, mmap_mode="r")
        data = data.reshape(len(data), -1)
        ch = int(name.split()[-1])

        def gen():
            for a in range(0, data.shape[0], block):
                yield np.asarray(data[a : a + block, ch], dtype=float)

        return rate, name, int(data.shape[0]), gen()
    if suffix == ".nc":
        import xarray as xr

        ds = xr.open_dataset(path)
        da = ds[name]

        def gen():
            try:
                for a in range(0, da.shape[0], block):
                    yield np.asarray(da[a : a + block].values, dtype=float)
            finally:
                ds.close()

        return rate, name, int(da.shape[0]), gen()
    x = read_signal(path, column=column, fs=fs).x  # .mat: whole
    return rate, name, int(x.size), iter([x[a : a + block] for a in range(0, x.size, block)])


def record_length(path: str | Path, *, column=None) -> int | None:
    """The number of samples in ``path`` without reading its data: exact for Parquet, WAV,
    NPY and NetCDF (metadata, memory map, lazy array), estimated for text from the file size
    and the bytes per line of its first 256 kB; None for MAT (scipy reads it whole) or a file
    that cannot be inspected (the full reader then says why)."""
    path = Path(path)
    suffix = path.suffix.lower()
    try:
        if suffix in (".csv", ".txt", ".tsv"):
            size = path.stat().st_size
            with open(path, "rb") as fh:
                head = fh.read(1 << 18)
            lines = head.count(b"\n")
            if lines < 2 or len(head) == size:
                return max(lines - 1, 0) if len(head) == size else None
            return int(size / (len(head) / lines))
        if suffix == ".parquet":
            import pyarrow.parquet as pq

            return int(pq.ParquetFile(path).metadata.num_rows)
        if suffix == ".wav":
            from scipy.io import wavfile

            return int(len(wavfile.read(path, mmap=True)[1]))
        if suffix == ".npy":
            return int(np.load(path, mmap_mode="r").shape[0])
        if suffix == ".nc":
            import xarray as xr

            with xr.open_dataset(path) as ds:
                _unsensed(ds, path, column)
                names = [k for k, v in ds.data_vars.items() if v.ndim == 1]
                return int(ds[_pick(names, column, path, "variable")].shape[0])
    except ParameterError:
        raise
    except Exception:  # noqa: BLE001 - the full reader reports a malformed file
        return None
    return None


def speed_hz(speed) -> float | None:
    """A crank speed option ('191 rpm', '20 rad/s', '3.2 Hz') in revolutions per second."""
    if speed is None:
        return None
    f_rev = to_si("speed", speed, "rad/s") / (2 * np.pi)
    if not f_rev > 0:
        raise ParameterError(f"speed: {speed!r}; allowed: a positive speed, e.g. 191 rpm")
    return f_rev


def crank_revs(path: str | Path, n: int, fs: float, *, tacho=None, speed=None):
    """The crank angle (revolutions) at each of the first ``n`` samples of ``path``: from its
    once-per-revolution ``tacho`` column/channel (only its first ``n`` samples are read), or
    a constant ``speed``; None with neither."""
    from .analysis.vibration import crank_angle, tacho_times

    if tacho is not None:
        pulse = read_signal(path, column=tacho, fs=fs, rows=n)  # checks missing values
        if pulse.x.size < n:
            raise ParameterError(f"tacho {tacho!r}: {pulse.x.size} samples, the signal {n}")
        try:
            return crank_angle(n, fs, pulses=tacho_times(pulse.x, fs))
        except ValueError as exc:
            raise ParameterError(f"tacho {tacho!r}: {exc}") from None
    f_rev = speed_hz(speed)
    return None if f_rev is None else crank_angle(n, fs, speed_hz=f_rev)
