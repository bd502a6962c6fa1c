"""The app's form: one field per parameter of a model's schema and per run setting, read in
the units engineers type, with one error per field.

A field holds text: a quantity with its unit (``"0.5 mm"``, ``"300 rpm"``, ``"3 bar"``), read
by pint through `recipdyn.units.to_si`, or a bare number, read in the field's display
unit (shown beside it). Values are written back in the display unit when that writes them
exactly to six digits (``0.001 m`` -> ``"1 mm"``), else in SI (``20 rad/s`` stays
``"20 rad/s"`` rather than an inexact ``"190.986 rpm"``), so the defaults of the form are the
model's defaults to the bit. The same texts make the page's address (`to_query`) and the
run's config file (`config_text`, read back by ``recipdyn simulate -c``).

A model whose parameters choose its configuration (the compressor's joints, load, drive and
guide: `Model.selector_schema`) gets those selectors first, as choice fields, then the fields
of the configuration they choose (`Model.configured`), less the parameters that do not act
in it (`Model.inactive`). The form reads the selectors from the texts themselves, so the
texts alone (a page's fields, an address) say which fields there are.
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass
from typing import Any
from urllib.parse import parse_qsl, urlencode

from ..defaults import ATOL_RANGE, RTOL_RANGE, SIMULATION
from ..errors import ParameterError
from ..model.protocol import Param
from ..model.registry import DEFAULT_MODEL, get_model, is_spec, model_names
from ..units import to_si

__all__ = ["Field", "fields", "selected", "selector_errors", "read_form", "format_value",
           "to_query", "from_query", "config_text", "MAX_SAMPLES", "RUN"]  # fmt: skip

#: The longest run the app draws (samples, or iterations of a map); longer runs belong to
#: ``recipdyn simulate``, which streams them to a file.
MAX_SAMPLES = 2_000_000
#: Prefix of the run settings' field keys (they share the form with a model's parameters).
RUN = "run."
#: The group of the selector fields (shown first).
CONFIGURATION = "configuration"


@dataclass(frozen=True)
class Field:
    """One field of the form: a model parameter or a run setting."""

    key: str  #: the name in the form and the address ("rc", "run.fs")
    name: str  #: the parameter or setting name
    si_unit: str  #: the unit values are stored in ("" for a plain number)
    unit: str  #: the unit a bare number is read in (the display unit)
    default: Any
    description: str = ""
    group: str = "run"
    choices: tuple[str, ...] | None = None
    optional: bool = False  #: empty means "derived by the model"
    assumed: str = ""
    param: Param | None = None

    @property
    def default_text(self) -> str:
        return format_value(self.default, self)

    def range_text(self) -> str:
        """The allowed range in the display unit, e.g. ``(0, 50] mm``."""
        p = self.param
        if self.choices is not None:
            return "one of " + ", ".join(self.choices)
        if p is None:
            return ""
        ends = []
        for v in (p.low, p.high):
            ends.append(f"{v / _factor(self.unit, self.si_unit):.6g}")
        lb, rb = "(" if p.low_open else "[", ")" if p.high_open else "]"
        return f"{lb}{ends[0]}, {ends[1]}{rb}" + (f" {self.unit}" if self.unit else "")

    def parse(self, text: Any) -> Any:
        """The value of ``text`` in SI, checked against the range (`ParameterError`
        naming the field, the value and the range otherwise)."""
        if self.choices is not None:
            if self.optional and (text is None or str(text).lower() in ("", "default", "none")):
                return None  # derived by the model (a joint family from the older parameters)
            value = str(text)
            if value not in self.choices:
                raise ParameterError(f"{self.name} = {value!r}; allowed: {self.range_text()}")
            return value
        text = "" if text is None else str(text).strip()
        if not text or (self.optional and text.lower() in ("default", "derived", "none")):
            if self.optional:
                return None
            raise ParameterError(f"{self.name}: empty; give a value in {self.unit or 'numbers'}")
        try:
            float(text)
            text = f"{text} {self.unit}" if self.unit else text  # a bare number: display unit
        except ValueError:
            pass
        value = to_si(self.name, text, unit=self.si_unit)
        if self.param is not None:
            try:
                self.param.check(value)
            except ParameterError:
                raise ParameterError(f"{self.name} = {format_value(value, self)} is out of "
                                     f"range; allowed: {self.range_text()}") from None  # fmt: skip
        return value


def _factor(unit: str, si_unit: str) -> float:
    """SI value of one display ``unit`` (1.0 when they are the same)."""
    if unit == si_unit:
        return 1.0
    from ..units import _ureg

    return float(_ureg().Quantity(1.0, unit).to(si_unit.replace("**", "^")).magnitude)


def _display_unit(p: Param) -> str:
    """The unit engineers type for ``p``: mm for lengths below a metre, bar for pressures
    (GPa for elastic moduli), rpm for a crank speed, degrees for angles."""
    d = abs(p.default) if isinstance(p.default, (int, float)) else 0.0
    if p.unit == "m" and d < 1.0:
        return "mm"
    if p.unit == "Pa":
        return "GPa" if d >= 1e8 else "bar"
    if p.unit == "rad/s" and p.name == "omega":
        return "rpm"
    if p.unit == "rad":
        return "deg"
    return p.unit


def format_value(value: Any, field: Field) -> str:
    """``value`` (SI) as field text that reads back to it exactly: six digits in the display
    unit when they are exact (``"1 mm"``), else six digits in SI (``"20 rad/s"``), else the
    shortest exact text in the display unit, else in SI (``"2.6666666666666665"``)."""
    if value is None:
        return ""
    if isinstance(value, str):
        return value
    value = float(value)
    units = list(dict.fromkeys((field.unit, field.si_unit)))
    for digits in ("{:.6g}", "{!r}"):
        for unit in units:
            f = _factor(unit, field.si_unit)
            text = digits.format(value / f)
            if float(text) * f == value:
                return f"{text} {unit}".strip()
    return f"{value!r} {field.si_unit}".strip()


def _run_fields() -> list[Field]:
    lo_r, hi_r = RTOL_RANGE
    lo_a, hi_a = ATOL_RANGE

    def num(name, unit, disp, low, high, desc, low_open=True):
        p = Param(name, unit, SIMULATION[name], desc, low=low, high=high, low_open=low_open)
        return Field(RUN + name, name, unit, disp, SIMULATION[name], desc, param=p)

    return [
        num("revolutions", "", "", 0.0, math.inf,
            "crank revolutions recorded (forcing periods, time units or iterations for other "
            "models)"),
        num("transient", "", "", 0.0, math.inf, "revolutions integrated and discarded first",
            low_open=False),
        num("fs", "Hz", "kHz", 0.0, math.inf, "output sampling rate"),
        Field(RUN + "method", "method", "", "", SIMULATION["method"],
              "dop853: adaptive Dormand-Prince 8(5,3); rk4: the paper's fixed step",
              choices=("dop853", "rk4")),
        num("rtol", "", "", lo_r, hi_r, "relative tolerance (dop853)", low_open=False),
        num("atol", "", "", lo_a, hi_a, "absolute tolerance (dop853)", low_open=False),
    ]  # fmt: skip


def selected(model: Any, texts: dict[str, Any] | None = None) -> dict[str, str]:
    """The selector values in ``texts`` (`Model.selector_schema`; a value that is not one of
    a selector's choices counts as its default here, and its field reports it); empty for a
    model of one configuration."""
    texts = texts or {}
    return {p.name: texts[p.name] if texts.get(p.name) in p.choices else p.default
            for p in get_model(model).selector_schema()}  # fmt: skip


def selector_errors(model: Any, texts: dict[str, Any] | None = None) -> dict[str, str]:
    """The model's refusal of the selector values in ``texts`` (a combination that does not
    exist), at the selector it names first; empty when they make a configuration."""
    m = get_model(model)
    sel = selected(m, texts)
    if not sel:
        return {}
    try:
        m.configured(sel)
    except ParameterError as exc:
        return {_owner(str(exc), list(sel)) or next(iter(sel)): str(exc)}
    return {}


def _configuration(m: Any, sel: dict[str, str]) -> tuple[Any, dict[str, str]]:
    """The configured model at the selector values ``sel`` and the names its form leaves out;
    a combination the model refuses shows its default configuration's fields (the refusal is
    told when the form is read)."""
    try:
        return m.configured(sel), m.inactive(sel)
    except ParameterError:
        dflt = {k: p.default for k, p in zip(sel, m.selector_schema(), strict=True)}
        return m.configured(dflt), m.inactive(dflt)


def fields(model: Any = None, texts: dict[str, Any] | None = None) -> list[Field]:
    """The form of ``model`` (a name or a model; default the compressor): its selectors, if
    it has any, then every parameter of the configuration the selector values in ``texts``
    choose (default: the model's defaults) that a field can hold (numbers, choices, optional
    numbers; a table such as the compressor's ``load_table`` is set in a config file), then
    the run settings."""
    m = get_model(model)
    sel = m.selector_schema()
    out = [Field(p.name, p.name, p.unit, "", p.default, p.description, CONFIGURATION,
                 p.choices, False, p.assumed, p) for p in sel]  # fmt: skip
    schema, skip = m.schema, set()
    if len(sel):
        configured, idle = _configuration(m, selected(m, texts))
        schema, skip = configured.schema, {*idle, *sel.names}
    for p in schema:
        if p.name in skip:
            continue
        if p.choices is None and not isinstance(p.default, (int, float)) and not p.optional:
            continue
        out.append(Field(p.name, p.name, p.unit, _display_unit(p), p.default, p.description,
                         p.group, p.choices, p.optional, p.assumed, p))  # fmt: skip
    return out + _run_fields()


@dataclass
class Form:
    """A read form: the model, its validated parameters, the run settings and the errors."""

    model: Any
    params: Any = None  #: the model's validated values (a dict)
    settings: dict[str, Any] = dataclasses.field(default_factory=dict)
    errors: dict[str, str] = dataclasses.field(default_factory=dict)  #: field key -> message
    general: str = ""  #: an error that belongs to no single field

    @property
    def ok(self) -> bool:
        return not self.errors and not self.general

    def values(self) -> dict[str, Any]:
        """The parameter values as a plain dict (SI)."""
        p = self.params
        return dataclasses.asdict(p) if dataclasses.is_dataclass(p) else dict(p)


def _owner(message: str, keys: list[str]) -> str | None:
    """The field a cross-parameter error names first (its first word, else any name in it)."""
    first = re.match(r"\s*([A-Za-z_][\w]*)", message)
    if first and first.group(1) in keys:
        return first.group(1)
    for k in sorted(keys, key=len, reverse=True):
        if re.search(rf"(?<![\w.]){re.escape(k)}(?![\w])", message):
            return k
    return None


def _derived(f: Field, text: Any) -> bool:
    """Whether field ``f`` is left to its rule (a default that follows other parameters,
    ``ls = l / 2``): its text is missing or still its default's."""
    return bool(f.param is not None and f.param.derive
                and (text is None or str(text).strip() == f.default_text))  # fmt: skip


def read_form(model: Any, texts: dict[str, Any]) -> Form:
    """Read the field ``texts`` (key -> text; missing keys take the default) of ``model``.

    Each field is parsed and range-checked on its own, so every bad field gets its message;
    then the model's checks across parameters run (an error there goes to the field it names)
    and the run's length is bounded by `MAX_SAMPLES`.
    """
    m = get_model(model)
    form = Form(m)
    flds = fields(m, texts)
    raw: dict[str, Any] = {}
    for f in flds:
        text = texts.get(f.key)
        try:
            raw[f.key] = f.default if text is None else f.parse(text)
        except ParameterError as exc:
            form.errors[f.key] = str(exc)
    form.settings = {f.name: raw[f.key] for f in flds if f.key.startswith(RUN) and f.key in raw}
    if form.errors:
        return form
    values = {f.name: raw[f.key] for f in flds if not f.key.startswith(RUN)
              and not _derived(f, texts.get(f.key))}  # fmt: skip
    try:
        # the schema's ranges, then the model's checks across parameters; an empty optional
        # field (None) is derived by the model
        form.params = m.parameters(values)
        form.model = m.configured(form.params)  # the configuration's declarations
    except (ParameterError, TypeError, ValueError) as exc:
        key = _owner(str(exc), [f.key for f in flds])
        if key is None:
            form.general = str(exc)
        else:
            form.errors[key] = str(exc)
        return form
    _check_length(form)
    return form


def _check_length(form: Form) -> None:
    m, s = form.model, form.settings
    if m.kind == "map":
        n = s["revolutions"]
        what = f"{n:.4g} iterations"
    else:
        period = m.period(form.params)
        n = s["revolutions"] * (float(period) if period else 1.0) * s["fs"]
        what = f"{n:.4g} samples"
    if n > MAX_SAMPLES:
        form.errors[RUN + "revolutions"] = (
            f"revolutions: {what}, more than the app draws ({MAX_SAMPLES:.0e}); fewer "
            "revolutions or a lower fs, or 'recipdyn simulate' (it streams long runs to a file)"
        )


def to_query(model: Any, texts: dict[str, Any]) -> str:
    """The address query of a form: the model and every field that differs from its default,
    the selectors first (``?model=compressor&crank_joint=contact&rc=0.5+mm``)."""
    m = get_model(model)
    items = [("model", m.name)]
    for f in fields(m, texts):
        text = texts.get(f.key)
        if text is not None and str(text).strip() != f.default_text:
            items.append((f.key, str(text).strip()))
    return "?" + urlencode(items)


def from_query(search: str | None) -> tuple[str, dict[str, str], str]:
    """``(model name, field texts, error)`` from an address query; parameter aliases are
    accepted and unknown names reported in ``error`` (the known ones are still read), a
    parameter of another configuration with the selector values that enable it. Only
    registered model names and the selectors' listed values are accepted, never a
    ``module:object`` path (opening a link must not import a file)."""
    pairs = parse_qsl((search or "").lstrip("?"), keep_blank_values=True)
    spec = dict(pairs).get("model") or DEFAULT_MODEL
    if spec not in model_names():  # never a module:object path: a link must not import code
        return DEFAULT_MODEL, {}, (f"address: unknown model {spec!r}; known: "
                                   f"{', '.join(model_names())}")  # fmt: skip
    m = get_model(spec)
    texts, problems = {}, []
    for p in m.selector_schema():
        v = dict(pairs).get(p.name)
        if v is None:
            continue
        if v in p.choices:
            texts[p.name] = v
        else:
            own = (" (a component of your own is given in a config file or on the command "
                   "line: a link does not import a file)") if is_spec(v) else ""  # fmt: skip
            problems.append(f"{p.name} = {v!r} is not offered here; allowed: "
                            f"{', '.join(p.choices)}{own}")  # fmt: skip
    keys = {f.key for f in fields(m, texts)}
    schema = _configuration(m, selected(m, texts))[0].schema if texts else m.schema
    unknown = []
    for k, v in pairs:
        if k == "model" or k in m.selector_schema():
            continue
        if k not in keys and not k.startswith(RUN):
            try:
                k = schema.resolve(k)
            except ParameterError:
                pass
        if k in keys:
            texts[k] = v
        elif (why := _elsewhere(m, texts, k, v)) is not None:
            problems.append(why)
        else:
            unknown.append(k)
    if unknown:
        problems.insert(0, f"unknown field(s) {', '.join(unknown)} for model {m.name!r}")
    return m.name, texts, "; ".join(f"address: {p}" for p in problems)


def _elsewhere(m: Any, texts: dict[str, str], key: str, text: str) -> str | None:
    """Why ``key``, a parameter of another configuration of ``m`` (`Model.parameter_table`),
    has no field here: the model's own message when it refuses the value at these selector
    values, else the selector values it belongs to; None for a name no configuration has."""
    rows = {p.name: (p, where) for p, where in m.parameter_table()}
    if key not in rows:
        return None
    p, where = rows[key]
    sel = selected(m, texts)
    where = _configuration(m, sel)[1].get(key) or where
    f = Field(p.name, p.name, p.unit, _display_unit(p), p.default, param=p, choices=p.choices)
    try:
        m.parameters({**sel, key: f.parse(text)})
    except (ParameterError, TypeError, ValueError) as exc:
        if re.search(rf"(?<![\w.]){re.escape(key)}(?![\w])", str(exc)):
            return str(exc)
    return (f"{key} is not a parameter of this configuration of {m.name!r}"
            + (f"; it belongs to {where}" if where not in ("", "selector") else ""))  # fmt: skip


def config_text(form: Form) -> str:
    """The run's full TOML config (``recipdyn simulate -c FILE`` runs it)."""
    from ..config import dump_config

    return dump_config(form.model, form.values(), {**SIMULATION, **form.settings})
