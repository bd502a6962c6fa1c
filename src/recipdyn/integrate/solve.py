"""Integrate any [`ODESystem`][recipdyn.model.base.ODESystem] with compiled Runge-Kutta loops.

Methods (registry [`METHODS`][recipdyn.integrate.solve.METHODS]):

``"dop853"``
    Dormand-Prince 8(5,3) with SciPy's error control and 7th-order dense output; outputs at
    ``t_eval`` come from the dense output (exact sampling times, like a sensor); optional events
    are root-found on the dense output. Counts ``nfev``, ``nsteps`` and ``nreject``.
``"rk4"``
    Classical fixed-step RK4 (the paper's method) with step ``h`` (at most), landing exactly on
    every output time; run from its tableau by the generic fixed-step kernel, like any explicit
    tableau added to [`METHODS`][recipdyn.integrate.solve.METHODS].

Long runs can be split into chunks so a progress bar can advance; a chunk ends after the first
step that reaches its boundary (the step is not shortened), so the results are bit-identical
whatever the number of chunks.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..defaults import ATOL, ATOL_RANGE, RTOL, RTOL_RANGE
from ..errors import IntegrationError, Interrupted, ParameterError, deferred_signals, is_number
from ..model.base import ODESystem, cache_holds, typed
from . import kernels
from .tableaus import RK4, Tableau, dop853

__all__ = ["integrate", "propagate", "prepare", "UniformGrid", "Solution", "IntegrationError",
           "METHODS", "Method"]  # fmt: skip


@dataclass(frozen=True)
class Method:
    """An integration method as data: its tableau and how its step is chosen."""

    name: str
    tableau: Callable[[], Tableau]
    adaptive: bool
    description: str


#: The registry of methods: adaptive ones run
#: [`kernels.dop853_kernel`][recipdyn.integrate.kernels.dop853_kernel] (error control and dense
#: output of DOP853), fixed-step ones run
#: [`kernels.fixed_step_kernel`][recipdyn.integrate.kernels.fixed_step_kernel] on any explicit
#: tableau.
METHODS: dict[str, Method] = {
    "dop853": Method("dop853", dop853, True, "Dormand-Prince 8(5,3), adaptive, dense output"),
    "rk4": Method("rk4", lambda: RK4, False, "classical Runge-Kutta, fixed step h"),
}
_MESSAGES = {
    0: "reached the end of the interval",
    1: "stopped at an event (terminal event or the requested number of events)",
    -1: "step size fell below the resolution of t (the problem may be singular or stiff)",
    -2: "max_steps exceeded",
    -3: "the state became non-finite (NaN/inf)",
    -4: "interrupted",
}


@dataclass
class Solution:
    """Result of [`integrate`][recipdyn.integrate.solve.integrate].

    Attributes
    ----------
    t : ndarray, shape (n,)
        Output times.
    y : ndarray, shape (n, dim)
        States at ``t``.
    t_final, y_final : float, ndarray
        Where the integration stopped.
    nfev, nsteps, nreject : int
        Right-hand-side evaluations, accepted and rejected steps.
    status : int
        0 success, 1 stopped at ``max_events``, < 0 failure (see ``message``).
    t_events, y_events : ndarray
        Event times and states at the events (if an event function was given).
    y_events_after : ndarray
        States after each event's action (equal to ``y_events`` unless the event resets).
    settings : dict
        Method and tolerances, for result attributes.
    """

    t: np.ndarray
    y: np.ndarray
    t_final: float
    y_final: np.ndarray
    nfev: int
    nsteps: int
    nreject: int
    status: int
    message: str
    t_events: np.ndarray = field(default_factory=lambda: np.empty(0))
    y_events: np.ndarray = field(default_factory=lambda: np.empty((0, 0)))
    y_events_after: np.ndarray = field(default_factory=lambda: np.empty((0, 0)))
    settings: dict = field(default_factory=dict)

    @property
    def success(self) -> bool:
        return self.status >= 0


def _check_inputs(system, y0, t_span, method, rtol, atol, h):
    if not isinstance(system, ODESystem):
        raise TypeError(f"system must be an ODESystem, got {type(system).__name__}")
    y0 = np.ascontiguousarray(y0, dtype=np.float64).reshape(-1)
    if y0.shape[0] != system.dim:
        raise ParameterError(f"y0 has {y0.shape[0]} components, the system has {system.dim}")
    if not np.all(np.isfinite(y0)):
        raise ParameterError(f"y0 must be finite, got {y0}")
    t0, t1 = (float(x) for x in t_span)
    if not (math.isfinite(t0) and math.isfinite(t1)) or t1 < t0:
        raise ParameterError(f"t_span must be finite with t1 >= t0, got {t_span}")
    if method not in METHODS:
        raise ParameterError(f"method = {method!r}; allowed: {', '.join(METHODS)}")
    check_tolerances(rtol, atol)
    fixed = not METHODS[method].adaptive
    if fixed and (h is None or not (is_number(h) and h > 0 and math.isfinite(h))):
        raise ParameterError(f"h = {h!r}: method {method!r} needs a step h > 0 s (finite)")
    return y0, t0, t1


def check_tolerances(rtol, atol) -> None:
    """Raise [`ParameterError`][recipdyn.errors.ParameterError] unless ``rtol`` and ``atol`` are in
    their ranges."""
    for name, v, (lo, hi) in (("rtol", rtol, RTOL_RANGE), ("atol", atol, ATOL_RANGE)):
        if not (is_number(v) and math.isfinite(v) and lo <= v <= hi):
            raise ParameterError(f"{name} = {v!r} out of range; allowed: [{lo:g}, {hi:g}]")


def integrate(
    system: ODESystem,
    y0,
    t_span: tuple[float, float],
    *,
    method: str = "dop853",
    rtol: float = RTOL,
    atol: float = ATOL,
    h: float | None = None,
    t_eval=None,
    max_step: float = math.inf,
    max_steps: int = 100_000_000,
    event: Callable | None = None,
    event_direction: int = 0,
    max_events: int = 0,
    event_action: str = "record",
    reset: Callable | None = None,
    chunks: int = 1,
    progress: Callable[[float], None] | None = None,
    raise_on_failure: bool = True,
    sink: Callable[[np.ndarray, np.ndarray], None] | None = None,
    block: int = 1 << 16,
) -> Solution:
    """Integrate ``system`` from ``y0`` over ``t_span``.

    Parameters
    ----------
    system : ODESystem
    y0 : array_like, shape (dim,)
    t_span : (t0, t1)
    method : {"dop853", "rk4"}
    rtol, atol : float
        DOP853 tolerances (error per step below ``atol + rtol |y|``).
    h : float
        RK4 maximum step (required for ``"rk4"``).
    t_eval : array_like, optional
        Sorted output times within ``t_span``; default ``[t0, t1]``.
    max_step : float
        DOP853 maximum step.
    event : numba function ``g(t, y, p) -> float``, optional
        Default: the system's own acting event (``system.events``), if it has one. Record
        crossings of ``g = 0`` (DOP853 only), root-found on the dense output;
        ``event_direction`` +1 rising, -1 falling, 0 both; ``max_events`` caps the count
        (and stops the integration when reached; 0 = capacity only, default 100 000).
    event_action : {"record", "terminal", "reset"}
        What an event does: only recorded (default); ends the integration at the event
        (status 1); or applies ``reset`` and continues from the event.
    reset : numba function ``reset(t, y, p, out)``, optional
        The state after a ``"reset"`` event (e.g. an impact law with restitution), compiled
        with `RHS_SIGNATURE`. States before and after each event are
        in ``y_events`` and ``y_events_after``.
    chunks : int
        Split the run in this many pieces, calling ``progress(fraction)`` after each.
    raise_on_failure : bool
        Raise [`IntegrationError`][recipdyn.errors.IntegrationError] (with the partial solution) on
        failure.
    sink : callable ``sink(t, y)``, optional
        Memory flat in run length: the outputs are handed to ``sink`` in blocks of about
        ``block`` samples as the integration goes (in order, each sample once) and not kept;
        the returned solution then has no samples (``t``, ``y`` empty). The steps, and so every
        number, are the same as without a sink.
    """
    y0, t0, t1 = _check_inputs(system, y0, t_span, method, rtol, atol, h)
    own = system.acting_event
    if own is not None:  # the model's impact law (or stop) is part of its dynamics
        if event is None:
            event, event_direction, event_action = own.function, own.direction, own.action
            reset = own.reset
        elif event is not own.function:
            raise ParameterError(
                f"system {system.name!r} has its own {own.action} event {own.name!r}; the "
                "integrator locates one event function, so another one cannot be added"
            )
    rtol, atol, max_step, max_steps = float(rtol), float(atol), float(max_step), int(max_steps)
    if t_eval is None:
        t_eval = np.array([t0, t1])
    if isinstance(t_eval, UniformGrid):
        if t_eval.n and (t_eval.at(0) < t0 or t_eval.at(t_eval.n - 1) > t1):
            raise ParameterError("t_eval must lie within t_span")
        if sink is None:
            t_eval = t_eval[0 : t_eval.n]
    else:
        t_eval = np.ascontiguousarray(t_eval, dtype=np.float64).reshape(-1)
        if t_eval.size and (np.any(np.diff(t_eval) < 0) or t_eval[0] < t0 or t_eval[-1] > t1):
            raise ParameterError("t_eval must be sorted and lie within t_span")
    use_event = event is not None
    actions = {"record": 0, "terminal": 1, "reset": 2}
    if event_action not in actions:
        raise ParameterError(f"event_action = {event_action!r}; allowed: {', '.join(actions)}")
    if event_action == "reset" and reset is None:
        raise ParameterError("event_action 'reset' needs a reset function")
    if event_action != "record" and not use_event:
        raise ParameterError(f"event_action {event_action!r} needs an event function")
    if use_event and not METHODS[method].adaptive:
        raise ParameterError("events need method 'dop853' (located on its dense output)")
    action = actions[event_action]
    reset_fn = reset if reset is not None else kernels.no_reset
    cap = max_events if max_events > 0 else 100_000
    ev = event if use_event else kernels.no_event
    chunks = max(1, int(chunks))
    # Progress stops: each kernel call returns after the first step that reaches the next one,
    # without clipping that step, so the step sequence (and every number) is the same for any
    # number of chunks: progress observes the integration, it never changes it.
    stops = np.linspace(t0, t1, chunks + 1)[1:]
    stops[-1] = t1
    if sink is None:
        Y = np.empty((t_eval.size, system.dim))
    else:  # bounded memory: outputs go to the sink block by block (stops add no steps)
        block = max(1, int(block))
        bstops = t_eval[block - 1 :: block]
        stops = np.unique(np.concatenate([stops, bstops[bstops < t1]]))
    n_eval = t_eval.size
    ev_t, ev_y, ev_y2 = [], [], []
    y = y0.copy()  # updated in place by the kernels
    t = t0
    h_abs = 0.0
    nfev = nsteps = nrej = 0
    status = 0
    n_out = 0
    interrupted = 0
    tab = METHODS[method].tableau()
    adaptive = METHODS[method].adaptive
    if adaptive:  # compiled (or loaded) once per process, for the FunctionType signature
        dop853_loop = typed(kernels.dop853_kernel, kernels.DOP853_SIG)
    else:
        fixed_loop = typed(kernels.fixed_step_kernel, kernels.FIXED_STEP_SIG)
    with deferred_signals() as pending:
        for t_stop in stops:
            if t >= t_stop and t_stop < t1:
                continue  # the previous call already stepped past this stop
            if pending.signum:  # everything before t is recorded: stop here and keep it
                interrupted, status = pending.signum, -4
                break
            if sink is not None:  # the window: samples up to t_stop plus the last step's
                k_end = _count_le(t_eval, t_stop)
                margin = block
                saved = (t, y.copy(), h_abs)
            while True:
                if sink is None:
                    Yw, tw = Y[n_out:], t_eval[n_out:]
                else:
                    size = min(n_eval - n_out, k_end - n_out + margin)
                    Yw, tw = np.empty((size, system.dim)), t_eval[n_out : n_out + size]
                stats = np.zeros(5, dtype=np.int64)
                fstate = np.zeros(2)
                if adaptive:
                    ev_cap = cap - len(ev_t) if use_event else 0
                    et, ey = np.empty(ev_cap), np.empty((ev_cap, system.dim))
                    ey2 = np.empty((ev_cap, system.dim))
                    status = dop853_loop(
                        system.rhs, ev, t, y, t1, float(t_stop), system.params, rtol, atol,
                        h_abs, max_step, tw, max_steps - nsteps, tab.A, tab.B, tab.C, tab.E3,
                        tab.E5, tab.D, use_event, event_direction, action, reset_fn, Yw, et, ey,
                        ey2, stats, fstate,
                    )  # fmt: skip
                else:
                    status = fixed_loop(
                        system.rhs, t, y, t1, float(t_stop), system.params, float(h), tw,
                        max_steps - nsteps, Yw, stats, fstate, tab.A, tab.B, tab.C,
                    )  # fmt: skip
                k_out = int(stats[3])
                full = sink is not None and k_out == tw.size and n_out + tw.size < n_eval
                if full and float(fstate[0]) >= tw[-1]:
                    # the last step may have passed samples beyond the window: redo the call
                    # from the saved state with a wider window (deterministic: same steps)
                    t, h_abs = saved[0], saved[2]
                    y[:] = saved[1]
                    margin *= 8
                    continue
                break
            if adaptive:
                ev_t.extend(et[: stats[4]])
                ev_y.extend(ey[: stats[4]])
                ev_y2.extend(ey2[: stats[4]])
            t, h_abs = float(fstate[0]), float(fstate[1])
            nf, ns, nr = (int(x) for x in stats[:3])
            if sink is not None and k_out:
                sink(tw[:k_out].copy(), Yw[:k_out])
            n_out += k_out
            nfev += nf
            nsteps += ns
            nrej += nr
            if progress is not None:
                progress(min(1.0, (t - t0) / (t1 - t0)) if t1 > t0 else 1.0)
            if status != 0 or t >= t1:
                break
    if sink is not None:  # everything went to the sink
        n_out, Y = 0, np.empty((0, system.dim))
    Y = Y[:n_out]
    sol = Solution(
        t=t_eval[: Y.shape[0]].copy(),
        y=Y,
        t_final=float(t),
        y_final=np.array(y),
        nfev=int(nfev),
        nsteps=int(nsteps),
        nreject=int(nrej),
        status=int(status),
        message=_MESSAGES[int(status)],
        t_events=np.array(ev_t, dtype=float),
        y_events=np.array(ev_y, dtype=float).reshape(-1, system.dim),
        y_events_after=np.array(ev_y2, dtype=float).reshape(-1, system.dim),
        settings=dict(method=method, rtol=rtol, atol=atol, h=h, max_step=max_step),
    )
    if interrupted:
        exc = Interrupted(interrupted)
        exc.partial = sol
        raise exc
    if status < 0 and raise_on_failure:
        raise IntegrationError(f"integration failed at t = {t:.6g}: {sol.message}", sol)
    return sol


@dataclass(frozen=True)
class UniformGrid:
    """Output times ``start + i / rate`` for ``i = 0 .. n-1``, made piece by piece (with a
    ``sink``, a long run never holds all its output times). Slicing gives exactly the values
    of ``start + np.arange(n) / rate``."""

    start: float
    rate: float
    n: int

    def __post_init__(self):
        if not (self.rate > 0 and self.n >= 0):
            raise ParameterError(f"UniformGrid: rate = {self.rate} must be > 0, n >= 0")

    @property
    def size(self) -> int:
        return self.n

    def at(self, i: int) -> float:
        return float(self.start + np.float64(i) / self.rate)

    def __getitem__(self, sl: slice) -> np.ndarray:
        i, j, step = sl.indices(self.n)
        return self.start + np.arange(i, j, step, dtype=np.float64) / self.rate


def _count_le(t_eval, t: float) -> int:
    """Number of output times <= t."""
    if not isinstance(t_eval, UniformGrid):
        return int(np.searchsorted(t_eval, t, side="right"))
    k = min(max(int(math.floor((t - t_eval.start) * t_eval.rate)) + 1, 0), t_eval.n)
    while k < t_eval.n and t_eval.at(k) <= t:
        k += 1
    while k > 0 and t_eval.at(k - 1) > t:
        k -= 1
    return k


def _to_prepare(system: ODESystem, method: str) -> list[tuple[Any, Any]]:
    """The (dispatcher, signature) pairs `prepare` compiles or loads for ``system``."""
    if method not in METHODS:
        raise ParameterError(f"method = {method!r}; allowed: {', '.join(METHODS)}")
    loop = ((kernels.dop853_kernel, kernels.DOP853_SIG) if METHODS[method].adaptive
            else (kernels.fixed_step_kernel, kernels.FIXED_STEP_SIG))  # fmt: skip
    out = [loop]
    own = system.acting_event
    for fn in (system.rhs, getattr(own, "function", None), getattr(own, "reset", None)):
        sig_obj = getattr(fn, "recipdyn_signature", None)
        if sig_obj is not None:
            out.append((fn, sig_obj.args))
    return out


def compiles(system: ODESystem, method: str = "dop853") -> list[str] | None:
    """What `prepare` will compile for ``system`` (the kernels' names; empty: it will load
    everything from numba's disk cache), decided before it happens from the cache's index
    (`recipdyn.model.base.cache_holds`); None if that cannot be told."""
    names = []
    for fn, sig in _to_prepare(system, method):
        held = cache_holds(fn, sig)
        if held is None:
            return None
        if not held:
            names.append(f"{fn.py_func.__module__}.{fn.__name__}")
    return names


def prepare(system: ODESystem, method: str = "dop853") -> None:
    """Compile (first run on a machine) or load from the cache everything
    [`integrate`][recipdyn.integrate.solve.integrate] needs for ``system``: the integrator loop, the
    model's right-hand side and its acting event.

    Optional: [`integrate`][recipdyn.integrate.solve.integrate] does the same on its first call. The
    command line calls it first, to say "compiling" while it takes long."""
    (loop, sig), *own = _to_prepare(system, method)
    typed(loop, sig)
    if METHODS[method].adaptive:
        METHODS[method].tableau()
    for fn, args in own:  # a compiled() kernel: compile exactly its signature
        fn.compile(args)


def propagate(system: ODESystem, y0, t0: float, t1: float, **kwargs) -> np.ndarray:
    """State at ``t1`` starting from ``y0`` at ``t0`` (no stored trajectory)."""
    return integrate(system, y0, (t0, t1), t_eval=np.empty(0), **kwargs).y_final
