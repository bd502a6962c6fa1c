"""Benettin's method against published exponents and exact identities (Sprott 2003)."""

import numpy as np
import pytest

from recipdyn.analysis import lyapunov_spectrum, lyapunov_spectrum_map
from recipdyn.analysis import systems as S
from recipdyn.model import CompressorParams, compressor_model


def test_lorenz():
    """Lorenz (10, 28, 8/3): (0.9056, 0, -14.572) within 0.01/0.01/0.05; the sum is the
    divergence -(sigma + 1 + beta) to 1e-3."""
    r = lyapunov_spectrum(S.lorenz(), [1.0, 1.0, 1.0], 2000.0, t_transient=50.0, dt=0.1)
    assert r.exponents[0] == pytest.approx(0.9056, abs=0.01)
    assert r.exponents[1] == pytest.approx(0.0, abs=0.01)
    assert r.exponents[2] == pytest.approx(-14.572, abs=0.05)
    assert r.sum == pytest.approx(-(10 + 1 + 8 / 3), abs=1e-3)
    assert r.history.shape[1] == 3 and r.times[-1] == pytest.approx(2000.0)


def test_rossler():
    r = lyapunov_spectrum(S.rossler(), [1.0, 1.0, 1.0], 5000.0, t_transient=100.0, dt=0.5)
    assert r.exponents[0] == pytest.approx(0.0714, abs=0.005)


def test_ueda_forced_oscillator():
    """Ueda x'' + 0.05 x' + x^3 = 7.5 cos t: lambda1 = 0.103 +- 0.005, sum = -0.05."""
    sysm = S.ueda()
    r = lyapunov_spectrum(sysm, [2.5, 0.0], 3000 * sysm.period, t_transient=50 * sysm.period)
    assert r.exponents[0] == pytest.approx(0.103, abs=0.005)
    assert r.sum == pytest.approx(-0.05, abs=1e-4)
    np.testing.assert_allclose(r.per_period, r.exponents * 2 * np.pi)


def test_linear_system_exact():
    """y' = A y: exponents are the real parts of the eigenvalues (negative ones too)."""
    A = [[-1.0, 2.0, 0.0], [0.0, -3.0, 1.0], [0.0, 0.0, -0.5]]
    r = lyapunov_spectrum(S.linear(A), [1.0, 1.0, 1.0], 3000.0, dt=0.5)
    np.testing.assert_allclose(r.exponents, [-0.5, -1.0, -3.0], atol=1e-3)


def test_short_run_does_not_collapse_to_zero():
    """Even one re-orthonormalisation interval gives the growth rate (final QR step)."""
    r = lyapunov_spectrum(S.linear([[0.7, 0.0], [0.0, -0.4]]), [1.0, 1.0], 0.05, dt=0.1)
    np.testing.assert_allclose(r.exponents, [0.7, -0.4], atol=1e-4)


def test_henon_map():
    r = lyapunov_spectrum_map(S.henon(), [0.1, 0.1], 1_000_000)
    np.testing.assert_allclose(r.exponents, [0.4192, -1.6232], atol=0.005)
    assert r.sum == pytest.approx(np.log(0.3), abs=1e-9)


def test_standard_map_is_symmetric():
    """Area-preserving: lambda1 = -lambda2."""
    r = lyapunov_spectrum_map(S.standard_map(6.0), [0.5, 0.3], 200_000)
    assert r.exponents[0] > 0.5
    assert r.exponents[0] == pytest.approx(-r.exponents[1], abs=1e-9)


@pytest.mark.parametrize("offset", [0.0, 0.5])
def test_compressor_is_conservative(offset):
    """The undamped compressor model is Lagrangian with a conservative time-dependent load: its
    two exponents sum to 0. Over 60 revolutions at rtol 1e-10 the residual (phase-volume error
    of the integration) stays below 0.5 % of lambda1 (or 1e-3 1/s)."""
    m = compressor_model(CompressorParams(theta_c_offset=offset))
    r = lyapunov_spectrum(m, m.initial_state(), 60 * m.period, rtol=1e-10, atol=1e-11)
    assert abs(r.sum) < max(1e-3, 5e-3 * abs(r.exponents[0]))
    assert r.per_period is not None


def test_ideal_mechanism_is_not_chaotic():
    """rc = 0: the clearance angle has no dynamics (theta_c'' = 0, a shear), so the finite-time
    exponents only decay like ln(T)/T -- never positive beyond that, never called chaotic."""
    from recipdyn.analysis import classify

    m = compressor_model(CompressorParams(rc=0.0))
    T = 30 * m.period
    r = lyapunov_spectrum(m, m.initial_state(), T)
    assert np.all(np.abs(r.exponents) < 2 * np.log(T) / T)
    assert classify(lambda1=r.exponents[0], lyap_tol=0.05).verdict != "chaotic"


def test_needs_jacobian():
    from recipdyn.model import ODESystem

    with pytest.raises(ValueError, match="Jacobian"):
        lyapunov_spectrum(ODESystem(rhs=S.lorenz().rhs, params=np.ones(3),
                                    state_names=("x", "y", "z")), [1, 1, 1], 1.0)  # fmt: skip
