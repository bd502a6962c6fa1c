"""Compiled integrator loops (numba): the public compiled API of the integrator.

The Python front end is [`recipdyn.integrate.integrate`][recipdyn.integrate.solve.integrate];
compiled callers (the Benettin loop of [`recipdyn.analysis.lyapunov`][recipdyn.analysis.lyapunov])
call [`dop853_kernel`][recipdyn.integrate.kernels.dop853_kernel] directly.

Both loops call the model's compiled ``rhs(t, y, p, out)`` directly. The DOP853 loop follows
SciPy's ``solve_ivp(method="DOP853")`` step for step (initial step selection, error norm, step
control, dense output), so given the same inputs it takes the same steps; it adds optional
event detection (root-finding on the 7th-order dense output).

Status codes: 0 reached ``t1``; 1 stopped at max events; -1 step size underflow;
-2 ``max_steps`` exceeded; -3 non-finite state.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from numba import types as T

from ..model.base import EVENT_SIGNATURE, EVENT_TYPE, RHS_SIGNATURE, RHS_TYPE, compiled

F8, I8 = T.float64, T.int64
V1, V2 = T.float64[::1], T.float64[:, ::1]

SAFETY = 0.9
#: Events are looked for at this many equally spaced points inside each step (on the dense
#: output), so two crossings within one step are both seen unless they are closer than h/4.
EVENT_SUBSTEPS = 4
#: Before that, a step is screened at this many points on the cubic Hermite interpolant
#: (free: no right-hand side calls); see ``_may_cross``.
SCREEN_POINTS = 8
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0


@compiled(EVENT_SIGNATURE)
def no_event(t, y, p):  # pragma: no cover - trivial
    return 1.0


@nb.njit(cache=True, inline="always")
def _copy(src, dst):
    """``dst[:] = src`` as a loop (a slice assignment may copy its source first, which
    allocates: not allowed without reference counting)."""
    for j in range(src.shape[0]):
        dst[j] = src[j]


@nb.njit(cache=True)
def _rms_scaled(x, scale):
    """The root mean square of ``x / scale`` (no temporaries)."""
    s = 0.0
    for j in range(x.shape[0]):
        v = x[j] / scale[j]
        s += v * v
    return math.sqrt(s / x.shape[0])


@nb.njit(cache=True)
def _dense_eval(x, y_old, F, out):
    """SciPy's Dop853DenseOutput: nested Horner-like evaluation in x and (1 - x)."""
    n = y_old.shape[0]
    for j in range(n):
        out[j] = 0.0
    npow = F.shape[0]
    for i in range(npow):
        f = F[npow - 1 - i]
        for j in range(n):
            out[j] += f[j]
            if i % 2 == 0:
                out[j] *= x
            else:
                out[j] *= 1.0 - x
    for j in range(n):
        out[j] += y_old[j]


@nb.njit(cache=True, inline="always")
def _crosses(ga, gb, event_dir):
    """Whether ``g`` crosses zero from ``ga`` to ``gb`` in direction ``event_dir`` (+1 rising,
    -1 falling, 0 both)."""
    return (ga < 0.0 <= gb and event_dir >= 0) or (ga > 0.0 >= gb and event_dir <= 0)


@nb.njit(cache=True)
def _hermite_eval(x, y_old, f_old, y_new, f_new, h, out):
    """The cubic Hermite interpolant of one step at ``x`` in [0, 1] (no right-hand side calls:
    it uses the values and slopes at both ends)."""
    x2 = x * x
    x3 = x2 * x
    h00 = 2.0 * x3 - 3.0 * x2 + 1.0
    h10 = (x3 - 2.0 * x2 + x) * h
    h01 = 3.0 * x2 - 2.0 * x3
    h11 = (x3 - x2) * h
    for j in range(y_old.shape[0]):
        out[j] = h00 * y_old[j] + h10 * f_old[j] + h01 * y_new[j] + h11 * f_new[j]


