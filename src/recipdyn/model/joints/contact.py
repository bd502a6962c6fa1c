r"""Force laws of a revolute clearance joint: a journal (radius ``R_j``) inside a bearing
(radius ``R_b = R_j + c``), eccentricity vector ``e`` from the journal centre to the bearing
centre, penetration :math:`\delta = |e| - c`.

Normal contact (``delta > 0``), with :math:`\dot\delta^-` the approach velocity recorded at the
start of the impact (an event at ``delta = 0``):

.. math:: F_n = K \delta^n \left(1 + \chi\,\dot\delta / \dot\delta^-\right),\qquad n = 3/2,

clamped at zero (a contact force cannot pull). The hysteresis factor ``chi`` for a nominal
coefficient of restitution ``e``
([`hysteresis_factor`][recipdyn.model.joints.contact.hysteresis_factor]):

==========================  ===================================  ===============================
law                         chi                                  source
==========================  ===================================  ===============================
``hertz``                   0 (elastic)                          Hertz (1881)
``hunt-crossley``           3(1 - e)/2                           Hunt & Crossley (1975), J. Appl.
                                                                 Mech. 42, 440-445
``lankarani-nikravesh``     3(1 - e^2)/4                         Lankarani & Nikravesh (1990),
                                                                 J. Mech. Des. 112, 369-376
``flores``                  8(1 - e)/(5e)                        Flores, Machado, Silva & Martins
                                                                 (2011), Multibody Syst. Dyn.
                                                                 25, 357-375
``gonthier``                (1 - e^2)/e                          Gonthier, McPhee, Lange & Piedbœuf
                                                                 (2004), Multibody Syst. Dyn.
                                                                 11, 209-233
==========================  ===================================  ===============================

(the formulas as collected by Machado, Moreira, Flores & Lankarani 2012, Mech. Mach. Theory 53,
99-121). Each is derived under its own approximation, so the restitution a law *delivers*
differs from the nominal ``e``; for this force law it has a closed form
([`delivered_restitution`][recipdyn.model.joints.contact.delivered_restitution]): integrating
:math:`m u\,du/d\delta = -K\delta^n(1 + \chi u/u^-)` from :math:`u^-` to :math:`-e_* u^-` between
two zeros of :math:`\delta` gives

.. math:: \chi (1 + e_*) = \ln\frac{1 + \chi}{1 - \chi e_*},

independent of ``K``, ``n``, the mass and the impact velocity (tests/test_contact.py checks
the integrated impacts against it).

Stiffness of a pin in a hole ([`hertz_stiffness`][recipdyn.model.joints.contact.hertz_stiffness]):
the formula used for revolute clearance joints by Flores et al. (2008), *Kinematics and Dynamics of
Multibody Systems with Imperfect Joints*, Springer, Eq. (3.9):
:math:`K = \frac{4}{3(\sigma_j + \sigma_b)}\sqrt{R_j R_b / (R_b - R_j)}`,
:math:`\sigma = (1 - \nu^2)/E`.

Friction: Coulomb with Ambrósio's dynamic correction (Ambrósio 2003, *Virtual Nonlinear
Multibody Systems*, NATO Sci. Ser. 103, 57-81): :math:`F_t = -\mu c_d F_n\,\mathrm{sgn}(v_t)`,
:math:`c_d = 0` for :math:`|v_t| \le v_0`, linear up to 1 at :math:`v_1`; ``friction_law =
"tanh"`` uses :math:`c_d\,\mathrm{sgn} = \tanh(v_t / v_0)` instead (smooth).

Lubrication: the hydrodynamic short journal bearing (Ocvirk; the forces in the form of Pinkus
& Sternlicht 1961, *Theory of Hydrodynamic Lubrication*, as used by Flores, Ambrósio, Claro,
Lankarani & Koshy 2006, Proc. IMechE K 220, 21-31), on the journal, along the unit vector of
the journal's eccentricity (radial) and perpendicular to it (tangential):

.. math:: F_r = -\frac{\mu_o L^3 R}{2c^2}\left[\frac{2\varepsilon^2(\omega_s - 2\dot\gamma)}
          {(1-\varepsilon^2)^2} + \frac{\pi(1 + 2\varepsilon^2)\dot\varepsilon}
          {(1-\varepsilon^2)^{5/2}}\right],\quad
          F_t = \frac{\mu_o L^3 R}{2c^2}\left[\frac{\pi\varepsilon(\omega_s - 2\dot\gamma)}
          {2(1-\varepsilon^2)^{3/2}} + \frac{4\varepsilon\dot\varepsilon}{(1-\varepsilon^2)^2}
          \right],

:math:`\varepsilon = |e|/c`, :math:`\gamma` its angle, :math:`\omega_s` the sum of the journal's
and the bearing's angular velocities. Above the eccentricity ratio ``eps_dry`` the film forces
are evaluated at ``eps_dry`` (continuous, bounded) and dry contact takes over for ``delta > 0``.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

__all__ = [
    "LAWS", "FRICTION_LAWS", "hysteresis_factor", "delivered_restitution", "hertz_stiffness",
    "normal_force", "ambrosio_friction", "tanh_friction", "FRICTION_ROLES", "power_law_normal",
    "power_law_elastic",
    "short_bearing_forces",
]  # fmt: skip

#: Normal-force laws (index = the code passed to the compiled kernels).
LAWS = ("hertz", "hunt-crossley", "lankarani-nikravesh", "flores", "gonthier")
FRICTION_LAWS = ("ambrosio", "tanh")


def hysteresis_factor(law: str, e: float) -> float:
    """``chi`` of the law for a nominal coefficient of restitution ``e`` (table above)."""
    if law not in LAWS:
        raise ValueError(f"contact_law = {law!r}; allowed: {', '.join(LAWS)}")
    if not 0.0 < e <= 1.0:
        raise ValueError(f"restitution = {e!r}; allowed: (0, 1]")
    return {
        "hertz": 0.0,
        "hunt-crossley": 1.5 * (1.0 - e),
        "lankarani-nikravesh": 0.75 * (1.0 - e * e),
        "flores": 8.0 * (1.0 - e) / (5.0 * e),
        "gonthier": (1.0 - e * e) / e,
    }[law]


def delivered_restitution(chi: float) -> float:
    """The restitution a single impact delivers under ``F = K d^n (1 + chi d'/d'-)``: the root
    ``e*`` in (0, 1] of ``chi (1 + e*) = ln((1 + chi) / (1 - chi e*))`` (module docstring).

    The force is clamped at zero, so when ``1 - chi e*`` would reach zero (``chi >= 1`` and a
    fast rebound) the relation still holds: the force's zero is then the separation."""
    if chi == 0.0:
        return 1.0
    from scipy.optimize import brentq

    def f(e):
        return chi * (1.0 + e) - math.log((1.0 + chi) / (1.0 - chi * e))

    hi = min(1.0, (1.0 - 1e-15) / chi)
    return float(brentq(f, 1e-12, hi, xtol=1e-15, rtol=1e-15))


