"""Typed configuration (TOML) for simulations: parameters and settings with units.

Example ``case.toml``::

    [params]            # any CompressorParams field or alias, numbers in SI or quantities
    rc = "1 mm"
    d = "1 mm"
    omega = "191 rpm"
    load_sign = "physical"

    [simulation]
    revolutions = 20
    transient = 5
    fs = "10 kHz"
    method = "dop853"
    rtol = 1e-10
"""

from __future__ import annotations

import dataclasses
import tomllib
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, ValidationError

from .defaults import SIMULATION
from .model.parameters import SCHEMA, CompressorParams, ParameterError, resolve_name
from .units import to_si

__all__ = ["SimulationConfig", "RunConfig", "read_config", "build_params", "model_values"]

#: The compressor's parameters whose values are names (every one with ``choices``).
_STRING_FIELDS = {p.name for p in SCHEMA if p.choices is not None}


class SimulationConfig(BaseModel):
    """Settings of :func:`recipdyn.simulate` (quantities allowed where units apply)."""

    model_config = ConfigDict(extra="forbid")
    revolutions: float | str = SIMULATION["revolutions"]
    transient: float | str = SIMULATION["transient"]
    fs: float | str = SIMULATION["fs"]
    method: Literal["dop853", "rk4"] = SIMULATION["method"]
    rtol: float = SIMULATION["rtol"]
    atol: float = SIMULATION["atol"]
    h: float | str | None = SIMULATION["h"]

    def resolved(self) -> dict[str, Any]:
        out = self.model_dump()
        for k in ("revolutions", "transient", "fs", "h"):
            if out[k] is not None:
                out[k] = to_si(k, out[k])
        return out


class RunConfig(BaseModel):
    """A whole config file: an optional ``model`` name and ``[params]``, ``[simulation]``."""

    model_config = ConfigDict(extra="forbid")
    model: str | None = None
    params: dict[str, Any] = {}
    simulation: SimulationConfig = SimulationConfig()


def build_params(values: dict[str, Any], base: CompressorParams | None = None) -> CompressorParams:
    """CompressorParams from ``{name_or_alias: number | quantity string}``, validated."""
    kw: dict[str, Any] = {}
    for k, v in values.items():
        name = resolve_name(k)
        if name in _STRING_FIELDS:
            kw[name] = str(v)
        elif name == "load_table":
            from .model.load import read_load_table

            kw[name] = read_load_table(v)
        elif name == "theta_c0" and (v is None or str(v).lower() in ("default", "none")):
            kw[name] = None
        else:
            kw[name] = to_si(name, v)
    return dataclasses.replace(base or CompressorParams(), **kw)


def read_config(path: str | Path) -> RunConfig:
    """Read and validate a TOML config file (clear errors, exit status 2 at the CLI)."""
    path = Path(path)
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ParameterError(f"config: file not found: {path}") from None
    except IsADirectoryError:
        raise ParameterError(f"config {path}: is a folder, expected a TOML file") from None
    except UnicodeDecodeError as exc:
        raise ParameterError(f"config {path}: not UTF-8 text (byte {exc.start}); TOML files "
                             "must be UTF-8") from None  # fmt: skip
    except PermissionError:
        raise ParameterError(f"config {path}: permission denied") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"config {path}: malformed TOML ({exc})") from None
    try:
        return RunConfig.model_validate(raw)
    except ValidationError as exc:
        first = exc.errors()[0]
        loc = ".".join(str(x) for x in first["loc"])
        raise ParameterError(f"config {path}: {loc}: {first['msg']}") from None


def model_values(model, values: dict[str, Any]) -> dict[str, Any]:
    """Validated values of any model's schema from ``{name: number | quantity string}``."""
    out: dict[str, Any] = {}
    for k, v in values.items():
        p = model.schema[model.schema.resolve(k)]
        out[p.name] = str(v) if p.choices is not None else to_si(p.name, v, unit=p.unit)
    return model.parameters(out)