@nb.njit(cache=True)
def _may_cross(event, t, y, f, y_new, f_new, h, g_old, g_new, event_dir, p, ybuf):
    """Whether the event function may cross zero in direction ``event_dir`` inside the step.

    ``g`` is sampled at the two ends (exact) and at ``SCREEN_POINTS - 1`` inner points of the
    cubic Hermite interpolant (free: no right-hand side calls). The step may cross if the
    samples change sign, or if ``|g|`` has an inner local minimum: ``g`` turns back toward
    zero, and a touch-and-return that the cubic (accurate to O(h^4) only) does not show may
    lie there. Only such steps pay for the 7th-order dense output (3 right-hand side calls),
    on which the crossings are then looked for and located."""
    ga = g_old
    prev = abs(g_old)  # |g| at the sample before ga
    for q in range(1, SCREEN_POINTS + 1):
        if q == SCREEN_POINTS:
            gb = g_new
        else:
            x = q / SCREEN_POINTS
            _hermite_eval(x, y, f, y_new, f_new, h, ybuf)
            gb = event(t + x * h, ybuf, p)
        if _crosses(ga, gb, event_dir):
            return True
        if q > 1 and abs(ga) < prev and abs(ga) < abs(gb):
            return True
        prev = abs(ga)
        ga = gb
    return False


#: From this many states on, the stage sums run stage by stage over contiguous rows of ``K``
#: (they vectorise: 12 states of the contact model, 263 -> 225 ns per evaluation); below, state
#: by state (2 states of the paper's model: 100 ns per evaluation, 120 the other way). Both
#: sum in the order of the stages: the same results to the bit.
ROW_SUMS_FROM = 8


@nb.njit(cache=True)
def _rk_stages(rhs, t, y, f, h, A, C, n_stages, K, p, ytmp, acc):
    """The stages ``K[1:n_stages]`` (``K[0] = f``; ``acc`` is scratch; zero coefficients are
    skipped in the row sums)."""
    n = y.shape[0]
    for j in range(n):
        K[0, j] = f[j]
    for s in range(1, n_stages):
        if n >= ROW_SUMS_FROM:
            for j in range(n):
                acc[j] = 0.0
            for k in range(s):
                a = A[s, k]
                if a != 0.0:
                    for j in range(n):
                        acc[j] += a * K[k, j]
            for j in range(n):
                ytmp[j] = y[j] + h * acc[j]
        else:
            for j in range(n):
                sj = 0.0
                for k in range(s):
                    sj += A[s, k] * K[k, j]
                ytmp[j] = y[j] + h * sj
        rhs(t + C[s] * h, ytmp, p, K[s])


@nb.njit(cache=True)
def _dense_coefficients(rhs, t, y, f, y_new, f_new, h, A, C, D, n_stages, K, p, ytmp, Fd):
    """The three extra stages and the 7th-order dense-output coefficients of one step."""
    n = y.shape[0]
    for s in range(3):
        st = n_stages + 1 + s
        for j in range(n):
            acc = 0.0
            for k in range(st):
                acc += A[st, k] * K[k, j]
            ytmp[j] = y[j] + h * acc
        rhs(t + C[st] * h, ytmp, p, K[st])
    for j in range(n):
        dy = y_new[j] - y[j]
        Fd[0, j] = dy
        Fd[1, j] = h * f[j] - dy
        Fd[2, j] = 2.0 * dy - h * (f_new[j] + f[j])
        for r in range(4):
            acc = 0.0
            for k in range(16):
                acc += D[r, k] * K[k, j]
            Fd[3 + r, j] = h * acc


