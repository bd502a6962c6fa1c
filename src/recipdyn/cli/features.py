"""``recipdyn features INPUT... -o TABLE``: a feature table for machine learning."""

from __future__ import annotations

from pathlib import Path

import typer

from .common import app, phase, refused_leaves_nothing


@app.command()
def features(
    inputs: list[Path] = typer.Argument(
        ...,
        help="Runs (NetCDF from 'recipdyn simulate'), "
        "signal files, or sweep stores (one row per point).",
    ),
    out: Path = typer.Option(..., "--out", "-o", help="Table to write: .csv or .parquet."),
    column: str = typer.Option(None, "--column", "-c", help="Signal files: column/variable."),
    fs: str = typer.Option(None, "--fs", help="Signal files: sampling rate, e.g. 10kHz."),
    window: str = typer.Option(
        None,
        "--window",
        "-w",
        help="One row per window: e.g. '2 s' or '10 rev' (default: one row per input).",
    ),
    speed: str = typer.Option(
        None,
        "--speed",
        help="Crank speed for order features, e.g. 191rpm (recipdyn runs know theirs).",
    ),
    tacho: str = typer.Option(None, "--tacho", help="Once-per-revolution pulse column."),
    chaos: bool = typer.Option(
        False,
        "--chaos",
        help="Add the 0-1 test and the Rosenstein exponent with their statuses (slower).",
    ),
    progress: bool = typer.Option(True, "--progress/--no-progress"),
    max_memory_samples: int = typer.Option(
        None,
        "--max-memory-samples",
        help="Signal files without --window: longer ones are refused (their one row needs the "
        "whole file in memory; with --window any length is read block by block). Default 2^24.",
    ),
) -> None:
    """Tabulate features: time-domain statistics, spectral and order features, chaos indicators.

    One row per run or window, labelled with the run's parameters."""
    from ..errors import ParameterError
    from .analyze import check_rates

    if out.suffix.lower() not in (".csv", ".parquet"):  # before any work
        raise ParameterError(f"output {out}: use .csv or .parquet")
    for path in inputs:
        if not path.exists():
            raise ParameterError(f"input not found: {path}")
    if max_memory_samples is not None and max_memory_samples < 1:
        raise ParameterError(f"max_memory_samples = {max_memory_samples}; allowed: >= 1")
    if tacho is not None and speed is not None:
        raise ParameterError("tacho and speed: give one of them")
    check_rates(fs=fs, speed=speed)
    from ..features import file_features, write_dictionary, write_table
    from ..sweep.run import sweep_features

    rows: list[dict] = []
    meta: dict = {}  # column -> unit, description, note: the data dictionary
    for path in inputs:
        with phase(f"features of {path.name}"):
            if path.is_dir():
                rows += [{"store": path.name, **r} for r in sweep_features(path, meta)]
            else:
                extra = {} if max_memory_samples is None else {
                    "max_memory_samples": max_memory_samples}  # fmt: skip
                rows += file_features(path, column=column, fs=fs, window=window, speed=speed,
                                      tacho=tacho, chaos=chaos, progress=progress,
                                      meta=meta, **extra)  # fmt: skip
    with refused_leaves_nothing(out):
        write_table(rows, out)
        guide = write_dictionary(meta, rows, out)
    typer.echo(f"wrote {len(rows)} row(s) to {out}; units, descriptions and notes of its "
               f"columns in {guide}")  # fmt: skip
