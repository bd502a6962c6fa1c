r"""The compression cycle with a real gas (CoolProp), ideal valves.

With ``load = "cycle"`` and ``gas`` a CoolProp fluid (``Air``, ``Nitrogen``, ``Methane``, ...)
each chamber follows the ideal-valve cycle of :mod:`recipdyn.model.cycle` with the polytropes
replaced by **isentropes of the real gas** (no heat transfer, no losses): the suction state is
``(p_s, T_s)`` with entropy ``s_s``; the gas compressed from bottom dead centre keeps its mass
``m = V_max rho_s`` and ``s_s`` until the discharge pressure; the clearance gas left at top dead
centre (``rho_d = rho(p_d, s_s)``) re-expands at ``s_s`` to the suction pressure. So::

    growing volume:   p = max(p_s, P(rho = V_0 rho_d / V, s_s))
    shrinking volume: p = min(p_d, P(rho = V_max rho_s / V, s_s))

with ``P(rho, s)`` from CoolProp's Helmholtz equations of state. The re-expanded gas reaches
``p_s`` at the suction state itself (same pressure and entropy), so the ideal-valve cycle closes.

CoolProp cannot be called from compiled code, so the pressures are computed once per parameter
set on a 0.25 deg grid (cached), and the kernels interpolate the resulting force table like
any tabulated load (:func:`recipdyn.model.load.gas_force_kernel`); the cost of a run is that of
a table load plus the table (96 CoolProp flashes along the isentrope, ~0.2 s, once).

Reference: Bell, Wronski, Quoilin, Lemort (2014), Pure and pseudo-pure fluid thermophysical
property evaluation and the open-source thermophysical property library CoolProp, Ind. Eng.
Chem. Res. 53(6), 2498-2508.
"""

from __future__ import annotations

import functools

import numpy as np

from .cycle import CYCLE_PARAMS, cycle_data, cycle_states, pressure_force
from .parameters import GASES  # noqa: F401  (re-exported)

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

    from .parameters import ParameterError

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


def isentrope_pressure(values, rho) -> np.ndarray:
    """CoolProp's pressure on the suction isentrope at densities ``rho`` (kg/m^3), flash by
    flash (the reference the tabulated isentrope is tested against)."""
    import CoolProp

    state = CoolProp.AbstractState("HEOS", values["gas"])
    state.update(CoolProp.PT_INPUTS, values["suction_pressure"], values["suction_temperature"])
    s_s = state.smass()
    out = []
    for r in np.atleast_1d(rho):
        state.update(CoolProp.DmassSmass_INPUTS, float(r), s_s)
        out.append(state.p())
    return np.array(out)
