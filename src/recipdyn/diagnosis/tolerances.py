"""The slacks and floors the diagnoser's checks share (the training ranges' refusals in
`recipdyn.diagnosis.diagnose`, the machine's tolerances in `recipdyn.diagnosis.machine`, the
healthy baseline in `recipdyn.diagnosis.train`). A module of constants only, below every other
module of the package, so that each reads them without importing another's code."""

__all__ = ["RANGE_SLACK", "RING_SLACK", "FLOOR_SLACK", "OPERATING", "BASELINE_SPREAD_FLOOR"]

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
