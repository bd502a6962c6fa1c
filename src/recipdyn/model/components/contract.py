r"""The component contract: what one piece of the compressor declares, and how pieces assemble.

A compressor is assembled from components, one per *family*: the mechanism (with the joint at
the crank pin), the **drive** (what turns the crank) and the **load** (the force of the gas on
the crosshead). A component is a `Component`:

* ``family`` and ``name`` (``drive`` / ``motor``): the parameter that chooses it
  (``--set drive=motor``) and the value that selects it;
* ``params``: its schema fragment (`recipdyn.model.protocol.Param`, with units,
  ranges, assumptions); a name may belong to one component only, so two components cannot
  read each other's values by accident (`check_fragments`);
* ``states`` and ``aux_states``: the state components it adds, with units (a motor adds the
  crank angle and speed, and the work it does);
* ``pack(values)``: its slice of the flat parameter vector ``p``. `Assembly` computes
  every slice's offset once and passes it to the component's compiled functions, so no
  component reads another's slice and none needs a kind code to tell loads apart;
* ``kernels``: its compiled contributions, ``role -> function`` in ``module`` (a load's
  ``force(theta1, p, o) -> F``, a drive's ``crank(t, y, p, o) -> (theta1, omega1)`` or
  ``torque(omega1, p, o) -> T``). They are plain ``numba.njit`` functions of scalars and the
  offset ``o``.

The glue that calls the chosen components in one right-hand side is **generated source**
(`glue_module`): the offsets and the chosen functions are written into it as literals
and imports, so numba compiles one specialised kernel per combination, inlines the components
and caches it on disk; a component's function cannot be called with another's offset or
slice. The generated file is named by the hash of its source in recipdyn's cache folder
(one folder per state of the sources, as numba's cache), so an edit of any component gives
a new file instead of stale machine code.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any

import numpy as np

from ..protocol import Param

__all__ = [
    "Component",
    "Assembly",
    "check_fragments",
    "glue_module",
    "resolve_component",
    "source_digest",
]


def _no_params(values: Mapping[str, Any]) -> np.ndarray:
    return np.zeros(0)


@dataclass(frozen=True)
class Component:
    """One piece of the compressor (module docstring: the contract).

    Attributes
    ----------
    family : str
        The parameter that chooses it (``drive``, ``load``).
    name : str
        The value of that parameter that selects it.
    description : str
        One line for ``recipdyn models`` and the docs.
    params : tuple of Param
        Its schema fragment: the parameters only it reads.
    states, aux_states : tuple of (name, unit)
        State components it adds: degrees of freedom, then auxiliary ones (work integrals).
    module : str
        The module that holds its compiled functions.
    kernels : mapping
        ``role -> function name`` in ``module`` (see the module docstring for the roles).
    pack : callable
        ``values -> ndarray``: its slice of the parameter vector.
    check : callable, optional
        ``values -> None``: cross-field checks; raise ``ParameterError`` naming the parameter.
    initial : callable, optional
        ``values -> ndarray``: a load with states, its states then its auxiliary states at
        ``t = 0`` (a load of a user's file with states needs it; the dynamic valves' model
        computes its own).
    steps : callable, optional
        ``values -> ndarray``: a load with states, the step of the Jacobian's central
        differences for each of its states as a pair ``(rel, abs)``, ``h = 1e-7 (|y| (1 +
        rel) + abs)`` (default ``(0, 1)``: steps of 1e-7 relative to 1).
    """

    family: str
    name: str
    description: str
    module: str
    kernels: Mapping[str, str]
    pack: Callable[[Mapping[str, Any]], np.ndarray] = _no_params
    params: tuple[Param, ...] = ()
    states: tuple[tuple[str, str], ...] = ()
    aux_states: tuple[tuple[str, str], ...] = ()
    check: Callable[[Mapping[str, Any]], None] | None = None
    initial: Callable[[Mapping[str, Any]], np.ndarray] | None = None
    steps: Callable[[Mapping[str, Any]], np.ndarray] | None = None

    def kernel(self, role: str) -> str:
        """``from MODULE import FUNCTION as ALIAS`` target for ``role``."""
        try:
            return self.kernels[role]
        except KeyError:
            raise ValueError(
                f"{self.family} component {self.name!r} provides no {role!r} kernel "
                f"(it provides: {', '.join(self.kernels)})"
            ) from None


def resolve_component(family: str, name: str, builtin: Mapping[str, Component]) -> Component:
    """The component of ``family`` that ``name`` chooses: a built-in one by its name, or one
    from a user's module or file by its spec (``module:object``, ``file.py:OBJ``: adding a
    component is one file, recipdyn untouched). Raise
    [`ParameterError`][recipdyn.errors.ParameterError] naming the family and the choices."""
    from ...errors import ParameterError
    from ..registry import is_spec, load_object

    if name in builtin:
        return builtin[name]
    if not is_spec(name):
        raise ParameterError(f"{family} = {name!r}; allowed: "
                             f"{', '.join(repr(k) for k in builtin)} or a component's "
                             "module:object / file.py:OBJ")  # fmt: skip
    obj = load_object(name, what=f"{family} component")
    if not isinstance(obj, Component) or obj.family != family:
        got = f"a {obj.family} component" if isinstance(obj, Component) else type(obj).__name__
        raise ParameterError(f"{family} = {name!r} is {got}, not a {family} component "
                             "(recipdyn.model.components.contract.Component)")  # fmt: skip
    return obj


def source_digest(module: str) -> str:
    """A short hash of the source file of the imported ``module`` (a user's component): written
    into the generated glue, so an edited component gives a new glue file, never stale
    machine code."""
    path = getattr(sys.modules.get(module), "__file__", None)
    if not path:
        return "?"
    with open(path, "rb") as fh:
        return hashlib.sha1(fh.read()).hexdigest()[:16]


def check_fragments(components: Iterable[Component], base: Iterable[Param] = ()) -> None:
    """Raise if two components (or a component and the base schema) declare one name."""
    owner: dict[str, str] = {p.name: "mechanism" for p in base}
    for c in components:
        for p in c.params:
            if p.name in owner and owner[p.name] != f"{c.family}={c.name}":
                raise ValueError(
                    f"parameter {p.name!r} of {c.family}={c.name} is already declared by "
                    f"{owner[p.name]}"
                )
            owner[p.name] = f"{c.family}={c.name}"


@dataclass(frozen=True)
class Assembly:
    """Chosen components in the order of the parameter vector, after a fixed head.

    ``head`` is the number of values the mechanism packs first; each part's slice follows in
    order, its offset computed here once (`offsets`).
    """

    head: int
    parts: tuple[Component, ...]
    offsets: Mapping[str, int] = field(init=False)

    def __post_init__(self) -> None:
        fams = [c.family for c in self.parts]
        if len(set(fams)) != len(fams):
            raise ValueError(f"one component per family, got {fams}")

    def part(self, family: str) -> Component:
        return next(c for c in self.parts if c.family == family)

    def pack(self, head: np.ndarray, values: Mapping[str, Any]) -> tuple[np.ndarray, dict]:
        """The parameter vector (``head`` then each part's slice) and each part's offset."""
        if head.size != self.head:
            raise ValueError(f"the mechanism packs {head.size} values, declared {self.head}")
        chunks, offsets, n = [np.asarray(head, dtype=np.float64)], {}, self.head
        for c in self.parts:
            s = np.asarray(c.pack(values), dtype=np.float64).ravel()
            offsets[c.family] = n
            chunks.append(s)
            n += s.size
        return np.concatenate(chunks), offsets

    def states(self) -> tuple[tuple[str, str], ...]:
        return tuple(s for c in self.parts for s in c.states)

    def aux_states(self) -> tuple[tuple[str, str], ...]:
        return tuple(s for c in self.parts for s in c.aux_states)


def _glue_dir() -> str:
    # one folder per state of the sources, beside numba's cache (recipdyn/__init__.py)
    base = os.environ.get("NUMBA_CACHE_DIR")
    if not base:
        from ...resources import cache_dir

        base = os.path.join(cache_dir(), "numba", "default")
    return os.path.join(base, "recipdyn_assembled")


def glue_module(source: str, stem: str) -> ModuleType:
    """Import generated glue ``source`` from a file named by its hash (written once,
    atomically), so numba caches its kernels on disk like any module's."""
    digest = hashlib.sha1(source.encode()).hexdigest()[:16]
    name = f"recipdyn_assembled_{stem}_{digest}"
    if name in sys.modules:
        return sys.modules[name]
    folder = _glue_dir()
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, f"{name}.py")
    if not os.path.exists(path):
        tmp = f"{path}.{os.getpid()}.tmp"
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(source)
        os.replace(tmp, path)
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module
