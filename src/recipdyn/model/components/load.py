r"""Load components: the force of the gas on the crosshead along +x, ``F(theta1)``.

* ``paper``: the piecewise load of the paper's Eq. (1)-(2), ``F = s P mu(theta1)``
  (`recipdyn.model.load`), slice ``load_amplitude, s``;
* ``table``: a periodic table of crank angle and force, linear between nodes (a measured
  indicator diagram through `recipdyn.model.load.read_pressure_table`, or the real-gas
  cycle tabulated once from CoolProp), slice ``n, angles (rad), forces (N)``;
* ``cycle``: the compression cycle with ideal valves and polytropic gas
  (`recipdyn.model.cycle`), slice `recipdyn.model.cycle.cycle_data`;
* ``valves``: the cylinder gas with dynamic plate valves (`recipdyn.model.valves`), a load
  with states: the chamber pressures, masses and plates (12) and four mass counters
  (auxiliary); slice `recipdyn.model.cycle.cycle_data`, then
  `recipdyn.model.valves.pack_valves`.

Each role is a compiled function, called (not inlined) by the kernels that use it, so it is
compiled once for every configuration (docs/architecture.md, Composing compiled components).
A load without states is one compiled function ``force(theta1, p, o)`` reading its slice at
offset ``o``; a load may add ``force_sc(sin theta1, cos theta1, p, o)``, the same force from
the sine and cosine of the crank angle, for a joint that has them (the contact joint's
kinematics). A load with states provides, with ``g`` (``a``) the index of its first state
(auxiliary state) in ``y``:

* ``state_force(y, g, p, o)``: the force on the crosshead from the states;
* ``state_rhs(x3, x3', y, g, a, p, o, out)``: the derivatives of its states, for the
  crosshead at ``x3`` moving at ``x3'``;
* ``event(y, g, p, o)`` and ``reset(y, g, p, o, out)``: its event factor (positive between
  events, falling through 0 at one) and the state after the event.

A load with states that can run between an interstage volume's lines (a machine's
``[[interstage]]``; the dynamic valves) adds ``state_rhs_lines(x3, x3', y, g, a, p, o, ps, ts,
pd, td, out)`` (`state_rhs` with the suction line at ``(ps, ts)`` and the discharge line at
``pd``, ``td`` for gas that flows back), ``lines(p, o) -> (ps, ts, pd, td)`` (its set lines)
and ``flows(dy, a) -> (m_in, m_out)`` (the mass flows it takes in and delivers, from its
auxiliary states' derivatives).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numba as nb
import numpy as np

from .. import valves as va
from ..base import Signal
from ..cycle import (
    C_PD,
    C_PS,
    N_CYCLE,
    cycle_data,
    cycle_force_kernel,
    cycle_states,
    indicated_work,
    mean_speed,
    pin_reversal_summary,
    volumetric_efficiency,
)
from ..load import mu_kernel, mu_sincos, pack_table
from .contract import Component, resolve_component

__all__ = [
    "PAPER",
    "TABLE",
    "CYCLE",
    "VALVES",
    "LOADS",
    "load_component",
    "force_series",
    "gas_force",
    "cycle_gas_states",
    "cycle_outputs",
    "cycle_summary",
]

_TWO_PI = 2.0 * math.pi


@nb.njit(cache=True)
def paper_force(th1, p, o):
    """The paper's load (slice ``amplitude, sign``)."""
    return p[o + 1] * p[o] * mu_kernel(th1)


@nb.njit(cache=True)
def paper_force_sc(s1, c1, p, o):
    """The paper's load from ``sin theta1`` and ``cos theta1`` (`recipdyn.model.load.mu_sincos`:
    equal to `paper_force` to rounding, without reducing the angle)."""
    return p[o + 1] * p[o] * mu_sincos(s1, c1)


@nb.njit(cache=True)
def table_force(th1, p, o):
    """Periodic linear interpolation of ``(angle, force)`` nodes (slice ``n, angles,
    forces``)."""
    n = int(p[o])
    ang = p[o + 1 : o + 1 + n]
    val = p[o + 1 + n : o + 1 + 2 * n]
    phi = th1 % _TWO_PI
    j = np.searchsorted(ang, phi)  # ang[j-1] < phi <= ang[j]
    if j == 0 or j == n:  # wrap-around segment between the last and the first node
        a0, f0 = ang[n - 1], val[n - 1]
        a1, f1 = ang[0] + _TWO_PI, val[0]
        if phi < a0:
            phi += _TWO_PI
    else:
        a0, f0, a1, f1 = ang[j - 1], val[j - 1], ang[j], val[j]
    return f0 + (f1 - f0) * (phi - a0) / (a1 - a0)


