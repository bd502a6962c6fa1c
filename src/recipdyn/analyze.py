"""Analyse a simulation result: spectrum, phase portraits, Poincaré section, Lyapunov
exponents (equation-based and signal-based), 0-1 test and a verdict, written as figures and a
JSON/Markdown summary. This is the application layer over the generic
[`recipdyn.analysis`][recipdyn.analysis].
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from .analysis import (
    amplitude_spectrum,
    angle_section,
    classify,
    find_spectral_peaks,
    lyapunov_spectrum,
    stroboscopic_section,
    zero_one_test,
)
from .analysis.plots import plot_divergence, plot_lyapunov_history, plot_phase, plot_spectrum
from .analysis.signal import assess_signal
from .defaults import ATOL, LYAP_TOL, MAX_MEMORY_SAMPLES, MIN_SIGNAL_SAMPLES, RTOL
from .io import forcing_frequency, save_figure, write_text
from .io import jsonable as _plain
from .model.parameters import ParameterError
from .plotting import _mpl, axis_label
from .progress import quiet

__all__ = ["analyze_run", "analyze_signal", "is_record", "MIN_SAMPLES"]

#: Fewest samples analyze accepts: those of the signal's exponent estimators, which every
#: analysis runs (a record of 64-199 samples passed a looser check here and then stopped in
#: the estimators with an internal error, exit 1).
MIN_SAMPLES = MIN_SIGNAL_SAMPLES


def analyze_run(path: str | Path, out: str | Path, *, section_points: int = 200,
                lyap_revolutions: float = 100.0, max_signal_samples: int = 40_000,
                rtol: float = RTOL, atol: float = ATOL, phase=quiet) -> dict[str, Any]:  # fmt: skip
    """Analyse ``path`` (a NetCDF file from ``recipdyn simulate``) into folder ``out``.

    Equation-based results (stroboscopic section over ``section_points`` revolutions, Benettin
    over ``lyap_revolutions``) are computed when the file records recipdyn parameters; the
    signal-based ones (spectrum, Wolf, Rosenstein on the crosshead acceleration) always.
    ``phase(message)`` is entered around each step that can take long (a context manager:
    [`recipdyn.progress.phase`][recipdyn.progress.phase] says what is running). Returns the summary
    dict (also written as ``summary.json`` and ``summary.md``).
    """
    from .io import check_output, read_dataset

    path, out = Path(path), Path(out)
    ds = read_dataset(path)
    m = _record_model(ds, path)
    dim = "iteration" if "iteration" in ds.dims else "time"
    vib, vib_unit = m.vibration()
    need = (vib, dim)
    missing = [v for v in need if v not in ds.variables]
    if missing:
        raise ParameterError(f"input {path}: variable(s) {', '.join(missing)} missing; expected "
                             "a recipdyn run (NetCDF from 'recipdyn simulate')")  # fmt: skip
    if ds.sizes[dim] < MIN_SAMPLES:
        raise ParameterError(
            f"{path}: {ds.sizes[dim]} samples; analyze needs at least {MIN_SAMPLES} "
            "(simulate more revolutions or a higher --fs)"
        )
    t = ds[dim].values
    dt = np.diff(t)
    if not (np.all(dt > 0) and np.ptp(dt) <= 1e-6 * np.median(dt)):
        raise ParameterError(f"{path}: time samples must be uniformly spaced and increasing")
    check_output(out, formats=None, what="analysis folder")
    plt = _mpl()
    fs = 1.0 / float(np.median(np.diff(t)))
    fc = forcing_frequency(ds.attrs)
    a = ds[vib].values
    revs = None
    turning = ds.attrs.get("section_angle")  # a crank of its own speed (a motor drive): its
    if turning in ds.variables and ds[turning].dims == (dim,):  # recorded angle, not omega
        th = np.asarray(ds[turning].values, dtype=float)
        revs = (th - float(ds.attrs.get("param_theta1_0", th[0]))) / (2 * np.pi)
        fc = float((revs[-1] - revs[0]) / (t[-1] - t[0]))  # its mean speed names the orders
    summary: dict[str, Any] = {"input": path.name, "samples": int(t.size), "fs_hz": fs,
                               "model": m.name, "signal": vib, "units": vib_unit}  # fmt: skip

    with phase("analyze: spectrum and phase portraits"):
        spec = amplitude_spectrum(a, fs)
        peaks = find_spectral_peaks(spec, n=8, fundamental=fc, min_separation=PEAK_SEPARATION)
        summary["spectrum"] = {
            "resolution_hz": spec.resolution,
            "peaks": [_peak_row(p) for p in peaks],
        }  # fmt: skip
        fmax = min(fs / 2, 1.5 * max(p.frequency for p in peaks)) if peaks else None
        what = ds[vib].attrs.get("long_name") or vib
        what = f"the {what}" if what != vib else vib
        fig = plot_spectrum(spec, peaks, fmax=fmax, title=f"spectrum of {what}")
        save_figure(fig, out / "spectrum.png", dpi=110)
        plt.close(fig)
        fig = _phase_portraits(m, ds, dim, plt)
        save_figure(fig, out / "phase_portraits.png", dpi=110)
        plt.close(fig)

    if fc and vib_unit == "m/s**2":  # a machine's acceleration: its vibration page
        from .analysis.vibration import crank_angle

        if revs is None:
            revs = crank_angle(a.size, fs, speed_hz=fc, zero_rev=float(t[0]) * fc)
        with phase("analyze: vibration page (orders, envelope, cepstrum, impacts)"):
            summary["vibration"] = vibration_section(
                a, fs, out, plt, revs=revs, title=f"{path.name}: {what.removeprefix('the ')}"
            )
    with phase(f"analyze: exponents from the signal, 0-1 test, surrogates "
               f"({min(a.size, max_signal_samples)} samples)"):  # fmt: skip
        assessment = assess_signal(a, fs, max_samples=max_signal_samples)
        summary["lyapunov_signal"] = {k: _plain(r.diagnostics())
                                      for k, r in assessment.lyapunov.items()}  # fmt: skip
        summary["signal_assessment"] = _plain(assessment.to_dict())
        _divergence_figures(assessment, out, plt)

    lam = None
    lam_err = 0.0
    section = None
    k01 = None
    lam, lam_err, section, k01 = _equations_any_model(
        m, ds, dim, out, summary, section_points, lyap_revolutions, rtol, atol, plt, path, phase
    )
    # a simulated record is deterministic by construction: the surrogate test is reported
    # (summary["signal_assessment"]) but does not enter; the signal exponents stand in only
    # when the equations give none
    verdict = classify(lambda1=lam, lambda1_err=lam_err, k01=k01, section=section, spectrum=spec,
                       lyap_tol=LYAP_TOL, signal_lyapunov=list(assessment.lyapunov.values()),
                       time_scale=assessment.embedding.delay / fs)  # fmt: skip
    summary["verdict"] = verdict.to_dict()
    summary["verdict"]["headline"] = _headline(verdict, summary.get("vibration"))
    write_text(out / "summary.json", json.dumps(_plain(summary), indent=2))
    write_text(out / "summary.md", _markdown(summary))
    return summary


#: Spectral peaks closer than this fraction of their frequency to a larger one belong to the
#: same hump (a ring's comb of harmonics) and are left out of the summary's peak table.
PEAK_SEPARATION = 0.1


def _headline(verdict, vib) -> str:
    """The verdict in a vibration analyst's words: 'periodic, 3 impacts a revolution at 30°,
    150°, 250°'."""
    text = verdict.verdict
    pattern = ((vib or {}).get("impacts") or {}).get("pattern") or []
    if pattern and verdict.verdict in ("periodic", "quasi-periodic"):
        n = sum(round(p["per_revolution"]) for p in pattern)
        where = ", ".join(f"{p['angle_deg']:.0f}°" for p in pattern)
        text += f", {n} impact{'s' if n != 1 else ''} a revolution at {where}"
    return text


