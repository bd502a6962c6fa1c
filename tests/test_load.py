"""Cylinder load model (Eq. 1-2), sign convention and table loads."""

import numpy as np
import pytest

from recipdyn.model import CompressorParams, ParameterError, gas_force, mu_paper, read_load_table


def test_mu_values_and_continuity():
    """Eq. (2): mu = 1 at 0 and over the exhaust, sin(pi/16) over the suction, continuous."""
    pi = np.pi
    assert mu_paper(0.0) == pytest.approx(1.0)
    assert mu_paper(pi / 2 + 0.3) == pytest.approx(np.sin(pi / 16))
    assert mu_paper(1.6 * pi) == pytest.approx(1.0)
    for b in (7 * pi / 16, pi, 23 * pi / 16, 2 * pi):
        assert mu_paper(b - 1e-9) == pytest.approx(mu_paper(b + 1e-9), abs=1e-8)
    th = np.linspace(0, 4 * pi, 1001)
    np.testing.assert_allclose(mu_paper(th), mu_paper(th + 2 * pi), atol=1e-12)
    assert np.all(mu_paper(th) > 0)


def test_sign_convention():
    """Physical: the gas pushes the crosshead toward the crank (-x); paper: +x."""
    assert gas_force(0.0, CompressorParams()) == pytest.approx(-2e5)
    assert gas_force(0.0, CompressorParams(load_sign="paper")) == pytest.approx(2e5)


def test_table_load_is_periodic_linear_interpolation(tmp_path):
    f = tmp_path / "load.csv"
    f.write_text("# angle_deg, force_N\nangle,force\n0,-100\n90,-200\n180,-50\n270,-300\n")
    table = read_load_table(f)
    p = CompressorParams(load_table=table)
    assert gas_force(np.deg2rad(45.0), p) == pytest.approx(-150.0)
    assert gas_force(np.deg2rad(315.0), p) == pytest.approx(-200.0)  # wraps to 0 deg
    assert gas_force(np.deg2rad(315.0) + 2 * np.pi, p) == pytest.approx(-200.0)
    p2 = CompressorParams(load_table=read_load_table(f, area=0.01))
    assert gas_force(np.deg2rad(90.0), p2) == pytest.approx(-2.0)


def test_bad_table(tmp_path):
    f = tmp_path / "bad.csv"
    f.write_text("0,1\n")
    with pytest.raises(ParameterError, match="rows"):
        read_load_table(f)
    with pytest.raises(ParameterError, match="increase"):
        CompressorParams(load_table=((10.0, 1.0), (5.0, 2.0)))


def test_mu_from_sine_and_cosine_equals_the_angle_form():
    """mu_sincos (branches by the signs and the cosine, the values by the addition theorem)
    against mu_kernel on 20 001 angles over two revolutions plus each branch point and its
    neighbours 1e-12 rad away: equal to 1e-14 (mu is continuous at every branch point, so a
    branch decided differently at the last bit moves the value only by rounding)."""
    import math

    from recipdyn.model.load import mu_kernel, mu_sincos

    pts = [k * math.pi / 16 + o for k in (0, 7, 16, 23, 32) for o in (-1e-12, 0.0, 1e-12)]
    for th in [*np.linspace(-2.0 * np.pi, 2.0 * np.pi, 20_001), *pts]:
        assert abs(mu_sincos(math.sin(th), math.cos(th)) - mu_kernel(th)) < 1e-14, th