@nb.njit(cache=True)
def cycle_force(th1, p, o):
    """The ideal-valve compression cycle (slice `recipdyn.model.cycle.cycle_data`)."""
    return cycle_force_kernel(th1, p[o:])


@nb.njit(cache=True)
def valves_force(y, g, p, o):
    """The gas force of the chamber pressures ``y[g]``, ``y[g + 6]``."""
    return va.state_force(y, g, p[o:])


@nb.njit(cache=True)
def valves_rhs(x, xdot, y, g, a, p, o, out):
    """The chambers' and plates' derivatives (`recipdyn.model.valves.gas_rhs`)."""
    c = p[o:]
    va.gas_rhs(x, xdot, y, g, a, c, c[N_CYCLE:], out)


@nb.njit(cache=True)
def valves_rhs_lines(x, xdot, y, g, a, p, o, ps, ts, pd, td, out):
    """`valves_rhs` with the suction line at ``(ps, ts)`` and the discharge line at ``pd``
    (``td`` for gas flowing back from it): an interstage volume's state
    (`recipdyn.model.valves.gas_rhs_lines`)."""
    c = p[o:]
    va.gas_rhs_lines(x, xdot, y, g, a, c, c[N_CYCLE:], ps, ts, pd, td, out)


@nb.njit(cache=True)
def valves_lines(p, o):
    """The set line values ``(p_s, T_s, p_d, T_d)`` of the cylinder's slice (what
    `valves_rhs` runs between)."""
    v = o + N_CYCLE
    return p[o + C_PS], p[v + va.V_TS], p[o + C_PD], p[v + va.V_TD]


@nb.njit(cache=True)
def valves_flows(dy, a):
    """The mass flows (kg/s) the cylinder takes in through its suction valves and delivers
    through its discharge valves, from its mass counters' derivatives ``dy[a:a+4]``."""
    return dy[a] + dy[a + 2], dy[a + 1] + dy[a + 3]


@nb.njit(cache=True)
def valves_event(y, g, p, o):
    """The smallest plate factor (`recipdyn.model.valves.valve_event`)."""
    return va.valve_event(y, g, p[o + N_CYCLE :])


@nb.njit(cache=True)
def valves_reset(y, g, p, o, out):
    """A plate's impact (`recipdyn.model.valves.valve_reset`)."""
    va.valve_reset(y, g, p[o + N_CYCLE :], out)


def _valves_steps(values: Mapping[str, Any]) -> np.ndarray:
    """The Jacobian's central-difference steps of the valves' states, ``(rel, abs)`` per
    state (`recipdyn.model.components.contract.Component.steps`): a pressure by 1e-7 of
    itself plus the suction pressure, a gas mass by 1e-7 of twice itself, a plate's lift by
    1e-7 of itself plus its full lift, a plate's velocity by 1e-7 of itself plus 1 m/s."""
    lift = float(values["valve_lift"])
    chamber = [0.0, float(values["suction_pressure"]), 1.0, 1e-12, 0.0, lift, 0.0, 1.0, 0.0,
               lift, 0.0, 1.0]  # fmt: skip
    return np.array(chamber * 2, dtype=np.float64)


def _valves(values: Mapping[str, Any]) -> np.ndarray:
    c = cycle_data(values)
    return np.concatenate([c, va.pack_valves(values, c)])


def _paper(values: Mapping[str, Any]) -> np.ndarray:
    sign = -1.0 if values.get("load_sign", "physical") == "physical" else 1.0
    return np.array([values["load_amplitude"], sign], dtype=np.float64)


def _table(values: Mapping[str, Any]) -> np.ndarray:
    table = values.get("load_table")
    if table is None:  # the real gas: its cycle tabulated once from CoolProp
        from ..realgas import real_gas_force_table

        table = real_gas_force_table(values)
    return pack_table(table)


PAPER = Component("load", "paper", "the paper's piecewise load, Eq. (1)-(2)", module=__name__,
                  kernels={"force": "paper_force", "force_sc": "paper_force_sc"},
                  pack=_paper)  # fmt: skip
TABLE = Component("load", "table", "a periodic force table (measured p-theta, or a real gas)",
                  module=__name__, kernels={"force": "table_force"}, pack=_table)  # fmt: skip
CYCLE = Component("load", "cycle", "the compression cycle, ideal valves, polytropic gas",
                  module=__name__, kernels={"force": "cycle_force"}, pack=cycle_data)  # fmt: skip

