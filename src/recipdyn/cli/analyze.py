"""``recipdyn analyze RUN.nc``."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from ..defaults import ANALYZE
from .common import app, phase, refused_leaves_nothing, report, with_json


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
    from ..errors import ParameterError

    # the options are checked before the analysis (numba, SciPy, matplotlib) is loaded
    if not run.exists():
        raise ParameterError(f"run file not found: {run}")
    if section_points < 1 or not lyap_revolutions > 0:
        raise ParameterError("section_points must be >= 1 and lyap_revolutions > 0")
    if quantity not in ("acceleration", "velocity", "other"):
        raise ParameterError(f"quantity: {quantity!r}; allowed: acceleration, velocity, "
                             "other")  # fmt: skip
    if tacho is not None and speed is not None:
        raise ParameterError("tacho and speed: give one of them")
    if max_memory_samples is not None and max_memory_samples < 1:
        raise ParameterError(f"max_memory_samples = {max_memory_samples}; allowed: >= 1")
    check_rates(fs=fs, speed=speed)
    from ..analyze import analyze_run, analyze_signal, is_record

    out = out or run.with_name(run.stem + "_analysis")
    with refused_leaves_nothing(out):
        if column is None and fs is None and is_record(run):
            s = analyze_run(run, out, section_points=section_points,
                            lyap_revolutions=lyap_revolutions, phase=phase)  # fmt: skip
        else:
            extra = {} if max_memory_samples is None else {
                "max_memory_samples": max_memory_samples}  # fmt: skip
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


def check_rates(*, fs: str | None = None, speed: str | None = None) -> None:
    """Refuse a sampling rate or crank speed that is not a positive quantity (units via
    pint), before anything heavy is loaded; the readers convert them again."""
    from ..errors import ParameterError
    from ..units import to_si

    for name, text, unit in (("fs", fs, "Hz"), ("speed", speed, "rad/s")):
        if text is not None and not to_si(name, text, unit=unit) > 0:
            raise ParameterError(f"{name} = {text!r}; allowed: > 0")
