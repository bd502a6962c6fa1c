"""The size of the model layer (issue 43): files and lines of ``src/recipdyn/model``, and the
lines of code that live inside strings (templates of generated code), in this tree and in an
earlier revision.

A string counts as code when it is not a docstring, spans several lines and holds a ``def``,
a ``return``, an ``import`` or a decorator line: the text of a kernel that a module fills in
and writes out. Generated modules checked into the tree (``_generated*.py``, the sympy
kernels) are counted apart: they are code, but no one writes them by hand.

    python benchmarks/count_model_layer.py [--before REV]
"""

from __future__ import annotations

import argparse
import ast
import re
import subprocess
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
_CODE = re.compile(r"^\s*(def |return\b|from \S+ import|import |@)", re.M)


def _docstrings(tree: ast.AST) -> set[int]:
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            body = getattr(node, "body", [])
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                out.add(id(body[0].value))
    return out


def count(model: Path) -> dict[str, int]:
    files = lines = generated = generated_lines = string_code = 0
    for path in sorted(model.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        n = text.count("\n")
        if path.name.startswith("_generated") or path.name in (
                "_compressor_contact.py", "_compressor_contact_drive.py",
                "_compressor_contact_share.py", "_guide.py",
                "_double_pendulum.py"):  # fmt: skip
            generated += 1
            generated_lines += n
            continue
        files += 1
        lines += n
        tree = ast.parse(text)
        docs = _docstrings(tree)
        for node in ast.walk(tree):
            if (isinstance(node, ast.Constant) and isinstance(node.value, str)
                    and id(node) not in docs and "\n" in node.value
                    and _CODE.search(node.value)):  # fmt: skip
                string_code += node.value.count("\n")
    return dict(files=files, lines=lines, code_lines_in_strings=string_code,
                generated_files=generated, generated_lines=generated_lines)  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default=None, help="an earlier revision to count too")
    args = ap.parse_args()
    rows = {"now": count(ROOT / "src" / "recipdyn" / "model")}
    if args.before:
        with tempfile.TemporaryDirectory() as tmp:
            tar = subprocess.run(["git", "-C", str(ROOT), "archive", args.before,
                                  "src/recipdyn/model"], check=True,
                                 capture_output=True).stdout  # fmt: skip
            subprocess.run(["tar", "-x", "-C", tmp], input=tar, check=True)
            rows["before"] = count(Path(tmp) / "src" / "recipdyn" / "model")
    for label, row in rows.items():
        print(f"{label:7s} " + ", ".join(f"{k} {v}" for k, v in row.items()))


if __name__ == "__main__":
    main()
