"""The small interface every dynamical model exposes to the integrators and the analysis.

A model is *state + rule + parameters*:

* an ODE ``dy/dt = f(t, y; p)`` ([`ODESystem`][recipdyn.model.base.ODESystem]) or a map ``x_{n+1} =
  g(n, x_n; p)`` ([`DiscreteMap`][recipdyn.model.base.DiscreteMap]);
* the rule is a compiled (``numba.njit``) kernel with a fixed calling convention, so the
  integrators and the tangent-space (Lyapunov) code can call it from inside their own compiled
  loops without Python overhead;
* the parameters are a flat ``float64`` array ``p`` packed by the model's Python side.

Kernel calling convention (all arrays ``float64``, C-contiguous):

``rhs(t, y, p, out)``
    writes ``f(t, y; p)`` into ``out`` (shape ``(dim,)``), returns nothing.
``jac(t, y, p, out)``
    writes the Jacobian ``df/dy`` into ``out`` (shape ``(dim, dim)``, ``out[i, j] = df_i/dy_j``).

Kernels are declared with [`compiled`][recipdyn.model.base.compiled] and their signature
(``@compiled(RHS_SIGNATURE)``): the integrators receive them as first-class function values
(`RHS_TYPE`), which keeps the integrators' own compiled code cacheable across processes (a
dispatcher argument would specialise the integrator per model, which numba cannot cache).
Compilation is lazy: a kernel is compiled (or loaded from numba's disk cache) when a run first uses
it, never at import, so a run pays only for what it uses.

For a map the same convention holds with the step index ``n`` (a float) in place of ``t`` and
``out`` receiving ``g``/``dg/dx``.

Derived outputs (e.g. crosshead displacement from the clearance angle) are *not* part of the
compiled rule: a model may implement [`ODESystem.outputs`][recipdyn.model.base.ODESystem.outputs] to
turn a trajectory into named, unit-labelled signals. Nothing here knows about cranks; the compressor
model ([`recipdyn.model.compressor`][recipdyn.model.compressor]) is one implementation, the Lorenz
system in the tests another.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numba as _nb
import numpy as np
from numba import types as _nbt

from ..errors import KernelAllocatesWarning

__all__ = [
    "ODESystem", "DiscreteMap", "Signal", "Event", "RHS_SIGNATURE", "JAC_SIGNATURE",
    "EVENT_SIGNATURE", "RHS_TYPE", "JAC_TYPE", "EVENT_TYPE", "RHS_JAC_SIGNATURE", "compiled",
    "typed", "rhs_series", "cache_holds",
]  # fmt: skip

#: ``rhs(t, y, p, out) -> None`` (also a map's ``step``).
RHS_SIGNATURE = _nbt.void(_nbt.float64, _nbt.float64[::1], _nbt.float64[::1], _nbt.float64[::1])
#: ``jac(t, y, p, out2d) -> None``.
JAC_SIGNATURE = _nbt.void(_nbt.float64, _nbt.float64[::1], _nbt.float64[::1], _nbt.float64[:, ::1])
#: ``g(t, y, p) -> float`` (event functions for sections).
EVENT_SIGNATURE = _nbt.float64(_nbt.float64, _nbt.float64[::1], _nbt.float64[::1])
RHS_TYPE = _nbt.FunctionType(RHS_SIGNATURE)
JAC_TYPE = _nbt.FunctionType(JAC_SIGNATURE)
EVENT_TYPE = _nbt.FunctionType(EVENT_SIGNATURE)
#: ``rhs_jac(t, y, p, out, out2d) -> None``: both at once (optional; saves shared work in
#: tangent-space integration).
RHS_JAC_SIGNATURE = _nbt.void(
    _nbt.float64, _nbt.float64[::1], _nbt.float64[::1], _nbt.float64[::1], _nbt.float64[:, ::1]
)


def _serialise_cache_saves() -> None:
    """Make numba's save of a cache entry one step across processes.

    numba saves a compiled function by reading the function's cache index, adding the new
    signature under the first free data-file name, writing the index back and then the code
    (`numba.core.caching.IndexDataCacheFile.save`). Two processes compiling two signatures
    of one function at once (parallel test workers, a process pool on a fresh machine) can
    interleave so that one entry is lost or, worse, names the other signature's code. An
    exclusive ``flock`` on a file beside the index, held through the save, rules that out;
    loading needs no lock (numba writes each file to a temporary name and renames it). numba's
    internals are pinned with numba (requirements/constraints.txt); without ``fcntl`` or that
    class nothing changes."""
    import os

    try:
        import fcntl

        from numba.core.caching import IndexDataCacheFile
    except ImportError:  # pragma: no cover - not POSIX, or another numba
        return
    plain = IndexDataCacheFile.save
    if getattr(plain, "recipdyn_locked", False):
        return

    def save(self, key, data):
        try:
            fd = os.open(self._index_path + ".lock", os.O_RDWR | os.O_CREAT, 0o644)
        except OSError:  # a read-only cache: numba's own save reports what it reports
            return plain(self, key, data)
        try:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX)
            except OSError:  # pragma: no cover - no flock on this file system
                pass
            return plain(self, key, data)
        finally:
            os.close(fd)  # releases the lock

    save.recipdyn_locked = True
    IndexDataCacheFile.save = save


_serialise_cache_saves()


def compiled(signature, *, allocates: bool = False):
    """Declare a compiled kernel: ``numba.njit(cache=True)``, compiled on first use.

    ``signature`` documents the calling convention; numba compiles exactly it when the kernel is
    first passed as a function value (`RHS_TYPE`, ...) to an integrator, and the machine
    code is kept in numba's disk cache (``NUMBA_CACHE_DIR``, by default the user's cache
    directory, see `recipdyn`), so later processes load it instead of compiling.

    A kernel that allocates no arrays (a right-hand side, an event function, a reset) is
    compiled without numba's reference counting (``_nrt=False``), together with every function
    it calls. The counting of the array arguments (atomic increments and decrements at every
    call and every view) took half of the contact model's right-hand side: 131 against 54 ns a
    call, the same results to the bit (architecture page, Compiled kernels). A kernel that
    allocates anywhere in its calls (``np.empty``, ``copy``, a slice assignment that may copy)
    says ``allocates=True``. One that does not say so still works: the compilation without
    counting fails, and the kernel is compiled with it instead, with a
    [`KernelAllocatesWarning`][recipdyn.errors.KernelAllocatesWarning] (slower, never wrong: without
    counting numba refuses every allocation, it cannot leak).
    """

    def deco(func):
        dispatcher = _nb.njit(cache=True, _nrt=allocates)(func)
        dispatcher.recipdyn_signature = signature
        if not allocates and hasattr(dispatcher, "targetoptions"):  # not NUMBA_DISABLE_JIT
            _fall_back_to_counting(dispatcher)
        return dispatcher

    return deco


def _fall_back_to_counting(dispatcher) -> None:
    """Let ``dispatcher`` (compiled without reference counting) compile with it when it
    cannot without (it allocates): numba compiles a kernel through ``dispatcher.compile``
    however it is first used (called, or passed as a function value)."""
    plain = dispatcher.compile

    def compile_or_fall_back(sig):
        try:
            return plain(sig)
        except _nb.core.errors.NumbaError:
            if dispatcher.targetoptions.get("_nrt", True):
                raise
            # numba's own state (pinned version; tests/test_integrate.py exercises this): the
            # options are read at each compilation, and the failure is forgotten
            dispatcher.targetoptions["_nrt"] = True
            dispatcher._compiler._failed_cache.clear()
            result = plain(sig)  # a genuine error is raised here, with counting
            warnings.warn(
                f"kernel {dispatcher.py_func.__module__}.{dispatcher.__name__} allocates "
                "arrays: compiled with reference counting (slower); declare it with "
                "@compiled(..., allocates=True)",
                KernelAllocatesWarning,
                stacklevel=2,
            )
            return result

    dispatcher.compile = compile_or_fall_back


def cache_holds(dispatcher, signature) -> bool | None:
    """Whether compiling ``dispatcher`` for ``signature`` (what is passed to its ``compile``)
    will load machine code rather than make it: True if this process has it already or
    numba's disk cache holds it for this source, signature and CPU; False if it will be
    compiled; None if that cannot be told (not a numba dispatcher, no disk cache, or numba's
    cache layout changed: it is not public API; numba 0.59-0.68 checked). Reads the cache's
    index file only (milliseconds): commands say "compiling" or "loading" before it happens.
    """
    try:
        args, _ = _nb.core.sigutils.normalize_signature(signature)
        if dispatcher.overloads.get(tuple(args)) is not None:
            return True
        cache = dispatcher._cache
        if not getattr(cache, "_enabled", False):  # (NullCache: cache=False)
            return None
        key = cache._index_key(signature, dispatcher.targetctx.codegen())
        return key in cache._cache_file._load_index()
    except Exception:  # noqa: BLE001 - numba's private layout: unknown, not an error
        return None


_TYPED: dict[int, Any] = {}


def typed(dispatcher, signature):
    """``dispatcher`` compiled for exactly ``signature`` and closed to other argument types.

    For compiled loops called from Python with function values as arguments (the integrators):
    the function values are then converted to `numba.types.FunctionType` instead of
    specialising the loop per model, so one cached loop serves every model. Compiled once per
    process, on first use.
    """
    key = id(dispatcher)
    if key not in _TYPED:
        with warnings.catch_warnings():
            # function values passed on to another compiled function (the loops' own helpers)
            # are numba's first-class function type, which it still calls experimental; the
            # loops are tested through it on every model
            warnings.simplefilter("ignore", _nb.errors.NumbaExperimentalFeatureWarning)
            dispatcher.compile(signature)
        dispatcher.disable_compile()
        _TYPED[key] = dispatcher
    return dispatcher


_SERIES_SIG = _nbt.float64[:, ::1](RHS_TYPE, _nbt.float64[::1], _nbt.float64[:, ::1],
                                   _nbt.float64[::1])  # fmt: skip


@_nb.njit(cache=True)  # compiled for _SERIES_SIG on first use (typed)
def _rhs_series(rhs, t, y, p):
    n = y.shape[1]
    out = np.empty((t.shape[0], n))
    buf = np.empty(n)
    yi = np.empty(n)
    for i in range(t.shape[0]):
        for j in range(n):
            yi[j] = y[i, j]
        rhs(t[i], yi, p, buf)
        for j in range(n):
            out[i, j] = buf[j]
    return out


def rhs_series(rhs, params: np.ndarray, t: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``f(t_i, y_i)`` at every sample of a trajectory (shape ``(len(t), dim)``), compiled:
    e.g. the accelerations a model's outputs need."""
    return typed(_rhs_series, _SERIES_SIG)(
        rhs,
        np.ascontiguousarray(t, dtype=np.float64),
        np.ascontiguousarray(y, dtype=np.float64),
        np.ascontiguousarray(params, dtype=np.float64),
    )


