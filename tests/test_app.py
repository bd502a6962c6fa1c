"""recipdyn app: the form (every model's schema, units, ranges, errors per field), the page's
functions behind each callback (run, address, config, sweep click), and the page in a real
headless Chromium driven through the Chrome DevTools Protocol (choose the contact model,
change a value with units, see its figures; a bad value shows its error and clears them;
click a fault-map cell; download the config and run it with the CLI)."""

import base64
import json
import math
import re
import struct
import time

import numpy as np
import pytest

from _cdp import chromium, served_page
from recipdyn.app import (
    GRAPHS,
    build_app,
    click_query,
    config_text,
    fields,
    format_value,
    from_query,
    log_ticks,
    panel_for,
    point_from_click,
    read_form,
    run_page,
    sweep_figure,
    to_query,
)
from recipdyn.defaults import SIMULATION
from recipdyn.errors import ParameterError
from recipdyn.model.parameters import CompressorParams
from recipdyn.model.registry import get_model, model_names
from recipdyn.plotting import contact_figure, cycle_figure, response_figure
from recipdyn.sweep.run import run_sweep
from recipdyn.sweep.spec import SweepSpec, parse_axis

#: Short runs: the app's own default is the CLI's (10 revolutions at 10 kHz).
SHORT = {"run.revolutions": "1", "run.fs": "2 kHz"}


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    out = tmp_path_factory.mktemp("appsweep")
    spec = SweepSpec(axes=(parse_axis("rc=0.2mm:2mm:3:log"), parse_axis("d=0:2mm:2")),
                     measures=("peak",), settings=dict(revolutions=0.5, transient=0))  # fmt: skip
    run_sweep(spec, out, backend="serial", progress=False)
    return out


def _png_size(uri: str) -> tuple[int, int]:
    """Width and height of a PNG data URI (from its IHDR chunk)."""
    data = base64.b64decode(uri.split(",", 1)[1])
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


# --- the form -----------------------------------------------------------------------------


@pytest.mark.parametrize("name", model_names())
def test_every_model_has_a_panel_whose_defaults_are_the_models(name):
    """Every registered model gets a field for each schema parameter a field can hold, and
    its default texts ("1 mm", "20 rad/s", "207 GPa") read back to the defaults to the bit."""
    m = get_model(name)
    flds = fields(m)
    keys = {f.key for f in flds}
    tables = {p.name for p in m.schema if p.choices is None and not p.optional
              and not isinstance(p.default, (int, float))}  # fmt: skip
    idle = set(m.inactive(m.parameters())) if len(m.selector_schema()) else set()
    assert keys >= set(m.schema.names) - tables - idle  # (idle: another configuration's)
    assert {"run.revolutions", "run.fs", "run.method"} <= keys
    form = read_form(m, {f.key: f.default_text if f.choices is None else f.default
                         for f in flds})  # fmt: skip
    assert form.ok, form.errors
    assert form.params == m.parameters()  # exact: no unit conversion rounds a default
    assert panel_for(name, {})  # the Dash components build


def test_fields_read_the_units_engineers_type():
    by = {f.key: f for f in fields("compressor", {"load": "cycle"})}
    assert by["rc"].unit == "mm" and by["suction_pressure"].unit == "bar"
    assert by["theta_c_offset"].unit == "deg"
    # the default 20 rad/s is 190.98593... rpm: the field is in rad/s, and rpm is typed
    assert by["omega"].unit == "rad/s" and by["theta1_0"].unit == "rad"
    assert by["rc"].parse("0.5 mm") == pytest.approx(0.5e-3, rel=1e-15)
    assert by["rc"].parse("0.5") == pytest.approx(0.5e-3, rel=1e-15)  # a bare number: mm
    assert by["rc"].parse("500 um") == pytest.approx(0.5e-3, rel=1e-15)
    assert by["omega"].parse("300 rpm") == pytest.approx(10 * math.pi, rel=1e-15)
    assert by["omega"].parse("20 rad/s") == 20.0
    assert by["suction_pressure"].parse("2 bar") == pytest.approx(2e5, rel=1e-15)
    assert by["theta_c_offset"].parse("90 deg") == pytest.approx(math.pi / 2, rel=1e-15)
    assert by["run.fs"].parse("5 kHz") == 5000.0
    # written in the display unit, exactly
    assert by["rc"].default_text == "1 mm" and by["omega"].default_text == "20 rad/s"
    assert by["suction_pressure"].range_text() == "(0, 10000] bar"
    assert by["theta1_0"].range_text() == "[-1e+06, 1e+06] rad"  # not "±5.72958e+07 deg"
    assert format_value(6.324555320336759e-4, by["rc"]) == "0.6324555320336759 mm"


def _configurations():
    """Every registered model at its defaults, and the compressor at each value of each of
    its selectors and at the combinations of ``CONFIGURATIONS``."""
    out = [(name, {}) for name in model_names()]
    for name in model_names():
        for p in get_model(name).selector_schema():
            out += [(name, {p.name: v}) for v in p.choices if v != p.default]
    return out + [("compressor", chosen) for chosen, _, _ in CONFIGURATIONS.values()]


def _reads_back(text: str, si_unit: str) -> float:
    from recipdyn.units import to_si

    return float(text) if not si_unit else to_si("x", text, unit=si_unit)


