"""recipdyn.diagnosis.baseline: the machine's own healthy baseline (docs/diagnosis.md).

A small case (one healthy record of ten revolutions, the clearance volume the one uncertain
parameter fitted): the fit recovers the pressure transducers' offsets, the tacho mark's angle
and the clearance volume it was not told, each within its interval; a later record of the
same machine through the same chain is answered healthy with the baseline. The benchmark
``benchmarks/bench_diagnosis_baseline.py`` counts the coverage over many cases and every
uncertain parameter, and the healthy recall with and without a baseline.
"""

from __future__ import annotations

import numpy as np
import pytest

from recipdyn.errors import ParameterError

#: The machine's truth and its chain's errors, unknown to the fit.
CLEARANCE = 0.108  # the diagnoser's machine: 0.1
#: The head end's offset lies outside the +-5 kPa the shipped diagnoser's chains were drawn
#: in: without the baseline the record is refused on it (`recipdyn.diagnosis.chainrange`).
CHAIN = {"p_head_offset": -7e3, "p_crank_offset": -2e3, "phase_deg": 0.8}


@pytest.fixture(scope="module")
def case():
    """The shipped diagnoser, a held-out condition of its data set (its first healthy record
    whose mounting resonance lies mid-band: 3 kHz to 0.4 fs), the baseline of one healthy
    record, and the record's parameters."""
    from recipdyn.diagnosis import default_model_path, load
    from recipdyn.diagnosis.baseline import UNCERTAIN, build_baseline, simulated_record
    from recipdyn.diagnosis.dataset import DatasetSpec, design

    diag = load(default_model_path())
    task = next(
        t
        for t in design(DatasetSpec.from_dict(diag.card["spec"]))
        if t["split"] == "test"
        and t["label"] == "healthy"
        and 3e3 < t["resonance_hz"] < 0.4 * t["fs"]  # mid-band, below Nyquist with margin
    )
    params = dict(task["params"], clearance_fraction=CLEARANCE)
    kw = {"fs": task["fs"], "resonance_hz": task["resonance_hz"], "chain": CHAIN}
    rec = simulated_record(params, revolutions=10, seed=11, **kw)
    b = build_baseline(
        [rec],
        diag,
        uncertain={"clearance_fraction": UNCERTAIN["clearance_fraction"]},
        workers=1,
        max_nfev=20,
    )
    return diag, b, params, kw, task


@pytest.mark.slow  # the fixture's fit: ~45 simulations (30-60 s on 2 cores)
def test_the_fit_recovers_the_chain_and_the_clearance_volume_it_was_not_told(case):
    """Each recovered value lies within the 99 % interval of its own uncertainty (Student's t
    at the fit's degrees of freedom; one case: the 90 % coverage is counted by the
    benchmark), and the fit measures: the intervals are far narrower than the priors (the
    clearance volume's +-20 %, the offsets' 10 kPa, the mark's 3 degrees). The mounting
    resonance, read from the impacts' ringing, within 5 % (the ringing lies within 7 % of the
    resonance on 95 % of the data set's records)."""
    from scipy.stats import t

    _, b, _, kw, task = case
    f = b.fit
    q99 = float(t.ppf(0.995, f.dof))
    truth = {"clearance_fraction": CLEARANCE / 0.1, **CHAIN}
    for n, v in truth.items():
        i = f.names.index(n)
        assert abs(f.value[i] - v) <= q99 * f.sigma[i], (n, f.value[i], f.sigma[i], v)
    sig = dict(zip(f.names, f.sigma, strict=True))
    assert sig["clearance_fraction"] < 0.01 and sig["phase_deg"] < 0.2
    assert sig["p_head_offset"] < 500 and sig["p_crank_offset"] < 500
    assert f.machine["clearance_fraction"] == pytest.approx(
        0.1 * f.value[f.names.index("clearance_fraction")]
    )
    assert f.resonance_hz[0] == pytest.approx(task["resonance_hz"], rel=0.05)
    assert f.dof >= 2 and f.quantile > 1.645  # the t quantile of an estimated variation


