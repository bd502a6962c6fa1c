"""The model protocol: what a model declares so that every layer above can use it.

A *model* is a family of dynamical systems with a typed parameter schema:

* ``name`` and a one-line ``description``;
* ``state_names`` and ``state_units``;
* ``schema``: a [`Schema`][recipdyn.model.protocol.Schema] of
  [`Param`][recipdyn.model.protocol.Param] (name, unit, default, allowed range or choices,
  description, whether the value is an assumption, group);
* [`Model.system`][recipdyn.model.protocol.Model.system]: the compiled system
  ([`ODESystem`][recipdyn.model.base.ODESystem] or [`DiscreteMap`][recipdyn.model.base.DiscreteMap])
  for validated parameter values — its kernels follow the calling convention of
  [`recipdyn.model.base`][recipdyn.model.base];
* [`Model.initial_state`][recipdyn.model.protocol.Model.initial_state],
  [`Model.period`][recipdyn.model.protocol.Model.period] (the forcing period, for stroboscopic
  sections and orders; ``None`` for autonomous systems),
  [`Model.outputs`][recipdyn.model.protocol.Model.outputs] (named signals with units, default: the
  state components) and [`Model.check`][recipdyn.model.protocol.Model.check] (validity checks across
  parameters).

A record of a run says what the model put in it with `Model.record_attrs` and is read back
with `Model.values_from_record`; an assembled model whose parameters choose a component from a
user's file gives the schema at those values with `Model.schema_for`.

Models are found by name through [`recipdyn.model.registry`][recipdyn.model.registry]. The layers
above the model talk to a model only through this class (no branch on a model's name or
parameter class: ``tests/test_one_track.py``); see ``docs/architecture.md``.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, fields, is_dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .base import DiscreteMap, Event, ODESystem, Signal

from ..errors import ParameterError, is_number

__all__ = ["Param", "Schema", "Model", "Event", "UnknownParameterError", "close_matches",
           "Derived", "DERIVED_ATTR", "derive_value", "derived_names", "rule_inputs"]  # fmt: skip

#: The record attribute that lists the values derived from others (`Derived`), each with its
#: rule: ``"rs = r / 2, ls = l / 2"``.
DERIVED_ATTR = "derived_parameters"


def __getattr__(name: str):
    # ``Event`` lives in .base, which loads numba: imported when first asked for, so that
    # schemas (and the command line's validation) load without compiled code
    if name == "Event":
        from .base import Event

        return Event
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def close_matches(word: str, candidates) -> list[str]:
    """The candidates ``word`` may be a misspelling of, closest first: difflib's similarity
    ratio (without case) at least 0.6 and within 0.1 of the best one's (so that
    ``discharge_presure`` suggests ``discharge_pressure`` alone, not every ``*_pressure``)."""
    from difflib import SequenceMatcher

    scored = []
    for c in set(candidates):
        m = SequenceMatcher(None, word.lower(), c.lower())
        if m.real_quick_ratio() >= 0.6 and m.quick_ratio() >= 0.6 and m.ratio() >= 0.6:
            scored.append((m.ratio(), c))
    if not scored:
        return []
    best = max(r for r, _ in scored)
    return [c for r, c in sorted(scored, key=lambda rc: (-rc[0], rc[1])) if r >= best - 0.1][:3]


class Derived(float):
    """A parameter value derived from other parameters by its `Param.derive` rule, not set by
    the user. It is a number like any other; validation derives it again from the values it
    follows (so ``{**values, "l": 0.45}`` moves a derived ``ls`` with ``l``), records name it
    (`DERIVED_ATTR`), and reading a record back keeps it derived."""

    __slots__ = ()

    def __reduce__(self):
        return Derived, (float(self),)


def rule_inputs(rule: str) -> tuple[str, ...]:
    """The parameter names a derivation rule (``"m2 * l**2 / 12"``) reads."""
    return compile(rule, "<rule>", "eval").co_names


def derive_value(p: Param, values: Mapping[str, Any]) -> Derived:
    """``p``'s value derived by its rule from ``values`` (validated numbers); a value out of
    ``p``'s range is refused naming the rule and the values it was derived from."""
    names = rule_inputs(p.derive)
    v = float(eval(p.derive, {"__builtins__": {}}, {k: float(values[k]) for k in names}))  # noqa: S307 - a rule declared in recipdyn's code
    try:
        p.check(v)
    except ParameterError:
        given = ", ".join(f"{k} = {float(values[k]):g}" for k in names)
        raise ParameterError(
            f"{p.name} = {p.derive} = {v:g} {p.unit} (derived from {given}) is out of range; "
            f"allowed: {p.range_text()}: set {p.name} or change {', '.join(names)}"
        ) from None
    return Derived(v)


