"""``recipdyn analyze RUN.nc``."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from ..defaults import ANALYZE
from . import app, phase, report, with_json


@app.command()
@with_json
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
    tacho: str = typer.Option(
        None, "--tacho", help="Signal file: once-per-revolution pulse column/channel."
    ),
    speed: str = typer.Option(
        None, "--speed", help="Signal file: constant crank speed instead of a tacho (191rpm)."
    ),
    quantity: str = typer.Option(
        "acceleration", "--quantity", help="acceleration (m/s^2), velocity (m/s) or other."
    ),
    max_memory_samples: int = typer.Option(
        None,
        "--max-memory-samples",
        help="Signal file: longer records are read in blocks (whole-record statistics and "
        "spectrum; detailed analyses on the first 2^20 samples). Default 2^24.",
    ),
    zones: str = typer.Option(
        None,
        "--zones",
        help="Velocity zone boundaries A/B,B/C,C/D for your machine from ISO 20816-8, "
        "e.g. '2.3,4.5,7.1 mm/s'.",
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
                        lyap_revolutions=lyap_revolutions, phase=phase)  # fmt: skip
    else:
        if quantity not in ("acceleration", "velocity", "other"):
            raise ParameterError(f"quantity: {quantity!r}; allowed: acceleration, velocity, "
                                 "other")  # fmt: skip
        if tacho is not None and speed is not None:
            raise ParameterError("tacho and speed: give one of them")
        extra = {} if max_memory_samples is None else {"max_memory_samples": max_memory_samples}
        s = analyze_signal(run, out, column=column, fs=fs, tacho=tacho, speed=speed,
                           quantity=quantity, zones=zones, phase=phase,
                           progress=sys.stderr.isatty(), **extra)  # fmt: skip
        for note in s["notes"]:
            typer.echo(f"note: {note}")
        for name, value, status in s["evidence"]:
            typer.echo(f"  {name:<20} {value:<28} {status}")
    typer.echo(
        f"verdict: {s['verdict'].get('headline', s['verdict']['verdict'])} "
        f"({'; '.join(s['verdict']['reasons'])})"
    )
    typer.echo(f"wrote {out}/summary.md, summary.json and figures")
    report(**s, output=str(out))
