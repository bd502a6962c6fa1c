"""recipdyn: nonlinear dynamics of reciprocating compressors with joint faults."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("recipdyn")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0+unknown"

__all__ = ["__version__"]
