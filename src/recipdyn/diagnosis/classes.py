"""The fault classes a diagnoser tells apart, the healthy machine they depart from, and the
operating conditions and sensor settings a data set spans.

Adding a class is one entry of `CLASSES`: its name, the model parameter that carries the
fault, the parameter's values at the mildest and the most severe level, the scale between
them, what the fault is physically and, if the fault needs it, the model's selectors its
records set (the worn crosshead guide is simulated with ``guide = clearance``; every other
record keeps the rigid guide). Every class is a parameter of one model,
`MODEL` (the contact–impact joints at both pins with the gas and dynamic valves), so the
healthy baseline is the same machine for every class.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = [
    "FaultClass",
    "CLASSES",
    "HEALTHY",
    "MODEL",
    "BASELINE",
    "CONDITIONS",
    "Range",
    "class_names",
    "get_class",
]

#: The one model every record is simulated with.
MODEL = "compressor-contact-valves"

#: The healthy machine: the model's defaults with both pins in clearance joints whose radial
#: clearance (0.1 mm) is that of a new bearing of this size (about 1e-3 of the pin diameter),
#: and the rigid crosshead guide (``guide = ideal``, the model's default): a new guide's
#: oil-filled play is not modelled (docs/diagnosis.md).
BASELINE: dict[str, object] = {
    "clearance_joints": "both",
    "rc": 1.0e-4,
    "rc_crosshead": 1.0e-4,
}


@dataclass(frozen=True)
class FaultClass:
    """One fault class.

    Parameters
    ----------
    name : str
        Class label (snake case).
    parameter : str or None
        The model parameter that carries the fault (None: the healthy machine).
    mild, severe : float
        The parameter's value at severity 0 (the mildest level in the data set) and 1 (the
        most severe), in the parameter's SI unit.
    unit : str
        The parameter's unit.
    scale : {"log", "linear"}
        How the value runs from ``mild`` to ``severe`` with the severity: geometrically (areas,
        clearances, forces that span a decade) or linearly.
    meaning : str
        What the fault is on a real machine.
    requires : tuple of (str, object)
        Model settings every record of this class needs besides the fault parameter (e.g.
        ``(("guide", "clearance"),)``: the guide's clearance is a parameter of the model only
        with the clearance guide); the other classes' records keep the `BASELINE`.
    """

    name: str
    parameter: str | None
    mild: float = math.nan
    severe: float = math.nan
    unit: str = ""
    scale: str = "log"
    meaning: str = ""
    requires: tuple[tuple[str, object], ...] = ()

    def value(self, severity: float) -> float:
        """The parameter's value at ``severity`` in [0, 1]."""
        s = min(max(float(severity), 0.0), 1.0)
        if self.scale == "log":
            return self.mild * (self.severe / self.mild) ** s
        return self.mild + (self.severe - self.mild) * s

    def severity(self, value: float) -> float:
        """Inverse of `value` (not clipped: a value beyond ``severe`` gives more than 1)."""
        if self.scale == "log":
            return math.log(value / self.mild) / math.log(self.severe / self.mild)
        return (value - self.mild) / (self.severe - self.mild)

    def overrides(self, severity: float) -> dict[str, float]:
        """Model parameters of this fault at ``severity`` (empty for the healthy machine): the
        settings it `requires` and the fault parameter's value."""
        if self.parameter is None:
            return {}
        return {**dict(self.requires), self.parameter: self.value(severity)}


HEALTHY = FaultClass(
    "healthy",
    None,
    meaning="the baseline machine: new pin bearings "
    "(0.1 mm radial clearance), the rigid crosshead guide, tight valves and rings, nominal "
    "springs",
)

