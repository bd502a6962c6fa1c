"""What the app draws for a run: interactive views of the record (Plotly) and the figures
``recipdyn simulate`` writes (matplotlib, rendered to PNG). Every curve is read from the
simulated record; nothing here computes physics."""

from __future__ import annotations

import base64
import io
import threading
import warnings
from typing import Any

import numpy as np

from ..analysis.spectrum import amplitude_spectrum, display_band
from ..errors import ModelValidityWarning
from ..plotting import section_times
from .form import Form

__all__ = ["simulate_form", "views", "images", "status_lines", "period_of", "below_toolbar",
           "POINTS", "TOOLBAR_BAND"]  # fmt: skip

#: At most this many points per trace reach the browser.
POINTS = 20_000
#: matplotlib's pyplot is not thread-safe; the server answers requests in threads.
_MPL_LOCK = threading.Lock()
#: The band (px) at the top of a graph where Plotly draws its toolbar (the mode bar,
#: right-aligned, about 25 px high); every graph of the app sets its title below it.
TOOLBAR_BAND = 34


def below_toolbar(fig):
    """``fig`` with its title, whatever it says, below the toolbar's band and left-aligned,
    and a top margin that holds both: a title in Plotly's default place, centred in the top
    margin, runs under the toolbar as soon as it is longer than the room left of it (the
    sweep browser's heading, the section's and the spectrum's titles were covered)."""
    return fig.update_layout(
        title=dict(x=0, xref="paper", xanchor="left", y=1, yref="container", yanchor="top",
                   pad=dict(t=TOOLBAR_BAND)),
        margin=dict(t=TOOLBAR_BAND + 36),
    )  # fmt: skip


def simulate_form(form: Form):
    """Simulate a valid `recipdyn.app.form.Form`; returns ``(record, warnings)``:
    the messages of the warnings the run raised (a law stretched beyond its range, ...),
    each once, to be shown on the page rather than on the server's console. The validity
    warning is left out: the record's ``validity`` attribute carries it (see
    `status_lines`)."""
    from ..simulate import simulate

    s = form.settings
    kw = dict(revolutions=s["revolutions"], transient=s["transient"], fs=s["fs"],
              method=s["method"], rtol=s["rtol"], atol=s["atol"])  # fmt: skip
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = simulate(form.params, model=form.model, **kw)
    notes = [str(w.message) for w in caught if not issubclass(w.category, ModelValidityWarning)]
    return ds, list(dict.fromkeys(notes))


def period_of(ds) -> float | None:
    """The forcing period of a record (the crank period for the compressors), from its
    attributes; None for an autonomous system or a map."""
    from ..io import forcing_frequency

    fc = forcing_frequency(ds.attrs) if "time" in ds.dims else None
    return 1.0 / fc if fc else None


def _label(ds, name: str) -> str:
    u = ds[name].attrs.get("units", "") if name in ds.variables else ""
    return f"{name} ({u.replace('**2', '²')})" if u not in ("", "1") else name


