"""Out-of-domain detection calibrated on held-out records (issue 42, item 4a).

A diagnoser answers only records that look like the records it was trained on. This module
scores how unlike them a record is and turns the score into a **conformal novelty p-value**:
the share of held-out in-domain records (records the detector was not fitted on: other
operating conditions, their drawn measurement chains, each channel set a record may have)
that score at least as high. A record whose p-value is below `ALPHA` is refused, so the rate
at which in-domain records are refused is at most `ALPHA` (exchangeability; Vovk, Gammerman &
Shafer 2005, ch. 4; Laxhammar & Falkman 2015, conformal anomaly detection), whatever the
score. The score decides only how many records *outside* the domain are caught.

Scores (`DETECTORS`), each fitted per channel set (`recipdyn.diagnosis.train.AVAILABILITY`) on
that set's columns of the training records, after a rank-based (quantile) transform of each
feature to a standard normal fitted on the same records (`TRANSFORM`; a few heavy-tailed
features, such as a knocking pin's peak, would otherwise dominate every distance):

* ``knn``: the distance to the `K_NEIGHBOURS`-th nearest training record (scikit-learn
  ``NearestNeighbors``), RMS per feature;
* ``lof``: the local outlier factor (``LocalOutlierFactor(novelty=True)``): the kNN distance
  relative to the neighbours' own density;
* ``iforest``: the isolation forest's anomaly score (``IsolationForest``);
* ``class``: the kNN distance to the training records **of the class the diagnoser names**:
  a record may lie among the training records as a whole and still far from every record of
  the class it is given (a healthy machine whose pressure offset makes the classifier name
  a worn pin shows none of the pin's knocks).

The p-values come from crepes' ``ConformalClassifier`` (Mondrian by channel set: each channel
set's scores are compared with the same channel set's held-out scores only). Why scikit-learn
and crepes rather than code of our own: the neighbour searches, the density ratio and the
isolation trees are the libraries' tested implementations (kd-trees, exact tie handling), and
the conformal p-value with its Mondrian categories is one call of a maintained library
written for exactly that; what is ours is the choice of score, of the calibration records and
of `ALPHA` (docs/diagnosis.md, "Out of domain", measured on the blind set).

The detectors are not stored: they are refitted when a diagnoser is loaded, from the training
records' scaled features the diagnoser file holds already (``Z_train``, float16), the very
rows they were fitted on when it was trained; each fit is deterministic (the isolation
forest's seed is stored), so the scores read back are those calibrated.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = [
    "ALPHA",
    "DETECTORS",
    "METHOD",
    "K_NEIGHBOURS",
    "fit_domain",
    "Domain",
    "refusal",
]

#: Refuse a record whose novelty p-value is below this: the stated rate at which records of
#: the training domain (held-out conditions, drawn chains) are refused as out of the domain.
ALPHA = 0.02
#: The score used (see the module docstring and docs/diagnosis.md for the comparison).
METHOD = "class"
DETECTORS = ("knn", "lof", "iforest", "class")
#: Neighbours of the kNN distances; of the local outlier factor.
K_NEIGHBOURS = 3
LOF_NEIGHBOURS = 20
#: Trees of the isolation forest.
FOREST_TREES = 300
#: Quantiles of the rank-based transform (at most the training records).
QUANTILES = 200
#: How the scaled features are transformed before a score: ``quantile`` (each to a standard
#: normal by its rank among the training records) or ``robust`` (the median/IQR scaling
#: alone, clipped at +-`CLIP`).
TRANSFORM = "quantile"
TRANSFORMS = ("quantile", "robust")
CLIP = 50.0


def _prep(Z: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """The columns ``cols`` of scaled rows ``Z``, a missing value at the training median (0)."""
    return np.nan_to_num(np.asarray(Z, float)[:, cols], nan=0.0, posinf=1e3, neginf=-1e3)


class _Scorer:
    """One channel set's detector, fitted on the training rows ``Zfit`` (columns ``cols``)."""

    def __init__(self, method: str, Zfit: np.ndarray, labels: np.ndarray, cols, seed: int,
                 transform: str = TRANSFORM):  # fmt: skip
        from sklearn.preprocessing import QuantileTransformer

        self.method, self.cols = method, np.asarray(cols, int)
        A = _prep(Zfit, self.cols)
        if transform == "quantile":
            self.qt = QuantileTransformer(
                n_quantiles=min(QUANTILES, A.shape[0]), output_distribution="normal"
            ).fit(A)
        elif transform == "robust":
            self.qt = None
        else:
            raise ValueError(f"transform {transform!r}; allowed: {', '.join(TRANSFORMS)}")
        T = self._transform(A)
        self.labels = np.asarray(labels)
        if method in ("knn", "class"):
            from sklearn.neighbors import NearestNeighbors

            if method == "knn":
                self.nn = {None: NearestNeighbors(n_neighbors=K_NEIGHBOURS).fit(T)}
            else:
                self.nn = {}
                for c in np.unique(self.labels):
                    m = self.labels == c
                    k = min(K_NEIGHBOURS, int(m.sum()))
                    self.nn[c] = NearestNeighbors(n_neighbors=k).fit(T[m])
        elif method == "lof":
            from sklearn.neighbors import LocalOutlierFactor

            self.det = LocalOutlierFactor(n_neighbors=LOF_NEIGHBOURS, novelty=True).fit(T)
        elif method == "iforest":
            from sklearn.ensemble import IsolationForest

            self.det = IsolationForest(n_estimators=FOREST_TREES, random_state=seed).fit(T)
        else:
            raise ValueError(f"method {method!r}; allowed: {', '.join(DETECTORS)}")

    def _transform(self, A: np.ndarray) -> np.ndarray:
        return np.clip(A, -CLIP, CLIP) if self.qt is None else self.qt.transform(A)

    def score(self, Z: np.ndarray, labels=None) -> np.ndarray:
        """Scores of the scaled rows ``Z`` (larger: less like the training records);
        ``labels``: the class each is given (the ``class`` score)."""
        T = self._transform(_prep(np.atleast_2d(Z), self.cols))
        d = np.sqrt(T.shape[1])
        if self.method == "knn":
            return self.nn[None].kneighbors(T)[0][:, -1] / d
        if self.method == "class":
            out = np.empty(T.shape[0])
            for c in np.unique(labels):
                m = np.asarray(labels) == c
                out[m] = self.nn[c].kneighbors(T[m])[0][:, -1] / d
            return out
        return -self.det.score_samples(T)


