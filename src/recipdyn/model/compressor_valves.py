r"""The compressor with dynamic valves: the massless-link mechanism and the cylinder gas as states.

The paper's mechanism with the crank-pin clearance as the massless link (`compressor`,
the exact equation of motion) driven by the compression cycle with dynamic plate valves
(`valves`): the chamber pressures and masses and the valve plates are states integrated
with the clearance angle, the chamber volumes follow the crosshead of the mechanism's own state,
and the gas force on the crosshead follows the pressures. State::

    (theta_c, theta_c', p_head, m_head, y_suction_head, u_suction_head, y_discharge_head,
     u_discharge_head, <the same six for the crank end>, mass_in_head, mass_out_head,
     mass_in_crank, mass_out_crank)

The last four are auxiliary (mass counters; ``ODESystem.aux_states``). A chamber that does not
compress (``acting = "head"`` or ``"crank"``) keeps its states at the frame pressure.

The Jacobian: the mechanism rows are exact (the generated ``d theta_c''/d(theta_c,
theta_c')`` of `_generated` and ``d theta_c''/d p`` = the equation's exact coefficient of
the gas force, which enters linearly, times the piston areas); the gas rows are central
differences of the gas right-hand side (the valve stops and the regularised nozzle are not
everywhere smooth), with steps scaled by each state's size.

Benettin's method is refused: a plate that comes to rest on a stop loses its velocity in a
reset whose saltation matrix is singular, so the tangent dynamics of the valves has exponents
of -infinity and the QR iteration is not defined (see `lyapunov_refusal`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numba as nb
import numpy as np

from . import cycle as cy
from . import valves as va
from ._generated import clearance_acceleration, clearance_acceleration_jac
from .base import (
    EVENT_SIGNATURE,
    JAC_SIGNATURE,
    RHS_SIGNATURE,
    Event,
    ODESystem,
    Signal,
    compiled,
    rhs_series,
)
from .components.contract import Assembly
from .components.drive import PRESCRIBED
from .components.load import VALVES
from .components.mechanism import HEAD, N_HEAD
from .compressor import Compressor, equilibrium_theta_c, mechanism_outputs
from .kinematics import kinematics
from .parameters import SCHEMA as LINK_SCHEMA
from .parameters import CompressorParams
from .protocol import Schema

__all__ = ["CompressorValves", "COMPRESSOR_VALVES"]

#: The packed vector: the mechanism's head (`recipdyn.model.components.mechanism.HEAD`), the
#: prescribed drive's slice (omega, theta1_0), then the valve load's (the cycle data, then the
#: valve data).
(P_R, P_RS, P_L, P_LS, P_M1, P_M2, P_M3, P_J1, P_J2, P_G, P_RC, P_D) = range(N_HEAD)
P_OMEGA, P_TH10, P_CYCLE = N_HEAD, N_HEAD + 1, N_HEAD + 2
P_VALVE = P_CYCLE + cy.N_CYCLE
_ASSEMBLY = Assembly(N_HEAD, (PRESCRIBED, VALVES))
#: Offsets in the state: the gas states, then the mass counters.
G0 = 2
A0 = G0 + va.N_GAS
STATE_NAMES = ("theta_c", "thetadot_c", *va.GAS_STATE_NAMES, *va.AUX_STATE_NAMES)
STATE_UNITS = ("rad", "rad/s", *va.GAS_STATE_UNITS, *va.AUX_STATE_UNITS)
N_STATE = len(STATE_NAMES)


@nb.njit(cache=True, inline="always")
def _crosshead(th1, thc, thcd, p):
    """Crosshead position and velocity of the massless-link mechanism
    ([`kinematics`][recipdyn.model.kinematics.kinematics])."""
    r, l, rc, w = p[P_R], p[P_L], p[P_RC], p[P_OMEGA]
    s2 = -(p[P_D] + r * math.sin(th1) + rc * math.sin(thc)) / l
    c2 = math.sqrt(1.0 - s2 * s2)
    th2d = -(r * w * math.cos(th1) + rc * thcd * math.cos(thc)) / (l * c2)
    x = r * math.cos(th1) + rc * math.cos(thc) + l * c2
    v = -r * w * math.sin(th1) - rc * thcd * math.sin(thc) - l * s2 * th2d
    return x, v


@nb.njit(cache=True, inline="always")
def _acc(th1, thc, thcd, F, p):
    return clearance_acceleration(th1, thc, thcd, F, p[P_R], p[P_L], p[P_LS], p[P_M2], p[P_M3],
                                  p[P_J2], p[P_G], p[P_RC], p[P_D], p[P_OMEGA])  # fmt: skip


@nb.njit(cache=True, inline="always")
def _gas(t, y, p, out):
    th1 = p[P_TH10] + p[P_OMEGA] * t
    x, xd = _crosshead(th1, y[0], y[1], p)
    return th1, va.gas_rhs(x, xd, y, G0, A0, p[P_CYCLE:P_VALVE], p[P_VALVE:], out)


@compiled(RHS_SIGNATURE)
def rhs_valves(t, y, p, out):
    """Mechanism and gas: ``(theta_c', theta_c'', gas states', mass flows)``."""
    th1, F = _gas(t, y, p, out)
    out[0] = y[1]
    out[1] = 0.0 if p[P_RC] == 0.0 else _acc(th1, y[0], y[1], F, p)


@compiled(JAC_SIGNATURE, allocates=True)
def jac_valves(t, y, p, J):
    n = y.shape[0]
    for i in range(n):
        for j in range(n):
            J[i, j] = 0.0
    f = np.empty(n)
    th1, F = _gas(t, y, p, f)
    J[0, 1] = 1.0
    c = p[P_CYCLE:P_VALVE]
    acting = int(c[cy.C_ACTING])
    if p[P_RC] != 0.0:
        _a, J[1, 0], J[1, 1] = clearance_acceleration_jac(
            th1, y[0], y[1], F, p[P_R], p[P_L], p[P_LS], p[P_M2], p[P_M3], p[P_J2], p[P_G],
            p[P_RC], p[P_D], p[P_OMEGA])  # fmt: skip
        # theta_c'' is linear in the gas force: its coefficient exactly, from two values
        dF = 1.0 + abs(F)
        dadF = (_acc(th1, y[0], y[1], F + dF, p) - _a) / dF
        if acting & 1:
            J[1, G0] = -dadF * c[cy.C_AHE]
        if acting & 2:
            J[1, G0 + 6] = dadF * c[cy.C_ACE]
    # gas rows: central differences over the mechanism and gas states
    v = p[P_VALVE:]
    yh = y.copy()
    f1 = np.empty(n)
    f2 = np.empty(n)
    for j in range(A0):
        k = (j - G0) % 6 if j >= G0 else -1
        if k == 0:
            scale = c[cy.C_PS]
        elif k == 1:
            scale = abs(y[j]) + 1e-12
        elif k == 2 or k == 4:
            scale = v[va.V_LIFT]
        else:
            scale = 1.0
        h = 1e-7 * (abs(y[j]) + scale)
        yh[j] = y[j] + h
        _gas(t, yh, p, f1)
        yh[j] = y[j] - h
        _gas(t, yh, p, f2)
        yh[j] = y[j]
        for i in range(G0, n):
            J[i, j] = (f1[i] - f2[i]) / (2.0 * h)


@compiled(EVENT_SIGNATURE)
def valve_impact(t, y, p):
    """Smallest normalised distance of a moving valve plate to its seat or guard."""
    return va.valve_event(y, G0, p[P_VALVE:])


@compiled(RHS_SIGNATURE)
def valve_rebound(t, y, p, out):
    va.valve_reset(y, G0, p[P_VALVE:], out)


_DROP = {"load", "load_amplitude", "load_sign", "equations", "gas"}
SCHEMA = Schema((
    *(p for p in LINK_SCHEMA if p.name not in _DROP),
    *va.SCHEMA_PARAMS,
), aliases=dict(LINK_SCHEMA.aliases))  # fmt: skip


def _cparams(values: Mapping[str, Any]) -> CompressorParams:
    # the mechanism's load is the valves' (their "gas" is not the cycle load's table)
    keys = set(CompressorParams.__dataclass_fields__) & set(LINK_SCHEMA.names) - {"gas"}
    return CompressorParams(load="cycle", **{k: values[k] for k in keys if k in values})


def pack(values: Mapping[str, Any]) -> np.ndarray:
    """Packed vector: the mechanism's head, the prescribed drive's slice, the valve load's
    (layout: the ``P_*`` constants)."""
    p = _cparams(values)
    head = np.array([getattr(p, k) for k in HEAD], dtype=np.float64)
    vec, offsets = _ASSEMBLY.pack(head, values)
    assert offsets["drive"] == P_OMEGA and offsets["load"] == P_CYCLE
    return vec


class CompressorValves(Compressor):
    """The compressor with dynamic valves as a registered model (module docstring)."""

    name = "compressor-valves"
    description = (
        "the compressor (massless-link clearance) driven by the compression cycle with "
        "dynamic plate valves: cylinder pressures and valves as states"
    )
    state_names = STATE_NAMES
    state_units = STATE_UNITS
    schema = SCHEMA
    lyapunov_refusal = (
        "valve plates come to rest on their stops in resets with a singular saltation matrix "
        "(Benettin's QR is undefined there); use the signal estimators or --model compressor "
        "with load=cycle (ideal valves)"
    )

    validity_bounds = ((
        *Compressor.validity_bounds[0][:4],
        "the contact-impact joint with dynamic valves (--model compressor-contact-valves)",
    ),)  # fmt: skip

    def lyapunov_supported(self, values: Mapping[str, Any]) -> bool:
        return False

    @staticmethod
    def params(values: Mapping[str, Any]) -> CompressorParams:
        return _cparams(values)

    def events(self, values: Mapping[str, Any]) -> tuple[Event, ...]:
        return (Event("impact", valve_impact, direction=-1, action="reset", reset=valve_rebound,
                      description="a valve plate reaches its seat or guard: rebound with the "
                      "restitution, or rest"),)  # fmt: skip

    def system(self, values: Mapping[str, Any]) -> ODESystem:
        p = self.params(values)
        return ODESystem(rhs=rhs_valves, jac=jac_valves, params=pack(values),
                         state_names=STATE_NAMES, state_units=STATE_UNITS,
                         period=p.crank_period, name=self.name, attrs=p.to_attrs(),
                         events=self.events(values), aux_states=va.N_AUX)  # fmt: skip

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        """The massless link aligned with the ideal cycle's load, the gas states of the ideal
        cycle at the initial crank angle, plates closed and at rest, counters 0."""
        p = self.params(values)
        thc0 = equilibrium_theta_c(p) if p.theta_c0 is None else p.theta_c0
        y = np.zeros(N_STATE)
        y[0], y[1] = thc0 + p.theta_c_offset, p.thetadot_c0
        y[G0:A0] = va.gas_initial(values, pack(values)[P_CYCLE:P_VALVE], p.theta1_0)
        return y

    def state_scale(self, values: Mapping[str, Any]) -> np.ndarray:
        """The mechanism's states at 1; the gas states at their own size
        ([`gas_scale`][recipdyn.model.valves.gas_scale])."""
        return va.gas_scale(values, self.initial_state(values), G0, A0, np.ones(N_STATE))

    def outputs(self, values: Mapping[str, Any], t: np.ndarray, y: np.ndarray
                ) -> dict[str, Signal]:  # fmt: skip
        """The massless-link model's outputs with the gas force of the pressure states, and
        the chambers' pressures, volumes, temperatures and mass flows."""
        p = self.params(values)
        sys_ = self.system(values)
        t = np.asarray(t, dtype=float)
        dy = rhs_series(sys_.rhs, sys_.params, t, y)
        thc, thcd = y[:, 0], y[:, 1]
        k = kinematics(p, t, thc, thcd, dy[:, 1])
        fg = cy.pressure_force(y[:, G0], y[:, G0 + 6], bore=p.bore, rod_diameter=p.rod_diameter,
                               frame_pressure=p.frame_pressure)  # fmt: skip
        return {
            **mechanism_outputs(p, k, thc, thcd, dy[:, 1], fg),
            **va.gas_outputs(values, k.x3, y, dy, G0, A0, sys_.params[P_CYCLE:P_VALVE]),
        }

    def run_summary(self, values: Mapping[str, Any], ds: Any) -> dict[str, Any]:
        return va.valve_summary(values, ds)


#: The registered instance (``recipdyn --model compressor-valves``).
COMPRESSOR_VALVES = CompressorValves()
