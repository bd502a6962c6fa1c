"""recipdyn.diagnosis: data sets, diagnosers and the diagnosis of a record (docs/diagnosis.md).

Everything runs at reduced size (a few conditions, one severity level, three classes), so the
claims tested are the machinery's (splits, determinism, resumption, refusals, calibration
bookkeeping), not the accuracy of a full-size diagnoser (docs/diagnosis.md measures that).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from recipdyn.diagnosis.classes import CLASSES, CONDITIONS
from recipdyn.diagnosis.dataset import DatasetSpec, build_dataset, design, read_features
from recipdyn.errors import Interrupted, ParameterError

SMALL = DatasetSpec(
    n_conditions=4,
    levels=(1.0,),
    classes=("healthy", "crank_pin_clearance", "ring_leak"),
    test_fraction=0.25,
    seed=3,
)


def test_every_class_is_one_entry_with_a_meaning_and_a_valid_range():
    """Adding a class is one entry: a parameter of the one model, two values in its schema's
    range, and a physical meaning."""
    from recipdyn.diagnosis.classes import MODEL
    from recipdyn.model.registry import get_model

    schema = get_model(MODEL).schema
    names = [c.name for c in CLASSES]
    assert len(set(names)) == len(names) and names[0] == "healthy"
    for c in CLASSES[1:]:
        assert c.parameter in schema and c.meaning
        lo, hi = sorted((c.mild, c.severe))
        get_model(MODEL).parameters({c.parameter: lo})
        get_model(MODEL).parameters({c.parameter: hi})
        for s in (0.0, 0.3, 1.0):  # value and severity are inverse
            assert c.severity(c.value(s)) == pytest.approx(s, abs=1e-12)


def test_design_is_seeded_balanced_and_split_by_condition():
    spec = DatasetSpec(n_conditions=20, seed=7)
    tasks = design(spec)
    assert tasks == design(spec)  # deterministic
    other = design(DatasetSpec(n_conditions=20, seed=8))
    assert [t["params"]["omega"] for t in tasks] != [t["params"]["omega"] for t in other]
    by_cond: dict[int, set] = {}
    for t in tasks:
        by_cond.setdefault(t["condition"], set()).add(t["split"])
    assert all(len(s) == 1 for s in by_cond.values())  # no condition in both splits
    splits = [next(iter(s)) for s in by_cond.values()]
    assert splits.count("test") == 5  # 25 % of 20
    for c in range(20):  # every class at every level at every condition: balanced
        labels = [t["label"] for t in tasks if t["condition"] == c]
        assert len(labels) == len(CLASSES) * len(spec.levels)
        assert len(set(labels)) == len(CLASSES)
    for t in tasks:  # conditions inside their stated ranges
        for k in ("omega", "suction_pressure", "discharge_pressure", "m2", "m3"):
            assert CONDITIONS[k].lo <= t["params"][k] <= CONDITIONS[k].hi
        assert CONDITIONS["resonance_hz"].lo <= t["resonance_hz"] <= CONDITIONS["resonance_hz"].hi
        assert t["resonance_hz"] < t["fs"] / 2  # the sensor model's own limit
    assert len({t["noise_seed"] for t in tasks}) == len(tasks)


@pytest.mark.parametrize(
    "kw, word",
    [
        (dict(n_conditions=1), "n_conditions"),
        (dict(levels=(0.0,)), "levels"),
        (dict(classes=("ring_leak",)), "healthy"),
        (dict(classes=("healthy", "rust")), "rust"),
        (dict(test_fraction=1.0), "test_fraction"),
    ],
)
def test_bad_specs_are_refused_naming_the_setting(kw, word):
    with pytest.raises(ParameterError, match=word):
        DatasetSpec(**kw)


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """SMALL built serially, interrupted after 5 records and resumed."""
    out = tmp_path_factory.mktemp("ds") / "small"
    seen = []

    def stop(res):
        seen.append(res["index"])
        if len(seen) == 5:
            raise Interrupted(2)

    with pytest.raises(Interrupted):
        build_dataset(out, SMALL, backend="serial", progress=False, on_record=stop)
    from recipdyn.diagnosis.dataset import records_done

    assert records_done(out).sum() == 5  # the finished records were kept
    again = []
    build_dataset(
        out,
        SMALL,
        backend="serial",
        progress=False,
        resume=True,
        on_record=lambda r: again.append(r["index"]),
    )
    return out, seen, again


def test_an_interrupted_build_resumes_keeping_finished_records(small):
    out, first, second = small
    assert len(first) == 5 and len(second) == 12 - 5
    assert not set(first) & set(second)  # nothing recomputed
    df, card = read_features(out)
    assert len(df) == 12 and card["throughput"]["reused"] == 5
    assert df.label.value_counts().to_dict() == {
        "healthy": 4,
        "crank_pin_clearance": 4,
        "ring_leak": 4,
    }
    tr, te = set(df[df.split == "train"].condition), set(df[df.split == "test"].condition)
    assert tr and te and not tr & te
    assert card["recipdyn_version"] and card["spec"]["seed"] == 3
    assert np.isfinite(df.filter(like="f_").to_numpy()).all()


def test_an_existing_data_set_needs_resume_or_force(small):
    out, *_ = small
    with pytest.raises(ParameterError, match="--resume"):
        build_dataset(out, SMALL, backend="serial", progress=False)
    with pytest.raises(ParameterError, match="another spec"):
        build_dataset(
            out, DatasetSpec(n_conditions=5), backend="serial", progress=False, resume=True
        )


def test_process_pool_gives_the_serial_records_to_the_bit(small, tmp_path):
    """The unit of work is pure: a process pool, in any completion order, stores the same
    features as the serial (interrupted and resumed) build."""
    out, *_ = small
    spec = DatasetSpec(
        n_conditions=2, levels=(1.0,), classes=("healthy", "ring_leak"), test_fraction=0.5, seed=3
    )
    a = build_dataset(tmp_path / "p", spec, backend="processes", workers=2, progress=False)
    b = build_dataset(tmp_path / "s", spec, backend="serial", progress=False)
    fa, fb = read_features(a)[0], read_features(b)[0]
    assert fa.drop(columns=[]).equals(fb)


# ---- training (at reduced size) -------------------------------------------------------------


@pytest.fixture(scope="module")
def trained(small):
    from recipdyn.diagnosis.train import train

    out, *_ = small
    return train(out, seed=0)


def test_condition_only_classifier_is_at_chance(trained):
    """Every condition holds every class equally often, so a classifier that sees only the
    condition and the sensor settings predicts one class per condition: accuracy 1/K exactly
    on a balanced test set; the bound allows 3 binomial standard deviations on the test size.
    A label leaking into a condition column (e.g. a class-dependent sampling rate) fails it."""
    _, ev = trained
    co = ev["condition_only"]
    k = 3
    assert co["chance"] == pytest.approx(1 / k)
    assert co["bound"] == pytest.approx(1 / k + 3 * math.sqrt((1 / k) * (1 - 1 / k) / ev["n_test"]))
    assert co["accuracy"] <= co["bound"]


def test_evaluation_bookkeeping(trained):
    diag, ev = trained
    f = ev["full"]
    cm = np.asarray(f["confusion"])
    assert cm.sum() == ev["n_test"] == 3  # one held-out condition x 3 classes x 1 level
    assert f["accuracy"] == pytest.approx(np.trace(cm) / cm.sum())
    assert 0 <= f["ece"] <= 1
    for d in f["detection"].values():  # the limit is a level whose recall is >= 90 %
        if d["limit_severity"] is not None:
            assert d["recall_by_severity"][d["limit_severity"]] >= 0.9


def test_expected_calibration_error_of_known_cases():
    """Perfectly calibrated bins give 0; always 90 % sure and always right gives 0.1."""
    from recipdyn.diagnosis.train import expected_calibration_error

    p = np.tile([[0.9, 0.1]], (10, 1))
    y = np.zeros(10, int)
    assert expected_calibration_error(p, y)[0] == pytest.approx(0.1)
    y[0] = 1  # 9 of 10 right at 0.9: calibrated
    assert expected_calibration_error(p, y)[0] == pytest.approx(0.0, abs=1e-12)


def test_a_saved_diagnoser_predicts_exactly_as_the_trained_one(trained, small, tmp_path):
    """The file packs every boosting model's trees into one array (small, fast to load);
    read back, the classifiers and the severity regressors give the same numbers to the bit,
    for every channel subset."""
    from recipdyn.diagnosis.train import AVAILABILITY, _augment, load, save

    diag, _ = trained
    df, _ = read_features(small[0])
    X, _ = _augment(df[[f"f_{n}" for n in diag.names]].to_numpy(float), diag.names)
    back = load(save(diag, tmp_path / "d.skops"))
    assert len(AVAILABILITY) == 3 and X.shape[0] == 3 * len(df)
    assert np.array_equal(back.predict_proba(X), diag.predict_proba(X))
    for c in diag.classes[1:]:
        for a, b in zip(back.severity(X, c), diag.severity(X, c), strict=True):
            assert np.array_equal(a, b)


def test_a_diagnoser_of_another_version_is_refused(trained, tmp_path):
    from recipdyn.diagnosis.train import Diagnoser, load, save

    diag, _ = trained
    state = dict(diag.state, recipdyn_version="0.0.1")
    path = save(Diagnoser(state), tmp_path / "old.skops")
    with pytest.raises(ParameterError, match="trained with recipdyn 0.0.1.*retrain"):
        load(path)


# ---- diagnose --------------------------------------------------------------------------------


def _record(tmp_path, name, **change):
    """A 10-revolution sensed record of the shipped diagnoser's first test condition."""
    from recipdyn.diagnosis.dataset import simulate_record
    from recipdyn.diagnosis.diagnose import default_model_path
    from recipdyn.diagnosis.train import load

    card = load(default_model_path()).card
    spec = DatasetSpec(
        **{k: tuple(v) if isinstance(v, list) else v for k, v in card["spec"].items()}
    )
    task = next(
        t
        for t in design(spec)
        if t["split"] == "test" and t["label"] == "ring_leak" and t["level"] == len(spec.levels) - 1
    )
    task = dict(task, revolutions=10.0, **{k: v for k, v in change.items() if k != "params"})
    task["params"] = dict(task["params"], **change.get("params", {}))
    rec = simulate_record(task)
    path = tmp_path / f"{name}.nc"
    rec[["accel_guide", "p_head_sensor", "p_crank_sensor", "tacho"]].to_netcdf(path)
    return path