def test_every_field_shows_its_numbers_in_the_unit_beside_it():
    """Every number field of every model's form, at every selector value: its default is
    written in the unit shown beside it (not "20 rad/s" beside "rpm"), and the ends of the
    range it states read back to the model's own bounds exactly (not 1e6 rad written as
    "5.72958e+07 deg", which is 999999.6 rad). One helper, `display_unit`, decides."""
    seen, wrong = 0, []
    for name, chosen in _configurations():
        for f in fields(name, chosen):
            if f.choices is not None or f.param is None:
                continue
            seen += 1
            text = f.default_text
            if text and (text.split(" ", 1)[1] if " " in text else "") != f.unit:
                wrong.append(f"{name} {chosen} {f.key}: {text!r} beside {f.unit!r}")
            ends = re.fullmatch(r"[\[(](\S+), (\S+)[\])]( .+)?", f.range_text())
            assert ends, f.range_text()
            unit = (ends.group(3) or "").strip()
            assert unit == f.unit, (f.key, f.range_text())
            for end, bound in zip(ends.groups()[:2], (f.param.low, f.param.high), strict=True):
                back = _reads_back(f"{end} {unit}".strip(), f.si_unit)
                if back != bound:
                    wrong.append(f"{name} {chosen} {f.key}: range end {end} {unit} is "
                                 f"{back!r}, the model's bound {bound!r}")  # fmt: skip
    assert seen > 300 and not wrong, "\n".join(wrong)


def test_run_settings_are_the_command_lines():
    """The app's defaults come from recipdyn.defaults, like `recipdyn simulate`'s."""
    s = read_form("compressor", {}).settings
    assert s == {k: v for k, v in SIMULATION.items() if k != "h"}
    assert s["fs"] == 10_000.0
    assert {f.key: f.default_text for f in fields("duffing")}["run.fs"] == "10 kHz"


@pytest.mark.parametrize(
    ("texts", "key", "match"),
    [
        ({"rc": "-0.001"}, "rc", r"rc = -0.001 mm is out of range; allowed: \[0, "),
        ({"rc": "3 bar"}, "rc", "cannot be converted to m"),
        ({"d": "abc"}, "d", "unknown unit"),
        ({"omega": ""}, "omega", "empty"),
        ({"run.fs": "-1 kHz"}, "run.fs", "fs = -1 kHz is out of range"),
        ({"run.revolutions": "1e6"}, "run.revolutions", "more than the app draws"),
        # a check across parameters goes to the field it names
        ({"load": "cycle", "suction_pressure": "5 bar"}, "discharge_pressure", "suction_pressure"),
        ({"m2": "0", "m3": "0", "J2": "0"}, "m2", "at least one must be > 0"),
    ],
)
def test_a_bad_value_is_told_at_its_field(texts, key, match):
    form = read_form("compressor", texts)
    assert list(form.errors) == [key]
    assert __import__("re").search(match, form.errors[key]), form.errors[key]


def test_every_bad_field_gets_its_message_at_once():
    form = read_form("compressor-contact", {"rc": "-1 mm", "restitution": "2", "bore": "x"})
    assert set(form.errors) == {"rc", "restitution", "bore"}
    assert "allowed: (0, 1]" in form.errors["restitution"]


# --- the page's functions -----------------------------------------------------------------


def test_a_bad_value_clears_the_figures():
    res = run_page("compressor", {"rc": "-0.001", **SHORT})
    assert res.query is None and res.images == []
    assert all(len(f.data) == 0 for f in res.figures) and len(res.figures) == len(GRAPHS)
    assert res.errors["rc"].startswith("rc = -0.001 mm")
    assert "1 field(s) to correct (rc)" in res.status[0]


def test_the_views_are_the_simulated_record():
    """The signal view is the record's acceleration sample for sample, and the section has
    one point per revolution; the base case's peak is the known 57.66 m/s^2."""
    from recipdyn import simulate

    res = run_page("compressor", {"run.revolutions": "2", "run.fs": "2 kHz"})
    ds = simulate(CompressorParams(), revolutions=2, fs=2000.0)
    sig, spec, _, sec = res.figures
    assert np.array_equal(np.asarray(sig.data[0].y), ds["a"].values)
    assert np.abs(ds["a"].values).max() == pytest.approx(57.66, rel=0.01)
    assert len(sec.data[0].x) == 2  # strobe times 0 and T in [0, 2T)
    assert spec.layout.yaxis.type == "log"
    assert res.query == "?model=compressor&run.revolutions=2&run.fs=2+kHz"
    assert [t for t, _ in res.images] == ["figure of recipdyn simulate"]
    assert _png_size(res.images[0][1]) == _sizes(ds, [response_figure])


def _sizes(ds, makers, dpi=80):
    """Pixel sizes of the figures ``makers`` draw for ``ds`` (what the app's images are)."""
    from recipdyn.plotting import _mpl

    out = []
    for make in makers:
        fig = make(ds)
        out.append(tuple(int(round(v * dpi)) for v in fig.get_size_inches()))
        _mpl().close(fig)
    return out[0] if len(out) == 1 else out


def test_the_contact_model_draws_simulates_figure():
    """The contact joint's run: its summary in the status, and its image is the figure
    `recipdyn simulate` draws (contact_figure: journal orbit, joint forces, impact map). The
    first compilation of the contact model takes about a minute."""
    from recipdyn.app import images, simulate_form

    res = run_page("compressor-contact", {"rc": "0.5 mm", **SHORT})
    assert res.query is not None, res.status
    assert "rc = 0.5 mm" in res.status[0]
    assert any(line.startswith("contact_fraction = ") for line in res.status)
    assert len(res.images) == 1
    ds, _ = simulate_form(read_form("compressor-contact", {"rc": "0.5 mm", **SHORT}))
    assert "ex" in ds and _png_size(images(ds)[0][1]) == _sizes(ds, [contact_figure])
    assert _png_size(res.images[0][1]) == _sizes(ds, [contact_figure])


