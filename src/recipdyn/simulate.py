"""High-level simulation: parameters in, a labelled `xarray.Dataset` out."""

from __future__ import annotations

import datetime as _dt
import math
import time
import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

from . import __version__
from .defaults import RK4_STEPS_PER_REVOLUTION, SIMULATION
from .errors import Interrupted, LawRangeWarning, ModelValidityWarning, is_number
from .integrate import METHODS, IntegrationError, integrate
from .integrate.solve import UniformGrid, check_tolerances
from .io import lazy_duck_arrays
from .model.base import Signal
from .model.parameters import ParameterError, params_from_attrs
from .model.protocol import Model
from .model.registry import get_model, model_spec
from .resources import check_memory

__all__ = ["simulate", "summarize", "DEFAULT_SETTINGS", "clean_attrs", "params_from_attrs",
           "estimate_memory", "STARTUP_REVOLUTIONS", "model_values"]  # fmt: skip

lazy_duck_arrays()  # a record is built without importing dask or pint (io)

#: Defaults of [`simulate`][recipdyn.simulate.simulate] (also recorded in every result); see
#: [`recipdyn.defaults`][recipdyn.defaults].
DEFAULT_SETTINGS: dict[str, Any] = SIMULATION

#: Bytes held per output sample during [`simulate`][recipdyn.simulate.simulate]: ~20 float64
#: signals, the state and the xarray/NetCDF copies (measured: 1000 revolutions at 10 kHz peak at
#: 1.41 GB RSS, i.e. ~450 B per sample with the interpreter).
BYTES_PER_SAMPLE = 480


def estimate_memory(n_samples: int) -> float:
    """Peak memory (bytes) [`simulate`][recipdyn.simulate.simulate] needs for ``n_samples`` output
    samples."""
    return 150e6 + BYTES_PER_SAMPLE * float(n_samples)


def clean_attrs(attrs: dict[str, Any]) -> dict[str, Any]:
    """Make attributes storable in NetCDF/Zarr (no None, no bools, no nested dicts)."""
    out = {}
    for k, v in attrs.items():
        if v is None:
            v = "none"
        elif isinstance(v, bool):
            v = int(v)
        elif isinstance(v, dict):
            v = repr(v)
        elif isinstance(v, (list, tuple)):
            v = [float(x) for x in v] if all(isinstance(x, (int, float)) for x in v) else repr(v)
        out[k] = v
    return out


def _track_minima(model, outs, minima: dict[str, float]) -> None:
    """Lower ``minima`` to the smallest value of every output ``model`` bounds."""
    for name, *_ in model.validity_bounds:
        if name in outs and np.size(outs[name].values):
            minima[name] = min(minima.get(name, math.inf), float(np.min(outs[name].values)))


def _check_validity(model, minima: dict[str, float], attrs: dict, values) -> None:
    """Record (``attrs["validity"]``) and warn
    ([`ModelValidityWarning`][recipdyn.errors.ModelValidityWarning]) when an output crossed the
    model's validity bound (where the bounds apply at ``values``)."""
    warning = validity_warning(model, minima) if model.validity_applies(values) else ""
    attrs["validity"] = warning or "ok"
    if warning:
        warnings.warn(warning, ModelValidityWarning, stacklevel=3)


def validity_warning(model, minima: dict[str, float]) -> str:
    """The warning text for the outputs whose minimum crossed the model's validity bound
    (empty when none did)."""
    out = []
    for name, unit, bound, why, instead in model.validity_bounds:
        low = minima.get(name)
        if low is not None and math.isfinite(low) and low < bound:
            out.append(f"{name} reaches {low:.4g} {unit} (< {bound:g}): {why}; use {instead}")
    return "; ".join(out)


#: The start-up a run summary leaves out: the first revolutions (forcing periods) after the
#: initial state, t < STARTUP_REVOLUTIONS * T. The initial state is a guess (the link aligned
#: with the load, the journal on the wall, at rest relative to the crank), not a state of the
#: steady motion, and the first impacts it causes belong to no steady motion. One revolution
#: is the shortest span that holds every crank angle once; a run recorded after
#: ``transient`` >= 1 revolutions has no start-up left. Measurements: docs/reliability.md.
STARTUP_REVOLUTIONS = 1.0


