"""The measurement chain's errors estimated from the record itself (recipdyn.diagnosis.correction).

Each estimate is checked against a chain error the test imposes: on closed-form records
(the ideal polytropic cycle of `recipdyn.model.cycle` sampled at a known crank angle, with a
known mark, offset, gain and noise; an impact train through a second-order mount of known
frequency and damping) and on simulated records of the diagnosis model with the chain
changed one thing at a time. Coverage: the reported 95 % half-widths must hold the truth;
over a handful of cases at most one miss is allowed (a binomial bound: two or more misses
among six cases of 95 % intervals happen with probability 3 %), and no case may miss by more
than twice its half-width.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from recipdyn.diagnosis.correction import (
    ChainReference,
    chamber_volume,
    correct_chain,
    known_chain,
    pressure_phase,
    reference_from,
    resonance,
    tacho_revolutions,
)


def _covered(cases):
    """``cases``: (estimate, truth, half-width). At most one outside its half-width, none
    outside twice it."""
    misses = [abs(e - t) / u for e, t, u in cases if abs(e - t) > u]
    assert len(misses) <= 1 and all(m <= 2 for m in misses), cases


def _ideal_record(mark_deg=0.0, offsets=(0.0, 0.0), gains=(1.0, 1.0), noise_pa=150.0,
                  revolutions=6, fs=10_000.0, f_rev=3.2, seed=0, n_exp=1.3):  # fmt: skip
    """Head- and crank-end pressures of the ideal-valve cycle (closed form, `cycle_states`)
    at the crank angle of a tacho whose mark sits at ``mark_deg``; the crank angle after
    the mark (revolutions) at each sample."""
    from recipdyn.model.cycle import cycle_data, cycle_states
    from recipdyn.model.registry import get_model

    v = dict(get_model("compressor-contact-valves").parameters({}))
    v["n_expansion"] = n_exp
    c = cycle_data(v)
    n = int(revolutions * fs / f_rev)
    revs = np.arange(n) * f_rev / fs
    theta = 2 * np.pi * revs + math.radians(mark_deg)
    st = cycle_states(theta, c)
    rng = np.random.default_rng(seed)
    ph = gains[0] * st["p_head"] + offsets[0] + noise_pa * rng.standard_normal(n)
    pc = gains[1] * st["p_crank"] + offsets[1] + noise_pa * rng.standard_normal(n)
    return revs, ph, pc


def test_the_volume_is_the_cycles_own():
    """`chamber_volume` is the cycle model's volume (`cycle_states`) at the same crank angle:
    the estimators read the polytropes against the kinematics the model integrates."""
    from recipdyn.model.cycle import cycle_data, cycle_states
    from recipdyn.model.registry import get_model

    c = cycle_data(get_model("compressor-contact-valves").parameters({}))
    th = np.linspace(0, 2 * np.pi, 73)
    st = cycle_states(th, c)
    assert chamber_volume(th, "head") == pytest.approx(st["V_head"], rel=1e-12)
    assert chamber_volume(th, "crank") == pytest.approx(st["V_crank"], rel=1e-12)


@pytest.mark.parametrize("mark_deg", [-3.0, 0.0, 0.3, 2.0, 40.0])
def test_the_polytropes_give_the_mark_and_the_offset(mark_deg):
    """The ideal cycle (polytropes at n = 1.3, no valve dynamics) with a mark, offsets and
    150 Pa of noise: each chamber returns the mark's crank angle and its offset within the
    fit's 95 % interval (twice its standard error: the closed form has no other error), and
    the exponent 1.3 of the model (its noise-limited error, ~1e-3)."""
    offsets = (5000.0, -3000.0)
    revs, ph, pc = _ideal_record(mark_deg, offsets)
    cases = []
    for ch, p, o in (("head", ph, offsets[0]), ("crank", pc, offsets[1])):
        r = pressure_phase(p, revs, ch)
        assert r["ok"]
        cases.append((r["phase_deg"], mark_deg, 2 * r["phase_sd"]))
        cases.append((r["offset_pa"], o, 2 * r["offset_sd"]))
        assert r["n_compression"] == pytest.approx(1.3, abs=5e-3)
        assert r["n_expansion"] == pytest.approx(1.3, abs=5e-3)
    _covered(cases)


def test_chain_errors_move_the_estimates_and_leave_the_exponents():
    """Equivariance, the property the correction rests on: a mark moves the phase by itself,
    an offset the offset by itself, a gain neither; the fitted exponents (the reference's
    coordinates) move by none of them (to 1e-3 of the noise-free fit)."""
    base = [pressure_phase(p, r, "head") for r, p, _ in [_ideal_record(noise_pa=0.0)]][0]
    revs, ph, _ = _ideal_record(1.5, (2000.0, 0.0), (1.02, 1.0), noise_pa=0.0)
    moved = pressure_phase(ph, revs, "head")
    assert moved["phase_deg"] - base["phase_deg"] == pytest.approx(1.5, abs=2e-3)
    assert moved["offset_pa"] - base["offset_pa"] == pytest.approx(2000.0, abs=5.0)
    for k in ("n_compression", "n_expansion"):
        assert moved[k] == pytest.approx(base[k], abs=1e-3)


def test_the_tacho_fit_averages_the_jitter():
    """Pulses jittered by 0.25 degree (RMS) at a constant speed: the fitted angle's error is
    well below the jitter (a parabola through 20 pulses leaves sqrt(3/20) of it, 0.1 deg;
    bound 0.15), and the jitter's estimate holds 0.25 within its interval."""
    rng = np.random.default_rng(3)
    f, fs, n_pulses = 3.0, 10_000.0, 20
    true_edges = np.arange(n_pulses) / f
    edges = true_edges + rng.normal(0, 0.25 / 360 / f, n_pulses)
    n = int((n_pulses - 1) / f * fs)
    revs, jitter = tacho_revolutions(edges, n, fs)
    t = np.arange(n) / fs
    ok = np.isfinite(revs)
    err_deg = (revs[ok] - (t[ok] - edges[0]) * f) * 360
    assert np.sqrt(np.mean((err_deg - np.mean(err_deg)) ** 2)) < 0.15
    assert abs(jitter.value - 0.25) <= jitter.uncertainty
    assert jitter.status == "corrected"


