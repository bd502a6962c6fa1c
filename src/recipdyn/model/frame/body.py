r"""The frame on its elastic mounts: a rigid body in the horizontal plane that every throw shakes.

**The plane.** The frame moves as a rigid body in the horizontal plane x-z of the frame's
axes (`FRAME_AXES`: x along the line of stroke of a throw with ``cylinder_angle`` 0, y up, z
along the crankshaft): the plane that holds every cylinder axis and the crankshaft's axis. In
it act the throws' shaking forces along the stroke, ``F_x,k``, and the rocking couple they
make about the vertical axis, ``sum_k z_k F_x,k``, through which throws at different places
along the shaft shake each other's guides. Out of the plane are left: the vertical forces
(the rotating unbalance's ``F_y``), the moment about the shaft's axis (the drive torque's
reaction and the guide's normal-force couple) and the rocking about x; each would need the
body's other three degrees of freedom.

**What shakes it.** Newton for a throw's moving parts (crank, rod, crosshead with piston): the
frame's bearings and guide, the gas and gravity act on them, so ``F_frame->parts + F_gas +
m g = sum m_i a_i``. The frame feels ``-F_frame->parts`` and, on the cylinder head, the gas
force ``-F_gas`` (equal and opposite to the piston's, on the same line): the two gas forces
cancel and the frame's dynamic load is the **shaking force** ``-sum m_i a_i``
(`recipdyn.model.mechanism.shaking`), with no moment about the vertical axis of its own beyond
``z_k F_x,k`` (the parts move in the throw's plane ``z = z_k``, so ``dH_y/dt = z_k sum m_i
a_x,i``; the gas pair lies on one line). Its weight is static and balanced by the mounts'
preload. So the frame's generalised forces are

    Q_x = sum_k F_x,k,    Q_z = 0,    Q_psi = sum_k (z_k - z_cm) F_x,k.

**Coordinates and equations.** ``q = (x, z, psi)``: the displacement of the centre of mass
``(x_cm, z_cm)`` along x and z, and the rotation about the vertical axis y (right-handed: a
point at ``(x_cm + dx, z_cm + dz)`` moves by ``(psi dz, -psi dx)``). The mass matrix is
``M = diag(mass, mass, inertia)`` (inertia about the vertical axis through the centre of
mass). Mount ``i`` at ``(x_i, z_i)`` with springs ``k_x,i``, ``k_z,i`` and dampers ``c_x,i``,
``c_z,i`` along x and z stretches by ``a_i . q`` along x and ``b_i . q`` along z with
``a_i = (1, 0, z_i - z_cm)``, ``b_i = (0, 1, -(x_i - x_cm))``, so

    K = sum_i k_x,i a_i a_i^T + k_z,i b_i b_i^T,   C likewise,   M q'' + C q' + K q = Q(t).

The frame's energy ``E = q'^T M q' / 2 + q^T K q / 2`` changes by the throws' work ``int Q .
q' dt`` less the mounts' dissipation ``int q'^T C q' dt`` (the states ``frame.W_throws``,
``frame.W_damping``).

**One-way coupling.** The throws' equations are written in axes fixed to the ground: the
frame's motion does not act back on them. The neglected term is the inertial force
``-(m1 + m2 + m3) a_f`` on a throw's parts from the frame's acceleration ``a_f`` at its
guide (and the frame's turning of the throw's axes, of second order in ``psi``); its size
beside the throw's own shaking force is the record's ``frame_feedback`` and the run summary's
``frame_feedback_ratio``; beyond `FEEDBACK_LIMIT` the run is outside the model's validity
(the machine's validity bound ``frame_coupling_margin >= 0``: warned, verdicts withheld).

**The accelerometers.** The frame's motion along a throw's line of stroke at its crosshead
guide (at ``z_k``) is ``cos(cylinder_angle) (x + psi (z_k - z_cm))`` (a cylinder at 0 or 180
deg: the frame's z motion is across every stroke); an accelerometer on the crosshead reads
the crosshead's acceleration relative to the frame plus the frame's there: ``throwK.accel =
throwK.a + throwK.frame_a``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ...errors import ParameterError
from ..protocol import Param

__all__ = ["PARAMS", "MOUNT_PARAMS", "STATES", "WORK", "local_params", "matrices", "pack",
           "check", "PACKED", "energy", "at_guide", "FEEDBACK_LIMIT"]  # fmt: skip

#: The largest neglected feedback (`frame_feedback`: a throw's moving mass times the frame's
#: acceleration at its guide, over its largest shaking force) the one-way coupling allows: the
#: frame's load, linear in the shaking forces, is then off by at most this fraction of a throw's
#: (to first order; the throws' own motion, driven by the much larger gas and inertia loads,
#: far less).
FEEDBACK_LIMIT = 0.05

_WHY = ("an assumed frame of a mid-size two-throw process compressor (steel bedplate ~3 x 2 m, "
        "8 t; mounts ~25 Hz, ~3 % damping): give your machine's")  # fmt: skip

#: The frame's parameters (under ``frame.``).
PARAMS = (
    Param("mass", "kg", 8000.0, "mass of the frame (with everything fixed to it: cylinders, "
          "guides, the crankshaft's bearings)", 0.0, 1e7, low_open=True, assumed=_WHY,
          group="frame"),
    Param("inertia", "kg*m**2", 8700.0, "moment of inertia of the frame about the vertical "
          "axis through its centre of mass", 0.0, 1e9, low_open=True, assumed=_WHY,
          group="frame"),
    Param("x_cm", "m", 0.0, "centre of mass of the frame along x (the line of stroke of a "
          "throw at cylinder_angle 0)", -100.0, 100.0, group="frame"),
    Param("z_cm", "m", 0.0, "centre of mass of the frame along z (the crankshaft)", -100.0,
          100.0, group="frame"),
)  # fmt: skip
#: Each mount's parameters (under ``frame.<mount>.``).
MOUNT_PARAMS = (
    Param("k_x", "N/m", 5e7, "mount stiffness along x", 0.0, 1e12, assumed=_WHY,
          group="frame"),
    Param("k_z", "N/m", 5e7, "mount stiffness along z", 0.0, 1e12, assumed=_WHY,
          group="frame"),
    Param("c_x", "N*s/m", 2e4, "mount damping along x", 0.0, 1e9, assumed=_WHY,
          group="frame"),
    Param("c_z", "N*s/m", 2e4, "mount damping along z", 0.0, 1e9, assumed=_WHY,
          group="frame"),
)  # fmt: skip
#: The frame's states (``frame.x``, ...) and its work integrals.
STATES = (("x", "m"), ("z", "m"), ("psi", "rad"), ("xdot", "m/s"), ("zdot", "m/s"),
          ("psidot", "rad/s"))  # fmt: skip
WORK = (("W_throws", "J"), ("W_damping", "J"))
#: The packed slice: mass, inertia, K (3 x 3, by rows), C (3 x 3), then per throw
#: ``(cos, sin)`` of its cylinder angle and its lever ``z_k - z_cm``.
PACKED = 20


def local_params(frame) -> tuple[Param, ...]:
    """The frame's parameters under their names inside ``frame.``: ``mass``, ...,
    ``mount2.k_x``."""
    from dataclasses import replace

    return (*PARAMS, *(replace(p, name=f"{m.name}.{p.name}") for m in frame.mounts
                       for p in MOUNT_PARAMS))  # fmt: skip


def matrices(frame, local: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(M, K, C)``, 3 x 3, of the frame at its values ``local`` (names inside ``frame.``):
    the module docstring's sums over the mounts."""
    xc, zc = float(local["x_cm"]), float(local["z_cm"])
    M = np.diag([float(local["mass"]), float(local["mass"]), float(local["inertia"])])
    K = np.zeros((3, 3))
    C = np.zeros((3, 3))
    for m in frame.mounts:
        a = np.array([1.0, 0.0, m.z - zc])
        b = np.array([0.0, 1.0, -(m.x - xc)])
        pre = f"{m.name}."
        K += float(local[pre + "k_x"]) * np.outer(a, a) + float(local[pre + "k_z"]) * np.outer(b, b)
        C += float(local[pre + "c_x"]) * np.outer(a, a) + float(local[pre + "c_z"]) * np.outer(b, b)
    return M, K, C


