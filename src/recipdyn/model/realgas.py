r"""The compression cycle with a real gas (CoolProp), ideal valves.

With ``load = "cycle"`` and ``gas`` a CoolProp fluid (``Air``, ``Nitrogen``, ``Methane``, ...)
each chamber follows the ideal-valve cycle of [`recipdyn.model.cycle`][recipdyn.model.cycle] with
the polytropes replaced by **isentropes of the real gas** (no heat transfer, no losses): the suction
state is ``(p_s, T_s)`` with entropy ``s_s``; the gas compressed from bottom dead centre keeps its
mass ``m = V_max rho_s`` and ``s_s`` until the discharge pressure; the clearance gas left at top
dead
centre (``rho_d = rho(p_d, s_s)``) re-expands at ``s_s`` to the suction pressure. So::

    growing volume:   p = max(p_s, P(rho = V_0 rho_d / V, s_s))
    shrinking volume: p = min(p_d, P(rho = V_max rho_s / V, s_s))

with ``P(rho, s)`` from CoolProp's Helmholtz equations of state. The re-expanded gas reaches
``p_s`` at the suction state itself (same pressure and entropy), so the ideal-valve cycle closes.

CoolProp cannot be called from compiled code, so the pressures are computed once per parameter
set on a 0.25 deg grid (cached), and the kernels interpolate the resulting force table like
any tabulated load (the ``table`` load component, `recipdyn.model.components.load`);
the cost of a run is that of a table load plus the table (96 CoolProp flashes along the isentrope,
~0.2 s, once).

Reference: Bell, Wronski, Quoilin, Lemort (2014), Pure and pseudo-pure fluid thermophysical
property evaluation and the open-source thermophysical property library CoolProp, Ind. Eng.
Chem. Res. 53(6), 2498-2508.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .cycle import CYCLE_PARAMS, cycle_data, cycle_states, pressure_force
from .gases import GASES  # noqa: F401  (re-exported)

__all__ = [
    "GASES",
    "real_gas_pressures",
    "real_gas_force_table",
    "real_gas_states",
    "isentrope_pressure",
]

#: Resolution of the pressure and force tables, deg.
STEP_DEG = 0.25
#: Densities at which the isentrope is evaluated with CoolProp (then interpolated).
ISENTROPE_NODES = 96

_KEYS = ("r", "l", "d", *CYCLE_PARAMS, "gas", "suction_temperature")


def _key(v) -> tuple:
    return tuple(v[k] for k in _KEYS)


@functools.lru_cache(maxsize=32)
def _tables(key: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    import CoolProp

    from ..errors import ParameterError

    v = dict(zip(_KEYS, key, strict=True))
    gas = v["gas"]
    ps, pd, Ts = v["suction_pressure"], v["discharge_pressure"], v["suction_temperature"]
    c = cycle_data(v)
    deg = np.arange(0.0, 360.0, STEP_DEG)
    st = cycle_states(np.deg2rad(deg), c)
    try:
        state = CoolProp.AbstractState("HEOS", gas)
        state.update(CoolProp.PT_INPUTS, ps, Ts)
        s_s, rho_s = state.smass(), state.rhomass()
        state.update(CoolProp.PSmass_INPUTS, pd, s_s)
        rho_d = state.rhomass()
    except ValueError as exc:
        raise ParameterError(
            f"gas = {gas!r} at suction {ps:g} Pa, {Ts:g} K and discharge {pd:g} Pa: CoolProp "
            f"cannot evaluate it ({exc})"
        ) from None

    # both chambers' gas follows the one isentrope s = s_s between rho_s and rho_d: evaluate
    # it on ISENTROPE_NODES log-spaced densities (a D-S flash costs ~2 ms) and interpolate
    # log p over log rho with a cubic spline (relative error < 1e-8, tested)
    from scipy.interpolate import CubicSpline

    nodes = np.geomspace(rho_s, rho_d, ISENTROPE_NODES) if rho_d > rho_s else None
    if nodes is not None:
        p_nodes = []
        for r in nodes:
            state.update(CoolProp.DmassSmass_INPUTS, float(r), s_s)
            p_nodes.append(state.p())
        spline = CubicSpline(np.log(nodes), np.log(p_nodes))

    def pressure(rho):
        return np.exp(spline(np.log(rho)))

    pressures = []
    for end, bit in (("head", 1), ("crank", 2)):
        V = st[f"V_{end}"]
        if not (c_acting(v["acting"]) & bit):
            pressures.append(np.full_like(V, v["frame_pressure"]))
            continue
        v_min, v_max = V.min(), V.max()
        grows = np.gradient(np.concatenate([V[-1:], V, V[:1]]))[1:-1] > 0
        rho = np.where(grows, v_min * rho_d / V, v_max * rho_s / V)
        p = np.where(grows, ps, pd)  # suction / discharge at the line pressure
        active = np.where(grows, rho > rho_s, rho < rho_d)  # on an isentrope
        active &= nodes is not None
        if active.any():
            p_isen = pressure(np.clip(rho[active], rho_s, rho_d))
            p[active] = np.where(grows[active], np.maximum(ps, p_isen), np.minimum(pd, p_isen))
        pressures.append(p)
    return deg, pressures[0], pressures[1], st["V_head"], st["V_crank"]


def c_acting(acting: str) -> int:
    """Chamber bits: 1 head end, 2 crank end."""
    return {"head": 1, "crank": 2, "double": 3}[acting]


def real_gas_pressures(values) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(deg, p_head, p_crank)`` of one revolution on the 0.25 deg grid (absolute, Pa)."""
    deg, ph, pc, _, _ = _tables(_key(values))
    return deg, ph, pc


