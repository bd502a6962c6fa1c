"""Consequences of each fault on the signals a diagnoser reads (docs/faults.md, Signatures).

`tests/test_valve_faults.py` checks the valve and ring faults on the gas (nozzle flow, mass
and gas-energy balances, valve timing). Here: what they do to the rod load (the reversal
angles move the way the chamber pressures say), that the energy balances close with every
fault at once on the contact joint, and that a joint clearance shrinking to 0 with stiff
contact gives the ideal pin's rod load.
"""

from __future__ import annotations

import functools
import math
import warnings

import numpy as np
import pytest

from recipdyn.simulate import simulate

FS = 20000.0
M3 = 30.0  # crosshead + piston mass, kg (the default)
A_HEAD = math.pi / 4.0 * 0.5**2  # head-end piston area, m^2 (bore 0.5 m)
A_CRANK = math.pi / 4.0 * (0.5**2 - 0.1**2)  # crank end: less the rod (0.1 m)


@functools.cache
def _valves(items):
    with warnings.catch_warnings():
        # the double-acting rod load reverses: the massless link's validity warning is expected
        warnings.simplefilter("ignore")
        return simulate(model="compressor-valves", revolutions=1, transient=2, fs=FS, rc=0.0,
                        **dict(items))  # fmt: skip


def _col(ds, name):
    return np.asarray(ds[name].values, dtype=float)


def _rod_load(ds):
    """Crosshead-pin load, > 0 compression: ``m3 a - F_gas`` (the crosshead's equation of
    motion along the guide; `recipdyn.model.cycle.pin_reversal_summary`)."""
    return M3 * _col(ds, "a") - _col(ds, "gas_force")


def _reversals(th, load):
    """(angle, index) of each sign change of ``load``, linearly interpolated between samples."""
    k = np.flatnonzero(np.sign(load[1:]) != np.sign(load[:-1]))
    return [(th[i] - load[i] * (th[i + 1] - th[i]) / (load[i + 1] - load[i]), i) for i in k]


#: fault -> its parameters and the sign of the shift of the two reversals: the falling one
#: near 34 deg (head end re-expanding, crank end compressing) and the rising one near 221 deg
#: (head end compressing, crank end re-expanding); 0: the fault acts after the reversal.
REVERSAL_SHIFTS = {
    "suction leak, head end": ({"leak_area_suction_head": 1e-4}, (-1, +1)),
    "discharge leak, head end": ({"leak_area_discharge_head": 3e-5}, (+1, -1)),
    "suction leak, crank end": ({"leak_area_suction_crank": 1e-4}, (+1, -1)),
    "discharge leak, crank end": ({"leak_area_discharge_crank": 3e-5}, (-1, +1)),
    "broken suction spring, head end": ({"spring_factor_suction_head": 0.0}, (0, +1)),
    "weak discharge spring, crank end": ({"spring_factor_discharge_crank": 0.3}, (0, +1)),
    "sticking suction plate, head end": ({"adhesion_force_suction_head": 300.0}, (0, 0)),
    "ring leak": ({"ring_leak_area": 1e-4}, (-1, -1)),
}  # fmt: skip


@pytest.mark.parametrize("fault", list(REVERSAL_SHIFTS))
def test_rod_load_reversals_move_as_the_chamber_pressures_say(fault):
    """The rod load ``L = m3 a - F_gas`` of the double-acting cylinder reverses twice a
    revolution. On the ideal mechanism the crosshead's acceleration is the same with and
    without a fault, so the fault changes the load only through the pressures:
    ``dL = A_head dp_head - A_crank dp_crank``.

    *Sign (the physics).* A leak to a line at lower pressure lowers its chamber's pressure
    (suction leaks), one from a line at higher pressure raises it (discharge leaks); a late
    closing suction valve lets gas back out of the head end after the dead centre (lower
    pressure through its compression), a late closing discharge valve lets discharge gas back
    into the crank end (higher pressure through its re-expansion); the ring leak has carried
    gas, since the dead centre, from the chamber at the higher pressure to the other. With the
    load falling at the first reversal and rising at the second, ``dL > 0`` delays the first
    and advances the second. A sticking suction plate opens late (at ~40 deg), after the
    first reversal, and changes the head end's intake by 0.04 % (volumetric efficiency
    0.8650 -> 0.8647): neither reversal moves by more than 1e-4 deg (the bound asks 1e-3).

    *Size (an independent estimate).* With ``L_h(θ_r) = 0`` at the healthy reversal and
    ``L_f(θ_f) = 0`` at the faulty one, the mean value theorem gives
    ``θ_f - θ_r = -dL(θ_r) / L_f'(ξ)`` for some ξ between them: the shift lies between
    ``-dL/max L_f'`` and ``-dL/min L_f'`` over that interval, ``dL`` read from the recorded
    pressures at the healthy reversal. The slope's extremes are taken from the secant
    slopes of the samples there, widened by the largest change between neighbouring
    secants (how far the derivative can move within a sample). The bound needs the load
    monotonic there (checked: at 3 cm^2 the suction leaks make the plate flutter through
    the reversal and it is not). Measured shifts (deg): suction leak head -2.23 / +0.12,
    discharge leak head +0.77 / -0.34, suction leak crank +0.08 / -3.22, discharge leak
    crank -0.23 / +1.10, broken spring 0 / +0.57, weak spring 0 / +0.06, ring leak
    -2.75 / -3.96; sticking plate < 1e-4."""
    kw, signs = REVERSAL_SHIFTS[fault]
    healthy, faulty = _valves(()), _valves(tuple(sorted(kw.items())))
    th = _col(healthy, "theta1")
    assert np.array_equal(th, _col(faulty, "theta1"))
    lh, lf = _rod_load(healthy), _rod_load(faulty)
    # the recorded load is the one the pressures make (the independent part of the estimate)
    ref = M3 * _col(faulty, "a") + A_HEAD * _col(faulty, "p_head") - A_CRANK * (
        _col(faulty, "p_crank")) - 101325.0 * (A_HEAD - A_CRANK)  # fmt: skip
    assert np.abs(ref - lf).max() < 1e-9 * np.abs(lf).max()
    rh, rf = _reversals(th, lh), _reversals(th, lf)
    assert len(rh) == len(rf) == 2
    for (tr, i), (tf, j), sign in zip(rh, rf, signs, strict=True):
        shift = math.degrees(tf - tr)
        if sign == 0:
            assert abs(shift) < 1e-3, (fault, shift)  # measured <= 1e-5 deg
            continue
        assert math.copysign(1.0, shift) == sign and abs(shift) > 0.03, (fault, shift)
        dph = np.interp(tr, th, _col(faulty, "p_head") - _col(healthy, "p_head"))
        dpc = np.interp(tr, th, _col(faulty, "p_crank") - _col(healthy, "p_crank"))
        dl = A_HEAD * dph - A_CRANK * dpc
        lo, hi = min(i, j) - 1, max(i, j) + 2
        sec = np.diff(lf[lo : hi + 1]) / np.diff(th[lo : hi + 1])
        wiggle = np.abs(np.diff(sec)).max()
        s_min, s_max = sec.min() - wiggle, sec.max() + wiggle
        assert s_min > 0.0 or s_max < 0.0, (fault, "rod load not monotonic at the reversal")
        bounds = sorted((math.degrees(-dl / s_min), math.degrees(-dl / s_max)))
        assert bounds[0] <= shift <= bounds[1], (fault, shift, bounds)
