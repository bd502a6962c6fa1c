"""Every default of recipdyn, in one place.

Each layer (simulate, analysis, sweep, reproduce, CLI, config files) reads its defaults from
here, so a setting means the same in every command and a change is made once.
"""

from __future__ import annotations

__all__ = [
    "RTOL", "ATOL", "CALIBRATION_RTOL", "CALIBRATION_ATOL", "FS", "SIMULATION",
    "RK4_STEPS_PER_REVOLUTION", "SWEEP", "ANALYZE", "LYAP_TOL", "MAX_PERIODIC_POINTS", "RC_MIN",
    "MEMORY_FRACTION", "RTOL_RANGE", "ATOL_RANGE", "MAX_RMS_RATIO", "MAX_SPEED_RATIO",
    "MIN_SIGNAL_SAMPLES",
]  # fmt: skip

#: DOP853 tolerances for every trajectory (simulate, sections, sweeps, Benettin). At 1e-10 the
#: global error of a 10-revolution base-case run is ~1e-8 rad in theta_c (tests/test_integrate).
RTOL = 1e-10
ATOL = 1e-12
#: Allowed tolerance ranges (below 1e-14 the error estimate is rounding noise; above 0.1 it
#: controls nothing).
RTOL_RANGE = (1e-14, 0.1)
ATOL_RANGE = (1e-300, 1.0)
#: The calibration's inner loop (hundreds of short runs inside an optimiser): peaks to ~1e-6,
#: far below the factor-of-several mismatch it measures.
CALIBRATION_RTOL = 1e-8
CALIBRATION_ATOL = 1e-10
#: Output sampling rate, Hz.
FS = 10_000.0
#: Defaults of `recipdyn.simulate` (recorded in every result).
SIMULATION: dict = dict(
    revolutions=10.0, transient=0.0, fs=FS, method="dop853", rtol=RTOL, atol=ATOL, h=None
)
#: The paper's fixed-step RK4: steps per crank revolution when ``h`` is not given.
RK4_STEPS_PER_REVOLUTION = 20_000
#: Defaults of a sweep point (``recipdyn sweep``).
SWEEP: dict = dict(
    revolutions=5.0, transient=20.0, points=100, lyap_revolutions=50.0, fs=FS, rtol=RTOL,
    atol=ATOL,
)  # fmt: skip
#: Defaults of ``recipdyn analyze``.
ANALYZE: dict = dict(section_points=200, lyap_revolutions=100.0)
#: Verdicts: a largest exponent above this (1/s, and beyond twice its spread) counts as positive.
#: The base case's finite-time lambda1 of regular motion decays like ln(T)/T and is below 0.02
#: after 50 revolutions (tests/test_analyze.py).
LYAP_TOL = 0.02
#: Verdicts: at most this many distinct stroboscopic points make a periodic orbit.
MAX_PERIODIC_POINTS = 16
#: Verdicts from a signal: a record whose quarters' RMS values (about the record's mean) differ
#: by more than this factor is not stationary (a decay, a run-up, a burst), and no verdict is
#: drawn from it. Stationary test signals (noise, AR(1), maps, flows, periodic and quasi-periodic
#: signals of 20 000 samples) give at most 1.07; a measured hammer-test decay 7.9.
MAX_RMS_RATIO = 3.0
#: ... and, with a crank angle (tacho or speed), one whose quarters' mean speeds differ by more
#: than this factor (a run-up or a coast-down; the vibration page switches to a Campbell
#: diagram at the same 5 %). Mean speeds over quarters, not the instantaneous speed, whose
#: ripple within a revolution is normal for a reciprocating machine.
MAX_SPEED_RATIO = 1.05
#: Fewest samples of a signal the neighbour-based estimators (embedding, exponents from a
#: signal, surrogates) accept, and ``recipdyn analyze`` for a signal file: below it no
#: divergence curve with a scaling region, nor 50 references with neighbours, can be had.
MIN_SIGNAL_SAMPLES = 200
#: Smallest non-zero clearance, m. The free link oscillates at ~sqrt(F / (m rc)); at 0.1 um the
#: integrator already needs ~0.5 million steps per revolution (rc = 0 is the ideal joint).
RC_MIN = 1e-7
#: A run may plan to use at most this fraction of the memory available when it starts
#: (``--max-memory`` overrides).
MEMORY_FRACTION = 0.5
#: Signal files longer than this many samples are read block by block (``analyze``), or
#: refused by ``features`` without ``--window`` (a whole-file row would need the whole file).
MAX_MEMORY_SAMPLES = 1 << 24
