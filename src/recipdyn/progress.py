"""Saying what a long phase is doing: one helper for every layer.

[`phase`][recipdyn.progress.phase] shows a spinner on a terminal while the phase runs and writes one
line to standard error when it took longer than a second, so a log shows where the time went too.
"""

from __future__ import annotations

import contextlib
import sys
import time

__all__ = ["phase", "quiet"]


@contextlib.contextmanager
def phase(message: str, *, say_after: float = 1.0):
    """Say what a phase is doing (``with phase("integrating 100 revolutions"): ...``)."""
    t0 = time.perf_counter()
    if sys.stderr.isatty():
        from rich.console import Console

        with Console(stderr=True).status(message + "..."):
            yield
    else:
        yield
    wall = time.perf_counter() - t0
    if wall > say_after:
        print(f"{message}: {wall:.1f} s", file=sys.stderr, flush=True)


@contextlib.contextmanager
def quiet(message: str, *, say_after: float = 1.0):
    """A [`phase`][recipdyn.progress.phase] that says nothing (library calls without progress)."""
    yield
