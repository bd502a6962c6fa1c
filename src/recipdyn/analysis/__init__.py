"""Generic analysis: spectra, Poincaré sections, Lyapunov exponents, 0-1 test, verdicts.

Nothing here knows about cranks: every function takes an
[`ODESystem`][recipdyn.model.base.ODESystem] / [`DiscreteMap`][recipdyn.model.base.DiscreteMap] or a
plain signal.
"""

from .classify import Verdict, classify
from .embedding import (
    delay_embed,
    estimate_delay,
    estimate_dimension,
    false_nearest_neighbours,
    mean_period,
    mutual_information,
)
from .lyapunov import LyapunovResult, lyapunov_spectrum, lyapunov_spectrum_map, tangent_system
from .lyapunov_signal import SignalLyapunov, lyap_kantz, lyap_rosenstein, lyap_wolf
from .poincare import (
    angle_section,
    angle_times,
    count_distinct_points,
    hyperplane_section,
    stroboscopic_section,
)
from .spectrum import Peak, Spectrum, amplitude_spectrum, find_spectral_peaks, order_spectrum
from .zero_one import zero_one_test

__all__ = [
    "Verdict", "classify", "delay_embed", "estimate_delay", "estimate_dimension",
    "false_nearest_neighbours", "mean_period", "mutual_information", "LyapunovResult",
    "lyapunov_spectrum", "lyapunov_spectrum_map", "tangent_system", "SignalLyapunov",
    "lyap_kantz", "lyap_rosenstein", "lyap_wolf", "count_distinct_points", "hyperplane_section",
    "stroboscopic_section", "angle_section", "angle_times", "Peak", "Spectrum",
    "amplitude_spectrum", "find_spectral_peaks", "order_spectrum", "zero_one_test",
]  # fmt: skip
