"""The features a diagnoser reads from one record, and the evidence shown with a diagnosis.

Three groups, by what the record must hold:

``base`` (an acceleration channel and the crank speed)
    The vibration features of `recipdyn.features.signal_features` (RMS, peak, crest
    factor, kurtosis, spectral shape, crank orders 1-10), the impacts per revolution, the
    ringing frequency and the noise floor without a crank angle (`quiet_share`).
``angle`` (a tacho whose mark is at outer dead centre)
    Where in the revolution the vibration energy sits: the share of the high-passed
    acceleration's energy in each 10-degree crank-angle bin, averaged over the revolutions.
``pressure`` (the angle, and the head- and crank-end pressure channels)
    The shape of each chamber's pressure over the revolution, normalised to its own range
    (0 at its minimum, 1 at its maximum) in 10-degree bins, and its max/min ratio.
``cycle`` (the angle and both pressure channels)
    The indicator-diagram diagnosis (Bloch, *A Practical Guide to Compressor Technology*,
    2nd ed., Wiley 2006; Bloch & Hoefner, *Reciprocating Compressors: Operation and
    Maintenance*, 1996), made independent of the operating condition by comparing each
    chamber with its own ideal cycle at its own measured suction and discharge levels: the
    crank angles of the four valve events (discharge closing, suction opening, suction
    closing, discharge opening: where the pressure crosses 10 % of the way between the two
    levels) minus the ideal cycle's closed-form angles (polytropic re-expansion from the
    clearance volume, compression from the bottom dead centre: `CLEARANCE`, `N_POLY`); the
    depth and angle of the dip below the suction level before the suction valve opens and of
    the peak above the discharge level (a plate held by stiction needs a larger pressure
    difference); the re-expansion and compression exponents fitted on ``log p - log V`` (a
    leak bends them); the indicated work over the ideal's; each also head end minus crank
    end (a head-end valve fault moves the head end only: the crank end is the record's own
    reference). For the joints: the crosshead-pin load (the gas force of the two pressures
    plus the nominal crosshead-and-piston mass times the kinematic acceleration), the share
    of the impact energy in the `REVERSAL_WINDOW_DEG` after its reversals, and how far after
    a reversal the largest burst lies. And the operating point the record shows: the suction
    and discharge levels (``cy_p_suction``, ``cy_p_discharge``, Pa: the two chambers'
    plateaus averaged), to which a diagnoser refers the other features
    (`recipdyn.diagnosis.train`, the healthy baseline).

A missing group is NaN; the classifiers are trained with the groups removed as a record
would lack them, so a record with fewer channels is still diagnosed (less sharply).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "record_features",
    "feature_groups",
    "impacts",
    "cycle_features",
    "BINS",
    "HIGHPASS_HZ",
]

#: Crank-angle bins per revolution of the angle and pressure features (10 degrees).
BINS = 36
#: Corner of the high-pass that separates impacts from the gas and inertia forces, Hz.
HIGHPASS_HZ = 500.0
#: An impact is a high-passed peak above this many robust standard deviations (MAD/0.6745).
IMPACT_SIGMAS = 6.0


def _highpass(x, fs):
    from scipy.signal import butter, sosfiltfilt

    sos = butter(4, HIGHPASS_HZ, "highpass", fs=fs, output="sos")
    return sosfiltfilt(sos, x)


def ringing_hz(x, fs: float) -> float:
    """The frequency at which the impacts ring: the most prominent peak (in decibels) of the
    acceleration's Welch spectrum above `HIGHPASS_HZ`. A lightly damped mounting resonance
    (Q = 10) excited by the impacts stands ~20 dB above its flanks, while the machine's own
    content falls smoothly with frequency; on 95 % of the default data set's records it lies
    within 7 % of the mounting resonance (the rest: records with few impacts)."""
    from scipy.signal import find_peaks, welch

    f, p = welch(np.asarray(x, float), fs=fs, nperseg=min(1024, len(x)))
    start = int(np.searchsorted(f, HIGHPASS_HZ, side="right"))
    lp = 10 * np.log10(p[start:] + 1e-300)
    peaks, props = find_peaks(lp, prominence=0)
    if not peaks.size:
        return math.nan
    return float(f[start + peaks[np.argmax(props["prominences"])]])


#: Quantile of the 10-degree windows' energy that `quiet_share` reads (the quietest windows,
#: not the single quietest: without a crank angle nothing is averaged over revolutions).
QUIET_QUANTILE = 0.05


def quiet_share(x, fs: float, speed_hz: float) -> float:
    """The acceleration's noise floor without a crank angle: the `QUIET_QUANTILE` of the
    high-passed energy in consecutive windows as long as a 10-degree crank-angle bin, over
    the windows' mean. The impacts and valve events fill
    some stretches of a revolution and leave others quiet, so the quiet windows hold the
    sensor's noise (the tacho's ``ang_`` bins measure the same, averaged over revolutions)."""
    e = _highpass(np.asarray(x, float), fs) ** 2
    w = round(fs / (speed_hz * BINS)) if speed_hz > 0 else 0
    n = e.size // w if w >= 1 else 0
    if n < BINS:  # less than a revolution
        return math.nan
    E = e[: n * w].reshape(n, w).mean(axis=1)
    return float(np.quantile(E, QUIET_QUANTILE) / E.mean()) if E.mean() > 0 else math.nan


def _whole_revs(revs):
    """Sample mask of the whole revolutions a crank angle covers, and their count."""
    r = np.asarray(revs, dtype=float)
    tol = 2.0 * abs(r[1] - r[0]) if r.size > 1 else 0.0  # a sample or two short still covers
    start = math.ceil(r[0] - tol)
    stop = math.floor(r[-1] + tol)
    return (r >= start) & (r < stop), max(stop - start, 0), start


def impacts(x, fs: float, revs) -> dict:
    """The impacts in an acceleration record: peaks of the high-passed signal above
    `IMPACT_SIGMAS` robust standard deviations, at least 5 degrees of crank apart.

    Returns ``{"per_rev", "angles_deg", "sizes"}``: the count per revolution and, for each
    impact, its crank angle (degrees after the tacho's mark) and peak (the signal's units)."""
    from scipy.signal import find_peaks

    h = np.abs(_highpass(np.asarray(x, float), fs))
    r = np.asarray(revs, float)
    n_revs = max(r[-1] - r[0], 1e-9)
    sigma = np.median(h) / 0.6745 if np.median(h) > 0 else np.std(h)
    dist = max(1, int(round(fs * (5.0 / 360.0) * (r.size / fs) / n_revs)))
    peaks, props = find_peaks(h, height=IMPACT_SIGMAS * sigma, distance=dist)
    return {
        "per_rev": peaks.size / n_revs,
        "angles_deg": (np.mod(r[peaks], 1.0) * 360.0).tolist(),
        "sizes": props["peak_heights"].tolist(),
    }


def _angle_bins(y, revs, mask, n_revs, start, bins=BINS):
    """Mean of ``y`` in each of ``bins`` crank-angle bins over the whole revolutions."""
    r = np.asarray(revs, float)[mask]
    b = np.minimum((np.mod(r - start, 1.0) * bins).astype(int), bins - 1)
    sums = np.bincount(b, weights=y[mask], minlength=bins)
    counts = np.bincount(b, minlength=bins)
    with np.errstate(invalid="ignore", divide="ignore"):
        return sums / counts


#: The crank angles (degrees) at which a chamber's pressure, normalised to its range over the
#: revolution, rises through 5, 50, 95 % after its minimum and falls through 95, 50, 5 %
#: after its maximum: the valve events (discharge opening at the top of the rise, suction
#: opening at the bottom of the fall) that valve faults move.
EVENTS = ("rise_05", "rise_50", "rise_95", "fall_95", "fall_50", "fall_05")


def _pressure_events(p360) -> dict[str, float]:
    p = np.asarray(p360, float)
    if not np.isfinite(p).all() or np.ptp(p) <= 0:
        return dict.fromkeys(EVENTS, math.nan)
    a = (p - p.min()) / np.ptp(p)
    out = {}
    for kind, start in (("rise", int(np.argmin(a))), ("fall", int(np.argmax(a)))):
        seq = np.roll(a, -start)
        for lev in (0.05, 0.5, 0.95):
            hit = np.flatnonzero(seq >= lev if kind == "rise" else seq <= lev)
            out[f"{kind}_{round(lev * 100):02d}"] = (
                float((start + hit[0]) % 360) if hit.size else math.nan
            )
    return {k: out[k] for k in EVENTS}


#: Nominal clearance fraction and polytropic exponent of the ideal cycle the measured one is
#: compared with (the model's defaults: `recipdyn.model.parameters`).
CLEARANCE = 0.1
N_POLY = 1.3
#: Fraction of the way between the suction and discharge levels at which a valve event is read.
EVENT_LEVEL = 0.1
#: Window after a crosshead-pin load reversal in which its knock is looked for, degrees.
REVERSAL_WINDOW_DEG = 30
CHAMBER_FEATURES = (
    "dc",
    "so",
    "sc",
    "do",
    "so_dip",
    "so_dip_deg",
    "do_peak",
    "do_peak_deg",
    "n_exp",
    "n_comp",
    "work",
)


def _geometry(machine=None):
    """The machine's chamber volumes (m**3) and crosshead acceleration per omega**2 (m) at
    each whole degree of crank after outer dead centre (the tacho's mark), from the one
    model's mechanism and cylinder; ``machine``: the changes of another machine
    (`recipdyn.diagnosis.machine.Machine.changes`), its own geometry, masses and clearance
    volume (the ideal cycle's clearance is then the machine's, not `CLEARANCE`)."""
    from ..model.cycle import cycle_geometry
    from ..model.registry import get_model
    from .classes import MODEL

    changes = dict(machine or {})
    v = get_model(MODEL).parameters(changes)
    clearance = float(v["clearance_fraction"]) if "clearance_fraction" in changes else CLEARANCE
    r, length, d = float(v["r"]), float(v["l"]), float(v["d"])
    g = cycle_geometry(r, length, d, float(v["bore"]), float(v["rod_diameter"]))
    th = g.theta_odc + np.radians(np.arange(360.0))

    def x(t):
        return r * np.cos(t) + np.sqrt(length**2 - (d + r * np.sin(t)) ** 2)

    h = 1e-4
    acc = (x(th + h) - 2 * x(th) + x(th - h)) / h**2  # d2x/dtheta2
    vs_he, vs_ce = g.area_head * g.stroke, g.area_crank * g.stroke
    return {
        "V_head": clearance * vs_he + g.area_head * (g.x_max - x(th)),
        "V_crank": clearance * vs_ce + g.area_crank * (x(th) - g.x_min),
        "clearance": clearance,
        "Vs_head": vs_he,
        "Vs_crank": vs_ce,
        "acc_per_omega2": acc,
        "area_head": g.area_head,
        "area_crank": g.area_crank,
        "area_rod": g.area_rod,
        "m_rec": float(v["m3"]),  # the crosshead pin carries the crosshead and piston
        "frame_pressure": float(v["frame_pressure"]),
    }


#: `_geometry` by machine (the changes as sorted pairs; () the default machine).
_GEOMETRY: dict[tuple, dict] = {}


def geometry(machine=None) -> dict:
    """`_geometry` of ``machine`` (its changes from the default machine), computed once."""
    key = tuple(sorted(dict(machine or {}).items()))
    if key not in _GEOMETRY:
        _GEOMETRY[key] = _geometry(key)
    return _GEOMETRY[key]


def _first_crossing(y, level, lo, hi, rising) -> float:
    """Fractional index in [lo, hi) where ``y`` first crosses ``level`` (NaN: never)."""
    seg = y[lo:hi]
    hit = np.flatnonzero(seg >= level if rising else seg <= level)
    if not hit.size:
        return math.nan
    k = lo + int(hit[0])
    if k == 0 or y[k] == y[k - 1]:
        return float(k)
    return float(k - 1 + (level - y[k - 1]) / (y[k] - y[k - 1]))


def _chamber_cycle(p, V, vs, clearance=CLEARANCE) -> dict[str, float]:
    """Valve-event deviations from the ideal cycle, fitted exponents and work ratio of one
    chamber (``p``, ``V``: 360 one-degree samples from outer dead centre)."""
    from ..model.cycle import ideal_indicated_work, indicated_work

    out = dict.fromkeys((*CHAMBER_FEATURES, "p_lo", "p_hi"), math.nan)
    if not (np.isfinite(p).all() and np.isfinite(V).all()):
        return out
    k0 = int(np.argmin(V))  # this chamber's top dead centre
    p, V = np.roll(p, -k0), np.roll(V, -k0)
    bdc = int(np.argmax(V))
    p_lo = float(np.median(p[int(0.5 * bdc) : int(0.85 * bdc)]))  # suction plateau
    p_hi = float(np.median(p[-40:-5]))  # discharge plateau, just before top dead centre
    span = p_hi - p_lo
    if not (p_lo > 0 and span > 0):
        return out
    out["p_lo"], out["p_hi"] = p_lo, p_hi
    lev_lo, lev_hi = p_lo + EVENT_LEVEL * span, p_hi - EVENT_LEVEL * span
    v0, vmax = V[0], V[bdc]
    ideal_v = {  # ideal cycle's volume at each event (polytropic through the two levels)
        "dc": v0 * (p_hi / lev_hi) ** (1 / N_POLY),
        "so": v0 * (p_hi / lev_lo) ** (1 / N_POLY),
        "sc": vmax * (p_lo / lev_lo) ** (1 / N_POLY),
        "do": vmax * (p_lo / lev_hi) ** (1 / N_POLY),
    }
    meas = {
        "dc": _first_crossing(p, lev_hi, 0, bdc, rising=False),
        "so": _first_crossing(p, lev_lo, 0, bdc, rising=False),
        "sc": _first_crossing(p, lev_lo, bdc, 360, rising=True),
        "do": _first_crossing(p, lev_hi, bdc, 360, rising=True),
    }
    for ev, vi in ideal_v.items():
        grow = ev in ("dc", "so")
        seg = np.arange(0, bdc + 1) if grow else np.arange(bdc, 360)
        vv = V[seg] if grow else -V[seg]
        ideal = float(np.interp(vi if grow else -vi, vv, seg))
        out[ev] = meas[ev] - ideal
    # a valve opens once the pressure difference overcomes its spring preload and any
    # stiction: the dip below the suction plateau (and the peak above the discharge plateau),
    # its depth relative to the span, and its angle after the ideal cycle reaches the level
    k_dip = int(np.argmin(p[:bdc]))
    k_peak = bdc + int(np.argmax(p[bdc:]))
    a_lo = float(np.interp(v0 * (p_hi / p_lo) ** (1 / N_POLY), V[: bdc + 1], np.arange(bdc + 1)))
    a_hi = float(np.interp(-vmax * (p_lo / p_hi) ** (1 / N_POLY), -V[bdc:], np.arange(bdc, 360)))
    out["so_dip"] = (p_lo - p[k_dip]) / span
    out["so_dip_deg"] = k_dip - a_lo
    out["do_peak"] = (p[k_peak] - p_hi) / span
    out["do_peak_deg"] = k_peak - a_hi
    for name, a, b in (("n_exp", meas["dc"], meas["so"]), ("n_comp", meas["sc"], meas["do"])):
        if np.isfinite(a) and np.isfinite(b) and b - a >= 4:
            k = np.arange(math.ceil(a), math.floor(b) + 1)
            slope = np.polyfit(np.log(V[k]), np.log(p[k]), 1)[0]
            out[name] = float(-slope)
    ideal_w = ideal_indicated_work(p_lo, p_hi / p_lo, clearance, N_POLY, vs)
    out["work"] = indicated_work(p, V) / ideal_w if ideal_w > 0 else math.nan
    return out


def cycle_features(
    p_head360, p_crank360, energy360, speed_hz: float, machine=None
) -> dict[str, float]:
    """The ``cycle`` group (module docstring) from the two chamber pressures (Pa) and the
    high-passed acceleration energy, each at the 360 whole degrees after outer dead centre;
    ``machine``: the changes of the machine whose geometry they are read against (None: the
    default machine)."""
    g = geometry(machine)
    row = {}
    ph, pc = np.asarray(p_head360, float), np.asarray(p_crank360, float)
    head = _chamber_cycle(ph, g["V_head"], g["Vs_head"], g["clearance"])
    crank = _chamber_cycle(pc, g["V_crank"], g["Vs_crank"], g["clearance"])
    for k in CHAMBER_FEATURES:
        row[f"cy_head_{k}"] = head[k]
        row[f"cy_crank_{k}"] = crank[k]
        row[f"cy_diff_{k}"] = head[k] - crank[k]
    for name, k in (("cy_p_suction", "p_lo"), ("cy_p_discharge", "p_hi")):
        row[name] = 0.5 * (head[k] + crank[k])
    # crosshead-pin load (> 0: compression) and where the impact energy sits after reversals
    omega = 2 * math.pi * speed_hz
    f_gas = -ph * g["area_head"] + pc * g["area_crank"] + g["frame_pressure"] * g["area_rod"]
    load = g["m_rec"] * omega**2 * g["acc_per_omega2"] - f_gas
    e = np.asarray(energy360, float)
    if not np.isfinite(load).all():  # a pressure channel missing: no pin load, no reversals
        row["cy_reversals"] = math.nan
        row["cy_energy_after_reversal"] = math.nan
        row["cy_peak_after_reversal_deg"] = math.nan
        return row
    flips = np.flatnonzero(np.sign(load) != np.sign(np.roll(load, 1)))
    row["cy_reversals"] = float(flips.size)
    ok = flips.size > 0 and np.isfinite(e).all() and e.sum() > 0
    if ok:
        w = np.zeros(360, bool)
        for f in flips:
            w[(f + np.arange(REVERSAL_WINDOW_DEG)) % 360] = True
        peak = int(np.argmax(e))
        row["cy_energy_after_reversal"] = float(e[w].sum() / e.sum())
        row["cy_peak_after_reversal_deg"] = float(np.min((peak - flips) % 360))
    else:
        row["cy_energy_after_reversal"] = math.nan
        row["cy_peak_after_reversal_deg"] = math.nan
    return row


#: Features of the sensor, not of the machine: stored and read by the refusals (the noise
#: floor), never by a classifier or a regressor (the ``sensor`` group of `feature_groups`,
#: which no channel subset of `recipdyn.diagnosis.train.AVAILABILITY` holds).
SENSOR_FEATURES = ("acc_quiet_share",)


def feature_groups(names) -> dict[str, list[str]]:
    """Feature names by group (``base``, ``angle``, ``pressure``, ``cycle``, ``sensor``)."""
    groups: dict[str, list[str]] = {
        "base": [], "angle": [], "pressure": [], "cycle": [], "sensor": []
    }  # fmt: skip
    for n in names:
        if n in SENSOR_FEATURES:
            groups["sensor"].append(n)
        elif n.startswith(("cy_", "dv_")):  # dv_: a deviation from the healthy baseline
            groups["cycle"].append(n)
        elif n.startswith("ang_"):
            groups["angle"].append(n)
        elif n.startswith(("ph_", "pc_")):
            groups["pressure"].append(n)
        else:
            groups["base"].append(n)
    return groups


def record_features(
    accel, fs: float, revs, *, angle: bool = True, p_head=None, p_crank=None, machine=None
) -> dict[str, float]:
    """Features of one record (see the module docstring).

    Parameters
    ----------
    accel : array
        Acceleration, m/s**2, sampled at ``fs`` Hz.
    revs : array
        Crank angle in revolutions at each sample (from a tacho or a constant speed).
    angle : bool
        Whether ``revs`` is referenced to outer dead centre (a tacho): else the angle and
        pressure features are NaN.
    p_head, p_crank : array, optional
        Chamber pressures, Pa.
    machine : mapping, optional
        The changes of the machine the cycle features are read against
        (`recipdyn.diagnosis.machine.Machine.changes`; None: the default machine).
    """
    from ..features import signal_features

    x = np.asarray(accel, dtype=float)
    r = np.asarray(revs, dtype=float)
    speed = (r[-1] - r[0]) / ((r.size - 1) / fs)
    row = {"speed_hz": float(speed)}
    for k, v in signal_features(x, fs, revs=r).items():
        row[f"acc_{k}"] = float(v)
    row["acc_impacts_per_rev"] = impacts(x, fs, r)["per_rev"]
    row["acc_ring_hz"] = ringing_hz(x, fs)
    row["acc_quiet_share"] = quiet_share(x, fs, speed)
    mask, n_revs, start = _whole_revs(r)
    ok_angle = angle and n_revs >= 1
    e = _highpass(x, fs) ** 2
    bins = _angle_bins(e, r, mask, n_revs, start) if ok_angle else np.full(BINS, np.nan)
    bins = bins / np.nansum(bins) if ok_angle and np.nansum(bins) > 0 else bins
    for i, v in enumerate(bins):
        row[f"ang_{i * 10:03d}"] = float(v)
    for tag, p in (("ph", p_head), ("pc", p_crank)):
        if p is not None and ok_angle:
            pb = _angle_bins(np.asarray(p, float), r, mask, n_revs, start)
            lo, hi = np.nanmin(pb), np.nanmax(pb)
            shape = (pb - lo) / (hi - lo) if hi > lo else np.full(BINS, np.nan)
            ratio = hi / lo if lo > 0 else math.nan
            events = _pressure_events(
                _angle_bins(np.asarray(p, float), r, mask, n_revs, start, 360)
            )
        else:
            shape, ratio = np.full(BINS, np.nan), math.nan
            events = dict.fromkeys(EVENTS, math.nan)
        for i, v in enumerate(shape):
            row[f"{tag}_{i * 10:03d}"] = float(v)
        row[f"{tag}_ratio"] = float(ratio)
        for k, v in events.items():
            row[f"{tag}_{k}"] = float(v)
    if p_head is not None and p_crank is not None and ok_angle:
        e360 = _angle_bins(e, r, mask, n_revs, start, 360)
        ph360 = _angle_bins(np.asarray(p_head, float), r, mask, n_revs, start, 360)
        pc360 = _angle_bins(np.asarray(p_crank, float), r, mask, n_revs, start, 360)
        row.update(cycle_features(ph360, pc360, e360, speed, machine))
    else:
        nan = np.full(360, np.nan)
        row.update(cycle_features(nan, nan, nan, speed, machine))
    return row