#: The fault classes after the healthy one; one entry each (docs/diagnosis.md, data card).
CLASSES: tuple[FaultClass, ...] = (
    HEALTHY,
    FaultClass(
        "crank_pin_clearance",
        "rc",
        2e-4,
        1e-3,
        "m",
        meaning="worn crank-pin (big-end) bearing: radial clearance 0.2 to 1 mm",
    ),
    FaultClass(
        "crosshead_pin_clearance",
        "rc_crosshead",
        2e-4,
        8e-4,
        "m",
        meaning="worn crosshead-pin (small-end) bushing: radial clearance 0.2 to 0.8 mm",
    ),
    FaultClass(
        "crosshead_guide_clearance",
        "guide_clearance",
        2e-4,
        8e-4,
        "m",
        meaning="worn crosshead guide (shoes or guide bore): radial clearance 0.2 to 0.8 mm "
        "shoe to guide, a lateral play of 0.4 to 1.6 mm on the 200 mm crosshead (assumed: "
        "a new guide ~0.1-0.15 mm of diametral play per 100 mm of crosshead, 0.2-0.3 mm "
        "here; the mildest level is about twice that, a usual wear limit, the most severe "
        "five to eight times it); the crosshead knocks on the shoes where the side force "
        "reverses",
        requires=(("guide", "clearance"),),
    ),
    FaultClass(
        "suction_valve_leak",
        "leak_area_suction_head",
        3e-5,
        3e-4,
        "m**2",
        meaning="leaking head-end suction valve (broken plate, eroded seat, debris): "
        "0.3 to 3 cm2 of leak area (0.2 to 2 % of the valve's flow area)",
    ),
    FaultClass(
        "discharge_valve_leak",
        "leak_area_discharge_head",
        5e-6,
        5e-5,
        "m**2",
        meaning="leaking head-end discharge valve: 0.05 to 0.5 cm2 of leak area",
    ),
    FaultClass(
        "weak_valve_spring",
        "spring_factor_suction_head",
        0.7,
        0.0,
        "1",
        scale="linear",
        meaning="weak or broken head-end suction-valve spring: stiffness and preload "
        "times 0.7 down to 0 (broken)",
    ),
    FaultClass(
        "sticking_valve",
        "adhesion_force_suction_head",
        20.0,
        300.0,
        "N",
        meaning="sticking head-end suction plate (oil stiction): 20 to 300 N holding "
        "it on its seat (4 to 60 times the preload)",
    ),
    FaultClass(
        "ring_leak",
        "ring_leak_area",
        2e-5,
        2e-4,
        "m**2",
        meaning="worn or broken piston rings: 0.2 to 2 cm2 of leak area between the chambers",
    ),
)


def class_names(classes=CLASSES) -> list[str]:
    return [c.name for c in classes]


def get_class(name: str, classes=CLASSES) -> FaultClass:
    from ..errors import ParameterError

    for c in classes:
        if c.name == name:
            return c
    raise ParameterError(f"fault class {name!r}; allowed: {', '.join(class_names(classes))}")


@dataclass(frozen=True)
class Range:
    """A uniform range ``[lo, hi]`` of an operating condition or a sensor setting."""

    lo: float
    hi: float
    unit: str
    meaning: str

    def draw(self, rng) -> float:
        return float(rng.uniform(self.lo, self.hi)) if self.hi > self.lo else float(self.lo)


#: The operating conditions and sensor settings a condition draws (uniformly, seeded).
CONDITIONS: dict[str, Range] = {
    "omega": Range(16.0, 24.0, "rad/s", "crank speed (153 to 229 rpm)"),
    "suction_pressure": Range(0.9e5, 1.1e5, "Pa", "suction line pressure, absolute"),
    "discharge_pressure": Range(2.7e5, 3.3e5, "Pa", "discharge line pressure, absolute"),
    "m2": Range(18.0, 22.0, "kg", "connecting-rod mass (±10 % of 20 kg)"),
    "m3": Range(27.0, 33.0, "kg", "crosshead and piston mass (±10 % of 30 kg)"),
    "resonance_hz": Range(3000.0, 4500.0, "Hz", "accelerometer mounting resonance"),
    "fs": Range(10_000.0, 12_500.0, "Hz", "sampling rate (rounded to 100 Hz)"),
}
