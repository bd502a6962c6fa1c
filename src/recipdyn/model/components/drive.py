r"""Drive components: what turns the crank.

* ``prescribed``: the crank turns at the constant speed ``omega``,
  ``theta1 = theta1_0 + omega t`` (the paper's assumption, an infinitely stiff drive);
* ``motor``: the crank angle and speed are states, driven by a motor torque on the inertia
  ``J_drive`` (motor rotor, coupling and flywheel, referred to the crank shaft: a gear or belt
  of ratio i multiplies the motor's torque by i and its inertia by i**2, divides its speed by
  i). The torque law is a component of its own family, ``motor``:

  - ``constant``: ``T = motor_torque`` (default: the mean load torque of one revolution of
    the ideal mechanism at ``omega``, so the mean speed stays near ``omega``);
  - ``induction``: Kloss's torque-speed curve of an induction motor,
    ``T = 2 T_b s s_b / (s**2 + s_b**2)`` with the slip ``s = (omega_s - omega1)/omega_s``,
    the breakdown torque ``T_b`` and breakdown slip ``s_b`` (e.g. Fitzgerald & Kingsley,
    *Electric Machinery*, 6th ed., 2003, Sec. 6.5; the steady-state curve, without the
    electrical transients);
  - ``held``: the rotor turns at ``omega`` whatever the load asks (an ideal speed-controlled
    drive: a synchronous motor on a stiff grid, a drive whose speed loop is much faster than
    the shaft): its torque is the one that keeps the rotor from accelerating, found by the
    machine's kernels from the shaft's state (the crank's equation on a rigid shaft, the
    coupling's torque on a torsionally flexible one). On a rigid shaft the crank then turns
    as with ``drive = prescribed``; on a flexible one the flywheel and the throws turn and
    twist behind the held rotor.

The motor adds the states ``theta1`` (rad), ``omega1`` (rad/s) and the work integral
``W_motor`` (J, auxiliary); the mechanism adds ``W_gas``, the work of the gas on the
crosshead, so the energy balance ``E(t) - E(0) = W_motor + W_gas`` can be checked.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ...errors import ParameterError
from ..protocol import Param
from .contract import Component

#: Where the drive components' compiled functions live (numba loads only when a run does).
KERNELS = "recipdyn.model.components.drive_kernels"

__all__ = ["PRESCRIBED", "MOTOR", "CONSTANT_TORQUE", "INDUCTION", "HELD", "DRIVES", "MOTORS",
           "mean_load_torque"]  # fmt: skip

_INF = math.inf


def _prescribed(values: Mapping[str, Any]) -> np.ndarray:
    return np.array([values["omega"], values["theta1_0"]], dtype=np.float64)


def mean_load_torque(values: Mapping[str, Any], n: int = 7200) -> float:
    """Mean torque the gas load asks of the crank over one revolution of the ideal mechanism
    (rc = 0) at constant speed: ``-(1/2 pi) integral F(theta1) dx3/dtheta1 dtheta1``, N m."""
    from .load import force_series

    th = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    r, l, d = float(values["r"]), float(values["l"]), float(values["d"])
    u = d + r * np.sin(th)
    dx3 = -r * np.sin(th) - u * r * np.cos(th) / np.sqrt(l * l - u * u)
    F = force_series(values, th)
    return float(-np.mean(F * dx3))


def _motor(values: Mapping[str, Any]) -> np.ndarray:
    return np.array([values["J_drive"]], dtype=np.float64)


def _constant(values: Mapping[str, Any]) -> np.ndarray:
    T = values.get("motor_torque")
    return np.array([mean_load_torque(values) if T is None else T], dtype=np.float64)


def _induction(values: Mapping[str, Any]) -> np.ndarray:
    return np.array([values["motor_sync_speed"], values["motor_breakdown_torque"],
                     values["motor_breakdown_slip"]], dtype=np.float64)  # fmt: skip


def _check_induction(values: Mapping[str, Any]) -> None:
    if values["motor_sync_speed"] <= values["omega"] * (1.0 - values["motor_breakdown_slip"]):
        raise ParameterError(
            f"motor_sync_speed = {values['motor_sync_speed']:g} rad/s is out of range for "
            f"omega = {values['omega']:g} rad/s; allowed: > omega (1 - motor_breakdown_slip) "
            "(the crank would start beyond the motor's breakdown slip)"
        )


PRESCRIBED = Component(
    "drive", "prescribed", "constant crank speed omega (an infinitely stiff drive)",
    module=KERNELS, kernels={"crank": "prescribed_crank"}, pack=_prescribed,
)  # fmt: skip

_ASSUMED_MOTOR = ("assumed: a 4-pole 50 Hz motor (157 rad/s) through a 7.5:1 belt, referred "
                  "to the crank shaft; not from the paper (drive = motor only)")  # fmt: skip

MOTOR = Component(
    "drive", "motor", "crank angle and speed as states, driven by a motor torque",
    module=KERNELS, kernels={}, pack=_motor,
    params=(
        Param("J_drive", "kg*m**2", 3000.0, "motor rotor + flywheel inertia referred to the "
              "crank shaft (drive = motor)", 0.0, _INF, high_open=True, assumed=_ASSUMED_MOTOR,
              group="drive"),
    ),
    states=(("theta1", "rad"), ("omega1", "rad/s")),
    aux_states=(("W_motor", "J"),),
)  # fmt: skip

CONSTANT_TORQUE = Component(
    "motor", "constant", "constant motor torque", module=KERNELS,
    kernels={"torque": "constant_torque"}, pack=_constant,
    params=(
        Param("motor_torque", "N*m", None, "constant motor torque at the crank (motor = "
              "constant; default: the mean load torque at omega)", -1e9, 1e9, optional=True,
              group="drive"),
    ),
)  # fmt: skip

INDUCTION = Component(
    "motor", "induction", "induction motor, Kloss's torque-speed curve", module=KERNELS,
    kernels={"torque": "induction_torque"}, pack=_induction, check=_check_induction,
    params=(
        Param("motor_sync_speed", "rad/s", 21.0, "synchronous speed referred to the crank "
              "(motor = induction)", 0.0, 1e4, low_open=True, assumed=_ASSUMED_MOTOR,
              group="drive"),
        Param("motor_breakdown_torque", "N*m", 11000.0, "breakdown (pull-out) torque at the "
              "crank (motor = induction)", 0.0, 1e9, low_open=True, assumed=_ASSUMED_MOTOR,
              group="drive"),
        Param("motor_breakdown_slip", "", 0.15, "slip at the breakdown torque (motor = "
              "induction)", 0.0, 1.0, low_open=True, assumed=_ASSUMED_MOTOR, group="drive"),
    ),
)  # fmt: skip


def _held(values: Mapping[str, Any]) -> np.ndarray:
    return np.zeros(0, dtype=np.float64)


HELD = Component(
    "motor", "held", "the rotor's speed held at omega (an ideal speed-controlled drive); its "
    "torque is what the shaft asks", module=KERNELS, kernels={}, pack=_held,
)  # fmt: skip

#: The drive family and the motor's torque laws, by name.
DRIVES = {c.name: c for c in (PRESCRIBED, MOTOR)}
MOTORS = {c.name: c for c in (CONSTANT_TORQUE, INDUCTION, HELD)}
