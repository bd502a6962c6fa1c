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

With ``drive = "motor"`` the crank angle and speed are states too: the free-crank
accelerations of the massless-link mechanism (`recipdyn.model._generated_drive`, as the
motor-driven `compressor`) with the gas force of the chamber pressures, in the generated glue
of `recipdyn.model.components.mechanism` (the valve component's own derivatives, event and
reset). State::

    (theta_c, theta_c', theta1, omega1, W_motor, W_gas, <the twelve gas states>,
     <the four mass counters>)

Benettin's method is refused: a plate that comes to rest on a stop loses its velocity in a
reset whose saltation matrix is singular, so the tangent dynamics of the valves has exponents
of -infinity and the QR iteration is not defined (see `lyapunov_refusal`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import lru_cache
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
from .components.contract import Assembly, glue_module
from .components.drive import MOTOR, MOTORS, PRESCRIBED
from .components.link import LinkModel, mechanism_energy_series, mechanism_outputs
from .components.load import VALVES
from .components.mechanism import HEAD, N_HEAD, equilibrium_theta_c, glue_source
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


#: With a motor: the mechanism's two states, the motor's four (crank angle and speed, the
#: work integrals of the motor and of the gas), then the gas states and the mass counters.
MOTOR_STATE_NAMES = ("theta_c", "thetadot_c", "theta1", "omega1", "W_motor", "W_gas",
                     *va.GAS_STATE_NAMES, *va.AUX_STATE_NAMES)  # fmt: skip
MOTOR_STATE_UNITS = ("rad", "rad/s", "rad", "rad/s", "J", "J", *va.GAS_STATE_UNITS,
                     *va.AUX_STATE_UNITS)  # fmt: skip
MG0 = 6
MA0 = MG0 + va.N_GAS


def _motor_values(values: Mapping[str, Any]) -> dict[str, Any]:
    """``values`` as the torque laws read them: a constant torque's default, the mean load
    torque, is the ideal-valve cycle's of the same cylinder (ideal gas), the valves' own
    mean torque to the valve losses."""
    return {**values, "load": "cycle", "gas": "ideal", "load_table": None}


def _motor_assembly(values: Mapping[str, Any]) -> Assembly:
    motor = MOTORS[values.get("motor", "induction")]
    return Assembly(N_HEAD, (MOTOR, motor, VALVES))


def pack_motor(values: Mapping[str, Any]) -> tuple[np.ndarray, dict[str, int]]:
    """Packed vector with a motor: the mechanism's head, the motor drive's slice (J_drive),
    the torque law's, the valve load's; and each part's offset."""
    p = _cparams(values)
    head = np.array([getattr(p, k) for k in HEAD], dtype=np.float64)
    return _motor_assembly(values).pack(head, _motor_values(values))


@lru_cache(maxsize=8)
def _motor_glue(motor: str, offsets: tuple[tuple[str, int], ...]):
    """The generated glue of the massless link, the motor ``motor`` and the valves."""
    src = glue_source(equations="exact", drive=MOTOR, load=VALVES, motor=MOTORS[motor],
                      offsets=dict(offsets), first_state=MG0)  # fmt: skip
    return glue_module(src, f"compressor_motor_valves_{motor}")


class CompressorValves(LinkModel):
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
        *LinkModel.validity_bounds[0][:4],
        "the contact-impact joint with dynamic valves (--model compressor-contact-valves)",
    ),)  # fmt: skip

    def lyapunov_supported(self, values: Mapping[str, Any]) -> bool:
        return False

    @staticmethod
    def _motor(values: Mapping[str, Any]) -> bool:
        return values.get("drive", "prescribed") == "motor"

    def _motor_kernels(self, values: Mapping[str, Any]):
        vec, offsets = pack_motor(values)
        return vec, _motor_glue(values.get("motor", "induction"),
                                tuple(sorted(offsets.items())))  # fmt: skip

    def states(self, values: Mapping[str, Any]) -> tuple[tuple[str, str], ...]:
        """The mechanism's, the gas's and the counters'; with a motor, the crank angle and
        speed and the work integrals after the mechanism's (module docstring)."""
        if self._motor(values):
            return tuple(zip(MOTOR_STATE_NAMES, MOTOR_STATE_UNITS, strict=True))
        return tuple(zip(STATE_NAMES, STATE_UNITS, strict=True))

    @staticmethod
    def params(values: Mapping[str, Any]) -> CompressorParams:
        return _cparams(values)

    def events(self, values: Mapping[str, Any]) -> tuple[Event, ...]:
        event, reset = valve_impact, valve_rebound
        if self._motor(values):
            k = self._motor_kernels(values)[1]
            event, reset = k.event, k.reset
        return (Event("impact", event, direction=-1, action="reset", reset=reset,
                      description="a valve plate reaches its seat or guard: rebound with the "
                      "restitution, or rest"),)  # fmt: skip

    def system(self, values: Mapping[str, Any]) -> ODESystem:
        p = self.params(values)
        if self._motor(values):
            vec, k = self._motor_kernels(values)
            # the crank is a state: autonomous; the work integrals (and with rc = 0 the
            # clearance angle) are passive, the mass counters auxiliary
            passive = (4, 5) if p.rc > 0 else (0, 1, 4, 5)
            return ODESystem(rhs=k.rhs, jac=k.jac, params=vec, state_names=MOTOR_STATE_NAMES,
                             state_units=MOTOR_STATE_UNITS, period=None, name=self.name,
                             attrs=p.to_attrs(), events=self.events(values),
                             aux_states=va.N_AUX, passive=passive)  # fmt: skip
        return ODESystem(rhs=rhs_valves, jac=jac_valves, params=pack(values),
                         state_names=STATE_NAMES, state_units=STATE_UNITS,
                         period=p.crank_period, name=self.name, attrs=p.to_attrs(),
                         events=self.events(values), aux_states=va.N_AUX)  # fmt: skip

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        """The massless link aligned with the ideal cycle's load, the gas states of the ideal
        cycle at the initial crank angle, plates closed and at rest, counters 0."""
        p = self.params(values)
        thc0 = equilibrium_theta_c(p) if p.theta_c0 is None else p.theta_c0
        gas = va.gas_initial(values, pack(values)[P_CYCLE:P_VALVE], p.theta1_0)
        if self._motor(values):  # with a motor: the crank at theta1_0 turning at omega
            return np.concatenate([[thc0 + p.theta_c_offset, p.thetadot_c0, p.theta1_0,
                                    p.omega, 0.0, 0.0], gas, np.zeros(va.N_AUX)])  # fmt: skip
        y = np.zeros(N_STATE)
        y[0], y[1] = thc0 + p.theta_c_offset, p.thetadot_c0
        y[G0:A0] = gas
        return y

    def state_scale(self, values: Mapping[str, Any]) -> np.ndarray:
        """The mechanism's states at 1; the gas states at their own size
        ([`gas_scale`][recipdyn.model.valves.gas_scale])."""
        y0 = self.initial_state(values)
        if self._motor(values):
            return va.gas_scale(values, y0, MG0, MA0, np.maximum(1.0, np.abs(y0)))
        return va.gas_scale(values, y0, G0, A0, np.ones(N_STATE))

    def outputs(self, values: Mapping[str, Any], t: np.ndarray, y: np.ndarray
                ) -> dict[str, Signal]:  # fmt: skip
        """The massless-link model's outputs with the gas force of the pressure states, and
        the chambers' pressures, volumes, temperatures and mass flows."""
        p = self.params(values)
        sys_ = self.system(values)
        t = np.asarray(t, dtype=float)
        if self._motor(values):
            return self._motor_outputs(values, p, sys_, t, y)
        dy = rhs_series(sys_.rhs, sys_.params, t, y)
        thc, thcd = y[:, 0], y[:, 1]
        k = kinematics(p, t, thc, thcd, dy[:, 1])
        fg = cy.pressure_force(y[:, G0], y[:, G0 + 6], bore=p.bore, rod_diameter=p.rod_diameter,
                               frame_pressure=p.frame_pressure)  # fmt: skip
        return {
            **mechanism_outputs(p, k, thc, thcd, dy[:, 1], fg),
            **va.gas_outputs(values, k.x3, y, dy, G0, A0, sys_.params[P_CYCLE:P_VALVE]),
        }

    def _motor_outputs(self, values, p, sys_, t, y) -> dict[str, Signal]:
        """With a motor: the massless link's outputs from the observed crank angle, speed and
        gas force (the compiled functions that were integrated), the crank's speed and
        acceleration, the motor torque, the work integrals and the mechanism's energy, and
        the chambers' signals."""
        y = np.ascontiguousarray(y, dtype=float)
        dy = rhs_series(sys_.rhs, sys_.params, t, y)
        obs = self._motor_kernels(values)[1].observe(np.ascontiguousarray(t), y, sys_.params)
        th1, w1, fg = obs[:, 0], obs[:, 1], obs[:, 2]
        thc, thcd, a1 = y[:, 0], y[:, 1], dy[:, 3]
        k = kinematics(p, t, thc, thcd, dy[:, 1], theta1=th1, omega1=w1, alpha1=a1)
        c = pack(values)[P_CYCLE:P_VALVE]
        return {
            **mechanism_outputs(p, k, thc, thcd, dy[:, 1], fg),
            **va.gas_outputs(values, k.x3, y, dy, MG0, MA0, c),
            "omega1": Signal(w1, "rad/s", "crank speed"),
            "alpha1": Signal(a1, "rad/s**2", "crank angular acceleration"),
            "motor_torque": Signal(dy[:, 4] / w1, "N*m", "motor torque at the crank"),
            "W_motor": Signal(y[:, 4], "J", "work done by the motor since t = 0"),
            "W_gas": Signal(y[:, 5], "J", "work done by the gas on the crosshead since t = 0"),
            "energy": Signal(mechanism_energy_series(p, y), "J",
                             "kinetic + potential energy of the mechanism and the drive"),
        }  # fmt: skip

    def run_summary(self, values: Mapping[str, Any], ds: Any) -> dict[str, Any]:
        return va.valve_summary(values, ds)


#: The registered instance (``recipdyn --model compressor-valves``).
COMPRESSOR_VALVES = CompressorValves()