def test_the_compression_cycle_adds_its_figure():
    """With load = cycle the app also shows the cycle figure (p-V, pressures, rod load),
    as `recipdyn simulate` writes it beside the record."""
    from recipdyn.app import simulate_form

    texts = {"load": "cycle", **SHORT}
    res = run_page("compressor", texts)
    assert [t.split(" ")[0] for t, _ in res.images] == ["figure", "compression"]
    ds, notes = simulate_form(read_form("compressor", texts))
    assert [_png_size(u) for _, u in res.images] == _sizes(ds, [response_figure, cycle_figure])
    # this run leaves the massless link's validity (the contact force turns negative): said
    # once, from the record, not again as a warning
    assert notes == [] and ds.attrs["validity"] != "ok"
    assert [line.startswith("outside the model: contact_force") for line in res.status].count(
        True
    ) == 1


def test_a_runs_warnings_are_shown_on_the_page(monkeypatch):
    """Whatever a run warns (a contact law stretched beyond its range, ...) reaches the
    status, once per message, instead of the server's console."""
    import sys
    import warnings

    mod = sys.modules["recipdyn.simulate"]
    real = mod.simulate

    def warned(*a, **kw):
        for _ in range(3):
            warnings.warn("the law is stretched", UserWarning, stacklevel=2)
        return real(*a, **kw)

    monkeypatch.setattr(mod, "simulate", warned)
    res = run_page("compressor", SHORT)
    assert res.status.count("warning: the law is stretched") == 1


def test_address_round_trip():
    texts = {"rc": "0.5 mm", "omega": "300 rpm", "d": "1 mm", "run.revolutions": "2"}
    q = to_query("compressor", texts)
    assert q == "?model=compressor&rc=0.5+mm&omega=300+rpm&run.revolutions=2"  # d: default
    name, back, err = from_query(q)
    assert (name, err) == ("compressor", "")
    assert back == {"rc": "0.5 mm", "omega": "300 rpm", "run.revolutions": "2"}
    # aliases are read, unknown names reported, the rest kept
    name, back, err = from_query("?clearance=2+mm&nope=1")
    assert back == {"rc": "2 mm"} and "nope" in err
    assert from_query("?model=nosuch")[2].startswith("address: unknown model")
    # a link never imports code: module:object paths are refused (the CLI accepts them)
    name, back, err = from_query("?model=os:path&rc=1+mm")
    assert (name, back) == ("compressor", {}) and "unknown model 'os:path'" in err


def test_downloaded_config_runs_on_the_command_line(tmp_path):
    """The config the app writes is what `recipdyn simulate -c FILE` runs: the same model,
    parameters (from mm and rpm) and settings in the record."""
    import xarray as xr

    from recipdyn.cli import main

    form = read_form("compressor", {"rc": "0.5 mm", "omega": "300 rpm", **SHORT})
    cfg = tmp_path / "run.toml"
    cfg.write_text(config_text(form), encoding="utf-8")
    out = tmp_path / "run.nc"
    assert main(["simulate", "-c", str(cfg), "-o", str(out), "--no-figure", "--no-progress"]) == 0
    with xr.open_dataset(out) as ds:
        assert ds.attrs["param_rc"] == form.params["rc"] == 0.5e-3
        assert ds.attrs["param_omega"] == pytest.approx(10 * math.pi, rel=1e-15)
        assert ds.attrs["sampling_rate_hz"] == 2000.0 and ds.attrs["revolutions"] == 1.0


# --- the compressor's configurations ------------------------------------------------------

#: Configurations of the one model: the selector values, parameters that must have a field
#: there, and parameters of other configurations that must not.
CONFIGURATIONS = {
    "the default: massless link, paper load": (
        {},
        {"rc", "d", "equations", "load_amplitude", "m1", "omega"},
        {"restitution", "valve_lift", "guide_clearance", "bore", "motor", "J_drive"},
    ),
    "contact crank pin": (
        {"crank_joint": "contact"},
        {"rc", "restitution", "contact_law", "journal_radius", "K", "e0_angle"},
        {
            "rc_crosshead",
            "oil_viscosity",
            "valve_lift",
            "guide_clearance",
            "equations",
            "m1",
            "bore",
            "motor",
        },
    ),
    "lubricated crosshead pin": (
        {"crank_joint": "ideal", "crosshead_joint": "lubricated"},
        {"rc_crosshead", "crosshead_pin_radius", "oil_viscosity", "eps_dry", "bearing_length"},
        {"rc", "journal_radius", "K", "valve_lift", "guide_clearance", "equations"},
    ),
    "valves load": (
        {"load": "valves"},
        {"valve_lift", "valve_mass", "discharge_coefficient", "ring_leak_area", "rc", "m1"},
        {"load_amplitude", "restitution", "rc_crosshead", "guide_clearance"},
    ),
    "guide clearance": (
        {"crank_joint": "ideal", "guide": "clearance"},
        {"guide_clearance", "guide_stiffness", "crosshead_half_length", "guide_friction"},
        {
            "rc",
            "rc_crosshead",
            "oil_viscosity",
            "valve_lift",
            "equations",
            "restitution",
            "contact_law",
            "friction",
        },
    ),
    "motor drive": (
        {"drive": "motor", "load": "cycle"},
        {"motor", "J_drive", "motor_torque", "bore", "equations"},
        {"restitution", "valve_lift", "guide_clearance", "load_amplitude"},
    ),
}


