r"""The paper's simplified coefficients, Eq. (43)-(47), exactly as printed (a labelled variant).

Xiao et al. (2017) write the equation of motion as (Eq. 38)

.. math:: A\,\ddot\theta_c = B\,\dot\theta_c + C\,\dot\theta_c^2 + D

and, after assuming ``l = 2 l_s`` and "``r_c x + y ~ y``", print closed forms for A, B, C, D
(Eq. 43-47). They are transcribed here symbol for symbol, including what we believe are errata,
so that the paper's results can be compared with the exact model
(``CompressorParams(equations="paper-printed")``). Gravity does not appear in them. ``P`` in
``d1 = P r_c`` is taken as the signed force on the crosshead along +x (``F_x``), which makes
``load_sign="paper"`` reproduce the printed equation exactly.

The list of errata and their tests: ``docs/errata.md`` and ``tests/test_errata.py``.
"""

from __future__ import annotations

import math

import numba as nb

__all__ = ["paper_coefficients", "paper_acceleration"]


@nb.njit(cache=True)
def paper_coefficients(theta1, theta_c, F, r, l, m2, m3, J2, rc, d, omega):
    """A, B, C, D of Eq. (43)-(47) as printed; theta2 from Eq. (4)."""
    th2 = -math.asin((d + r * math.sin(theta1) + rc * math.sin(theta_c)) / l)
    s1, c1 = math.sin(theta1), math.cos(theta1)
    sc, cc = math.sin(theta_c), math.cos(theta_c)
    s2, c2 = math.sin(th2), math.cos(th2)
    t2 = s2 / c2
    # Eq. (43)
    a1 = J2 * (rc / l) ** 2
    a2 = m2 * rc**2
    a3 = m3 * rc**2
    A = (a1 + a2 / 4.0) * (cc / c2) ** 2 + a2 + a2 * cc * (sc * t2 - cc) + a3 * (t2 * cc - sc) ** 2
    # Eq. (44)
    b1 = -2.0 * omega * J2 * rc**2 * r / l**3
    b2 = -m2 * r * rc**2 * omega / (4.0 * l)
    b3 = 3.0 * b2
    b4 = -2.0 * m3 * r * rc**2 * omega
    B = (c1 * cc / c2**4) * (
        b1 * s2 * c1 + b2 * math.sin(th2 + theta_c) + (b3 + b4) * math.sin(theta_c - th2)
    )
    # Eq. (45)
    k2 = m2 * rc**2
    k3 = -m3 * rc**2 / 2.0
    k1 = -J2 * rc**2 / (2.0 * l**2) + 3.0 * k2 / 16.0 - k3
    C = (
        k1 * sc
        + k2 * (5.0 / 16.0 * math.cos(2 * th2) * math.sin(2 * theta_c)
                - 0.25 * math.cos(2 * theta_c) * math.sin(2 * th2))
        + k3 * math.sin(2 * th2)
    ) / c2**2 - k2 / 8.0 * math.sin(2 * theta_c)  # fmt: skip
    # Eq. (46)-(47)
    d0 = omega**2 * r * rc
    d1 = F * rc
    d2 = d0 * J2 / l**2
    d3 = d0 * (m2 / 2.0 + m3)
    d4 = d0 * (m2 / 4.0 + m3 + m2 / 4.0 * sc)
    d5 = d0 * m2 / 4.0
    D = d1 * (-sc + t2 * cc) - (
        d2 * cc / c2**4 * (l * c2**2 * s1 + r * s2 * c1**2)
        + d3 * math.sin(theta_c - th2) * c1 / c2
        + d4 * (t2 * s1 + r * c1**2 / (l * c2**3))
        + d5 * (sc * c1 + math.sin(theta_c - theta1))
    )
    return A, B, C, D


@nb.njit(cache=True)
def paper_acceleration(theta1, theta_c, thetadot_c, F, r, l, m2, m3, J2, rc, d, omega):
    """theta_c'' from Eq. (38) with the printed coefficients."""
    A, B, C, D = paper_coefficients(theta1, theta_c, F, r, l, m2, m3, J2, rc, d, omega)
    return (B * thetadot_c + C * thetadot_c**2 + D) / A
