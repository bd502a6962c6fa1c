"""``recipdyn models [NAME]``: the registered models and their parameter tables."""

from __future__ import annotations

import typer

from .common import app

#: From this console width on, the parameter table has a column per field.
WIDE = 150


def _where(owner: str) -> str:
    """Which configuration a parameter belongs to, as shown beside it."""
    if not owner:
        return ""
    text = "selects the implementation" if owner == "selector" else f"with {owner}"
    return f"; [italic]{text}[/italic]"


@app.command()
def models(
    name: str = typer.Argument(None, help="A model name or module:object; omit to list all."),
) -> None:
    """List the registered models, or print one model's parameters.

    For each parameter: its default, unit, range, description, and whether it is assumed."""
    from rich.console import Console
    from rich.markup import escape
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
    from ..model.protocol import Schema

    m = get_model(name)
    index = m.parameter_table()  # every configuration's, with the selector values enabling it
    width = max(len(p.name) for p, _ in index)  # names are never cut: users type them
    table_rows = Schema(tuple(p for p, _ in index)).table()
    rows = [{**{k: escape(str(v)) for k, v in row.items()}, "for": escape(owner)}
            for row, (_, owner) in zip(table_rows, index, strict=True)]  # fmt: skip
    title = f"{m.name}: {m.description}"
    if console.width >= WIDE:  # one column per field
        table = Table(Column("name", no_wrap=True, min_width=width), "default", "unit",
                      "allowed", "group", "assumed", "description", title=title)  # fmt: skip
        for row in rows:
            table.add_row(
                row["name"],
                row["default"],
                row["unit"],
                row["range"],
                row["group"],
                row["assumed"],
                row["description"] + _where(row["for"]),
            )
    else:  # narrower: the values on one line, the description under them (nothing cut)
        table = Table(Column("name", no_wrap=True, min_width=width),
                      Column("default, allowed range, group; description", overflow="fold"),
                      title=title, show_lines=True)  # fmt: skip
        for row in rows:
            unit = "" if row["unit"] in ("-", "") else f" {row['unit']}"
            assumed = ", [bold]assumed[/bold]" if row["assumed"] else ""
            head = f"{row['default']}{unit}; allowed {row['range']}; {row['group']}{assumed}"
            table.add_row(row["name"], f"{head}{_where(row['for'])}\n"
                          f"[dim]{row['description']}[/dim]")  # fmt: skip
    console.print(table)
    state = ", ".join(f"{s} ({u})" for s, u in zip(m.state_names, m.state_units, strict=True))
    console.print(f"state: {state}; kind: {m.kind}; time unit: {m.time_unit}")
    if any(owner for _, owner in index):
        console.print(
            "Parameters marked 'with ...' belong to another configuration: set the "
            "selector to that value (--set crank_joint=contact); docs/components.md"
        )
