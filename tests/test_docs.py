"""The documentation site builds with every warning an error (mkdocs --strict: broken links,
missing pages, API objects that do not resolve), and every page of the nav is produced."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_docs_site_builds_strict(tmp_path):
    if shutil.which("mkdocs", path=str(Path(sys.executable).parent)) is None:
        pytest.fail("mkdocs is not installed: it is part of the dev extras (make test installs)")
    site = tmp_path / "site"
    proc = subprocess.run(
        [str(Path(sys.executable).parent / "mkdocs"), "build", "--strict", "-d", str(site)],
        cwd=ROOT, capture_output=True, text=True, timeout=600,
        env={"NO_MKDOCS_2_WARNING": "1", "PATH": "/usr/bin:/bin"},
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "WARNING" not in proc.stderr, proc.stderr[-3000:]
    pages = (
        "index.html",
        "model/index.html",
        "reproduction/index.html",
        "reliability/index.html",
        "signal_analysis/index.html",
        "api/index.html",
    )
    for page in pages:
        assert (site / page).stat().st_size > 1000, page
    api = (site / "api" / "index.html").read_text(encoding="utf-8")
    for name in ("simulate", "CompressorParams", "amplitude_spectrum", "compare_runs",
                 "lyapunov_spectrum"):  # fmt: skip
        assert name in api, name