def _divergence_figures(assessment, out, plt) -> None:
    for name, r in assessment.lyapunov.items():
        if r.curve.size:
            fig = plot_divergence(r)
            save_figure(fig, out / f"lyapunov_{name}.png", dpi=110)
            plt.close(fig)


def parse_zones(text: str | None):
    """'2.3,4.5,7.1 mm/s' -> the three boundaries in m/s (a bare number is m/s)."""
    if not text:
        return None
    from .units import to_si

    body, _, unit = text.strip().partition(" ")
    parts = [p for p in body.split(",") if p.strip()]
    if len(parts) != 3:
        raise ParameterError(f"zones: {text!r}; allowed: three boundaries A/B, B/C, C/D, e.g. "
                             "'2.3,4.5,7.1 mm/s' (from your copy of ISO 20816-8)")  # fmt: skip
    vals = [to_si("zones", f"{p} {unit}".strip(), "m/s") for p in parts]
    if not vals[0] < vals[1] < vals[2] or vals[0] <= 0:
        raise ParameterError(f"zones: {text!r}; allowed: three increasing positive values")
    return vals


def vibration_section(x, fs, out, plt, *, revs=None, quantity="acceleration", zones=None,
                      band=None, title="") -> dict[str, Any]:  # fmt: skip
    """The vibration toolkit on one signal: ``vibration.png`` and the summary's section."""
    from .analysis.plots import plot_vibration
    from .analysis.vibration import vibration_report

    try:
        rep = vibration_report(x, fs, revs=revs, quantity=quantity, zones=zones, band=band)
    except ValueError as exc:
        raise ParameterError(f"vibration analysis: {exc}") from None
    unit = {"acceleration": "(m/s$^2$)", "velocity": "(m/s)"}.get(quantity, "")
    fig = plot_vibration(rep, title=title, unit=unit)
    save_figure(fig, out / "vibration.png", dpi=100)
    plt.close(fig)
    return _plain(rep["summary"])


