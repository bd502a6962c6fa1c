"""A class is named only with the channels that can show it (recipdyn.diagnosis.channels)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from recipdyn.diagnosis.channels import (
    ANSWERS_MIN,
    CONFIDENCE,
    PRECISION_MIN,
    gate,
    naming_table,
    selective_threshold,
)

CLASSES = ["healthy", "ring_leak", "sticking_valve"]


def _table():
    """Held-out answers of a channel set: 20 healthy records (18 answered healthy, 2 ring
    leak), 20 ring leaks (all right), 20 sticking plates, 10 of them below the detection
    limit 0.5 and answered healthy, 10 above: 5 right, 5 answered ring leak."""
    labels = ["healthy"] * 20 + ["ring_leak"] * 20 + ["sticking_valve"] * 20
    pred = ["healthy"] * 18 + ["ring_leak"] * 2 + ["ring_leak"] * 20
    pred += ["healthy"] * 10 + ["sticking_valve"] * 5 + ["ring_leak"] * 5
    sev = [0.0] * 20 + [0.8] * 20 + [0.3] * 10 + [0.8] * 10
    detection = {"ring_leak": {"limit_severity": 0.25}, "sticking_valve": {"limit_severity": 0.5}}
    return naming_table(labels, pred, sev, CLASSES, detection)


def test_precision_counts_what_each_answer_was():
    """By hand: 'healthy' answered 28 times, 10 of them mild sticking plates below their
    detection limit (set aside: the channels cannot see them) -> 18 of 18; 'ring_leak' 27
    times, 20 right -> 0.74 (a sticking plate above its limit answered as a leak is wrong,
    and so is a healthy record); 'sticking_valve' 5 of 5 right but too few answers."""
    t = _table()
    c = t["classes"]
    assert c["healthy"]["precision"] == 1.0 and c["healthy"]["set_aside"] == 10
    assert c["healthy"]["recall"] == pytest.approx(18 / 20)
    assert c["ring_leak"]["precision"] == pytest.approx(20 / 27)
    assert c["ring_leak"]["set_aside"] == 0
    assert c["ring_leak"]["behind"][0] == ["ring_leak", 20]
    assert c["sticking_valve"]["precision"] == 1.0 and c["sticking_valve"]["answers"] == 5
    assert t["accuracy"] == pytest.approx((18 + 20 + 5) / 60)


def test_a_class_is_named_only_where_its_answers_were_right():
    t = {"no_pressure": _table()}
    assert ANSWERS_MIN > 5 and PRECISION_MIN > 20 / 27
    named, why, facts = gate(t, "no_pressure", "healthy")
    assert named and facts["precision"] == 1.0 and "tacho" in facts["channels"]
    named, why, _ = gate(t, "no_pressure", "ring_leak")
    assert not named and "74%" in why and "cannot tell apart" in why and "pressure" in why
    named, why, _ = gate(t, "no_pressure", "sticking_valve")
    assert not named and "too few answers" in why


def test_a_diagnoser_without_a_table_names_with_all_channels_only():
    assert gate(None, "full", "ring_leak")[0]
    named, why, _ = gate(None, "vibration_only", "ring_leak")
    assert not named and "retrain" in why and "tacho" in why


def test_the_shipped_diagnosers_channel_sets():
    """The shipped (drawn-chain) diagnoser's table, measured on its 350 held-out records:
    with every channel the classes whose held-out precision reaches the gate are named at
    any p, all but the worn crosshead pin (0.83: taken for the crank pin; its answers reach
    0.9 at no threshold) and the sticking plate (0.79: healthy records and weak springs taken
    for it, all at p <= 0.952), which is named at p >= 0.957 (27 answers of 27 right there);
    without pressure no valve or ring fault is named, at any p (a worn crank pin at p >=
    0.853: 34 of 34); with a speed only, no class at all (its accuracy there: 0.323)."""
    from recipdyn.diagnosis.diagnose import default_model_path, naming_of
    from recipdyn.diagnosis.train import load

    diag = load(default_model_path())
    table = naming_of(diag)
    assert table["full"]["accuracy"] == pytest.approx(0.906, abs=1e-3)
    named = {c for c in diag.classes if gate(table, "full", c)[0]}  # no p: the whole precision
    assert named == set(diag.classes) - {"crosshead_pin_clearance", "sticking_valve"}
    assert {c for c in diag.classes if gate(table, "full", c, 0.5)[0]} == named
    sure = {c for c in diag.classes if gate(table, "full", c, 1.0)[0]}
    assert sure == set(diag.classes) - {"crosshead_pin_clearance"}
    sel = selective_threshold(table["full"]["classes"]["sticking_valve"])
    assert sel["threshold"] == pytest.approx(0.957, abs=1e-3) and sel["answers"] == 27
    assert sel["right"] == 27
    assert selective_threshold(table["full"]["classes"]["crosshead_pin_clearance"])[
        "threshold"
    ] is None  # fmt: skip
    valves = ["suction_valve_leak", "discharge_valve_leak", "weak_valve_spring",
              "sticking_valve", "ring_leak"]  # fmt: skip
    assert not any(gate(table, "no_pressure", c, 1.0)[0] for c in valves)
    assert not any(gate(table, "vibration_only", c, 1.0)[0] for c in diag.classes)
    for k in table:
        prec = [e["precision"] for e in table[k]["classes"].values()]
        assert all(math.isnan(p) or 0 <= p <= 1 for p in prec)
        for e in table[k]["classes"].values():  # the answers kept are those counted
            assert len(e["p"]) == len(e["right"]) == e["answers"]
            if e["answers"]:
                assert sum(e["right"]) / e["answers"] == pytest.approx(e["precision"])


def test_a_speed_only_record_is_refused_with_what_would_tell(tmp_path):
    """The issue's example: a healthy record with a speed only was called a worn guide at
    p 0.88 with no caveat (that channel set's held-out accuracy: 0.375). Now it is refused,
    saying how often that answer was right and which channels to add; the probabilities
    are kept."""
    from _records import healthy_run, sensed
    from recipdyn.diagnosis.diagnose import diagnose_arrays

    ds, task = healthy_run()
    s = sensed(ds, task)
    res = diagnose_arrays(s["x"], s["fs"], speed_hz=task["params"]["omega"] / (2 * np.pi))
    assert res.refused, res.probabilities
    assert "cannot tell apart" in res.reason and "tacho" in res.reason
    assert sum(res.probabilities.values()) == pytest.approx(1.0)
    assert res.evidence["channels"]["subset"] == "vibration_only"


# ---- the selective gate: a class named above a confidence threshold ----------------------


def _wilson_lower(k: int, n: int) -> float:
    """Wilson's one-sided lower bound, written out (an implementation independent of
    scipy's): (p + z^2/2n - z sqrt(p(1-p)/n + z^2/4n^2)) / (1 + z^2/n)."""
    from statistics import NormalDist

    z = NormalDist().inv_cdf(CONFIDENCE)
    p = k / n
    return (p + z * z / (2 * n) - z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))) / (
        1 + z * z / n
    )


