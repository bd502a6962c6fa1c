"""``recipdyn app``: the local web app (Dash)."""

from __future__ import annotations

from pathlib import Path

import typer

from .common import app as cli_app


@cli_app.command("app")
def app_command(
    store: Path = typer.Option(None, "--store", help="A sweep folder to open in the browser."),
    port: int = typer.Option(8050, "--port", help="Port on this machine (1024-65535)."),
    host: str = typer.Option(
        "127.0.0.1", "--host", help="Address to listen on (default: this machine only)."
    ),
) -> None:
    """Explore every registered model in the browser, with live simulation and a sweep browser.

    Its parameters in engineering units (mm, bar, rpm) with their ranges, the figures
    'recipdyn simulate' draws, a shareable address and config, and a sweep browser (fault map
    or bifurcation diagram; click a point to run it)."""
    from ..app import build_app
    from ..errors import ParameterError

    if not 1024 <= port <= 65535:
        raise ParameterError(f"port: {port}; allowed: 1024 to 65535")
    if store is not None and not store.exists():
        raise ParameterError(f"store {store}: not found")
    typer.echo(f"recipdyn app on http://{host}:{port}/ (Ctrl-C stops it)")
    build_app(store).run(host=host, port=port, debug=False)
