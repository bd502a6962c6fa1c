"""What is computed for each run of the reproduction: signals, spectrum, section, exponents."""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
import xarray as xr

from ..analysis.poincare import count_distinct_points, stroboscopic_section
from ..errors import ModelValidityWarning
from ..integrate import IntegrationError
from ..model.assembler.model import compressor_model
from ..simulate import clean_attrs, simulate

__all__ = ["measure_run", "spectral_peaks", "F_MAX_STORED"]

#: Highest frequency kept of the stored acceleration spectrum, Hz.
F_MAX_STORED = 2000.0
_KEEP = ("x", "v", "a", "theta_c", "thetadot_c", "contact_force")


def spectral_peaks(a: np.ndarray, fs: float, f_crank: float, n: int = 6):
    """Amplitude spectrum of ``a`` (Hann window, coherent-gain corrected) and its largest peaks.

    Returns ``(freq, amp, peaks)`` where ``peaks`` is a list of ``(f, amplitude, order)`` sorted
    by amplitude, ``order`` the crank harmonic (k if ``|f - k f_crank|`` is within 1.5 bins,
    else 0).
    """
    from ..analysis.spectrum import amplitude_spectrum, find_spectral_peaks

    spec = amplitude_spectrum(a, fs, window="hann")
    peaks = find_spectral_peaks(spec, n=n, fundamental=f_crank)
    return spec.frequency, spec.amplitude, [(p.frequency, p.amplitude, p.order) for p in peaks]


def _lyapunov_equations(model, y0, revolutions: float, settings) -> dict[str, float]:
    from ..analysis import lyapunov_spectrum

    res = lyapunov_spectrum(model, y0, t_total=revolutions * model.period,
                            rtol=settings.rtol, atol=settings.atol)  # fmt: skip
    ex = np.asarray(res.exponents, dtype=float)
    return {"lyap_benettin": float(ex[0]), "lyap_benettin_sum": float(ex.sum()),
            "lyap_benettin_2": float(ex[-1])}  # fmt: skip


def _lyapunov_wolf(a: np.ndarray, fs: float) -> dict[str, float]:
    from ..analysis import lyap_wolf

    res = lyap_wolf(a, dt=1.0 / fs)
    return {"lyap_wolf": float(res.exponent), "wolf_dim": float(res.params.get("dim", np.nan)),
            "wolf_delay": float(res.params.get("delay", np.nan))}  # fmt: skip


def measure_run(spec) -> xr.Dataset:
    """Simulate one run and compute every measure the report needs."""
    s = spec.settings
    p = spec.params
    error = ""
    try:
        with warnings.catch_warnings():  # contact loss is reported as a measure
            warnings.simplefilter("ignore", ModelValidityWarning)
            ds = simulate(p, revolutions=s.revolutions, fs=s.fs, rtol=s.rtol, atol=s.atol)
    except IntegrationError as exc:
        if exc.dataset is None or exc.dataset.sizes["time"] < 16:
            raise
        ds, error = exc.dataset, str(exc)  # measure what was computed before the failure
    out = ds[list(_KEEP)]
    a = ds["a"].values
    freq, amp, peaks = spectral_peaks(a, s.fs, p.crank_frequency)
    keep = freq <= F_MAX_STORED
    out = out.assign(
        spectrum_a=xr.DataArray(amp[keep], dims="frequency", attrs={"units": "m/s**2"}),
    ).assign_coords(frequency=("frequency", freq[keep], {"units": "Hz"}))
    m: dict[str, Any] = {
        "peak_a": float(np.max(np.abs(a))),
        "min_x": 1e3 * float(ds.x.min()),
        "max_v": float(np.max(np.abs(ds.v))),
        "min_contact_force": float(ds.contact_force.min()),
        "peak_freqs": [float(f) for f, _, _ in peaks],
        "peak_amps": [float(x) for _, x, _ in peaks],
        "peak_orders": [int(k) for _, _, k in peaks],
    }
    model = compressor_model(p)
    y0 = model.initial_state()
    m["error"] = error
    nan = float("nan")
    m.update(poincare_distinct=-1, lyap_benettin=nan, lyap_benettin_sum=nan,
             lyap_benettin_2=nan, lyap_wolf=nan, wolf_dim=nan, wolf_delay=nan)  # fmt: skip
    if error:  # no long-run measures for a run that fails early
        return _finish(out, ds, m, spec)
    try:
        sec = stroboscopic_section(model, y0, s.poincare_points, rtol=s.rtol, atol=s.atol)
        out = out.assign(
            poincare_v=("section", sec.v.values, {"units": "m/s"}),
            poincare_a=("section", sec.a.values, {"units": "m/s**2"}),
            poincare_theta_c=("section", sec.theta_c.values, {"units": "rad"}),
            poincare_thetadot_c=("section", sec.thetadot_c.values, {"units": "rad/s"}),
        )
        m["poincare_distinct"] = count_distinct_points(np.c_[sec.v, sec.a], rtol=1e-6)
        if p.rc > 0:
            m.update(_lyapunov_equations(model, y0, s.lyap_revolutions, s))
        else:
            m.update(lyap_benettin=0.0, lyap_benettin_sum=0.0, lyap_benettin_2=0.0)
    except IntegrationError as exc:  # e.g. the printed equations blowing up on a long run
        m["error"] = f"long run: {exc}"
    n_w = min(a.size, s.wolf_samples)
    m.update(_lyapunov_wolf(a[:n_w], s.fs))
    return _finish(out, ds, m, spec)


def _finish(out, ds, m, spec) -> xr.Dataset:
    attrs = dict(ds.attrs)
    attrs.update({f"m_{k}": v for k, v in m.items()})
    attrs.update(case=spec.case.id, variant=spec.variant.id, variant_label=spec.variant.label)
    out.attrs = clean_attrs(attrs)
    if "section" not in out.dims:  # keep the layout uniform for the figures
        empty = ("section", np.empty(0))
        out = out.assign(poincare_v=empty, poincare_a=empty, poincare_theta_c=empty,
                         poincare_thetadot_c=empty)  # fmt: skip
    return out