def _components(tree):
    """Every Dash component in ``tree`` (depth first)."""
    items = tree if isinstance(tree, (list, tuple)) else [tree]
    for c in items:
        if c is None or isinstance(c, (str, int, float)):
            continue
        yield c
        yield from _components(getattr(c, "children", None))


def _widgets(panel) -> dict[str, object]:
    """The panel's field and choice values by key."""
    return {c.id["key"]: c.value for c in _components(panel)
            if isinstance(getattr(c, "id", None), dict) and c.id.get("type") in
            ("field", "choice")}  # fmt: skip


def test_the_compressor_shows_its_selectors_first_with_the_models_values():
    """The one model's form opens with its five selectors as choice fields, their values the
    model's own (`selector_schema`, the values `recipdyn models` lists), their defaults the
    massless link with the paper's load."""
    m = get_model("compressor")
    sel = m.selector_schema()
    flds = fields("compressor")
    head = flds[: len(sel)]
    assert [f.key for f in head] == ["crank_joint", "crosshead_joint", "load", "drive", "guide"]
    assert [f.choices for f in head] == [p.choices for p in sel]
    table = {p.name: p for p, where in m.parameter_table() if where == "selector"}
    for f in head:  # the selectors recipdyn models tags as such have the same values
        assert f.name not in table or table[f.name].choices == f.choices
    assert {"contact", "lubricated"} <= set(head[0].choices) and "valves" in head[2].choices
    assert "motor" in head[3].choices and "clearance" in head[4].choices
    assert [f.default for f in head] == ["link", "ideal", "paper", "prescribed", "ideal"]
    assert {f.group for f in head} == {"configuration"}
    assert sum(f.key in sel for f in flds) == len(sel)  # each once: not again in its group


@pytest.mark.parametrize("name", list(CONFIGURATIONS))
def test_each_configuration_shows_its_own_fields(name):
    """A configuration's form has the fields of the parameters that act in it and none of
    another's; its default texts read back to the model's values at those selectors, to
    the bit; the form is read with the configured model (its states)."""
    chosen, own, others = CONFIGURATIONS[name]
    m = get_model("compressor")
    flds = fields("compressor", chosen)
    keys = {f.key for f in flds}
    assert own <= keys, own - keys
    assert not others & keys, others & keys
    configured = m.configured(chosen)
    assert keys - set(m.selector_schema().names) - {k for k in keys if k.startswith("run.")} <= \
        set(configured.schema.names)  # fmt: skip
    texts = {f.key: f.default_text if f.choices is None else f.default for f in flds}
    form = read_form("compressor", {**texts, **chosen})
    assert form.ok, (form.errors, form.general)
    assert form.params == m.parameters(chosen)
    assert form.model.states(form.params) == configured.states(form.params)
    assert {k: form.params.get(k) for k in chosen} == chosen


def test_changing_a_selector_keeps_the_texts_of_the_fields_that_remain():
    """The panel of another selector value holds that configuration's fields, with the texts
    already typed in the fields that it has too."""
    typed = {"rc": "0.5 mm", "omega": "300 rpm", "equations": "exact", "load": "cycle",
             "bore": "0.4 m"}  # fmt: skip
    before = _widgets(panel_for("compressor", typed))
    assert before["crank_joint"] == "link" and before["equations"] == "exact"
    after = _widgets(panel_for("compressor", {**typed, "crank_joint": "contact"}))
    assert after["crank_joint"] == "contact"
    assert (after["rc"], after["omega"], after["bore"]) == ("0.5 mm", "300 rpm", "0.4 m")
    assert "equations" not in after and after["restitution"] == "0.9"
    assert after["load"] == "cycle"
    assert set(after) == {f.key for f in fields("compressor", {"crank_joint": "contact",
                                                               "load": "cycle"})}  # fmt: skip


def test_the_address_carries_the_selectors():
    texts = {"crank_joint": "ideal", "crosshead_joint": "lubricated", "rc_crosshead": "0.2 mm",
             "oil_viscosity": "0.04 Pa*s", "run.revolutions": "2"}  # fmt: skip
    q = to_query("compressor", texts)
    assert q == (
        "?model=compressor&crank_joint=ideal&crosshead_joint=lubricated"
        "&rc_crosshead=0.2+mm&run.revolutions=2"
    )  # oil_viscosity: its default
    name, back, err = from_query(q)
    assert (name, err) == ("compressor", "")
    assert back == {k: v for k, v in texts.items() if k != "oil_viscosity"}
    assert to_query(name, back) == q
    form = read_form(name, back)
    assert form.ok and form.params["rc_crosshead"] == pytest.approx(2e-4, rel=1e-15)
    assert (form.params["crank_joint"], form.params["crosshead_joint"]) == ("ideal", "lubricated")
    # the brief's example: the selector, then the configuration's field
    assert from_query("?model=compressor&crank_joint=contact&rc=0.5+mm") == (
        "compressor",
        {"crank_joint": "contact", "rc": "0.5 mm"},
        "",
    )


