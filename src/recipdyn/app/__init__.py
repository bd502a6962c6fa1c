"""``recipdyn app``: a local web app to explore every registered model and browse sweeps.

Choose a model (the compressor with its massless clearance link, the contact-impact joint,
the valves, the reference systems): its parameter panel is built from the model's schema,
grouped as the schema groups them, each field in the unit engineers type (mm, bar, rpm, deg;
any quantity pint reads is accepted) with its allowed range, and the run settings with the
command line's defaults (`recipdyn.defaults`). "Simulate" runs the model and shows

* four interactive views of the record: the model's vibration signal, its amplitude spectrum,
  a phase portrait and the stroboscopic section;
* the figures ``recipdyn simulate`` writes for the same run (the response, or the contact
  joint's journal orbit and joint forces, and with the compression cycle the p-V diagram,
  pressures, rod load and valve lifts), drawn by the same plotting functions;
* the run's summary and, when it left the model's validity, why.

A bad value is shown next to its field, and the previous figures are cleared. The address
carries the model and every changed field (``?model=compressor-contact&rc=0.5+mm``), so a
link reopens the same run; "Download config" writes the run's TOML config, which
``recipdyn simulate -c FILE`` runs. The sweep browser opens a sweep store and shows its
fault map (2-D) or bifurcation diagram (1-D); clicking a point opens it in the panel and
runs it. The diagnosis section takes a dropped record (or a simulated example) and its
channel names and shows `recipdyn.diagnose`'s answer: the probabilities, the severity, the
evidence and the overlay, or the refusal and its reason (`recipdyn.app.diagnosis`).

Why Dash: a plain Flask server with React components, so the app is one Python process and
its callbacks are plain functions (tested without a browser, and in a real headless
Chromium); Plotly figures report clicks on map cells, which the sweep browser needs.
"""

from __future__ import annotations

from .diagnosis import DiagnosisView, diagnose_upload
from .figures import images, simulate_form, status_lines, views
from .form import (
    MAX_SAMPLES,
    Field,
    config_text,
    fields,
    format_value,
    from_query,
    read_form,
    to_query,
)
from .page import GRAPHS, PageResult, build_app, click_query, panel_for, run_page
from .sweeps import log_ticks, point_from_click, sweep_figure

__all__ = [
    "build_app", "run_page", "PageResult", "panel_for", "click_query", "GRAPHS", "fields",
    "Field", "read_form", "format_value", "to_query", "from_query", "config_text",
    "MAX_SAMPLES", "simulate_form", "views", "images", "status_lines", "sweep_figure",
    "point_from_click", "log_ticks", "DiagnosisView", "diagnose_upload",
]  # fmt: skip