def real_gas_force_table(values) -> tuple[tuple[float, float], ...]:
    """The gas force on the crosshead along +x as load-table rows ``(deg, N)``:
    ``F = -p_he A + p_ce (A - A_rod) + p_frame A_rod``."""
    deg, ph, pc = real_gas_pressures(values)
    force = pressure_force(ph, pc, bore=values["bore"], rod_diameter=values["rod_diameter"],
                           frame_pressure=values["frame_pressure"])  # fmt: skip
    return tuple((float(a), float(f)) for a, f in zip(deg, force, strict=True))


def real_gas_states(theta1, values) -> dict[str, np.ndarray]:
    """Pressures and volumes at crank angles ``theta1`` (rad), interpolated periodically on
    the table (the volumes are exact: they follow the crank)."""
    deg, ph, pc, _, _ = _tables(_key(values))
    c = cycle_data(values)
    th = np.asarray(theta1, dtype=float)
    st = cycle_states(th, c)
    x = np.mod(np.degrees(th), 360.0)
    period = dict(period=360.0)
    return {"p_head": np.interp(x, deg, ph, **period), "p_crank": np.interp(x, deg, pc, **period),
            "V_head": st["V_head"], "V_crank": st["V_crank"]}  # fmt: skip


def _suction_state(gas: str, ps: float, Ts: float):
    """A CoolProp state of ``gas`` at the suction state, and its specific entropy."""
    import CoolProp

    state = CoolProp.AbstractState("HEOS", gas)
    state.update(CoolProp.PT_INPUTS, ps, Ts)
    return state, state.smass()


def isentrope_pressure(values, rho) -> np.ndarray:
    """CoolProp's pressure on the suction isentrope at densities ``rho`` (kg/m^3), flash by
    flash (the reference the tabulated isentrope is tested against)."""
    import CoolProp

    state, s_s = _suction_state(values["gas"], values["suction_pressure"],
                                values["suction_temperature"])  # fmt: skip
    out = []
    for r in np.atleast_1d(rho):
        state.update(CoolProp.DmassSmass_INPUTS, float(r), s_s)
        out.append(state.p())
    return np.array(out)


# --- The property table of the dynamic valves' chambers (real gas) ---------------------------

#: Nodes per axis of the chamber property table (ln(p/rho) x ln p).
CHAMBER_NODES = 48
#: The table spans these multiples of the suction and discharge pressures ...
CHAMBER_P_RANGE = (0.25, 2.5)
#: ... and, in p/rho (Z R T), of the suction state's and the isentropic discharge state's.
CHAMBER_T_RANGE = (0.75, 1.6)
#: Layout of the table header (then four blocks of CHAMBER_NODES^2 values: phi_u, phi_A,
#: phi_B, phi_T, row = ln(p/rho) index).
(T_NX, T_NP, T_LX0, T_DLX, T_LP0, T_DLP, T_HS, T_HD, T_RTS, T_RTD, T_KAPPA) = range(11)
T_HEADER = 11


