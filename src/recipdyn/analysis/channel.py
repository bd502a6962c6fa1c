"""What a sampled channel's own samples tell of the chain that recorded it: clipping, the
converter's step, and mains hum.

Generic estimators of any digitised signal (nothing here knows of cranks): a record whose
channel clipped, whose converter is coarser, or that carries more mains hum than the records
a model was built from, lies outside that model's domain, and each of these is read from the
channel itself.

**Clipping** (`clipping`). An analog-to-digital converter maps every input beyond its range
to its end code, so a clipped channel reaches *exactly the same* extreme value again and
again, each time jumping onto it from well below and leaving it as steeply: flat tops at the
extremes. An unclipped signal reaches its extreme once (noise makes the largest sample
unique), and a smooth, unclipped peak that spans several samples of one code turns over
beneath it, one code step at a time. So an excursion counts as clipped where it sits on the
channel's extreme value and both the sample before and the one after lie more than
`CLIP_STEP_CODES` converter steps below it; the channel is clipped when `CLIP_MIN_RUNS` or
more excursions do (Eaton & Naylor 2013 read clipping from the same spike at the histogram's
ends).

**Converter step** (`level_spacing`). The values of a converter's output are whole multiples
of its step (plus an offset): the step is the smallest spacing of adjacent distinct values,
confirmed by the other spacings being whole multiples of it. Read only where the signal
visits enough adjacent codes (its noise spans several steps); otherwise unknown.

**Mains hum** (`mains_hum`). The hum is a sinusoid at the mains frequency and its
harmonics; a machine's own signal has lines at the orders of its speed too. With the
signal's crank angle given, its synchronous average (the mean over revolutions at each angle
bin) is taken out first, and the hum's amplitude is the least-squares fit of a sinusoid at
the mains harmonic to what remains, against templates put through the same removal (so a
hum that the average partly absorbs is not under-read). Its uncertainty is the same fit at
neighbouring frequencies, where no line is: their mean square is the noise's share of the
estimate. Where the mains harmonic lies so close to an order of the speed that the average
absorbs most of it the hum is not estimated.

References
----------
J. Eaton, P. A. Naylor, "Detection of clipping in coded speech signals", EUSIPCO 2013.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Clipping", "clipping", "level_spacing", "Hum", "mains_hum", "mains_hums",
           "CLIP_MIN_RUNS", "CLIP_STEP_CODES"]  # fmt: skip

#: Excursions onto one extreme value that make a channel clipped (`clipping`): an unclipped
#: signal with noise reaches its extreme once.
CLIP_MIN_RUNS = 3
#: How far (in converter steps) the samples either side of a clipped excursion lie below it:
#: a smooth unclipped peak turns over within about one step of its top code.
CLIP_STEP_CODES = 2.0
#: Share of a hum template's energy the synchronous average may absorb before the hum is
#: not estimated (`mains_hum`).
HUM_MIN_KEPT = 0.3
#: Neighbouring frequencies (in steps of ``1/T``) the hum fit's noise is read at.
HUM_NEIGHBOURS = tuple(range(3, 13))
#: Two-sided 95 % point of the normal distribution.
K95 = 1.959964


@dataclass(frozen=True)
class Clipping:
    """``runs``: excursions onto the channel's maximum (``top``) and minimum (``bottom``)
    that jump onto it and off it (`clipping`); ``samples``: the samples they hold;
    ``clipped``: at either end at least `CLIP_MIN_RUNS` of them."""

    top_runs: int
    bottom_runs: int
    top: float
    bottom: float
    samples: int
    step: float

    @property
    def clipped(self) -> bool:
        return max(self.top_runs, self.bottom_runs) >= CLIP_MIN_RUNS

    def text(self) -> str:
        ends = []
        if self.top_runs >= CLIP_MIN_RUNS:
            ends.append(f"{self.top_runs} flat tops at its maximum {self.top:.6g}")
        if self.bottom_runs >= CLIP_MIN_RUNS:
            ends.append(f"{self.bottom_runs} flat bottoms at its minimum {self.bottom:.6g}")
        return " and ".join(ends) or "no flat tops at its extremes"


def level_spacing(x, min_codes: int = 50) -> float:
    """The converter step of ``x``: the smallest spacing of adjacent distinct values, where
    at least ``min_codes`` adjacent pairs of distinct values are that spacing apart and the
    spacings are whole multiples of it (within 1 %); NaN otherwise (an unquantised signal, or
    one whose noise visits too few codes)."""
    v = np.unique(np.asarray(x, float))
    v = v[np.isfinite(v)]
    if v.size < min_codes + 1:
        return math.nan
    d = np.diff(v)
    scale = max(float(np.max(np.abs(v))), 1e-300)
    d = d[d > 1e-12 * scale]
    if d.size < min_codes:
        return math.nan
    q = float(np.min(d))
    ratio = d / q
    whole = np.abs(ratio - np.round(ratio)) <= 0.01
    near = np.count_nonzero(np.round(ratio) == 1)
    if near < min_codes or np.count_nonzero(whole) < 0.99 * d.size:
        return math.nan
    return float(np.mean(d[np.round(ratio) == 1]))


def _runs(mask) -> list[tuple[int, int]]:
    """``[(start, stop)]`` of the runs of True in ``mask``."""
    m = np.concatenate(([False], np.asarray(mask, bool), [False]))
    edges = np.flatnonzero(m[1:] != m[:-1])
    return list(zip(edges[::2].tolist(), edges[1::2].tolist(), strict=True))


def clipping(x) -> Clipping:
    """Flat tops at the extremes of ``x`` (see the module's notes): the excursions onto its
    maximum (and minimum) value whose neighbours lie more than `CLIP_STEP_CODES` converter
    steps away (`level_spacing`; where it is not read, the smallest spacing of distinct
    values: an unquantised signal's is tiny, so any step off its extreme counts).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(4000) / 1000.0
    >>> x = np.round(np.sin(2 * np.pi * 3 * t) * 2**12) / 2**12
    >>> clipping(x).clipped, clipping(np.clip(1.5 * x, -1, 1)).clipped
    (False, True)
    """
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    step = level_spacing(x)
    if not math.isfinite(step):  # too few adjacent codes: the smallest spacing seen
        d = np.diff(np.unique(x))
        step = float(np.min(d)) if d.size else 0.0
    gap = CLIP_STEP_CODES * step
    counts, samples = [], 0
    for sign in (1.0, -1.0):
        y = sign * x
        top = float(np.max(y))
        n = 0
        for a, b in _runs(y == top):
            before = y[a - 1] if a > 0 else -math.inf
            after = y[b] if b < y.size else -math.inf
            if top - before > gap and top - after > gap:
                n += 1
                samples += b - a
        counts.append(n)
    return Clipping(counts[0], counts[1], float(np.max(x)), float(np.min(x)), samples, step)


@dataclass(frozen=True)
class Hum:
    """A mains harmonic's amplitude in a signal: ``amplitude`` (the sinusoid's peak, the
    signal's units) with its 95 % interval ``[lo, hi]``, ``rms`` the signal's RMS without
    it, and the level ``db = 20 log10(amplitude / rms)`` with its interval (``db_lo`` -inf
    where the interval reaches zero); NaN and ``note`` where not estimated."""

    freq_hz: float
    amplitude: float
    lo: float
    hi: float
    rms: float
    note: str = ""

    @property
    def db(self) -> float:
        return _db(self.amplitude, self.rms)

    @property
    def db_lo(self) -> float:
        return _db(self.lo, self.rms)

    @property
    def db_hi(self) -> float:
        return _db(self.hi, self.rms)


def _db(a, rms) -> float:
    if not (math.isfinite(a) and math.isfinite(rms)) or rms <= 0:
        return math.nan
    return 20.0 * math.log10(a / rms) if a > 0 else -math.inf


def _synchronous_remover(revs, bins: int):
    """A function removing the synchronous average (``bins`` bins per revolution of
    ``revs``) from a signal on the same samples."""
    r = np.asarray(revs, float)
    idx = np.minimum((np.mod(r, 1.0) * bins).astype(np.int64), bins - 1)
    count = np.bincount(idx, minlength=bins).astype(float)
    count[count == 0] = 1.0

    def remove(y):
        mean = np.bincount(idx, weights=y, minlength=bins) / count
        return y - mean[idx]

    return remove


def mains_hum(
    x, fs: float, freq_hz: float, revs=None, bins: int | None = None, about_mean: bool = True
) -> Hum:
    """The amplitude of the sinusoid at ``freq_hz`` in ``x`` (sampled at ``fs`` Hz) with its
    95 % interval; ``revs``: the signal's crank angle in revolutions at each sample, whose
    synchronous average (``bins`` per revolution; default about one per sample) is removed
    first (see the module's notes). ``about_mean``: the level is against the RMS of the
    signal less its mean (an AC signal's); False: against its RMS with the mean (an absolute
    pressure's). `mains_hums` reads several frequencies of one signal at once.

    Examples
    --------
    >>> import numpy as np
    >>> fs = 2000.0; t = np.arange(8000) / fs
    >>> x = np.random.default_rng(0).normal(size=t.size) + 0.1 * np.sin(2 * np.pi * 50 * t)
    >>> h = mains_hum(x, fs, 50.0)
    >>> bool(h.lo < 0.1 < h.hi)
    True
    """
    return mains_hums(x, fs, (freq_hz,), revs, bins, about_mean)[0]


def mains_hums(
    x, fs: float, freqs, revs=None, bins: int | None = None, about_mean: bool = True
) -> tuple[Hum, ...]:
    """`mains_hum` at each of ``freqs``, the signal's synchronous average removed once."""
    x = np.asarray(x, float)
    n = x.size
    if n < 16:
        return tuple(_no_hum(f, "above the Nyquist frequency") for f in freqs)
    mean = float(np.mean(x))
    x = x - mean
    t = np.arange(n) / fs
    if revs is not None:
        r = np.asarray(revs, float)
        if r.shape != x.shape or not np.all(np.isfinite(r)):
            raise ValueError("revs: one finite crank angle per sample")
        span = float(r[-1] - r[0])
        m = bins or max(8, int(round(n / max(span, 1.0))))
        remove = _synchronous_remover(r, m)
    else:

        def remove(y):
            return y - np.mean(y)

    y = remove(x)
    return tuple(_hum(x, y, t, fs, f, remove, mean, about_mean) for f in freqs)


def _no_hum(freq_hz: float, note: str) -> Hum:
    return Hum(freq_hz, math.nan, math.nan, math.nan, math.nan, note)


def _hum(x, y, t, fs: float, freq_hz: float, remove, mean: float, about_mean: bool) -> Hum:
    """One frequency of `mains_hums`: ``x`` the signal less its mean, ``y`` that less its
    synchronous average (``remove``), ``t`` the samples' times."""
    n = x.size
    if not 0 < freq_hz < 0.5 * fs:
        return _no_hum(freq_hz, "above the Nyquist frequency")

    def fit(f):
        c, s = np.cos(2 * np.pi * f * t), np.sin(2 * np.pi * f * t)
        a = np.column_stack([remove(c), remove(s)])
        kept = float(np.sum(a**2)) / float(np.sum(c**2) + np.sum(s**2))
        coef, *_ = np.linalg.lstsq(a, y, rcond=None)
        return coef, kept

    coef, kept = fit(freq_hz)
    if kept < HUM_MIN_KEPT:
        return _no_hum(freq_hz, f"{freq_hz:g} Hz lies on an order of the speed (the "
                       "synchronous average holds it)")  # fmt: skip
    amp = float(math.hypot(*coef))
    # the noise's share: the same fit at neighbouring frequencies, away from any hum line
    df = fs / n
    noise = []
    for j in HUM_NEIGHBOURS:
        for f in (freq_hz - j * df, freq_hz + j * df):
            if 0 < f < 0.5 * fs:
                c2, k2 = fit(f)
                if k2 >= HUM_MIN_KEPT:
                    noise.append(float(np.sum(c2**2)))
    if len(noise) < 5:
        return _no_hum(freq_hz, "too few neighbouring frequencies")
    sd = math.sqrt(0.5 * float(np.mean(noise)))  # one coefficient's standard deviation
    w = 2 * np.pi * freq_hz * t
    rest = x - coef[0] * np.cos(w) - coef[1] * np.sin(w) + (0.0 if about_mean else mean)
    rms = float(np.sqrt(np.mean(rest**2)))
    return Hum(freq_hz, amp, max(amp - K95 * sd, 0.0), amp + K95 * sd, rms)
