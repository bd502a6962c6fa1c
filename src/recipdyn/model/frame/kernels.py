"""Compiled functions of the frame on its mounts (`recipdyn.model.frame.body`), by role.

Each reads the frame's slice of the parameter vector at the offset ``o`` (`body.PACKED`:
mass, inertia, K, C by rows, then per throw the cosine and sine of its cylinder angle and its
lever ``z_k - z_cm``); compiled once and linked by every configuration that holds a frame
(docs/architecture.md, Composing compiled components).
"""

import numba as nb

__all__ = ["throw_load", "frame_rhs"]

_MASS, _INERTIA, _K, _C, _THROWS = 0, 1, 2, 11, 20


@nb.njit(cache=True)
def throw_load(k, fx, fy, p, o):
    """Throw ``k``'s shaking force ``(fx, fy)`` in its own axes as generalised forces on the
    frame: ``(F_x, (z_k - z_cm) F_x)`` with ``F_x = cos(a) fx - sin(a) fy`` its component
    along the frame's x."""
    b = o + _THROWS + 3 * k
    f = p[b] * fx - p[b + 1] * fy
    return f, p[b + 2] * f


@nb.njit(cache=True)
def frame_rhs(qx, qpsi, y, s, w, p, o, out):
    """The frame's derivatives at ``out[s:s+6]`` (``x, z, psi`` and their rates) from ``M
    q'' = Q - K q - C q'`` with ``Q = (qx, 0, qpsi)``; at ``out[w]``, ``out[w+1]`` the power
    of the throws' forces ``Q . q'`` and the mounts' dissipation ``q'^T C q'``."""
    power = qx * y[s + 3] + qpsi * y[s + 5]
    loss = 0.0
    for i in range(3):
        f = qx if i == 0 else (qpsi if i == 2 else 0.0)
        d = 0.0
        for j in range(3):
            f -= p[o + _K + 3 * i + j] * y[s + j] + p[o + _C + 3 * i + j] * y[s + 3 + j]
            d += p[o + _C + 3 * i + j] * y[s + 3 + j]
        loss += y[s + 3 + i] * d
        out[s + i] = y[s + 3 + i]
        out[s + 3 + i] = f / (p[o + _INERTIA] if i == 2 else p[o + _MASS])
    out[w] = power
    out[w + 1] = loss