def fit_domain(
    Z_fit: np.ndarray,
    labels_fit,
    subsets: dict[str, np.ndarray],
    calibration: list[tuple[np.ndarray, Any, str]],
    *,
    fit_rows: np.ndarray,
    method: str = METHOD,
    transform: str = TRANSFORM,
    alpha: float = ALPHA,
    seed: int = 0,
    source: str = "",
) -> dict[str, Any]:
    """The out-of-domain state of a diagnoser (plain arrays: a diagnoser file holds it).

    Parameters
    ----------
    Z_fit : array (n, features)
        Scaled training rows (exactly as stored in the diagnoser, float16 values).
    labels_fit : array of str (n,)
        Their classes.
    subsets : dict
        Channel set -> the columns it has.
    calibration : list of (Z, labels, subset)
        Held-out in-domain rows (scaled), their classes, and the channel set each was cut
        to: rows the detector is not fitted on.
    fit_rows : bool array (n,)
        Which rows of ``Z_fit`` the detector is fitted on (the others are not used).
    """
    dom = {
        "method": method,
        "transform": transform,
        "alpha": float(alpha),
        "seed": int(seed),
        "fit_rows": np.asarray(fit_rows, bool),
        "subsets": {k: np.asarray(v, int) for k, v in subsets.items()},
        "source": source,
    }
    d = Domain(dom, Z_fit, labels_fit)
    scores, bins = [], []
    for Z, lab, subset in calibration:
        if len(Z):
            scores.append(d.score(Z, subset, lab))
            bins += [subset] * len(Z)
    dom["cal_scores"] = np.concatenate(scores) if scores else np.zeros(0)
    dom["cal_bins"] = np.array(bins, dtype=str)
    return dom


