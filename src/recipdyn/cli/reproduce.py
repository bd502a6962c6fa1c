"""``recipdyn reproduce``: the paper's figures and numbers, side by side."""

from __future__ import annotations

from pathlib import Path

import typer

from .common import app, refused_leaves_nothing


@app.command()
def reproduce(
    out: Path = typer.Option(Path("out"), "--out", "-o", help="Output folder."),
    quick: bool = typer.Option(False, "--quick", help="Reduced lengths (smoke run)."),
    force: bool = typer.Option(False, "--force", help="Recompute cached runs."),
    jobs: int = typer.Option(None, "--jobs", "-j", help="Worker processes (default: all cores)."),
    progress: bool = typer.Option(True, "--progress/--no-progress"),
) -> None:
    """Rerun Xiao et al. (2017): figures, comparison table, HTML report (OUT/report.html)."""
    from ..errors import ParameterError

    if jobs is not None and jobs < 1:
        raise ParameterError(f"jobs = {jobs}; allowed: >= 1")
    from ..reproduce import reproduce as run

    with refused_leaves_nothing(out):
        path = run(out, quick=quick, force=force, jobs=jobs, progress=progress)
    typer.echo(f"wrote {path}, {out / 'comparison.md'}, {out / 'comparison.csv'}, "
               f"{out / 'figures'}/")  # fmt: skip


@app.command()
def calibrate(
    free: str = typer.Option(
        "m2,m3,J2", help="Comma list of parameters to fit (m2, m3, J2, theta_c_offset)."
    ),  # fmt: skip
    with_offset: bool = typer.Option(
        True, "--with-offset/--no-offset", help="Also fit with the initial link offset free."
    ),
    maxiter: int = typer.Option(15, help="Differential-evolution generations."),
    popsize: int = typer.Option(6, help="Population size multiplier."),
    jobs: int = typer.Option(1, "--jobs", "-j", help="Parallel workers (-1: all cores)."),
    out: Path = typer.Option(Path("out/calibration"), "--out", "-o"),
) -> None:
    """Fit the unknown inertia parameters to the paper's peak accelerations.

    The fit stays within physical bounds and reports how close any choice gets. The defaults
    are never changed."""
    from ..errors import ParameterError

    names = tuple(n.strip() for n in free.split(",") if n.strip())
    if maxiter < 1 or popsize < 1:
        raise ParameterError("maxiter and popsize must be >= 1")
    if jobs == 0 or jobs < -1:
        raise ParameterError(f"jobs = {jobs}; allowed: -1 (all cores) or >= 1")
    from ..reproduce.calibrate import calibrate as fit
    from ..reproduce.calibrate import write_calibration

    results = [fit(names, maxiter=maxiter, popsize=popsize, workers=jobs)]
    if with_offset and "theta_c_offset" not in names:
        results.append(fit((*names, "theta_c_offset"), maxiter=maxiter, popsize=popsize,
                           workers=jobs))  # fmt: skip
    path = write_calibration(results, out)
    for r in results:
        typer.echo(f"free {r['free']}: RMS log error {r['rms_log_error']:.3f}, best {r['best']}")
    typer.echo(f"wrote {path}")
