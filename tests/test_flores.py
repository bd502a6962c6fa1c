"""The slider-crank benchmark with a clearance joint at the slider pin (Flores et al. 2008,
Ch. 4; Flores & Ambrosio 2004): the ideal reference in closed form, and the benchmark's
qualitative findings at reduced size (2 revolutions instead of 5)."""

from __future__ import annotations

import numpy as np
import pytest

from recipdyn.model.registry import get_model
from recipdyn.reproduce import flores


def test_the_ideal_reference_is_the_rigid_slider_crank():
    """x from the closed form; a must equal its second derivative (central differences on a
    fine grid: error ~ h^2 a'''' / 12 ~ 1e-6 of the peak at 20 000 samples a revolution) and
    the pin force's x component must be -m3 a (the slider's only horizontal force)."""
    v = get_model("compressor-contact").parameters(flores.PARAMS)
    T = 2 * np.pi / v["omega"]
    t = np.linspace(0.0, T, 20001)
    ref = flores.ideal(v, t)
    x_closed = v["r"] * np.cos(v["omega"] * t) + np.sqrt(
        v["l"] ** 2 - (v["r"] * np.sin(v["omega"] * t)) ** 2
    )
    assert np.abs(ref["x"] - x_closed).max() < 1e-15
    h = t[1] - t[0]
    a_fd = (ref["x"][2:] - 2 * ref["x"][1:-1] + ref["x"][:-2]) / h**2
    assert np.abs(a_fd - ref["a"][1:-1]).max() < 1e-5 * np.abs(ref["a"]).max()
    assert np.allclose(ref["force_x"], -v["m3"] * ref["a"], rtol=0, atol=1e-9)
    # the peak slider acceleration of the rigid mechanism: r w^2 (1 + r / l) at dead centre
    assert np.abs(ref["a"]).max() == pytest.approx(
        v["r"] * v["omega"] ** 2 * (1 + v["r"] / v["l"]), rel=1e-9
    )


def test_the_benchmark_shows_the_published_qualitative_findings():
    """The findings the papers state for this case (their curves were not available to compare
    numerically): the journal alternates free flight, impacts and contact (both modes take a
    sizable part of each revolution); every revolution has many impacts; the slider
    acceleration and the pin force show peaks far above the ideal joint's. Measured over 5
    revolutions: 13-29 impacts a revolution, peaks 8-17x the ideal acceleration, contact
    fraction 0.52-0.73; the bounds (5 impacts, 4x, 0.3-0.9) leave room for the trajectory to
    differ between machines after the first impacts (it is sensitive to rounding), while an
    ideal joint (0 impacts, 1x) or a journal stuck to the wall (contact fraction 1) fails."""
    ds = flores.run(revolutions=2.0)
    f = flores.findings(ds)
    assert f["impacts_per_revolution"] >= 5
    assert 0.3 < f["contact_fraction"] < 0.9
    assert f["max_eccentricity_ratio"] < 1.3  # penetrations stay small against the clearance
    T = 2 * np.pi / ds.attrs["param_omega"]
    t = ds.time.values
    for k in range(2):
        rev = (t >= k * T + T / 100) & (t < (k + 1) * T)  # after the start's first impact
        a = np.abs(ds["a"].values[rev]).max()
        assert a > 4 * np.abs(ds["a_ideal"].values[rev]).max()
        assert ds["joint_force_crosshead"].values[rev].max() > 4 * ds["joint_force_ideal"].values[
            rev].max()  # fmt: skip
    assert ds.attrs["energy_balance_residual"] < 1e-6


@pytest.mark.parametrize("law", ["hertz", "lankarani-nikravesh"])
def test_exudyn_converges_to_recipdyn_on_the_benchmark(law):
    """The benchmark rebuilt in Exudyn (an open multibody code: absolute coordinates, joints as
    constraints with Lagrange multipliers, Newmark's implicit trapezoidal rule at a fixed step;
    `recipdyn.reproduce.flores_exudyn`) against recipdyn's model (two minimal coordinates from
    the Lagrange generator, DOP853, located onsets) over the first quarter revolution (9-10
    impacts). Hypothesis: both solve the same equations, so Exudyn's error is its own
    second-order truncation error. Then (1) halving its step must cut the difference to
    recipdyn by 4 (order 2: measured 2.02 and 2.03; bound 1.8-2.2), and (2) Richardson's
    extrapolation of its two runs, which removes that error to leading order, must agree with
    recipdyn to well below the error it removed (measured 60x and 30x below it; bound 10x).
    A wrong sign, a missed term, a mis-recorded approach velocity or a different mechanism would
    leave a difference that does not shrink with the step (before the approach velocity was
    interpolated to the crossing, Lankarani-Nikravesh's converged to 1.7e-5 c, not to 0).
    Rounding cannot matter: over this window a change of 1e-10 m/s in the initial rate moves e
    by at most 1.2e-10 m (Hertz; 4e-13 m with Lankarani-Nikravesh; measured), so rounding-level
    changes stay near 1e-15 m, against distances of 1e-10 m and more between the codes."""
    pytest.importorskip("exudyn")
    from recipdyn.reproduce.flores_exudyn import compare

    r = compare({"contact_law": law})
    assert r["impacts"] >= 8
    assert 1.8 < r["order"] < 2.2, r
    assert r["extrapolated"] < r["estimate"] / 10, r
    assert r["slider"][1] < r["slider"][0] / 10, r
