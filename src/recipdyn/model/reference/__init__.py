"""Reference models: small systems with known answers, registered beside the compressor.

They exercise every layer with dynamics whose properties are known exactly (the forced damped
Duffing oscillator's exponent sum is ``-delta``; Lorenz's is ``-(sigma + 1 + beta)``; the Hénon
map's is ``ln b``), and they are the template for a user's own model (``examples/``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..base import EVENT_SIGNATURE, JAC_SIGNATURE, RHS_SIGNATURE, DiscreteMap, ODESystem, compiled
from ..protocol import Event, Model, Param, Schema
from . import systems

__all__ = ["Duffing", "Lorenz", "Henon", "DUFFING", "LORENZ", "HENON", "systems"]

_INF = math.inf


@compiled(RHS_SIGNATURE)
def _duffing(t, y, p, out):
    out[0] = y[1]
    out[1] = -p[0] * y[1] - p[1] * y[0] - p[2] * y[0] ** 3 + p[3] * math.cos(p[4] * t)


@compiled(JAC_SIGNATURE)
def _duffing_jac(t, y, p, J):
    J[0, 0], J[0, 1] = 0.0, 1.0
    J[1, 0], J[1, 1] = -p[1] - 3.0 * p[2] * y[0] ** 2, -p[0]


@compiled(EVENT_SIGNATURE)
def _x_zero(t, y, p):
    return y[0]


class Duffing(Model):
    """Forced damped Duffing oscillator ``x'' + delta x' + alpha x + beta x^3 = gamma cos(w t)``.

    Defaults: the double-well chaotic case of Guckenheimer & Holmes (1983), Sec. 2.2
    (delta = 0.3, alpha = -1, beta = 1, gamma = 0.5, w = 1.2). The Jacobian's trace is
    ``-delta``, so the two Lyapunov exponents sum to ``-delta`` exactly.
    """

    name = "duffing"
    description = "forced damped Duffing oscillator x'' + delta x' + alpha x + beta x^3 = " \
        "gamma cos(w t)"  # fmt: skip
    state_names = ("x", "v")
    state_units = ("m", "m/s")
    schema = Schema((
        Param("delta", "1/s", 0.3, "damping", 0.0, _INF, group="oscillator"),
        Param("alpha", "1/s**2", -1.0, "linear stiffness per mass", -_INF, _INF,
              group="oscillator"),
        Param("beta", "1/(m**2*s**2)", 1.0, "cubic stiffness per mass", -_INF, _INF,
              group="oscillator"),
        Param("gamma", "m/s**2", 0.5, "forcing amplitude per mass", -_INF, _INF, group="forcing"),
        Param("w", "rad/s", 1.2, "forcing frequency", 0.0, _INF, low_open=True, group="forcing"),
        Param("x0", "m", 1.0, "initial displacement", -1e6, 1e6, group="initial"),
        Param("v0", "m/s", 0.0, "initial velocity", -1e6, 1e6, group="initial"),
    ))  # fmt: skip

    def system(self, values: Mapping[str, Any]) -> ODESystem:
        p = np.array([values[k] for k in ("delta", "alpha", "beta", "gamma", "w")], dtype=float)
        return ODESystem(rhs=_duffing, jac=_duffing_jac, params=p, state_names=self.state_names,
                         state_units=self.state_units, period=self.period(values),
                         name=self.name)  # fmt: skip

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        return np.array([values["x0"], values["v0"]], dtype=float)

    def period(self, values: Mapping[str, Any]) -> float:
        return 2.0 * math.pi / float(values["w"])

    def events(self, values: Mapping[str, Any]) -> tuple[Event, ...]:
        """Well crossings: x through 0 upward (left well -> right well), recorded."""
        return (Event("crossing", _x_zero, direction=1, description="x crosses 0 upward"),)


class Lorenz(Model):
    """The Lorenz (1963) system; defaults (10, 28, 8/3): lambda = 0.9056, 0, -14.5723
    (Sprott 2003)."""

    name = "lorenz"
    description = "Lorenz (1963) convection model x' = sigma (y - x), y' = x (rho - z) - y, " \
        "z' = x y - beta z"  # fmt: skip
    state_names = ("x", "y", "z")
    state_units = ("1", "1", "1")
    time_unit = "1"
    schema = Schema((
        Param("sigma", "", 10.0, "Prandtl number", 0.0, _INF, low_open=True, group="flow"),
        Param("rho", "", 28.0, "Rayleigh number ratio", 0.0, _INF, group="flow"),
        Param("beta", "", 8.0 / 3.0, "geometry factor", 0.0, _INF, low_open=True, group="flow"),
        Param("x0", "", 1.0, "initial x", -1e6, 1e6, group="initial"),
        Param("y0", "", 1.0, "initial y", -1e6, 1e6, group="initial"),
        Param("z0", "", 1.0, "initial z", -1e6, 1e6, group="initial"),
    ))  # fmt: skip

    def system(self, values: Mapping[str, Any]) -> ODESystem:
        s = systems.lorenz(values["sigma"], values["rho"], values["beta"])
        return ODESystem(rhs=s.rhs, jac=s.jac, params=s.params, state_names=self.state_names,
                         state_units=self.state_units, name=self.name)  # fmt: skip

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        return np.array([values["x0"], values["y0"], values["z0"]], dtype=float)

    def period(self, values: Mapping[str, Any]) -> None:
        return None


class Henon(Model):
    """The Hénon (1976) map; defaults (1.4, 0.3): lambda = 0.41922, -1.62319 (Sprott 2003)."""

    name = "henon"
    description = "Hénon (1976) map x' = 1 - a x^2 + y, y' = b x"
    state_names = ("x", "y")
    state_units = ("1", "1")
    time_unit = "1"
    schema = Schema((
        Param("a", "", 1.4, "nonlinearity", -_INF, _INF, group="map"),
        Param("b", "", 0.3, "contraction (Jacobian determinant -b)", -_INF, _INF, group="map"),
        Param("x0", "", 0.1, "initial x", -1e6, 1e6, group="initial"),
        Param("y0", "", 0.1, "initial y", -1e6, 1e6, group="initial"),
    ))  # fmt: skip

    @property
    def kind(self) -> str:
        return "map"

    def system(self, values: Mapping[str, Any]) -> DiscreteMap:
        return systems.henon(values["a"], values["b"])

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        return np.array([values["x0"], values["y0"]], dtype=float)

    def period(self, values: Mapping[str, Any]) -> None:
        return None


DUFFING = Duffing()
LORENZ = Lorenz()
HENON = Henon()