@pytest.mark.slow  # the fixture's fit: ~45 simulations (30-60 s on 2 cores)
def test_a_later_record_is_read_against_the_machines_own_healthy_state(case):
    """A later healthy record of the same machine (8 % more clearance volume) through the
    same chain (offsets -7 / -2 kPa, the mark 0.8 degree late): without the baseline it is
    refused (the head end's offset is outside the chain ranges the diagnoser was trained
    under); with it, its chain is corrected and its features referred to the machine's own
    healthy records, and it is answered healthy, the corrections in the evidence."""
    import dataclasses

    from recipdyn.diagnosis.baseline import simulated_record
    from recipdyn.diagnosis.diagnose import diagnose_arrays

    diag, b, params, kw, _ = case
    later = simulated_record(params, revolutions=4, seed=12, **kw)
    args = {"tacho": later.tacho, "p_head": later.p_head, "p_crank": later.p_crank,
            "model": diag}  # fmt: skip
    alone = diagnose_arrays(later.accel, later.fs, **args)
    assert alone.refused and "offset" in alone.reason, (alone.label, alone.reason)
    # one baseline record: its features carry their own cycle-to-cycle noise into the
    # default (records) referral, and this record was then named a worn crosshead pin; the
    # model referral (the fitted clearance volume's effect, the one parameter this machine
    # departs in) is read here; the records referral is measured from 3 records by the
    # benchmark (docs/diagnosis.md)
    b = dataclasses.replace(b, delta=b.delta_model, referral="model")
    res = diagnose_arrays(later.accel, later.fs, **args, baseline=b)
    assert not res.refused, res.reason
    assert res.label == "healthy" and res.probabilities["healthy"] > 0.9
    ev = res.evidence["baseline"]
    assert ev["chain"]["p_head_offset"] == pytest.approx(CHAIN["p_head_offset"], abs=500)
    assert set(b.delta) and all(n.startswith(("ph_", "pc_", "cy_", "dv_")) for n in b.delta)


@pytest.mark.slow  # the fixture's fit (above) and one record
def test_a_fault_of_the_same_machine_is_still_named_with_the_baseline(case):
    """The baseline takes off the machine's healthy state, not a fault: a suction-valve leak
    (severity 0.6, inside the range the shipped diagnoser names it right at every severity
    bin: docs/diagnosis.md) of the same machine through the same chain is named, not called
    healthy, with its severity's 90 % interval reported."""
    from recipdyn.diagnosis.baseline import simulated_record
    from recipdyn.diagnosis.classes import get_class
    from recipdyn.diagnosis.diagnose import diagnose_arrays

    diag, b, params, kw, _ = case
    leak = {**params, **get_class("suction_valve_leak").overrides(0.6)}
    rec = simulated_record(leak, revolutions=4, seed=13, **kw)
    res = diagnose_arrays(rec.accel, rec.fs, tacho=rec.tacho, p_head=rec.p_head,
                          p_crank=rec.p_crank, model=diag, baseline=b)  # fmt: skip
    assert not res.refused, res.reason
    assert res.label == "suction_valve_leak", res.probabilities
    lo, hi = res.severity_interval
    assert lo <= res.severity <= hi


@pytest.mark.slow  # the fixture's fit: ~45 simulations (30-60 s on 2 cores)
def test_a_baseline_file_round_trips_and_belongs_to_its_diagnoser(case, tmp_path):
    import dataclasses

    from recipdyn.diagnosis.baseline import baseline_for, load_baseline

    diag, b, *_ = case
    path = b.save(tmp_path / "b.json")
    again = load_baseline(path)
    assert again.delta == b.delta and again.fit.value == b.fit.value
    assert baseline_for(diag, path).chain == b.chain
    with pytest.raises(ParameterError, match="another diagnoser"):
        baseline_for(diag, dataclasses.replace(b, diagnoser="0" * 16))
    (tmp_path / "x.json").write_text("{}")
    with pytest.raises(ParameterError, match="not a recipdyn baseline"):
        load_baseline(tmp_path / "x.json")


def test_records_too_short_to_show_the_cycle_to_cycle_variation_are_refused():
    from recipdyn.diagnosis.baseline import _bin_sigma

    one = np.zeros((2, 2, 360))  # one record of two revolutions: one degree of freedom
    with pytest.raises(ParameterError, match="at least 3"):
        _bin_sigma([one])
    sigma, dof = _bin_sigma([np.random.default_rng(0).normal(size=(4, 2, 360))])
    assert dof == 3 and sigma.shape == (1, 2, 360)


