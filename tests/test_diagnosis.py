"""recipdyn.diagnosis: data sets, diagnosers and the diagnosis of a record (docs/diagnosis.md).

Everything runs at reduced size (a few conditions, one severity level, three classes), so the
claims tested are the machinery's (splits, determinism, resumption, refusals, calibration
bookkeeping), not the accuracy of a full-size diagnoser (docs/diagnosis.md measures that).
"""

from __future__ import annotations

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
