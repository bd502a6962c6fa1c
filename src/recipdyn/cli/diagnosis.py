"""``recipdyn dataset``, ``recipdyn train`` and ``recipdyn diagnose``: fault diagnosis from
physics-generated records (docs/diagnosis.md)."""

from __future__ import annotations

import json
from pathlib import Path

import typer

from .common import app, refused_leaves_nothing, report, with_json


def _levels(text: str, name: str = "levels", example: str = "0.25,0.5,0.75,1"):
    from ..errors import ParameterError

    try:
        return tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise ParameterError(
            f"{name} = {text!r}; allowed: a comma list of severities in [0, 1], e.g. {example}"
        ) from None


def _snrs(text: str):
    from ..errors import ParameterError

    try:
        return tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise ParameterError(
            f"snr_range = {text!r}; allowed: two SNRs in dB, LO,HI, e.g. 10,40"
        ) from None


def _chain_range(text: str):
    from ..errors import ParameterError

    name, _, rest = text.partition("=")
    try:
        lo, hi = (float(v) for v in rest.split(","))
    except ValueError:
        raise ParameterError(
            f"chain_range = {text!r}; allowed: NAME=LO,HI, e.g. accelerometer.resonance_hz=800,6000"
        ) from None
    return name.strip(), lo, hi


def _machine_changes(machine: Path | None, sets: list[str] | None):
    """The machine of ``--machine`` and ``--set`` as its changes from the default machine; the
    names are checked before the model loads."""
    from ..diagnosis.dataset import _machine_pairs
    from ..diagnosis.machine import Machine, machine_from_file
    from ..units import parse_assignment

    changes = dict(parse_assignment(item) for item in sets or [])
    _machine_pairs(changes)  # only machine parameters
    m = machine_from_file(machine, changes) if machine is not None else Machine.of(changes)
    return m.pairs()


#: The data-set spec's fields by the option of `dataset` that sets them (for its refusals).
_SPEC_OPTIONS = {
    "n_conditions": "--conditions",
    "levels": "--levels",
    "snr_db": "--snr",
    "severity_range": "--severity-range",
    "severity_draws": "--draws",
    "snr_range": "--snr-range",
    "chain_spans": "--chain-range",
    "test_fraction": "--test-fraction",
    "revolutions": "--revolutions",
    "transient": "--transient",
    "classes": "--classes",
    "chain": "--chain",
    "seed": "--seed",
}


def _as_options(make, **kw):
    """``make(**kw)``, its refusal naming the command's options rather than the spec's fields
    (``--conditions = 0; allowed: ...`` for ``n_conditions``)."""
    import re

    from ..errors import ParameterError

    try:
        return make(**kw)
    except ParameterError as e:
        # a field's name where it is given a value or a bound ("n_conditions = 0",
        # "n_conditions >= 3", "classes: ..."), never the same word in the prose
        names = "|".join(sorted(_SPEC_OPTIONS, key=len, reverse=True))
        pattern = r"(?<![\w-])(" + names + r")(?=\s*(?:=|>=|<=|:))"
        raise ParameterError(re.sub(pattern, lambda m: _SPEC_OPTIONS[m[1]], str(e))) from None


