r"""The torsionally flexible shaft in the time integration (issue 43, point 3).

A machine whose ``[shaft]`` holds a ``[shaft.torsion]`` table (drive = motor) turns its
crankshaft as a chain of nodes, each with its own angle and speed (states):

* node 0, the motor's rotor (``J_motor``; its angle and speed are the machine's ``theta1``,
  ``omega1``); the motor's torque ``T_m(omega1)`` acts on it;
* node 1, the flywheel (``J_drive`` less ``J_motor``: ``J_drive`` keeps its meaning, the
  inertia of the whole drive, so a machine and its rigid version take the same values);
* nodes 2 ..., the throws' cranks in the order of their ``axial_position`` from the
  flywheel's end (``throw2.theta_shaft``, ``throw2.omega_shaft``).

Node ``i`` and node ``i + 1`` are joined by section ``i``: the coupling (``k_coupling``,
``c_coupling``) between rotor and flywheel, then the crankshaft between the flywheel and the
first throw and between neighbouring throws (a throw's ``k_shaft``, ``c_shaft``: the section
that ends at it). A section's twist is ``theta_i - theta_(i+1)`` (positive when the driving
end leads) and it carries the torque ``k twist + c twist'`` from node ``i`` to ``i + 1``.

Node ``i``'s equation, with ``T_(-1) = T_(n-1) = 0``::

    J_i theta_i'' = Q_i + T_(i-1) - T_i

with ``(J_0, Q_0) = (J_motor, T_m)``, ``(J_1, Q_1) = (J_drive - J_motor, 0)`` and, at a
throw's node, ``(J_i, Q_i) = (I_k, Q_k)``, the throw's own share of a free crank's equation
(`recipdyn.model.mechanism.link_kernels.free_contribution`) at its own crank angle (its node's
plus its phase) and speed: its crank, rod and crosshead (``J1`` holds the crank's own inertia,
its webs and counterweights with it). The throw's clearance angle then accelerates at ``c - k
theta_i''`` as on a rigid shaft. The equations are explicit: the springs' torques depend on the
states only, so each node's acceleration is its own torque over its own inertia, no system to
solve. In the limit of stiff sections the nodes turn together and the sum of the equations is
the rigid crank's, ``(J_drive + sum I_k) theta1'' = T_m + sum Q_k`` (the twists then go as
``1/k``: `tests/test_flexible_shaft.py`).

The energy: the mechanisms', the rotor's and flywheel's ``J w^2 / 2`` and the sections'
``k twist^2 / 2`` change by the motor's and the gas's work less the sections' dissipation
``sum c twist'^2`` (the state ``W_shaft_damping``).

The linearised train (each throw its mean inertia, `recipdyn.model.shaft.torsion`) gives the
natural frequencies the run summary checks against API 618's separation from orders 1-10 of
the running speed (`recipdyn.model.shaft.torsion.torsion_summary`). What is left out: the
throws' inertia between the nodes (the crankshaft's own inertia is lumped at the cranks), the
motor's electrical dynamics (its torque follows Kloss's steady-state curve of the rotor's
speed), a gear or belt's own compliance beyond the coupling's.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ...errors import ParameterError
from ..protocol import Param

__all__ = ["PARAMS", "THROW_PARAMS", "order", "nodes", "pack", "check", "twisted_start",
           "state_entries", "section_names", "stiffnesses"]  # fmt: skip

_WHY = ("an assumed drive of the paper's compressor: a 400 kg*m**2 rotor referred to the crank "
        "through a flexible coupling that puts the first torsional mode at ~1.5 x the running "
        "speed of 20 rad/s (API 618's 10 % clear of orders 1 and 2), ~5 % damped: give your "
        "machine's")  # fmt: skip
_WHY_SHAFT = ("an assumed crankshaft section of the paper's compressor (steel, 100 mm journals, "
              "0.3 m between cranks: G pi d^4 / (32 L) = 2.6e6 N*m/rad), ~2 % of a throw's "
              "critical damping: give your machine's")  # fmt: skip

#: The flexible shaft's own parameters (the shaft's, in ``[shaft.torsion]``).
PARAMS = (
    Param("J_motor", "kg*m**2", 400.0, "inertia of the motor's rotor referred to the crank "
          "shaft (the flywheel is J_drive less it; [shaft.torsion])", 0.0, 1e7, low_open=True,
          high_ref="J_drive", assumed=_WHY, group="torsion"),
    Param("k_coupling", "N*m/rad", 3e5, "torsional stiffness of the coupling between the "
          "rotor and the flywheel", 0.0, 1e12, low_open=True, assumed=_WHY, group="torsion"),
    Param("c_coupling", "N*m*s/rad", 1e3, "torsional damping of the coupling", 0.0, 1e9,
          assumed=_WHY, group="torsion"),
)  # fmt: skip
#: Each throw's: the crankshaft section between it and its neighbour toward the flywheel.
THROW_PARAMS = (
    Param("k_shaft", "N*m/rad", 2.5e6, "torsional stiffness of the crankshaft between this "
          "throw's crank and its neighbour toward the flywheel ([shaft.torsion])", 0.0, 1e12,
          low_open=True, assumed=_WHY_SHAFT, group="torsion"),
    Param("c_shaft", "N*m*s/rad", 40.0, "torsional damping of that crankshaft section", 0.0,
          1e9, assumed=_WHY_SHAFT, group="torsion"),
)  # fmt: skip


def order(machine) -> list[int]:
    """The throws' indexes in the order of their ``axial_position`` from the flywheel's end
    (ties keep the file's order), as `recipdyn.model.shaft.train_of` orders them."""
    return sorted(range(len(machine.throws)), key=lambda k: machine.throws[k].axial_position)


def nodes(machine) -> list[str]:
    """The nodes' names along the shaft: ``motor``, ``flywheel``, then the throws'."""
    return ["motor", "flywheel", *(machine.throws[k].name for k in order(machine))]


def state_entries(machine) -> tuple[tuple[str, str], ...]:
    """The states after the rotor's (``theta1``, ``omega1``): each further node's angle and
    speed, along the shaft."""
    pre = machine.prefix("shaft")
    out = [(pre + "theta_flywheel", "rad"), (pre + "omega_flywheel", "rad/s")]
    for k in order(machine):
        q = machine.prefix(machine.throws[k].name)
        out += [(q + "theta_shaft", "rad"), (q + "omega_shaft", "rad/s")]
    return tuple(out)


def section_names(machine) -> list[str]:
    """Each section's name prefix in the records: ``coupling_`` (rotor to flywheel), then
    ``<throw>.shaft_`` (the section that ends at that throw)."""
    pre = machine.prefix("shaft")
    return [
        pre + "coupling_",
        *(machine.prefix(machine.throws[k].name) + "shaft_" for k in order(machine)),
    ]


def stiffnesses(machine, values: Mapping[str, Any]) -> tuple[float, ...]:
    """The sections' stiffnesses along the shaft, N m/rad."""
    pre = machine.prefix("shaft")
    return (float(values[pre + "k_coupling"]),
            *(float(values[machine.prefix(machine.throws[k].name) + "k_shaft"])
              for k in order(machine)))  # fmt: skip


def _dampings(machine, values: Mapping[str, Any]) -> tuple[float, ...]:
    pre = machine.prefix("shaft")
    return (float(values[pre + "c_coupling"]),
            *(float(values[machine.prefix(machine.throws[k].name) + "c_shaft"])
              for k in order(machine)))  # fmt: skip


def check(machine, values: Mapping[str, Any]) -> None:
    """The rotor lighter than the whole drive: ``J_motor < J_drive``."""
    pre = machine.prefix("shaft")
    jm, jd = float(values[pre + "J_motor"]), float(values[pre + "J_drive"])
    if not jm < jd:
        raise ParameterError(f"{pre}J_motor = {jm:g} kg*m**2 is out of range; allowed: (0, "
                             f"{pre}J_drive = {jd:g}) kg*m**2 (J_drive: the rotor and the "
                             "flywheel together)")  # fmt: skip


def pack(machine, values: Mapping[str, Any]) -> tuple[np.ndarray, list[tuple[str, str]]]:
    """The flexible shaft's slice of the parameter vector and its entries' names: ``J_motor``,
    the flywheel's ``J_drive - J_motor``, then per section its ``(k, c)`` along the shaft."""
    pre = machine.prefix("shaft")
    jm, jd = float(values[pre + "J_motor"]), float(values[pre + "J_drive"])
    out = [jm, jd - jm]
    names = [(pre + "J_motor", "kg*m**2"), ("", "kg*m**2")]
    ks, cs = stiffnesses(machine, values), _dampings(machine, values)
    for i, (k, c) in enumerate(zip(ks, cs, strict=True)):
        out += [k, c]
        if i == 0:
            names += [(pre + "k_coupling", "N*m/rad"), (pre + "c_coupling", "N*m*s/rad")]
        else:
            q = machine.prefix(machine.throws[order(machine)[i - 1]].name)
            names += [(q + "k_shaft", "N*m/rad"), (q + "c_shaft", "N*m*s/rad")]
    return np.asarray(out, dtype=np.float64), names


def twisted_start(rhs, y: np.ndarray, angles: Sequence[int], inertias: tuple[float, float],
                  ks: Sequence[float], held: bool = False) -> np.ndarray:  # fmt: skip
    """``y`` with the nodes (their angles' states ``angles``, along the shaft; their speeds
    next to them) twisted as the rigid shaft's motion at that instant asks: the sections'
    quasi-static twists, so that a run starts without the torsional transient of the whole
    load (only the twists' rates, ``O(T' / k)``, are left to start one).

    The throws' shares ``(I_k, Q_k)`` come from the right-hand side ``rhs(y) -> dy/dt``
    itself: with every node at the rotor's angle and speed (no twist) a throw's node
    accelerates at ``Q_k / I_k``; with its upstream neighbour turned on by ``delta`` the
    section adds ``k delta`` (the throw's share does not depend on its neighbour), so
    ``I_k = k delta / (change of its acceleration)``. The rotor's at no twist is ``T_m /
    J_motor``. Then the rigid shaft's acceleration ``a = (T_m + sum Q) / (J_motor + J_flywheel
    + sum I)`` and each node's equation ``J_i a = Q_i + T_(i-1) - T_i`` give the sections'
    torques ``T_i`` along the shaft, and their twists ``T_i / k_i``. ``inertias``: ``(J_motor,
    J_flywheel)``; ``ks``: the sections' stiffnesses. ``held``: the rotor is held at its
    speed (the torque law ``held``): the shaft's acceleration is then 0 and the rotor's
    torque the one the shares ask, ``-sum Q``."""
    y = np.array(y, dtype=np.float64)
    rotor = angles[0]
    for i in angles:
        y[i], y[i + 1] = y[rotor], y[rotor + 1]
    f0 = rhs(y)
    delta = 1e-3
    shares = []
    for j in range(2, len(angles)):
        yy = y.copy()
        yy[angles[j - 1]] += delta
        a0, a1 = f0[angles[j] + 1], rhs(yy)[angles[j] + 1]
        inertia = ks[j - 1] * delta / (a1 - a0)
        shares.append((inertia, inertia * a0))
    if held:
        tm, alpha = -sum(q for _, q in shares), 0.0
    else:
        tm = inertias[0] * f0[rotor + 1]
        alpha = (tm + sum(q for _, q in shares)) / (sum(inertias) + sum(i for i, _ in shares))
    torque = tm - inertias[0] * alpha  # the coupling's
    torques = [torque, torque - inertias[1] * alpha]
    for inertia, q in shares[:-1]:
        torques.append(torques[-1] + q - inertia * alpha)
    theta = y[rotor]
    for j in range(1, len(angles)):
        theta = theta - torques[j - 1] / ks[j - 1]
        y[angles[j]] = theta
    return y
