"""Compiled functions of the drive components (`recipdyn.model.components.drive`): each
reads its own slice of the parameter vector at the offset ``o``."""

import numba as nb

__all__ = ["prescribed_crank", "constant_torque", "induction_torque"]


@nb.njit(cache=True)
def prescribed_crank(t, y, p, o):
    """``(theta1, omega1)`` of the prescribed drive (slice ``omega, theta1_0``)."""
    return p[o + 1] + p[o] * t, p[o]


@nb.njit(cache=True)
def constant_torque(w, p, o):
    """Constant motor torque, N m (slice ``motor_torque``)."""
    return p[o]


@nb.njit(cache=True)
def induction_torque(w, p, o):
    """Kloss's curve, N m (slice ``omega_s, T_b, s_b``); finite through s = 0."""
    s = (p[o] - w) / p[o]
    return 2.0 * p[o + 1] * s * p[o + 2] / (s * s + p[o + 2] * p[o + 2])
