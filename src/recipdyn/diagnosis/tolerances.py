"""The slacks and floors the diagnoser's checks share (the training ranges' refusals in
`recipdyn.diagnosis.diagnose`, the machine's tolerances in `recipdyn.diagnosis.machine`, the
healthy baseline in `recipdyn.diagnosis.train`). A module of constants only, below every other
module of the package, so that each reads them without importing another's code."""

__all__ = ["RANGE_SLACK", "RING_SLACK", "FLOOR_SLACK", "OPERATING", "BASELINE_SPREAD_FLOOR",
           "SNR_CALIBRATION", "RING_AGREEMENT", "RESONANCE_CHECK_MIN_HZ",
           "RESONANCE_CHECK_REL", "FINGERPRINT"]  # fmt: skip

#: Slack on the training range of the crank speed and the sampling rate (relative).
RANGE_SLACK = 0.02
#: Slack on the training range of the impacts' ringing frequency (relative; the Welch
#: spectrum's resolution is fs/1024, ~10 Hz, and the resonance's peak is broad: Q = 10).
RING_SLACK = 0.1
#: Factor of slack on the training range of the acceleration's noise floor (`noise_floor`):
#: x1.5 in the floor's share is about +-1.8 dB of SNR.
FLOOR_SLACK = 1.5
#: The operating point the healthy baseline refers features to (`fit_baseline`).
OPERATING = ("speed_hz", "cy_p_suction", "cy_p_discharge")
#: Floor of a baseline fit's residual spread, as a fraction of the feature's spread over all
#: training records: a feature the healthy machine holds constant (a count) would otherwise
#: turn any departure into an unbounded deviation.
BASELINE_SPREAD_FLOOR = 0.05

#: The noise floor's calibration to the accelerometer's SNR (`recipdyn.diagnosis.chainrange.
#: snr_estimate`): ``x = 10 log10(1/q - 1)`` of the floor's share ``q``, then ``snr = x +
#: offset`` with a 95 % interval ``[snr + lo, snr + hi]`` dB while ``x <= x_max``; above it the
#: signal itself fills the quietest bin and ``snr + lo`` is a lower bound only. ``angle``: the
#: crank-angle floor (a tacho); ``quiet``: the quiet windows (a constant speed). Measured by
#: ``benchmarks/bench_chain_ranges.py --part calibrate`` on 792 records made with known
#: chains (99 simulated machines of the shipped data set's training conditions, every class,
#: each through 8 chains drawn from `recipdyn.chain.DEFAULT_RANGES` with the SNR widened to
#: 0-50 dB and the resonance to 0.7-7 kHz; 2, 4 and 10 revolutions: 216, 360, 216 records):
#: ``offset`` the pooled median of ``snr - x`` over the records with ``x <= 25`` dB (424 and
#: 383 records), ``lo``/``hi`` the widest 2.5 / 97.5 % residuals of any one record length (2
#: revolutions: the pooled interval covers 95 % of them, 97-100 % at 4 and 10). Above
#: ``x_max`` the residuals' 2.5 % lay at -1.3 dB or above (angle) and -0.6 dB (quiet), within
#: ``lo``; their 97.5 % at +6 to +20 dB.
SNR_CALIBRATION = {
    "angle": {"offset": -0.05, "lo": -2.5, "hi": 1.93, "x_max": 25.0, "records": 424},
    "quiet": {"offset": -0.23, "lo": -1.39, "hi": 2.74, "x_max": 25.0, "records": 383},
}
#: The mount's fitted resonance counts as read only where the impacts ring within this share
#: of it (`recipdyn.diagnosis.chainrange.check_chain`): a machine's own spectral peak (a worn
#: crosshead pin's, near 2 kHz) fits a second-order response as well, where the mount's lies
#: above the anti-alias corner (docs/diagnosis.md).
RING_AGREEMENT = 0.1
#: The lowest spectral peak tried as the mount's resonance when it is checked against the
#: declared range (`recipdyn.diagnosis.correction.resonance`'s ``min_hz``; above the
#: impacts' 500 Hz high-pass): from 1 kHz, 85 of 154 resonances at 0.8-2 kHz were read, from
#: 600 Hz 144, with the same 2 of 145 in-band resonances misread below the band
#: (``benchmarks/bench_chain_ranges.py --part calibrate``, 4 revolutions).
RESONANCE_CHECK_MIN_HZ = 600.0
#: Relative error added (in quadrature) to the resonance's own 95 % half-width before it is
#: checked: its reported interval covered 87 % of 369 read resonances below 0.45 fs (4 and 10
#: revolutions; the relative errors' 97.5 % quantile: 0.043); with 5 % added, 98.9 %.
RESONANCE_CHECK_REL = 0.05

#: The machine fingerprint's tolerances (`recipdyn.diagnosis.fingerprint`): a record of 2 or
#: more whole revolutions is another machine when its r times the gain (the acceleration's
#: 1st crank order over omega**2, corrected for the AC coupling) departs from the
#: diagnoser's machine by more than ``r_tol`` (relative), or its r/l (the 2nd over the 1st
#: order, corrected) by more than ``lam_z_limit`` times its own standard uncertainty
#: ``u = sqrt(e_12**2 + e_2**2 + s**2)``: ``e_12``, ``e_2`` the RMS of the crank orders 3-6
#: (which the kinematics leave below 1 % of the 1st) over the 1st and over the 2nd order's
#: amplitude, ``s`` half the disagreement of the AC coupling's two candidate orders (median
#: 0.005, 99 % 0.061). Measured by
#: ``benchmarks/bench_fingerprint.py --min-revs`` on the shipped diagnoser's data set: its
#: 1379 records (of 1440) whose two tacho edges span 2 whole revolutions (the diagnoser's
#: own machine, 9 classes, chains drawn from `recipdyn.chain.DEFAULT_RANGES`; 347 of
#: held-out conditions). ``|r/r0 - 1|``: median 0.034, 95 % 0.106, 99 % 0.147, largest
#: 0.202 (held-out: 95 % 0.103, 99 % 0.154); ``r_tol`` lies above the largest. ``|lam/lam0
#: - 1| / u``: median 0.21, 95 % 0.85, 99 % 1.31, then 1.84, 1.88, 1.90, 2.33, 2.59, 3.18
#: (held-out: 95 % 0.72, 99 % 1.06, largest 1.27); ``lam_z_limit`` is the 99 % quantile
#: times a margin of 1.5, beyond which 3 of the 1379 lie (SNR 10.7-12.6 dB, the range's
#: noisiest). ``|lam/lam0 - 1|`` itself: median 0.018, 95 % 0.109, 99 % 0.223, largest
#: 0.745 (a worn crank pin's impacts, whose ``u`` is as large). ``r_u95`` and ``lam_z95``
#: (the 95 % quantiles) give the reported 95 % half-widths. The 1st order's error grows with
#: the coupling's corner (95 % quantile 0.06 below 0.3 Hz, 0.12-0.15 at 1.2-2 Hz); the
#: corner read from the phases corrects part of it (uncorrected: 99 % 0.183, largest 0.246).
FINGERPRINT = {"r_tol": 0.21, "r_u95": 0.106, "lam_z_limit": 2.0, "lam_z95": 0.85,
               "records": 1379}  # fmt: skip
