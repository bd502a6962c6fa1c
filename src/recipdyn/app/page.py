"""The page: layout and callbacks. Each callback is a thin wrapper around a plain function
of this module (``panel_for``, ``run_page``, ...), which the tests call without a browser.

Two pages under tabs: "Simulate" (the parameter panel, the run's views and figures, the sweep
browser) and "Diagnose a record" (`recipdyn.app.diagnosis`). The address's fragment names the
page (``#diagnose``), so a link opens it; the tabs hide one page and show the other, both
stay on the page (a form's texts survive a visit to the other).

State lives in the address: ``?model=compressor-contact&rc=0.5+mm&run.revolutions=2`` opens
that model with those fields and runs it; ``?model=compressor&crank_joint=contact&rc=0.5+mm``
opens the compressor's contact configuration. Changing a selector (crank_joint, load, ...)
redraws the panel with that configuration's fields, keeping the texts of the fields that
remain, and runs nothing (a new configuration may compile first): Simulate runs it. Choosing a
model, clicking a sweep point or a run that succeeds writes the address (one history entry
each), so the browser's back button and a copied link give the same page.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ParameterError
from ..model.registry import DEFAULT_MODEL, configured_for_record, get_model, model_names
from .diagnosis import diagnosis_page
from .figures import below_toolbar, images, simulate_form, status_lines, views
from .form import (
    RUN,
    Field,
    config_text,
    fields,
    format_value,
    from_query,
    read_form,
    selected,
    selector_errors,
    to_query,
)

__all__ = ["build_app", "panel_for", "run_page", "PageResult", "click_query", "GRAPHS", "PAGES"]

#: The interactive views, in the order `recipdyn.app.figures.views` returns them.
GRAPHS = ("signal", "spectrum", "phase", "section")
#: The pages (tab value -> label); the first opens by default, ``#<value>`` opens another.
PAGES = {"simulate": "Simulate", "diagnose": "Diagnose a record"}
_RED = "#B00020"
_INPUT = {"width": "12em"}


def _field_row(f: Field, text: Any, error: str = "") -> Any:
    from dash import dcc, html

    tip = f.description + (f" [assumed: {f.assumed}]" if f.assumed else "")
    if f.choices is not None:
        widget = dcc.Dropdown(id={"type": "choice", "key": f.key}, options=list(f.choices),
                              value=text if text in f.choices else f.default, clearable=False,
                              style={"width": "13em"})  # fmt: skip
    else:
        widget = dcc.Input(id={"type": "field", "key": f.key}, type="text", value=text,
                           placeholder="derived" if f.optional else f.default_text,
                           debounce=False, style=_INPUT)  # fmt: skip
    unit = f.unit.replace("**2", "²").replace("**1.5", "^1.5")
    return html.Div([
        html.Div([
            html.Label(f.name, title=tip, style={"width": "10.5em", "display": "inline-block",
                                                  "fontWeight": "bold" if f.assumed == "" else
                                                  "normal"}),
            html.Div(widget, style={"display": "inline-block", "verticalAlign": "middle"}),
            html.Span(f" {unit}" if unit and f.choices is None else "",
                      style={"marginLeft": "0.3em"}),
            html.Span(" assumed", title=f.assumed, style={"color": "#D55E00"})
            if f.assumed else None,
        ]),
        html.Div(f"allowed {f.range_text()}" + ("; empty: derived" if f.optional else ""),
                 style={"color": "#666", "fontSize": "11px", "marginLeft": "10.5em"}),
        html.Div(error, id={"type": "ferr", "key": f.key},
                 style={"color": _RED, "fontSize": "12px", "marginLeft": "10.5em"}),
    ], style={"marginBottom": "4px"})  # fmt: skip


def panel_for(model: str, texts: dict[str, str]) -> list[Any]:
    """The parameter panel of ``model``: its selectors first (if it has any), then one group
    per schema group of the configuration they choose (the run settings last), each field
    holding ``texts[key]`` or its default."""
    from dash import html

    groups: dict[str, list[Any]] = {}
    refused = selector_errors(model, texts)  # a combination that does not exist: told at once
    for f in fields(model, texts):
        text = texts.get(f.key, f.default if f.choices is not None else f.default_text)
        groups.setdefault("run" if f.key.startswith(RUN) else f.group, []).append(
            _field_row(f, text, refused.get(f.key, ""))
        )
    return [html.Details([html.Summary(g, style={"fontWeight": "bold", "cursor": "pointer"}),
                          *rows], open=True, style={"marginBottom": "6px"})
            for g, rows in groups.items()]  # fmt: skip


@dataclass
class PageResult:
    """What a Simulate press puts on the page."""

    figures: list[Any]
    images: list[tuple[str, str]]
    status: list[str]
    errors: dict[str, str] = field(default_factory=dict)
    general: str = ""
    query: str | None = None  #: the address of the run (None: the run failed)


def _empty() -> Any:
    import plotly.graph_objects as go

    fig = go.Figure().update_layout(
        xaxis_visible=False,
        yaxis_visible=False,
        plot_bgcolor="white",
        margin=dict(l=10, r=10, b=10),
    )
    return below_toolbar(fig)


def run_page(model: str, texts: dict[str, Any]) -> PageResult:
    """Read the form, simulate and draw; with any error the figures are cleared and each
    message is given to its field (or to ``general``)."""
    from ..integrate import IntegrationError

    if model not in model_names():  # the page offers registered models only
        return PageResult([_empty() for _ in GRAPHS], [], [f"not run: unknown model {model!r}"],
                          general=f"unknown model {model!r}")  # fmt: skip
    form = read_form(model, texts)
    blank = PageResult([_empty() for _ in GRAPHS], [], [], dict(form.errors), form.general)
    if not form.ok:
        n = len(form.errors)
        blank.status = [f"not run: {n} field(s) to correct ({', '.join(form.errors)})" if n
                        else f"not run: {form.general}"]  # fmt: skip
        return blank
    try:
        ds, notes = simulate_form(form)
    except (ParameterError, IntegrationError) as exc:
        blank.general = str(exc)
        blank.status = [f"not run: {exc}"]
        return blank
    m = form.model
    run = configured_for_record(m, ds.attrs)  # the declarations of the run's configuration
    status = status_lines(ds, run) + [f"warning: {n}" for n in notes]
    return PageResult(views(ds, run), images(ds), status, query=to_query(m, texts))


def click_query(store: str, click: dict, texts: dict[str, Any]) -> str:
    """The address of the sweep point under ``click``: the store's model and base case with
    the clicked values, and the run settings of the form."""
    from .sweeps import point_from_click

    name, values = point_from_click(store, click)
    by_key = {f.key: f for f in fields(name, values)}
    out = {k: format_value(v, by_key[k]) for k, v in values.items() if k in by_key}
    out.update({k: v for k, v in texts.items() if k.startswith(RUN)})
    return to_query(name, out)


def _texts(ids: list[dict], values: list[Any]) -> dict[str, Any]:
    return {i["key"]: v for i, v in zip(ids, values, strict=True)}


def page_of(fragment: str | None) -> str:
    """The page an address's fragment names (``#diagnose``), the first page otherwise."""
    name = (fragment or "").lstrip("#")
    return name if name in PAGES else next(iter(PAGES))


