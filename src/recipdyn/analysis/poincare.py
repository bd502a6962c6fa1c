"""Poincaré sections of any [`ODESystem`][recipdyn.model.base.ODESystem].

Two kinds:

* [`stroboscopic_section`][recipdyn.analysis.poincare.stroboscopic_section] -- for a periodically
  forced system (``system.period`` set, e.g. the compressor's crank period), the state exactly once
  per period at a chosen phase. The samples come from the integrator's 7th-order dense output at the
  exact instants ``t_k = t0 + (k + phase / 2 pi) T``, never from the nearest stored sample.
* [`hyperplane_section`][recipdyn.analysis.poincare.hyperplane_section] -- crossings of a hyperplane
  ``y[i] = value`` in a chosen direction, root-found on the dense output inside the integrator.
* [`angle_section`][recipdyn.analysis.poincare.angle_section] -- for an autonomous system with a
  turning angle among its states (a crank driven by a motor), the state once per turn of that
  angle, where it passes ``phase`` modulo ``2 pi``: the section a stroboscopic one becomes when
  the speed is not imposed. [`angle_times`][recipdyn.analysis.poincare.angle_times] gives the
  same instants from a recorded angle.

Both return an `xarray.Dataset` over a ``section`` dimension with the state components
and (optionally) the model's derived outputs at the section points, plus the settings in attrs.
A period-1 orbit gives one distinct point, period-n n points, quasi-periodic motion a closed
curve and chaotic motion a scattered set (see
[`count_distinct_points`][recipdyn.analysis.poincare.count_distinct_points]).
"""

from __future__ import annotations

import math
from typing import Any

import numba as nb
import numpy as np
import xarray as xr

from ..integrate import integrate
from ..model.base import EVENT_SIGNATURE, ODESystem

__all__ = ["stroboscopic_section", "hyperplane_section", "angle_section", "count_distinct_points",
           "strobe_times", "angle_times"]  # fmt: skip


def strobe_times(t_first: float, t_last: float, period: float) -> np.ndarray:
    """The multiples of ``period`` in ``[t_first, t_last]`` (ends within 1e-9 periods count):
    the once-per-period instants at which a recorded signal is sampled (interpolated) for a
    stroboscopic section of a record."""
    return np.arange(np.ceil(t_first / period - 1e-9), np.floor(t_last / period + 1e-9) + 1
                     ) * period  # fmt: skip


def angle_times(t, angle, phase: float = 0.0) -> np.ndarray:
    """The instants at which a recorded angle ``angle(t)`` (rad, unwrapped and increasing: a
    crank turning one way) passes ``phase + 2 pi k``: the once-per-turn instants at which a
    record of an autonomous system is sampled for its section (`angle_section`'s, from a
    record). Linear inverse interpolation between samples: its error in time is at most
    ``h^2 max|angle''| / (8 min angle')`` for a sample spacing ``h`` (for a crank with a 2 %
    speed ripple sampled 100 times a turn, ~1e-7 of a turn)."""
    t = np.asarray(t, dtype=float).reshape(-1)
    a = np.asarray(angle, dtype=float).reshape(-1)
    if t.size != a.size:
        raise ValueError(f"t and angle have {t.size} and {a.size} samples; allowed: as many")
    if a.size < 2:
        return np.empty(0)
    if not np.all(np.diff(a) > 0):
        raise ValueError("angle must increase from sample to sample (an unwrapped angle of a "
                         "crank turning one way)")  # fmt: skip
    two_pi = 2.0 * math.pi
    k = np.arange(math.ceil((a[0] - phase) / two_pi - 1e-9),
                  math.floor((a[-1] - phase) / two_pi + 1e-9) + 1)  # fmt: skip
    return np.interp(phase + two_pi * k, a, t)


def _dataset(system: ODESystem, t, y, outputs: bool, attrs: dict[str, Any]) -> xr.Dataset:
    data = {
        name: ("section", y[:, i], {"units": (system.state_units or ("1",) * system.dim)[i]})
        for i, name in enumerate(system.state_names)
    }
    if outputs and len(t):
        for name, sig in system.outputs(t, y).items():
            if name not in data:
                data[name] = (
                    "section",
                    sig.values,
                    {"units": sig.units, "long_name": sig.long_name},
                )
    ds = xr.Dataset(data, coords={"time": ("section", np.asarray(t), {"units": "s"})})
    ds.attrs.update({k: v for k, v in attrs.items() if v is not None})
    return ds


