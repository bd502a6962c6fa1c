"""recipdyn.diagnosis.machine: a diagnoser belongs to one machine (docs/diagnosis.md).

What is tested: machine files read into (model, values); the default machine leaves every
data set as it was; another machine's operating ranges, fault values and healthy pins are
re-derived from it; a parameter outside the machine's is refused; the tolerances' comparison;
one tolerance against the physics it was measured from; and `diagnose` refusing a record of
another machine (given by the user's machine file or by the record's own parameters) with the
commands that build a diagnoser for it.
"""

from __future__ import annotations

import math

import pytest

from recipdyn.diagnosis.classes import BASELINE, CLASSES, CONDITIONS
from recipdyn.diagnosis.dataset import DatasetSpec, design
from recipdyn.errors import ParameterError


def _dump(tmp_path, name, *sets):
    from recipdyn.cli import main

    path = tmp_path / name
    args = ["simulate", "--model", "compressor-contact-valves"]
    for s in sets:
        args += ["--set", s]
    assert main([*args, "--dump-config", str(path)]) == 0
    return path


def test_a_machine_file_reads_into_its_model_and_values(tmp_path):
    """A config as ``simulate --dump-config`` writes it is a machine file: its model and its
    validated values (SI), and the machine taken from them (only the machine's parameters:
    the file's own crank-pin clearance, a fault parameter, is not the machine's)."""
    from recipdyn.diagnosis.machine import Machine, machine_from_file, read_machine

    path = _dump(tmp_path, "m.toml", "bore=300 mm", "r=90 mm", "rc=0.5 mm", "omega=200 rpm")
    model, values = read_machine(path)
    assert model.name == "compressor-contact-valves"
    assert values["bore"] == pytest.approx(0.3) and values["rc"] == pytest.approx(5e-4)
    m = machine_from_file(path)
    assert dict(m.changes()) == pytest.approx(
        {"bore": 0.3, "r": 0.09, "omega": 200 * 2 * math.pi / 60}
    )
    assert m.source == str(path)
    assert Machine.default().is_default and not m.is_default
    # what the file says is the machine, a value the model would otherwise derive included
    # (the rod's centroid, half its length when not given): the data set simulates it
    rod = machine_from_file(_dump(tmp_path, "rod.toml", "l=450 mm", "ls=300 mm"))
    assert rod["ls"] == pytest.approx(0.3) and Machine.of({"l": 0.45})["ls"] == pytest.approx(0.225)
    spec = DatasetSpec(n_conditions=3, levels=(1.0,), classes=("healthy",), machine=rod.pairs())
    assert all(t["params"]["ls"] == pytest.approx(0.3) for t in design(spec))
    with pytest.raises(ParameterError, match="machine .*unknown format"):
        read_machine(tmp_path / "m.csv")
    with pytest.raises(ParameterError, match="file not found"):
        read_machine(tmp_path / "none.toml")


def test_the_default_machine_leaves_the_data_set_as_it_was():
    """No machine: the spec's identity, the condition ranges, the fault classes and the healthy
    pins are those of before (the shipped diagnoser's pinned records are checked to the bit by
    test_diagnosis.py::test_shipped_diagnoser_matches_todays_physics)."""
    from recipdyn.diagnosis.machine import (
        Machine,
        condition_ranges,
        fault_classes,
        healthy_parameters,
    )

    assert "machine" not in DatasetSpec().to_json()
    d = Machine.default()
    assert condition_ranges(d) is CONDITIONS and condition_ranges(None) is CONDITIONS
    assert fault_classes(d) == tuple(CLASSES) and healthy_parameters(d) == BASELINE
    assert all("machine" not in t for t in design(DatasetSpec(n_conditions=3)))


