"""``recipdyn simulate`` and ``recipdyn run``."""

from __future__ import annotations

from pathlib import Path

import typer

from . import app

_SET_HELP = "Set any parameter: NAME=VALUE with units, e.g. --set m3='40 kg' (repeatable)."


def _collect(rc, d, omega, sets, config):
    from ..config import build_params, load_config
    from ..units import parse_assignment

    settings: dict = {}
    if config is not None:
        params, settings = load_config(config)
    else:
        from ..model.parameters import CompressorParams

        params = CompressorParams()
    values = {}
    for name, val in (("rc", rc), ("d", d), ("omega", omega)):
        if val is not None:
            values[name] = val
    for item in sets or []:
        k, v = parse_assignment(item)
        values[k] = v
    return build_params(values, params), settings


@app.command()
def simulate(
    rc: str = typer.Option(None, "--rc", "--clearance", help="Radial clearance, e.g. '1 mm'."),
    d: str = typer.Option(None, "--d", "--subsidence", help="Crosshead subsidence, e.g. '1 mm'."),
    omega: str = typer.Option(None, "--omega", help="Crank speed, e.g. '20 rad/s', '191 rpm'."),
    sets: list[str] = typer.Option(None, "--set", help=_SET_HELP),
    config: Path = typer.Option(
        None, "--config", "-c", help="TOML config ([params], [simulation])."
    ),
    revolutions: str = typer.Option(None, "--revolutions", "-n", help="Revolutions to record."),
    transient: str = typer.Option(None, "--transient", help="Revolutions to discard first."),
    fs: str = typer.Option(None, "--fs", help="Sampling rate, e.g. '10 kHz'."),
    method: str = typer.Option(None, "--method", help="dop853 (default) or rk4."),
    rtol: float = typer.Option(None, "--rtol", help="Relative tolerance (dop853)."),
    out: Path = typer.Option(Path("out/simulation.nc"), "--out", "-o", help="NetCDF output."),
    figure: bool = typer.Option(True, "--figure/--no-figure", help="Also write a PNG figure."),
    progress: bool = typer.Option(True, "--progress/--no-progress"),
) -> None:
    """Simulate the compressor; write a NetCDF dataset and a figure (x, v, a, spectrum)."""
    from ..simulate import DEFAULT_SETTINGS
    from ..simulate import simulate as run_sim
    from ..units import to_si

    params, settings = _collect(rc, d, omega, sets, config)
    kw = {**DEFAULT_SETTINGS, **settings}
    for name, val in (("revolutions", revolutions), ("transient", transient), ("fs", fs)):
        if val is not None:
            kw[name] = to_si(name, val)
    if method is not None:
        kw["method"] = method
    if rtol is not None:
        kw["rtol"] = rtol
    from ..model.parameters import ParameterError

    if kw["method"] not in ("dop853", "rk4"):
        raise ParameterError(f"method = {kw['method']!r}; allowed: dop853, rk4")
    ds = run_sim(params, progress=progress, **kw)
    out.parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(out)
    typer.echo(f"wrote {out}  ({ds.sizes['time']} samples, nfev={ds.attrs['solver_nfev']})")
    if figure:
        from ..plotting import response_figure

        fig = response_figure(ds)
        png = out.with_suffix(".png")
        fig.savefig(png, dpi=130)
        typer.echo(f"wrote {png}")
    a = ds["a"].values
    typer.echo(
        f"peak |a| = {abs(a).max():.4g} m/s^2, x in [{ds.x.min().item():.5f}, "
        f"{ds.x.max().item():.5f}] m, min contact force = {ds.attrs['min_contact_force_N']:.4g} N"
    )


@app.command()
def run(
    out: Path = typer.Option(Path("out"), "--out", "-o", help="Output folder."),
) -> None:
    """The main job with embedded defaults: the paper's base case (rc = d = 1 mm, 20 rad/s)."""
    from ..model.parameters import paper_2d12
    from ..plotting import response_figure
    from ..simulate import simulate as run_sim

    out.mkdir(parents=True, exist_ok=True)
    ds = run_sim(paper_2d12(), revolutions=10, transient=0, progress=True)
    ds.to_netcdf(out / "base_case.nc")
    response_figure(ds, title="Base case: rc = 1 mm, d = 1 mm, omega = 20 rad/s").savefig(
        out / "base_case.png", dpi=130
    )
    typer.echo(f"wrote {out / 'base_case.nc'} and {out / 'base_case.png'}")
