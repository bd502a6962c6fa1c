"""Physics consistency: the best-fitting simulated record must explain the measured one
(issue 42, item 4b).

A classifier names the class whose training records a record's features resemble most; it
does not say that any simulated machine of that class looks like the record. This check
asks it directly. From the diagnoser's library of simulated records (its training records),
the **best-fitting simulated record** of the class named is built at the record's own
operating point (crank speed, suction and discharge levels) and at the severity that fits
best, and its curves over the revolution are compared with the record's, bin by bin, in units
of their uncertainty:

* the curves (`CURVES`), on quantities a measurement chain cannot fake: the shape of each
  chamber's pressure over the revolution normalised to its own range (a transducer's gain
  and offset leave it unchanged; a delay, a filter or a wrong crank-angle reference move
  it) and the acceleration's envelope over the revolution, each 10-degree bin's share of the
  high-passed energy (the accelerometer's gain and its mounting leave the shares; where in
  the revolution the knocks sit they do not) — the ``ph_``, ``pc_`` and ``ang_`` features;
* the best-fitting record: a local linear fit over the named class's library records
  nearest to the record in operating point and severity (`LOCAL_RECORDS`, tricube weights),
  evaluated at the record's operating point, at the severity (on a grid of `SEVERITY_GRID`
  values) that minimises the squared residuals: an interpolation of the simulator between
  the simulated records, not a new simulation;
* the uncertainty of each bin: the record's own revolution-to-revolution spread (the
  standard error of its mean curve, `revolution_spread`), combined with the library's
  interpolation error (the same local fit's leave-one-out residuals over the class's
  library records, `fit_consistency`), floored per curve at `SIGMA_FLOOR` of its median
  bin;
* the statistic: the largest absolute residual in those units over the bins of the curves
  the record has. Its conformal p-value against held-out in-domain records of the same
  channel set (crepes, Mondrian by channel set) below `ALPHA` refuses the record, naming the
  largest residual: which curve, which crank-angle bin, how many standard deviations.

So at most `ALPHA` of in-domain records whose class is named right are refused by it
(exchangeability with the held-out records). A record without a crank angle (a speed only)
has no curves and is not checked (the answer says so).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = [
    "ALPHA",
    "CURVES",
    "revolution_spread",
    "record_spread",
    "fit_consistency",
    "Consistency",
    "refusal",
]

#: Refuse a record whose consistency p-value is below this (the stated rate at which
#: in-domain records named right are refused by this check).
ALPHA = 0.02
#: The curves compared: feature prefix -> the name a refusal gives it.
CURVES = {
    "ang_": "acceleration envelope",
    "ph_": "head-end pressure shape",
    "pc_": "crank-end pressure shape",
}
#: Bins of a curve (10 degrees each).
BINS = 36
#: Library records of the named class a local fit uses (the nearest in operating point and
#: severity).
LOCAL_RECORDS = 24
#: Severities tried for the best fit.
SEVERITY_GRID = 21
#: A bin's standard deviation is at least this share of its curve's median bin's (a bin the
#: normalisation pins, such as the pressure shape's minimum, would otherwise have none).
SIGMA_FLOOR = 0.25
#: The operating point a fit is local in: every channel; without the pressures, the speed.
OPERATING = {"full": ("speed_hz", "cy_p_suction", "cy_p_discharge"), "no_pressure": ("speed_hz",)}


def _curve_columns(names, subset: str) -> list[str]:
    keep = ("ang_", "ph_", "pc_") if subset == "full" else ("ang_",)
    return [
        n
        for p in keep
        for n in names
        if n.startswith(p) and n[len(p) :].isdigit() and len(n) == len(p) + 3
    ]


def _per_revolution(y, revs, bins=BINS):
    """``(n_revs, bins)`` means of ``y`` in each crank-angle bin of each whole revolution."""
    r = np.asarray(revs, float)
    ok = np.isfinite(r)
    # whole revolutions as the features count them (`evidence._whole_revs`: a sample or two
    # short still covers one)
    fin = r[ok]
    tol = 2.0 * abs(fin[1] - fin[0]) if fin.size > 1 else 0.0
    start, stop = math.ceil(fin.min() - tol), math.floor(fin.max() + tol)
    n = stop - start
    if n < 1:
        return np.full((0, bins), np.nan)
    m = ok & (r >= start) & (r < stop)
    k = np.floor(r[m] - start).astype(int)
    b = np.minimum((np.mod(r[m] - start, 1.0) * bins).astype(int), bins - 1)
    idx = k * bins + b
    sums = np.bincount(idx, weights=np.asarray(y, float)[m], minlength=n * bins)
    counts = np.bincount(idx, minlength=n * bins)
    with np.errstate(invalid="ignore", divide="ignore"):
        return (sums / counts).reshape(n, bins)


def revolution_spread(x, fs: float, revs, p_head=None, p_crank=None) -> dict[str, np.ndarray]:
    """The standard error of each curve's bins (`CURVES`: the acceleration envelope's shares,
    the pressures' shapes) from the record's revolution-to-revolution spread: each whole
    revolution's curve in the units of the feature (the shares of the mean curve's total
    energy, the shape normalised by the mean curve's range), their standard deviation over
    the revolutions over the square root of their number. NaN with fewer than two."""
    from .evidence import _highpass

    out = {}
    e = _highpass(np.asarray(x, float), fs) ** 2
    chans = {"ang_": e, "ph_": p_head, "pc_": p_crank}
    for pre, y in chans.items():
        if y is None:
            continue
        R = _per_revolution(y, revs)
        if R.shape[0] < 2 or not np.isfinite(R).all():
            out[pre] = np.full(BINS, np.nan)
            continue
        mean = R.mean(axis=0)
        if pre == "ang_":
            R = R / mean.sum()
        else:
            lo, hi = mean.min(), mean.max()
            R = (R - lo) / (hi - lo) if hi > lo else np.full_like(R, np.nan)
        out[pre] = R.std(axis=0, ddof=1) / math.sqrt(R.shape[0])
    return out


def record_spread(channels: dict, fs: float, speed_hz: float) -> dict[str, np.ndarray]:
    """`revolution_spread` of a data set's record (its channels as stored), with the crank
    angle as the data set's features read it (`recipdyn.diagnosis.dataset.features_of`)."""
    from ..analysis.vibration import tacho_times

    x = np.asarray(channels["accel_guide"], float)
    edges = tacho_times(np.asarray(channels["tacho"], float), fs)
    revs = (np.arange(x.size) / fs - edges[0]) * speed_hz
    revs = np.where(revs >= 0, revs, np.nan)
    return revolution_spread(
        x, fs, revs, channels.get("p_head_sensor"), channels.get("p_crank_sensor")
    )


