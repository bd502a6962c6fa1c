"""A simulated record of the shipped diagnoser's domain, sensed through its data set's chain
with one change (``tests/test_correction.py``, ``tests/test_channels.py``). Not a test module
(no ``test_`` prefix): pytest puts this folder on ``sys.path``."""

from __future__ import annotations

import functools
import math
import warnings

import numpy as np


@functools.lru_cache(maxsize=1)
def healthy_run():
    """A 6-revolution healthy run (unsensed) of the shipped diagnoser's second held-out
    condition (the first's healthy machine rings below the training sensor band and is
    refused) and its data-set task."""
    from recipdyn.diagnosis.dataset import DatasetSpec, design
    from recipdyn.diagnosis.diagnose import default_model_path
    from recipdyn.diagnosis.train import load
    from recipdyn.simulate import simulate

    card = load(default_model_path()).card
    spec = DatasetSpec.from_dict(card["spec"])  # its chain: fixed, as it was built
    tasks = [t for t in design(spec) if t["split"] == "test" and t["label"] == "healthy"]
    cond = sorted({t["condition"] for t in tasks})[1]
    task = next(t for t in tasks if t["condition"] == cond)
    with warnings.catch_warnings():  # the healthy pins stretch Hertz's law (docs/diagnosis.md)
        warnings.simplefilter("ignore")
        ds = simulate(model="compressor-contact-valves", revolutions=6.0, transient=1.0,
                      fs=task["fs"], summary=False, **task["params"])  # fmt: skip
    return ds, task


def sensed(ds, task, mark_deg=0.0, offset=(0.0, 0.0), delay=0):
    """The data set's chain (`recipdyn.diagnosis.dataset.simulate_record`'s sensors) with one
    change: the tacho's mark (degrees from outer dead centre), the pressures' offsets (Pa)
    or a delay of both pressures (samples)."""
    from recipdyn import sensors

    rec = sensors.record(
        ds,
        accelerometer=sensors.Accelerometer(
            snr_db=task["snr_db"], resonance_hz=task["resonance_hz"]
        ),
        pressure=sensors.PressureTransducer(),
        tacho=sensors.Tacho(angle=math.radians(mark_deg)),
        seed=task["noise_seed"],
    )
    out = {"x": rec["accel_guide"].values, "tacho": rec["tacho"].values, "fs": task["fs"]}
    for k, name in enumerate(("p_head_sensor", "p_crank_sensor")):
        p = rec[name].values
        if delay:
            p = np.concatenate([np.full(delay, p[0]), p[:-delay]])
        out[name] = p + offset[k]
    return out