def _stream_record(path, column, fs, keep: int, progress: bool):
    """Read a long signal file block by block: the first ``keep`` samples (the excerpt the
    detailed analyses run on) and the whole record's moments and Welch spectrum."""
    from .analysis.streaming import RunningMoments, StreamingWelch
    from .io_signal import MeasuredSignal, signal_blocks

    rate, name, _, blocks = signal_blocks(
        path, column=column, fs=fs, progress=f"analyze {path.name}" if progress else None
    )
    moments = RunningMoments()
    welch = StreamingWelch(rate, WELCH_SEGMENT)
    kept: list[np.ndarray] = []
    n_kept = 0
    for block in blocks:
        moments.feed(block)
        welch.feed(block)
        if n_kept < keep:
            kept.append(block[: keep - n_kept].copy())
            n_kept += kept[-1].size
    x = np.concatenate(kept) if kept else np.empty(0)
    notes = [f"long record ({moments.n} samples): read in blocks; the overall statistics and "
             f"the spectrum (Welch, {welch.segments} Hann segments of {WELCH_SEGMENT}) cover "
             f"all of it, the signal-based estimators and the vibration page its first "
             f"{x.size} samples ({x.size / rate:.4g} s)"]  # fmt: skip
    return MeasuredSignal(x, rate, name, path.name, "", notes), moments, welch


#: Samples per Welch segment of a long record's spectrum (resolution fs / 65536: 0.15 Hz at
#: 10 kHz); the record length above which a file is read in blocks is MAX_MEMORY_SAMPLES.
WELCH_SEGMENT = 1 << 16
#: The first samples of a long record that the detailed analyses use.
EXCERPT_SAMPLES = 1 << 20


