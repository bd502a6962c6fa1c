"""Figures show what they claim: the feature inside the axes, labels with units, no NaN,
cells where their values are, a colour-blind-safe palette (issue 14, item 1).

Each test checks a property of the drawn figure (axis limits, artists, labels) against a
number computed independently of the plotting code, not only that a file was written.
"""

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
