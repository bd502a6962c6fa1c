"""Figures show what they claim: the feature inside the axes, labels with units, no NaN,
cells where their values are, a colour-blind-safe palette (issue 14, item 1).

Each test checks a property of the drawn figure (axis limits, artists, labels) against a
number computed independently of the plotting code, not only that a file was written.
"""

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from recipdyn.analysis.spectrum import amplitude_spectrum, display_band, nonharmonic_peak
from recipdyn.model.parameters import CompressorParams
from recipdyn.plotting import (
    PALETTE,
    _mpl,
    centred,
    is_dense,
    plot_orbit,
    plot_signal,
    response_figure,
    unit_tex,
)
from recipdyn.simulate import simulate
from recipdyn.sweep.plots import cell_edges, sweep_figures, wrap_around_mean


def _labelled(ax) -> bool:
    return bool(ax.get_xlabel().strip()) and bool(ax.get_ylabel().strip())


def _finite_lines(fig) -> bool:
    return all(
        np.all(np.isfinite(np.asarray(line.get_xydata(), dtype=float)))
        for ax in fig.axes
        for line in ax.get_lines()
    )


@pytest.fixture(scope="module")
def ringing_run():
    """rc = 0.5 mm started 0.2 rad off the link's equilibrium: the link rings at ~2.3 kHz,
    far above the 60 crank orders (191 Hz) the simulate figure used to show."""
    p = CompressorParams(rc=0.5e-3, d=0.0, theta_c_offset=0.2)
    return simulate(p, revolutions=4, transient=0, fs=10_000)


def test_response_figure_shows_the_link_line(ringing_run):
    ds = ringing_run
    fc = float(ds.attrs["crank_frequency_hz"])
    spec = amplitude_spectrum(ds["a"].values, 10_000.0)
    f_link = nonharmonic_peak(spec.frequency, spec.amplitude, fc)
    assert f_link > 60 * fc  # the line the old fixed 60-order band cut off
    fig = response_figure(ds)
    try:
        spec_ax = fig.axes[3]
        assert spec_ax.get_xlim()[0] <= f_link <= spec_ax.get_xlim()[1]
        assert spec_ax.get_yscale() == "log"
        assert any("crank orders" in t.get_text() for t in spec_ax.texts)  # the annotation
        assert all(_labelled(ax) for ax in fig.axes[:4])
        assert _finite_lines(fig)
    finally:
        _mpl().close(fig)


def test_display_band_limits():
    """Every line above 1e-3 of the largest is inside the band; the band never passes
    Nyquist and never drops below min_orders of the fundamental."""
    fs, n = 2000.0, 20_000
    t = np.arange(n) / fs
    x = np.sin(2 * np.pi * 3.0 * t) + 0.01 * np.sin(2 * np.pi * 700.0 * t)
    spec = amplitude_spectrum(x, fs)
    top = display_band(spec, 3.0)
    assert 700.0 < top <= fs / 2
    assert display_band(amplitude_spectrum(np.sin(2 * np.pi * 3.0 * t), fs), 3.0) == 90.0
    x2 = x + 0.5 * np.sin(2 * np.pi * 990.0 * t)  # a line near Nyquist: capped there
    assert display_band(amplitude_spectrum(x2, fs), 3.0) == fs / 2


def test_dense_signal_drawn_as_envelope_with_zoom():
    """1 kHz over 2 s is ~2000 cycles on ~800 pixel columns: drawn as the per-column
    min/max band, whose extremes are the signal's, plus an inset with a few periods."""
    plt = _mpl()
    t = np.arange(0, 2.0, 1e-5)
    y = np.sin(2 * np.pi * 1.5 * t) + 0.3 * np.sin(2 * np.pi * 1000.0 * t)
    fig, ax = plt.subplots(figsize=(9, 3))
    try:
        assert is_dense(y, 800)
        art = plot_signal(ax, t, y)
        verts = art.get_paths()[0].vertices
        assert verts[:, 1].max() == pytest.approx(y.max(), abs=1e-12)
        assert verts[:, 1].min() == pytest.approx(y.min(), abs=1e-12)
        assert len(ax.child_axes) == 1  # the zoom
        zoom = ax.child_axes[0].get_lines()[0].get_xdata()
        assert 3e-3 < np.ptp(zoom) < 2e-2  # six periods of 1 ms
    finally:
        plt.close(fig)
    fig, ax = plt.subplots(figsize=(9, 3))
    try:
        slow = np.sin(2 * np.pi * 1.5 * t)
        assert not is_dense(slow, 800)
        assert plot_signal(ax, t, slow)[0].get_xydata().shape == (t.size, 2)
        assert not ax.child_axes
    finally:
        plt.close(fig)