def hertz_stiffness(R_j: float, R_b: float, E_j: float, nu_j: float, E_b: float,
                    nu_b: float) -> float:  # fmt: skip
    """Contact stiffness K (N/m^1.5) of a journal of radius ``R_j`` in a bearing ``R_b``."""
    if not R_b > R_j > 0:
        raise ValueError(f"need R_b > R_j > 0, got R_j = {R_j}, R_b = {R_b}")
    s = (1.0 - nu_j**2) / E_j + (1.0 - nu_b**2) / E_b
    return 4.0 / (3.0 * s) * math.sqrt(R_j * R_b / (R_b - R_j))


# The kernels below take real or complex arguments (numpy's scalar functions, branches on the
# real part): the contact model's Jacobian is the complex step of its right-hand side.


@nb.njit(cache=True)
def normal_force(delta, ddelta, v_impact, K, chi):
    """``F_n >= 0`` for penetration ``delta`` (m), its rate and the approach velocity."""
    if delta.real <= 0.0:
        return 0.0
    f = K * delta * np.sqrt(delta) * (1.0 + chi * ddelta / v_impact)
    return f if f.real > 0.0 else 0.0


# The built-in law as a contact law's roles (docs/components.md, a new contact law): the
# joints' module of the built-in law binds them (`recipdyn.model.assembler.templates.joints`).


@nb.njit(cache=True)
def power_law_normal(delta, ddelta, v_impact, K, p, o):
    """The ``normal`` role of the built-in law: `normal_force` with its hysteresis factor
    ``chi`` at ``p[o]``."""
    return normal_force(delta, ddelta, v_impact, K, p[o])


@nb.njit(cache=True)
def power_law_elastic(delta, K, p, o):
    """The ``elastic`` role of the built-in law: ``K delta^1.5``."""
    return K * delta * np.sqrt(delta)


# The built-in friction laws as the contact law's ``friction(vt, p, o)`` role: ``F_t / F_n``
# opposing the sliding velocity ``vt``, with the slice ``(mu, v0, v1)`` at ``o``. The pins'
# glue imports the one ``friction_law`` names (`FRICTION_ROLES`) when it is written, the
# guide's the one ``guide_friction_law`` names, so no kernel reads a law code.


@nb.njit(cache=True, inline="always")
def ambrosio_friction(vt, p, o):
    """Coulomb with Ambrósio's dynamic correction (module docstring): 0 for ``|vt| <= v0``,
    linear up to full Coulomb at ``v1``; slice ``(mu, v0, v1)`` at ``o``."""
    mu, v0, v1 = p[o], p[o + 1], p[o + 2]
    if mu == 0.0:
        return 0.0
    a = vt if vt.real > 0.0 else -vt
    if a.real <= v0:
        return 0.0
    cd = 1.0 if a.real >= v1 else (a - v0) / (v1 - v0)
    return -mu * cd * (1.0 if vt.real > 0.0 else -1.0)


@nb.njit(cache=True, inline="always")
def tanh_friction(vt, p, o):
    """Coulomb regularised by ``tanh(vt / v0)`` (smooth); slice ``(mu, v0, v1)`` at ``o``
    (``v1`` unused)."""
    mu, v0 = p[o], p[o + 1]
    if mu == 0.0:
        return 0.0
    x = vt / v0
    if abs(x.real) > 20.0:  # tanh = +-1 to 1e-17 (a complex tanh would overflow here)
        return -mu if x.real > 0.0 else mu
    return -mu * np.tanh(x)


#: The friction role function of each built-in ``friction_law`` (its name in this module).
FRICTION_ROLES = {"ambrosio": "ambrosio_friction", "tanh": "tanh_friction"}


@nb.njit(cache=True)
def short_bearing_forces(eps, deps, dgamma, omega_sum, mu_oil, L, R, c, eps_dry):
    """Film forces on the journal (radial, tangential), N; ``eps`` is clipped at ``eps_dry``."""
    if mu_oil == 0.0:
        return 0.0, 0.0
    e = eps if eps.real < eps_dry else eps_dry
    k = mu_oil * L**3 * R / (2.0 * c * c)
    s = 1.0 - e * e
    w = omega_sum - 2.0 * dgamma
    fr = -k * (2.0 * e * e * w / (s * s) + math.pi * (1.0 + 2.0 * e * e) * deps / s**2.5)
    ft = k * (math.pi * e * w / (2.0 * s**1.5) + 4.0 * e * deps / (s * s))
    return fr, ft
