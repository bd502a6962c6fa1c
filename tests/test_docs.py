"""The documentation: the site builds with every warning an error (mkdocs --strict: broken
links, missing pages, API objects and cross-references that do not resolve), every page of the
nav is produced, the API reference shows no raw Sphinx roles and no default written as an
expression, and the pages describe the package as it is (the history of changes lives in
CHANGELOG.md, not in docs/ or the README).

``python tests/test_docs.py`` prints the counts (history passages per page, words, raw roles)."""

import inspect
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = sorted((ROOT / "docs").glob("*.md")) + [ROOT / "README.md"]

DATE = r"20\d\d-\d\d-\d\d"
#: Phrases that narrate a change rather than describe the package ("Before 2026-11-24 the
#: function was ...", "X was 5.3x, now 3.8x", "used to stop", "Correction (...)").
HISTORY = re.compile("|".join([
    rf"\b(?:[Bb]efore|[Ss]ince|[Uu]ntil|[Oo]n|[Aa]fter) (?:the \w+ of )?{DATE}",
    r"\bwas\b[^.;]{0,80}\bnow\b", r"\bnow\b[^.;]{0,60}\bwas\b", r"\(was\b", r"\bused to\b",
    r"\b(?:is|are|runs?|uses?|costs?) now\b",
    r"\bnow (?:runs?|uses?|costs?|agrees?|redoes|starts?|is|are|a|the|\d)",
    r"\bthe (?:old|former)\b", r"\bbecame\b", r"\bBefore these\b",
    r"\ban earlier (?:run|version)\b",
    r"\bbefore the (?:change|fix)", r"\bwhat was tried\b", r"\*\*Now\b", r"\b[Pp]reviously\b",
    r"\b[Ff]ormerly\b", r"\bbefore → after\b", r"\bCorrection\b", rf"\bchanges? of {DATE}",
]))  # fmt: skip
#: Sphinx cross-reference roles, which mkdocstrings prints as they are (``:func:`x```).
ROLE = re.compile(r":(?:func|class|meth|data|mod|attr|exc|obj):`")


def passages(text: str) -> list[str]:
    """Paragraphs, list items and table rows of a Markdown page (code blocks left out)."""
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    parts = re.split(r"\n\s*\n|\n(?=\s*[*-] |\s*\d+\. |\|)", text)
    return [p for p in parts if p.strip()]


def is_history(passage: str) -> bool:
    """A passage that tells a story of changes: a history phrase, or a date that is not a short
    provenance note in parentheses (``(measured 2026-11-25, 2 cores)`` is allowed)."""
    if HISTORY.search(passage):
        return True
    short_parens = re.sub(r"\(([^()]{0,80})\)", "", passage)
    return re.search(DATE, short_parens) is not None


def history_counts() -> dict[str, int]:
    return {p.name: sum(map(is_history, passages(p.read_text(encoding="utf-8"))))
            for p in PAGES}  # fmt: skip


def raw_roles() -> dict[str, int]:
    counts = {}
    for f in sorted((ROOT / "src").rglob("*.py")):
        n = len(ROLE.findall(f.read_text(encoding="utf-8")))
        if n:
            counts[str(f.relative_to(ROOT))] = n
    return counts


def test_the_history_detector_finds_history_and_spares_provenance():
    """The counter below would pass vacuously if it found nothing: it must flag each kind of
    narrative and leave descriptions and short provenance notes alone."""
    told = [
        "Before 2026-11-24 the function was the product of the two penetrations.",
        "The ratio was 5.3x and is now 3.8x.",
        "At 70 rad/s rtol 1e-12 used to stop with a step-size underflow.",
        "Benettin's method runs on this model (since 2026-11-25; before, it was refused).",
        "Two changes of 2026-11-25, measured side by side on one machine, cut the time.",
        "On 2026-11-23 ours was 3.7e-4 at rtol 1e-10 in a run that compared one tolerance.",
    ]
    described = [
        "The contact joint runs 43x (42-53x) faster than SciPy (measured 2026-11-25, 2 cores).",
        "At 1 → 3 bar the volumetric efficiency is 0.865.",
        "The free oscillation is no longer pinned by the gas load above 60 rad/s.",
    ]
    assert all(map(is_history, told))
    assert not any(map(is_history, described))


def test_docs_describe_the_package_not_its_history():
    """docs/*.md and README.md carry no dated narrative of changes (CHANGELOG.md does)."""
    counts = {k: v for k, v in history_counts().items() if v}
    assert not counts, f"history passages per page (move them to CHANGELOG.md): {counts}"
    assert (ROOT / "CHANGELOG.md").stat().st_size > 1000


def test_docstrings_use_markdown_cross_references_not_sphinx_roles():
    """mkdocstrings renders ``[`name`][recipdyn.module.name]``; a Sphinx role would appear raw."""
    assert not raw_roles(), raw_roles()


def test_simulate_defaults_are_the_defaults_module_values():
    """simulate's signature writes its defaults as values (so the API reference shows them);
    they must be the single source's (defaults.SIMULATION)."""
    sys.path.insert(0, str(ROOT / "src"))
    from recipdyn.defaults import SIMULATION
    from recipdyn.simulate import simulate

    sig = inspect.signature(simulate).parameters
    assert {k: sig[k].default for k in SIMULATION} == SIMULATION


def test_docs_site_builds_strict(tmp_path):
    if shutil.which("mkdocs", path=str(Path(sys.executable).parent)) is None:
        pytest.fail("mkdocs is not installed: it is part of the dev extras (make test installs)")
    site = tmp_path / "site"
    env = {"NO_MKDOCS_2_WARNING": "1", "PATH": "/usr/bin:/bin"}
    for name in ("PYTHONPATH", "JUPYTER_PATH"):  # a checkout's sources, nbconvert's templates
        if name in os.environ:
            env[name] = os.environ[name]
    mkdocs = str(Path(sys.executable).parent / "mkdocs")
    proc = subprocess.run(  # run elsewhere: mkdocs-jupyter leaves a .cache folder in the cwd
        [mkdocs, "build", "--strict", "-f", str(ROOT / "mkdocs.yml"), "-d", str(site)],
        cwd=tmp_path, capture_output=True, text=True, timeout=600, env=env,
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
        "notebooks/05_contact_joint/index.html",
        "notebooks/06_gas_cycle_and_valves/index.html",
    )
    for page in pages:
        assert (site / page).stat().st_size > 1000, page
    api = (site / "api" / "index.html").read_text(encoding="utf-8")
    for name in ("simulate", "CompressorParams", "amplitude_spectrum", "compare_runs",
                 "lyapunov_spectrum"):  # fmt: skip
        assert name in api, name
    assert not ROLE.search(api), ROLE.findall(api)[:5]
    assert "DEFAULT_SETTINGS[" not in api
    assert "fs=10000.0" in re.sub(r"<[^>]+>", "", api)  # the value, not DEFAULT_SETTINGS["fs"]
    assert 'href="#recipdyn.model.base.ODESystem"' in api  # a cross-reference resolved
    # the notebooks are shown with their stored outputs (figures as images)
    nb = (site / "notebooks" / "05_contact_joint" / "index.html").read_text(encoding="utf-8")
    assert "data:image/png;base64" in nb


if __name__ == "__main__":
    counts = history_counts()
    words = sum(len(p.read_text(encoding="utf-8").split()) for p in PAGES)
    print({k: v for k, v in counts.items() if v})
    print(f"history passages {sum(counts.values())}, words {words}, "
          f"raw roles in src {sum(raw_roles().values())}")  # fmt: skip
