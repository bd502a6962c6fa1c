"""``recipdyn compare A.nc B.nc ...``: overlays and a table of differences."""

from __future__ import annotations

from pathlib import Path

import typer

from .common import app, phase, refused_leaves_nothing, report, with_json


@app.command()
@with_json
def compare(
    runs: list[Path] = typer.Argument(
        ..., help="Two or more runs (NetCDF from 'recipdyn simulate'); the first is the reference."
    ),
    out: Path = typer.Option(Path("out/compare"), "--out", "-o", help="Output folder."),
    signal: str = typer.Option(
        None,
        "--signal",
        "-s",
        help="Variable to compare (default: a, the crosshead "
        "acceleration, or the first signal common to all runs).",
    ),
    labels: str = typer.Option(None, "--labels", help="Comma list of names for the runs."),
) -> None:
    """Compare runs: their signals, spectra and sections overlaid, and the inputs that differ.

    A table gives the differences of the main measures (peak, RMS, dominant line, own line,
    contact force) from the first run."""
    from ..errors import ParameterError

    names = [s.strip() for s in labels.split(",")] if labels else None
    if names is not None and len(names) != len(runs):
        raise ParameterError(f"labels: {len(names)} given for {len(runs)} runs")
    if len(runs) < 2:
        raise ParameterError(f"runs: {len(runs)} given; compare needs at least 2")
    for path in runs:  # before the analysis is loaded
        if not path.is_file():
            raise ParameterError(f"input {path}: file not found")
    from ..compare import MEASURES, compare_runs

    with phase(f"compare: reading and measuring {len(runs)} runs"), refused_leaves_nothing(out):
        s = compare_runs(runs, out, signal=signal, labels=names)
    for k, vals in s["differing_inputs"].items():
        typer.echo(f"  {k:<24} " + "  ".join(str(v) for v in vals))
    if not s["differing_inputs"]:
        typer.echo("  the runs have the same parameters and settings")
    typer.echo(f"{'run':<24} " + " ".join(f"{k:>20}" for k in MEASURES))
    for row in s["measures"]:
        typer.echo(f"{row['run'][:24]:<24} " + " ".join(f"{row[k]:>20.6g}" for k in MEASURES))
    typer.echo(f"wrote {out}/compare.png, compare.md, compare.json")
    report(**s, output=str(out))
