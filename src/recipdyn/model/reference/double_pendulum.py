"""The planar double pendulum with joint damping: the first model derived by the N-coordinate
generator ([`recipdyn.model.derive`][recipdyn.model.derive]), two coordinates, a generalized force.

Point masses m1, m2 on massless rods l1, l2; angles q1, q2 from the downward vertical; viscous
damping c at both joints (generalized forces ``Q = -c (q1', q2')``). Undamped, the energy is
conserved (tests/test_derive.py checks it along chaotic runs and compares the accelerations with
the textbook closed form).

Run ``python -m recipdyn.model.reference.double_pendulum`` to regenerate
``_double_pendulum.py``; a test fails if the committed file is stale.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from ..base import ODESystem, Signal
from ..protocol import Model, Param, Schema

__all__ = ["DoublePendulum", "DOUBLE_PENDULUM", "lagrangian", "generate", "energy"]

PARAMS = ("m1", "m2", "l1", "l2", "g", "c")


@lru_cache(maxsize=1)
def lagrangian():
    """The derived [`Lagrangian`][recipdyn.model.derive.Lagrangian]."""
    import sympy as sp

    from ..derive import derive

    t = sp.Symbol("t", real=True)
    q1, q2, w1, w2 = sp.symbols("q1 q2 w1 w2", real=True)
    m1, m2, l1, l2, g, c = sp.symbols(" ".join(PARAMS), real=True)
    x1, y1 = l1 * sp.sin(q1), -l1 * sp.cos(q1)
    x2, y2 = x1 + l2 * sp.sin(q2), y1 - l2 * sp.cos(q2)

    def vel(e):  # d/dt of a position depending on q1, q2
        return sp.diff(e, q1) * w1 + sp.diff(e, q2) * w2

    T = (m1 * (vel(x1) ** 2 + vel(y1) ** 2) + m2 * (vel(x2) ** 2 + vel(y2) ** 2)) / 2
    V = g * (m1 * y1 + m2 * y2)
    return derive(T, V, (q1, q2), (w1, w2), t, (m1, m2, l1, l2, g, c), Q=(-c * w1, -c * w2))


def generate() -> str:
    from ..derive import kernel_source

    return kernel_source(lagrangian(), "double_pendulum",
                         "Double pendulum with joint damping (recipdyn.model.reference."
                         "double_pendulum).")  # fmt: skip


def energy(values: Mapping[str, Any], y: np.ndarray) -> np.ndarray:
    """Total mechanical energy (J) along a trajectory ``y`` of shape (n, 4)."""
    m1, m2, l1, l2, g = (values[k] for k in ("m1", "m2", "l1", "l2", "g"))
    q1, q2, w1, w2 = y[:, 0], y[:, 1], y[:, 2], y[:, 3]
    v1sq = (l1 * w1) ** 2
    v2sq = v1sq + (l2 * w2) ** 2 + 2 * l1 * l2 * w1 * w2 * np.cos(q1 - q2)
    V = -g * (m1 * l1 * np.cos(q1) + m2 * (l1 * np.cos(q1) + l2 * np.cos(q2)))
    return 0.5 * m1 * v1sq + 0.5 * m2 * v2sq + V


class DoublePendulum(Model):
    name = "double-pendulum"
    description = "planar double pendulum with joint damping (2 coordinates, derived by sympy)"
    state_names = ("q1", "q2", "w1", "w2")
    state_units = ("rad", "rad", "rad/s", "rad/s")
    schema = Schema((
        Param("m1", "kg", 1.0, "upper bob mass", 0.0, math.inf, low_open=True, group="pendulum"),
        Param("m2", "kg", 1.0, "lower bob mass", 0.0, math.inf, low_open=True, group="pendulum"),
        Param("l1", "m", 1.0, "upper rod length", 0.0, math.inf, low_open=True, group="pendulum"),
        Param("l2", "m", 1.0, "lower rod length", 0.0, math.inf, low_open=True, group="pendulum"),
        Param("g", "m/s**2", 9.81, "gravitational acceleration", 0.0, 100.0, group="pendulum"),
        Param("c", "N*m*s", 0.0, "joint damping (0: conservative)", 0.0, math.inf,
              group="pendulum"),
        Param("q1_0", "rad", 2.0, "initial upper angle", -1e3, 1e3, group="initial"),
        Param("q2_0", "rad", 2.5, "initial lower angle", -1e3, 1e3, group="initial"),
        Param("w1_0", "rad/s", 0.0, "initial upper angular velocity", -1e3, 1e3,
              group="initial"),
        Param("w2_0", "rad/s", 0.0, "initial lower angular velocity", -1e3, 1e3,
              group="initial"),
    ))  # fmt: skip

    def system(self, values: Mapping[str, Any]) -> ODESystem:
        from ._double_pendulum import double_pendulum_jac, double_pendulum_rhs

        p = np.array([values[k] for k in PARAMS], dtype=float)
        return ODESystem(rhs=double_pendulum_rhs, jac=double_pendulum_jac, params=p,
                         state_names=self.state_names, state_units=self.state_units,
                         name=self.name)  # fmt: skip

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        return np.array([values[k] for k in ("q1_0", "q2_0", "w1_0", "w2_0")], dtype=float)

    def period(self, values: Mapping[str, Any]) -> None:
        return None

    def outputs(self, values, t, y) -> dict[str, Signal]:
        out = super().outputs(values, t, y)
        out["energy"] = Signal(energy(values, np.atleast_2d(y)), "J", "mechanical energy")
        return out


DOUBLE_PENDULUM = DoublePendulum()


def _target() -> Path:
    return Path(__file__).with_name("_double_pendulum.py")


if __name__ == "__main__":  # pragma: no cover - developer tool
    _target().write_text(generate())
    print(f"wrote {_target().name}")