def test_another_machine_re_derives_its_ranges_fault_values_and_healthy_pins():
    """Twice the speed, a 250 mm bore, a 60 kg crosshead, a 100 mm crank pin, a 10 N valve
    preload: the speed and mass ranges scale with them (the same relative spread), a valve
    leak with the valve's flow area (bore squared), the rings' leak with the bore, the plate's
    stiction with the preload, the crank-pin clearances (faulty and healthy) with its radius;
    the line pressures, the sensor's ranges and the spring factor stay."""
    from recipdyn.diagnosis.machine import Machine, condition_ranges, fault_classes

    m = Machine.of(
        {"omega": 40.0, "bore": 0.25, "m3": 60.0, "journal_radius": 0.1, "valve_preload": 10.0}
    )
    r = condition_ranges(m)
    assert (r["omega"].lo, r["omega"].hi) == pytest.approx((32.0, 48.0))
    assert (r["m3"].lo, r["m3"].hi) == pytest.approx((54.0, 66.0))
    for k in ("suction_pressure", "discharge_pressure", "m2", "resonance_hz", "fs"):
        assert r[k] is CONDITIONS[k]
    base = {c.name: c for c in CLASSES}
    scale = {"suction_valve_leak": 0.25, "discharge_valve_leak": 0.25, "ring_leak": 0.5,
             "sticking_valve": 2.0, "crank_pin_clearance": 2.0, "weak_valve_spring": 1.0,
             "crosshead_pin_clearance": 1.0, "crosshead_guide_clearance": 1.0}  # fmt: skip
    for c in fault_classes(m):
        if c.parameter:
            f = scale[c.name]
            assert (c.mild, c.severe) == pytest.approx(
                (base[c.name].mild * f, base[c.name].severe * f)
            )
    spec = DatasetSpec(n_conditions=3, levels=(1.0,), classes=("healthy", "ring_leak"),
                       machine=m.pairs())  # fmt: skip
    tasks = design(spec)
    assert all(t["machine"] == dict(m.pairs()) for t in tasks)
    assert all(t["params"]["bore"] == 0.25 and t["params"]["rc"] == pytest.approx(2e-4)
               for t in tasks)  # fmt: skip
    assert all(32.0 <= t["params"]["omega"] <= 48.0 for t in tasks)
    ring = next(t for t in tasks if t["label"] == "ring_leak")
    assert ring["params"]["ring_leak_area"] == pytest.approx(1e-4)  # 2 cm2 x 0.5
    assert '"machine"' in spec.to_json()
    assert DatasetSpec.from_dict(__import__("json").loads(spec.to_json())) == spec


@pytest.mark.parametrize(
    "machine, word",
    [({"rc": 1e-3}, "fault"), ({"theta1_0": 1.0}, "not a machine parameter"), (5, "pairs")],
)
def test_a_spec_refuses_what_is_not_the_machine(machine, word):
    with pytest.raises(ParameterError, match=word):
        DatasetSpec(machine=machine)


def test_differences_follow_the_tolerances_and_the_drawn_ranges():
    """Within a parameter's tolerance the machine is the same; beyond it, named with its value,
    the diagnoser's and the tolerance; a drawn parameter (the crosshead's mass, 27-33 kg) may
    lie anywhere in its range widened by its tolerance; a name (the gas) must be equal."""
    from recipdyn.diagnosis.machine import TOLERANCES, Machine, differences, drawn_ranges

    d = Machine.default()
    drawn = drawn_ranges(d)
    assert drawn["m3"] == pytest.approx((27.0, 33.0))
    tol_r, tol_m3 = TOLERANCES["r"].relative, TOLERANCES["m3"].relative
    assert differences(d, Machine.of({"r": 0.12 * (1 + 0.5 * tol_r)}), drawn) == []
    far = differences(d, Machine.of({"r": 0.12 * (1 + 2 * tol_r)}), drawn)
    assert len(far) == 1 and far[0].startswith("r = ") and "tolerance" in far[0]
    assert differences(d, Machine.of({"m3": 33.0 * (1 + 0.9 * tol_m3)}), drawn) == []
    assert differences(d, Machine.of({"m3": 33.0 * (1 + 1.1 * tol_m3)}), drawn)
    assert differences(d, Machine.of({"gas": "Nitrogen"}), drawn) == [
        "gas = Nitrogen (the diagnoser's: ideal)"
    ]
    # the nominal operating point: inside the drawn ranges (2.7-3.3 bar, 16-24 rad/s) or not
    assert differences(d, Machine.of({"discharge_pressure": 3.3e5, "omega": 16.0}), drawn) == []
    six = differences(d, Machine.of({"discharge_pressure": 6e5}), drawn)
    assert six == ["discharge_pressure = 6e+05 (nominal; the diagnoser's range: 2.7e+05..3.3e+05)"]
    assert set(TOLERANCES) | {"acting", "gas"} == set(
        __import__("recipdyn.diagnosis.machine", fromlist=["x"]).MACHINE_PARAMETERS
    )


