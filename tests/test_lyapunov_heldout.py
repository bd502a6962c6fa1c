"""An exponent with status ok is right, on systems never used to choose a threshold (issue 44,
item 8).

The withholding rules of the signal estimators (Wolf, Rosenstein, Kantz) were calibrated on
the calibration set of ``benchmarks/bench_lyap_calibration.py`` (docs/signal_analysis.md,
"Calibration study"); the study's held-out set verifies them. This is its reduced version
for CI: three held-out cases at 5000 samples -- a flow (Chen), the delay equation (Ikeda) and
a noise signal (AR(2) narrow-band noise) -- each generated here by code independent of the
study's (SciPy's DOP853, a plain RK4 method of steps). The rule checked: every estimate with
status ok is within the stated accuracy (``ESTIMATE_ACCURACY``, 25 %) of the equations'
largest exponent, or, for noise, is not positive; a chaotic system is never called regular
or stochastic, noise never chaotic.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from recipdyn.analysis.lyapunov_signal import ESTIMATE_ACCURACY
from recipdyn.analysis.signal import assess_signal
from recipdyn.defaults import LYAP_TOL

N = 5000

#: The equations' largest exponents (benchmarks/bench_lyap_calibration.py, docs table):
#: Chen (a, b, c) = (35, 3, 28), Benettin 4 x 5000 time units: 2.028 +- 0.006 (the
#: spread of the four); the Ikeda delay equation x' = -x + 5 sin x(t - 2), the tangent of its
#: method-of-steps discretisation (h = 0.02; 0.01 agrees) over 4 x 1e5 time units: 0.2018 +-
#: 0.0019. Both spreads are below 1 % of the 25 % the estimates are held to.
TRUTH = {"chen": 2.028, "ikeda-delay": 0.2018}


def chen(noise, seed=0):
    """x of the Chen flow, 5000 samples every 0.0098 (50 a mean period of 0.488), after 50
    time units from (-10, 0, 37); white observation noise of ``noise`` times its spread."""

    def f(t, y):
        return [35 * (y[1] - y[0]), -7 * y[0] - y[0] * y[2] + 28 * y[1], y[0] * y[1] - 3 * y[2]]

    t = 50 + np.arange(N) * 0.0098
    x = solve_ivp(f, (0, t[-1]), [-10.0, 0.0, 37.0], method="DOP853", t_eval=t, rtol=1e-9,
                  atol=1e-9).y[0]  # fmt: skip
    rng = np.random.default_rng(seed)
    return x + noise * x.std() * rng.standard_normal(N), 1 / 0.0098


def ikeda_delay(h=0.02, every=8, transient=500.0):
    """x' = -x + 5 sin x(t - 2) by RK4 with step h (the delayed value at half steps by linear
    interpolation), history 0.5, sampled every 8 steps (0.16: 50 a mean period of 8.1)."""
    d = int(round(2.0 / h))
    n_tr = int(round(transient / h))
    total = n_tr + N * every
    x = np.empty(total + d + 1)
    x[: d + 1] = 0.5

    def f(xt, xd):
        return -xt + 5.0 * np.sin(xd)

    for i in range(d, total + d):
        a, b = x[i - d], x[i - d + 1]
        m, xi = 0.5 * (a + b), x[i]
        k1 = f(xi, a)
        k2 = f(xi + 0.5 * h * k1, m)
        k3 = f(xi + 0.5 * h * k2, m)
        k4 = f(xi + h * k3, b)
        x[i + 1] = xi + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x[d + 1 + n_tr :: every][:N], 1 / (h * every)


def ar2(seed=5):
    """AR(2) with poles 0.98 exp(+-2 pi i 0.02): noise with a narrow spectral line."""
    rng = np.random.default_rng(seed)
    e = rng.standard_normal(N + 500)
    x = np.zeros(N + 500)
    c1, c2 = 2 * 0.98 * np.cos(2 * np.pi * 0.02), -(0.98**2)
    for i in range(2, N + 500):
        x[i] = c1 * x[i - 1] + c2 * x[i - 2] + e[i]
    return x[500:], 1.0


def check(a, truth):
    """Every ok estimate right within ESTIMATE_ACCURACY (chaotic) or not positive (noise)."""
    for r in a.lyapunov.values():
        if r.status != "ok":
            assert r.status in ("flat", "refused", "inconsistent") and (r.reason or r.ok)
            continue
        if truth is None:
            assert r.exponent <= LYAP_TOL / (a.embedding.delay / a.fs), (r.method, r.exponent)
        else:
            assert abs(r.exponent / truth - 1) <= ESTIMATE_ACCURACY, (r.method, r.exponent)


@pytest.mark.parametrize("case", ["chen", "chen-noisy", "ikeda-delay", "ar2"])
def test_ok_estimates_are_right_on_held_out_systems(case):
    """Before the recalibration (issue 44) the Chen flow with 10 % observation noise gave
    Rosenstein 1.25 (-38 %) with status ok; its divergence curve rises by less than
    MIN_DIVERGENCE_RISE and it is now refused with the reason."""
    if case.startswith("chen"):
        x, fs = chen(0.1 if case == "chen-noisy" else 0.0)
        truth = TRUTH["chen"]
    elif case == "ikeda-delay":
        x, fs = ikeda_delay()
        truth = TRUTH[case]
    else:
        x, fs = ar2()
        truth = None
    a = assess_signal(x, fs)
    check(a, truth)
    if truth is None:
        assert a.verdict.verdict != "chaotic", a.verdict.reasons
    else:
        assert a.verdict.verdict in ("chaotic", "undetermined"), a.verdict.reasons