def stroboscopic_section(
    system: ODESystem,
    y0,
    n_points: int,
    *,
    transient_periods: float = 0.0,
    phase: float = 0.0,
    t0: float = 0.0,
    outputs: bool = True,
    **solver: Any,
) -> xr.Dataset:
    """State once per forcing period, exactly at phase ``phase`` (rad) of the period.

    Parameters
    ----------
    system : ODESystem
        Must have ``period`` (the forcing period, e.g. ``2 pi / omega``).
    y0 : array_like
        State at ``t0``.
    n_points : int
        Number of section points to record.
    transient_periods : float
        Periods integrated and discarded first.
    phase : float
        Forcing phase of the section in [0, 2 pi): for the compressor, the crank angle
        ``theta1 - theta1_0`` at which the section is taken.
    outputs : bool
        Include the model's derived outputs (crosshead x, v, a, ...) at the section points.
    **solver
        Passed to [`recipdyn.integrate.integrate`][recipdyn.integrate.solve.integrate] (method,
        rtol, atol, ...).
    """
    if system.period is None:
        raise ValueError(f"system {system.name!r} has no forcing period; use hyperplane_section")
    if n_points < 1:
        raise ValueError(f"n_points = {n_points}; allowed: >= 1")
    if not (0.0 <= phase < 2 * math.pi):
        raise ValueError(f"phase = {phase}; allowed: [0, 2 pi)")
    T = system.period
    k = np.arange(n_points) + transient_periods + phase / (2 * math.pi)
    t_eval = t0 + k * T
    sol = integrate(system, y0, (t0, float(t_eval[-1])), t_eval=t_eval, **solver)
    attrs = dict(
        section="stroboscopic", period=T, phase=phase, transient_periods=transient_periods,
        nfev=sol.nfev, **{f"solver_{k}": v for k, v in sol.settings.items()},
    )  # fmt: skip
    return _dataset(system, sol.t, sol.y, outputs, attrs)


def _crossing(system: ODESystem, t_a: float, y_a: np.ndarray, t_b: float, a_b: float,
              index: int, target: float, solver: dict[str, Any]):  # fmt: skip
    """The instant in ``[t_a, t_b]`` at which ``y[index]`` passes ``target``, and the state
    there: Newton's iteration on ``t``, each iterate's state integrated from the sample
    ``(t_a, y_a)`` (the system's own events act), its rate from the right-hand side. Converges
    quadratically from the linear guess; returns also the evaluations spent."""
    a_a = float(y_a[index])
    if a_a == target:
        return t_a, y_a.copy(), 0
    t_g = t_a + (target - a_a) / (a_b - a_a) * (t_b - t_a)
    tol = 4.0 * np.finfo(float).eps * max(1.0, abs(target))
    f = np.empty(y_a.size)
    nfev = 0
    for _ in range(8):
        if t_g <= t_a:
            t_g = t_a + 1e-3 * (t_b - t_a)
        sol = integrate(system, y_a, (t_a, t_g), **solver)
        nfev += sol.nfev
        y_g = np.asarray(sol.y_final, dtype=float)
        r = float(y_g[index]) - target
        system.rhs(t_g, y_g, system.params, f)
        if abs(r) <= tol or f[index] == 0.0:
            break
        t_g -= r / f[index]
    return t_g, y_g, nfev


def angle_section(
    system: ODESystem,
    y0,
    n_points: int,
    *,
    index: int,
    turn_time: float,
    phase: float = 0.0,
    t0: float = 0.0,
    transient_turns: float = 0.0,
    samples_per_turn: int = 32,
    outputs: bool = True,
    **solver: Any,
) -> xr.Dataset:
    """State once per turn of the angle ``y[index]`` (rad, increasing), where it passes
    ``phase`` modulo ``2 pi``: the Poincaré section of an autonomous system that turns, such as
    a crank driven by a motor, whose speed (and so the instant of each turn) is part of the
    solution.

    The run is sampled ``samples_per_turn`` times per ``turn_time`` (an estimate of one turn's
    duration: the nominal crank period) to bracket each passage; each is then located by
    Newton's iteration on time, the state at each iterate integrated from the bracket's first
    sample, to ``4 eps |target|`` in the angle. The section's states are the integration's
    (its tolerances), at the instant the angle passes, whatever the system's own events.

    Parameters
    ----------
    index : int
        The angle's place in the state.
    turn_time : float
        About how long one turn takes (> 0; only the sampling and the run's length follow it).
    phase : float
        The angle, modulo ``2 pi``, at which the section is taken, in [0, 2 pi).
    transient_turns : float
        Turns integrated and discarded first (counted on the angle from ``y0``).
    **solver
        Passed to [`recipdyn.integrate.integrate`][recipdyn.integrate.solve.integrate].
    """
    if not (0 <= index < system.dim):
        raise ValueError(f"index = {index}; allowed: 0..{system.dim - 1}")
    if n_points < 1:
        raise ValueError(f"n_points = {n_points}; allowed: >= 1")
    if not (0.0 <= phase < 2 * math.pi):
        raise ValueError(f"phase = {phase}; allowed: [0, 2 pi)")
    if not (turn_time > 0 and math.isfinite(turn_time)):
        raise ValueError(f"turn_time = {turn_time}; allowed: > 0")
    two_pi = 2.0 * math.pi
    y = np.array(y0, dtype=float)
    t = float(t0)
    start = float(y[index]) + two_pi * transient_turns
    first = math.ceil((start - phase) / two_pi - 1e-12)
    targets = phase + two_pi * (first + np.arange(n_points))
    ts, ys = [], []
    nfev = 0
    dt = turn_time / max(2, int(samples_per_turn))
    while len(ts) < n_points:
        left = float(targets[-1] - y[index]) / two_pi  # turns still to go, at least one chunk
        t_end = t + max(1.0, 1.25 * left + 0.5) * turn_time
        grid = np.arange(t, t_end, dt)
        sol = integrate(system, y, (t, float(grid[-1])), t_eval=grid, **solver)
        nfev += sol.nfev
        a = sol.y[:, index]
        if not np.all(np.diff(a) > 0):
            raise ValueError(f"the angle y[{index}] does not increase along the run; allowed: "
                             "an angle that turns one way (a crank driven forwards)")  # fmt: skip
        for k in range(len(ts), n_points):
            j = int(np.searchsorted(a, targets[k], side="right"))  # a[j-1] <= target < a[j]
            if j >= a.size:
                break
            if j == 0:  # the start itself, within rounding (a section at the angle of y0)
                ts.append(float(sol.t[0]))
                ys.append(np.array(sol.y[0]))
                continue
            tk, yk, n = _crossing(system, float(sol.t[j - 1]), sol.y[j - 1],
                                  float(sol.t[j]), float(a[j]), index, float(targets[k]),
                                  solver)  # fmt: skip
            nfev += n
            ts.append(tk)
            ys.append(yk)
        t, y = float(sol.t[-1]), np.array(sol.y[-1])
    attrs = dict(
        section="angle", angle=system.state_names[index], phase=phase,
        transient_turns=transient_turns, turn_time_estimate=turn_time, nfev=nfev,
        **{f"solver_{k}": v for k, v in sol.settings.items()},
    )  # fmt: skip
    return _dataset(system, np.array(ts), np.array(ys).reshape(-1, system.dim), outputs, attrs)


