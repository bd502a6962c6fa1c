r"""The contact joints driven by the cylinder gas with dynamic valves: the joints'
configuration part of a throw with ``crank_joint`` (or ``crosshead_joint``, ``guide``) worn
and ``load = valves`` (``compressor-contact-valves``, the family's route ``contact-valves``:
`recipdyn.model.assembler.model.OneContact`; a machine's throws,
`recipdyn.model.assembler.contact_throws`).

The contact joints (`recipdyn.model.compressor_contact`: journal free in its bearing, flight,
impacts, friction, oil film) with the gas load of `valves`: the chamber pressures and masses
and the valve plates are states integrated with the eccentricities, the chamber volumes follow
the crosshead of the joint's own state, and the gas force follows the pressures (the load
component `recipdyn.model.components.load.VALVES`, a load with states, joined to the joints by
the generated glue of `recipdyn.model.components.contact`). This is the pairing the double-
acting cycle needs: its rod load reverses twice a revolution, where the massless link of
``compressor-valves`` leaves its validity and the journal really crosses its clearance.

State: the contact model's twelve (``ex ... W_loss``), then the twelve gas states and the four
mass counters of `valves` (with a motor, then the crank's ``theta1, omega1, W_motor``).

Events: the integrator locates one event function, so the contact onsets and separations and
the valve impacts share one: the minimum of the joints' phased contact factors
(`phased_factor`) and the valves' normalised distances to the stop
each moving plate moves toward. Every factor is positive between its events and falls through
0 at one, and its reset makes it positive again (a joint changes phase, an onset recording the
approach velocity; a plate rebounds or rests), so the minimum falls through 0 at each event and
two events however close are both located (a product of signed factors would lose both
events of a pair closer than a quarter step).

The Jacobian is a fourth-order central difference over the whole state (the valve laws are
not written for the contact model's complex-step Jacobian); Benettin's method is refused as
for the massless link with dynamic valves.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .. import cycle as cy
from .. import valves as va
from ..base import Event, ODESystem, Signal
from ..joints import pins
from ..protocol import Schema
from . import contact_model as cm
from .load import VALVES

__all__ = ["ContactJointsValves", "SCHEMA", "STATE_NAMES", "STATE_UNITS", "P_VALVE", "pack"]

G0, A0 = pins.G_GAS, pins.G_AUX
STATE_NAMES = (*pins.STATE_NAMES, *va.GAS_STATE_NAMES, *va.AUX_STATE_NAMES)
#: The gas states' and the counters' names and units (after the guide's, with its clearance).
_GAS = tuple(zip((*va.GAS_STATE_NAMES, *va.AUX_STATE_NAMES),
                 (*va.GAS_STATE_UNITS, *va.AUX_STATE_UNITS), strict=True))  # fmt: skip
STATE_UNITS = (*pins.STATE_UNITS, *va.GAS_STATE_UNITS, *va.AUX_STATE_UNITS)
N_STATE = len(STATE_NAMES)
#: The valve data in the parameter vector: after the joints' and the cycle's.
P_VALVE = pins.N_PACKED + cy.N_CYCLE


def _layout(values: Mapping[str, Any]) -> tuple[int, int, int]:
    """The first gas state, the first mass counter, and the load's offset in the parameter
    vector (after a user's contact law's slice, and the guide's states and slice, with its
    clearance)."""
    g = cm.first_load_state(values)
    lo = pins.N_PACKED + cm.law_size(values) + (pins.N_GUIDE if cm.has_guide(values) else 0)
    if cm.has_motor(values):  # the free crank's and the torque law's slices
        lo += cm.N_CRANK + cm.motor_size(values)
    return g, g + va.N_GAS, lo


_DROP = {"load", "load_amplitude", "load_sign", "gas"}
SCHEMA = Schema((*(p for p in cm.SCHEMA if p.name not in _DROP), *va.SCHEMA_PARAMS),
                aliases=dict(cm.SCHEMA.aliases))  # fmt: skip
_LOAD = {"load": "cycle", "load_amplitude": 0.0, "load_sign": "physical", "gas": "ideal"}


def pack(values: Mapping[str, Any]) -> np.ndarray:
    """The contact model's vector, then the cycle data and the valve data (the load component
    `recipdyn.model.components.load.VALVES`)."""
    return cm.pack(values, load=VALVES)


class ContactJointsValves(cm.ContactJoints):
    """The contact joints' configuration part with the cylinder gas and dynamic valves
    (module docstring)."""

    name = "compressor-contact-valves"
    description = ("compressor with contact-impact clearance joints driven by the compression "
                   "cycle with dynamic plate valves (pressures and valves as states)")  # fmt: skip
    state_names = STATE_NAMES
    state_units = STATE_UNITS
    schema = SCHEMA
    event_example = {}  # the valves hit their stops at the defaults
    lyapunov_refusal = (
        "the valve plates come to rest on their stops in resets with a singular saltation "
        "matrix (Benettin's QR is undefined there); use the signal estimators, or --model "
        "compressor-contact with load=cycle (ideal valves)"
    )

    def load_part(self, values: Mapping[str, Any]):
        return VALVES

    @staticmethod
    def _table(values: Mapping[str, Any], table: Any, ptab: Any) -> None:
        if table is not None or ptab is not None:
            from ...errors import ParameterError

            raise ParameterError(
                f"{'load_table' if table is not None else 'pressure_table'}: not for the "
                "dynamic valves, whose gas force follows the chamber pressures; use --model "
                "compressor-contact for a table load"
            )

    def _values(self, values: Mapping[str, Any]) -> dict[str, Any]:
        return {**values, **_LOAD}

    def events(self, values: Mapping[str, Any]) -> tuple[Event, ...]:
        k = self.kernels(values)
        return (Event("impact", k.event, direction=-1, action="reset", reset=k.reset,
                      description="a contact onset or separation, or a valve plate reaching "
                      "its seat or guard (one event function: the minimum of the factors): "
                      "an onset records the approach velocity, a plate rebounds or "
                      "rests"),)  # fmt: skip

    def _load_states(self, values: Mapping[str, Any]) -> tuple[tuple[str, str], ...]:
        """The gas states and the four mass counters, after the contact model's (the
        joints', the guide's with its clearance; with a motor the crank's follow)."""
        return _GAS

    def tangent(self, values: Mapping[str, Any]) -> dict[str, Any]:
        """With a motor the contact model's; else the valves' mass counters the last
        auxiliary states, no fused Jacobian."""
        if cm.has_motor(values):
            return super().tangent(values)
        return {"rhs_jac": False, "period": self.period(values), "aux_states": va.N_AUX,
                "aux": (), "passive": ()}  # fmt: skip

    def system(self, values: Mapping[str, Any]) -> ODESystem:
        k = self.kernels(values)
        own = self.tangent(values)
        names, units = zip(*self.states(values), strict=True)
        return ODESystem(rhs=k.rhs, jac=k.jac, rhs_jac=k.rhs_jac if own["rhs_jac"] else None,
                         params=pack(values), state_names=names, state_units=units,
                         period=own["period"], name=self.name, events=self.events(values),
                         aux_states=own["aux_states"], aux=own["aux"],
                         passive=own["passive"])  # fmt: skip

    def check(self, values: Mapping[str, Any]) -> None:
        super().check(self._values(values))

    def tracks_separations(self, values: Mapping[str, Any]) -> bool:
        return True

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        """The contact model's initial state (journal along the ideal cycle's rod load), the
        ideal cycle's gas states at the initial crank angle, plates closed, counters 0."""
        g0, a0, _ = _layout(values)
        own = super().initial_state(self._values(values))
        y = np.zeros(a0 + va.N_AUX)
        y[:g0] = own[:g0]
        y[g0:a0] = va.gas_initial(values, cy.cycle_data(values), float(values["theta1_0"]))
        return np.concatenate([y, own[g0:]])  # (with a motor, the crank's states)

    def state_scale(self, values: Mapping[str, Any]) -> np.ndarray:
        """The contact model's scales for its states; the gas states at their own size."""
        y0 = self.initial_state(values)
        g0, a0, _ = _layout(values)
        return va.gas_scale(values, y0, g0, a0, super().state_scale(values))

    def outputs(self, values: Mapping[str, Any], t: np.ndarray, y: np.ndarray,
                dy: np.ndarray | None = None) -> dict[str, Signal]:  # fmt: skip
        """The contact model's outputs (its gas force is the pressures'), then the chambers'
        pressures, volumes (from the recorded crosshead), temperatures and mass flows. ``dy``:
        the derivatives at ``y`` when they are not this model's own (a throw's slice of a
        machine whose interstage volume is a line of its cylinder)."""
        from ..base import rhs_series

        sig = super().outputs(values, t, y)
        s = self.system(values)
        if dy is None:
            dy = rhs_series(s.rhs, s.params, t, y)
        g0, a0, lo = _layout(values)
        sig.update(va.gas_outputs(values, sig["x"].values, y, dy, g0, a0,
                                  s.params[lo:lo + cy.N_CYCLE]))  # fmt: skip
        return sig

    def run_summary(self, values: Mapping[str, Any], ds: Any) -> dict[str, Any]:
        """The contact model's figures over the contact events and the valves' over the valve
        events (each event is assigned to the factor of the event function on its surface)."""
        if "impact_time" in ds:
            p = self.system(values).params
            names = [k for k, _ in self.states(values)]
            ev = np.ascontiguousarray(np.column_stack([ds[f"impact_{k}"].values
                                                       for k in names]))  # fmt: skip
            cfg = pins.CFG[values["clearance_joints"]]
            g0, _, lo = _layout(values)
            contact = np.array([abs(pins.contact_factor(e, p, cfg)[0]) if cfg < 3 else np.inf
                                for e in ev])  # fmt: skip
            valve = np.array([abs(va.valve_event(e, g0, p[lo + cy.N_CYCLE :])) for e in ev])
            is_valve = valve < contact
            if cm.has_guide(values):  # a guide's event: its corners changed phase
                after = np.column_stack([ds[f"impact_v_impact_guide_{k}_after"].values
                                         for k in range(1, 5)])  # fmt: skip
                before = np.column_stack([ds[f"impact_v_impact_guide_{k}"].values
                                          for k in range(1, 5)])  # fmt: skip
                is_valve &= ~(before != after).any(axis=1)
            ds_contact = ds.isel(impact_event=np.flatnonzero(~is_valve))
            ds_valve = ds.isel(impact_event=np.flatnonzero(is_valve))
        else:
            ds_contact = ds_valve = ds
        out = super().run_summary(self._values(values), ds_contact)
        for k in [k for k in out if k.startswith(("volumetric_efficiency", "indicated_power"))]:
            del out[k]  # the ideal cycle's figures: the valves' own are below
        out.update(va.valve_summary(values, ds_valve))
        return out
