r"""Dynamic valves: the cylinder pressure as a state, plate valves with mass, spring and stops.

The compression cycle of `cycle` with its ideal valves replaced by the lumped
control-volume model of Soedel (*Design and Mechanics of Compressor Valves*, Purdue 1984, ch. 2
and 5; the same formulation as Habing, *Flow and plate motion in compressor valves*, PhD thesis,
University of Twente 2005, ch. 2). For each working chamber (head end, crank end):

**Gas** (ideal gas, gas constant ``R``, uniform state in the chamber, adiabatic walls): the mass
``m`` and pressure ``p`` are states; the temperature is ``T = p V / (m R)``. Mass and energy
balances of the control volume give::

    dm/dt = mdot_s + mdot_d
    dp/dt = n / V (R T_s* mdot_s + R T_d* mdot_d - p dV/dt)

``mdot`` > 0 into the chamber, ``T*`` the temperature of the gas that enters (the line's, or the
chamber's own ``T`` for gas that leaves). With ``n = k`` this is the exact first law; like the
ideal cycle, the exponent is ``n_compression`` while the chamber shrinks and ``n_expansion``
while it grows, so that with closed valves ``p V^n`` is constant and the closed forms of
`cycle` are the limit of stiff, light valves (the tests check this). The suction line is
at ``(p_s, T_s)``; the discharge line at ``p_d`` and (for back-flow) at the isentropic discharge
temperature ``T_d = T_s (p_d/p_s)^((n_c-1)/n_c)``.

**Real gas** (``gas`` a CoolProp fluid): the first law of the open, adiabatic chamber with
real-gas properties, ``dp/dt = (dp/drho)_u (mdot - rho dV/dt)/V + (dp/du)_rho (sum mdot_i
(h_i - u) - p dV/dt)/m`` (``h_i``: the suction gas's, the discharge line's on the suction
isentrope, or the chamber's own ``u + p/rho`` for gas that leaves), the properties
interpolated in `recipdyn.model.realgas.chamber_table` (the equation above with ``n = k``
for an ideal gas). The nozzle then takes ``Z R T = p/rho`` of the upstream gas and the suction
gas's isentropic exponent.

**Flow** through a valve of lift ``y`` (max ``y_max``, the guard): an isentropic nozzle of
effective area ``C_d A_v min(max(y, 0) / y_max, 1)`` (``A_v`` the flow area at full lift),
exponent ``k`` (``isentropic_exponent``), choked below the critical pressure ratio::

    mdot = C_d A p_u sqrt(2 k / ((k-1) R T_u) (pi^(2/k) - pi^((k+1)/k))),  pi = p_dn / p_u.

Its slope in ``p_dn`` is infinite at ``pi -> 1``; below ``1 - pi = 1e-3`` the function is
continued linearly to 0 (a laminar-like regularisation: at the default sizes it acts below a
pressure difference of 0.1 % of the line pressure, where the flow is < 4 % of its value at the
typical valve pressure drop), so that the equations stay Lipschitz.

**Plates** (one lumped plate per valve group): ``m_v y'' = A_F dp - F_0 - k_v y - c_v y'``
with ``dp`` the pressure difference that opens the valve (``p_s - p`` for suction, ``p - p_d``
for discharge), ``A_F`` the effective force area (``valve_force_factor A_v``), ``F_0`` the
spring preload, ``c_v = 2 zeta sqrt(k_v m_v)``. The seat (``y = 0``) and the guard
(``y = y_max``) are rigid stops: an impact reverses the plate's velocity with the restitution
``e`` (an event with a state reset), and a plate whose rebound is below ``V_REST`` = 1 cm/s
rests there, as does a plate slower than ``V_REST`` that is pressed onto a stop (its
derivatives are 0), until the net force pulls it away. This is the classical impact treatment
of valve plates (Soedel 1984, ch. 5); it needs no stiff stop springs, so an explicit
integrator steps through the cycle at the gas's own time scales.

A plate faster than ``V_REST`` is never stopped by the right-hand side: within a step it moves
on through the stop (the right-hand side is smooth there) until the impact event, located on
the step's dense output, puts it back on the stop. The event factor of a plate
(`_distance`) is continuous in the state and negative exactly where a fast plate is
beyond its stop, so rest (right-hand side) and impact (event) share one bound. When the
right-hand side instead stopped every plate pressed onto its stop, a step across the stop met
the error test only at steps below the resolution of ``t`` at tight tolerances: the runs
stopped with a step-size underflow at rtol 1e-12 (70 rad/s) and 1e-13 (20 rad/s), 5 of 6
cases tried (tests/test_valves.py).

**Force on the mechanism**: ``F = -p_he A + p_ce (A - A_rod) + p_frame A_rod`` as in
`cycle`, with the pressures of the states. The chamber volumes follow the crosshead
position of the mechanism's own state (not the ideal crank angle), so gas and mechanism are
coupled both ways.

**Faults** (docs/faults.md; `FAULT_PARAMS`, each per valve of `VALVES`; the defaults are
the healthy valves and leave every result unchanged to the bit): a leak area in parallel with
the plate (the effective area ``C_d (A_v min(max(y,0)/y_max, 1) + A_leak)``, same nozzle
equation, both directions); a spring factor scaling ``k_v`` and ``F_0`` (0: broken; the
damping keeps its healthy value); an adhesion force ``F_a`` holding a plate resting on its seat
until ``A_F dp - F_0 > F_a`` (oil stiction); a piston-ring leak area between the two chambers
(to the frame, at ``p_frame`` and ``T_s``, for a single-acting cylinder), through the same
nozzle from the chamber at the higher pressure, its gas's enthalpy carried along.

**Lines**: the suction line at ``(p_s, T_s)`` and the discharge line at ``p_d`` are the set
values of the cylinder's stage, or, in a machine with an interstage volume between two stages
(`recipdyn.model.components.interstage`), that volume's pressure, a state, at its cooler's
temperature (`gas_rhs_lines`).

Limits, stated: uniform chamber state (no pulsation in the cylinder or the lines: a line's
pressure is constant or an interstage volume's, uniform), no heat transfer other than through
the polytropic exponent, one lumped plate per valve group.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numba as nb
import numpy as np

from . import cycle as cy
from . import realgas as rg
from .gases import GASES
from .protocol import Param

__all__ = [
    "N_GAS", "N_AUX", "GAS_STATE_NAMES", "GAS_STATE_UNITS", "AUX_STATE_NAMES",
    "AUX_STATE_UNITS", "pack_valves", "gas_rhs", "gas_rhs_lines", "valve_event", "valve_reset",
    "gas_initial", "flow_function", "V_REST", "EPS_LIN", "SCHEMA_PARAMS", "valve_summary",
    "state_force", "real_properties",
    "gas_outputs", "gas_scale", "FAULT_PARAMS", "VALVES",
]  # fmt: skip

#: Rebound velocity (m/s) below which a plate comes to rest on its stop (no Zeno sequence of
#: ever shorter bounces: a 1 cm/s bounce rises < 1 um against the default preload).
V_REST = 1e-2
#: ``1 - p_dn/p_u`` below which the nozzle flow is continued linearly to zero.
EPS_LIN = 1e-3

_ASSUMED = "assumed: a lumped plate valve of typical proportions (the paper gives no valves)"
#: The valves' parameters, shared by every model with dynamic valves.
SCHEMA_PARAMS = (
    Param(
        "valve_area_fraction",
        "",
        0.08,
        "flow area of each valve group at full lift / piston area (head end)",
        0.0,
        1.0,
        low_open=True,
        assumed=_ASSUMED,
        group="valves",
    ),
    Param(
        "valve_lift",
        "m",
        2.5e-3,
        "plate lift at the guard (full lift)",
        0.0,
        0.1,
        low_open=True,
        assumed=_ASSUMED,
        group="valves",
    ),
    Param(
        "valve_mass",
        "kg",
        0.05,
        "moving mass of each valve group's plates (lumped)",
        0.0,
        100.0,
        low_open=True,
        assumed=_ASSUMED,
        group="valves",
    ),
    Param(
        "valve_stiffness",
        "N/m",
        8000.0,
        "spring stiffness of each valve group",
        0.0,
        1e9,
        low_open=True,
        assumed=_ASSUMED,
        group="valves",
    ),
    Param(
        "valve_preload",
        "N",
        5.0,
        "spring preload holding the plates on the seat",
        0.0,
        1e6,
        assumed=_ASSUMED,
        group="valves",
    ),
    Param(
        "valve_damping",
        "",
        0.1,
        "damping ratio of the plate on its spring (gas and sticking)",
        0.0,
        10.0,
        assumed=_ASSUMED,
        group="valves",
    ),
    Param(
        "valve_force_factor",
        "",
        2.0,
        "effective force area of the plate / its flow area",
        0.0,
        100.0,
        low_open=True,
        assumed=_ASSUMED,
        group="valves",
    ),
    Param(
        "discharge_coefficient",
        "",
        0.7,
        "discharge coefficient of the valve flow",
        0.0,
        1.0,
        low_open=True,
        assumed=_ASSUMED,
        group="valves",
    ),
    Param(
        "valve_restitution",
        "",
        0.3,
        "coefficient of restitution of the plate at the seat and the guard",
        0.0,
        1.0,
        high_open=True,
        assumed=_ASSUMED,
        group="valves",
    ),
    Param(
        "gas",
        "",
        "ideal",
        "gas in the cylinder: 'ideal' (gas_constant, isentropic_exponent and the polytropes "
        "n_compression, n_expansion) or a CoolProp fluid (the first law of the adiabatic "
        "chamber with real-gas properties from a table; those four are then not used)",
        choices=GASES,
        group="valves",
    ),
    Param(
        "gas_constant",
        "J/(kg*K)",
        287.05,
        "specific gas constant R (air: 287.05)",
        0.0,
        1e5,
        low_open=True,
        group="valves",
    ),
    Param(
        "isentropic_exponent",
        "",
        1.4,
        "isentropic exponent of the flow through the valves (air: 1.4)",
        1.0,
        2.0,
        low_open=True,
        group="valves",
    ),
)

#: The four valves, in the order of the fault data (index ``2 j + kind``: chamber ``j``, 0 head
#: end, 1 crank end; kind 0 suction, 1 discharge).
VALVES = tuple((kind, end) for end in ("head", "crank") for kind in ("suction", "discharge"))
#: Faults of the valves and the piston rings (docs/faults.md), each a parameter of the valve
#: load; the defaults are the healthy machine.
FAULT_PARAMS = (
    *(Param(f"leak_area_{kind}_{end}", "m**2", 0.0,
            f"{end}-end {kind} valve leak: flow area in parallel with the plate (same nozzle "
            "equation and discharge coefficient), e.g. a broken plate or a worn seat",
            0.0, 0.1, group="faults") for kind, end in VALVES),
    *(Param(f"spring_factor_{kind}_{end}", "", 1.0,
            f"{end}-end {kind} valve spring: stiffness and preload times this factor (1 "
            "healthy, 0 broken)", 0.0, 1.0, group="faults") for kind, end in VALVES),
    *(Param(f"adhesion_force_{kind}_{end}", "N", 0.0,
            f"{end}-end {kind} valve sticking: oil-film adhesion holding the plate on its "
            "seat until the net opening force exceeds it", 0.0, 1e6, group="faults")
      for kind, end in VALVES),
    Param("ring_leak_area", "m**2", 0.0,
          "piston-ring leak: flow area between the head-end and crank-end chambers (to the "
          "frame for a single-acting cylinder), same nozzle equation and discharge coefficient",
          0.0, 0.1, group="faults"),
)  # fmt: skip
SCHEMA_PARAMS = (*SCHEMA_PARAMS, *FAULT_PARAMS)

# Layout of the valve data (after the cycle data); the fault data hold four values each, one
# per valve in the order of `VALVES`.
(V_AREA, V_LIFT, V_MASS, V_K, V_F0, V_C, V_AF, V_CD, V_E, V_R, V_KAPPA, V_TS, V_TD,
 V_NCH, V_CRIT, V_E1, V_E2, V_COEF) = range(18)  # fmt: skip
V_LEAK, V_SPRING, V_STICK, V_RING, V_PFRAME = 18, 22, 26, 30, 31
#: 1.0 when a real gas's property table follows the valve data (``v[N_VALVE:]``), else 0.0:
#: the data says so itself, because a kernel's slice of the parameters runs on into the next
#: component's (a machine's second throw): its length tells nothing
V_REAL = 32
N_VALVE = 33

#: Gas states of one chamber: pressure, mass, suction-plate lift and velocity, discharge-plate
#: lift and velocity.
CHAMBER_STATES = ("p", "m", "y_suction", "u_suction", "y_discharge", "u_discharge")
CHAMBER_UNITS = ("Pa", "kg", "m", "m/s", "m", "m/s")
GAS_STATE_NAMES = tuple(f"{s}_{end}" for end in ("head", "crank") for s in CHAMBER_STATES)
GAS_STATE_UNITS = CHAMBER_UNITS * 2
N_GAS = len(GAS_STATE_NAMES)
#: Auxiliary states: the mass that has passed each valve into the chamber (suction) or out of
#: it (discharge) since t0, for the mass balance and the delivered mass.
AUX_STATE_NAMES = ("mass_in_head", "mass_out_head", "mass_in_crank", "mass_out_crank")
AUX_STATE_UNITS = ("kg",) * 4
N_AUX = len(AUX_STATE_NAMES)


def _gas_table(values) -> np.ndarray | None:
    """The chamber property table of a real gas (`recipdyn.model.realgas.chamber_table`,
    cached per parameter set), or None for the ideal gas."""
    gas = values.get("gas", "ideal")
    if gas == "ideal":
        return None
    return rg.chamber_table(gas, float(values["suction_pressure"]),
                            float(values["discharge_pressure"]),
                            float(values["suction_temperature"]))  # fmt: skip


def pack_valves(values, cycle_data: np.ndarray) -> np.ndarray:
    """Valve data for [`gas_rhs`][recipdyn.model.valves.gas_rhs] (layout: the ``V_*`` constants)."""
    area = float(values["valve_area_fraction"]) * cycle_data[cy.C_AHE]
    k, m = float(values["valve_stiffness"]), float(values["valve_mass"])
    nc = float(values["n_compression"])
    ratio = float(values["discharge_pressure"]) / float(values["suction_pressure"])
    t_s = float(values["suction_temperature"])
    out = np.empty(N_VALVE)
    out[V_AREA] = area
    out[V_LIFT] = values["valve_lift"]
    out[V_MASS] = m
    out[V_K] = k
    out[V_F0] = values["valve_preload"]
    out[V_C] = 2.0 * float(values["valve_damping"]) * math.sqrt(k * m)
    out[V_AF] = float(values["valve_force_factor"]) * area
    out[V_CD] = values["discharge_coefficient"]
    out[V_E] = values["valve_restitution"]
    out[V_R] = values["gas_constant"]
    out[V_KAPPA] = values["isentropic_exponent"]
    out[V_TS] = t_s
    out[V_TD] = t_s * ratio ** ((nc - 1.0) / nc)
    out[V_NCH] = cycle_data[cy.C_ACTING]
    cd = float(values["discharge_coefficient"])
    for q, (kind, end) in enumerate(VALVES):
        out[V_LEAK + q] = cd * float(values.get(f"leak_area_{kind}_{end}", 0.0))
        out[V_SPRING + q] = values.get(f"spring_factor_{kind}_{end}", 1.0)
        out[V_STICK + q] = values.get(f"adhesion_force_{kind}_{end}", 0.0)
    out[V_RING] = cd * float(values.get("ring_leak_area", 0.0))
    out[V_PFRAME] = cycle_data[cy.C_PFRAME]
    tab = _gas_table(values)
    out[V_REAL] = 0.0 if tab is None else 1.0
    if tab is None:
        out[V_CRIT:V_LEAK] = _nozzle_constants(float(values["isentropic_exponent"]))
        return out
    # a real gas: the chamber property table follows, and the nozzle takes the isentropic
    # exponent of the suction gas
    out[V_CRIT:V_LEAK] = _nozzle_constants(float(tab[rg.T_KAPPA]))
    return np.concatenate([out, tab])


def _nozzle_constants(kappa: float) -> tuple[float, float, float, float]:
    """Critical pressure ratio, the exponents ``2/k`` and ``(k+1)/k``, and ``2k/(k-1)``."""
    return ((2.0 / (kappa + 1.0)) ** (kappa / (kappa - 1.0)), 2.0 / kappa,
            (kappa + 1.0) / kappa, 2.0 * kappa / (kappa - 1.0))  # fmt: skip


@nb.njit(cache=True, inline="always")
def _psi(ratio, crit, e1, e2, coef):
    lin = ratio > 1.0 - EPS_LIN
    r = 1.0 - EPS_LIN if lin else max(ratio, crit)
    psi = math.sqrt(coef * (r**e1 - r**e2))
    if lin:
        psi *= (1.0 - ratio) / EPS_LIN
    return psi


def flow_function(ratio: float, kappa: float) -> float:
    """``sqrt(2 k/(k-1) (pi^(2/k) - pi^((k+1)/k)))`` for ``pi = p_dn/p_u`` in ``[0, 1]``,
    choked below the critical ratio and linear in ``1 - pi`` below `EPS_LIN` (the
    kernel's function, callable from Python)."""
    return float(_psi(float(ratio), *_nozzle_constants(float(kappa))))


@nb.njit(cache=True, inline="always")
def _mdot(p_line, rt_line, p, rt, area, v):
    """Mass flow into the chamber from a line through an effective area (< 0: out of it);
    ``rt``: ``p / rho`` of the gas upstream (``R T`` for an ideal gas, ``Z R T`` for a real
    one)."""
    if area == 0.0 or p_line == p:
        return 0.0
    if p_line > p:
        psi = _psi(p / p_line, v[V_CRIT], v[V_E1], v[V_E2], v[V_COEF])
        return area * p_line * psi / math.sqrt(rt_line)
    psi = _psi(p_line / p, v[V_CRIT], v[V_E1], v[V_E2], v[V_COEF])
    return -area * p * psi / math.sqrt(rt)


@nb.njit(cache=True, inline="always")
def _plate(y, dp, v, out, i, q):
    """Plate equation of valve ``q`` (`VALVES`) at ``y[i], y[i+1]`` opened by ``dp``; rests
    on its stops. Its spring is scaled by its factor, and an adhesion force holds it on the
    seat until the net opening force exceeds it (docs/faults.md)."""
    lift, u_ = y[i], y[i + 1]
    sf = v[V_SPRING + q]
    force = v[V_AF] * dp - sf * v[V_F0] - sf * v[V_K] * lift - v[V_C] * u_
    ymax = v[V_LIFT]
    # A plate pressed onto a stop rests there when it is slower than V_REST (a fast one
    # moves on through the stop until its impact event acts, so that a step that crosses the
    # stop sees a smooth right-hand side; _distance makes the event at the same bound)
    if (lift <= 0.0 and -V_REST < u_ <= 0.0 and force <= v[V_STICK + q]) or (
            lift >= ymax and 0.0 <= u_ < V_REST and force >= 0.0):  # fmt: skip
        out[i] = 0.0
        out[i + 1] = 0.0
    else:
        out[i] = u_
        out[i + 1] = force / v[V_MASS]


@nb.njit(cache=True, inline="always")
def _stop_factor(lift, u, ymax):
    """`_distance` of a plate at ``lift`` moving at ``u``: negative exactly where a plate
    faster than `V_REST` is beyond the stop it moves toward (its impact to act on)."""
    if u < 0.0:
        return max(lift / ymax, (u + V_REST) / V_REST)
    if u > 0.0:
        return max((ymax - lift) / ymax, (V_REST - u) / V_REST)
    return 1.0


@nb.njit(cache=True, inline="always")
def _area(lift, u, v):
    ymax = v[V_LIFT]
    x = lift  # a fast plate through its stop: continued smoothly until its impact event acts
    if _stop_factor(lift, u, ymax) >= 0.0:  # elsewhere the plate's opening, within its stops
        x = min(max(lift, 0.0), ymax)
    return v[V_CD] * v[V_AREA] * x / ymax


@nb.njit(cache=True)
def _bilinear(tab, k, i, j, wx, wp):
    n = int(tab[rg.T_NP])
    o = rg.T_HEADER + k * int(tab[rg.T_NX]) * n + i * n + j
    return ((1.0 - wx) * ((1.0 - wp) * tab[o] + wp * tab[o + 1])
            + wx * ((1.0 - wp) * tab[o + n] + wp * tab[o + n + 1]))  # fmt: skip


@nb.njit(cache=True)
def real_properties(p, rt, tab):
    """``(u - u0, (dp/drho)_u, (dp/du)_rho, T)`` of the real gas at pressure ``p`` and
    ``p/rho = rt``, bilinear on `recipdyn.model.realgas.chamber_table` (its scaled
    values, held constant beyond the table's edges)."""
    fx = (math.log(rt) - tab[rg.T_LX0]) / tab[rg.T_DLX]
    fp = (math.log(p) - tab[rg.T_LP0]) / tab[rg.T_DLP]
    fx = min(max(fx, 0.0), tab[rg.T_NX] - 1.0 - 1e-9)
    fp = min(max(fp, 0.0), tab[rg.T_NP] - 1.0 - 1e-9)
    i, j = int(fx), int(fp)
    wx, wp = fx - i, fp - j
    u = _bilinear(tab, 0, i, j, wx, wp) * rt
    a = _bilinear(tab, 1, i, j, wx, wp) * rt
    b = _bilinear(tab, 2, i, j, wx, wp) * p / rt
    return u, a, b, rt / _bilinear(tab, 3, i, j, wx, wp)


@nb.njit(cache=True, inline="always")
def _chamber(V, dV, y, b, q, c, v, mr, hr, ps, ts, pd, td, out):
    """Derivatives of one chamber's six states at ``y[b:b+6]`` (its suction valve ``q``, its
    discharge valve ``q + 1``); ``mr``: the ring leak into it, with the enthalpy (real gas) or
    ``R T`` (ideal gas) of its upstream gas ``hr``; the suction line at ``(ps, ts)``, the
    discharge line at ``(pd, td)`` (``td``: the temperature of gas that flows back from it).
    Returns (mdot_s, mdot_d)."""
    p, m = y[b], y[b + 1]
    # a leak is an area in parallel with the plate (0 when healthy: the sum is exact)
    a_s = _area(y[b + 2], y[b + 3], v) + v[V_LEAK + q]
    a_d = _area(y[b + 4], y[b + 5], v) + v[V_LEAK + q + 1]
    if v[V_REAL] != 0.0:  # a real gas: the first law with the tabulated properties
        tab = v[N_VALVE:]
        rt = p * V / m
        ms = _mdot(ps, tab[rg.T_RTS], p, rt, a_s, v)
        md = _mdot(pd, tab[rg.T_RTD], p, rt, a_d, v)
        u, dp_drho, dp_du, _t = real_properties(p, rt, tab)
        hs = tab[rg.T_HS] if ms > 0.0 else u + rt
        hd = tab[rg.T_HD] if md > 0.0 else u + rt
        q_in = ms * (hs - u) + md * (hd - u)
        if mr != 0.0:
            q_in += mr * ((hr if mr > 0.0 else u + rt) - u)
        out[b] = (dp_drho * (ms + md + mr - m / V * dV) / V
                  + dp_du / m * (q_in - p * dV))  # fmt: skip
    else:
        R = v[V_R]
        T = p * V / (m * R)
        ms = _mdot(ps, R * ts, p, R * T, a_s, v)
        md = _mdot(pd, R * td, p, R * T, a_d, v)
        n = c[cy.C_NC] if dV < 0.0 else c[cy.C_NE]
        t_s = ts if ms > 0.0 else T
        t_d = td if md > 0.0 else T
        h_in = t_s * ms + t_d * md
        if mr != 0.0:
            h_in += mr * (hr / R if mr > 0.0 else T)
        out[b] = n / V * (R * h_in - p * dV)
    out[b + 1] = ms + md + mr
    _plate(y, ps - p, v, out, b + 2, q)
    _plate(y, p - pd, v, out, b + 4, q + 1)
    return ms, md


@nb.njit(cache=True)
def _gas_rt(p, m, V, v):
    """``p / rho`` and the specific enthalpy (real gas) or ``R T`` (ideal gas) of a chamber's
    gas, for the ring leak that leaves it."""
    rt = p * V / m
    if v[V_REAL] != 0.0:
        return rt, real_properties(p, rt, v[N_VALVE:])[0] + rt
    return rt, rt


@nb.njit(cache=True)
def _ring(x, xdot, y, g, c, v):
    """Ring leak into the head-end chamber (kg/s, < 0: out of it) and into the crank-end
    chamber, each with the ``h`` or ``R T`` of its upstream gas: the nozzle equation between
    the two chambers of a double-acting cylinder, or between the working chamber and the frame
    (at the frame pressure and the suction temperature) for a single-acting one."""
    area = v[V_RING]
    acting = int(v[V_NCH])
    if v[V_REAL] != 0.0:
        tab = v[N_VALVE:]
        rt_f, h_f = tab[rg.T_RTS], tab[rg.T_HS]
    else:
        rt_f = h_f = v[V_R] * v[V_TS]
    if acting == 3:
        rt0, h0 = _gas_rt(y[g], y[g + 1], _volume(x, xdot, 0, c)[0], v)
        rt1, h1 = _gas_rt(y[g + 6], y[g + 7], _volume(x, xdot, 1, c)[0], v)
        m0 = _mdot(y[g + 6], rt1, y[g], rt0, area, v)
        return m0, h1, -m0, h0
    pf = v[V_PFRAME]
    if acting == 1:
        rt0, h0 = _gas_rt(y[g], y[g + 1], _volume(x, xdot, 0, c)[0], v)
        return _mdot(pf, rt_f, y[g], rt0, area, v), h_f, 0.0, 0.0
    rt1, h1 = _gas_rt(y[g + 6], y[g + 7], _volume(x, xdot, 1, c)[0], v)
    return 0.0, 0.0, _mdot(pf, rt_f, y[g + 6], rt1, area, v), h_f


@nb.njit(cache=True, inline="always")
def state_force(y, g, c):
    """Gas force on the crosshead along +x from the chamber pressures ``y[g]``, ``y[g+6]`` (an
    inactive chamber's pressure state stays at the frame pressure)."""
    return -y[g] * c[cy.C_AHE] + y[g + 6] * c[cy.C_ACE] + c[cy.C_PFRAME] * c[cy.C_AROD]


@nb.njit(cache=True, inline="always")
def _volume(x, xdot, j, c):
    """Volume of chamber ``j`` (0 head end, 1 crank end) and its rate, for the crosshead at
    ``x`` moving at ``xdot`` (`cycle`'s chamber geometry)."""
    stroke = c[cy.C_XMAX] - c[cy.C_XMIN]
    if j == 0:
        return (c[cy.C_CLEAR] * c[cy.C_AHE] * stroke + c[cy.C_AHE] * (c[cy.C_XMAX] - x),
                -c[cy.C_AHE] * xdot)  # fmt: skip
    return (c[cy.C_CLEAR] * c[cy.C_ACE] * stroke + c[cy.C_ACE] * (x - c[cy.C_XMIN]),
            c[cy.C_ACE] * xdot)  # fmt: skip


# _chamber and gas_rhs are inlined into the load's compiled role (a call between numba
# functions passing arrays costs ~30 ns): 18 % less time per revolution with dynamic valves,
# bit-identical results. The paths a healthy cylinder of an ideal gas never takes (the ring
# leak, the real gas's table: _ring, _gas_rt, real_properties, _bilinear) are called, not
# inlined: inlined at numba's level they were typed again at each of their seven call sites,
# and the load's role `valves_rhs` took 28 s of CPU to compile on first use; called, 8 s,
# the time per right-hand side unchanged (171 against 169 ns, measured 2026-12-08, one
# machine; issue 43, a configuration never run before).
@nb.njit(cache=True, inline="always")
def gas_rhs(x, xdot, y, g, a, c, v, out):
    """`gas_rhs_lines` between the cylinder's set line pressures and temperatures (``c``
    and ``v``)."""
    return gas_rhs_lines(x, xdot, y, g, a, c, v, c[cy.C_PS], v[V_TS], c[cy.C_PD], v[V_TD], out)


@nb.njit(cache=True, inline="always")
def gas_rhs_lines(x, xdot, y, g, a, c, v, ps, ts, pd, td, out):
    """Derivatives of the gas states ``y[g:g+12]`` and the mass counters ``y[a:a+4]`` for the
    crosshead at ``x`` moving at ``xdot``; returns the gas force on the crosshead along +x.
    ``c``: the cycle data ([`recipdyn.model.cycle.pack_cycle`][recipdyn.model.cycle.pack_cycle]),
    ``v``: [`pack_valves`][recipdyn.model.valves.pack_valves]; the suction line at pressure
    ``ps`` (Pa) and temperature ``ts`` (K), the discharge line at ``pd`` and, for gas that
    flows back from it, ``td`` (an interstage volume's state, or the set lines). A chamber
    that does not compress (single-acting) keeps its states (derivatives 0) and the frame
    pressure acts on its piston face."""
    acting = int(v[V_NCH])
    m0 = h0 = m1 = h1 = 0.0
    if v[V_RING] > 0.0:
        m0, h0, m1, h1 = _ring(x, xdot, y, g, c, v)
    for j in range(2):
        b = g + 6 * j
        if not acting & (1 << j):
            for i in range(6):
                out[b + i] = 0.0
            out[a + 2 * j] = 0.0
            out[a + 2 * j + 1] = 0.0
            continue
        V, dV = _volume(x, xdot, j, c)
        ms, md = _chamber(V, dV, y, b, 2 * j, c, v, m0 if j == 0 else m1,
                          h0 if j == 0 else h1, ps, ts, pd, td, out)  # fmt: skip
        out[a + 2 * j] = ms
        out[a + 2 * j + 1] = -md
    return state_force(y, g, c)


@nb.njit(cache=True)
def _distance(y, i, ymax):
    """Event factor of plate ``i``: negative only for a plate beyond the stop it moves toward
    and faster than `V_REST` (an impact to act on); 1 at rest.

    Toward the seat (``u < 0``) it is ``max(lift / ymax, (u + V_REST) / V_REST)``, toward the
    guard the mirror image: continuous in the state, so it falls through 0 where a fast plate
    reaches its stop (the impact), and a slow plate, or one at rest that the dense output
    shows a rounding-size velocity toward its stop, never makes an event (the right-hand
    side lets such a plate rest on the stop instead; `_plate`). It is the distance to
    the stop the plate moves *toward* (not the nearer one), so it is 1 right after a rebound
    and the event function leaves its surface at once (a crossing of another factor just
    after the rebound is not hidden); it jumps where the plate turns, between two positive
    values, which is no crossing."""
    return _stop_factor(y[i], y[i + 1], ymax)


@nb.njit(cache=True)
def _nearest(y, g, v):
    """(index of the lift of the plate with the smallest event factor, the factor)."""
    ymax = v[V_LIFT]
    acting = int(v[V_NCH])
    best, out = -1, 1.0
    for j in range(2):
        if acting & (1 << j):
            for i in (g + 6 * j + 2, g + 6 * j + 4):
                d = _distance(y, i, ymax)
                if d < out:
                    best, out = i, d
    return best, out


@nb.njit(cache=True)
def valve_event(y, g, v):
    """The smallest event factor of the plates (`_distance`; falls through 0 at an
    impact)."""
    return _nearest(y, g, v)[1]


@nb.njit(cache=True)
def valve_reset(y, g, v, out):
    """The impact of the plate whose factor is smallest (on its surface at the event): it is
    put on the stop it moves toward and rebounds with the restitution, or rests there when
    the rebound is below `V_REST`."""
    for i in range(y.shape[0]):
        out[i] = y[i]
    best, d = _nearest(y, g, v)
    if best < 0 or d >= 1.0:
        return
    out[best] = 0.0 if y[best + 1] < 0.0 else v[V_LIFT]
    u = -v[V_E] * y[best + 1]
    out[best + 1] = 0.0 if abs(u) < V_REST else u


def gas_initial(values, c: np.ndarray, theta1: float) -> np.ndarray:
    """The gas states at crank angle ``theta1``: the ideal cycle's pressures, the masses at
    the temperature of a polytrope from the suction state, plates closed and at rest."""
    p_he, p_ce, v_he, v_ce = cy.cycle_state(float(theta1), c)
    R = float(values["gas_constant"])
    ts, ps = float(values["suction_temperature"]), float(values["suction_pressure"])
    nc = float(values["n_compression"])
    gas = values.get("gas", "ideal")
    real = None if gas == "ideal" else rg.isentropic_density(gas, ps, ts, [p_he, p_ce])
    y = np.zeros(N_GAS)
    for j, (p, V) in enumerate(((p_he, v_he), (p_ce, v_ce))):
        y[6 * j] = p
        if real is None:  # on the polytrope from the suction state
            T = ts * (p / ps) ** ((nc - 1.0) / nc)
            y[6 * j + 1] = p * V / (R * T)
        else:  # on the suction isentrope
            y[6 * j + 1] = float(real[j]) * V
    return y


def gas_outputs(values, x, y, dy, g: int, a: int, c: np.ndarray) -> dict[str, Any]:
    """The chambers' signals over a record (crosshead ``x``, states ``y``, their derivatives
    ``dy``; gas states from column ``g``, mass counters from ``a``): pressures, volumes,
    temperatures and the mass flows through the valves."""
    from .base import Signal

    R = float(values["gas_constant"])
    tab = _gas_table(values)
    out = {}
    for j, end in enumerate(("head", "crank")):
        b = g + 6 * j
        vol = _volume(x, 0.0, j, c)[0]
        out[f"p_{end}"] = Signal(y[:, b], "Pa", f"{end}-end cylinder pressure (absolute)")
        out[f"V_{end}"] = Signal(vol, "m**3", f"{end}-end cylinder volume")
        if tab is None:
            temp = y[:, b] * vol / (y[:, b + 1] * R)
        else:
            temp = _real_temperatures(y[:, b], y[:, b] * vol / y[:, b + 1], tab)
        out[f"T_{end}"] = Signal(temp, "K", f"{end}-end gas temperature")
        out[f"mdot_suction_{end}"] = Signal(dy[:, a + 2 * j], "kg/s",
                                            f"{end}-end suction mass flow (in)")  # fmt: skip
        out[f"mdot_discharge_{end}"] = Signal(dy[:, a + 2 * j + 1], "kg/s",
                                              f"{end}-end discharge mass flow (out)")  # fmt: skip
    return out


@nb.njit(cache=True)
def _real_temperatures(p, rt, tab):
    out = np.empty(p.shape[0])
    for k in range(p.shape[0]):
        out[k] = real_properties(p[k], rt[k], tab)[3]
    return out


def gas_scale(values, y0: np.ndarray, g: int, a: int, out: np.ndarray) -> np.ndarray:
    """Typical sizes of the gas states in ``out`` (`Model.state_scale`): pressures and
    masses at their initial values, lifts at the full lift, the mass counters at the initial
    gas mass (plate velocities keep ``out``'s)."""
    for j in range(2):
        b = g + 6 * j
        out[b], out[b + 1] = y0[b], y0[b + 1]
        out[b + 2] = out[b + 4] = values["valve_lift"]
        out[a + 2 * j] = out[a + 2 * j + 1] = y0[b + 1]
    return out


def valve_summary(values: Mapping[str, Any], ds: Any) -> dict[str, Any]:
    """Figures of the last recorded revolution: indicated power, volumetric efficiency from
    the mass taken in, the mass balance of each chamber, and per valve the number of impacts,
    of separate openings (> 1: the plate flutters or reopens) and the crank angle of its final
    closing after the dead centre at which the ideal valve closes (> 0: late closing)."""
    out: dict[str, Any] = cy.pin_reversal_summary(values, ds)
    if not out:  # shorter than a revolution
        return out
    ds = cy.last_revolution(ds, float(values["omega"]))
    th = np.asarray(ds["theta1"].values, dtype=float)
    last = th >= th[-1] - 2.0 * math.pi
    c = cy.cycle_data(values)
    stroke = c[cy.C_XMAX] - c[cy.C_XMIN]
    tab = _gas_table(values)
    rt_s = values["gas_constant"] * values["suction_temperature"] if tab is None else tab[rg.T_RTS]
    rho_s = values["suction_pressure"] / rt_s
    work = 0.0
    for j, end in enumerate(("head", "crank")):
        if not int(c[cy.C_ACTING]) & (1 << j):
            continue
        p = np.asarray(ds[f"p_{end}"].values, dtype=float)[last]
        V = np.asarray(ds[f"V_{end}"].values, dtype=float)[last]
        work += cy.indicated_work(p, V)
        m_in = np.asarray(ds[f"mass_in_{end}"].values, dtype=float)[last]
        m_out = np.asarray(ds[f"mass_out_{end}"].values, dtype=float)[last]
        din, dout = m_in[-1] - m_in[0], m_out[-1] - m_out[0]
        area = c[cy.C_AHE] if j == 0 else c[cy.C_ACE]
        out[f"volumetric_efficiency_{end}"] = float(din / (rho_s * area * stroke))
        out[f"mass_balance_{end}"] = float((din - dout) / din) if din > 0 else math.nan
        # the dead centre at which the ideal suction (discharge) valve closes
        odc, idc = math.degrees(c[cy.C_THODC]), math.degrees(c[cy.C_THIDC])
        close = {"suction": idc if j == 0 else odc, "discharge": odc if j == 0 else idc}
        for kind in ("suction", "discharge"):
            lift = np.asarray(ds[f"y_{kind}_{end}"].values, dtype=float)[last]
            is_open = lift > 0.0
            starts = np.flatnonzero(is_open & ~np.roll(is_open, 1))
            out[f"openings_{kind}_{end}"] = int(starts.size)
            # share of the open time at full lift (< 1 and many impacts: the plate flutters)
            n_open = np.count_nonzero(is_open)
            at_guard = np.count_nonzero(lift >= float(values["valve_lift"]) * (1 - 1e-9))
            out[f"full_lift_share_{kind}_{end}"] = at_guard / n_open if n_open else 0.0
            if is_open.any() and not is_open.all():
                ends = np.flatnonzero(~is_open & np.roll(is_open, 1))
                # the last closing within 90 degrees of the dead centre
                ang = np.degrees(th[last][ends]) % 360.0
                lag = (ang - close[kind] + 180.0) % 360.0 - 180.0
                near = lag[np.abs(lag) <= 90.0]
                if near.size:
                    out[f"closing_lag_{kind}_{end}_deg"] = float(near.max())
    speed = cy.mean_speed(values, ds)
    out["indicated_power_W"] = work * speed / (2.0 * math.pi)
    if "impact_time" in ds:
        out["valve_impacts_per_rev"] = int(np.count_nonzero(
            np.asarray(ds["impact_time"].values) >= float(ds["time"].values[-1])
            - 2.0 * math.pi / speed))  # fmt: skip
    return out
