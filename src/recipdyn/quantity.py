"""Quantities with units (pint), converted to a given unit: the floor every layer may use.

`to_unit` converts a number or a quantity text (``"1 mm"``, ``"191 rpm"``) to a float in
the unit asked for; `recipdyn.units.to_si` asks for a model parameter's or a setting's
SI unit. pint is imported only when a text with units is converted.
"""

from __future__ import annotations

import functools
import math

from .errors import ParameterError

__all__ = ["to_unit"]


def _import_pint():
    """pint, imported without letting it import dask (~0.4 s): pint only uses dask to wrap
    dask arrays, and recipdyn converts plain numbers. A dask imported earlier is used as is."""
    import sys

    if "pint" in sys.modules or "dask" in sys.modules:
        import pint

        return pint
    import importlib.util

    find_spec = importlib.util.find_spec

    def _without_dask(name, *args, **kw):
        return None if name.partition(".")[0] == "dask" else find_spec(name, *args, **kw)

    importlib.util.find_spec = _without_dask
    try:
        import pint
    finally:
        importlib.util.find_spec = find_spec
    return pint


@functools.lru_cache(maxsize=1)
def _ureg():
    import os

    from .resources import cache_dir

    pint = _import_pint()
    try:  # the parsed unit definitions are cached: 0.1 s instead of 1 s
        ureg = pint.UnitRegistry(cache_folder=os.path.join(cache_dir(), "pint"))
    except Exception:  # an unwritable cache folder, or a cache file another process is
        ureg = pint.UnitRegistry()  # writing (pint writes it in place): parse without it
    ureg.define("rev = 2 * pi * radian = revolution")
    return ureg


def to_unit(name: str, value, unit: str) -> float:
    """Convert ``value`` (number or string such as ``"1 mm"``, ``"191 rpm"``) to ``unit``
    (``""``: a plain number); ``name`` names it in a refusal. A bare number is taken to be
    in ``unit`` already (pint, ~0.3 s to import on an idle machine, only loads for text with
    units)."""
    if isinstance(value, bool):
        raise ParameterError(f"{name}: expected a number or quantity, got {value!r}")
    if isinstance(value, (int, float)):
        out = float(value)
    else:
        text = str(value).strip()
        try:
            bare = float(text)  # a bare number is already in SI
        except ValueError:
            bare = None
        if bare is not None:
            return _finite_or_nan_error(name, bare)
        pint = _import_pint()
        try:
            q = _ureg().Quantity(text)
        except (pint.errors.UndefinedUnitError, pint.errors.DefinitionSyntaxError) as exc:
            raise ParameterError(f"{name}: unknown unit in {text!r} ({exc})") from None
        except Exception as exc:  # pint raises assorted parse errors
            raise ParameterError(f"{name}: cannot parse {text!r} as a quantity ({exc})") from None
        target = unit.replace("**", "^") if unit else "dimensionless"
        try:
            out = float(q.to(target).magnitude)
            if unit == "rad/s" and "hertz" in str(q.units):
                out *= 2.0 * math.pi  # a crank speed in Hz means revolutions per second
        except pint.errors.DimensionalityError:
            raise ParameterError(
                f"{name}: {text!r} cannot be converted to {unit or 'a plain number'}"
            ) from None
    return _finite_or_nan_error(name, out)


def _finite_or_nan_error(name: str, out: float) -> float:
    if math.isnan(out):
        raise ParameterError(f"{name} must not be NaN")
    return out