@nb.njit(cache=True)
def _error_norm(K, y, y_new, h, rtol, atol, E3, E5, n_stages):
    """SciPy's DOP853 error norm: the 5th-order estimate, corrected by the 3rd-order one."""
    n = y.shape[0]
    e5n = 0.0
    e3n = 0.0
    for j in range(n):
        sc = atol + max(abs(y[j]), abs(y_new[j])) * rtol
        a5 = 0.0
        a3 = 0.0
        for k in range(n_stages + 1):
            a5 += K[k, j] * E5[k]
            a3 += K[k, j] * E3[k]
        e5n += (a5 / sc) ** 2
        e3n += (a3 / sc) ** 2
    if e5n == 0.0 and e3n == 0.0:
        return 0.0
    return abs(h) * e5n / math.sqrt((e5n + 0.01 * e3n) * n)


@nb.njit(cache=True)
def _locate_event(event, t, y, h, xa, xb, ga, gb, Fd, p, ydense):
    """Illinois (modified regula falsi) on the dense output between ``x = xa`` and ``xb``
    (``x = (t - t_step) / h``, a sign change of ``g`` between them); returns the root's x."""
    side = 0
    xm = xb
    for _ in range(100):
        xm = xb - gb * (xb - xa) / (gb - ga) if gb != ga else 0.5 * (xa + xb)
        _dense_eval(xm, y, Fd, ydense)
        gm = event(t + xm * h, ydense, p)
        if gm == 0.0 or abs(xb - xa) * abs(h) < 4e-16 * max(1.0, abs(t)):
            break
        if (gm > 0.0) == (gb > 0.0):
            xb, gb = xm, gm
            if side == -1:
                ga *= 0.5
            side = -1
        else:
            xa, ga = xm, gm
            if side == 1:
                gb *= 0.5
            side = 1
    return xm


@compiled(RHS_SIGNATURE)
def no_reset(t, y, p, out):  # pragma: no cover - trivial
    for j in range(y.shape[0]):
        out[j] = y[j]


DOP853_SIG = I8(
    RHS_TYPE, EVENT_TYPE, F8, V1, F8, F8, V1, F8, F8, F8, F8, V1, I8,
    V2, V1, V1, V1, V1, V2, T.boolean, I8, I8, RHS_TYPE, V2, V1, V2, V2, T.int64[::1], V1,
)  # fmt: skip


@nb.njit(cache=True)  # compiled for DOP853_SIG on first use: see typed()
def dop853_kernel(
    rhs, event, t0, y0, t1, t_stop, p, rtol, atol, h_abs0, max_step, t_eval, max_steps,
    A, B, C, E3, E5, D, use_event, event_dir, event_action, reset, Y, ev_t, ev_y, ev_y2, stats,
    fstate,
):  # fmt: skip
    """Integrate from ``(t0, y0)`` toward ``t1``; ``y0`` is updated in place to the final state.

    Steps are clipped at ``t1`` only. ``t_stop <= t1`` ends the call after the first step that
    reaches it (without clipping that step), so a run split into several calls with
    ``t_stop`` at the split points (for a progress bar) takes exactly the steps of one call:
    the results are bit-identical (given ``h_abs0`` = the previous call's ``fstate[1]``).

    Events (``use_event``): crossings of ``event(t, y, p) = 0`` in direction ``event_dir``
    (+1 rising, -1 falling, 0 both) are located on the dense output and recorded in ``ev_t``,
    ``ev_y`` (state at the event) and ``ev_y2`` (state after the event's action; capacity =
    their length). ``event_action``: 0 record only; 1 terminal (stop at the event, status 1);
    2 reset (``reset(t, y_event, p, y_after)`` sets the state, the integration continues from
    the event). Outputs after an acting event within its step are never taken from the
    pre-event trajectory.

    Outputs: ``Y[i]`` at ``t_eval[i]``;
    ``stats = [nfev, nsteps, nreject, n_out, n_events]``; ``fstate = [t_final, h_abs_next]``.
    Returns the status code.
    """
    n = y0.shape[0]
    K = np.empty((17, n))  # 12 stages + f_new + 3 extra dense stages (+1 spare)
    W = np.empty((6, n))  # ytmp, y_new, f_new, ydense, sacc, scratch of the first step
    Fd = np.empty((7, n))
    y = y0.copy()
    f = np.empty(n)
    return _dop853_run(
        rhs, event, t0, y0, t1, t_stop, p, rtol, atol, h_abs0, max_step, t_eval, max_steps,
        A, B, C, E3, E5, D, use_event, event_dir, event_action, reset, Y, ev_t, ev_y, ev_y2,
        stats, fstate, K, W, Fd, y, f,
    )  # fmt: skip


