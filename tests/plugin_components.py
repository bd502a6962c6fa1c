"""Components added to the compressor from this one file, recipdyn untouched (issue 30,
item 6; docs/components.md): a load, a motor torque law and two contact laws of the pin joints.
Used by ``tests/test_plugin_components.py`` as
``--set load=tests/plugin_components.py:HARMONIC``,
``--set drive=motor --set motor=tests/plugin_components.py:LINEAR`` and
``--set crank_joint=contact --set contact_law=tests/plugin_components.py:KELVIN_VOIGT``, and
by ``tests/test_contact_law_plugin.py``."""

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

#: The paper's load of recipdyn under another name, from this file (the same kernels and
#: slice: ``load_amplitude`` and ``load_sign``, the compressor's own parameters): a user's
#: load must give the built-in load's trajectory.
PAPER_AGAIN = Component(
    "load", "paper-again", "the paper's load, re-exported", module="recipdyn.model.components.load",
    kernels={"force": "paper_force", "force_sc": "paper_force_sc"},
    pack=lambda v: np.array([v["load_amplitude"],
                             -1.0 if v["load_sign"] == "physical" else 1.0]),
)  # fmt: skip


@nb.njit(cache=True, inline="always")
def spring_force(th1, p, o):
    """A gas spring in the crank angle: ``-p0 (1 + k (1 - cos th1))`` (slice: p0, k), a
    pressure force that grows as the crosshead nears the crank end."""
    return -p[o] * (1.0 + p[o + 1] * (1.0 - math.cos(th1)))


SPRING = Component(
    "load", "spring", "a gas spring in the crank angle", module=__name__,
    kernels={"force": "spring_force"},
    pack=lambda v: np.array([v["spring_preload"], v["spring_rate"]]),
    params=(
        Param("spring_preload", "N", 2.0e4, "force at outer dead centre", 0.0, 1e9,
              group="load"),
        Param("spring_rate", "", 1.5, "growth of the force over half a stroke", 0.0, 100.0,
              group="load"),
    ),
)  # fmt: skip

# -- a load with a state: a closed gas chamber over the crosshead with a relief valve. The
# chamber's volume is A (x_top - x3); its gas is compressed polytropically, p (x_top - x3)^n
# constant, until the pressure reaches the relief valve's set pressure, which vents it at
# once to the vent pressure (an event of the load and its reset).


@nb.njit(cache=True, inline="always")
def chamber_force(y, g, p, o):
    """The chamber's pressure on the crosshead, ``-(p_c - p_frame) A`` (slice: A, x_top, n,
    p_frame, p_relief, p_vent)."""
    return -(y[g] - p[o + 3]) * p[o]


@nb.njit(cache=True, inline="always")
def chamber_rhs(x, xdot, y, g, a, p, o, out):
    """``p_c' = n p_c x3' / (x_top - x3)``: the polytrope of the closed chamber."""
    out[g] = p[o + 2] * y[g] * xdot / (p[o + 1] - x)


@nb.njit(cache=True, inline="always")
def chamber_event(y, g, p, o):
    """The relief valve's factor: positive below its set pressure."""
    return (p[o + 4] - y[g]) / p[o + 4]


@nb.njit(cache=True, inline="always")
def chamber_reset(y, g, p, o, out):
    """The relief valve vents the chamber to the vent pressure."""
    for i in range(y.shape[0]):
        out[i] = y[i]
    out[g] = p[o + 5]