def analyze_signal(path: str | Path, out: str | Path, *, column=None, fs=None,
                   max_signal_samples: int = 40_000, tacho=None, speed=None,
                   quantity: str = "acceleration", zones=None, band=None, phase=quiet,
                   max_memory_samples: int = MAX_MEMORY_SAMPLES,
                   excerpt_samples: int = EXCERPT_SAMPLES,
                   progress: bool = False) -> dict[str, Any]:  # fmt: skip
    """Analyse one channel of a measured (or any) signal file into folder ``out``: the signal,
    its spectrum, the exponents from the signal with their statuses, the 0-1 test, the
    surrogate test and the verdict with the evidence table (``summary.json``/``summary.md``).

    A record longer than ``max_memory_samples`` is read in blocks (with a progress bar if
    ``progress``): its overall statistics, band velocity RMS and spectrum (Welch) cover the
    whole record; the figures of the signal, the vibration page and the signal-based chaos
    estimators use its first ``excerpt_samples``, as the summary's notes say."""
    from .analysis.spectrum import Spectrum
    from .io import check_output
    from .io_signal import crank_revs, read_signal, record_length

    path, out = Path(path), Path(out)
    for name, value in (("max_memory_samples", max_memory_samples),
                        ("excerpt_samples", excerpt_samples)):  # fmt: skip
        if not int(value) >= 1000:
            raise ParameterError(f"{name} = {value!r}; allowed: >= 1000")
    zone_bounds = parse_zones(zones)
    moments = welch = None
    n_est = record_length(path, column=column)  # None for a bad path: read_signal says why
    if n_est is not None and n_est > max_memory_samples:
        with phase(f"analyze: reading {path.name} in blocks"):
            sig, moments, welch = _stream_record(path, column, fs,
                                                 min(excerpt_samples, max_memory_samples),
                                                 progress)  # fmt: skip
    else:
        with phase(f"analyze: reading {path.name}"):
            sig = read_signal(path, column=column, fs=fs)
    if sig.x.size < 200:
        raise ParameterError(f"{path}: {sig.x.size} samples in {sig.name!r}; analyze needs at "
                             "least 200 for a signal without equations")  # fmt: skip
    if np.ptp(sig.x) == 0 and (moments is None or moments.hi == moments.lo):
        raise ParameterError(f"{path}: column {sig.name!r} is constant")
    check_output(out, formats=None, what="analysis folder")
    plt = _mpl()
    x, rate = sig.x, sig.fs
    n_total = x.size if moments is None else moments.n
    t = np.arange(x.size) / rate
    fig, ax = plt.subplots(figsize=(10, 3.5), constrained_layout=True)
    shown = slice(0, min(x.size, 20_000))
    ax.plot(t[shown], x[shown], lw=0.5)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(f"{sig.name} ({sig.units})" if sig.units else sig.name)
    ax.set_title(
        f"{sig.source}: {sig.name}, {rate:g} Hz"
        + (f" (first {shown.stop} of {n_total} samples)" if shown.stop < n_total else "")
    )
    ax.grid(alpha=0.3)
    save_figure(fig, out / "signal.png", dpi=110)
    plt.close(fig)
    if welch is None:
        spec = amplitude_spectrum(x, rate)
        title = f"spectrum of {sig.name}"
    else:
        f_w, a_w = welch.amplitude()
        spec = Spectrum(f_w, a_w, rate / welch.nperseg, "hann", rate)
        title = (f"spectrum of {sig.name}: whole record, Welch mean of {welch.segments} "
                 f"segments")  # fmt: skip
    revs = crank_revs(path, x.size, rate, tacho=tacho, speed=speed)
    f_crank = None
    if revs is not None:
        from .analysis.classify import quarter_speed_ratio
        from .defaults import MAX_SPEED_RATIO

        ok = np.isfinite(revs)
        if ok.sum() > 1 and quarter_speed_ratio(revs, rate) <= MAX_SPEED_RATIO:
            idx = np.flatnonzero(ok)  # the mean speed: orders of a steady machine
            f_crank = float((revs[idx[-1]] - revs[idx[0]]) * rate / (idx[-1] - idx[0]))
    peaks = find_spectral_peaks(spec, n=8, fundamental=f_crank, min_separation=PEAK_SEPARATION)
    fig = plot_spectrum(spec, peaks, title=title)
    save_figure(fig, out / "spectrum.png", dpi=110)
    plt.close(fig)
    with phase("analyze: vibration page (orders, envelope, cepstrum, impacts)"):
        vib = vibration_section(x, rate, out, plt, revs=revs, quantity=quantity,
                                zones=zone_bounds, band=band,
                                title=f"{sig.source}: {sig.name}")  # fmt: skip
    if moments is not None:
        vib["excerpt_samples"] = int(x.size)
        vib["whole_record"] = _whole_record(moments, welch, quantity, zone_bounds)
    with phase(f"analyze: exponents from the signal, 0-1 test, surrogates "
               f"({min(x.size, max_signal_samples)} samples)"):  # fmt: skip
        a = assess_signal(x, rate, max_samples=max_signal_samples, revs=revs)
        _divergence_figures(a, out, plt)
    summary: dict[str, Any] = {
        "input": path.name, "signal": sig.name, "units": sig.units, "samples": int(n_total),
        "fs_hz": rate, "notes": sig.notes + a.notes, "model": "none (measured signal)",
        "spectrum": {"resolution_hz": spec.resolution,
                     "peaks": [_peak_row(p) for p in peaks]},
        "lyapunov_signal": {k: r.diagnostics() for k, r in a.lyapunov.items()},
        "signal_assessment": a.to_dict(),
        "verdict": a.verdict.to_dict() | {"headline": _headline(a.verdict, vib)},
        "evidence": [list(r) for r in a.evidence_table()], "vibration": vib,
    }  # fmt: skip
    summary = _plain(summary)
    write_text(out / "summary.json", json.dumps(summary, indent=2))
    write_text(out / "summary.md", _markdown(summary))
    return summary


