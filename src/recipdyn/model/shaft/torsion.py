r"""The crankshaft train's torsional natural frequencies and modes (issue 43; API 618's
torsional analysis).

A train is a chain of lumped inertias joined by torsional springs: the motor's rotor, the
flywheel and the throws along the crankshaft (in the order of their ``axial_position``),
``J_i`` in kg m² and ``k_i`` in N m/rad between node ``i`` and ``i + 1``. Its undamped free
vibration ``M theta'' + K theta = 0`` has the modes of the generalised eigenproblem
``K phi = w^2 M phi`` (`scipy.linalg.eigh`); the first, at 0, is the train turning as one
body and is left out of the natural frequencies.

A throw's inertia is its slider-crank's **mean** kinetic energy at unit crank speed,
``J_eq = 2 <T> / w^2`` over a revolution of the exact kinematics (crank about the main
bearing, rod with its centroid at ``ls`` and its own ``J2``, crosshead with piston; the
crosshead's offset ``d`` included): the usual equivalent inertia of torsional analyses, in
which the reciprocating mass counts about half (``m_rec r^2 (1/2 + lam^2/8 + O(lam^4))``,
Wilson, *Practical Solution of Torsional Vibration Problems*, vol. 1, ch. 3; Den Hartog,
*Mechanical Vibrations*, 4th ed., 1956, sec. 5.8). The variation of that inertia over the
revolution (the secondary effects of the reciprocating parts) is not a linear mode's
concern: it is what a time integration of a flexible shaft would show.

API 618 (5th ed., 2007, sec. 7.9.2.5 and 7.9.2.6) asks that the train's torsional natural
frequencies lie at least 10 % away from every order of the running speed up to the 10th
(`TorsionalTrain.interference`): the orders of the gas and inertia torque excite them.

What this module does not do: damping, or the time integration of the flexible shaft (a
machine with a ``[shaft.torsion]``: `recipdyn.model.shaft.flexible`, whose run summary gives
`torsion_summary`). The independent check is openTorsion's lumped model
(`tests/test_torsion.py`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import ParameterError

__all__ = ["TorsionalTrain", "throw_inertia", "train_of", "torsion_summary", "API618_MARGIN",
           "API618_ORDERS"]  # fmt: skip

#: API 618's separation margin of a torsional natural frequency from an excitation order.
API618_MARGIN = 0.10
#: The orders of the running speed API 618 asks the train to be separated from (1 to 10).
API618_ORDERS = tuple(range(1, 11))
#: Points per revolution of the mean kinetic energy (the derivatives are spectral: the
#: kinematics are smooth and periodic, so the mean converges geometrically; 512 reach
#: rounding for lam < 0.5).
_POINTS = 512


@dataclass(frozen=True)
class TorsionalTrain:
    """A chain of lumped inertias joined by torsional springs.

    Parameters
    ----------
    names : tuple of str
        The nodes' names, along the shaft.
    inertias : tuple of float
        Each node's moment of inertia about the shaft's axis, kg m² (> 0).
    stiffnesses : tuple of float
        The springs between consecutive nodes, N m/rad (> 0; one fewer than the nodes).
    grounded : bool
        The first node is held at a constant speed (a rotor held by its drive, the torque law
        ``held``): it does not take part in the vibration, and the train has no rigid
        turning; its inertia is then left out.
    """

    names: tuple[str, ...]
    inertias: tuple[float, ...]
    stiffnesses: tuple[float, ...]
    grounded: bool = False

    def __post_init__(self) -> None:
        n = len(self.inertias)
        if n < 2 or len(self.names) != n:
            raise ParameterError(f"torsional train: {n} inertias for {len(self.names)} names; "
                                 "allowed: at least 2 nodes, one name each")  # fmt: skip
        if len(self.stiffnesses) != n - 1:
            raise ParameterError(f"stiffness: {len(self.stiffnesses)} values for {n} nodes "
                                 f"({', '.join(self.names)}); allowed: {n - 1}, one between "
                                 "each pair of neighbours")  # fmt: skip
        for name, j in zip(self.names, self.inertias, strict=True):
            if not (math.isfinite(j) and j > 0.0):
                raise ParameterError(f"{name}: inertia = {j!r} kg*m**2; allowed: (0, inf)")
        for i, k in enumerate(self.stiffnesses):
            if not (math.isfinite(k) and k > 0.0):
                raise ParameterError(f"stiffness[{i}] ({self.names[i]}-{self.names[i + 1]}) = "
                                     f"{k!r} N*m/rad; allowed: (0, inf)")  # fmt: skip

    def matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """The mass and stiffness matrices ``(M, K)`` of the chain."""
        m = np.diag(np.asarray(self.inertias, dtype=float))
        n = len(self.inertias)
        k = np.zeros((n, n))
        for i, ki in enumerate(self.stiffnesses):
            k[i : i + 2, i : i + 2] += ki * np.array([[1.0, -1.0], [-1.0, 1.0]])
        return m, k

    def modes(self) -> tuple[np.ndarray, np.ndarray]:
        """``(f, phi)``: the natural frequencies in Hz, ascending, the rigid turning (0 Hz)
        left out, and their mode shapes (columns, mass-normalised; a grounded train's over
        the nodes after the first)."""
        from scipy.linalg import eigh

        m, k = self.matrices()
        if self.grounded:  # the first node's angle is given: its row and column go
            w2, phi = eigh(k[1:, 1:], m[1:, 1:])
            return np.sqrt(np.clip(w2, 0.0, None)) / (2.0 * math.pi), phi
        w2, phi = eigh(k, m)
        return np.sqrt(np.clip(w2[1:], 0.0, None)) / (2.0 * math.pi), phi[:, 1:]

    def natural_frequencies(self) -> np.ndarray:
        """The torsional natural frequencies in Hz, ascending (the rigid turning left out)."""
        return self.modes()[0]

    def interference(
        self,
        speed_hz: float,
        orders: Sequence[int] = API618_ORDERS,
        margin: float = API618_MARGIN,
    ) -> list[dict[str, Any]]:
        """The pairs (natural frequency, order of ``speed_hz``) closer than ``margin``
        (relative to the order's frequency), each ``{"mode", "f_hz", "order", "order_hz",
        "separation"}``; empty when every natural frequency is clear of every order."""
        if not (math.isfinite(speed_hz) and speed_hz > 0.0):
            raise ParameterError(f"speed_hz = {speed_hz!r}; allowed: (0, inf) Hz")
        out = []
        for i, f in enumerate(self.natural_frequencies(), 1):
            for n in orders:
                sep = abs(f - n * speed_hz) / (n * speed_hz)
                if sep < margin:
                    out.append({"mode": i, "f_hz": float(f), "order": int(n),
                                "order_hz": n * speed_hz, "separation": float(sep)})  # fmt: skip
        return out


def throw_inertia(local: Mapping[str, Any], points: int = _POINTS) -> float:
    """A throw's equivalent inertia about the shaft, kg m²: twice its mean kinetic energy over
    a revolution at unit crank speed (module docstring), from its values under the
    compressor's names (``r, rs, l, ls, m1, m2, m3, J1, J2, d``)."""
    r, l, ls, d = (float(local[k]) for k in ("r", "l", "ls", "d"))
    m1, m2, m3 = (float(local[k]) for k in ("m1", "m2", "m3"))
    th = 2.0 * math.pi * np.arange(points) / points
    s = r * np.sin(th) + d  # the crank pin's height above the crosshead's line
    if np.max(np.abs(s)) >= l:
        raise ParameterError(f"l = {l:g} m; allowed: > r + |d| = {r + abs(d):g} m")
    cx, cy = r * np.cos(th), r * np.sin(th)  # crank pin
    x3 = cx + np.sqrt(l * l - s * s)  # crosshead, at y = -d
    gx, gy = cx + ls / l * (x3 - cx), cy + ls / l * (-d - cy)  # rod's centroid
    th2 = np.arcsin(-s / l)  # rod's angle

    def ddth(f):
        k = np.fft.rfftfreq(points, 1.0 / points)
        return np.fft.irfft(1j * k * np.fft.rfft(f), points)

    rod = m2 * (ddth(gx) ** 2 + ddth(gy) ** 2) + float(local["J2"]) * ddth(th2) ** 2
    reciprocating = m3 * ddth(x3) ** 2
    crank = float(local["J1"]) + m1 * float(local["rs"]) ** 2
    return crank + float(np.mean(rod + reciprocating))


