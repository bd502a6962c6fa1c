"""Typed configuration (TOML) for simulations: parameters and settings with units.

Example (``examples/base_case.toml``; ``recipdyn simulate --dump-config FILE`` writes the full,
commented config of any run, and ``recipdyn simulate -c RUN.nc`` reruns a recorded run)::

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
import functools
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from .defaults import SIMULATION
from .model.parameters import (
    PIN_SPELLINGS,
    SCHEMA,
    CompressorParams,
    ParameterError,
    resolve_name,
)
from .model.protocol import Derived
from .units import to_si

if TYPE_CHECKING:
    from pydantic import BaseModel as RunConfig  # (the class _config_classes builds)

__all__ = [
    "SimulationConfig",  # noqa: F822  (built by _config_classes, given by __getattr__)
    "RunConfig",
    "read_config",
    "build_params",
    "model_values",
    "dump_config",
    "config_from_record",
]

#: The compressor's parameters whose values are names (every one with ``choices``).
_STRING_FIELDS = {p.name for p in SCHEMA if p.choices is not None}
#: The default model's parameters that choose a component: a ``module:object`` or
#: ``file.py:OBJ`` value names a component from a user's file, whose parameters only the
#: loaded model knows (`recipdyn.model.protocol.Model.schema_for`).
CHOICES = frozenset(_STRING_FIELDS)


@functools.cache
def _config_classes() -> tuple[type, type]:
    """(SimulationConfig, RunConfig), built on first use: pydantic is imported only when a
    config file is read or written, not to validate command-line options."""
    from pydantic import BaseModel, ConfigDict

    class SimulationConfig(BaseModel):
        """Settings of `recipdyn.simulate` (quantities allowed where units apply)."""

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

    for cls in (SimulationConfig, RunConfig):
        cls.__module__ = __name__
    return SimulationConfig, RunConfig


def __getattr__(name: str):
    if name in ("SimulationConfig", "RunConfig"):
        return _config_classes()[name == "RunConfig"]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _optional(name: str) -> bool:
    """Whether the compressor's parameter ``name`` may be None (derived by the model)."""
    return name in SCHEMA and SCHEMA[name].optional


def build_params(values: dict[str, Any], base: CompressorParams | None = None) -> CompressorParams:
    """CompressorParams from ``{name_or_alias: number | quantity string}``, validated."""
    kw: dict[str, Any] = {}
    pressure_table = None
    for k, v in values.items():
        if k == "pressure_table":  # a measured indicator diagram: needs the final geometry
            pressure_table = v
            continue
        name = resolve_name(k)
        if name in _STRING_FIELDS:
            kw[name] = str(v)
        elif name == "load_table":
            from .model.load import read_load_table

            if isinstance(v, (list, tuple)):  # inline [[deg, N], ...] (a dumped config)
                rows = [tuple(map(float, r)) for r in v]
                if len(rows) < 2 or any(len(r) != 2 for r in rows):
                    raise ParameterError("load_table: need >= 2 rows of [angle_deg, force_N]")
                kw[name] = tuple(sorted((a % 360.0, f) for a, f in rows))
            else:
                kw[name] = read_load_table(v)
        elif _optional(name) and (v is None or str(v).lower() in ("default", "none")):
            kw[name] = None  # derived by the model (theta_c0, motor_torque)
        elif isinstance(v, Derived):
            kw[name] = v  # (a record's derived value, in SI: derived again)
        else:
            kw[name] = to_si(name, v)
    params = dataclasses.replace(base or CompressorParams(), **kw)
    if pressure_table is not None:
        from .model.load import read_pressure_table

        if "load_table" in kw:
            raise ParameterError("pressure_table and load_table: give one of them")
        table = read_pressure_table(pressure_table, bore=params.bore,
                                    rod_diameter=params.rod_diameter,
                                    frame_pressure=params.frame_pressure)  # fmt: skip
        params = dataclasses.replace(params, load_table=table)
    return params


def read_config(path: str | Path) -> RunConfig:
    """Read and validate a TOML config file (clear errors, exit status 2 at the CLI); a run
    written by ``recipdyn simulate`` (``.nc``) gives the config that made it."""
    import tomllib

    from pydantic import ValidationError

    path = Path(path)
    if path.suffix.lower() == ".nc":
        return config_from_record(path)
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
        return _config_classes()[1].model_validate(raw)
    except ValidationError as exc:
        first = exc.errors()[0]
        loc = ".".join(str(x) for x in first["loc"])
        raise ParameterError(f"config {path}: {loc}: {first['msg']}") from None