def _whole_record(moments, welch, quantity, zones) -> dict[str, Any]:
    """The vibration summary's overall numbers for a whole long record (streamed)."""
    from .analysis.vibration import ISO20816_8_BAND_HZ, zone

    res: dict[str, Any] = {"samples": int(moments.n), "indicators": moments.indicators(),
                           "spectrum_segments": int(welch.segments),
                           "spectrum_resolution_hz": welch.fs / welch.nperseg}  # fmt: skip
    lo, hi = ISO20816_8_BAND_HZ
    if quantity in ("acceleration", "velocity") and welch.fs > 2 * hi:  # as vibration_report
        v = welch.band_rms((lo, hi), integrate=1 if quantity == "acceleration" else 0)
        res["velocity_rms_band_hz"] = [lo, hi]
        res["velocity_rms"] = v
        if zones:
            res["zone"] = zone(v, zones)
    return res


def is_record(path: str | Path) -> bool:
    """True for a NetCDF run written by recipdyn (it records its model and parameters)."""
    import xarray as xr

    path = Path(path)
    if path.suffix.lower() != ".nc" or not path.is_file():
        return False
    try:
        with xr.open_dataset(path) as ds:
            attrs = ds.attrs  # a model named, or (an older record) its parameters
            return "model_spec" in attrs or "model_name" in attrs or any(
                str(k).startswith("param_") for k in attrs)  # fmt: skip
    except Exception:
        return True  # let analyze_run report what is wrong with it


def _with_uncertainty(le: dict) -> str:
    """The Benettin exponents to the digits their uncertainty supports: the larger of the
    limit's error and the spread over the second half, its first digit the last one printed
    (at most 4 significant digits each), followed by that uncertainty: ``0.621, -0.004,
    -25.37 (+- 0.003)``."""
    vals = np.asarray(le["exponents_per_s"], dtype=float)
    errs = [le.get("lambda1_limit_error"), le.get("spread_second_half")]
    u = max((float(e) for e in errs if e is not None and np.isfinite(e)), default=0.0)
    if not (u > 0 and vals.size and np.isfinite(vals).all()):
        return ", ".join(f"{v:.4g}" for v in vals)
    decimals = int(max(0, -np.floor(np.log10(u))))

    def fmt(v: float) -> str:  # no more than 4 significant digits
        return f"{v:.{min(decimals, int(max(0, 3 - np.floor(np.log10(abs(v) or 1.0)))))}f}"

    return ", ".join(fmt(v) for v in vals) + f" (\u00b1 {u:.1g})"


