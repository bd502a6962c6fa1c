"""``recipdyn simulate`` and ``recipdyn run``."""

from __future__ import annotations

import warnings
from pathlib import Path

import typer

from ..defaults import SIMULATION
from ..io import DATASET_FORMATS
from .common import app, phase, refused_leaves_nothing, report, with_json

_SET_HELP = "Set any parameter: NAME=VALUE with units, e.g. --set m3='40 kg' (repeatable)."
_MEM_HELP = "Refuse runs estimated to need more memory than this, e.g. '4 GB' (default: half " \
    "of the available memory)."  # fmt: skip


def _collect_model(model, rc, d, omega, sets, config, *, load: bool = True):
    """(model, parameters, simulation settings) from the options and an optional config.

    The parameters are a dict of the model's validated values, for every model;
    ``--rc/--d/--omega`` apply to every model whose schema has them. The default model's
    values are validated by its schema module, without loading its compiled code; with
    ``load=False`` its model is returned as ``None`` (``get_model()`` loads it), so that bad
    input is answered before heavy imports. Another model's schema lives beside its kernels:
    naming one loads them.
    """
    import dataclasses

    from ..config import CHOICES, build_params, model_values, read_config
    from ..errors import ParameterError
    from ..model.parameters import configures
    from ..model.protocol import UnknownParameterError
    from ..model.registry import DEFAULT_MODEL, get_model, is_spec
    from ..units import parse_assignment

    cfg = read_config(config) if config is not None else None
    spec = model or (cfg.model if cfg is not None else None)
    m = None if spec in (None, DEFAULT_MODEL) else get_model(spec)
    name = DEFAULT_MODEL if m is None else m.name
    settings = cfg.simulation.resolved() if cfg is not None else {}
    values = dict(cfg.params) if cfg is not None else {}
    options = {n: v for n, v in (("rc", rc), ("d", d), ("omega", omega)) if v is not None}
    lacking = [n for n in options if m is not None and n not in m.schema]
    if lacking:  # the crank options belong to every model whose schema has them
        raise ParameterError(f"{', '.join('--' + n for n in lacking)}: model {name!r} has no "
                             f"such parameter (see 'recipdyn models {name}')")  # fmt: skip
    values.update(options)  # the config, then the options, then --set (last wins)
    for item in sets or []:
        k, v = parse_assignment(item)
        values[k] = v
    if m is None and (any(is_spec(values.get(k)) for k in CHOICES) or configures(values)):
        # a component from a user's file, or a selector choosing another configuration
        # (crank_joint = contact ...): the model's schema at these values validates them
        m = get_model(DEFAULT_MODEL)
    try:
        params = (dataclasses.asdict(build_params(values)) if m is None
                  else model_values(m, values))  # fmt: skip
    except UnknownParameterError as exc:
        if m is not None or exc.suggestions:
            raise _unknown_parameter(exc, name) from None
        m = get_model(DEFAULT_MODEL)  # a parameter of another configuration: the model says
        try:  # which selector value enables it
            params = model_values(m, values)
        except UnknownParameterError as exc2:
            raise _unknown_parameter(exc2, name) from None
    if m is None and load:
        m = get_model(DEFAULT_MODEL)
    return m, params, settings


def _unknown_parameter(exc, model_name: str):
    """The error for a parameter ``model_name`` does not have: the close names if it looks
    misspelt, else the other models that have it, else where to look."""
    from ..errors import ParameterError
    from ..model.registry import models_with_parameter

    if exc.suggestions:
        return ParameterError(f"{exc} (model {model_name!r})")
    others = [n for n in models_with_parameter(exc.name) if n != model_name]
    if others:
        return ParameterError(
            f"{exc.name!r} is not a parameter of model {model_name!r}; it belongs to "
            f"{', '.join(repr(n) for n in others)}: add --model {others[0]} (its "
            f"parameters: recipdyn models {others[0]})"
        )
    return ParameterError(f"unknown parameter {exc.name!r} of model {model_name!r}; its "
                          f"parameters: recipdyn models {model_name}")  # fmt: skip


#: The integration methods (``recipdyn.integrate.METHODS``, whose module loads numba; a test
#: keeps the two the same).
METHOD_NAMES = ("dop853", "rk4")