@pytest.mark.parametrize(
    ("query", "message"),
    [
        ("crank_joint=contact&equations=exact",
         "address: equations is not a parameter of this configuration of 'compressor'; it "
         "belongs to crank_joint = 'link' | 'ideal'"),
        ("valve_lift=2+mm", "valve_lift is not a parameter of this configuration of "
         "'compressor'; it belongs to load = 'valves'"),
        ("crank_joint=contact&rc_crosshead=0.2+mm",
         "it belongs to crosshead_joint = 'contact' | 'lubricated'"),
        ("crank_joint=contact&oil_viscosity=0.1", "it belongs to crank_joint or "
         "crosshead_joint = 'lubricated'"),
        ("guide_clearance=0.1+mm", "guide_clearance belongs to guide = 'clearance'"),
        ("J_drive=2", "J_drive is not a parameter of this configuration of 'compressor'; it "
         "belongs to drive = 'motor'"),
        ("bore=0.4+m", "it belongs to load = 'cycle'"),
        ("load=cycle&load_amplitude=1e5", "it belongs to load = 'paper'"),
        # the model's own message
        ("crank_joint=ideal&rc=0.5+mm", "rc = 0.0005: the crank pin is ideal (crank_joint = "
         "'ideal'); rc belongs to crank_joint = 'link' | 'contact' | 'lubricated'"),
    ],
)  # fmt: skip
def test_a_field_of_another_configuration_is_told(query, message):
    """A parameter of another configuration in an address is not read; the error names the
    selector values that enable it, like an unknown field's."""
    name, texts, err = from_query(f"?model=compressor&{query}")
    foreign = query.rsplit("&", 1)[-1].split("=")[0]
    assert foreign not in texts and message in err, err
    assert "unknown field" not in err  # it is known: it belongs elsewhere


def test_a_link_never_chooses_a_component_from_a_file():
    """A selector's value from an address is one of the model's listed values: a load of
    your own (``file.py:OBJ``) is refused without importing it, as a model path is."""
    plugin = "tests/plugin_components.py:LOAD"
    name, texts, err = from_query(f"?model=compressor&load={plugin}&rc=0.5+mm")
    assert texts == {"rc": "0.5 mm"} and "load" not in texts
    assert "a link does not import a file" in err and "allowed: paper, table" in err
    form = read_form("compressor", {"load": plugin})
    assert list(form.errors) == ["load"] and "allowed: one of paper" in form.errors["load"]
    assert from_query("?model=compressor&crank_joint=welded")[2] == (
        "address: crank_joint = 'welded' is not offered here; allowed: link, ideal, contact, "
        "lubricated"
    )


def test_a_combination_the_model_refuses_is_told_at_its_selector():
    """A combination that does not exist is told under the selector as soon as the panel is
    drawn (its other fields are the default configuration's), and again when read."""
    refused = {"crank_joint": "link", "crosshead_joint": "contact"}

    def told(texts):
        return {c.id["key"]: c.children for c in _components(panel_for("compressor", texts))
                if isinstance(getattr(c, "id", None), dict) and c.id.get("type") == "ferr"
                and c.children}  # fmt: skip

    assert list(told(refused)) == ["crank_joint"]
    assert "massless link exists" in told(refused)["crank_joint"]
    assert {f.key for f in fields("compressor", refused)} == {f.key for f in fields("compressor")}
    assert told({"crank_joint": "contact"}) == {}
    form = read_form("compressor", refused)
    assert list(form.errors) == ["crank_joint"]
    assert "the massless link exists at the crank pin" in form.errors["crank_joint"]
    form = read_form("compressor", {"load": "table"})
    assert list(form.errors) == ["load"] and "needs load_table" in form.errors["load"]


@pytest.mark.parametrize("name", ["contact crank pin", "lubricated crosshead pin",
                                  "valves load", "guide clearance"])  # fmt: skip
def test_the_config_of_a_configuration_reads_back_to_its_values(name, tmp_path):
    """The TOML config the app writes for a configuration is read by ``recipdyn simulate
    -c`` (`read_config`, `model_values`) to the same model and values, to the bit."""
    from recipdyn.config import model_values, read_config

    chosen = CONFIGURATIONS[name][0]
    typed = {"omega": "300 rpm", "d": "0.5 mm", **chosen}
    form = read_form("compressor", {**typed, **SHORT})
    assert form.ok, (form.errors, form.general)
    cfg = tmp_path / "run.toml"
    cfg.write_text(config_text(form), encoding="utf-8")
    back = read_config(cfg)
    assert back.model == "compressor"
    values = model_values(get_model(back.model), back.params)
    assert values == form.params
    assert {k: values[k] for k in chosen} == chosen


def test_a_selected_contact_configuration_runs_what_its_preset_runs(tmp_path):
    """The compressor with crank_joint = contact, chosen in the form, runs the kernel the
    compressor-contact preset runs: the same record, sample for sample, its address carries
    the selector and its figure is the contact figure (0.1 revolution); its downloaded
    config, run by ``recipdyn simulate -c``, gives that record again."""
    import xarray as xr

    from recipdyn.app import simulate_form
    from recipdyn.cli import main

    short = {"rc": "0.5 mm", "run.revolutions": "0.1", "run.fs": "2 kHz"}
    res = run_page("compressor", {"crank_joint": "contact", **short})
    assert res.query == ("?model=compressor&crank_joint=contact&rc=0.5+mm"
                         "&run.revolutions=0.1&run.fs=2+kHz"), res.status  # fmt: skip
    assert any(line.startswith("contact_fraction = ") for line in res.status)
    ds, _ = simulate_form(read_form("compressor", {"crank_joint": "contact", **short}))
    ref, _ = simulate_form(read_form("compressor-contact", short))
    assert ds.attrs["model"] == "compressor" and ds.attrs["param_crank_joint"] == "contact"
    for k in ("a", "ex", "ey"):
        assert np.array_equal(ds[k].values, ref[k].values), k
    assert _png_size(res.images[0][1]) == _sizes(ds, [contact_figure])
    cfg, out = tmp_path / "contact.toml", tmp_path / "contact.nc"
    cfg.write_text(config_text(read_form("compressor", {"crank_joint": "contact", **short})),
                   encoding="utf-8")  # fmt: skip
    assert main(["simulate", "-c", str(cfg), "-o", str(out), "--no-figure", "--no-progress"]) == 0
    with xr.open_dataset(out) as cli:
        assert cli.attrs["model"] == "compressor" and cli.attrs["param_crank_joint"] == "contact"
        assert np.array_equal(cli["a"].values, ds["a"].values)


