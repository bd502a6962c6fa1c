"""Named layouts: where each part's values live in the state, the parameters and the outputs.

The assembler computes a machine's layout once (`recipdyn.model.assembler.assemble`): every
part adds its entries in order, and the layout remembers each part's slice
(``layout.params["throw2.load"]``) and each named entry's index
(``layout.state["throw2.theta_c"]``). The kernels receive these offsets as constants; nothing
else counts indexes.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

__all__ = ["Slices", "Layout", "SlicesBuilder"]


@dataclass(frozen=True)
class Slices:
    """Named slices of one flat vector.

    Attributes
    ----------
    size : int
        The vector's length.
    parts : mapping
        Each part's slice, by the part's name (``"throw2.load"``, ``"shaft.drive"``).
    names : tuple of str
        The name of each entry that has one, by index (``""`` for a packed value without a
        name of its own, such as a load table's nodes).
    units : tuple of str
        The unit of each entry (``""`` where it has none).
    """

    size: int
    parts: Mapping[str, slice]
    names: tuple[str, ...]
    units: tuple[str, ...]
    _index: Mapping[str, int] = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self) -> None:
        index = {n: i for i, n in enumerate(self.names) if n}
        if len(index) != sum(1 for n in self.names if n):
            raise ValueError(f"duplicate names in a layout: {self.names}")
        object.__setattr__(self, "_index", index)

    def __getitem__(self, name: str) -> int | slice:
        """The index of the entry ``name``, or the slice of the part ``name``."""
        if name in self._index:
            return self._index[name]
        if name in self.parts:
            return self.parts[name]
        raise KeyError(f"{name!r} is neither an entry nor a part of this layout")

    def __contains__(self, name: str) -> bool:
        return name in self._index or name in self.parts

    def __len__(self) -> int:
        return self.size

    def start(self, part: str) -> int:
        """The first index of part ``part``."""
        return self.parts[part].start

    def named(self) -> tuple[tuple[str, str], ...]:
        """``(name, unit)`` of every entry, in order (a state's components)."""
        return tuple(zip(self.names, self.units, strict=True))


class SlicesBuilder:
    """Builds a `Slices` part by part (the assembler's only way to place a value)."""

    def __init__(self) -> None:
        self._names: list[str] = []
        self._units: list[str] = []
        self._parts: dict[str, slice] = {}

    def add(self, part: str, entries: Iterable[tuple[str, str]]) -> slice:
        """Append the named entries ``(name, unit)`` of ``part``; its slice."""
        start = len(self._names)
        for name, unit in entries:
            self._names.append(name)
            self._units.append(unit)
        return self._close(part, start)

    def reserve(self, part: str, n: int) -> slice:
        """Append ``n`` unnamed entries (a packed parameter slice); its slice."""
        start = len(self._names)
        self._names += [""] * n
        self._units += [""] * n
        return self._close(part, start)

    def _close(self, part: str, start: int) -> slice:
        if part in self._parts:
            raise ValueError(f"part {part!r} placed twice")
        self._parts[part] = slice(start, len(self._names))
        return self._parts[part]

    def build(self) -> Slices:
        return Slices(len(self._names), dict(self._parts), tuple(self._names),
                      tuple(self._units))  # fmt: skip


@dataclass(frozen=True)
class Layout:
    """The state's, the parameter vector's and the observer's columns' `Slices` of one
    configuration."""

    state: Slices
    params: Slices
    outputs: Slices