def check_settings(kw: dict, period: float | None) -> None:
    """Refuse run settings out of range before anything is loaded or written (the library
    checks them again; these are its ranges)."""
    import math

    from ..defaults import ATOL_RANGE, RTOL_RANGE
    from ..errors import ParameterError, is_number

    for name in ("revolutions", "fs"):
        v = kw[name]
        if not (is_number(v) and math.isfinite(v) and v > 0):
            raise ParameterError(f"{name} = {v!r} out of range; allowed: > 0")
    v = kw["transient"]
    if not (is_number(v) and math.isfinite(v) and v >= 0):
        raise ParameterError(f"transient = {v!r} out of range; allowed: >= 0")
    if kw["method"] not in METHOD_NAMES:
        raise ParameterError(f"method = {kw['method']!r}; allowed: {', '.join(METHOD_NAMES)}")
    for name, (lo, hi) in (("rtol", RTOL_RANGE), ("atol", ATOL_RANGE)):
        v = kw[name]
        if not (is_number(v) and math.isfinite(v) and lo <= v <= hi):
            raise ParameterError(f"{name} = {v!r} out of range; allowed: [{lo:g}, {hi:g}]")
    h = kw.get("h")
    if h is not None:
        top = period if period else math.inf
        if not (is_number(h) and math.isfinite(h) and 0 < h <= top):
            where = f"{top:g}] (one revolution)" if period else "inf)"
            raise ParameterError(f"h = {h!r} s out of range; allowed: (0, {where}")


def max_memory_bytes(text: str | None) -> float | None:
    """``--max-memory`` in bytes (a quantity such as '4 GB', or a number of bytes)."""
    if text is None:
        return None
    from ..units import to_si

    return to_si("max_memory", text, unit="byte")


def keep_partial(exc, out: Path) -> Path | None:
    """Write the partial record an interrupted or failed simulation carries, next to ``out``."""
    from ..io import write_dataset

    if getattr(exc, "kept_path", None) is not None:  # a streamed run kept it already
        return exc.kept_path
    ds = getattr(exc, "dataset", None)
    if ds is None or ds.sizes.get("time", 0) == 0:
        return None
    path = out.with_name(out.stem + ".partial" + out.suffix)
    return write_dataset(ds, path)


#: Runs with more samples than this are streamed to their file by default.
STREAM_AUTO = 1e6
#: A streamed run's figure and summary use at most this many of its last samples.
FIGURE_SAMPLES = 500_000


#: CPU seconds the first run of a configuration spends compiling (its kernels before the run,
#: its outputs' when it records them), by what compiles: the integrator loop (once for every
#: model), and the model's right-hand side by its module, whose name (a generated glue's: its
#: configuration) holds the parts that add up. Measured with numba 0.68 on a 2-core machine,
#: one configuration after another into one empty cache: `time.process_time` of
#: `recipdyn.integrate.prepare` plus that of a first 0.05-revolution `recipdyn.simulate` less
#: a second one's (2026-12, this branch): loop 8.6; massless link 2.7 (with a motor 3.2);
#: its dynamic valves 54.7; contact pins 12.9 (both pins 16.1, a motor 11.2, the worn guide
#: 48.2, the dynamic valves 127.1); compressor-guide's own kernel 21.5. The wall time is this
#: on an idle machine; beside six other busy processes it was 3 to 9 times longer (the
#: contact pins with valves: 457 s).
COMPILE_CPU = {"recipdyn.integrate.kernels": 9.0, "recipdyn.model.compressor_valves": 55.0,
               "recipdyn.model.compressor_guide": 22.0, "recipdyn_assembled_compressor_": 3.0,
               "recipdyn_assembled_contact_": 13.0}  # fmt: skip
#: What a part of a contact glue's configuration adds (its name holds them).
COMPILE_CPU_PARTS = {"_valves_": 115.0, "_guide_": 35.0, "contact_both_": 3.0,
                     "contact_crosshead_": 3.0}  # fmt: skip


