"""Compiled integrators for any :class:`~recipdyn.model.base.ODESystem`."""

from .solve import METHODS, IntegrationError, Solution, integrate, propagate
from .tableaus import DOP853, RK4, Tableau

__all__ = [
    "integrate", "propagate", "Solution", "IntegrationError", "METHODS", "DOP853", "RK4", "Tableau",
]  # fmt: skip
