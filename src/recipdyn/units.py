"""Quantities with units for the CLI and config files (pint), converted to SI floats."""

from __future__ import annotations

from .model.parameters import PARAM_UNITS, ParameterError
from .quantity import to_unit

__all__ = ["to_si", "parse_assignment"]

#: SI unit each settings key is converted to (besides the model parameters' own units).
SETTING_UNITS = {"fs": "Hz", "h": "s", "revolutions": "", "transient": ""}


def to_si(name: str, value, unit: str | None = None) -> float:
    """Convert ``value`` (number or string such as ``"1 mm"``, ``"191 rpm"``) to SI.

    ``unit`` is the SI unit expected for ``name`` (default: from `PARAM_UNITS`). A bare
    number is taken to be in that unit already (`recipdyn.quantity.to_unit`).
    """
    unit = PARAM_UNITS.get(name, SETTING_UNITS.get(name, "")) if unit is None else unit
    return to_unit(name, value, unit)


def parse_assignment(text: str) -> tuple[str, str]:
    """Split ``"name=value"``; raise a clear error otherwise."""
    if "=" not in text:
        raise ParameterError(f"expected NAME=VALUE, got {text!r}")
    k, v = text.split("=", 1)
    return k.strip(), v.strip()