def _impacts(fn, zeta, fs, seconds=3.0, snr_db=25.0, seed=0):
    """An impact train (Poisson, lognormal sizes) through the analog mount
    ``wn^2 / (s^2 + 2 zeta wn s + wn^2)``, applied exactly in the frequency domain, and a
    4th-order Butterworth anti-alias magnitude at 0.4 fs; white noise at ``snr_db``."""
    rng = np.random.default_rng(seed)
    n = int(seconds * fs)
    x = np.zeros(n)
    k = rng.integers(0, n, int(30 * seconds))
    x[k] = rng.lognormal(0, 1, k.size)
    f = np.fft.rfftfreq(n, 1 / fs)
    h = fn**2 / (fn**2 - f**2 + 2j * zeta * fn * f)
    lp = 1 / np.sqrt(1 + (f / (0.4 * fs)) ** 8)
    y = np.fft.irfft(np.fft.rfft(x) * h * lp, n)
    return y + np.sqrt(np.mean(y**2)) * 10 ** (-snr_db / 20) * rng.standard_normal(n)


def test_the_mounting_resonance_is_read_from_the_impacts():
    """Frequency and damping of the mount behind the impacts, 2-10 kHz at damping 0.02-0.2
    (25 kHz sampling) and the data set's band (3-4.5 kHz at 11 kHz), within their 95 %
    half-widths."""
    cases = []
    grid = [
        (25_000.0, 2000.0, 0.02, 1),
        (25_000.0, 10_000.0, 0.2, 2),
        (25_000.0, 5000.0, 0.1, 3),
        (11_000.0, 3000.0, 0.05, 4),
        (11_000.0, 4500.0, 0.12, 5),
        (11_000.0, 3800.0, 0.2, 6),
    ]
    for fs, fn, zeta, seed in grid:
        r = resonance(_impacts(fn, zeta, fs, seed=seed), fs)
        cases.append((r["resonance_hz"].value, fn, r["resonance_hz"].uncertainty))
        cases.append((r["damping"].value, zeta, r["damping"].uncertainty))
    _covered(cases)


def _reference(n=24):
    """A reference from ideal-cycle records of exactly the diagnoser's frame (mark 0, no
    offset) at six 'conditions' of different noise: its bias is that of the estimator on
    the closed form, ~0."""
    fits = []
    for i in range(n):
        revs, ph, pc = _ideal_record(noise_pa=150.0, revolutions=2, seed=100 + i)
        fits.append({"condition": i % 6, "head": pressure_phase(ph, revs, "head"),
                     "crank": pressure_phase(pc, revs, "crank")})  # fmt: skip
    return reference_from(fits, source="test")


@pytest.fixture(scope="module")
def reference():
    return _reference()