@functools.lru_cache(maxsize=16)
def chamber_table(gas: str, ps: float, pd: float, Ts: float) -> np.ndarray:
    r"""Real-gas properties of a chamber on a grid of ``(ln(p/rho), ln p)``, for
    [`recipdyn.model.valves.gas_rhs`][recipdyn.model.valves.gas_rhs] (layout: the ``T_*``
    constants).

    The first law of the open, adiabatic chamber in the states ``p`` and ``m`` needs, at
    ``rho = m / V``: the specific internal energy ``u`` and the derivatives
    ``A = (dp/drho)_u`` and ``B = (dp/du)_rho``. They are stored scaled so that an ideal gas
    with constant heat capacities gives constants, which bilinear interpolation reproduces
    exactly: ``phi_u = (u - u0) rho / p`` (``u0 = u_s - c_v,s T_s``: ``1/(k-1)`` for that
    gas), ``phi_A = A rho / p`` (1), ``phi_B = B / rho`` (``k - 1``), ``phi_T = p / (rho T)``
    (``R``). ``p/rho`` (``Z R T``) is the grid's first axis, so the chamber's states, between
    a little below the suction temperature and a little above the discharge temperature at
    any pressure, fill it. Energies are relative to ``u0``. The header holds the grid, the
    enthalpies of the suction gas and of the discharge line's gas (``p_d`` on the suction
    isentrope), ``p/rho`` of both (the nozzle's ``Z R T``) and the isentropic exponent
    ``rho c^2 / p`` at suction (the nozzle's). Nodes that CoolProp cannot evaluate or that
    are not gas (two-phase) take the values of the nearest valid node of their pressure."""
    import CoolProp

    from ..errors import ParameterError

    st = CoolProp.AbstractState("HEOS", gas)
    try:
        st.update(CoolProp.PT_INPUTS, ps, Ts)
        rho_s, u_s, h_s, s_s = st.rhomass(), st.umass(), st.hmass(), st.smass()
        u0 = u_s - st.cvmass() * Ts
        kappa = rho_s * st.speed_sound() ** 2 / ps  # (rho/p)(dp/drho)_s
        st.update(CoolProp.PSmass_INPUTS, pd, s_s)
        rho_d, h_d = st.rhomass(), st.hmass()
    except ValueError as exc:
        raise ParameterError(
            f"gas = {gas!r} at suction {ps:g} Pa, {Ts:g} K and discharge {pd:g} Pa: CoolProp "
            f"cannot evaluate it ({exc})"
        ) from None
    n = CHAMBER_NODES
    lx = np.linspace(math.log(CHAMBER_T_RANGE[0] * ps / rho_s),
                     math.log(CHAMBER_T_RANGE[1] * pd / rho_d), n)  # fmt: skip
    lp = np.linspace(math.log(CHAMBER_P_RANGE[0] * ps), math.log(CHAMBER_P_RANGE[1] * pd), n)
    phi = np.full((4, n, n), np.nan)
    for i, x in enumerate(np.exp(lx)):
        for j, p in enumerate(np.exp(lp)):
            r = p / x
            try:
                st.update(CoolProp.DmassP_INPUTS, float(r), float(p))
                if 0.0 <= st.Q() <= 1.0:  # two-phase: not a gas
                    continue
                A = st.first_partial_deriv(CoolProp.iP, CoolProp.iDmass, CoolProp.iUmass)
                B = st.first_partial_deriv(CoolProp.iP, CoolProp.iUmass, CoolProp.iDmass)
                phi[:, i, j] = ((st.umass() - u0) / x, A / x, B / r, x / st.T())
            except ValueError:
                continue
    ok = np.isfinite(phi).all(axis=0)
    if not ok.any(axis=0).all():
        raise ParameterError(f"gas = {gas!r}: CoolProp cannot evaluate the gas at some chamber "
                             f"pressure between {math.exp(lp[0]):g} and {math.exp(lp[-1]):g} "
                             "Pa; choose other pressures")  # fmt: skip
    for j in range(n):  # fill invalid nodes from the nearest valid one of their pressure
        good = np.flatnonzero(ok[:, j])
        for i in np.flatnonzero(~ok[:, j]):
            phi[:, i, j] = phi[:, good[np.argmin(np.abs(good - i))], j]
    head = np.zeros(T_HEADER)
    head[[T_NX, T_NP]] = n
    head[T_LX0], head[T_DLX] = lx[0], lx[1] - lx[0]
    head[T_LP0], head[T_DLP] = lp[0], lp[1] - lp[0]
    head[T_HS], head[T_HD] = h_s - u0, h_d - u0
    head[T_RTS], head[T_RTD] = ps / rho_s, pd / rho_d
    head[T_KAPPA] = kappa
    return np.concatenate([head, phi.ravel()])


def isentropic_density(gas: str, ps: float, Ts: float, p) -> np.ndarray:
    """Densities on the suction isentrope at pressures ``p`` (kg/m^3)."""
    import CoolProp

    st, s_s = _suction_state(gas, ps, Ts)
    out = []
    for q in np.atleast_1d(p):
        st.update(CoolProp.PSmass_INPUTS, float(q), s_s)
        out.append(st.rhomass())
    return np.array(out)
