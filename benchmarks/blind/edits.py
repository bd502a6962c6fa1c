"""Changes applied to a record's recorded channels after its chain: one thing at a time, as
the issue's examples make them (an offset on a pressure channel, a delay of some samples, a
filter, a tacho of other settings). Each is a small frozen dataclass (so a record's
description prints and pickles) called as ``edit(channels, physics, k)``, with ``k`` the
decimation from the physics rate to the record's."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from . import chain as C

__all__ = ["PressureOffset", "PressureGain", "PressureDelay", "PressureLowpass",
           "SwapPressures", "NewTacho"]  # fmt: skip


@dataclass(frozen=True)
class PressureOffset:
    head_pa: float = 0.0
    crank_pa: float = 0.0

    def __call__(self, ch, phys, k):
        ch["p_head"] = ch["p_head"] + self.head_pa
        ch["p_crank"] = ch["p_crank"] + self.crank_pa
        return ch


@dataclass(frozen=True)
class PressureGain:
    head: float = 1.0
    crank: float = 1.0

    def __call__(self, ch, phys, k):
        ch["p_head"] = ch["p_head"] * self.head
        ch["p_crank"] = ch["p_crank"] * self.crank
        return ch


@dataclass(frozen=True)
class PressureDelay:
    """Both pressures ``samples`` samples late against the acceleration and the tacho."""

    samples: int

    def __call__(self, ch, phys, k):
        n = self.samples
        for name in ("p_head", "p_crank"):
            x = ch[name]
            ch[name] = np.concatenate([np.full(n, x[0]), x[:-n]])
        return ch


@dataclass(frozen=True)
class PressureLowpass:
    """A Butterworth low-pass on both recorded pressures: causal (``sosfilt``, started in
    the steady state of the first sample) or zero-phase (``sosfiltfilt``)."""

    order: int
    corner_hz: float
    zero_phase: bool = False

    def __call__(self, ch, phys, k):
        sos = signal.butter(self.order, self.corner_hz, fs=ch["fs"], output="sos")
        for name in ("p_head", "p_crank"):
            x = ch[name]
            if self.zero_phase:
                ch[name] = signal.sosfiltfilt(sos, x)
            else:
                ch[name] = signal.sosfilt(sos, x, zi=signal.sosfilt_zi(sos) * x[0])[0]
        return ch


@dataclass(frozen=True)
class SwapPressures:
    def __call__(self, ch, phys, k):
        ch["p_head"], ch["p_crank"] = ch["p_crank"], ch["p_head"]
        return ch


@dataclass(frozen=True)
class NewTacho:
    """The tacho channel replaced by `blind.chain`'s pickup of settings ``tacho``, sampled
    every ``k``-th physics sample from the first (as recipdyn's own chain samples), on a
    digital input (no anti-alias filter)."""

    tacho: C.Tacho
    seed: int = 0

    def __call__(self, ch, phys, k):
        rng = np.random.default_rng(self.seed)
        t = np.asarray(phys["t"], float)
        v = C.tacho_analogue(np.asarray(phys["theta1"], float), t, self.tacho, phys["fs"], rng)
        ch["tacho"] = v[::k][: ch["accel"].size]
        return ch
