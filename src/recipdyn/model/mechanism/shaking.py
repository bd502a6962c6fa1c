r"""The forces a throw's moving parts exert on the frame, and the machine's sums.

A throw's crank (mass ``m1``, centroid at ``rs`` from the shaft's axis), connecting rod
(``m2``, centroid at ``ls`` from the crank pin) and crosshead with piston and piston rod
(``m3``) move; by d'Alembert the frame that holds the shaft's bearings, the crosshead guide
and the cylinder feels, beyond their constant weight, the **shaking force**

    F = -(m1 a1 + m2 a2 + m3 a3)

(``a1 = rs (-omega1^2 e(theta1) + alpha1 n(theta1))``, ``a2`` the rod centroid's, ``a3`` the
crosshead's along the stroke). The gas force is internal to each throw: it pushes the piston
and, equal and opposite, the cylinder head bolted to the frame, so it cancels in the frame's
load. The accelerations are those of the record (`recipdyn.model.kinematics`: the integrated
clearance angle, the crank's speed and, with a motor, its acceleration), so the link's
clearance motion shows in the forces.

A throw's equations run in its own axes, its x along its line of stroke; in the frame those
axes are turned by its ``cylinder_angle`` about the shaft's axis z, and its plane sits at
``axial_position`` along z. The machine's force is the sum of the throws' in the frame's axes,
and its moments about the frame's x and y axes through the datum ``z = 0`` are

    M_x = -sum_k z_k F_y,k,     M_y = sum_k z_k F_x,k

(a force couple: independent of the datum when the sum of the forces vanishes). The moment
about the shaft's axis (the reaction of the drive's torque and of the parts' in-plane
moments) is not part of it.

For the closed forms these reproduce (rotating and reciprocating masses; primary and
secondary forces; balanced-opposed and inline arrangements): Den Hartog, *Mechanical
Vibrations*, 4th ed. (1956), ch. 5 (sections 5.3-5.5); the tests
(`tests/test_shaking.py`).

The rod load at the crosshead pin (API Standard 618, 5th ed., 6.6.3: gas force plus the
reciprocating parts' inertia) is ``m3 a3 - F_gas``, positive in compression (the rod pushes
the crosshead away from the crank), as `recipdyn.model.cycle.pin_reversal_summary` takes it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ..kinematics import Kinematics

__all__ = ["throw_shaking", "in_frame", "rod_load"]


def throw_shaking(p, kin: Kinematics, omega1, alpha1=None) -> tuple[np.ndarray, np.ndarray]:
    """The shaking force of one throw in its own axes, N: ``(F_x, F_y)`` at each sample.

    Parameters
    ----------
    p : CompressorParams
        The throw's masses and lengths (``m1, rs, m2, m3``).
    kin : Kinematics
        Its kinematics on the recorded states (`recipdyn.model.kinematics.kinematics`); its
        ``theta1`` is the crank angle in the throw's axes.
    omega1, alpha1 : float or array_like
        The crank's speed (rad/s) and acceleration (rad/s^2; None: 0, a prescribed speed).
    """
    th = np.asarray(kin.theta1, dtype=float)
    c, s = np.cos(th), np.sin(th)
    w2 = np.asarray(omega1, dtype=float) ** 2
    a1x, a1y = -p.rs * w2 * c, -p.rs * w2 * s
    if alpha1 is not None:
        al = np.asarray(alpha1, dtype=float)
        a1x, a1y = a1x - p.rs * al * s, a1y + p.rs * al * c
    fx = -(p.m1 * a1x + p.m2 * kin.ax2 + p.m3 * kin.a3)
    fy = -(p.m1 * a1y + p.m2 * kin.ay2)
    return fx, fy


def in_frame(fx, fy, cylinder_angle: float) -> tuple[np.ndarray, np.ndarray]:
    """A throw's force in the frame's axes: its own axes turned by ``cylinder_angle`` (rad).
    The angles a machine allows (0, pi) turn exactly: no rounding of ``cos(pi)``."""
    if cylinder_angle == 0.0:
        return np.asarray(fx, dtype=float), np.asarray(fy, dtype=float)
    if cylinder_angle == np.pi:
        return -np.asarray(fx, dtype=float), -np.asarray(fy, dtype=float)
    c, s = np.cos(cylinder_angle), np.sin(cylinder_angle)
    return c * fx - s * fy, s * fx + c * fy


def rod_load(p, kin: Kinematics, gas_force) -> np.ndarray:
    """The combined rod load at the crosshead pin, N (> 0: compression): ``m3 a3 - F_gas``."""
    return p.m3 * np.asarray(kin.a3, dtype=float) - np.asarray(gas_force, dtype=float)