def train_of(
    machine,
    values: Mapping[str, Any],
    stiffness: Sequence[float],
    J_motor: float | None = None,
    J_drive: float | None = None,
    held: bool = False,
) -> TorsionalTrain:
    """The torsional train of ``machine`` (a `recipdyn.model.machine.Machine`) at its
    validated ``values``: the motor's rotor (``J_motor``, if given), the flywheel (the drive's
    inertia ``J_drive`` less ``J_motor``; ``J_drive`` from the shaft's values with a motor,
    given here with a prescribed speed, whose drive has no inertia of its own), then each
    throw's equivalent inertia (`throw_inertia`) in the order of their ``axial_position``;
    ``stiffness`` the springs between them in that order, N m/rad (the coupling, the shaft to
    the first throw, then between neighbouring throws). ``held``: the rotor is held at its
    speed (`TorsionalTrain`'s ``grounded``; needs ``J_motor``)."""
    from ..assembler.assemble import throw_values

    locals_ = [throw_values(machine, values, k) for k in range(len(machine.throws))]
    order = sorted(range(len(machine.throws)), key=lambda k: machine.throws[k].axial_position)
    if J_drive is None and "J_drive" not in locals_[0]:
        raise ParameterError("J_drive: not given; allowed: the drive's inertia (0, inf) "
                             "kg*m**2 (a machine with drive = 'motor' has it)")  # fmt: skip
    j_drive = float(locals_[0]["J_drive"] if J_drive is None else J_drive)
    names, inertias = [], []
    if J_motor is not None:
        if not (math.isfinite(J_motor) and 0.0 < J_motor < j_drive):
            raise ParameterError(f"J_motor = {J_motor!r} kg*m**2; allowed: (0, J_drive = "
                                 f"{j_drive:g}) kg*m**2 (J_drive: rotor and flywheel)")  # fmt: skip
        names.append("motor")
        inertias.append(float(J_motor))
        j_drive -= float(J_motor)
    names.append("flywheel")
    inertias.append(j_drive)
    for k in order:
        names.append(machine.throws[k].name)
        inertias.append(throw_inertia(locals_[k]))
    if held and J_motor is None:
        raise ParameterError("held: a held rotor needs its node, J_motor; allowed: J_motor in "
                             "(0, J_drive) kg*m**2")  # fmt: skip
    return TorsionalTrain(tuple(names), tuple(inertias), tuple(float(k) for k in stiffness),
                          grounded=held)  # fmt: skip