def _entry(right: list[int]) -> dict:
    """A class's held-out answers, highest p first: p = 0.99, 0.98, ... (one per answer)."""
    p = [round(0.99 - 0.01 * i, 6) for i in range(len(right))]
    return {"p": p, "right": right, "answers": len(right),
            "precision": sum(right) / len(right)}  # fmt: skip


def test_the_threshold_is_where_the_lower_bound_reaches_the_gate():
    """56 answers: 40 right (p 0.99..0.60), one wrong, 5 right, 10 wrong: 45 of 56 (0.80)
    as a whole. The precision above a threshold first reaches 0.9 at the 50th answer (45 of
    50; that point estimate is what a threshold chosen on these answers would take); the
    Wilson bound at 95 % reaches 0.9 only down to the 46th (45 of 46: 0.908; 45 of 47:
    0.879), so t_c is the 46th answer's p, 0.54."""
    right = [1] * 40 + [0] + [1] * 5 + [0] * 10
    e = _entry(right)
    assert _wilson_lower(45, 46) >= PRECISION_MIN > _wilson_lower(45, 47)
    assert 45 / 50 >= PRECISION_MIN  # the optimistic choice would go down to 0.50
    sel = selective_threshold(e)
    assert sel["threshold"] == pytest.approx(e["p"][45]) == pytest.approx(0.54)
    assert (sel["answers"], sel["right"]) == (46, 45)
    assert sel["lower"] == pytest.approx(_wilson_lower(45, 46), abs=1e-9)
    t = {"full": {"accuracy": 0.8, "n": 56, "classes": {"sticking_valve": e}}}
    named, why, facts = gate(t, "full", "sticking_valve", 0.54)
    assert named and facts["confidence"]["threshold"] == pytest.approx(0.54)
    named, why, facts = gate(t, "full", "sticking_valve", 0.53)
    assert not named and "p >= 0.540" in why and "p 0.530" in why
    assert facts["confidence"]["answers"] == 46 and facts["confidence"]["precision"] == 45 / 46


