"""The measurement chain's errors estimated from the record itself, and the record corrected.

A diagnoser learns records of one measurement chain: its data set's tacho mark at outer dead
centre, pressure transducers without offset, channels sampled together, an accelerometer
with the data set's mounting. A measured record comes through another chain, and the
cycle features read the indicator diagram to a fraction of a degree and of a kilopascal:
on the shipped diagnoser a tacho mark 0.3 degree before outer dead centre, +1 kPa on both
pressures or the pressures 3 samples late each turned a healthy record into a fault at
p >= 0.75. Condition-monitoring practice does not trust those settings; it reads them from
the pressure trace, and so does this module, before any feature is computed:

**Crank-angle phase** (`pressure_phase`). With its valves closed a chamber's gas follows a
polytrope, ``p V^n = const`` (the model's gas obeys it exactly: `recipdyn.model.valves`), so
``log p`` is a straight line in ``log V`` on the re-expansion and on the compression. ``V``
is the slider-crank's kinematic volume at the crank angle ``theta = A + phi``, ``phi`` the
angle after the tacho's mark and ``A`` the mark's own crank angle: a wrong ``A``, or a
pressure channel that lags the tacho, bends both lines (most the re-expansion, where the
volume changes fastest in relative terms), and so does an offset ``o`` of the transducer
(``log(p - o)``). ``A`` and ``o`` are the values that straighten both segments at once, the
lines' slopes and intercepts fitted inside (variable projection: Tunestål, Hedrick &
Johansson, "Model-based estimation of cylinder pressure sensor offset using least-squares
methods", IEEE CDC 2001; the polytropic TDC method of combustion-engine practice:
Pipitone & Beccari, Appl. Therm. Eng. 30 (2010) 1914; for compressors, e.g. US patent
10 323 937, "Top dead center determination for a reciprocating compressor", 2019). Each
chamber gives its own estimate, the head end near outer and the crank end near inner dead
centre, half a revolution apart: **their agreement is the check**.

**Pressure offsets and gains.** The offset is the one that straightens the polytropes
(above). A gain multiplies ``p`` and leaves ``log p`` straight: it is not identifiable from
the record, except as the ratio of the two channels' gains, which the two chambers' spans
between the shared suction and discharge lines give (`relative gain`).

**Delays.** At a steady speed a delay ``tau`` of the pressure channels is a phase
``omega tau`` of the pressure against the tacho: the estimate above is the mark's error and
the pressures' delay together (a causal anti-alias filter's delay included: at the
polytropes' low frequencies a causal filter is its group delay). The split between the two
is not identifiable from the pressures; the crosshead's acceleration would tell it only
through its low crank orders, whose phase the accelerometer's high-pass (0.5-5 Hz corners
on a 2.5-4 Hz crank) sets by tens of degrees. The phase is applied to the crank angle of
every channel, which is exact for a mark error and leaves the acceleration ``omega tau``
off for a pressure delay (0.36 degree for 3 samples at 10 kHz and 200 rpm, against the
10-degree bins of the angle features).

**Tacho jitter** (`tacho_revolutions`). The crank angle is a least-squares fit of the pulse
count against the pulse times (constant speed, or a slow drift), not an interpolation
through every pulse: a pulse's jitter then moves the angle by ``1/sqrt(N)`` of itself. The
residuals' RMS is the jitter's estimate.

**Accelerometer mounting resonance** (`resonance`): the frequency and damping of the
second-order response that the impacts' broadband excitation shows in the acceleration's
spectrum, fitted with a free sloping excitation and a white noise floor.

Every estimate carries its value, its uncertainty as the half-width of a 95 % interval (the
fit's own statistics, the spread over revolutions, and the estimator's spread over the
diagnoser's own training records: `ChainReference`) and a status. The record is corrected
relative to the reference, the estimate a record of the diagnoser's own chain gives, so the
diagnoser sees a record in its own frame; a record whose chain cannot be made consistent is
refused, naming the channel and why.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

__all__ = [
    "Estimate",
    "ChainReference",
    "ChainCorrection",
    "reference_from",
    "known_chain",
    "undo_known_chain",
    "pressure_phase",
    "tacho_revolutions",
    "resonance",
    "correct_chain",
    "chamber_volume",
]

#: Coverage factor of the reported uncertainties (half-width of a ~95 % interval).
K95 = 2.0
#: The closed-phase segments: where the chamber's angle-binned pressure lies between these
#: fractions of the way from its suction to its discharge level (valve events and their
#: plate dynamics stay outside).
SEGMENT = (0.1, 0.9)
#: Consistency bound: two estimates that should agree may differ by this many of their
#: combined standard uncertainties (about 3 sigma: a false refusal in ~3 records of 1000 of the
#: diagnoser's own chain).
CONSISTENCY_SIGMAS = 3.0
#: Largest tacho residual RMS (degrees) still read as jitter around a constant or slowly
#: drifting speed; beyond it the speed itself varies and the pulses are followed.
JITTER_MAX_DEG = 3.0
#: Relative systematic errors (95 % half-widths) of the mounting resonance's damping and
#: frequency estimates (`resonance`), beyond their spread over the record's parts: measured
#: by ``benchmarks/bench_chain_correction.py --seed 1`` (54 records through drawn chains, the
#: mount at 2.5 kHz-0.45 fs with damping 0.02-0.2 behind the data set's 0.4 fs anti-alias
#: filter: relative errors up to 0.42 and 0.011, 90th percentiles 0.34 and 0.008); the
#: unknown anti-alias filter and the impacts' own spectrum are what the damping trades
#: against. Checked out of sample on seed 0 (docs/diagnosis.md).
RESONANCE_DAMPING_REL = 0.35
RESONANCE_FREQUENCY_REL = 0.01
#: Spectral peaks tried as the mounting resonance (`resonance`), above this frequency (Hz:
#: mounted accelerometers resonate above ~1 kHz, a hand-held probe at 1-2 kHz; Serridge &
#: Licht 1987, ch. 5), and the largest damping ratio a mount's resonance is read with.
RESONANCE_CANDIDATES = 3
RESONANCE_MIN_HZ = 1000.0
RESONANCE_DAMPING_MAX = 0.35


@dataclass(frozen=True)
class Estimate:
    """One estimated chain error: ``value`` and ``uncertainty`` (95 % half-width) in
    ``unit``; ``status`` says what was done with it (``corrected``, ``consistent``,
    ``inconsistent``, ``not identifiable``, ``not measured``); ``note`` why."""

    value: float
    uncertainty: float
    unit: str
    status: str
    note: str = ""

    def text(self) -> str:
        if not math.isfinite(self.value):
            return f"{self.status}" + (f" ({self.note})" if self.note else "")
        return f"{self.value:+.3g} +- {self.uncertainty:.2g} {self.unit} ({self.status})" + (
            f": {self.note}" if self.note else ""
        )


#: Neighbours of the reference's bias model (`ChainReference.bias`).
REFERENCE_NEIGHBOURS = 7
#: A chamber whose exponents lie farther from the reference records than this many times the
#: reference's own farthest neighbour distance is not referred to it (`ChainReference.bias`).
REFERENCE_REACH = 2.0
#: Reference records of each class a diagnoser's reference is built from (`reference_from`).
REFERENCE_PER_CLASS = 45


@dataclass(frozen=True)
class ChainReference:
    """What the estimators give on records of the diagnoser's own measurement chain.

    The polytropes of a healthy chamber give the tacho mark's crank angle and the offset to
    within their noise, but a fault bends them: a leaking valve or ring passes gas during
    compression and re-expansion, and the crank angle and offset that straighten the
    segments move with it (1-2 deg and 2-7 kPa for the data set's leaks); a worn pin moves
    the crosshead, and the volume with it, by up to its clearance (0.2-0.3 deg). What the
    chain changes, the fitted exponents do not (the fit takes the phase and the offset
    out), while every fault that bends the polytropes changes them. So the estimators'
    bias is read from the chamber's exponents: the `REFERENCE_NEIGHBOURS` reference records
    (the diagnoser's own chain) nearest in ``(n_compression, n_expansion)`` give the phase
    and offset a record of the diagnoser's chain with those exponents shows (their mean),
    and how far off that is (the root mean square of their own leave-one-condition-out
    errors, less their estimates' own noise).

    ``rows`` per chamber: the columns ``n_compression``, ``n_expansion``, ``phase_deg``,
    ``offset_pa``, ``phase_res``, ``offset_res`` (leave-one-condition-out errors),
    ``phase_sd``, ``offset_sd`` (each record's own statistical uncertainty). The two
    chambers draw from one suction line: the head-end minus crank-end suction level
    (``suction_diff``, Pa) and the ratio of their spans between the line pressures
    (``gain_ratio``) are the same on every record up to ``*_spread``."""

    rows: dict[str, dict[str, list[float]]] = field(default_factory=dict)
    suction_diff: float = 0.0
    suction_diff_spread: float = 50.0
    gain_ratio: float = 1.0
    gain_ratio_spread: float = 0.002
    reach: dict[str, float] = field(default_factory=dict)
    records: int = 0
    source: str = ""

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any] | None) -> ChainReference | None:
        if not d:
            return None
        return cls(**{k: v for k, v in d.items() if k in cls.__dataclass_fields__})

    def _space(self, chamber: str):
        r = self.rows[chamber]
        X = np.column_stack([r["n_compression"], r["n_expansion"]]).astype(float)
        scale = np.std(X, axis=0)
        return X, np.where(scale > 0, scale, 1.0)

    def bias(self, chamber: str, n_compression: float, n_expansion: float, exclude=None):
        """``(phase_deg, offset_pa, phase_spread, offset_spread, inside)`` that a record of
        the diagnoser's chain with these exponents shows, the spreads as standard
        uncertainties, and whether the exponents lie within `REFERENCE_REACH` of the
        reference records'. ``exclude``: an operating condition whose reference records are
        left out (a data set correcting its own records reads each from the other
        conditions', as a new record is read)."""
        from sklearn.neighbors import NearestNeighbors

        X, scale = self._space(chamber)
        r = {k: np.asarray(v, float) for k, v in self.rows[chamber].items()}
        if exclude is not None and "condition" in r:
            keep = r["condition"] != exclude
            X, r = X[keep], {k: v[keep] for k, v in r.items()}
        k = min(REFERENCE_NEIGHBOURS, X.shape[0])
        nn = NearestNeighbors(n_neighbors=k).fit(X / scale)
        dist, idx = nn.kneighbors(np.array([[n_compression, n_expansion]]) / scale)
        i = idx[0]
        out = []
        for name in ("phase", "offset"):
            unit = "deg" if name == "phase" else "pa"
            res2 = float(np.mean(r[f"{name}_res"][i] ** 2))
            own2 = float(np.mean(r[f"{name}_sd"][i] ** 2))
            # the model's own error: what is left of the neighbours' errors once their
            # estimates' noise is taken off (at least a quarter of it: no model is exact)
            spread = math.sqrt(max(res2 - own2, 0.25 * res2))
            out.append((float(np.mean(r[f"{name}_{unit}"][i])), spread))
        inside = float(dist[0, -1]) <= REFERENCE_REACH * self.reach.get(chamber, math.inf)
        return out[0][0], out[1][0], out[0][1], out[1][1], inside


def _column(row, name: str, k: int, default):
    """A data set's chain column ``chain.<name>`` (one value, or per chamber ``.<k>``)."""
    for key in (f"chain.{name}.{k}", f"chain.{name}"):
        v = row.get(key) if hasattr(row, "get") else None
        if v is not None and not (isinstance(v, float) and math.isnan(v)):
            return v
    return default


def _lowpass_delay(fc, order, phase) -> float:
    """Group delay (s) at low frequency of a causal Butterworth low-pass (0 if zero-phase)."""
    from scipy.signal import butter, freqs

    if fc is None or phase == "zero" or not fc or not order:
        return 0.0
    b, a = butter(int(order), 2 * math.pi * float(fc), analog=True)
    w = 2 * math.pi * np.array([0.5, 1.5])  # rad/s: the polytropes' own frequencies
    ph = np.unwrap(np.angle(freqs(b, a, worN=w)[1]))
    return float(-(ph[1] - ph[0]) / (w[1] - w[0]))


def known_chain(row, k: int, speed_hz: float) -> tuple[float, float, float]:
    """``(phase_deg, offset_pa, gain)`` a data set's drawn chain gives pressure channel
    ``k`` (0 head, 1 crank) of the record ``row`` (its ``chain.*`` columns: the tacho's
    mark, delay and low-pass, the channel's delay, causal low-pass, passage resonance,
    offset and gain); ``(0, 0, 1)``
    for a data set of the fixed chain, which has no such columns. The phase is the one
    `pressure_phase` reads: the mark's crank angle, plus the tacho's delay, less the
    pressure's delays, as crank angle."""
    mark = math.degrees(float(_column(row, "tacho.angle", k, 0.0)))
    # the tacho's pulse delayed (its own delay; an analog input's low-pass moves the edge by
    # about its group delay)
    t_delay = float(_column(row, "tacho.delay_s", k, 0.0)) + _lowpass_delay(
        _column(row, "tacho.lowpass_hz", k, None),
        _column(row, "tacho.lowpass_order", k, 4),
        "causal",
    )
    p_delay = float(_column(row, "pressure.delay_s", k, 0.0)) + _lowpass_delay(
        _column(row, "pressure.lowpass_hz", k, None),
        _column(row, "pressure.lowpass_order", k, None),
        _column(row, "pressure.lowpass_phase", k, "causal"),
    )
    fn = _column(row, "pressure.resonance_hz", k, None)
    if fn:  # a passage resonance delays the slow content by 2 zeta / wn
        p_delay += 2 * float(_column(row, "pressure.damping", k, 0.0)) / (2 * math.pi * float(fn))
    phase = mark + 360.0 * speed_hz * (t_delay - p_delay)
    return (
        phase,
        float(_column(row, "pressure.offset", k, 0.0)),
        float(_column(row, "pressure.gain", k, 1.0)),
    )


def undo_known_chain(row, revs, p_head, p_crank, speed_hz: float):
    """A record of a data set's drawn chain, put in the frame `correct_chain` maps a record
    to, from its *known* chain (``row``: its ``chain.*`` columns, `known_chain`): the crank
    angle re-phased by the two pressure channels' mean phase, each offset removed, the crank
    end's gain matched to the head end's; the common gain, the filters, the noise and the
    mount left as drawn. Returns ``(revs, p_head, p_crank)``. A data set whose features are
    computed so holds what `recipdyn diagnose` makes of a record when its estimates are
    exact."""
    (ph_h, o_h, g_h), (ph_c, o_c, g_c) = (known_chain(row, k, speed_hz) for k in (0, 1))
    revs = np.asarray(revs, float) + 0.5 * (ph_h + ph_c) / 360.0
    if p_head is not None:
        p_head = np.asarray(p_head, float) - o_h
    if p_crank is not None:
        p_crank = (np.asarray(p_crank, float) - o_c) * (g_h / g_c)
    return revs, p_head, p_crank


def reference_from(fits: list[dict[str, Any]], source: str = "") -> ChainReference:
    """The `ChainReference` of records of a diagnoser's own chain.

    ``fits``: per record ``{"head": pressure_phase(...), "crank": pressure_phase(...),
    "condition": int}``. The leave-one-condition-out errors come from a 5-fold split by
    operating condition (scikit-learn's ``GroupKFold``): the error of a condition the
    reference has not seen."""
    from sklearn.model_selection import GroupKFold
    from sklearn.neighbors import NearestNeighbors

    rows: dict[str, dict[str, list[float]]] = {}
    reach: dict[str, float] = {}
    for ch in ("head", "crank"):
        ok = [f for f in fits if f.get(ch, {}).get("ok")]
        if len(ok) < REFERENCE_NEIGHBOURS + 1:
            continue
        col = {
            k: np.array([f[ch][k] for f in ok], float)
            for k in ("n_compression", "n_expansion", "phase_deg", "offset_pa", "phase_sd",
                      "offset_sd")
        }  # fmt: skip
        groups = np.array([f["condition"] for f in ok])
        X = np.column_stack([col["n_compression"], col["n_expansion"]])
        scale = np.std(X, axis=0)
        Z = X / np.where(scale > 0, scale, 1.0)
        res = {"phase": np.zeros(len(ok)), "offset": np.zeros(len(ok))}
        folds = min(5, np.unique(groups).size)
        k = REFERENCE_NEIGHBOURS
        if folds >= 2:
            for tr, te in GroupKFold(folds).split(Z, groups=groups):
                nn = NearestNeighbors(n_neighbors=min(k, tr.size)).fit(Z[tr])
                _, idx = nn.kneighbors(Z[te])
                for name, unit in (("phase", "deg"), ("offset", "pa")):
                    y = col[f"{name}_{unit}"]
                    res[name][te] = y[te] - y[tr][idx].mean(axis=1)
        nn = NearestNeighbors(n_neighbors=min(k + 1, len(ok))).fit(Z)
        dist, _ = nn.kneighbors(Z)
        reach[ch] = float(np.max(dist[:, -1]))
        rows[ch] = {name: v.tolist() for name, v in col.items()}
        rows[ch]["condition"] = groups.astype(float).tolist()
        rows[ch]["phase_res"] = res["phase"].tolist()
        rows[ch]["offset_res"] = res["offset"].tolist()
    both = [f for f in fits if f.get("head", {}).get("ok") and f.get("crank", {}).get("ok")]
    kw: dict[str, Any] = {}
    if both:
        d = np.array([f["head"]["p_lo"] - f["crank"]["p_lo"] for f in both])
        g = np.array(
            [(f["head"]["p_hi"] - f["head"]["p_lo"]) / (f["crank"]["p_hi"] - f["crank"]["p_lo"])
             for f in both]
        )  # fmt: skip
        kw = {
            "suction_diff": float(np.median(d)),
            "suction_diff_spread": float(np.std(d, ddof=1)) if d.size > 1 else 50.0,
            "gain_ratio": float(np.median(g)),
            "gain_ratio_spread": float(np.std(g, ddof=1)) if g.size > 1 else 0.002,
        }
    return ChainReference(rows=rows, reach=reach, records=len(fits), source=source, **kw)


@dataclass
class ChainCorrection:
    """The estimates (`Estimate` by name), the corrected channels and, when the chain
    cannot be made consistent, the refusal's reason."""

    estimates: dict[str, Estimate] = field(default_factory=dict)
    refused: str = ""
    revs: np.ndarray | None = None
    p_head: np.ndarray | None = None
    p_crank: np.ndarray | None = None

    def summary(self) -> dict[str, dict[str, Any]]:
        return {k: asdict(v) for k, v in self.estimates.items()}


# -- kinematics ---------------------------------------------------------------------------------


#: `_machine` by machine (its changes as sorted pairs; () the default machine).
_GEOM: dict[tuple, dict[str, float]] = {}


def _machine(machine=None) -> dict[str, float]:
    """The diagnosis model's mechanism and cylinder: the default machine's, or those of
    ``machine`` (a diagnoser's, `recipdyn.diagnosis.machine.Machine.pairs`)."""
    key = tuple(sorted(dict(machine or {}).items()))
    if key not in _GEOM:
        from ..model.cycle import cycle_geometry
        from ..model.registry import get_model
        from .classes import MODEL

        v = get_model(MODEL).parameters(dict(key))
        r, length, d = float(v["r"]), float(v["l"]), float(v["d"])
        g = cycle_geometry(r, length, d, float(v["bore"]), float(v["rod_diameter"]))
        _GEOM[key] = {
            "r": r,
            "l": length,
            "d": d,
            "x_max": g.x_max,
            "x_min": g.x_min,
            "area_head": g.area_head,
            "area_crank": g.area_crank,
            "clearance": float(v["clearance_fraction"]),
        }
    return _GEOM[key]


def chamber_volume(theta, chamber: str, machine=None) -> np.ndarray:
    """A chamber's volume (m**3) at the crank angle ``theta`` (rad; 0 where the crank points
    along the cylinder axis toward the crosshead), from the slider-crank's kinematics and
    the nominal clearance volume (``machine``: another machine's, `_machine`)."""
    g = _machine(machine)
    th = np.asarray(theta, float)
    x = g["r"] * np.cos(th) + np.sqrt(g["l"] ** 2 - (g["d"] + g["r"] * np.sin(th)) ** 2)
    stroke = g["x_max"] - g["x_min"]
    if chamber == "head":
        a = g["area_head"]
        return g["clearance"] * a * stroke + a * (g["x_max"] - x)
    a = g["area_crank"]
    return g["clearance"] * a * stroke + a * (x - g["x_min"])


# -- the crank angle from the tacho ------------------------------------------------------------


#: From this many tacho pulses the crank angle's fit is a parabola (a drifting speed).
PARABOLA_PULSES = 10


def _degree(n_pulses: int) -> int:
    return 1 if n_pulses < PARABOLA_PULSES else 2


def axis_sd(jitter: Estimate, n_pulses: int) -> float:
    """Standard error (deg) of the fitted crank angle's zero from the pulses' jitter: the
    jitter times ``sqrt(p / N)`` (``p`` coefficients through ``N`` pulses); 0 unmeasured."""
    if not math.isfinite(jitter.value):
        return 0.0
    return jitter.value * math.sqrt((_degree(n_pulses) + 1) / n_pulses)


def tacho_revolutions(edges, n: int, fs: float) -> tuple[np.ndarray, Estimate]:
    """The crank angle (revolutions after the first pulse) at ``n`` samples, fitted to the
    tacho's pulse times (``edges``, s), and the jitter's estimate (degrees RMS).

    A least-squares polynomial of the pulse count in time: a line (constant speed) for
    fewer than 10 pulses, else a parabola (a speed that drifts over the record). A pulse's
    jitter then moves the angle by about ``sqrt(p/N)`` of itself instead of all of it
    (``p`` coefficients, ``N`` pulses). The residuals' RMS over ``N - p`` degrees of
    freedom estimates the jitter; its 95 % half-width is the upper side of a standard
    deviation's chi-square interval (a factor 3.7 at 3 degrees of freedom). Residuals above
    `JITTER_MAX_DEG` are a speed that varies within the record, not jitter: then the angle
    follows the pulses (monotone cubic interpolation, NaN outside them), as
    `recipdyn.analysis.vibration.crank_angle` does."""
    from ..analysis.vibration import crank_angle

    e = np.asarray(edges, float)
    k = np.arange(e.size, dtype=float)
    deg = _degree(e.size)
    t0, ts = e[0], max(e[-1] - e[0], 1e-12)
    coef = np.polyfit((e - t0) / ts, k, deg)
    resid = k - np.polyval(coef, (e - t0) / ts)
    dof = e.size - deg - 1
    t = np.arange(n) / fs
    if dof <= 0:
        revs = np.polyval(coef, (t - t0) / ts)
        jitter = Estimate(math.nan, math.nan, "deg", "not measured", f"{e.size} pulses")
    else:
        from scipy.stats import chi2

        rms = float(np.sqrt(np.sum(resid**2) / dof)) * 360.0
        # the 95 % interval of a standard deviation from dof degrees of freedom is
        # asymmetric; its longer (upper) side is reported
        u = rms * (math.sqrt(dof / chi2.ppf(0.025, dof)) - 1.0)
        if rms > JITTER_MAX_DEG:
            revs = crank_angle(n, fs, pulses=e)
            return revs, Estimate(
                rms,
                u,
                "deg",
                "speed varies",
                "the pulses' spacing varies more than a jitter would: the angle follows them",
            )
        revs = np.polyval(coef, (t - t0) / ts)
        jitter = Estimate(rms, u, "deg", "corrected", f"a {deg}-degree fit through {e.size} pulses")
    # the angle is read between the first and the last pulse, as from the pulses themselves
    revs = np.where((t >= e[0]) & (t <= e[-1]), revs, np.nan)
    return revs, jitter


# -- the crank-angle phase and the offset of one chamber's pressure ------------------------------


def _segments(p, phi, bins: int = 360):
    """The closed-phase segments of one chamber: sample masks of its compression and
    re-expansion (where the angle-binned pressure lies inside `SEGMENT` of the way between
    its levels), and the levels (10th and 90th percentiles of the bins)."""
    b = np.minimum((np.mod(phi, 2 * np.pi) / (2 * np.pi) * bins).astype(int), bins - 1)
    cnt = np.bincount(b, minlength=bins)
    pb = np.bincount(b, p, bins) / np.maximum(cnt, 1)
    if (cnt == 0).any():
        return {}, (math.nan, math.nan)
    lo, hi = np.percentile(pb, 10), np.percentile(pb, 90)
    a, c = lo + SEGMENT[0] * (hi - lo), lo + SEGMENT[1] * (hi - lo)
    inside = (pb > a) & (pb < c)
    if inside.all() or not inside.any():
        return {}, (lo, hi)
    start = int(np.argmin(inside))  # an outside bin: runs do not wrap around it
    runs, cur = [], []
    for k in (np.arange(bins) + start) % bins:
        if inside[k]:
            cur.append(int(k))
        elif cur:
            runs.append(cur)
            cur = []
    if cur:
        runs.append(cur)
    out: dict[str, list[int]] = {}
    for r in runs:
        if len(r) < 6:
            continue
        kind = "compression" if pb[r[-1]] > pb[r[0]] else "expansion"
        if kind not in out or len(r) > len(out[kind]):
            out[kind] = r
    # one bin off each end: a bin straddling the segment's edge holds part of a valve event
    return {k: np.isin(b, r[1:-1]) for k, r in out.items()}, (lo, hi)


def _coarse_phase(parts, chamber, machine=None) -> float:
    """The basin of the phase: every 2 degrees around the circle, the one that straightens
    the segments best, read on their 1-degree means (a mark may sit anywhere)."""
    binned = []
    for q, f in parts:
        b = np.floor(np.degrees(np.mod(f, 2 * np.pi))).astype(int)
        u, inv = np.unique(b, return_inverse=True)
        binned.append((np.bincount(inv, q) / np.bincount(inv), np.radians(u + 0.5)))
    grid = np.radians(np.arange(-180.0, 180.0, 2.0))
    cost = np.zeros(grid.size)
    for i, a in enumerate(grid):
        for q, f in binned:
            y = np.log(q)
            lv = np.log(chamber_volume(f + a, chamber, machine))
            A = np.column_stack([np.ones_like(lv), lv])
            coef, *_ = np.linalg.lstsq(A, y, rcond=None)
            cost[i] += float(np.sum(((y - A @ coef) * q) ** 2))
    return float(grid[np.argmin(cost)])


def _fit_phase(p, phi, segs, chamber, a0=None, machine=None):
    """Variable-projection least squares of ``(A, o)``; returns the solution, its
    covariance from the Jacobian and the residuals' RMS (Pa)."""
    from scipy.optimize import least_squares

    parts = [(p[m], phi[m]) for m in segs.values()]
    floor = min(float(np.min(q)) for q, _ in parts)

    def resid(x):
        a, o = x
        out = []
        for q, f in parts:
            y = np.log(np.maximum(q - o, 1e-3 * floor))
            lv = np.log(chamber_volume(f + a, chamber, machine))
            A = np.column_stack([np.ones_like(lv), lv])
            coef, *_ = np.linalg.lstsq(A, y, rcond=None)
            out.append((y - A @ coef) * (q - o))  # ~ the residual in Pa
        return np.concatenate(out)

    if a0 is None:
        a0 = _coarse_phase(parts, chamber, machine)
    sol = least_squares(resid, [a0, 0.0], x_scale=[1e-2, 1e3], diff_step=[1e-6, 1e-6])
    n = sol.fun.size
    dof = max(n - 2 - 2 * len(parts), 1)
    s2 = float(sol.fun @ sol.fun) / dof
    cov = np.linalg.pinv(sol.jac.T @ sol.jac) * s2
    # the exponents at the solution, and the residuals' white-noise part (successive
    # differences: a slow misfit cancels in them)
    a, o = sol.x
    exps, noise = {}, []
    for kind, (q, f) in zip(segs, parts, strict=True):
        lv = np.log(chamber_volume(f + a, chamber, machine))
        if np.all(q - o > 0):
            exps[kind] = -float(np.polyfit(lv, np.log(q - o), 1)[0])
        else:  # the segment dips below the fitted offset: no polytrope (not a chamber's)
            exps[kind] = math.nan
    r = sol.fun
    noise = float(np.std(np.diff(r)) / math.sqrt(2.0))
    return sol.x, cov, math.sqrt(s2), exps, noise


def pressure_phase(p, revs, chamber: str, machine=None) -> dict[str, Any]:
    """The crank-angle phase and the offset of one chamber's pressure (module docstring).

    Parameters
    ----------
    p : array
        The chamber's pressure, Pa.
    revs : array
        The crank angle in revolutions after the tacho's mark at each sample (NaN: none).
    chamber : {"head", "crank"}
    machine : mapping, optional
        The machine whose chamber it is (`recipdyn.diagnosis.machine.Machine.pairs`; None:
        the default machine).

    Returns
    -------
    dict
        ``phase_deg`` (the mark's crank angle ``A`` read from this chamber: the crank angle
        at which the tacho fires, in the frame where the crank points to the crosshead at 0),
        ``offset_pa``, their standard uncertainties ``phase_sd``, ``offset_sd`` (the larger
        of the Jacobian's and the spread over revolutions / sqrt(N)), the per-revolution
        phases, the residuals' RMS, the levels (``p_lo``, ``p_hi``) and ``ok`` (False: no
        closed-phase segments found)."""
    p = np.asarray(p, float)
    r = np.asarray(revs, float)
    ok = np.isfinite(r) & np.isfinite(p)
    out: dict[str, Any] = {"ok": False, "chamber": chamber}
    if ok.sum() < 100:
        return out
    # a sample or two short of a revolution still covers it (as `evidence._whole_revs`)
    tol = 2.0 * float(np.nanmedian(np.abs(np.diff(r[ok]))))
    start = math.ceil(np.nanmin(r[ok]) - tol)
    stop = math.floor(np.nanmax(r[ok]) + tol)
    whole = ok & (r >= start) & (r < stop)
    if stop - start < 1:
        return out
    pp, phi = p[whole], 2 * np.pi * (r[whole] - start)
    segs, (lo, hi) = _segments(pp, phi)
    if set(segs) != {"compression", "expansion"} or not hi > lo > 0:
        out.update(p_lo=lo, p_hi=hi)
        return out
    x, cov, rms, exps, noise = _fit_phase(pp, phi, segs, chamber, machine=machine)
    if not all(math.isfinite(v) for v in exps.values()):
        # no exponent could be fitted (a flat or noisy channel): no polytropic segments
        out.update(p_lo=float(lo), p_hi=float(hi))
        return out
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
    per_rev, per_off = [], []
    rev_of = np.floor(r[whole] - start).astype(int)
    for k in range(stop - start):
        m = rev_of == k
        seg_k = {s: v & m for s, v in segs.items()}
        if min(int(v.sum()) for v in seg_k.values()) < 10:
            continue
        xk, *_ = _fit_phase(pp, phi, seg_k, chamber, a0=float(x[0]), machine=machine)
        per_rev.append(math.degrees(xk[0]))
        per_off.append(float(xk[1]))
    n = len(per_rev)
    phase_sd, offset_sd = math.degrees(sd[0]), float(sd[1])
    if n >= 3:
        phase_sd = max(phase_sd, float(np.std(per_rev, ddof=1)) / math.sqrt(n))
        offset_sd = max(offset_sd, float(np.std(per_off, ddof=1)) / math.sqrt(n))
    out.update(
        ok=True,
        phase_deg=math.degrees(float(x[0])),
        offset_pa=float(x[1]),
        phase_sd=phase_sd,
        offset_sd=offset_sd,
        per_rev_deg=per_rev,
        rms_pa=rms,
        noise_pa=noise,
        n_compression=exps["compression"],
        n_expansion=exps["expansion"],
        p_lo=float(lo),
        p_hi=float(hi),
        revolutions=stop - start,
    )
    return out


# -- the accelerometer's mounting resonance ------------------------------------------------------


def _resonance_fit(f, s, f0, fs, response="analog"):
    """Fit ``log S = log(K f^b |H(f)|^2 |B(f)|^2 + N)`` over the band around ``f0``: ``H`` the
    mounting resonance, a base-excited single degree of freedom (``response="analog"``: a
    real mount's; ``"bilinear"``: as `recipdyn.sensors.resonance_filter` discretises it, the
    closed form at the bilinear transform's warped frequency), ``B`` a 4th-order Butterworth
    anti-alias low-pass of free corner, analog or digital like ``H`` (the data set's sits at
    0.4 fs, on the flank of a 3-4.5 kHz resonance sampled at 10-12.5 kHz), ``K f^b`` the
    impacts' sloping excitation, ``N`` the white noise floor. Returns ``(parameters (fn, log
    zeta, ...), RMS residual in log power, whether fn or zeta ended at a bound)``, or None."""
    from scipy.optimize import least_squares

    band = (f >= 0.5 * f0) & (f <= min(1.8 * f0, 0.49 * fs))
    fb, sb = f[band], np.log(np.maximum(s[band], 1e-300))
    if fb.size < 12:
        return None
    tb = np.tan(np.pi * fb / fs)
    warped = response == "bilinear"

    def model(x):
        fn, lz, lk, b, ln, fc = x
        z = math.exp(lz)
        rr = tb / math.tan(math.pi * fn / fs) if warped else fb / fn
        h2 = 1.0 / ((1 - rr**2) ** 2 + (2 * z * rr) ** 2)
        lp2 = 1.0 / (1.0 + ((tb / math.tan(math.pi * fc / fs)) if warped else fb / fc) ** 8)
        return np.logaddexp(lk + b * np.log(fb / f0) + np.log(h2 * lp2), ln)

    k0 = float(np.median(sb))
    x0 = [f0, math.log(0.05), k0, 0.0, float(np.min(sb)), 0.4 * fs]
    lb = [0.8 * f0, math.log(0.005), -np.inf, -8.0, -np.inf, 0.2 * fs]
    ub = [min(1.25 * f0, 0.499 * fs), math.log(0.7), np.inf, 8.0, np.inf, 0.499 * fs]
    x0 = np.clip(x0, np.array(lb) + 1e-9, np.array(ub) - 1e-9)
    sol = least_squares(lambda x: model(x) - sb, x0, bounds=(lb, ub), x_scale="jac")
    at_bound = bool(
        sol.x[1] >= ub[1] - 0.05 or sol.x[0] <= lb[0] * 1.005 or sol.x[0] >= ub[0] * 0.995
    )
    return sol.x, float(np.sqrt(np.mean(sol.fun**2))), at_bound


def resonance(
    x, fs: float, revs=None, response: str = "analog", min_hz: float = RESONANCE_MIN_HZ
) -> dict[str, Estimate]:
    """The accelerometer's mounting resonance: frequency and damping ratio with their 95 %
    half-widths, from the spread of the fit (`_resonance_fit`) over the record's parts (its
    revolutions, or up to eight equal parts without a crank angle) and the fit's own
    systematic error. ``response``: the resonance's form, ``"analog"`` (a real mount) or
    ``"bilinear"`` (`recipdyn.sensors.resonance_filter`, whose warped flank makes an analog
    fit read the damping low near the Nyquist frequency: 0.05 read as 0.014 at 0.4 fs).
    ``min_hz``: the lowest spectral peak tried (default `RESONANCE_MIN_HZ`)."""
    from scipy.signal import find_peaks, welch

    x = np.asarray(x, float)
    nan = Estimate(math.nan, math.nan, "Hz", "not measured", "no resonance peak")
    nper = min(1024, x.size)
    f, s = welch(x, fs=fs, nperseg=nper)
    # the candidates: the most prominent peaks above the impacts' high-pass (the largest is
    # `evidence.ringing_hz`); the resonance is the one the second-order response fits best
    start = int(np.searchsorted(f, min_hz, side="right"))
    lp = 10 * np.log10(s[start:] + 1e-300)
    peaks, props = find_peaks(lp, prominence=0)
    order = np.argsort(props["prominences"])[::-1][:RESONANCE_CANDIDATES]
    best = at_bound = None
    for i in order:  # the most prominent peak a mount's second-order response fits
        r = _resonance_fit(f, s, f[start + peaks[i]], fs, response)
        if r is not None and not r[2] and math.exp(r[0][1]) <= RESONANCE_DAMPING_MAX:
            best, at_bound = r[0], False
            break
        if best is None and r is not None:
            best, at_bound = r[0], True
    if best is None:
        return {"resonance_hz": nan, "damping": dataclass_replace(nan, unit="1")}
    fn, z = float(best[0]), math.exp(float(best[1]))
    if at_bound:
        why = (
            "no peak of the spectrum is a mount's second-order response (its fit ends at a "
            f"bound, or its damping exceeds {RESONANCE_DAMPING_MAX:g})"
        )
        return {
            "resonance_hz": Estimate(fn, math.nan, "Hz", "not identified", why),
            "damping": Estimate(z, math.nan, "1", "not identified", why),
        }
    # the spread over parts of the record
    if revs is not None and np.isfinite(revs).any():
        r = np.asarray(revs, float)
        k = np.floor(r - np.nanmin(r))
        parts = [x[k == i] for i in range(int(np.nanmax(k)) + 1)]
    else:
        parts = np.array_split(x, max(2, min(8, x.size // (2 * nper))))
    parts = [q for q in parts if q.size >= 2 * nper]
    fits = []
    for q in parts:
        ff, sq = welch(q, fs=fs, nperseg=nper)
        b = _resonance_fit(ff, sq, fn, fs, response)
        if b is not None and not b[2]:
            fits.append((b[0][0], math.exp(b[0][1])))
    # the fit's own systematic error: half a spectral line, and the relative errors above
    sys_fn = math.hypot(0.5 * fs / nper, RESONANCE_FREQUENCY_REL * fn)
    sys_z = RESONANCE_DAMPING_REL * z
    if len(fits) >= 3:
        a = np.array(fits)
        u_fn = math.hypot(K95 * float(np.std(a[:, 0], ddof=1)) / math.sqrt(len(fits)), sys_fn)
        u_z = math.hypot(K95 * float(np.std(a[:, 1], ddof=1)) / math.sqrt(len(fits)), sys_z)
        note = f"spread over {len(fits)} parts of the record"
        status = "measured"
    else:
        u_fn, u_z = math.nan, math.nan
        note, status = "too few parts of the record fit it for its spread", "not identified"
    return {
        "resonance_hz": Estimate(fn, u_fn, "Hz", status, note),
        "damping": Estimate(z, u_z, "1", status, note),
    }


def dataclass_replace(e: Estimate, **kw) -> Estimate:
    from dataclasses import replace

    return replace(e, **kw)


# -- the whole chain ------------------------------------------------------------------------------


def _significant(d: float, sd: float) -> bool:
    """Whether ``d`` lies outside the 95 % interval (``sd``: its standard uncertainty)
    around 0: a smaller correction is indistinguishable from the estimate's own error, and
    applying it would only add that error."""
    return abs(d) > K95 * sd


def correct_chain(
    revs,
    *,
    p_head=None,
    p_crank=None,
    reference: ChainReference | None = None,
    axis_sd_deg: float = 0.0,
    fits: dict[str, dict[str, Any]] | None = None,
    exclude_condition=None,
    machine=None,
) -> ChainCorrection:
    """Estimate the pressure channels' crank-angle phase, offsets and relative gain against
    the diagnoser's own chain (``reference``), check the two chambers against each other
    and return the corrected crank angle and pressures (``machine``: the diagnoser's machine,
    `recipdyn.diagnosis.machine.Machine.pairs`, whose chambers' volumes the polytropes are
    read against; None: the default machine). ``axis_sd_deg``: the standard error
    of the crank angle's zero from the tacho's jitter (`axis_sd`); ``fits``: the chambers'
    `pressure_phase` already computed on these ``revs`` (a data set stores them);
    ``exclude_condition``: the record's operating condition, left out of the reference
    (`ChainReference.bias`).

    For each chamber, `pressure_phase` gives the mark's crank angle and the offset; the
    reference's records with the same polytropic exponents give what the diagnoser's own
    chain shows there (`ChainReference.bias`); the difference is the chain's error. Then:

    * **phase**: the two chambers' errors, which one crank angle must share, are checked
      against each other (within `CONSISTENCY_SIGMAS` combined standard uncertainties) and
      combined (inverse-variance weights);
    * **relative gain**: the ratio of the two chambers' spans between the suction and
      discharge lines they share, against the reference's; the crank end is scaled to the
      head end's gain (the common gain is not identifiable);
    * **offsets**: each chamber's, and their difference from the two suction levels (both
      chambers draw from one line: on the reference records their difference spreads by
      tens of pascals, against hundreds for an offset from the polytropes), combined by least
      squares after a check that the three agree.

    A correction is applied where it lies outside its own 95 % interval (`_significant`).
    Refused (``refused`` holds the reason, naming the channel): a pressure channel without
    a compression and a re-expansion; exponents unlike any of the reference's records;
    chambers that disagree; a suction level that is not positive once the offset is off.
    Without a reference the estimates are reported and nothing is corrected."""
    revs = np.asarray(revs, float)
    out = ChainCorrection(revs=revs, p_head=p_head, p_crank=p_crank)
    est = out.estimates
    given = fits or {}
    fits = {}
    for chamber, p in (("head", p_head), ("crank", p_crank)):
        if p is None:
            continue
        r = given.get(chamber) or pressure_phase(p, revs, chamber, machine)
        if not r["ok"]:
            out.refused = (
                f"p_{chamber}: no polytropic compression and re-expansion found in the "
                f"{chamber}-end pressure (its levels {r.get('p_lo', math.nan):.4g}.."
                f"{r.get('p_hi', math.nan):.4g} Pa), so its crank-angle phase and offset "
                "cannot be read: is it this machine's chamber pressure, in Pa, over whole "
                "revolutions?"
            )
            return out
        fits[chamber] = r
    if not fits:
        return out
    ref = reference
    # each chamber's chain errors: its estimates less what the reference shows there
    err: dict[str, dict[str, float]] = {}
    for ch, r in fits.items():
        if ref is None or ch not in ref.rows:
            b = (0.0, 0.0, math.inf, math.inf, True)
        else:
            b = ref.bias(ch, r["n_compression"], r["n_expansion"], exclude_condition)
        if not b[4]:
            out.refused = (
                f"p_{ch}: the {ch} end's polytropic exponents (compression "
                f"{r['n_compression']:.3f}, re-expansion {r['n_expansion']:.3f}) are unlike "
                "those of every record the diagnoser's chain was measured on: another gas, "
                "another machine or a fault outside the data set, against which its phase "
                "and offset cannot be read"
            )
            return out
        err[ch] = {
            "phase": r["phase_deg"] - b[0],
            "phase_sd": math.hypot(r["phase_sd"], b[2]),
            "offset": r["offset_pa"] - b[1],
            "offset_sd": math.hypot(r["offset_sd"], b[3]),
        }
        est[f"phase_{ch}"] = Estimate(
            err[ch]["phase"],
            K95 * err[ch]["phase_sd"],
            "deg",
            "measured",
            f"the tacho mark's crank angle from the {ch} end's polytropes, against the "
            f"diagnoser's chain ({r['revolutions']} revolutions; exponents "
            f"{r['n_compression']:.3f}, {r['n_expansion']:.3f})",
        )
    if ref is None:
        for ch in fits:
            est[f"offset_{ch}"] = Estimate(
                err[ch]["offset"], math.inf, "Pa", "no reference: not corrected"
            )
        return out
    # -- the phase ---------------------------------------------------------------------------
    if len(err) == 2:
        h, c = err["head"], err["crank"]
        sd = math.hypot(h["phase_sd"], c["phase_sd"])
        ok = abs(h["phase"] - c["phase"]) <= CONSISTENCY_SIGMAS * sd
        est["phase_agreement"] = Estimate(
            h["phase"] - c["phase"],
            K95 * sd,
            "deg",
            "consistent" if ok else "inconsistent",
            "head-end minus crank-end phase: one crank angle, two chambers",
        )
        if not ok:
            out.refused = (
                f"p_head and p_crank: the two chambers put the crank angle "
                f"{h['phase'] - c['phase']:+.2f} deg apart (head end {h['phase']:+.2f}, crank "
                f"end {c['phase']:+.2f} deg from the diagnoser's frame; allowed "
                f"{CONSISTENCY_SIGMAS * sd:.2f} deg): a delay between the two pressure "
                "channels, or a chamber that is not this machine's; align the pressure "
                "channels, or diagnose with one of them"
            )
            return out
    w = {ch: 1.0 / e["phase_sd"] ** 2 for ch, e in err.items()}
    phase = sum(err[ch]["phase"] * w[ch] for ch in err) / sum(w.values())
    # the pressures' phase against the fitted crank angle: what the correction applies
    core_sd = 1.0 / math.sqrt(sum(w.values()))
    applied = _significant(phase, core_sd)
    # the fitted crank angle's own zero is uncertain by the tacho's jitter (`axis_sd`): the
    # correction aligns it to the pressures whatever it is, but as the mark's angle the
    # estimate carries that uncertainty too
    phase_sd = math.hypot(core_sd, axis_sd_deg)
    est["phase"] = Estimate(
        phase,
        K95 * phase_sd,
        "deg",
        "corrected" if applied else "within its uncertainty: left",
        "the crank angle of the tacho's mark, with the pressures' delay behind it (the two "
        "are not identifiable apart), against the diagnoser's chain; applied to the crank "
        "angle of every channel",
    )
    if applied:
        out.revs = revs + phase / 360.0
    # -- the relative gain and the offsets ------------------------------------------------------
    gamma = 1.0  # the crank end's gain over the head end's
    if len(fits) == 2:
        h, c = fits["head"], fits["crank"]
        ratio = (h["p_hi"] - h["p_lo"]) / (c["p_hi"] - c["p_lo"])
        rel = ratio / ref.gain_ratio - 1.0
        sd = ref.gain_ratio_spread / ref.gain_ratio
        g_applied = _significant(rel, sd)
        est["gain_ratio"] = Estimate(
            rel,
            K95 * sd,
            "1",
            "corrected" if g_applied else "within its uncertainty: left",
            "the head end's gain over the crank end's, minus 1, from their spans between "
            "the line pressures they share; the crank end is scaled to the head end's (a "
            "common gain leaves the polytropes straight: not identifiable)",
        )
        if g_applied:
            gamma = 1.0 / (1.0 + rel)
        # the two offsets and their difference from the suction levels, by least squares
        lo_c_true = (c["p_lo"] - err["crank"]["offset"]) / gamma
        diff = h["p_lo"] - c["p_lo"] - (1.0 - gamma) * lo_c_true - ref.suction_diff
        s_h, s_c, s_d = err["head"]["offset_sd"], err["crank"]["offset_sd"], ref.suction_diff_spread
        o_h, o_c = err["head"]["offset"], err["crank"]["offset"]
        s_all = math.sqrt(s_h**2 + s_c**2 + s_d**2)
        chi = (o_h - o_c - diff) / s_all
        ok = abs(chi) <= CONSISTENCY_SIGMAS
        est["suction_agreement"] = Estimate(
            o_h - o_c - diff,
            K95 * s_all,
            "Pa",
            "consistent" if ok else "inconsistent",
            "the two offsets' difference from the polytropes less that from the suction "
            "levels (both chambers draw from one suction line)",
        )
        if not ok:
            out.refused = (
                f"p_head and p_crank: their offsets from the polytropes ({o_h:+.3g}, "
                f"{o_c:+.3g} Pa) differ by {o_h - o_c - diff:+.3g} Pa from what their suction "
                f"levels say (allowed {CONSISTENCY_SIGMAS * s_all:.2g} Pa), though both chambers "
                "draw from one suction line: an offset that "
                "drifts, a chamber that is not this machine's, or a nonlinear transducer; "
                "check the two transducers' zero"
            )
            return out
        # minimise (o_h - ô_h)^2/s_h^2 + (o_c - ô_c)^2/s_c^2 + (o_h - o_c - diff)^2/s_d^2
        A = np.array(
            [[1 / s_h**2 + 1 / s_d**2, -1 / s_d**2], [-1 / s_d**2, 1 / s_c**2 + 1 / s_d**2]]
        )
        b = np.array([o_h / s_h**2 + diff / s_d**2, o_c / s_c**2 - diff / s_d**2])
        cov = np.linalg.inv(A)
        (o_h, o_c), sds = np.linalg.solve(A, b), np.sqrt(np.diag(cov))
        err["head"]["offset"], err["head"]["offset_sd"] = float(o_h), float(sds[0])
        err["crank"]["offset"], err["crank"]["offset_sd"] = float(o_c), float(sds[1])
    for ch, r in fits.items():
        o, sd = err[ch]["offset"], err[ch]["offset_sd"]
        applied = _significant(o, sd)
        est[f"offset_{ch}"] = Estimate(
            o,
            K95 * sd,
            "Pa",
            "corrected" if applied else "within its uncertainty: left",
            f"the {ch}-end transducer's offset against the diagnoser's chain",
        )
        p = p_head if ch == "head" else p_crank
        o_used = o if applied else 0.0
        g = gamma if ch == "crank" else 1.0
        q = p if (o_used == 0.0 and g == 1.0) else (np.asarray(p, float) - o_used) / g
        lo, hi = (r["p_lo"] - o_used) / g, (r["p_hi"] - o_used) / g
        if not lo > 0 or not hi > lo:
            out.refused = (
                f"p_{ch}: with its offset ({o:+.3g} Pa) removed the {ch} end's suction level "
                f"is {lo:.4g} Pa and its discharge level {hi:.4g} Pa: not a compressor "
                "chamber's absolute pressure; check the channel's units and zero"
            )
            return out
        if ch == "head":
            out.p_head = q
        else:
            out.p_crank = q
    return out
