"""Whole-record statistics of a signal longer than memory, fed block by block.

A measured record can be hours at tens of kHz (10^8-10^9 samples): the detailed analyses run on
an excerpt, but the numbers a vibration engineer quotes for the record (overall RMS, peak, crest
factor, kurtosis, band velocity RMS, the averaged spectrum) must cover all of it. Both
accumulators here give, for any split of the record into blocks, the result of the whole-array
computation up to rounding:

- [`RunningMoments`][recipdyn.analysis.streaming.RunningMoments]: count, mean, central moments 2-4,
  min and max, merged block by block with the pairwise update of Chan, Golub & LeVeque (1983) and
  Pébay (2008, Sandia report SAND2008-6212, Eq. 1.1-1.3), which stays accurate where raw power sums
  cancel;
- [`StreamingWelch`][recipdyn.analysis.streaming.StreamingWelch]: Welch's averaged periodogram
  (scipy.signal.welch, Hann window, half overlap, mean removed per segment) with segments that
  straddle the block boundaries, so the segments and their average are exactly those of ``welch`` on
  the whole record.

Memory: one block plus one segment, whatever the record's length.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.signal import get_window, welch

__all__ = ["RunningMoments", "StreamingWelch", "TachoEdges"]


@dataclass
class RunningMoments:
    """Count, mean and central moments of everything fed so far (merged exactly per block)."""

    n: int = 0
    mean: float = 0.0
    m2: float = 0.0
    m3: float = 0.0
    m4: float = 0.0
    lo: float = math.inf
    hi: float = -math.inf

    def feed(self, block) -> None:
        x = np.asarray(block, dtype=float).ravel()
        nb = x.size
        if nb == 0:
            return
        mb = float(x.mean())
        d = x - mb
        d2 = d * d
        m2b, m3b, m4b = float(d2.sum()), float((d2 * d).sum()), float((d2 * d2).sum())
        self.lo, self.hi = min(self.lo, float(x.min())), max(self.hi, float(x.max()))
        na = self.n
        if na == 0:
            self.n, self.mean, self.m2, self.m3, self.m4 = nb, mb, m2b, m3b, m4b
            return
        n = na + nb
        delta = mb - self.mean
        m2a, m3a = self.m2, self.m3
        self.m4 += (m4b + delta**4 * na * nb * (na * na - na * nb + nb * nb) / n**3
                    + 6.0 * delta**2 * (na * na * m2b + nb * nb * m2a) / n**2
                    + 4.0 * delta * (na * m3b - nb * m3a) / n)  # fmt: skip
        self.m3 += (m3b + delta**3 * na * nb * (na - nb) / n**2
                    + 3.0 * delta * (na * m2b - nb * m2a) / n)  # fmt: skip
        self.m2 += m2b + delta**2 * na * nb / n
        self.mean += delta * nb / n
        self.n = n

    def indicators(self) -> dict[str, float]:
        """The keys and definitions of
        [`recipdyn.analysis.vibration.indicators`][recipdyn.analysis.vibration.indicators] (RMS,
        peak and crest factor of the mean-free record, peak-to-peak, Pearson kurtosis, skewness)."""
        if self.n < 2:
            raise ValueError(f"{self.n} sample(s) fed; need at least 2")
        rms = math.sqrt(self.m2 / self.n)
        peak = max(self.hi - self.mean, self.mean - self.lo)
        nan, m2 = float("nan"), self.m2
        return {"rms": rms, "peak": peak, "peak_to_peak": self.hi - self.lo,
                "crest_factor": peak / rms if rms > 0 else nan,
                "kurtosis": self.n * self.m4 / m2**2 if m2 > 0 else nan,
                "skewness": math.sqrt(self.n) * self.m3 / m2**1.5 if m2 > 0 else nan}  # fmt: skip


@dataclass
class StreamingWelch:
    """Welch's PSD (one-sided, density scaling, Hann, ``nperseg // 2`` overlap) of a record fed
    block by block; equal to ``scipy.signal.welch(x, fs, nperseg=nperseg)`` on the whole."""

    fs: float
    nperseg: int
    segments: int = 0
    _sum: np.ndarray | None = field(default=None, repr=False)
    _buf: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)

    @property
    def hop(self) -> int:
        return self.nperseg - self.nperseg // 2

    def feed(self, block) -> None:
        buf = np.concatenate([self._buf, np.asarray(block, dtype=float).ravel()])
        if buf.size >= self.nperseg:
            k = (buf.size - self.nperseg) // self.hop + 1
            span = self.nperseg + (k - 1) * self.hop
            self.frequency, p = welch(buf[:span], self.fs, nperseg=self.nperseg)
            self._sum = p * k if self._sum is None else self._sum + p * k
            self.segments += k
            buf = buf[k * self.hop :]
        self._buf = buf

    def psd(self) -> tuple[np.ndarray, np.ndarray]:
        """``(frequency Hz, PSD unit**2/Hz)``, the mean over all complete segments."""
        if not self.segments:
            raise ValueError(f"the record is shorter than one segment ({self.nperseg} samples)")
        return self.frequency, self._sum / self.segments

    def amplitude(self) -> tuple[np.ndarray, np.ndarray]:
        """``(frequency, peak amplitude of a sinusoid centred on a bin)``:
        ``sqrt(2 PSD ENBW)``, ENBW = ``fs sum(w^2) / sum(w)^2`` the window's noise bandwidth."""
        f, p = self.psd()
        w = get_window("hann", self.nperseg)
        enbw = self.fs * np.sum(w**2) / np.sum(w) ** 2
        amp = np.sqrt(2.0 * p * enbw)
        amp[0] /= math.sqrt(2.0)  # DC and Nyquist are not doubled in the one-sided PSD
        if self.nperseg % 2 == 0:
            amp[-1] /= math.sqrt(2.0)
        return f, amp

    def band_rms(self, band: tuple[float, float], *, integrate: int = 0) -> float:
        """RMS in ``band`` (Hz) from the PSD, after ``integrate`` integrations in frequency
        (1: acceleration to velocity): ``sqrt(sum PSD / (2 pi f)^(2 integrate) df)``."""
        f, p = self.psd()
        keep = (f >= band[0]) & (f <= band[1]) & (f > 0)
        df = self.fs / self.nperseg
        return float(np.sqrt(np.sum(p[keep] / (2 * np.pi * f[keep]) ** (2 * integrate)) * df))


