"""What every command shares: the typer application the commands register on, the
``--json`` option (`with_json`, `report`), the phase helper, and the guard that a refused
command leaves no folder behind (`refused_leaves_nothing`). The commands' modules import
these from here, and `recipdyn.cli` imports the commands' modules to register them; this
module imports neither, so the package has no import cycle."""

from __future__ import annotations

import contextlib
import contextvars
import functools
import inspect
import json
import os
import sys
from pathlib import Path

import typer

from ..errors import ParameterError
from ..io import jsonable
from ..progress import phase  # noqa: F401  (the commands' phase helper)

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Nonlinear dynamics of reciprocating compressors with joint clearance and subsidence.",
    pretty_exceptions_enable=False,
)


_REPORT: contextvars.ContextVar[dict | None] = contextvars.ContextVar("report", default=None)


def with_json(func):
    """Give a command a ``--json`` option: everything it says goes to standard error and one
    JSON object (what the command passed to [`report`][recipdyn.cli.common.report]) is
    printed on standard output at the end, for scripts
    (``recipdyn simulate ... --json | jq .peak_a``)."""
    sig = inspect.signature(func)
    extra = inspect.Parameter(
        "json_out", inspect.Parameter.KEYWORD_ONLY, annotation=bool,
        default=typer.Option(False, "--json", help="Print a JSON summary on stdout (what is "
                             "said goes to stderr)."),
    )  # fmt: skip

    @functools.wraps(func)
    def wrapper(*args, json_out: bool = False, **kw):
        if not json_out:
            return func(*args, **kw)
        collected: dict = {}
        token = _REPORT.set(collected)
        real = sys.stdout
        try:
            with contextlib.redirect_stdout(sys.stderr):
                rv = func(*args, **kw)
        finally:
            _REPORT.reset(token)
        real.write(json.dumps(jsonable(collected), allow_nan=False) + "\n")
        real.flush()
        return rv

    wrapper.__signature__ = sig.replace(parameters=[*sig.parameters.values(), extra])
    wrapper.__annotations__ = {**func.__annotations__, "json_out": bool}
    return wrapper


def report(**items) -> None:
    """Add items to the ``--json`` summary of the running command (nothing without it)."""
    collected = _REPORT.get()
    if collected is not None:
        collected.update(items)


def _first_missing(path: Path) -> Path | None:
    """The outermost folder of ``path`` (itself included) that does not exist yet."""
    path = Path(path).absolute()
    missing = None
    for folder in (path, *path.parents):
        if folder.exists():
            return missing
        missing = folder
    return missing  # pragma: no cover - the root exists


@contextlib.contextmanager
def refused_leaves_nothing(*paths: Path):
    """A command refused inside this block (a `ParameterError`, exit status 2) leaves
    no folder behind: the folders on the way to ``paths`` that it created are removed again,
    provided they hold no file (a finished or partial result is never removed).

    Commands validate everything they can before they touch the file system; this covers the
    refusals that can only come later (a run too large for its disk, a column name known once
    the model is built)."""
    created = {m for m in (_first_missing(p) for p in paths if p is not None) if m is not None}
    try:
        yield
    except ParameterError:
        import shutil

        for folder in created:
            kept = [f for f in folder.rglob("*") if f.is_file() and f.name != ".recipdyn.lock"]
            if folder.is_dir() and not kept:
                shutil.rmtree(folder, ignore_errors=True)
        raise


def _version(value: bool) -> None:
    if value:
        from .. import __version__

        typer.echo(f"recipdyn {__version__}")
        raise typer.Exit(0)


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Print the version and exit."
    ),
    debug: bool = typer.Option(False, "--debug", help="Show tracebacks of unexpected errors."),
) -> None:
    """Nonlinear dynamics of reciprocating compressors with joint clearance and subsidence."""
    if debug:
        os.environ["RECIPDYN_DEBUG"] = "1"
