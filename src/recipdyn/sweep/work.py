"""The unit of work of a sweep: one parameter point -> a small summary (pure, picklable).

The same function runs in the serial loop, a process pool and on Dask workers, so results do
not depend on the backend. Nothing here uses random numbers or global state.
"""

from __future__ import annotations

import math
import traceback
from typing import Any

import numpy as np

from ..analysis import (
    amplitude_spectrum,
    classify,
    count_distinct_points,
    find_spectral_peaks,
    lyapunov_spectrum,
    zero_one_test,
)
from ..defaults import LYAP_TOL
from ..errors import ParameterError
from ..integrate import IntegrationError, integrate
from ..model.registry import DEFAULT_MODEL, get_model

__all__ = ["run_point", "N_PEAKS"]

#: Spectral lines stored per point (``--measure spectrum``; the Campbell diagram's markers).
N_PEAKS = 8


def run_point(task: dict[str, Any]) -> dict[str, Any]:
    """Compute the requested measures for one point.

    ``task``: ``index`` (tuple), ``model`` (a registered name or module:object, default the
    compressor), ``params`` (the model's validated values), ``measures``, ``settings``,
    optional ``y0`` (continuation). Returns ``{"index", "error", "y_final", <measure
    arrays>}``; failures (integrator, infeasible geometry) are
    caught and returned as ``error``.
    """
    out: dict[str, Any] = {"index": task["index"], "error": ""}
    try:
        out.update(_compute(task))
    except (IntegrationError, ParameterError, FloatingPointError, ValueError) as exc:
        out["error"] = f"{type(exc).__name__}: {exc}"
    except Exception as exc:  # record anything else too; the sweep goes on
        out["error"] = f"{type(exc).__name__}: {exc} | {traceback.format_exc(limit=2)}"
    return out


