"""Command-line interface: ``recipdyn simulate | run | ...``.

Each command parses its options, calls one library function and writes files. Bad input
(out-of-range parameters, unknown units, malformed configs) prints one clear line naming the
parameter and its allowed range and exits with status 2, without a traceback.
"""

from __future__ import annotations

import sys

import typer

from ..model.parameters import ParameterError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Nonlinear dynamics of reciprocating compressors with joint clearance and subsidence.",
    pretty_exceptions_enable=False,
)


def _register() -> None:
    from . import analyze as _analyze  # noqa: F401  (commands register on import)
    from . import reproduce as _reproduce  # noqa: F401
    from . import simulate as _simulate  # noqa: F401
    from . import sweep as _sweep  # noqa: F401


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the exit status (0 ok, 1 run failure, 2 bad input)."""
    _register()
    try:
        app(args=argv, standalone_mode=False)
    except ParameterError as exc:
        typer.echo(f"error: {exc}", err=True)
        return 2
    except (typer.Abort, KeyboardInterrupt):
        typer.echo("aborted", err=True)
        return 130
    except typer.Exit as exc:
        return exc.exit_code or 0
    except Exception as exc:  # click usage errors carry their own exit code
        import click

        if isinstance(exc, click.ClickException):
            exc.show()
            return exc.exit_code or 0
        from ..integrate import IntegrationError

        if isinstance(exc, IntegrationError):
            typer.echo(f"error: {exc}", err=True)
            return 1
        raise
    return 0


def cli_entry() -> None:
    """Console-script entry point."""
    sys.exit(main())
