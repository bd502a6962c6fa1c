"""The diagnosis page: drop a record (or take a simulated example), name its channels, and
see what `recipdyn.diagnose` answers, on a page of its own: the class probabilities (a bar
each), the severity with its interval and the fault's size, the evidence (one row an item:
what was measured, its value, what it means), the channels used, the check that the record
lies in the diagnoser's training domain, and the closest simulated record overlaid at the
page's full width; or the refusal, prominent, with its reason.

The page renders the `Diagnosis` it gets field by field, without knowing them all: a field or
an evidence item it has no words for is shown by its name and value (an evidence item that is
a mapping with a ``meaning`` or ``description`` says what it means itself), so what the
diagnosis layer adds shows up without a change here. Nothing on the page names a file of
the server: the overlay comes as an image, and a message that names the uploaded copy of
the record names the record as the user knows it.

``diagnose_upload`` is the plain function the page's callback wraps; ``result_children``
draws its answer.
"""

from __future__ import annotations

import base64
import math
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ParameterError

__all__ = ["DiagnosisView", "diagnose_upload", "example_record", "result_children",
           "diagnosis_page", "EVIDENCE"]  # fmt: skip

#: File types `recipdyn.diagnose` reads (those of ``recipdyn analyze``).
SUFFIXES = (".csv", ".tsv", ".txt", ".wav", ".mat", ".nc", ".parquet")
_RED = "#B00020"
#: The channel roles the page asks for, as ``diagnose``'s keywords and as the page names them.
ROLES = {"channel": "acceleration", "tacho": "tacho", "speed": "constant speed",
         "p_head": "head-end pressure", "p_crank": "crank-end pressure",
         "fs": "sampling rate"}  # fmt: skip


def _db(share: float) -> str:
    return f"{-10.0 * math.log10(max(float(share), 1e-30)):.0f} dB"


#: What the evidence items `recipdyn.diagnose` gives today are (docs/diagnosis.md): the
#: item's name on the page, what it means, and how its value reads (None: the generic
#: rendering). An item not listed is shown by its name and value, with its own ``meaning``
#: or ``description`` when it carries one.
EVIDENCE: dict[str, tuple[str, str, Any]] = {
    "impacts_per_rev": (
        "impacts per revolution",
        "peaks of the high-passed acceleration above the record's own noise (robust standard "
        "deviations), at least 5 degrees of crank apart, counted per revolution: a joint "
        "with clearance knocks where its load reverses",
        lambda v: f"{float(v):.1f}",
    ),
    "impact_angles_deg": (
        "crank angles of the largest impacts",
        "degrees after the tacho's mark (outer dead centre), the largest at distinct places "
        "of the revolution; none without a tacho",
        lambda v: ", ".join(f"{float(a):.0f}°" for a in v) if len(v) else "none (no tacho)",
    ),
    "deciding": (
        "deciding features",
        "the features farthest from the healthy training records, as robust z (the "
        "distance from their median in interquartile ranges); |z| of a few is ordinary "
        "for a healthy machine",
        lambda v: ", ".join(f"{k} {float(z):+.1f}" for k, z in v),
    ),
    "noise_floor": (
        "accelerometer noise floor",
        "the energy of the quietest 10-degree stretch of the revolution below the mean "
        "stretch's, and the range of the training records: outside it the diagnosis is "
        "withheld (another signal-to-noise ratio)",
        lambda v: (
            f"{_db(v['share'])} below the mean (training "
            f"{_db(v['training_range'][1])} to {_db(v['training_range'][0])})"
        ),
    ),
    "windows": (
        "windows of the data set's length",
        "a record longer than the data set's is classified on its windows of that length, "
        "one revolution apart: the answer is their mean probability, and a class that needs "
        "a confidence threshold is named only where every window reaches it",
        lambda v: (
            f"{v['n']} windows of {float(v['revolutions']):g} revolutions: p "
            + ", ".join(f"{float(x):.2f}" for x in v["p"])
            + " (each window's answer: "
            + ", ".join(v["labels"])
            + ")"
        ),
    ),
    "pressure_deviation": (
        "head-end pressure shape",
        "the largest difference between the record's head-end pressure over a revolution "
        "and the closest healthy simulated record's, each scaled to its own range, and "
        "the crank angle where it is",
        lambda v: f"{float(v['max']):.3f} of the range at {float(v['angle_deg']):.0f}°",
    ),
    "channels": (
        "channels the answer rests on",
        "a class is named only from channels whose answers of it were right often enough "
        "on held-out conditions, or, for a class short of that, where the record's "
        "probability is above the threshold from which its held-out answers were "
        "(docs/diagnosis.md): how often, for the class named",
        lambda v: (
            v["channels"]
            + (
                f": right for {v['precision']:.0%} of its {v['answers']} answers on held-out "
                f"conditions (recall {v['recall']:.0%}; all classes {v['accuracy']:.0%} of "
                f"{v['n']} records)"
                if v.get("measured")
                else ""
            )
            + (
                f"; its confidence threshold p {c['threshold']:.3f} (this record "
                f"{c['p']:.3f}): the held-out answers above it right for {c['precision']:.0%} "
                f"of {c['answers']}"
                if (c := v.get("confidence")) and v.get("measured")
                else ""
            )
        ),
    ),
    "chain": (
        "measurement chain",
        "an error of the sensors or the acquisition estimated from the record itself, with "
        "its 95 % half-width, and what was done with it (corrected before the features, "
        "consistent with the diagnoser's chain, left, or not identified)",
        None,
    ),
    "closest_record": (
        "closest simulated record",
        "the training record of the named class nearest to this record in the diagnoser's "
        "features: the overlay below draws it over this record",
        lambda v: (
            f"{v['label']}, severity {float(v['severity']):.2f} (training record {v['record']})"
        ),
    ),
}

