"""``recipdyn sweep`` and ``recipdyn plot``."""

from __future__ import annotations

from pathlib import Path

import typer

from ..defaults import SWEEP as DEFAULTS
from .common import app, refused_leaves_nothing


@app.command()
def sweep(
    params: list[str] = typer.Option(
        ...,
        "--param",
        "-p",
        help="NAME=start:stop:count[:log] or NAME=v1,v2 (units allowed); one or two.",
    ),  # fmt: skip
    measure: str = typer.Option(
        "poincare,peak",
        "--measure",
        "-m",
        help="Comma list of: poincare, peak, spectrum, lyapunov, verdict, features (the "
        "vibration signal's features for 'recipdyn features').",
    ),
    sets: list[str] = typer.Option(None, "--set", help="Base parameter NAME=VALUE (repeatable)."),
    config: Path = typer.Option(None, "--config", "-c", help="TOML config for the base case."),
    revolutions: float = typer.Option(
        DEFAULTS["revolutions"], help="Revolutions for peak/spectrum."
    ),
    transient: float = typer.Option(DEFAULTS["transient"], help="Revolutions discarded first."),
    points: int = typer.Option(DEFAULTS["points"], help="Stroboscopic points per value."),
    lyap_revolutions: float = typer.Option(DEFAULTS["lyap_revolutions"]),
    fs: str = typer.Option("10 kHz", help="Sampling rate for peak/spectrum."),
    rtol: float = typer.Option(DEFAULTS["rtol"], help="Relative tolerance (dop853)."),
    atol: float = typer.Option(DEFAULTS["atol"], help="Absolute tolerance (dop853)."),
    backend: str = typer.Option("processes", help="serial, processes or dask."),
    workers: int = typer.Option(None, help="Worker processes (default: all cores)."),
    dask_local: int = typer.Option(None, "--dask-local", help="Start a LocalCluster of N workers."),
    scheduler: str = typer.Option(None, help="Existing Dask scheduler, tcp://HOST:PORT."),
    continuation: bool = typer.Option(
        False, help="Each point starts from the previous one's final state (sequential, 1-D)."
    ),  # fmt: skip
    resume: bool = typer.Option(False, help="Continue an interrupted sweep in OUT."),
    force: bool = typer.Option(False, help="Overwrite an existing sweep in OUT."),
    out: Path = typer.Option(Path("out/sweep"), "--out", "-o"),
    progress: bool = typer.Option(True, "--progress/--no-progress"),
    max_memory: str = typer.Option(None, "--max-memory", help="Memory limit, e.g. '4 GB'."),
    model: str = typer.Option(
        None, "--model", help="A registered model or module:object (default: the compressor)."
    ),
) -> None:
    """Sweep one or two parameters; write OUT/sweep.zarr and the figures."""
    from ..errors import ParameterError
    from ..io import check_output
    from ..sweep.spec import split_axis
    from ..units import to_si
    from .simulate import _collect_model, max_memory_bytes

    # the options are checked before the sweep machinery (numba, xarray, zarr) is loaded
    if workers is not None and workers < 1:
        raise ParameterError(f"workers = {workers}; allowed: >= 1")
    if dask_local is not None and dask_local < 1:
        raise ParameterError(f"dask_local = {dask_local}; allowed: >= 1")
    if points < 1:
        raise ParameterError(f"points = {points}; allowed: >= 1")
    if backend not in ("serial", "processes", "dask"):
        raise ParameterError(f"backend = {backend!r}; allowed: serial, processes, dask")
    if not 1 <= len(params) <= 2:
        raise ParameterError(f"a sweep needs 1 or 2 --param axes, got {len(params)}")
    measures = tuple(x.strip() for x in measure.split(",") if x.strip())
    bad = [x for x in measures if x not in _MEASURES]
    if bad or not measures:
        raise ParameterError(f"--measure {bad or '(none)'}; allowed: {', '.join(_MEASURES)}")
    for p in params:  # (the axes' syntax and counts; their names need the model)
        split_axis(p)
    settings = dict(revolutions=revolutions, transient=transient, points=points,
                    lyap_revolutions=lyap_revolutions, fs=to_si("fs", fs), rtol=rtol,
                    atol=atol)  # fmt: skip
    limit = max_memory_bytes(max_memory)
    m, base, _ = _collect_model(model, None, None, None, sets, config, load=False)
    if dask_local is not None or scheduler is not None:
        backend = "dask"
    with refused_leaves_nothing(out):
        check_output(out, formats=None, what="sweep folder")  # (before the machinery loads)
        from ..model.registry import get_model, model_spec
        from ..sweep import SweepSpec, open_sweep, parse_axis, run_sweep, sweep_figures

        m = m or get_model()
        spec = SweepSpec(axes=tuple(parse_axis(p, m, base) for p in params),
                         measures=measures, base=base, settings=settings,
                         continuation=continuation, model=model_spec(m))  # fmt: skip
        run_kw = dict(workers=workers, dask_local=dask_local, scheduler=scheduler,
                      resume=resume, max_memory=limit)  # fmt: skip
        store = run_sweep(spec, out, backend=backend, force=force, progress=progress, **run_kw)
    for p in sweep_figures(open_sweep(store).load(), out):
        typer.echo(f"wrote {p}")


#: The sweep's measures (``recipdyn.sweep.spec.MEASURES``, whose module loads numba; a test
#: keeps the two the same).
_MEASURES = ("poincare", "peak", "spectrum", "lyapunov", "verdict", "features")


@app.command()
def plot(
    store: Path = typer.Argument(..., help="A sweep store (OUT/sweep.zarr)."),
    out: Path = typer.Option(None, "--out", "-o", help="Folder (default: next to the store)."),
) -> None:
    """Regenerate a sweep's figures from its store."""
    from ..sweep import open_sweep, sweep_figures

    ds = open_sweep(store).load()
    for p in sweep_figures(ds, out or store.parent):
        typer.echo(f"wrote {p}")