def test_is_dense_counts_prominent_peaks_as_find_peaks_does(rng):
    """is_dense skips SciPy's signal module when a signal has too few local maxima to be dense;
    the answer is the one the prominence count gives, for smooth signals, plateaus, ripple
    that only rounding would show, and dense rings."""
    from scipy.signal import find_peaks

    t = np.linspace(0.0, 1.0, 20_000)
    cases = {
        "slow": np.sin(2 * np.pi * 3 * t),
        "plateaus": np.round(np.sin(2 * np.pi * 40 * t), 1),
        "ripple": np.sin(2 * np.pi * 3 * t) + 1e-6 * rng.standard_normal(t.size),
        "ring": np.sin(2 * np.pi * 3 * t) + 0.2 * np.sin(2 * np.pi * 900 * t),
        "noise": rng.standard_normal(t.size),
    }
    answers = set()
    for name, y in cases.items():
        for cols in (100, 400, 1000):
            expected = find_peaks(y, prominence=0.01 * np.ptp(y))[0].size > cols / 3
            assert is_dense(y, cols) == expected, (name, cols)
            answers.add(expected)
    assert answers == {True, False}


def test_dense_orbit_is_drawn_as_density():
    """A dense orbit becomes its occupation density: the histogram sums to 1 over the cells
    the orbit visits; a sparse one stays a line."""
    plt = _mpl()
    t = np.arange(0, 2.0, 1e-5)
    x, y = np.sin(2 * np.pi * 500 * t), np.cos(2 * np.pi * 500 * t) * (1 + 0.1 * t)
    fig, ax = plt.subplots()
    try:
        mesh = plot_orbit(ax, x, y)
        h = np.ma.filled(mesh.get_array(), np.nan).astype(float)
        assert np.nansum(h) == pytest.approx(1.0, rel=1e-12)
        (line,) = plot_orbit(ax, x[:2000], y[:2000])  # 10 turns: an ordinary line
        assert line.get_xydata().shape == (2000, 2)
    finally:
        plt.close(fig)


def test_centred_section_axis():
    """A section spanning micrometres per second around -4 mm/s: deviations in um/s, the
    median in the label, and the values recoverable from the two."""
    v = -0.0040067 + 5e-6 * np.sin(np.linspace(0, 6, 200))
    dev, label = centred(v, "v", "m/s")
    assert "\u00b5m/s" in label and "v + 0.00400" in label
    mid = float(np.median(v))
    np.testing.assert_allclose(mid + dev * 1e-6, v, rtol=0, atol=1e-15)
    assert 5 < np.ptp(dev) < 20
    wide = np.linspace(-1, 1, 50)  # a spread larger than the mean: unchanged
    same, label2 = centred(wide, "a", "m/s**2")
    assert same is wide or np.array_equal(same, wide)
    assert label2 == "a (m/s$^{2}$)"
    assert unit_tex("kg*m**2") == "kg*m$^{2}$"


def test_log_cells_are_centred_on_their_values():
    """On a log axis each cell's edges are geometric midpoints: the value is the geometric
    mean of its edges and a regular log grid has equal cells (linear midpoints, as
    shading='nearest' uses, violate both)."""
    c = np.geomspace(0.1, 5.0, 8)
    e = cell_edges(c, log=True)
    np.testing.assert_allclose(np.sqrt(e[:-1] * e[1:]), c, rtol=1e-12)
    np.testing.assert_allclose(np.diff(np.log(e)), np.log(c[1] / c[0]), rtol=1e-12)
    lin = cell_edges(np.array([0.0, 1.0, 3.0]))
    np.testing.assert_allclose(lin, [-0.5, 0.5, 2.0, 4.0])


