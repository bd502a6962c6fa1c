"""The signature of every fault next to the healthy machine (docs/faults.md, Signatures).

Runs the contact-impact joint with dynamic valves (``compressor-contact-valves``), air
1 → 3 bar at 20 rad/s, clearances at both pins, healthy and with each fault at a moderate
severity, four revolutions after three, and draws one figure per fault
(``fault_signature_<fault>.png``, the last revolution beside the healthy one): the p–V diagram
of the head end, both chambers' pressures over crank angle, the crosshead-pin rod load over
crank angle and the guide accelerometer's channel (`recipdyn.sensors`: 4 kHz mounting
resonance, 40 dB SNR, 16-bit ADC over ±500 g) over crank angle. It prints the table of the
features a diagnoser reads (docs/faults.md), and writes it as CSV when given a file name.

Usage: ``python examples/scripts/fault_signatures.py [OUTDIR [TABLE.csv]]`` (default
``docs/img``, no CSV).
A few seconds per run after the model's first compilation (~5 min).
"""

from __future__ import annotations

import csv
import math
import sys
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import recipdyn.sensors as sensors  # noqa: E402
from recipdyn.features import signal_features  # noqa: E402
from recipdyn.simulate import simulate  # noqa: E402

FS = 20000.0
#: The healthy machine: new bearings (radial clearance 0.1 mm at the crank pin, 0.05 mm at
#: the crosshead pin), healthy valves and rings.
HEALTHY = {"clearance_joints": "both", "rc": 1e-4, "rc_crosshead": 5e-5}
#: file stem: (title, parameters changed from the healthy machine)
FAULTS = {
    "leak_suction": ("leaking suction valve, head end (1 cm², 0.6 % of the valve's flow area)",
                     {"leak_area_suction_head": 1e-4}),
    "leak_discharge": ("leaking discharge valve, head end (0.3 cm²)",
                       {"leak_area_discharge_head": 3e-5}),
    "broken_spring": ("broken suction-valve spring, head end (spring factor 0)",
                      {"spring_factor_suction_head": 0.0}),
    "sticking_plate": ("sticking suction plate, head end (300 N adhesion)",
                       {"adhesion_force_suction_head": 300.0}),
    "ring_leak": ("piston-ring leak (1 cm²)", {"ring_leak_area": 1e-4}),
    "crank_pin": ("worn crank-pin bearing (radial clearance 0.1 → 0.5 mm)", {"rc": 5e-4}),
    "crosshead_pin": ("worn crosshead-pin bush (radial clearance 0.05 → 0.3 mm)",
                      {"rc_crosshead": 3e-4}),
}  # fmt: skip
ACCEL = sensors.Accelerometer(resonance_hz=4000.0, snr_db=40.0)
#: Revolutions recorded (after three of transient); the figures show the last.
REVS = 4


def run(**changes):
    """`REVS` revolutions after three of the healthy machine with ``changes``, with the guide
    accelerometer's channel ``accel_guide`` added (seed 1)."""
    with warnings.catch_warnings():
        # the point-contact law's range note (the contact arc of a small clearance under a
        # 140 kN rod load): the forces are the model's, see docs/contact.md
        warnings.simplefilter("ignore")
        ds = simulate(model="compressor-contact-valves", revolutions=REVS, transient=3, fs=FS,
                      **{**HEALTHY, **changes})  # fmt: skip
    return sensors.record(ds, accelerometer=ACCEL, seed=1)


def crank_deg(ds) -> np.ndarray:
    """Crank angle of each sample in degrees, 0 … 360 from the outer dead centre."""
    return np.degrees(np.asarray(ds["theta1"].values, dtype=float)) % 360.0


def rod_load(ds) -> np.ndarray:
    """Crosshead-pin rod load (N, > 0 compression): ``m3 a - F_gas``."""
    m3 = float(ds.attrs["param_m3"])
    return m3 * np.asarray(ds["a"].values, dtype=float) - np.asarray(ds["gas_force"].values)


