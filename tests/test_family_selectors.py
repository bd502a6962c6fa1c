"""Every selector value is run as asked or refused (issue 44, item 1).

``--model compressor-contact --set clearance_joints=ideal`` recorded ``clearance_joints =
'both'``: both pins in contact, without a word. Here every value of every selector (the five,
``crank_joint``, ``crosshead_joint``, ``load``, ``drive``, ``guide``, and the pins' older
spelling, ``clearance_joints`` and ``joint``) is asked of the model and of each preset, through
the Python API, ``--set`` and a config file, and its record must say what was asked (the
five selectors, each recorded, read back to the configuration the test expects) or it must be
refused in one line naming what was asked. What each request means, and which combinations
do not exist, is written out here independently of `recipdyn.model.family`.

Nothing is integrated or compiled: parameters, routes and record attributes only.
"""

from __future__ import annotations

import pytest

from recipdyn.cli import main
from recipdyn.cli.simulate import _collect_model
from recipdyn.errors import ParameterError
from recipdyn.model import family
from recipdyn.model.registry import get_model

MODELS = ("compressor", *family.PRESETS)
SELECTOR_NAMES = ("crank_joint", "crosshead_joint", "load", "drive", "guide")
#: Every value of every selector, and of the older spelling of the pins.
WALK = {
    "crank_joint": ("link", "ideal", "contact", "lubricated"),
    "crosshead_joint": ("ideal", "contact", "lubricated"),
    "load": ("paper", "table", "cycle", "valves"),
    "drive": ("prescribed", "motor"),
    "guide": ("ideal", "clearance"),
    "clearance_joints": ("crank", "crosshead", "both", "ideal"),
    "joint": ("dry", "lubricated"),
}
#: Each model's configuration at its defaults (the presets as documented in
#: docs/components.md).
DEFAULTS = {
    "compressor": dict(crank_joint="link", crosshead_joint="ideal", load="paper",
                       drive="prescribed", guide="ideal"),
    "compressor-contact": dict(crank_joint="contact", crosshead_joint="ideal", load="paper",
                               drive="prescribed", guide="ideal"),
    "compressor-valves": dict(crank_joint="link", crosshead_joint="ideal", load="valves",
                              drive="prescribed", guide="ideal"),
    "compressor-contact-valves": dict(crank_joint="contact", crosshead_joint="ideal",
                                      load="valves", drive="prescribed", guide="ideal"),
    "compressor-guide": dict(crank_joint="ideal", crosshead_joint="ideal", load="paper",
                             drive="prescribed", guide="clearance"),
}  # fmt: skip
TABLE_ROWS = "0,-1e4\n90,-5e4\n180,2e4\n270,-3e4\n"


def expected(model: str, key: str, value: str) -> dict[str, str]:
    """The configuration that asking ``key = value`` of ``model`` means."""
    s = dict(DEFAULTS[model])
    if key in SELECTOR_NAMES:
        s[key] = value
    elif key == "clearance_joints":  # where the clearance is; dry contact there
        s["crank_joint"] = "contact" if value in ("crank", "both") else "ideal"
        s["crosshead_joint"] = "contact" if value in ("crosshead", "both") else "ideal"
    else:  # joint: the kind of contact at the default place, the crank pin
        s["crank_joint"] = "lubricated" if value == "lubricated" else "contact"
        s["crosshead_joint"] = "ideal"
    return s


def exists(s: dict[str, str]) -> bool:
    """Whether a configuration exists: the massless link holds the crosshead on its line
    (no guide clearance) and exists only with an ideal crosshead pin."""
    return s["crank_joint"] != "link" or (s["crosshead_joint"] == "ideal"
                                          and s["guide"] == "ideal")  # fmt: skip


CASES = [(m, k, v) for m in MODELS for k, vals in WALK.items() for v in vals]


def _api(model, key, value, table):
    kw = {key: value}
    if value == "table":
        kw["load_table"] = ((0.0, -1e4), (90.0, -5e4), (180.0, 2e4), (270.0, -3e4))
    m = get_model(model)
    return m, m.parameters(kw)


def _set(model, key, value, table):
    sets = [f"{key}={value}"] + ([f"load_table={table}"] if value == "table" else [])
    m, params, _ = _collect_model(model, None, None, None, sets, None)
    return m, m.parameters(params)


def _config(model, key, value, table):
    path = table.with_name(f"{model}-{key}-{value}.toml")
    extra = f'load_table = "{table}"\n' if value == "table" else ""
    path.write_text(f'model = "{model}"\n[params]\n{key} = "{value}"\n{extra}')
    m, params, _ = _collect_model(None, None, None, None, None, path)
    return m, m.parameters(params)


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    path = tmp_path_factory.mktemp("walk") / "table.csv"
    path.write_text(TABLE_ROWS)
    return path


