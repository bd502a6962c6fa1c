"""The one compressor model (`recipdyn.model.family`): selectors choose the implementation.

* every route gives, to the bit, what its implementation (the model class each old name
  reached) gives, with the same step count: the model only delegates;
* the old names are presets: their values, records and sweep digests are the
  implementations';
* a record of ``--model compressor --set crank_joint=contact`` reruns and is analysed;
* the matrix of joints x loads x drives x guide (issue 30, item 3): every allowed combination
  builds, integrates a short stretch, and its recorded crosshead velocity and acceleration are
  the derivatives of its recorded position and velocity; every refused one is refused in one
  line that says why. CI (``make test``) runs every refusal and the allowed cells that hold
  every pair of two components' choices (`all_pairs`); ``make test-all`` runs every cell.
"""

from __future__ import annotations

import itertools
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

import recipdyn
from recipdyn.cli import main
from recipdyn.errors import LawRangeWarning, ModelValidityWarning, ParameterError
from recipdyn.model import family
from recipdyn.model.registry import get_model, register

#: The test suite's file of components (a load of your own: tests/test_load_plugin.py).
PLUGIN = (Path(__file__).parent / "plugin_components.py").resolve()
HARMONIC, WITH_STATES = f"{PLUGIN}:HARMONIC", f"{PLUGIN}:WITH_STATES"
CHAMBER = f"{PLUGIN}:CHAMBER"

#: One configuration per route: the compressor's selectors, the route, and the values the
#: implementation (the model class the old name reached) takes for the same run.
ROUTES = [
    ({}, "link", {}),
    ({"crank_joint": "contact"}, "contact", {}),
    ({"load": "valves"}, "link-valves", {}),
    ({"crank_joint": "contact", "load": "valves"}, "contact-valves", {}),
    ({"guide": "clearance", "crank_joint": "ideal", "guide_clearance": 2e-4}, "contact",
     {"guide": "clearance", "crank_joint": "ideal", "crosshead_joint": "ideal",
      "guide_clearance": 2e-4}),
]  # fmt: skip


def _simulate(**kw):
    with warnings.catch_warnings():  # (the link under the valves' load; deep cold starts)
        warnings.simplefilter("ignore", ModelValidityWarning)
        warnings.simplefilter("ignore", LawRangeWarning)  # (deep contacts of a cold start)
        return recipdyn.simulate(**kw)


@pytest.mark.parametrize("selectors,route,own", ROUTES, ids=[r[1] for r in ROUTES])
def test_every_route_runs_its_implementation_to_the_bit(selectors, route, own):
    """The model delegates to the machine of one throw the assembler builds, and a contact
    route's machine (`OneContact`: the assembled layout and parameter vector) holds what its
    joints' configuration part (`ContactJoints`, no model: the joints' kernels on their own
    packed values) holds: the same parameter vector, initial state and right-hand side at a
    perturbed state, to the bit. The model's run and the machine's (asked for directly, under
    the old class's values) record every variable and right-hand-side call the same (no
    tolerance: the arithmetic is the same)."""
    from recipdyn.model.base import rhs_series

    m = get_model("compressor")
    values = m.parameters(selectors)
    assert m.route(values)[0] == route
    impl = family.machine(route)
    assert m.route(values)[1] is impl
    part = getattr(impl, "part", impl)  # (the contact routes: the joints' part)
    pv = part.parameters(own)
    sm, sp = m.system(values), part.system(pv)
    assert np.array_equal(sm.params, sp.params)
    y0 = m.initial_state(values)
    assert np.array_equal(y0, part.initial_state(pv))
    y = y0 + 1e-3 * np.random.default_rng(43).standard_normal(y0.size) * m.state_scale(values)
    t = np.array([0.01])
    assert np.array_equal(rhs_series(sm.rhs, sm.params, t, y[None]),
                          rhs_series(sp.rhs, sp.params, t, y[None]))  # fmt: skip
    kw = dict(revolutions=0.25, fs=2000.0)
    a = _simulate(model=m, params=selectors, **kw)
    b = _simulate(model=impl, params=own, **kw)
    assert set(a.data_vars) == set(b.data_vars)
    for k in b.data_vars:
        assert np.array_equal(a[k].values, b[k].values, equal_nan=True), k
    assert a.attrs["solver_nfev"] == b.attrs["solver_nfev"]
    assert a.attrs["model"] == "compressor"
    assert a.attrs["vibration_signal"] == impl.vibration()[0]