class UnknownParameterError(ParameterError):
    """A parameter name no schema entry or alias matches; ``suggestions`` are the closest
    known names (possibly none)."""

    def __init__(self, name: str, known) -> None:
        self.name = name
        self.suggestions = close_matches(name, known)
        hint = (f"did you mean {' or '.join(repr(s) for s in self.suggestions)}?"
                if self.suggestions else f"known: {', '.join(sorted(known))}")  # fmt: skip
        super().__init__(f"unknown parameter {name!r}; {hint}")


@dataclass(frozen=True)
class Param:
    """One parameter of a model.

    Attributes
    ----------
    name : str
        Identifier (also the CLI/config key).
    unit : str
        SI unit understood by pint (``"m"``, ``"rad/s"``, ``"kg*m**2"``); ``""`` if
        dimensionless. Values are always stored in this unit.
    default : float, str or None
        Default value (``None`` only if ``optional``).
    description : str
        One line, shown by ``recipdyn models NAME``.
    low, high : float
        Allowed range (``low_open``/``high_open`` exclude the end points).
    choices : tuple of str, optional
        For string-valued parameters: the allowed values.
    assumed : str
        Why the default is an assumption (empty if it is not), recorded in every output.
    group : str
        The part of the model it belongs to (e.g. ``mechanism``, ``joint``, ``load``,
        ``initial``, ``operation``).
    optional : bool
        ``None`` is allowed (meaning "derived by the model", e.g. an initial angle).
    low_ref, high_ref : str
        A bound that depends on other parameters, as text (``"r"``, ``"l - r - rc"``): shown
        in place of ``low``/``high`` by `range_text`; the model's cross-field check
        (`Model.check`) enforces it.
    derive : str
        A default that follows other parameters: an arithmetic rule over their names
        (``"l / 2"``, ``"m2 * l**2 / 12"``). Unless the value is set, validation derives it
        (a `Derived` number) from the validated values; ``default`` is its value at the
        defaults of the others.
    """

    name: str
    unit: str
    default: Any
    description: str
    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False
    high_open: bool = False
    choices: tuple[str, ...] | None = None
    assumed: str = ""
    group: str = "model"
    optional: bool = False
    low_ref: str = ""
    high_ref: str = ""
    derive: str = ""

    @property
    def kind(self) -> str:
        return "choice" if self.choices is not None else "number"

    def range_text(self, unit: bool = True) -> str:
        """The allowed values as text: ``'a', 'b'``, or an interval such as ``[0, r) m``."""
        if self.choices is not None:
            return ", ".join(repr(c) for c in self.choices)
        lb = "(" if self.low_open else "["
        rb = ")" if self.high_open else "]"
        low = self.low_ref or f"{self.low:g}"
        high = self.high_ref or f"{self.high:g}"
        return f"{lb}{low}, {high}{rb}" + (f" {self.unit}" if self.unit and unit else "")

    def check(self, value: Any) -> Any:
        """``value`` validated (numbers as float);
        [`ParameterError`][recipdyn.errors.ParameterError] names the range."""
        if value is None and self.optional:
            return None
        if self.choices is not None:
            if value not in self.choices:
                raise ParameterError(f"{self.name} = {value!r}; allowed: {self.range_text()}")
            return value
        if not is_number(value):
            raise ParameterError(f"{self.name} must be a number, got {value!r}")
        value = float(value)
        if not math.isfinite(value):
            raise ParameterError(f"{self.name} must be finite, got {value!r}")
        bad_lo = value <= self.low if self.low_open else value < self.low
        bad_hi = value >= self.high if self.high_open else value > self.high
        if bad_lo or bad_hi:
            unit = f" {self.unit}" if self.unit else ""
            raise ParameterError(
                f"{self.name} = {value!r}{unit} is out of range; allowed: {self.range_text()}"
            )
        return value


