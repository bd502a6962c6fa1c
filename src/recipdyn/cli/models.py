"""``recipdyn models [NAME]``: the registered models and their parameter tables."""

from __future__ import annotations

import typer

from . import app


@app.command()
def models(
    name: str = typer.Argument(None, help="A model name or module:object; omit to list all."),
) -> None:
    """List the registered models, or print one model's parameters (default, unit, range,
    description, assumed or not)."""
    from rich.console import Console
    from rich.table import Column, Table

    from ..model.registry import DEFAULT_MODEL, get_model, model_names

    console = Console(width=max(100, Console().width))
    if name is None:
        table = Table("model", "kind", "state", "description", title="registered models")
        for n in model_names():
            m = get_model(n)
            mark = " (default)" if n == DEFAULT_MODEL else ""
            table.add_row(n + mark, m.kind, ", ".join(m.state_names), m.description)
        console.print(table)
        console.print("Parameters of one model: recipdyn models NAME")
        return
    m = get_model(name)
    width = max(len(p.name) for p in m.schema)  # names are never cut: users type them
    table = Table(Column("name", no_wrap=True, min_width=width), "default", "unit", "allowed",
                  "group", "assumed", "description",
                  title=f"{m.name}: {m.description}")  # fmt: skip
    for row in m.schema.table():
        table.add_row(row["name"], row["default"], row["unit"], row["range"], row["group"],
                      row["assumed"], row["description"])  # fmt: skip
    console.print(table)
    state = ", ".join(f"{s} ({u})" for s, u in zip(m.state_names, m.state_units, strict=True))
    console.print(f"state: {state}; kind: {m.kind}; time unit: {m.time_unit}")
