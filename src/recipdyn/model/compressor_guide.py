r"""The compressor with clearance in the crosshead guide ("crosshead knock").

The paper's mechanism (crank ``r`` driven at ``omega``, rod ``l`` with centroid at ``ls``, the
gas load on the crosshead) with ideal pins, and a crosshead that is a body of its own between
the guide's upper and lower shoes: it moves sideways within the radial clearance
``guide_clearance`` and tilts, and its four corners (half-length ``crosshead_half_length``,
half-height ``crosshead_half_height`` about the pin) strike the shoes. The equations are those
of the slider in a guide, `recipdyn.model.joints.guide` (one sympy derivation for this model
and the Flores–Leine–Glocker benchmark), with the crank angle prescribed,
``theta1 = theta1_0 + omega t``: coordinates ``(theta2, phi)``, the rod angle and the
crosshead's tilt; the crosshead pin is at
``(r cos theta1 + l cos theta2, r sin theta1 + l sin theta2)`` and the guide's centreline at
``y = -d``. Each corner's contact is recipdyn's compliant law with Coulomb friction
(regularised), as at the pins of `compressor-contact`.

Signature: the side force the guide must supply changes sign where the rod's inclination or
the rod load does (near the dead centres under a load that never reverses, and at the
rod-load reversals under a reversing one); the crosshead then crosses the clearance and knocks
on the other shoe, which the guide's accelerometer sees as spikes of the lateral acceleration
(`guide_acc`) at those crank angles.

State ``(theta2, phi, theta2', phi', v_1..v_4, W_in, W_loss)``: the coordinates and rates, the
four corners' recorded approach velocities (their sign the phase: > 0 in contact), the work of
the drive and of the gas on the mechanism and the work lost to the shoes (contact damping and
friction). ``T + V + U = E0 + W_in - W_loss`` holds along every run (``U`` the shoes' elastic
energy); the drive's torque is the first row of the same Lagrange equations (`solve_prescribed`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numba as nb
import numpy as np

from ..errors import ParameterError
from .base import EVENT_SIGNATURE, JAC_SIGNATURE, RHS_SIGNATURE, Event, ODESystem, Signal, compiled
from .components.guide import GUIDE_PARAMS, tilt_inertia
from .components.load import (
    cycle_force,
    cycle_outputs,
    cycle_summary,
    force_series,
    load_component,
    table_force,
)
from .joints._guide import guide_energy, guide_system
from .joints.contact import (
    FRICTION_ROLES,
    ambrosio_friction,
    delivered_restitution,
    hysteresis_factor,
    tanh_friction,
)
from .joints.guide import (
    N_HEAD,
    P_A,
    P_B,
    P_C,
    P_CHI,
    P_K,
    P_MU,
    P_VMIN,
    corner_force,
    flip_phases,
    guide_forces,
    pin_kinematics,
    smallest_factor,
    solve_prescribed,
)
from .kinematics import ideal_mechanism
from .load import CYCLE_PARAMS, mu_sincos
from .parameters import SCHEMA as LINK_SCHEMA
from .parameters import check_reach
from .protocol import Model, Param, Schema

__all__ = ["CompressorGuide", "COMPRESSOR_GUIDE", "ideal_crosshead"]

_INF = math.inf
STATE_NAMES = ("theta2", "phi", "theta2_dot", "phi_dot", "v_impact_1", "v_impact_2",
               "v_impact_3", "v_impact_4", "W_in", "W_loss")  # fmt: skip
STATE_UNITS = ("rad", "rad", "rad/s", "rad/s", "m/s", "m/s", "m/s", "m/s", "J", "J")
K0 = 4  # first corner phase in the state
# after the joint's head: the drive, then the load
P_OMEGA, P_TH10, P_LOADAMP, P_LOADSIGN, P_LOADKIND = range(N_HEAD, N_HEAD + 5)
P_TABLE = N_HEAD + 5
#: The load components this model's kernel calls (their index is packed at P_LOADKIND).
GUIDE_LOADS = ("paper", "table", "cycle")


@nb.njit(cache=True, inline="always")
def _gas(th1, p):
    # which of GUIDE_LOADS (set by pack from the load component, never by a user): each
    # component's own kernel reads its own slice at P_TABLE
    if p[P_LOADKIND] == 0.0:
        return p[P_LOADSIGN] * p[P_LOADAMP] * mu_sincos(math.sin(th1), math.cos(th1))
    if p[P_LOADKIND] == 1.0:
        return table_force(th1, p, P_TABLE)
    return cycle_force(th1, p, P_TABLE)


@nb.njit(cache=True, inline="always")
def _core(t, y, p, friction):
    """Everything the right-hand side and the outputs need: the accelerations, the drive's
    torque, the gas force, the contact's resultant, power lost and elastic energy, and the
    pin's kinematics (``friction``: the shoes' friction law)."""
    w = p[P_OMEGA]
    th1 = p[P_TH10] + w * t
    y_rel, vx, vy = pin_kinematics(p, th1, w, y[0], y[2])
    fx, fy, mz, lost, elastic = guide_forces(p, friction, y_rel, vx, vy, y[1], y[3], y[4], y[5],
                                             y[6], y[7])  # fmt: skip
    fg = _gas(th1, p)
    m = guide_system((th1, y[0], y[1], w, y[2], y[3]), p, (fx + fg, fy, mz, 0.0))
    a2, aphi, torque = solve_prescribed(m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8])
    return a2, aphi, torque, fg, fx, fy, mz, lost, elastic, th1, y_rel, vx, vy


@nb.njit(cache=True, inline="always")
def _rhs(t, y, p, out, friction):
    """The right-hand side for real or complex ``y`` and ``out`` (no arrays allocated)."""
    a2, aphi, torque, fg, _, _, _, lost, _, _, _, vx, _ = _core(t, y, p, friction)
    out[0], out[1], out[2], out[3] = y[2], y[3], a2, aphi
    for k in range(4, 8):
        out[k] = 0.0
    out[8] = torque * p[P_OMEGA] + fg * vx
    out[9] = lost


@compiled(RHS_SIGNATURE)
def rhs_ambrosio(t, y, p, out):
    _rhs(t, y, p, out, ambrosio_friction)


@compiled(RHS_SIGNATURE)
def rhs_tanh(t, y, p, out):
    _rhs(t, y, p, out, tanh_friction)


#: Imaginary step of the complex-step Jacobian (no difference is taken: any tiny size).
CS_STEP = 1e-60


@nb.njit(cache=True, inline="always")
def _jac(t, y, p, J, friction):
    """The complex step (Squire & Trapp 1998, SIAM Rev. 40, 110-112):
    ``J[:, k] = Im f(y + i h e_k) / h``, exact to rounding on the branch of each switch
    (contact, clamp, friction law) that the real state takes, as in `compressor_contact`.
    The work integrals act on nothing (their columns are 0)."""
    n = y.shape[0]
    yc = np.empty(n, np.complex128)
    fc = np.empty(n, np.complex128)
    for i in range(n):
        yc[i] = y[i]
    J[:, :] = 0.0
    for k in range(8):
        yc[k] = complex(y[k], CS_STEP)
        _rhs(t, yc, p, fc, friction)
        yc[k] = y[k]
        for i in range(n):
            J[i, k] = fc[i].imag / CS_STEP


@compiled(JAC_SIGNATURE, allocates=True)
def jac_ambrosio(t, y, p, J):
    _jac(t, y, p, J, ambrosio_friction)


@compiled(JAC_SIGNATURE, allocates=True)
def jac_tanh(t, y, p, J):
    _jac(t, y, p, J, tanh_friction)


@nb.njit(cache=True, inline="always")
def _pin(t, y, p):
    w = p[P_OMEGA]
    return pin_kinematics(p, p[P_TH10] + w * t, w, y[0], y[2])


@compiled(EVENT_SIGNATURE)
def contact_event(t, y, p):
    """Falls through 0 at every onset and separation of a crosshead corner on a shoe."""
    y_rel, vx, vy = _pin(t, y, p)
    return smallest_factor(p, y_rel, vx, vy, y[1], y[3], y, K0)[0]


@compiled(RHS_SIGNATURE)
def contact_reset(t, y, p, out):
    """[`flip_phases`][recipdyn.model.joints.guide.flip_phases] of the corners."""
    for i in range(y.shape[0]):
        out[i] = y[i]
    y_rel, vx, vy = _pin(t, y, p)
    flip_phases(p, y_rel, vx, vy, y[1], y[3], y, K0, out)


@nb.njit(cache=True, inline="always")
def _series(t, y, p, friction):
    """Per sample: x, v, a (axial), lateral position, velocity, acceleration of the pin, the
    gas force, the drive torque, the side force of the shoes (upper and lower, N), the
    contact's moment, the energy T + V + U, the number of corners in contact."""
    n = t.shape[0]
    out = np.empty((n, 13))
    r, l = p[0], p[2]
    w = p[P_OMEGA]
    for i in range(n):
        yi = y[i]
        a2, _, torque, fg, _, _, mz, _, elastic, th1, y_rel, vx, vy = _core(t[i], yi, p, friction)
        s1, c1 = math.sin(th1), math.cos(th1)
        s2, c2 = math.sin(yi[0]), math.cos(yi[0])
        w2 = yi[2]
        out[i, 0] = r * c1 + l * c2
        out[i, 1] = vx
        out[i, 2] = -r * w * w * c1 - l * (c2 * w2 * w2 + s2 * a2)
        out[i, 3] = y_rel
        out[i, 4] = vy
        out[i, 5] = -r * w * w * s1 + l * (c2 * a2 - s2 * w2 * w2)
        out[i, 6] = fg
        out[i, 7] = torque
        up = 0.0
        low = 0.0
        inc = 0.0
        for k in range(4):
            fk = corner_force(k, y_rel, vx, vy, yi[1], yi[3], p[P_A], p[P_B], p[P_C], p[P_K],
                              p[P_CHI], friction, p, P_MU, p[P_VMIN], yi[K0 + k])  # fmt: skip
            if k < 2:
                up += fk[5]
            else:
                low += fk[5]
            if fk[5] > 0.0:
                inc += 1.0
        out[i, 8] = up
        out[i, 9] = low
        out[i, 10] = mz
        out[i, 11] = guide_energy((th1, yi[0], yi[1], w, yi[2], yi[3]), p) + elastic
        out[i, 12] = inc
    return out