@pytest.mark.parametrize("name", [n for n in model_names() if n != "compressor"])
def test_the_presets_and_other_models_keep_their_forms(name):
    """A model without selectors (the presets, fixed starting configurations; the reference
    systems) has the form of its schema, as before: every parameter a field can hold, in
    the schema's order, then the run settings; its fields do not depend on the texts."""
    m = get_model(name)
    assert len(m.selector_schema()) == 0
    flds = fields(name)
    expect = [p.name for p in m.schema if p.choices is not None or p.optional
              or isinstance(p.default, (int, float))]  # fmt: skip
    assert [f.key for f in flds if not f.key.startswith("run.")] == expect
    assert [f.key for f in fields(name, {"crank_joint": "contact", "load": "valves"})] == [
        f.key for f in flds]  # fmt: skip


# --- the sweep browser --------------------------------------------------------------------


def test_log_ticks():
    assert log_ticks(0.2, 2.0) == pytest.approx([0.2, 0.5, 1.0, 2.0])
    assert log_ticks(1e-4, 1.0) == pytest.approx([1e-4, 1e-3, 1e-2, 0.1, 1.0])
    assert log_ticks(3.0, 4.0) == [3.0, 4.0]  # no 1-2-5 value inside: the ends


def test_sweep_figure_and_click(store):
    fig, options, shown = sweep_figure(store)
    assert shown == "peak_a" and "peak_a" in options
    x = fig.layout.xaxis  # d, linear, in mm
    y = fig.layout.yaxis  # rc, swept on a log grid, in mm with readable 1-2-5 labels
    assert x.title.text == "d (mm)" and x.type is None
    assert np.allclose(fig.data[0].x, [0, 2]) and np.allclose(fig.data[0].y, [0.2, 0.632, 2],
                                                              rtol=1e-3)  # fmt: skip
    assert y.type == "log" and y.title.text == "rc (mm)"
    assert list(y.ticktext) == ["0.2", "0.5", "1", "2"]
    name, values = point_from_click(store, {"points": [{"x": 2.1, "y": 0.62}]})
    assert name == "compressor"
    assert values["d"] == pytest.approx(2e-3)
    assert values["rc"] == pytest.approx(np.sqrt(0.2e-3 * 2e-3), rel=1e-12)  # the log middle
    q = click_query(store, {"points": [{"x": 2.1, "y": 0.62}]}, {"run.revolutions": "1"})
    form = read_form(*from_query(q)[:2])
    assert form.params["rc"] == values["rc"]  # the text is exact
    assert form.settings["revolutions"] == 1.0
    with pytest.raises(ParameterError, match="not found"):
        sweep_figure(store / "nope")


def test_the_app_builds_with_every_callback(store):
    app = build_app(store)
    outputs = " ".join(app.callback_map)
    for part in ("panel.children", "g-signal.figure", "download.data", "sweep.figure",
                 "nav.search", "dx-result.children"):  # fmt: skip
        assert part in outputs


# --- the diagnosis section ----------------------------------------------------------------


def _texts_of(component) -> str:
    """Every text and attribute value of a Dash component tree, as one string."""
    return json.dumps(component, default=lambda c: c.to_plotly_json(), ensure_ascii=False)


def test_the_diagnosis_page_answers_a_dropped_record_and_shows_a_refusal(tmp_path):
    """A record of the shipped diagnoser's domain, dropped as a CSV (the page receives it
    base64-encoded), is diagnosed: probabilities summing to 1, shown in a table; the
    severity; the evidence, one row an item; the channels named; the overlay image; and no
    path of the server anywhere. The same record read at another speed is refused with its
    reason; a file of an unreadable type, or without the channel named, is told by the
    uploaded file's name, not the server's copy."""
    import tempfile

    import pandas as pd

    from recipdyn.app import diagnose_upload
    from recipdyn.app.diagnosis import example_record, result_children

    nc = example_record(tmp_path, revolutions=4.0)
    import xarray as xr

    rec = xr.open_dataset(nc)
    fs = 1.0 / float(rec.time[1] - rec.time[0])
    csv = tmp_path / "record.csv"
    names = ("accel_guide", "tacho", "p_head_sensor", "p_crank_sensor")
    pd.DataFrame({k: rec[k].values for k in names}).to_csv(csv, index=False)
    upload = "data:text/csv;base64," + base64.b64encode(csv.read_bytes()).decode()
    view = diagnose_upload(upload, "record.csv", tacho="tacho", p_head="p_head_sensor",
                           p_crank="p_crank_sensor", fs=f"{fs} Hz")  # fmt: skip
    assert not view.error and not view.refused, view.error or view.lines
    assert sum(view.probabilities.values()) == pytest.approx(1.0)
    assert view.lines[0].startswith("diagnosis:") and any("impacts" in x for x in view.lines)
    assert min(_png_size(view.image)) > 100
    assert view.channels == {"acceleration": "accel_guide", "tacho": "tacho",
                             "head-end pressure": "p_head_sensor",
                             "crank-end pressure": "p_crank_sensor",
                             "sampling rate": f"{fs} Hz"}  # fmt: skip
    page = _texts_of(result_children(view))
    for part in ('"dx-probabilities"', '"dx-evidence"', '"dx-channels"', '"dx-overlay"',
                 "impacts per revolution", "head-end pressure shape", "deciding features",
                 "distance to the training records", view.result["label"]):  # fmt: skip
        assert part in page, part
    server = tempfile.gettempdir()
    assert server not in page and server not in "\n".join(view.lines)
    assert "figure" not in view.result  # the overlay's path: not kept
    fast = diagnose_upload(upload, "record.csv", tacho=None, speed="600 rpm", fs=f"{fs} Hz")
    assert fast.refused and "crank speed" in fast.result["reason"] and fast.image is None
    refusal = _texts_of(result_children(fast))
    assert '"dx-refusal"' in refusal and "Diagnosis withheld" in refusal
    assert '"dx-probabilities"' not in refusal
    bad = diagnose_upload(upload, "record.xyz")
    assert "allowed" in bad.error and ".csv" in bad.error
    assert "drop a file" in diagnose_upload(None, None).error
    missing = diagnose_upload(upload, "record.csv", channel="accel_crank", fs=f"{fs} Hz")
    assert missing.error and "record.csv" in missing.error and server not in missing.error
    assert '"dx-error"' in _texts_of(result_children(missing))


