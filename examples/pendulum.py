"""A user's own model in a file of its own: the forced damped pendulum.

    theta'' + b theta' + (g / L) sin(theta) = A cos(w t)

Use it from the command line or the API without editing recipdyn:

    recipdyn models examples/pendulum.py:PENDULUM
    recipdyn simulate --model examples/pendulum.py:PENDULUM --set A="1.2 1/s**2" -n 50
    recipdyn.simulate(model="examples/pendulum.py:PENDULUM", revolutions=50)

or register it for good from a package's ``pyproject.toml``::

    [project.entry-points."recipdyn.models"]
    pendulum = "mypackage.pendulum:PENDULUM"

A model declares its state, a parameter schema (units, ranges, descriptions) and compiled
kernels with the calling convention of ``recipdyn.model.base`` (``rhs(t, y, p, out)``,
``jac(t, y, p, J)``); everything else (simulate, figures, records with every input) comes from
recipdyn. With b = 0.5, g/L = 1, A = 1.2, w = 2/3 the pendulum is chaotic (Baker & Gollub,
*Chaotic Dynamics*, 1996, Sec. 3); its two Lyapunov exponents sum to -b exactly.
"""

from __future__ import annotations

import math

import numpy as np

from recipdyn.model.base import JAC_SIGNATURE, RHS_SIGNATURE, ODESystem, compiled
from recipdyn.model.protocol import Model, Param, Schema


# numba, compiled on first use and cached on disk; a kernel that allocates arrays (np.empty)
# says @compiled(SIGNATURE, allocates=True), see docs/architecture.md, Compiled kernels
@compiled(RHS_SIGNATURE)
def _rhs(t, y, p, out):
    out[0] = y[1]
    out[1] = -p[0] * y[1] - p[1] * math.sin(y[0]) + p[2] * math.cos(p[3] * t)


@compiled(JAC_SIGNATURE)
def _jac(t, y, p, J):
    J[0, 0], J[0, 1] = 0.0, 1.0
    J[1, 0], J[1, 1] = -p[1] * math.cos(y[0]), -p[0]


class Pendulum(Model):
    name = "pendulum"
    description = "forced damped pendulum theta'' + b theta' + (g/L) sin(theta) = A cos(w t)"
    state_names = ("theta", "omega")
    state_units = ("rad", "rad/s")
    schema = Schema((
        Param("b", "1/s", 0.5, "damping", 0.0, math.inf, group="pendulum"),
        Param("g_over_L", "1/s**2", 1.0, "gravity over length", 0.0, math.inf, low_open=True,
              group="pendulum"),
        Param("A", "1/s**2", 1.2, "forcing amplitude", -math.inf, math.inf, group="forcing"),
        Param("w", "rad/s", 2.0 / 3.0, "forcing frequency", 0.0, math.inf, low_open=True,
              group="forcing"),
        Param("theta0", "rad", 0.2, "initial angle", -1e3, 1e3, group="initial"),
        Param("omega0", "rad/s", 0.0, "initial angular velocity", -1e3, 1e3, group="initial"),
    ))  # fmt: skip

    def system(self, values):
        p = np.array([values["b"], values["g_over_L"], values["A"], values["w"]], dtype=float)
        return ODESystem(rhs=_rhs, jac=_jac, params=p, state_names=self.state_names,
                         state_units=self.state_units, period=self.period(values),
                         name=self.name)  # fmt: skip

    def initial_state(self, values):
        return np.array([values["theta0"], values["omega0"]], dtype=float)

    def period(self, values):
        return 2.0 * math.pi / values["w"]


PENDULUM = Pendulum()