@nb.njit(cache=True)
def series_ambrosio(t, y, p):
    return _series(t, y, p, ambrosio_friction)


@nb.njit(cache=True)
def series_tanh(t, y, p):
    return _series(t, y, p, tanh_friction)


#: The compiled right-hand side, Jacobian and outputs for each ``guide_friction_law``.
KERNELS = {"ambrosio": (rhs_ambrosio, jac_ambrosio, series_ambrosio),
           "tanh": (rhs_tanh, jac_tanh, series_tanh)}  # fmt: skip
assert set(KERNELS) == set(FRICTION_ROLES)


def pack(v: Mapping[str, Any]) -> np.ndarray:
    mech = (v["r"], 0.0, v["l"], v["ls"], 0.0, v["m2"], v["m3"], 0.0, v["J2"], tilt_inertia(v),
            v["g"])  # fmt: skip
    c = float(v["guide_clearance"])
    head = [*mech, v["d"], v["crosshead_half_length"], v["crosshead_half_height"], c,
            v["guide_stiffness"], hysteresis_factor(v["guide_contact_law"],
                                                    v["guide_restitution"]),
            v["guide_friction"], v["guide_v0"], v["guide_v1"], v["v_impact_min"],
            v["crosshead_half_height"]]  # fmt: skip
    part = load_component(v)
    if part.name not in GUIDE_LOADS:
        raise ParameterError(f"load = {part.name!r}: compressor-guide takes the "
                             f"{', '.join(GUIDE_LOADS)} loads; any load: --model "
                             "compressor-contact --set guide=clearance --set crank_joint=ideal "
                             "--set crosshead_joint=ideal")  # fmt: skip
    data = np.asarray(part.pack(v), dtype=np.float64)
    head += [v["omega"], v["theta1_0"], v["load_amplitude"],
             -1.0 if v["load_sign"] == "physical" else 1.0,
             float(GUIDE_LOADS.index(part.name))]  # fmt: skip
    return np.concatenate([np.asarray(head, dtype=np.float64), data])