@pytest.mark.parametrize("selectors,route", [(r[0], r[1]) for r in ROUTES],
                         ids=[f"{r[1]}-{i}" for i, r in enumerate(ROUTES)])  # fmt: skip
def test_every_route_is_a_machine_of_the_one_assembler(selectors, route):
    """Every configuration is a machine of one throw built by the assembler (issue 43: one
    path): ``family`` holds no table of implementations, only `family.ASSEMBLER`, and a
    contact route's system is its assembled configuration's (the throw's slice of the state
    and of the parameter vector from `contact_throws.one_throw_configuration`), the same
    module as a machine file's throw (its kernels the throw's module). Nothing integrates."""
    from recipdyn.model.assembler.model import ContactMachine, MachineModel

    assert not hasattr(family, "ROUTES") and not hasattr(family, "implementation")
    m = get_model("compressor")
    values = m.parameters(selectors)
    name, machine, _ = m.route(values)
    assert name == route and isinstance(machine, MachineModel)
    assert set(family.ROUTE_NAMES) == {"link", "link-valves", "contact", "contact-valves"}
    if not route.startswith("contact"):
        return
    assert isinstance(machine, ContactMachine)
    own = {k: v for k, v in values.items() if k in machine.schema.names}
    c = machine.contact(own)
    s = machine.system(own)
    assert len(c.machine.throws) == 1 and c.machine.flat
    assert s.params is c.params and s.state_names == c.layout.state.names
    assert s.rhs is c.throw_module.rhs and s.jac is c.throw_module.jac
    assert c.layout.params.parts["throw1"] == slice(0, c.params.size)


#: The presets whose implementation is the one their old name reached (compressor-guide's was
#: a kernel of its own, now the reference model compressor-guide-reference: the preset runs
#: the contact joints' kernels with the guide's clearance, `test_compressor_guide_is_the_..`).
SAME_IMPLEMENTATION = sorted(set(family.PRESETS) - {"compressor-guide"})


@pytest.mark.parametrize("name", SAME_IMPLEMENTATION)
def test_presets_keep_the_values_and_sweep_digests_of_the_old_names(name):
    """A preset at its defaults validates to exactly the values its implementation gives
    (no selector added), so a sweep store made before the presets keeps its digest: the
    spec's digest with the preset equals the one with the one-throw machine registered under
    the name, and both the pinned digest of the code that made the old stores."""
    from recipdyn.model import registry
    from recipdyn.sweep import SweepSpec, parse_axis

    preset = get_model(name)
    impl = preset.route(family.PRESETS[name])[1]  # (the machine of one throw, a model)
    assert preset.parameters() == impl.parameters()
    assert preset.parameters() == getattr(impl, "part", impl).parameters()  # (its joints')
    assert preset.schema is impl.schema and preset.state_names == impl.state_names
    axis = parse_axis("omega=19:21:2", name)
    digest = SweepSpec(axes=(axis,), measures=("peak",), model=name).digest
    register(impl)
    try:
        assert SweepSpec(axes=(axis,), measures=("peak",), model=name).digest == digest
    finally:
        registry._REGISTERED.pop(impl.name)
    assert digest == PINNED_DIGESTS[name]


#: The digests of ``sweep --model NAME -p omega=19:21:2 -m peak`` computed by the code before
#: the presets (each name its own model class then).
PINNED_DIGESTS = {
    "compressor": "7ea050575d92065b",
    "compressor-contact": "91a4fb581c4b9ea1",
    "compressor-valves": "0a1cb736b638e9ce",
    "compressor-contact-valves": "452894a907246e77",
    "compressor-guide": "ca4e62f122ef6f28",
}


