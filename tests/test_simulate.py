"""simulate(): labelled output, recorded inputs, partial results on failure."""

import dataclasses
import math

import numpy as np
import pytest

from recipdyn import CompressorParams, IntegrationError, simulate
from recipdyn.simulate import params_from_attrs


def test_dataset_records_every_input_and_units(tmp_path):
    p = CompressorParams(rc=0.5e-3, d=2e-3, omega=30.0, theta_c_offset=0.05)
    ds = simulate(p, revolutions=0.5, transient=0.5, fs=4000)
    for f in dataclasses.fields(CompressorParams):
        if f.name != "load_table":
            assert f"param_{f.name}" in ds.attrs
    assert params_from_attrs(ds.attrs) == p
    # the default start: the link aligned with the rod at t = 0 (checked from the closure
    # equation, independently of equilibrium_theta_c), plus the offset
    thc_eq = ds.attrs["theta_c_initial"] - p.theta_c_offset
    th2 = math.asin(-(p.d + p.r * math.sin(p.theta1_0) + p.rc * math.sin(thc_eq)) / p.l)
    assert math.sin(thc_eq - th2) == pytest.approx(0.0, abs=1e-12)
    assert math.cos(thc_eq - th2) == pytest.approx(-1.0)  # gas force toward the crank at t = 0
    assert ds.time.values[0] == pytest.approx(0.5 * p.crank_period)
    assert ds.time.attrs["units"] == "s" and ds.x.attrs["units"] == "m"
    np.testing.assert_allclose(np.diff(ds.time.values), 1 / 4000, rtol=1e-9)
    path = tmp_path / "r.nc"
    ds.to_netcdf(path)
    import xarray as xr

    back = xr.open_dataset(path)
    assert params_from_attrs(back.attrs) == p


def test_failure_keeps_what_was_computed():
    """The printed equations with a large initial offset blow up; the samples computed before
    the failure are returned with the error, not lost."""
    p = CompressorParams(equations="paper-printed", load_sign="paper", theta_c_offset=1.0)
    with pytest.raises(IntegrationError) as info:
        simulate(p, revolutions=2, fs=5000, rtol=1e-9)
    ds = info.value.dataset
    assert ds is not None and ds.sizes["time"] > 10
    assert np.all(np.isfinite(ds.a.values))


def test_bad_settings():
    from recipdyn import ParameterError

    with pytest.raises(ParameterError, match="revolutions"):
        simulate(revolutions=0)
    with pytest.raises(ParameterError, match="fs"):
        simulate(fs=-1.0)
    with pytest.raises(ParameterError, match="unknown parameter"):
        simulate(wobble=1.0)
