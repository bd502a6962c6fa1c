r"""The compressor: one model whose parameters describe the machine the assembler builds.

``--model compressor`` takes five *selectors*, each a parameter:

========================  ==================================================================
``crank_joint``           ``link`` (the paper's massless link of length ``rc``), ``ideal``,
                          ``contact`` (dry contact–impact), ``lubricated``
``crosshead_joint``       ``ideal``, ``contact``, ``lubricated``
``load``                  ``paper``, ``table`` (``load_table`` or ``pressure_table``),
                          ``cycle``, ``valves`` (the cylinder gas with dynamic plate valves),
                          or a component of your own, ``file.py:OBJ``
``drive``                 ``prescribed`` (constant ``omega``), ``motor``
``guide``                 ``ideal`` (the crosshead runs at ``y = -d``), ``clearance`` (the
                          crosshead moves and tilts between the guide's shoes)
========================  ==================================================================

The selectors describe a machine of one throw (`route`: the massless link or ideal pins,
``link`` and ``link-valves``; contact-impact or lubricated pins or the guide's clearance,
``contact`` and ``contact-valves``), which the one assembler builds
(`recipdyn.model.assembler.model.one_throw`: `OneThrow`, `OneContact`), and the model
delegates every call to it. A combination that no machine covers is refused in one line
that says why (`route`), and a parameter that belongs to another configuration is refused in
one line naming the selector value that enables it (`owner`).

The old model names are *presets*: ``compressor-contact`` is this model with
``crank_joint = contact`` as its default, ``compressor-valves`` with ``load = valves``,
``compressor-contact-valves`` with both, ``compressor-guide`` with ``guide = clearance`` and
ideal pins (`PRESETS`; its former kernel of its own is the reference model
``compressor-guide-reference``).

**Values and records.** A configuration's validated values are its implementation's values
plus each selector the implementation does not itself have whose value differs from the
preset's default. So the values of every preset at its defaults, and of every configuration
its old model name reached, are the ones that name gave before: sweep stores keep their
digests, records and configs rerun. A record stores the model it was made with (a preset's
name, or ``compressor``) and the selectors as ``param_*`` like any parameter;
`Compressor.values_from_record` reads them back, so ``--model compressor --set
crank_joint=contact`` and ``--model compressor-contact`` give records that rerun and analyse
alike (and hold the same values).
"""

from __future__ import annotations

import copy
import importlib
from collections.abc import Mapping
from dataclasses import fields, is_dataclass, replace
from os import PathLike
from typing import Any

import numpy as np

from ..errors import ParameterError
from .parameters import PIN_SPELLINGS, SELECTORS, pin_joints
from .protocol import Model, Param, Schema, UnknownParameterError
from .registry import is_spec

__all__ = [
    "Compressor", "SELECTORS", "ROUTE_NAMES", "PRESETS", "route", "owner", "machine",
    "COMPRESSOR",
    "COMPRESSOR_CONTACT", "COMPRESSOR_VALVES",  # noqa: F822 (built on first use, __getattr__)
    "COMPRESSOR_CONTACT_VALVES", "COMPRESSOR_GUIDE",  # noqa: F822
]  # fmt: skip

_DEFAULTS = SELECTORS.defaults()

#: The one assembler's compressor of one throw (`recipdyn.model.assembler.model.one_throw`):
#: the machine each route is, imported when a configuration first asks for one (this model
#: module imports no other model module, tests/test_layers.py).
ASSEMBLER = "recipdyn.model.assembler.model:one_throw"
#: The routes: which machine of one throw the selectors describe (`route`).
ROUTE_NAMES = ("link", "link-valves", "contact", "contact-valves")


def machine(name: str) -> Model:
    """The machine of one throw of route ``name`` (`ROUTE_NAMES`), built by the one
    assembler."""
    module, _, attr = ASSEMBLER.partition(":")
    return getattr(importlib.import_module(module), attr)(name)