@app.command()
def dataset(
    out: Path = typer.Option(Path("out/dataset"), "--out", "-o", help="Data set folder."),
    conditions: int = typer.Option(16, "--conditions", "-n", help="Operating conditions drawn."),
    levels: str = typer.Option("0.25,0.5,0.75,1", help="Severity levels in (0, 1]."),
    severity_range: str = typer.Option(
        None,
        "--severity-range",
        help="LO,HI: draw each fault record's severity uniformly in [LO, HI] (seeded) "
        "instead of the fixed --levels.",
    ),
    draws: int = typer.Option(
        None,
        help="With --severity-range: records of each class per condition (default: "
        "as many as --levels).",
    ),
    chain: str = typer.Option(
        "drawn",
        "--chain",
        help="drawn (default): every record's measurement chain drawn from the stated ranges "
        "(docs/sensors.md); fixed: the one chain of earlier versions (for comparisons).",
    ),
    snr: float = typer.Option(
        None, "--snr", help="Accelerometer SNR, dB, with --chain fixed (default 20)."
    ),
    snr_range: str = typer.Option(
        None,
        "--snr-range",
        help="LO,HI: draw each record's accelerometer SNR uniformly in [LO, HI] dB (seeded) "
        "instead of --snr for all.",
    ),
    chain_range: list[str] = typer.Option(
        None,
        "--chain-range",
        help="NAME=LO,HI: draw the chain parameter NAME (a range of docs/sensors.md, e.g. "
        "accelerometer.resonance_hz=800,6000) in [LO, HI] instead of its default range "
        "(repeatable; with --chain drawn).",
    ),
    revolutions: float = typer.Option(2.0, help="Revolutions recorded per record."),
    transient: float = typer.Option(1.0, help="Revolutions discarded first."),
    classes: str = typer.Option(None, help="Comma list of classes (default: all)."),
    test_fraction: float = typer.Option(0.25, help="Share of the conditions held out."),
    seed: int = typer.Option(0, help="Seed of the conditions, the split and the noise."),
    backend: str = typer.Option("processes", help="serial, processes or dask."),
    workers: int = typer.Option(None, help="Worker processes (default: all cores)."),
    dask_local: int = typer.Option(None, "--dask-local", help="Start a LocalCluster of N workers."),
    scheduler: str = typer.Option(None, help="Existing Dask scheduler, tcp://HOST:PORT."),
    resume: bool = typer.Option(False, help="Continue an interrupted data set in OUT."),
    force: bool = typer.Option(False, help="Overwrite an existing data set in OUT."),
    progress: bool = typer.Option(True, "--progress/--no-progress"),
    machine: Path = typer.Option(
        None,
        "--machine",
        help="The machine to simulate: a config TOML ('recipdyn simulate --dump-config FILE') "
        "or a recorded run (.nc); its geometry, masses, cylinder, valves, gas and nominal "
        "operating point (default: the diagnosis model's machine).",
    ),
    sets: list[str] = typer.Option(
        None,
        "--set",
        help="Set one machine parameter: NAME=VALUE with units, e.g. --set bore='300 mm' "
        "(repeatable; after --machine).",
    ),
) -> None:
    """Build a labelled data set of simulated, sensed records, split by operating condition.

    Fault classes x severities x operating conditions x sensor settings; signals in Zarr,
    features and labels in Parquet, a data card (docs/diagnosis.md)."""
    from ..diagnosis.classes import class_names
    from ..diagnosis.dataset import DatasetSpec, build_dataset, spec_machine

    kw = {} if classes is None else {"classes": tuple(c.strip() for c in classes.split(","))}
    if machine is not None or sets:
        kw["machine"] = _machine_changes(machine, sets)
    if severity_range is not None:
        kw["severity_range"] = _levels(severity_range, "severity_range", "0.1,1")
        kw["severity_draws"] = draws
    if snr_range is not None:
        kw["snr_range"] = _snrs(snr_range)
    if chain_range:
        kw["chain_spans"] = tuple(_chain_range(item) for item in chain_range)
    if snr is not None and chain != "fixed":
        from ..errors import ParameterError

        raise ParameterError(
            "snr: sets the fixed chain's accelerometer SNR; allowed with --chain fixed, or "
            "give the drawn chain's range with --snr-range LO,HI"
        )
    spec = _as_options(
        DatasetSpec,
        n_conditions=conditions,
        levels=_levels(levels),
        snr_db=20.0 if snr is None else snr,
        chain=chain,
        revolutions=revolutions,
        transient=transient,
        test_fraction=test_fraction,
        seed=seed,
        **kw,
    )
    if dask_local is not None or scheduler is not None:
        backend = "dask"
    with refused_leaves_nothing(out):
        build_dataset(
            out,
            spec,
            backend=backend,
            workers=workers,
            dask_local=dask_local,
            scheduler=scheduler,
            resume=resume,
            force=force,
            progress=progress,
        )
    typer.echo(
        f"wrote {out}/features.parquet, {out}/signals.zarr, {out}/datacard.md "
        f"({len(spec.classes)} of {len(class_names())} classes"
        + (f"; machine: {spec_machine(spec).text()}" if spec.machine else "")
        + f"); train a diagnoser on it: recipdyn train {out} -o {out}.skops"
    )