def compile_seconds(kernels: list[str]) -> float | None:
    """The CPU seconds a first run spends compiling ``kernels`` (``module.function`` names
    as `recipdyn.integrate.compiles` gives them; a module's compile counted once), from
    `COMPILE_CPU`; None if one is not among the measured ones (another model's)."""
    total = 0.0
    for module in {k.rpartition(".")[0] for k in kernels}:
        if module.startswith("recipdyn.model.joints."):  # (a pin's event: with its glue)
            continue
        base = next((v for k, v in COMPILE_CPU.items() if module.startswith(k)), None)
        if base is None:
            return None
        total += base
        if module.startswith("recipdyn_assembled_contact_"):
            total += sum(v for k, v in COMPILE_CPU_PARTS.items() if k in module)
    return total


def _about(seconds: float) -> str:
    return f"~{seconds:.0f} s" if seconds < 90 else f"~{seconds / 60:.0f} min"


def compile_note(name: str, configuration: str, kernels: list[str]) -> str:
    """The line said before a configuration's kernels are compiled: what, how long (CPU
    time, `COMPILE_CPU`), that it happens once."""
    secs = compile_seconds(kernels)
    took = (f"{_about(secs)} of CPU on a 2-core machine, longer while other programs share "
            "its cores" if secs else "a few seconds to a few minutes")  # fmt: skip
    what = f"{name} ({configuration})" if configuration else name
    return f"compiling the kernels of {what}: {took}; once per configuration, later runs " \
        "load them ('recipdyn warmup' compiles ahead)..."  # fmt: skip


def configuration(m, params) -> str:
    """The choices of ``params`` away from the model's defaults (``crosshead_joint =
    contact``): what a configuration's compiled kernels depend on, as text."""
    schema = m.configured(params).schema
    chosen = [p for p in schema
              if p.choices is not None and params.get(p.name, p.default) != p.default]  # fmt: skip
    return ", ".join(f"{p.name} = {params[p.name]}" for p in chosen)


def _prepare(m, params, method: str) -> None:
    """Load the compiled code a run needs, or compile it (said before, with its estimate)."""
    from ..integrate import compiles, prepare

    if m.kind == "map":  # iterated, not integrated: nothing to prepare
        return
    system = m.system(params)
    todo = compiles(system, method)
    if todo is None:  # (numba's cache cannot be read: either may happen)
        label = "preparing compiled kernels (compiling them on a first run)"
    elif todo:
        typer.echo(compile_note(m.name, configuration(m, params), todo), err=True)
        label = "compiling kernels"
    else:
        label = "loading compiled kernels"
    with phase(label):
        prepare(system, method)


