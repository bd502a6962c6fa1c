"""``recipdyn warmup [MODEL...]``: compile the models' kernels ahead of their first run."""

from __future__ import annotations

import time

import typer

from .common import app


@app.command()
def warmup(
    models: list[str] = typer.Argument(
        None, help="Models to prepare (default: every registered model)."
    ),
    method: str = typer.Option("dop853", "--method", help="dop853, rk4 or all."),
) -> None:
    """Compile the kernels each model's run uses ahead, so later runs start at once.

    Each kernel is compiled, or loaded from the cache, and the time it took is said;
    'make run' does this first."""
    import warnings

    from ..errors import ParameterError
    from ..integrate import compiles
    from ..model.registry import get_model, model_names
    from ..simulate import simulate
    from .simulate import METHOD_NAMES, compile_note, configuration

    methods = METHOD_NAMES if method == "all" else (method,)
    if method != "all" and method not in METHOD_NAMES:
        raise ParameterError(f"method = {method!r}; allowed: {', '.join(METHOD_NAMES)}, all")
    names = list(models or model_names())
    loaded = [get_model(n) for n in names]  # every name checked before any compiling
    for m in loaded:
        values = m.parameters({})
        system = m.system(values)
        for meth in methods[:1] if m.kind == "map" else methods:  # a map is iterated
            todo = [] if m.kind == "map" else compiles(system, meth)
            cold = todo is None or bool(todo)
            if todo:
                typer.echo(compile_note(m.name, configuration(m, values), todo), err=True)
            t0 = time.perf_counter()
            with warnings.catch_warnings():  # a fraction of a revolution: no verdicts drawn
                warnings.simplefilter("ignore")
                simulate(model=m, revolutions=0.05, transient=0.0, method=meth)
            how = ("compiled or loaded" if todo is None else "compiled" if cold
                   else "loaded from the cache")  # fmt: skip
            typer.echo(f"{m.name} ({meth}): {time.perf_counter() - t0:.1f} s ({how})")