class TachoEdges:
    """Leading edges of a once-per-revolution pulse channel fed block by block: the rule of
    [`recipdyn.analysis.vibration.tacho_times`][recipdyn.analysis.vibration.tacho_times] (the
    levels, polarity and noise of
    [`tacho_levels`][recipdyn.analysis.vibration.tacho_levels], a half-way trigger, an edge
    re-armed once the signal has passed back through the re-arm level), with the levels taken
    from the first block (which must hold a few revolutions) and the re-arm state carried
    across blocks, so an edge on a block boundary counts once; `times` checks the train as
    ``tacho_times`` does."""

    def __init__(self, fs: float, *, hysteresis: float = 0.1, polarity: str = "auto",
                 max_speed_hz: float = 100.0) -> None:  # fmt: skip
        self.fs, self.hysteresis, self.polarity = float(fs), float(hysteresis), polarity
        self.max_speed_hz = float(max_speed_hz)
        self.levels = None
        self.threshold: float | None = None
        self._armed = True
        self._last = math.nan
        self._offset = 0  # index of the block's first sample in the record
        self._edges: list[float] = []

    def feed(self, block) -> None:
        from .vibration import _leading_edges, tacho_levels

        v = np.asarray(block, dtype=float).ravel()
        if v.size == 0:
            return
        if self.levels is None:
            if not np.ptp(v) > 0:
                raise ValueError("tacho channel is flat in its first block: no pulses")
            self.levels = tacho_levels(v, polarity=self.polarity, hysteresis=self.hysteresis)
            self.threshold = self.levels.threshold
        w = np.r_[self._last, v]  # the previous block's last sample: edges across the seam
        if self._offset == 0:
            w = w[1:]
        edges, self._armed = _leading_edges(w, self.levels, self.fs,
                                            offset=self._offset - (self._offset > 0),
                                            armed=self._armed)  # fmt: skip
        self._edges.extend(edges)
        self._last = float(v[-1])
        self._offset += v.size

    def times(self) -> np.ndarray:
        """Edge times (s from the record's first sample)."""
        from .vibration import check_pulse_train

        check_pulse_train(self._edges, max_speed_hz=self.max_speed_hz)
        return np.array(self._edges)
