r"""Cylinder load: the paper's piecewise pressure model (Eq. 1-2) or a user table.

The force on the crosshead along +x is ``F_x(theta1) = s * P(theta1)`` with
``P = load_amplitude * mu(theta1)`` (the paper's ``P = 200000 mu``, taken as a force in N) and

* ``s = -1`` for ``load_sign="physical"``: the cylinder lies beyond the outer dead centre
  (``theta1 = 0``, crosshead at ``x = r + l``), so the gas pushes the piston toward the crank;
* ``s = +1`` for ``load_sign="paper"``: the sign with which P enters the paper's Eq. (46).

Eq. (2), with ``phi = theta1 mod 2 pi``::

    mu = sin(pi/2 - phi)        0       <= phi <= 7pi/16   expansion
         sin(pi/16)             7pi/16  <= phi <= pi       suction
         -sin(phi + pi/16)      pi      <= phi <= 23pi/16  compression
         1                      23pi/16 <= phi <= 2pi      exhaust

mu is continuous (the pieces meet at sin(pi/16) and 1) with kinks at the breakpoints; it is
always positive, so the load never reverses.

A table load (``CompressorParams.load_table``: rows of crank angle in degrees and force in N,
already signed as the force on the crosshead along +x) is interpolated linearly and
periodically; ``load_sign`` does not apply to it.

A measured indicator diagram (cylinder pressure over crank angle, head end and optionally crank
end) becomes such a table through [`read_pressure_table`][recipdyn.model.load.read_pressure_table]:
each pressure is interpolated periodically with a shape-preserving cubic (PCHIP: continuous slope,
no overshoot at the valve events, passes through every sample), resampled every ``step_deg`` and
turned into the force of the compression-cycle model, ``F = -p_he A + p_ce (A - A_rod) + p_frame
A_rod`` ([`recipdyn.model.cycle`][recipdyn.model.cycle]); an end without a column is at ``p_frame``.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .cycle import CYCLE_PARAMS, pressure_force

__all__ = [
    "mu_paper",
    "mu_kernel",
    "read_load_table",
    "read_pressure_table",
    "pack_table",
    "CYCLE_PARAMS",
]

_PI = math.pi


@nb.njit(cache=True)
def mu_kernel(theta1: float) -> float:
    phi = theta1 % (2.0 * _PI)
    if phi <= 7.0 * _PI / 16.0:
        return math.sin(0.5 * _PI - phi)
    if phi <= _PI:
        return math.sin(_PI / 16.0)
    if phi <= 23.0 * _PI / 16.0:
        return -math.sin(phi + _PI / 16.0)
    return 1.0


_SIN16, _COS16 = math.sin(_PI / 16.0), math.cos(_PI / 16.0)
_COS7, _COS23 = math.cos(7.0 * _PI / 16.0), math.cos(23.0 * _PI / 16.0)


@nb.njit(cache=True)
def mu_sincos(s1: float, c1: float) -> float:
    """[`mu_kernel`][recipdyn.model.load.mu_kernel] from ``sin`` and ``cos`` of the crank angle (a
    caller that has them saves the angle's reduction and a sine): ``sin(pi/2 - phi) = cos theta1``,
    ``sin(phi + pi/16)`` by the addition theorem, the branches by the signs and ``cos`` (it
    decreases on [0, pi], increases on [pi, 2 pi]). Equal to
    [`mu_kernel`][recipdyn.model.load.mu_kernel] to rounding: mu is continuous at every branch
    point."""
    if s1 >= 0.0:
        return c1 if c1 >= _COS7 else _SIN16
    if c1 <= _COS23:
        return -(s1 * _COS16 + c1 * _SIN16)
    return 1.0


def mu_paper(theta1) -> np.ndarray:
    """Cylinder pressure coefficient mu of Eq. (2) at crank angle(s) theta1 (rad)."""
    th = np.asarray(theta1, dtype=np.float64)
    return np.vectorize(mu_kernel, otypes=[np.float64])(th)


def pack_table(table) -> np.ndarray:
    """Pack ``((deg, N), ...)`` rows as ``[n, angles_rad, forces]`` for the kernel."""
    if table is None:
        return np.zeros(1)
    arr = np.asarray(table, dtype=np.float64)
    return np.concatenate([[len(arr)], np.deg2rad(arr[:, 0]), arr[:, 1]])


def read_load_table(path, *, area: float | None = None) -> tuple[tuple[float, float], ...]:
    """Read a CSV load table: crank angle (deg) and force (N), or pressure (Pa) with ``area``.

    Lines starting with ``#`` and a non-numeric header line are skipped. With ``area`` (m^2)
    the second column is a pressure and the force is ``pressure * area``. Angles are wrapped
    into [0, 360) and sorted.
    """
    from ..errors import ParameterError

    try:
        data = np.genfromtxt(path, delimiter=",", comments="#", dtype=float)
    except (OSError, ValueError) as exc:
        raise ParameterError(f"load table {path}: cannot read ({exc})") from None
    data = np.atleast_2d(data)
    data = data[~np.isnan(data).all(axis=1)]
    if data.ndim != 2 or data.shape[1] < 2 or data.shape[0] < 2:
        raise ParameterError(f"load table {path}: need >= 2 rows of 'angle_deg, value'")
    if np.isnan(data[:, :2]).any():
        raise ParameterError(f"load table {path}: non-numeric entries")
    ang = np.mod(data[:, 0], 360.0)
    val = data[:, 1] * (area if area is not None else 1.0)
    order = np.argsort(ang)
    return tuple((float(a), float(v)) for a, v in zip(ang[order], val[order], strict=True))


def _unit_factor(header: str, default: str, what: str, path) -> float:
    """The SI factor of the unit in ``name [unit]`` or ``name (unit)`` (pint), else of
    ``default``."""
    import re

    import pint

    from ..errors import ParameterError

    m = re.search(r"[\[(]\s*([^\])]+?)\s*[\])]", header)
    unit = m.group(1) if m else default
    try:
        q = pint.UnitRegistry().Quantity(1.0, unit)
        return float(q.to("Pa" if what == "pressure" else "degree").magnitude)
    except Exception:
        raise ParameterError(f"pressure table {path}: column {header.strip()!r}: unit {unit!r} "
                             f"is not a {what} unit") from None  # fmt: skip


def read_pressure_table(path, *, bore: float, rod_diameter: float,
                        frame_pressure: float = 101325.0,
                        step_deg: float = 0.25) -> tuple[tuple[float, float], ...]:  # fmt: skip
    """A measured indicator diagram as a load table (rows of crank angle in deg and force in N).

    Parameters
    ----------
    path : path
        CSV: crank angle, head-end pressure and optionally crank-end pressure (absolute), one
        revolution, ``#`` comments allowed. A header line may give units in brackets
        (``angle [deg], p_head [bar], p_crank [bar]``); without one, degrees and Pa.
    bore, rod_diameter : float
        Cylinder bore and piston-rod diameter, m (the areas the pressures act on).
    frame_pressure : float
        Pressure on the rod section and in an end without a column, Pa.
    step_deg : float
        Resampling step of the force table, deg.

    Notes
    -----
    PCHIP on the periodically continued samples (three copies) keeps the slope continuous and
    never overshoots a sample, so a sharp valve event does not ring; between the
    ``step_deg`` nodes the kernel interpolates linearly (error <= step^2/8 max|F''|).
    """
    from scipy.interpolate import PchipInterpolator

    from ..errors import ParameterError

    try:
        with open(path, encoding="utf-8") as fh:
            lines = [ln for ln in fh if ln.strip() and not ln.lstrip().startswith("#")]
    except (OSError, UnicodeDecodeError) as exc:
        raise ParameterError(f"pressure table {path}: cannot read ({exc})") from None
    if not lines:
        raise ParameterError(f"pressure table {path}: empty")
    head = [c for c in lines[0].split(",")]
    try:
        [float(c) for c in head]
        header, rows = None, lines
    except ValueError:
        header, rows = head, lines[1:]
    try:
        data = np.array([[float(c) for c in ln.split(",")] for ln in rows], dtype=float)
    except ValueError:
        raise ParameterError(f"pressure table {path}: non-numeric entries") from None
    if data.ndim != 2 or data.shape[1] not in (2, 3) or data.shape[0] < 4:
        raise ParameterError(f"pressure table {path}: need >= 4 rows of 'angle, p_head' or "
                             "'angle, p_head, p_crank'")  # fmt: skip
    if not np.all(np.isfinite(data)):
        raise ParameterError(f"pressure table {path}: non-finite entries")
    k_ang = _unit_factor(header[0], "deg", "angle", path) if header else 1.0
    k_p = [_unit_factor(h, "Pa", "pressure", path) for h in header[1:]] if header else \
        [1.0] * (data.shape[1] - 1)  # fmt: skip
    ang = np.mod(data[:, 0] * k_ang, 360.0)
    order = np.argsort(ang)
    ang = ang[order]
    keep = np.concatenate([[True], np.diff(ang) > 1e-9])  # 0 and 360 are one angle
    ang = ang[keep]
    press = [(data[order, j + 1] * k_p[j])[keep] for j in range(data.shape[1] - 1)]
    if ang.size < 4:
        raise ParameterError(f"pressure table {path}: need >= 4 distinct angles")
    if any(np.any(p < 0) for p in press):
        raise ParameterError(f"pressure table {path}: negative pressure; allowed: absolute "
                             "pressures >= 0")  # fmt: skip
    if not (0 < rod_diameter < bore):
        raise ParameterError(f"rod_diameter = {rod_diameter}; allowed: 0 < rod_diameter < "
                             f"bore = {bore}")  # fmt: skip
    grid = np.arange(0.0, 360.0, step_deg)
    a3 = np.concatenate([ang - 360.0, ang, ang + 360.0])

    def smooth(p):
        return PchipInterpolator(a3, np.tile(p, 3))(grid)

    p_he = smooth(press[0])
    p_ce = smooth(press[1]) if len(press) > 1 else np.full_like(grid, frame_pressure)
    force = pressure_force(p_he, p_ce, bore=bore, rod_diameter=rod_diameter,
                           frame_pressure=frame_pressure)  # fmt: skip
    return tuple((float(a), float(f)) for a, f in zip(grid, force, strict=True))