def _unit_suffix(unit: str) -> str:
    """``m/s**2`` -> ``_m_s2``: the unit as a suffix of a summary entry's name."""
    u = unit.replace("**", "").replace("/", "_").replace("*", "_").replace(" ", "")
    return f"_{u}" if u not in ("", "1") else ""


def _time_slice(ds: xr.Dataset, t_lo: float) -> xr.Dataset:
    """The samples at ``time >= t_lo`` and the events (``NAME_event`` dimensions with a
    ``NAME_time`` variable) there."""
    t = np.asarray(ds["time"].values, dtype=float)
    part = ds.isel(time=np.flatnonzero(t >= t_lo))
    for dim in [d for d in ds.dims if str(d).endswith("_event")]:
        tv = f"{str(dim)[: -len('_event')]}_time"
        if tv in ds:
            part = part.isel({dim: np.flatnonzero(np.asarray(ds[tv].values) >= t_lo)})
    return part


def summarize(m: Model, values: Mapping[str, Any], ds: xr.Dataset,
              validity: str = "ok") -> dict[str, Any]:  # fmt: skip
    """The run summary of a record ``ds`` of model ``m`` (what `simulate` writes into
    the attributes and the CLI prints): the model's `Model.run_summary` over the steady
    state, the start-up separately, verdicts withheld outside
    the model's validity.

    * Steady state: the samples after `STARTUP_REVOLUTIONS` forcing periods from the
      initial state (all of them for a record that starts later, for an autonomous system or a
      map, and -- said in ``summary_interval`` -- for a record with less than one period after
      the start-up).
    * Start-up: ``startup_peak_abs_<signal>``, the largest magnitude of the model's vibration
      signal over the start-up part of the record, and ``startup_revolutions``.
    * Verdicts (`recipdyn.model.protocol.Model.summary_verdicts`): when ``validity``
      is not ``"ok"`` (the run left the model's validity) their value is ``"invalid"`` and
      ``<verdict>_reason`` says why and which model to use.
    """
    period = m.period(values) if m.kind == "ode" else None
    vib, unit = m.vibration()
    part, interval, startup = ds, "the whole record", None
    if period and "time" in ds.dims and ds.sizes["time"] > 1:
        t = np.asarray(ds["time"].values, dtype=float)
        t_cut = STARTUP_REVOLUTIONS * float(period)
        dt = float(t[1] - t[0])
        if t[0] < t_cut - 0.5 * dt:  # the record holds (part of) the start-up
            if t[-1] - t_cut >= float(period) - 1.5 * dt:  # at least a period after it
                part = _time_slice(ds, t_cut)
                startup = ds.isel(time=np.flatnonzero(t < t_cut))
                interval = (f"steady state: t >= {t_cut:.6g} s (after the first "
                            f"{STARTUP_REVOLUTIONS:g} revolution(s) of the start-up, reported "
                            "as startup_*)")  # fmt: skip
            else:
                interval = (f"the whole record, start-up included: less than one revolution "
                            f"after the first {STARTUP_REVOLUTIONS:g} (raise --revolutions or "
                            "--transient)")  # fmt: skip
        else:
            interval = "steady state: the whole record (after the transient)"
    out: dict[str, Any] = dict(m.run_summary(values, part)) if part.sizes.get(
        "time", 0) else {}  # fmt: skip
    if period and vib in ds:
        out.setdefault(f"peak_abs_{vib}{_unit_suffix(unit)}",
                       float(np.nanmax(np.abs(part[vib].values))))  # fmt: skip
        if startup is not None and startup.sizes["time"]:
            out[f"startup_peak_abs_{vib}{_unit_suffix(unit)}"] = float(
                np.nanmax(np.abs(startup[vib].values)))  # fmt: skip
            out["startup_revolutions"] = STARTUP_REVOLUTIONS
    out["summary_interval"] = interval
    if validity != "ok" and any(key in out for key in m.summary_verdicts):
        withheld: dict[str, Any] = {}
        for key, value in out.items():  # the reason right after its verdict
            if key in m.summary_verdicts:
                withheld[key] = "invalid"
                withheld[f"{key}_reason"] = (f"withheld: the run left the model's validity "
                                             f"({validity})")  # fmt: skip
            else:
                withheld[key] = value
        out = withheld
    return out