def test_compressor_guide_is_the_contact_joints_with_ideal_pins_in_a_worn_guide():
    """The preset compressor-guide runs the contact joints' kernels (both pins ideal, the
    guide's clearance): its values are that configuration's, and its sweep stores' digest is
    theirs (pinned: it changed when the preset's own kernel became the reference model
    compressor-guide-reference, whose values a store made before holds; the reference model
    keeps that kernel and those values for them)."""
    from recipdyn.sweep import SweepSpec, parse_axis

    preset = get_model("compressor-guide")
    values = preset.parameters()
    assert preset.route(values)[0] == "contact"
    assert values == get_model("compressor-contact").parameters(family.PRESETS[
        "compressor-guide"])  # fmt: skip
    axis = parse_axis("omega=19:21:2", "compressor-guide")
    digest = SweepSpec(axes=(axis,), measures=("peak",), model="compressor-guide").digest
    assert digest == GUIDE_DIGEST != PINNED_DIGESTS["compressor-guide"]


#: compressor-guide's digest since it runs the contact joints' kernels (a store made before,
#: digest ``PINNED_DIGESTS["compressor-guide"]``, is not resumed: its points are computed
#: again on the contact joints' kernels, which agree with the former kernel to ~1e-6 of the
#: clearance, tests/test_guide_component.py).
GUIDE_DIGEST = "9ff9df5070b41466"


def test_the_default_models_sweep_digest_is_unchanged():
    from recipdyn.sweep import SweepSpec, parse_axis

    axis = parse_axis("omega=19:21:2")
    assert SweepSpec(axes=(axis,), measures=("peak",)).digest == PINNED_DIGESTS["compressor"]


def test_a_record_of_the_model_with_a_selector_reruns_and_is_analysed(tmp_path, capsys):
    """``--model compressor --set crank_joint=contact``: the record stores the model's name
    and the selector (``param_crank_joint``); ``simulate -c`` reruns it to the bit and
    ``analyze`` reads it; its values equal the preset's (``--model compressor-contact``)."""
    rec = tmp_path / "r.nc"
    args = ["-n", "1.1", "--fs", "2 kHz", "--no-progress", "--no-figure"]
    assert main(["simulate", "--set", "crank_joint=contact", "-o", str(rec), *args]) == 0
    import xarray as xr

    ds = xr.open_dataset(rec).load()
    assert ds.attrs["model"] == "compressor" and ds.attrs["param_crank_joint"] == "contact"
    m = get_model("compressor")
    values = m.values_from_record(ds.attrs)
    assert values == get_model("compressor-contact").parameters()
    assert m.configured(values).sections()[0][0] == "ex"
    again = tmp_path / "again.nc"
    assert main(["simulate", "-c", str(rec), "-o", str(again), *args]) == 0
    ds2 = xr.open_dataset(again).load()
    for k in ("ex", "ey", "a", "gas_force"):
        assert np.array_equal(ds[k].values, ds2[k].values), k
    capsys.readouterr()
    out = tmp_path / "an"
    assert main(["analyze", str(rec), "-o", str(out), "--section-points", "3",
                 "--lyap-revolutions", "1"]) == 0  # fmt: skip
    summary = json.loads((out / "summary.json").read_text())
    assert "lyapunov_equations" in summary  # the equations were rebuilt from the record
    assert (out / "poincare.png").stat().st_size > 100


@pytest.mark.parametrize("preset,kw,route", [
    ("compressor-contact", {"crank_joint": "link"}, "link"),
    ("compressor-contact", {"clearance_joints": "both", "joint": "lubricated"}, "contact"),
    ("compressor-valves", {"crank_joint": "lubricated"}, "contact-valves"),
    ("compressor-guide", {"guide": "ideal"}, "link"),
])  # fmt: skip
def test_a_preset_is_the_model_with_other_defaults(preset, kw, route):
    """A preset's selectors can be set like the model's: ``--model compressor-contact --set
    crank_joint=link`` is the massless link."""
    m = get_model(preset)
    assert m.route(m.parameters(kw))[0] == route


