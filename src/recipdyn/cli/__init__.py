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
import contextvars
import functools
import inspect
import json
import os
import sys
from collections.abc import Iterator
from pathlib import Path

import typer

from ..errors import IntegrationError, Interrupted, ParameterError, raise_on_signals
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
    JSON object (what the command passed to [`report`][recipdyn.cli.report]) is printed on standard
    output at the end, for scripts (``recipdyn simulate ... --json | jq .peak_a``)."""
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
