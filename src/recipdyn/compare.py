"""Compare runs: what differs in their inputs, and how their responses differ.

[`compare_runs`][recipdyn.compare.compare_runs] reads two or more records of ``recipdyn simulate``
(NetCDF), lists the parameters and settings that differ between them, overlays the vibration signal,
its amplitude spectrum and the once-per-revolution section, and tabulates the main measures of
each run with its difference from the first (the reference):

========================  ===============================================================
peak                      largest absolute value of the signal
rms                       root mean square about the mean
dominant_hz               the largest spectral line (Hann window, whole record)
own_line_hz               the largest line that is not a crank harmonic above 8 orders
                          (the link's or joint's own oscillation; NaN when there is none
                          above 1e-4 of the largest line)
min_contact_force_N       the compressor's smallest joint contact force (validity)
========================  ===============================================================

Runs of different lengths or sampling rates are compared measure by measure; the overlays
share the time axis from each run's own start.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from .analysis.spectrum import amplitude_spectrum, display_band, nonharmonic_peak
from .errors import ParameterError
from .io import check_output, forcing_frequency, jsonable, read_dataset, save_figure, write_text
from .plotting import PALETTE, _mpl, axis_label, plot_signal, section_times

__all__ = ["compare_runs", "MEASURES"]

MEASURES = ("peak", "rms", "dominant_hz", "own_line_hz", "min_contact_force_N")

#: Attributes that name a run's inputs (parameters and solver settings), compared one by one;
#: the solver's counters and timings are results, not inputs.
_INPUT_PREFIXES = ("param_", "theta_c_initial", "model_name", "revolutions")
_SETTINGS = ("solver_method", "solver_rtol", "solver_atol", "solver_h")


def _inputs(ds) -> dict[str, Any]:
    return {k: v for k, v in ds.attrs.items()
            if (k.startswith(_INPUT_PREFIXES) or k in _SETTINGS)
            and not k.endswith(("_note", "_units"))}  # fmt: skip


def _same(a, b) -> bool:
    if isinstance(a, (int, float, np.number)) and isinstance(b, (int, float, np.number)):
        return bool(np.isclose(float(a), float(b), rtol=1e-12, atol=0) or (a != a and b != b))
    return str(a) == str(b)


def _measures(ds, signal: str) -> dict[str, float]:
    t = ds["time"].values
    x = ds[signal].values.astype(float)
    fs = 1.0 / float(np.median(np.diff(t)))
    spec = amplitude_spectrum(x, fs)
    fc = forcing_frequency(ds.attrs)
    out = {
        "peak": float(np.max(np.abs(x))),
        "rms": float(np.sqrt(np.mean((x - x.mean()) ** 2))),
        "dominant_hz": float(spec.frequency[1:][np.argmax(spec.amplitude[1:])]),
        "own_line_hz": nonharmonic_peak(spec.frequency, spec.amplitude, fc, min_rel_height=1e-4)
        if fc
        else np.nan,
        "min_contact_force_N": float(ds.attrs.get("min_contact_force_N", np.nan)),
    }
    return out


def _section(ds, signal: str) -> tuple[np.ndarray, np.ndarray, str, str] | None:
    """Once-per-period samples of (velocity, signal) for the compressor, else of the first
    two state variables; ``None`` when the record is shorter than two periods."""
    fc = forcing_frequency(ds.attrs)
    t = ds["time"].values
    ts, _ = section_times(ds, 1.0 / fc if fc else None)  # (a motor's crank: once per turn)
    if ts.size < 2:
        return None
    first = "v" if "v" in ds and signal != "v" else next(
        (k for k in ds.data_vars if ds[k].dims == ("time",) and k != signal), None)  # fmt: skip
    if first is None:
        return None
    return (np.interp(ts, t, ds[first].values), np.interp(ts, t, ds[signal].values),
            axis_label(first, ds[first]), axis_label(signal, ds[signal]))  # fmt: skip


def compare_runs(paths: list[str | Path], out: str | Path, *, signal: str | None = None,
                 labels: list[str] | None = None) -> dict[str, Any]:  # fmt: skip
    """Compare the records ``paths`` (the first is the reference) into folder ``out``:
    ``compare.png`` (signal, spectra, sections overlaid), ``compare.md`` and ``compare.json``
    (the differing inputs and the measures with their differences). Returns the summary."""
    if len(paths) < 2:
        raise ParameterError(f"runs: {len(paths)} given; compare needs at least 2")
    paths = [Path(p) for p in paths]
    runs = [read_dataset(p) for p in paths]
    for p, ds in zip(paths, runs, strict=True):
        if "time" not in ds.dims:
            raise ParameterError(f"{p}: no 'time' dimension; compare takes records of "
                                 "'recipdyn simulate' of a flow (not a map)")  # fmt: skip
    if signal is None:
        named = {str(ds.attrs.get("vibration_signal", "a")) for ds in runs}  # the models'
        signal = next(iter(named)) if len(named) == 1 else None
        signal = signal if signal is not None and all(signal in ds for ds in runs) else None
        if signal is None:
            common = set.intersection(*({k for k in ds.data_vars if ds[k].dims == ("time",)}
                                        for ds in runs))  # fmt: skip
            if not common:
                raise ParameterError("runs: no signal common to all runs")
            signal = sorted(common)[0]
    for p, ds in zip(paths, runs, strict=True):
        if signal not in ds:
            have = ", ".join(k for k in ds.data_vars if ds[k].dims == ("time",))
            raise ParameterError(f"signal: {signal!r} not in {p}; it has {have}")
    labels = labels or [p.stem for p in paths]
    if len(set(labels)) < len(labels):
        labels = [str(p) for p in paths]
    out = check_output(out, formats=None, what="comparison folder")
    out.mkdir(parents=True, exist_ok=True)

    inputs = [_inputs(ds) for ds in runs]
    keys = sorted(set().union(*inputs))
    differing = {k: [inp.get(k, "(absent)") for inp in inputs] for k in keys
                 if not all(_same(inputs[0].get(k), inp.get(k)) for inp in inputs[1:])}  # fmt: skip
    measures = [_measures(ds, signal) for ds in runs]
    ref = measures[0]
    table = []
    for label, m in zip(labels, measures, strict=True):
        row: dict[str, Any] = {"run": label}
        for k in MEASURES:
            row[k] = m[k]
            d = m[k] - ref[k]
            row[f"{k}_diff"] = d
            row[f"{k}_rel"] = d / abs(ref[k]) if ref[k] and np.isfinite(ref[k]) else np.nan
        table.append(row)
    summary = {"runs": [str(p) for p in paths], "labels": labels, "signal": signal,
               "units": runs[0][signal].attrs.get("units", ""), "differing_inputs": differing,
               "measures": table}  # fmt: skip
    _figure(runs, labels, signal, out / "compare.png")
    write_text(out / "compare.json", json.dumps(jsonable(summary), indent=2))
    write_text(out / "compare.md", _markdown(summary))
    return summary


def _figure(runs, labels, signal, path: Path) -> None:
    plt = _mpl()
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.6), constrained_layout=True)
    top, bottom = 0.0, np.inf
    for ds, label, color in zip(runs, labels, PALETTE * 4, strict=False):
        t = ds["time"].values
        plot_signal(axes[0], t - t[0], ds[signal].values, color=color, label=label, zoom=False)
        fs = 1.0 / float(np.median(np.diff(t)))
        spec = amplitude_spectrum(ds[signal].values, fs)
        # a log frequency axis: the crank's few hertz and a link's kilohertz both readable
        axes[1].loglog(spec.frequency[1:], np.maximum(spec.amplitude[1:], 1e-300), lw=0.8,
                       color=color, label=label)  # fmt: skip
        fc = forcing_frequency(ds.attrs)
        top = max(top, display_band(spec, fc))
        bottom = min(bottom, spec.frequency[1] if spec.frequency.size > 1 else 1.0,
                     fc / 2 if fc else np.inf)  # fmt: skip
        sec = _section(ds, signal)
        if sec is not None:
            axes[2].plot(sec[0], sec[1], "o", ms=3, color=color, label=label)
            axes[2].set_xlabel(sec[2])
            axes[2].set_ylabel(sec[3])
    ref = runs[0][signal]
    axes[0].set_xlabel("time from the start of each record (s)")
    axes[0].set_ylabel(axis_label(signal, ref))
    axes[0].set_title("signal")
    axes[1].set_xlim(bottom, top)
    amp_max = max(float(np.nanmax(np.abs(ds[signal].values))) for ds in runs)
    axes[1].set_ylim(amp_max * 1e-7, amp_max * 2)
    axes[1].set_xlabel("frequency (Hz), log scale")
    fcs = {forcing_frequency(ds.attrs) for ds in runs}
    if len(fcs) == 1 and (fc := fcs.pop()):  # one crank speed: its orders on the top axis
        orders = axes[1].secondary_xaxis("top", functions=(lambda f: f / fc,
                                                           lambda o: o * fc))  # fmt: skip
        orders.set_xlabel("crank order", fontsize=8)
        orders.tick_params(labelsize=7)
    axes[1].set_ylabel(f"amplitude of {axis_label(signal, ref)}, log scale")
    axes[1].set_title("amplitude spectra (Hann window)")
    axes[2].set_title("section: once per revolution" if runs[0].attrs.get("crank_frequency_hz")
                      else "section: once per period")  # fmt: skip
    if not axes[2].lines:
        axes[2].text(0.5, 0.5, "records shorter than two periods:\nno section", ha="center",
                     va="center", transform=axes[2].transAxes)  # fmt: skip
    for ax in axes:
        ax.grid(alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
    fig.suptitle(f"Comparison of {len(runs)} runs (reference: {labels[0]})")
    save_figure(fig, path, dpi=120)
    plt.close(fig)


def _fmt(v) -> str:
    if isinstance(v, float):
        return "n/a" if not np.isfinite(v) else f"{v:.5g}"
    return str(v)


def _markdown(s: dict[str, Any]) -> str:
    lines = [f"# Comparison of {len(s['runs'])} runs", "",
             f"Reference: {s['labels'][0]}; signal {s['signal']} ({s['units']}).", "",
             "## Inputs that differ", ""]  # fmt: skip
    if s["differing_inputs"]:
        lines.append("| input | " + " | ".join(s["labels"]) + " |")
        lines.append("|---" * (len(s["labels"]) + 1) + "|")
        for k, vals in s["differing_inputs"].items():
            lines.append(f"| {k} | " + " | ".join(_fmt(v) for v in vals) + " |")
    else:
        lines.append("None: the runs have the same parameters and settings.")
    lines += ["", "## Measures (difference from the reference, relative in brackets)", ""]
    lines += ["| run | " + " | ".join(MEASURES) + " |", "|---" * (len(MEASURES) + 1) + "|"]
    for row in s["measures"]:
        cells = []
        for k in MEASURES:
            rel = row[f"{k}_rel"]
            rel_s = f" ({100 * rel:+.2f} %)" if np.isfinite(rel) and row is not s["measures"][0] \
                else ""  # fmt: skip
            cells.append(_fmt(row[k]) + rel_s)
        lines.append(f"| {row['run']} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