def test_angle_wrapped_around_its_mean_is_one_band():
    """A link hanging near +-pi: wrapped to (-pi, pi] it splits into two bands 2 pi apart;
    around its circular mean it is one band of its true width."""
    rng = np.random.default_rng(1)
    theta = np.pi + rng.uniform(-0.3, 0.3, 500) + 2 * np.pi * rng.integers(-3, 3, 500)
    assert np.ptp(np.angle(np.exp(1j * theta))) > 5.0  # the old plot: two bands
    wrapped, centre = wrap_around_mean(theta)
    assert np.ptp(wrapped) < 0.6 + 1e-9
    assert abs(np.angle(np.exp(1j * (centre - np.pi)))) < 0.05


def test_fault_map_mesh_on_log_axis(tmp_path):
    """The fault map of a synthetic rc (log) x d store: the drawn mesh's cell edges are the
    geometric midpoints, and the value grid is labelled on the log axis."""
    import matplotlib

    rc = np.geomspace(1e-4, 5e-3, 5)
    d = np.linspace(0, 5e-3, 3)
    z = np.add.outer(np.arange(5.0), np.arange(3.0))
    ds = xr.Dataset(
        {"lambda1": (("rc", "d"), z), "done": (("rc", "d"), np.ones_like(z, dtype=bool))},
        coords={"rc": ("rc", rc, {"units": "m", "scale": "log"}), "d": ("d", d, {"units": "m"})},
        attrs={"sweep_axes": "rc,d", "model": "compressor"},
    )
    seen = {}
    orig = matplotlib.axes.Axes.pcolormesh

    def spy(self, *args, **kw):
        seen.setdefault("args", args)  # the first: the map (the colour bar draws one too)
        return orig(self, *args, **kw)

    matplotlib.axes.Axes.pcolormesh = spy
    try:
        paths = sweep_figures(ds, tmp_path)
    finally:
        matplotlib.axes.Axes.pcolormesh = orig
    assert any(p.name == "map_lambda1.png" for p in paths)
    xe, ye = seen["args"][0], seen["args"][1]
    np.testing.assert_allclose(np.sqrt(ye[:-1] * ye[1:]), 1e3 * rc, rtol=1e-12)
    np.testing.assert_allclose(xe, cell_edges(1e3 * d))


def test_palette_is_the_default_cycle():
    """Okabe-Ito colours (distinguishable with the common colour-vision deficiencies)."""
    plt = _mpl()
    cycle = [c["color"].upper() for c in plt.rcParams["axes.prop_cycle"]]
    assert cycle == [c.upper() for c in PALETTE]


# --- Layout: no text on text, nothing outside the figure (issue 34, item 2) -------------------
#
# Every figure a command writes is drawn at its own size (the layout depends on the size in
# inches and the font sizes, not on the length of the record, so short records keep the tests
# fast) and its text boxes are compared: tick labels, axis labels, titles, annotations, legend
# entries and the provenance footer must not intersect one another, no text and no axes may
# leave the figure, and an annotation must stay inside its own axes.


def _all_axes(fig) -> list:
    """The figure's axes and their insets (child axes), each once."""
    seen, stack = [], list(fig.axes)
    while stack:
        ax = stack.pop(0)
        if ax not in seen:
            seen.append(ax)
            stack.extend(ax.child_axes)
    return seen


def _texts(fig) -> list:
    """(name, Text, owning axes or None) of every visible, non-empty text that is drawn."""
    out, ids = [], set()

    def add(name, t, ax):
        if t is not None and id(t) not in ids and t.get_visible() and t.get_text().strip():
            ids.add(id(t))
            out.append((name, t, ax))

    for attr in ("_suptitle", "_supxlabel", "_supylabel"):
        add(attr.strip("_"), getattr(fig, attr, None), None)
    for t in fig.texts:
        add(f"figure text {t.get_text()[:40]!r}", t, None)
    for k, ax in enumerate(_all_axes(fig)):
        if not ax.get_visible():
            continue
        what = ax.title.get_text() or ax.yaxis.label.get_text() or ax.get_label()
        tag = f"axes {k} ({what[:30]!r})"
        for t in (ax.title, ax._left_title, ax._right_title):
            add(f"{tag} title", t, ax)
        if ax.axison:
            for name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
                if not axis.get_visible():
                    continue
                add(f"{tag} {name}label", axis.label, ax)
                add(f"{tag} {name} offset text", axis.get_offset_text(), ax)
                for tick in axis._update_ticks():  # the ticks that are drawn
                    for lab in (tick.label1, tick.label2):
                        add(f"{tag} {name}tick {lab.get_text()!r}", lab, ax)
        for t in ax.texts:
            add(f"{tag} text {t.get_text()[:40]!r}", t, ax)
        leg = ax.get_legend()
        if leg is not None and leg.get_visible():
            for t in leg.get_texts():
                add(f"{tag} legend {t.get_text()[:30]!r}", t, ax)
    return out


