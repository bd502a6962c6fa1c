"""``recipdyn animate RUN.nc -o RUN.gif``: the mechanism in motion."""

from __future__ import annotations

from pathlib import Path

import typer

from .common import app


@app.command()
def animate(
    run: Path = typer.Argument(..., help="A compressor run (NetCDF from 'recipdyn simulate')."),
    out: Path = typer.Option(
        None, "--out", "-o", help="Animation: .gif or .mp4 (needs ffmpeg); default RUN.gif."
    ),
    exaggerate: float = typer.Option(
        None,
        "--exaggerate",
        help="Magnification of clearance and subsidence (default: the "
        "clearance drawn as 15 % of the crank radius).",
    ),
    revolutions: float = typer.Option(2.0, "--revolutions", "-n", help="Last revolutions shown."),
    fps: int = typer.Option(24, "--fps", help="Frames per second."),
    frames_per_revolution: int = typer.Option(48, "--frames-per-revolution"),
    progress: bool = typer.Option(True, "--progress/--no-progress"),
) -> None:
    """Animate the crank, the (magnified) clearance link, the rod and the crosshead.

    Below the mechanism: the crosshead acceleration, with a cursor at the frame's time."""
    from ..animate import animate_run
    from ..io import read_dataset

    ds = read_dataset(run)
    out = out or run.with_suffix(".gif")
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(desc="animate: frames", unit="frame")

    def tick(i, n, _bar=bar):
        if _bar is not None:
            _bar.total = n
            _bar.update(1)

    try:
        path = animate_run(ds, out, exaggerate=exaggerate, revolutions=revolutions, fps=fps,
                           frames_per_revolution=frames_per_revolution, progress=tick)  # fmt: skip
    finally:
        if bar is not None:
            bar.close()
    typer.echo(f"wrote {path}")