def test_diagnose_a_ten_revolution_record(tmp_path):
    """The shipped diagnoser answers a record of its domain (a held-out condition) with
    probabilities, a severity inside its interval, the impacts and the overlay figure."""
    from recipdyn.diagnosis.diagnose import diagnose

    path = _record(tmp_path, "ring")
    res = diagnose(
        path, tacho="tacho", p_head="p_head_sensor", p_crank="p_crank_sensor", out=tmp_path / "fig"
    )
    assert not res.refused, res.reason
    assert sum(res.probabilities.values()) == pytest.approx(1.0)
    assert res.label == max(res.probabilities, key=res.probabilities.get)
    if res.label != "healthy":
        lo, hi = res.severity_interval
        assert lo <= res.severity <= hi
    assert res.evidence["closest_record"]["label"] == res.label
    assert res.evidence["impacts_per_rev"] >= 0
    from matplotlib.image import imread

    img = imread(res.figure)
    assert img.shape[0] > 100 and img.std() > 0  # a drawn figure, not a blank one


def test_diagnose_refuses_another_speed_range(tmp_path):
    from recipdyn.cli import main
    from recipdyn.diagnosis.diagnose import diagnose

    path = _record(tmp_path, "fast", params={"omega": 40.0})
    res = diagnose(path, tacho="tacho")
    assert res.refused and "crank speed" in res.reason and "training range" in res.reason
    assert main(["diagnose", str(path), "--tacho", "tacho"]) == 2