#: The `Diagnosis` fields the page draws in their own places; every other field is listed
#: under "more of the answer", by name and value.
_PLACED = {"refused", "reason", "probabilities", "label", "severity", "severity_interval",
           "value", "value_interval", "unit", "evidence", "ood", "figure", "seconds"}  # fmt: skip


@dataclass
class DiagnosisView:
    """What the page shows for one record: the answer's fields (``result``: the
    `Diagnosis`'s, without the overlay's server path), the channels the page named for it
    (role -> name), the answer as the command line prints it (``lines``), the overlay (a
    data URI), or why there is no answer (``error``: a bad input)."""

    result: dict[str, Any] = field(default_factory=dict)
    channels: dict[str, str] = field(default_factory=dict)
    lines: list[str] = field(default_factory=list)
    error: str = ""
    image: str | None = None

    @property
    def refused(self) -> bool:
        return bool(self.result.get("refused"))

    @property
    def probabilities(self) -> dict[str, float]:
        return dict(self.result.get("probabilities") or {})


def _decode(contents: str) -> bytes:
    """The bytes of a ``dcc.Upload`` value (``data:<type>;base64,<data>``)."""
    try:
        return base64.b64decode(contents.split(",", 1)[1])
    except (IndexError, ValueError):
        raise ParameterError("record: not a file upload (expected base64 contents)") from None


def example_record(folder: Path, revolutions: float = 6.0) -> Path:
    """A simulated example record (NetCDF, the four channels) of the shipped diagnoser's
    domain: the ring leak it pins, at ``revolutions`` revolutions."""
    import json

    from ..diagnosis.dataset import simulate_record
    from ..diagnosis.diagnose import default_model_path
    from ..diagnosis.train import load

    pins = json.loads(load(default_model_path()).state["fingerprints_json"])
    task = dict(next(p["task"] for p in pins if p["task"]["label"] == "ring_leak"))
    task["revolutions"] = revolutions
    rec = simulate_record(task)
    path = Path(folder) / "example_ring_leak.nc"
    rec[["accel_guide", "p_head_sensor", "p_crank_sensor", "tacho"]].to_netcdf(path)
    return path