@dataclass(frozen=True)
class Signal:
    """A derived output: values over the trajectory's samples plus metadata.

    Attributes
    ----------
    values : ndarray
        One value per sample.
    units : str
        SI units as a string understood by pint (``"m"``, ``"m/s**2"``, ``"rad"``, ``"N"``).
    long_name : str
        Human-readable name for axis labels.
    """

    values: np.ndarray
    units: str
    long_name: str


@dataclass(frozen=True)
class Event:
    """An event a model declares: crossings of ``function(t, y, p) = 0``.

    Attributes
    ----------
    name : str
        Prefix of the recorded variables (``NAME_time``, ``NAME_<state>``,
        ``NAME_<state>_after``).
    function : numba function
        ``g(t, y, p) -> float`` compiled with
        [`EVENT_SIGNATURE`][recipdyn.model.base.EVENT_SIGNATURE].
    direction : int
        +1 rising, -1 falling, 0 both.
    action : {"record", "terminal", "reset"}
        Only recorded; ends the run; or ``reset(t, y, p, out)`` sets the state (impact laws).
    reset : numba function, optional
        With ``action="reset"``, compiled with `RHS_SIGNATURE`.
    description : str
    """

    name: str
    function: Callable[..., float]
    direction: int = 0
    action: str = "record"
    reset: Callable[..., None] | None = None
    description: str = ""


