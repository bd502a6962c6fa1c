r"""The massless-link throw: what it declares and the signals a record draws from it.

A throw is a crank of the shaft with its connecting rod and crosshead; at the crank pin the
paper's massless link of length ``rc`` (``rc = 0``: an ideal pin). Its parts of a machine:

* parameter slice `MECHANISM` (``r, rs, l, ls, m1, m2, m3, J1, J2, g, rc, d``; the head of
  the contact joints' vector too), and its ``phase``: the angle its crank leads the shaft's by
  (`PHASE`);
* states `STATES`: the clearance angle and its rate;
* compiled roles (`.link_kernels`): the clearance angle's acceleration with a prescribed crank
  (exact, or the paper's printed equations) and its partial derivatives; its contribution to
  a free crank's equation; the crosshead's motion.

The records' signals (`mechanism_outputs`: crosshead motion, rod angle, joint and guide
forces) are the hand-derived kinematics of `recipdyn.model.kinematics` on the integrated
states, independent of the sympy derivation the kernels come from.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ..protocol import Param

if TYPE_CHECKING:
    from ..base import Signal

__all__ = ["MECHANISM", "HEAD", "N_HEAD", "STATES", "PHASE", "equilibrium_theta_c",
           "mechanism_outputs", "mechanism_energy", "SIGN_CONVENTION"]  # fmt: skip

#: The mechanism's slice of the parameter vector, in order.
MECHANISM = ("r", "rs", "l", "ls", "m1", "m2", "m3", "J1", "J2", "g", "rc", "d")
#: The same, as the contact joints' vector begins (`recipdyn.model.joints.pins`).
HEAD = MECHANISM
N_HEAD = len(HEAD)
#: The throw's states.
STATES = (("theta_c", "rad"), ("thetadot_c", "rad/s"))
#: The throw's phase: a machine of several throws has one per throw (``throw2.phase``).
PHASE = Param("phase", "rad", 0.0, "crank phase angle of this throw: its crank angle is the "
              "shaft's plus this (0 = its outer dead centre with the shaft's)", -1e6, 1e6,
              group="mechanism")  # fmt: skip

#: The axes and signs of every compressor record (``sign_convention``).
SIGN_CONVENTION = (
    "x along the cylinder axis from the crank centre toward the cylinder (theta1 = 0: outer dead "
    "centre, x3 = r + l); y up, gravity along -y; crosshead at y3 = -d; gas_force is the force on "
    "the crosshead along +x: -P (load_sign='physical', gas pushes the piston toward the crank) "
    "or +P (load_sign='paper', the sign of Eq. 46)."
)


def equilibrium_theta_c(p, t: float = 0.0, extra=None, force: float | None = None,
                        phase: float = 0.0) -> float:  # fmt: skip
    r"""Clearance angle at which the link is aligned with the rod load at time ``t``.

    The gas force on the crosshead is transmitted along the rod; the massless link is in
    static equilibrium when it points along the rod, ``sin(theta_c - theta2) = 0``, i.e.
    ``dx3/dtheta_c = 0``. The stable branch has the journal pushed away from the load:
    ``theta_c = theta2 + pi`` when the force on the crosshead points toward the crank
    (``F_x < 0``, physical sign, rod in compression) and ``theta_c = theta2`` when it points
    away (``F_x > 0``, the paper's sign, rod in tension). theta2 depends weakly on theta_c
    (``|d theta2/d theta_c| <= rc/(l cos theta2)``), so a fixed-point iteration converges.
    ``extra``: the values of a load from a user's file (beside ``p``'s fields); ``force``: the
    gas force at ``t`` if known (a load with states gives it from its states); ``phase``: the
    throw's, added to the crank angle.
    """
    from ..components.load import force_series

    th1 = p.theta1_0 + p.omega * t + phase
    F = (
        force if force is not None else float(force_series({**vars(p), **(extra or {})}, th1))
    )  # extra: a user's component's
    shift = math.pi if F <= 0.0 else 0.0
    thc = shift
    for _ in range(100):
        s2 = -(p.d + p.r * math.sin(th1) + p.rc * math.sin(thc)) / p.l
        new = math.asin(s2) + shift
        if abs(new - thc) < 1e-15:
            break
        thc = new
    return thc


def mechanism_outputs(p, k, thc, thcd, thcdd, fg) -> dict[str, Signal]:
    """The massless-link throw's signals from its kinematics ``k``
    ([`kinematics`][recipdyn.model.kinematics.kinematics]) and the gas force ``fg`` on the
    crosshead, whatever load gives it (``p``: the throw's
    [`CompressorParams`][recipdyn.model.parameters.CompressorParams])."""
    from ..base import Signal
    from ..kinematics import joint_forces

    jf = joint_forces(p, k, thc, fg)
    return {
        "x": Signal(k.x3, "m", "crosshead displacement x3"),
        "v": Signal(k.v3, "m/s", "crosshead velocity"),
        "a": Signal(k.a3, "m/s**2", "crosshead acceleration"),
        "theta1": Signal(k.theta1, "rad", "crank angle"),
        "theta2": Signal(k.theta2, "rad", "connecting-rod angle"),
        "theta_c": Signal(thc, "rad", "clearance angle"),
        "thetadot_c": Signal(thcd, "rad/s", "clearance angular velocity"),
        "thetaddot_c": Signal(thcdd, "rad/s**2", "clearance angular acceleration"),
        "gas_force": Signal(fg, "N", "gas force on the crosshead along +x"),
        "joint_force_x": Signal(jf.Fx, "N", "clearance-joint force on the rod, x"),
        "joint_force_y": Signal(jf.Fy, "N", "clearance-joint force on the rod, y"),
        "joint_force": Signal(jf.magnitude, "N", "clearance-joint force magnitude"),
        "joint_force_angle": Signal(jf.direction, "rad", "clearance-joint force direction"),
        "contact_force": Signal(jf.contact, "N",
                                "joint contact force (>0: permanent contact holds)"),
        "guide_force": Signal(jf.guide, "N", "guide normal force on the crosshead"),
    }  # fmt: skip


def mechanism_energy(p, theta1, thc, omega1, thcd, J_drive: float = 0.0) -> np.ndarray:
    """``T + V`` of one throw's crank, rod and crosshead (with ``J_drive`` on its crank) at
    each sample, J (the generated expression of the free-crank derivation)."""
    from .._generated_drive import mechanism_energy as energy

    args = [getattr(p, k) for k in MECHANISM] + [J_drive]
    return np.array([energy(a, c, w, cd, *args)
                     for a, c, w, cd in zip(theta1, thc, omega1, thcd, strict=True)])  # fmt: skip
