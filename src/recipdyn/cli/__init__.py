"""Command-line interface: ``recipdyn simulate | sense | analyze | sweep | plot | reproduce | ...``.

Each command parses its options, calls one library function and writes files. The exit
statuses are the contract of ``docs/reliability.md``:

* 0 success;
* 1 the computation failed (the integrator; the partial record is kept and named);
* 2 bad input (usage errors, out-of-range parameters or settings, unknown units, unreadable or
  wrong files, unwritable outputs): one line naming the parameter and its allowed range;
* 130 / 143 interrupted by SIGINT / SIGTERM, after saying what was kept and how to resume.

No traceback reaches the user unless ``--debug`` (or ``RECIPDYN_DEBUG=1``) asks for it.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator
from pathlib import Path

import typer

from ..errors import IntegrationError, Interrupted, ParameterError, raise_on_signals
from .common import app, phase, refused_leaves_nothing, report, with_json

__all__ = ["app", "main", "phase", "refused_leaves_nothing", "report", "say_line", "with_json"]


def _register() -> None:
    from . import analyze as _analyze  # noqa: F401  (commands register on import)
    from . import animate as _animate  # noqa: F401
    from . import compare as _compare  # noqa: F401
    from . import diagnosis as _diagnosis  # noqa: F401
    from . import features as _features  # noqa: F401
    from . import models as _models  # noqa: F401
    from . import reproduce as _reproduce  # noqa: F401
    from . import sense as _sense  # noqa: F401
    from . import simulate as _simulate  # noqa: F401
    from . import sweep as _sweep  # noqa: F401
    from . import warmup as _warmup  # noqa: F401
    from . import webapp as _webapp  # noqa: F401


def _click_exception_types() -> list[tuple[type, type]]:
    """(ClickException, UsageError) classes: typer bundles its own copy of click
    (``typer._click``), and a plain ``click`` may also be installed; catch both."""
    types = []
    for modname in ("typer._click.exceptions", "click.exceptions"):
        try:
            mod = __import__(modname, fromlist=["ClickException"])
        except ImportError:
            continue
        types.append((mod.ClickException, mod.UsageError))
    return types


def _err(msg: str) -> None:
    typer.echo(msg, err=True)


def say_line(text: str) -> None:
    """One line on standard error that leaves a running progress bar whole (tqdm's write
    clears the bar, prints the line and draws the bar again below it)."""
    if "tqdm" in sys.modules:  # (a bar can only be running once tqdm is loaded)
        from tqdm import tqdm

        tqdm.write(text, file=sys.stderr)
    else:
        typer.echo(text, err=True)


@contextlib.contextmanager
def warnings_said_once() -> Iterator[None]:
    """Every warning that reaches the user while a command runs is one line, ``warning:
    TEXT`` (its text on one line; no category, file or source line), through `say_line`, and
    each text is said once per command: a warning a worker process raised comes back to this
    process with the worker's result (`recipdyn.parallel.run_unordered`), so a hundred
    records that warn alike say it once. ``--debug`` shows warnings as Python does."""
    import warnings

    seen: set[str] = set()

    def show(message, category, filename, lineno, file=None, line=None):
        text = " ".join(str(message).split())
        if not category.__module__.startswith("recipdyn"):  # (a library's: where it arose)
            where = "/".join(Path(str(filename)).parts[-2:])
            text = f"{text} ({category.__name__} in {where}:{lineno})"
        if text not in seen:
            seen.add(text)
            say_line(f"warning: {text}")

    old = warnings.showwarning
    warnings.showwarning = show
    try:
        yield
    finally:
        warnings.showwarning = old


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the exit status (see the module docstring)."""
    _register()
    raise_on_signals()

    debug = "--debug" in (sys.argv[1:] if argv is None else argv)
    said = contextlib.nullcontext() if debug else warnings_said_once()
    try:
        with said:
            rv = app(args=argv, standalone_mode=False)
    except ParameterError as exc:
        _err(f"error: {exc}")
        return 2
    except IntegrationError as exc:
        _err(f"error: {exc}")
        return 1
    except (Interrupted, KeyboardInterrupt) as exc:
        intr = Interrupted.wrap(exc)
        for line in intr.kept:
            _err(f"kept: {line}")
        if not intr.kept:
            _err("nothing finished was pending; no output written")
        _err(f"interrupted ({intr})")
        return intr.exit_code
    except OSError as exc:  # an output that cannot be written, a full disk, ...
        if debug or os.environ.get("RECIPDYN_DEBUG"):
            raise
        where = f": {exc.filename}" if exc.filename else ""
        _err(f"error: {exc.strerror or exc}{where}")
        return 2
    except typer.Exit as exc:
        return exc.exit_code or 0
    except typer.Abort:
        _err("aborted")
        return 130
    except Exception as exc:
        for click_exc, usage in _click_exception_types():
            if isinstance(exc, usage):  # one line, like every other refusal
                ctx = getattr(exc, "ctx", None)
                where = ctx.command_path if ctx is not None else "recipdyn"
                _err(f"error: {exc.format_message()} (see '{where} --help')")
                return 2
            if isinstance(exc, click_exc):
                exc.show()
                return exc.exit_code or 1
        if debug or os.environ.get("RECIPDYN_DEBUG"):
            raise
        _err(f"internal error: {type(exc).__name__}: {exc} (rerun with --debug for details)")
        return 1
    return rv if isinstance(rv, int) else 0


def cli_entry() -> None:
    """Console-script entry point."""
    sys.exit(main())
