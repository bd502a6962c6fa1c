"""Train and evaluate diagnosers on a data set (``recipdyn train``).

* **Class**: scikit-learn's `HistGradientBoostingClassifier`, one per feature subset a
  record may have (`AVAILABILITY`: all channels, no pressure, vibration and speed only),
  each trained on its subset's columns alone (one model trained on the three subsets at
  once, the missing groups as NaN, was less accurate on full records: 0.52 against 0.69 on
  a 12-condition data set's held-out conditions). Why not LightGBM: the same algorithm
  (histogram gradient boosting), but a compiled dependency more; scikit-learn's handles
  missing features natively, is deterministic for a fixed ``random_state`` and persists
  with skops.
* **Severity**: one `HistGradientBoostingRegressor` per fault class on the severity in [0, 1],
  with **split-conformal** intervals (crepes' Mondrian ``ConformalRegressor``, one category
  per channel set): a quarter of the training conditions (whole conditions) is held out to
  calibrate the absolute residuals, each record cut to every channel set, so the interval's
  coverage is that of a new operating condition and its drawn measurement chain, for the
  channels the record has (Vovk et al. 2005; Angelopoulos & Bates 2021, sec. 1;
  `recalibrate` calibrates on another data set instead).
* **Healthy baseline**: every pressure and cycle feature of the healthy training records is
  fitted by least squares as an affine function of the operating point the record itself
  shows (`OPERATING`: the crank speed, the suction and discharge levels), and the classifier
  and the regressors also read each record's deviation from it, in units of the fit's
  residual spread (``dv_`` features): what a fault changes and the operating point does not
  (condition normalisation, as condition monitoring refers a machine's readings to its own
  healthy baseline at the same load). On the 40-condition data set it raised the healthy
  machine's recall on held-out conditions from 0.70 to about 0.9: a mildly sticking plate's
  extra suction dip is a few per mille of the span, as large as the dip's own change with
  speed and pressures, and stands out once those are taken off.
* **Out of distribution** (`recipdyn.diagnosis.domain`): a detector fitted on the proper
  training conditions' records, per channel set, scores a record; its conformal novelty
  p-value against the held-out conditions' records (each cut to every channel set) below
  `recipdyn.diagnosis.domain.ALPHA` refuses it. The crank speed and the sampling rate must
  lie in the training ranges.
* **Physics consistency** (`recipdyn.diagnosis.consistency`): the best-fitting record of
  the named class, interpolated from the proper training records at the record's operating
  point and best severity, must explain the record's curves over the revolution within
  their uncertainty (p-value against the held-out records).

Evaluation (on the held-out test conditions): accuracy, confusion matrix, per-class recall,
the reliability diagram and expected calibration error of the top-class probability, the
detection limit of each fault (the smallest severity level from which every level's recall is
at least 90 %; on continuous severities, the lower edge of the lowest of `SEVERITY_BINS` equal
severity bins from which every bin's recall is), the severity's median relative error and the
intervals' coverage, the permutation importance of the features, and a classifier trained on
the operating condition alone (it must be at chance).
"""

from __future__ import annotations

import contextlib
import json
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ParameterError
from .channels import AVAILABILITY, _cols, available, naming_table
from .classes import get_class
from .dataset import CONDITION_COLUMNS, MIN_TRAIN_CONDITIONS, min_conditions, read_features
from .evidence import feature_groups
from .tolerances import BASELINE_SPREAD_FLOOR, OPERATING, RING_SLACK

__all__ = [
    "train",
    "evaluate",
    "Diagnoser",
    "save",
    "load",
    "recalibrate",
    "renaming",
    "expected_calibration_error",
    "detection_limits",
    "severity_bins",
    "fit_baseline",
    "deviations",
]

#: Quantiles of the training records' ringing frequency that bound the sensor band accepted.
RING_QUANTILES = (0.05, 0.95)
#: Nominal coverage of the severity intervals.
COVERAGE = 0.9
#: Layout version of a diagnoser file (4: the out-of-domain detector, the consistency check
#: and the severity's conformal residuals by channel set; 3 held a kNN threshold and one
#: half-width per channel set, and is refused with the command that rebuilds it).
FORMAT = 4
#: Prefix of a feature's deviation from the healthy baseline.
DEVIATION = "dv_"
#: Healthy training records, and distinct crank speeds among them (operating points: the
#: records of one condition share theirs), needed per coefficient of a baseline fit: fewer,
#: and the diagnoser has no baseline (a small data set's reads the raw features only).
BASELINE_RECORDS_PER_COEF = 5
BASELINE_POINTS_PER_COEF = 2
#: Samples per revolution of the stored angle-domain curves (the overlay's library; 2.8
#: degrees: the acceleration library, noisy float16, is the largest part of a diagnoser file).
CURVE_POINTS = 128


def _hgb_classifier(seed: int):
    from sklearn.ensemble import HistGradientBoostingClassifier

    return HistGradientBoostingClassifier(
        max_iter=100, learning_rate=0.1, max_leaf_nodes=8, early_stopping=False, random_state=seed
    )


def _hgb_regressor(seed: int):
    from sklearn.ensemble import HistGradientBoostingRegressor

    return HistGradientBoostingRegressor(
        max_iter=100, learning_rate=0.1, max_leaf_nodes=8, early_stopping=False, random_state=seed
    )