def test_few_answers_above_a_threshold_do_not_vouch_for_it():
    """12 answers right at p 0.99..0.88, then 10 wrong: above p 0.88 the precision is 1 on
    12 answers (>= ANSWERS_MIN, so the point estimate would name the class), but the lower
    bound is 12 / (12 + z^2) = 0.82: no threshold, refused even at p 0.999, saying the
    closest. With 30 answers right (bound 0.917) the same shape is named above 0.70."""
    e = _entry([1] * 12 + [0] * 10)
    assert 12 >= ANSWERS_MIN and _wilson_lower(12, 12) < PRECISION_MIN
    sel = selective_threshold(e)
    assert sel["threshold"] is None and sel["closest"] == pytest.approx(0.88)
    t = {"full": {"accuracy": 0.5, "n": 22, "classes": {"ring_leak": e}}}
    named, why, _ = gate(t, "full", "ring_leak", 0.999)
    assert not named and "at no confidence threshold" in why and "12 of 12" in why
    e = _entry([1] * 30 + [0] * 10)
    assert _wilson_lower(30, 30) >= PRECISION_MIN
    assert selective_threshold(e)["threshold"] == pytest.approx(0.70)


def test_tied_probabilities_are_taken_together():
    """30 right and 5 wrong answers all at p 1.0 (then nothing): a threshold takes every
    answer at its p, so 30 of 35 (0.86) is all there is above 1.0: no threshold."""
    e = {"p": [1.0] * 35, "right": [1] * 30 + [0] * 5, "answers": 35, "precision": 30 / 35}
    assert selective_threshold(e)["threshold"] is None


def test_a_class_precise_as_a_whole_keeps_threshold_zero():
    """Precision >= 0.9 on >= 10 answers as a whole: threshold 0, named at any p (the gate as
    it was), although its Wilson bound (27 of 30: 0.77) is below 0.9."""
    e = _entry([1] * 27 + [0] * 3)
    sel = selective_threshold(e)
    assert sel["threshold"] == 0.0 and sel["lower"] < PRECISION_MIN
    t = {"full": {"accuracy": 0.9, "n": 30, "classes": {"healthy": e}}}
    assert gate(t, "full", "healthy", 0.2)[0] and gate(t, "full", "healthy")[0]


def test_a_class_whose_answers_never_reach_the_gate_stays_refused():
    """Right and wrong answers alternating at every p: the precision above any threshold is
    about 0.5; refused at p 1.0, saying it reached the gate at no threshold."""
    e = _entry([1, 0] * 20)
    assert selective_threshold(e)["threshold"] is None
    t = {"full": {"accuracy": 0.5, "n": 40, "classes": {"sticking_valve": e}}}
    named, why, facts = gate(t, "full", "sticking_valve", 1.0)
    assert not named and "at no confidence threshold" in why and "confidence" not in facts


