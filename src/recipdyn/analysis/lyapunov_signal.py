r"""Largest Lyapunov exponent from a measured signal: Wolf, Rosenstein, Kantz.

All three embed the signal ([`delay_embed`][recipdyn.analysis.embedding.delay_embed]), search
neighbours with a KD-tree (memory linear in N), exclude temporal neighbours with a Theiler
window, and guard against zero distances (duplicate points never give ``-inf``).
Every tunable defaults to ``None`` = estimated from the data; the estimates and every
intermediate (divergence curve, fitted region, replacements) are returned in
[`SignalLyapunov`][recipdyn.analysis.lyapunov_signal.SignalLyapunov] so a user can see why the
estimate came out as it did, and `recipdyn.analysis.plots.plot_divergence` draws them.

* **Wolf et al. (1985)** -- the reference paper's method: follow one fiducial trajectory and
  one neighbour for ``evolve`` samples, accumulate ``log(d_end / d_start)``, then replace the
  neighbour by the point closest in angle to the old separation (within ``max_angle``) among
  those closer than ``scale_max``. Only positive exponents are meaningful (it cannot resolve
  negative ones); for a periodic signal it returns ~0.
* **Rosenstein et al. (1993)** -- mean log distance of every point's nearest neighbour pair
  after k steps; the slope of its initial linear rise is lambda_1.
* **Kantz (1994)** -- like Rosenstein but averaging the distances of all neighbours within
  ``eps`` before the logarithm (more robust to noise).

Linear-region detection (Rosenstein, Kantz): the divergence curve ``S(k)`` rises then
saturates at the attractor size. The fit uses ``k`` from where ``S`` first exceeds
``S(0) + 0.1 (S_max - S(0))`` to where it first exceeds ``S(0) + 0.7 (S_max - S(0))`` --
before saturation -- unless ``fit_range`` is given. A curve that never rises by more than
``flat_tol`` (log units) is declared flat: lambda_1 = 0 (no divergence, e.g. periodic). A
positive slope from a curve that rises by less than ``MIN_DIVERGENCE_RISE`` is refused: the
fit then has no exponential range to measure (noise, slowly rotating flows).

An estimator's own diagnostics say its fit is sound, not that the number is right: the
comparisons between estimators (`check_agreement`) and with the rest of the evidence
(`recipdyn.analysis.signal.assess_signal`) decide which numbers are reported; their
thresholds come from the calibration study ``benchmarks/bench_lyap_calibration.py``.

References
----------
Wolf, Swift, Swinney & Vastano (1985), Physica D 16, 285-317.
Rosenstein, Collins & De Luca (1993), Physica D 65, 117-134.
Kantz (1994), Phys. Lett. A 185, 77-87.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.spatial import cKDTree
from scipy.stats import linregress

from ..defaults import LYAP_TOL, MIN_SIGNAL_SAMPLES
from .checks import as_signal, check_rate
from .embedding import choose_embedding, delay_embed

__all__ = ["SignalLyapunov", "lyap_wolf", "lyap_rosenstein", "lyap_kantz", "ESTIMATE_ACCURACY",
           "AGREEMENT_RATIO", "MIN_DIVERGENCE_RISE", "withhold_disagreeing",
           "withhold_unconfirmed", "check_agreement"]  # fmt: skip

#: Fewest points of a divergence curve a slope is fitted to (else: refused, no scaling region).
MIN_FIT_POINTS = 5
#: Least R^2 of the straight-line fit over the automatic scaling region.
MIN_FIT_R2 = 0.95
#: Fewest reference points with neighbours that Kantz's average must have.
MIN_REFERENCES = 50
#: Fewest Wolf evolutions (replacement intervals) an estimate is averaged over.
MIN_EVOLUTIONS = 100
#: The thresholds below were chosen on the calibration set of the study
#: ``benchmarks/bench_lyap_calibration.py`` (245 signals: 25 flows, 4 delay equations, 6 maps
#: at several sampling steps, lengths and noise levels, 9 regular or stochastic signals;
#: docs/signal_analysis.md, "Calibration study") as the least strict that left no estimate
#: with status ``ok`` outside ``ESTIMATE_ACCURACY`` of the equations' exponent, and verified on
#: systems kept out of it.
#:
#: Stated accuracy of an estimate with status ``ok``: within 25 % of the largest exponent.
ESTIMATE_ACCURACY = 0.25
#: Two usable positive estimates agree when the larger is at most this many times the
#: smaller; otherwise all are withheld (`withhold_disagreeing`). Measured: at 1.3 two Kantz
#: estimates of the Ikeda map 25-26 % low stood beside Wolf and Rosenstein (1.29-1.30x
#: apart); at 1.25 none outside 25 % (at 1.67, the bound of two +-25 % intervals, 77 of
#: 380 ok estimates were wrong).
AGREEMENT_RATIO = 1.25
#: Rosenstein, Kantz: a positive slope needs a divergence curve that rises by at least this
#: much (natural log units: a factor e^3 = 20) from the neighbours' initial distance to its
#: largest value; less leaves no exponential range between the alignment transient and the
#: saturation, and the slope is biased (measured: observation noise of 10 % of the signal
#: gives rises of 1.9-2.7 and slopes 35-70 % low; slowly rotating flows -- Rossler, Ueda,
#: Thomas -- 1.2-1.8 and 20-60 % low; Mackey-Glass 1.4 and 40-85 % high). At 2.6 the
#: calibration kept two estimates 27 % high (Lorenz-84 oversampled, rise 2.76); from 2.8
#: none; 3.0 keeps a margin.
MIN_DIVERGENCE_RISE = 3.0


@dataclass
class SignalLyapunov:
    """Estimate of the largest Lyapunov exponent from a signal, with its evidence.

    ``exponent`` is per unit time when ``dt`` was given (else per sample). ``curve`` and
    ``steps`` are the divergence curve (Rosenstein/Kantz) or the running estimate (Wolf);
    ``fit`` the (start, stop) indices used; ``params`` every setting actually used.
    ``status``: ``ok``; ``flat`` (no divergence: the exponent is 0 to the estimator's
    resolution, a regular signal); ``refused`` (``exponent`` is NaN and ``reason`` says why:
    no embedding dimension found, no linear scaling region, too few neighbours...);
    ``inconsistent`` (the estimator's own fit was fine, but the number contradicts other
    evidence -- its slope changes with the embedding dimension, the other estimators
    disagree beyond their accuracy, or the once-per-revolution section is a periodic orbit;
    ``exponent`` keeps the number for the record, ``reason`` says what it contradicts, and
    it is never used as an exponent: `recipdyn.analysis.signal.assess_signal`);
    ``unconfirmed`` (a positive estimate that passed its own checks but that no second
    estimator confirms: the number is kept and not used, `withhold_unconfirmed`).
    """

    method: str
    exponent: float
    steps: np.ndarray
    curve: np.ndarray
    fit: tuple[int, int] | None
    params: dict = field(default_factory=dict)
    stderr: float = float("nan")
    status: str = "ok"
    reason: str = ""

    @property
    def ok(self) -> bool:
        """True when the estimate can be used (``status`` ``ok`` or ``flat``)."""
        return self.status in ("ok", "flat")

    def withheld(self, reason: str, status: str = "inconsistent") -> SignalLyapunov:
        """This estimate with ``status`` (``inconsistent`` or ``unconfirmed``) and ``reason``
        (the number is kept)."""
        return replace(self, status=status, reason=reason)

    def diagnostics(self) -> dict:
        """Everything a reader needs to judge the estimate (JSON-ready)."""
        out = {"method": self.method, "status": self.status, "reason": self.reason,
               "exponent": None if not np.isfinite(self.exponent) else self.exponent,
               "stderr": None if not np.isfinite(self.stderr) else self.stderr,
               "fit": list(self.fit) if self.fit else None}  # fmt: skip
        out.update({k: (v.item() if isinstance(v, np.generic) else v)
                    for k, v in self.params.items()})  # fmt: skip
        return out


def _items(estimates):
    return dict(estimates) if isinstance(estimates, dict) else dict(enumerate(estimates))


def _same_kind(estimates, items):
    return items if isinstance(estimates, dict) else list(items.values())


def withhold_disagreeing(estimates):
    """The estimates with every usable positive one withheld (status ``inconsistent``, the
    reason naming them all) when the largest is more than ``AGREEMENT_RATIO`` times the
    smallest. ``estimates``: a list or a dict of `SignalLyapunov`; the same kind is returned
    (unchanged when they agree; the given estimates are never modified)."""
    items = _items(estimates)
    pos = {k: r for k, r in items.items() if r.status == "ok" and r.exponent > 0}
    if len(pos) >= 2:
        vals = np.array([r.exponent for r in pos.values()])
        ratio = float(vals.max() / vals.min())
        if ratio > AGREEMENT_RATIO:
            listed = ", ".join(f"{r.method} {r.exponent:.3g}" for r in pos.values())
            why = (f"the estimators disagree ({listed}: {ratio:.2g}x apart, more than the "
                   f"{AGREEMENT_RATIO:g}x within which estimates were right to "
                   f"+-{ESTIMATE_ACCURACY:.0%} in the calibration study)")  # fmt: skip
            items = {k: (r.withheld(why) if k in pos else r) for k, r in items.items()}
    return _same_kind(estimates, items)


def withhold_unconfirmed(estimates):
    """The estimates with a lone usable positive one marked ``unconfirmed`` (the number kept,
    never used as an exponent): an estimator's own diagnostics do not see its bias (in the
    calibration study Wolf alone read 2x high on the Moore-Spiegel flow, 40 % low on
    Lorenz-96 with 10 sites; Rosenstein alone 25-35 % low on slowly rotating flows), so a
    number is reported only when a second estimator agrees with it. Same conventions as
    `withhold_disagreeing`."""
    items = _items(estimates)
    pos = {k: r for k, r in items.items() if r.status == "ok" and r.exponent > 0}
    if len(pos) == 1:
        others = [r.method for r in items.values() if r.status != "ok"]
        why = (
            "no second estimator confirms it ("
            + (", ".join(others) + " not usable" if others else "the only estimator")
            + "): one estimator's bias is invisible to its own diagnostics"
        )
        items = {k: (r.withheld(why, status="unconfirmed") if k in pos else r)
                 for k, r in items.items()}  # fmt: skip
    return _same_kind(estimates, items)


def check_agreement(estimates):
    """The estimates after the two rules that compare them with each other: disagreement
    (`withhold_disagreeing`), then confirmation (`withhold_unconfirmed`). The one
    implementation, applied by `recipdyn.analysis.signal.assess_signal` and by
    `recipdyn.analysis.classify.classify` to any list it is given (a second application
    changes nothing)."""
    return withhold_unconfirmed(withhold_disagreeing(estimates))


def _prepare(x, dim, delay, theiler, dt):
    x = as_signal(x, name="x", min_samples=MIN_SIGNAL_SAMPLES)
    if dt is not None:
        dt = check_rate(dt, "dt")
    emb = choose_embedding(x, delay=delay, dim=dim, theiler=theiler)
    dim = max(emb.dim, 2)
    X = delay_embed(x, dim, emb.delay)
    prm = dict(dim=dim, delay=emb.delay, theiler=emb.theiler, dt=dt if dt else 1.0,
               embedding=emb.status, embedding_reason=emb.reason)  # fmt: skip
    return X, prm


def _gate(method, prm):
    """The result when no embedding was found: flat for an exactly repeating record (it is
    periodic), refused otherwise."""
    if prm["embedding"] == "degenerate":
        return SignalLyapunov(method, 0.0, np.arange(0), np.arange(0.0), None, prm, 0.0,
                              status="flat", reason="the record repeats exactly")  # fmt: skip
    return _refused(method, "embedding: " + prm["embedding_reason"], prm)


def _refused(method, reason, prm, steps=None, curve=None):
    return SignalLyapunov(method, float("nan"), np.arange(0) if steps is None else steps,
                          np.arange(0.0) if curve is None else curve, None, prm,
                          status="refused", reason=reason)  # fmt: skip


def _nearest_valid(tree, X, theiler, limit, k0=8, d_min=0.0):
    """Nearest neighbour of each point among points with |i - j| > theiler, index < limit,
    and distance > d_min. Returns (j, d) with j = -1 where none was found."""
    n = X.shape[0]
    idx = np.arange(n)
    res_j = np.full(n, -1)
    res_d = np.full(n, np.inf)
    todo = idx[:limit]
    k = k0
    while todo.size and k <= n:
        d, j = tree.query(X[todo], k=min(k, n))
        ok = (np.abs(j - todo[:, None]) > theiler) & (d > d_min) & (j < limit)
        has = ok.any(axis=1)
        first = np.argmax(ok, axis=1)
        rows = np.nonzero(has)[0]
        res_j[todo[rows]] = j[rows, first[rows]]
        res_d[todo[rows]] = d[rows, first[rows]]
        todo = todo[~has]
        k *= 4
    return res_j, res_d


def _fit_linear(curve, fit_range, fractions):
    """The scaling region: from where the curve has risen by ``fractions[0]`` of its total rise
    to where it has risen by ``fractions[1]``; ``None`` with the reason if it is too short."""
    if fit_range is not None:
        lo, hi = fit_range
        return (int(lo), min(int(hi), len(curve) - 1)), ""
    s0, smax = curve[0], np.nanmax(curve)
    lo = int(np.argmax(curve >= s0 + fractions[0] * (smax - s0)))
    hi = int(np.argmax(curve >= s0 + fractions[1] * (smax - s0)))
    if hi - lo < MIN_FIT_POINTS - 1:
        return None, (
            f"no scaling region: the divergence curve rises from "
            f"{100 * fractions[0]:.0f} % to {100 * fractions[1]:.0f} % of its total "
            f"rise within {hi - lo} step(s) (at least {MIN_FIT_POINTS - 1} needed): "
            "no exponential divergence resolved (noise, or too coarse sampling)"
        )
    return (lo, hi), ""


def _divergence_result(method, steps, curve, fit_range, flat_tol, params, fractions=(0.1, 0.7)):
    dt = params["dt"]
    if params.get("embedding") not in ("ok", None):
        return _refused(method, "embedding: " + params["embedding_reason"], params, steps, curve)
    if not np.any(np.isfinite(curve)):  # no usable pairs: the record repeats exactly
        return SignalLyapunov(method, 0.0, steps, curve, None,
                              params | {"note": "no non-degenerate neighbours"}, 0.0,
                              status="flat", reason="the record repeats exactly")  # fmt: skip
    rise = np.nanmax(curve) - curve[0]
    if fit_range is None and rise < flat_tol:
        return SignalLyapunov(method, 0.0, steps, curve, None, params, 0.0, status="flat",
                              reason=f"divergence curve rises by {rise:.2f} < {flat_tol} "
                              "(log units): no divergence")  # fmt: skip
    fr, why = _fit_linear(curve, fit_range, fractions)
    if fr is None:
        return _refused(method, why, params, steps, curve)
    lo, hi = fr
    reg = linregress(steps[lo : hi + 1] * dt, curve[lo : hi + 1])
    r2 = float(reg.rvalue**2)
    params = params | {"fit_r2": r2, "fit_points": hi - lo + 1}
    if fit_range is None and r2 < MIN_FIT_R2:
        return _refused(method, f"no linear scaling region: R^2 = {r2:.3f} < {MIN_FIT_R2} over "
                        f"steps {lo}..{hi}", params, steps, curve)  # fmt: skip
    positive = LYAP_TOL / (params.get("delay", 1) * dt)  # the smallest slope counted positive
    if fit_range is None and reg.slope > positive and rise < MIN_DIVERGENCE_RISE:
        return _refused(method, f"the divergence curve rises by {rise:.2f} < "
                        f"{MIN_DIVERGENCE_RISE:g} (log units) from the neighbours' distance to "
                        "the attractor's size: no exponential range between alignment and "
                        "saturation (noise, or a slowly rotating flow); its slope "
                        f"{reg.slope:.3g} is not an exponent to trust (such slopes were 20-85 % "
                        "off in the calibration study)", params | {"slope": float(reg.slope)},
                        steps, curve)  # fmt: skip
    return SignalLyapunov(method, float(reg.slope), steps, curve, (lo, hi), params,
                          float(reg.stderr))  # fmt: skip


def lyap_rosenstein(x, dt: float | None = None, *, dim: int | None = None,
                    delay: int | None = None, theiler: int | None = None,
                    max_steps: int | None = None, fit_range=None, flat_tol: float = 0.5,
                    max_pairs: int = 10_000, seed: int = 0) -> SignalLyapunov:  # fmt: skip
    """Rosenstein et al. (1993). ``max_steps`` defaults to 4 mean periods (>= 20 samples).
    The curve averages at most ``max_pairs`` nearest-neighbour pairs (a seeded random choice:
    the mean of 10^4 log distances is fixed to ~1 % of its spread)."""
    X, prm = _prepare(x, dim, delay, theiler, dt)
    if prm["embedding"] != "ok":
        return _gate("rosenstein", prm)
    n = X.shape[0]
    K = max_steps or int(max(20, 4 * prm["theiler"]))
    K = min(K, n // 4)
    limit = n - K
    tree = cKDTree(X)
    # repeats of an exactly periodic record (distance ~ rounding) carry no information
    d_min = 1e-8 * np.linalg.norm(np.ptp(X, axis=0))
    j, d = _nearest_valid(tree, X, prm["theiler"], limit, d_min=d_min)
    i = np.nonzero(j >= 0)[0]
    i = i[i < limit]
    if i.size > max_pairs:
        i = np.sort(np.random.default_rng(seed).choice(i, max_pairs, replace=False))
    j = j[i]
    curve = np.empty(K + 1)
    for k in range(K + 1):
        dist = np.linalg.norm(X[i + k] - X[j + k], axis=1)
        good = dist > 0
        curve[k] = np.mean(np.log(dist[good])) if good.any() else np.nan
    prm.update(max_steps=K, pairs=int(i.size))
    return _divergence_result("rosenstein", np.arange(K + 1), curve, fit_range, flat_tol, prm)


def lyap_kantz(x, dt: float | None = None, *, dim: int | None = None, delay: int | None = None,
               theiler: int | None = None, eps: float | None = None,
               max_steps: int | None = None, max_points: int = 2000, fit_range=None,
               flat_tol: float = 0.5, seed: int = 0,
               max_neighbours: int = 32) -> SignalLyapunov:  # fmt: skip
    """Kantz (1994). At most ``max_points`` reference points (seeded random choice) are
    averaged. ``eps`` defaults to the smallest of 0.1, 0.2, 0.5, 1, 2, 4, 8 % of the attractor's
    diameter at which half the references have at least 3 neighbours (outside the Theiler
    window); if even 8 % does not, or fewer than ``MIN_REFERENCES`` references have any
    neighbour, the estimate is refused (too few samples for the embedding dimension). The
    automatic fit skips the initial fast rise (neighbours not yet aligned with the unstable
    direction): it uses the part of the curve between 35 % and 80 % of its total rise."""
    X, prm = _prepare(x, dim, delay, theiler, dt)
    if prm["embedding"] != "ok":
        return _gate("kantz", prm)
    n = X.shape[0]
    K = max_steps or int(max(20, 4 * prm["theiler"]))
    K = min(K, n // 4)
    limit = n - K
    diam = np.linalg.norm(np.ptp(X, axis=0))
    d_min = 1e-8 * diam  # exact repeats carry no information (and would give log 0)
    tree = cKDTree(X[:limit])
    rng = np.random.default_rng(seed)
    refs = rng.choice(limit, size=min(max_points, limit), replace=False)

    def neighbours(i, r):
        nb = np.array(tree.query_ball_point(X[i], r), dtype=int)
        nb = nb[np.abs(nb - i) > prm["theiler"]]
        nb = nb[np.linalg.norm(X[nb] - X[i], axis=1) > d_min]
        if nb.size > max_neighbours:  # a periodic record has thousands: 32 fix the mean
            nb = rng.choice(nb, max_neighbours, replace=False)
        return nb

    if eps is None:
        probe = refs[:200]
        for frac in (0.001, 0.002, 0.005, 0.01, 0.02, 0.04, 0.08):
            counts = np.array([neighbours(i, frac * diam).size for i in probe])
            if np.median(counts) >= 3:
                break
        eps = frac * diam
        prm["eps_fraction_of_diameter"] = frac
    eps = float(eps)
    sums = np.zeros(K + 1)
    count = 0
    n_neighbours = []
    ks = np.arange(K + 1)
    for i in refs:
        nb_idx = neighbours(i, eps)
        if nb_idx.size == 0:
            continue
        diff = X[i + ks][None, :, :] - X[nb_idx[:, None] + ks[None, :]]
        m = np.sqrt(np.einsum("abk,abk->ab", diff, diff)).mean(axis=0)
        if np.any(m <= 0):
            continue
        sums += np.log(m)
        count += 1
        n_neighbours.append(nb_idx.size)
    prm.update(
        eps=eps,
        max_steps=K,
        references=count,
        references_tried=int(refs.size),
        median_neighbours=float(np.median(n_neighbours)) if n_neighbours else 0.0,
    )
    curve = sums / count if count else np.full(K + 1, np.nan)
    if count < MIN_REFERENCES:
        return _refused("kantz", f"only {count} of {refs.size} reference points have a neighbour "
                        f"within eps = {eps:.3g} ({count} < {MIN_REFERENCES}): too few samples "
                        f"for dimension {prm['dim']}", prm, ks, curve)  # fmt: skip
    if prm.get("median_neighbours", 0) < 3 and "eps_fraction_of_diameter" in prm:
        return _refused("kantz", f"median {prm['median_neighbours']:.0f} neighbour(s) within "
                        f"8 % of the attractor's diameter: too few samples for dimension "
                        f"{prm['dim']}", prm, ks, curve)  # fmt: skip
    return _divergence_result("kantz", ks, curve, fit_range, flat_tol, prm,
                              fractions=(0.35, 0.8))  # fmt: skip


def lyap_wolf(x, dt: float | None = None, *, dim: int | None = None, delay: int | None = None,
              theiler: int | None = None, evolve: int | None = None,
              scale_max: float | None = None, scale_min: float | None = None,
              max_angle: float = 0.3) -> SignalLyapunov:  # fmt: skip
    """Wolf et al. (1985), fixed evolution time.

    Parameters (defaults)
    ---------------------
    evolve : samples between replacements (``delay``, at least 1).
    scale_max : replace the neighbour when it is farther than this (5 % of the attractor's
        diameter); replacement candidates must also be closer than this.
    scale_min : ignore neighbours closer than this (1e-4 of the diameter: the noise floor).
    max_angle : largest accepted angle between the old and new separation (rad); if no
        candidate qualifies the closest one in angle is taken anyway and counted.
    """
    X, prm = _prepare(x, dim, delay, theiler, dt)
    if prm["embedding"] != "ok":
        return _gate("wolf", prm)
    n = X.shape[0]
    evolve = max(1, prm["delay"] if evolve is None else int(evolve))
    diam = np.linalg.norm(np.ptp(X, axis=0))
    scale_max = 0.05 * diam if scale_max is None else float(scale_max)
    scale_min = 1e-4 * diam if scale_min is None else float(scale_min)
    th = prm["theiler"]
    tree = cKDTree(X[: n - evolve])

    def candidates(i, k=32):
        while True:
            d, j = tree.query(X[i], k=min(k, n - evolve))
            ok = (np.abs(j - i) > th) & (d > scale_min) & np.isfinite(d)
            if ok.any() or k >= n - evolve:
                return j[ok], d[ok]
            k *= 8

    i = 0
    js, ds = candidates(i)
    if js.size == 0:
        return _refused("wolf", "no neighbour of the first point outside the Theiler window and "
                        "above scale_min", prm)  # fmt: skip
    j = int(js[0])
    total = 0.0
    steps_done = 0
    replacements = 0
    bad_angles = 0
    running = []
    while i + evolve < n and j + evolve < n:
        d0 = np.linalg.norm(X[i] - X[j])
        i1, j1 = i + evolve, j + evolve
        sep = X[j1] - X[i1]
        d1 = np.linalg.norm(sep)
        if d0 > 0 and d1 > 0:
            total += np.log(d1 / d0)
        steps_done += 1
        running.append(total / (steps_done * evolve * prm["dt"]))
        i = i1
        if i + evolve >= n:
            break
        if scale_min < d1 < scale_max and j1 + evolve < n:
            j = j1  # keep following the same neighbour
            continue
        js, ds = candidates(i)
        keep = (ds < scale_max) & (js + evolve < n)
        js, ds = js[keep], ds[keep]
        if js.size == 0:
            js, ds = candidates(i, k=256)
            keep = js + evolve < n
            js, ds = js[keep], ds[keep]
            if js.size == 0:
                break
        vec = X[js] - X[i]
        cos = (vec @ sep) / (np.linalg.norm(vec, axis=1) * max(d1, 1e-300))
        ang = np.arccos(np.clip(cos, -1.0, 1.0))
        best = int(np.argmin(ang + 1e-12 * ds))
        if ang[best] > max_angle:
            bad_angles += 1
        j = int(js[best])
        replacements += 1
    lam = total / (steps_done * evolve * prm["dt"]) if steps_done else float("nan")
    prm.update(evolve=evolve, scale_max=scale_max, scale_min=scale_min, max_angle=max_angle,
               replacements=replacements, replacements_over_max_angle=bad_angles,
               evolutions=steps_done)  # fmt: skip
    steps = (np.arange(len(running)) + 1) * evolve
    running = np.array(running)
    if steps_done < MIN_EVOLUTIONS or not np.isfinite(lam):
        return _refused("wolf", f"{steps_done} evolution(s) before the neighbours ran out "
                        f"(at least {MIN_EVOLUTIONS} needed)", prm, steps, running)  # fmt: skip
    if replacements and bad_angles > 0.5 * replacements:
        return _refused("wolf", f"{bad_angles} of {replacements} replacements exceed the angle "
                        f"limit {max_angle} rad: the separation's direction is not kept (too few "
                        "samples for the embedding)", prm, steps, running)  # fmt: skip
    return SignalLyapunov("wolf", float(lam), steps, running, None, prm)