def test_diagnose_refuses_another_sensor_band(tmp_path):
    """A mounting resonance at 1.2 kHz (the training set's lie at 3-4.5 kHz): the impacts
    ring there, outside the training sensor band. (The distance over all features does not
    see it: the spectral features move by less than the conditions spread them.)"""
    from recipdyn.diagnosis.diagnose import diagnose

    path = _record(tmp_path, "band", resonance_hz=1200.0)
    res = diagnose(path, tacho="tacho", p_head="p_head_sensor", p_crank="p_crank_sensor")
    assert res.refused and "sensor band" in res.reason


def test_shipped_diagnoser_matches_todays_physics():
    """Regenerate the records the shipped diagnoser pinned (same tasks, same seeds) with
    today's code: the features and the diagnoser's probabilities must be those stored. Fails
    when the physics (model, sensors, features) moved away from the data the diagnoser was
    trained on: then rebuild it ('make diagnoser'). Tolerances: the runs are deterministic;
    across machines the impacts' rounding differs, so the features are compared to 2 % (their
    spread over the held-out noise seeds is larger) and the probabilities to 0.05."""
    import json

    from recipdyn.diagnosis.dataset import make_record
    from recipdyn.diagnosis.diagnose import default_model_path
    from recipdyn.diagnosis.train import load

    diag = load(default_model_path())
    pins = json.loads(diag.state["fingerprints_json"])
    assert len(pins) == 3
    for pin in pins:
        res = make_record(pin["task"])
        assert not res["error"], res["error"]
        for k in (
            "acc_rms",
            "acc_order_1",
            "acc_order_2",
            "ph_ratio",
            "pc_ratio",
            "ph_rise_50",
            "ph_fall_50",
            "cy_head_n_exp",
            "cy_crank_work",
        ):
            assert res["features"][k] == pytest.approx(pin["features"][k], rel=0.02), k
        x = np.array([[res["features"][n] for n in diag.names]])
        assert diag.predict_proba(x)[0] == pytest.approx(pin["proba"], abs=0.05)


