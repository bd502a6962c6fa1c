"""Estimate what a run will need before it starts, and refuse clearly when it cannot fit."""

from __future__ import annotations

import os

from .defaults import MEMORY_FRACTION
from .errors import ParameterError

__all__ = ["available_memory", "cache_dir", "check_memory", "format_bytes", "memory_limit"]


def cache_dir() -> str:
    """recipdyn's folder in the user's cache directory (compiled code, the DOP853 tableau)."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "recipdyn")


def available_memory() -> int:
    """Bytes of memory available to a new allocation now (psutil)."""
    import psutil

    return int(psutil.virtual_memory().available)


def format_bytes(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB", "PB"):
        if abs(n) < 1000 or unit == "PB":
            return f"{n:.3g} {unit}"
        n /= 1000.0
    return f"{n:.3g} PB"  # pragma: no cover


def memory_limit(max_memory: float | None = None) -> float:
    """``max_memory`` (bytes) if given, else [`MEMORY_FRACTION`][recipdyn.resources.MEMORY_FRACTION]
    of the available memory."""
    if max_memory is not None:
        if not max_memory > 0:
            raise ParameterError(f"max_memory = {max_memory!r} bytes; allowed: > 0")
        return float(max_memory)
    return MEMORY_FRACTION * available_memory()


def check_memory(nbytes: float, what: str, how_to_reduce: str,
                 max_memory: float | None = None) -> None:  # fmt: skip
    """Raise [`ParameterError`][recipdyn.errors.ParameterError] if ``nbytes`` exceeds
    [`memory_limit`][recipdyn.resources.memory_limit]."""
    limit = memory_limit(max_memory)
    if nbytes > limit:
        origin = "--max-memory" if max_memory is not None else (
            f"{MEMORY_FRACTION:.0%} of the {format_bytes(available_memory())} available"
        )  # fmt: skip
        raise ParameterError(
            f"{what} needs about {format_bytes(nbytes)} of memory, more than the limit of "
            f"{format_bytes(limit)} ({origin}): {how_to_reduce}, or raise the limit with "
            "--max-memory"
        )
