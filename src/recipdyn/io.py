"""Reading and writing result files safely.

* Outputs are checked *before* any work ([`check_output`][recipdyn.io.check_output]): a known format
  from the file extension, a folder that exists or can be made, and permission to write there.
* Every file is written to a temporary name in the same folder and renamed when complete
  ([`atomic_path`][recipdyn.io.atomic_path]): an interrupted or failed write never destroys the
  previous file and never leaves a half-written one under the final name.
* Inputs are read with clear refusals ([`read_dataset`][recipdyn.io.read_dataset]): missing, empty,
  not the expected format, or missing variables ->
  [`ParameterError`][recipdyn.errors.ParameterError] naming what is wrong.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

from .errors import ParameterError

__all__ = [
    "DATASET_FORMATS", "check_output", "atomic_path", "write_dataset", "read_dataset",
    "write_text", "save_figure", "StreamWriter", "open_record", "forcing_frequency",
    "remove_orphans",
]  # fmt: skip


def forcing_frequency(attrs) -> float | None:
    """The forcing frequency (Hz) a simulation record states: the compressor's crank
    frequency, or ``1 / period`` of a periodically forced model; ``None`` for an autonomous
    system or a record without either."""
    fc = attrs.get("crank_frequency_hz")
    if fc:
        return float(fc)
    try:  # a number (also a numpy scalar read from a file) or a text for autonomous systems
        period = float(attrs.get("period"))
    except (TypeError, ValueError):
        return None
    return 1.0 / period if period > 0 else None


#: File extension -> format of a simulated record.
DATASET_FORMATS = {".nc": "NetCDF", ".csv": "CSV", ".zarr": "Zarr", ".mat": "MAT"}


def check_output(path: str | Path, formats: dict[str, str] | None = DATASET_FORMATS,
                 what: str = "output") -> Path:  # fmt: skip
    """Check that ``path`` can be written (before computing anything); returns it as a Path.

    ``formats`` maps allowed extensions to names (``None``: any extension, e.g. a folder).
    """
    path = Path(path)
    if formats is not None and path.suffix.lower() not in formats:
        allowed = ", ".join(f"{k} ({v})" for k, v in formats.items())
        raise ParameterError(
            f"{what} {path}: unknown extension {path.suffix or '(none)'!r}; allowed: {allowed}"
        )
    folder = path.parent if formats is not None else path
    try:  # made now, so that an impossible path is reported before any work
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ParameterError(f"{what} {path}: cannot create folder {folder} "
                             f"({exc.strerror or exc})") from None  # fmt: skip
    if not folder.is_dir():
        raise ParameterError(f"{what} {path}: {folder} is not a folder")
    try:  # permissions can lie (root, read-only mounts): try it
        fd, probe = tempfile.mkstemp(dir=folder, prefix=".recipdyn-probe-")
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise ParameterError(f"{what} {path}: folder {folder} is not writable "
                             f"({exc.strerror or exc})") from None  # fmt: skip
    if formats is not None and path.suffix.lower() != ".zarr" and path.is_dir():
        raise ParameterError(f"{what} {path}: is a folder, expected a file name")
    return path


@contextlib.contextmanager
def atomic_path(path: str | Path, *, directory: bool = False) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; rename it to ``path`` if the block succeeds.

    On any exception (including an interruption) the temporary file is removed and the
    previous content of ``path``, if any, is untouched. A process ended from outside while
    inside the block (a pool worker terminated when a run is interrupted, ``kill -9``) cannot
    clean up: the temporary folder carries its process id, and
    [`remove_orphans`][recipdyn.io.remove_orphans] removes it once that process is gone.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.tmp-{os.getpid()}-"))
    target = tmp / path.name if not directory else tmp / "data"
    try:
        yield target
        if directory:
            old = None
            if path.exists():
                old = path.with_name(f".{path.name}.old-{os.getpid()}")
                os.replace(path, old)
            os.replace(target, path)
            if old is not None:
                shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(target, path)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def remove_orphans(folder: str | Path) -> int:
    """Remove the temporary folders [`atomic_path`][recipdyn.io.atomic_path] left in ``folder``
    whose process no longer runs (never a finished result, never another live process's work);
    returns how many."""
    import re

    n = 0
    for tmp in Path(folder).glob(".*.tmp-*"):
        m = re.search(r"\.tmp-(\d+)-", tmp.name)
        if m is None or not tmp.is_dir():
            continue
        try:
            os.kill(int(m.group(1)), 0)
            continue  # its process still runs
        except ProcessLookupError:
            pass
        except PermissionError:
            continue  # another user's live process
        shutil.rmtree(tmp, ignore_errors=True)
        n += 1
    return n


def lazy_duck_arrays() -> None:
    """Let xarray build datasets without importing dask or pint until they are in use.

    xarray asks of every array it wraps whether it is a dask array or a pint quantity, and
    answers by importing ``dask.array`` and ``pint`` (together 0.5-1 s of a 10-revolution
    ``simulate``). No array can be a dask array before ``dask.array`` is imported, nor a
    quantity before ``pint`` is, so until then the answer is "no" without the import; once
    anything imports them (a chunked read, a sweep, a unit conversion), xarray's own answer is
    used. Installs once per process; a no-op if xarray's internals differ from the version this
    was written for (``xarray.namedarray.pycompat``), which then imports them as before.
    """
    import sys

    try:
        from xarray.namedarray import pycompat

        cache = pycompat._cached_duck_array_modules
        base = pycompat.DuckArrayModule
    except (ImportError, AttributeError):  # pragma: no cover - another xarray
        return

    class _OnDemand(base):
        def __init__(self, mod: str, marker: str) -> None:  # no import here
            self._mod, self._marker = mod, marker

        def _real(self):
            real = base(self._mod)
            cache[self._mod] = real
            return real

        @property
        def type(self):
            return self._real().type if self._marker in sys.modules else ()

        def __getattr__(self, name: str):  # module, version, available: xarray's answer
            if name.startswith("_"):
                raise AttributeError(name)
            return getattr(self._real(), name)

    for mod, marker in (("dask", "dask.array"), ("pint", "pint")):
        if mod not in cache:
            cache[mod] = _OnDemand(mod, marker)
    _lazy_dask_collection()


def _lazy_dask_collection() -> None:
    """xarray's index building asks ``dask.base.is_dask_collection`` of every coordinate,
    importing dask (0.07 s with its jinja2). An object is a dask collection only through
    ``__dask_graph__``; without that method (every numpy array) the answer is no without the
    import; with it, xarray's own answer."""
    try:
        from xarray.namedarray import utils
    except ImportError:  # pragma: no cover - another xarray
        return
    real = getattr(utils, "is_dask_collection", None)
    if real is None or getattr(real, "_recipdyn_lazy", False):
        return

    def is_dask_collection(x: object) -> bool:
        if sys.modules.get("dask") is None and not hasattr(type(x), "__dask_graph__"):
            return False
        return real(x)

    is_dask_collection._recipdyn_lazy = True
    utils.is_dask_collection = is_dask_collection


@contextlib.contextmanager
def _no_unused_scheduler() -> Iterator[None]:
    """While writing NetCDF or computing a dask-backed record, xarray asks dask which
    scheduler runs (to choose a lock), and dask asks ``distributed`` for a client, importing
    it (~0.4 s, 13 MB); before that, xarray imports dask itself to ask (6 MB and jinja2), even
    for a record of numpy arrays. A package not imported yet cannot be in use: no array can
    be a dask array before dask is imported, and no client can run before ``distributed``
    is. So this answers as if they were not installed, then puts everything back."""
    import sys

    hidden = [n for n in ("distributed", "dask.distributed") if "distributed" not in sys.modules
              and n not in sys.modules]  # fmt: skip
    if "dask" not in sys.modules:
        hidden += ["dask", "dask.base"]
    for name in hidden:
        sys.modules[name] = None  # an import of it raises ImportError, which dask expects
    try:
        yield
    finally:
        for name in hidden:
            if sys.modules.get(name, 0) is None:
                del sys.modules[name]


no_unused_scheduler = _no_unused_scheduler


def pandas_without_pyarrow() -> None:
    """Import pandas (which xarray imports) as if pyarrow were not installed, for a command
    that reads and writes no Parquet (``recipdyn simulate``: NetCDF, Zarr, CSV, MAT).

    pandas imports pyarrow at its own import whenever it is installed (for its Arrow-backed
    types; recipdyn installs it for the Parquet files of ``dataset``, ``features`` and
    ``analyze``): 34 MB of resident memory and ~0.3 s in every process that imports xarray.
    pandas then keeps its Python-backed string type, its default without pyarrow, which
    nothing of such a command stores. pyarrow itself stays importable. Does nothing when
    pandas or pyarrow is loaded already; never call it in a process that will read or write
    Parquet (the library never does: only the commands that need neither)."""
    import sys

    if "pandas" in sys.modules or "pyarrow" in sys.modules:
        return
    sys.modules["pyarrow"] = None  # an import of it raises ImportError: "not installed"
    try:
        import pandas  # noqa: F401
    finally:
        if sys.modules.get("pyarrow", 0) is None:
            del sys.modules["pyarrow"]


def write_dataset(ds, path: str | Path) -> Path:
    """Write a Dataset in the format its extension names (.nc, .csv, .zarr, .mat), atomically.

    CSV: one column per variable over the first dimension, ``name [units]`` headers, and the
    attributes as ``# key = value`` comment lines above the table. MAT (MATLAB 5, read by
    MATLAB, Octave and ``scipy.io.loadmat``): one variable per data variable and coordinate,
    a struct ``units`` (variable -> unit) and a struct ``attrs`` with every attribute.
    """
    path = check_output(path)
    fmt = DATASET_FORMATS[path.suffix.lower()]
    try:
        if fmt == "Zarr":
            with atomic_path(path, directory=True) as tmp:
                ds.to_zarr(str(tmp), mode="w", consolidated=False)
            return path
        with atomic_path(path) as tmp:
            if fmt == "NetCDF":
                with _no_unused_scheduler():
                    ds.to_netcdf(tmp)
            elif fmt == "MAT":
                _write_mat(ds, tmp)
            else:
                _write_csv(ds, tmp)
    except Exception as exc:  # HDF5/netCDF report a full disk as RuntimeError, zarr variously
        raise write_error(path, exc) from None
    return path


def write_error(path: Path, exc: BaseException) -> OSError:
    """An OSError naming the output, the cause and the free space left (a full disk?)."""
    if isinstance(exc, OSError) and exc.filename:
        reason = exc.strerror or str(exc)
    else:
        reason = str(exc) or type(exc).__name__
    try:
        free = shutil.disk_usage(path.parent).free
        reason += f"; {free / 1e6:.3g} MB free in {path.parent}"
    except OSError:
        pass
    return OSError(f"cannot write {path}: {reason}")


def _write_csv(ds, path: Path) -> None:
    import numpy as np

    dim = next((d for d in ("time", "iteration") if d in ds.dims), next(iter(ds.dims)))
    names = [k for k in ds.data_vars if ds[k].dims == (dim,)]
    other = [k for k in ds.data_vars if ds[k].dims != (dim,)]
    cols = [dim, *names]
    head = [f"{c} [{ds[c].attrs.get('units', '')}]" for c in cols]
    with open(path, "w", encoding="utf-8") as fh:
        for k, v in ds.attrs.items():
            fh.write(f"# {k} = {str(v).replace(chr(10), ' ')}\n")
        if other:  # e.g. event records: another dimension, not a column of this table
            fh.write(f"# not in this table (other dimensions; use .nc or .zarr): "
                     f"{', '.join(other)}\n")  # fmt: skip
        fh.write(",".join(head) + "\n")
        np.savetxt(fh, np.column_stack([ds[c].values for c in cols]), delimiter=",", fmt="%.17g")


def _mat_name(name: str) -> str:
    """A valid MATLAB identifier (letters, digits, underscores; a letter first; <= 63)."""
    import re

    out = re.sub(r"\W", "_", str(name))
    return (out if out[:1].isalpha() else "v_" + out)[:63]


def _write_mat(ds, path: Path) -> None:
    import numpy as np
    from scipy.io import savemat

    names = [*ds.coords, *ds.data_vars]
    data = {_mat_name(k): np.asarray(ds[k].values) for k in names}
    data["units"] = {_mat_name(k): str(ds[k].attrs.get("units", "")) for k in names}
    data["attrs"] = {_mat_name(k): (v if isinstance(v, (int, float, np.number)) else str(v))
                     for k, v in ds.attrs.items()}  # fmt: skip
    with open(path, "wb") as fh:
        savemat(fh, data, do_compression=True, oned_as="column", long_field_names=True)


def jsonable(obj):
    """``obj`` ready for strict JSON: numpy scalars and arrays to Python, paths to strings,
    dict keys to strings, NaN and infinities to ``None`` (JSON has no NaN)."""
    import math
    import os

    import numpy as np

    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [jsonable(v) for v in obj.tolist()]
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    return obj


def save_figure(fig, path: str | Path, **kw) -> Path:
    """``fig.savefig`` to ``path`` atomically."""
    path = Path(path)
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, format=path.suffix.lstrip(".") or "png", **kw)
    except Exception as exc:
        raise write_error(path, exc) from None
    return path