def route(s: Mapping[str, Any], table: bool = False) -> str:
    """The route (one of `ROUTE_NAMES`: the machine of one throw) for the selector values
    ``s`` (``table``: a load or pressure table is given); a combination that none covers raises
    [`ParameterError`][recipdyn.errors.ParameterError] in one line that says why and what is
    allowed."""
    crank, cross, load, drive, guide = (s[k] for k in SELECTORS.names)
    rigid_pins = crank in ("link", "ideal") and cross == "ideal"
    if guide == "clearance":
        if crank == "link":
            raise ParameterError(
                "guide = 'clearance' with crank_joint = 'link' is not available: the massless "
                "link's equations hold the crosshead on its line; allowed with the guide "
                "clearance: crank_joint = 'ideal', 'contact' or 'lubricated'"
            )
        # the contact joints' kernels with the guide (any pin joint, ideal pins included; with
        # a motor, the crank's states after the guide's); the preset compressor-guide's own
        # kernel is the reference model compressor-guide-reference, its independent check
        return "contact-valves" if load == "valves" else "contact"
    if crank == "link" and cross != "ideal":
        raise ParameterError(
            f"crank_joint = 'link' with crosshead_joint = {cross!r}: the massless link exists "
            "at the crank pin with an ideal crosshead pin only; for clearance at both pins: "
            "crank_joint = 'contact' or 'lubricated'"
        )
    if rigid_pins:
        if load == "valves":
            return "link-valves"
        return "link"
    return "contact-valves" if load == "valves" else "contact"


def _chosen(raw: Mapping[str, Any], defaults: Mapping[str, Any]) -> dict[str, Any]:
    """The selector values in ``raw`` (names, raw or validated; a record's ``None``, unset)
    over ``defaults``, checked against their choices. The contact joints' older spelling
    (``clearance_joints`` where, ``joint`` dry or lubricated) gives the pins it names where
    the selectors do not (`pin_joints`: a contradiction of the two is refused); a load table
    given makes the load ``table``."""
    s = dict(defaults)
    for k in SELECTORS.names:
        v = raw.get(k)
        if v is not None:
            s[k] = v
    crank, cross = pin_joints(raw)  # (the older spelling; its contradictions refused)
    if crank is not None:
        s["crank_joint"] = crank
    if cross is not None:
        s["crosshead_joint"] = cross
    if s["load"] == "paper" and any(raw.get(k) is not None for k in _TABLES):
        s["load"] = "table"  # (a table given is the table load: records say so)
    for k, v in s.items():
        if not (k == "load" and is_spec(v)):
            SELECTORS[k].check(v)
    return s


#: The values that choose the route.
_KEYS = (*SELECTORS.names, *PIN_SPELLINGS)
#: Names every configuration takes (the selectors, the pins' older spelling, the tables).
_ALWAYS = frozenset({*_KEYS, "load_table", "pressure_table"})
#: The load tables (beside the schemas).
_TABLES = ("load_table", "pressure_table")
#: The oil film's parameters (a lubricated joint's).
_OIL = ("oil_viscosity", "eps_dry", "bearing_length")
#: The parameters of the crank pin's joint alone, and of the crosshead pin's.
_CRANK_PIN = ("rc", "K", "journal_radius", "e0_angle")
_CROSSHEAD_PIN = ("rc_crosshead", "K_crosshead", "crosshead_pin_radius", "e0_angle_crosshead")
#: The contact law, materials and friction of the pins' joints (not the guide's).
_PIN_CONTACT = ("contact_law", "restitution", "E_journal", "nu_journal", "E_bearing",
                "nu_bearing", "friction", "friction_law", "v0", "v1", "e0_ratio")  # fmt: skip


_NOT_OWN: dict[int, frozenset[str]] = {}
_NAMES: dict[int, tuple[Schema, frozenset[str]]] = {}


def _known(schema: Schema) -> frozenset[str]:
    """The names, aliases and extras of ``schema`` (remembered: the protocol asks often)."""
    hit = _NAMES.get(id(schema))
    if hit is None or hit[0] is not schema:
        hit = _NAMES[id(schema)] = schema, frozenset({*schema.names, *schema.aliases,
                                                      *schema.extras})  # fmt: skip
    return hit[1]


def _not_own(impl: Model) -> frozenset[str]:
    """The selectors that ``impl`` does not have (left out of its values)."""
    key = id(impl)
    if key not in _NOT_OWN:
        _NOT_OWN[key] = frozenset(SELECTORS.names) - set(impl.schema.names)
    return _NOT_OWN[key]