@nb.njit(cache=True, _nrt=False)
def _dop853_run(
    rhs, event, t0, y0, t1, t_stop, p, rtol, atol, h_abs0, max_step, t_eval, max_steps,
    A, B, C, E3, E5, D, use_event, event_dir, event_action, reset, Y, ev_t, ev_y, ev_y2, stats,
    fstate, K, W, Fd, y, f,
):  # fmt: skip
    """[`dop853_kernel`][recipdyn.integrate.kernels.dop853_kernel]'s loop, given its work arrays,
    compiled without reference counting (with it, the atomic counts of the array arguments at every
    call and view cost ~0.1 us a step: the contact model's revolution at rtol 1e-10, 8.0 -> 7.5 ms
    for 5 536 steps)."""
    n = y0.shape[0]
    max_events = ev_t.shape[0]
    n_stages = 12
    ytmp, y_new, f_new, ydense, sacc, scale = W[0], W[1], W[2], W[3], W[4], W[5]
    rhs(t0, y, p, f)
    nfev = 1
    n_eval = t_eval.shape[0]
    ie = 0
    while ie < n_eval and t_eval[ie] <= t0:
        _copy(y, Y[ie])
        ie += 1
    n_ev = 0
    g_old = event(t0, y, p) if use_event else 0.0
    direction = 1.0
    interval = abs(t1 - t0)

    # initial step (SciPy's select_initial_step with order 7)
    if h_abs0 > 0.0:
        h_abs = h_abs0
    elif interval == 0.0:
        h_abs = 0.0
    else:
        for j in range(n):
            scale[j] = atol + abs(y[j]) * rtol
        d0 = _rms_scaled(y, scale)
        d1 = _rms_scaled(f, scale)
        h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
        h0 = min(h0, interval)
        for j in range(n):
            ytmp[j] = y[j] + h0 * direction * f[j]
        rhs(t0 + h0 * direction, ytmp, p, y_new)  # y_new: scratch for f(y1) here
        nfev += 1
        for j in range(n):
            ytmp[j] = y_new[j] - f[j]
        d2 = _rms_scaled(ytmp, scale) / h0
        if d1 <= 1e-15 and d2 <= 1e-15:
            h1 = max(1e-6, h0 * 1e-3)
        else:
            h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
        h_abs = min(100.0 * h0, h1, interval, max_step)

    t = t0
    nsteps = 0
    nrej = 0
    status = 0
    err_exp = -1.0 / 8.0
    while t < t_stop:
        if nsteps >= max_steps:
            status = -2
            break
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        if h_abs > max_step:
            h_abs = max_step
        elif h_abs < min_step:
            h_abs = min_step
        accepted = False
        rejected = False
        h = 0.0
        t_new = t
        while not accepted:
            if h_abs < min_step:
                status = -1
                break
            h = h_abs
            t_new = t + h
            if t_new - t1 > 0:
                t_new = t1
            h = t_new - t
            h_abs = abs(h)
            _rk_stages(rhs, t, y, f, h, A, C, n_stages, K, p, ytmp, sacc)
            if n >= ROW_SUMS_FROM:
                for j in range(n):
                    sacc[j] = 0.0
                for k in range(n_stages):
                    b = B[k]
                    if b != 0.0:
                        for j in range(n):
                            sacc[j] += b * K[k, j]
                for j in range(n):
                    y_new[j] = y[j] + h * sacc[j]
            else:
                for j in range(n):
                    sj = 0.0
                    for k in range(n_stages):
                        sj += B[k] * K[k, j]
                    y_new[j] = y[j] + h * sj
            rhs(t + h, y_new, p, f_new)
            nfev += n_stages
            for j in range(n):
                K[n_stages, j] = f_new[j]
            err_norm = _error_norm(K, y, y_new, h, rtol, atol, E3, E5, n_stages)
            if not math.isfinite(err_norm):
                err_norm = 1e10  # treat as a failed step; shrink
            if err_norm < 1.0:
                if err_norm == 0.0:
                    factor = MAX_FACTOR
                else:
                    factor = min(MAX_FACTOR, SAFETY * err_norm**err_exp)
                if rejected:
                    factor = min(1.0, factor)
                h_abs *= factor
                accepted = True
            else:
                h_abs *= max(MIN_FACTOR, SAFETY * err_norm**err_exp)
                rejected = True
                nrej += 1
        if status != 0:
            break
        finite = True
        for j in range(n):
            if not math.isfinite(y_new[j]):
                finite = False
        if not finite:
            status = -3
            break
        nsteps += 1
        # dense output, only when needed: for outputs inside the step, and for events when
        # the cheap screen says the step may contain a crossing (they are then looked for on
        # the dense output at h/4, so a step that contains two crossings does not hide them)
        need_dense = ie < n_eval and t_eval[ie] <= t_new
        g_new = 0.0
        screened = False
        if use_event:
            g_new = event(t_new, y_new, p)
            screened = _may_cross(event, t, y, f, y_new, f_new, h, g_old, g_new, event_dir, p,
                                  ydense)  # fmt: skip
            need_dense = need_dense or screened
        if need_dense:
            _dense_coefficients(rhs, t, y, f, y_new, f_new, h, A, C, D, n_stages, K, p, ytmp, Fd)
            nfev += 3
            t_cut = t_new  # outputs up to here belong to this step's trajectory
            acting = False
            if screened:
                xa, ga = 0.0, g_old
                for q in range(1, EVENT_SUBSTEPS + 1):
                    if n_ev >= max_events or acting:
                        break
                    xb = q / EVENT_SUBSTEPS
                    if q == EVENT_SUBSTEPS:
                        gb = g_new
                    else:
                        _dense_eval(xb, y, Fd, ydense)
                        gb = event(t + xb * h, ydense, p)
                    if _crosses(ga, gb, event_dir):
                        xm = _locate_event(event, t, y, h, xa, xb, ga, gb, Fd, p, ydense)
                        ev_t[n_ev] = t + xm * h
                        _dense_eval(xm, y, Fd, ydense)
                        _copy(ydense, ev_y[n_ev])
                        _copy(ydense, ev_y2[n_ev])
                        if event_action != 0:  # terminal or reset: the step ends here
                            acting = True
                            t_cut = ev_t[n_ev]
                        else:
                            n_ev += 1
                    xa, ga = xb, gb
            while ie < n_eval and t_eval[ie] <= t_cut:
                if t_eval[ie] == t_new:
                    _copy(y_new, Y[ie])
                elif acting and t_eval[ie] == t_cut:
                    _copy(ev_y[n_ev], Y[ie])
                else:
                    _dense_eval((t_eval[ie] - t) / h, y, Fd, ydense)
                    _copy(ydense, Y[ie])
                ie += 1
            if acting:
                t_new = ev_t[n_ev]
                if event_action == 2:  # reset the state, continue from the event
                    reset(t_new, ev_y[n_ev], p, y_new)
                    _copy(y_new, ev_y2[n_ev])
                else:
                    _copy(ev_y[n_ev], y_new)
                    status = 1
                rhs(t_new, y_new, p, f_new)
                nfev += 1
                g_scale = max(abs(g_old), abs(g_new))
                g_new = event(t_new, y_new, p)
                # A reset that leaves the state on the event surface (it changed other
                # components, e.g. a recorded approach velocity) must not count the same
                # crossing again: within rounding of the located root, g counts as 0, and a
                # new crossing has to leave the surface first.
                if abs(g_new) <= 2.0 * abs(event(t_new, ev_y[n_ev], p)) + 1e-12 * g_scale:
                    g_new = 0.0
                n_ev += 1
        g_old = g_new
        t = t_new
        _copy(y_new, y)
        _copy(f_new, f)
        if status == 1 or (use_event and n_ev >= max_events):
            status = 1
            break
    _copy(y, y0)
    stats[0] = nfev
    stats[1] = nsteps
    stats[2] = nrej
    stats[3] = ie
    stats[4] = n_ev
    fstate[0] = t
    fstate[1] = h_abs
    return status