def check(frame, local: Mapping[str, Any]) -> None:
    """Refuse mounts that leave the frame free (``K`` singular: a rigid-body motion without a
    spring, such as every mount without a ``k_z``)."""
    _, K, _ = matrices(frame, local)
    w = np.linalg.eigvalsh(K)
    if not w[0] > 1e-9 * max(w[-1], 0.0):
        raise ParameterError(
            "frame: its mounts leave it free to move (the stiffness matrix is singular); "
            "allowed: mounts whose k_x and k_z restrain x, z and the turning about the "
            "vertical axis (e.g. k_x > 0 at two places along z and k_z > 0 somewhere)"
        )


def _cos_sin(angle: float) -> tuple[float, float]:
    """The cylinder angle's cosine and sine, exact at 0 and pi."""
    if angle == 0.0:
        return 1.0, 0.0
    if angle == math.pi:
        return -1.0, 0.0
    return math.cos(angle), math.sin(angle)


def pack(machine, local: Mapping[str, Any]) -> np.ndarray:
    """The frame's slice of the parameter vector (`PACKED`, then 3 per throw)."""
    M, K, C = matrices(machine.frame, local)
    zc = float(local["z_cm"])
    per = [(*_cos_sin(t.cylinder_angle), t.axial_position - zc) for t in machine.throws]
    return np.concatenate([[M[0, 0], M[2, 2]], K.ravel(), C.ravel(), np.ravel(per)])


def energy(M, K, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """``q'^T M q' / 2 + q^T K q / 2`` at each sample (``q``, ``qd``: (n, 3)), J."""
    return 0.5 * (np.einsum("ni,ij,nj->n", qd, M, qd) + np.einsum("ni,ij,nj->n", q, K, q))


def at_guide(throw, local: Mapping[str, Any], q: np.ndarray) -> np.ndarray:
    """The frame's motion along ``throw``'s line of stroke at its guide, in the throw's own
    axes, from ``q`` (n, 3) of displacements, velocities or accelerations: ``cos(cylinder
    angle) (x + psi (z_k - z_cm))``."""
    c, _ = _cos_sin(throw.cylinder_angle)
    return c * (q[:, 0] + q[:, 2] * (throw.axial_position - float(local["z_cm"])))
