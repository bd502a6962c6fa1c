r"""The interstage volume: stage 1's discharge into a cooled volume that is stage 2's suction.

A machine's ``[[interstage]]`` (`recipdyn.model.machine.description.Interstage`) joins two
stages. Its gas (the cylinders' ideal gas, gas constant ``R``) is held at the cooler's
temperature ``T_c`` (an ideal cooler: the gas the upstream stage delivers leaves it at
``T_c``), so its state is its pressure ``p_i`` alone, with the mass ``m_i = p_i V / (R T_c)``
in its volume ``V``; the mass balance of the volume gives::

    dp_i/dt = R T_c / V (sum over the upstream throws of the mass their discharge valves
                         deliver - sum over the downstream throws of the mass their suction
                         valves take in)

The upstream stage's cylinders discharge into ``p_i`` (gas that flows back from the volume
comes at ``T_c``); the downstream stage's cylinders take in from ``p_i`` at ``T_c``
(`recipdyn.model.valves.gas_rhs_lines`). The templates read the flows from the cylinders'
mass counters (the load role ``flows``), so the volume's mass and the counters keep one linear
invariant, ``m_i - sum delivered + sum taken in``, which every Runge-Kutta step preserves to
rounding.

Its time constant: with the upstream stage's delivery ``Q1`` (kg/s) and the downstream stage's
intake ``p_i Q2 eta_2 / (R T_c)`` (``Q2`` its swept volume per second, ``eta_2`` its
volumetric efficiency), a departure from the steady pressure decays as ``exp(-t / tau)``,
``tau = V / (Q2 eta_2 (1 + s))`` with ``s`` the relative slopes of the stages' volumetric
efficiencies in ``p_i`` (0 at zero clearance: ``tau = V / Q2``).

Limits, stated: one uniform pressure (no pulsation in the pipes; no pressure drop across the
cooler), an ideal cooler (no lag: the gas is at ``T_c`` at once), an ideal gas (a real gas's
line states are tabulated at the set pressures: refused).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numba as nb
import numpy as np

from ..protocol import Param
from .contract import Component

__all__ = ["INTERSTAGE", "PARAMS", "STATES", "interstage_line", "interstage_rate"]

#: Offsets in its slice: the volume, the cooler's temperature, the gas constant.
I_VOLUME, I_TEMPERATURE, I_R = range(3)

PARAMS = (
    Param("volume", "m**3", 1.0, "interstage volume: the pipes, cooler and separator between "
          "the stages", 1e-6, 1e4, low_open=False, group="interstage"),
    Param("cooler_temperature", "K", 313.15, "temperature the interstage cooler holds the gas "
          "at (the downstream stage's suction temperature)", 50.0, 2000.0, group="interstage"),
)  # fmt: skip
#: Its state: the pressure of its gas.
STATES = (("p", "Pa"),)


def _pack(values: Mapping[str, Any]) -> np.ndarray:
    return np.array([values["volume"], values["cooler_temperature"], values["gas_constant"]],
                    dtype=np.float64)  # fmt: skip


@nb.njit(cache=True)
def interstage_line(y, s, p, o):
    """The volume's pressure ``y[s]`` and its gas's temperature (the cooler's): the line a
    stage's cylinders discharge into or take in from."""
    return y[s], p[o + I_TEMPERATURE]


@nb.njit(cache=True)
def interstage_rate(mdot, p, o):
    """``dp_i/dt`` for the net mass flow ``mdot`` (kg/s) into the volume."""
    return p[o + I_R] * p[o + I_TEMPERATURE] / p[o + I_VOLUME] * mdot


INTERSTAGE = Component(
    "interstage", "cooler", "a volume between two stages, its gas at the cooler's temperature",
    module=__name__, pack=_pack, params=PARAMS, states=STATES,
    kernels={"line": "interstage_line", "rate": "interstage_rate"},
)  # fmt: skip
