"""``recipdyn analyze RUN.nc``."""

from __future__ import annotations

from pathlib import Path

import typer

from ..defaults import ANALYZE
from . import app


@app.command()
def analyze(
    run: Path = typer.Argument(..., help="NetCDF file written by 'recipdyn simulate'."),
    out: Path = typer.Option(None, "--out", "-o", help="Output folder (default: RUN_analysis)."),
    section_points: int = typer.Option(
        ANALYZE["section_points"], "--section-points", help="Poincaré points."
    ),
    lyap_revolutions: float = typer.Option(
        ANALYZE["lyap_revolutions"], "--lyap-revolutions", help="Benettin averaging length."
    ),
) -> None:
    """Spectrum, phase portraits, Poincaré section, Lyapunov exponents, 0-1 test, verdict."""
    from ..analyze import analyze_run
    from ..model.parameters import ParameterError

    if not run.exists():
        raise ParameterError(f"run file not found: {run}")
    if section_points < 1 or lyap_revolutions <= 0:
        raise ParameterError("section_points must be >= 1 and lyap_revolutions > 0")
    out = out or run.with_name(run.stem + "_analysis")
    s = analyze_run(run, out, section_points=section_points, lyap_revolutions=lyap_revolutions)
    typer.echo(f"verdict: {s['verdict']['verdict']} ({'; '.join(s['verdict']['reasons'])})")
    typer.echo(f"wrote {out}/summary.md, summary.json and figures")