def smooth_rod_load(ds) -> np.ndarray:
    """The rod load with the impacts' ringing averaged out: a centred moving average over 5°
    of crank angle, wrapped around the recorded revolution (N)."""
    n = max(3, int(round(math.radians(5.0) / float(ds.attrs["param_omega"]) * FS)) | 1)
    return np.convolve(np.pad(rod_load(ds), n // 2, mode="wrap"), np.ones(n) / n, mode="valid")


def reversals(ds) -> tuple[float, float]:
    """Crank angles (deg) where the smoothed rod load (`smooth_rod_load`) changes sign,
    interpolated linearly between samples: falling near 35° and rising near 220°."""
    th = crank_deg(ds)
    smooth = smooth_rod_load(ds)
    k = np.flatnonzero(np.sign(smooth[1:]) != np.sign(smooth[:-1]))
    at = {i: th[i] - smooth[i] * (th[i + 1] - th[i]) / (smooth[i + 1] - smooth[i]) for i in k}
    falling = [at[i] for i in k if smooth[i + 1] < smooth[i]]
    rising = [at[i] for i in k if smooth[i + 1] > smooth[i]]
    return (falling[0] if falling else math.nan, rising[0] if rising else math.nan)


def revolutions(ds) -> list:
    """The record cut into its crank revolutions (from the outer dead centre)."""
    turn = np.floor(np.asarray(ds["theta1"].values) / (2.0 * math.pi) + 1e-9).astype(int)
    return [ds.isel(time=np.flatnonzero(turn == k)) for k in np.unique(turn)]


#: Threshold of the knock's onset on the accelerometer channel, in g (the crosshead's own
#: acceleration at 20 rad/s stays below 6 g; the channel's noise is ~0.1 g).
KNOCK_G = 20.0


def knock_onsets(ds) -> tuple[float, float]:
    """Crank angles (deg) of the knock's onset in each half revolution: the first sample of
    ``accel_guide`` beyond `KNOCK_G` after 0° and after 180°."""
    th = crank_deg(ds)
    big = np.abs(np.asarray(ds["accel_guide"].values)) > KNOCK_G * sensors.G0
    out = []
    for lo, hi in ((0.0, 180.0), (180.0, 360.0)):
        hit = th[big & (th >= lo) & (th < hi)]
        out.append(float(hit[np.argmin((hit - lo) % 360.0)]) if hit.size else math.nan)
    return out[0], out[1]


#: Accelerometer features (`recipdyn.features.signal_features` columns), per revolution.
KNOCK = ("rms", "peak", "crest_factor", "kurtosis")


def features(ds) -> dict:
    """What a diagnoser reads from a run: from the last revolution the thermodynamic figures
    (the run's summary) and the rod load's reversals, the suction plate's opening; over all
    recorded revolutions the impacts per revolution at each pin, the knock's onsets (median
    over the revolutions, and their largest spread), the accelerometer's crank
    orders 1, 2, 4 and the median, least and largest per-revolution value of its
    time-domain features (the knock differs from one revolution to the next)."""
    a = ds.attrs
    revs = revolutions(ds)
    last = revs[-1]
    r1, r2 = reversals(last)
    row = {
        "volumetric_efficiency_head": a["volumetric_efficiency_head"],
        "volumetric_efficiency_crank": a["volumetric_efficiency_crank"],
        "indicated_power_W": a["indicated_power_W"],
        "closing_lag_suction_head_deg": a.get("closing_lag_suction_head_deg", math.nan),
        "opening_suction_head_deg": _opening(last, "suction", "head"),
        "opening_discharge_head_deg": _opening(last, "discharge", "head"),
        "rod_reversal_falling_deg": r1,
        "rod_reversal_rising_deg": r2,
        "impacts_per_revolution": a.get("impacts_per_revolution", 0.0),
        "impacts_per_revolution_crosshead": a.get("impacts_per_revolution_crosshead", 0.0),
        "accel_clipped_samples": ds["accel_guide"].attrs["sensor_clipped_samples"],
    }
    onsets = np.array([knock_onsets(r) for r in revs])
    row["knock_onset_falling_deg"] = float(np.median(onsets[:, 0]))
    row["knock_onset_rising_deg"] = float(np.median(onsets[:, 1]))
    row["knock_onset_spread_deg"] = float(np.ptp(onsets, axis=0).max())
    whole = signal_features(ds["accel_guide"].values, FS,
                            revs=np.asarray(ds["theta1"].values) / (2.0 * math.pi))  # fmt: skip
    row.update({f"order_{k}": whole[f"order_{k}"] for k in (1, 2, 4)})
    per_rev = [signal_features(r["accel_guide"].values, FS) for r in revs]
    for k in KNOCK:
        v = np.array([f[k] for f in per_rev])
        row.update({k: float(np.median(v)), f"{k}_min": float(v.min()),
                    f"{k}_max": float(v.max())})  # fmt: skip
    return row


def _opening(ds, kind: str, end: str) -> float:
    """Crank angle (deg) of the plate's lift-off after 90° or more on its seat (the recorded
    revolution read cyclically)."""
    lift = np.asarray(ds[f"y_{kind}_{end}"].values) > 0.0
    gap = int(FS * (math.pi / 2.0) / float(ds.attrs["param_omega"]))
    th = crank_deg(ds)
    twice = np.concatenate([lift, lift])
    for k in range(gap, twice.size):
        if twice[k] and not twice[k - gap : k].any():
            return float(th[k % lift.size])
    return math.nan


def _sorted(ds, values):
    th = crank_deg(ds)
    order = np.argsort(th)
    return th[order], np.asarray(values)[order]


def figure(healthy, faulty, title: str):
    fig, ax = plt.subplots(2, 2, figsize=(10.0, 6.4), dpi=90, layout="constrained")
    for ds, color, ls, label in ((healthy, "k", "--", "healthy"), (faulty, "C3", "-", "fault")):
        kw = {"color": color, "ls": ls, "lw": 0.9}
        p_h = np.asarray(ds["p_head"].values) / 1e5
        ax[0, 0].plot(np.asarray(ds["V_head"].values) * 1e3, p_h, label=label, **kw)
        for end, alpha in (("head", 1.0), ("crank", 0.5)):
            th, p = _sorted(ds, np.asarray(ds[f"p_{end}"].values) / 1e5)
            ax[0, 1].plot(th, p, alpha=alpha, label=f"{label}, {end} end", **kw)
        th, load = _sorted(ds, rod_load(ds) / 1e3)
        ax[1, 0].plot(th, load, color=color, lw=0.5, alpha=0.35)
        th, load = _sorted(ds, smooth_rod_load(ds) / 1e3)
        ax[1, 0].plot(th, load, label=label, **{**kw, "lw": 1.2})
        for r in reversals(ds):
            ax[1, 0].axvline(r, color=color, ls=":", lw=0.8)
    # the accelerometer's traces stacked: the healthy one above the faulty one
    acc = [_sorted(ds, np.asarray(ds["accel_guide"].values) / sensors.G0)
           for ds in (healthy, faulty)]  # fmt: skip
    span = max(np.ptp(a) for _, a in acc)
    shift = 0.6 * span
    for (th, a), color, off, label in zip(acc, ("k", "C3"), (shift, -shift),
                                          ("healthy", "fault"), strict=True):  # fmt: skip
        ax[1, 1].plot(th, a + off, color=color, lw=0.5)
        ax[1, 1].text(100, off + 0.1 * span, f"{label} (offset {off:+.0f} g)", fontsize=8,
                      color=color, va="bottom")  # fmt: skip
    ax[0, 0].set(xlabel="head-end volume V (L)", ylabel="head-end pressure (bar)",
                 title="p–V, head end")  # fmt: skip
    ax[0, 1].set(xlabel="crank angle θ1 (deg)", ylabel="pressure (bar)", xlim=(0, 360),
                 title="p–θ (pale: crank end)")  # fmt: skip
    ax[1, 0].set(xlabel="crank angle θ1 (deg)", ylabel="rod load (kN, > 0 compression)",
                 xlim=(0, 360),
                 title="rod load: 5° mean, pale: raw; dotted: reversals")  # fmt: skip
    ax[1, 1].set(xlabel="crank angle θ1 (deg)", ylabel="accel_guide (g), stacked", xlim=(0, 360),
                 title="guide accelerometer (4 kHz mount, 40 dB, 16 bit)")  # fmt: skip
    for a in ax.flat:
        a.grid(alpha=0.3)
    ax[0, 0].legend(fontsize=8, loc="upper right")
    fig.suptitle(title, fontsize=10)
    return fig


def main(outdir: str = "docs/img", table: str | None = None) -> list[dict]:
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    healthy = run()
    rows = [{"fault": "healthy", **features(healthy)}]
    for stem, (title, changes) in FAULTS.items():
        ds = run(**changes)
        rows.append({"fault": stem, **features(ds)})
        fig = figure(revolutions(healthy)[-1], revolutions(ds)[-1], title)
        path = out / f"fault_signature_{stem}.png"
        fig.savefig(path)
        plt.close(fig)
        print(path, flush=True)
    if table:
        with open(table, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    keys = list(rows[0])[1:]
    print("| fault | " + " | ".join(keys) + " |")
    for r in rows:
        print(f"| {r['fault']} | " + " | ".join(f"{r[k]:.4g}" for k in keys) + " |")
    return rows


if __name__ == "__main__":
    main(*sys.argv[1:])