def _augment(X: np.ndarray, names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """The rows three times: all features, without the pressure group, base only (a record
    without pressure channels, or without a tacho); returns the rows and the source index."""
    groups = feature_groups(names)
    idx = {n: i for i, n in enumerate(names)}
    blocks = []
    for keep in AVAILABILITY.values():
        Y = X.copy()
        for g, cols in groups.items():
            if g not in keep:
                Y[:, [idx[c] for c in cols]] = np.nan
        blocks.append(Y)
    return np.vstack(blocks), np.tile(np.arange(X.shape[0]), len(blocks))


def _subset_rows(X: np.ndarray, names: list[str]) -> dict[str, np.ndarray]:
    """Indices of the rows of ``X`` by the availability subset each has."""
    subs = np.array([available(row, names) for row in X])
    return {k: np.flatnonzero(subs == k) for k in AVAILABILITY if (subs == k).any()}


def _fit_subsets(make, X: np.ndarray, y: np.ndarray, names: list[str]) -> dict[str, Any]:
    """One model per availability subset, fitted on that subset's columns of every row."""
    return {k: make().fit(X[:, _cols(names, k)], y) for k in AVAILABILITY}


def fit_baseline(X: np.ndarray, names: list[str], healthy: np.ndarray) -> dict | None:
    """The healthy baseline (module docstring) of the rows ``X`` (columns ``names``), fitted
    on the rows where ``healthy``; None if they are too few (`BASELINE_RECORDS_PER_COEF`)."""
    groups = feature_groups(names)
    if not set(OPERATING) <= set(names):
        return None
    ops = np.array([names.index(o) for o in OPERATING])
    O = X[:, ops]
    H = np.asarray(healthy, bool) & np.isfinite(O).all(axis=1)
    k = len(OPERATING) + 1
    need = BASELINE_RECORDS_PER_COEF * k
    points = np.unique(np.round(O[H, 0], 2)).size  # distinct speeds to 0.01 Hz
    if H.sum() < need or points < BASELINE_POINTS_PER_COEF * k:
        return None
    mu, sd = O[H].mean(axis=0), O[H].std(axis=0)
    sd = np.where(sd > 0, sd, 1.0)
    A = (O[H] - mu) / sd
    targets, coefs, spreads = [], [], []
    for n in groups["pressure"] + groups["cycle"]:
        if n in OPERATING:
            continue
        j = names.index(n)
        y = X[H, j]
        ok = np.isfinite(y)
        if ok.sum() < need:
            continue
        # centred, so the intercept is exact and the residuals average to zero even where
        # the operating points are nearly collinear (lstsq then drops a direction)
        a_mean, y_mean = A[ok].mean(axis=0), y[ok].mean()
        slope, *_ = np.linalg.lstsq(A[ok] - a_mean, y[ok] - y_mean, rcond=None)
        c = np.concatenate([[y_mean - a_mean @ slope], slope])
        r = y[ok] - c[0] - A[ok] @ slope
        spread = float(np.std(r, ddof=k))
        whole = float(np.nanstd(X[:, j]))
        spread = max(spread, BASELINE_SPREAD_FLOOR * whole)
        if not spread > 0:
            continue
        targets.append(n)
        coefs.append(c)
        spreads.append(spread)
    return {
        "operating": list(OPERATING),
        "mean": mu,
        "scale": sd,
        "targets": targets,
        "coef": np.array(coefs, float),
        "spread": np.array(spreads, float),
        "n_healthy": int(H.sum()),
    }


def deviations(X: np.ndarray, names: list[str], baseline: dict) -> np.ndarray:
    """Each row's deviation from the healthy baseline, in units of the fit's residual spread
    (columns: ``baseline["targets"]``; NaN where the row lacks the feature or the operating
    point)."""
    X = np.atleast_2d(np.asarray(X, float))
    O = X[:, [names.index(o) for o in baseline["operating"]]]
    A = np.column_stack([np.ones(X.shape[0]), (O - baseline["mean"]) / baseline["scale"]])
    Y = X[:, [names.index(t) for t in baseline["targets"]]]
    return (Y - A @ np.asarray(baseline["coef"]).T) / baseline["spread"]


def _with_baseline(X: np.ndarray, names: list[str], baseline: dict | None):
    """``(rows, names)`` with the deviation columns appended (unchanged without baseline)."""
    X = np.atleast_2d(np.asarray(X, float))
    if not baseline:
        return X, list(names)
    dv = [DEVIATION + t for t in baseline["targets"]]
    return np.hstack([X, deviations(X, names, baseline)]), [*names, *dv]


def _predict_subsets(models: dict, X: np.ndarray, names: list[str], proba: bool):
    """Each row predicted by the model of the subset it has."""
    X = np.asarray(X, float)
    out = None
    for k, rows in _subset_rows(X, names).items():
        m = models[k]
        Y = X[np.ix_(rows, _cols(names, k))]
        r = m.predict_proba(Y) if proba else m.predict(Y)
        if out is None:
            out = np.zeros((X.shape[0],) + r.shape[1:])
        out[rows] = r
    return out


def _scaler(X):
    med = np.nanmedian(X, axis=0)
    q1, q3 = np.nanpercentile(X, [25, 75], axis=0)
    iqr = q3 - q1
    sd = np.nanstd(X, axis=0)
    scale = np.where(iqr > 0, iqr, np.where(sd > 0, sd, 1.0))
    return med, scale


def expected_calibration_error(proba: np.ndarray, y: np.ndarray, bins: int = 10):
    """Top-label expected calibration error (Guo et al. 2017, eq. 3) and the reliability
    diagram's bins: ``(ece, [(mean confidence, accuracy, count), ...])``."""
    conf = proba.max(axis=1)
    correct = proba.argmax(axis=1) == y
    edges = np.linspace(0, 1, bins + 1)
    ece, diagram = 0.0, []
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        m = (conf > lo) & (conf <= hi)
        if m.any():
            ece += m.mean() * abs(conf[m].mean() - correct[m].mean())
            diagram.append((float(conf[m].mean()), float(correct[m].mean()), int(m.sum())))
    return float(ece), diagram


def detection_limits(
    labels, levels, severities, predicted, classes, threshold=0.9, bins=None, known=None
):
    """Per fault class: the recall at each severity level and the detection limit, the
    smallest level from which every level's recall is at least ``threshold`` (None: not
    reached).

    ``bins`` (edges, increasing): for continuous severities, the recall in each bin
    ``[edges[i], edges[i + 1])`` (the last bin closed), keyed by the bin's centre, and the
    limit is the lower edge of the lowest bin from which every bin's recall reaches
    ``threshold``; ``recall_bins`` gives the edges and ``n_by_severity`` the records of each
    bin or level. ``known``: the fault classes the values are read from (default
    `recipdyn.diagnosis.classes.CLASSES`; a machine's own: `Diagnoser.fault_classes`)."""
    out = {}
    edges = None if bins is None else np.asarray(bins, float)
    for c in classes:
        if c == "healthy":
            continue
        m = labels == c
        recall, count, lower = {}, {}, {}
        if edges is None:
            for lv in sorted(set(severities[m].tolist())):
                mm = m & (severities == lv)
                recall[float(lv)] = float((predicted[mm] == c).mean())
                count[float(lv)] = int(mm.sum())
                lower[float(lv)] = float(lv)
        else:
            idx = np.clip(np.searchsorted(edges, severities, side="right") - 1, 0, edges.size - 2)
            for b in range(edges.size - 1):
                mm = m & (idx == b)
                if not mm.any():
                    continue
                key = float(0.5 * (edges[b] + edges[b + 1]))
                recall[key] = float((predicted[mm] == c).mean())
                count[key] = int(mm.sum())
                lower[key] = float(edges[b])
        limit = None
        for lv in sorted(recall, reverse=True):
            if recall[lv] >= threshold:
                limit = lower[lv]
            else:
                break
        fc = get_class(c) if known is None else get_class(c, known)
        out[c] = {
            "recall_by_severity": recall,
            "n_by_severity": count,
            "recall_bins": None if edges is None else edges.tolist(),
            "limit_severity": limit,
            "limit_value": fc.value(limit) if limit is not None else None,
            "unit": fc.unit,
        }
    return out


#: Equal bins over a data set's severity range in which the detection limit reads the recall
#: on continuous severities.
SEVERITY_BINS = 4


def severity_bins(card: dict) -> np.ndarray | None:
    """Edges of the detection limit's severity bins for a data set of continuous
    severities (`SEVERITY_BINS` equal bins over its range); None for fixed levels."""
    r = card["spec"].get("severity_range")
    return None if r is None else np.linspace(r[0], r[1], SEVERITY_BINS + 1)


class Diagnoser:
    """A trained diagnoser: the classifier, the severity regressors with their conformal
    half-widths, the out-of-distribution reference, the angle-domain library and the data
    card it was trained on. Build with `train`; persist with `save` / `load`."""

    def __init__(self, state: dict[str, Any]):
        self.state = state

    @property
    def classes(self) -> list[str]:
        return list(self.state["classes"])

    @property
    def names(self) -> list[str]:
        return list(self.state["feature_names"])

    @property
    def card(self) -> dict:
        return json.loads(self.state["datacard_json"])

    @property
    def baseline(self) -> dict | None:
        """The healthy baseline (`fit_baseline`), or None."""
        return self.state.get("baseline")

    @property
    def machine(self):
        """The `recipdyn.diagnosis.machine.Machine` the diagnoser was built for: its data
        set's (the default machine for a data set, or a diagnoser file, without one)."""
        from .machine import Machine

        changes = self.card["spec"].get("machine") or ()
        return Machine.of(changes, source="the diagnoser's data set")

    @property
    def fault_classes(self):
        """The fault classes of the diagnoser's machine (their values re-derived for it:
        `recipdyn.diagnosis.machine.fault_classes`)."""
        from .machine import fault_classes

        changes = self.card["spec"].get("machine")
        return fault_classes(self.machine if changes else None)

    def fault_class(self, name: str):
        """The fault class ``name`` of the diagnoser's machine."""
        return get_class(name, self.fault_classes)

    def model_rows(self, X: np.ndarray) -> tuple[np.ndarray, list[str]]:
        """The rows the learners read: ``X`` (columns `names`) and the deviations from the
        healthy baseline; and their column names."""
        return _with_baseline(X, self.names, self.baseline)

    def predict_proba(self, X: np.ndarray) -> np.ndarray:
        """Class probabilities, each row by the classifier of the features it has."""
        Xm, names = self.model_rows(X)
        return _predict_subsets(self.state["classifiers"], Xm, names, proba=True)

    def severity(self, X: np.ndarray, label: str):
        """Severity in [0, 1] and its `COVERAGE` interval for class ``label``."""
        reg = self.state["regressors"].get(label)
        if reg is None:
            n = np.asarray(X).shape[0]
            return np.zeros(n), np.zeros(n), np.zeros(n)
        X = np.asarray(X, float)
        Xm, names = self.model_rows(X)
        s = np.clip(_predict_subsets(reg, Xm, names, proba=False), 0.0, 1.0)
        subs = np.array([available(row, self.names) for row in X])
        q = np.maximum(self.half_widths(label, subs), self.severity_resolution)
        return s, np.clip(s - q, 0, 1), np.clip(s + q, 0, 1)

    def half_widths(self, label: str, subsets) -> np.ndarray:
        """The conformal half-width of class ``label``'s severity interval for records of
        each channel set in ``subsets``: crepes' Mondrian ``ConformalRegressor`` on the
        held-out records' absolute residuals of that channel set (1, the whole range, where
        they are too few for `COVERAGE`)."""
        from crepes import ConformalRegressor

        subsets = np.atleast_1d(np.asarray(subsets, dtype=str))
        cal = self.state["severity_calibration"].get(label)
        out = np.ones(subsets.size)
        if cal is None or not len(cal["residuals"]):
            return out
        bins = np.asarray(cal["bins"], dtype=str)
        known = np.isin(subsets, bins)
        if known.any():
            import warnings

            cr = ConformalRegressor().fit(np.asarray(cal["residuals"], float), bins=bins)
            with warnings.catch_warnings():  # too few records of a set: the whole range, as said
                warnings.filterwarnings("ignore", "the no. of calibration examples")
                iv = cr.predict_int(np.zeros(int(known.sum())), bins=subsets[known],
                                    confidence=COVERAGE)  # fmt: skip
            out[known] = np.minimum(np.asarray(iv, float)[:, 1], 1.0)
        return out

    @property
    def severity_resolution(self) -> float:
        """The narrowest half-width a severity interval may have: half the spacing of the
        fixed levels the diagnoser was trained on (0 for drawn severities). A regressor
        trained on four levels learns them exactly, and its conformal residuals on records of
        those same levels are ~0, but a machine between two levels is not one of them: an
        interval narrower than the levels' spacing claims what the data set cannot show."""
        spec = json.loads(self.state["datacard_json"]).get("spec", {})
        levels = sorted(spec.get("levels") or ())
        if spec.get("severity_range") is not None or len(levels) < 2:
            return 0.0
        return 0.5 * float(np.min(np.diff(levels)))

    @property
    def domain(self):
        """The out-of-domain detector (`recipdyn.diagnosis.domain.Domain`), refitted on the
        training rows it was fitted on when first used."""
        if getattr(self, "_domain", None) is None:
            from .domain import Domain

            self._domain = Domain(
                self.state["domain"], self.state["Z_train"], self.state["train_labels"]
            )
        return self._domain

    @property
    def consistency(self):
        """The physics consistency check (`recipdyn.diagnosis.consistency.Consistency`)."""
        if getattr(self, "_consistency", None) is None:
            from .consistency import Consistency

            st = self.state
            self._consistency = Consistency(
                st["consistency"], st["Z_train"], st["center"], st["scale"], self.names,
                st["train_labels"], st["train_severity"],
            )  # fmt: skip
        return self._consistency

    def ood(self, row: np.ndarray, label: str | None = None) -> dict[str, Any]:
        """The out-of-domain verdict of one feature row (the class named: ``label``):
        ``score``, ``p_value``, ``alpha`` (refuse below), ``features`` (the channel set),
        ``method``, ``n_calibration`` (held-out records of the set)."""
        subset = available(row, self.names)
        z = (np.asarray(row, float) - self.state["center"]) / self.state["scale"]
        d = self.domain
        return {
            "score": float(d.score(z[None, :], subset, label)[0]),
            "p_value": float(d.p_value(z[None, :], subset, label)[0]),
            "alpha": d.alpha,
            "features": subset,
            "method": d.state["method"],
            "n_calibration": d.n_calibration(subset),
        }


def _split_train(df, seed: int):
    conds = np.array(sorted(df.condition.unique()))
    rng = np.random.default_rng([seed, 2])
    n_cal = max(1, round(len(conds) / 4)) if len(conds) > 1 else 0
    cal = set(rng.permutation(conds)[:n_cal].tolist())
    is_cal = df.condition.isin(cal).to_numpy()
    return ~is_cal, is_cal


def curve(x, tacho, fs, f_rev, points: int = CURVE_POINTS) -> np.ndarray:
    """One revolution of ``x`` from the tacho's first edge (or the record's start) at
    ``points`` crank angles (linear interpolation)."""
    from ..analysis.vibration import tacho_times

    t = np.arange(x.size) / fs
    t0 = 0.0
    if tacho is not None:
        e = tacho_times(tacho, fs)
        if e.size and e[0] + 1 / f_rev <= t[-1]:
            t0 = float(e[0])
    tq = t0 + np.arange(points) / points / f_rev
    if tq[-1] > t[-1]:
        return np.full(points, np.nan)
    return np.interp(tq, t, x)


@contextlib.contextmanager
def one_thread() -> Iterator[None]:
    """Run scikit-learn's boosting on one OpenMP thread. Its threads wait for each other by
    spinning, so on a machine whose cores are busy (a sweep, a test worker) every fit and
    every prediction of these small models waits for a descheduled thread: 10x slower or
    worse, never faster. threadpoolctl limits only the runtimes already loaded, so the
    OpenMP runtime scikit-learn brings is loaded first."""
    import sklearn.ensemble  # noqa: F401 - loads the OpenMP runtime threadpoolctl must see
    from threadpoolctl import threadpool_limits

    with threadpool_limits(1):
        yield


def train(
    folder: str | Path,
    *,
    seed: int = 0,
    progress: bool = True,
    classes: list[str] | tuple[str, ...] | None = None,
) -> tuple[Diagnoser, dict]:
    """Train a diagnoser on the training conditions of the data set in ``folder`` and
    evaluate it on the test conditions; returns ``(diagnoser, evaluation)``.

    ``classes``: train and evaluate on these classes of the data set only (its records of
    the other classes left out; default all), e.g. to measure what a class adds."""
    folder = Path(folder)
    with one_thread():
        return _train(folder, seed, classes)


def _train(folder: Path, seed: int, only=None) -> tuple[Diagnoser, dict]:
    from .. import __version__

    df, card = read_features(folder)
    if "chain_refused" in df.columns:  # records the chain correction refused: left out
        df = df[df.chain_refused.fillna("") == ""].reset_index(drop=True)
    names = [c[2:] for c in df.columns if c.startswith("f_")]
    classes = list(card["spec"]["classes"])
    if only is not None:
        bad = [c for c in only if c not in classes] + ([] if "healthy" in only else ["healthy"])
        if bad:
            raise ParameterError(
                f"classes = {list(only)!r}; allowed: 'healthy' and any of the data set's "
                f"{', '.join(classes)}"
            )
        classes = [c for c in classes if c in only]
        df = df[df.label.isin(classes)].reset_index(drop=True)
    train_df = df[df.split == "train"].reset_index(drop=True)
    test_df = df[df.split == "test"].reset_index(drop=True)
    n_train = train_df.condition.nunique()
    if n_train < MIN_TRAIN_CONDITIONS:
        raise ParameterError(
            f"{folder}: {n_train} training condition(s); a diagnoser trains on "
            f"{MIN_TRAIN_CONDITIONS} at least (one to fit, one to calibrate its severity "
            "intervals and out-of-distribution threshold): build a data set of "
            f"{min_conditions(0.25)} conditions or more ('recipdyn dataset --conditions')"
        )
    if train_df.label.nunique() < len(classes) or test_df.empty:
        raise ParameterError(
            f"{folder}: the training conditions lack some classes or there "
            "is no test condition; build a larger data set"
        )
    X = train_df[[f"f_{n}" for n in names]].to_numpy(float)
    y = train_df.label.map({c: i for i, c in enumerate(classes)}).to_numpy()
    baseline = fit_baseline(X, names, (train_df.label == "healthy").to_numpy())
    Xm, mnames = _with_baseline(X, names, baseline)
    clfs = _fit_subsets(lambda: _hgb_classifier(seed), Xm, y, mnames)
    proper, cal = _split_train(train_df, seed)
    regs = {}
    for c in classes:
        if c == "healthy":
            continue
        m = (train_df.label == c).to_numpy()
        s = train_df.severity.to_numpy()
        regs[c] = _fit_subsets(lambda: _hgb_regressor(seed), Xm[m & proper], s[m & proper], mnames)
    center, scale = _scaler(X[proper])
    speed = train_df.f_speed_hz.to_numpy()
    acc_curves, p_curves = _library(folder, train_df)
    # the reference the data set's features were corrected against, or one built here
    chain_ref = (card.get("chain_correction") or {}).get("reference") or _chain_reference(
        folder, train_df, seed
    )
    state = {
        "format": FORMAT,
        "recipdyn_version": __version__,
        "sklearn_version": _sk_version(),
        "datacard_json": json.dumps(card, default=float),
        "classes": classes,
        "feature_names": names,
        "baseline": baseline,
        "classifiers": clfs,
        "regressors": regs,
        "center": center,
        "scale": scale,
        # float16 (3 significant digits: the distances compare spreads of whole units)
        "Z_train": _half((X - center) / scale),
        "speed_range": [float(speed.min()), float(speed.max())],
        "fs_range": [float(train_df.fs.min()), float(train_df.fs.max())],
        # the central 90 % (a few records with few impacts peak elsewhere: RING_QUANTILES)
        "ring_range": [float(np.nanquantile(train_df.f_acc_ring_hz, q)) for q in RING_QUANTILES],
        "noise_floor_range": _noise_floor_range(X, names),
        "quiet_range": _finite_range(X, names, "acc_quiet_share"),
        "train_labels": train_df.label.tolist(),
        "train_severity": train_df.severity.to_numpy(float),
        "train_records": train_df.record.to_numpy(int),
        "library_accel": acc_curves,
        # what the chain estimators give on the diagnoser's own chain (correction.py)
        "chain_reference": chain_ref,
        # the head-end pressure of the healthy records only: the evidence compares a record's
        # with its closest healthy one (zeros elsewhere, which compress away)
        "library_p_head": np.where(
            (train_df.label == "healthy").to_numpy()[:, None], p_curves, 0
        ).astype(np.float16),
    }
    for k in ("center", "scale"):
        state[k] = np.asarray(state[k], float)
    diag = Diagnoser(state)
    # the held-out calibration: the quarter of the training conditions the regressors, the
    # detector and the consistency library were not fitted on
    held = held_out_rows(folder, train_df[cal].reset_index(drop=True), names)
    _calibrate_state(state, held, fit_rows=proper,
                     source=f"{int(cal.sum())} records of {int(train_df[cal].condition.nunique())} "
                     f"held-out training conditions of {folder.name}")  # fmt: skip
    state["fingerprints_json"] = json.dumps(
        _fingerprints(train_df, card, names, diag), default=float
    )
    ev = evaluate(diag, test_df, train_df, seed=seed)
    # what each channel set can name, measured on the held-out conditions (channels.gate)
    state["naming"] = {k: ev[k]["naming"] for k in AVAILABILITY}
    return diag, ev


def held_out_rows(folder: Path, rows_df, names: list[str]) -> dict[str, Any]:
    """The records of ``rows_df`` (rows of a data set's feature table in ``folder``) as the
    calibration reads them: features ``X`` (columns ``names``), ``labels``, ``severity``,
    and each record's revolution-to-revolution spread of its curves
    (`recipdyn.diagnosis.consistency.record_spread`, from its stored channels)."""
    import zarr

    from .consistency import record_spread

    g = zarr.open_group(str(Path(folder) / "signals.zarr"), mode="r")
    spreads = []
    for _, r in rows_df.iterrows():
        i, n = int(r.record), int(g["n_samples"][int(r.record)])
        ch = {c: np.asarray(g[c][i, :n], float) for c in
              ("accel_guide", "tacho", "p_head_sensor", "p_crank_sensor") if c in g}  # fmt: skip
        try:
            spreads.append(record_spread(ch, float(r.fs), float(r.f_speed_hz)))
        except (ValueError, IndexError):  # no tacho edge: no spread
            spreads.append({})
    return {
        "X": rows_df[[f"f_{n}" for n in names]].to_numpy(float),
        "labels": rows_df.label.to_numpy(str),
        "severity": rows_df.severity.to_numpy(float),
        "spreads": spreads,
    }


def _calibrate_state(state: dict, held: dict, *, fit_rows, source: str) -> None:
    """The held-out calibration of a diagnoser's ``state`` (in place) from the records
    ``held`` (`held_out_rows`): the severity's conformal residuals by channel set, the
    out-of-domain detector's calibration scores and the consistency check's statistics.
    ``fit_rows``: the training rows the detector and the consistency library use."""
    from .consistency import fit_consistency
    from .domain import fit_domain

    diag = Diagnoser(state)
    names, classes = diag.names, diag.classes
    X, labels, sev = held["X"], held["labels"], held["severity"]
    n = X.shape[0]
    subsets = list(AVAILABILITY)
    sevcal = {}
    for c in classes:
        if c == "healthy":
            continue
        m = labels == c
        Xa, src = _augment(X[m], names)  # the subsets stacked in AVAILABILITY's order
        if not m.any():
            sevcal[c] = {"residuals": np.zeros(0), "bins": np.zeros(0, dtype=str)}
            continue
        Xm, mnames = _with_baseline(Xa, names, diag.baseline)
        pred = np.clip(_predict_subsets(state["regressors"][c], Xm, mnames, proba=False), 0, 1)
        sevcal[c] = {
            "residuals": np.abs(pred - sev[m][src]),
            "bins": np.repeat(subsets, int(m.sum())).astype(str),
        }
    state["severity_calibration"] = sevcal
    Z = (X - state["center"]) / state["scale"]
    cols = {k: _cols(names, k) for k in subsets}
    state["domain"] = fit_domain(
        state["Z_train"], np.asarray(state["train_labels"]), cols,
        [(Z, labels, k) for k in subsets], fit_rows=fit_rows, source=source,
    )  # fmt: skip
    spreads = held["spreads"]
    state["consistency"] = fit_consistency(
        state["Z_train"], state["center"], state["scale"], names, state["train_labels"],
        state["train_severity"], fit_rows=fit_rows, source=source,
        calibration=[(X, labels, spreads, k) for k in ("full", "no_pressure")],
    )  # fmt: skip
    state["calibration_records"] = int(n)
    for k in ("_domain", "_consistency"):
        diag.__dict__.pop(k, None)


def recalibrate(diag: Diagnoser, *folders: str | Path) -> Diagnoser:
    """``diag`` calibrated anew on every record of the data sets in ``folders``: records its
    training did not use (other operating conditions, other drawn measurement chains), each
    cut to every channel set. The detector and the consistency library are then fitted on
    all of ``diag``'s training records, the regressors and classifiers kept as they are.
    A data set must be of ``diag``'s features and share a class with it (else refused,
    naming it); its records of other classes are left out."""
    import copy

    names = diag.names
    parts, sources = [], []
    with one_thread():
        for folder in map(Path, folders):
            df, card = read_features(folder)
            missing = [n for n in names if f"f_{n}" not in df.columns]
            if missing:
                raise ParameterError(
                    f"{folder}: its features lack {missing[:3]} of the diagnoser's; build "
                    "the calibration data set with this recipdyn"
                )
            df = df[df.label.isin(diag.classes)].reset_index(drop=True)
            if "chain_refused" in df.columns:  # records the chain correction refused
                df = df[df.chain_refused.fillna("") == ""].reset_index(drop=True)
            if df.empty:
                raise ParameterError(f"{folder}: no record of the diagnoser's classes")
            parts.append(held_out_rows(folder, df, names))
            sources.append(f"{len(df)} records of {df.condition.nunique()} conditions of "
                           f"{folder.name} (seed {card['spec'].get('seed')})")  # fmt: skip
        if not parts:
            raise ParameterError("recalibrate: give at least one data set")
        held = {k: np.concatenate([p[k] for p in parts]) for k in ("X", "labels", "severity")}
        held["spreads"] = [s for p in parts for s in p["spreads"]]
        state = copy.copy(diag.state)
        for old in ("ood_threshold", "conformal"):  # format 3's threshold and half-widths
            state.pop(old, None)
        state["format"] = FORMAT
        n = len(state["train_labels"])
        _calibrate_state(state, held, fit_rows=np.ones(n, bool), source="; ".join(sources))
    return Diagnoser(state)


def renaming(diag: Diagnoser, folder: str | Path, *, seed: int = 0) -> Diagnoser:
    """``diag`` with its naming tables (`recipdyn.diagnosis.channels`: what each channel set
    can name) measured anew by `evaluate` on the test conditions of the data set in
    ``folder``, which must be the one ``diag`` was trained on (its data card and training
    records; refused otherwise, saying which differs): e.g. to add the held-out answers'
    probabilities to the table of a diagnoser trained before they were kept, without
    retraining its models. ``seed``: `train`'s (the evaluation's permutation importance and
    condition-only classifier; the naming tables do not depend on it)."""
    import copy

    folder = Path(folder)
    with one_thread():
        df, card = read_features(folder)
        if json.loads(json.dumps(card, default=float)) != json.loads(diag.state["datacard_json"]):
            raise ParameterError(
                f"{folder}: its data card is not the one this diagnoser was trained on; "
                "give the diagnoser's own data set (its test conditions are held out)"
            )
        if "chain_refused" in df.columns:  # as _train: records the correction refused
            df = df[df.chain_refused.fillna("") == ""].reset_index(drop=True)
        df = df[df.label.isin(diag.classes)].reset_index(drop=True)
        train_df = df[df.split == "train"].reset_index(drop=True)
        test_df = df[df.split == "test"].reset_index(drop=True)
        if not np.array_equal(
            train_df.record.to_numpy(int), np.asarray(diag.state["train_records"], int)
        ):
            raise ParameterError(
                f"{folder}: its training records are not this diagnoser's; give the "
                "diagnoser's own data set"
            )
        ev = evaluate(diag, test_df, train_df, seed=seed)
    state = copy.copy(diag.state)
    state["naming"] = {k: ev[k]["naming"] for k in AVAILABILITY}
    return Diagnoser(state)


def _noise_floor_range(X: np.ndarray, names: list[str]) -> list[float] | None:
    """The training records' noise floors (`recipdyn.diagnosis.diagnose.noise_floor`: the
    quietest crank-angle bin's share of the mean bin), least and largest; None without the
    angle features."""
    cols = [i for i, n in enumerate(names) if n.startswith("ang_")]
    q = len(cols) * np.nanmin(X[:, cols], axis=1) if cols else np.zeros(0)
    q = q[np.isfinite(q)]
    return [float(q.min()), float(q.max())] if q.size else None


def _finite_range(X: np.ndarray, names: list[str], name: str) -> list[float] | None:
    """Least and largest finite value of feature ``name`` (None: absent or never finite)."""
    if name not in names:
        return None
    v = X[:, names.index(name)]
    v = v[np.isfinite(v)]
    return [float(v.min()), float(v.max())] if v.size else None


def _library(folder, train_df):
    import zarr

    g = zarr.open_group(str(folder / "signals.zarr"), mode="r")
    recs = train_df.record.to_numpy(int)
    acc = np.full((recs.size, CURVE_POINTS), np.nan, np.float32)
    ph = np.full((recs.size, CURVE_POINTS), np.nan, np.float32)
    for j, i in enumerate(recs):
        n = int(g["n_samples"][i])
        fs = float(train_df.fs.iloc[j])
        f_rev = float(train_df.omega.iloc[j]) / (2 * np.pi)
        tach = np.asarray(g["tacho"][i, :n], float)
        acc[j] = curve(np.asarray(g["accel_guide"][i, :n], float), tach, fs, f_rev)
        ph[j] = curve(np.asarray(g["p_head_sensor"][i, :n], float), tach, fs, f_rev)
    return _half(acc), _half(ph / 1e5)  # the pressure in bar (float16 tops at 65 504)


def _chain_reference(folder, train_df, seed: int) -> dict | None:
    """The `recipdyn.diagnosis.correction.ChainReference` of the data set's own chain, from
    up to `recipdyn.diagnosis.correction.REFERENCE_PER_CLASS` training records of each class
    (seeded draw): the pressure channels' phase and offset estimates and the exponents
    they go with. None without pressure channels."""
    import zarr

    from ..analysis.vibration import tacho_times
    from .correction import REFERENCE_PER_CLASS, known_chain, pressure_phase, reference_from

    g = zarr.open_group(str(folder / "signals.zarr"), mode="r")
    if "p_head_sensor" not in g or "p_crank_sensor" not in g:
        return None
    machine = json.loads(g.attrs["spec_json"]).get("machine") or None  # its chambers
    rng = np.random.default_rng([seed, 7])
    pick = []
    for _, sub in train_df.groupby("label"):
        idx = sub.index.to_numpy()
        pick += rng.permutation(idx)[:REFERENCE_PER_CLASS].tolist()
    fits = []
    for j in sorted(pick):
        i = int(train_df.record.iloc[j])
        n = int(g["n_samples"][i])
        fs = float(train_df.fs.iloc[j])
        edges = tacho_times(np.asarray(g["tacho"][i, :n], float), fs)
        if not edges.size:
            continue
        # the crank angle as the data set's features read it (dataset.features_of)
        revs = (np.arange(n) / fs - edges[0]) * float(train_df.f_speed_hz.iloc[j])
        revs = np.where(revs >= 0, revs, np.nan)
        fit = {"condition": int(train_df.condition.iloc[j])}
        row = train_df.iloc[j]
        for k, ch in enumerate(("head", "crank")):
            p = np.asarray(g[f"p_{ch}_sensor"][i, :n], float)
            f = pressure_phase(p, revs, ch, machine)
            if f["ok"]:  # a drawn chain's own errors off: the reference is the physics'
                phase, offset, gain = known_chain(row, k, float(row.f_speed_hz))
                f["phase_deg"] -= phase
                f["offset_pa"] -= offset
                f["p_lo"] = (f["p_lo"] - offset) / gain
                f["p_hi"] = (f["p_hi"] - offset) / gain
            fit[ch] = f
        fits.append(fit)
    if not fits:
        return None
    ref = reference_from(fits, source=f"{len(fits)} training records of {folder.name}")
    return ref.to_dict() if ref.rows else None


def _half(a) -> np.ndarray:
    """``a`` as float16, clipped to its range (the file stays small)."""
    a = np.asarray(a, float)
    return np.clip(a, -6e4, 6e4).astype(np.float16)


def _fingerprints(train_df, card, names, diag) -> list[dict[str, Any]]:
    """Records whose physics a diagnoser pins: their tasks, features and predicted
    probabilities (the healthy machine, the ring leak and the suction-valve leak at the first
    training condition)."""
    from .dataset import DatasetSpec, design

    tasks = {t["index"]: t for t in design(DatasetSpec.from_dict(card["spec"]))}
    first = train_df.condition.min()
    out = []
    for c in ("healthy", "ring_leak", "suction_valve_leak"):
        sub = train_df[(train_df.condition == first) & (train_df.label == c)]
        if sub.empty:
            continue
        r = sub.iloc[-1]
        x = np.array([[r[f"f_{n}"] for n in names]], float)
        out.append(
            {
                "task": tasks[int(r.record)],
                "features": dict(zip(names, x[0].tolist(), strict=True)),
                "proba": diag.predict_proba(x)[0].tolist(),
            }
        )
    return out


def _sk_version() -> str:
    import sklearn

    return sklearn.__version__


def evaluate(diag: Diagnoser, test_df, train_df, *, seed: int = 0) -> dict[str, Any]:
    """The evaluation on held-out conditions (see the module docstring)."""
    from sklearn.metrics import confusion_matrix

    classes, names = diag.classes, diag.names
    X = test_df[[f"f_{n}" for n in names]].to_numpy(float)
    y = test_df.label.map({c: i for i, c in enumerate(classes)}).to_numpy()
    res: dict[str, Any] = {
        "n_test": int(len(test_df)),
        "n_train": int(len(train_df)),
        "test_conditions": sorted(int(c) for c in test_df.condition.unique()),
    }
    Xa, src = _augment(X, names)
    for (subset, _), k in zip(AVAILABILITY.items(), range(3), strict=True):
        rows = slice(k * X.shape[0], (k + 1) * X.shape[0])
        proba = diag.predict_proba(Xa[rows])
        pred = proba.argmax(axis=1)
        ece, diagram = expected_calibration_error(proba, y)
        moderate = (test_df.label == "healthy").to_numpy() | (test_df.severity >= 0.5).to_numpy()
        res[subset] = {
            "accuracy": float((pred == y).mean()),
            "accuracy_moderate_severe": float((pred == y)[moderate].mean()),
            "ece": ece,
            "reliability": diagram,
            "confusion": confusion_matrix(y, pred, labels=range(len(classes))).tolist(),
            "recall": {c: float((pred[y == i] == i).mean()) for i, c in enumerate(classes)},
            "detection": detection_limits(
                test_df.label.to_numpy(),
                None,
                test_df.severity.to_numpy(),
                np.array(classes)[pred],
                classes,
                bins=severity_bins(diag.card),
                known=diag.fault_classes,
            ),
        }
        # which classes this channel set can name (recipdyn.diagnosis.channels)
        res[subset]["naming"] = naming_table(
            test_df.label.to_numpy(),
            np.array(classes)[pred],
            test_df.severity.to_numpy(),
            classes,
            res[subset]["detection"],
            top=proba.max(axis=1),
        )
        if subset == "full":
            res["predicted"] = np.array(classes)[pred].tolist()
            res["proba"] = proba.tolist()
    # severity, given the true class
    sev: dict[str, Any] = {}
    rel_all, cover_all = [], []
    for c in classes:
        if c == "healthy":
            continue
        m = (test_df.label == c).to_numpy()
        if not m.any():
            continue
        s, lo, hi = diag.severity(X[m], c)
        true = test_df.severity.to_numpy()[m]
        fc = diag.fault_class(c)
        v_hat = np.array([fc.value(v) for v in s])
        v_true = np.array([fc.value(v) for v in true])
        rel = np.abs(v_hat - v_true) / np.abs(v_true - (1.0 if c == "weak_valve_spring" else 0))
        cover = (true >= lo - 1e-12) & (true <= hi + 1e-12)
        sev[c] = {
            "median_relative_error": float(np.median(rel)),
            "coverage": float(cover.mean()),
            "half_width": max(float(diag.half_widths(c, "full")[0]), diag.severity_resolution),
            "n": int(m.sum()),
        }
        rel_all += rel.tolist()
        cover_all += cover.tolist()
    res["severity"] = sev
    res["severity_median_relative_error"] = float(np.median(rel_all)) if rel_all else math.nan
    res["severity_coverage"] = float(np.mean(cover_all)) if cover_all else math.nan
    res["condition_only"] = condition_only(train_df, test_df, classes, seed)
    res["importance"] = _importance(diag, X, y, seed)
    lo, hi = diag.state["ring_range"]
    ring = X[:, names.index("acc_ring_hz")]
    out_band = ~((ring >= lo * (1 - RING_SLACK)) & (ring <= hi * (1 + RING_SLACK)))
    pred = np.array(classes)[np.asarray(res["proba"]).argmax(axis=1)]
    far = np.array([(o := diag.ood(row, lab))["p_value"] < o["alpha"]
                    for row, lab in zip(X, pred, strict=True)])  # fmt: skip
    res["ood_false_refusals"] = float(np.mean(out_band | far))
    return res


def condition_only(train_df, test_df, classes, seed: int) -> dict[str, float]:
    """Accuracy of a classifier that sees only the operating condition and the sensor
    settings, against chance (1 / number of classes) and its binomial bound on the test
    size (chance + 3 standard deviations)."""
    cols = list(CONDITION_COLUMNS)
    ytr = train_df.label.map({c: i for i, c in enumerate(classes)}).to_numpy()
    yte = test_df.label.map({c: i for i, c in enumerate(classes)}).to_numpy()
    clf = _hgb_classifier(seed).fit(train_df[cols].to_numpy(float), ytr)
    acc = float((clf.predict(test_df[cols].to_numpy(float)) == yte).mean())
    p = 1.0 / len(classes)
    bound = p + 3 * math.sqrt(p * (1 - p) / len(test_df))
    return {"accuracy": acc, "chance": p, "bound": bound}


def _importance(diag, X, y, seed) -> list[tuple[str, float]]:
    from sklearn.inspection import permutation_importance

    Xm, names = diag.model_rows(X)
    cols = _cols(names, "full")
    r = permutation_importance(
        diag.state["classifiers"]["full"],
        Xm[:, cols],
        y,
        n_repeats=3,
        random_state=seed,
        scoring="accuracy",
    )
    order = np.argsort(r.importances_mean)[::-1][:15]
    return [(names[cols[i]], float(r.importances_mean[i])) for i in order]


#: Types a diagnoser file may hold (checked before loading: skops refuses anything else).
TRUSTED_PREFIXES = ("sklearn.", "numpy.", "builtins.", "collections.")


def _estimators(state: dict):
    """``(key, estimator)`` of every gradient-boosting model in a diagnoser's state."""
    for k, est in state["classifiers"].items():
        yield f"classifiers/{k}", est
    for c, regs in state["regressors"].items():
        for k, est in regs.items():
            yield f"regressors/{c}/{k}", est


def _pack(state: dict) -> dict:
    """A copy of ``state`` whose boosting models hold their trees as one byte array each
    (`PACKED`) instead of one object a tree: skops writes and reads each object with its own
    schema entry, which made a file of 4 500 trees 7 MB and 15 s to load. The nodes' split
    gains and sample counts (not used to predict) are zeroed, so they compress away."""
    import copy

    state = dict(state)
    state["classifiers"] = dict(state["classifiers"])
    state["regressors"] = {c: dict(r) for c, r in state["regressors"].items()}
    packed = {}
    for key, est in _estimators(state):
        preds = est._predictors
        trees = [p for row in preds for p in row]
        if any(p.binned_left_cat_bitsets.size or p.raw_left_cat_bitsets.size for p in trees):
            continue  # categorical splits: kept as objects
        nodes = np.concatenate([p.nodes for p in trees])
        nodes["gain"] = 0.0
        nodes["count"] = 0
        packed[key] = {
            "nodes": np.frombuffer(nodes.tobytes(), np.uint8).copy(),
            "sizes": np.array([p.nodes.size for p in trees], np.int32),
            "shape": [len(preds), len(preds[0])],
            "bitset_dtype": str(trees[0].binned_left_cat_bitsets.dtype),
        }
        slim = copy.copy(est)
        slim._predictors = []
        # the bin edges serve the fit and the categorical features only (prediction compares
        # raw values with each node's threshold): 180 features x 255 edges a model, dropped
        # (None, not an empty array: each array is an entry of its own in the file)
        bm = copy.copy(est._bin_mapper)
        bm.bin_thresholds_ = [
            t if cat else None
            for t, cat in zip(bm.bin_thresholds_, bm.is_categorical_, strict=True)
        ]
        slim._bin_mapper = bm
        parts = key.split("/")
        if parts[0] == "classifiers":
            state["classifiers"][parts[1]] = slim
        else:
            state["regressors"][parts[1]][parts[2]] = slim
    state[PACKED] = packed
    return state


def _unpack(state: dict) -> dict:
    """Inverse of `_pack` (the trees rebuilt as scikit-learn's own predictor objects)."""
    from sklearn.ensemble._hist_gradient_boosting.common import PREDICTOR_RECORD_DTYPE
    from sklearn.ensemble._hist_gradient_boosting.predictor import TreePredictor

    packed = state.pop(PACKED, {})
    ests = dict(_estimators(state))
    for key, p in packed.items():
        nodes = np.asarray(p["nodes"], np.uint8).view(PREDICTOR_RECORD_DTYPE)
        bounds = np.concatenate([[0], np.cumsum(p["sizes"])])
        empty = np.zeros((0, 8), dtype=p["bitset_dtype"])
        trees = [
            TreePredictor(nodes[a:b].copy(), empty, empty)
            for a, b in zip(bounds[:-1], bounds[1:], strict=True)
        ]
        n, k = p["shape"]
        ests[key]._predictors = [trees[i * k : (i + 1) * k] for i in range(n)]
    return state


#: Key of the packed trees in a diagnoser file.
PACKED = "packed_trees"


def save(diag: Diagnoser, path: str | Path) -> Path:
    """Write ``diag`` to a skops file (written to a temporary file, then renamed), its trees
    packed (`_pack`)."""
    import zipfile

    import skops.io as sio

    from ..io import atomic_path

    path = Path(path)
    with atomic_path(path) as tmp:
        sio.dump(_pack(diag.state), tmp, compression=zipfile.ZIP_DEFLATED, compresslevel=9)
    return path


def load(path: str | Path, *, check_version: bool = True, any_format: bool = False) -> Diagnoser:
    """Read a diagnoser file; refuses one written by another recipdyn or scikit-learn version
    (its predictions would not be those evaluated) and one holding untrusted types.
    ``any_format``: read an older file format too (for `recalibrate`, which brings it to
    `FORMAT`; such a diagnoser cannot diagnose until calibrated)."""
    import skops.io as sio

    from .. import __version__

    path = Path(path)
    if not path.is_file():
        raise ParameterError(
            f"diagnoser {path}: file not found; build one with 'recipdyn train DATASET -o FILE'"
        )
    try:
        untrusted = sio.get_untrusted_types(file=path)
    except Exception as exc:  # noqa: BLE001
        raise ParameterError(f"diagnoser {path}: not a skops file ({type(exc).__name__})") from None
    bad = [t for t in untrusted if not t.startswith(TRUSTED_PREFIXES)]
    if bad:
        raise ParameterError(f"diagnoser {path}: holds untrusted types {bad}; refused")
    state = sio.load(path, trusted=untrusted)
    if not isinstance(state, dict) or not isinstance(state.get("format"), int):
        raise ParameterError(f"diagnoser {path}: not a recipdyn diagnoser")
    if state["format"] != FORMAT and not (any_format and state["format"] >= 3):
        raise ParameterError(
            f"diagnoser {path}: file format {state['format']}, this recipdyn reads format "
            f"{FORMAT} (its out-of-domain refusal and severity intervals are calibrated on "
            "held-out records; format 3 held a fixed distance threshold); recalibrate it with "
            "'recipdyn recalibrate FILE DATASET -o NEW' on a data set of other conditions, or "
            "rebuild it with 'recipdyn train DATASET -o FILE' ('make diagnoser' for the "
            "default one)"
        )
    state = _unpack(state)
    if check_version:
        for what, have, want in (
            ("recipdyn", state["recipdyn_version"], __version__),
            ("scikit-learn", state["sklearn_version"], _sk_version()),
        ):
            if have != want:
                raise ParameterError(
                    f"diagnoser {path}: trained with {what} {have}, this is {what} {want}; "
                    "retrain it ('recipdyn train DATASET -o FILE', or 'make diagnoser' for "
                    "the default one)"
                )
    return Diagnoser(state)