def _spread(res) -> float:
    """Uncertainty of lambda1: the spread of its running estimate over the second half."""
    tail = res.history[len(res.history) // 2 :, 0]
    return float(np.std(tail)) if tail.size > 1 else 0.0


def _record_model(ds, path):
    """The model a record was made with (its spec: a plug-in model's file too). A record
    with parameters but no model named was written when recipdyn had one model, the
    default."""
    from .model.registry import DEFAULT_MODEL, configured_for_record, get_model

    spec = ds.attrs.get("model_spec") or ds.attrs.get("model_name")
    if spec is None:
        if not any(str(k).startswith("param_") for k in ds.attrs):
            raise ParameterError(f"{path}: names no model and records no parameters; expected "
                                 "a recipdyn run (NetCDF from 'recipdyn simulate')")  # fmt: skip
        spec = DEFAULT_MODEL
    try:
        return configured_for_record(get_model(str(spec)), ds.attrs)
    except ParameterError as exc:
        raise ParameterError(f"{path}: made with model {spec!r}, which is not available here "
                             f"({exc})") from None  # fmt: skip


def _phase_portraits(m, ds, dim, plt):
    """Phase portraits of a record: consecutive state components (up to three pairs) and the
    model's section pair (the compressor's velocity-acceleration)."""
    names = [s for s in m.state_names if s in ds]
    pairs = list(zip(names, names[1:], strict=False))[:3] or [(names[0], names[0])]
    declared = m.pair()
    if declared not in pairs and all(k in ds for k in declared) and len(pairs) < 3:
        pairs.append(declared)
    fig, axes = plt.subplots(1, len(pairs), figsize=(5 * len(pairs), 4.5),
                             constrained_layout=True, squeeze=False)  # fmt: skip
    for ax, (u, w) in zip(axes[0], pairs, strict=True):
        plot_phase(ds[u], ds[w], axis_label(u, ds[u]), axis_label(w, ds[w]), ax=ax,
                   points=dim == "iteration", title=f"{u}-{w}")  # fmt: skip
    return fig


def _equations_any_model(m, ds, dim, out, summary, section_points, lyap_revolutions, rtol,
                         atol, plt, path, phase=quiet):  # fmt: skip
    """Section, Benettin exponents and 0-1 test of any registered model's record."""
    from .analysis import lyapunov_spectrum_map

    try:
        values = m.values_from_record(ds.attrs)
    except (ParameterError, TypeError, ValueError) as exc:
        raise ParameterError(f"{path}: the recorded parameters are not valid ({exc})") from None
    state_names = tuple(s for s, _ in m.states(values))
    missing = [s for s in state_names if s not in ds]
    if missing:
        raise ParameterError(f"{path}: state variable(s) {', '.join(missing)} missing")
    system = m.system(values)
    y0 = np.array([float(ds[s].values[0]) for s in state_names])
    t0 = float(ds[dim].values[0])
    pair = state_names[:2] if len(state_names) >= 2 else state_names * 2
    declared = m.pair()  # the model's section pair (the compressor's v, a) when it records it
    lam, lam_err, section, k01 = None, 0.0, None, None
    supported = m.lyapunov_supported(values)
    if not supported:
        summary["lyapunov_equations"] = {"refused": m.lyapunov_refusal}
    if m.kind == "map":
        section = np.c_[tuple(ds[s].values for s in pair)]
        with phase("analyze: Lyapunov exponents of the map"):
            res = lyapunov_spectrum_map(system, y0, max(1000, int(lyap_revolutions)),
                                        n_transient=0)  # fmt: skip
        unit = "per iteration"
    else:
        period = m.period(values)
        # a free crank (a motor drive) is autonomous: no forcing period to strobe at, its
        # section is taken once per turn of the crank, at the record's first crank angle (the
        # nominal period still scales the runs)
        angle = m.section_angle(values) if system.period is None else None
        sec = None
        if period and system.period is not None:
            with phase(f"analyze: Poincaré section ({section_points} periods)"):
                sec = stroboscopic_section(system, y0, section_points, t0=t0, rtol=rtol,
                                           atol=atol)  # fmt: skip
            title = f"Poincaré section, once per period ({section_points})"
        elif angle in state_names and period:
            i = state_names.index(angle)
            with phase(f"analyze: Poincaré section ({section_points} turns of {angle})"):
                sec = angle_section(system, y0, section_points, index=i, turn_time=period,
                                    phase=float(y0[i]) % (2 * np.pi), t0=t0, rtol=rtol,
                                    atol=atol)  # fmt: skip
            title = f"Poincaré section, once per turn of {angle} ({section_points})"
        if sec is not None:
            if all(k in sec for k in declared):
                pair = declared
            section = np.c_[tuple(sec[s].values for s in pair)]
            fig = plot_phase(sec[pair[0]], sec[pair[1]], pair[0], pair[1], points=True,
                             title=title)  # fmt: skip
            save_figure(fig, out / "poincare.png", dpi=110)
            plt.close(fig)
            if section_points >= 100:
                k01 = zero_one_test(sec[pair[0]].values)
            summary["poincare"] = {"points": section_points,
                                   "kind": sec.attrs["section"], **({"angle": angle}
                                   if sec.attrs["section"] == "angle" else {})}  # fmt: skip
        if not m.has_dynamics(values):  # nothing moves but the forcing: no exponents
            summary["zero_one_K"] = k01
            return None, 0.0, section, k01
        if not supported:
            summary["zero_one_K"] = k01
            return None, 0.0, section, k01
        # in periods of the model (a motor's crank: its nominal revolution 2 pi / omega, the
        # system being autonomous), else in time units
        with phase(f"analyze: Benettin exponents ({lyap_revolutions:g} periods)"):
            res = lyapunov_spectrum(system, y0, lyap_revolutions * (period or 1.0), t0=t0,
                                    rtol=rtol, atol=atol)  # fmt: skip
        unit = f"per {m.time_unit}"
    lam, lam_err = res.largest_limit()
    summary["lyapunov_equations"] = {
        "lambda1_limit": lam, "lambda1_limit_error": lam_err,
        "exponents_per_s": res.exponents.tolist(), "units": unit, "sum_per_s": res.sum,
        "spread_second_half": _spread(res), "revolutions": lyap_revolutions,
        "duration": float(res.settings.get("t_total", np.nan)),
    }  # fmt: skip
    if m.kind == "ode" and m.period(values):
        # a free crank (autonomous: no forcing period) per nominal revolution, 2 pi / omega
        per = getattr(res, "per_period", None)
        per = res.exponents * m.period(values) if per is None else per
        summary["lyapunov_equations"]["exponents_per_revolution"] = per.tolist()
    fig = plot_lyapunov_history(res, unit=unit)  # per s or per iteration
    save_figure(fig, out / "lyapunov_benettin.png", dpi=110)
    plt.close(fig)
    summary["zero_one_K"] = k01
    return lam, lam_err, section, k01


def _peak_row(p) -> dict[str, Any]:
    """A spectral peak for the summary: its crank order only when it is one (within the
    harmonic tolerance of `find_spectral_peaks`, 1.5 bins), else ``None``: a line between
    orders is named by its frequency alone (it said "crank order 0")."""
    return dict(frequency_hz=p.frequency, amplitude=p.amplitude, crank_order=p.order or None)


def _markdown(s: dict[str, Any]) -> str:
    v = s["verdict"]
    measured = s.get("model") == "none (measured signal)"
    what = s.get("signal", "signal")
    unit = (s.get("units") or "signal units").replace("**", "^")
    peaks = s["spectrum"]["peaks"]
    orders = not measured or any(p["crank_order"] for p in peaks)  # a speed was known
    lines = [f"# Analysis of {s['input']}", "", f"**Verdict: {v.get('headline', v['verdict'])}**"
             " — " + "; ".join(v["reasons"]), "", f"## Spectrum peaks ({what})", "",
             f"| f (Hz) | amplitude ({unit}) |" + (" crank order |" if orders else ""),
             "|---|---|" + ("---|" if orders else "")]  # fmt: skip
    for p in peaks:  # a line between orders: its frequency alone
        order = f" {p['crank_order'] or '—'} |" if orders else ""
        lines.append(f"| {p['frequency_hz']:.4g} | {p['amplitude']:.4g} |{order}")
    vib = s.get("vibration")
    if vib:
        lines += ["", "## Vibration", ""]
        lines += [f"- {k}: {v:.4g}" for k, v in vib["indicators"].items()]
        if "velocity_rms_2_1000hz" in vib:
            z = f" (zone {vib['zone']})" if "zone" in vib else ""
            lines.append(f"- velocity RMS, 2-1000 Hz (ISO 20816-8 band): "
                         f"{vib['velocity_rms_2_1000hz']:.4g} m/s{z}")  # fmt: skip
        whole = vib.get("whole_record")
        if whole:
            lines += [
                "",
                f"Whole record ({whole['samples']} samples, read in blocks; the "
                f"lines above are from its first {vib['excerpt_samples']}):",
                "",
            ]
            lines += [f"- {k}: {v:.4g}" for k, v in whole["indicators"].items()]
            if "velocity_rms" in whole:
                z = f" (zone {whole['zone']})" if "zone" in whole else ""
                b = whole["velocity_rms_band_hz"]
                lines.append(f"- velocity RMS, {b[0]:g}-{b[1]:g} Hz: "
                             f"{whole['velocity_rms']:.4g} m/s{z}")  # fmt: skip
        imp = vib["impacts"]
        per = f", {imp['per_revolution']:.3g} per revolution" if imp["per_revolution"] else ""
        lines.append(f"- impacts: {imp['count']}{per}")
        for p in imp.get("pattern") or []:
            lines.append(f"  - at {p['angle_deg']:.0f}° of the crank, "
                         f"{p['per_revolution']:.2f} per revolution")  # fmt: skip
        if vib.get("order_lines"):
            lines += ["", "## Orders (angle domain)", "", "| crank order | amplitude |",
                      "|---|---|"]  # fmt: skip
            lines += [f"| {o['order']:.3g} | {o['amplitude']:.4g} |" for o in vib["order_lines"]]
    if s.get("evidence"):
        lines += ["", "## Evidence", "", "| evidence | value | status |", "|---|---|---|"]
        lines += [f"| {a} | {b} | {c} |" for a, b, c in s["evidence"]]
    lines += ["", "## Lyapunov exponents", ""]
    le = s.get("lyapunov_equations")
    if le and "refused" in le:
        lines.append(f"- Benettin (equations): refused — {le['refused']}")
    elif le:
        unit = le.get("units", "1/s")
        lines.append(f"- Benettin (equations): {_with_uncertainty(le)} ({unit}), "
                     f"sum {le['sum_per_s']:.3g}")  # fmt: skip
    for name, r in s["lyapunov_signal"].items():
        val = (r["exponent"] if r["status"] in ("ok", "flat")
               else f"{r['exponent']:.4g}, withheld ({r['reason']})"
               if r["status"] in ("inconsistent", "unconfirmed")
               else f"refused ({r['reason']})")  # fmt: skip
        lines.append(f"- {name} (signal {s.get('signal', 'a')}): {val}")
    if s.get("zero_one_K") is not None:
        lines.append(f"- 0-1 test K (stroboscopic section): {s['zero_one_K']:.3f}")
    return "\n".join(lines) + "\n"
