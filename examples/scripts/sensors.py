"""What a monitoring system records of a worn crank pin: the sensors' channels beside the
simulated outputs.

Draws ``sensors.png`` (into the folder given as the first argument, default: here): the
contact-impact joint (rc = 1 mm) under the compression-cycle load, sampled at 40 kHz; the
crosshead acceleration and the guide accelerometer's channel over the last revolution, a
zoom on the largest impact (the 4 kHz mounting resonance rings), and the head-end pressure
with its transducer's channel and the tacho. Runs in about a minute (the contact model's
first compilation adds one).
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import recipdyn  # noqa: E402
import recipdyn.sensors as sensors  # noqa: E402


def main(folder: Path) -> Path:
    m = recipdyn.get_model("compressor-contact")
    ds = recipdyn.simulate(model=m, params=m.parameters({"load": "cycle"}), revolutions=3,
                           fs=40e3)  # fmt: skip
    acc = sensors.Accelerometer(resonance_hz=4000.0, snr_db=30.0)
    out = sensors.record(ds, accelerometer=acc, pressure=sensors.PressureTransducer(),
                         tacho=sensors.Tacho(), seed=1)  # fmt: skip
    deg = np.degrees(ds.theta1.values) - 720.0
    last = deg >= 0
    fig, ax = plt.subplots(3, 1, figsize=(10, 10), constrained_layout=True)
    ax[0].plot(deg[last], ds.a.values[last], lw=0.8, label="a (simulated)")
    ax[0].plot(deg[last], out.accel_guide.values[last], lw=0.6, alpha=0.8,
               label="accel_guide (sensor: 4 kHz mount, 1 Hz-16 kHz, 30 dB, 16 bit)")  # fmt: skip
    ax[0].set(xlabel="crank angle (deg)", ylabel="m/s$^2$", title="last revolution")
    ax[0].legend(loc="upper right", fontsize=8)
    i = int(np.argmax(np.abs(ds.a.values) * last))
    z = slice(max(i - 80, 0), i + 240)  # 2 ms before, 6 ms after
    t_ms = (ds.time.values[z] - ds.time.values[i]) * 1e3
    ax[1].plot(t_ms, ds.a.values[z], lw=1.0, label="a (simulated)")
    ax[1].plot(t_ms, out.accel_guide.values[z], lw=0.8, label="accel_guide")
    ax[1].set(xlabel="time from the largest impact (ms)", ylabel="m/s$^2$",
              title="an impact: the mounting resonance rings (4 kHz, damping 0.05)")  # fmt: skip
    ax[1].legend(loc="upper right", fontsize=8)
    ax[2].plot(deg[last], ds.p_head.values[last] / 1e5, lw=1.0, label="p_head (simulated)")
    ax[2].plot(deg[last], out.p_head_sensor.values[last] / 1e5, lw=0.6,
               label="p_head_sensor (16 kHz low-pass, 60 dB, 16 bit over 0-5 bar)")  # fmt: skip
    ax[2].set(xlabel="crank angle (deg)", ylabel="bar")
    tw = ax[2].twinx()
    tw.plot(np.degrees(ds.theta1.values) - 720.0, out.tacho.values, "k", lw=0.6)
    tw.set(ylabel="tacho (V)", ylim=(-0.5, 12), xlim=(-20, 360))
    ax[2].set_xlim(-20, 360)
    ax[2].legend(loc="upper right", fontsize=8)
    path = folder / "sensors.png"
    fig.savefig(path, dpi=100)
    return path


if __name__ == "__main__":
    print(main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")))