class Domain:
    """The out-of-domain detector of a diagnoser, rebuilt from its state (`fit_domain`) and
    the training rows it was fitted on."""

    def __init__(self, state: dict[str, Any], Z_fit: np.ndarray, labels_fit):
        self.state = state
        rows = np.asarray(state["fit_rows"], bool)
        Z = np.asarray(Z_fit, float)[rows]
        lab = np.asarray(labels_fit)[rows]
        self._scorers = {
            k: _Scorer(
                state["method"], Z, lab, cols, state["seed"], state.get("transform", TRANSFORM)
            )  # fmt: skip
            for k, cols in state["subsets"].items()
        }
        self._cc = None

    @property
    def alpha(self) -> float:
        return float(self.state["alpha"])

    def score(self, Z: np.ndarray, subset: str, labels=None) -> np.ndarray:
        Z = np.atleast_2d(Z)
        if self.state["method"] == "class" and labels is None:
            raise ValueError("the class score needs the class each record is given (labels)")
        if labels is None or np.ndim(labels) == 0:
            labels = np.full(Z.shape[0], labels, dtype=object)
        return self._scorers[subset].score(Z, np.asarray(labels))

    def n_calibration(self, subset: str) -> int:
        return int((np.asarray(self.state["cal_bins"]) == subset).sum())

    def p_value(self, Z: np.ndarray, subset: str, labels=None) -> np.ndarray:
        """Conformal novelty p-values of the rows ``Z`` of channel set ``subset``: (1 + the
        held-out rows of that set scoring at least as high) / (their number + 1)."""
        from crepes import ConformalClassifier

        s = self.score(Z, subset, labels)
        if self.n_calibration(subset) == 0:
            return np.zeros_like(s)  # nothing to compare with: never in the domain
        if self._cc is None:
            self._cc = ConformalClassifier().fit(
                np.asarray(self.state["cal_scores"], float),
                bins=np.asarray(self.state["cal_bins"]),
            )
        p = self._cc.predict_p(s[:, None], bins=np.full(s.size, subset), smoothing=False)
        return np.asarray(p, float)[:, 0]

    def resolution(self, subset: str) -> float:
        """The smallest p-value channel set ``subset`` can give: 1/(held-out rows + 1)."""
        return 1.0 / (self.n_calibration(subset) + 1)


def refusal(diag, row: np.ndarray, label: str) -> tuple[dict[str, Any], str]:
    """``(verdict, reason)`` of one feature row of ``diag`` (`recipdyn.diagnosis.train.
    Diagnoser.ood`, the class named ``label``); the reason is empty for a record in the
    domain."""
    o = diag.ood(row, label)
    if o["p_value"] >= o["alpha"]:
        return o, ""
    n = o["n_calibration"]
    k = round(o["p_value"] * (n + 1)) - 1  # held-out records scoring at least as high
    share = f"any of the {n}" if k == 0 else f"all but {k} of the {n}"
    what = f"the {label} training records" if o["method"] == "class" else "the training records"
    return o, (
        f"the record lies outside the training domain: its features (channels: "
        f"{o['features']}) are less like {what} than {share} held-out in-domain records "
        f"are (novelty p-value {o['p_value']:.3f} < "
        f"{o['alpha']:g}, score {o['score']:.2f}, {o['method']}): another measurement chain, "
        "another machine or a fault outside the data set; train or calibrate a diagnoser on "
        "records like it"
    )