def _within(bb, box) -> bool:
    """Bounding box ``bb`` lies wholly inside ``box``."""
    return box.x0 <= bb.x0 and bb.x1 <= box.x1 and box.y0 <= bb.y0 and bb.y1 <= box.y1


def layout_defects(fig, tol: float = 0.5) -> list[str]:
    """Draw ``fig`` (its layout engine runs) and list its layout defects: two texts whose boxes
    intersect, a layout engine that gave up (axes collapsed), a text or an axes outside the
    figure, a text running into another axes (a panel or a colour bar; an inset's texts may
    lie on its parent), a note or annotation crossing its own axes' frame (half in, half
    out; a label wholly in the margin is fine).
    ``tol`` pixels at each box's edge are forgiven (glyph boxes include antialiasing
    margins)."""
    import warnings

    from matplotlib.text import Text

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fig.canvas.draw()
    bad = [f"layout engine: {w.message}" for w in caught if "layout" in str(w.message)]
    r = fig.canvas.get_renderer()
    fb = fig.bbox.padded(tol)
    items = []
    for name, t, ax in _texts(fig):
        bb = Text.get_window_extent(t, r)  # the text alone, not an annotation's arrow
        if bb.width > 0 and bb.height > 0:
            items.append((name, ax, bb.padded(-tol)))
    bad += [f"outside the figure: {n}" for n, _, bb in items if not _within(bb, fb)]
    for ax in _all_axes(fig):
        bb = ax.get_window_extent(r).padded(-tol)
        if ax.get_visible() and not _within(bb, fb):
            bad.append(f"axes outside the figure: {ax.title.get_text() or ax.get_label()!r}")
    boxes = [(ax, ax.get_window_extent(r)) for ax in _all_axes(fig) if ax.get_visible()]
    parent = {child: ax for ax in _all_axes(fig) for child in ax.child_axes}
    for name, ax, bb in items:
        family = {ax, parent.get(ax), *getattr(ax, "child_axes", ())}
        for other, box in boxes:
            inside = _within(bb, box.padded(tol))
            if other is ax and " text " in name and not inside and bb.overlaps(box):
                bad.append(f"crosses its axes' frame: {name}")  # half in, half out
            elif other not in family and bb.overlaps(box):
                bad.append(f"runs into another axes ({other.title.get_text()[:30]!r}): {name}")
    for i, (ni, _, bi) in enumerate(items):
        for nj, _, bj in items[i + 1 :]:
            if bi.overlaps(bj):
                bad.append(f"overlap: {ni} / {nj}")
    return bad


def test_layout_checker_finds_overlaps_and_escapes():
    """The checker itself: two texts placed on one another, a text half outside the figure, an
    annotation crossing its axes' frame and a note running into the next panel are found; a
    clean figure gives nothing."""
    plt = _mpl()
    fig, ax = plt.subplots(figsize=(4, 3), layout="constrained")
    try:
        ax.plot([0, 1], [0, 1])
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        assert layout_defects(fig) == []
        ax.text(0.5, 0.5, "first label", transform=ax.transAxes)
        ax.text(0.52, 0.5, "second label", transform=ax.transAxes)
        fig.text(0.98, 0.5, "runs off the edge")
        ax.annotate("half outside", (0.5, 0.5), xytext=(0.9, 0.3), textcoords="axes fraction")
        found = layout_defects(fig)
        assert any("overlap" in d and "first label" in d and "second label" in d for d in found)
        assert any(d.startswith("outside the figure") and "runs off" in d for d in found)
        assert any(d.startswith("crosses its axes") and "half outside" in d for d in found)
    finally:
        plt.close(fig)
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(6, 3), layout="constrained")
    try:
        ax.text(
            0.5, 0.5, "a note too long for its own panel", transform=ax.transAxes, in_layout=False
        )  # a layout engine would otherwise make room for it
        assert any(d.startswith("runs into another axes") for d in layout_defects(fig))
    finally:
        plt.close(fig)


