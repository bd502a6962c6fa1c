"""Two components added to the compressor from this one file, recipdyn untouched (issue 30,
item 6; docs/components.md): a load and a motor torque law. Used by
``tests/test_plugin_components.py`` as ``--set load=tests/plugin_components.py:HARMONIC`` and
``--set drive=motor --set motor=tests/plugin_components.py:LINEAR``."""

import math

import numba as nb
import numpy as np

from recipdyn.model.components.contract import Component
from recipdyn.model.protocol import Param


@nb.njit(cache=True, inline="always")
def harmonic_force(th1, p, o):
    """A gas force that only pushes the piston toward the crank, ``-A (1 + cos(k th1 +
    phi))`` (slice: amplitude, order, phase)."""
    return -p[o] * (1.0 + math.cos(p[o + 1] * th1 + p[o + 2]))


HARMONIC = Component(
    "load", "harmonic", "a one-sided harmonic force in the crank angle",
    module=__name__, kernels={"force": "harmonic_force"},
    pack=lambda v: np.array([v["harmonic_amplitude"], v["harmonic_order"],
                             v["harmonic_phase"]]),
    params=(
        Param("harmonic_amplitude", "N", 5.0e4, "half the peak force", 0.0, 1e9, group="load"),
        Param("harmonic_order", "", 1.0, "crank order of the force", 0.0, 100.0, group="load"),
        Param("harmonic_phase", "rad", 0.3, "phase of the force", -math.pi, math.pi,
              group="load"),
    ),
)  # fmt: skip


@nb.njit(cache=True, inline="always")
def linear_torque(w, p, o):
    """A straight torque-speed line through the synchronous speed, ``T = c (w_s - w)``
    (slice: slope c, synchronous speed w_s): the linear part of an induction motor's curve."""
    return p[o] * (p[o + 1] - w)


LINEAR = Component(
    "motor", "linear", "a linear torque-speed line", module=__name__,
    kernels={"torque": "linear_torque"},
    pack=lambda v: np.array([v["linear_slope"], v["linear_sync_speed"]]),
    params=(
        Param("linear_slope", "N*m*s", 2.0e4, "torque per rad/s of slip speed", 0.0, 1e9,
              low_open=True, group="drive"),
        Param("linear_sync_speed", "rad/s", 21.0, "speed of zero torque", 0.0, 1e4,
              low_open=True, group="drive"),
    ),
)  # fmt: skip

#: Not a component: a spec naming it is refused.
NOT_A_COMPONENT = 42
