"""Out-of-domain detection (recipdyn.diagnosis.domain) and the physics consistency check
(recipdyn.diagnosis.consistency) against cases whose answers are known in closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from recipdyn.diagnosis.consistency import BINS, CURVES, _Library, revolution_spread
from recipdyn.diagnosis.domain import DETECTORS, Domain, fit_domain

# ---- out of domain ----------------------------------------------------------------------


def _domain(method, rng, n_fit=400, n_cal=500, dim=6):
    """A detector fitted on ``n_fit`` standard normal rows (two classes, their means 4 apart
    in the first feature), calibrated on ``n_cal`` more of the same, on two channel sets
    (``all``: every column; ``two``: the first two)."""
    lab = np.where(rng.random(n_fit) < 0.5, "a", "b")
    Z = rng.standard_normal((n_fit, dim))
    Z[:, 0] += np.where(lab == "a", -2.0, 2.0)
    labc = np.where(rng.random(n_cal) < 0.5, "a", "b")
    Zc = rng.standard_normal((n_cal, dim))
    Zc[:, 0] += np.where(labc == "a", -2.0, 2.0)
    subsets = {"all": np.arange(dim), "two": np.arange(2)}
    st = fit_domain(Z, lab, subsets, [(Zc, labc, "all"), (Zc, labc, "two")],
                    fit_rows=np.ones(n_fit, bool), method=method, alpha=0.05)  # fmt: skip
    return Domain(st, Z, lab), st, Z, lab


@pytest.mark.parametrize("method", DETECTORS)
def test_in_domain_records_are_refused_at_the_stated_rate(method):
    """Conformal novelty p-values: a new record of the calibration records' distribution has
    P(p <= alpha) <= alpha, whatever the score. For one calibration set the realised rate
    scatters around alpha by the Beta spread of its order statistic, sqrt(a(1-a)/n_cal),
    and the test rows' binomial spread sqrt(a(1-a)/n_test); the bound allows 3 of each. A
    score that is not exchangeable between the calibration and the test rows (a detector
    fitted on the calibration rows, a p-value counting the wrong tail) fails it."""
    rng = np.random.default_rng(1)
    dom, *_ = _domain(method, rng)
    n = 2000
    lab = np.where(rng.random(n) < 0.5, "a", "b")
    Z = rng.standard_normal((n, 6))
    Z[:, 0] += np.where(lab == "a", -2.0, 2.0)
    a = 0.05
    bound = a + 3 * math.sqrt(a * (1 - a) / 500) + 3 * math.sqrt(a * (1 - a) / n)
    for subset in ("all", "two"):
        p = dom.p_value(Z, subset, lab)
        rate = float(np.mean(p < a))
        assert rate <= bound, (subset, rate)
        assert rate >= a - (bound - a)  # and not a detector that never refuses
        assert p.min() >= dom.resolution(subset) - 1e-12


@pytest.mark.parametrize("method", DETECTORS)
def test_records_far_from_the_training_records_are_refused(method):
    """Rows 8 standard deviations out in two features are scored above every calibration row
    by each detector: p-value 1/(n_cal + 1), refused (the isolation forest's score saturates
    at its trees' depth, so a far row may tie with the most isolated calibration row)."""
    rng = np.random.default_rng(2)
    dom, *_ = _domain(method, rng)
    Z = rng.standard_normal((50, 6))
    Z[:, 2:4] += 8.0
    lab = np.full(50, "a")
    p = dom.p_value(Z, "all", lab)
    assert np.all(p < 0.05)
    res = dom.resolution("all")
    if method == "iforest":  # ties with the one or two most isolated calibration rows
        assert np.all(p <= 3 * res + 1e-12)
    else:
        assert np.allclose(p, res)


def _crossed(rng, n):
    """Two classes on crossed lines, x1 = x0 (a) and x1 = -x0 (b), x0 standard normal, with
    0.1 of scatter: each feature's distribution is the same for both (the rank transform
    leaves them apart)."""
    lab = np.where(rng.random(n) < 0.5, "a", "b")
    x0 = rng.standard_normal(n)
    Z = np.column_stack([x0, np.where(lab == "a", x0, -x0), rng.standard_normal((n, 2))])
    Z[:, :2] += 0.1 * rng.standard_normal((n, 2))
    return Z, lab


def test_the_class_score_refuses_a_record_given_the_wrong_class():
    """Records on class b's line, given class a: among the training records as a whole (the
    plain kNN score keeps them) but ~1.5 from every record of class a where a record of a
    lies within ~0.1 of its line (the class score refuses them); given b, kept."""
    rng = np.random.default_rng(3)
    Z, lab = _crossed(rng, 600)
    Zc, labc = _crossed(rng, 500)
    subsets = {"all": np.arange(4)}
    out = {}
    for method in ("knn", "class"):
        st = fit_domain(Z, lab, subsets, [(Zc, labc, "all")], fit_rows=np.ones(600, bool),
                        method=method, alpha=0.05)  # fmt: skip
        out[method] = Domain(st, Z, lab)
    x0 = rng.uniform(1.0, 2.0, 40)
    R = np.column_stack([x0, -x0, rng.standard_normal((40, 2))])
    a, b = np.full(40, "a"), np.full(40, "b")
    assert np.mean(out["knn"].p_value(R, "all", a) < 0.05) < 0.2
    assert np.mean(out["class"].p_value(R, "all", a) < 0.05) > 0.9
    assert np.mean(out["class"].p_value(R, "all", b) < 0.05) < 0.2


def test_each_channel_set_is_compared_with_its_own_held_out_records():
    """Mondrian p-values: the calibration scores of one channel set do not enter another's.
    Made visible by scaling one set's stored calibration scores: its p-values change, the
    other set's stay to the bit."""
    rng = np.random.default_rng(5)
    dom, st, Zfit, labfit = _domain("knn", rng)
    Z = rng.standard_normal((30, 6))
    lab = np.full(30, "a")
    before = {k: dom.p_value(Z, k, lab) for k in ("all", "two")}
    two = st["cal_bins"] == "two"
    st2 = dict(st, cal_scores=np.where(two, 10 * st["cal_scores"], st["cal_scores"]))
    again = Domain(st2, Zfit, labfit)
    assert np.array_equal(again.p_value(Z, "all", lab), before["all"])
    assert not np.array_equal(again.p_value(Z, "two", lab), before["two"])


# ---- physics consistency ----------------------------------------------------------------


def _record(rng, n_revs, fs=3600.0, f_rev=10.0, noise=0.01, acc_noise=0.3):
    """``n_revs`` revolutions: a pressure with one smooth shape each revolution plus white
    noise of ``noise`` (range 1), and an acceleration of white noise with a 1 kHz burst in
    the 90-100 degree bin of each revolution."""
    n = int(n_revs * fs / f_rev)
    t = (np.arange(n) + 0.5) / fs  # half a sample off the bins' edges: m samples in each
    revs = t * f_rev
    th = 2 * np.pi * np.mod(revs, 1.0)
    p = 0.5 + 0.5 * np.cos(th) + noise * rng.standard_normal(n)
    a = acc_noise * rng.standard_normal(n)
    burst = (np.mod(revs, 1.0) >= 0.25) & (np.mod(revs, 1.0) < 0.25 + 1 / 36)
    a[burst] += 3.0 * np.sin(2 * np.pi * 1000.0 * t[burst])
    return a, fs, revs, p


def test_the_revolution_spread_is_the_standard_error_of_the_mean_curve():
    """White noise of sd s on a pressure of range 1, m samples a 10-degree bin: each
    revolution's bin mean scatters by s/sqrt(m), the mean of n revolutions by
    s/sqrt(m n). The estimate pools 36 bins of n - 1 degrees of freedom each: its RMS over
    the bins is within 3 sqrt(1/(2 * 36 (n - 1))) of the truth (relative)."""
    rng = np.random.default_rng(6)
    n_revs, fs, f_rev, s = 8, 3600.0, 10.0, 0.01
    a, fs, revs, p = _record(rng, n_revs, fs, f_rev, noise=s)
    sp = revolution_spread(a, fs, revs, p_head=p)
    m = fs / f_rev / BINS
    truth = s / math.sqrt(m * n_revs)  # the shape is normalised by a range of 0.996
    rms = float(np.sqrt(np.mean(sp["ph_"] ** 2)))
    assert rms == pytest.approx(truth, rel=3 * math.sqrt(1 / (2 * 36 * (n_revs - 1))))
    assert set(sp) == {"ang_", "ph_"}
    assert sp["ang_"].shape == (BINS,)
    # the burst's bin spreads most in the envelope (its energy varies with the noise)
    assert int(np.argmax(sp["ang_"])) == 9


def _linear_library(rng, n=60, slope=0.02):
    """Library curves that are exactly linear in the operating point and the severity."""
    U = np.column_stack([rng.uniform(2.5, 4, n), rng.uniform(0.9e5, 1.1e5, n),
                         rng.uniform(2.7e5, 3.3e5, n)])  # fmt: skip
    sev = rng.uniform(0, 1, n)
    base = np.linspace(0, 1, 3 * BINS)
    Y = base + slope * np.outer((U[:, 0] - 3) + (U[:, 1] - 1e5) / 1e4 + 2 * sev, np.ones(base.size))
    Y[:, 5] += 0.3 * sev  # a bin that the severity moves most
    return _Library(Y, U, sev, True), U, sev, Y


def test_the_best_fit_reproduces_a_linear_library_and_finds_its_severity():
    """A local linear fit is exact on curves linear in the operating point and the
    severity: the prediction at a library record's own point equals its curve to rounding,
    and the severity search finds a record's severity to the grid's step (1/20)."""
    rng = np.random.default_rng(7)
    lib, U, sev, Y = _linear_library(rng)
    i = 11
    f = lib.predict(U[i], sev[i], exclude=i)
    assert np.allclose(f, Y[i], atol=1e-9)
    sigma = np.full(Y.shape[1], 1e-3)
    _, s_fit = lib.best(U[i], Y[i], sigma)
    assert abs(s_fit - sev[i]) <= 0.5 / 20 + 1e-12


def test_a_bin_off_by_k_standard_deviations_is_named_with_k():
    """The consistency statistic of a record equal to the best fit but for one bin moved by
    k sigma is k, and the refusal names that bin's curve and crank angles."""
    from recipdyn.diagnosis.consistency import Consistency

    rng = np.random.default_rng(8)
    lib, U, sev, Y = _linear_library(rng)
    names = ([f"ang_{i * 10:03d}" for i in range(BINS)] + [f"ph_{i * 10:03d}" for i in range(BINS)]
             + [f"pc_{i * 10:03d}" for i in range(BINS)]
             + ["speed_hz", "cy_p_suction", "cy_p_discharge"])  # fmt: skip
    X = np.column_stack([Y, U])
    labels = np.full(X.shape[0], "leak")
    sigma = 0.01
    state = {"fit_rows": np.ones(X.shape[0], bool),
             "sigma_model": {"full": {"leak": np.full(3 * BINS, sigma)}, "no_pressure": {}},
             "cal_statistic": np.arange(1.0, 100.0), "cal_bins": np.full(99, "full")}  # fmt: skip
    c = Consistency(state, X, np.zeros(X.shape[1]), np.ones(X.shape[1]), names, labels, sev)
    u, s = np.array([3.1, 1.02e5, 2.9e5]), 0.45
    row = np.concatenate([lib.predict(u, s), u])
    k, j = 7.0, BINS + 14  # the head-end pressure shape's 140-150 degree bin
    row[j] += k * sigma
    r = c.check(row, {}, "leak", "full", severity=s)
    assert r["statistic"] == pytest.approx(k, rel=1e-6)
    assert r["worst"]["curve"] == CURVES["ph_"]
    assert r["worst"]["angle_deg"] == (140, 150)
    assert r["fit"]["severity"] == pytest.approx(s)
    # conformal p-value among the 99 calibration statistics 1..99: (1 + #{>= 7}) / 100
    assert r["p_value"] == pytest.approx((1 + 93) / 100)
    row[j] += 200 * sigma  # far beyond every calibration statistic
    assert c.check(row, {}, "leak", "full", severity=s)["p_value"] == pytest.approx(1 / 100)