def read_dataset(path: str | Path, *, what: str = "input",
                 expected: str = "a recipdyn run (NetCDF from 'recipdyn simulate')"):  # fmt: skip
    """Open a NetCDF file as a loaded Dataset, refusing clearly when it is not what is needed."""
    import xarray as xr

    lazy_duck_arrays()

    path = Path(path)
    if not path.exists():
        raise ParameterError(f"{what} {path}: file not found")
    if path.is_dir():
        raise ParameterError(f"{what} {path}: is a folder; expected {expected}")
    if path.stat().st_size == 0:
        raise ParameterError(f"{what} {path}: file is empty; expected {expected}")
    try:
        with xr.open_dataset(path) as ds:
            ds = ds.load()
    except Exception as exc:  # netCDF4/h5netcdf/xarray raise assorted errors on foreign files
        raise ParameterError(f"{what} {path}: cannot be read as NetCDF "
                             f"({type(exc).__name__}); expected {expected}") from None  # fmt: skip
    return ds


def write_text(path: str | Path, text: str) -> Path:
    """Write UTF-8 text to ``path`` atomically."""
    path = Path(path)
    try:
        with atomic_path(path) as tmp:
            tmp.write_text(text, encoding="utf-8")
    except Exception as exc:
        raise write_error(path, exc) from None
    return path