@dataclass(frozen=True)
class Schema:
    """An ordered set of [`Param`][recipdyn.model.protocol.Param] with validation and round
    trips."""

    params: tuple[Param, ...]
    aliases: Mapping[str, str] = field(default_factory=dict)
    #: Values the model takes beside its parameters, without a row (a table such as the
    #: compressor's ``load_table``): default None, passed through `validate` unchecked (the
    #: model's `Model.check` checks them), recorded by the model's `Model.record_attrs`.
    extras: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        names = [p.name for p in self.params]
        if len(set(names)) != len(names):
            raise ValueError(f"duplicate parameter names in schema: {names}")

    def __iter__(self) -> Iterator[Param]:
        return iter(self.params)

    def __len__(self) -> int:
        return len(self.params)

    def __contains__(self, name: str) -> bool:
        return any(p.name == name for p in self.params)

    def __getitem__(self, name: str) -> Param:
        name = self.resolve(name)
        return next(p for p in self.params if p.name == name)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.params)

    def resolve(self, name: str) -> str:
        """The parameter's name for ``name`` or an alias; raise
        `UnknownParameterError` (with the closest names) on unknown names."""
        name = self.aliases.get(name, name)
        if name not in self and name not in self.extras:
            raise UnknownParameterError(name, {*self.names, *self.aliases})
        return name

    def defaults(self) -> dict[str, Any]:
        return {p.name: p.default for p in self.params}

    def validate(self, values: Mapping[str, Any] | None = None) -> dict[str, Any]:
        """Defaults updated with ``values`` (names or aliases), each checked against its range."""
        out = {**self.defaults(), **dict.fromkeys(self.extras)}
        given = set()
        for k, v in (values or {}).items():
            name = self.resolve(k)
            out[name] = v
            if not (v is None or isinstance(v, Derived)):
                given.add(name)
        rules = [p for p in self.params if p.derive and p.name not in given]
        checked = {p.name: p.check(out[p.name]) for p in self.params if p not in rules}
        for p in rules:  # a default that follows the values it derives from
            checked[p.name] = derive_value(p, checked)
        checked = {p.name: checked[p.name] for p in self.params}  # (the schema's order)
        return {**checked, **{e: out[e] for e in self.extras}}

    def units(self) -> dict[str, str]:
        return {p.name: p.unit for p in self.params}

    def to_attrs(self, values: Mapping[str, Any]) -> dict[str, Any]:
        """Flat attributes for result files: ``param_NAME``, its units, and assumption notes."""
        out: dict[str, Any] = {}
        derived = []
        for p in self.params:
            v = values[p.name]
            out[f"param_{p.name}"] = "default" if v is None else v
            if p.unit:
                out[f"param_{p.name}_units"] = p.unit
            if p.assumed:
                out[f"param_{p.name}_note"] = p.assumed
            if p.derive and isinstance(v, Derived):
                derived.append(f"{p.name} = {p.derive}")
        if derived:
            out[DERIVED_ATTR] = ", ".join(derived)
        return out

    def from_attrs(self, attrs: Mapping[str, Any]) -> dict[str, Any]:
        """Values recorded by `to_attrs` (unknown keys ignored)."""
        out: dict[str, Any] = {}
        derived = derived_names(attrs)
        for p in self.params:
            key = f"param_{p.name}"
            if key in attrs:
                v = attrs[key]
                if isinstance(v, np.generic):
                    v = v.item()
                out[p.name] = None if v == "default" else Derived(v) if p.name in derived else v
        return self.validate(out)

    def table(self) -> list[dict[str, str]]:
        """Rows for display: name, default, unit, range, group, assumed, description."""
        return [dict(name=p.name, default="derived" if p.default is None else p.derive
                     if p.derive else f"{p.default:g}"
                     if is_number(p.default) else str(p.default), unit=p.unit or "-",
                     range=p.range_text(), group=p.group, assumed="yes" if p.assumed else "",
                     description=p.description) for p in self.params]  # fmt: skip


