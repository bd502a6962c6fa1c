"""Chaos estimates from signals that say when they fail (issue 12): embedding, exponents with
statuses, the FFT 0-1 test, IAAFT surrogates and the combined verdict, on systems with
published exponents that the other tests do not use, on noise and on regular signals."""

import numpy as np
import pytest

from recipdyn.analysis import lyapunov_spectrum, lyapunov_spectrum_map
from recipdyn.analysis.embedding import choose_embedding
from recipdyn.analysis.signal import assess_signal
from recipdyn.analysis.surrogates import iaaft, match_ends, surrogate_test
from recipdyn.analysis.zero_one import zero_one, zero_one_test
from recipdyn.integrate import integrate
from recipdyn.model.reference import systems as S

N = 20_000

# Published largest exponents (Sprott, Chaos and Time-Series Analysis, 2003, App. A; the
# logistic map's is ln 2 exactly). Per iteration for maps, per time unit for flows.
MAPS = {
    "logistic": (S.logistic_map, [0.3], np.log(2.0)),
    "ikeda": (S.ikeda_map, [0.1, 0.1], 0.5076),
    "lozi": (S.lozi_map, [0.1, 0.1], 0.4702),
}
FLOWS = {  # system, start, sampling step, published lambda1
    "rossler": (S.rossler, [1.0, 1.0, 1.0], 0.1, 0.0714),
    "rossler-hyper": (S.rossler_hyper, [-10.0, -6.0, 0.0, 10.0], 0.1, 0.1120),
    "ueda": (S.ueda, [2.5, 0.0], 2 * np.pi / 40, 0.1034),
}

_cache: dict = {}


def signal(name, start=0):
    """(x, dt, lambda1) of a named test signal, generated once per session; a flow's
    trajectory number ``start`` > 0 starts 1e-6 (relative and absolute) away, i.e. is another
    sample of the attractor, as another CPU's rounding gives."""
    if (name, start) in _cache:
        return _cache[name, start]
    rng = np.random.default_rng(1)
    if name in MAPS:
        make, x0, lam = MAPS[name]
        out = (S.iterate(make(), x0, N, 1000)[:, 0], 1.0, lam)
    elif name in FLOWS:
        make, y0, dt, lam = FLOWS[name]
        t = 100.0 + np.arange(N) * dt
        y0 = np.asarray(y0) * (1 + 1e-6 * start) + 1e-6 * start
        sol = integrate(make(), y0, (0.0, t[-1]), t_eval=t, rtol=1e-10, atol=1e-10)
        out = (sol.y[:, 0], dt, lam)
    elif name == "lorenz96":
        y0 = np.r_[8.01, np.full(9, 8.0)]
        t = 100.0 + np.arange(N) * 0.05
        sol = integrate(S.lorenz96(10), y0, (0.0, t[-1]), t_eval=t, rtol=1e-10, atol=1e-10)
        out = (sol.y[:, 0], 0.05, 1.178)
    elif name == "white":
        out = (rng.standard_normal(N), 1.0, 0.0)
    elif name == "ar1":
        e = rng.standard_normal(N)
        x = np.empty(N)
        x[0] = 0.0
        for i in range(1, N):
            x[i] = 0.95 * x[i - 1] + e[i]
        out = (x, 1.0, 0.0)
    else:
        t = np.arange(N)
        x = np.sin(2 * np.pi * 0.013 * t)
        if name == "quasi":
            x = x + 0.6 * np.sin(2 * np.pi * 0.013 * np.sqrt(2) * t)
        elif name == "noisy-sine":
            x = x + 0.2 * rng.standard_normal(N)
        out = (x, 1.0, 0.0)
    _cache[name, start] = out
    return out


def assessed(name, stride=1, start=0):
    key = ("assessed", name, stride, start)
    if key not in _cache:
        x, dt, _ = signal(name, start)
        _cache[key] = assess_signal(x[::stride], 1.0 / (dt * stride))
    return _cache[key]