@app.command()
@with_json
def simulate(
    rc: str = typer.Option(None, "--rc", "--clearance", help="Radial clearance, e.g. '1 mm'."),
    d: str = typer.Option(None, "--d", "--subsidence", help="Crosshead subsidence, e.g. '1 mm'."),
    omega: str = typer.Option(None, "--omega", help="Crank speed, e.g. '20 rad/s', '191 rpm'."),
    sets: list[str] = typer.Option(None, "--set", help=_SET_HELP),
    config: Path = typer.Option(
        None, "--config", "-c", help="TOML config with \\[params] and \\[simulation] tables."
    ),
    revolutions: str = typer.Option(None, "--revolutions", "-n", help="Revolutions to record."),
    transient: str = typer.Option(None, "--transient", help="Revolutions to discard first."),
    fs: str = typer.Option(None, "--fs", help="Sampling rate, e.g. '10 kHz'."),
    method: str = typer.Option(None, "--method", help="dop853 (default) or rk4."),
    rtol: float = typer.Option(None, "--rtol", help="Relative tolerance (dop853)."),
    atol: float = typer.Option(None, "--atol", help="Absolute tolerance (dop853)."),
    h: str = typer.Option(None, "--h", help="RK4 step, e.g. '1e-5 s'."),
    out: Path = typer.Option(
        Path("out/simulation.nc"),
        "--out",
        "-o",
        help="Output: .nc (NetCDF), .csv, .mat (MATLAB) or .zarr.",
    ),
    figure: bool = typer.Option(True, "--figure/--no-figure", help="Also write a PNG figure."),
    progress: bool = typer.Option(True, "--progress/--no-progress"),
    max_memory: str = typer.Option(None, "--max-memory", help=_MEM_HELP),
    stream: bool = typer.Option(
        None,
        "--stream/--no-stream",
        help="Write the record block by block as it is computed "
        "(memory flat in run length; .nc/.zarr). Default: for runs over 10^6 samples.",
    ),
    columns: str = typer.Option(
        None, "--columns", help="Comma list of outputs to keep, e.g. 'x,v,a' (default all)."
    ),
    float32: bool = typer.Option(
        False, "--float32", help="Store signals in single precision (streamed runs)."
    ),
    compress: bool = typer.Option(
        False, "--compress", help="zlib-compress NetCDF (streamed runs)."
    ),
    model: str = typer.Option(
        None,
        "--model",
        help="A registered model (see 'recipdyn models') or module:object; "
        "default: the paper's compressor.",
    ),  # fmt: skip
    machine: Path = typer.Option(
        None,
        "--machine",
        help="A machine file (TOML: its shaft and drive, throws at their phase angles, stages, "
        "sensors; docs/machines.md): assembled into the model that runs.",
    ),
    dump_config: Path = typer.Option(
        None,
        "--dump-config",
        help="Write the full, commented TOML config of this run to the file ('-': print it) "
        "and stop; 'simulate -c FILE' runs it. A recorded run (.nc) is a config too.",
    ),
) -> None:
    """Simulate a model (default: the compressor); write the record and a figure.

    The record's format follows the extension of --out: .nc, .csv, .mat or .zarr."""
    from ..errors import ParameterError
    from ..units import to_si

    if machine is not None:
        if model is not None:
            raise ParameterError("--machine and --model: give one of them (a machine file is "
                                 "the model it describes)")  # fmt: skip
        model = str(machine)
    # everything is validated before anything heavy is imported or any file written
    m, params, settings = _collect_model(model, rc, d, omega, sets, config, load=False)
    kw = {**SIMULATION, **settings}
    for name, val in (("revolutions", revolutions), ("transient", transient), ("fs", fs),
                      ("h", h)):  # fmt: skip
        if val is not None:
            kw[name] = to_si(name, val)
    for name, val in (("method", method), ("rtol", rtol), ("atol", atol)):
        if val is not None:
            kw[name] = val
    # the forcing period bounds the RK4 step (the library checks it again for the default
    # model, whose kernels are not loaded yet)
    period = None if m is None or m.kind == "map" else m.period(params)
    check_settings(kw, period)
    limit = max_memory_bytes(max_memory)
    if limit is not None and not limit > 0:
        raise ParameterError(f"max_memory = {max_memory!r}; allowed: > 0")
    note = subsidence_note(params)
    if note:
        typer.echo(f"warning: {note}", err=True)
    if dump_config is not None:
        return _dump_config(m, params, kw, dump_config)
    if out.suffix.lower() not in DATASET_FORMATS:
        allowed = ", ".join(f"{k} ({v})" for k, v in DATASET_FORMATS.items())
        raise ParameterError(f"output {out}: unknown extension {out.suffix or '(none)'!r}; "
                             f"allowed: {allowed}")  # fmt: skip
    from ..io import pandas_without_pyarrow

    pandas_without_pyarrow()  # it writes no Parquet: 34 MB less (docs/reliability.md)
    from ..model.registry import get_model

    m = m or get_model()  # every input is valid: the model's module may load now
    period = m.period(params) if m.kind != "map" else None
    check_settings(kw, period)  # the RK4 step against the default model's period too
    n_samples = kw["revolutions"] * (period or 1.0) * (kw["fs"] if m.kind != "map" else 1.0)
    if stream is None:
        stream = n_samples > STREAM_AUTO and out.suffix.lower() in (".nc", ".zarr")
    extra = {}
    if columns is not None:
        extra["columns"] = [c for c in columns.split(",") if c.strip()]
    if stream:
        extra.update(out=out, float32=float32, compress=compress)
    elif float32 or compress:
        raise ParameterError("--float32/--compress apply to streamed runs: add --stream")
    _check_resources(out, n_samples, stream, float32, extra.get("columns"), limit)
    with refused_leaves_nothing(out):
        _run(m, params, kw, out, stream, extra, limit, figure, progress)


#: A crosshead subsidence beyond this fraction of the crank radius is warned about.
SUBSIDENCE_FRACTION = 0.1


