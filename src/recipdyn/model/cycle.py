r"""Gas load from the compression cycle: ideal valves, polytropic compression and re-expansion.

The cylinder lies beyond the outer dead centre (crank angle 0, crosshead farthest from the
crank, as in `load`). The crosshead position follows the crank angle with the ideal
kinematics of the offset slider-crank (the guide at ``y = -d``)::

    x(theta1) = r cos(theta1) + sqrt(l^2 - (d + r sin(theta1))^2),

between ``x_min`` (inner dead centre) and ``x_max`` (outer dead centre), stroke
``s = x_max - x_min``. The two working chambers:

* head end, area ``A = pi D^2 / 4``: ``V_he = C A s + A (x_max - x)``;
* crank end, area ``A - A_rod``: ``V_ce = C (A - A_rod) s + (A - A_rod) (x - x_min)``;

``C`` the clearance-volume fraction of the swept volume. With ideal valves (open exactly at the
line pressures, no pressure drop) and polytropic exponents ``n_c`` (compression) and ``n_e``
(re-expansion), a chamber of swept volume ``V_s`` and clearance volume ``V_0 = C V_s`` has

* while its volume grows: ``p = max(p_s, p_top (V_0 / V)^{n_e})`` (re-expansion, then suction);
* while it shrinks: ``p = min(p_d, p_bot (V_max / V)^{n_c})`` (compression, then discharge);

``p_top = min(p_d, p_s (V_max / V_0)^{n_c})`` (below p_d only when the compression cannot open
the discharge valve: no delivery) and ``p_bot = max(p_s, p_top (V_0 / V_max)^{n_e})``.

The force on the crosshead along +x (head-end gas pushes toward the crank) is::

    F = -p_he A + p_ce (A - A_rod) + p_frame A_rod,

with an inactive chamber at the frame pressure ``p_frame`` (single-acting: ``acting = "head"``
or ``"crank"``). With ``n_c = n_e = n`` the cycle has the closed forms (e.g. Hanlon,
*Compressor Handbook*, 2001, ch. 2; Bloch & Hoefner, *Reciprocating Compressors*, 1996)::

    eta_v = 1 - C ((p_d/p_s)^(1/n) - 1)
    W     = n/(n-1) p_s eta_v V_s ((p_d/p_s)^((n-1)/n) - 1)    (indicated work a cycle)

which [`ideal_volumetric_efficiency`][recipdyn.model.cycle.ideal_volumetric_efficiency] and
[`ideal_indicated_work`][recipdyn.model.cycle.ideal_indicated_work] return and the tests compare
with the quadrature of ``p dV`` of this kernel.

Limits, stated: the volume follows the crank angle, not the clearance-joint state (the piston
position differs by up to the clearance, ``rc / s`` ~ 0.4 % of the stroke at the paper's base
case); the pressures are those of ideal valves (no valve dynamics, no pulsation); the gas is
ideal with constant exponents.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

__all__ = [
    "pressure_force", "CYCLE_PARAMS", "cycle_data", "pin_reversal_summary",
    "CycleGeometry", "cycle_geometry", "pack_cycle", "cycle_state", "cycle_force_kernel",
    "ideal_volumetric_efficiency", "ideal_indicated_work", "indicated_work",
    "volumetric_efficiency", "RodReversal", "rod_load_reversal", "ACTING", "last_revolution",
    "mean_speed",
]  # fmt: skip

#: Parameter names of the compression cycle, in [`pack_cycle`][recipdyn.model.cycle.pack_cycle]'s
#: keyword order.
CYCLE_PARAMS = ("bore", "rod_diameter", "clearance_fraction", "suction_pressure",
                "discharge_pressure", "n_compression", "n_expansion", "frame_pressure",
                "acting")  # fmt: skip

#: Which chambers compress gas: 1 head end, 2 crank end, 3 both.
ACTING = {"head": 1.0, "crank": 2.0, "double": 3.0}

# Layout of the packed cycle data (after the load-kind header in the model's parameter vector).
(C_R, C_L, C_D, C_XMAX, C_XMIN, C_THODC, C_THIDC, C_AHE, C_ACE, C_AROD, C_CLEAR, C_PS, C_PD,
 C_NC, C_NE, C_PFRAME, C_ACTING, C_PTOP, C_PBOT) = range(19)  # fmt: skip
N_CYCLE = 19


@dataclass(frozen=True)
class CycleGeometry:
    """Dead centres and chamber sizes of the offset slider-crank (SI units)."""

    x_max: float
    x_min: float
    theta_odc: float  # crank angle of the outer dead centre (x = x_max), in [-pi, pi)
    theta_idc: float  # crank angle of the inner dead centre (x = x_min), near pi
    area_head: float
    area_crank: float
    area_rod: float

    @property
    def stroke(self) -> float:
        return self.x_max - self.x_min


def pressure_force(p_head, p_crank, *, bore: float, rod_diameter: float,
                   frame_pressure: float):  # fmt: skip
    """Gas force on the crosshead along +x from the chamber pressures (Pa, absolute):
    ``F = -p_he A + p_ce (A - A_rod) + p_frame A_rod`` (the kernel's formula, for tables)."""
    area = math.pi * bore**2 / 4.0
    a_rod = math.pi * rod_diameter**2 / 4.0
    return -np.asarray(p_head) * area + np.asarray(p_crank) * (area - a_rod) \
        + frame_pressure * a_rod  # fmt: skip


def _x(theta, r, l, d):
    return r * np.cos(theta) + np.sqrt(l * l - (d + r * np.sin(theta)) ** 2)


def cycle_geometry(r: float, l: float, d: float, bore: float, rod_diameter: float
                   ) -> CycleGeometry:  # fmt: skip
    """Dead centres of the offset slider-crank, exactly: crank and rod aligned, stretched out
    (crank pin toward the crosshead, ``sin(theta) = -d / (l + r)``) or folded (the crank pin
    opposite, ``sin(theta) = d / (l - r)``, theta near pi)."""
    th_odc = math.asin(-d / (l + r))  # x = sqrt((l + r)^2 - d^2)
    th_idc = math.pi - math.asin(d / (l - r))  # x = sqrt((l - r)^2 - d^2)
    x_max = float(_x(th_odc, r, l, d))
    x_min = float(_x(th_idc, r, l, d))
    a = math.pi * bore**2 / 4.0
    a_rod = math.pi * rod_diameter**2 / 4.0
    return CycleGeometry(x_max, x_min, th_odc, th_idc, a, a - a_rod, a_rod)


def pack_cycle(r: float, l: float, d: float, *, bore: float, rod_diameter: float,
               clearance_fraction: float, suction_pressure: float, discharge_pressure: float,
               n_compression: float, n_expansion: float, frame_pressure: float,
               acting: str) -> np.ndarray:  # fmt: skip
    """The cycle's data vector for [`cycle_force_kernel`][recipdyn.model.cycle.cycle_force_kernel]
    (layout: the ``C_*`` constants)."""
    g = cycle_geometry(r, l, d, bore, rod_diameter)
    # the chambers' pressures at the dead centres are constants (module docstring): computed
    # once here, so a call of the kernel costs one power per chamber
    c = clearance_fraction
    p_top = min(discharge_pressure, suction_pressure * ((1.0 + c) / c) ** n_compression)
    p_bot = max(suction_pressure, p_top * (c / (1.0 + c)) ** n_expansion)
    return np.array([r, l, d, g.x_max, g.x_min, g.theta_odc, g.theta_idc, g.area_head,
                     g.area_crank, g.area_rod, clearance_fraction, suction_pressure,
                     discharge_pressure, n_compression, n_expansion, frame_pressure,
                     ACTING[acting], p_top, p_bot], dtype=np.float64)  # fmt: skip


def cycle_data(values) -> np.ndarray:
    """[`pack_cycle`][recipdyn.model.cycle.pack_cycle] of a mapping of parameter values (the
    mechanism's ``r``, ``l``, ``d`` and `CYCLE_PARAMS`)."""
    return pack_cycle(values["r"], values["l"], values["d"],
                      **{k: values[k] for k in CYCLE_PARAMS})  # fmt: skip


@nb.njit(cache=True, inline="always")
def _chamber(V, V0, Vs, growing, ps, pd, nc, ne, p_top, p_bot):
    """Pressure of an ideal-valve chamber. At the top (V0) it holds ``p_top``: p_d, or less
    when compression from p_s cannot reach p_d (no delivery); at the bottom ``p_bot``: p_s,
    or more when re-expansion cannot reach p_s (both the same for either chamber)."""
    if growing:
        return max(ps, p_top * (V0 / V) ** ne)
    return min(pd, p_bot * ((V0 + Vs) / V) ** nc)


@nb.njit(cache=True, inline="always")
def cycle_state(theta1, c):
    """``(p_head, p_crank, V_head, V_crank)`` at crank angle ``theta1`` (Pa, m^3)."""
    r, l, d = c[C_R], c[C_L], c[C_D]
    s = d + r * math.sin(theta1)
    x = r * math.cos(theta1) + math.sqrt(l * l - s * s)
    xmax, xmin = c[C_XMAX], c[C_XMIN]
    stroke = xmax - xmin
    # x falls from the outer to the inner dead centre: the head end grows, the crank end shrinks
    phi = (theta1 - c[C_THODC]) % (2.0 * math.pi)
    head_grows = phi < c[C_THIDC] - c[C_THODC]
    ps, pd, nc, ne, pf = c[C_PS], c[C_PD], c[C_NC], c[C_NE], c[C_PFRAME]
    acting = int(c[C_ACTING])
    vs_he = c[C_AHE] * stroke
    v0_he = c[C_CLEAR] * vs_he
    v_he = v0_he + c[C_AHE] * (xmax - x)
    vs_ce = c[C_ACE] * stroke
    v0_ce = c[C_CLEAR] * vs_ce
    v_ce = v0_ce + c[C_ACE] * (x - xmin)
    pt, pb = c[C_PTOP], c[C_PBOT]
    p_he = _chamber(v_he, v0_he, vs_he, head_grows, ps, pd, nc, ne, pt, pb) if acting & 1 else pf
    p_ce = (_chamber(v_ce, v0_ce, vs_ce, not head_grows, ps, pd, nc, ne, pt, pb)
            if acting & 2 else pf)  # fmt: skip
    return p_he, p_ce, v_he, v_ce


@nb.njit(cache=True)
def cycle_force_kernel(theta1, c):
    """Gas force on the crosshead along +x, N (see the module docstring)."""
    p_he, p_ce, _vh, _vc = cycle_state(theta1, c)
    return -p_he * c[C_AHE] + p_ce * c[C_ACE] + c[C_PFRAME] * c[C_AROD]


def cycle_states(theta1, c: np.ndarray) -> dict[str, np.ndarray]:
    """[`cycle_state`][recipdyn.model.cycle.cycle_state] over an array of crank angles."""
    th = np.atleast_1d(np.asarray(theta1, dtype=np.float64))
    out = np.array([cycle_state(float(x), c) for x in th]).reshape(*th.shape, 4)
    return dict(p_head=out[..., 0], p_crank=out[..., 1], V_head=out[..., 2],
                V_crank=out[..., 3])  # fmt: skip


def ideal_volumetric_efficiency(pressure_ratio: float, clearance_fraction: float,
                                n: float) -> float:  # fmt: skip
    """``1 - C (r^(1/n) - 1)``: the swept-volume fraction taken in at suction pressure."""
    return 1.0 - clearance_fraction * (pressure_ratio ** (1.0 / n) - 1.0)


def ideal_indicated_work(suction_pressure: float, pressure_ratio: float,
                         clearance_fraction: float, n: float,
                         swept_volume: float) -> float:  # fmt: skip
    """Indicated work of one cycle of one chamber (J), ideal valves, exponent ``n``."""
    ev = ideal_volumetric_efficiency(pressure_ratio, clearance_fraction, n)
    return (n / (n - 1.0) * suction_pressure * ev * swept_volume
            * (pressure_ratio ** ((n - 1.0) / n) - 1.0))  # fmt: skip


def indicated_work(pressure: np.ndarray, volume: np.ndarray) -> float:
    """``-closed integral p dV`` over one cycle sampled at increasing crank angle (first
    sample repeated at the end or not), by the trapezoid rule: the work done on the gas (J)."""
    p = np.append(pressure, pressure[0])
    v = np.append(volume, volume[0])
    return float(-np.sum(0.5 * (p[1:] + p[:-1]) * np.diff(v)))


def volumetric_efficiency(pressure: np.ndarray, volume: np.ndarray, suction_pressure: float,
                          rtol: float = 1e-9) -> float:  # fmt: skip
    """Fraction of the swept volume taken in at suction pressure, from one sampled cycle
    (increasing crank angle): ``(V_max - V_open) / (V_max - V_min)``, with ``V_open`` where
    re-expansion reaches the suction pressure, extrapolated linearly in ``p(V)`` from the two
    samples before it (error O(h^2) in the sample spacing; the first sample at suction pressure
    alone would be O(h)). 0 when the chamber never reaches suction pressure."""
    p = np.asarray(pressure, dtype=float)
    v = np.asarray(volume, dtype=float)
    grow = np.roll(v, -1) > v
    suction = grow & (np.abs(p - suction_pressure) <= rtol * suction_pressure)
    starts = np.flatnonzero(suction & ~np.roll(suction, 1))
    if starts.size == 0:
        return 0.0
    j = int(starts[0])
    v1, v2 = v[j - 2], v[j - 1]
    p1, p2 = p[j - 2], p[j - 1]
    v_open = v2 if p1 == p2 else v2 + (suction_pressure - p2) * (v2 - v1) / (p2 - p1)
    v_open = min(max(v_open, v2), v[j])
    return float((v.max() - v_open) / (v.max() - v.min()))


@dataclass(frozen=True)
class RodReversal:
    """The API 618 crosshead-pin load-reversal criteria for one revolution.

    API Standard 618, 5th edition (2007), 6.6.3: the combined (gas + inertia) rod load shall
    reverse at the crosshead pin for at least 15 degrees of crank angle, and the peak reverse
    load shall be at least 3 % of the peak load in the opposite direction.
    """

    reversal_deg: float  # crank angle over which the load has the minority sign
    reverse_fraction: float  # peak minority-sign load / peak majority-sign load
    peak_tension: float  # N, largest load pulling the pin (rod in tension)
    peak_compression: float  # N, largest load pushing it (rod in compression)
    min_deg: float = 15.0
    min_fraction: float = 0.03

    @property
    def passed(self) -> bool:
        return self.reversal_deg >= self.min_deg and self.reverse_fraction >= self.min_fraction

    def describe(self) -> str:
        verdict = "PASS" if self.passed else "FAIL"
        return (f"crosshead-pin load reversal {self.reversal_deg:.1f} deg (API 618 >= "
                f"{self.min_deg:g}), reverse peak {100 * self.reverse_fraction:.1f} % of the "
                f"opposite peak (>= {100 * self.min_fraction:g} %): {verdict}")  # fmt: skip


def rod_load_reversal(theta1: np.ndarray, load: np.ndarray) -> RodReversal:
    """The reversal of a pin load over one revolution sampled uniformly in crank angle.

    ``load`` > 0 is compression (the rod pushes the crosshead away from the crank)."""
    theta1 = np.asarray(theta1, dtype=float)
    load = np.asarray(load, dtype=float)
    if load.size < 8:
        raise ValueError("need at least 8 samples of one revolution")
    span = float(theta1[-1] - theta1[0]) * load.size / max(1, load.size - 1)
    deg_per_sample = math.degrees(span) / load.size
    comp = float(max(0.0, load.max()))
    tens = float(max(0.0, -load.min()))
    minority = load < 0 if comp >= tens else load > 0
    reversal = float(np.count_nonzero(minority) * deg_per_sample)
    frac = min(comp, tens) / max(comp, tens) if max(comp, tens) > 0 else 0.0
    return RodReversal(reversal, frac, tens, comp)


def covers_revolution(theta1: np.ndarray) -> bool:
    """Whether uniformly sampled crank angles cover a whole revolution: ``n`` samples one step
    apart span ``2 pi`` less one step when the revolution's end is not sampled again."""
    th = np.asarray(theta1, dtype=float)
    return th.size >= 2 and th[-1] - th[0] >= 2.0 * math.pi - 1.5 * (th[1] - th[0])


def last_revolution(ds, omega: float, extra: int = 2):
    """The samples of a uniformly sampled record's last crank revolution (plus ``extra``),
    selected by position, so a streamed record is read only there."""
    n = ds.sizes["time"]
    if n < 2:
        return ds
    t01 = np.asarray(ds["time"].isel(time=slice(0, 2)).values, dtype=float)
    k = int(math.ceil(2.0 * math.pi / omega / (t01[1] - t01[0]))) + extra if t01[1] > t01[0] else n
    out = ds.isel(time=slice(max(0, n - k), None))
    # a crank driven by a motor turns slower than omega: widen until theta1 covers a turn
    while "theta1" in ds.variables and k < n:
        th = np.asarray(out["theta1"].values, dtype=float)
        if th[-1] - th[0] >= 2.0 * math.pi * (1.0 - 1e-9):  # (a window of exactly one turn)
            break
        k *= 2
        out = ds.isel(time=slice(max(0, n - k), None))
    return out


def mean_speed(values, ds) -> float:
    """The crank's mean angular speed over the record's last revolution, rad/s: ``omega``
    for a prescribed crank, measured from ``theta1`` with a motor (whose mean speed sits
    below the synchronous one by the slip, not at ``omega``)."""
    omega = float(values["omega"])
    if values.get("drive", "prescribed") != "motor" or "theta1" not in ds.variables:
        return omega
    part = last_revolution(ds, omega)
    th = np.asarray(part["theta1"].values, dtype=float)
    t = np.asarray(part["time"].values, dtype=float)
    k = int(np.argmax(th >= th[-1] - 2.0 * math.pi))
    return float((th[-1] - th[k]) / (t[-1] - t[k])) if t[-1] > t[k] else omega


def pin_reversal_summary(values, ds) -> dict[str, float | str]:
    """The API 618 crosshead-pin reversal over the last recorded revolution of a record with
    ``theta1``, ``a`` and ``gas_force``: of the combined load ``m3 a - F_gas`` (degrees,
    reverse fraction, peaks, verdict) and of the gas load alone; empty for a record shorter
    than a revolution."""
    ds = last_revolution(ds, float(values["omega"]))
    th = np.asarray(ds["theta1"].values, dtype=float)
    last = th >= th[-1] - 2.0 * math.pi
    if np.count_nonzero(last) < 8 or not covers_revolution(th):
        return {}
    fg = np.asarray(ds["gas_force"].values, dtype=float)[last]
    pin = float(values["m3"]) * np.asarray(ds["a"].values, dtype=float)[last] - fg
    rev = rod_load_reversal(th[last], pin)
    gas = rod_load_reversal(th[last], -fg)
    return dict(pin_reversal_deg=rev.reversal_deg, pin_reverse_fraction=rev.reverse_fraction,
                pin_peak_compression_N=rev.peak_compression,
                pin_peak_tension_N=rev.peak_tension,
                api618_pin_reversal="pass" if rev.passed else "FAIL",
                gas_rod_load_reversal_deg=gas.reversal_deg)  # fmt: skip