def test_correct_chain_removes_a_mark_offsets_and_a_gain(reference):
    """A mark 1.2 deg off, offsets +5 / -3 kPa and the crank end's gain 1 % low: each is
    recovered within its interval and corrected; the corrected record's pressures equal the
    true ones to the noise (150 Pa) plus the corrections' own errors."""
    revs, ph, pc = _ideal_record(1.2, (5000.0, -3000.0), (1.0, 0.99), seed=7)
    fix = correct_chain(revs, p_head=ph, p_crank=pc, reference=reference)
    assert not fix.refused, fix.refused
    e = fix.estimates
    _covered(
        [
            (e["phase"].value, 1.2, e["phase"].uncertainty),
            (e["offset_head"].value, 5000.0, e["offset_head"].uncertainty),
            (e["offset_crank"].value, -3000.0, e["offset_crank"].uncertainty),
            (e["gain_ratio"].value, 1 / 0.99 - 1, e["gain_ratio"].uncertainty),
        ]
    )
    assert e["phase"].status == e["offset_head"].status == "corrected"
    clean_revs, clean_h, clean_c = _ideal_record(noise_pa=0.0)
    # the corrected record against the clean one at the same corrected crank angles
    from recipdyn.model.cycle import cycle_data, cycle_states
    from recipdyn.model.registry import get_model

    st = cycle_states(2 * np.pi * fix.revs, cycle_data(get_model(
        "compressor-contact-valves").parameters({})))  # fmt: skip
    for q, true in ((fix.p_head, st["p_head"]), (fix.p_crank, st["p_crank"])):
        closed = np.abs(np.gradient(true)) < 50  # away from the valve events' steps
        assert np.sqrt(np.mean((q - true)[closed] ** 2)) < 600


def test_a_clean_record_is_left_as_it_is(reference):
    """No chain error: nothing is corrected (each estimate lies within its interval of 0)."""
    revs, ph, pc = _ideal_record(seed=11)
    fix = correct_chain(revs, p_head=ph, p_crank=pc, reference=reference)
    assert not fix.refused
    assert all(
        e.status in ("within its uncertainty: left", "consistent", "measured")
        for e in fix.estimates.values()
    ), {k: (e.value, e.status) for k, e in fix.estimates.items()}
    assert fix.p_head is ph and fix.p_crank is pc and fix.revs is revs


def test_chambers_that_disagree_are_refused_naming_both(reference):
    """The head-end pressure 30 samples (3 deg of crank) later than the crank end's: one
    crank angle cannot hold both; refused, naming the two channels."""
    revs, ph, pc = _ideal_record(seed=12)
    ph = np.concatenate([np.full(30, ph[0]), ph[:-30]])
    fix = correct_chain(revs, p_head=ph, p_crank=pc, reference=reference)
    assert fix.refused.startswith("p_head and p_crank") and "apart" in fix.refused


def test_a_channel_that_is_no_chamber_pressure_is_refused(reference):
    """A sine in Pa is no compressor chamber: no polytropes found, refused naming p_crank."""
    revs, ph, _ = _ideal_record(seed=13)
    pc = 2e5 + 1e5 * np.sin(2 * np.pi * revs)
    fix = correct_chain(revs, p_head=ph, p_crank=pc, reference=reference)
    assert fix.refused.startswith("p_crank:")


def test_exponents_unlike_the_references_are_refused(reference):
    """A chamber re-expanding at n = 1.05 (another gas or machine): its phase and offset
    cannot be referred to the diagnoser's chain; refused, naming the chamber."""
    revs, ph, pc = _ideal_record(seed=14, n_exp=1.05)
    fix = correct_chain(revs, p_head=ph, p_crank=pc, reference=reference)
    assert fix.refused.startswith("p_head:") and "exponents" in fix.refused


def test_without_a_reference_nothing_is_corrected():
    revs, ph, pc = _ideal_record(1.0, (3000.0, 3000.0), seed=15)
    fix = correct_chain(revs, p_head=ph, p_crank=pc, reference=None)
    assert not fix.refused and fix.p_head is ph and fix.revs is revs
    assert fix.estimates["phase_head"].value == pytest.approx(1.0, abs=0.1)


def test_a_reference_round_trips_and_reads_its_own_records(reference):
    d = reference.to_dict()
    again = ChainReference.from_dict(d)
    assert again == reference
    r = reference.rows["head"]
    b = reference.bias("head", r["n_compression"][0], r["n_expansion"][0])
    assert b[4] and abs(b[0]) < 0.05 and abs(b[1]) < 300