def test_a_table_without_probabilities_keeps_the_whole_precision_gate():
    """A stored table of a diagnoser trained before the answers' probabilities were kept
    (no ``p``): a class short of 0.9 as a whole stays refused at any p, as before."""
    t = {"no_pressure": _table()}
    assert "p" not in t["no_pressure"]["classes"]["ring_leak"]
    assert selective_threshold(t["no_pressure"]["classes"]["ring_leak"]) is None
    named, why, facts = gate(t, "no_pressure", "ring_leak", 1.0)
    assert not named and "74%" in why and "confidence" not in facts


def test_the_table_keeps_each_counted_answers_p_highest_first():
    """`naming_table` given the top probabilities keeps, per class, those of its counted
    answers (the 10 mild sticking plates answered healthy are set aside: not kept), highest
    first, with whether each was right."""
    labels = ["healthy"] * 20 + ["ring_leak"] * 20 + ["sticking_valve"] * 20
    pred = ["healthy"] * 18 + ["ring_leak"] * 2 + ["ring_leak"] * 20
    pred += ["healthy"] * 10 + ["sticking_valve"] * 5 + ["ring_leak"] * 5
    sev = [0.0] * 20 + [0.8] * 20 + [0.3] * 10 + [0.8] * 10
    top = np.linspace(0.41, 0.999, 60)
    detection = {"ring_leak": {"limit_severity": 0.25}, "sticking_valve": {"limit_severity": 0.5}}
    c = naming_table(labels, pred, sev, CLASSES, detection, top=top)["classes"]
    assert len(c["healthy"]["p"]) == 18 and c["healthy"]["right"] == [1] * 18
    assert c["healthy"]["p"] == sorted(np.round(top[:18], 6).tolist(), reverse=True)
    ring = c["ring_leak"]
    assert len(ring["p"]) == 27 and sum(ring["right"]) == 20
    assert ring["p"] == sorted(ring["p"], reverse=True)
    # the 5 sticking plates answered ring_leak had the highest p: they lead, all wrong
    assert ring["right"][:5] == [0] * 5


def _sticking_record(severity: float):
    """A 4-revolution record of the shipped diagnoser's held-out sticking plate at condition
    33 (its data set's record 1217, drawn chain and noise seed as built), at ``severity``."""
    from recipdyn.diagnosis.dataset import DatasetSpec, design, simulate_record
    from recipdyn.diagnosis.diagnose import default_model_path
    from recipdyn.diagnosis.train import load

    diag = load(default_model_path())
    task = next(t for t in design(DatasetSpec.from_dict(diag.card["spec"])) if t["index"] == 1217)
    assert task["split"] == "test" and task["label"] == "sticking_valve"
    task = dict(task, revolutions=4.0)
    value = diag.fault_class("sticking_valve").value(severity)
    task["params"] = dict(task["params"], adhesion_force_suction_head=value)
    return simulate_record(task), task["fs"]