def _plane_event(index: int, value: float):
    @nb.njit(EVENT_SIGNATURE, _nrt=False)  # no reference counting, like model.base.compiled
    def event(t, y, p):
        return y[index] - value

    return event


def hyperplane_section(
    system: ODESystem,
    y0,
    t_span: tuple[float, float],
    *,
    index: int,
    value: float = 0.0,
    direction: int = 1,
    outputs: bool = True,
    max_points: int = 100_000,
    **solver: Any,
) -> xr.Dataset:
    """Crossings of the hyperplane ``y[index] = value`` during ``t_span``.

    ``direction`` +1 records upward crossings, -1 downward, 0 both. The crossing times are
    found by regula falsi (Illinois) on the 7th-order dense output, to ~1e-15 relative in t.
    """
    if not (0 <= index < system.dim):
        raise ValueError(f"index = {index}; allowed: 0..{system.dim - 1}")
    if direction not in (-1, 0, 1):
        raise ValueError(f"direction = {direction}; allowed: -1, 0, 1")
    sol = integrate(
        system, y0, t_span, t_eval=np.empty(0), event=_plane_event(index, float(value)),
        event_direction=direction, max_events=max_points, **solver,
    )  # fmt: skip
    attrs = dict(
        section="hyperplane", plane=f"{system.state_names[index]} = {value}", direction=direction,
        nfev=sol.nfev, **{f"solver_{k}": v for k, v in sol.settings.items()},
    )  # fmt: skip
    return _dataset(system, sol.t_events, sol.y_events, outputs, attrs)


def count_distinct_points(points, rtol: float = 1e-6, scale=None,
                          max_extent: float | None = None) -> int:  # fmt: skip
    """Number of distinct points in a section: points closer than ``rtol * scale`` (per axis,
    default scale = the largest magnitude on that axis) are the same point.

    A period-n orbit gives n; quasi-periodic and chaotic motion give (nearly) as many as there
    are points. KD-tree pairs + connected components (scipy).

    ``max_extent`` (in the same scaled units as ``rtol``): a group whose bounding box is wider
    than this on some axis is not one point but a chain of neighbours along a curve (a
    quasi-periodic or chaotic section with a tolerance near its point spacing), and counts as
    its number of points. A noisy periodic point is a compact cloud and stays one.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    pts = np.atleast_2d(np.asarray(points, dtype=float))
    if not np.all(np.isfinite(pts)):
        raise ValueError("points: NaN or infinite coordinates; allowed: finite values")
    n = pts.shape[0]
    if n == 0:
        return 0
    if scale is None:
        scale = np.max(np.abs(pts), axis=0)
    scale = np.where(np.asarray(scale, dtype=float) > 0, scale, 1.0)
    z = pts / scale
    pairs = cKDTree(z).query_pairs(rtol, p=np.inf, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    n_groups, label = connected_components(graph, directed=False)
    if max_extent is None:
        return int(n_groups)
    order = np.argsort(label, kind="stable")
    starts = np.r_[0, np.flatnonzero(np.diff(label[order])) + 1]
    zs = z[order]
    span = np.maximum.reduceat(zs, starts) - np.minimum.reduceat(zs, starts)
    size = np.diff(np.r_[starts, n])
    return int(np.where(span.max(axis=1) > max_extent, size, 1).sum())