def derived_names(attrs: Mapping[str, Any]) -> set[str]:
    """The names a record lists as derived from others (`DERIVED_ATTR`)."""
    text = attrs.get(DERIVED_ATTR, "")
    return {part.split("=")[0].strip() for part in str(text).split(",") if "=" in part}


class Model(ABC):
    """Base class of registered models (see the module docstring).

    Subclasses set ``name``, ``description``, ``state_names``, ``state_units``, ``schema`` and
    implement `system` and `initial_state`; the rest has generic defaults.
    """

    name: str = ""
    description: str = ""
    state_names: tuple[str, ...] = ()
    state_units: tuple[str, ...] = ()
    time_unit: str = "s"
    schema: Schema = Schema(())
    #: Signals recorded at each stroboscopic (or map) section point by sweeps: (name, unit);
    #: empty = the state components.
    section_signals: tuple[tuple[str, str], ...] = ()
    #: The measured vibration signal (peak, RMS and spectrum in sweeps): (name, unit); empty =
    #: the first state component.
    vibration_signal: tuple[str, str] = ()
    #: Two section signals whose points are counted for periodicity (default: the first two).
    section_pair: tuple[str, str] = ()

    def states(self, values: Mapping[str, Any]) -> tuple[tuple[str, str], ...]:
        """``(name, unit)`` of each state component at ``values`` (default: the class's
        ``state_names`` and ``state_units``; an assembled model whose components add states,
        such as a motor drive, says so here)."""
        return tuple(zip(self.state_names, self.state_units, strict=True))

    def sections(self) -> tuple[tuple[str, str], ...]:
        return self.section_signals or tuple(zip(self.state_names, self.state_units,
                                                 strict=True))  # fmt: skip

    def pair(self) -> tuple[str, str]:
        names = [k for k, _ in self.sections()]
        return self.section_pair or tuple((names * 2)[:2])

    def vibration(self) -> tuple[str, str]:
        return self.vibration_signal or (self.state_names[0], self.state_units[0])

    #: Outputs that must stay at or above a bound for the model to hold: (output name, unit,
    #: lower bound, why, what to use instead). Simulate warns and sweeps record the minimum
    #: (``min_<output>``) and mark the points that cross.
    validity_bounds: tuple[tuple[str, str, float, str, str], ...] = ()
    #: Entries of `run_summary` that are verdicts (pass/fail against a standard, e.g.
    #: the API 618 pin-load reversal): `recipdyn.simulate.summarize` withholds them
    #: (value ``"invalid"``, the reason in ``<entry>_reason``) for a run that left the model's
    #: validity, since a verdict computed from equations that no longer describe the machine
    #: must not be acted on.
    summary_verdicts: tuple[str, ...] = ()
    #: Outputs whose mean over a run sweeps store with the ``peak`` measure: (output name,
    #: stored name, unit), e.g. the contact-impact joint's time fraction in contact; NaN for a
    #: point whose run lacks the output.
    mean_signals: tuple[tuple[str, str, str], ...] = ()
    #: Outputs whose largest value over a run sweeps store with the ``peak`` measure, in the
    #: same form, e.g. the contact-impact joint's largest eccentricity ratio (above 1: the
    #: deepest penetration as a fraction of the clearance).
    max_signals: tuple[tuple[str, str, str], ...] = ()

    def events(self, values: Mapping[str, Any]) -> tuple[Event, ...]:
        """Events to locate during a simulation (at most one today: the integrator locates
        one event function). Default: none. An acting one (reset, terminal) must also be in
        the [`ODESystem`][recipdyn.model.base.ODESystem]'s ``events``, so that every integration
        applies it (the interface test checks this)."""
        return ()

    #: Parameter values at which the model's declared events occur (for the interface test and
    #: the docs, when they do not occur at the defaults).
    event_example: Mapping[str, Any] = {}
    #: Why Benettin's method is refused for this model (empty: it is supported).
    lyapunov_refusal: str = ""

    def lyapunov_supported(self, values: Mapping[str, Any]) -> bool:
        """Whether Benettin's method applies (it needs the Jacobian; state resets are handled
        by saltation matrices). A model refuses it by setting ``lyapunov_refusal``."""
        return not self.lyapunov_refusal

    def identity_values(self, values: Mapping[str, Any]) -> dict[str, Any]:
        """The values that identify a run (a sweep store's digest): ``values`` without the
        parameters that have no effect at them. Default: all of them. A model that gains a
        component keeps the digests of the stores made before by leaving the component's
        parameters out while it is not chosen."""
        return dict(values)

    def state_scale(self, values: Mapping[str, Any]) -> np.ndarray:
        """Typical size of each state component (used to perturb states in the interface
        tests). Default: ``max(1, |initial state|)``; a model whose states are far smaller
        than 1 in SI units (a valve lift in m, a gas mass in kg) says so here."""
        return np.maximum(1.0, np.abs(self.initial_state(values)))

    def validity_applies(self, values: Mapping[str, Any]) -> bool:
        """Whether `validity_bounds` apply at ``values`` (e.g. not to the compressor
        without clearance, whose pin is an ideal two-way joint). Default: always."""
        return True

    def law_range(self, values: Mapping[str, Any], ds: Any) -> str:
        """Where a run (``ds``: its record) used a constitutive law of the model beyond the
        range its source states (e.g. a point-contact law at a contact arc of the order of the
        radii): the message with the threshold and its source; empty when within range (the
        default). `recipdyn.simulate` records it (``law_range``) and warns
        (`recipdyn.errors.LawRangeWarning`)."""
        return ""

    def has_dynamics(self, values: Mapping[str, Any]) -> bool:
        """False where the state cannot move (e.g. the compressor with rc = 0): Lyapunov
        exponents are then reported as 0 without integrating."""
        return True

    @property
    def kind(self) -> str:
        """``"ode"`` or ``"map"``."""
        return "ode"

    @property
    def dim(self) -> int:
        return len(self.state_names)

    def parameters(self, values: Mapping[str, Any] | Any | None = None, **kw: Any
                   ) -> dict[str, Any]:  # fmt: skip
        """Validated parameter values: defaults updated with ``values`` (a mapping by name or
        alias, or a parameter dataclass taken field by field, such as the compressor's
        ``CompressorParams``) and ``kw``."""
        if is_dataclass(values) and not isinstance(values, type):
            values = {f.name: getattr(values, f.name) for f in fields(values)}
        elif values is not None and not isinstance(values, Mapping):
            raise ParameterError(f"parameters of model {self.name!r}: expected a mapping of "
                                 f"names to values, got {type(values).__name__}")  # fmt: skip
        raw = {**(values or {}), **kw}
        out = self.schema_for(raw).validate(raw)
        self.check(out)
        return out

    def schema_for(self, values: Mapping[str, Any]) -> Schema:
        """The schema at ``values`` (names or aliases, raw or validated): default the class's
        ``schema``; an assembled model whose parameters choose components from a user's file
        adds their fragments here (the compressor, `recipdyn.model.components`)."""
        return self.schema

    def configured(self, values: Mapping[str, Any]) -> Model:
        """The model that describes runs at validated ``values``: itself (the default), or,
        for a model whose parameters choose its implementation (the compressor,
        `recipdyn.model.family`), this model with that implementation's declarations
        (section and vibration signals, validity bounds, refusals, state names). The layers
        above read those declarations from it."""
        return self

    def parameter_table(self) -> list[tuple[Param, str]]:
        """Every parameter with the configuration it belongs to (``""``: the default one),
        for ``recipdyn models``. Default: the schema's."""
        return [(p, "") for p in self.schema]

    def selector_schema(self) -> Schema:
        """The parameters whose values choose the configuration (`configured`), each with
        every value it takes and this model's default, in the order a form shows them; empty
        (the default) for a model of one configuration. The app shows them first, then the
        fields of ``configured(their values)``."""
        return Schema(())

    def inactive(self, values: Mapping[str, Any]) -> dict[str, str]:
        """The parameters of ``configured(values).schema`` that a form leaves out at the
        selector values in ``values``, each with the selector values under which it acts
        (``""``: none to tell): parameters that do not act in that configuration (a pin's
        clearance where the pin is ideal) and older spellings of a selector. Default: none."""
        return {}

    def check(self, values: Mapping[str, Any]) -> None:  # noqa: B027 - optional hook
        """Validity checks across parameters; raise
        [`ParameterError`][recipdyn.errors.ParameterError]."""

    @abstractmethod
    def system(self, values: Mapping[str, Any]) -> ODESystem | DiscreteMap:
        """The compiled system for validated ``values``."""

    @abstractmethod
    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        """The initial state for validated ``values``."""

    def period(self, values: Mapping[str, Any]) -> float | None:
        """Forcing period in ``time_unit`` (None for an autonomous system)."""
        sys_ = self.system(values)
        return getattr(sys_, "period", None)

    def section_angle(self, values: Mapping[str, Any]) -> str | None:
        """The state that turns (an angle in rad that increases, such as a crank's driven by a
        motor) whose turns give an autonomous system its Poincaré section, once per turn
        ([`angle_section`][recipdyn.analysis.poincare.angle_section]); None (the default) when
        there is none: a forced system's section is taken once per forcing period."""
        return None

    def outputs(self, values: Mapping[str, Any], t: np.ndarray, y: np.ndarray
                ) -> dict[str, Signal]:  # fmt: skip
        """Named signals over a trajectory (default: the state components)."""
        from .base import Signal

        return {n: Signal(np.asarray(y[:, i]), u, n)
                for i, (n, u) in enumerate(zip(self.state_names, self.state_units,
                                               strict=True))}  # fmt: skip

    def record_attrs(self, values: Mapping[str, Any], y0: np.ndarray | None = None
                     ) -> dict[str, Any]:  # fmt: skip
        """What a record of a run from the initial state ``y0`` says about the model: its
        title, description and initial state (when given), and its parameters
        (``param_NAME`` with units and assumption notes, `Schema.to_attrs`).
        `recipdyn.simulate` writes them, a sweep store the ``param_*`` ones;
        `values_from_record` reads them back."""
        out = {"title": f"recipdyn simulation: {self.name}", "model": self.name,
               "model_description": self.description}  # fmt: skip
        if y0 is not None:
            out["state_initial"] = [float(x) for x in np.atleast_1d(y0)]
        return {**out, **self.schema_for(values).to_attrs(values)}

    def values_from_record(self, attrs: Mapping[str, Any]) -> dict[str, Any]:
        """The validated parameter values a record (its attributes, written by
        `record_attrs`) was made with; raise [`ParameterError`][recipdyn.errors.ParameterError]
        if they are not valid."""
        chosen = {p.name: attrs[f"param_{p.name}"] for p in self.schema
                  if p.choices is not None and f"param_{p.name}" in attrs}  # fmt: skip
        values = self.schema_for(chosen).from_attrs(attrs)
        self.check(values)
        return values

    def run_summary(self, values: Mapping[str, Any], ds: Any) -> dict[str, float]:
        """Figures of merit of one simulated run (``ds``: the labelled result of
        `recipdyn.simulate`), written into its attributes and printed by the CLI.
        Default: none."""
        return {}

    def __repr__(self) -> str:
        return f"<model {self.name!r}: {self.description}>"