def _link(name: str, **changes) -> Param:
    from dataclasses import replace

    return replace(LINK_SCHEMA[name], **changes)


SCHEMA = Schema((
    *(_link(k) for k in ("r", "l", "ls", "m2", "m3", "J2", "g", "d")),
    *GUIDE_PARAMS,
    Param("v_impact_min", "m/s", 1e-3, "floor of the recorded approach velocity (grazing "
          "contacts)", 0.0, _INF, low_open=True, group="guide"),
    _link("omega"), _link("theta1_0"),
    _link("load_amplitude"), _link("load_sign"), _link("load"),
    *(_link(k) for k in (*CYCLE_PARAMS, "gas", "suction_temperature")),
), aliases={"speed": "omega", "crank_speed": "omega", "guide_c": "guide_clearance"})  # fmt: skip


def ideal_crosshead(values: Mapping[str, Any], theta1: np.ndarray) -> dict[str, np.ndarray]:
    """The ideal guide in closed form (crosshead on ``y = -d``, ideal pins, the crank at
    constant ``omega``): axial position and acceleration, the rod angle, and the side force the
    guide must supply (``N > 0``: the lower shoe pushes up), from Newton–Euler for the crosshead
    and for the rod about the crank pin with the gas force and gravity."""
    fg = force_series(values, np.asarray(theta1, dtype=float))
    m = ideal_mechanism(values, theta1, fg)
    return {"x": m["x"], "a": m["a"], "theta2": m["theta2"], "side_force": m["side_force"],
            "gas_force": fg}  # fmt: skip


