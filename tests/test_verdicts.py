"""Answers a user acts on are right, or refused with the reason (issue 31, items 1 and 7).

Signal verdicts on systems and signals the other tests do not use: a delay system
(Mackey-Glass), a 5-site Lorenz-96 flow, the Henon map, GARCH-like and AR(1) noise, a
phase-randomised surrogate of a chaotic signal, a regular machine signal with impacts and a
ring-dominated one. The rule checked everywhere: never *chaotic* for a regular or stochastic
signal, and never an exponent with status *ok* more than 30 % from the reference. The default
run uses short records (the properties hold for refusals too); the full 20 000-sample table of
docs/signal_analysis.md is under ``slow``.
"""

import numpy as np
import pytest

from recipdyn.analysis import classify
from recipdyn.analysis.lyapunov_signal import SignalLyapunov
from recipdyn.analysis.signal import assess_signal
from recipdyn.analysis.vibration import crank_angle, tacho_times
from recipdyn.integrate import integrate
from recipdyn.model.reference import systems as S


def mackey_glass(n, tau=17.0, h=0.1, every=10, transient=5000):
    """x(t) of dx/dt = 0.2 x(t - tau) / (1 + x(t - tau)^10) - 0.1 x(t), sampled every
    ``every`` steps of a fixed-step RK4 (the delayed value at half steps: the mean of its two
    neighbours, second order like the interpolation error of the delayed term)."""
    d = int(round(tau / h))
    total = transient + n * every
    x = np.empty(total + d + 1)
    x[: d + 1] = 1.2

    def f(xt, xd):
        return 0.2 * xd / (1.0 + xd**10) - 0.1 * xt

    for i in range(d, total + d):
        a, b = x[i - d], x[i - d + 1]
        m, xi = 0.5 * (a + b), x[i]
        k1 = f(xi, a)
        k2 = f(xi + 0.5 * h * k1, m)
        k3 = f(xi + 0.5 * h * k2, m)
        k4 = f(xi + h * k3, b)
        x[i + 1] = xi + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x[d + 1 + transient :][::every][:n]


def impacts_signal(n_rev=40, fs=10_000.0, f0=12.5, ring=2000.0, tau=0.002, noise=0.001):
    """A sine at the crank frequency plus three decaying bursts a revolution at 30, 150 and
    250 deg of the crank (a valve or a knocking joint ringing a structure), and a tacho."""
    n = int(n_rev / f0 * fs)
    t = np.arange(n) / fs
    x = np.sin(2 * np.pi * f0 * t)
    for k in range(n_rev + 1):
        for ang in (30.0, 150.0, 250.0):
            t0 = (k + ang / 360.0) / f0
            m = (t >= t0) & (t < t0 + 10 * tau)
            x[m] += 2.0 * np.exp(-(t[m] - t0) / tau) * np.sin(2 * np.pi * ring * (t[m] - t0))
    x += noise * np.random.default_rng(4).standard_normal(n)
    tacho = ((f0 * t) % 1.0 < 0.02).astype(float)
    return x, tacho, fs, f0


#: Reference exponents. Henon: 0.419 per iteration (Sprott 2003, App. A). Mackey-Glass
#: (tau 17): 0.0050 per time unit, Benettin on this test's discretisation (two trajectories,
#: renormalised over the whole delay buffer, 1e5 time units; 0.0056 from the coarser step
#: tau/100 of Brown, Bryant & Abarbanel's code; Farmer 1982 gives the same order). Lorenz-96
#: with 5 sites (F = 8): Benettin on the equations (tests below recompute it).
REFERENCE = {"henon": 0.419, "mackey-glass": 0.0050, "lorenz96-5": 0.42}


def chaotic(name, n):
    if name == "henon":
        return S.iterate(S.henon(), [0.1, 0.1], n, 1000)[:, 0], 1.0
    if name == "mackey-glass":
        return mackey_glass(n), 1.0
    t = 100.0 + np.arange(n) * 0.05
    y0 = np.r_[8.01, np.full(4, 8.0)]
    sol = integrate(S.lorenz96(5), y0, (0.0, t[-1]), t_eval=t, rtol=1e-10, atol=1e-10)
    return sol.y[:, 0], 0.05


