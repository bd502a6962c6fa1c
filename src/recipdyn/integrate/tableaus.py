"""Butcher tableaus as data.

The Dormand-Prince 8(5,3) coefficients (method, embedded 5th and 3rd order error estimators and
the 7th-order dense-output extension) are taken from SciPy's ``dop853_coefficients`` rather than
retyped, so our compiled integrator takes exactly SciPy's steps (tests compare step counts).
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass

import numpy as np


def _load_scipy_dop853():
    """SciPy's ``dop853_coefficients`` module, loaded from its file: importing it the usual way
    pulls in all of ``scipy.integrate`` (~0.2 s), which the CLI's start-up time cannot afford."""
    from pathlib import Path

    import scipy

    path = Path(scipy.__file__).parent / "integrate" / "_ivp" / "dop853_coefficients.py"
    spec = importlib.util.spec_from_file_location("_recipdyn_scipy_dop853", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


_dop = _load_scipy_dop853()

__all__ = ["DOP853", "RK4", "Tableau"]


@dataclass(frozen=True)
class Tableau:
    """An explicit Runge-Kutta tableau (``A`` strictly lower triangular)."""

    name: str
    order: int
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    E3: np.ndarray | None = None
    E5: np.ndarray | None = None
    D: np.ndarray | None = None
    n_stages: int = 0
    error_estimator_order: int = 0


DOP853 = Tableau(
    name="DOP853",
    order=8,
    A=np.ascontiguousarray(_dop.A, dtype=np.float64),
    B=np.ascontiguousarray(_dop.B, dtype=np.float64),
    C=np.ascontiguousarray(_dop.C, dtype=np.float64),
    E3=np.ascontiguousarray(_dop.E3, dtype=np.float64),
    E5=np.ascontiguousarray(_dop.E5, dtype=np.float64),
    D=np.ascontiguousarray(_dop.D, dtype=np.float64),
    n_stages=_dop.N_STAGES,
    error_estimator_order=7,
)

#: The classical 4th-order Runge-Kutta method (the paper's "Runge-Kutta method").
RK4 = Tableau(
    name="RK4",
    order=4,
    A=np.array([[0, 0, 0, 0], [0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1.0, 0]], dtype=np.float64),
    B=np.array([1 / 6, 1 / 3, 1 / 3, 1 / 6], dtype=np.float64),
    C=np.array([0, 0.5, 0.5, 1.0], dtype=np.float64),
    n_stages=4,
)
