r"""Largest Lyapunov exponent from a measured signal: Wolf, Rosenstein, Kantz.

All three embed the signal (:func:`~recipdyn.analysis.embedding.delay_embed`), search
neighbours with a KD-tree (memory linear in N), exclude temporal neighbours with a Theiler
window, and guard against zero distances (duplicate points never give ``-inf``).
Every tunable defaults to ``None`` = estimated from the data; the estimates and every
intermediate (divergence curve, fitted region, replacements) are returned in
:class:`SignalLyapunov` so a user can see why the estimate came out as it did, and
:func:`recipdyn.analysis.plots.plot_divergence` draws them.

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
``flat_tol`` (log units) is declared flat: lambda_1 = 0 (no divergence, e.g. periodic).

References
----------
Wolf, Swift, Swinney & Vastano (1985), Physica D 16, 285-317.
Rosenstein, Collins & De Luca (1993), Physica D 65, 117-134.
Kantz (1994), Phys. Lett. A 185, 77-87.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree
from scipy.stats import linregress

from .embedding import delay_embed, estimate_delay, estimate_dimension, mean_period

__all__ = ["SignalLyapunov", "lyap_wolf", "lyap_rosenstein", "lyap_kantz"]


@dataclass
class SignalLyapunov:
    """Estimate of the largest Lyapunov exponent from a signal, with its evidence.

    ``exponent`` is per unit time when ``dt`` was given (else per sample). ``curve`` and
    ``steps`` are the divergence curve (Rosenstein/Kantz) or the running estimate (Wolf);
    ``fit`` the (start, stop) indices used; ``params`` every setting actually used.
    """

    method: str
    exponent: float
    steps: np.ndarray
    curve: np.ndarray
    fit: tuple[int, int] | None
    params: dict = field(default_factory=dict)
    stderr: float = float("nan")


def _prepare(x, dim, delay, theiler, dt):
    x = np.asarray(x, dtype=float)
    if x.ndim != 1 or x.size < 50:
        raise ValueError("need a 1-D signal of at least 50 samples")
    if not np.all(np.isfinite(x)):
        raise ValueError("signal contains NaN or inf")
    if np.ptp(x) == 0:
        raise ValueError("signal is constant")
    delay = estimate_delay(x) if delay is None else int(delay)
    theiler = int(round(mean_period(x))) if theiler is None else int(theiler)
    theiler = min(theiler, x.size // 10)
    dim = estimate_dimension(x, delay, max_dim=8, theiler=0) if dim is None else int(dim)
    dim = max(dim, 2)
    X = delay_embed(x, dim, delay)
    return X, dict(dim=dim, delay=delay, theiler=theiler, dt=dt if dt else 1.0)


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


def _fit_linear(steps, curve, fit_range, flat_tol, fractions=(0.1, 0.7)):
    s0 = curve[0]
    smax = np.nanmax(curve)
    if fit_range is None:
        if smax - s0 < flat_tol:
            return None
        lo = int(np.argmax(curve >= s0 + fractions[0] * (smax - s0)))
        hi = int(np.argmax(curve >= s0 + fractions[1] * (smax - s0)))
        if hi - lo < 3:
            lo, hi = 0, max(hi, 3)
        fit_range = (lo, hi)
    lo, hi = fit_range
    return lo, min(hi, len(curve) - 1)


def _divergence_result(method, steps, curve, fit_range, flat_tol, params, fractions=(0.1, 0.7)):
    dt = params["dt"]
    if not np.any(np.isfinite(curve)):  # no usable pairs: the record repeats exactly
        return SignalLyapunov(method, 0.0, steps, curve, None,
                              params | {"flat": True, "note": "no non-degenerate neighbours"},
                              0.0)  # fmt: skip
    fr = _fit_linear(steps, curve, fit_range, flat_tol, fractions)
    if fr is None:
        return SignalLyapunov(method, 0.0, steps, curve, None, params | {"flat": True}, 0.0)
    lo, hi = fr
    reg = linregress(steps[lo : hi + 1] * dt, curve[lo : hi + 1])
    return SignalLyapunov(method, float(reg.slope), steps, curve, (lo, hi), params,
                          float(reg.stderr))  # fmt: skip


def lyap_rosenstein(x, dt: float | None = None, *, dim: int | None = None,
                    delay: int | None = None, theiler: int | None = None,
                    max_steps: int | None = None, fit_range=None,
                    flat_tol: float = 0.5) -> SignalLyapunov:  # fmt: skip
    """Rosenstein et al. (1993). ``max_steps`` defaults to 4 mean periods (>= 20 samples)."""
    X, prm = _prepare(x, dim, delay, theiler, dt)
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
               flat_tol: float = 0.5, seed: int = 0) -> SignalLyapunov:  # fmt: skip
    """Kantz (1994). ``eps`` defaults to 0.5 % of the attractor's diameter; at most
    ``max_points`` reference points (seeded random choice) are averaged. The automatic fit
    skips the initial fast rise (neighbours not yet aligned with the unstable direction): it
    uses the part of the curve between 35 % and 80 % of its total rise."""
    X, prm = _prepare(x, dim, delay, theiler, dt)
    n = X.shape[0]
    K = max_steps or int(max(20, 4 * prm["theiler"]))
    K = min(K, n // 4)
    limit = n - K
    diam = np.linalg.norm(np.ptp(X, axis=0))
    eps = 0.005 * diam if eps is None else float(eps)
    tree = cKDTree(X[:limit])
    rng = np.random.default_rng(seed)
    refs = rng.choice(limit, size=min(max_points, limit), replace=False)
    sums = np.zeros(K + 1)
    count = 0
    found_any = False
    d_min = 1e-8 * diam  # exact repeats carry no information (and would give log 0)
    for i in refs:
        nb_idx = np.array(tree.query_ball_point(X[i], eps), dtype=int)
        nb_idx = nb_idx[np.abs(nb_idx - i) > prm["theiler"]]
        found_any |= nb_idx.size > 0
        nb_idx = nb_idx[np.linalg.norm(X[nb_idx] - X[i], axis=1) > d_min]
        if nb_idx.size == 0:
            continue
        ks = np.arange(K + 1)
        dist = np.linalg.norm(X[i + ks][None, :, :] - X[nb_idx[:, None] + ks[None, :]], axis=2)
        m = dist.mean(axis=0)
        if np.any(m <= 0):
            continue
        sums += np.log(m)
        count += 1
    if count == 0 and not found_any:
        raise ValueError(f"no neighbours within eps = {eps:g}; increase eps")
    if count == 0:
        sums[:] = np.nan
        count = 1
    prm.update(eps=eps, max_steps=K, references=count)
    return _divergence_result("kantz", np.arange(K + 1), sums / count, fit_range, flat_tol, prm,
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
        raise ValueError("no valid neighbour for the first point; adjust theiler/scale_min")
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
    return SignalLyapunov("wolf", float(lam), steps, np.array(running), None, prm)