def torsion_summary(machine, values: Mapping[str, Any], speed_hz: float) -> dict[str, Any]:
    """The linearised train's natural frequencies (`recipdyn.model.shaft.train_of`: each
    throw its mean inertia) and API 618's separation from orders 1-10 of ``speed_hz``: per
    mode ``torsion_f<i>_hz``, its nearest order ``torsion_f<i>_order`` and its separation from
    it ``torsion_f<i>_separation`` (``|f - n f_run| / (n f_run)``); the smallest over the modes,
    ``torsion_min_separation`` with its mode and order, and the verdict ``api618_torsional``
    (``pass``: every mode at least 10 % clear of every order)."""
    from .flexible import stiffnesses

    pre = machine.prefix("shaft")
    train = train_of(machine, values, stiffnesses(machine, values),
                     J_motor=float(values[pre + "J_motor"]),
                     J_drive=float(values[pre + "J_drive"]),
                     held=machine.shaft.motor == "held")  # fmt: skip
    out: dict[str, Any] = {"torsion_running_speed_hz": float(speed_hz)}
    best = (math.inf, 0, 0)
    for i, x in enumerate(train.natural_frequencies(), 1):
        sep, n = min((abs(x - n * speed_hz) / (n * speed_hz), n) for n in API618_ORDERS)
        out.update({f"torsion_f{i}_hz": float(x), f"torsion_f{i}_order": n,
                    f"torsion_f{i}_separation": float(sep)})  # fmt: skip
        best = min(best, (sep, i, n))
    out.update(torsion_min_separation=float(best[0]), torsion_min_separation_mode=best[1],
               torsion_min_separation_order=best[2],
               api618_torsional="pass" if best[0] >= API618_MARGIN else "FAIL")  # fmt: skip
    return out