class StreamWriter:
    """Write a long record block by block, so memory stays flat in run length.

    Blocks (Datasets over ``time``) are appended as they are computed: to a NetCDF-4 file with
    an unlimited ``time`` dimension (netCDF4, one write per variable and block) for ``.nc``, to
    a Zarr store (``to_zarr(append_dim="time")``) for ``.zarr``. Both are built beside the
    output and moved into place by `finish`, so nothing is at ``path`` until the record
    is complete; ``finish(partial=True)`` keeps an incomplete record as ``NAME.partial.EXT``.
    ``float32`` stores the signals (not time) in single precision; ``compress`` adds zlib
    compression to NetCDF (Zarr is always compressed).
    """

    #: Samples per NetCDF chunk.
    CHUNK = 1 << 16

    def __init__(self, path: str | Path, *, float32: bool = False, compress: bool = False):
        path = check_output(path)
        if path.suffix.lower() not in (".nc", ".zarr"):
            raise ParameterError(f"streamed output {path}: use .nc or .zarr (CSV is written in "
                                 "one piece: shorten the run or choose .nc)")  # fmt: skip
        self.path, self.float32, self.compress = path, float32, compress
        self.zarr = path.suffix.lower() == ".zarr"
        self.tmpdir = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.stream-"))
        self.tmp = self.tmpdir / ("data.zarr" if self.zarr else "data.nc")
        self.nc = None
        self.n = 0

    def append(self, block) -> None:
        import numpy as np

        m = block.sizes["time"]
        if self.float32:  # the signals only: time and the coordinates keep float64
            block = block.assign({k: v.astype(np.float32) for k, v in block.data_vars.items()
                                  if v.dtype == np.float64})  # fmt: skip
        try:
            if self.zarr:
                if self.n == 0:
                    self.order = list(block.data_vars)
                    block.to_zarr(str(self.tmp), mode="w", consolidated=False)
                else:
                    block.to_zarr(str(self.tmp), append_dim="time", consolidated=False)
            else:
                if self.nc is None:
                    self._create(block)
                for name in [*block.coords, *block.data_vars]:
                    self.nc.variables[name][self.n : self.n + m] = block[name].values
        except Exception as exc:
            raise write_error(self.path, exc) from None
        self.n += m

    def _add(self, extra) -> None:
        if self.zarr:
            extra.to_zarr(str(self.tmp), mode="a", consolidated=False)
            self.order += list(extra.data_vars)
            return
        for dim, size in extra.sizes.items():
            if dim not in self.nc.dimensions:
                self.nc.createDimension(dim, size)
        for name, v in extra.data_vars.items():
            var = self.nc.createVariable(name, v.dtype, v.dims, zlib=self.compress, complevel=4)
            var[:] = v.values
            var.setncatts(dict(v.attrs))

    def _create(self, block) -> None:
        import netCDF4

        self.nc = netCDF4.Dataset(self.tmp, "w", format="NETCDF4")
        self.nc.createDimension("time", None)
        coords = [c for c in block.coords if c != "time"]
        for name in ["time", *coords, *block.data_vars]:
            v = block[name]
            var = self.nc.createVariable(name, v.dtype, ("time",), zlib=self.compress,
                                         complevel=4, chunksizes=(self.CHUNK,))  # fmt: skip
            # HDF5 keeps up to its chunk cache per variable in memory (netCDF's default grows
            # with the file): two chunks are enough for appending in order
            var.set_var_chunk_cache(size=2 * self.CHUNK * 8, nelems=4, preemption=1.0)
            var.setncatts({k: val for k, val in v.attrs.items()})
            if name in block.data_vars and coords:
                var.coordinates = " ".join(coords)

    def finish(self, attrs: dict, *, partial: bool = False, extra=None) -> Path | None:
        """Move the record into place (``NAME.partial.EXT`` if ``partial``); ``None`` when
        no sample was written. ``extra``: a Dataset of variables over other dimensions than
        ``time`` (a model's events), written whole before the record is moved."""
        path = self.path
        if partial:
            path = path.with_name(path.stem + ".partial" + path.suffix)
        try:
            if self.n == 0:
                return None
            if extra is not None and extra.data_vars:
                self._add(extra)
            if self.zarr:
                import zarr

                # a Zarr group lists its arrays in the file system's order (not the order they
                # were written in): the column order is kept as an attribute for open_record
                attrs = {**attrs, ORDER_ATTR: " ".join(self.order)}
                zarr.open_group(str(self.tmp), mode="r+").attrs.update(attrs)
            else:
                self.nc.setncatts(dict(attrs))
                self.nc.close()
                self.nc = None
            with atomic_path(path, directory=self.zarr) as target:
                os.replace(self.tmp, target)
        except Exception as exc:
            raise write_error(path, exc) from None
        finally:
            self.discard()
        return path

    def discard(self) -> None:
        if self.nc is not None:
            try:
                self.nc.close()
            except Exception:  # pragma: no cover - already broken
                pass
            self.nc = None
        shutil.rmtree(self.tmpdir, ignore_errors=True)


ORDER_ATTR = "data_variables"


def open_record(path: str | Path):
    """A record written by [`StreamWriter`][recipdyn.io.StreamWriter], opened lazily (dask, chunk by
    chunk).

    Without a default index on ``time``: xarray would read the whole time coordinate into a
    pandas index (16 bytes a sample, twice over while it is built: 500 MB at 10^4
    revolutions), undoing the streaming. Select by position (``isel``), or add the index when
    the record fits in memory: ``ds.set_xindex("time")``."""
    import xarray as xr

    path = Path(path)
    if path.suffix.lower() == ".zarr":
        ds = xr.open_zarr(str(path), consolidated=False, create_default_indexes=False)
        order = ds.attrs.pop(ORDER_ATTR, "").split()
        if sorted(order) == sorted(ds.data_vars):
            ds = ds[order]
        return ds
    return xr.open_dataset(path, chunks={}, create_default_indexes=False)
