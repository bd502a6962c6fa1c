r"""The contact-impact clearance joint driven by the cylinder gas with dynamic valves.

`compressor_contact` (journal free in its bearing: flight, impacts, friction, oil film)
with the gas load of `valves`: the chamber pressures and masses and the valve plates are
states integrated with the eccentricities, the chamber volumes follow the crosshead of the
joint's own state, and the gas force follows the pressures (the load component
`recipdyn.model.components.load.VALVES`, a load with states, joined to the joints by the
generated glue of `recipdyn.model.components.contact`). This is the pairing the
double-acting cycle needs: its rod load reverses twice a revolution, where the massless link of
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

from .components.contact_valves_model import (
    P_VALVE,
    SCHEMA,
    STATE_NAMES,
    STATE_UNITS,
    CompressorContactValves,
    pack,
)

__all__ = ["CompressorContactValves", "COMPRESSOR_CONTACT_VALVES", "SCHEMA", "STATE_NAMES",
           "STATE_UNITS", "P_VALVE", "pack"]  # fmt: skip

#: The registered instance (``recipdyn --model compressor-contact-valves``).
COMPRESSOR_CONTACT_VALVES = CompressorContactValves()
