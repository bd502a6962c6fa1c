"""The unit of work of a sweep: one parameter point -> a small summary (pure, picklable).

The same function runs in the serial loop, a process pool and on Dask workers, so results do
not depend on the backend. Nothing here uses random numbers or global state.
"""

from __future__ import annotations

import traceback
from typing import Any

import numpy as np

from ..analysis import (
    amplitude_spectrum,
    classify,
    count_distinct_points,
    find_spectral_peaks,
    lyapunov_spectrum,
)
from ..defaults import LYAP_TOL
from ..integrate import IntegrationError, integrate
from ..model.compressor import compressor_model
from ..model.parameters import CompressorParams, ParameterError

__all__ = ["run_point", "N_PEAKS"]

N_PEAKS = 3


def run_point(task: dict[str, Any]) -> dict[str, Any]:
    """Compute the requested measures for one point.

    ``task``: ``index`` (tuple), ``params`` (CompressorParams), ``measures``, ``settings``,
    optional ``y0`` (continuation). Returns ``{"index", "error", "y_final", <measure arrays>}``;
    failures (integrator, infeasible geometry) are caught and returned as ``error``.
    """
    out: dict[str, Any] = {"index": task["index"], "error": ""}
    try:
        out.update(_compute(task["params"], task["measures"], task["settings"], task.get("y0")))
    except (IntegrationError, ParameterError, FloatingPointError, ValueError) as exc:
        out["error"] = f"{type(exc).__name__}: {exc}"
    except Exception as exc:  # record anything else too; the sweep goes on
        out["error"] = f"{type(exc).__name__}: {exc} | {traceback.format_exc(limit=2)}"
    return out


def _compute(p: CompressorParams, measures, s, y0) -> dict[str, Any]:
    m = compressor_model(p)
    T = p.crank_period
    y = m.initial_state() if y0 is None else np.asarray(y0, dtype=float)
    solver = dict(rtol=s["rtol"], atol=s["atol"])
    res: dict[str, Any] = {}
    t0 = s["transient"] * T
    n_pts = int(s["points"])
    need_section = "poincare" in measures or "verdict" in measures
    if need_section:
        te = t0 + np.arange(n_pts) * T
        sol = integrate(m, y, (0.0, te[-1]), t_eval=te, **solver)
        outs = m.outputs(sol.t, sol.y)
        for k in ("theta_c", "thetadot_c", "x", "v", "a"):
            res[f"poincare_{k}"] = outs[k].values
        res["poincare_distinct"] = count_distinct_points(np.c_[outs["v"].values,
                                                              outs["a"].values])  # fmt: skip
        y_end, t_end = sol.y_final, sol.t_final
    else:
        y_end, t_end = y, 0.0
    if "peak" in measures or "spectrum" in measures:
        fs = s["fs"]
        n = int(s["revolutions"] * T * fs) + 1
        te = t0 + np.arange(n) / fs
        sol = integrate(m, y, (0.0, te[-1]), t_eval=te, **solver)
        a = m.outputs(sol.t, sol.y)["a"].values
        res["peak_a"] = float(np.max(np.abs(a)))
        res["rms_a"] = float(np.sqrt(np.mean(a**2)))
        if "spectrum" in measures:
            peaks = find_spectral_peaks(amplitude_spectrum(a, fs), n=N_PEAKS,
                                        fundamental=p.crank_frequency)  # fmt: skip
            f = np.full(N_PEAKS, np.nan)
            amp = np.full(N_PEAKS, np.nan)
            for i, pk in enumerate(peaks):
                f[i], amp[i] = pk.frequency, pk.amplitude
            res["peak_freq"], res["peak_amp"] = f, amp
        if not need_section:
            y_end, t_end = sol.y_final, sol.t_final
    if "lyapunov" in measures or "verdict" in measures:
        if p.rc > 0:
            r = lyapunov_spectrum(m, y, s["lyap_revolutions"] * T, t_transient=t0, **solver)
            res["lambda1"], res["lambda_sum"] = float(r.exponents[0]), float(r.sum)
        else:
            res["lambda1"], res["lambda_sum"] = 0.0, 0.0
    if "verdict" in measures:
        v = classify(lambda1=res["lambda1"], lyap_tol=s.get("lyap_tol", LYAP_TOL),
                     section=np.c_[res["poincare_v"], res["poincare_a"]])  # fmt: skip
        res["verdict"] = v.verdict
    # final state, for continuation: integrate to a whole number of periods after t_end
    res["y_final"] = np.asarray(y_end, dtype=float)
    res["t_final"] = float(t_end)
    return res