def test_cli_refuses_bad_settings_in_one_line(capsys):
    from recipdyn.cli import main

    assert main(["dataset", "--conditions", "1", "-o", "unused-folder"]) == 2
    assert main(["diagnose", "missing.csv"]) == 2  # neither --speed nor --tacho
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "n_conditions" in err[0] and "speed and tacho" in err[1]


def test_dask_backend_gives_the_serial_records_to_the_bit(tmp_path):
    pytest.importorskip("dask.distributed")
    spec = DatasetSpec(n_conditions=2, levels=(1.0,), classes=("healthy", "ring_leak"),
                       test_fraction=0.5, seed=3)  # fmt: skip
    a = build_dataset(tmp_path / "d", spec, backend="dask", dask_local=1, progress=False)
    b = build_dataset(tmp_path / "s", spec, backend="serial", progress=False)
    assert read_features(a)[0].equals(read_features(b)[0])


def test_boosting_runs_on_one_thread_even_when_scikit_learn_is_not_yet_loaded():
    """scikit-learn's boosting spins its OpenMP threads at every barrier: on busy cores a
    small model's fit or prediction waits for a descheduled thread (a notebook's training
    took over 20 CPU-minutes instead of seconds beside another busy process). threadpoolctl
    limits only the runtimes already loaded, so `one_thread` must load scikit-learn's first:
    checked in a fresh interpreter, where nothing has loaded it yet."""
    import json
    import os
    import subprocess
    import sys

    probe = ("import json\nfrom threadpoolctl import threadpool_info\n"
             "from recipdyn.diagnosis.train import one_thread\n"
             "with one_thread():\n"
             "    omp = [i['num_threads'] for i in threadpool_info()\n"
             "           if i['user_api'] == 'openmp']\n"
             "print(json.dumps(omp))\n")  # fmt: skip
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path), "OMP_NUM_THREADS": "2"}
    done = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True,
                          text=True, timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    omp = json.loads(done.stdout.strip().splitlines()[-1])
    assert omp and all(n == 1 for n in omp), omp


def test_a_missing_pressure_channel_gives_no_pin_load_reversals():
    """Without a chamber pressure the crosshead-pin load is unknown: the reversal features are
    NaN (they counted every degree as a reversal, 360, and looked like evidence). With both
    pressures of an ideal cycle the load reverses an even number of times a revolution."""
    from recipdyn.diagnosis.evidence import cycle_features

    th = np.radians(np.arange(360.0))
    ph = 2e5 + 1e5 * np.cos(th)
    pc = 2e5 - 1e5 * np.cos(th)
    e = np.ones(360)
    full = cycle_features(ph, pc, e, 3.0)
    assert full["cy_reversals"] >= 2 and full["cy_reversals"] % 2 == 0
    for missing in ((np.full(360, np.nan), pc), (ph, np.full(360, np.nan))):
        row = cycle_features(*missing, e, 3.0)
        for k in ("cy_reversals", "cy_energy_after_reversal", "cy_peak_after_reversal_deg"):
            assert math.isnan(row[k]), k


def test_deciding_features_are_the_subsets_and_their_z_is_bounded():
    """The shipped diagnoser's deciding features: a record at the healthy training median but
    one pin-load reversal more (a feature the healthy records hold constant) gets a finite z
    of 1 / HEALTHY_SPREAD_FLOOR training scales (it was 1e12 with a zero spread); with the
    pressure channels missing, no pressure or cycle feature is among them (the classifier
    of that subset does not read them)."""
    from recipdyn.diagnosis.diagnose import HEALTHY_SPREAD_FLOOR, _deciding, default_model_path
    from recipdyn.diagnosis.train import load

    diag = load(default_model_path())
    st = diag.state
    healthy = np.array([lab == "healthy" for lab in st["train_labels"]])
    Z = st["Z_train"].astype(float)[healthy]
    row = st["center"] + np.nanmedian(Z, axis=0) * st["scale"]
    i = diag.names.index("cy_reversals")
    assert np.ptp(Z[:, i]) == 0  # constant in the healthy records: the case of the floor
    row[i] += st["scale"][i]
    top = dict(_deciding(diag, row))
    assert top["cy_reversals"] == pytest.approx(1.0 / HEALTHY_SPREAD_FLOOR)
    no_p = row.copy()
    no_p[[k for k, n in enumerate(diag.names) if n.startswith(("cy_", "ph_", "pc_"))]] = np.nan
    no_p[diag.names.index("acc_skewness")] += 3 * st["scale"][diag.names.index("acc_skewness")]
    names = [n for n, _ in _deciding(diag, no_p)]
    assert names and not any(n.startswith(("cy_", "ph_", "pc_")) for n in names)
