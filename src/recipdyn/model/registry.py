"""Find models by name: the built-in ones, Python entry points, or a ``module:object`` path.

* Built-in: ``compressor`` (the default), ``duffing``, ``lorenz``, ``henon``,
  ``double-pendulum``.
* Entry points: another package registers ``name = "pkg.module:object"`` in the group
  ``recipdyn.models`` of its ``pyproject.toml``; ``recipdyn models`` then lists it.
* A path: ``"my_models:PENDULUM"`` (an importable module) or ``"path/to/file.py:PENDULUM"``
  (a file of the user's own), naming a [`Model`][recipdyn.model.protocol.Model] instance or
  class.
* A machine file: ``"path/to/machine.toml"`` (`recipdyn.model.machine`), assembled into a
  model of its throws (``recipdyn simulate --machine FILE``).

Modules are imported only when a model is asked for, so listing names costs nothing.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import sys
from pathlib import Path

from ..errors import ParameterError
from .protocol import Model, close_matches

__all__ = ["get_model", "model_names", "register", "models_with_parameter", "model_spec",
           "load_object", "is_spec", "absolute_spec", "configured_for_record", "DEFAULT_MODEL",
           "ENTRY_POINT_GROUP", "is_machine_file", "machine_model"]  # fmt: skip

DEFAULT_MODEL = "compressor"
ENTRY_POINT_GROUP = "recipdyn.models"

_BUILTIN = {
    "compressor": "recipdyn.model.family:COMPRESSOR",
    "duffing": "recipdyn.model.reference:DUFFING",
    "lorenz": "recipdyn.model.reference:LORENZ",
    "henon": "recipdyn.model.reference:HENON",
    "double-pendulum": "recipdyn.model.reference.double_pendulum:DOUBLE_PENDULUM",
    "impact-oscillator": "recipdyn.model.reference.impact_oscillator:IMPACT_OSCILLATOR",
    "compressor-contact": "recipdyn.model.family:COMPRESSOR_CONTACT",
    "compressor-valves": "recipdyn.model.family:COMPRESSOR_VALVES",
    "compressor-contact-valves": "recipdyn.model.family:COMPRESSOR_CONTACT_VALVES",
    "compressor-guide": "recipdyn.model.family:COMPRESSOR_GUIDE",
    "compressor-guide-reference": "recipdyn.model.reference.compressor_guide:COMPRESSOR_GUIDE",
}
_REGISTERED: dict[str, Model] = {}


def register(model: Model) -> Model:
    """Register ``model`` under ``model.name`` for this process (returns it)."""
    if not isinstance(model, Model) or not model.name:
        raise ParameterError(f"cannot register {model!r}: not a named recipdyn Model")
    _REGISTERED[model.name] = model
    return model


def _entry_points() -> dict[str, str]:
    from importlib.metadata import entry_points

    return {ep.name: ep.value for ep in entry_points(group=ENTRY_POINT_GROUP)}


def model_names() -> list[str]:
    """Every model name that [`get_model`][recipdyn.model.registry.get_model] accepts (paths
    aside)."""
    return sorted({*_BUILTIN, *_entry_points(), *_REGISTERED})


def _load_path(spec: str) -> object:
    module_name, _, attr = spec.rpartition(":")
    if not module_name or not attr:
        raise ParameterError(f"model {spec!r}: expected NAME or module:object")
    try:
        if module_name.endswith(".py") or "/" in module_name or "\\" in module_name:
            path = Path(module_name)
            if not path.is_file():
                raise ParameterError(f"model {spec!r}: file {path} not found")
            # a stable name (numba's on-disk cache records it; hash() would change per process)
            digest = hashlib.sha1(str(path.resolve()).encode()).hexdigest()[:12]
            mod_id = f"recipdyn_user_model_{path.stem}_{digest}"
            if mod_id in sys.modules:  # loaded once per process (its objects stay the same)
                module = sys.modules[mod_id]
            else:
                mspec = importlib.util.spec_from_file_location(mod_id, path)
                module = importlib.util.module_from_spec(mspec)
                sys.modules[mod_id] = module  # picklable by reference in worker processes
                try:
                    mspec.loader.exec_module(module)
                except BaseException:
                    del sys.modules[mod_id]
                    raise
        else:
            module = importlib.import_module(module_name)
    except ParameterError:
        raise
    except Exception as exc:
        raise ParameterError(f"model {spec!r}: cannot import {module_name} "
                             f"({type(exc).__name__}: {exc})") from None  # fmt: skip
    try:
        return getattr(module, attr)
    except AttributeError:
        raise ParameterError(f"model {spec!r}: {module_name} has no {attr!r}") from None


def is_spec(text: object) -> bool:
    """Whether ``text`` names an object by path (``module:object`` or ``file.py:OBJ``)
    rather than by a registered name."""
    return isinstance(text, str) and ":" in text.strip()


def absolute_spec(spec: str) -> str:
    """``spec`` with a file path made absolute (``file.py:OBJ`` finds the same file from
    any folder: records and worker processes store it); a ``module:object`` as it is."""
    where, _, name = spec.strip().rpartition(":")
    return f"{Path(where).resolve()}:{name}" if where.endswith(".py") else spec.strip()


def load_object(spec: str, what: str = "object") -> object:
    """The object ``spec`` (``module:object`` or ``file.py:OBJ``) names, imported once per
    process (a file under a stable module name, so numba's disk cache and worker processes
    find it again); [`ParameterError`][recipdyn.errors.ParameterError] if it cannot be
    loaded."""
    try:
        return _load_path(absolute_spec(spec))
    except ParameterError as exc:
        raise ParameterError(str(exc).replace("model ", f"{what} ", 1)) from None


#: The model of a machine file (a routing entry like `_BUILTIN`'s: imported when a file is
#: first asked for).
MACHINE_MODEL = "recipdyn.model.assembler.model:MachineModel"
_MACHINES: dict[tuple[str, int], Model] = {}


def is_machine_file(spec: object) -> bool:
    """Whether ``spec`` names a machine file (``*.toml``)."""
    return isinstance(spec, str) and spec.strip().lower().endswith(".toml")


def machine_model(path: str) -> Model:
    """The model of the machine file ``path`` (one per file and version of it in a process,
    so its systems are assembled once)."""
    from .machine import read_machine

    p = Path(path).resolve()
    try:
        key = (str(p), p.stat().st_mtime_ns)
    except OSError:
        raise ParameterError(f"machine: file not found: {path}") from None
    if key not in _MACHINES:
        _MACHINES[key] = _load_path(MACHINE_MODEL)(read_machine(p))
    return _MACHINES[key]


def get_model(spec: str | Model | None = None) -> Model:
    """The model named ``spec`` (default `DEFAULT_MODEL`); see the module docstring."""
    if isinstance(spec, Model):
        return spec
    spec = DEFAULT_MODEL if spec is None else str(spec).strip()
    if spec in _REGISTERED:
        return _REGISTERED[spec]
    if is_machine_file(spec):
        return machine_model(spec)
    target = _BUILTIN.get(spec)
    if target is None:
        target = _entry_points().get(spec)
    if target is None and ":" not in spec:
        close = close_matches(spec, model_names())
        hint = (
            f"did you mean {' or '.join(repr(c) for c in close)}? (every model: recipdyn models)"
            if close
            else f"known: {', '.join(model_names())} (or module:object)"
        )
        raise ParameterError(f"unknown model {spec!r}; {hint}")
    obj = _load_path(target or spec)
    if isinstance(obj, type) and issubclass(obj, Model):
        obj = obj()
    if not isinstance(obj, Model):
        raise ParameterError(f"model {spec!r} is a {type(obj).__name__}, not a recipdyn Model "
                             "(subclass recipdyn.model.protocol.Model)")  # fmt: skip
    if target is None:  # a user's module or file: the spec finds it again (records, workers)
        where, _, name = spec.rpartition(":")
        obj.spec = f"{Path(where).resolve()}:{name}" if where.endswith(".py") else spec
    return obj


def model_spec(model: Model) -> str:
    """The string that `get_model` finds ``model`` by again: its name when registered or
    built in, else the ``module:object`` or absolute ``file.py:object`` it was loaded from
    (what a record stores, so that a plug-in model's record can be analysed)."""
    return getattr(model, "spec", None) or model.name


def models_with_parameter(name: str) -> list[str]:
    """The registered models (built-in, entry points, registered) whose schema has a parameter
    or alias ``name``: where to point a user who set a parameter on the wrong model. Loads
    every model (their schemas live beside their kernels: ~1 s), so it is for error paths."""
    found = []
    for model_name in model_names():
        try:
            schema = get_model(model_name).schema
        except Exception:  # a broken plug-in must not hide the answer for the others
            continue
        if name in schema or name in schema.aliases:
            found.append(model_name)
    return found


def configured_for_record(model: Model, attrs) -> Model:
    """``model`` configured (`Model.configured`) by the values a record's or a sweep store's
    attributes hold; ``model`` itself when they hold none it can read (a measured signal)."""
    try:
        return model.configured(model.values_from_record(attrs))
    except (ParameterError, KeyError, TypeError, ValueError):
        return model
