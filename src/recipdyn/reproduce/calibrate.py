"""Can any choice of the unknown inertia parameters reproduce the paper's peak accelerations?

The paper's Table 1 (masses, inertia) is illegible, so its seven reported peak crosshead
accelerations (77.68 ... 16010 m/s^2) are the only handle on them.
[`calibrate`][recipdyn.reproduce.calibrate.calibrate] searches the unknowns within physical bounds
(scipy's differential evolution, seeded) for the best match in the log-ratio sense, optionally
together with the unknown initial clearance-angle offset, and reports how close the best choice
gets. This is a diagnostic of whether the published numbers are reachable by this model at all; it
never changes the package's defaults.
"""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from ..defaults import CALIBRATION_ATOL, CALIBRATION_RTOL
from ..errors import ModelValidityWarning
from ..integrate import IntegrationError
from ..io import jsonable, write_text
from ..model.parameters import CompressorParams
from ..simulate import simulate
from .cases import PAPER_VALUES, case_by_id

__all__ = ["calibrate", "TARGETS", "BOUNDS"]

#: (case id, reported peak |a| in m/s^2)
TARGETS = tuple((pv.case, pv.value) for pv in PAPER_VALUES if pv.quantity == "peak_a"
                and pv.key != "peak_a_d0")  # fmt: skip
#: Physical search bounds of the unknowns.
BOUNDS = {"m2": (2.0, 100.0), "m3": (2.0, 150.0), "J2": (0.01, 5.0), "theta_c_offset": (0.0, 1.0)}


def _peaks(values: dict[str, float], revolutions: float) -> list[float]:
    out = []
    for cid, _ in TARGETS:
        c = case_by_id(cid)
        p = CompressorParams(rc=c.rc, d=c.d, omega=c.omega, **values)
        try:
            with warnings.catch_warnings():  # contact loss is reported as a measure
                warnings.simplefilter("ignore", ModelValidityWarning)
                ds = simulate(
                    p,
                    revolutions=revolutions,
                    fs=20_000.0,
                    rtol=CALIBRATION_RTOL,
                    atol=CALIBRATION_ATOL,
                )
            out.append(float(np.abs(ds.a).max()))
        except IntegrationError:
            out.append(float("nan"))
    return out


def _objective(x, names, fixed, revolutions):
    vals = dict(fixed, **dict(zip(names, (float(v) for v in x), strict=True)))
    peaks = _peaks(vals, revolutions)
    errs = [math.log(p / t) if np.isfinite(p) and p > 0 else 10.0
            for p, (_, t) in zip(peaks, TARGETS, strict=True)]  # fmt: skip
    return float(np.sqrt(np.mean(np.square(errs))))


def calibrate(free=("m2", "m3", "J2"), *, fixed: dict[str, float] | None = None,
              maxiter: int = 15, popsize: int = 6, revolutions: float = 2.0, seed: int = 0,
              workers: int = 1) -> dict[str, Any]:  # fmt: skip
    """Best match of the paper's peak accelerations over the ``free`` parameters.

    Returns a dict with the best values, the RMS log-ratio error (0 = perfect; 0.1 ~ 10 %),
    and per target the paper's value, ours, and the ratio.
    """
    from scipy.optimize import differential_evolution

    bad = [n for n in free if n not in BOUNDS]
    if bad:
        from ..model.parameters import ParameterError

        raise ParameterError(f"cannot calibrate {bad}; allowed: {', '.join(BOUNDS)}")
    fixed = dict(fixed or {})
    names = list(free)
    res = differential_evolution(
        _objective, [BOUNDS[n] for n in names], args=(names, fixed, revolutions),
        maxiter=maxiter, popsize=popsize, seed=seed, polish=False, workers=workers,
        updating="deferred" if workers != 1 else "immediate", tol=1e-3,
    )  # fmt: skip
    best = dict(fixed, **dict(zip(names, (float(v) for v in res.x), strict=True)))
    peaks = _peaks(best, revolutions)
    defaults = {n: getattr(CompressorParams(), n) for n in names}
    return {
        "free": names, "fixed": fixed, "best": best, "defaults": defaults,
        "rms_log_error": float(res.fun), "evaluations": int(res.nfev),
        "targets": [dict(case=c, paper=t, ours=p, ratio=p / t) for (c, t), p
                    in zip(TARGETS, peaks, strict=True)],
    }  # fmt: skip


def write_calibration(results: list[dict[str, Any]], out: Path) -> Path:
    out.mkdir(parents=True, exist_ok=True)
    write_text(out / "calibration.json", json.dumps(jsonable(results), indent=1, default=float))
    lines = ["# Calibration of the unknown parameters to the paper's peak accelerations", ""]
    for r in results:
        lines += [f"## free: {', '.join(r['free'])}; fixed: {r['fixed'] or 'none'}", "",
                  f"best: {', '.join(f'{k} = {v:.4g}' for k, v in r['best'].items())} "
                  f"(RMS log error {r['rms_log_error']:.3f}, {r['evaluations']} evaluations)", "",
                  "| case | paper (m/s^2) | ours | ratio |", "|---|---|---|---|"]  # fmt: skip
        lines += [f"| {t['case']} | {t['paper']:.4g} | {t['ours']:.4g} | {t['ratio']:.3g} |"
                  for t in r["targets"]]  # fmt: skip
        lines.append("")
    path = out / "calibration.md"
    write_text(path, "\n".join(lines))
    return path
