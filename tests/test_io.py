"""recipdyn.io: datasets are built and written without loading dask, pint or distributed
unless they are in use, and dask arrays and quantities are still recognised once they are."""

from __future__ import annotations

import json
import os
import subprocess
import sys

#: Run in a fresh interpreter: the test process has long imported dask.
_PROBE = r"""
import json, sys
import numpy as np
import xarray as xr
from recipdyn.io import lazy_duck_arrays, write_dataset

lazy_duck_arrays()
bare = xr.Dataset({"b": ("n", np.arange(4.0))})  # no index: xarray has not imported dask yet
indexed = xr.Dataset({"a": ("time", np.arange(5.0))}, coords={"time": np.arange(5.0)})
dask_after_build = "dask" in sys.modules  # an index asks whether its data are a dask collection
write_dataset(bare, sys.argv[1] + "/bare.nc")
bare_equal = bool(xr.open_dataset(sys.argv[1] + "/bare.nc").b.equals(bare.b))
ds = xr.Dataset({"a": ("time", np.arange(50.0))}, coords={"time": np.arange(50.0) / 10})
out = {"dask_array_after_build": "dask.array" in sys.modules,
       "dask_after_build": dask_after_build,
       "pint_after_build": "pint" in sys.modules}
write_dataset(ds, sys.argv[1] + "/plain.nc")
out["distributed_after_write"] = "distributed" in sys.modules
out["bare_equal"] = bare_equal

out["hidden_left"] = sorted(k for k, v in sys.modules.items() if v is None and "dask" in k
                            or v is None and k.startswith("distributed"))
back = xr.open_dataset(sys.argv[1] + "/plain.nc").load()
out["plain_equal"] = bool(back.a.equals(ds.a))

import dask.array as da
chunked = xr.Dataset({"a": ("time", da.arange(50.0, chunks=10))})
out["recognised"] = type(chunked.a.data).__module__.startswith("dask")
out["chunks"] = list(chunked.chunks["time"])
write_dataset(chunked, sys.argv[1] + "/chunked.nc")
out["chunked_equal"] = bool(xr.open_dataset(sys.argv[1] + "/chunked.nc").a.values.tolist()
                            == list(np.arange(50.0)))
import pint
q = xr.DataArray(pint.UnitRegistry().Quantity(np.arange(3.0), "m"), dims="x")
out["quantity_kept"] = isinstance(q.data, pint.Quantity)
print(json.dumps(out))
"""


def test_records_are_built_and_written_without_dask_until_it_is_used(tmp_path):
    """xarray asks of every array whether it is a dask array or a pint quantity (importing
    dask.array and pint) and, when writing NetCDF, which dask scheduler runs (importing
    distributed): about a second of a short simulate. Until they are imported nothing can be
    one, so `lazy_duck_arrays` answers no without importing them; the write hides the
    unimported schedulers and puts them back. Once imported, chunked data are dask arrays
    again and are written whole, and a quantity stays a quantity."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run([sys.executable, "-c", _PROBE, str(tmp_path)], env=env,
                          capture_output=True, text=True, timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    res = json.loads(done.stdout.strip().splitlines()[-1])
    assert res == {"dask_array_after_build": False, "dask_after_build": False,
                   "pint_after_build": False,
                   "distributed_after_write": False, "bare_equal": True, "hidden_left": [],
                   "plain_equal": True,
                   "recognised": True, "chunks": [10] * 5, "chunked_equal": True,
                   "quantity_kept": True}  # fmt: skip


def test_a_torn_unit_cache_file_is_parsed_again(tmp_path, monkeypatch):
    """pint writes its cache of parsed unit definitions in place, so a process can find a file
    another one is still writing (two test workers, two sweeps starting on a fresh machine).
    Such a file is ignored: the units are parsed again and the value is right."""
    from recipdyn import quantity, units

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    quantity._ureg.cache_clear()
    try:
        assert units.to_si("rc", "1 mm") == 1e-3  # fills the cache
        files = [p for p in (tmp_path / "recipdyn" / "pint").rglob("*.pickle")]
        assert files
        for p in files:
            p.write_bytes(p.read_bytes()[:20])  # torn halfway
        quantity._ureg.cache_clear()
        assert units.to_si("omega", "191 rpm") == 191 * 2 * 3.141592653589793 / 60
    finally:
        quantity._ureg.cache_clear()