# ---------------------------------------------------------------------------------------------
# The matrix (issue 30, item 3)

TABLE = ((0.0, -1.0e4), (90.0, -5.0e4), (180.0, 2.0e4), (270.0, -3.0e4))
#: Allowed combinations run by default: every selector value at least once, with and without
#: another family's non-default, on configurations the other test files compile too (the
#: contact glue compiles per configuration, 30-60 s on a loaded machine, then is cached).
ALLOWED = [
    ({}, "link"),
    ({"crank_joint": "ideal"}, "link"),
    ({"load": "cycle"}, "link"),
    ({"load": "table", "load_table": TABLE}, "link"),
    ({"drive": "motor"}, "link"),
    ({"crank_joint": "ideal", "drive": "motor"}, "link"),
    ({"load": "valves"}, "link-valves"),
    ({"load": "valves", "drive": "motor"}, "link-valves"),
    ({"crank_joint": "contact"}, "contact"),
    ({"crank_joint": "contact", "load": "cycle"}, "contact"),
    ({"crank_joint": "contact", "load": "table", "load_table": TABLE}, "contact"),
    ({"crank_joint": "lubricated", "crosshead_joint": "contact"}, "contact"),
    ({"crank_joint": "ideal", "crosshead_joint": "contact"}, "contact"),
    ({"crank_joint": "lubricated", "crosshead_joint": "lubricated"}, "contact"),
    ({"crank_joint": "contact", "load": "valves"}, "contact-valves"),
    ({"crank_joint": "contact", "drive": "motor"}, "contact"),
    ({"guide": "clearance", "crank_joint": "ideal"}, "contact"),
    ({"guide": "clearance", "crank_joint": "ideal", "load": "cycle"}, "contact"),
    ({"guide": "clearance", "crank_joint": "contact", "guide_clearance": 2e-4}, "contact"),
    ({"crank_joint": "contact", "load": HARMONIC}, "contact"),
    ({"crank_joint": "contact", "load": CHAMBER, "theta1_0": 3.14}, "contact"),
    ({"guide": "clearance", "crank_joint": "ideal", "drive": "motor", "motor": "constant"},
     "contact"),
]  # fmt: skip
#: Refused combinations and a phrase of the one line that says why.
REFUSED = [
    ({"crosshead_joint": "contact"}, "the massless link exists at the crank pin"),
    ({"crank_joint": "contact", "drive": "motor", "load": WITH_STATES},
     "has states but provides no initial"),
    ({"guide": "clearance"}, "guide = 'clearance' with crank_joint = 'link'"),
    ({"guide": "clearance", "crank_joint": "link", "crosshead_joint": "ideal"},
     "guide = 'clearance' with crank_joint = 'link'"),
    ({"load": CHAMBER}, "with states runs at a contact or lubricated pin"),
    ({"crank_joint": "contact", "load": HARMONIC, "load_table": TABLE},
     "not with load = "),
    ({"load": "valves", "load_table": TABLE}, "not with load = 'valves'"),
    ({"crank_joint": "contact", "load": "valves", "load_table": TABLE},
     "not with load = 'valves'"),
    ({"load": "table"}, "load = 'table' needs load_table"),
    ({"crank_joint": "contact", "drive": "motor", "motor": f"{PLUGIN}:LINEAR"},
     "a torque law of your own file drives the massless link or ideal pins"),
    ({"crank_joint": "lubricated", "load": f"{PLUGIN}:NOT_A_COMPONENT"},
     "is int, not a load component"),
    ({"crank_joint": "ideal", "rc": 1e-3}, "the crank pin is ideal"),
    ({"rc_crosshead": 3e-4}, "belongs to crosshead_joint = 'contact' | 'lubricated'"),
    ({"oil_viscosity": 0.05}, "crosshead_joint = 'lubricated'"),
    ({"contact_law": "hertz"}, "crank_joint or crosshead_joint = 'contact' | 'lubricated'"),
    ({"guide_clearance": 1e-4}, "belongs to guide = 'clearance'"),
    ({"crank_joint": "contact", "equations": "exact"}, "belongs to crank_joint = 'link'"),
    ({"load": "valves", "load_amplitude": 1e5}, "belongs to load = 'paper'"),
    ({"crank_joint": "nope"}, "crank_joint = 'nope'"),
]  # fmt: skip