def _holds_valves(attrs: Mapping[str, Any]) -> bool:
    """Whether record attributes hold the dynamic valves' parameters."""
    link = machine("link").schema.names
    return any(f"param_{k}" in attrs for k in machine("link-valves").schema.names
               if k not in link)  # fmt: skip


def owner(name: str, s: Mapping[str, Any]) -> str:
    """The selector values under which parameter ``name`` exists, as text
    (``"crosshead_joint = 'contact' | 'lubricated'"``), or ``""`` if none does; ``s``: the
    current selector values (one selector is changed at a time; a crosshead-pin parameter is
    the crosshead joint's)."""
    contact = machine("contact").schema
    if name in contact and name not in machine("link").schema:
        if contact[name].group == "guide":
            return "guide = 'clearance'"
        if name.endswith("_crosshead") or name.startswith("crosshead_pin"):
            return "crosshead_joint = 'contact' | 'lubricated'"
        if name in _OIL:
            return "crank_joint or crosshead_joint = 'lubricated'"
        return "crank_joint or crosshead_joint = 'contact' | 'lubricated'"
    found = []
    for sel in SELECTORS:
        ok = []
        for v in sel.choices:
            if v == s[sel.name]:
                continue
            trial = {**s, sel.name: v}
            if sel.name == "crank_joint" and v != "link":  # (contact at the crank pin alone)
                trial["crosshead_joint"] = "ideal"
            if sel.name == "guide":  # the guide's clearance runs with ideal pins
                trial.update(crank_joint="ideal", crosshead_joint="ideal")
            try:
                impl = machine(route(trial))
            except ParameterError:
                continue
            if name in impl.schema or name in impl.schema.aliases:
                ok.append(v)
        if ok:
            found.append(f"{sel.name} = {' | '.join(repr(v) for v in ok)}")
    return " or ".join(found)


