"""The forced impact oscillator: a linear oscillator against a rigid stop with restitution.

``x'' + 2 zeta x' + x = A cos(w t)`` for ``x < sigma``; when ``x`` reaches the stop the
velocity is reversed and scaled, ``v+ = -r v-`` (Newton's law of restitution). The classic
non-smooth oscillator of Shaw & Holmes (1983), *J. Sound Vib.* 90(1), 129-155, and of
Nordmark's grazing analysis (1991, *J. Sound Vib.* 145(2), 279-297); defaults in its chaotic
regime are ours (checked: a positive largest exponent at them).

It is the reference for events that act: the impact is a state reset, located on the dense
output, and the Lyapunov exponents include each impact's saltation matrix, whose determinant
is ``r**2`` for every impact; so the exponents sum to exactly
``-2 zeta + 2 N ln(r) / T`` along any run with ``N`` impacts in time ``T``
(tests/test_events.py).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..base import EVENT_SIGNATURE, JAC_SIGNATURE, RHS_SIGNATURE, ODESystem, compiled
from ..protocol import Event, Model, Param, Schema

__all__ = ["ImpactOscillator", "IMPACT_OSCILLATOR"]


@compiled(RHS_SIGNATURE)
def _rhs(t, y, p, out):
    out[0] = y[1]
    out[1] = -2.0 * p[0] * y[1] - y[0] + p[1] * math.cos(p[2] * t)


@compiled(JAC_SIGNATURE)
def _jac(t, y, p, J):
    J[0, 0], J[0, 1] = 0.0, 1.0
    J[1, 0], J[1, 1] = -1.0, -2.0 * p[0]


@compiled(EVENT_SIGNATURE)
def _at_stop(t, y, p):
    return y[0] - p[3]


@compiled(RHS_SIGNATURE)
def _impact(t, y, p, out):
    out[0] = p[3]  # exactly on the stop (the root is found to rounding)
    out[1] = -p[4] * y[1]


class ImpactOscillator(Model):
    """Forced damped linear oscillator against a rigid stop at ``x = sigma``."""

    name = "impact-oscillator"
    description = "forced linear oscillator against a rigid stop, restitution r (state resets)"
    state_names = ("x", "v")
    state_units = ("", "")
    time_unit = ""
    schema = Schema((
        Param("zeta", "", 0.05, "damping ratio", 0.0, 10.0, group="oscillator"),
        Param("A", "", 0.7, "forcing amplitude", -1e6, 1e6, group="forcing"),
        Param("w", "", 2.8, "forcing frequency (natural frequency = 1)", 0.0, 1e3,
              low_open=True, group="forcing"),
        Param("sigma", "", 0.0, "position of the stop", -1e6, 1e6, group="stop"),
        Param("r", "", 0.8, "coefficient of restitution", 0.0, 1.0, low_open=True,
              group="stop"),
        Param("x0", "", -0.5, "initial displacement (below the stop)", -1e6, 1e6,
              group="initial"),
        Param("v0", "", 0.0, "initial velocity", -1e6, 1e6, group="initial"),
    ))  # fmt: skip

    def check(self, values: Mapping[str, Any]) -> None:
        from ...errors import ParameterError

        if values["x0"] > values["sigma"]:
            raise ParameterError(f"x0 = {values['x0']!r} is beyond the stop; allowed: "
                                 f"x0 <= sigma = {values['sigma']!r}")  # fmt: skip

    def system(self, values: Mapping[str, Any]) -> ODESystem:
        p = np.array([values[k] for k in ("zeta", "A", "w", "sigma", "r")], dtype=float)
        return ODESystem(rhs=_rhs, jac=_jac, params=p, state_names=self.state_names,
                         state_units=self.state_units, period=self.period(values),
                         name=self.name, events=self.events(values))  # fmt: skip

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        return np.array([values["x0"], values["v0"]], dtype=float)

    def period(self, values: Mapping[str, Any]) -> float:
        return 2.0 * math.pi / float(values["w"])

    def events(self, values: Mapping[str, Any]) -> tuple[Event, ...]:
        return (Event("impact", _at_stop, direction=1, action="reset", reset=_impact,
                      description="x reaches the stop: v+ = -r v-"),)  # fmt: skip


IMPACT_OSCILLATOR = ImpactOscillator()