def _check_law_range(m: Model, values, ds: xr.Dataset, attrs: dict) -> None:
    """Record (``attrs["law_range"]``) and warn (`LawRangeWarning`) when the run used
    a law of the model beyond its stated range (over the whole record, start-up included)."""
    msg = m.law_range(values, ds) if ds.sizes.get("time", 0) else ""
    attrs["law_range"] = msg or "ok"
    if msg:
        warnings.warn(msg, LawRangeWarning, stacklevel=3)


def simulate(
    params: Mapping[str, Any] | Any | None = None,
    *,
    # the values of DEFAULT_SETTINGS (defaults.SIMULATION), written out so that the signature
    # and the API reference show them (tests/test_docs.py checks they agree)
    revolutions: float = 10.0,
    transient: float = 0.0,
    fs: float = 10_000.0,
    method: str = "dop853",
    rtol: float = 1e-10,
    atol: float = 1e-12,
    h: float | None = None,
    progress: bool = False,
    max_memory: float | None = None,
    model: str | Model | None = None,
    out: str | None = None,
    columns: list[str] | None = None,
    float32: bool = False,
    compress: bool = False,
    summary: bool = True,
    **overrides: Any,
) -> xr.Dataset:
    """Simulate a model (default: the compressor) and return its outputs as a Dataset.

    Every model goes the same way: its parameters are validated against its schema, its
    compiled system is integrated, its outputs (`recipdyn.model.protocol.Model.outputs`) are
    recorded with units, and its `recipdyn.model.protocol.Model.record_attrs` and every
    setting go into the attributes.

    Parameters
    ----------
    params : mapping or parameter dataclass, optional
        The model's parameter values by name or alias (default: its schema's defaults; for
        the compressor the paper's base case,
        [`paper_2d12`][recipdyn.model.parameters.paper_2d12]). A model's parameter dataclass
        (such as [`CompressorParams`][recipdyn.model.parameters.CompressorParams]) is taken
        field by field.
    revolutions : float
        Crank revolutions (forcing periods; time units for an autonomous system, iterations
        for a map) to record after the transient.
    transient : float
        Revolutions to integrate first and discard.
    fs : float
        Output sampling rate, Hz (samples come from the dense output at exact times, like a
        sensor; the integrator's own steps are independent of it).
    method : {"dop853", "rk4"}
        Adaptive Dormand-Prince 8(5,3) (default) or the paper's fixed-step RK4.
    rtol, atol : float
        DOP853 tolerances.
    h : float, optional
        RK4 step, s (default: 1/20000 of a forcing period).
    progress : bool
        Show a progress bar (it never changes the result).
    max_memory : float, optional
        Refuse runs estimated to need more memory than this, bytes (default: half of the memory
        available at the start).
    model : str or Model, optional
        A registered model
        ([`recipdyn.model.registry.get_model`][recipdyn.model.registry.get_model]: a name such as
        ``"duffing"``, a ``module:object`` or ``file.py:OBJ`` path); default the paper's
        compressor.
    out : str or Path, optional
        Stream the record to this file (``.nc`` or ``.zarr``) block by block as it is
        computed, so memory stays flat in run length; the returned Dataset is then opened
        lazily from the file. The samples are the same as in memory.
    columns : list of str, optional
        Keep only these output variables (default: all, and every state component).
    float32, compress : bool
        With ``out``: store the signals in single precision; compress NetCDF (zlib).
    summary : bool
        Compute the model's run summary and check the contact law's range into the attrs
        (default). False leaves both out (the signals are the same): for callers that read
        the signals only, such as a data set's records (a tenth of a record's time).
    **overrides
        Parameter overrides by name or alias, e.g. ``rc=0.5e-3``, ``clearance=0.5e-3``.

    Returns
    -------
    xarray.Dataset
        The model's outputs over ``time`` (s; ``iteration`` for a map), units in each
        variable's attrs; the compressor's: ``x, v, a`` (crosshead), ``theta1, theta2,
        theta_c, thetadot_c, thetaddot_c``, ``gas_force``, joint and guide forces. All
        parameters, assumptions, initial conditions, solver settings and statistics, the
        model's spec and the package version in the Dataset's attrs.

    Raises
    ------
    ParameterError
        Bad parameters or settings, or a run that would not fit in memory.
    IntegrationError
        If the integrator fails; its ``dataset`` attribute holds the samples computed before
        the failure (nothing computed is lost) and ``partial`` the raw solution.
    recipdyn.errors.Interrupted
        On SIGINT/SIGTERM (between chunks of the integration); ``dataset`` holds the samples
        computed so far, with ``solver_status = "interrupted"``.

    Examples
    --------
    >>> import recipdyn
    >>> ds = recipdyn.simulate(rc=1e-3, d=1e-3, omega=20.0, revolutions=2)  # doctest: +SKIP
    >>> float(ds.a.max())  # doctest: +SKIP
    """
    m = get_model(model)
    values = model_values(m, params, overrides)
    m = m.configured(values)  # the declarations of the configuration the values choose
    _check_run_settings(revolutions, transient, fs, method, rtol, atol)
    spec = model_spec(m)
    settings = dict(revolutions=revolutions, transient=transient, fs=fs, method=method,
                    rtol=rtol, atol=atol, h=h)  # fmt: skip
    if m.kind == "map":
        return _simulate_map(m, values, settings, max_memory, spec, out, columns, float32,
                             compress)  # fmt: skip
    period = m.period(values)
    T = float(period) if period else 1.0  # one "revolution" = one forcing period
    if method == "rk4" and h is None:
        h = T / RK4_STEPS_PER_REVOLUTION
    top = T if period else math.inf
    if h is not None and not (is_number(h) and math.isfinite(h) and 0 < h <= top):
        where = f"{top:g}] (one revolution)" if period else "inf)"
        raise ParameterError(f"h = {h!r} s out of range; allowed: (0, {where}")
    n_float = revolutions * T * fs
    held = min(n_float, 2 * STREAM_BLOCK) if out is not None else n_float  # streamed: a block
    check_memory(
        estimate_memory(held), f"simulate ({n_float:.3g} samples: {revolutions:g} revolutions "
        f"at fs = {fs:g} Hz)", "reduce --revolutions or --fs", max_memory,
    )  # fmt: skip
    system = m.system(values)
    y0 = m.initial_state(values)
    states = m.states(values)
    t_start = transient * T
    # the output names, from one sample: columns are checked, and the disk, before any work
    every = _names(m.outputs(values, np.array([t_start]), y0[None, :]), states)
    keep = _columns(columns, every)
    if out is not None:
        _check_disk(out, n_float, len(keep) + 2, float32)  # + time, revolution
    events = m.events(values)
    if len(events) > 1:
        raise ParameterError(f"model {m.name!r} declares {len(events)} events; the integrator "
                             "locates one event function")  # fmt: skip
    ev_kw: dict[str, Any] = {}
    if events:
        e = events[0]
        ev_kw = dict(event=e.function, event_direction=e.direction, event_action=e.action,
                     reset=e.reset)  # fmt: skip
    n = int(math.floor(n_float + 1e-9)) + 1
    # the last sample may lie a rounding error past the run's end (n_float a hair below a
    # whole number of samples): the run ends at it, not before
    t_end = max(t_start + revolutions * T, t_start + (n - 1) / fs)
    # streamed: the output times are made block by block (never all 8 bytes x n at once)
    t_eval = UniformGrid(t_start, fs, n) if out is not None else t_start + np.arange(n) / fs
    t_last = t_start + (n - 1) / fs  # the last sample: events after it are not recorded
    bar = None
    cb = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=100, unit="%", desc="simulate", leave=False)

        def cb(frac, _bar=bar):
            _bar.update(round(100 * frac) - _bar.n)

    t0 = time.perf_counter()
    failure: IntegrationError | Interrupted | None = None
    # Chunks let Ctrl-C stop a long run between chunks (the rest is kept) and drive the
    # progress bar; they never change the result (see recipdyn.integrate).
    chunks = max(1, min(1000, int(math.ceil(transient + revolutions))))
    writer = sink = None
    minima: dict[str, float] = {}
    tail: list[xr.Dataset] = []  # the last two blocks: the run summary's last revolution
    if out is not None:
        from .io import StreamWriter

        writer = StreamWriter(out, float32=float32, compress=compress)

        def sink(t, y):
            outs = _with_states(m.outputs(values, t, y), states, y)
            _track_minima(m, outs, minima)
            rec = _record(outs, t, period, every)  # all outputs: the model's run summary
            writer.append(rec[keep])
            tail[:] = [*tail[-1:], rec]

    try:
        sol = integrate(
            system, y0, (0.0, t_end), method=method, rtol=rtol, atol=atol, h=h, t_eval=t_eval,
            chunks=chunks, progress=cb, sink=sink, block=STREAM_BLOCK, **ev_kw,
        )  # fmt: skip
    except IntegrationError as exc:  # keep what was computed: the partial record
        failure, sol = exc, exc.partial
    except Interrupted as exc:
        failure, sol = exc, exc.partial
    except BaseException:  # anything else: no half-written store is left behind
        if writer is not None:
            writer.discard()
        raise
    finally:
        if bar is not None:
            bar.close()
    wall = time.perf_counter() - t0
    if writer is None:
        try:
            outs = _with_states(m.outputs(values, sol.t, sol.y), states, sol.y)
        except ParameterError as exc:  # the state left the feasible geometry before failing
            raise IntegrationError(f"{failure or ''} {exc}".strip(), sol) from None
        if sol.t.size == 0 and failure is None:
            raise ParameterError("simulate produced no samples: raise --revolutions or --fs")
        full = _record(outs, sol.t, period, every)  # (the run summary reads every output)
        ds = full[keep]
        _track_minima(m, outs, minima)
    attrs: dict[str, Any] = {
        "title": f"recipdyn simulation: {m.name}",
        "recipdyn_version": __version__,
        "created": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "model": m.name,
        "model_name": m.name,
        "model_spec": spec,
        **m.record_attrs(values, y0),
        "solver_method": method,
        "solver_rtol": rtol,
        "solver_atol": atol,
        "solver_h": h if h is not None else "adaptive",
        "solver_nfev": sol.nfev,
        "solver_nsteps": sol.nsteps,
        "solver_nreject": sol.nreject,
        "solver_status": sol.message,
        "solver_wall_time_s": wall,
        "revolutions": revolutions,
        "transient_revolutions": transient,
        "sampling_rate_hz": fs,
        "period": period if period else "none (autonomous: revolutions count time units)",
        # the state whose turns give an autonomous record its section (a motor's crank angle)
        **({"section_angle": angle} if (angle := m.section_angle(values)) else {}),
        **{f"min_{name}{_unit_suffix(unit)}": minima.get(name, float("nan"))
           for name, unit, *_ in m.validity_bounds},
        "columns": "all" if columns is None else ",".join(keep),
        "storage": "float32" if (float32 and writer is not None) else "float64",
        "vibration_signal": m.vibration()[0],  # what features and compare read by default
    }  # fmt: skip
    from .config import dump_config  # pydantic: imported when a run is recorded

    attrs["config_toml"] = dump_config(m, values, settings, spec=spec)
    _check_validity(m, minima, attrs, values)
    events_ds = _events(m, values, events[0], sol, t_start, t_last) if events else None
    if events_ds is not None:
        attrs.update(events_ds.attrs)  # what each event is
    recent = full if writer is None else xr.concat(tail, "time") if tail else None
    if summary and recent is not None and recent.sizes.get("time", 0):
        if events_ds is not None:
            recent = recent.merge(events_ds)
        _check_law_range(m, values, recent, attrs)
        attrs.update(clean_attrs(summarize(m, values, recent, attrs["validity"])))
    if writer is not None:
        from .io import open_record

        written = writer.finish(clean_attrs(attrs), partial=failure is not None,
                                extra=events_ds)  # fmt: skip
        if written is None and failure is None:
            raise ParameterError("simulate produced no samples: raise --revolutions or --fs")
        ds = open_record(written) if written is not None else xr.Dataset(attrs=clean_attrs(attrs))
        if failure is not None:
            failure.kept_path = written
    elif events_ds is not None:
        ds = ds.merge(events_ds)
    ds.attrs = clean_attrs(attrs)
    if failure is not None:
        failure.dataset = ds  # the samples before the failure, with all attributes
        raise failure
    return ds


