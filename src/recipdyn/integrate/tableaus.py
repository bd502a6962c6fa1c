"""Butcher tableaus as data.

The Dormand-Prince 8(5,3) coefficients (method, embedded 5th and 3rd order error estimators and
the 7th-order dense-output extension) come from the public class attributes of SciPy's
``scipy.integrate.DOP853`` (``A``, ``B``, ``C``, ``E3``, ``E5``, ``D``, ``A_EXTRA``,
``C_EXTRA``) rather than being retyped, so our compiled integrator takes exactly SciPy's steps
(tests compare step counts). They are assembled on first use (:func:`dop853`), so importing
recipdyn does not import ``scipy.integrate``.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

__all__ = ["RK4", "Tableau", "dop853"]  # and DOP853, built on first access


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


@functools.lru_cache(maxsize=1)
def dop853() -> Tableau:
    """The DOP853 tableau: stages 0-11, the FSAL stage 12 (row ``B``, node 1) and the three
    extra dense-output stages 13-15 (``A_EXTRA``, ``C_EXTRA``)."""
    from scipy.integrate import DOP853 as S

    n = S.n_stages
    A = np.zeros((n + 4, n + 4))
    A[:n, :n] = S.A
    A[n, :n] = S.B
    A[n + 1 :, :] = S.A_EXTRA
    C = np.concatenate([S.C, [1.0], S.C_EXTRA])
    return Tableau(name="DOP853", order=S.order, A=np.ascontiguousarray(A),
                   B=np.ascontiguousarray(S.B, dtype=np.float64), C=np.ascontiguousarray(C),
                   E3=np.ascontiguousarray(S.E3, dtype=np.float64),
                   E5=np.ascontiguousarray(S.E5, dtype=np.float64),
                   D=np.ascontiguousarray(S.D, dtype=np.float64), n_stages=n,
                   error_estimator_order=S.error_estimator_order)  # fmt: skip


def __getattr__(name: str):
    if name == "DOP853":  # lazy: built (and scipy.integrate imported) on first use
        return dop853()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


#: The classical 4th-order Runge-Kutta method (the paper's "Runge-Kutta method").
RK4 = Tableau(
    name="RK4",
    order=4,
    A=np.array([[0, 0, 0, 0], [0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1.0, 0]], dtype=np.float64),
    B=np.array([1 / 6, 1 / 3, 1 / 3, 1 / 6], dtype=np.float64),
    C=np.array([0, 0.5, 0.5, 1.0], dtype=np.float64),
    n_stages=4,
)