def test_published_exponents_hold_for_the_equations():
    """The reference values the estimators are judged against, recomputed from the equations
    (QR over 2e5 iterations: standard error ~1e-3): the maps within 2 % of the published
    numbers, so the table below tests the estimators, not the references.

    The hyperchaotic Rossler flow's finite-time exponent scatters: 48 Benettin runs of 5000
    time units from starts 1e-6 apart (independent samples after the transient; another CPU's
    rounding draws one such sample) gave lambda1 = 0.101 ... 0.123, mean 0.1126, standard
    deviation 0.0038 (3.4 %). One run held to 3 % failed on a machine whose rounding drew
    0.1154. The mean of eight runs (~7 s) has sigma 0.0013: bound 0.006 (4 sigma plus the
    0.0006 by which the mean of 48 differs from the published 0.112)."""
    for make, x0, lam in MAPS.values():
        r = lyapunov_spectrum_map(make(), x0, 200_000)
        assert r.exponents[0] == pytest.approx(lam, rel=0.02)
    runs = [lyapunov_spectrum(S.rossler_hyper(), np.array([-10, -6, 0, 10]) * (1 + 1e-6 * i),
                              5000.0, t_transient=200.0).exponents for i in range(8)]  # fmt: skip
    assert np.mean([r[0] for r in runs]) == pytest.approx(0.1120, abs=0.006)
    # the second positive exponent (hyperchaos; published 0.019) converges slowly: 0.0178 ...
    # 0.0253 after 5000 time units in the 48 runs above (sigma 0.0019), 0.0206 after 20000
    assert all(0.012 < r[1] < 0.032 for r in runs)


CHAOTIC = [*MAPS, *FLOWS]


#: Trajectories per flow in the accuracy test (maps: one; their estimates scatter by < 1 %).
FLOW_SAMPLES = 6


@pytest.mark.parametrize("name", CHAOTIC)
def test_chaotic_signals_within_25_percent_or_refused(name):
    """On every trajectory: each estimate with status ok is within 25 % of the published
    lambda1 (the stated accuracy, ESTIMATE_ACCURACY); every other one is refused (NaN),
    withheld as inconsistent or unconfirmed (the number kept), with the reason; the
    surrogates show determinism and the verdict is chaotic. Where numbers are reported, the
    median of the ok estimates averaged over the trajectories is within 10 % (below).

    Measured 2026-11-25 over trajectories from starts 1e-6 apart (another CPU's rounding draws
    one such sample; 12 per flow, 8 per map), the median's relative error: Rossler -0.17
    +- 0.039 (-0.12 ... -0.27: Rosenstein and Kantz read low on this slowly rotating flow, a
    bias of the methods), Rossler hyperchaos -0.05 +- 0.03, Ueda -0.02 +- 0.06, Ikeda -0.08,
    Lozi -0.045, logistic 0.00; the worst single estimate -0.335 (Kantz, Rossler). Since issue
    44 those biased slopes are refused (their divergence curves rise by 1.2-1.7 log units,
    below MIN_DIVERGENCE_RISE) and a lone Wolf estimate is unconfirmed: on Rossler and Ueda no
    number is reported, and the verdict counts the sign (chaotic). Ok estimates on the maps
    (Rosenstein, Kantz, Wolf agreeing within 1.25x) scatter by < 1 % between trajectories;
    the mean of the medians is held to 15 %: Ikeda's is -10 % (Rosenstein and Kantz read
    10-25 % low on this map, a bias of the methods; -8 % over 8 trajectories before), the
    others within 5 %."""
    from recipdyn.analysis.lyapunov_signal import ESTIMATE_ACCURACY

    _, _, lam = signal(name)
    medians = []
    for start in range(FLOW_SAMPLES if name in FLOWS else 1):
        a = assessed(name, start=start)
        usable = [r for r in a.lyapunov.values() if r.ok]
        for r in a.lyapunov.values():
            assert (
                r.ok
                or (r.status == "refused" and r.reason and np.isnan(r.exponent))
                or (r.status in ("inconsistent", "unconfirmed") and r.reason)
            )
        vals = np.array([r.exponent for r in usable])
        assert np.all(np.abs(vals / lam - 1) <= ESTIMATE_ACCURACY), (start, vals)
        assert a.surrogates.nonlinear
        assert a.verdict.verdict == "chaotic", a.verdict.reasons
        if vals.size:
            medians.append(np.median(vals))
    if medians:
        assert np.mean(medians) == pytest.approx(lam, rel=0.15), medians


