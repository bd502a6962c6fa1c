"""Packaging and first setup (issue 44, items 6 and 10).

* `pyproject.toml` states its license as an SPDX expression with its file (PEP 639): the
  TOML table form made pip warn three times that building stops on 2027-02-18; the build
  backend must be a setuptools that reads the new form (77 or later).
* `make env` says what it is doing before pip's quiet install (about 2.5 silent minutes).
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_license_is_an_spdx_expression_with_its_file():
    from packaging.licenses import canonicalize_license_expression

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    license_ = project["project"]["license"]
    assert isinstance(license_, str) and canonicalize_license_expression(license_) == "MIT"
    files = project["project"]["license-files"]
    assert files and all((ROOT / f).is_file() for f in files)
    assert "MIT License" in (ROOT / files[0]).read_text()
    (backend,) = [r for r in project["build-system"]["requires"] if r.startswith("setuptools")]
    assert int(re.search(r">=\s*(\d+)", backend).group(1)) >= 77, backend


def test_make_env_says_what_it_does_before_pip_installs():
    """The recipe of the environment's stamp echoes a line before its first pip install."""
    text = (ROOT / "Makefile").read_text()
    recipe = text.split("$(STAMP):", 1)[1].split("\n\n", 1)[0].splitlines()[1:]
    first_pip = next(i for i, line in enumerate(recipe) if "pip install" in line)
    said = [line for line in recipe[:first_pip] if line.strip().startswith("@echo")]
    assert said and "pip" in said[0], recipe