@dataclass(frozen=True)
class ODESystem:
    """A first-order ODE ``dy/dt = f(t, y; p)`` with compiled kernels.

    Parameters
    ----------
    rhs : numba dispatcher
        ``rhs(t, y, p, out)``; see the module docstring.
    params : ndarray
        Packed ``float64`` parameter vector passed to the kernels unchanged.
    state_names : tuple of str
        One name per state component; ``dim`` is its length.
    jac : numba dispatcher, optional
        ``jac(t, y, p, out)``, the exact Jacobian ``df/dy``. Needed for Benettin's method.
    rhs_jac : numba dispatcher, optional
        ``rhs_jac(t, y, p, out, out2d)``: right-hand side and Jacobian in one call, when they
        share work (used by the tangent-space integration instead of ``rhs`` + ``jac``). The
        columns of ``passive`` components may be left 0: tangent vectors have none.
    period : float, optional
        Period (in ``t``) of the explicit time dependence, if the system is periodically forced
        (the compressor's crank period ``2*pi/omega``). Used for stroboscopic sections.
    state_units : tuple of str, optional
        Units of each state component.
    name : str
        Short identifier.
    attrs : mapping
        Extra metadata (every input parameter) copied into result attributes.
    events : tuple of Event
        The model's events. One that acts (``reset`` or ``terminal``) is part of the dynamics:
        [`recipdyn.integrate.integrate`][recipdyn.integrate.solve.integrate] and the Lyapunov
        integration apply it whenever they are not given another event function.
    """

    rhs: Callable[..., Any]
    params: np.ndarray
    state_names: tuple[str, ...]
    jac: Callable[..., Any] | None = None
    period: float | None = None
    rhs_jac: Callable[..., Any] | None = None
    state_units: tuple[str, ...] | None = None
    name: str = "ode"
    attrs: Mapping[str, Any] = field(default_factory=dict)
    events: tuple[Event, ...] = ()
    #: The last ``aux_states`` components are auxiliary, not degrees of freedom (values an
    #: event records, work integrals): their derivatives do not depend on them, and Lyapunov
    #: exponents are computed for the other components only.
    aux_states: int = 0
    #: Components left out of the tangent space of the Lyapunov integration (their tangent
    #: components are held at 0): ones that stay 0 by construction (the eccentricity of a
    #: joint modelled as rigid) and ones nothing depends on (work integrals).
    passive: tuple[int, ...] = ()
    #: Auxiliary components that are not last (values an event records that the motion
    #: depends on, followed by later degrees of freedom: the contact joints' approach
    #: velocities before a free crank's angle and speed). Like the last ``aux_states`` they
    #: are no degrees of freedom, but their tangent components follow the flow (a passive
    #: one's are held at 0, which would drop the damping law's dependence on them).
    aux: tuple[int, ...] = ()

    @property
    def dof(self) -> tuple[int, ...]:
        """The degrees of freedom: the components that are neither auxiliary (the last
        ``aux_states``, ``aux``) nor passive; Lyapunov exponents are theirs."""
        skip = set(self.passive) | set(self.aux)
        return tuple(i for i in range(self.dim - self.aux_states) if i not in skip)

    @property
    def acting_event(self) -> Event | None:
        """The event that is part of the dynamics (reset or terminal), if any."""
        return next((e for e in self.events if e.action != "record"), None)

    def __post_init__(self) -> None:
        # The kernels are compiled for float64 arrays: cast at the boundary (integer
        # parameters would otherwise fail to dispatch inside compiled code).
        object.__setattr__(self, "params", np.ascontiguousarray(self.params, dtype=np.float64))

    @property
    def dim(self) -> int:
        return len(self.state_names)

    def f(self, t: float, y: np.ndarray) -> np.ndarray:
        """Evaluate the right-hand side from Python (for tests and reference solvers)."""
        out = np.empty(self.dim)
        self.rhs(float(t), np.ascontiguousarray(y, dtype=np.float64), self.params, out)
        return out

    def jacobian(self, t: float, y: np.ndarray) -> np.ndarray:
        """Evaluate the Jacobian from Python; raises if the model has none."""
        if self.jac is None:
            raise ValueError(f"model {self.name!r} provides no Jacobian")
        out = np.empty((self.dim, self.dim))
        self.jac(float(t), np.ascontiguousarray(y, dtype=np.float64), self.params, out)
        return out

    def outputs(self, t: np.ndarray, y: np.ndarray) -> dict[str, Signal]:
        """Derived signals over a trajectory ``y`` of shape ``(len(t), dim)``.

        The generic system's outputs are its state components.
        """
        units = self.state_units or ("1",) * self.dim
        return {n: Signal(np.asarray(y[:, i]), units[i], n) for i, n in enumerate(self.state_names)}


@dataclass(frozen=True)
class DiscreteMap:
    """A map ``x_{n+1} = g(n, x_n; p)`` with compiled kernels (same convention as ODESystem)."""

    step: Callable[..., Any]
    params: np.ndarray
    state_names: tuple[str, ...]
    jac: Callable[..., Any] | None = None
    name: str = "map"
    attrs: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "params", np.ascontiguousarray(self.params, dtype=np.float64))

    @property
    def dim(self) -> int:
        return len(self.state_names)

    def g(self, n: int, x: np.ndarray) -> np.ndarray:
        out = np.empty(self.dim)
        self.step(float(n), np.ascontiguousarray(x, dtype=np.float64), self.params, out)
        return out
