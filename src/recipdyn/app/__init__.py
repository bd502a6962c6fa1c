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

The compressor (``compressor``) opens with its selectors as choice fields, ``crank_joint``,
``crosshead_joint``, ``load``, ``drive`` and ``guide``, with the values the model lists
(`Model.selector_schema`); below them come the fields of the configuration they choose
(`Model.configured`), less those that do not act in it (`Model.inactive`: a pin's own
parameters where it is ideal, the oil film's where no pin is lubricated, the guide's where it
is ideal, the motor's with the prescribed speed, the cycle's with the paper's load).
Changing a selector redraws the panel, keeping the texts of the fields that remain; a
combination the model refuses is told at the selector. A model without selectors (the
presets, the reference systems) shows its schema's fields.

A bad value is shown next to its field, and the previous figures are cleared. The address
carries the model, the selectors and every changed field
(``?model=compressor&crank_joint=contact&rc=0.5+mm``), so a link reopens the same run (a
field of another configuration is named with the selector value that enables it; a selector
value that is a file, ``file.py:OBJ``, is never taken from a link); "Download config" writes
the run's TOML config, which ``recipdyn simulate -c FILE`` runs. The sweep browser opens a
sweep store and shows its fault map (2-D) or bifurcation diagram (1-D); clicking a point
opens it in the panel and runs it. Each field is shown in one unit (`display_unit`): the
unit engineers type when the field's default and range are exact in it, else SI.

The diagnosis has a page of its own (the tab "Diagnose a record", or ``#diagnose`` in the
address): it takes a dropped record (or a simulated example) and its channel names and shows
`recipdyn.diagnose`'s answer: the class probabilities, the severity and its interval, the
evidence (what was measured, its value, what it means), the channels used and the closest
simulated record overlaid at full width; or the refusal and its reason, prominently
(`recipdyn.app.diagnosis`). No server path is shown.

Why Dash: a plain Flask server with React components, so the app is one Python process and
its callbacks are plain functions (tested without a browser, and in a real headless
Chromium); Plotly figures report clicks on map cells, which the sweep browser needs.
"""

from __future__ import annotations

from .diagnosis import DiagnosisView, diagnose_upload, result_children
from .figures import images, simulate_form, status_lines, views
from .form import (
    MAX_SAMPLES,
    Field,
    config_text,
    display_unit,
    fields,
    format_value,
    from_query,
    read_form,
    to_query,
)
from .page import GRAPHS, PAGES, PageResult, build_app, click_query, panel_for, run_page
from .sweeps import log_ticks, point_from_click, sweep_figure

__all__ = [
    "build_app", "run_page", "PageResult", "panel_for", "click_query", "GRAPHS", "fields",
    "Field", "read_form", "format_value", "to_query", "from_query", "config_text",
    "MAX_SAMPLES", "simulate_form", "views", "images", "status_lines", "sweep_figure",
    "point_from_click", "log_ticks", "DiagnosisView", "diagnose_upload", "result_children",
    "display_unit", "PAGES",
]  # fmt: skip