FIXED_STEP_SIG = I8(RHS_TYPE, F8, V1, F8, F8, V1, F8, V1, I8, V2, T.int64[::1], V1, V2, V1, V1)


@nb.njit(cache=True)  # compiled for FIXED_STEP_SIG on first use: see typed()
def fixed_step_kernel(rhs, t0, y0, t1, t_stop, p, h_max, t_eval, max_steps, Y, stats, fstate,
                      A, B, C):  # fmt: skip
    """An explicit Runge-Kutta method given by its tableau ``(A, B, C)``, with fixed steps
    that land exactly on every output time.

    Between consecutive stops (output times and ``t1``) it takes ``m = ceil(dt / h_max)`` equal
    steps, so outputs are method values, not interpolations. The call returns after the first
    stop at or beyond ``t_stop`` (so splitting a run for a progress bar does not add stops).
    ``y0`` is updated in place; ``stats = [nfev, nsteps, 0, n_out, 0]``,
    ``fstate = [t_final, h]``.
    """
    K = np.empty((B.shape[0], y0.shape[0]))
    yt = np.empty(y0.shape[0])
    y = y0.copy()
    return _fixed_step_run(rhs, t0, y0, t1, t_stop, p, h_max, t_eval, max_steps, Y, stats,
                           fstate, A, B, C, K, yt, y)  # fmt: skip