def subsidence_note(params) -> str | None:
    """Why a subsidence ``d`` is implausible for a worn crosshead, or None.

    Subsidence is wear of the crosshead shoes and guide: tenths of a millimetre to a few
    millimetres (Xiao et al. 2017 go to 5 mm = 0.04 r on the 2D12's r = 120 mm). Beyond
    `SUBSIDENCE_FRACTION` of the crank radius the mechanism is an offset (desaxe)
    slider-crank by design, not a worn one: the equations still hold (for the compressor to
    |d| < l - r - rc, where the rod can no longer reach the crosshead), so the run is warned,
    not refused.
    """
    d, r = params.get("d"), params.get("r")
    if d is None or not r or abs(d) <= SUBSIDENCE_FRACTION * r:
        return None
    reach = ""  # each model states its own reach in its schema (``recipdyn models NAME``)
    return (f"d = {1e3 * d:g} mm is {abs(d) / r:.2g} crank radii: a crosshead subsidence (worn "
            f"shoes or guide) is at most a few mm (the paper's largest: 5 mm = 0.04 r); above "
            f"{SUBSIDENCE_FRACTION:g} r = {1e3 * SUBSIDENCE_FRACTION * r:g} mm this is an offset "
            f"slider-crank, not a worn machine{reach}")  # fmt: skip


def _dump_config(m, params, kw: dict, dump_config: Path) -> None:
    """``--dump-config``: the run's full TOML config, to a file or ('-') standard output."""
    from ..config import dump_config as dump
    from ..io import write_text
    from ..model.registry import get_model, model_spec

    m = m or get_model()
    text = dump(m, params, kw, spec=model_spec(m))
    if str(dump_config) == "-":
        typer.echo(text, nl=False)
    else:
        write_text(dump_config, text)
        typer.echo(f"wrote {dump_config} (run it with: recipdyn simulate -c {dump_config})")


def _check_resources(out: Path, n_samples: float, stream: bool, float32: bool, columns,
                     limit: float | None) -> None:  # fmt: skip
    """Refuse a run that cannot fit in memory or on its disk, before its kernels are loaded
    (the library checks again with the exact number of outputs; this uses a lower bound)."""
    from ..resources import check_memory
    from ..simulate import STREAM_BLOCK, _check_disk, estimate_memory

    held = min(n_samples, 2 * STREAM_BLOCK) if stream else n_samples
    check_memory(estimate_memory(held), f"simulate ({n_samples:.3g} samples)",
                 "reduce --revolutions or --fs", limit)  # fmt: skip
    if stream:
        _check_disk(out, n_samples, (len(columns) if columns else 1) + 2, float32)