class CompressorGuide(Model):
    """The compressor with clearance in the crosshead guide (crosshead knock)."""

    name = "compressor-guide"
    description = ("compressor with clearance in the crosshead guide: the crosshead moves "
                   "sideways and tilts between the shoes and knocks on them (Flores, Leine & "
                   "Glocker 2010 joint, compliant contact)")  # fmt: skip
    state_names = STATE_NAMES
    state_units = STATE_UNITS
    schema = SCHEMA
    section_signals = (("guide_y", "m"), ("guide_acc", "m/s**2"), ("x", "m"), ("v", "m/s"),
                       ("a", "m/s**2"))  # fmt: skip
    vibration_signal = ("guide_acc", "m/s**2")
    section_pair = ("guide_y", "guide_acc")
    mean_signals = (("guide_contact", "guide_contact_fraction", "1"),)
    #: With 0.2 mm of play and a tenth of the paper's load the crosshead knocks at every
    #: side-force reversal.
    event_example = {"guide_clearance": 2e-4, "load_amplitude": 2e4}
    lyapunov_refusal = ("Benettin's method is not offered for compressor-guide: its tangent "
                        "integration across the shoe impacts (the saltation matrices of the four "
                        "corners' event) has not been checked against differences of the flow, "
                        "as compressor-contact's has; use compressor-contact for exponents of a "
                        "worn machine")  # fmt: skip

    def check(self, values: Mapping[str, Any]) -> None:
        from ..errors import ParameterError

        check_reach(values["l"], values["r"], 1e-3, "1 mm")
        dmax = values["l"] - values["r"] - 1e-3
        if not abs(values["d"]) < dmax:
            raise ParameterError(f"d = {values['d']!r} m is out of range; allowed: "
                                 f"(-{dmax:g}, {dmax:g}) m (l - r - 1 mm)")  # fmt: skip
        if values["guide_v1"] <= values["guide_v0"]:
            raise ParameterError(f"guide_v1 = {values['guide_v1']!r} m/s must exceed guide_v0 = "
                                 f"{values['guide_v0']!r} m/s")  # fmt: skip

    def events(self, values: Mapping[str, Any]) -> tuple[Event, ...]:
        return (Event("impact", contact_event, direction=-1, action="reset",
                      reset=contact_reset, description="onset or separation of a crosshead "
                      "corner on a guide shoe (the smallest phased factor falls through 0): "
                      "at an onset the approach velocity is recorded for the damping "
                      "law"),)  # fmt: skip

    def system(self, values: Mapping[str, Any]) -> ODESystem:
        rhs, jac, _ = KERNELS[values["guide_friction_law"]]
        return ODESystem(rhs=rhs, jac=jac, params=pack(values), state_names=self.state_names,
                         state_units=self.state_units, period=self.period(values),
                         name=self.name, events=self.events(values), aux_states=6,
                         passive=(4, 5, 6, 7, 8, 9))  # fmt: skip

    def period(self, values: Mapping[str, Any]) -> float:
        return 2.0 * math.pi / float(values["omega"])

    def initial_state(self, values: Mapping[str, Any]) -> np.ndarray:
        """The ideal mechanism's state at ``theta1_0`` (the crosshead centred, level, moving
        along the guide); a corner that touches its shoe already (no clearance) starts in
        contact."""
        r, l, d, w = (float(values[k]) for k in ("r", "l", "d", "omega"))
        th1 = float(values["theta1_0"])
        s2 = -(d + r * math.sin(th1)) / l
        y = np.zeros(len(STATE_NAMES))
        y[0] = math.asin(s2)
        y[2] = -r * w * math.cos(th1) / (l * math.cos(y[0]))
        sign = 1.0 if values["guide_clearance"] == 0 else -1.0
        y[4:8] = sign * values["v_impact_min"]
        return y

    def state_scale(self, values: Mapping[str, Any]) -> np.ndarray:
        """Rod angle 0.04 rad and tilt 0.01 rad (perturbations of a few percent of these put
        the crosshead ~1 mm into a shoe: deep, but where the contact law is smooth on the
        interface test's steps), rates as the default, approach velocities 1 mm/s."""
        s = np.maximum(1.0, np.abs(self.initial_state(values)))
        s[0], s[1] = 0.04, 0.01
        s[4:8] = 1e-3
        return s

    def outputs(self, values: Mapping[str, Any], t: np.ndarray, y: np.ndarray
                ) -> dict[str, Signal]:  # fmt: skip
        p = pack(values)
        t = np.ascontiguousarray(t, dtype=float)
        y = np.ascontiguousarray(y, dtype=float)
        s = KERNELS[values["guide_friction_law"]][2](t, y, p)
        th1 = float(values["theta1_0"]) + float(values["omega"]) * t
        return {
            "x": Signal(s[:, 0], "m", "crosshead (pin) displacement along the guide"),
            "v": Signal(s[:, 1], "m/s", "crosshead velocity along the guide"),
            "a": Signal(s[:, 2], "m/s**2", "crosshead acceleration along the guide"),
            "guide_y": Signal(s[:, 3], "m", "crosshead lateral position from the guide's "
                              "centreline (+ up)"),
            "guide_v": Signal(s[:, 4], "m/s", "crosshead lateral velocity"),
            "guide_acc": Signal(s[:, 5], "m/s**2", "crosshead lateral acceleration (what an "
                                "accelerometer on the guide sees of the knock)"),
            "tilt": Signal(y[:, 1], "rad", "crosshead tilt in the guide"),
            "theta1": Signal(th1, "rad", "crank angle"),
            "theta2": Signal(y[:, 0], "rad", "connecting-rod angle"),
            "gas_force": Signal(s[:, 6], "N", "gas force on the crosshead along +x"),
            "drive_torque": Signal(s[:, 7], "N*m", "torque the drive supplies to hold omega"),
            "shoe_force_upper": Signal(s[:, 8], "N", "normal force of the upper shoe"),
            "shoe_force_lower": Signal(s[:, 9], "N", "normal force of the lower shoe"),
            "side_force": Signal(s[:, 9] - s[:, 8], "N", "net side force of the guide on the "
                                 "crosshead (+ up)"),
            "guide_contact": Signal((s[:, 12] > 0).astype(float), "", "1 while a corner "
                                    "touches a shoe"),
            "energy": Signal(s[:, 11], "J", "kinetic + gravity energy of rod and crosshead + "
                             "the shoes' elastic energy"),
            **cycle_outputs(values, th1),
        }  # fmt: skip

    def run_summary(self, values: Mapping[str, Any], ds: Any) -> dict[str, float]:
        """Shoe impacts (count, per revolution, largest approach velocity), the crossings of
        the clearance (an impact on the other shoe), the peak lateral acceleration, the
        largest penetration, the contact fraction and the energy-balance residual."""
        t = ds["time"].values
        revs = (t[-1] - t[0]) / self.period(values) if t.size > 1 else float("nan")
        out: dict[str, float] = {}
        if "impact_time" in ds:
            before = np.column_stack([ds[f"impact_v_impact_{k}"].values for k in range(1, 5)])
            after = np.column_stack([ds[f"impact_v_impact_{k}_after"].values for k in range(1, 5)])
            onset = (after > 0) & (before <= 0)
            n_on = int(onset.sum())
            vel = after[onset]
            out.update({
                "impacts": float(n_on),
                "impacts_per_revolution": n_on / revs if revs > 0 else float("nan"),
                "impact_velocity_max_m_s": float(vel.max()) if vel.size else 0.0,
            })  # fmt: skip
        E = ds["energy"].values
        w_in, w_loss = ds["W_in"].values, ds["W_loss"].values
        bal = E - E[0] - ((w_in - w_in[0]) - (w_loss - w_loss[0]))
        c = float(values["guide_clearance"])
        out.update({
            "peak_abs_guide_acc_m_s2": float(np.abs(ds["guide_acc"].values).max()),
            "peak_abs_a_m_s2": float(np.abs(ds["a"].values).max()),
            "max_lateral_excursion_m": float(np.abs(ds["guide_y"].values).max()),
            "max_lateral_excursion_ratio": float(np.abs(ds["guide_y"].values).max() / c)
            if c > 0 else float("nan"),
            "guide_contact_fraction": float(ds["guide_contact"].values.mean()),
            "energy_lost_in_guide_J": float(w_loss[-1] - w_loss[0]),
            "energy_balance_residual": float(np.abs(bal).max() / max(np.abs(E).max(), 1e-300)),
            "restitution_delivered": delivered_restitution(
                hysteresis_factor(values["guide_contact_law"], values["guide_restitution"])),
        })  # fmt: skip
        out.update(cycle_summary(values, ds))
        return out


COMPRESSOR_GUIDE = CompressorGuide()