@app.command()
@with_json
def train(
    data: Path = typer.Argument(..., help="A data set folder ('recipdyn dataset')."),
    out: Path = typer.Option(Path("out/diagnoser.skops"), "--out", "-o", help="Model file."),
    seed: int = typer.Option(0, help="Seed of the learners and the calibration split."),
    report_dir: Path = typer.Option(
        None,
        "--report",
        help="Folder for the evaluation's tables and figures (default: next to the model).",
    ),
) -> None:
    """Train the fault class and severity diagnosers on a data set and evaluate them.

    Trained on the training conditions, evaluated on the held-out ones; writes the model
    (skops) and the evaluation's tables and figures."""
    from ..diagnosis.report import write_report
    from ..diagnosis.train import save
    from ..diagnosis.train import train as train_fn

    if out.suffix != ".skops":
        from ..errors import ParameterError

        raise ParameterError(f"--out {out}: use a .skops file")
    diag, ev = train_fn(data, seed=seed)
    with refused_leaves_nothing(out):
        save(diag, out)
    folder = report_dir or out.with_suffix("")
    paths = write_report(ev, diag, folder)
    f = ev["full"]
    typer.echo(
        f"accuracy {f['accuracy']:.3f} (moderate and severe {f['accuracy_moderate_severe']:.3f}), "
        f"ECE {f['ece']:.3f}, severity median relative error "
        f"{ev['severity_median_relative_error']:.3f}, 90 % interval coverage "
        f"{ev['severity_coverage']:.3f}; condition-only accuracy "
        f"{ev['condition_only']['accuracy']:.3f} (chance {ev['condition_only']['chance']:.3f})"
    )
    typer.echo(f"wrote {out}; evaluation in {paths[0].parent}")
    report(model=str(out), evaluation=ev)


@app.command()
@with_json
def recalibrate(
    model: Path = typer.Argument(..., help="A diagnoser file (.skops)."),
    data: list[Path] = typer.Argument(
        ..., help="Data sets of other conditions than the diagnoser's ('recipdyn dataset')."
    ),
    out: Path = typer.Option(..., "--out", "-o", help="The calibrated diagnoser (.skops)."),
) -> None:
    """Calibrate a diagnoser anew on data sets it was not trained on.

    Its out-of-domain refusal, physics consistency check and severity intervals are
    calibrated on every record of the DATA sets (other operating conditions, other drawn measurement
    chains), each cut to every channel set; its classifiers and regressors are kept. Reads
    an older diagnoser file too (format 3) and writes the current format."""
    from ..errors import ParameterError

    if out.suffix != ".skops":
        raise ParameterError(f"--out {out}: use a .skops file")
    from ..diagnosis.train import load, save
    from ..diagnosis.train import recalibrate as recalibrate_fn

    diag = recalibrate_fn(load(model, any_format=True), *data)
    with refused_leaves_nothing(out):
        save(diag, out)
    d = diag.state["domain"]
    typer.echo(
        f"calibrated on {diag.state['calibration_records']} records ({d['source']}); wrote {out}"
    )
    report(model=str(out), calibration=d["source"])


@app.command()
@with_json
def diagnose(
    record: Path = typer.Argument(..., help="A record: CSV/TSV/WAV/MAT/NetCDF/Parquet."),
    channel: str = typer.Option(
        "accel_guide", "--channel", "-c", help="Acceleration channel (m/s**2)."
    ),
    fs: str = typer.Option(None, "--fs", help="Sampling rate, if the file does not give it."),
    speed: str = typer.Option(None, "--speed", help="Crank speed, e.g. 191rpm."),
    tacho: str = typer.Option(
        None, "--tacho", help="Once-per-revolution pulse channel (mark at outer dead centre)."
    ),
    p_head: str = typer.Option(None, "--p-head", help="Head-end pressure channel (Pa)."),
    p_crank: str = typer.Option(None, "--p-crank", help="Crank-end pressure channel (Pa)."),
    model: Path = typer.Option(
        None, "--model", "-m", help="Diagnoser file (default: the one shipped with recipdyn)."
    ),
    out: Path = typer.Option(None, "--out", "-o", help="Folder for the overlay figure."),
    machine: Path = typer.Option(
        None,
        "--machine",
        help="The record's machine: a config TOML ('recipdyn simulate --dump-config') or a "
        "recorded run; a machine other than the diagnoser's is refused.",
    ),
    baseline: Path = typer.Option(
        None,
        "--baseline",
        help="The machine's own healthy baseline ('recipdyn baseline'): the chain is corrected "
        "with it and the features referred to the machine's healthy state.",
    ),
    no_correction: bool = typer.Option(
        False,
        "--no-correction",
        help="Trust the tacho's mark, the pressures' zero and alignment (no chain correction).",
    ),
) -> None:
    """Diagnose a record: fault class, severity and evidence, or a refusal with its reason.

    The measurement chain's errors read from the record (the tacho mark's crank angle and
    the pressures' offsets from the polytropes, their relative gain, the tacho's jitter, the
    mount's resonance) and corrected; class probabilities, the severity with its interval,
    the channels used and how often their answer was right on held-out conditions, impacts
    and deciding features, the closest simulated record overlaid. A record outside the
    training domain, whose chain cannot be made consistent, or whose channels cannot tell
    its class apart is refused."""
    from ..diagnosis.diagnose import diagnose as diagnose_fn
    from ..errors import ParameterError
    from ..io_signal import check_signal_file

    check_signal_file(record)  # (a file that is not there is said first)
    if (speed is None) == (tacho is None):
        raise ParameterError("speed and tacho: give exactly one (the crank angle is needed)")
    res = diagnose_fn(
        record,
        channel=channel,
        fs=fs,
        speed=speed,
        tacho=tacho,
        p_head=p_head,
        p_crank=p_crank,
        model=model,
        out=out,
        correct=not no_correction,
        machine=machine,
        baseline=baseline,
    )
    if res.refused:
        raise ParameterError(f"diagnose {record.name}: refused: {res.reason}")
    typer.echo(res.text())
    report(**res.summary())