def test_the_diagnosis_page_shows_what_it_has_no_words_for():
    """A field of the answer or an evidence item the page does not know (the diagnosis
    layer adds them) is shown by its name and value, an item's own meaning with it; a
    known item whose value has another shape falls back to the generic rendering."""
    from recipdyn.app import DiagnosisView, result_children
    from recipdyn.app.diagnosis import evidence_rows

    view = DiagnosisView(
        result=dict(refused=False, label="ring_leak", probabilities={"ring_leak": 0.7,
                    "healthy": 0.3}, severity=0.5, severity_interval=(0.3, 0.8),
                    value=1e-6, value_interval=(5e-7, 2e-6), unit="m**2",
                    evidence={"impacts_per_rev": 2.0,
                              "mounting_resonance_hz": {"value": 3812.0, "uncertainty": 40.0,
                                                        "meaning": "the accelerometer's own"},
                              "deciding": "another shape",
                              "sensor_chain": {"offset": {"value": 600.0, "uncertainty": 3e2,
                                                          "unit": "Pa", "status": "corrected",
                                                          "note": "the transducer's offset"},
                                               "gain": {"value": 1e-3, "unit": "1"}},
                              "counts": {"knocks": 3, "quiet": [1, 2]}},
                    ood={"distance": 1.0, "threshold": 2.0, "features": "all"},
                    channel_set="acceleration + tacho", seconds=1.5),
        channels={"acceleration": "acc"})  # fmt: skip
    page = _texts_of(result_children(view))
    rows = dict((r[0], r[1:]) for r in evidence_rows(view.result["evidence"]))
    assert rows["sensor chain: offset"] == ("+600 ± 3e+02 Pa (corrected)",
                                            "the transducer's offset")  # fmt: skip
    assert rows["sensor chain: gain"] == ("+0.001", "")
    assert rows["counts"] == ("knocks 3; quiet 1, 2", "")
    for part in (
        "mounting resonance (Hz)",
        "+3.81e+03 ± 40",
        "the accelerometer's own",
        "channel set",
        "acceleration + tacho",
        "another shape",
        "More of the answer",
        "severity 0.50",
        "ring_leak_area",
    ):
        assert part in page, part
    assert "inside the training domain" in page


# --- a real browser -----------------------------------------------------------------------


_STATUS = "(document.getElementById('status') || {innerText: ''}).innerText"
_POINTS = ("(() => { const g = document.querySelector('#g-signal .js-plotly-plot');"
           " return g && g._fullData ? g._fullData.length && g._fullData[0].y.length : -1; })()")  # fmt: skip  # noqa: E501
_IMAGE = ("(() => { const i = document.querySelector('#images img');"
          " return i && i.complete && i.naturalWidth; })()")  # fmt: skip
#: The titles of the page's graphs that their toolbar (Plotly's mode bar) covers, and how
#: many graphs have both.
_COVERED = """(() => { const out = []; let n = 0;
  for (const g of document.querySelectorAll('.js-plotly-plot')) {
    const t = g.querySelector('.gtitle'), m = g.querySelector('.modebar');
    if (!t || !m || !t.textContent) continue;
    n += 1;
    const a = t.getBoundingClientRect(), b = m.getBoundingClientRect();
    if (a.left < b.right && b.left < a.right && a.top < b.bottom && b.top < a.bottom)
      out.push(t.textContent);
  }
  return [out, n]; })()"""