VALVES = Component(
    "load", "valves", "the cylinder gas with dynamic plate valves (pressures, plates as states)",
    module=__name__, pack=_valves, params=va.SCHEMA_PARAMS, steps=_valves_steps,
    kernels={"state_force": "valves_force", "state_rhs": "valves_rhs",
             "event": "valves_event", "reset": "valves_reset",
             # a load that can run between an interstage volume's lines (optional roles)
             "state_rhs_lines": "valves_rhs_lines", "lines": "valves_lines",
             "flows": "valves_flows"},
    states=tuple(zip(va.GAS_STATE_NAMES, va.GAS_STATE_UNITS, strict=True)),
    aux_states=tuple(zip(va.AUX_STATE_NAMES, va.AUX_STATE_UNITS, strict=True)),
)  # fmt: skip

LOADS = {c.name: c for c in (PAPER, TABLE, CYCLE)}


def load_component(values: Mapping[str, Any]) -> Component:
    """The load component the values choose: a table when one is given (or for a real gas's
    cycle, tabulated from CoolProp), else the ``load`` parameter's."""
    if values.get("load_table") is not None:
        return TABLE
    if values.get("load", "paper") == "cycle" and values.get("gas", "ideal") != "ideal":
        return TABLE
    return resolve_component("load", values.get("load", "paper"), LOADS)  # a user's too


def force_series(values: Mapping[str, Any], theta1) -> np.ndarray:
    """The force on the crosshead along +x (N) of the load the values choose
    (`load_component`) at crank angle(s) ``theta1``: its compiled ``force`` on its own slice
    (offset 0), the arithmetic of a run."""
    import importlib

    part = load_component(values)
    vec = np.asarray(part.pack(values), dtype=np.float64)
    fn = getattr(importlib.import_module(part.module), part.kernel("force"))
    th = np.atleast_1d(np.asarray(theta1, dtype=np.float64))
    return np.array([fn(x, vec, 0) for x in th]).reshape(np.shape(theta1))


def gas_force(theta1, params) -> np.ndarray:
    """Force on the crosshead along +x (N) at crank angle(s) theta1 for ``params`` (a
    `recipdyn.model.parameters.CompressorParams`; `force_series`)."""
    return force_series(vars(params), theta1)


def cycle_gas_states(theta1: np.ndarray, values: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """Chamber pressures and volumes of the cycle load at crank angles ``theta1``: the
    polytropic cycle, or the real gas's isentropes (CoolProp) for ``gas`` other than ideal."""
    if values.get("gas", "ideal") != "ideal":
        from ..realgas import real_gas_states

        return real_gas_states(theta1, values)
    return cycle_states(theta1, cycle_data(values))


def cycle_outputs(values: Mapping[str, Any], theta1: np.ndarray) -> dict[str, Signal]:
    """Cylinder pressures and volumes of the compression-cycle load (none for other loads),
    for any joint model whose parameters include the cycle's."""
    if values.get("load") != "cycle" or values.get("load_table") is not None:
        return {}
    st = cycle_gas_states(theta1, values)
    return {
        "p_head": Signal(st["p_head"], "Pa", "head-end cylinder pressure (absolute)"),
        "p_crank": Signal(st["p_crank"], "Pa", "crank-end cylinder pressure (absolute)"),
        "V_head": Signal(st["V_head"], "m**3", "head-end cylinder volume"),
        "V_crank": Signal(st["V_crank"], "m**3", "crank-end cylinder volume"),
    }


def cycle_summary(values, ds) -> dict[str, float | str]:
    """Figures of a run with ``load = "cycle"`` (empty otherwise): the API 618 crosshead-pin
    reversal over the last recorded revolution, of the combined load ``m3 a - F_gas`` and of
    the gas load alone, and the ideal cycle's indicated power and volumetric efficiencies."""
    if values.get("load") != "cycle" or not {"theta1", "a", "gas_force"} <= set(ds.variables):
        return {}
    out: dict[str, float | str] = pin_reversal_summary(values, ds)
    grid = np.linspace(0.0, 2.0 * math.pi, 20_000, endpoint=False)
    st = cycle_gas_states(grid, values)
    acting = values.get("acting", "double")
    work = 0.0
    for end, on in (("head", acting in ("head", "double")), ("crank", acting != "head")):
        if on:
            work += indicated_work(st[f"p_{end}"], st[f"V_{end}"])
            out[f"volumetric_efficiency_{end}"] = volumetric_efficiency(
                st[f"p_{end}"], st[f"V_{end}"], float(values["suction_pressure"]), rtol=1e-9
            )
    out["indicated_power_W"] = work * mean_speed(values, ds) / (2.0 * math.pi)
    return out