def _scrub(obj: Any, names: dict[str, str]) -> Any:
    """``obj`` with every server path in ``names`` (path -> what the user calls it) replaced,
    in every string it holds."""
    if isinstance(obj, str):
        for path, name in sorted(names.items(), key=lambda kv: -len(kv[0])):
            obj = obj.replace(path, name)
        return obj
    if isinstance(obj, dict):
        return {k: _scrub(v, names) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return type(obj)(_scrub(v, names) for v in obj)
    return obj


def diagnose_upload(
    contents: str | None,
    filename: str | None,
    *,
    channel: str = "accel_guide",
    tacho: str | None = "tacho",
    speed: str | None = None,
    p_head: str | None = None,
    p_crank: str | None = None,
    fs: str | None = None,
    model: Any = None,
    path: str | Path | None = None,
    name: str | None = None,
) -> DiagnosisView:
    """Diagnose an uploaded record (``contents`` as ``dcc.Upload`` gives it, ``filename``
    for its type) or the file ``path`` (called ``name`` on the page); a bad input comes
    back as ``error``, not raised. No text of the answer names a file of the server."""
    from ..diagnosis.diagnose import diagnose

    blank = {None, ""}
    given = {"channel": channel or "accel_guide", "tacho": tacho, "speed": speed,
             "p_head": p_head, "p_crank": p_crank, "fs": fs}  # fmt: skip
    given = {k: str(v).strip() for k, v in given.items() if v not in blank}
    view = DiagnosisView(channels={ROLES[k]: v for k, v in given.items()})
    with tempfile.TemporaryDirectory() as tmp:
        names = {tmp: "(upload)"}
        try:
            if path is None:
                if not contents or not filename:
                    raise ParameterError("record: drop a file or take the simulated example")
                suffix = Path(filename).suffix.lower()
                if suffix not in SUFFIXES:
                    raise ParameterError(
                        f"record {filename}: type {suffix or '(none)'}; allowed: "
                        + ", ".join(SUFFIXES)
                    )
                path = Path(tmp) / f"record{suffix}"
                path.write_bytes(_decode(contents))
                names[str(path)] = filename
            else:
                names[str(path)] = name or Path(path).name
                names[str(Path(path).parent)] = "(server)"
            res = diagnose(path, **{k: v for k, v in given.items() if k != "channel"},
                           channel=given["channel"], model=model,
                           out=Path(tmp) / "fig")  # fmt: skip
            figure = getattr(res, "figure", None)
            if figure:
                data = base64.b64encode(Path(figure).read_bytes()).decode()
                view.image = f"data:image/png;base64,{data}"
                names[str(figure)] = "shown below"
            result = dict(res.summary())
            result.pop("figure", None)
            view.result = _scrub(result, names)
            view.lines = _scrub(res.text(), names).splitlines()
        except ParameterError as exc:
            view.error = _scrub(str(exc), names)
    return view


# --- drawing ------------------------------------------------------------------------------


def _label(key: str) -> str:
    """A field's or an item's name as the page writes it (``impact_angles_deg`` ->
    ``impact angles (deg)``)."""
    units = {"_deg": "deg", "_hz": "Hz", "_db": "dB", "_s": "s", "_mm": "mm", "_pa": "Pa"}
    for suffix, unit in units.items():
        if key.lower().endswith(suffix):
            return f"{key[: -len(suffix)].replace('_', ' ')} ({unit})"
    return key.replace("_per_rev", " per revolution").replace("_", " ")


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _unit(unit: str | None) -> str:
    """A unit as a reader writes it (``m**2`` -> ``m²``)."""
    return (unit or "").replace("**2", "²").replace("**3", "³").replace("*", "·")


#: Keys of an evidence mapping that say what it means rather than what was measured.
_SAYS = ("meaning", "description", "note")


def _says(d: dict[str, Any]) -> str:
    return next((str(d[k]) for k in _SAYS if d.get(k)), "")


def _quantity_text(d: dict[str, Any]) -> str:
    """A measured quantity (``value``, and ``uncertainty``, ``unit``, ``status`` if given)
    as ``+623 ± 310 Pa (corrected)``."""
    v, u = float(d["value"]), d.get("uncertainty")
    unit = "" if d.get("unit") in (None, "", "1") else _unit(str(d["unit"]))
    text = "—" if math.isnan(v) else f"{v:+.3g}"
    if _is_number(u) and math.isfinite(u):
        text += f" ± {u:.2g}"
    text += f" {unit}" if unit else ""
    return text + (f" ({d['status']})" if d.get("status") else "")


def text_of(value: Any) -> str:
    """Any value of an answer as text: numbers to three digits, sequences joined, mappings
    as ``name value`` pairs."""
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if _is_number(value):
        v = float(value)
        return "—" if math.isnan(v) else str(value) if isinstance(value, int) else f"{v:.3g}"
    if isinstance(value, str):
        return value
    if isinstance(value, dict):
        if _is_number(value.get("value")):  # a measured quantity: value, uncertainty, unit
            return _quantity_text(value)
        return "; ".join(f"{_label(str(k))} {text_of(v)}" for k, v in value.items()
                         if k not in _SAYS)  # fmt: skip
    if isinstance(value, (list, tuple)):
        if not value:
            return "none"
        if all(isinstance(v, (list, tuple)) for v in value):
            return ", ".join(" ".join(text_of(x) for x in v) for v in value)
        return ", ".join(text_of(v) for v in value)
    if hasattr(value, "tolist"):  # a numpy scalar or array
        return text_of(value.tolist())
    return str(value)


def evidence_rows(evidence: dict[str, Any]) -> list[tuple[str, str, str]]:
    """``(what was measured, value, what it means)`` for each evidence item, in the
    diagnoser's order: the page's words for the items it knows (`EVIDENCE`), else the item's
    name, its value and its own ``meaning``, ``description`` or ``note`` if it gives one; a
    mapping of mappings (the chain's estimates) a row each."""
    rows = []
    for key, value in (evidence or {}).items():
        name, meaning, show = EVIDENCE.get(key, (_label(key), "", None))
        if isinstance(value, dict) and value and all(isinstance(v, dict) for v in value.values()):
            for i, (k, v) in enumerate(value.items()):  # a group of items: a row each
                rows.append((f"{name}: {_label(str(k))}", text_of(v),
                             _says(v) or (meaning if i == 0 else "")))  # fmt: skip
            continue
        if isinstance(value, dict):
            meaning = _says(value) or meaning
        text = None
        if show is not None:
            try:
                text = show(value)
            except (KeyError, TypeError, ValueError, IndexError):  # another shape: generic
                text = None
        rows.append((name, text_of(value) if text is None else text, meaning))
    return rows


def _table(header: list[str], rows: list[list[Any]], id_: str, widths=None) -> Any:
    from dash import html

    cell = {"padding": "6px 10px", "borderBottom": "1px solid #ddd", "verticalAlign": "top",
            "textAlign": "left"}  # fmt: skip
    head = html.Tr([html.Th(h, style=cell | {"background": "#f3f3f3"} |
                            ({"width": widths[i]} if widths else {}))
                    for i, h in enumerate(header)])  # fmt: skip
    body = [html.Tr([html.Td(c, style=cell) for c in r]) for r in rows]
    return html.Table([html.Thead(head), html.Tbody(body)], id=id_,
                      style={"borderCollapse": "collapse", "width": "100%",
                             "fontSize": "14px", "marginBottom": "14px"})  # fmt: skip


def _probability_rows(probs: dict[str, float], label: str) -> list[list[Any]]:
    from dash import html

    rows = []
    for cls, p in sorted(probs.items(), key=lambda kv: -kv[1]):
        bar = html.Div(style={"width": f"{100 * max(0.0, min(1.0, p)):.1f}%", "height": "14px",
                              "background": "#0072B2" if cls == label else "#9ec5e0"})  # fmt: skip
        rows.append([html.B(cls) if cls == label else cls, f"{p:.2f}",
                     html.Div(bar, style={"background": "#eee", "width": "100%"})])  # fmt: skip
    return rows


def _severity(r: dict[str, Any]) -> Any:
    """The severity, its interval and the fault's size, if the answer has them."""
    from dash import html

    s, (lo, hi) = r.get("severity", math.nan), r.get("severity_interval", (math.nan,) * 2)
    if not (_is_number(s) and math.isfinite(s)):
        return None
    parts = [html.Span(f"severity {s:.2f}", style={"fontWeight": "bold"}),
             f" (90 % interval {lo:.2f} to {hi:.2f}, on the data set's scale from 0, the "
             "mildest, to 1, the most severe)"]  # fmt: skip
    v, (vlo, vhi), unit = r.get("value"), r.get("value_interval", (math.nan,) * 2), r.get("unit")
    if _is_number(v) and math.isfinite(v):
        try:
            from ..diagnosis.classes import get_class

            what = get_class(r.get("label", "")).parameter or "fault size"
        except (ParameterError, KeyError, ValueError):
            what = "fault size"
        u = _unit(unit)
        parts += [html.Br(), f"{what} = {v:.3g} {u} "
                  f"(interval {min(vlo, vhi):.3g} to {max(vlo, vhi):.3g} {u})"]  # fmt: skip
    return html.P(parts, id="dx-severity", style={"fontSize": "15px", "margin": 0})


def result_children(view: DiagnosisView) -> list[Any]:
    """The page's rendering of a `DiagnosisView`."""
    from dash import html

    box = {"padding": "12px 16px", "borderRadius": "4px", "marginBottom": "14px"}
    if view.error:
        return [html.Div([html.B("Not diagnosed: "), view.error], id="dx-error",
                         style=box | {"border": f"2px solid {_RED}", "color": _RED})]  # fmt: skip
    r = view.result
    out: list[Any] = []
    if view.refused:
        out.append(html.Div([
            html.H3("Diagnosis withheld", style={"margin": "0 0 6px 0"}),
            html.P(r.get("reason", ""), style={"margin": 0, "fontSize": "15px"}),
        ], id="dx-refusal", style=box | {"border": f"3px solid {_RED}", "color": _RED,
                                         "background": "#fdecee"}))  # fmt: skip
    else:
        label, probs = r.get("label", ""), view.probabilities
        head = [html.H3([f"Most probable: {label}",
                         html.Span(f"   p = {probs.get(label, math.nan):.2f}",
                                   style={"fontWeight": "normal"})],
                        id="dx-label", style={"margin": "0 0 4px 0"})]  # fmt: skip
        sev = _severity(r)
        if sev is not None:
            head.append(sev)
        out.append(html.Div(head, id="dx-answer", style=box | {
            "borderLeft": "6px solid #0072B2", "background": "#eef5fb"}))  # fmt: skip
        out += [html.H4("Class probabilities"),
                _table(["class", "probability", ""], _probability_rows(probs, label),
                       "dx-probabilities", ["30%", "12%", "58%"])]  # fmt: skip
    rows = [list(x) for x in evidence_rows(r.get("evidence") or {})]
    ood = r.get("ood") or {}
    if ood:
        d, thr = ood.get("distance"), ood.get("threshold")
        inside = _is_number(d) and _is_number(thr) and d <= thr
        rows.append(["distance to the training records",
                     f"{text_of(d)} against a threshold of {text_of(thr)}"
                     + (f" (features: {ood['features']})" if ood.get("features") else ""),
                     "how far the record's features lie from the training records', against "
                     "the held-out conditions' farthest: "
                     + ("inside the training domain" if inside else "outside it")])  # fmt: skip
    if rows:
        out += [html.H4("Evidence"),
                _table(["what was measured", "value", "what it means"], rows, "dx-evidence",
                       ["22%", "33%", "45%"])]  # fmt: skip
    out += [html.H4("Channels used"),
            _table(["role", "channel or value"], [[k, v] for k, v in view.channels.items()],
                   "dx-channels", ["30%", "70%"])]  # fmt: skip
    more = [[_label(k), text_of(v)] for k, v in r.items()
            if k not in _PLACED and v not in (None, "", [], {})]  # fmt: skip
    if more:
        out += [html.H4("More of the answer"),
                _table(["field", "value"], more, "dx-more", ["30%", "70%"])]  # fmt: skip
    if view.image:
        out += [html.H4("The record and the closest simulated record"),
                html.Img(src=view.image, id="dx-overlay",
                         alt="the record's first whole revolution with the closest simulated "
                         "record overlaid", style={"width": "100%", "height": "auto"})]  # fmt: skip
    footer = []
    if _is_number(r.get("seconds")) and math.isfinite(r["seconds"]):
        footer.append(f"answered in {r['seconds']:.1f} s. ")
    out.append(html.Details([html.Summary("as the command line prints it (recipdyn diagnose)"),
                             html.Pre("\n".join(view.lines), style={"whiteSpace": "pre-wrap",
                                                                    "fontSize": "12px"})],
                            style={"marginTop": "10px", "color": "#444"}))  # fmt: skip
    if footer:
        out.append(html.Div(footer, style={"fontSize": "12px", "color": "#666"}))
    return out


def diagnosis_page() -> Any:
    """The diagnosis page (layout only; `recipdyn.app.page.build_app` wires it)."""
    from dash import dcc, html

    def box(id_, value, label, tip):
        return html.Div([
            html.Label(label, htmlFor=id_, title=tip,
                       style={"display": "block", "fontSize": "12px", "color": "#444"}),
            dcc.Input(id=id_, type="text", value=value, placeholder=tip,
                      style={"width": "100%", "boxSizing": "border-box"}),
        ])  # fmt: skip

    return html.Div([
        html.H2("Diagnose a record", style={"margin": "6px 0"}),
        html.P("A record of the compressor's vibration (an accelerometer on the crosshead "
               "guide), with a once-per-revolution tacho or its constant speed and, if "
               "recorded, the chamber pressures. The shipped diagnoser answers only for "
               "records like those it was trained on (simulated ones: docs/diagnosis.md); "
               "for any other it says why it withholds the answer.",
               style={"maxWidth": "60em", "color": "#444"}),
        html.Div([
            dcc.Upload(id="dx-upload",
                       children=html.Div(["drop a record here or ", html.A("choose a file"),
                                          html.Br(), html.Span(", ".join(SUFFIXES),
                                                               style={"fontSize": "12px",
                                                                      "color": "#666"})]),
                       style={"border": "2px dashed #888", "padding": "14px",
                              "textAlign": "center", "borderRadius": "4px"}),
            html.Div(id="dx-file", style={"fontSize": "13px", "color": "#444",
                                          "margin": "4px 0"}),
        ]),
        html.Div([
            box("dx-channel", "accel_guide", "acceleration channel", "in m/s²"),
            box("dx-tacho", "tacho", "tacho channel", "once-per-revolution pulse, mark at ODC"),
            box("dx-speed", "", "or a constant speed", "e.g. 191 rpm"),
            box("dx-phead", "p_head_sensor", "head-end pressure", "channel, Pa (optional)"),
            box("dx-pcrank", "p_crank_sensor", "crank-end pressure", "channel, Pa (optional)"),
            box("dx-fs", "", "sampling rate", "from the file, or e.g. 10 kHz"),
        ], style={"display": "grid", "gridTemplateColumns": "repeat(6, minmax(8em, 1fr))",
                  "gap": "10px", "margin": "8px 0"}),
        html.Div([
            html.Button("Diagnose", id="dx-run", n_clicks=0, style={"marginRight": "0.5em"}),
            html.Button("Simulated example", id="dx-example", n_clicks=0,
                        title="simulate a record of the shipped diagnoser's domain (a ring "
                        "leak) and diagnose it"),
        ], style={"marginBottom": "12px"}),
        dcc.Loading(html.Div(id="dx-result", style={"minHeight": "2em"})),
    ], id="diagnose-page", style={"padding": "0 8px", "fontSize": "14px"})  # fmt: skip
