"""The compression-cycle gas load against the ideal cycle's closed forms (issue 13)."""

import math

import numpy as np
import pytest

from recipdyn.model.cycle import (
    cycle_force_kernel,
    cycle_geometry,
    cycle_states,
    ideal_indicated_work,
    ideal_volumetric_efficiency,
    indicated_work,
    pack_cycle,
    rod_load_reversal,
    volumetric_efficiency,
)

R, L, D = 0.12, 0.6, 1e-3
N_SAMPLES = 200_000  # trapezoid on a p(V) with kinks: relative error ~ (2 pi / N)^2 ~ 1e-9


def _cycle(ratio, clear, n, acting="head", ne=None, d=D, bore=0.4, rod=0.08):
    return pack_cycle(R, L, d, bore=bore, rod_diameter=rod, clearance_fraction=clear,
                      suction_pressure=1e5, discharge_pressure=1e5 * ratio, n_compression=n,
                      n_expansion=n if ne is None else ne, frame_pressure=101325.0,
                      acting=acting)  # fmt: skip


def test_dead_centres_are_the_extremes_of_the_offset_slider_crank():
    """x_max, x_min are the exact extremes of x(theta): no sample exceeds them, and they are
    sqrt((l +- r)^2 - d^2)."""
    g = cycle_geometry(R, L, 0.01, 0.4, 0.08)
    th = np.linspace(0, 2 * np.pi, 100_001)
    x = R * np.cos(th) + np.sqrt(L**2 - (0.01 + R * np.sin(th)) ** 2)
    assert x.max() <= g.x_max * (1 + 1e-15) and x.min() >= g.x_min * (1 - 1e-15)
    assert g.x_max == pytest.approx(math.sqrt((L + R) ** 2 - 0.01**2), rel=1e-15)
    assert g.x_min == pytest.approx(math.sqrt((L - R) ** 2 - 0.01**2), rel=1e-15)
    assert g.stroke > 2 * R  # an offset lengthens the stroke


@pytest.mark.parametrize("ratio", [1.5, 3.0, 6.0])
@pytest.mark.parametrize("clear", [0.05, 0.15, 0.3])
@pytest.mark.parametrize("acting", ["head", "crank"])
def test_ideal_cycle_matches_closed_forms(ratio, clear, acting):
    """Volumetric efficiency 1 - C (r^(1/n) - 1) and indicated work
    n/(n-1) p_s eta_v V_s (r^((n-1)/n) - 1), from the sampled cycle of either chamber, over a
    grid of pressure ratios and clearance fractions (n = 1.3). Tolerance 1e-7: the trapezoid's
    error on N = 2e5 samples of a p(theta) with kinks at the valve events."""
    n = 1.3
    c = _cycle(ratio, clear, n, acting)
    g = cycle_geometry(R, L, D, 0.4, 0.08)
    th = np.linspace(0, 2 * np.pi, N_SAMPLES, endpoint=False)
    st = cycle_states(th, c)
    key = "head" if acting == "head" else "crank"
    p, v = st[f"p_{key}"], st[f"V_{key}"]
    area = g.area_head if acting == "head" else g.area_crank
    vs = area * g.stroke
    ev = ideal_volumetric_efficiency(ratio, clear, n)
    if ev <= 0:
        pytest.skip("no delivery at this ratio and clearance")
    assert volumetric_efficiency(p, v, 1e5) == pytest.approx(ev, rel=1e-6, abs=1e-6)
    w = indicated_work(p, v)
    assert w == pytest.approx(ideal_indicated_work(1e5, ratio, clear, n, vs), rel=1e-7)
    assert p.min() == pytest.approx(1e5) and p.max() == pytest.approx(1e5 * ratio)


def test_zero_delivery_when_reexpansion_fills_the_stroke():
    """Beyond the ratio where C (r^(1/n) - 1) = 1 the valves never open: the gas is compressed
    and re-expanded along one polytrope, p V^n constant, and the net work is 0."""
    n, clear = 1.3, 0.3
    ratio = (1 + 1 / clear) ** n * 1.5
    c = _cycle(ratio, clear, n)
    th = np.linspace(0, 2 * np.pi, N_SAMPLES, endpoint=False)
    st = cycle_states(th, c)
    pvn = st["p_head"] * st["V_head"] ** n
    assert np.ptp(pvn) / pvn.mean() < 1e-12
    assert abs(indicated_work(st["p_head"], st["V_head"])) < 1e-9 * st["p_head"].max() * 0.1


def test_double_acting_force_is_the_sum_of_both_chambers():
    """F = -p_he A + p_ce (A - A_rod) + p_frame A_rod; with one chamber inactive it sits at the
    frame pressure, so the double-acting force is the sum of the single-acting ones minus the
    frame's share counted twice."""
    g = cycle_geometry(R, L, D, 0.4, 0.08)
    th = np.linspace(0, 2 * np.pi, 721)
    f = {a: np.array([cycle_force_kernel(t, _cycle(3.0, 0.1, 1.3, a)) for t in th])
         for a in ("head", "crank", "double")}  # fmt: skip
    frame = 101325.0 * (-g.area_head + g.area_crank + g.area_rod)  # both chambers at frame
    np.testing.assert_allclose(f["double"], f["head"] + f["crank"] - frame, rtol=1e-12,
                               atol=1e-9 * np.abs(f["double"]).max())  # fmt: skip
    st = cycle_states(th, _cycle(3.0, 0.1, 1.3, "double"))
    np.testing.assert_allclose(
        f["double"], -st["p_head"] * g.area_head + st["p_crank"] * g.area_crank
        + 101325.0 * g.area_rod, rtol=1e-12)  # fmt: skip