def _capture(monkeypatch, module) -> dict:
    """Replace ``module.save_figure`` by one that records each figure's layout defects (by
    file name) before saving it: the figures a command writes, checked as written."""
    found: dict[str, list[str]] = {}
    orig = module.save_figure

    def check_and_save(fig, path, **kw):
        found[Path(path).name] = layout_defects(fig)
        return orig(fig, path, **kw)

    monkeypatch.setattr(module, "save_figure", check_and_save)
    return found


def _report(found: dict) -> str:
    return "\n".join(f"{name}: {len(d)} defect(s)\n  " + "\n  ".join(d[:12])
                     for name, d in found.items() if d)  # fmt: skip


SIM_MODELS = ("compressor", "compressor-contact", "compressor-valves",
              "compressor-contact-valves")  # fmt: skip


@pytest.fixture(scope="module")
def short_records(tmp_path_factory):
    """Two revolutions of each compressor model from the start (the start-up included, as
    ``simulate`` records it), at 5 kHz."""
    from recipdyn.cli import main

    d = tmp_path_factory.mktemp("records")
    out = {}
    for m in SIM_MODELS:
        p = d / f"{m}.nc"
        assert main(["simulate", "--model", m, "-n", "2", "--fs", "5 kHz", "--no-figure",
                     "--no-progress", "-o", str(p)]) == 0  # fmt: skip
        out[m] = xr.load_dataset(p)
    return out


@pytest.mark.parametrize("model", SIM_MODELS)
def test_simulate_figures_have_no_layout_defects(short_records, model):
    """The figure ``simulate`` writes for each compressor model (and the compression-cycle
    figure of the models with a gas cycle)."""
    from recipdyn.plotting import cycle_figure, model_figure

    plt = _mpl()
    ds = short_records[model]
    found = {}
    fig = model_figure(ds)
    found["simulate"] = layout_defects(fig)
    plt.close(fig)
    if "y_suction_head" in ds or ds.attrs.get("param_load") == "cycle":
        fig = cycle_figure(ds)
        found["cycle"] = layout_defects(fig)
        plt.close(fig)
    assert not any(found.values()), _report(found)


def test_ringing_response_figure_has_no_layout_defects(ringing_run):
    """The link's ~2 kHz line annotated in the spectrum, envelopes with zoom insets."""
    fig = response_figure(ringing_run)
    try:
        found = layout_defects(fig)
        assert not found, "\n".join(found)
    finally:
        _mpl().close(fig)


def test_compare_figure_has_no_layout_defects(short_records, ringing_run, tmp_path, monkeypatch):
    """``compare`` of a smooth run and a ringing one (a 3 Hz crank line beside a 2 kHz link
    line)."""
    import recipdyn.compare as compare

    a, b = tmp_path / "natural.nc", tmp_path / "ringing.nc"
    short_records["compressor"].to_netcdf(a)
    ringing_run.to_netcdf(b)
    found = _capture(monkeypatch, compare)
    compare.compare_runs([a, b], tmp_path / "cmp")
    assert set(found) == {"compare.png"}
    assert not any(found.values()), _report(found)


def test_analyze_figures_have_no_layout_defects(tmp_path, monkeypatch):
    """Every figure ``analyze`` writes for a chaotic compressor run (spectrum, phase portraits,
    vibration page, Poincaré section, Benettin and signal-exponent figures), on a short run."""
    import recipdyn.analyze as analyze
    from recipdyn.cli import main

    run = tmp_path / "run.nc"
    assert main(["simulate", "--rc", "1 mm", "--set", "theta_c_offset=0.3", "-n", "3", "--fs",
                 "5 kHz", "-o", str(run), "--no-figure", "--no-progress"]) == 0  # fmt: skip
    found = _capture(monkeypatch, analyze)
    analyze.analyze_run(run, tmp_path / "an", section_points=30, lyap_revolutions=5,
                        max_signal_samples=5000)  # fmt: skip
    assert {"spectrum.png", "phase_portraits.png", "vibration.png", "poincare.png",
            "lyapunov_benettin.png"} <= set(found)  # fmt: skip
    assert not any(found.values()), _report(found)