@pytest.mark.parametrize("severity", [0.855, 0.1])
def test_the_shipped_diagnoser_names_a_sure_sticking_plate_and_refuses_an_unsure_one(severity):
    """The shipped diagnoser's sticking plate was never named before (held-out precision
    0.79 < 0.9); now it is named above its threshold 0.957. A held-out condition's sticking
    plate at its drawn severity 0.855: p 0.99999 (measured), named. The same plate at
    severity 0.1 (milder than its detection limit): still the top class, at p 0.82
    (measured), below the threshold: refused, saying the threshold and the record's p. The
    margins (4e-2 and 0.14 in p) are far above what another CPU changes in a 4-revolution
    record."""
    from recipdyn.diagnosis.diagnose import diagnose_arrays

    rec, fs = _sticking_record(severity)
    res = diagnose_arrays(rec["accel_guide"].values, fs, tacho=rec["tacho"].values,
                          p_head=rec["p_head_sensor"].values,
                          p_crank=rec["p_crank_sensor"].values)  # fmt: skip
    p = res.probabilities
    assert max(p, key=p.get) == "sticking_valve"
    conf = res.evidence["channels"]["confidence"]
    assert conf["threshold"] == pytest.approx(0.957, abs=1e-3)
    # its 4 pulses hold 3 revolutions, 2 whole once the crank-angle correction has moved
    # its start 0.7 degrees past the first pulse (measured): one window of the data set's 2,
    # scored whole (windows.py)
    assert "windows" not in res.evidence
    assert conf["p"] == pytest.approx(p["sticking_valve"])
    from recipdyn.app.diagnosis import evidence_rows  # the page says it too

    shown = dict((r[0], r[1]) for r in evidence_rows(res.evidence))["channels the answer rests on"]
    assert f"threshold p 0.957 (this record {conf['p']:.3f})" in shown
    if severity > 0.5:
        assert not res.refused and res.label == "sticking_valve", res.reason
        assert p["sticking_valve"] > 0.99
    else:
        assert res.refused and 0.5 < p["sticking_valve"] < 0.92
        assert "p >= 0.957" in res.reason and f"p {p['sticking_valve']:.3f}" in res.reason


def test_a_long_record_is_named_only_where_each_window_of_the_data_sets_length_would_be():
    """A record longer than the data set's (2 revolutions) makes the classifier surer than
    the held-out records its thresholds were measured on; so it is scored on its windows of
    2 revolutions (windows.py) and the gate reads the lowest window's p. Hypothesis: each
    window is scored as the same stretch would be as a record of its own. The healthy run
    (4 whole revolutions between its 5 tacho pulses), sensed by the data set's chain, is cut
    at its tacho pulses into 2-revolution records, each diagnosed whole (the path of the
    data set's own records): every window's p of the class named lies within 0.02 of one
    of theirs. The difference is the crank-angle fit and the chain correction read over 2
    revolutions instead of 4 (measured 0.0013 and 0.0002 on the first two); 0.02 is 15
    times that. So the gate's p is no higher than the cut records', whose answers the
    held-out table vouches for."""
    from _records import healthy_run, sensed
    from recipdyn.analysis.vibration import tacho_times
    from recipdyn.diagnosis.diagnose import diagnose_arrays

    ds, task = healthy_run()
    s = sensed(ds, task)
    ch = (s["x"], s["tacho"], s["p_head_sensor"], s["p_crank_sensor"])
    res = diagnose_arrays(ch[0], s["fs"], tacho=ch[1], p_head=ch[2], p_crank=ch[3])
    assert not res.refused and res.label == "healthy", res.reason
    win = res.evidence["windows"]
    assert win["revolutions"] == 2 and win["n"] >= 2
    assert res.probabilities["healthy"] == pytest.approx(np.mean(win["p"]))
    from recipdyn.app.diagnosis import evidence_rows  # the answer and the page say so

    assert f"scored on {win['n']} windows of 2 revolutions" in res.text()
    shown = dict((r[0], r[1]) for r in evidence_rows(res.evidence))
    assert shown["windows of the data set's length"].startswith(f"{win['n']} windows of 2 ")
    edges = tacho_times(s["tacho"], s["fs"])
    cut_p = []
    for i in range(edges.size - 2):  # a little before the first pulse to after the third
        i0 = int(edges[i] * s["fs"]) - 20
        i1 = int(edges[i + 2] * s["fs"]) + 20
        r = diagnose_arrays(ch[0][i0:i1], s["fs"], tacho=ch[1][i0:i1],
                            p_head=ch[2][i0:i1], p_crank=ch[3][i0:i1])  # fmt: skip
        assert "windows" not in r.evidence  # a record of the data set's length: whole
        cut_p.append(r.probabilities["healthy"])
    for p in win["p"]:
        assert min(abs(p - q) for q in cut_p) < 0.02, (win["p"], cut_p)