def views(ds, model) -> list[Any]:
    """Four interactive views of a record: the vibration signal over time, its amplitude
    spectrum (log scale), the phase portrait of the model's section pair and its
    stroboscopic section (once per forcing period; for a map, its iterates)."""
    import plotly.graph_objects as go

    dim = "iteration" if "iteration" in ds.dims else "time"
    t = ds[dim].values
    name = model.vibration()[0]
    name = name if name in ds else next(k for k in ds.data_vars if ds[k].dims == (dim,))
    y = ds[name].values
    step = max(1, t.size // POINTS)
    is_map = dim == "iteration"
    mode = "markers" if is_map else "lines"
    sig = go.Figure(go.Scattergl(x=t[::step], y=y[::step], mode=mode, line=dict(width=1),
                                 marker=dict(size=3)))  # fmt: skip
    tu = ds[dim].attrs.get("units", "")
    sig.update_layout(title=f"{name}: the vibration signal", yaxis_title=_label(ds, name),
                      xaxis_title=f"{dim} ({tu})" if tu not in ("", "1") else dim)  # fmt: skip
    period = period_of(ds)
    spc = go.Figure()
    if not is_map and t.size >= 4:
        fs = 1.0 / float(np.median(np.diff(t)))
        spec = amplitude_spectrum(y, fs)
        top = display_band(spec, 1.0 / period if period else None)
        keep = spec.frequency <= top
        spc.add_trace(go.Scatter(x=spec.frequency[keep], y=np.maximum(spec.amplitude[keep],
                                 1e-12), mode="lines", line=dict(width=1)))  # fmt: skip
        spc.update_layout(title=f"amplitude spectrum of {name} (Hann)", yaxis_type="log",
                          xaxis_title="frequency (Hz)", yaxis_title=_label(ds, name))  # fmt: skip
    else:
        spc.update_layout(title="no spectrum (a map, or too few samples)")
    a, b = model.pair()
    ph, sec = go.Figure(), go.Figure()
    if a in ds and b in ds:
        xa, xb = ds[a].values, ds[b].values
        ph.add_trace(go.Scattergl(x=xa[::step], y=xb[::step], mode=mode, line=dict(width=0.6),
                                  marker=dict(size=2)))  # fmt: skip
        ph.update_layout(title=f"phase portrait {a}-{b}", xaxis_title=_label(ds, a),
                         yaxis_title=_label(ds, b))  # fmt: skip
        if is_map:
            sx, sy, what = xa, xb, f"the map's iterates ({xa.size})"
        else:
            ts, once = section_times(ds, period)  # a motor's crank: once per turn
            sx, sy = np.interp(ts, t, xa), np.interp(ts, t, xb)
            what = (f"{ts.size} point{'s' if ts.size != 1 else ''}, {once}" if once != "none" else
                    "none: an autonomous system has no forcing period")  # fmt: skip
        sec.add_trace(go.Scatter(x=sx, y=sy, mode="markers", marker=dict(size=5)))
        sec.update_layout(title=f"section ({what})", xaxis_title=_label(ds, a),
                          yaxis_title=_label(ds, b))  # fmt: skip
    for fig in (sig, spc, ph, sec):
        below_toolbar(fig.update_layout(margin=dict(l=60, r=20, b=50), showlegend=False))
    return [sig, spc, ph, sec]


def _has_cycle(ds) -> bool:
    """Whether the record's load is the compression cycle (the condition under which
    ``recipdyn simulate`` also writes the cycle figure)."""
    cycle = ds.attrs.get("param_load") == "cycle" or "y_suction_head" in ds.data_vars
    return cycle and {"p_head", "V_head", "theta1", "a", "gas_force"} <= set(ds.data_vars)


def _png(fig, dpi: int) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def images(ds, dpi: int = 80) -> list[tuple[str, str]]:
    """The figures ``recipdyn simulate`` writes for this record, as ``(title, PNG data
    URI)``: the model's figure (the compressor's response, the contact joint's orbit and
    joint forces, any other model's signals and phase portrait) and, when the load is the
    compression cycle, the cycle figure (p-V diagram, pressures, rod load, valve lifts)."""
    from ..plotting import _mpl, cycle_figure, model_figure

    out = []
    with _MPL_LOCK:
        plt = _mpl()
        ds = ds.load()
        makers = [("figure of recipdyn simulate", model_figure)]
        if _has_cycle(ds):
            makers.append(("compression cycle (recipdyn simulate's .cycle.png)", cycle_figure))
        for title, make in makers:
            fig = make(ds)
            try:
                out.append((title, _png(fig, dpi)))
            finally:
                plt.close(fig)
    return out


def status_lines(ds, model) -> list[str]:
    """What the run says about itself: the model, samples, solver, its summary (the lines
    ``recipdyn simulate`` prints) and whether it left the model's validity."""
    dim = "iteration" if "iteration" in ds.dims else "time"
    head = f"{model.name}: {ds.sizes[dim]} samples"
    if "param_omega" in ds.attrs:
        head += f", omega = {float(ds.attrs['param_omega']):g} rad/s"
    for key in ("rc", "d"):
        v = ds.attrs.get(f"param_{key}")
        if isinstance(v, (int, float, np.floating)):
            head += f", {key} = {1e3 * float(v):g} mm"
    if "solver_nfev" in ds.attrs:
        head += f" | {ds.attrs.get('solver_method')} nfev = {int(ds.attrs['solver_nfev'])}"
    lines = [head]
    summary = model.run_summary(model.values_from_record(ds.attrs), ds) if ds.sizes[dim] else {}
    for k, v in summary.items():
        lines.append(f"{k} = {v:.4g}" if isinstance(v, float) else f"{k} = {v}")
    if ds.attrs.get("validity", "ok") != "ok":
        lines.append(f"outside the model: {ds.attrs['validity']}")
    return lines