@nb.njit(cache=True, _nrt=False)
def _fixed_step_run(rhs, t0, y0, t1, t_stop, p, h_max, t_eval, max_steps, Y, stats, fstate,
                    A, B, C, K, yt, y):  # fmt: skip
    """[`fixed_step_kernel`][recipdyn.integrate.kernels.fixed_step_kernel]'s loop, given its work
    arrays, without reference counting (as `_dop853_run`)."""
    n = y0.shape[0]
    s = B.shape[0]
    n_eval = t_eval.shape[0]
    ie = 0
    t = t0
    nfev = 0
    nsteps = 0
    status = 0
    while True:
        while ie < n_eval and t_eval[ie] <= t:
            _copy(y, Y[ie])
            ie += 1
        if t >= t1 or t >= t_stop:
            break
        stop = t_eval[ie] if ie < n_eval and t_eval[ie] < t1 else t1
        m = max(1, int(math.ceil((stop - t) / h_max - 1e-9)))
        h = (stop - t) / m
        for i in range(m):
            tc = t + i * h
            for st in range(s):
                for j in range(n):
                    acc = 0.0
                    for k in range(st):
                        acc += A[st, k] * K[k, j]
                    yt[j] = y[j] + h * acc
                rhs(tc + C[st] * h, yt, p, K[st])
            for j in range(n):
                acc = 0.0
                for k in range(s):
                    acc += B[k] * K[k, j]
                y[j] += h * acc
            nfev += s
            nsteps += 1
        t = stop
        finite = True
        for j in range(n):
            if not math.isfinite(y[j]):
                finite = False
        if not finite:
            status = -3
            break
        if nsteps > max_steps:
            status = -2
            break
    _copy(y, y0)
    stats[0] = nfev
    stats[1] = nsteps
    stats[3] = ie
    fstate[0] = t
    fstate[1] = h_max
    return status