def test_high_dimensional_flow_is_refused_not_misestimated():
    """Lorenz-96 with 10 sites (lambda1 = 1.18, Kaplan-Yorke dimension ~6.5): 2e4 samples do
    not embed it, so every estimator refuses and says so (the earlier code returned +466 %
    from Rosenstein and a ValueError from Kantz); the verdict still says chaotic from the
    0-1 test and the surrogates, with the reason.

    Since issue 31 the surrogate test's rejection alone does not show determinism: GARCH
    noise rejects it too. A local predictor one delay ahead does no better on this record
    than on GARCH noise (error >= 0.8 of the spread), so with no exponent and no shown
    determinism the verdict is 'undetermined' -- never 'stochastic' for this chaotic flow,
    and never an exponent from a record that cannot embed it."""
    a = assessed("lorenz96")
    assert a.embedding.status == "not_saturated"
    for r in a.lyapunov.values():
        assert r.status == "refused" and "embedding" in r.reason
    assert a.surrogates.nonlinear and a.surrogates.statistic >= 0.8  # measured 1.00
    assert a.verdict.verdict == "undetermined", a.verdict.reasons
    assert any("determinism not shown" in s for s in a.verdict.reasons)


@pytest.mark.parametrize("name", ["white", "ar1", "noisy-sine"])
def test_noise_is_never_chaotic(name):
    """White noise, AR(1) noise (phi = 0.95) and a sine with 20 % noise: the surrogates do not
    reject linear noise, no estimator returns a positive exponent as usable, the verdict is
    'stochastic' (the 0-1 test alone says K ~ 1 for noise, which is why it is not enough)."""
    a = assessed(name)
    assert not a.surrogates.nonlinear
    assert not any(r.ok and r.exponent > 0.01 for r in a.lyapunov.values())
    assert a.verdict.verdict == "stochastic", a.verdict.reasons


@pytest.mark.parametrize("name, verdict", [("sine", "periodic"), ("quasi", "quasi-periodic")])
def test_regular_signals(name, verdict):
    """A sine and a two-tone incommensurate signal: exponents flat (|lambda1| at the level of
    the estimators' resolution, below 1e-3 per sample), K ~ 0, the right verdict."""
    a = assessed(name)
    usable = [r for r in a.lyapunov.values() if r.ok]
    assert usable and all(abs(r.exponent) < 1e-3 for r in usable)
    assert abs(a.zero_one.K) < 0.1
    assert a.verdict.verdict == verdict, a.verdict.reasons


@pytest.mark.parametrize("name", ["rossler", "ueda", "sine", "quasi", "white"])
def test_same_verdict_at_two_sampling_rates(name):
    """Half the sampling rate, same verdict (the 0-1 test thins to one sample per
    decorrelation time, the estimators work in time units)."""
    assert assessed(name).verdict.verdict == assessed(name, 2).verdict.verdict


