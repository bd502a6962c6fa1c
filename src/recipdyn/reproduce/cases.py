"""The cases of Xiao et al. (2017) and every number the paper reports about them.

Section 3 and 4 of the paper simulate the 2D12 compressor for three one-parameter sweeps:

* clearance rc = 0, 0.1, 0.5, (1,) 5 mm at d = 0, omega = 20 rad/s (Figs. 4-10; the phase
  trajectories of Figs. 18-19 and the exponents of Fig. 24a use d = 1 mm);
* subsidence d = 0, 0.1, 1, 5 mm at rc = 1 mm, omega = 20 rad/s (Figs. 11-13, 20-21, 24b);
* crank speed omega = 10, (20,) 70, 150 rad/s at rc = d = 1 mm (Figs. 14-16); the phase
  trajectories and exponents (Figs. 22-23, 24c) use rc = 5 mm, d = 1 mm.

[`CASES`][recipdyn.reproduce.cases.CASES] names every parameter set once;
[`PAPER_VALUES`][recipdyn.reproduce.cases.PAPER_VALUES] lists every reported number with the case it
belongs to, the quantity we compute for it and the paper's location.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Case", "CASES", "PaperValue", "PAPER_VALUES", "case_by_id"]


@dataclass(frozen=True)
class Case:
    """A parameter set of the paper (SI units)."""

    id: str
    rc: float
    d: float
    omega: float
    label: str


def _c(rc_mm: float, d_mm: float, omega: float) -> Case:
    cid = f"rc{rc_mm:g}_d{d_mm:g}_w{omega:g}"
    return Case(cid, rc_mm * 1e-3, d_mm * 1e-3, float(omega),
                f"rc = {rc_mm:g} mm, d = {d_mm:g} mm, omega = {omega:g} rad/s")  # fmt: skip


CASES: tuple[Case, ...] = tuple(
    {c.id: c for c in [
        # clearance sweep, d = 0 (Figs. 4-10)
        *(_c(rc, 0, 20) for rc in (0, 0.1, 0.5, 1, 5)),
        # clearance sweep, d = 1 mm (Figs. 18-19, 24a, 26) and ideal (Fig. 17, 25)
        *(_c(rc, 1, 20) for rc in (0.1, 0.5, 1, 5)),
        # subsidence sweep, rc = 1 mm (Figs. 11-13, 20-21, 24b, 27)
        *(_c(1, d, 20) for d in (0, 0.1, 1, 5)),
        # speed sweep, rc = d = 1 mm (Figs. 14-16)
        *(_c(1, 1, w) for w in (10, 70, 150)),
        # speed sweep, rc = 5 mm, d = 1 mm (Figs. 22-23, 24c, 28)
        *(_c(5, 1, w) for w in (10, 20, 70, 150)),
        _c(0, 0, 20),
    ]}.values()
)  # fmt: skip


def case_by_id(cid: str) -> Case:
    for c in CASES:
        if c.id == cid:
            return c
    raise KeyError(cid)


@dataclass(frozen=True)
class PaperValue:
    """One number reported in the paper.

    ``quantity`` names what we compute (see `measures`): ``peak_a`` (max |a|, m/s^2),
    ``dev_x``/``dev_v`` (max |x - x_ref|, |v - v_ref| against the case ``ref``; mm and m/s),
    ``min_x`` (mm), ``max_v`` (m/s), ``freq`` (a spectral peak, Hz; ``harmonic`` = the crank
    order it is, 0 = a non-harmonic component), ``lyap`` (largest Lyapunov exponent).
    """

    key: str
    case: str
    quantity: str
    value: float
    unit: str
    where: str
    ref: str | None = None
    harmonic: int = 0


def _pv(key, case, quantity, value, unit, where, ref=None, harmonic=0):
    return PaperValue(key, case, quantity, value, unit, where, ref, harmonic)


PAPER_VALUES: tuple[PaperValue, ...] = (
    # Section 3.1: clearance (d = 0, omega = 20)
    _pv("peak_a_rc0.1", "rc0.1_d0_w20", "peak_a", 77.68, "m/s^2", "Sec. 3.1, Fig. 10"),
    _pv("peak_a_rc1", "rc1_d0_w20", "peak_a", 402.6, "m/s^2", "Sec. 3.1, Fig. 10"),
    _pv("peak_a_rc5", "rc5_d0_w20", "peak_a", 1164.0, "m/s^2", "Sec. 3.1, Fig. 10"),
    _pv("dev_x_rc0.1", "rc0.1_d0_w20", "dev_x", 0.1, "mm", "Sec. 3.1, Fig. 8", "rc0_d0_w20"),
    _pv("dev_x_rc1", "rc1_d0_w20", "dev_x", 1.0, "mm", "Sec. 3.1, Fig. 8", "rc0_d0_w20"),
    _pv("dev_x_rc5", "rc5_d0_w20", "dev_x", 4.9, "mm", "Sec. 3.1, Fig. 8", "rc0_d0_w20"),
    _pv("dev_v_rc0.1", "rc0.1_d0_w20", "dev_v", 0.002, "m/s", "Sec. 3.1, Fig. 9", "rc0_d0_w20"),
    _pv("dev_v_rc1", "rc1_d0_w20", "dev_v", 0.042, "m/s", "Sec. 3.1, Fig. 9", "rc0_d0_w20"),
    _pv("dev_v_rc5", "rc5_d0_w20", "dev_v", 0.959, "m/s", "Sec. 3.1, Fig. 9", "rc0_d0_w20"),
    _pv("f_rc0_1x", "rc0_d0_w20", "freq", 3.109, "Hz", "Fig. 4(d)", harmonic=1),
    _pv("f_rc0_2x", "rc0_d0_w20", "freq", 6.217, "Hz", "Fig. 4(d)", harmonic=2),
    _pv("f_rc0.5_a", "rc0.5_d0_w20", "freq", 113.5, "Hz", "Fig. 6(d)"),
    _pv("f_rc0.5_b", "rc0.5_d0_w20", "freq", 223.1, "Hz", "Fig. 6(d)"),
    _pv("f_rc0.5_c", "rc0.5_d0_w20", "freq", 330.3, "Hz", "Fig. 6(d)"),
    _pv("f_rc5_a", "rc5_d0_w20", "freq", 148.4, "Hz", "Fig. 7(d)"),
    _pv("f_rc5_b", "rc5_d0_w20", "freq", 287.6, "Hz", "Fig. 7(d)"),
    _pv("f_rc5_c", "rc5_d0_w20", "freq", 448.4, "Hz", "Fig. 7(d)"),
    # Section 3.2: subsidence (rc = 1 mm, omega = 20)
    _pv("peak_a_d0", "rc1_d0_w20", "peak_a", 402.6, "m/s^2", "Sec. 3.2, Fig. 13"),
    _pv("peak_a_d1", "rc1_d1_w20", "peak_a", 548.1, "m/s^2", "Sec. 3.2, Fig. 13"),
    _pv("peak_a_d5", "rc1_d5_w20", "peak_a", 772.4, "m/s^2", "Sec. 3.2, Fig. 13"),
    _pv("dev_x_d1", "rc1_d1_w20", "dev_x", 0.4, "mm", "Sec. 3.2, Fig. 11", "rc1_d0_w20"),
    _pv("dev_x_d5", "rc1_d5_w20", "dev_x", 0.7, "mm", "Sec. 3.2, Fig. 11", "rc1_d0_w20"),
    _pv("dev_v_d1", "rc1_d1_w20", "dev_v", 0.059, "m/s", "Sec. 3.2, Fig. 12", "rc1_d0_w20"),
    _pv("dev_v_d5", "rc1_d5_w20", "dev_v", 0.312, "m/s", "Sec. 3.2, Fig. 12", "rc1_d0_w20"),
    # Section 3.3: speed (rc = d = 1 mm)
    _pv("min_x_w10", "rc1_d1_w10", "min_x", 480.6, "mm", "Sec. 3.3, Fig. 14"),
    _pv("min_x_w150", "rc1_d1_w150", "min_x", 481.1, "mm", "Sec. 3.3, Fig. 16"),
    _pv("max_v_w10", "rc1_d1_w10", "max_v", 1.267, "m/s", "Sec. 3.3, Fig. 14"),
    _pv("max_v_w150", "rc1_d1_w150", "max_v", 20.14, "m/s", "Sec. 3.3, Fig. 16"),
    _pv("peak_a_w10", "rc1_d1_w10", "peak_a", 172.7, "m/s^2", "Sec. 3.3, Fig. 14"),
    _pv("peak_a_w150", "rc1_d1_w150", "peak_a", 16010.0, "m/s^2", "Sec. 3.3, Fig. 16"),
    _pv("f_w10_1x", "rc1_d1_w10", "freq", 1.554, "Hz", "Fig. 14(d)", harmonic=1),
    _pv("f_w10_2x", "rc1_d1_w10", "freq", 3.109, "Hz", "Fig. 14(d)", harmonic=2),
    _pv("f_w10_a", "rc1_d1_w10", "freq", 167.9, "Hz", "Fig. 14(d)"),
    _pv("f_w10_b", "rc1_d1_w10", "freq", 337.3, "Hz", "Fig. 14(d)"),
    _pv("f_w70_1x", "rc1_d1_w70", "freq", 10.88, "Hz", "Fig. 15(d)", harmonic=1),
    _pv("f_w70_2x", "rc1_d1_w70", "freq", 22.44, "Hz", "Fig. 15(d)", harmonic=2),
    _pv("f_w150_1x", "rc1_d1_w150", "freq", 24.04, "Hz", "Fig. 16(d)", harmonic=1),
    _pv("f_w150_2x", "rc1_d1_w150", "freq", 48.04, "Hz", "Fig. 16(d)", harmonic=2),
    # Section 4: largest Lyapunov exponents (Wolf's method on the crosshead acceleration)
    _pv("lyap_rc0.1", "rc0.1_d1_w20", "lyap", 1.57, "1", "Sec. 4, Fig. 24(a)"),
    _pv("lyap_rc0.5", "rc0.5_d1_w20", "lyap", 0.68, "1", "Sec. 4, Fig. 24(a)"),
    _pv("lyap_rc1", "rc1_d1_w20", "lyap", 0.62, "1", "Sec. 4, Fig. 24(a)"),
    _pv("lyap_rc5", "rc5_d1_w20", "lyap", 0.59, "1", "Sec. 4, Fig. 24(a)"),
    _pv("lyap_d0", "rc1_d0_w20", "lyap", 0.51, "1", "Sec. 4, Fig. 24(b)"),
    _pv("lyap_d0.1", "rc1_d0.1_w20", "lyap", 0.53, "1", "Sec. 4, Fig. 24(b)"),
    _pv("lyap_d1", "rc1_d1_w20", "lyap", 0.62, "1", "Sec. 4, Fig. 24(b)"),
    _pv("lyap_d5", "rc1_d5_w20", "lyap", 0.52, "1", "Sec. 4, Fig. 24(b)"),
    _pv("lyap_w10", "rc5_d1_w10", "lyap", 0.97, "1", "Sec. 4, Fig. 24(c)"),
    _pv("lyap_w20", "rc5_d1_w20", "lyap", 0.59, "1", "Sec. 4, Fig. 24(c)"),
    _pv("lyap_w70", "rc5_d1_w70", "lyap", 0.23, "1", "Sec. 4, Fig. 24(c)"),
    _pv("lyap_w150", "rc5_d1_w150", "lyap", 1.5, "1", "Sec. 4, Fig. 24(c)"),
)