def run_points(tasks: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """`run_point` for each task (one Dask task carries several short points)."""
    return [run_point(t) for t in tasks]


class _Point:
    """One point's system, period, initial state and outputs, for any registered model
    (through its protocol only)."""

    def __init__(self, model_spec: str, p: Any):
        m = get_model(model_spec).configured(p)
        self.model = m
        self.system = m.system(p)
        period = m.period(p)
        self.T = float(period) if period else 1.0
        self.y_init = m.initial_state(p)
        self.outputs = lambda t, y, _m=m, _p=p: _m.outputs(_p, t, y)
        self.fc = 1.0 / period if period else None
        self.dynamic = m.has_dynamics(p)
        self.bounded = m.validity_applies(p)
        self.sections = [k for k, _ in m.sections()]
        self.pair = m.pair()
        self.vib = m.vibration()[0]


def _compute(task: dict[str, Any]) -> dict[str, Any]:
    pt = _Point(task.get("model", DEFAULT_MODEL), task["params"])
    measures, s, y0 = task["measures"], task["settings"], task.get("y0")
    if pt.model.kind == "map":
        return _compute_map(pt, measures, s, y0)
    m = pt.system
    T = pt.T
    y = pt.y_init if y0 is None else np.asarray(y0, dtype=float)
    solver = dict(rtol=s["rtol"], atol=s["atol"])
    res: dict[str, Any] = {}
    t0 = s["transient"] * T
    n_pts = int(s["points"])
    need_section = "poincare" in measures or "verdict" in measures
    if need_section:
        te = t0 + np.arange(n_pts) * T
        sol = integrate(m, y, (0.0, te[-1]), t_eval=te, **solver)
        outs = pt.outputs(sol.t, sol.y)
        for k in pt.sections:
            res[f"poincare_{k}"] = outs[k].values
        res["poincare_distinct"] = count_distinct_points(
            np.c_[tuple(outs[k].values for k in pt.pair)]
        )
        y_end, t_end = sol.y_final, sol.t_final
    else:
        y_end, t_end = y, 0.0
    if {"peak", "spectrum", "features"} & set(measures):
        fs = s["fs"]
        n = int(s["revolutions"] * T * fs) + 1
        te = t0 + np.arange(n) / fs
        sol = integrate(m, y, (0.0, te[-1]), t_eval=te, **solver)
        outs = pt.outputs(sol.t, sol.y)
        a = outs[pt.vib].values
        for name, *_ in pt.model.validity_bounds:  # NaN where the bound does not apply
            res[f"min_{name}"] = float(np.min(outs[name].values)) if pt.bounded else math.nan
        for out, name, _unit in pt.model.mean_signals:
            res[name] = float(np.mean(outs[out].values)) if out in outs else float("nan")
        for out, name, _unit in pt.model.max_signals:
            res[name] = float(np.max(outs[out].values)) if out in outs else float("nan")
        res[f"peak_{pt.vib}"] = float(np.max(np.abs(a)))
        res[f"rms_{pt.vib}"] = float(np.sqrt(np.mean(a**2)))
        if "features" in measures:
            # the crank angle in revolutions is exact: the forcing phase of each sample
            revs = (sol.t - sol.t[0]) * pt.fc if pt.fc else None
            res.update(_features(a, fs, revs, pt))
        if "spectrum" in measures:
            peaks = find_spectral_peaks(amplitude_spectrum(a, fs), n=N_PEAKS, fundamental=pt.fc)
            f = np.full(N_PEAKS, np.nan)
            amp = np.full(N_PEAKS, np.nan)
            for i, pk in enumerate(peaks):
                f[i], amp[i] = pk.frequency, pk.amplitude
            res["peak_freq"], res["peak_amp"] = f, amp
            res["forcing_hz"] = float(pt.fc) if pt.fc else float("nan")
        if not need_section:
            y_end, t_end = sol.y_final, sol.t_final
    if "lyapunov" in measures or "verdict" in measures:
        if pt.dynamic:
            r = lyapunov_spectrum(m, y, s["lyap_revolutions"] * T, t_transient=t0, **solver)
            res["lambda1"], res["lambda_sum"] = float(r.exponents[0]), float(r.sum)
            limit = r.largest_limit()  # the verdict's exponent: finite-time bias removed
        else:
            res["lambda1"], res["lambda_sum"] = 0.0, 0.0
            limit = (0.0, 0.0)
    if "verdict" in measures:
        sec = np.c_[tuple(res[f"poincare_{k}"] for k in pt.pair)]
        k01 = zero_one_test(sec[:, 0]) if sec.shape[0] >= 100 else None
        v = classify(lambda1=limit[0], lambda1_err=limit[1], k01=k01, section=sec,
                     lyap_tol=s.get("lyap_tol", LYAP_TOL))  # fmt: skip
        res["verdict"] = v.verdict
    # final state, for continuation: integrate to a whole number of periods after t_end
    res["y_final"] = np.asarray(y_end, dtype=float)
    res["t_final"] = float(t_end)
    return res


def _features(a, fs: float, revs, pt) -> dict[str, float]:
    """The sweep's ``features`` measure:
    [`recipdyn.features.signal_features`][recipdyn.features.signal_features] of the vibration
    signal, as ``feat_<name>`` (the numeric ones the store declares)."""
    from ..features import feature_units, signal_features

    row = signal_features(a, fs, revs=revs)
    names = feature_units("", orders=revs is not None)
    return {f"feat_{k}": float(row.get(k, float("nan"))) for k in names}


def _compute_map(pt: _Point, measures, s, y0) -> dict[str, Any]:
    """A map: section points are the iterates after the transient; exponents per iteration."""
    from ..analysis import lyapunov_spectrum_map
    from ..model.reference.systems import iterate

    y = pt.y_init if y0 is None else np.asarray(y0, dtype=float)
    n0 = int(s["transient"])
    n = max(int(s["points"]), int(s.get("revolutions", 0)))
    orbit = iterate(pt.system, y, n, n_transient=n0)
    outs = pt.outputs(np.arange(n0 + 1, n0 + n + 1, dtype=float), orbit)
    res: dict[str, Any] = {}
    k_pts = int(s["points"])
    for k in pt.sections:
        res[f"poincare_{k}"] = outs[k].values[:k_pts]
    res["poincare_distinct"] = count_distinct_points(
        np.c_[tuple(outs[k].values[:k_pts] for k in pt.pair)]
    )
    a = outs[pt.vib].values
    if "features" in measures:
        res.update(_features(a, 1.0, None, pt))
    if "peak" in measures or "spectrum" in measures:
        res[f"peak_{pt.vib}"] = float(np.max(np.abs(a)))
        res[f"rms_{pt.vib}"] = float(np.sqrt(np.mean(a**2)))
    if "spectrum" in measures:
        peaks = find_spectral_peaks(amplitude_spectrum(a, 1.0), n=N_PEAKS)
        f = np.full(N_PEAKS, np.nan)
        amp = np.full(N_PEAKS, np.nan)
        for i, pk in enumerate(peaks):
            f[i], amp[i] = pk.frequency, pk.amplitude
        res["peak_freq"], res["peak_amp"] = f, amp
        res["forcing_hz"] = float("nan")  # a map has no forcing
    if "lyapunov" in measures or "verdict" in measures:
        r = lyapunov_spectrum_map(pt.system, y, max(1, int(s["lyap_revolutions"])),
                                  n_transient=n0)  # fmt: skip
        res["lambda1"], res["lambda_sum"] = float(r.exponents[0]), float(r.sum)
        limit = r.largest_limit()
    if "verdict" in measures:
        sec = np.c_[tuple(res[f"poincare_{k}"] for k in pt.pair)]
        k01 = zero_one_test(sec[:, 0]) if sec.shape[0] >= 100 else None
        v = classify(lambda1=limit[0], lambda1_err=limit[1], k01=k01, section=sec,
                     lyap_tol=s.get("lyap_tol", LYAP_TOL))  # fmt: skip
        res["verdict"] = v.verdict
    res["y_final"] = np.asarray(orbit[-1], dtype=float)
    res["t_final"] = float(n0 + n)
    return res
