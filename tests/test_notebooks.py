"""The tutorial notebooks in examples/notebooks: stored executed (with their outputs, small),
written against the public API (``import recipdyn`` only), and re-executed here on a real
kernel from a folder that is not theirs, without an error and with the text of their checked
cells (tagged ``check``) equal to the stored one, numbers within the cell's ``check_rtol``.

``python tests/test_notebooks.py`` re-executes every notebook and stores it with its outputs
(the way the stored outputs are made)."""

import ast
import os
import re
import sys
import tempfile
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

FOLDER = Path(__file__).resolve().parents[1] / "examples" / "notebooks"
NOTEBOOKS = sorted(FOLDER.glob("*.ipynb"))
#: A stored notebook stays small enough to review and to keep in git (figures at 60 dpi).
MAX_BYTES = 1_000_000
NUMBER = re.compile(r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)")


def execute(path: Path, cwd: Path) -> nbformat.NotebookNode:
    """Run ``path`` top to bottom with ``cwd`` as the kernel's working folder."""
    nb = nbformat.read(path, as_version=4)
    NotebookClient(nb, timeout=1200, kernel_name="python3",
                   resources={"metadata": {"path": str(cwd)}}).execute()  # fmt: skip
    return nb


def text_of(cell) -> str:
    out = []
    for o in cell.get("outputs", []):
        if o.get("output_type") == "stream" and o.get("name") == "stdout":
            out.append(o["text"])
        elif o.get("output_type") in ("execute_result", "display_data"):
            out.append(o.get("data", {}).get("text/plain", "") if "image/png" not in
                       o.get("data", {}) else "")  # fmt: skip
    return "".join(out)


def differences(new: str, old: str, rtol: float) -> list[str]:
    """Where two outputs differ: words must be equal (spacing aside), numbers equal within
    ``rtol`` relative to the larger (and 1e-12 absolute, for zeros)."""
    a, b = NUMBER.split(new), NUMBER.split(old)
    if len(a) != len(b):
        return [f"different shape:\n{new}\n--- stored ---\n{old}"]
    found = []
    for i, (x, y) in enumerate(zip(a, b, strict=True)):
        if i % 2 == 0:
            if x.split() != y.split():
                found.append(f"text {x!r} != stored {y!r}")
        elif abs(float(x) - float(y)) > rtol * max(abs(float(x)), abs(float(y))) + 1e-12:
            found.append(f"{x} != stored {y} (rtol {rtol:g})")
    return found


def test_the_output_comparison_tolerates_rounding_and_catches_changes():
    assert not differences("peak 57.61 m/s2, 3 impacts\n", "peak 57.62 m/s2, 3 impacts\n", 1e-3)
    assert differences("peak 57.61 m/s2\n", "peak 58.61 m/s2\n", 1e-3)
    assert differences("verdict: periodic\n", "verdict: chaotic\n", 1.0)
    assert differences("1 2 3\n", "1 2\n", 1.0)


def test_there_are_seven_tutorials():
    assert [p.name[:2] for p in NOTEBOOKS] == ["01", "02", "03", "04", "05", "06", "07"]
    names = " ".join(p.stem for p in NOTEBOOKS)
    assert "contact_joint" in names and "valves" in names and "diagnosis" in names


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_uses_only_the_public_api(path):
    """Only ``import recipdyn`` and its top-level names: no ``from recipdyn.sweep.run import``,
    no ``recipdyn.model.parameters.X``."""
    sys.path.insert(0, str(FOLDER.parents[1] / "src"))
    import recipdyn

    nb = nbformat.read(path, as_version=4)
    for cell in nb.cells:
        if cell.cell_type != "code":
            continue
        source = "\n".join("" if line.startswith("%") else line for line in cell.source.split("\n"))
        tree = ast.parse(source)  # IPython magics (%matplotlib inline) left out
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                assert not (node.module or "").startswith("recipdyn"), cell.source
            elif isinstance(node, ast.Import):
                assert all(a.name == "recipdyn" or not a.name.startswith("recipdyn")
                           for a in node.names), cell.source  # fmt: skip
            elif (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                  and node.value.id == "recipdyn"):  # fmt: skip
                public = node.attr in recipdyn.__all__ or node.attr.startswith("__")
                assert public, f"recipdyn.{node.attr} is not public"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_is_stored_executed_and_small(path):
    assert path.stat().st_size < MAX_BYTES, f"{path.name}: {path.stat().st_size} bytes"
    nb = nbformat.read(path, as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert all(c.execution_count for c in code), "stored without running every cell"
    outputs = [o for c in code for o in c.outputs]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    assert any("image/png" in o.get("data", {}) for o in outputs), "no figure stored"
    assert any("check" in c.metadata.get("tags", []) for c in code), "no checked cell"


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_runs_from_any_folder_and_reproduces_its_outputs(path, tmp_path, monkeypatch):
    """Run in a temporary folder (not the notebook's: paths must not assume the working
    folder). Tolerances are per cell (``check_rtol``): 1e-6 for deterministic short runs, wider
    where a count of impacts over a few revolutions depends on rounding at each impact."""
    monkeypatch.setenv("RECIPDYN_NB_OUT", str(tmp_path / "out"))
    monkeypatch.delenv("MPLBACKEND", raising=False)  # the kernel draws inline
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    new = execute(path, elsewhere)
    old = nbformat.read(path, as_version=4)
    errors = [o for c in new.cells if c.cell_type == "code" for o in c.get("outputs", [])
              if o.get("output_type") == "error"]  # fmt: skip
    assert not errors, errors[0].get("evalue") if errors else ""
    checked = 0
    for c_new, c_old in zip(new.cells, old.cells, strict=True):
        if "check" in c_new.metadata.get("tags", []):
            rtol = float(c_new.metadata.get("check_rtol", 1e-6))
            found = differences(text_of(c_new), text_of(c_old), rtol)
            assert not found, found
            checked += 1
    assert checked


def _store(paths) -> None:
    """Execute and store each notebook with its outputs (volatile metadata removed)."""
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["RECIPDYN_NB_OUT"] = str(Path(tmp) / "out")
        os.environ.pop("MPLBACKEND", None)  # the kernel draws inline
        for path in paths:
            nb = execute(path, Path(tmp))
            for c in nb.cells:
                c.metadata.pop("execution", None)
            nb.metadata.pop("widgets", None)
            nbformat.write(nb, path)
            print(f"{path.name}: {path.stat().st_size} bytes")


if __name__ == "__main__":
    _store([Path(p) for p in sys.argv[1:]] or NOTEBOOKS)
