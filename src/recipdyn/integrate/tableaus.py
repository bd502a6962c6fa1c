"""Butcher tableaus as data.

The Dormand-Prince 8(5,3) coefficients (method, embedded 5th and 3rd order error estimators and
the 7th-order dense-output extension) come from the public class attributes of SciPy's
``scipy.integrate.DOP853`` (``A``, ``B``, ``C``, ``E3``, ``E5``, ``D``, ``A_EXTRA``,
``C_EXTRA``) rather than being retyped, so our compiled integrator takes exactly SciPy's steps
(tests compare step counts). They are assembled on first use
([`dop853`][recipdyn.integrate.tableaus.dop853]) and kept in the user's cache directory, so
importing recipdyn, and later runs, do not import ``scipy.integrate``.
"""

from __future__ import annotations

import functools
import os
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
    extra dense-output stages 13-15 (``A_EXTRA``, ``C_EXTRA``).

    Importing ``scipy.integrate`` costs ~0.4 s, so the assembled arrays are kept in the user's
    cache directory (one file per SciPy version) and read from there by later processes."""
    import scipy

    from ..resources import cache_dir

    path = os.path.join(cache_dir(), f"dop853-scipy-{scipy.__version__}.npz")
    try:
        with np.load(path) as z:
            arrays = {k: np.ascontiguousarray(z[k], dtype=np.float64) for k in _DOP853_ARRAYS}
            meta = [int(x) for x in z["meta"]]
    except (OSError, KeyError, ValueError):
        arrays, meta = _dop853_from_scipy()
        try:  # atomic: a concurrent reader sees the old file or the whole new one
            os.makedirs(os.path.dirname(path), exist_ok=True)
            tmp = f"{path}.{os.getpid()}.tmp.npz"
            np.savez(tmp, meta=np.array(meta), **arrays)
            os.replace(tmp, path)
        except OSError:  # a read-only cache only costs the import next time
            pass
    order, n_stages, err_order = meta
    return Tableau(name="DOP853", order=order, n_stages=n_stages,
                   error_estimator_order=err_order, **arrays)  # fmt: skip


_DOP853_ARRAYS = ("A", "B", "C", "E3", "E5", "D")


def _dop853_from_scipy() -> tuple[dict[str, np.ndarray], list[int]]:
    from scipy.integrate import DOP853 as S

    n = S.n_stages
    A = np.zeros((n + 4, n + 4))
    A[:n, :n] = S.A
    A[n, :n] = S.B
    A[n + 1 :, :] = S.A_EXTRA
    C = np.concatenate([S.C, [1.0], S.C_EXTRA])
    arrays = dict(A=A, B=S.B, C=C, E3=S.E3, E5=S.E5, D=S.D)
    arrays = {k: np.ascontiguousarray(v, dtype=np.float64) for k, v in arrays.items()}
    return arrays, [int(S.order), int(n), int(S.error_estimator_order)]


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
