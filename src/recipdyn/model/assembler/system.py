"""The system of an assembled machine: an [`ODESystem`][recipdyn.model.base.ODESystem] that
remembers the model and values it was built from (loaded with the compiled code, not with the
model: a machine's values are validated before numba loads)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..base import ODESystem, Signal, rhs_series

__all__ = ["AssembledSystem", "Frozen"]


@dataclass(frozen=True)
class Frozen:
    """Values held by a system (compared by identity: a system is built per values)."""

    values: Mapping[str, Any]

    def __hash__(self) -> int:
        return id(self)


@dataclass(frozen=True)
class AssembledSystem(ODESystem):
    """An assembled machine's system with the model and values it was built from:
    ``initial_state()``, ``outputs(t, y)`` and ``accelerations(t, y)`` without repeating
    them."""

    model: Any = None
    values: Any = field(default=None, repr=False)

    def initial_state(self) -> np.ndarray:
        return self.model.initial_state(self.values.values)

    def outputs(self, t: np.ndarray, y: np.ndarray) -> dict[str, Signal]:
        return self.model.outputs(self.values.values, t, y)

    def accelerations(self, t: np.ndarray, y: np.ndarray) -> np.ndarray:
        """The first throw's clearance-angle acceleration at each sample."""
        return rhs_series(self.rhs, self.params, t, y)[:, 1]

    @property
    def cparams(self):
        """The first throw's [`CompressorParams`][recipdyn.model.parameters.CompressorParams]."""
        return self.model.throw_params(self.model.throws(self.values.values)[0])