def _event_times(ds) -> np.ndarray:
    """The times of every recorded event (impacts, valve stops: ``NAME_time``)."""
    times = [ds[f"{str(d)[: -len('_event')]}_time"].values for d in ds.dims
             if str(d).endswith("_event") and f"{str(d)[: -len('_event')]}_time" in ds]  # fmt: skip
    return np.concatenate(times) if times else np.empty(0)


def _phases(ds) -> list[str]:
    """The recorded phase indicators (a joint's or a shoe's contact: 1 in contact, 0 in
    free flight)."""
    return [k for k in ds.data_vars if ds[k].dims == ("time",) and ds[k].size
            and np.isin(ds[k].values, (0.0, 1.0)).all()]  # fmt: skip


def _derivative_check(ds, x: str, v: str) -> None:
    """``v`` is the time derivative of ``x``: the central difference of ``x`` at step h equals
    ``v`` within the difference's own error, estimated from its change at step 2h (its error
    falls as h^2, so |D_h - D_2h| ~ 3 |D_h - x'|; twice that is allowed), plus the error of
    the samples themselves (the dense output's, bounded by the integration tolerance, divided
    by the step) and rounding.

    The estimate holds where the error is in its h^2 regime: there the differences at steps
    h, 2h and 3h satisfy (D_3h - D_h) = 8/3 (D_2h - D_h). Samples where they do not (within a
    factor 2), or whose stencil holds a recorded event (an impact, a valve at its stop) or a
    change of a recorded contact phase, are set aside: the contact force switches or rings
    faster than the sampling there. At most 10 % may be."""
    t = ds["time"].values
    h = t[2] - t[1]
    X, V = ds[x].values, ds[v].values
    n = len(X)
    d = {k: (X[3 + k : n - 3 + k] - X[3 - k : n - 3 - k]) / (2 * k * h) for k in (1, 2, 3)}
    rtol = float(ds.attrs.get("solver_rtol", 1e-9))
    samples = 10 * (rtol + np.finfo(float).eps) * np.abs(X).max() / h
    err = np.abs(d[1] - V[3:-3])
    tol = 2 * np.abs(d[2] - d[1]) + samples
    q = (d[3] - d[1]) / np.where(d[2] == d[1], np.nan, d[2] - d[1])
    clear = (np.abs(d[2] - d[1]) < samples) | ((q > 4 / 3) & (q < 16 / 3))
    ev = _event_times(ds)
    lo, hi = t[:-6] - 1e-12, t[6:] + 1e-12
    clear &= ~np.any((ev[None, :] >= lo[:, None]) & (ev[None, :] <= hi[:, None]), axis=1)
    for k in _phases(ds):  # a contact that begins or ends without an event
        p = ds[k].values
        clear &= np.all([p[i : n - 6 + i] == p[3:-3] for i in range(7)], axis=0)
    assert clear.mean() > 0.9, (x, v, clear.mean())
    bad = (err > tol) & clear
    assert not bad.any(), (x, v, float((err / tol)[clear].max()), t[3:-3][bad][:5])