CHAMBER = Component(
    "load", "chamber", "a closed gas chamber with a relief valve", module=__name__,
    kernels={"state_force": "chamber_force", "state_rhs": "chamber_rhs",
             "event": "chamber_event", "reset": "chamber_reset"},
    pack=lambda v: np.array([v["chamber_area"], v["chamber_top"], v["chamber_n"],
                             v["frame_pressure"], v["chamber_relief"], v["chamber_vent"]]),
    states=(("p_chamber", "Pa"),),
    initial=lambda v: np.array([v["chamber_p0"]]),
    params=(
        Param("chamber_area", "m**2", 0.05, "piston area", 0.0, 1.0, low_open=True,
              group="load"),
        Param("chamber_top", "m", 0.75, "crosshead position of zero volume (> r + l)", 0.0,
              10.0, low_open=True, group="load"),
        Param("chamber_n", "", 1.3, "polytropic exponent", 1.0, 2.0, group="load"),
        Param("chamber_relief", "Pa", 1.0e6, "relief valve's set pressure", 0.0, 1e9,
              low_open=True, group="load"),
        Param("chamber_vent", "Pa", 5.0e5, "pressure the relief valve vents to", 0.0, 1e9,
              group="load"),
        Param("chamber_p0", "Pa", 1.0e5, "pressure at t = 0", 0.0, 1e9, group="load"),
    ),
)  # fmt: skip

#: A load with a state but no initial states: refused (its start is unknown).
WITH_STATES = Component(
    "load", "stateless-start", "a load with a state, no initial", module=__name__,
    kernels=CHAMBER.kernels, pack=CHAMBER.pack, states=CHAMBER.states,
)  # fmt: skip

# -- contact laws of the pin joints (family ``contact_law``). Their functions take complex
# arguments too (the joints' Jacobian is the complex step): branches on the real part.


@nb.njit(cache=True, inline="always")
def ln_normal(delta, ddelta, v_impact, K, p, o):
    """Lankarani & Nikravesh (1990) written again: ``K delta^1.5 (1 + chi delta' / v-)``,
    clamped at 0 (slice: chi)."""
    f = K * delta * np.sqrt(delta) * (1.0 + p[o] * ddelta / v_impact)
    return f if f.real > 0.0 else 0.0


@nb.njit(cache=True, inline="always")
def hertz_elastic(delta, K, p, o):
    """Hertz's elastic force ``K delta^1.5``."""
    return K * delta * np.sqrt(delta)


@nb.njit(cache=True, inline="always")
def hertz_potential(delta, K, p, o):
    """Its energy ``K delta^2.5 / 2.5``."""
    return K * delta**2.5 / 2.5


LANKARANI = Component(
    "contact_law", "ln-again", "Lankarani-Nikravesh, from a user's file", module=__name__,
    kernels={"normal": "ln_normal", "elastic": "hertz_elastic", "potential": "hertz_potential"},
    pack=lambda v: np.array([0.75 * (1.0 - v["ln_restitution"] * v["ln_restitution"])]),
    params=(Param("ln_restitution", "", 0.9, "nominal coefficient of restitution", 0.0, 1.0,
                  low_open=True, group="joint"),),
)  # fmt: skip


@nb.njit(cache=True, inline="always")
def kv_normal(delta, ddelta, v_impact, K, p, o):
    """A linear spring and dashpot (Kelvin-Voigt) ``k delta + c delta'``, clamped at 0 (a
    contact cannot pull); K and the approach velocity are not used (slice: k, c)."""
    f = p[o] * delta + p[o + 1] * ddelta
    return f if f.real > 0.0 else 0.0


@nb.njit(cache=True, inline="always")
def kv_elastic(delta, K, p, o):
    """The spring ``k delta``."""
    return p[o] * delta


KELVIN_VOIGT = Component(
    "contact_law", "kelvin-voigt", "a linear spring-dashpot contact", module=__name__,
    kernels={"normal": "kv_normal", "elastic": "kv_elastic"},
    pack=lambda v: np.array([v["kv_stiffness"], v["kv_damping"]]),
    params=(
        Param("kv_stiffness", "N/m", 1.0e9, "contact stiffness k", 0.0, 1e13, low_open=True,
              group="joint"),
        Param("kv_damping", "N*s/m", 1.0e5, "contact damping c", 0.0, 1e9, group="joint"),
    ),
)  # fmt: skip

#: A contact law without its elastic part: refused (the power lost needs it).
NO_ELASTIC = Component("contact_law", "broken", "a normal force alone", module=__name__,
                       kernels={"normal": "kv_normal"})  # fmt: skip

#: Not a component: a spec naming it is refused.
NOT_A_COMPONENT = 42