def _split(name: str) -> tuple[str, int]:
    """A curve feature's prefix and crank angle: ``"ang_120"`` -> ``("ang_", 120)``."""
    pre, _, deg = name.rpartition("_")
    return pre + "_", int(deg)


def _spread_vector(spread: dict, cols: list[str]) -> np.ndarray:
    out = np.full(len(cols), np.nan)
    for j, n in enumerate(cols):
        pre, deg = _split(n)
        s = spread.get(pre)
        if s is not None:
            out[j] = s[deg // 10]
    return out


class _Library:
    """The named class's library records: their curves and where they were simulated."""

    def __init__(self, Y, U, sev, has_sev):
        self.Y, self.U, self.sev, self.has_sev = Y, U, sev, has_sev
        P = np.column_stack([U, sev]) if has_sev else U
        self.mu = P.mean(axis=0)
        sd = P.std(axis=0)
        self.sd = np.where(sd > 0, sd, 1.0)
        self.P = (P - self.mu) / self.sd

    def predict(self, u, s=None, exclude: int | None = None) -> np.ndarray:
        """The local linear fit's curve at operating point ``u`` (and severity ``s``)."""
        q = np.asarray(u, float) if not self.has_sev else np.append(u, s)
        q = (q - self.mu) / self.sd
        P, Y = self.P, self.Y
        if exclude is not None:
            keep = np.arange(P.shape[0]) != exclude
            P, Y = P[keep], Y[keep]
        d = np.sqrt(((P - q) ** 2).sum(axis=1))
        k = min(LOCAL_RECORDS, P.shape[0])
        near = np.argsort(d)[:k]
        dmax = d[near].max() * 1.0001 + 1e-12
        w = (1 - (d[near] / dmax) ** 3) ** 3
        A = np.column_stack([np.ones(k), P[near] - q])
        if k < 2 * A.shape[1]:  # too few records for a slope: their weighted mean
            return (w[:, None] * Y[near]).sum(axis=0) / w.sum()
        sw = np.sqrt(w)[:, None]
        lam = 1e-6 * k
        AtA = (A * sw).T @ (A * sw) + lam * np.eye(A.shape[1])
        coef = np.linalg.solve(AtA, (A * sw).T @ (Y[near] * sw))
        return coef[0]

    def best(self, u, y, sigma, s0=None):
        """``(curve, severity)`` of the best fit to ``y`` at ``u`` (weights 1/sigma**2)."""
        if not self.has_sev:
            return self.predict(u), math.nan
        grid = np.linspace(0.0, 1.0, SEVERITY_GRID)
        if s0 is not None and math.isfinite(s0):
            grid = np.append(grid, np.clip(s0, 0, 1))
        best = None
        for s in grid:
            f = self.predict(u, s)
            cost = np.nansum(((y - f) / sigma) ** 2)
            if best is None or cost < best[0]:
                best = (cost, f, float(s))
        return best[1], best[2]


def _library(Z, center, scale, names, labels, severities, rows, label, subset):
    cols = _curve_columns(names, subset)
    idx = [names.index(n) for n in cols]
    ops = [names.index(o) for o in OPERATING[subset]]
    m = np.asarray(rows, bool) & (np.asarray(labels) == label)
    X = np.asarray(Z, float)[m] * scale + center
    Y, U = X[:, idx], X[:, ops]
    sev = np.asarray(severities, float)[m]
    ok = np.isfinite(Y).all(axis=1) & np.isfinite(U).all(axis=1)
    s_ok = sev[ok][np.isfinite(sev[ok])]
    has_sev = bool(s_ok.size and np.ptp(s_ok) > 0)  # the healthy machine: no severity
    sev = np.nan_to_num(sev, nan=0.0)
    return _Library(Y[ok], U[ok], sev[ok], has_sev), cols


def fit_consistency(
    Z, center, scale, names, labels, severities, *, fit_rows, calibration, source=""
) -> dict[str, Any]:
    """The consistency state of a diagnoser (plain arrays).

    ``Z``: the training rows, scaled (as stored); ``fit_rows``: the rows the library is made
    of (the others left out); ``calibration``: a list of ``(X, labels, spreads, subset)``
    held-out in-domain rows (unscaled), their classes, their `revolution_spread` dicts and
    the channel set each is cut to. The library's interpolation error per class and channel
    set is the leave-one-out residual of the local fit over the library's records."""
    state: dict[str, Any] = {"fit_rows": np.asarray(fit_rows, bool), "source": source}
    sig: dict[str, dict[str, np.ndarray]] = {}
    classes = sorted(set(np.asarray(labels)[np.asarray(fit_rows, bool)].tolist()))
    for subset in OPERATING:
        sig[subset] = {}
        for c in classes:
            lib, cols = _library(Z, center, scale, names, labels, severities, fit_rows, c, subset)
            n = lib.Y.shape[0]
            if n < 3:
                continue
            E = np.array(
                [lib.Y[i] - lib.predict(lib.U[i], lib.sev[i], exclude=i) for i in range(n)]
            )
            s = np.sqrt(np.mean(E**2, axis=0))
            sig[subset][c] = _floored(s, cols)
    state["sigma_model"] = sig
    c = Consistency(state, Z, center, scale, names, labels, severities)
    T, bins = [], []
    for X, labs, spreads, subset in calibration:
        for row, lab, sp in zip(X, labs, spreads, strict=True):
            r = c.check(row, sp, lab, subset)
            if r is not None and math.isfinite(r["statistic"]):
                T.append(r["statistic"])
                bins.append(subset)
    state["cal_statistic"] = np.array(T, float)
    state["cal_bins"] = np.array(bins, dtype=str)
    return state


def _floored(s: np.ndarray, cols: list[str]) -> np.ndarray:
    s = np.array(s, float)
    for pre in CURVES:
        j = [i for i, n in enumerate(cols) if n.startswith(pre)]
        if j:
            med = np.nanmedian(s[j])
            s[j] = np.maximum(np.nan_to_num(s[j], nan=med), SIGMA_FLOOR * med)
    return s


class Consistency:
    """The consistency check of a diagnoser, rebuilt from its state and training rows."""

    def __init__(self, state, Z, center, scale, names, labels, severities):
        self.state = state
        self._args = (Z, np.asarray(center, float), np.asarray(scale, float), list(names),
                      np.asarray(labels), np.asarray(severities, float))  # fmt: skip
        self._libs: dict = {}
        self._cc = None

    def _lib(self, label, subset):
        key = (label, subset)
        if key not in self._libs:
            Z, center, scale, names, labels, sev = self._args
            self._libs[key] = _library(
                Z, center, scale, names, labels, sev, self.state["fit_rows"], label, subset
            )
        return self._libs[key]

    def check(self, row, spread: dict, label: str, subset: str, severity=None):
        """The check of one record: its feature row (unscaled), its `revolution_spread`,
        the class named and its channel set. None if the set has no curves (no crank
        angle) or the class no library; else a dict: ``statistic`` (the largest residual in
        standard deviations), ``worst`` (curve, bin's crank angles, residual, its
        standard deviation, the record's own share of it), ``fit`` (severity, operating
        point) and ``p_value`` (once calibrated)."""
        if subset not in OPERATING:
            return None
        sig = self.state["sigma_model"][subset].get(label)
        if sig is None:
            return None
        lib, cols = self._lib(label, subset)
        names = self._args[3]
        row = np.asarray(row, float)
        y = row[[names.index(n) for n in cols]]
        u = row[[names.index(o) for o in OPERATING[subset]]]
        if not (np.isfinite(y).all() and np.isfinite(u).all()) or lib.Y.shape[0] < 3:
            why = "curves or operating point could not be read"
            return {"statistic": math.inf, "worst": None, "fit": None, "p_value": 0.0,
                    "reason": why}  # fmt: skip
        se = np.nan_to_num(_spread_vector(spread, cols), nan=0.0)
        sigma = np.sqrt(np.asarray(sig, float) ** 2 + se**2)
        f, s_fit = lib.best(u, y, sigma, severity)
        z = (y - f) / sigma
        j = int(np.argmax(np.abs(z)))
        name = cols[j]
        pre, a0 = _split(name)
        out = {
            "statistic": float(abs(z[j])),
            "worst": {
                "curve": CURVES[pre],
                "feature": name,
                "angle_deg": (a0, a0 + 10),
                "residual": float(y[j] - f[j]),
                "sigma": float(sigma[j]),
                "record_share": float(se[j] / sigma[j]) if sigma[j] > 0 else math.nan,
                "z": float(z[j]),
            },
            "fit": {
                "label": label,
                "severity": s_fit,
                **{o: float(v) for o, v in zip(OPERATING[subset], u, strict=True)},
            },
        }
        out["p_value"] = self.p_value(out["statistic"], subset)
        return out

    def n_calibration(self, subset: str) -> int:
        return int((np.asarray(self.state.get("cal_bins", [])) == subset).sum())

    def p_value(self, statistic: float, subset: str) -> float:
        """Conformal p-value of ``statistic`` among the held-out records of ``subset``
        (NaN before calibration)."""
        from crepes import ConformalClassifier

        if self.n_calibration(subset) == 0:
            return math.nan
        if self._cc is None:
            self._cc = ConformalClassifier().fit(
                np.asarray(self.state["cal_statistic"], float),
                bins=np.asarray(self.state["cal_bins"]),
            )
        p = self._cc.predict_p(np.array([[statistic]]), bins=np.array([subset]), smoothing=False)
        return float(np.asarray(p)[0, 0])


def refusal(diag, row, label, x, fs, revs, p_head, p_crank, *, angle: bool, severity=None):
    """``(check, reason)`` for one record of ``diag`` given the class ``label``: the
    `Consistency.check` result as plain values (None: not checked) and the reason to refuse
    it (empty if the best fit explains it)."""
    from .channels import available

    subset = available(row, diag.names)
    if not angle or subset not in OPERATING:
        return {"reason": "no crank angle: the curves over the revolution cannot be read"}, ""
    spread = revolution_spread(x, fs, revs, p_head if subset == "full" else None,
                               p_crank if subset == "full" else None)  # fmt: skip
    c = diag.consistency.check(row, spread, label, subset, severity)
    if c is None:
        return {"reason": f"no library records of {label}"}, ""
    p, alpha = c["p_value"], float(diag.state["consistency"].get("alpha", ALPHA))
    c["alpha"] = alpha
    if not (math.isfinite(p) and p < alpha):
        return c, ""
    w, f = c["worst"], c["fit"]
    if w is None:
        return c, f"the record's {c['reason']}"
    sev = f" at severity {f['severity']:.2f}" if math.isfinite(f["severity"]) else ""
    return c, (
        f"no simulated {label} explains the record: the best-fitting one{sev} (at "
        f"{f['speed_hz'] * 60:.0f} rpm"
        + (f", {f['cy_p_suction'] / 1e5:.2f}/{f['cy_p_discharge'] / 1e5:.2f} bar"
           if "cy_p_suction" in f else "")
        + f") misses its {w['curve']} at {w['angle_deg'][0]}-{w['angle_deg'][1]} deg crank "
        f"angle by {abs(w['z']):.1f} standard deviations (the record's revolution-to-revolution "
        f"spread and the library's interpolation error; p-value {p:.3f} < {alpha:g}): a chain "
        "error, another machine or a fault the data set does not hold"
    )  # fmt: skip