@pytest.mark.browser
def test_app_in_headless_chromium(store, tmp_path, monkeypatch):
    chromium()
    import recipdyn.app.page as page

    runs = []  # every simulation the page asks for (no loops, no double runs)
    real = page.run_page
    monkeypatch.setattr(page, "run_page", lambda m, t: runs.append(m) or real(m, t))
    # compile (or load) the two models first, so the page waits for runs, not compilers
    assert run_page("compressor-contact", SHORT).query is not None
    with served_page(build_app(store), tmp_path) as (page_, port, downloads):
        # 1. the address opens the compressor with short run settings and runs it once
        page_.call("Page.navigate", url=f"http://127.0.0.1:{port}/?run.revolutions=1"
                   "&run.fs=2+kHz")  # fmt: skip
        assert "compressor: 629 samples" in page_.wait(f"{_STATUS}.includes('compressor:') "
                                                        f"&& {_STATUS}")  # fmt: skip
        assert page_.wait(f"{_POINTS} > 100 && {_POINTS}") == 629  # decoded by plotly.js
        assert page_.wait(_IMAGE) > 500  # simulate's figure, decoded
        assert runs == ["compressor"]
        page_.wait(
            "(() => { const g = document.querySelector('#sweep .js-plotly-plot');"
            " return g && g._fullData && g._fullData.length; })()"
        )  # the map too
        assert page_.js(_COVERED) == [[], 5]  # the four views and the map: no title covered

        # 1b. a selector, chosen with the mouse: the contact configuration's fields (its
        # contact law's restitution, not the massless link's equations), no run yet
        def exists(key, kind):
            return page_.js(f"!!document.getElementById('{{\"key\":\"{key}\",\"type\":"
                            f"\"{kind}\"}}')")  # fmt: skip

        assert exists("equations", "choice") and not exists("restitution", "field")
        page_.click('document.getElementById(\'{"key":"crank_joint","type":"choice"}\')')
        page_.click("[...document.querySelectorAll('[role=option]')]"
                    ".find(e => e.innerText.trim() === 'contact')")  # fmt: skip
        page_.wait('!!document.getElementById(\'{"key":"restitution","type":"field"}\')')
        assert not exists("equations", "choice") and exists("rc", "field")
        assert runs == ["compressor"]
        # 2. choose the contact model with the mouse: its panel, its run, its figure
        page_.click("document.getElementById('model')")
        page_.click("[...document.querySelectorAll('[role=option]')]"
                    ".find(e => e.innerText.trim() === 'compressor-contact')")  # fmt: skip
        page_.wait(f"{_STATUS}.includes('compressor-contact:')")
        assert page_.js("location.search") == (
            "?model=compressor-contact&run.revolutions=1&run.fs=2+kHz"
        )  # the settings are kept
        assert page_.wait(_IMAGE) > 500  # the contact figure (journal orbit, forces)
        assert page_.js("document.body.innerText.includes('rc_crosshead')")
        # 3. a value with units, typed and entered: the figures follow it
        src = page_.js("document.querySelector('#images img').src")
        assert page_.type_into("rc", "0.5 mm", enter=True) == "0.5 mm"
        assert "rc = 0.5 mm" in page_.wait(f"{_STATUS}.includes('rc = 0.5 mm') && {_STATUS}")
        page_.wait(f"document.querySelector('#images img').src !== {json.dumps(src)}")
        assert page_.js("location.search").endswith("&rc=0.5+mm&run.revolutions=1&run.fs=2+kHz")
        assert runs == ["compressor", "compressor-contact", "compressor-contact"]
        # 4. the config it downloads runs on the command line (checked in
        # test_downloaded_config_runs_on_the_command_line); here: it arrives, with rc
        page_.click("document.getElementById('dl')")
        toml = downloads / "recipdyn-compressor-contact.toml"
        for _ in range(100):
            if toml.exists() and toml.stat().st_size:
                break
            time.sleep(0.2)
        assert 'model = "compressor-contact"' in toml.read_text()
        assert "\nrc = 0.0005  #" in toml.read_text()
        # 5. a bad value: its message beside the field, the figures cleared
        page_.type_into("rc", "-0.001")
        page_.click("document.getElementById('run')")
        err = page_.wait("document.getElementById('{\"key\":\"rc\",\"type\":\"ferr\"}')"
                         ".innerText")  # fmt: skip
        assert err == "rc = -0.001 mm is out of range; allowed: (0, inf) mm"
        assert page_.wait(f"{_POINTS} === 0") and page_.js(
            "document.querySelectorAll('#images img').length") == 0  # fmt: skip
        assert "not run" in page_.js(_STATUS)
        frame = 'document.getElementById(\'{"key":"rc","type":"field"}\').parentElement'
        assert page_.js(f"getComputedStyle({frame}).borderColor") == "rgb(176, 0, 32)"  # red
        # 6. click the fault map's (rc = 2 mm, d = 2 mm) cell: that point of the
        # compressor's sweep opens in the panel and runs
        page_.wait("(() => { const g = document.querySelector('#sweep .js-plotly-plot');"
                   " return g && g._fullData && g._fullData.length"
                   " && g._fullData[0].type === 'heatmap'; })()")  # fmt: skip
        page_.js("""(() => { const g = document.querySelector('#sweep .js-plotly-plot');
            g.emit('plotly_click', {points: [{x: 2, y: 2, curveNumber: 0,
                                              pointNumber: [2, 1]}]}); })()""")
        status = page_.wait(f"{_STATUS}.includes('compressor: ') && {_STATUS}")
        assert "rc = 2 mm, d = 2 mm" in status
        assert page_.js("document.getElementById('{\"key\":\"rc\",\"type\":\"field\"}')"
                        ".value") == "2 mm"  # fmt: skip
        assert runs[-1] == "compressor" and len(runs) == 5
        # 7. the address reopens the same run in a fresh page
        search = page_.js("location.search")
        assert "rc=2+mm" in search and "d=2+mm" in search
    params = read_form(*from_query(search)[:2]).params  # the model's values, as every model's
    assert params["rc"] == pytest.approx(2e-3) and params["d"] == pytest.approx(2e-3)