def model_values(m: Model, params: Any, overrides: Mapping[str, Any]) -> dict[str, Any]:
    """``m``'s validated parameter values from ``params`` (a mapping by name or alias, a
    parameter dataclass taken field by field, or None for the defaults) and ``overrides``."""
    if params is not None and not isinstance(params, Mapping):
        params = m.parameters(params)  # a parameter dataclass (valid as a whole)
    return m.parameters({**(params or {}), **overrides})


def _names(outs: Mapping[str, Any], states) -> list[str]:
    """Every output name, then the state components no output already is."""
    return [*outs, *(s for s, _ in states if s not in outs)]


def _with_states(outs: dict[str, Signal], states, y: np.ndarray) -> dict[str, Signal]:
    """The outputs and every state component (a record always holds the whole state, so
    that analyze can rebuild the trajectory)."""
    outs = dict(outs)
    for i, (name, unit) in enumerate(states):
        if name not in outs:
            outs[name] = Signal(np.asarray(y[:, i]), unit, name)
    return outs


def _simulate_map(m: Model, values, settings, max_memory, spec, out, columns, float32,
                  compress) -> xr.Dataset:  # fmt: skip
    """`simulate` for a map: iterated, not integrated (a record over ``iteration``)."""
    from .config import dump_config  # pydantic: imported when a run is recorded
    from .model.reference.systems import iterate

    n0, n = int(round(settings["transient"])), max(1, int(round(settings["revolutions"])))
    check_memory(estimate_memory(n), f"simulate ({n} iterations)", "fewer iterations",
                 max_memory)  # fmt: skip
    y0 = m.initial_state(values)
    y = iterate(m.system(values), y0, n, n_transient=n0)
    t = np.arange(n0 + 1, n0 + n + 1, dtype=float)
    outs = _with_states(m.outputs(values, t, y), m.states(values), y)
    keep = _columns(columns, list(outs))
    ds = xr.Dataset(
        {k: ("iteration", outs[k].values, {"units": outs[k].units,
                                           "long_name": outs[k].long_name}) for k in keep},
        coords={"iteration": ("iteration", t, {"units": "1", "long_name": "iteration"})},
    )  # fmt: skip
    ds.attrs = clean_attrs({
        "recipdyn_version": __version__,
        "created": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "model": m.name, "model_name": m.name, "model_spec": spec,
        **m.record_attrs(values, y0),
        "revolutions": settings["revolutions"], "transient_revolutions": settings["transient"],
        "period": "none (a map: revolutions count iterations)",
        "solver_method": "map iteration", "solver_status": "reached the end",
        "columns": "all" if columns is None else ",".join(keep),
        "config_toml": dump_config(m, values, settings, spec=spec),
    })  # fmt: skip
    if out is not None:
        from .io import write_dataset

        if float32:
            ds = ds.astype({k: np.float32 for k in ds.data_vars})
        write_dataset(ds, out)
    return ds