def test_the_sandwich_is_the_inverse_information_when_the_bins_errors_are_independent():
    """`_covariance` with independent unit errors in every bin (many revolutions, so their
    estimate is close) gives ``H^-1 (Jd^T Jd + P) H^-1 = H^-1``: checked to the sampling error
    of the variation's estimate (800 revolutions: ~5 % on a variance; 15 % allowed)."""
    from recipdyn.diagnosis.baseline import FIT_REVOLUTIONS, _covariance

    rng = np.random.default_rng(3)
    n_rev = 800
    Jd = rng.normal(size=(720, 3)) * [1.0, 0.3, 0.05]
    Jp = np.diag([1.0, 2.0, 5.0])
    f = 1.0 / n_rev + 1.0 / FIT_REVOLUTIONS
    per_rev = [rng.normal(size=(n_rev, 2, 360))]
    scale = np.full((1, 2, 360), np.sqrt(f))  # the weights are the errors' own sd
    cov = _covariance(Jd, Jp, per_rev, scale)
    expect = np.linalg.inv(Jd.T @ Jd + Jp.T @ Jp)
    assert np.diag(cov) == pytest.approx(np.diag(expect), rel=0.15)


@pytest.mark.parametrize(
    "args, words",
    [
        (["baseline", "missing.nc", "-o", "o/b.json"], ["missing.nc", "not found"]),
        (["baseline", "missing.nc", "-o", "o/b.txt"], ["--out", ".json"]),
        (["dataset", "--set", "rc=1 mm", "-o", "o/ds"], ["rc", "fault", "allowed"]),
        (["dataset", "--machine", "m.csv", "-o", "o/ds"], ["machine", "unknown format"]),
        (["diagnose", "r.nc", "--tacho", "t", "--machine", "m.txt"], ["machine", "format"]),
    ],
)
def test_the_commands_refuse_bad_input_in_one_line(tmp_path, monkeypatch, capsys, args, words):
    """Exit 2, one line naming the problem, nothing written."""
    from recipdyn.cli import main

    monkeypatch.chdir(tmp_path)
    (tmp_path / "m.csv").write_text("x\n")
    (tmp_path / "r.nc").write_text("not read: the machine file is refused first")
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and all(w in err for w in words), err
    assert not (tmp_path / "o").exists()


@pytest.mark.exhaustive  # a whole baseline, every uncertain parameter (1-3 min on 2 cores);
# the fit itself runs in CI above (one parameter)
def test_the_baseline_command_writes_a_baseline_that_diagnose_reads(case, tmp_path, capsys):
    """``recipdyn baseline REC -o FILE`` (every uncertain parameter: the clearance volume
    fitted, the springs, lifts and masses marginalised) writes a file whose summary names the
    fitted values and whose chain ``recipdyn diagnose --baseline`` applies."""
    import xarray as xr

    from recipdyn.cli import main
    from recipdyn.diagnosis.baseline import load_baseline, simulated_record

    diag, _, params, kw, _ = case
    rec = simulated_record(params, revolutions=4, seed=21, **kw)
    t = np.arange(rec.accel.size) / rec.fs
    path = tmp_path / "healthy.nc"
    chans = {"accel_guide": rec.accel, "tacho": rec.tacho, "p_head_sensor": rec.p_head,
             "p_crank_sensor": rec.p_crank}  # fmt: skip
    xr.Dataset({k: ("time", v) for k, v in chans.items()}, coords={"time": t}).to_netcdf(path)
    out = tmp_path / "b.json"
    assert main(["baseline", str(path), "-o", str(out), "--workers", "1"]) == 0
    text = capsys.readouterr().out
    assert "clearance_fraction" in text and "valve_lift" in text and f"--baseline {out}" in text
    b = load_baseline(out)
    assert b.fit.unseen == ["m2", "m3", "valve_lift", "valve_spring"]
    assert b.fit.machine_interval["valve_lift"] == pytest.approx([0.9 * 0.0025, 1.1 * 0.0025])
    assert b.chain["p_head_offset"] == pytest.approx(CHAIN["p_head_offset"], abs=1000)
    assert main(["diagnose", str(path), "--tacho", "tacho", "--p-head", "p_head_sensor",
                 "--p-crank", "p_crank_sensor", "--baseline", str(out)]) == 0  # fmt: skip
    assert "diagnosis: healthy" in capsys.readouterr().out