@pytest.mark.parametrize("way", [_api, _set, _config], ids=["api", "set", "config"])
def test_every_selector_value_is_recorded_as_asked_or_refused(way, table):
    """For each model and preset, each selector and each value: refused (one line naming the
    selector) exactly where the configuration does not exist; otherwise the record states all
    five selectors at the values asked, a recorded older spelling states the value asked, and
    the record reads back to the same values and configuration."""
    wrong = []
    for model, key, value in CASES:
        want = expected(model, key, value)
        try:
            m, values = way(model, key, value, table)
        except ParameterError as exc:
            msg = str(exc)
            if exists(want) or "\n" in msg or key not in msg:
                wrong.append((model, key, value, f"refused: {msg}"))
            continue
        if not exists(want):
            wrong.append((model, key, value, "ran a configuration that does not exist"))
            continue
        attrs = m.record_attrs(values)
        recorded = {k: attrs.get(f"param_{k}") for k in SELECTOR_NAMES}
        if recorded != want:
            wrong.append((model, key, value, f"recorded {recorded}"))
        if key in ("clearance_joints", "joint") and attrs.get(f"param_{key}", value) != value:
            wrong.append((model, key, value, f"recorded {key} = {attrs[f'param_{key}']!r}"))
        back = m.values_from_record(attrs)
        if m.selectors(back) != want or m.route(back)[0] != m.route(values)[0]:
            wrong.append((model, key, value, f"read back as {m.selectors(back)}"))
    assert not wrong, "\n".join(map(str, wrong))
    # the walk holds every value the selectors take
    assert {k: WALK[k] for k in SELECTOR_NAMES} == {p.name: p.choices for p in family.SELECTORS}


@pytest.mark.parametrize("kw,words", [
    ({"clearance_joints": "crosshead", "crank_joint": "contact"},
     ["crank_joint = 'contact'", "clearance_joints = 'crosshead'", "contradict"]),
    ({"clearance_joints": "crank", "crosshead_joint": "lubricated"},
     ["crosshead_joint = 'lubricated'", "clearance_joints = 'crank'", "contradict"]),
    ({"clearance_joints": "both", "crank_joint": "ideal"},
     ["crank_joint = 'ideal'", "clearance_joints = 'both'"]),
    ({"joint": "lubricated", "crank_joint": "contact"},
     ["joint = 'lubricated'", "no pin", "crank_joint = 'contact'"]),
    ({"joint": "lubricated", "clearance_joints": "ideal"}, ["joint = 'lubricated'", "no pin"]),
    ({"load": "cycle", "load_table": ((0.0, -1e4), (180.0, 2e4))},
     ["load_table", "not with load = 'cycle'"]),
])  # fmt: skip
@pytest.mark.parametrize("model", ["compressor", "compressor-contact"])
def test_the_two_spellings_contradicting_each_other_are_refused(model, kw, words):
    """A request in both spellings that disagree (or a table with the cycle's load) would run
    one of them and drop the other: refused in one line naming both."""
    with pytest.raises(ParameterError) as exc:
        get_model(model).parameters(kw)
    msg = str(exc.value)
    assert all(w in msg for w in words) and "\n" not in msg, msg


def test_the_issues_command_records_ideal_pins(tmp_path):
    """``simulate --model compressor-contact --set clearance_joints=ideal`` (the issue's
    command, its config dumped instead of run): the ideal pins are what the config holds, and
    the config runs them again."""
    cfg = tmp_path / "c.toml"
    argv = ["simulate", "--model", "compressor-contact", "--set", "clearance_joints=ideal",
            "--dump-config", str(cfg)]  # fmt: skip
    assert main(argv) == 0
    text = cfg.read_text()
    assert 'crank_joint = "ideal"' in text and 'clearance_joints = "both"' not in text, text
    m, params, _ = _collect_model(None, None, None, None, None, cfg)
    assert m.selectors(m.parameters(params))["crosshead_joint"] == "ideal"


def test_a_record_of_the_valves_made_before_the_selectors_were_recorded_reads_as_valves():
    """Records of ``compressor-valves`` made before every selector was recorded hold the
    massless link's own ``param_load = 'cycle'`` beside the valves' parameters; they read back
    as the dynamic valves (they read as the ideal-valve cycle before: another model)."""
    m = get_model("compressor-valves")
    values = m.parameters()
    attrs = m.record_attrs(values)
    for k in SELECTOR_NAMES:  # what such a record held
        attrs.pop(f"param_{k}")
    attrs["param_load"] = "cycle"
    back = m.values_from_record(attrs)
    assert m.route(back)[0] == "link-valves" and back == values