def test_zero_one_fft_equals_the_direct_sums():
    """The O(N log N) mean-square displacement equals the textbook O(N n_cut) sums: K of the
    two agree to 1e-9 (only summation order differs)."""
    rng = np.random.default_rng(3)
    phi = np.cumsum(rng.standard_normal(3000)) * 0.01 + np.sin(0.3 * np.arange(3000))
    K, ks = zero_one_test(phi, n_c=10, return_all=True)
    cs = np.random.default_rng(0).uniform(np.pi / 5, 4 * np.pi / 5, 10)
    j = np.arange(1, phi.size + 1)
    ns = np.arange(1, phi.size // 10 + 1)
    for c, k in zip(cs, ks, strict=True):
        p, q = np.cumsum(phi * np.cos(j * c)), np.cumsum(phi * np.sin(j * c))
        M = np.array([np.mean((p[n:] - p[:-n]) ** 2 + (q[n:] - q[:-n]) ** 2) for n in ns])
        D = M - phi.mean() ** 2 * (1 - np.cos(ns * c)) / (1 - np.cos(c))
        assert k == pytest.approx(np.corrcoef(ns, D)[0, 1], abs=1e-9)


def test_zero_one_refuses_a_record_too_short_after_thinning():
    x = np.sin(0.01 * np.arange(5000))  # decorrelation ~150 samples: ~30 values left
    r = zero_one(x)
    assert r.status == "refused" and np.isnan(r.K) and "at least" in r.reason


def test_iaaft_keeps_values_and_spectrum():
    """Each surrogate is a rearrangement of the data (identical sorted values) with Fourier
    amplitudes within 2 % (relative L2) of the data's, and differs from the data."""
    x, _, _ = signal("rossler")
    x = x[:4096]
    amp = np.abs(np.fft.rfft(x))
    for s in iaaft(x, 5, seed=2):
        assert np.array_equal(np.sort(s), np.sort(x))
        assert np.linalg.norm(np.abs(np.fft.rfft(s)) - amp) / np.linalg.norm(amp) < 0.02
        assert not np.allclose(s, x)


def test_end_matching_finds_the_periodic_cut():
    """A sine of period 100 samples, started off-phase: the chosen sub-record's ends agree to
    within one sample's change in value and slope."""
    x = np.sin(2 * np.pi * (np.arange(1037) + 13) / 100.0)
    a, b = match_ends(x)
    assert abs(x[a] - x[b - 1]) < 2 * np.pi / 100 and b - a > 0.8 * x.size
    assert abs((x[a + 1] - x[a]) - (x[b - 1] - x[b - 2])) < 2e-3


def test_surrogate_test_rejects_determinism_only():
    """Henon's map is told apart from its surrogates by a wide margin (z > 10); its IAAFT
    surrogates themselves are not (a surrogate tested as data: null hypothesis true)."""
    x = S.iterate(S.henon(), [0.1, 0.1], 8000, 1000)[:, 0]
    r = surrogate_test(x, dim=2, delay=1)
    assert r.nonlinear and r.z > 10 and r.rank == 0
    s = iaaft(x, 1, seed=7)[0]
    assert not surrogate_test(s, dim=2, delay=1, seed=1).nonlinear


def test_embedding_choice():
    """Cao's E1: dimension 2 for the logistic map (delay 1: a map), 3 for Lorenz; white noise
    does not saturate up to 10 and is flagged."""
    x, _, _ = signal("logistic")
    e = choose_embedding(x)
    assert (e.delay, e.dim, e.status) == (1, 2, "ok")
    sol = integrate(S.lorenz(), [1, 1, 1], (0, 150), t_eval=50 + np.arange(10000) * 0.01,
                    rtol=1e-10, atol=1e-10)  # fmt: skip
    e = choose_embedding(sol.y[:, 0])
    assert e.dim == 3 and 8 <= e.delay <= 25 and e.status == "ok"
    e = choose_embedding(signal("white")[0])
    assert e.status == "not_saturated" and e.delay == 1


def test_noise_level_from_fourth_differences():
    """White noise of sigma 0.01 on an oversampled two-tone signal (100 samples a period): the
    estimate is within 5 % (MAD of 40 000 correlated 4th differences: ~1 % standard error);
    one impact spike per 1000 samples moves it by < 5 % (the median ignores them)."""
    from recipdyn.analysis.signal import noise_level

    rng = np.random.default_rng(5)
    t = np.arange(40_000) / 2000.0
    x = np.sin(2 * np.pi * 20 * t) + 0.3 * np.sin(2 * np.pi * 3 * t)
    noisy = x + 0.01 * rng.standard_normal(t.size)
    assert noise_level(noisy) == pytest.approx(0.01, rel=0.05)
    spiky = noisy.copy()
    spiky[::1000] += 5.0
    assert noise_level(spiky) == pytest.approx(noise_level(noisy), rel=0.05)
    assert noise_level(x) < 1e-4  # the smooth part alone: (2 pi 20 / 2000)^4 ~ 1e-5


def test_count_distinct_points_tells_a_noise_cloud_from_a_chain():
    """200 points on a circle, spaced 0.031 apart: at tolerance 0.05 they chain into one group,
    which max_extent counts as 200 points; 200 points of a Gaussian cloud (sigma 0.01) stay one
    point at tolerance 0.04 and extent 0.12 (their span is ~6.5 sigma = 0.065)."""
    from recipdyn.analysis.poincare import count_distinct_points

    a = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    ring = np.c_[np.cos(a), np.sin(a)]
    one = np.ones(2)
    assert count_distinct_points(ring, rtol=0.05, scale=one) == 1
    assert count_distinct_points(ring, rtol=0.05, scale=one, max_extent=0.15) == 200
    cloud = 0.5 + 0.01 * np.random.default_rng(1).standard_normal((200, 2))
    assert count_distinct_points(cloud, rtol=0.04, scale=one, max_extent=0.12) == 1


@pytest.mark.parametrize("noise", [0.003, 0.01])
def test_noisy_periodic_machine_signal_is_periodic(noise):
    """A periodic signal once per revolution (orders 1 and 3, crank angle known) with
    measurement noise of 0.3 % and 1 % of its amplitude: the section tolerance follows the
    noise estimate, the section is one point, the verdict periodic. With the fixed tolerance of
    1e-3 the same signals gave 70 and 98 distinct points and the verdicts 'undetermined' and
    'quasi-periodic'. A quasi-periodic signal with the same noise stays many points and is not
    called periodic."""
    fs, n = 2000.0, 40_000
    t = np.arange(n) / fs
    revs = 5.0 * t
    rng = np.random.default_rng(0)
    x = np.sin(2 * np.pi * revs) + 0.4 * np.sin(6 * np.pi * revs + 0.3)
    a = assess_signal(x + noise * rng.standard_normal(n), fs, revs=revs)
    assert a.verdict.evidence["section_distinct"] == 1
    assert a.verdict.verdict == "periodic", a.verdict.reasons
    assert a.verdict.evidence["section_tolerance"] == pytest.approx(4 * noise / np.ptp(x),
                                                                    rel=0.1)  # fmt: skip
    q = np.sin(2 * np.pi * revs) + 0.5 * np.sin(2 * np.pi * np.sqrt(2) * revs)
    b = assess_signal(q + noise * rng.standard_normal(n), fs, revs=revs)
    assert b.verdict.evidence["section_distinct"] > 16
    assert b.verdict.verdict != "periodic"


def test_section_blurred_by_noise_is_left_out():
    """Noise of 5 % of the amplitude blurs the once-per-revolution points by 4 sigma = 6.7 % of
    the signal's range (3): beyond 5 % the section resolves nothing and is left out of the
    verdict, with a note (it would otherwise count one point for any motion)."""
    fs, n = 2000.0, 40_000
    t = np.arange(n) / fs
    revs = 5.0 * t
    q = np.sin(2 * np.pi * revs) + 0.5 * np.sin(2 * np.pi * np.sqrt(2) * revs)
    a = assess_signal(q + 0.05 * np.random.default_rng(2).standard_normal(n), fs, revs=revs)
    assert "section_distinct" not in a.verdict.evidence
    assert any("section left out" in note for note in a.notes)
    assert a.verdict.verdict != "periodic"


def test_a_few_point_section_outweighs_the_zero_one_test_when_no_exponent_is_estimated():
    """The once-per-revolution section of a noisy periodic signal is one cloud; the 0-1 test
    on it measures the noise (K ~ 1). With every exponent estimate refused and the signal
    deterministic, this was called 'chaotic' (seen on a 20 million-sample record, 12 Hz
    orders 1 and 2 with 1.7 % noise); a section of few points decides: 'periodic', with K
    explained. Without the section, the same evidence stays 'chaotic'."""
    from recipdyn.analysis.classify import classify
    from recipdyn.analysis.lyapunov_signal import SignalLyapunov

    refused = [SignalLyapunov(m, np.nan, np.empty(0), np.empty(0), None, status="refused",
                              reason="no scaling region")
               for m in ("wolf", "rosenstein")]  # fmt: skip
    cloud = np.array([0.0, 1.0]) + 0.02 * np.random.default_rng(0).standard_normal((600, 2))
    kw = dict(k01=0.99, determinism=True, signal_lyapunov=refused)
    v = classify(section=cloud, section_rtol=0.04, section_extent=0.12, section_scale=2.0, **kw)
    assert v.verdict == "periodic", v.reasons
    assert any("sees the noise" in r for r in v.reasons)
    assert classify(**kw).verdict == "chaotic"


def test_a_short_record_of_a_slow_signal_is_embedded_as_far_as_it_goes():
    """A record shorter than Cao's test up to d = 10 needs at its delay ((10 + 1) tau + 2
    samples: 552 for 500 samples of a slow two-tone signal, whose delay is 50) is tested up to
    the dimension it embeds, and assessed (it raised a ValueError from inside Cao's test); at a
    delay where it embeds fewer than 4 dimensions the embedding is "too_short" with its reason,
    and the estimators then refuse."""
    rng = np.random.default_rng(1)
    t = np.arange(500)
    x = (np.sin(2 * np.pi * t / 800) + 0.3 * np.sin(2 * np.pi * t / 258)
         + 1e-3 * rng.standard_normal(t.size))  # fmt: skip
    emb = choose_embedding(x)
    fits = (x.size - 2) // emb.delay - 1
    assert (10 + 1) * emb.delay + 2 > x.size  # (the case: too short for d = 10)
    assert emb.status in ("ok", "not_saturated") and emb.e1.size == fits
    assessed = assess_signal(x, 1000.0)  # two tones, 1e-3 noise: never chaotic
    assert assessed.embedding.delay == emb.delay and assessed.embedding.status == emb.status
    assert assessed.verdict.verdict != "chaotic"
    short = choose_embedding(x, delay=200)  # 500 samples embed d = 1 at delay 200
    assert short.status == "too_short" and "embed up to d = 1" in short.reason