#: Samples per block when a record is streamed to a file (memory ~ 25 signals x 8 B each).
STREAM_BLOCK = 1 << 16


def _check_disk(out, n_samples: float, n_vars: int, float32: bool) -> None:
    """Refuse a streamed run whose record cannot fit on the output's disk."""
    import shutil
    from pathlib import Path

    from .resources import format_bytes

    need = n_samples * n_vars * (4 if float32 else 8)
    folder = Path(out).resolve().parent
    while not folder.exists():
        folder = folder.parent
    free = shutil.disk_usage(folder).free
    if need > free:
        raise ParameterError(
            f"simulate ({n_samples:.3g} samples) needs ~{format_bytes(need)} of disk for {out}; "
            f"{format_bytes(free)} free: reduce --revolutions or --fs, or keep fewer --columns"
        )


def _columns(columns, names: list[str]) -> list[str]:
    """The outputs to keep: ``columns`` (checked against ``names``), default all."""
    if columns is None:
        return names
    cols = [c.strip() for c in ([columns] if isinstance(columns, str) else columns)]
    bad = [c for c in cols if c not in names]
    if bad or not cols:
        raise ParameterError(f"columns {bad or cols}: unknown; allowed: {', '.join(names)}")
    return cols


def _record(outs, t, period: float | None, keep: list[str]) -> xr.Dataset:
    """The Dataset of one block (or the whole run) of a model's outputs (with the crank
    revolutions, or forcing periods, as a second coordinate when the model has a period)."""
    data_vars = {k: ("time", outs[k].values, {"units": outs[k].units,
                                              "long_name": outs[k].long_name})
                 for k in keep}  # fmt: skip
    coords = {"time": ("time", t, {"units": "s", "long_name": "time"})}
    if period:
        coords["revolution"] = ("time", t / float(period),
                                {"units": "1", "long_name": "crank revolutions"})  # fmt: skip
    return xr.Dataset(data_vars, coords=coords)


