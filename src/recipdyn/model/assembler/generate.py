"""The generated code: one module per configuration, from one template, names and constants only.

A template (``templates/<drive>.py``) is an ordinary module whose kernels call their
components through names bound in one block between the markers ``# <bindings>`` and ``#
</bindings>``: imports (``from MODULE import FUNCTION as ROLE``) and constants (``NAME =
np.int64(k)``, ``NAME = np.array([...], dtype=np.int64)``, ``NAME = True``). `module` writes
the template with that block replaced by a configuration's own block of the same names (every
name the template binds, no other), and imports the result from a file named by the hash of
its text (`recipdyn.model.components.contract.glue_module`: written once, in a folder of
numba's cache that changes with every state of recipdyn's sources), so numba caches its
kernels on disk like any module's. Nothing else of the template's text is touched: the code
that runs is the code that is linted, read and tested.

The components are compiled once and linked, not inlined, and they receive their offsets as
``int64`` values (constants of the block), so every configuration that holds a component
reuses its cached machine code (docs/architecture.md, Composing compiled components).
"""

from __future__ import annotations

import ast
from collections.abc import Mapping
from functools import cache
from pathlib import Path
from types import ModuleType

import numpy as np

__all__ = ["absent", "template_names", "bindings", "module", "Literal", "TEMPLATES"]

TEMPLATES = Path(__file__).with_name("templates")
BEGIN, END = "# <bindings>", "# </bindings>"


def absent(*args):
    """Bound to the roles a configuration lacks (a load without states has no
    ``load_rhs``): the templates call them only in branches on a constant (``if
    LOAD_STATES:``) that numba removes before typing, so it is never compiled; called from
    Python it says so."""
    raise RuntimeError("a role this configuration does not have was called")


def _block(template: str) -> tuple[str, int, int]:
    text = (TEMPLATES / f"{template}.py").read_text(encoding="utf-8")
    i, j = text.index(BEGIN), text.index(END)
    return text, i, j + len(END)


@cache
def template_names(template: str) -> tuple[frozenset[str], frozenset[str]]:
    """(roles, constants) the template ``template`` binds in its block."""
    text, i, j = _block(template)
    roles, constants = set(), set()
    for node in ast.parse(text[i:j]).body:
        if isinstance(node, ast.ImportFrom):
            roles.update(a.asname or a.name for a in node.names)
        elif isinstance(node, ast.Assign) and all(isinstance(t, ast.Name) for t in node.targets):
            constants.update(t.id for t in node.targets)
        else:
            raise ValueError(f"template {template}: not a binding: {ast.unparse(node)!r}")
    return frozenset(roles), frozenset(constants)


class Literal(int):
    """An integer constant written as a plain literal (``CFG = 2``): numba types it as
    ``Literal[int]``, so a function it is passed to compiles once per value and prunes the
    branches on it (a configuration code); `_constant` writes other integers as ``np.int64``,
    one compilation for every value (an offset)."""


def _constant(value) -> str:
    if isinstance(value, Literal):
        return str(int(value))
    if isinstance(value, (bool, np.bool_)):
        return "True" if value else "False"
    if isinstance(value, (int, np.integer)):
        return f"np.int64({int(value)})"
    arr = np.asarray(value)
    if arr.ndim == 1 and arr.dtype.kind in "iu":
        return f"np.array([{', '.join(str(int(v)) for v in arr)}], dtype=np.int64)"
    raise TypeError(f"a template's constant is a bool, an integer or integers, got {value!r}")


def bindings(template: str, roles: Mapping[str, tuple[str, str]],
             constants: Mapping[str, object]) -> str:  # fmt: skip
    """The block that binds ``roles`` (``role -> (module, function)``) and ``constants`` for
    ``template``; raise if a name the template binds is missing or one it does not is given."""
    want_roles, want_consts = template_names(template)
    if set(roles) != want_roles or set(constants) != want_consts:
        raise ValueError(
            f"template {template}: roles {sorted(set(roles) ^ want_roles)} and constants "
            f"{sorted(set(constants) ^ want_consts)} do not match its bindings"
        )
    lines = [BEGIN]
    for role in sorted(roles):
        mod, fn = roles[role]
        lines.append(f"from {mod} import {fn}" + ("" if fn == role else f" as {role}"))
    lines.append("")
    lines += [f"{name} = {_constant(constants[name])}" for name in sorted(constants)]
    lines.append(END)
    return "\n".join(lines)


def module(template: str, roles: Mapping[str, tuple[str, str]], constants: Mapping[str, object],
           stem: str, note: str = "") -> ModuleType:  # fmt: skip
    """The module of one configuration: ``template`` with its bindings block replaced by
    `bindings` (``note``: a comment after it, e.g. the hash of a user's component file, so an
    edited file gives a new module, never stale machine code)."""
    from ..components.contract import glue_module

    text, i, j = _block(template)
    block = bindings(template, roles, constants)
    if note:
        block += f"\n# {note}"
    return glue_module(text[:i] + block + text[j:], f"{template}_{stem}")
