r"""Lyapunov spectra from the equations: Benettin's method with QR re-orthonormalisation.

For an ODE ``y' = f(t, y)`` the tangent vectors obey the variational equation
``W' = J(t, y) W`` with the exact Jacobian ``J = df/dy``. Integrating the state and ``k``
tangent vectors together and re-orthonormalising them (QR) every ``dt`` gives
``lambda_i = (1 / T) sum log |R_ii|`` (Benettin et al. 1980; Shimada & Nagashima 1979). For a
map ``x_{n+1} = g(x_n)`` the tangent vectors are multiplied by ``Dg`` each iteration.

Notes
-----
* The last interval always ends with a QR step, so a short run never "collapses to 0": every
  stretch of integration contributes its growth.
* The re-orthonormalisation interval is adapted: while the mean growth spread per interval,
  ``(lambda_1 - lambda_k) dt`` from the running sums, exceeds ``max_log_spread`` (default 5:
  the tangent vectors would become indistinguishable in floating point), ``dt`` is halved,
  down to 1/16 of its initial value. One interval's spread ``log(R_11 / R_kk)`` is not the
  criterion (only beyond 25, where ``R_kk`` keeps ~5 digits, or where a diagonal of ``R`` is 0:
  that interval is then done again with half the length): it also contains the ratio of the
  state components' units (rad vs rad/s at the compressor's kHz clearance frequency gives ~18),
  which no interval removes. Re-orthonormalising more often than needed costs a truncated step
  and a QR per interval; once per forcing period is the default.
* Periodically forced systems (``system.period``) also report exponents per forcing period.
* Exponents of a conservative (Hamiltonian) system sum to zero; for a dissipative system the
  sum is the mean divergence of the flow (e.g. ``-(sigma + 1 + beta)`` for Lorenz).

References
----------
Benettin, Galgani, Giorgilli, Strelcyn (1980), Meccanica 15, 9-30.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numba as nb
import numpy as np

from ..defaults import ATOL, RTOL
from ..integrate import IntegrationError, propagate
from ..integrate import kernels as _ik
from ..integrate.tableaus import dop853
from ..model.base import (
    EVENT_TYPE,
    JAC_TYPE,
    RHS_SIGNATURE,
    RHS_TYPE,
    DiscreteMap,
    ODESystem,
    typed,
)

__all__ = ["LyapunovResult", "lyapunov_spectrum", "lyapunov_spectrum_map", "tangent_system"]


_BENETTIN_SIG = nb.int64(
    RHS_TYPE, nb.float64[::1], nb.float64[::1], nb.int64, nb.int64, nb.float64, nb.float64,
    nb.float64, nb.float64, nb.float64, nb.float64, nb.float64[:, ::1], nb.float64[::1],
    nb.float64[::1], EVENT_TYPE, nb.boolean, nb.int64, RHS_TYPE, nb.float64[:, ::1],
    nb.float64[::1], nb.float64[::1], nb.float64[::1], nb.float64[::1], nb.float64[:, ::1],
    nb.int64[::1],
)  # fmt: skip

#: One interval's growth spread ``log(R_11 / R_kk)`` beyond which the interval is done again
#: with half the length whatever the mean rate: the relative rounding error of ``R_kk`` is then
#: ~eps e^25 ~ 2e-5.
_HARD_SPREAD = 25.0

#: Events located per kernel call in the Benettin loop (the call is repeated when full).
_EVENT_BATCH = 256


@nb.njit(cache=True)  # compiled for _BENETTIN_SIG on first use (base.typed)
def _benettin_dop853(trhs, z, p, n, k, t0, t_total, dt, rtol, atol, max_spread, hist, times,
                     info, event, use_event, event_dir, treset, A, B, C, E3, E5, D,
                     rows):  # fmt: skip
    """Benettin loop, compiled: DOP853 over each interval, then QR; records running means.

    With ``use_event``, crossings of ``event`` reset the augmented state through ``treset``
    (the state's reset and the tangent vectors' saltation matrix); ``info[3]`` counts them.
    The vectors are measured and orthonormalised on the degree-of-freedom ``rows`` only
    (``W_dof = Q R``, then ``W <- W R^-1``): auxiliary components (an impact's recorded
    approach velocity) follow linearly without entering the norms. Measured with them, a
    vector could turn into an auxiliary direction that the next impact's reset wipes out,
    and the exponents lost their meaning (a -inf seen at 150 rad/s with a worn crank pin).
    Returns -5 if the rows' parts become dependent.
    """
    t = t0
    t_end = t0 + t_total
    sums = np.zeros(k)
    n_hist = hist.shape[0]
    every = t_total / n_hist
    next_rec = t0 + every
    filled = 0
    h_abs = 0.0
    empty1 = np.empty(0)
    Yd = np.empty((0, z.shape[0]))
    cap = _EVENT_BATCH if use_event else 0
    et = np.empty(cap)
    ey = np.empty((cap, z.shape[0]))
    ey2 = np.empty((cap, z.shape[0]))
    n_events = 0
    stats = np.zeros(5, dtype=np.int64)
    fstate = np.zeros(2)
    nr = rows.shape[0]
    is_row = np.zeros(n, dtype=np.bool_)
    for a in range(nr):
        is_row[rows[a]] = True
    W = np.empty((nr, k))
    x = np.empty(k)
    sgn = np.empty(k)
    z_start = z.copy()
    dt_min = dt / 16.0
    dt_floor = dt / 2.0**20
    t_settle = min(8.0 * dt, 0.1 * t_total)  # averaging before the mean rate is trusted
    while t < t_end - 1e-12 * max(1.0, abs(t_end)):
        t1 = min(t + dt, t_end)
        ts = t
        z_start[:] = z
        h_start, ev_start = h_abs, n_events
        while True:  # one call, repeated only when the event buffer fills up
            status = _ik.dop853_kernel(
                trhs, event, ts, z, t1, t1, p, rtol, atol, h_abs, np.inf, empty1, 1 << 40,
                A, B, C, E3, E5, D, use_event, event_dir, 2, treset, Yd, et, ey, ey2, stats,
                fstate,
            )  # fmt: skip
            n_events += stats[4]
            h_abs = fstate[1]
            ts = fstate[0]
            if status != 1 or ts >= t1:
                break
        if status < 0:
            info[0] = t
            return status
        for a in range(nr):
            for j in range(k):
                W[a, j] = z[n + rows[a] * k + j]
        Q, R = np.linalg.qr(W)
        singular = False
        for j in range(k):
            if not (R[j, j] != 0.0 and math.isfinite(R[j, j])):
                singular = True
        l0 = 0.0 if singular else math.log(abs(R[0, 0]))
        lk = 0.0 if singular else math.log(abs(R[k - 1, k - 1]))
        # An interval so long that the smallest vector lost its significance (R_kk ~ eps
        # exp(spread)) or fell into the others' span (R_kk = 0: a strongly contracting mode,
        # such as a stiff contact's, over the first interval of one period) is done again
        # with half the interval, instead of adding a meaningless log R_kk to the sums.
        if singular or (k > 1 and dt > dt_min and l0 - lk > _HARD_SPREAD):
            if dt <= dt_floor:
                info[0] = t
                return -5
            z[:] = z_start
            h_abs, n_events = h_start, ev_start
            dt *= 0.5
            continue
        t = t1
        for j in range(k):
            sums[j] += math.log(abs(R[j, j]))
            sgn[j] = 1.0 if R[j, j] >= 0 else -1.0  # makes R's diagonal positive
        # the rows measured become Q; the others (auxiliary values carried along) W R^-1:
        # x R = w_i, R upper triangular
        for i in range(n):
            if is_row[i]:
                continue
            for j in range(k):
                acc = z[n + i * k + j]
                for m in range(j):
                    acc -= x[m] * R[m, j]
                x[j] = acc / R[j, j]
            for j in range(k):
                z[n + i * k + j] = x[j] * sgn[j]
        for a in range(nr):
            for j in range(k):
                z[n + rows[a] * k + j] = Q[a, j] * sgn[j]
        if k > 1 and dt > dt_min:
            # halve dt when the mean growth spread over one interval is too large (a rate, so
            # only after a period of averaging). The spread within one interval also
            # contains the ratio of the state components' units, which no interval removes,
            # so the mean rate, not the single interval, is the criterion (the single
            # interval's spread only until dt_min, above).
            elapsed = t - t0
            rate = (sums[0] - sums[k - 1]) / elapsed
            if elapsed >= t_settle and rate * dt > max_spread:
                dt *= 0.5
        if (t >= next_rec or t >= t_end - 1e-12 * max(1.0, abs(t_end))) and filled < n_hist:
            hist[filled] = sums / (t - t0)
            times[filled] = t - t0
            filled += 1
            next_rec += every
    if filled == 0 or times[filled - 1] < t - t0:  # make sure the final estimate is recorded
        idx = min(filled, n_hist - 1)
        hist[idx] = sums / (t - t0)
        times[idx] = t - t0
        filled = idx + 1
    info[0] = t
    info[1] = dt
    info[2] = filled
    info[3] = n_events
    return 0


@dataclass
class LyapunovResult:
    """Lyapunov exponents and their convergence.

    Attributes
    ----------
    exponents : ndarray, shape (k,)
        Largest first, in 1/(time unit of the system) (1/iteration for maps).
    times : ndarray
        Times (or iteration counts) at which the running estimates were recorded.
    history : ndarray, shape (len(times), k)
        Running estimates (for convergence plots).
    per_period : ndarray or None
        ``exponents * period`` for periodically forced systems.
    settings : dict
    t_start, y_start, t_final, y_final : float, ndarray
        Where the averaging began (after the transient) and where it ended, so that invariants
        along the computed trajectory can be checked (e.g. the exponent sum of a Lagrangian
        system, ``-ln(M(t_final, y_final) / M(t_start, y_start)) / t_total``).
    """

    exponents: np.ndarray
    times: np.ndarray
    history: np.ndarray
    per_period: np.ndarray | None = None
    settings: dict = field(default_factory=dict)
    t_start: float = float("nan")
    y_start: np.ndarray | None = None
    t_final: float = float("nan")
    y_final: np.ndarray | None = None

    @property
    def sum(self) -> float:
        return float(np.sum(self.exponents))

    @property
    def largest(self) -> float:
        return float(self.exponents[0])

    def largest_limit(self) -> tuple[float, float]:
        """``(lambda_inf, error)``: the largest exponent extrapolated to infinite averaging.

        On a regular orbit the finite-time estimate is ``ln(growth) / T`` of a bounded growth
        factor, so it decays like ``b / T`` and is positive at every finite T (0.20 1/s after
        100 revolutions of the compressor's quasi-periodic base case, 0.060 after 400, 0.015
        after 1600); on a chaotic one it levels off. A least-squares fit ``lambda(T) = a +
        b / T`` over the second half of the running estimate separates the two: ``a`` is the
        limit, the error its standard error (at least the spread of the residuals).

        The error is at least half the slope that growth without exponential divergence can
        fake over the run (`regular_growth_slope`), so that ``limit > 2 error`` -- the
        verdict's test -- holds only for a growth a regular orbit cannot give in that time."""
        h, T = self.history[:, 0], np.asarray(self.times, dtype=float)
        half = len(T) // 2
        h, T = h[half:], T[half:]
        ok = T > 0
        h, T = h[ok], T[ok]
        if h.size < 8:
            tail = self.history[len(self.history) // 2 :, 0]
            return self.largest, float(np.std(tail)) if tail.size > 1 else 0.0
        A = np.c_[np.ones_like(T), 1.0 / T]
        coef, *_ = np.linalg.lstsq(A, h, rcond=None)
        resid = h - A @ coef
        dof = max(h.size - 2, 1)
        cov = np.linalg.pinv(A.T @ A) * (resid @ resid) / dof
        err = float(max(np.sqrt(max(cov[0, 0], 0.0)), np.std(resid)))
        return float(coef[0]), max(err, 0.5 * self.regular_growth_slope())

    def regular_growth_slope(self) -> float:
        """The largest exponent a regular orbit can show over the second half of this run.

        On a regular orbit the tangent vector grows at most like a polynomial of degree p
        (p = 1 along a torus or a non-isochronous periodic orbit: the shear; p = 2 is the
        largest generic case) times a bounded oscillation. Its log grows over ``[T/2, T]`` by
        at most ``p ln 2 + R``, ``R`` the range of ln|v| about its trend there: a slope of
        ``(2 ln 2 + R) / (T/2)``. The finite-time exponent of the compressor's
        quasi-periodic base case falls like 1/T (0.20 1/s after 100 revolutions, 0.015
        after 1600); the chaotic case's stays at 3.4 1/s, far above this bound."""
        T = np.asarray(self.times, dtype=float)
        lng = self.history[:, 0] * T  # log growth of the first vector since the start
        half = len(T) // 2
        t2, g2 = T[half:], lng[half:]
        if t2.size < 3 or not t2[-1] > t2[0]:
            return 0.0
        trend = np.polyval(np.polyfit(t2, g2, 1), t2)
        spread = float(np.ptp(g2 - trend))
        return (2.0 * np.log(2.0) + spread) / float(T[-1] - T[-1] / 2)


def _initial_basis(n: int, k: int) -> np.ndarray:
    """A fixed (seeded) random orthonormal n x k basis: generic, so the first vector is not
    confined to an invariant subspace (the identity fails for triangular Jacobians)."""
    q, _ = np.linalg.qr(np.random.default_rng(20250101).standard_normal((n, k)))
    return np.ascontiguousarray(q)


#: Cached by (rhs, jac, rhs_jac, n, k, passive): numba compiles a closure on
#: its first call (~0.5 s), so a sweep that asks for exponents at every point compiles once per
#: worker process instead of once per point.
def _active_rows(n: int, passive: tuple[int, ...]) -> np.ndarray:
    """Rows of the tangent vectors that evolve: the ``passive`` ones are held at 0."""
    active = np.ones(n, dtype=np.bool_)
    active[list(passive)] = False
    return active


@functools.cache
def _tangent_rhs(rhs, jac, both, n: int, k: int, passive: tuple[int, ...] = ()):
    active = _active_rows(n, passive)
    # f_and_j is inlined into trhs: a call between numba functions passing arrays costs
    # ~30 ns, a sixth of a tangent evaluation of the 2-state compressor (Benettin, 100
    # revolutions: 0.64 -> 0.54 s, against 0.46 s for benchmarks/reference_port.py; the same
    # exponents to the bit). Since the DOP853 loop and the model kernels run without reference
    # counting (model/base.compiled), 0.44 s: 0.96x the port. This function still counts and
    # allocates J (~17 ns a call): its signature has no room for scratch space.
    if both is not None:  # right-hand side and Jacobian share work: one call

        @nb.njit(inline="always")
        def f_and_j(t, y, p, f, J):
            both(t, y, p, f, J)

    else:

        @nb.njit(inline="always")
        def f_and_j(t, y, p, f, J):
            rhs(t, y, p, f)
            jac(t, y, p, J)

    @nb.njit(RHS_SIGNATURE)
    def trhs(t, z, p, out):
        y = z[:n]
        J = np.empty((n, n))
        f_and_j(t, y, p, out[:n], J)
        for i in range(n):
            for j in range(k):
                s = 0.0
                if active[i]:
                    for m in range(n):
                        s += J[i, m] * z[n + m * k + j]
                out[n + i * k + j] = s

    return trhs


@functools.cache  # compiled once per process, like _tangent_rhs
def _tangent_reset(rhs, event, reset, n: int, k: int, passive: tuple[int, ...] = ()):
    r"""The reset of the augmented state ``[y, W]`` at an event: ``y+ = R(t, y)`` and
    ``W+ = S W`` with the saltation matrix (Müller 1995; Leine & Nijmeijer 2004)

    .. math:: S = R_y + \frac{(f^+ - R_y f^- - R_t)\,g_y^\top}{g_y f^- + g_t},

    ``f-``/``f+`` the vector field before/after the reset. ``g_y``, ``g_t``, ``R_y`` and
    ``R_t`` are central differences with steps ``1e-9 max(1, |y_i|)``: states far below 1 in
    SI units (a clearance joint's eccentricity, ~1e-4 m) need a step far below their size,
    and an event function that is a minimum of factors (two joints) must not switch factor
    inside the step. (A step of 1e-6 spanned a thousandth of a 1 mm clearance, and the tangent
    flow of two worn pins lost all agreement with differences of the flow after four events;
    measured: tests/test_contact.py.) Rounding is then ~1e-7 of the gradient for an event
    function of size 1, truncation negligible.
    The ``passive`` rows stay 0, as in `_tangent_rhs`.
    """
    active = _active_rows(n, passive)

    @nb.njit(RHS_SIGNATURE)
    def treset(t, z, p, out):
        y = z[:n].copy()
        yp = np.empty(n)
        reset(t, y, p, yp)
        fm = np.empty(n)
        fp = np.empty(n)
        rhs(t, y, p, fm)
        rhs(t, yp, p, fp)
        grad = np.empty(n)
        Ry = np.empty((n, n))
        r1 = np.empty(n)
        r2 = np.empty(n)
        yh = y.copy()
        for i in range(n):
            hi = 1e-9 * max(1.0, abs(y[i]))
            yh[i] = y[i] + hi
            g1 = event(t, yh, p)
            reset(t, yh, p, r1)
            yh[i] = y[i] - hi
            g2 = event(t, yh, p)
            reset(t, yh, p, r2)
            yh[i] = y[i]
            grad[i] = (g1 - g2) / (2.0 * hi)
            for j in range(n):
                Ry[j, i] = (r1[j] - r2[j]) / (2.0 * hi)
        ht = 1e-9 * max(1.0, abs(t))
        gt = (event(t + ht, y, p) - event(t - ht, y, p)) / (2.0 * ht)
        reset(t + ht, y, p, r1)
        reset(t - ht, y, p, r2)
        denom = gt
        for i in range(n):
            denom += grad[i] * fm[i]
        v = np.empty(n)
        for j in range(n):
            s = fp[j] - (r1[j] - r2[j]) / (2.0 * ht)
            for i in range(n):
                s -= Ry[j, i] * fm[i]
            v[j] = s / denom if denom != 0.0 else 0.0
        for j in range(n):
            out[j] = yp[j]
        for i in range(n):
            for c in range(k):
                acc = 0.0
                if active[i]:
                    for m in range(n):
                        acc += (Ry[i, m] + v[i] * grad[m]) * z[n + m * k + c]
                out[n + i * k + c] = acc

    return treset


def tangent_system(system: ODESystem, k: int | None = None) -> ODESystem:
    """The system augmented with ``k`` tangent vectors (state ``[y, W.ravel()]``, W n x k)."""
    if system.jac is None:
        raise ValueError(f"system {system.name!r} has no Jacobian; Benettin's method needs one")
    n = system.dim
    k = n if k is None else int(k)
    trhs = _tangent_rhs(system.rhs, system.jac, system.rhs_jac, n, k, tuple(system.passive))
    names = system.state_names + tuple(f"w{i}{j}" for i in range(n) for j in range(k))
    return ODESystem(rhs=trhs, params=system.params, state_names=names, period=system.period,
                     name=f"{system.name}-tangent")  # fmt: skip


def lyapunov_spectrum(
    system: ODESystem,
    y0,
    t_total: float,
    *,
    k: int | None = None,
    dt: float | None = None,
    t_transient: float = 0.0,
    t0: float = 0.0,
    rtol: float = RTOL,
    atol: float = ATOL,
    method: str = "dop853",
    h: float | None = None,
    max_log_spread: float = 5.0,
    n_history: int = 200,
    event=None,
) -> LyapunovResult:
    """The ``k`` largest Lyapunov exponents of an ODE by Benettin's method.

    Parameters
    ----------
    system : ODESystem
        With an exact Jacobian ``jac``.
    y0 : array_like
        Initial state at ``t0``.
    t_total : float
        Averaging time (after ``t_transient``).
    k : int, optional
        Number of exponents (default: all, one per degree-of-freedom component,
        ``system.dof``: not the ``system.aux_states`` last ones nor ``system.aux``, not the
        ``system.passive`` ones). The tangent vectors
        start without components along auxiliary and passive states; values an event records
        (an impact's approach velocity) then follow the state through the saltation matrix,
        and passive components (a rigid joint's eccentricity, constant 0; work integrals that
        nothing depends on) get none: they would add to the vectors' norms without acting
        on the motion (a work integral's perturbation tends to a constant while the motion's
        decays, which reads as a zero exponent).
    dt : float, optional
        Re-orthonormalisation interval; default one forcing period for forced systems, else
        0.1 time units; halved automatically while ``(lambda_1 - lambda_k) dt`` exceeds
        ``max_log_spread`` (see module notes).
    rtol, atol : float
        Tolerances of the (adaptive) integration of the augmented system.
    event : [`Event`][recipdyn.model.base.Event], optional
        Default: the system's own acting event. A state-resetting event (an impact law): the
        state is reset at each crossing and the tangent vectors are mapped by the event's
        saltation matrix (`_tangent_reset`), so the exponents include the growth or
        contraction of each impact; the count is in ``settings["events"]``. Events that only
        record do not change the flow: pass none.
    """
    y = np.asarray(y0, dtype=float).copy()
    n = system.dim
    # not auxiliary (recorded values, work integrals), not passive (fixed ones)
    dof = list(system.dof)
    n_dof = len(dof)
    k = n_dof if k is None else int(k)
    if not (1 <= k <= n_dof):
        raise ValueError(f"k = {k}; allowed: 1..{n_dof}")
    if not (t_total > 0 and math.isfinite(t_total)):
        raise ValueError(f"t_total = {t_total}; allowed: > 0")
    if dt is None:
        dt = system.period if system.period else 0.1
    solver = dict(rtol=rtol, atol=atol, method=method, h=h)
    t = t0
    if event is None:
        event = system.acting_event
    if event is not None and event.action == "terminal":
        raise ValueError(f"system {system.name!r} stops at its event {event.name!r}: "
                         "Lyapunov exponents need an unbounded run")  # fmt: skip
    use_event = event is not None and event.action == "reset"
    if use_event and method != "dop853":
        raise ValueError("events need method 'dop853' (located on its dense output)")
    if t_transient > 0:
        ev_kw = {}
        if use_event:
            ev_kw = dict(event=event.function, event_direction=int(event.direction),
                         event_action="reset", reset=event.reset)  # fmt: skip
        y = propagate(system, y, t, t + t_transient, **solver, **ev_kw)
        t += t_transient
    tsys = tangent_system(system, k)
    t_start, y_start = t, y.copy()
    basis = np.zeros((n, k))
    basis[dof] = _initial_basis(n_dof, k)  # no components along auxiliary or passive states
    z = np.concatenate([y, basis.ravel()])
    n_hist = max(1, int(n_history))
    hist = np.zeros((n_hist, k))
    times = np.zeros(n_hist)
    info = np.zeros(4)  # [t_reached, dt_final, n_hist_filled, n_events]
    if method == "dop853":
        _DOP = dop853()
        ev, ev_dir, treset = _ik.no_event, 0, tsys.rhs
        if use_event:
            ev, ev_dir = event.function, int(event.direction)
            treset = _tangent_reset(system.rhs, event.function, event.reset, n, k,
                                    tuple(system.passive))  # fmt: skip
        status = typed(_benettin_dop853, _BENETTIN_SIG)(
            tsys.rhs, z, system.params, n, k, t, t_total, dt, rtol, atol, max_log_spread,
            hist, times, info, ev, use_event, ev_dir, treset, _DOP.A, _DOP.B, _DOP.C, _DOP.E3,
            _DOP.E5, _DOP.D, np.asarray(dof, dtype=np.int64),
        )  # fmt: skip
        if status == -5:
            raise IntegrationError(f"Benettin's tangent vectors became dependent at t = "
                                   f"{info[0]:.6g} (a singular saltation matrix?): no "
                                   f"exponents")  # fmt: skip
        if status < 0:
            raise IntegrationError(f"Benettin integration failed (status {status}) at "
                                   f"t = {info[0]:.6g}")  # fmt: skip
        sums_over_t = hist[int(info[2]) - 1]
        dt = info[1]
        filled = int(info[2])
        ex = sums_over_t
        per = ex * system.period if system.period else None
        return LyapunovResult(ex.copy(), times[:filled].copy(), hist[:filled].copy(), per,
                              dict(method="benettin", dt_final=dt, t_total=t_total,
                                   t_transient=t_transient, rtol=rtol, atol=atol, k=k,
                                   events=int(info[3])),
                              t_start, y_start, float(info[0]), z[:n].copy())  # fmt: skip
    # fixed-step RK4 path (the paper's integrator): plain Python loop over intervals
    t_start, t_end = t, t + t_total
    sums = np.zeros(k)
    times_l, hist_l = [], []
    while t < t_end - 1e-12 * max(1.0, abs(t_end)):
        step = min(dt, t_end - t)
        z = propagate(tsys, z, t, t + step, **solver)
        t += step
        Q, R = np.linalg.qr(z[n:].reshape(n, k))
        d = np.abs(np.diag(R))
        sums += np.log(d)
        z[n:] = (Q * np.sign(np.diag(R))).ravel()
        times_l.append(t - t_start)
        hist_l.append(sums / (t - t_start))
    times, hist = np.array(times_l), np.array(hist_l)
    ex = sums / (t - t_start)
    per = ex * system.period if system.period else None
    return LyapunovResult(ex, np.array(times), np.array(hist), per,
                          dict(method="benettin", dt_final=dt, t_total=t_total,
                               t_transient=t_transient, rtol=rtol, atol=atol, k=k),
                          t_start, y_start, float(t), z[:n].copy())  # fmt: skip


def _map_kernel(step, jac, x0, p, n_iter, n_transient, k, n_hist, q0):
    n = x0.shape[0]
    x = x0.copy()
    xn = np.empty(n)
    for i in range(n_transient):
        step(float(i), x, p, xn)
        x[:] = xn
    Q = q0.copy()
    J = np.empty((n, n))
    sums = np.zeros(k)
    hist = np.empty((n_hist, k))
    every = max(1, n_iter // n_hist)
    h = 0
    for it in range(n_iter):
        jac(float(n_transient + it), x, p, J)
        step(float(n_transient + it), x, p, xn)
        x[:] = xn
        W = J @ Q
        Qn, R = np.linalg.qr(W)
        for j in range(k):
            r = R[j, j]
            sums[j] += math.log(abs(r))
            if r < 0:
                Qn[:, j] = -Qn[:, j]
        Q = np.ascontiguousarray(Qn[:, :k])
        if (it + 1) % every == 0 and h < n_hist:
            hist[h] = sums / (it + 1)
            h += 1
    return sums / n_iter, hist[:h]


_MAP_KERNEL_SIG = nb.types.Tuple((nb.float64[::1], nb.float64[:, :]))(
    RHS_TYPE, JAC_TYPE, nb.float64[::1], nb.float64[::1], nb.int64, nb.int64, nb.int64, nb.int64,
    nb.float64[:, ::1],
)  # fmt: skip
#: Compiled for _MAP_KERNEL_SIG on first use (base.typed).
_map_kernel_jit = nb.njit(cache=True)(_map_kernel)


def lyapunov_spectrum_map(
    dmap: DiscreteMap, x0, n_iter: int, *, n_transient: int = 1000, k: int | None = None,
    n_history: int = 200,
) -> LyapunovResult:  # fmt: skip
    """Lyapunov exponents (per iteration) of a map by QR of the Jacobian products."""
    if dmap.jac is None:
        raise ValueError(f"map {dmap.name!r} has no Jacobian")
    n = dmap.dim
    k = n if k is None else int(k)
    ex, hist = typed(_map_kernel_jit, _MAP_KERNEL_SIG)(
        dmap.step, dmap.jac, np.ascontiguousarray(x0, dtype=float), dmap.params, int(n_iter),
        int(n_transient), k, int(n_history), _initial_basis(n, k),
    )  # fmt: skip
    every = max(1, n_iter // n_history)
    times = every * (np.arange(hist.shape[0]) + 1.0)
    return LyapunovResult(np.asarray(ex), times, np.asarray(hist), None,
                          dict(method="benettin-map", n_iter=n_iter,
                               n_transient=n_transient))  # fmt: skip
