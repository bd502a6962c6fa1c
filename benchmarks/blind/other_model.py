"""A second compressor model, written for the blind set independently of recipdyn's.

A double-acting crosshead compressor: the crank turns at a prescribed speed; its pin sits in
the connecting rod's big-end bearing with a radial clearance (a contact-impact joint); the
crosshead pin is ideal and the crosshead runs on the cylinder axis; the two chambers hold an
ideal gas whose mass and temperature follow from the flows through quasi-static valves,
optional leaks and the piston's motion. What the diagnoser is asked about a record of this
model is the same question as for recipdyn's: which fault, and how badly.

What it shares with recipdyn's ``compressor-contact-valves``: the machine's nominal numbers
(crank radius, rod length and mass, crosshead mass, bore, rod diameter, clearance volume, line
pressures, the valves' flow area as a share of the piston's), an ideal gas of air, the Hertz
stiffness of a pin in a hole ``K = 4/3 E* sqrt(R*)``, the crank angle convention (0 at outer
dead centre, the head end's top dead centre) and the recorded quantity (the crosshead's axial
acceleration). What it does not share:

* the equations: Lagrange's equations in the crosshead position and the rod angle, written
  by hand (`_rhs`); recipdyn writes the joint in the eccentricity of the pin and generates its
  equations;
* the contact damping: a constant Hunt-Crossley coefficient (``F = K d^1.5 + lam d^1.5 d'``,
  ``lam`` set for a restitution of 0.9 at 0.1 m/s, so the restitution falls as impacts get
  faster), where recipdyn's Lankarani-Nikravesh law scales it by each impact's approach
  velocity;
* the crosshead pin: ideal here (one joint with clearance, not two);
* the valves: quasi-static (the flow area opens in proportion to the pressure difference up to
  ``dp_full``, no plate, spring, stiction or impacts on the seat), against recipdyn's plate
  valves with their own dynamics; so no spring or stiction fault exists here;
* the integrator: a fixed-step classical Runge-Kutta (4th order, ``SUBSTEPS`` steps a sample),
  compiled here; recipdyn's is an adaptive DOP853 with located contact events.

Its faults: the crank-pin clearance ``c``; leaks of the head end's suction and discharge valves
and of the piston rings (orifices, both directions). Not validated against a measured machine
either; it is a second opinion, not a reference.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numba as nb
import numpy as np

__all__ = ["Machine", "simulate_other"]

#: Integration steps per output sample (at 61 440 Hz output: a 4.07 us step; the stiffest
#: motion, the pin's contact at ~2e4 rad/s, is then resolved with omega h ~ 0.1).
SUBSTEPS = 4


@dataclass(frozen=True)
class Machine:
    """The second model's parameters (SI units), nominally recipdyn's machine."""

    r: float = 0.12  # crank radius, m
    l: float = 0.6  # rod length, m
    ls: float = 0.3  # big end to the rod's centroid, m
    m2: float = 20.0  # rod mass, kg
    J2: float = 0.6  # rod inertia about its centroid, kg m^2
    m3: float = 30.0  # crosshead + piston, kg
    g: float = 9.81
    clearance: float = 1e-4  # crank-pin radial clearance, m
    journal_radius: float = 0.05
    E: float = 2.07e11
    nu: float = 0.3
    restitution: float = 0.9  # Hunt-Crossley restitution at v_ref
    v_ref: float = 0.1  # m/s
    bore: float = 0.5
    rod_diameter: float = 0.1
    clearance_fraction: float = 0.1  # clearance volume / swept volume, each chamber
    suction_pressure: float = 1e5
    discharge_pressure: float = 3e5
    frame_pressure: float = 101325.0
    suction_temperature: float = 293.15
    gas_constant: float = 287.05
    gamma: float = 1.4
    valve_area_fraction: float = 0.08  # valve flow area / piston area
    discharge_coefficient: float = 0.7
    dp_full: float = 5000.0  # pressure difference that opens a valve fully, Pa
    leak_suction_head: float = 0.0  # m^2
    leak_discharge_head: float = 0.0
    ring_leak: float = 0.0
    omega: float = 20.0  # rad/s


def _pack(m: Machine) -> np.ndarray:
    a_h = math.pi * m.bore**2 / 4
    a_rod = math.pi * m.rod_diameter**2 / 4
    a_c = a_h - a_rod
    e_star = m.E / (2 * (1 - m.nu**2))
    r_b = m.journal_radius + m.clearance
    r_star = m.journal_radius * r_b / m.clearance
    k = 4.0 / 3.0 * e_star * math.sqrt(r_star)
    lam = 3 * (1 - m.restitution) * k / (2 * m.v_ref)
    t_d = m.suction_temperature * (m.discharge_pressure / m.suction_pressure) ** (
        (m.gamma - 1) / m.gamma
    )
    return np.array(
        [
            m.r, m.l, m.l - m.ls, m.m2, m.J2, m.m3, m.g, m.clearance, k, lam,  # 0-9
            a_h, a_c, a_rod, m.clearance_fraction * a_h * 2 * m.r,  # 10-13: V0 head
            m.clearance_fraction * a_c * 2 * m.r,  # 14: V0 crank
            m.suction_pressure, m.discharge_pressure, m.frame_pressure,  # 15-17
            m.suction_temperature, t_d, m.gas_constant, m.gamma,  # 18-21
            m.valve_area_fraction * a_h, m.discharge_coefficient, m.dp_full,  # 22-24
            m.leak_suction_head, m.leak_discharge_head, m.ring_leak, m.omega,  # 25-28
        ],
        dtype=float,
    )  # fmt: skip


@nb.njit(cache=True)
def _orifice(p_up, t_up, p_down, area, cd, rgas, gam):
    """Isentropic orifice mass flow (kg/s) from ``p_up`` to ``p_down`` (choked below the
    critical ratio), linear in the pressure ratio within 1e-3 of equal pressures so that
    its slope stays finite."""
    if area <= 0.0 or p_up <= p_down:
        return 0.0
    prc = (2.0 / (gam + 1.0)) ** (gam / (gam - 1.0))
    pr = p_down / p_up
    eps = 1e-3
    scale = 1.0
    if 1.0 - pr < eps:
        scale = (1.0 - pr) / eps
        pr = 1.0 - eps
    if pr < prc:
        pr = prc
    psi = math.sqrt(2.0 * gam / (gam - 1.0) * (pr ** (2.0 / gam) - pr ** ((gam + 1.0) / gam)))
    return scale * cd * area * p_up / math.sqrt(rgas * t_up) * psi


@nb.njit(cache=True)
def _flow(p_a, t_a, p_b, t_b, area, cd, rgas, gam):
    """Signed flow a -> b through an orifice (both directions) and its upstream temperature."""
    if p_a >= p_b:
        return _orifice(p_a, t_a, p_b, area, cd, rgas, gam), t_a
    return -_orifice(p_b, t_b, p_a, area, cd, rgas, gam), t_b


@nb.njit(cache=True)
def _chamber_rates(m, T, V, dV, p_line_s, p_line_d, t_s, t_d, a_valve, cd, dp_full,
                   leak_s, leak_d, ring_in, t_ring, P):  # fmt: skip
    """dm/dt, dT/dt of one chamber (adiabatic walls) and its pressure."""
    rgas, gam = P[20], P[21]
    cv = rgas / (gam - 1.0)
    cp = gam * cv
    p = m * rgas * T / V
    # suction valve: opens inward when the line pressure exceeds the chamber's
    f = min(max((p_line_s - p) / dp_full, 0.0), 1.0)
    q_s = _orifice(p_line_s, t_s, p, f * a_valve, cd, rgas, gam)
    # discharge valve: opens outward
    f = min(max((p - p_line_d) / dp_full, 0.0), 1.0)
    q_d = _orifice(p, T, p_line_d, f * a_valve, cd, rgas, gam)
    # leaks (signed: > 0 into the chamber)
    ls, tls = _flow(p_line_s, t_s, p, T, leak_s, cd, rgas, gam)
    ld, tld = _flow(p_line_d, t_d, p, T, leak_d, cd, rgas, gam)
    dm = q_s - q_d + ls + ld + ring_in
    h = q_s * (cp * t_s - cv * T) - q_d * rgas * T
    for q, tq in ((ls, tls), (ld, tld), (ring_in, t_ring)):
        if q > 0.0:
            h += q * (cp * tq - cv * T)
        else:
            h += q * rgas * T
    dT = (h - p * dV) / (m * cv)
    return dm, dT, p


@nb.njit(cache=True)
def _rhs(t, y, P, out):
    r, l, a, m2, J2, m3, g, c, K, lam = P[0], P[1], P[2], P[3], P[4], P[5], P[6], P[7], P[8], P[9]
    a_h, a_c, a_rod, v0h, v0c = P[10], P[11], P[12], P[13], P[14]
    ps, pd, pf, ts, td, rgas, gam = P[15], P[16], P[17], P[18], P[19], P[20], P[21]
    a_v, cd, dp_full, leak_s, leak_d, ring, om = P[22], P[23], P[24], P[25], P[26], P[27], P[28]
    x3, phi, xd, phid = y[0], y[1], y[2], y[3]
    th = om * t
    sphi, cphi = math.sin(phi), math.cos(phi)
    # big-end bearing centre B and the journal (crank pin) centre A
    bx, by = x3 - l * cphi, -l * sphi
    bxd, byd = xd + l * sphi * phid, -l * cphi * phid
    ax, ay = r * math.cos(th), r * math.sin(th)
    axd, ayd = -r * om * math.sin(th), r * om * math.cos(th)
    dx, dy = ax - bx, ay - by
    dist = math.sqrt(dx * dx + dy * dy)
    fx = 0.0
    fy = 0.0
    if dist > c:
        nx, ny = dx / dist, dy / dist
        dlt = dist - c
        dltd = nx * (axd - bxd) + ny * (ayd - byd)
        fn = K * dlt**1.5 + lam * dlt**1.5 * dltd
        if fn > 0.0:
            fx, fy = fn * nx, fn * ny
    # chambers: head end beyond the crosshead's outer position, crank end towards the crank
    xmax, xmin = l + r, l - r
    vh = v0h + a_h * (xmax - x3)
    vc = v0c + a_c * (x3 - xmin)
    ph = y[4] * rgas * y[5] / vh
    pc = y[6] * rgas * y[7] / vc
    q_ring, t_ring = _flow(pc, y[7], ph, y[5], ring, cd, rgas, gam)  # crank end -> head end
    dmh, dth, ph = _chamber_rates(y[4], y[5], vh, -a_h * xd, ps, pd, ts, td, a_v, cd, dp_full,
                                  leak_s, leak_d, q_ring, t_ring, P)  # fmt: skip
    dmc, dtc, pc = _chamber_rates(y[6], y[7], vc, a_c * xd, ps, pd, ts, td, a_v, cd, dp_full,
                                  0.0, 0.0, -q_ring, t_ring, P)  # fmt: skip
    f_gas = -ph * a_h + pc * a_c + pf * a_rod
    # Lagrange's equations in (x3, phi): M q'' = Q - (velocity terms)
    m11 = m2 + m3
    m12 = m2 * a * sphi
    m22 = m2 * a * a + J2
    q1 = f_gas + fx - m2 * a * cphi * phid * phid
    q2 = m2 * g * a * cphi + fx * l * sphi - fy * l * cphi
    det = m11 * m22 - m12 * m12
    out[0] = xd
    out[1] = phid
    out[2] = (m22 * q1 - m12 * q2) / det
    out[3] = (m11 * q2 - m12 * q1) / det
    out[4] = dmh
    out[5] = dth
    out[6] = dmc
    out[7] = dtc
    return ph, pc


@nb.njit(cache=True)
def _integrate(y0, P, h, n_out, sub, skip):
    """Classical RK4 at step ``h``; after ``skip`` samples of transient, records ``n_out``
    samples every ``sub`` steps: time, crank angle, acceleration, both pressures."""
    n = y0.size
    y = y0.copy()
    k1, k2, k3, k4, tmp = (np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n))
    res = np.empty((n_out, 5))
    t = 0.0
    for i in range(skip + n_out):
        if i >= skip:
            ph, pc = _rhs(t, y, P, k1)
            j = i - skip
            res[j, 0] = t
            res[j, 1] = P[28] * t
            res[j, 2] = k1[2]
            res[j, 3] = ph
            res[j, 4] = pc
        for _ in range(sub):
            _rhs(t, y, P, k1)
            for q in range(n):
                tmp[q] = y[q] + 0.5 * h * k1[q]
            _rhs(t + 0.5 * h, tmp, P, k2)
            for q in range(n):
                tmp[q] = y[q] + 0.5 * h * k2[q]
            _rhs(t + 0.5 * h, tmp, P, k3)
            for q in range(n):
                tmp[q] = y[q] + h * k3[q]
            _rhs(t + h, tmp, P, k4)
            for q in range(n):
                y[q] += h / 6.0 * (k1[q] + 2.0 * k2[q] + 2.0 * k3[q] + k4[q])
            t += h
    return res


def simulate_other(machine: Machine, *, revolutions: float = 4.0, transient: float = 2.0,
                   fs: float = 61_440.0) -> dict:  # fmt: skip
    """Simulate the second model; returns ``t`` (s), ``theta1`` (rad), ``a`` (crosshead axial
    acceleration, m/s**2), ``p_head``, ``p_crank`` (Pa) sampled at ``fs`` after ``transient``
    revolutions, and ``params`` (the machine, as a dict).

    Starts at outer dead centre with the kinematic motion of ideal pins (the pin centred in
    its bearing), the head end full of discharge gas, the crank end of suction gas.
    """
    P = _pack(machine)
    r, l, om = machine.r, machine.l, machine.omega
    # theta = 0: crosshead at its outer position; the rod's rate from phi = -asin(r sin th / l)
    y0 = np.zeros(8)
    y0[0] = r + l
    y0[3] = -r * om / l
    rgas = machine.gas_constant
    vh = P[13]
    vc = P[14] + P[11] * 2 * r
    y0[4] = machine.discharge_pressure * vh / (rgas * P[19])
    y0[5] = P[19]
    y0[6] = machine.suction_pressure * vc / (rgas * P[18])
    y0[7] = P[18]
    period = 2 * math.pi / om
    skip = int(round(transient * period * fs))
    n_out = int(round(revolutions * period * fs))
    res = _integrate(y0, P, 1.0 / (fs * SUBSTEPS), n_out, SUBSTEPS, skip)
    return {
        "t": res[:, 0],
        "theta1": res[:, 1],
        "a": res[:, 2],
        "p_head": res[:, 3],
        "p_crank": res[:, 4],
        "fs": fs,
        "params": asdict(machine),
    }
