"""``recipdyn simulate`` loads what it needs and nothing more (issue 44, item 11).

A structural check, not a timing or a memory bound: the command runs in a fresh interpreter
and the test reads which modules it loaded. Its baseline memory had grown from 289 MB to
283-371 MB (`benchmarks/bench_memory.py`: the record alone, and with its figure) with
modules a simulation never uses: pandas imported pyarrow (34 MB; installed for the diagnosis
layer's Parquet files), xarray imported dask to choose a lock for a record of numpy arrays,
dask imported ``distributed`` to look for a cluster. The learning, web and diagnosis layers
must stay out too: each would add tens of MB to every run.
"""

import json
import os
import subprocess
import sys

import pytest

#: Never needed by ``recipdyn simulate`` of the default model to NetCDF.
NEVER = ("sklearn", "skops", "dash", "flask", "plotly", "pyarrow", "distributed", "dask",
         "zarr", "recipdyn.diagnosis", "recipdyn.app", "recipdyn.sweep", "recipdyn.sensors",
         "recipdyn.reproduce", "recipdyn.analyze", "recipdyn.features")  # fmt: skip
#: Needed only by the figure (``--no-figure`` leaves them out).
FIGURE = ("matplotlib", "scipy.signal", "scipy.stats", "recipdyn.plotting", "recipdyn.analysis")
#: Needed by every run: the probe saw a simulation, not an early exit.
ALWAYS = ("numba", "xarray", "netCDF4", "recipdyn.integrate", "recipdyn.simulate")


def _loaded(args: list[str], tmp_path) -> set[str]:
    """The modules ``recipdyn ARGS`` loaded, run in a new interpreter."""
    probe = (
        "import sys, json\n"
        "from recipdyn.cli import main\n"
        f"code = main({args!r})\n"
        "print(json.dumps(dict(code=code, modules=sorted(sys.modules))))\n"
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run([sys.executable, "-c", probe], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=1200)  # fmt: skip
    assert done.returncode == 0, done.stderr
    res = json.loads(done.stdout.strip().splitlines()[-1])
    assert res["code"] == 0, done.stderr
    return set(res["modules"])


def _present(names, modules: set[str]) -> list[str]:
    return [n for n in names if n in modules]


@pytest.mark.parametrize("figure", [True, False], ids=["figure", "no-figure"])
def test_simulate_loads_only_what_it_needs(tmp_path, figure):
    args = ["simulate", "-n", "0.2", "--fs", "2 kHz", "--no-progress", "-o", "run.nc"]
    modules = _loaded(args + ([] if figure else ["--no-figure"]), tmp_path)
    assert (tmp_path / "run.nc").exists()
    assert _present(ALWAYS, modules) == list(ALWAYS)
    assert _present(NEVER, modules) == []
    if figure:
        assert (tmp_path / "run.png").exists() and "matplotlib" in modules
    else:
        assert _present(FIGURE, modules) == []


def test_pyarrow_stays_usable_after_simulate_left_it_out(tmp_path):
    """The command hides pyarrow from pandas's import only: pandas works without it, and
    a Parquet file still round-trips afterwards in the same process (pyarrow imports on
    demand), its strings in pandas's own string type."""
    probe = (
        "import sys\n"
        "from recipdyn.io import pandas_without_pyarrow\n"
        "pandas_without_pyarrow()\n"
        "assert 'pandas' in sys.modules and 'pyarrow' not in sys.modules\n"
        "import pandas as pd\n"
        "df = pd.DataFrame({'a': [1.5, 2.5], 'b': ['x', 'y']})\n"
        "df.to_parquet('t.parquet')\n"
        "back = pd.read_parquet('t.parquet')\n"
        "assert back.a.tolist() == [1.5, 2.5] and back.b.tolist() == ['x', 'y']\n"
        "import pyarrow\n"
        "print('ok', pyarrow.__version__)\n"
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run([sys.executable, "-c", probe], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)  # fmt: skip
    assert done.returncode == 0 and done.stdout.startswith("ok"), done.stderr
