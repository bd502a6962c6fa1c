"""``recipdyn analyze RUN.nc``."""

from __future__ import annotations

from pathlib import Path

import typer

from ..defaults import ANALYZE
from . import app


@app.command()
def analyze(
    run: Path = typer.Argument(
        ...,
        help="A run from 'recipdyn simulate' (NetCDF), or a "
        "measured signal: CSV, TSV, TXT, WAV, MAT, NetCDF, Parquet, NPY.",
    ),
    out: Path = typer.Option(None, "--out", "-o", help="Output folder (default: RUN_analysis)."),
    section_points: int = typer.Option(
        ANALYZE["section_points"], "--section-points", help="Poincaré points."
    ),
    lyap_revolutions: float = typer.Option(
        ANALYZE["lyap_revolutions"], "--lyap-revolutions", help="Benettin averaging length."
    ),
    column: str = typer.Option(
        None, "--column", "-c", help="Signal file: column/variable name or index, WAV channel."
    ),
    fs: str = typer.Option(
        None,
        "--fs",
        help="Signal file: sampling rate, e.g. 10kHz (else "
        "from a time column, the WAV header or an fs variable).",
    ),
) -> None:
    """Spectrum, phase portraits, Poincaré section, Lyapunov exponents, 0-1 test, verdict."""
    from ..analyze import analyze_run, analyze_signal, is_record
    from ..model.parameters import ParameterError

    if not run.exists():
        raise ParameterError(f"run file not found: {run}")
    if section_points < 1 or lyap_revolutions <= 0:
        raise ParameterError("section_points must be >= 1 and lyap_revolutions > 0")
    out = out or run.with_name(run.stem + "_analysis")
    if column is None and fs is None and is_record(run):
        s = analyze_run(run, out, section_points=section_points,
                        lyap_revolutions=lyap_revolutions)  # fmt: skip
    else:
        s = analyze_signal(run, out, column=column, fs=fs)
        for note in s["notes"]:
            typer.echo(f"note: {note}")
        for name, value, status in s["evidence"]:
            typer.echo(f"  {name:<20} {value:<28} {status}")
    typer.echo(f"verdict: {s['verdict']['verdict']} ({'; '.join(s['verdict']['reasons'])})")
    typer.echo(f"wrote {out}/summary.md, summary.json and figures")
