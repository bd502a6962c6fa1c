r"""The slider-crank with a translational clearance joint of Flores, Leine & Glocker (2010).

A free crank (no driving torque, started at 150 rad/s) drives, through a connecting rod, a
slider that is free to move sideways and tilt inside its guide (radial clearance ``c``); the
slider's four corners hit the guide's two surfaces. Parameters "according to Table 1" of
Flores, Leine & Glocker (2010), *Multibody Syst. Dyn.* 23, 165-190, as the open nonsmooth
multibody code siconos implements the benchmark (``examples/Mechanics/SliderCrank``, Apache-2.0):
see [`FloresTranslational`][recipdyn.model.reference.slider_crank_guide.FloresTranslational].

siconos treats the impacts as Newton impacts with Coulomb friction in a time-stepping scheme;
here the contacts are compliant (`recipdyn.model.joints.guide`): the equations of motion of
the mechanism come from the sympy derivation there, each corner's normal force from one of
recipdyn's contact laws, friction from its regularised Coulomb law, and DOP853 integrates them
with every contact onset and separation located as an event.

State ``(theta1, theta2, phi, theta1', theta2', phi', v_1, v_2, v_3, v_4, W_in, W_loss)``:
the coordinates and their rates; per corner the recorded approach velocity (its sign the
phase: > 0 in contact, < 0 in free flight); the work done on the mechanism by the crank torque
(0 here: the crank is free) and the work lost to contact damping and friction. The energy
balance ``T + V + U = E0 + W_in - W_loss`` (``U`` the contacts' elastic energy) holds along
every run.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba as nb
import numpy as np

from ..base import EVENT_SIGNATURE, RHS_SIGNATURE, Event, ODESystem, compiled
from ..joints._guide import guide_energy, guide_system
from ..joints.contact import (
    FRICTION_LAWS,
    LAWS,
    ambrosio_friction,
    hysteresis_factor,
    tanh_friction,
)
from ..joints.guide import (
    P_A,
    P_B,
    P_C,
    corner_kinematics,
    flip_phases,
    guide_forces,
    pin_kinematics,
    smallest_factor,
    solve_free,
)

__all__ = ["FloresTranslational", "STATE_NAMES", "system", "initial_state", "energy",
           "corner_series"]  # fmt: skip

STATE_NAMES = ("theta1", "theta2", "phi", "theta1_dot", "theta2_dot", "phi_dot", "v_impact_1",
               "v_impact_2", "v_impact_3", "v_impact_4", "W_in", "W_loss")  # fmt: skip
STATE_UNITS = ("rad",) * 3 + ("rad/s",) * 3 + ("m/s",) * 4 + ("J", "J")


@dataclass(frozen=True)
class FloresTranslational:
    """Parameters of the benchmark (SI units).

    Mechanism (siconos's ``SliderCrankPlugin.cpp``, "parameters according to Table 1"):
    crank ``l1`` with mass ``m1`` and inertia ``J1`` about its centre (at ``l1/2``), rod ``l2``
    (``m2``, ``J2``, centre at ``l2/2``), slider ``m3``, ``J3``, half-length ``a``,
    half-height ``b``, radial clearance ``c`` (guide gap ``2(b + c)``), gravity ``g`` along -y;
    start (siconos's ``...OSI.cpp``): all angles 0, crank at ``omega0``, rod at
    ``-omega0 l1/l2`` (the slider's lateral velocity 0).

    Contact (recipdyn's choice, see docs/flores_benchmark.md): ``law`` with nominal
    restitution ``restitution`` (the benchmark's ``eN = 0.4``), stiffness ``K`` of a corner on a
    guide surface, Coulomb friction ``mu`` (the benchmark's 0.01) regularised as recipdyn's
    joints are (`friction_law`, ``v0``, ``v1``), floor ``v_impact_min`` of the recorded
    approach velocity.
    """

    l1: float = 0.1530
    l2: float = 0.3060
    a: float = 0.05
    b: float = 0.025
    c: float = 0.001
    m1: float = 0.038
    m2: float = 0.038
    m3: float = 0.076
    J1: float = 7.4e-5
    J2: float = 5.9e-4
    J3: float = 2.7e-6
    g: float = 9.81
    omega0: float = 150.0
    law: str = "gonthier"
    restitution: float = 0.4
    K: float = 1e10
    mu: float = 0.01
    friction_law: str = "ambrosio"
    v0: float = 1e-4
    v1: float = 1e-3
    v_impact_min: float = 1e-3

    def __post_init__(self) -> None:
        for k in ("l1", "l2", "a", "b", "m1", "m2", "m3", "J1", "J2", "J3", "K", "v0",
                  "v1", "v_impact_min"):  # fmt: skip
            if not getattr(self, k) > 0:
                raise ValueError(f"{k} = {getattr(self, k)!r}; allowed: (0, inf)")
        if not 0 <= self.c < self.b:
            raise ValueError(f"c = {self.c!r} m; allowed: [0, b = {self.b}) m")
        if not self.l2 > self.l1:
            raise ValueError(f"l2 = {self.l2!r} m; allowed: (l1 = {self.l1}, inf) m")
        if self.law not in LAWS:
            raise ValueError(f"law = {self.law!r}; allowed: {', '.join(LAWS)}")
        if self.friction_law not in FRICTION_LAWS:
            raise ValueError(f"friction_law = {self.friction_law!r}; allowed: "
                             f"{', '.join(FRICTION_LAWS)}")  # fmt: skip
        if not 0 <= self.mu <= 2:
            raise ValueError(f"mu = {self.mu!r}; allowed: [0, 2]")
        if self.v1 <= self.v0:
            raise ValueError(f"v1 = {self.v1!r} m/s must exceed v0 = {self.v0!r} m/s")
        hysteresis_factor(self.law, self.restitution)  # checks the restitution's range

    def pack(self) -> np.ndarray:
        mech = (self.l1, self.l1 / 2, self.l2, self.l2 / 2, self.m1, self.m2, self.m3,
                self.J1, self.J2, self.J3, self.g)  # fmt: skip
        return np.array([*mech, 0.0, self.a, self.b, self.c, self.K,
                         hysteresis_factor(self.law, self.restitution), self.mu, self.v0,
                         self.v1, self.v_impact_min, self.b], dtype=np.float64)  # fmt: skip


@nb.njit(cache=True, inline="always")
def _pin(y, p):
    return pin_kinematics(p, y[0], y[3], y[1], y[4])


@nb.njit(cache=True, inline="always")
def _forces(y, p, friction):
    y_rel, vx, vy = _pin(y, p)
    return guide_forces(p, friction, y_rel, vx, vy, y[2], y[5], y[6], y[7], y[8], y[9])


@nb.njit(cache=True, inline="always")
def _rhs(t, y, p, out, friction):
    """``(q', q'', 0, 0, 0, 0, W_in', W_loss')`` with the crank free."""
    fx, fy, mz, lost, _ = _forces(y, p, friction)
    m = guide_system((y[0], y[1], y[2], y[3], y[4], y[5]), p, (fx, fy, mz, 0.0))
    a0, a1, a2 = solve_free(m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8])
    out[0], out[1], out[2] = y[3], y[4], y[5]
    out[3], out[4], out[5] = a0, a1, a2
    for k in range(6, 10):
        out[k] = 0.0
    out[10] = 0.0
    out[11] = lost


@compiled(RHS_SIGNATURE)
def rhs_ambrosio(t, y, p, out):
    _rhs(t, y, p, out, ambrosio_friction)


@compiled(RHS_SIGNATURE)
def rhs_tanh(t, y, p, out):
    _rhs(t, y, p, out, tanh_friction)


@compiled(EVENT_SIGNATURE)
def contact_event(t, y, p):
    """Falls through 0 at every contact onset and separation of any corner."""
    y_rel, vx, vy = _pin(y, p)
    return smallest_factor(p, y_rel, vx, vy, y[2], y[5], y, 6)[0]


@compiled(RHS_SIGNATURE)
def contact_reset(t, y, p, out):
    """[`flip_phases`][recipdyn.model.joints.guide.flip_phases] of the corners."""
    for i in range(y.shape[0]):
        out[i] = y[i]
    y_rel, vx, vy = _pin(y, p)
    flip_phases(p, y_rel, vx, vy, y[2], y[5], y, 6, out)


def system(par: FloresTranslational) -> ODESystem:
    """The benchmark as an [`ODESystem`][recipdyn.model.base.ODESystem] with its contact event."""
    ev = Event("contact", contact_event, direction=-1, action="reset", reset=contact_reset,
               description="contact onset or separation of a slider corner")  # fmt: skip
    return ODESystem(rhs=KERNELS[par.friction_law][0], params=par.pack(),
                     state_names=STATE_NAMES,
                     state_units=STATE_UNITS, name="flores-translational", events=(ev,),
                     aux_states=6)  # fmt: skip


def initial_state(par: FloresTranslational) -> np.ndarray:
    """siconos's start: angles 0, crank at ``omega0``, rod at ``-omega0 l1/l2``, slider
    centred; a corner that touches its surface already (``c = 0``) starts in contact."""
    y = np.zeros(len(STATE_NAMES))
    y[3], y[4] = par.omega0, -par.omega0 * par.l1 / par.l2
    y[6:10] = 1.0 if par.c == 0 else -1.0
    y[6:10] *= par.v_impact_min
    return y


@nb.njit(cache=True, inline="always")
def _series(y, p, friction):
    n = y.shape[0]
    out = np.empty((n, 10))
    for i in range(n):
        yi = y[i]
        y_rel, vx, vy = _pin(yi, p)
        fx, fy, mz, lost, el = _forces(yi, p, friction)
        out[i, 0] = guide_energy((yi[0], yi[1], yi[2], yi[3], yi[4], yi[5]), p) + el
        out[i, 1] = y_rel
        for k in range(4):
            _, dy, pen, _, _, _ = corner_kinematics(k, y_rel, vx, vy, yi[2], yi[5], p[P_A],
                                                    p[P_B])  # fmt: skip
            out[i, 2 + k] = y_rel + dy  # the corner's lateral position
            out[i, 6 + k] = pen - p[P_C]  # its penetration (-gap)
    return out


@nb.njit(cache=True)
def series_ambrosio(y, p):
    return _series(y, p, ambrosio_friction)


@nb.njit(cache=True)
def series_tanh(y, p):
    return _series(y, p, tanh_friction)


#: The compiled right-hand side and outputs for each friction law (chosen by name).
KERNELS = {"ambrosio": (rhs_ambrosio, series_ambrosio), "tanh": (rhs_tanh, series_tanh)}


def energy(par: FloresTranslational, y: np.ndarray) -> np.ndarray:
    """``T + V + U`` (kinetic, gravity and the contacts' elastic energy, J) along ``y``."""
    series = KERNELS[par.friction_law][1]
    return series(np.ascontiguousarray(np.atleast_2d(y)), par.pack())[:, 0]


def corner_series(par: FloresTranslational, y: np.ndarray) -> dict[str, np.ndarray]:
    """Along a trajectory ``y``: the energy, the slider's lateral position ``y_rel`` (m), the
    corners' lateral positions ``corner_y`` (n x 4, m) and their gaps ``gap`` (n x 4, m;
    siconos's ``g1..g4``)."""
    s = KERNELS[par.friction_law][1](np.ascontiguousarray(np.atleast_2d(y)), par.pack())
    return {"energy": s[:, 0], "y_rel": s[:, 1], "corner_y": s[:, 2:6], "gap": -s[:, 6:10]}
