"""``recipdyn app``: a local web app to explore the compressor and browse sweeps.

Every parameter of the model's schema is a widget with its unit and allowed range; "Simulate"
runs the model and draws the crosshead acceleration, its amplitude spectrum, the v-a phase
portrait, the once-per-revolution Poincaré section and the clearance link's (theta_c,
theta_c') portrait. The sweep browser opens a sweep store, shows its fault map (2-D) or
bifurcation diagram (1-D); clicking a point simulates that point with the store's base case.

Why Dash: a plain Flask server with React components, so the app is one Python process and
its callbacks are plain functions (tested here without a browser, and once in a real headless
Chromium); Plotly figures report clicks on map cells, which the sweep browser needs. Panel/
HoloViews would add Bokeh, param and a Tornado server for the same result.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np

from .analysis.spectrum import amplitude_spectrum, display_band
from .errors import ParameterError
from .model.parameters import SCHEMA, CompressorParams

__all__ = ["build_app", "run_figures", "sweep_figure", "point_from_click", "WIDGETS"]

#: The schema parameters shown as numeric widgets (the rest keep their defaults).
WIDGETS = tuple(p for p in SCHEMA.params if isinstance(p.default, float) and not p.optional)
#: Choice parameters shown as drop-downs.
CHOICES = tuple(p for p in SCHEMA.params if p.choices)
#: Run settings of the app (short runs: the app is for exploring).
RUN_DEFAULTS = {"revolutions": 5.0, "fs": 5000.0}


def _params(values: dict[str, Any]) -> CompressorParams:
    try:
        return CompressorParams(**values)
    except (TypeError, ValueError) as exc:  # ParameterError is a ValueError
        raise ParameterError(str(exc)) from None


def run_figures(values: dict[str, Any], revolutions: float, fs: float,
                transient: float = 0.0) -> tuple[list[Any], str]:  # fmt: skip
    """Simulate ``values`` and return the five Plotly figures and a status line."""
    import plotly.graph_objects as go

    from .simulate import simulate

    if not (revolutions and 0 < revolutions <= 200):
        raise ParameterError(f"revolutions: {revolutions}; allowed: 0 < revolutions <= 200")
    if not (fs and 100 <= fs <= 100_000):
        raise ParameterError(f"fs: {fs} Hz; allowed: 100 to 100000 Hz")
    p = _params(values)
    import warnings

    from .errors import ModelValidityWarning

    with warnings.catch_warnings():  # shown in the status line instead
        warnings.simplefilter("ignore", ModelValidityWarning)
        ds = simulate(p, revolutions=revolutions, transient=transient, fs=fs)
    t, a, v = ds.time.values, ds.a.values, ds.v.values
    step = max(1, t.size // 20_000)  # at most 20 000 points per trace in the browser
    sig = go.Figure(go.Scattergl(x=t[::step], y=a[::step], mode="lines", line=dict(width=1)))
    sig.update_layout(title="crosshead acceleration", xaxis_title="time (s)",
                      yaxis_title="a (m/s²)")  # fmt: skip
    spec = amplitude_spectrum(a, fs)
    top = display_band(spec, p.crank_frequency)
    keep = spec.frequency <= top
    spc = go.Figure(go.Scatter(x=spec.frequency[keep], y=np.maximum(spec.amplitude[keep], 1e-12),
                               mode="lines", line=dict(width=1)))  # fmt: skip
    spc.update_layout(title="amplitude spectrum of a (Hann)", xaxis_title="frequency (Hz)",
                      yaxis_title="amplitude (m/s²)", yaxis_type="log")  # fmt: skip
    ph = go.Figure(go.Scattergl(x=v[::step], y=a[::step], mode="lines", line=dict(width=0.6)))
    ph.update_layout(title="phase portrait v-a", xaxis_title="v (m/s)", yaxis_title="a (m/s²)")
    T = p.crank_period
    from .analysis.poincare import strobe_times

    ts = strobe_times(t[0], t[-1], T)
    sec = go.Figure(go.Scatter(x=np.interp(ts, t, v), y=np.interp(ts, t, a), mode="markers"))
    sec.update_layout(title=f"Poincaré section, once per revolution ({ts.size} points)",
                      xaxis_title="v (m/s)", yaxis_title="a (m/s²)")  # fmt: skip
    link = go.Figure(go.Scattergl(x=ds.theta_c.values[::step], y=ds.thetadot_c.values[::step],
                                  mode="lines", line=dict(width=0.6)))  # fmt: skip
    link.update_layout(title="clearance link", xaxis_title="theta_c (rad)",
                       yaxis_title="theta_c' (rad/s)")  # fmt: skip
    status = (f"rc = {1e3 * p.rc:g} mm, d = {1e3 * p.d:g} mm, omega = {p.omega:g} rad/s: "
              f"{t.size} samples, peak |a| = {np.abs(a).max():.4g} m/s², min contact force "
              f"{ds.attrs['min_contact_force_N']:.4g} N")  # fmt: skip
    if ds.attrs.get("validity", "ok") != "ok":
        status += f" | outside the model: {ds.attrs['validity']}"
    return [sig, spc, ph, sec, link], status


def _open(store: str | Path):
    from .sweep.run import open_sweep

    path = Path(store)
    if path.is_dir() and (path / "sweep.zarr").is_dir():
        path = path / "sweep.zarr"
    if not path.is_dir():
        raise ParameterError(f"store {store}: not found (a sweep folder or its sweep.zarr)")
    return open_sweep(path)


def sweep_figure(store: str | Path, variable: str | None = None) -> tuple[Any, list[str], str]:
    """The sweep's map (2-D: a heat map of ``variable``) or bifurcation diagram (1-D); returns
    ``(figure, variables that can be shown, the variable shown)``."""
    import plotly.graph_objects as go

    ds = _open(store)
    dims = ds.attrs["sweep_axes"].split(",")
    done = ds["done"].values.astype(bool)
    if len(dims) == 2:
        skip = ("done", "checksum", "error")
        options = [
            k for k in ds.data_vars
            if ds[k].dims == tuple(dims) and k not in skip and ds[k].dtype.kind == "f"
        ]  # fmt: skip
        if not options:
            raise ParameterError(f"store {store}: no map variable")
        # a stable order whatever the store lists first: exponent, peaks, RMS, the rest
        rank = ("lambda1", "peak_", "rms_", "min_")
        options.sort(key=lambda k: (next((i for i, r in enumerate(rank) if k.startswith(r)),
                                         len(rank)), k))  # fmt: skip
        variable = variable if variable in options else options[0]
        z = np.where(done, ds[variable].values, np.nan)
        fig = go.Figure(go.Heatmap(x=ds[dims[1]].values, y=ds[dims[0]].values, z=z,
                                   colorbar=dict(title=variable)))  # fmt: skip
        for axis, dim in (("xaxis", dims[1]), ("yaxis", dims[0])):
            log = ds[dim].attrs.get("scale") == "log"
            fig.update_layout({axis: dict(title=f"{dim} ({ds[dim].attrs.get('units', '')})",
                                          type="log" if log else "linear")})  # fmt: skip
        fig.update_layout(title=f"fault map: {variable} (click a cell to simulate it)")
        return fig, options, variable
    dim = dims[0]
    options = [k for k in ds.data_vars if k.startswith("poincare_") and ds[k].ndim == 2]
    if not options:
        raise ParameterError(f"store {store}: a 1-D sweep without a Poincaré section")
    variable = variable if variable in options else options[0]
    x = np.repeat(ds[dim].values[:, None], ds[variable].shape[1], axis=1)[done].ravel()
    y = ds[variable].values[done].ravel()
    fig = go.Figure(go.Scattergl(x=x, y=y, mode="markers", marker=dict(size=2, color="black")))
    fig.update_layout(title=f"bifurcation diagram: {variable} (click a value to simulate it)",
                      xaxis_title=f"{dim} ({ds[dim].attrs.get('units', '')})",
                      yaxis_title=variable)  # fmt: skip
    return fig, options, variable


def point_from_click(store: str | Path, click: dict) -> dict[str, Any]:
    """The parameter values of the sweep point under a Plotly click: the store's base case
    with the swept parameters at the nearest grid values."""
    from .simulate import params_from_attrs

    ds = _open(store)
    dims = ds.attrs["sweep_axes"].split(",")
    pt = (click or {}).get("points", [{}])[0]
    if "x" not in pt:
        raise ParameterError("click: no point")
    coords = {dims[-1]: pt["x"]} if len(dims) == 1 else {dims[1]: pt["x"], dims[0]: pt["y"]}
    base = dataclasses.asdict(params_from_attrs(ds.attrs))
    for dim, val in coords.items():
        grid = ds[dim].values
        base[dim] = float(grid[np.argmin(np.abs(grid - float(val)))])
    return base


def build_app(store: str | Path | None = None):
    """The Dash application (``app.run(port=...)`` serves it)."""
    from dash import Dash, Input, Output, State, dcc, html

    app = Dash(__name__, title="recipdyn")
    p0 = CompressorParams()
    rows = []
    for prm in WIDGETS:
        lo = prm.low if np.isfinite(prm.low) else None
        hi = prm.high if np.isfinite(prm.high) else None
        rows.append(html.Div([
            html.Label(f"{prm.name} ({prm.unit.replace('**2', '²') or '-'})",
                       htmlFor=f"p-{prm.name}",
                       title=prm.description + (f" [{prm.assumed}]" if prm.assumed else ""),
                       style={"width": "11em", "display": "inline-block"}),
            dcc.Input(id=f"p-{prm.name}", type="number", value=getattr(p0, prm.name),
                      min=lo, max=hi, step="any", style={"width": "10em"}),
            html.Span(" assumed" if prm.assumed else "", style={"color": "#D55E00"}),
        ]))  # fmt: skip
    for prm in CHOICES:
        rows.append(html.Div([
            html.Label(prm.name, style={"width": "11em", "display": "inline-block"}),
            dcc.Dropdown(id=f"p-{prm.name}", options=list(prm.choices),
                         value=getattr(p0, prm.name), clearable=False,
                         style={"width": "10em", "display": "inline-block"}),
        ]))  # fmt: skip
    graphs = ["signal", "spectrum", "phase", "section", "link"]
    app.layout = html.Div([
        html.H2("recipdyn: reciprocating compressor with a clearance joint"),
        html.Div([
            html.Div([
                html.H4("Parameters (hover a name for its meaning)"), *rows,
                html.H4("Run"),
                html.Label("revolutions "), dcc.Input(id="revolutions", type="number",
                                                      value=RUN_DEFAULTS["revolutions"], min=0.1,
                                                      max=200, step="any"),
                html.Br(), html.Label("fs (Hz) "),
                dcc.Input(id="fs", type="number", value=RUN_DEFAULTS["fs"], min=100,
                          max=100000, step="any"),
                html.Br(), html.Button("Simulate", id="run", n_clicks=0),
                html.H4("Sweep browser"),
                dcc.Input(id="store", type="text", value=str(store) if store else "",
                          placeholder="folder of a sweep", style={"width": "20em"}),
                html.Button("Open", id="open", n_clicks=0),
                dcc.Dropdown(id="sweep-var", options=[], value=None),
            ], style={"width": "26em", "flex": "none", "fontSize": "13px"}),
            html.Div([
                html.Div(id="status", style={"fontFamily": "monospace", "margin": "4px"}),
                dcc.Loading(html.Div([dcc.Graph(id=f"g-{g}", style={"height": "330px"})
                                      for g in graphs],
                                     style={"display": "grid",
                                            "gridTemplateColumns": "1fr 1fr"})),
                dcc.Graph(id="sweep", style={"height": "480px"}),
            ], style={"flex": "1"}),
        ], style={"display": "flex", "gap": "1em"}),
    ], style={"fontFamily": "sans-serif"})  # fmt: skip

    param_ids = [f"p-{p.name}" for p in (*WIDGETS, *CHOICES)]
    names = [p.name for p in (*WIDGETS, *CHOICES)]

    @app.callback(
        [Output(f"g-{g}", "figure") for g in graphs] + [Output("status", "children")]
        + [Output(i, "value") for i in param_ids],
        Input("run", "n_clicks"), Input("sweep", "clickData"),
        [State(i, "value") for i in param_ids] + [State("revolutions", "value"),
                                                  State("fs", "value"), State("store", "value")],
    )  # fmt: skip
    def _simulate(_n, click, *state):
        from dash import ctx, no_update

        *vals, revolutions, fs, store_path = state
        values = dict(zip(names, vals, strict=True))
        try:
            if ctx.triggered_id == "sweep" and click:
                values = {k: v for k, v in point_from_click(store_path, click).items()
                          if k in names}  # fmt: skip
            figs, status = run_figures(values, float(revolutions or 0), float(fs or 0))
        except ParameterError as exc:
            return [no_update] * len(graphs) + [f"error: {exc}"] + [no_update] * len(names)
        return [*figs, status, *[values[n] for n in names]]

    @app.callback(
        Output("sweep", "figure"), Output("sweep-var", "options"), Output("sweep-var", "value"),
        Input("open", "n_clicks"), Input("sweep-var", "value"), State("store", "value"),
        prevent_initial_call=not bool(store),
    )  # fmt: skip
    def _open_sweep(_n, variable, store_path):
        from dash import no_update

        if not store_path:
            return no_update, no_update, no_update
        try:
            fig, options, shown = sweep_figure(store_path, variable)
        except ParameterError as exc:
            import plotly.graph_objects as go

            return go.Figure().update_layout(title=f"error: {exc}"), [], None
        return fig, options, shown

    return app