def stochastic(name, n):
    rng = np.random.default_rng(11)
    e = rng.standard_normal(n)
    x = np.empty(n)
    if name == "ar1":
        x[0] = 0.0
        for i in range(1, n):
            x[i] = 0.9 * x[i - 1] + e[i]
    elif name == "garch":  # GARCH(1, 1): volatility clusters, uncorrelated values
        s2, prev = 1.0, 0.0
        for i in range(n):
            s2 = 0.05 + 0.1 * prev**2 + 0.85 * s2
            prev = np.sqrt(s2) * e[i]
            x[i] = prev
    else:  # a phase-randomised surrogate of the Lorenz x signal: its spectrum, no dynamics
        t = 50.0 + np.arange(n) * 0.01
        lx = integrate(S.lorenz(), [1, 1, 1], (0, t[-1]), t_eval=t, rtol=1e-10, atol=1e-10).y[:, 0]
        F = np.fft.rfft(lx - lx.mean())
        phase = rng.uniform(0, 2 * np.pi, F.size)
        phase[0] = phase[-1] = 0.0
        return np.fft.irfft(np.abs(F) * np.exp(1j * phase), n=n), 0.01
    return x, 1.0


def check_never_wrong(a, reference=None, regular=False):
    """The two rules of the issue's verification on one assessment."""
    if reference is None:
        assert a.verdict.verdict != "chaotic", a.verdict.reasons
    for r in a.lyapunov.values():
        if r.status == "ok" and reference is not None:
            assert abs(r.exponent / reference - 1) < 0.30, (r.method, r.exponent, reference)
        if r.status == "ok" and reference is None and not regular:
            assert r.exponent <= 0.02 / (a.embedding.delay / a.fs), (r.method, r.exponent)


@pytest.mark.parametrize("name", ["henon", "mackey-glass", "lorenz96-5"])
def test_chaotic_signals_never_misestimated_short(name):
    """5000 samples: every estimate is refused, withheld with its reason, or within 30 % of
    the reference; a verdict is chaotic or undetermined (never regular)."""
    x, dt = chaotic(name, 5000)
    a = assess_signal(x, 1.0 / dt)
    check_never_wrong(a, REFERENCE[name])
    assert a.verdict.verdict in ("chaotic", "undetermined"), a.verdict.reasons


@pytest.mark.parametrize("name", ["ar1", "garch", "surrogate"])
def test_stochastic_signals_never_chaotic_short(name):
    x, dt = stochastic(name, 5000)
    check_never_wrong(assess_signal(x, 1.0 / dt))


@pytest.mark.slow
@pytest.mark.parametrize("name", ["henon", "mackey-glass", "lorenz96-5"])
def test_chaotic_signals_never_misestimated(name):
    x, dt = chaotic(name, 20_000)
    a = assess_signal(x, 1.0 / dt)
    check_never_wrong(a, REFERENCE[name])
    assert a.verdict.verdict in ("chaotic", "undetermined"), a.verdict.reasons


@pytest.mark.slow
@pytest.mark.parametrize("name", ["ar1", "garch", "surrogate"])
def test_stochastic_signals_never_chaotic(name):
    x, dt = stochastic(name, 20_000)
    check_never_wrong(assess_signal(x, 1.0 / dt))


def test_mackey_glass_estimators_that_disagree_are_withheld():
    """Mackey-Glass (20 000 samples; lambda1 0.0050): Wolf reads 0.0049, Rosenstein 0.0093
    and Kantz 0.0085 -- 1.9x apart, beyond the 1.67x their +-25 % accuracy allows. Before,
    all three were 'ok' and the verdict 'chaotic' with Rosenstein and Kantz 70-85 % high;
    now the three are withheld with the reason and the verdict is 'undetermined'."""
    x = mackey_glass(20_000)
    a = assess_signal(x, 1.0)
    statuses = {k: r.status for k, r in a.lyapunov.items()}
    assert "ok" not in statuses.values() or all(
        abs(r.exponent / 0.0050 - 1) < 0.3 for r in a.lyapunov.values() if r.status == "ok"
    ), statuses
    if a.verdict.verdict != "chaotic":
        assert a.verdict.verdict == "undetermined"
        assert any("withheld" in s or "disagree" in s for s in a.verdict.reasons)