def _run(m, params, kw: dict, out: Path, stream: bool, extra: dict, max_memory, figure: bool,
         progress: bool) -> None:  # fmt: skip
    """Load the model and its compiled code, integrate, write the record, figure and summary."""
    from ..errors import Interrupted, LawRangeWarning, ModelValidityWarning
    from ..integrate import IntegrationError
    from ..io import check_output, save_figure, write_dataset
    from ..model.registry import get_model
    from ..simulate import _unit_suffix, summarize
    from ..simulate import simulate as run_sim

    out = check_output(out)
    m = m or get_model()
    _prepare(m, params, kw["method"])
    try:
        with warnings.catch_warnings():  # said once below, as a line of its own
            warnings.simplefilter("ignore", ModelValidityWarning)
            warnings.simplefilter("ignore", LawRangeWarning)
            ds = run_sim(params, progress=progress, max_memory=max_memory, model=m, **extra,
                         **kw)  # fmt: skip
    except (IntegrationError, Interrupted) as exc:
        kept = keep_partial(exc, out)
        if kept is not None:
            n = exc.dataset.sizes["time"]
            msg = f"partial record ({n} samples up to t = {exc.dataset.time.values[-1]:.6g} s) " \
                f"in {kept}"  # fmt: skip
            if isinstance(exc, Interrupted):
                exc.kept.append(msg + "; rerun the command to compute it all")
            else:
                typer.echo(f"kept: {msg}", err=True)
        raise
    if not stream:
        write_dataset(ds, out)
    params_used = {k.removeprefix("param_"): v for k, v in ds.attrs.items()
                   if k.startswith("param_") and not k.endswith(("_note", "_units"))}  # fmt: skip
    report(output=str(out), model=m.name, samples=dict(ds.sizes), parameters=params_used,
           validity=ds.attrs.get("validity", "ok"))  # fmt: skip
    validity = ds.attrs.get("validity", "ok")
    for key in ("validity", "law_range"):
        if ds.attrs.get(key, "ok") != "ok":
            typer.echo(f"warning: {ds.attrs[key]}", err=True)
    dim = "iteration" if "iteration" in ds.dims else "time"
    nfev = ds.attrs.get("solver_nfev")
    typer.echo(f"wrote {out}  ({m.name}: {ds.sizes[dim]} samples"
               + (f", nfev={nfev})" if nfev is not None else ")"))  # fmt: skip
    if stream and ds.sizes[dim] > FIGURE_SAMPLES:  # the figure shows the last part
        ds = ds.isel({dim: slice(-FIGURE_SAMPLES, None)})
        typer.echo(f"figure and summary: the last {FIGURE_SAMPLES} samples")
    from ..io import no_unused_scheduler

    with no_unused_scheduler():  # a streamed record's tail: read by dask, on no cluster
        ds = ds.load()
    values = m.values_from_record(ds.attrs)
    m = m.configured(values)
    if figure:
        from ..plotting import _mpl, mark_invalid, model_figure

        fig = mark_invalid(model_figure(ds), ds.attrs)
        typer.echo(f"wrote {save_figure(fig, out.with_suffix('.png'), dpi=130)}")
        _mpl().close(fig)
        _cycle_png(ds, out)
    summary = summarize(m, values, ds, validity) if ds.sizes.get(dim) else {}
    vib, unit = m.vibration()
    found = {}
    key = next((k for k in summary if k.startswith(f"peak_abs_{vib}")), None)
    if key is not None:
        found[f"peak_{vib}"] = summary.pop(key)
        typer.echo(f"peak |{vib}| = {found[f'peak_{vib}']:.4g} {unit}")
    for name, unit_, *_ in m.validity_bounds:  # the smallest value of each bounded output
        low = ds.attrs.get(f"min_{name}{_unit_suffix(unit_)}")
        if low is not None:
            found[f"min_{name}"] = float(low)
            typer.echo(f"min {name} = {float(low):.4g} {unit_}")
    _echo_summary(summary)
    report(**found, summary=summary)


def _cycle_png(ds, out: Path) -> None:
    """The compression-cycle figure (p-V, pressures, rod loads, valve lifts) of a run whose
    load is the compression cycle (ideal or dynamic valves)."""
    cycle = ds.attrs.get("param_load") == "cycle" or "y_suction_head" in ds.data_vars
    if cycle and {"p_head", "V_head", "theta1", "a", "gas_force"} <= set(ds.data_vars):
        from ..io import save_figure
        from ..plotting import _mpl, cycle_figure, mark_invalid

        fig = mark_invalid(cycle_figure(ds.load()), ds.attrs)
        png = save_figure(fig, out.with_name(out.stem + ".cycle.png"), dpi=110)
        _mpl().close(fig)
        typer.echo(f"wrote {png}")


def _echo_summary(summary: dict) -> None:
    for k, val in summary.items():
        typer.echo(f"  {k} = {val:.4g}" if isinstance(val, float) else f"  {k} = {val}")


@app.command()
def run(
    out: Path = typer.Option(Path("out"), "--out", "-o", help="Output folder."),
) -> None:
    """The paper's base case (rc = d = 1 mm, 20 rad/s, 10 revolutions) -> OUT/base_case.nc/.png."""
    from ..io import check_output, save_figure, write_dataset
    from ..model.parameters import paper_2d12
    from ..plotting import response_figure
    from ..simulate import simulate as run_sim

    check_output(out / "base_case.nc")
    ds = run_sim(paper_2d12(), revolutions=10, transient=0, progress=True)
    write_dataset(ds, out / "base_case.nc")
    fig = response_figure(ds, title="Base case: rc = 1 mm, d = 1 mm, omega = 20 rad/s")
    save_figure(fig, out / "base_case.png", dpi=130)
    typer.echo(f"wrote {out / 'base_case.nc'} and {out / 'base_case.png'}")