def test_the_clearance_volume_tolerance_is_one_healthy_spread_of_its_feature():
    """The tolerance of the clearance volume was measured as the change that moves its most
    sensitive feature (the crank end's suction-opening angle against the ideal cycle) by one
    healthy spread. Paired records (the same condition and sensor noise, the clearance volume
    alone changed): at a third of the tolerance the feature moves by less than one spread,
    at three times it by more than two (the slope is linear over this 1 % change; the
    tolerance came from the slope's lower 2-standard-error bound, so the shift at 3 tol is at
    least 3 and at most 3 |slope| / lower bound, which 6 bounds for this precise slope)."""
    from recipdyn.diagnosis import default_model_path, load
    from recipdyn.diagnosis.dataset import make_record
    from recipdyn.diagnosis.machine import TOLERANCES, healthy_spreads

    diag = load(default_model_path())
    tol = TOLERANCES["clearance_fraction"]
    s = healthy_spreads(diag)[tol.feature]
    task = next(
        t
        for t in design(DatasetSpec.from_dict(diag.card["spec"]))
        if t["split"] == "test" and t["label"] == "healthy"
    )
    f0 = make_record(task)["features"][tol.feature]
    shift = {}
    for k in (1 / 3, 3.0):
        params = dict(task["params"], clearance_fraction=0.1 * (1 + k * tol.relative))
        shift[k] = abs(make_record(dict(task, params=params))["features"][tol.feature] - f0) / s
    assert shift[1 / 3] < 1.0
    assert 2.0 < shift[3.0] < 6.0


def _record(tmp_path, name, **params):
    """A sensed 4-revolution healthy record of the shipped diagnoser's first held-out
    condition, with ``params`` changed (the record keeps its parameters in its attributes)."""
    from recipdyn.diagnosis import default_model_path, load
    from recipdyn.diagnosis.dataset import simulate_record

    spec = DatasetSpec.from_dict(load(default_model_path()).card["spec"])
    task = next(t for t in design(spec) if t["split"] == "test" and t["label"] == "healthy")
    task = dict(task, revolutions=4.0, params=dict(task["params"], **params))
    path = tmp_path / f"{name}.nc"
    simulate_record(task).to_netcdf(path)
    return path


def test_diagnose_refuses_a_record_of_another_machine_and_says_how_to_build_one(tmp_path):
    """A simulated record carries its parameters: a 90 mm crank (the diagnoser's: 120 mm) is
    refused without a machine file, naming the parameter and giving the commands that build a
    diagnoser for that machine from the record itself; the CLI exits 2 in one line. The same
    machine is answered; a user's machine file names the machine whatever the record's
    attributes say (its own acceleration is still fingerprinted: test_diagnosis_fingerprint)."""
    from recipdyn.cli import main
    from recipdyn.diagnosis.diagnose import diagnose

    kw = {"tacho": "tacho", "p_head": "p_head_sensor", "p_crank": "p_crank_sensor"}
    other = _record(tmp_path, "short_crank", r=0.09)
    res = diagnose(other, **kw)
    assert res.refused and res.reason.startswith("another machine")
    assert "r = 0.09 (the diagnoser's: 0.12" in res.reason
    assert f"recipdyn dataset --machine {other}" in res.reason
    assert "--conditions 40 --severity-range 0.25,1 --draws 4 --snr-range 10,40" in res.reason
    assert "recipdyn train" in res.reason
    assert main(["diagnose", str(other), "--tacho", "tacho"]) == 2

    same = _record(tmp_path, "same")
    assert not diagnose(same, **kw).reason.startswith("another machine")
    theirs = _dump(tmp_path, "theirs.toml", "bore=300 mm")
    res = diagnose(same, machine=theirs, **kw)
    assert res.refused and "bore = 0.3 (the diagnoser's: 0.5" in res.reason
    assert f"--machine {theirs}" in res.reason
    # the user's file is read instead of the record's attributes (their check passes), but
    # the record's own crosshead acceleration still shows a 90 mm crank (fingerprint.py)
    mine = _dump(tmp_path, "mine.toml")
    res = diagnose(other, machine=mine, **kw)
    assert res.reason.startswith("another machine (its crosshead acceleration's crank orders)")
    assert "r = 0.09" not in res.reason