@pytest.mark.parametrize("crank", ["tacho", "speed"])
def test_periodic_machine_signal_with_impacts(crank, tmp_path):
    """A sine at 12.5 Hz with three decaying 2 kHz bursts a revolution at 30, 150, 250 deg:
    'periodic, 3 impacts a revolution at 30°, 150°, 250°' with a tacho and with a constant
    speed; the peak table names crank orders (order 1 for the 12.5 Hz line; it said 0 with a
    tacho) and lists separate lines, not the comb of harmonics under the ring's hump; the
    reasons stay short."""
    import json

    import pandas as pd

    from recipdyn.analyze import analyze_signal

    x, tacho, fs, f0 = impacts_signal()
    path = tmp_path / "machine.csv"
    pd.DataFrame({"time": np.arange(x.size) / fs, "acc": x, "key": tacho}).to_csv(path,
                                                                                   index=False)  # fmt: skip
    kw = {"tacho": "key"} if crank == "tacho" else {"speed": f"{60 * f0} rpm"}
    s = analyze_signal(path, tmp_path / "an", column="acc", **kw)
    v = s["verdict"]
    assert v["verdict"] == "periodic", v["reasons"]
    assert v["headline"].startswith("periodic, 3 impacts a revolution at ")
    angles = [p["angle_deg"] for p in s["vibration"]["impacts"]["pattern"]]
    assert np.allclose(angles, [30, 150, 250], atol=3), angles
    peaks = s["spectrum"]["peaks"]
    top = min(peaks, key=lambda p: abs(p["frequency_hz"] - f0))
    assert abs(top["frequency_hz"] - f0) < 0.5 and top["crank_order"] == 1
    freqs = sorted(p["frequency_hz"] for p in peaks)
    ring = [f for f in freqs if 1500 < f < 2500]
    assert len(ring) == 1, freqs  # one hump, one line
    assert len("; ".join(v["reasons"])) < 600
    assert not any(r["status"] == "ok" and r["exponent"] > 1.0
                   for r in s["lyapunov_signal"].values())  # fmt: skip
    orders = [o["order"] for o in s["vibration"]["order_lines"]]
    assert any(abs(o - 1) < 0.05 for o in orders), orders
    assert json.loads((tmp_path / "an" / "summary.json").read_text())["verdict"]["headline"]


def ring_signal(fs=10_000.0, f0=3.2, n_rev=10, ring=1200.0, q_decay=0.01, seed=0):
    """A slow periodic motion whose every half revolution re-excites a lightly damped
    1.2 kHz ring with a slightly varying phase (as the compressor's link rings at each load
    reversal): the ring dominates the acceleration, the motion is regular."""
    rng = np.random.default_rng(seed)
    n = int(n_rev / f0 * fs)
    t = np.arange(n) / fs
    x = 0.3 * np.sin(2 * np.pi * f0 * t) + 0.1 * np.sin(4 * np.pi * f0 * t)
    for k in range(2 * n_rev + 1):
        t0 = (k / 2 + 0.05 * rng.uniform()) / f0
        m = t >= t0
        tt = t[m] - t0
        x[m] += np.exp(-tt / q_decay) * np.sin(2 * np.pi * ring * tt + rng.uniform(0, 2 * np.pi))
    return x, fs, f0


def test_classify_disagreeing_signal_estimates_are_undetermined():
    """Three usable but inconsistent estimates (the issue's rc = 2 mm numbers, withheld by
    assess_signal) give 'undetermined' with the reason, whatever the 0-1 test says."""

    def est(m, v, status="ok"):
        return SignalLyapunov(m, v, np.empty(0), np.empty(0), None, status=status,
                              reason="" if status == "ok" else "the estimators disagree")  # fmt: skip

    withheld = [est("wolf", 58.0, "inconsistent"), est("rosenstein", 313.0, "inconsistent"),
                est("kantz", 272.0, "inconsistent")]  # fmt: skip
    v = classify(k01=0.93, determinism=True, signal_lyapunov=withheld, time_scale=2e-4)
    assert v.verdict == "undetermined", v.reasons
    assert any("contradict" in r for r in v.reasons)


def test_a_section_of_too_few_points_is_left_out():
    """Nine points of a ten-revolution record, all distinct, are no period-9 orbit: the
    section is left out of the verdict with the reason (it said 'periodic')."""
    pts = np.random.default_rng(0).uniform(size=(9, 2))
    v = classify(section=pts, k01=None)
    assert v.verdict != "periodic", v.reasons
    assert v.evidence.get("section_inconclusive")