def test_known_chain_reads_a_drawn_chains_columns():
    """A data set's drawn chain (its ``chain.*`` columns): the mark plus the tacho's delay
    less the pressure's delay and its causal low-pass's group delay (a 2nd-order
    Butterworth at f_c: sqrt(2) / (2 pi f_c)), as crank angle."""
    fc = 2000.0
    row = {"chain.tacho.angle": math.radians(0.5), "chain.pressure.delay_s.0": 1e-4,
           "chain.pressure.lowpass_hz": fc, "chain.pressure.lowpass_order": 2,
           "chain.pressure.lowpass_phase": "causal", "chain.pressure.offset.0": 3000.0,
           "chain.pressure.gain.0": 1.01}  # fmt: skip
    phase, offset, gain = known_chain(row, 0, 3.0)
    tau = 1e-4 + math.sqrt(2) / (2 * math.pi * fc)
    assert phase == pytest.approx(0.5 - 360 * 3.0 * tau, rel=1e-4)
    assert (offset, gain) == (3000.0, 1.01)
    assert known_chain({}, 1, 3.0) == (0.0, 0.0, 1.0)


# ---- simulated records through the shipped diagnoser -------------------------------------------


@pytest.fixture(scope="module")
def healthy_run():
    from _records import healthy_run

    return healthy_run()


@pytest.mark.parametrize(
    "change, truth",
    [
        ({"offset": (1000.0, 1000.0)}, {"offset_head": 1000.0, "offset_crank": 1000.0}),
        ({"mark_deg": -0.3}, {"phase": -0.3}),
        ({"mark_deg": 1.0}, {"phase": 1.0}),
        ({"delay": 3}, {"phase": "delay"}),
    ],
)
def test_the_issues_chain_errors_are_corrected_before_the_diagnosis(healthy_run, change, truth):
    """The issue's single changes on a healthy record of a held-out condition (+1 kPa on both
    pressures, the mark 0.3 deg before or 1 deg after outer dead centre, the pressures 3
    samples late: each turned the shipped diagnoser's answer into a fault at p >= 0.98):
    each is recovered within its interval, and the corrected record is answered healthy,
    as the clean record is."""
    from _records import sensed
    from recipdyn.diagnosis.diagnose import diagnose_arrays

    ds, task = healthy_run
    s = sensed(ds, task, **change)
    res = diagnose_arrays(s["x"], s["fs"], tacho=s["tacho"], p_head=s["p_head_sensor"],
                          p_crank=s["p_crank_sensor"])  # fmt: skip
    assert not res.refused, res.reason
    assert res.label == "healthy", res.probabilities
    chain = res.evidence["chain"]
    omega = task["params"]["omega"]
    for name, want in truth.items():
        if want == "delay":  # 3 samples late: the pressures lag the tacho by omega * 3 / fs
            want = -math.degrees(omega * 3 / task["fs"])
        e = chain[name]
        assert abs(e["value"] - want) <= e["uncertainty"], (name, e)
        assert e["status"] == "corrected"


def test_a_clean_record_is_answered_as_without_the_correction(healthy_run):
    from _records import sensed
    from recipdyn.diagnosis.diagnose import diagnose_arrays

    ds, task = healthy_run
    s = sensed(ds, task)
    kw = dict(tacho=s["tacho"], p_head=s["p_head_sensor"], p_crank=s["p_crank_sensor"])
    on = diagnose_arrays(s["x"], s["fs"], **kw)
    off = diagnose_arrays(s["x"], s["fs"], correct=False, **kw)
    assert on.label == off.label == "healthy"
    assert "chain: phase" in on.text() and "channels used" in on.text()


def test_undoing_a_known_chain_gives_the_frame_correct_chain_maps_to(reference):
    """A data set of drawn chains can compute its features in the frame `correct_chain`
    puts a record in, from each record's known chain (`undo_known_chain`): on the ideal
    cycle with a mark of 1.2 deg, offsets +5 / -3 kPa and the crank end's gain 1 % low, the
    two give the same crank angle (to the estimate's interval) and the same pressures (to
    the offsets' intervals)."""
    from recipdyn.diagnosis.correction import undo_known_chain

    revs, ph, pc = _ideal_record(1.2, (5000.0, -3000.0), (1.0, 0.99), seed=21)
    row = {"chain.tacho.angle": math.radians(1.2), "chain.pressure.offset.0": 5000.0,
           "chain.pressure.offset.1": -3000.0, "chain.pressure.gain.0": 1.0,
           "chain.pressure.gain.1": 0.99}  # fmt: skip
    r_known, h_known, c_known = undo_known_chain(row, revs, ph, pc, 3.2)
    fix = correct_chain(revs, p_head=ph, p_crank=pc, reference=reference)
    e = fix.estimates
    assert np.max(np.abs(fix.revs - r_known)) * 360 <= e["phase"].uncertainty
    assert np.max(np.abs(fix.p_head - h_known)) <= e["offset_head"].uncertainty
    # the crank end: its offset's interval, and the gain ratio's times the pressure it scales
    bound = e["offset_crank"].uncertainty + e["gain_ratio"].uncertainty * np.max(np.abs(pc))
    assert np.max(np.abs(fix.p_crank - c_known)) <= bound