def _run_and_check(kw, route):
    m = get_model("compressor")
    values = m.parameters(kw)
    assert m.route(values)[0] == route
    ds = _simulate(model=m, params=kw, revolutions=0.1, fs=200_000.0)
    for k in ds.data_vars:
        assert np.all(np.isfinite(ds[k].values)), k
    _derivative_check(ds, "x", "v")
    if not route.startswith("contact"):
        # (at a contact joint `a` is the right-hand side at the interpolated state, which
        # differs from the derivative of the interpolated velocity by the stiff contact's
        # Jacobian times the dense output's error: up to 3x the bound above at the
        # crosshead pin and with oil at both pins, measured)
        _derivative_check(ds, "v", "a")
    cfg = m.configured(values)
    assert all(name in ds for name, _ in cfg.sections())  # its sections are recorded
    assert cfg.vibration()[0] in ds


@pytest.mark.parametrize("kw,route", ALLOWED,
                         ids=[",".join(f"{k}={v}" for k, v in kw.items() if k != "load_table")
                              or "default" for kw, _ in ALLOWED])  # fmt: skip
def test_every_allowed_combination_runs(kw, route):
    _run_and_check(kw, route)


@pytest.mark.parametrize("kw,words", REFUSED,
                         ids=[",".join(f"{k}={v}" for k, v in kw.items() if k != "load_table")
                              for kw, _ in REFUSED])  # fmt: skip
def test_every_refused_combination_says_why_in_one_line(kw, words):
    with pytest.raises(ParameterError) as exc:
        get_model("compressor").parameters(kw)
    msg = str(exc.value)
    assert words in msg and "\n" not in msg, msg


