"""``make bench`` runs every benchmark and fails when one does (issue 44, item 11).

Seven benchmarks once stopped inside ``benchmarks/run_all.py`` with "main() takes 0
positional arguments but 1 was given" while ``make bench`` still exited 0. Here, without
running any benchmark's measurements: every ``benchmarks/bench_*.py`` imports, says what it
measures, and its ``main`` reads the arguments it is given (``--help`` answered from them
exits 0 at once; a main that read ``sys.argv`` or ignored its argument would run the whole
benchmark or fail on pytest's own arguments), and it has the ``--quick`` option that
``run_all.py --quick`` passes; and ``run_all.py`` runs a folder of stand-in benchmarks, lists
each as ran or FAILED (an exception, a nonzero ``sys.exit``, argparse's usage error) and exits
with status 1, or 0 when every one ran. A benchmark's functions pickle by name (a process
pool sends them to its workers).
"""

import contextlib
import inspect
import io
import pickle
import re
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"
sys.path.insert(0, str(BENCH))

import run_all  # noqa: E402  (benchmarks/ is not a package)

NAMES = sorted(p.stem for p in BENCH.glob("bench_*.py"))


def test_the_benchmarks_are_found():
    assert len(NAMES) >= 20 and "bench_memory" in NAMES and "bench_family" in NAMES


@pytest.mark.parametrize("name", NAMES)
def test_every_benchmark_reads_the_arguments_it_is_given(name):
    mod = run_all.load(BENCH / f"{name}.py")
    assert run_all.describe(mod) != "(no description)"
    assert pickle.loads(pickle.dumps(mod.main)) is mod.main  # a process pool can take it
    params = list(inspect.signature(mod.main).parameters.values())
    assert params and params[0].kind in (params[0].POSITIONAL_ONLY,
                                         params[0].POSITIONAL_OR_KEYWORD), name  # fmt: skip
    assert all(p.default is not p.empty for p in params[1:])
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit) as done:
        mod.main(["--help"])
    assert done.value.code in (0, None)
    assert "--quick" in out.getvalue()  # what run_all.py --quick passes
    extra = getattr(mod, "RUN_ALL_ARGV", [])
    assert set(extra) <= {"--quick"}, extra


STANDINS = {
    "bench_good.py": '"""A benchmark that works."""\n'
    "def main(argv=None):\n"
    "    return {'summary': [dict(metric='m', value=2.0, unit='x', target=1.0,"
    " better='higher')]}\n",
    "bench_raises.py": '"""A benchmark that raises."""\n'
    "def main(argv=None):\n    raise RuntimeError('boom')\n",
    "bench_exits.py": '"""A benchmark whose arguments are refused."""\n'
    "import argparse\n"
    "def main(argv=None):\n"
    "    ap = argparse.ArgumentParser()\n"
    "    ap.add_argument('dataset')\n"
    "    ap.parse_args(argv)\n",
    "bench_none.py": '"""A benchmark that prints and returns nothing."""\n'
    "def main(argv=None):\n    print('measured', argv)\n",
}


def _standins(folder: Path, which) -> Path:
    folder.mkdir()
    for name in which:
        (folder / name).write_text(STANDINS[name])
    return folder


def test_a_failing_benchmark_fails_make_bench(tmp_path, capsys):
    folder = _standins(tmp_path / "b", STANDINS)
    code = run_all.main(["--dir", str(folder), "--out", str(tmp_path / "res")])
    out = capsys.readouterr().out
    assert code == 1
    table = out[out.index("benchmark ") :]
    rows = {line.split()[0]: line for line in out.splitlines()
            if line.startswith("bench_") and ("ran" in line or "FAILED" in line)}  # fmt: skip
    assert "FAILED" in rows["bench_raises"] and "RuntimeError: boom" in rows["bench_raises"]
    assert "FAILED" in rows["bench_exits"] and "exit status 2" in rows["bench_exits"]
    assert " ran " in rows["bench_good"] and " ran " in rows["bench_none"]
    assert "2 ran, 2 failed" in table
    assert "measured []" in out  # the runner passes a list, never the command line's


def test_make_bench_succeeds_when_every_benchmark_ran(tmp_path, capsys):
    folder = _standins(tmp_path / "b", ["bench_good.py", "bench_none.py"])
    assert run_all.main(["--dir", str(folder), "--out", str(tmp_path / "res")]) == 0
    assert run_all.main(["--quick", "--dir", str(folder), "--out", str(tmp_path / "r")]) == 0
    out = capsys.readouterr().out
    assert "measured ['--quick']" in out and "2 ran, 0 failed" in out
    assert re.search(r"^good +m +2 x +≥ 1 +met", out, re.M)  # the table of metrics
