"""The one place where analysis functions check the signal they are given.

Every public function of `recipdyn.analysis` that takes a sampled signal passes it
through `as_signal` first, so bad input is refused the same way everywhere: a
``ValueError`` that names the argument and the problem (not 1-D, too short, NaN or infinite
values and where the first one is, constant), before any numpy routine fails inside or
returns a number computed from garbage.
"""

from __future__ import annotations

import numpy as np

from ..defaults import MIN_SIGNAL_SAMPLES

__all__ = ["as_signal", "check_rate", "MIN_SIGNAL_SAMPLES"]


def as_signal(x, *, name: str = "signal", min_samples: int = 2,
              allow_constant: bool = False) -> np.ndarray:  # fmt: skip
    """``x`` as a 1-D float array, or a ``ValueError`` naming ``name`` and what is wrong.

    ``min_samples``: fewest samples the caller can use (the signal estimators take
    ``MIN_SIGNAL_SAMPLES``, as ``recipdyn analyze`` does). ``allow_constant``: accept a
    signal whose values are all equal (a spectrum of one is exactly zero; an embedding, a
    delay or an exponent of one means nothing)."""
    try:
        arr = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: not a numeric array") from None
    if arr.ndim != 1:
        raise ValueError(f"{name}: array of shape {arr.shape}; allowed: a 1-D signal")
    bad = ~np.isfinite(arr)
    if bad.any():
        raise ValueError(f"{name}: {int(bad.sum())} NaN or infinite value(s), the first at "
                         f"sample {int(np.argmax(bad))}; allowed: finite values (fill or cut "
                         "them first)")  # fmt: skip
    if arr.size < min_samples:
        raise ValueError(f"{name}: {arr.size} sample(s); at least {min_samples} needed")
    if not allow_constant and arr.max() == arr.min():
        raise ValueError(f"{name}: constant (every sample {arr[0]:g}); a constant signal has "
                         "no dynamics to analyse")  # fmt: skip
    return arr


def check_rate(fs, name: str = "fs") -> float:
    """A sampling rate (or step) as a positive finite float, else a ``ValueError``."""
    try:
        value = float(fs)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {fs!r}; allowed: a positive number") from None
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"{name} = {fs!r}; allowed: a positive finite number")
    return value
