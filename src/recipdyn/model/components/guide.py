r"""The crosshead guide: rigid (the crosshead on the line ``y = -d``), or with clearance.

``guide = clearance`` makes the crosshead a body of its own between the guide's upper and
lower shoes: it moves sideways within the radial clearance ``guide_clearance`` and tilts, and
its four corners (half-length ``crosshead_half_length``, half-height ``crosshead_half_height``
about the pin) strike the shoes with recipdyn's compliant contact law and regularised
Coulomb friction. The corner geometry, the contact forces, the phased event factor and its
reset are those of `recipdyn.model.joints.guide` (the Flores, Leine & Glocker 2010 joint,
checked against siconos), read at the guide's own slice of the parameter vector (layout
``S_*`` of that module) and called by the generated glue of the contact joints
(`recipdyn.model.components.contact`).

States it adds (after the joints'): the crosshead pin's lateral position from the guide's
centreline and the crosshead's tilt, their rates, and the four corners' recorded approach
velocities (their sign the phase: > 0 in contact).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..joints.contact import FRICTION_LAWS, LAWS, hysteresis_factor
from ..protocol import Param
from .contract import Component

__all__ = ["GUIDES", "GUIDE_PARAMS", "CLEARANCE", "guide_slice", "tilt_inertia"]

_INF = math.inf
#: The choices of the ``guide`` parameter.
GUIDES = ("ideal", "clearance")

#: The clearance guide's schema fragment (shared with `compressor-guide`).
GUIDE_PARAMS = (
    Param("guide_clearance", "m", 0.0, "radial clearance of the crosshead in its guide (shoe "
          "to guide: the crosshead's lateral play is twice it); 0 = the ideal guide", 0.0,
          0.01, assumed="assumed: a new guide; API 618 machines run 0.1-0.3 mm and more worn",
          group="guide"),
    Param("crosshead_half_length", "m", 0.15, "half the crosshead shoe's length along the "
          "guide, about the pin", 0.0, 2.0, low_open=True,
          assumed="assumed: not given in the paper", group="guide"),
    Param("crosshead_half_height", "m", 0.1, "half the crosshead's height, pin to shoe face",
          0.0, 2.0, low_open=True, assumed="assumed: not given in the paper", group="guide"),
    Param("crosshead_tilt_inertia", "kg*m**2", None, "crosshead's moment of inertia about the "
          "pin (default: a uniform block, m3 (a^2 + b^2) / 3)", 0.0, _INF, low_open=True,
          optional=True, group="guide"),
    Param("guide_stiffness", "N/m**1.5", 1e12, "contact stiffness K of a crosshead corner on a "
          "shoe (F = K delta^1.5 ...)", 0.0, _INF, low_open=True,
          assumed="assumed: stiff shoes; 40 kN of side force on one corner: 12 um",
          group="guide"),
    Param("guide_contact_law", "", "gonthier", "normal force law at the shoes", choices=LAWS,
          group="guide"),
    Param("guide_restitution", "", 0.5, "nominal restitution of a shoe impact", 0.0, 1.0,
          low_open=True, assumed="assumed: a lubricated shoe", group="guide"),
    Param("guide_friction", "", 0.05, "Coulomb friction coefficient at the shoes", 0.0, 2.0,
          assumed="assumed: boundary-lubricated shoe", group="guide"),
    Param("guide_friction_law", "", "ambrosio", "'ambrosio' (dynamic correction, v0/v1) or "
          "'tanh'", choices=FRICTION_LAWS, group="guide"),
    Param("guide_v0", "m/s", 1e-4, "friction: sliding velocity below which there is none", 0.0,
          _INF, low_open=True, group="guide"),
    Param("guide_v1", "m/s", 1e-3, "friction: sliding velocity above which it is full Coulomb",
          0.0, _INF, low_open=True, group="guide"),
)  # fmt: skip


def tilt_inertia(v: Mapping[str, Any]) -> float:
    """The crosshead's moment of inertia about the pin: the value given, or a uniform block's
    ``m3 (a^2 + b^2) / 3``."""
    if v.get("crosshead_tilt_inertia") is not None:
        return float(v["crosshead_tilt_inertia"])
    a, b = v["crosshead_half_length"], v["crosshead_half_height"]
    return float(v["m3"]) * (a * a + b * b) / 3.0


def guide_slice(v: Mapping[str, Any]) -> np.ndarray:
    """The clearance guide's slice (layout ``S_*`` of `recipdyn.model.joints.guide`): ``d``,
    the corners' geometry, the clearance, the contact law's stiffness and hysteresis factor,
    friction (the slice of the law ``guide_friction_law`` names, chosen when the glue is
    written), the approach velocity's floor, the event's length scale (the half-height), the
    tilt inertia."""
    b = v["crosshead_half_height"]
    return np.array([v["d"], v["crosshead_half_length"], b, v["guide_clearance"],
                     v["guide_stiffness"], hysteresis_factor(v["guide_contact_law"],
                                                             v["guide_restitution"]),
                     v["guide_friction"], v["guide_v0"], v["guide_v1"], v["v_impact_min"],
                     b, tilt_inertia(v)], dtype=np.float64)  # fmt: skip


#: The guide with clearance as a component of the contact joints' glue.
CLEARANCE = Component(
    "guide", "clearance", "the crosshead between the guide's shoes with a radial clearance "
    "(lateral motion, tilt, corner impacts with friction)",
    module="recipdyn.model.joints.guide",
    kernels={"forces": "slice_forces", "event": "slice_smallest_factor",
             "reset": "slice_flip_phases"},
    pack=guide_slice, params=GUIDE_PARAMS,
    states=(("guide_y", "m"), ("tilt", "rad"), ("guide_y_dot", "m/s"), ("tilt_dot", "rad/s")),
    aux_states=tuple((f"v_impact_guide_{k}", "m/s") for k in range(1, 5)),
)  # fmt: skip