@app.command("baseline")
@with_json
def baseline_cmd(
    records: list[Path] = typer.Argument(..., help="Records of the healthy machine."),
    out: Path = typer.Option(Path("out/baseline.json"), "--out", "-o", help="Baseline file."),
    model: Path = typer.Option(
        None, "--model", "-m", help="Diagnoser file (default: the one shipped with recipdyn)."
    ),
    machine: Path = typer.Option(
        None, "--machine", help="The machine's description (default: the diagnoser's)."
    ),
    channel: str = typer.Option(
        "accel_guide", "--channel", "-c", help="Acceleration channel (m/s**2)."
    ),
    fs: str = typer.Option(None, "--fs", help="Sampling rate, if the files do not give it."),
    tacho: str = typer.Option("tacho", "--tacho", help="Once-per-revolution pulse channel."),
    p_head: str = typer.Option("p_head_sensor", "--p-head", help="Head-end pressure (Pa)."),
    p_crank: str = typer.Option("p_crank_sensor", "--p-crank", help="Crank-end pressure (Pa)."),
    workers: int = typer.Option(2, help="Processes that run the fit's simulations."),
) -> None:
    """The machine's own healthy baseline from records known to be healthy (after an overhaul).

    Fits the simulator's healthy machine (masses, clearance volume, valve springs and lift,
    within their ranges) and the measurement chain (pressure offsets, tacho mark angle,
    mounting resonance) to the records; later 'recipdyn diagnose --baseline FILE' corrects the
    chain and refers the features to the machine's own healthy state (docs/diagnosis.md)."""
    import sys

    from ..errors import ParameterError

    if out.suffix != ".json":
        raise ParameterError(f"--out {out}: use a .json file")
    if workers < 1:
        raise ParameterError(f"workers = {workers}; allowed: an integer >= 1")
    for r in records:
        if not r.is_file():
            raise ParameterError(f"record {r}: file not found")
    from ..diagnosis.baseline import build_baseline, read_record
    from ..diagnosis.diagnose import _load
    from ..diagnosis.machine import machine_from_file, refusal

    diag = _load(model)
    mach = None
    if machine is not None:
        mach = machine_from_file(machine)
        why = refusal(diag, mach)
        if why is not None:
            raise ParameterError(f"baseline: {why}")
    recs = [read_record(r, channel=channel, tacho=tacho, p_head=p_head, p_crank=p_crank, fs=fs)
            for r in records]  # fmt: skip
    with refused_leaves_nothing(out):
        b = build_baseline(recs, diag, machine=mach, workers=workers,
                           progress=lambda m: print(m, file=sys.stderr, flush=True))  # fmt: skip
        b.save(out)
    typer.echo(b.summary())
    typer.echo(f"wrote {out}; diagnose with: recipdyn diagnose RECORD --baseline {out}"
               + (f" -m {model}" if model else ""))  # fmt: skip
    report(baseline=json.loads(b.to_json()))