def _sweep_store_1d() -> xr.Dataset:
    """A synthetic crank-speed sweep: section points, lambda1, peaks and the strongest lines,
    among them a resonance at 2 kHz (the link) that stays put while the orders (1.6-24 Hz)
    fan out."""
    rng = np.random.default_rng(3)
    omega = np.linspace(10.0, 150.0, 15)
    fc = omega / (2 * np.pi)
    n_lines, n_sec = 6, 40
    freq = np.c_[fc[:, None] * np.arange(1, n_lines), np.full(omega.size, 2000.0)]
    amp = np.c_[1.0 / np.arange(1, n_lines)[None, :].repeat(omega.size, 0),
                np.full(omega.size, 0.05)]  # fmt: skip
    return xr.Dataset(
        {
            "done": ("omega", np.ones(omega.size, dtype=bool)),
            "poincare_v": (("omega", "section"), rng.normal(0, 1e-3, (omega.size, n_sec)),
                           {"units": "m/s"}),
            "poincare_theta_c": (("omega", "section"), np.pi + rng.normal(0, 0.1,
                                 (omega.size, n_sec)), {"units": "rad"}),
            "lambda1": ("omega", rng.normal(0, 1, omega.size), {"units": "1/s"}),
            "peak_a": ("omega", 10 + omega, {"units": "m/s**2"}),
            "peak_freq": (("omega", "line"), freq, {"units": "Hz"}),
            "peak_amp": (("omega", "line"), amp, {"units": "m/s**2"}),
            "forcing_hz": ("omega", fc, {"units": "Hz"}),
        },
        coords={"omega": ("omega", omega, {"units": "rad/s"})},
        attrs={"sweep_axes": "omega", "model": "compressor"},
    )  # fmt: skip


def _sweep_store_2d() -> xr.Dataset:
    """A synthetic rc (log) x d fault map with lambda1, peaks, RMS and distinct points."""
    rc = np.geomspace(1e-4, 5e-3, 9)
    d = np.linspace(0, 5e-3, 6)
    z = np.add.outer(np.log(rc), d * 100)
    return xr.Dataset(
        {"lambda1": (("rc", "d"), z, {"units": "1/s"}),
         "peak_a": (("rc", "d"), 1e3 * np.exp(z), {"units": "m/s**2"}),
         "rms_a": (("rc", "d"), 3e2 * np.exp(z), {"units": "m/s**2"}),
         "poincare_distinct": (("rc", "d"), np.ones_like(z)),
         "done": (("rc", "d"), np.ones_like(z, dtype=bool))},
        coords={"rc": ("rc", rc, {"units": "m", "scale": "log"}), "d": ("d", d, {"units": "m"})},
        attrs={"sweep_axes": "rc,d", "model": "compressor"},
    )  # fmt: skip


@pytest.mark.parametrize("store", [_sweep_store_1d, _sweep_store_2d], ids=["1d", "2d"])
def test_sweep_figures_have_no_layout_defects(store, tmp_path, monkeypatch):
    """Bifurcation diagrams, exponent and peak curves, the Campbell diagram (orders 1-10 fan
    out below a 2 kHz resonance) and the fault maps on a log axis."""
    import recipdyn.sweep.plots as plots

    found = _capture(monkeypatch, plots)
    plots.sweep_figures(store(), tmp_path)
    assert found
    assert not any(found.values()), _report(found)