def model_values(model, values: dict[str, Any]) -> dict[str, Any]:
    """Validated values of any model's schema (at these values: a component from a user's
    file brings its own parameters) from ``{name: number | quantity string}``."""
    schema = model.schema_for(values)
    out: dict[str, Any] = {}
    for k, v in values.items():
        if k in PIN_SPELLINGS and k not in schema.names:  # (the compressor's pins, spelt
            out[k] = str(v)  # the older way: the model reads them into its selectors)
            continue
        if k in ("load_table", "pressure_table") and k not in schema.names:
            # a table (rows) or its file beside the schema: the model's parameters() reads it
            # or refuses it
            out[k] = tuple(tuple(r) for r in v) if isinstance(v, list) else v
            continue
        name = schema.resolve(k)
        p = schema[name]
        out[p.name] = (str(v) if p.choices is not None else v if isinstance(v, Derived)
                       else to_si(p.name, v, unit=p.unit))  # fmt: skip
    return model.parameters(out)


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return repr(float(v)) if isinstance(v, float) else str(v)


def dump_config(model, values: dict[str, Any], settings: dict[str, Any], *,
                spec: str | None = None) -> str:  # fmt: skip
    """The full, commented TOML config of a run: the model (``spec``: how it is found again,
    default its name; a plug-in model's ``file.py:OBJ``), every parameter of ``model`` (values
    in SI; units, description, allowed range and assumptions as comments), the values it
    takes beside its schema (a load table) and every simulation setting.
    ``recipdyn simulate -c`` reads it back to the same run."""
    lines = [f"# recipdyn run configuration: model {model.name!r} ({model.description})",
             "# numbers are SI (the unit in each comment); quantities such as '1 mm' work too",
             f"model = {_toml_value(spec or model.name)}", "", "[params]"]  # fmt: skip
    group = None
    for p in model.schema_for(values):
        if p.group != group:
            group = p.group
            lines.append(f"# -- {group}")
        v = values.get(p.name, p.default)
        rng = f"one of {', '.join(p.choices)}" if p.choices else p.range_text(unit=False)
        note = f"; note: {p.assumed}" if p.assumed else ""
        comment = f"  # {p.unit or '-'}; {p.description}; allowed {rng}{note}"
        if v is None:
            lines.append(f"# {p.name} = (derived by the model){comment}")
        elif isinstance(v, Derived):  # (commented: it follows what it derives from)
            lines.append(f"# {p.name} = {_toml_value(v)} (derived: {p.derive}){comment}")
        else:
            lines.append(f"{p.name} = {_toml_value(v)}{comment}")
    for name in model.schema.extras:  # values without a schema row: a table as rows
        v = values.get(name)
        if v is not None:
            lines.append(f"{name} = {_toml_value([list(r) for r in v])}")
    lines += ["", "[simulation]"]
    notes = {"revolutions": "revolutions recorded (periods for other models)",
             "transient": "revolutions discarded first", "fs": "sampling rate, Hz",
             "method": "dop853 or rk4", "rtol": "relative tolerance (dop853)",
             "atol": "absolute tolerance (dop853)", "h": "RK4 step, s"}  # fmt: skip
    for k, text in notes.items():
        v = settings.get(k, SIMULATION.get(k))
        if v is None:
            lines.append(f"# {k} = (not set)  # {text}")
        else:
            lines.append(f"{k} = {_toml_value(v)}  # {text}")
    return "\n".join(lines) + "\n"


def config_from_record(path: str | Path) -> RunConfig:
    """The config a recorded run was made with (its ``param_*`` and solver attributes)."""
    import numpy as np
    from pydantic import ValidationError

    from .io import read_dataset
    from .model.registry import get_model

    path = Path(path)
    ds = read_dataset(path, what="config", expected="a run written by 'recipdyn simulate'")
    attrs = ds.attrs
    spec = attrs.get("model_spec") or attrs.get("model_name")
    if spec is None or not any(k.startswith("param_") for k in attrs):
        raise ParameterError(f"config {path}: not a recipdyn run (no model and parameters "
                             "recorded)")  # fmt: skip
    m = get_model(str(spec))
    try:  # the model reads its own record (a table beside its schema included)
        values = m.values_from_record(attrs)
    except (ParameterError, TypeError, ValueError) as exc:
        raise ParameterError(f"config {path}: the recorded parameters are not valid "
                             f"({exc})") from None  # fmt: skip
    params: dict[str, Any] = {}
    for k, v in values.items():
        if v is not None:
            table = k in m.schema.extras or k == "load_table"
            params[k] = [list(r) for r in v] if table else v
    sim: dict[str, Any] = {}
    for key, name in (
        ("revolutions", "revolutions"),
        ("transient_revolutions", "transient"),
        ("sampling_rate_hz", "fs"),
        ("solver_method", "method"),
        ("solver_rtol", "rtol"),
        ("solver_atol", "atol"),
        ("solver_h", "h"),
    ):
        if key in attrs and attrs[key] != "adaptive":
            v = attrs[key]
            sim[name] = v.item() if isinstance(v, np.generic) else v
    try:
        simulation_config, run_config = _config_classes()
        return run_config(model=str(spec), params=params, simulation=simulation_config(**sim))
    except ValidationError as exc:
        raise ParameterError(f"config {path}: recorded settings not valid ({exc})") from None
