"""Exceptions shared by every layer (the bottom of the package: imports nothing of recipdyn).

The command line maps them to exit statuses (``docs/reliability.md``):

* [`ParameterError`][recipdyn.errors.ParameterError] (bad input: a parameter, setting, path or file)
  -> 2;
* [`IntegrationError`][recipdyn.errors.IntegrationError] (the integrator failed) -> 1;
* [`Interrupted`][recipdyn.errors.Interrupted] (SIGINT / SIGTERM) -> 128 + signal number (130 /
  143).
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from typing import Any

__all__ = ["ParameterError", "Interrupted", "raise_on_signals", "deferred_signals",
           "is_number"]  # fmt: skip


def is_number(x: Any) -> bool:
    """A real number (Python or NumPy int/float), not a bool."""
    import numbers

    return isinstance(x, numbers.Real) and not isinstance(x, bool)


class ParameterError(ValueError):
    """Bad input; the message names the parameter (or file) and the allowed range."""


class ModelValidityWarning(UserWarning):
    """A result left the region where its model holds (e.g. the massless link asked to pull):
    the numbers are what the equations give, but the equations no longer describe the
    machine there."""


class LawRangeWarning(UserWarning):
    """A run used a constitutive law (e.g. Hertz's point-contact law) beyond the range its
    source states: the equations still hold as the model defines them, but the law no longer
    describes the real contact there, so forces and accelerations are the model's, not the
    machine's."""


class KernelAllocatesWarning(UserWarning):
    """A compiled kernel declared without ``allocates=True`` allocates arrays, so it was
    compiled with numba's reference counting after all: correct, but slower
    ([`recipdyn.model.base.compiled`][recipdyn.model.base.compiled])."""


class IntegrationError(RuntimeError):
    """The integrator failed; ``partial`` holds what was computed before the failure."""

    def __init__(self, message: str, partial: Any = None):
        super().__init__(message)
        self.partial = partial  # a recipdyn.integrate.Solution
        self.dataset = None  # set by recipdyn.simulate: the partial record as a Dataset


class Interrupted(BaseException):
    """Work was stopped by a signal.

    Like `KeyboardInterrupt` it derives from `BaseException`, so ``except
    Exception`` does not swallow it; it is not a KeyboardInterrupt subclass, so that command
    frameworks that turn KeyboardInterrupt into a bare exit status (click, typer) let it reach
    recipdyn's own handler, which reports what was kept.

    Layers that catch it on the way up add what they kept (``kept``: one line each, e.g. "12 of
    40 sweep points in out/sweep.zarr; rerun with --resume") and re-raise it; ``partial`` may
    carry a partial result (an integrator [`Solution`][recipdyn.integrate.solve.Solution] or a
    Dataset).
    """

    def __init__(self, signum: int = signal.SIGINT, message: str = ""):
        super().__init__(message or f"interrupted by {signal.Signals(signum).name}")
        self.signum = int(signum)
        self.kept: list[str] = []
        self.partial: Any = None  # raw partial result (an integrator Solution)
        self.dataset: Any = None  # the partial record as a Dataset, where one was built

    @property
    def exit_code(self) -> int:
        return 128 + self.signum

    @classmethod
    def wrap(cls, exc: BaseException) -> Interrupted:
        """``exc`` itself if it is an [`Interrupted`][recipdyn.errors.Interrupted], else one for
        SIGINT (for a plain `KeyboardInterrupt`)."""
        return exc if isinstance(exc, Interrupted) else cls(signal.SIGINT)


def _raise(signum, _frame):
    raise Interrupted(signum)


def raise_on_signals() -> None:
    """Turn SIGINT and SIGTERM into [`Interrupted`][recipdyn.errors.Interrupted] in this (main)
    thread."""
    signal.signal(signal.SIGINT, _raise)
    signal.signal(signal.SIGTERM, _raise)


class _Pending:
    """The first signal received inside [`deferred_signals`][recipdyn.errors.deferred_signals] (0 =
    none)."""

    signum: int = 0

    def check(self) -> None:
        """Raise [`Interrupted`][recipdyn.errors.Interrupted] if a signal arrived."""
        if self.signum:
            raise Interrupted(self.signum)


@contextlib.contextmanager
def deferred_signals() -> Iterator[_Pending]:
    """Hold SIGINT/SIGTERM while a block runs; the block polls ``pending.signum``.

    A Python signal handler raises between any two bytecodes, e.g. between an integrator chunk
    and the bookkeeping that records it. Inside this context a signal only sets a flag, which
    the code checks at points where everything finished is consistent and can be kept. Signals
    whose handler is the operating system's default (SIGTERM in a plain Python program) are
    left alone. Outside the main thread this does nothing (Python delivers signals there).
    """
    pending = _Pending()
    if threading.current_thread() is not threading.main_thread():
        yield pending
        return
    saved = {}

    def _flag(signum, _frame):
        if not pending.signum:
            pending.signum = signum

    for sig in (signal.SIGINT, signal.SIGTERM):
        old = signal.getsignal(sig)
        if callable(old):
            saved[sig] = old
            signal.signal(sig, _flag)
    try:
        yield pending
    finally:
        for sig, old in saved.items():
            signal.signal(sig, old)