def test_compare_spectra_on_a_log_frequency_axis(short_records, ringing_run, tmp_path,
                                                 monkeypatch):  # fmt: skip
    """The spectra panel of ``compare``: a log frequency axis whose range holds both the
    3.18 Hz crank line (at 20 rad/s) and the ~2.3 kHz link line, with crank orders on top."""
    import recipdyn.compare as compare

    a, b = tmp_path / "natural.nc", tmp_path / "ringing.nc"
    short_records["compressor"].to_netcdf(a)
    ringing_run.to_netcdf(b)
    figs = []
    monkeypatch.setattr(compare, "save_figure", lambda fig, path, **kw: figs.append(fig))
    monkeypatch.setattr(_mpl(), "close", lambda fig: None)
    compare.compare_runs([a, b], tmp_path / "cmp")
    ax = figs[0].axes[1]
    try:
        assert ax.get_xscale() == "log"
        lo, hi = ax.get_xlim()
        fc = 20.0 / (2 * np.pi)
        assert lo <= fc / 2 and hi >= 2000.0
        assert any(c.get_xlabel() == "crank order" for c in ax.child_axes)
    finally:
        import matplotlib.pyplot as plt

        plt.close(figs[0])


def test_contact_figure_is_scaled_to_the_steady_part(short_records):
    """The contact record starts with the journal's fall onto the bearing (|a| ~4000 m/s^2
    against ~60 after it): the acceleration panel is scaled to the second revolution and the
    start-up is marked as off scale."""
    from recipdyn.plotting import contact_figure

    ds = short_records["compressor-contact"]
    t, a = ds["time"].values, ds["a"].values
    steady = t >= t[0] + 2 * np.pi / ds.attrs["param_omega"]
    assert np.abs(a[~steady]).max() > 10 * np.abs(a[steady]).max()  # the premise
    fig = contact_figure(ds)
    try:
        lo, hi = fig.axes[0].get_ylim()
        span = a[steady].max() - a[steady].min()
        assert lo == pytest.approx(a[steady].min() - 0.05 * span)
        assert hi == pytest.approx(a[steady].max() + 0.05 * span)
        labels = fig.axes[0].get_legend_handles_labels()[1]
        assert any(lab.startswith("start-up (1st revolution): off scale") for lab in labels)
    finally:
        _mpl().close(fig)


def test_dense_phase_portrait_is_a_density_and_a_cycle_stays_a_line():
    """analyze's phase portrait: 2000 turns of a quasi-periodic orbit are drawn as their
    occupation density (fractions summing to 1), ten turns of a cycle as a line."""
    from recipdyn.analysis.plots import plot_phase

    plt = _mpl()
    t = np.linspace(0, 1.0, 60_000)
    x = np.sin(2 * np.pi * 2000 * t) + 0.5 * np.sin(2 * np.pi * 2000 * np.sqrt(2) * t)
    y = np.cos(2 * np.pi * 2000 * t) + 0.5 * np.cos(2 * np.pi * 2000 * np.sqrt(2) * t)
    fig = plot_phase(x, y, "x", "y", title="torus")
    try:
        ax = fig.axes[0]
        (mesh,) = ax.collections
        h = np.ma.filled(mesh.get_array(), np.nan).astype(float)
        assert np.nansum(h) == pytest.approx(1.0, rel=1e-12)
        assert "occupation density" in ax.get_title()
    finally:
        plt.close(fig)
    fig = plot_phase(x[:300], y[:300], "x", "y")
    try:
        assert len(fig.axes[0].get_lines()) == 1 and not fig.axes[0].collections
    finally:
        plt.close(fig)


def test_lyapunov_plots_give_the_time_unit():
    """The averaging time of Benettin's history and the divergence time carry units."""
    from types import SimpleNamespace

    from recipdyn.analysis.plots import plot_divergence, plot_lyapunov_history

    plt = _mpl()
    res = SimpleNamespace(times=np.arange(1.0, 5.0), history=np.ones((4, 2)),
                          exponents=np.array([1.0, -1.0]), sum=0.0)  # fmt: skip
    for unit, expect in (("1/s", "(s)"), ("per iteration", "(iterations)")):
        fig = plot_lyapunov_history(res, unit=unit)
        assert fig.axes[0].get_xlabel() == f"averaging time {expect}"
        plt.close(fig)
    div = SimpleNamespace(params={"dt": 1e-4, "dim": 3, "delay": 2}, steps=np.arange(10),
                          curve=np.linspace(0, 1, 10), fit=(1, 5), exponent=10.0, ok=True,
                          method="rosenstein", reason="")  # fmt: skip
    fig = plot_divergence(div)
    assert fig.axes[0].get_xlabel() == "divergence time (s)"
    plt.close(fig)