def _check_run_settings(revolutions, transient, fs, method, rtol, atol) -> None:
    for name, val, lo in (("revolutions", revolutions, 0.0), ("fs", fs, 0.0)):
        if not (is_number(val) and math.isfinite(val) and val > lo):
            raise ParameterError(f"{name} = {val!r} out of range; allowed: > {lo:g}")
    if not (is_number(transient) and math.isfinite(transient) and transient >= 0):
        raise ParameterError(f"transient = {transient!r} out of range; allowed: >= 0")
    if method not in METHODS:
        raise ParameterError(f"method = {method!r}; allowed: {', '.join(METHODS)}")
    check_tolerances(rtol, atol)


def _events(m: Model, values, e, sol, t_start: float, t_last: float) -> xr.Dataset:
    """The event records of the recorded interval (first to last sample), over an
    ``NAME_event`` dimension."""
    keep = (sol.t_events >= t_start) & (sol.t_events <= t_last)
    dim = f"{e.name}_event"
    data = {f"{e.name}_time": (dim, sol.t_events[keep], {"units": m.time_unit,
            "long_name": f"time of {e.name}: {e.description}"})}  # fmt: skip
    for i, (s, u) in enumerate(m.states(values)):
        data[f"{e.name}_{s}"] = (dim, sol.y_events[keep, i], {"units": u,
                                 "long_name": f"{s} at {e.name}"})  # fmt: skip
        if e.action == "reset":
            data[f"{e.name}_{s}_after"] = (dim, sol.y_events_after[keep, i], {"units": u,
                                           "long_name": f"{s} after {e.name}"})  # fmt: skip
    # built at once: one Dataset of ~50 variables (adding them one by one merged each time)
    ds = xr.Dataset(data)
    ds.attrs[f"events_{e.name}"] = f"{e.description} (direction {e.direction}, {e.action})"
    return ds