@pytest.mark.parametrize("args,words", [
    (["--set", "crosshead_joint=contact"], "the massless link exists at the crank pin"),
    (["--set", "rc_crosshead=0.3mm"], "rc_crosshead"),
    (["--set", "contact_law=hertz"], "crank_joint or crosshead_joint"),
    (["--set", "guide=clearance"], "guide = 'clearance' with crank_joint = 'link'"),
])  # fmt: skip
def test_the_command_line_refuses_in_one_line(args, words, tmp_path, capsys):
    assert main(["simulate", *args, "-o", str(tmp_path / "x.nc")]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and "Traceback" not in err and len(err.splitlines()) == 1, err
    assert not (tmp_path / "x.nc").exists()


def _cross_product():
    names = family.SELECTORS.names
    choices = [family.SELECTORS[n].choices for n in names]
    for combo in itertools.product(*choices):
        kw = dict(zip(names, combo, strict=True))
        if kw["load"] == "table":
            kw["load_table"] = TABLE
        yield kw


def _allowed(kw) -> bool:
    try:
        get_model("compressor").parameters(kw)
    except ParameterError:
        return False
    return True


def _cost(kw) -> int:
    """A rank of a cell's compile time (the glue with a valve chamber or a worn guide is the
    largest: 150-190 s on one core)."""
    g = kw.get
    return (1 + 2 * (g("load") == "valves") + 2 * (g("guide") == "clearance")
            + (g("crank_joint") in ("contact", "lubricated"))
            + (g("crosshead_joint", "ideal") != "ideal")
            + (g("drive", "prescribed") != "prescribed"))  # fmt: skip


def _pairs(kw) -> set:
    items = [(k, v) for k, v in kw.items() if k in family.SELECTORS.names]
    return set(itertools.combinations(items, 2))


def all_pairs(cells: list[dict]) -> list[dict]:
    """A subset of ``cells`` in which every pair of two selectors' values that some cell
    holds is held at least once (all-pairs combinatorial testing: a fault that needs two
    components together shows in one of them), chosen greedily: the most pairs not yet
    covered, then the cheaper (`_cost`), then the matrix order."""
    left = set().union(*(_pairs(c) for c in cells)) if cells else set()
    chosen = []
    while left:
        best = min(range(len(cells)),
                   key=lambda i: (-len(_pairs(cells[i]) & left), _cost(cells[i]), i))  # fmt: skip
        chosen.append(cells[best])
        left -= _pairs(cells[best])
    return chosen


def test_all_pairs_covers_every_pair_and_leaves_out_cells():
    """The CI subset of the matrix below: every pair of two selectors' values that an
    allowed combination holds is run together at least once, with fewer cells than the
    whole product; a pair that no allowed cell holds (the massless link with a contact pin)
    is not asked for."""
    cells = [kw for kw in _cross_product() if _allowed(kw)]
    ci = all_pairs(cells)
    want = set().union(*(_pairs(c) for c in cells))
    assert set().union(*(_pairs(c) for c in ci)) == want
    assert len(ci) < len(cells)
    assert (("crank_joint", "link"), ("crosshead_joint", "contact")) not in want
    toy = [{"crank_joint": a, "load": b} for a in "xy" for b in "pq"]
    assert len(all_pairs(toy)) == 4  # two selectors: every cell is a pair of its own


def _matrix():
    """The whole matrix; the allowed cells outside the `all_pairs` subset are marked
    ``exhaustive`` (run by ``make test-all``; CI runs the pairs and every refusal)."""
    cells = list(_cross_product())
    allowed = [kw for kw in cells if _allowed(kw)]
    ci = all_pairs(allowed)
    return [
        pytest.param(kw, marks=() if kw in ci or kw not in allowed else pytest.mark.exhaustive,
                     id=",".join(f"{k}={v}" for k, v in kw.items() if k != "load_table"))
        for kw in cells
    ]  # fmt: skip


@pytest.mark.slow
@pytest.mark.parametrize("kw", _matrix())
def test_the_whole_matrix(kw):
    """Every combination of the selectors' values: it runs (as above), or it is refused in
    one line."""
    m = get_model("compressor")
    try:
        values = m.parameters(kw)
    except ParameterError as exc:
        assert "\n" not in str(exc)
        return
    _run_and_check(kw, m.route(values)[0])


@pytest.mark.parametrize("kw,route", [
    ({"guide": "clearance", "crank_joint": "ideal"}, "contact"),
    ({"guide": "clearance", "crank_joint": "ideal", "load": "valves"}, "contact-valves"),
    ({"guide": "clearance", "crank_joint": "ideal", "load_table": TABLE}, "contact"),
    ({"guide": "clearance", "crank_joint": "ideal", "crosshead_joint": "contact"}, "contact"),
    ({"guide": "clearance", "crank_joint": "lubricated", "load": "valves"}, "contact-valves"),
])  # fmt: skip
def test_the_guide_clearance_runs_on_the_contact_joints_kernels(kw, route):
    """The contact joints' kernels carry the guide (tests/test_guide_component.py checks them
    against the independent kernel of compressor-guide-reference) with any pin joint and any
    load, so every combination with the guide clearance routes there and keeps guide =
    clearance in its values. (Routing and validation only: the runs are
    test_guide_component's.)"""
    m = get_model("compressor")
    values = m.parameters(kw)
    assert m.route(values)[0] == route
    assert values["guide"] == "clearance"
    assert (values["crank_joint"], values["crosshead_joint"]) == (
        kw["crank_joint"], kw.get("crosshead_joint", "ideal"))  # fmt: skip


def test_a_chosen_guide_is_part_of_a_sweep_stores_identity():
    """The contact joints leave the guide's parameters out of a store's digest while the
    guide is ideal (the old stores keep theirs: the pinned digests above) and keep them once
    it is chosen: two stores that differ only in the guide's clearance never share a digest."""
    from recipdyn.sweep import SweepSpec, parse_axis

    axis = parse_axis("omega=19:21:2", "compressor-contact")

    def digest(**base):
        return SweepSpec(axes=(axis,), measures=("peak",), model="compressor-contact",
                         base=base).digest  # fmt: skip

    ideal = digest()
    assert ideal == PINNED_DIGESTS["compressor-contact"]
    worn = digest(guide="clearance", guide_clearance=2e-4)
    assert worn != ideal and worn != digest(guide="clearance", guide_clearance=3e-4)
