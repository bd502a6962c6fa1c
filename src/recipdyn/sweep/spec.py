"""Sweep specifications: which parameters, which values, what to compute per point.

``--param omega=10:150:281`` (start:stop:count, linear), ``--param clearance=0.1mm:5mm:50:log``
(logarithmic), ``--param d=0,0.1mm,1mm`` (explicit list). One ``--param`` gives a 1-D sweep, two
give the outer-product grid (fault map). Values carry units (pint) and are converted to SI;
every grid point is validated by the model's schema and checks
([`Model.parameters`][recipdyn.model.protocol.Model.parameters]) before anything runs, so a
value outside a parameter's range is reported up front.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..defaults import SWEEP
from ..errors import ParameterError, is_number
from ..model.protocol import Derived, Model, rule_inputs
from ..model.registry import DEFAULT_MODEL, get_model
from ..units import to_si

__all__ = ["Axis", "SweepSpec", "parse_axis", "split_axis", "MEASURES"]

#: Per-point work that can be requested.
MEASURES = ("poincare", "peak", "spectrum", "lyapunov", "verdict", "features")
#: Most points one sweep store holds (one chunk file per point and variable).
MAX_POINTS = 10_000_000


def _finite(v) -> bool:
    import math

    return is_number(v) and math.isfinite(v)


@dataclass(frozen=True)
class Axis:
    """One swept parameter (SI values)."""

    name: str
    values: tuple[float, ...]
    scale: str = "linear"


def split_axis(text: str) -> tuple[str, str, list[str] | None, int | None]:
    """The syntax of an axis, ``NAME=start:stop:count[:log]`` or ``NAME=v1,v2,...``, checked
    without the model (the command line refuses a malformed one before anything loads):
    ``(name as written, right-hand side, range parts or None, count or None)``."""
    if "=" not in text:
        raise ParameterError(f"--param {text!r}: expected NAME=start:stop:count or NAME=v1,v2")
    raw_name, rhs = (s.strip() for s in text.split("=", 1))
    if ":" not in rhs:
        if not [s for s in rhs.split(",") if s.strip()]:
            raise ParameterError(f"--param {raw_name}: no values given")
        return raw_name, rhs, None, None
    parts = rhs.split(":")
    if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] not in ("log", "lin")):
        raise ParameterError(
            f"--param {raw_name}: range must be start:stop:count or start:stop:count:log"
        )
    try:
        count = int(parts[2])
    except ValueError:
        raise ParameterError(f"--param {raw_name}: count {parts[2]!r} is not an integer") from None
    if not 1 <= count <= MAX_POINTS:
        raise ParameterError(f"--param {raw_name}: count = {count}; allowed: 1..{MAX_POINTS}")
    return raw_name, rhs, parts, count


def parse_axis(text: str, model: str | Model | None = None,
               base: Mapping[str, Any] | None = None) -> Axis:  # fmt: skip
    """Parse ``NAME=start:stop:count[:log]`` or ``NAME=v1,v2,...`` (values may have units,
    converted to the unit of the parameter in ``model``'s schema at the ``base`` values --
    a component from a user's file brings its parameters; default the compressor)."""
    raw_name, rhs, parts, count = split_axis(text)
    m = get_model(model)
    schema = m.schema_for(base or {})
    name = schema.resolve(raw_name)
    if name not in schema or schema[name].choices is not None:
        raise ParameterError(f"--param {raw_name}: only numeric parameters can be swept")
    unit = schema[name].unit
    if parts is not None:
        lo, hi = to_si(name, parts[0], unit=unit), to_si(name, parts[1], unit=unit)
        scale = "log" if len(parts) == 4 and parts[3] == "log" else "linear"
        if scale == "log":
            if lo <= 0 or hi <= 0:
                raise ParameterError(
                    f"--param {raw_name}: a log range needs start and stop > 0, got {lo:g}, {hi:g}"
                )
            vals = np.geomspace(lo, hi, count)
        else:
            vals = np.linspace(lo, hi, count)
        return Axis(name, tuple(float(v) for v in vals), scale)
    items = [s for s in rhs.split(",") if s.strip()]
    if not items:
        raise ParameterError(f"--param {raw_name}: no values given")
    return Axis(name, tuple(to_si(name, s, unit=unit) for s in items), "list")


@dataclass(frozen=True)
class SweepSpec:
    """Everything that defines a sweep's results (hashed to guard ``--resume``).

    ``settings``: ``revolutions`` (recorded after the transient, for peak/spectrum),
    ``transient`` (revolutions discarded), ``points`` (stroboscopic points for the
    bifurcation diagram), ``lyap_revolutions``, ``fs`` (Hz), ``rtol``, ``atol``.
    """

    axes: tuple[Axis, ...]
    measures: tuple[str, ...]
    #: The base case: the model's values (a mapping, or its parameter dataclass such as
    #: CompressorParams; stored as the validated mapping), default the model's defaults.
    base: Any = None
    settings: dict[str, Any] = field(default_factory=dict)
    continuation: bool = False
    #: A registered model name or module:object path (see recipdyn.model.registry).
    model: str = DEFAULT_MODEL

    def __post_init__(self):
        unknown = set(self.settings) - set(SWEEP) - {"lyap_tol"}
        if unknown:
            raise ParameterError(f"unknown sweep setting(s) {sorted(unknown)}; known: "
                                 f"{', '.join(sorted(SWEEP))}, lyap_tol")  # fmt: skip
        # every setting not given takes its default (defaults.SWEEP), so the spec is complete
        given = {k: v for k, v in self.settings.items() if v is not None}  # None = default
        object.__setattr__(self, "settings", {**SWEEP, **given})
        m = self.get_model()
        object.__setattr__(self, "base", m.parameters(self.base))
        if not 1 <= len(self.axes) <= 2:
            raise ParameterError(f"a sweep needs 1 or 2 --param axes, got {len(self.axes)}")
        if len({a.name for a in self.axes}) != len(self.axes):
            raise ParameterError("the same parameter is swept twice")
        bad = [m for m in self.measures if m not in MEASURES]
        if bad or not self.measures:
            raise ParameterError(f"--measure {bad or '(none)'}; allowed: {', '.join(MEASURES)}")
        if self.continuation and len(self.axes) != 1:
            raise ParameterError("--continuation needs a 1-D sweep")
        s = self.settings
        for key in ("revolutions", "points", "lyap_revolutions", "fs"):
            if not (_finite(s[key]) and s[key] > 0):
                raise ParameterError(f"{key} = {s[key]!r}; allowed: > 0 (finite)")
        tr = s["transient"]
        if not (_finite(tr) and tr >= 0):
            raise ParameterError(f"transient = {tr!r}; allowed: >= 0 (finite)")
        if self.continuation and tr != int(tr):
            raise ParameterError(
                f"transient = {tr!r}: --continuation needs a whole number of "
                "revolutions (each point hands on its state at crank angle 0)"
            )
        if s["points"] != int(s["points"]):
            raise ParameterError(f"points = {s['points']!r}; allowed: an integer >= 1")
        from ..integrate.solve import check_tolerances

        check_tolerances(s["rtol"], s["atol"])
        if {"lyapunov", "verdict"} & set(self.measures) and not m.lyapunov_supported(self.base):
            # the reason of the configuration the base values choose (the compressor's)
            raise ParameterError(
                f"--measure lyapunov/verdict: not available for model {m.name!r}: "
                f"{m.configured(self.base).lyapunov_refusal}"
            )
        n = self.n_points
        if n > MAX_POINTS:
            raise ParameterError(
                f"a sweep of {n:.3g} points is more than one store holds "
                f"(limit {MAX_POINTS:.0e}); split it into several sweeps"
            )
        for point in self.grid():  # validate every point up front
            self.point_params(point)

    @property
    def n_points(self) -> int:
        return int(np.prod([len(a.values) for a in self.axes], dtype=float))

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(a.values) for a in self.axes)

    def grid(self):
        """Iterate over ``(index_tuple, {name: value})``."""
        for idx in itertools.product(*(range(n) for n in self.shape)):
            yield idx, {a.name: a.values[i] for a, i in zip(self.axes, idx, strict=True)}

    def get_model(self) -> Model:
        return get_model(self.model)

    def point_params(self, point) -> Any:
        """The point's validated parameter values."""
        values = point[1] if isinstance(point, tuple) else point
        try:
            return self.get_model().parameters({**self.base, **values})
        except ParameterError as exc:
            raise ParameterError(f"sweep point {values}: {exc}") from None

    def base_attrs(self) -> dict[str, Any]:
        """The base case's parameters as result attributes."""
        attrs = self.get_model().record_attrs(self.base)
        return {k[len("param_") :]: v for k, v in attrs.items() if k.startswith("param_")}

    def to_json(self) -> str:
        return json.dumps(
            dict(axes=[dataclasses.asdict(a) for a in self.axes], measures=list(self.measures),
                 base=self.get_model().identity_values(self.base), settings=self.settings,
                 continuation=self.continuation,
                 # (the default model is not named: the digests of stores made before
                 # sweeps took other models stay the same)
                 **({} if self.model == DEFAULT_MODEL else {"model": self.model}),
                 **self._followers()),
            sort_keys=True, default=str,
        )  # fmt: skip

    def _followers(self) -> dict[str, list[str]]:
        """The base's derived values that follow a swept parameter (``ls = l / 2`` in a
        sweep of ``l``), by their rules: part of the spec (a store made when they did not
        follow differs; other specs keep their digests)."""
        swept = {a.name for a in self.axes}
        rules = sorted(f"{p.name} = {p.derive}" for p in self.get_model().schema_for(self.base)
                       if p.derive and isinstance(self.base.get(p.name), Derived)
                       and swept & set(rule_inputs(p.derive)))  # fmt: skip
        return {"derived": rules} if rules else {}

    @property
    def digest(self) -> str:
        return hashlib.sha256(self.to_json().encode()).hexdigest()[:16]
