"""recipdyn: nonlinear dynamics of reciprocating compressors with joint faults.

Quick start::

    import recipdyn
    ds = recipdyn.simulate(rc=1e-3, d=1e-3, omega=20.0, revolutions=5)
    ds.a.plot()
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("recipdyn")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0+unknown"

from .integrate import IntegrationError, integrate, propagate  # noqa: E402
from .model import (  # noqa: E402
    ASSUMED,
    CompressorParams,
    DiscreteMap,
    ODESystem,
    ParameterError,
    compressor_model,
    paper_2d12,
)
from .simulate import simulate  # noqa: E402

__all__ = [
    "__version__", "simulate", "integrate", "propagate", "IntegrationError", "CompressorParams",
    "paper_2d12", "compressor_model", "ODESystem", "DiscreteMap", "ParameterError", "ASSUMED",
]  # fmt: skip