def test_rod_load_reversal_criteria():
    """A sinusoid reverses for 180 deg at 100 %; a load offset to stay positive never reverses;
    one with a short negative dip reverses for the dip only."""
    th = np.linspace(0, 2 * np.pi, 3600, endpoint=False)
    r = rod_load_reversal(th, np.cos(th))
    assert r.reversal_deg == pytest.approx(180.0, abs=0.2) and r.reverse_fraction == 1.0
    assert r.passed
    r = rod_load_reversal(th, 2.0 + np.cos(th))
    assert r.reversal_deg == 0.0 and r.reverse_fraction == 0.0 and not r.passed
    load = np.where(np.abs(th - np.pi) < np.radians(5), -0.02, 1.0)  # 10 deg at 2 %
    r = rod_load_reversal(th, load)
    assert r.reversal_deg == pytest.approx(10.0, abs=0.2)
    assert r.reverse_fraction == pytest.approx(0.02) and not r.passed
    assert "FAIL" in r.describe() and "API 618" in r.describe()


def test_simulated_gas_force_is_the_cycle_and_the_report_has_api618(tmp_path, capsys):
    """`recipdyn simulate --set load=cycle`: the gas force in the record is the cycle kernel's
    at the recorded crank angles (exactly: it is computed from them), the pressures stay within
    the line pressures, and the run prints the API 618 pin-reversal verdict and the indicated
    power, which equals the closed form for the double-acting cylinder (two chambers)."""
    import xarray as xr

    from recipdyn.cli import main
    from recipdyn.model import CompressorParams
    from recipdyn.model.load import gas_force

    out = tmp_path / "c.nc"
    code = main(["simulate", "--set", "load=cycle", "--set", "discharge_pressure=4 bar",
                 "-n", "2", "--fs", "5 kHz", "-o", str(out), "--no-figure",
                 "--no-progress"])  # fmt: skip
    text = capsys.readouterr().out
    assert code == 0, text
    assert "api618_pin_reversal" in text and "indicated_power_W" in text
    ds = xr.open_dataset(out)
    p = CompressorParams(load="cycle", discharge_pressure=4e5)
    np.testing.assert_array_equal(ds.gas_force.values, gas_force(ds.theta1.values, p))
    assert ds.p_head.min() >= 1e5 * (1 - 1e-12) and ds.p_head.max() <= 4e5 * (1 + 1e-12)
    assert ds.attrs["param_load_model"].startswith("compression cycle")
    g = cycle_geometry(p.r, p.l, p.d, p.bore, p.rod_diameter)
    w = sum(ideal_indicated_work(1e5, 4.0, 0.1, 1.3, a * g.stroke)
            for a in (g.area_head, g.area_crank))  # fmt: skip
    assert ds.attrs["indicated_power_W"] == pytest.approx(w * p.omega / (2 * math.pi), rel=1e-6)
    assert ds.attrs["api618_pin_reversal"] in ("pass", "FAIL")


@pytest.mark.parametrize("args, words", [
    (["--set", "load=cycle", "--set", "discharge_pressure=0.5 bar"],
     ["discharge_pressure", "suction_pressure"]),
    (["--set", "load=cycle", "--set", "rod_diameter=0.6"], ["rod_diameter", "allowed"]),
    (["--set", "load=cycle", "--set", "n_compression=3"], ["n_compression", "allowed"]),
    (["--set", "load=gas"], ["load", "cycle"]),
])  # fmt: skip
def test_cycle_bad_input_exit_2(tmp_path, capsys, args, words):
    from recipdyn.cli import main

    code = main(["simulate", *args, "-o", str(tmp_path / "x.nc"), "--no-figure",
                 "--no-progress"])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    for w in words:
        assert w in err


def test_contact_joint_takes_the_cycle_load():
    """The contact-impact model reads the same load parameters: its packed gas force is the
    cycle kernel's."""
    from recipdyn.model.compressor_contact import _gas
    from recipdyn.model.load import pack_load
    from recipdyn.model.registry import get_model

    m = get_model("compressor-contact")
    values = m.schema.validate({"load": "cycle", "discharge_pressure": 5e5})
    sysm = m.system(values)
    c = pack_load(values)[1]
    for t in (0.0, 0.05, 0.2):
        th1 = values["theta1_0"] + values["omega"] * t
        assert _gas(t, sysm.params) == cycle_force_kernel(th1, c)


def test_cycle_figure_shows_the_cycle(tmp_path):
    """The p-V panel spans the line pressures and both chambers' volumes, the rod-load panel
    carries the API 618 verdict, nothing drawn is NaN, every axis is labelled."""
    from recipdyn.model import CompressorParams
    from recipdyn.plotting import cycle_figure
    from recipdyn.simulate import simulate

    ds = simulate(CompressorParams(load="cycle", rc=0.0), revolutions=1.5, transient=0,
                  fs=4000.0)  # fmt: skip
    fig = cycle_figure(ds)
    pv, pt, rod = fig.axes[:3]
    lo, hi = pv.get_ylim()
    assert lo <= 1.0 and hi >= 3.0  # bar: suction and discharge inside the view
    assert pv.get_xlim()[1] >= 1e3 * float(ds.V_head.max())
    assert any("API 618" in t.get_text() for t in rod.texts)
    for ax in (pv, pt, rod):
        assert ax.get_xlabel() and ax.get_ylabel()
        for line in ax.get_lines():
            assert np.isfinite(np.asarray(line.get_ydata(), dtype=float)).all()
    fig.savefig(tmp_path / "c.png", dpi=60)
    assert (tmp_path / "c.png").stat().st_size > 5000
