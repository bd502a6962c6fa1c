"""recipdyn.diagnosis.chainrange: the record's estimated chain against the chain ranges its
diagnoser was trained under (docs/diagnosis.md, "The chain ranges a diagnoser was trained
under"). The refusals of whole records by the shipped diagnoser (a 1.2 kHz resonance, a 5 dB
record with and without a tacho) are in tests/test_diagnosis.py."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from recipdyn.diagnosis.chainrange import check_chain, declared_ranges, snr_estimate
from recipdyn.diagnosis.correction import Estimate
from recipdyn.diagnosis.tolerances import RESONANCE_CHECK_REL, SNR_CALIBRATION
from recipdyn.errors import ParameterError

DECLARED = {
    "accelerometer.resonance_hz": (2500.0, 6000.0, "Hz"),
    "accelerometer.snr_db": (10.0, 40.0, "dB"),
    "pressure.offset": (-5000.0, 5000.0, "Pa"),
}


def test_the_shipped_diagnosers_declared_ranges_are_read_from_its_data_card():
    """The shipped diagnoser (a drawn-chain data set, SNR drawn in 10-40 dB) declares the
    ranges of `recipdyn.chain.DEFAULT_RANGES` with its SNR range; a card of the fixed chain,
    or one without ranges (an older file), declares none: the learnt-range checks stay."""
    from recipdyn.chain import DEFAULT_RANGES
    from recipdyn.diagnosis.diagnose import default_model_path
    from recipdyn.diagnosis.train import load

    d = declared_ranges(load(default_model_path()))
    assert d["accelerometer.snr_db"] == (10.0, 40.0, "dB")
    r = DEFAULT_RANGES["accelerometer.resonance_hz"]
    assert d["accelerometer.resonance_hz"] == (r.lo, r.hi, "Hz")
    assert d["pressure.offset"] == (-5000.0, 5000.0, "Pa")
    assert declared_ranges(SimpleNamespace(card={"chain": {"kind": "fixed"}})) is None
    assert declared_ranges(SimpleNamespace(card={"chain": {"kind": "drawn"}})) is None
    assert declared_ranges(SimpleNamespace(card={})) is None


def test_a_data_sets_own_chain_ranges_reach_its_card_and_are_read_back():
    """``recipdyn dataset --chain-range NAME=LO,HI`` (`DatasetSpec.chain_spans`) replaces a
    range; the card lists it and `declared_ranges` reads it back; the store's identity of a
    spec without it is unchanged."""
    from recipdyn.diagnosis.dataset import DatasetSpec, _chain_card

    spec = DatasetSpec(n_conditions=4, chain_spans=(("accelerometer.resonance_hz", 800, 6000),))
    d = declared_ranges(SimpleNamespace(card={"chain": _chain_card(spec)}))
    assert d["accelerometer.resonance_hz"] == (800.0, 6000.0, "Hz")
    assert d["accelerometer.snr_db"] == (10.0, 40.0, "dB")
    assert "chain_spans" not in DatasetSpec(n_conditions=4).to_json()
    assert DatasetSpec.from_dict(__import__("json").loads(spec.to_json())) == spec


@pytest.mark.parametrize(
    "kw, word",
    [
        (dict(chain_spans=(("accelerometer.rust", 1, 2),)), "accelerometer.rust"),
        (dict(chain_spans=(("accelerometer.bits", 16, 24),)), "accelerometer.bits"),
        (dict(chain_spans=(("accelerometer.snr_db", 40, 10),)), "LO <= HI"),
        (dict(chain_spans=(("accelerometer.resonance_hz", 0, 10),)), "lo > 0"),
        (dict(chain_spans=(("accelerometer.snr_db", 5, 40),), chain="fixed"), "chain_spans"),
    ],
)
def test_bad_chain_ranges_are_refused_naming_the_range(kw, word):
    from recipdyn.diagnosis.dataset import DatasetSpec

    with pytest.raises(ParameterError, match=word):
        DatasetSpec(n_conditions=4, **kw)


def test_cli_refuses_a_bad_chain_range_in_one_line(capsys, tmp_path):
    from recipdyn.cli import main

    out = tmp_path / "ds"
    assert main(["dataset", "-n", "4", "-o", str(out), "--chain-range", "x=1"]) == 2
    assert (
        main(["dataset", "-n", "4", "-o", str(out), "--chain-range", "tacho.angle_deg=3,-3"]) == 2
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "NAME=LO,HI" in err[0] and "tacho.angle_deg" in err[1]
    assert not out.exists()


def test_snr_from_a_noise_floor_of_white_noise_alone():
    """Closed form: a quietest bin of noise alone holds ``q = N / (N + S)`` of the mean bin,
    so ``x = 10 log10(1/q - 1)`` is the high-passed signal-to-noise ratio exactly and the
    estimate is ``x`` plus the calibration's offset, its interval the offset's residuals;
    where the signal fills the bin (``x > x_max``) only a lower bound is read."""
    for kind, cal in SNR_CALIBRATION.items():
        for x in (-3.0, 5.0, 17.5, cal["x_max"]):
            q = 1.0 / (1.0 + 10 ** (x / 10))
            v, lo, hi, note = snr_estimate(q, kind)
            assert v == pytest.approx(x + cal["offset"], abs=1e-9)
            assert (lo, hi) == pytest.approx((v + cal["lo"], v + cal["hi"]), abs=1e-9)
            assert lo < v < hi and not note
        v, lo, hi, note = snr_estimate(1.0 / (1.0 + 10 ** ((cal["x_max"] + 5) / 10)), kind)
        assert hi == math.inf and lo == pytest.approx(v + cal["lo"]) and "lower bound" in note
    for q in (0.0, 1.0, math.nan):
        assert math.isnan(snr_estimate(q)[0])


@pytest.fixture(scope="module")
def healthy_record():
    """A healthy record of the shipped diagnoser's first test condition, 4 revolutions,
    simulated once (the sensed chains vary, the machine does not)."""
    import warnings

    from recipdyn.diagnosis.classes import MODEL
    from recipdyn.diagnosis.dataset import DatasetSpec, design
    from recipdyn.diagnosis.diagnose import default_model_path
    from recipdyn.diagnosis.train import load
    from recipdyn.simulate import simulate

    spec = DatasetSpec.from_dict(load(default_model_path()).card["spec"])
    task = next(t for t in design(spec) if t["split"] == "test" and t["label"] == "healthy")
    with warnings.catch_warnings():  # (the healthy pins stretch Hertz's law: dataset.py)
        warnings.simplefilter("ignore")
        ds = simulate(model=MODEL, revolutions=4.0, transient=task["transient"], fs=task["fs"],
                      **task["params"])  # fmt: skip
    return task, ds


@pytest.mark.parametrize("snr_db", [4.0, 12.0, 21.0])
def test_the_noise_floor_reads_the_chains_snr_within_its_interval(healthy_record, snr_db):
    """Independent of the calibration's records: a new healthy record (a test condition, a
    chain of its own data set's draw with the SNR set) read through `recipdyn diagnose`'s own
    path; the SNR estimate's 95 % interval must hold the SNR the chain was given. The
    interval is the calibration's measured 2.5-97.5 % residuals (about -2.5..+1.9 dB); these
    three records are seeded (deterministic), each inside it with ~95 % probability a priori."""
    from recipdyn import sensors
    from recipdyn.chain import Chain
    from recipdyn.diagnosis.diagnose import diagnose_arrays

    task, ds = healthy_record
    ch = Chain.from_dict(dict(task["chain"], **{"accelerometer.snr_db": snr_db}))
    rec = sensors.record(ds, chain=ch, seed=task["noise_seed"])
    res = diagnose_arrays(rec["accel_guide"].values, task["fs"], tacho=rec["tacho"].values,
                          p_head=rec["p_head_sensor"].values,
                          p_crank=rec["p_crank_sensor"].values)  # fmt: skip
    c = res.evidence["chain_ranges"]["snr_db"]
    assert c["lo"] <= snr_db <= c["hi"], c
    assert (c["status"] == "outside") == (snr_db < 10.0), res.reason
    if snr_db < 10.0:
        assert res.refused and "accelerometer.snr_db range 10..40 dB" in res.reason
        assert "--snr-range" in res.reason


def _res(value, u=50.0, status="measured"):
    return {"resonance_hz": Estimate(value, u, "Hz", status), "offset_head":
            Estimate(100.0, 500.0, "Pa", "corrected")}  # fmt: skip


def test_a_resonance_is_refused_only_where_it_is_read_and_outside_by_its_uncertainty():
    """Outside by more than its interval (its own 95 % half-width and `RESONANCE_CHECK_REL`
    in quadrature): refused, naming the channel, the parameter, the estimate, the range and
    the data set option. Inside that interval of the range's edge, not measured, or not where
    the impacts ring (a machine's own spectral peak): not refused, reported as such."""
    checks, why = check_chain(DECLARED, _res(1200.0), None, ring_hz=1190.0)
    assert "accelerometer" in why and "resonance" in why and "2500..6000 Hz" in why
    assert "1.2e+03" in why and "--chain-range" in why and "sensor band" in why
    assert {c.name: c.status for c in checks} == {"resonance_hz": "outside",
                                                   "offset_head": "inside"}  # fmt: skip
    edge = 2400.0  # outside the range, not by more than its uncertainty
    assert edge + math.hypot(50.0, RESONANCE_CHECK_REL * edge) > 2500.0 > edge + 50.0
    checks, why = check_chain(DECLARED, _res(edge), None, ring_hz=edge)
    assert why is None and checks[0].status == "inside"
    checks, why = check_chain(DECLARED, _res(1200.0), None, ring_hz=3000.0)
    assert why is None and checks[0].status == "not estimated" and "ring" in checks[0].note
    checks, why = check_chain(DECLARED, _res(1200.0, math.nan, "not identified"), None, 1200.0)
    assert why is None and checks[0].status == "not estimated"


def test_an_snr_is_refused_where_its_interval_lies_outside_a_lower_bound_above_x_max():
    """Below the range by more than its interval: refused, naming the noise floor, the SNR
    and ``--snr-range``. Above `SNR_CALIBRATION`'s ``x_max`` the floor gives a lower bound
    only: a floor 1 dB above the range's top is inside it, one 20 dB above is outside (at
    least that quiet a sensor: the angle features of a much quieter sensor than trained
    moved a third of the healthy records to a fault, docs/diagnosis.md)."""
    low = 1.0 / (1.0 + 10 ** (4.0 / 10))  # x = 4 dB
    checks, why = check_chain(DECLARED, {}, (low, "angle"))
    assert why and "noise floor" in why and "SNR" in why and "--snr-range" in why
    assert checks[0].status == "outside" and checks[0].hi < 10.0
    for x, status in ((41.0, "inside"), (60.0, "outside")):
        q = 1.0 / (1.0 + 10 ** (x / 10))
        checks, why = check_chain(DECLARED, {}, (q, "quiet"))
        assert checks[0].hi == math.inf and checks[0].status == status, checks
        assert (why is None) == (status == "inside")
        assert status == "inside" or "at least" in why


def test_an_offset_outside_the_declared_range_names_the_channel():
    est = {"offset_crank": Estimate(-9000.0, 800.0, "Pa", "corrected")}
    checks, why = check_chain(DECLARED, est, None)
    assert "p_crank" in why and "pressure.offset" in why and "-5000..5000 Pa" in why
    est = {"offset_crank": Estimate(-5500.0, 800.0, "Pa", "corrected")}
    assert check_chain(DECLARED, est, None)[1] is None  # within its uncertainty of the edge
    # a range the diagnoser does not declare is not checked
    assert check_chain({}, est, None) == ([], None)
    assert np.isfinite(checks[0].value)


@pytest.mark.parametrize(
    "change, words",
    [
        # the shipped data set's chain with one parameter far outside its declared range
        ({"accelerometer.full_scale": 40 * 9.80665}, ["accelerometer clipped", "re-record"]),
        ({"accelerometer.hum_db": 0.0, "accelerometer.mains_hz": 60.0,
          "pressure.mains_hz": 60.0}, ["accelerometer: mains hum at 60 Hz", "re-record"]),
        ({"accelerometer.bits": 8}, ["accelerometer: converter step", "finer converter"]),
        ({"tacho.angle": math.radians(10.0)}, ["tacho: mark's angle", "outer dead centre"]),
    ],
)  # fmt: skip
def test_a_chain_far_outside_its_ranges_is_refused_naming_channel_and_remedy(
    healthy_record, change, words
):
    """The healthy test record through its own drawn chain (inside every range: answered
    without a chain refusal) and through that chain with one parameter changed far outside
    the declared ranges: a clipped accelerometer (range 40 g against healthy peaks of ~150
    g), 60 Hz hum at 0 dB (20 dB above the -20 dB top), an 8-bit converter (its step 32x the
    coarsest declared), a keyphasor 10 degrees off (the declared +-2 degrees widened by the
    pressures' delay, < 1 degree at this speed): each refused in one line naming the channel,
    the estimate, the range and what to do."""
    from recipdyn import sensors
    from recipdyn.chain import Chain
    from recipdyn.diagnosis.diagnose import diagnose_arrays

    task, ds = healthy_record

    def run(d):
        rec = sensors.record(ds, chain=Chain.from_dict(d), seed=task["noise_seed"])
        return diagnose_arrays(rec["accel_guide"].values, task["fs"], tacho=rec["tacho"].values,
                               p_head=rec["p_head_sensor"].values,
                               p_crank=rec["p_crank_sensor"].values)  # fmt: skip

    base = dict(task["chain"], **{"accelerometer.snr_db": 25.0})
    res = run(base)
    assert "trained under" not in (res.reason or "") and "clipped" not in (res.reason or "")
    res = run(dict(base, **change))
    assert res.refused and "\n" not in res.reason, res.reason
    for w in words:
        assert w in res.reason, res.reason


def test_an_accelerometer_clipped_inside_its_declared_full_scale_is_answered():
    """The default ranges draw the accelerometer's converter range at 250-1000 g so that the
    worn pins' impacts (~450 g) sometimes clip: such a record lies inside the data set, and
    its flat tops give the full scale (the extreme over g, to a converter step). A sine
    clipped at 300 g is therefore not refused (the evidence says where it clipped), at 40 g
    it is, naming the range; a clipped pressure is refused whatever the ranges (no drawn
    transducer range lets the pressure clip); a diagnoser that declares no converter range
    refuses a clipped accelerometer."""
    from recipdyn.analysis.channel import clipping
    from recipdyn.diagnosis.chainrange import clipping_refusal
    from recipdyn.sensors import G0

    t = np.arange(20000) / 10240.0
    wave = np.sin(2 * np.pi * 7.0 * t)
    declared = {"accelerometer.full_scale_g": (250.0, 1000.0, "g")}

    def clipped_at(g):
        step = 2 * g * G0 / 2**16  # a 16-bit converter spanning +-g
        return {
            "clip_accelerometer": clipping(
                np.round(np.clip(1.5 * g * G0 * wave, -g * G0, g * G0) / step) * step
            )
        }

    why, ev = clipping_refusal(clipped_at(300.0), declared)
    assert why is None and "inside the declared" in ev["accelerometer_clipping"]["status"]
    assert ev["accelerometer_clipping"]["full_scale_g"] == pytest.approx(300.0, rel=1e-3)
    why, _ = clipping_refusal(clipped_at(40.0), declared)
    assert "outside the declared accelerometer.full_scale_g 250..1000 g" in why, why
    assert "\n" not in why
    assert "declares no converter range" in clipping_refusal(clipped_at(300.0), None)[0]
    p = np.clip(3e5 + 2e5 * wave, 0, 4e5)
    why, _ = clipping_refusal({"clip_p_head": clipping(np.round(p / 10.0) * 10.0)}, declared)
    assert why.startswith("p_head clipped"), why


def test_the_tacho_is_refused_on_the_crank_angle_error_its_jitter_leaves_not_the_jitter():
    """A jitter of 0.5 deg (twice the declared 0.25) read on 40 pulses leaves the fitted crank
    angle ``0.5 sqrt(3 / 40)`` = 0.14 deg off (a parabola through them: `correction.axis_sd`),
    within what the data set's 3-pulse records held at 0.25 deg (``0.25 sqrt(2 / 3)`` = 0.20
    deg): reported, not refused; the same jitter on 5 pulses leaves 0.32 deg and 2 deg on 40
    pulses 0.55 deg: refused where the whole interval is beyond (the chi-square interval of
    the jitter, scaled), naming the tacho and the remedy. The jitter itself and the mount's
    damping are reported, never refused on (`REPORTED_ONLY`: their intervals are not 95 %
    ones)."""
    declared = {"tacho.jitter_deg": (0.0, 0.25, "deg"),
                "accelerometer.damping": (0.02, 0.15, "1")}  # fmt: skip

    def run(jitter, pulses):
        est = {"tacho_jitter": Estimate(jitter, math.nan, "deg", "corrected")}
        return check_chain(declared, est, None, signals={"n_pulses": pulses}, train_pulses=3)

    checks, why = run(0.5, 40)
    st = {c.name: c for c in checks}
    assert why is None, why
    assert st["tacho_jitter"].status == "outside" and st["tacho_axis"].status == "inside"
    assert st["tacho_axis"].value == pytest.approx(0.5 * math.sqrt(3 / 40))
    assert st["tacho_axis"].range[1] == pytest.approx(0.25 * math.sqrt(2 / 3))
    checks, why = run(2.0, 40)
    assert "tacho: crank-angle error" in why and "more revolutions" in why, why
    checks, why = run(0.5, 5)  # 3 degrees of freedom: a wide interval, its low end inside
    assert why is None and {c.name: c.status for c in checks}["tacho_axis"] == "inside"
    checks, why = run(1.0, 12)
    assert why is not None and "tacho" in why
    # the damping far outside its range: reported, not refused
    est = {"resonance_hz": Estimate(3000.0, 50.0, "Hz", "measured"),
           "damping": Estimate(0.005, 0.001, "1", "measured")}  # fmt: skip
    checks, why = check_chain({**declared, "accelerometer.resonance_hz": (2500.0, 6000.0, "Hz")},
                              est, None, ring_hz=3000.0)  # fmt: skip
    assert why is None and {c.name: c.status for c in checks}["damping"] == "outside"