class Compressor(Model):
    """The compressor whose selectors (module docstring) choose the implementation; a
    preset is an instance with other defaults (`with_defaults`)."""

    def __init__(self, name: str = "compressor", defaults: Mapping[str, Any] | None = None,
                 description: str = "", choosable: bool = True) -> None:  # fmt: skip
        self.name = name
        self.defaults = dict(defaults or {})
        #: Whether a form offers the selectors (`selector_schema`): the one model does; a
        #: preset is a fixed starting point whose form is its implementation's.
        self.choosable = choosable
        self._selectors = _chosen(self.defaults, _DEFAULTS)
        self._routes: dict[tuple, tuple[str, dict[str, Any]]] = {}
        impl = machine(route(self._selectors))
        self.description = description or impl.description
        self._adopt(impl)
        others = {k: v for k, v in self.defaults.items() if k not in SELECTORS.names}
        if others:  # (a preset of other parameter defaults: shown in its schema)
            self.schema = Schema(tuple(replace(p, default=others.get(p.name, p.default))
                                       for p in impl.schema), impl.schema.aliases,
                                 impl.schema.extras)  # fmt: skip
        self._schema0 = self.schema
        if self.defaults:  # a preset: its schema's choices default to what it runs (the
            # implementation's own defaults may be another route's: compressor-guide runs on
            # the contact route, whose crank_joint defaults to 'contact')
            ran = self.parameters()
            moved = {p.name for p in self.schema if p.choices is not None and p.name in ran
                     and p.default is not None and ran[p.name] != p.default}  # fmt: skip
            if moved:  # (else the implementation's own schema, the very object)
                self.schema = Schema(tuple(replace(p, default=ran[p.name]) if p.name in moved
                                           else p for p in self.schema), self.schema.aliases,
                                     self.schema.extras)  # fmt: skip
                self._schema0 = self.schema

    def _adopt(self, impl: Model) -> None:
        """Take the implementation's declarations that do not depend on values."""
        for k in (
            "state_names",
            "state_units",
            "schema",
            "section_signals",
            "vibration_signal",
            "section_pair",
            "validity_bounds",
            "summary_verdicts",
            "mean_signals",
            "max_signals",
            "event_example",
            "lyapunov_refusal",
            "time_unit",
        ):
            if hasattr(impl, k):
                setattr(self, k, getattr(impl, k))

    def _route0(self, s: Mapping[str, Any] | None = None) -> str:
        """The route at the selector values ``s`` (default: this preset's)."""
        return route(self._selectors if s is None else s)

    def with_defaults(self, **defaults: Any) -> Compressor:
        """This model with other defaults (selectors or any parameter), under its name."""
        return Compressor(
            self.name, {**self.defaults, **defaults}, self.description, self.choosable
        )

    # -- routing ------------------------------------------------------------------------
    def selectors(self, values: Mapping[str, Any]) -> dict[str, Any]:
        """The selector values at ``values`` (raw or validated), this preset's defaults for
        the ones not given."""
        return _chosen(values, self._selectors)

    def route(self, values: Mapping[str, Any]) -> tuple[str, Model, dict[str, Any]]:
        """(route, implementation, selector values) at ``values`` (remembered per value of
        the selectors: every call of the protocol asks)."""
        table = any(values.get(k) is not None for k in _TABLES)
        key = (*(values.get(k) for k in _KEYS), table)
        try:
            name, s = self._routes[key]
        except KeyError:
            s = self.selectors(values)
            name = route(s, table)
            if len(self._routes) < 256:
                self._routes[key] = name, s
        except TypeError:  # an unhashable value
            s = self.selectors(values)
            name = route(s, table)
        return name, machine(name), dict(s)

    def _split(self, values: Mapping[str, Any]) -> tuple[Model, dict[str, Any]]:
        """The implementation at validated ``values`` and its own values."""
        _, impl, _ = self.route(values)
        drop = _not_own(impl)
        return impl, {k: v for k, v in values.items() if k not in drop}

    def configured(self, values: Mapping[str, Any]) -> Model:
        """This model with the declarations of the implementation ``values`` choose (its
        section signals, vibration signal, validity bounds, refusals, state names)."""
        _, impl, _ = self.route(values)
        out = copy.copy(self)
        out._adopt(impl)
        out.schema = self.schema_for(values)
        return out

    # -- parameters ---------------------------------------------------------------------
    def schema_for(self, values: Mapping[str, Any]) -> Schema:
        """The implementation's schema at ``values``, with the selectors that it does not
        have and ``values`` holds."""
        name, impl, s = self.route(values)
        mine = _known(impl.schema)
        schema = impl.schema_for({k: v for k, v in values.items() if k in mine})
        if schema is impl.schema and name == self._route0():
            schema = self._schema0  # (a preset's defaults)
        known = _known(schema) | _ALWAYS
        for k in values:
            if k not in known and (where := owner(k, s)):
                raise ParameterError(self._elsewhere(k, where))
        extra = [p for p in SELECTORS if p.name not in schema.names and p.name in values
                 and values[p.name] is not None]  # fmt: skip
        if not extra:
            return schema
        extra = [replace(p, choices=(*p.choices, values[p.name])) if is_spec(values[p.name])
                 else p for p in extra]  # fmt: skip
        return Schema((*schema.params, *extra), schema.aliases, schema.extras)

    def parameters(self, values: Mapping[str, Any] | Any | None = None, **kw: Any
                   ) -> dict[str, Any]:  # fmt: skip
        """Validated values: the implementation the selectors choose validates its own, the
        selectors it does not have are added where they differ from this preset's defaults
        (module docstring). A parameter of another configuration is refused in one line
        naming the selector value that enables it."""
        if is_dataclass(values) and not isinstance(values, type):
            values = {f.name: getattr(values, f.name) for f in fields(values)}
        elif values is not None and not isinstance(values, Mapping):
            raise ParameterError(f"parameters of model {self.name!r}: expected a mapping of "
                                 f"names to values, got {type(values).__name__}")  # fmt: skip
        raw = {k: v for k, v in self.defaults.items() if k not in SELECTORS.names}
        raw.update(values or {})
        raw.update(kw)
        name, impl, s = self.route(raw)
        own = _known(impl.schema)
        mine = {k: v for k, v in raw.items()
                if k not in (*SELECTORS.names, *PIN_SPELLINGS) or k in own}  # fmt: skip
        for k in SELECTORS.names:  # a selector the implementation has (the pins, the guide)
            if k in own:
                mine[k] = s[k]
        if s["load"] in ("table", "valves") and "load" in own:
            mine["load"] = "paper"
        if s["load"] == "table" and raw.get("load_table") is None and raw.get(
                "pressure_table") is None:  # fmt: skip
            raise ParameterError(
                "load = 'table' needs load_table (rows of crank angle in deg "
                "and force in N, or their CSV file) or pressure_table"
            )
        if s["load"] in ("cycle", "valves"):
            for k in _TABLES:
                if raw.get(k) is not None:
                    raise ParameterError(f"{k}: not with load = {s['load']!r}, whose gas force "
                                         "follows the chamber pressures; allowed: load = "
                                         "'table'")  # fmt: skip
        if s["crank_joint"] == "ideal" and "rc" in own and name.startswith("link"):
            if raw.get("rc", 0.0) not in (0.0, 0, None):
                raise ParameterError(f"rc = {raw['rc']!r}: the crank pin is ideal (crank_joint "
                                     "= 'ideal'); rc belongs to crank_joint = 'link' | "
                                     "'contact' | 'lubricated'")  # fmt: skip
            mine["rc"] = 0.0
        if s["guide"] == "ideal" and raw.get("guide_clearance") not in (None, 0, 0.0):
            raise ParameterError("guide_clearance belongs to guide = 'clearance'")
        if name.startswith("contact") and is_spec(raw.get("motor")):
            raise ParameterError(
                f"motor = {raw['motor']!r}: a torque law of your own file drives the massless "
                "link or ideal pins in a rigid guide (crank_joint = 'link' or 'ideal', "
                "crosshead_joint = 'ideal', guide = 'ideal'); with a contact or lubricated pin "
                "or the guide's clearance: motor = 'constant' or 'induction'"
            )
        ptab = mine.pop("pressure_table", None) if "pressure_table" not in impl.schema else None
        if isinstance(mine.get("load_table"), (str, PathLike)):  # (a CSV file of the rows)
            from .load import read_load_table

            mine["load_table"] = read_load_table(mine["load_table"])
        try:
            out = impl.parameters(mine)
            if ptab is not None:
                from .load import read_pressure_table

                if mine.get("load_table") is not None:
                    raise ParameterError("pressure_table and load_table: give one of them")
                out = impl.parameters({**out, "load_table": read_pressure_table(
                    ptab, bore=out["bore"], rod_diameter=out["rod_diameter"],
                    frame_pressure=out["frame_pressure"])})  # fmt: skip
        except UnknownParameterError as exc:
            where = owner(exc.name, s)
            if where:
                raise ParameterError(self._elsewhere(exc.name, where)) from None
            raise
        for k in SELECTORS.names:
            if k not in out and s[k] != self._selectors[k]:
                out[k] = s[k]
        return out

    def _elsewhere(self, name: str, where: str) -> str:
        return (f"{name} is not a parameter of this configuration of {self.name!r}; it "
                f"belongs to {where}")  # fmt: skip

    def check(self, values: Mapping[str, Any]) -> None:
        impl, own = self._split(values)
        impl.check(own)

    # -- the rest: delegated -------------------------------------------------------------
    def system(self, values: Mapping[str, Any]):
        impl, own = self._split(values)
        return impl.system(own)

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        impl, own = self._split(values)
        return impl.initial_state(own)

    def period(self, values: Mapping[str, Any]) -> float | None:
        impl, own = self._split(values)
        return impl.period(own)

    def section_angle(self, values: Mapping[str, Any]) -> str | None:
        """The crank angle ``theta1`` with ``drive = motor`` (a state then: the section is
        taken once per turn of the crank, wherever its speed puts it in time); None with the
        prescribed speed (the section is stroboscopic, once per crank period)."""
        return "theta1" if values.get("drive") == "motor" else None

    def states(self, values: Mapping[str, Any]) -> tuple[tuple[str, str], ...]:
        impl, own = self._split(values)
        return impl.states(own)

    def outputs(self, values: Mapping[str, Any], t: np.ndarray, y: np.ndarray):
        impl, own = self._split(values)
        return impl.outputs(own, t, y)

    def events(self, values: Mapping[str, Any]):
        impl, own = self._split(values)
        return impl.events(own)

    def lyapunov_supported(self, values: Mapping[str, Any]) -> bool:
        impl, own = self._split(values)
        return impl.lyapunov_supported(own)

    def identity_values(self, values: Mapping[str, Any]) -> dict[str, Any]:
        impl, own = self._split(values)
        kept = impl.identity_values(own)
        return {k: v for k, v in values.items() if k in kept or k not in own}

    def state_scale(self, values: Mapping[str, Any]) -> np.ndarray:
        impl, own = self._split(values)
        return impl.state_scale(own)

    def validity_applies(self, values: Mapping[str, Any]) -> bool:
        impl, own = self._split(values)
        return impl.validity_applies(own)

    def law_range(self, values: Mapping[str, Any], ds: Any) -> str:
        impl, own = self._split(values)
        return impl.law_range(own, ds)

    def has_dynamics(self, values: Mapping[str, Any]) -> bool:
        impl, own = self._split(values)
        return impl.has_dynamics(own)

    def run_summary(self, values: Mapping[str, Any], ds: Any) -> dict[str, Any]:
        impl, own = self._split(values)
        return impl.run_summary(own, ds)

    # -- beyond the protocol: the contact joints' compiled module and load ----------------
    def kernels(self, values: Mapping[str, Any]):
        """The compiled kernels of the configuration at validated ``values`` (a contact
        route's: its throw's module, with ``fd_jac`` and ``observe``)."""
        impl, own = self._split(values)
        return impl.kernels(own)

    def load_part(self, values: Mapping[str, Any]):
        """The load component of the configuration at validated ``values`` (a contact
        route's)."""
        impl, own = self._split(values)
        return impl.load_part(own)

    def record_attrs(self, values: Mapping[str, Any], y0: np.ndarray | None = None
                     ) -> dict[str, Any]:  # fmt: skip
        """The implementation's record attributes under this model's name, with the
        selectors ``values`` holds beside the implementation's parameters."""
        _, impl, s = self.route(values)
        own = {k: v for k, v in values.items() if k not in _not_own(impl)}
        out = impl.record_attrs(own, y0)
        out.update({"title": f"recipdyn simulation: {self.name}", "model": self.name,
                    "model_description": self.description})  # fmt: skip
        extra = [p for p in self.schema_for(values) if p.name not in own]
        out.update(Schema(tuple(extra)).to_attrs(values))
        # every selector at the value that ran (an implementation's own ``load`` is its
        # mechanism's: 'paper' under a table, 'cycle' under the valves)
        out.update({f"param_{k}": v for k, v in s.items() if not is_spec(v)})
        return out

    def values_from_record(self, attrs: Mapping[str, Any]) -> dict[str, Any]:
        """The values of a record of any configuration (its selectors as ``param_*``, this
        preset's defaults for the ones it lacks)."""
        names = {*SELECTORS.names, *PIN_SPELLINGS}
        given = {k[len("param_") :]: attrs[k] for k in attrs
                 if k.startswith("param_") and k[len("param_") :] in names}  # fmt: skip
        given = {k: (None if isinstance(v, str) and v == "default" else
                     v.item() if isinstance(v, np.generic) else v)
                 for k, v in given.items()}  # fmt: skip
        if given.get("load") == "cycle" and _holds_valves(attrs):
            given["load"] = "valves"  # (a record of the massless link with dynamic valves
            # made before the selectors were recorded: its mechanism's own load, 'cycle')
        _, impl, s = self.route(given)
        if "load" in impl.schema.names and s["load"] in ("table", "valves"):
            attrs = {**attrs, "param_load": "paper"}  # (the implementation's own load)
        out = impl.values_from_record(attrs)
        for k in SELECTORS.names:
            if k not in out and s[k] != self._selectors[k]:
                out[k] = s[k]
        return out

    def selector_schema(self) -> Schema:
        """The five selectors with every value they take (a load of your own, ``file.py:OBJ``,
        is given on the command line or in a config file) and this model's defaults; empty for
        a preset (``choosable = False``)."""
        if not self.choosable:
            return Schema(())
        return Schema(tuple(replace(p, default=self._selectors[p.name]) for p in SELECTORS))

    def inactive(self, values: Mapping[str, Any]) -> dict[str, str]:
        """The parameters of ``configured(values)`` that do not act at the selector values
        of ``values``, each with the selector values under which it does: a pin's own
        parameters where that pin is ideal, the pins' contact law, materials and friction
        where both are rigid (a worn guide has its own), the oil film's where no pin is
        lubricated, the guide's (but ``guide``) where the guide is ideal, the motor's where
        the drive is prescribed, the compression cycle's with the paper's load and the
        paper's amplitude with the cycle; and the pins' older spelling
        (``clearance_joints``, ``joint``), which the selectors replace."""
        s = self.selectors(values)
        schema = self.configured(values).schema
        out = dict.fromkeys(PIN_SPELLINGS, "")
        pins = (s["crank_joint"], s["crosshead_joint"])
        if s["crank_joint"] == "ideal":
            out.update(dict.fromkeys(_CRANK_PIN, "crank_joint = 'contact' | 'lubricated'"))
            out["rc"] = "crank_joint = 'link' | 'contact' | 'lubricated'"
        if s["crosshead_joint"] == "ideal":
            out.update(dict.fromkeys(_CROSSHEAD_PIN, "crosshead_joint = 'contact' | "
                                                     "'lubricated'"))  # fmt: skip
        if "lubricated" not in pins:
            out.update(dict.fromkeys(_OIL, "crank_joint or crosshead_joint = 'lubricated'"))
        if set(pins) <= {"link", "ideal"}:  # (the worn guide has its own law and friction)
            out.update(dict.fromkeys(_PIN_CONTACT, "crank_joint or crosshead_joint = "
                                                   "'contact' | 'lubricated'"))  # fmt: skip
        by_group = {
            "guide": "guide = 'clearance'" if s["guide"] == "ideal" else None,
            "drive": "drive = 'motor'" if s["drive"] == "prescribed" else None,
            "cycle": "load = 'cycle'" if s["load"] == "paper" else None,
        }
        for p in schema:
            if by_group.get(p.group) and p.name not in SELECTORS.names:
                out[p.name] = by_group[p.group]
        if s["load"] in ("cycle", "valves"):
            out["load_amplitude"] = "load = 'paper'"
        return {k: v for k, v in out.items() if k in schema.names}

    def parameter_table(self) -> list[tuple[Param, str]]:
        """Every parameter of every configuration with the selector values it belongs to
        (``""``: this preset's default configuration), for ``recipdyn models``."""
        rows: list[tuple[Param, str]] = [(p, "") for p in self.schema]
        seen = set(self.schema.names)
        for p in SELECTORS:
            if p.name not in seen:
                rows.append((replace(p, default=self._selectors[p.name]), "selector"))
                seen.add(p.name)
        for name in ROUTE_NAMES:
            for p in machine(name).schema:
                if p.name not in seen:
                    rows.append((p, owner(p.name, self._selectors)))
                    seen.add(p.name)
        return rows


#: The presets: the old model names, this model with other defaults.
PRESETS = {
    "compressor-contact": {"crank_joint": "contact"},
    "compressor-valves": {"load": "valves"},
    "compressor-contact-valves": {"crank_joint": "contact", "load": "valves"},
    "compressor-guide": {"guide": "clearance", "crank_joint": "ideal"},
}

#: The registered instance (``--model compressor``, the default); the presets are
#: ``COMPRESSOR_CONTACT``, ``COMPRESSOR_VALVES``, ``COMPRESSOR_CONTACT_VALVES`` and
#: ``COMPRESSOR_GUIDE``, built when first asked for (each loads its implementation).
COMPRESSOR = Compressor()
_PRESET_NAMES = {f"COMPRESSOR_{k[len('compressor-'):].upper().replace('-', '_')}": k
                 for k in PRESETS}  # fmt: skip


def __getattr__(name: str) -> Compressor:
    if name in _PRESET_NAMES:
        key = _PRESET_NAMES[name]
        globals()[name] = Compressor(key, PRESETS[key], choosable=False)
        return globals()[name]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