def _import_once() -> None:
    """Import dask and pint here, in one thread, before the server answers requests in
    threads: the first request of a page opens the sweep (dask) and draws the panel (pint,
    which imports dask.base) at once, and dask's package and its ``dask.base`` import each
    other, so two threads importing them at once could meet a half-imported ``dask.base``
    (ImportError: cannot import name 'annotate' from partially initialized module)."""
    import importlib.util

    from ..quantity import _ureg

    if importlib.util.find_spec("dask") is not None:
        import dask  # noqa: F401
    _ureg()


def build_app(store: str | Path | None = None):
    """The Dash application (``app.run(port=...)`` serves it)."""
    from dash import ALL, Dash, Input, Output, State, ctx, dcc, html, no_update
    from dash.exceptions import PreventUpdate

    _import_once()
    app = Dash(__name__, title="recipdyn")
    options = [{"label": f"{n}" + (" (default)" if n == DEFAULT_MODEL else ""), "value": n}
               for n in model_names()]  # fmt: skip
    button = {"marginRight": "0.5em", "marginTop": "0.5em"}
    tab = {"padding": "6px 18px", "fontWeight": "bold", "width": "auto", "flex": "0 0 auto"}
    app.layout = html.Div([
        dcc.Location(id="url", refresh=False),
        dcc.Location(id="nav", refresh="callback-nav"),
        dcc.Store(id="shown"), dcc.Store(id="go", data=0), dcc.Download(id="download"),
        dcc.Store(id="configuration"),
        html.Div([
            html.H2("recipdyn: reciprocating compressor dynamics",
                    style={"margin": "4px 1em 4px 0", "display": "inline-block"}),
            dcc.Tabs(id="page", value=next(iter(PAGES)), children=[
                dcc.Tab(label=label, value=value, id=f"tab-{value}", style=tab,
                        selected_style=tab | {"borderTop": "3px solid #0072B2"})
                for value, label in PAGES.items()],
                parent_style={"display": "inline-block", "verticalAlign": "bottom"},
                style={"height": "36px"}),
        ], style={"borderBottom": "1px solid #d6d6d6", "marginBottom": "6px"}),
        html.Div([
            html.Div([
                html.Label("model ", htmlFor="model", style={"fontWeight": "bold"}),
                dcc.Dropdown(id="model", options=options, value=DEFAULT_MODEL,
                             clearable=False),
                html.Div(id="model-help", style={"fontSize": "12px", "color": "#444",
                                                 "margin": "4px 0"}),
                html.Div("Type values with units ('0.5 mm', '300 rpm', '3 bar'); a bare number "
                         "is read in the unit beside the field. Hover a name for its meaning. "
                         "A model's first run on a machine compiles it (a minute or two).",
                         style={"fontSize": "12px", "color": "#444", "marginBottom": "6px"}),
                html.Button("Simulate", id="run", n_clicks=0, style=button),
                html.Button("Download config", id="dl", n_clicks=0, style=button,
                            title="a TOML file that 'recipdyn simulate -c FILE' runs"),
                html.Div(id="form-error", style={"color": _RED}),
                html.Div(id="dl-msg", style={"color": _RED, "fontSize": "12px"}),
                html.Div([
                    html.Div(id="panel"),
                    html.H4("Sweep browser"),
                    dcc.Input(id="store", type="text", value=str(store) if store else "",
                              placeholder="folder of a sweep", style={"width": "20em"}),
                    html.Button("Open", id="open", n_clicks=0),
                    dcc.Dropdown(id="sweep-var", options=[], value=None),
                ], id="panel-scroll", style={"maxHeight": "calc(100vh - 230px)",
                                             "overflowY": "auto", "marginTop": "6px",
                                             "borderTop": "1px solid #ccc"}),
            ], style={"width": "31em", "flex": "none", "fontSize": "13px"}),
            html.Div([
                html.Div(id="status", style={"fontFamily": "monospace", "margin": "4px",
                                             "whiteSpace": "pre-wrap"}),
                dcc.Loading(html.Div([
                    html.Div([dcc.Graph(id=f"g-{g}", figure=_empty(), config={"displaylogo": False},
                                        style={"height": "330px"}) for g in GRAPHS],
                             style={"display": "grid", "gridTemplateColumns": "1fr 1fr"}),
                    html.Div(id="images"),
                ])),
                dcc.Graph(id="sweep", style={"height": "480px"}, figure=_empty().update_layout(
                    title="sweep browser: open a sweep folder to see its map")),
            ], style={"flex": "1", "minWidth": "0"}),
        ], id="simulate-page", style={"display": "flex", "gap": "1em"}),
        html.Div(diagnosis_page(), id="diagnose-tab", style={"display": "none"}),
    ], style={"fontFamily": "sans-serif"})  # fmt: skip

    fields_state = [State({"type": "field", "key": ALL}, "value"),
                    State({"type": "field", "key": ALL}, "id"),
                    State({"type": "choice", "key": ALL}, "value"),
                    State({"type": "choice", "key": ALL}, "id")]  # fmt: skip

    def form_texts(fv, fi, cv, ci) -> dict[str, Any]:
        return {**_texts(fi, fv), **_texts(ci, cv)}

    @app.callback(Output("page", "value"), Input("url", "hash"), State("page", "value"))
    def _open_page(fragment, shown):
        # a link's fragment (#diagnose) opens its page; a fragment naming the page already
        # shown changes nothing, so that the first load's answer (the first page) cannot
        # arrive after a click on a tab and take the click back
        name = page_of(fragment)
        if name == shown:
            raise PreventUpdate
        return name

    @app.callback(
        Output("simulate-page", "style"), Output("diagnose-tab", "style"),
        Output("nav", "hash"), Input("page", "value"), State("url", "hash"),
        State("simulate-page", "style"),
    )  # fmt: skip
    def _show_page(name, fragment, style):
        # one page shown, the other hidden (both stay: their texts survive); the address
        # names the page shown, so that a copied link opens it
        shown = {**style, "display": "flex" if name == "simulate" else "none"}
        other = {"display": "block" if name == "diagnose" else "none"}
        first = next(iter(PAGES))
        want = "" if name == first else f"#{name}"
        return shown, other, no_update if (fragment or "") == want else want

    @app.callback(
        Output("model", "value"), Output("panel", "children"), Output("model-help", "children"),
        Output("form-error", "children"), Output("go", "data"), Output("configuration", "data"),
        Input("url", "search"), State("shown", "data"), State("go", "data"),
    )  # fmt: skip
    def _panel(search, shown, go):
        name, texts, err = from_query(search)
        if shown is not None and to_query(name, texts) == shown:
            raise PreventUpdate  # the run on the page is this address's run
        return (name, panel_for(name, texts), get_model(name).description, err,
                (go or 0) + 1, [name, selected(name, texts)])  # fmt: skip

    @app.callback(
        Output("panel", "children", allow_duplicate=True),
        Output("configuration", "data", allow_duplicate=True),
        Input({"type": "choice", "key": ALL}, "value"), State("model", "value"),
        State("configuration", "data"), *fields_state,
        prevent_initial_call=True,
    )  # fmt: skip
    def _reconfigure(_choices, name, shown, *state):
        # a selector changed: the panel of the configuration it chooses (no run: the next
        # Simulate runs it and writes the address)
        if name not in model_names():
            raise PreventUpdate
        texts = form_texts(*state)
        now = [name, selected(name, texts)]
        if shown == now:
            raise PreventUpdate  # (a choice that is no selector, or the panel just drawn)
        return panel_for(name, texts), now

    @app.callback(
        Output("nav", "search", allow_duplicate=True),
        Input("model", "value"), State("url", "search"), *fields_state,
        prevent_initial_call=True,
    )  # fmt: skip
    def _choose(name, search, *state):
        if name == from_query(search)[0]:
            raise PreventUpdate
        run = {k: v for k, v in form_texts(*state).items() if k.startswith(RUN)}
        return to_query(name, run)

    @app.callback(
        [Output(f"g-{g}", "figure") for g in GRAPHS]
        + [Output("images", "children"), Output("status", "children"),
           Output({"type": "ferr", "key": ALL}, "children"),
           Output("form-error", "children", allow_duplicate=True),
           Output("nav", "search", allow_duplicate=True), Output("shown", "data"),
           Output({"type": "field", "key": ALL}, "style")],
        Input("run", "n_clicks"), Input("go", "data"),
        Input({"type": "field", "key": ALL}, "n_submit"),
        State("model", "value"), State("url", "search"), *fields_state,
        prevent_initial_call=True,
    )  # fmt: skip
    def _simulate(_n, _go, _submit, name, search, *state):
        if all(t["prop_id"].endswith(".n_submit") and not t["value"] for t in ctx.triggered):
            raise PreventUpdate  # fields just drawn (a selector changed), no Enter pressed
        texts = form_texts(*state)
        res = run_page(name, texts)
        errs = [res.errors.get(o["id"]["key"], "") for o in ctx.outputs_list[6]]
        imgs = [html.Figure([html.Img(src=src, alt=title, style={"maxWidth": "100%"}),
                             html.Figcaption(title, style={"fontSize": "12px"})])
                for title, src in res.images]  # fmt: skip
        status = html.Div([html.Div(line) for line in res.status],
                          style={"color": _RED} if res.query is None else {})  # fmt: skip
        nav = res.query if res.query is not None and res.query != search else no_update
        marks = [_INPUT | ({"borderColor": _RED, "outline": f"1px solid {_RED}"}
                           if o["id"]["key"] in res.errors else {})
                 for o in ctx.outputs_list[10]]  # fmt: skip
        return [*res.figures, imgs, status, errs, res.general, nav, res.query, marks]

    @app.callback(
        Output("download", "data"), Output("dl-msg", "children"),
        Input("dl", "n_clicks"), State("model", "value"), *fields_state,
        prevent_initial_call=True,
    )  # fmt: skip
    def _download(_n, name, *state):
        if name not in model_names():
            raise PreventUpdate
        form = read_form(name, form_texts(*state))
        if not form.ok:
            bad = "; ".join([*form.errors.values(), form.general][: len(form.errors) or 1])
            return no_update, f"no config written: {bad}"
        return dcc.send_string(config_text(form), f"recipdyn-{form.model.name}.toml"), ""

    @app.callback(
        Output("sweep", "figure"), Output("sweep-var", "options"), Output("sweep-var", "value"),
        Input("open", "n_clicks"), Input("sweep-var", "value"), State("store", "value"),
        prevent_initial_call=not bool(store),
    )  # fmt: skip
    def _open_sweep(_n, variable, store_path):
        from .sweeps import sweep_figure

        if not store_path:
            return no_update, no_update, no_update
        try:
            fig, opts, shown = sweep_figure(store_path, variable)
        except ParameterError as exc:
            return _empty().update_layout(title=f"error: {exc}"), [], None
        return fig, opts, shown

    @app.callback(
        Output("nav", "search", allow_duplicate=True),
        Output("form-error", "children", allow_duplicate=True),
        Input("sweep", "clickData"), State("store", "value"), *fields_state,
        prevent_initial_call=True,
    )  # fmt: skip
    def _click(click, store_path, *state):
        try:
            return click_query(store_path, click, form_texts(*state)), ""
        except ParameterError as exc:
            return no_update, str(exc)

    @app.callback(Output("dx-file", "children"), Input("dx-upload", "filename"))
    def _dx_file(filename):
        return f"record: {filename}" if filename else ""

    @app.callback(
        Output("dx-result", "children"),
        Input("dx-run", "n_clicks"), Input("dx-example", "n_clicks"),
        State("dx-upload", "contents"), State("dx-upload", "filename"),
        State("dx-channel", "value"), State("dx-tacho", "value"), State("dx-speed", "value"),
        State("dx-phead", "value"), State("dx-pcrank", "value"), State("dx-fs", "value"),
        prevent_initial_call=True,
    )  # fmt: skip
    def _diagnose(_n, _example, contents, filename, channel, tacho, speed, ph, pc, fs):
        import tempfile

        from .diagnosis import diagnose_upload, example_record, result_children

        kw = dict(channel=channel, tacho=None if speed else tacho, speed=speed, p_head=ph,
                  p_crank=pc, fs=fs)  # fmt: skip
        if ctx.triggered_id == "dx-example":
            with tempfile.TemporaryDirectory() as tmp:
                kw.update(channel="accel_guide", tacho="tacho", speed=None,
                          p_head="p_head_sensor", p_crank="p_crank_sensor", fs=None)  # fmt: skip
                view = diagnose_upload(None, None, path=example_record(Path(tmp)),
                                       name="the simulated example", **kw)  # fmt: skip
        else:
            view = diagnose_upload(contents, filename, **kw)
        return result_children(view)

    return app
