"""The diagnosis page: drop a record (or take a simulated example), name its channels, and
see what `recipdyn.diagnose` answers: the class probabilities, the severity with its
interval, the evidence and the closest simulated record overlaid, or the refusal and its
reason. ``diagnose_upload`` is the plain function the page's callback wraps."""

from __future__ import annotations

import base64
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ParameterError

__all__ = ["DiagnosisView", "diagnose_upload", "example_record"]

#: File types `recipdyn.diagnose` reads (those of ``recipdyn analyze``).
SUFFIXES = (".csv", ".tsv", ".txt", ".wav", ".mat", ".nc", ".parquet")


@dataclass
class DiagnosisView:
    """What the page shows for one record."""

    lines: list[str] = field(default_factory=list)
    refused: bool = False
    error: str = ""
    probabilities: dict[str, float] = field(default_factory=dict)
    image: str | None = None  # the overlay, as a data URI


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
) -> DiagnosisView:
    """Diagnose an uploaded record (``contents`` as ``dcc.Upload`` gives it, ``filename``
    for its type) or the file ``path``; a bad input comes back as ``error``, not raised."""
    from ..diagnosis.diagnose import diagnose

    view = DiagnosisView()
    blank = {None, ""}
    try:
        with tempfile.TemporaryDirectory() as tmp:
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
            res = diagnose(
                path,
                channel=channel or "accel_guide",
                fs=None if fs in blank else fs,
                speed=None if speed in blank else speed,
                tacho=None if tacho in blank else tacho,
                p_head=None if p_head in blank else p_head,
                p_crank=None if p_crank in blank else p_crank,
                model=model,
                out=Path(tmp) / "fig",
            )
            if res.figure:
                data = base64.b64encode(Path(res.figure).read_bytes()).decode()
                view.image = f"data:image/png;base64,{data}"
    except ParameterError as exc:
        view.error = str(exc)
        return view
    view.refused = res.refused
    view.lines = res.text().splitlines()
    view.probabilities = dict(res.probabilities)
    return view


def diagnosis_section() -> Any:
    """The page's diagnosis section (layout only; `recipdyn.app.page.build_app` wires it)."""
    from dash import dcc, html

    small = {"width": "9em", "marginRight": "0.5em"}

    def box(id_, value, label, tip):
        return html.Span(
            [
                html.Label(label, title=tip, style={"marginRight": "0.3em"}),
                dcc.Input(id=id_, type="text", value=value, style=small),
            ],
            style={"display": "inline-block", "marginBottom": "4px"},
        )

    return html.Div(
        [
            html.H4("Diagnose a record"),
            dcc.Upload(
                id="dx-upload",
                children=html.Div(["drop a record here or ", html.A("choose a file")]),
                style={
                    "border": "1px dashed #888",
                    "padding": "8px",
                    "textAlign": "center",
                    "marginBottom": "6px",
                },
            ),
            html.Div(id="dx-file", style={"fontSize": "12px", "color": "#444"}),
            box("dx-channel", "accel_guide", "acceleration", "channel in m/s²"),
            box("dx-tacho", "tacho", "tacho", "once-per-revolution channel, mark at ODC"),
            box("dx-speed", "", "or speed", "constant crank speed, e.g. 191 rpm"),
            box("dx-phead", "p_head_sensor", "p head", "head-end pressure channel, Pa"),
            box("dx-pcrank", "p_crank_sensor", "p crank", "crank-end pressure channel, Pa"),
            box("dx-fs", "", "fs", "sampling rate if the file does not give it"),
            html.Div(
                [
                    html.Button("Diagnose", id="dx-run", n_clicks=0),
                    html.Button(
                        "Simulated example",
                        id="dx-example",
                        n_clicks=0,
                        title="simulate a record of the shipped diagnoser's domain and diagnose it",
                    ),
                ]
            ),
            dcc.Loading(html.Div(id="dx-result")),
        ],
        style={"marginTop": "8px", "borderTop": "1px solid #ccc"},
    )


def result_children(view: DiagnosisView) -> list[Any]:
    """The page's rendering of a `DiagnosisView`."""
    from dash import html

    if view.error:
        return [html.Div(view.error, style={"color": "#B00020"})]
    style = {"fontFamily": "monospace", "whiteSpace": "pre-wrap", "fontSize": "12px"}
    out = [html.Div("\n".join(view.lines), style=style | ({"color": "#B00020"} if view.refused
                                                          else {}))]  # fmt: skip
    if view.image:
        out.append(html.Img(src=view.image, alt="closest simulated record overlaid",
                            style={"maxWidth": "100%"}))  # fmt: skip
    return out
