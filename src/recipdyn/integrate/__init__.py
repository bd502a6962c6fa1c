"""Compiled integrators for any [`ODESystem`][recipdyn.model.base.ODESystem]."""

from .solve import (
    METHODS,
    IntegrationError,
    Method,
    Solution,
    compiles,
    integrate,
    prepare,
    propagate,
)
from .tableaus import RK4, Tableau, dop853

# DOP853 (the tableau) is built on first access (module __getattr__ below).
__all__ = [
    "integrate", "prepare", "compiles", "propagate", "Solution", "IntegrationError", "METHODS",
    "Method", "RK4", "Tableau", "dop853",
]  # fmt: skip


def __getattr__(name: str):
    if name == "DOP853":
        return dop853()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
