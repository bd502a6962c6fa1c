"""``recipdyn reproduce``: the paper's figures and numbers, side by side."""

from __future__ import annotations

from pathlib import Path

import typer

from . import app


@app.command()
def reproduce(
    out: Path = typer.Option(Path("out"), "--out", "-o", help="Output folder."),
    quick: bool = typer.Option(False, "--quick", help="Reduced lengths (smoke run)."),
    force: bool = typer.Option(False, "--force", help="Recompute cached runs."),
    jobs: int = typer.Option(None, "--jobs", "-j", help="Worker processes (default: all cores)."),
    progress: bool = typer.Option(True, "--progress/--no-progress"),
) -> None:
    """Rerun Xiao et al. (2017): figures, comparison table, HTML report (OUT/report.html)."""
    from ..model.parameters import ParameterError
    from ..reproduce import reproduce as run

    if jobs is not None and jobs < 1:
        raise ParameterError(f"jobs = {jobs}; allowed: >= 1")
    path = run(out, quick=quick, force=force, jobs=jobs, progress=progress)
    typer.echo(f"wrote {path}, {out / 'comparison.md'}, {out / 'comparison.csv'}, "
               f"{out / 'figures'}/")  # fmt: skip
