r"""The record's own machine, read from its crosshead acceleration: a kinematic fingerprint.

A diagnoser belongs to one machine (`recipdyn.diagnosis.machine`); a record that comes
without its machine's description must still not be answered for another one. The
crosshead's axial acceleration carries the mechanism's geometry in its lowest crank orders:
the slider-crank's ``a(theta) = -r w^2 (cos theta + lambda cos 2 theta + ...)``,
``lambda = r/l``. Resampled by crank angle with the tacho over whole revolutions
(`recipdyn.analysis.vibration.angle_resample`), the record's 1st and 2nd orders give

* **r/l** from the ratio of the 2nd to the 1st order's amplitude, which the
  accelerometer's gain leaves unchanged (`estimate`);
* **r** (times the gain) from the 1st order's amplitude over ``w^2``; the gain's declared
  range (`recipdyn.chain.DEFAULT_RANGES`, +-5 %) widens its tolerance.

Both are compared with the same orders of the diagnoser's own machine, computed numerically
from its exact kinematics (`recipdyn.model.kinematics.ideal_mechanism`, the offset ``d``
included), not from the truncated series.

**The AC coupling.** An accelerometer input is AC-coupled: a Butterworth high-pass of
order 1 or 2 with its corner at 0.1-2 Hz (`recipdyn.chain.DEFAULT_RANGES`), on a crank that
turns at 2.5-4 Hz. It lowers the 1st order by up to 20 % and the 2nd by up to 3 %, and leads
both in phase (up to 70 and 40 degrees), so the raw ratio overstates r/l by up to ~20 % for
the chain's corner at its top. The phase leads tell the corner: the combination
``D = 2 psi_1 - psi_2`` of the two orders' phases, less that of the kinematic orders, is
independent of the crank angle's zero (a tacho mark off dead centre, a channel's delay
cancel in it) and equals ``2 arg H(f) - arg H(2 f)`` of the high-pass ``H`` alone. For each
order of the coupling (1 or 2) the corner that gives ``D`` is solved and the two orders'
amplitudes are divided by ``|H|``; the two candidate orders' results are averaged, their
difference is part of the uncertainty.

**What else moves these orders** (measured by ``benchmarks/bench_fingerprint.py`` on the
shipped diagnoser's data set, every class and drawn chain): the gas force and the joints'
impacts (the pins' clearance adds short impulses whose low-order content is the small
velocity change they make), the sensor's drift (0.02-0.5 Hz, leaking into the 1st order
on a 2-revolution record) and noise. The estimator's spread over those records sets the
tolerances (`recipdyn.diagnosis.tolerances.FINGERPRINT`).

A record without a tacho, or with less than two whole revolutions, cannot be fingerprinted
this way; the check then says so in the evidence and the other checks decide.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

__all__ = ["Fingerprint", "harmonics", "kinematic_orders", "estimate", "check", "refusal"]

#: Crank-angle samples per revolution for the orders (the 2nd order has 180 per period).
PER_REV = 360
#: The fewest whole revolutions the fingerprint is read from.
MIN_REVOLUTIONS = 2


@dataclass(frozen=True)
class Fingerprint:
    """The record's estimated geometry against the diagnoser's machine.

    ``lam`` (r/l) and ``r`` (m; the crank radius times the accelerometer's gain) with their
    95 % half-widths ``lam_u``, ``r_u`` from the measured spread of the estimator; the
    diagnoser's own ``lam_ref`` and ``r_ref``; the relative tolerances ``lam_tol``,
    ``r_tol`` a record is refused beyond; ``corner_hz``: the AC coupling's corner read from
    the phases (averaged over its two candidate orders); ``status``: ``"consistent"``,
    ``"another machine"`` or ``"not checked"`` (``note`` says why)."""

    status: str
    note: str = ""
    lam: float = math.nan
    lam_u: float = math.nan
    lam_ref: float = math.nan
    lam_tol: float = math.nan
    r: float = math.nan
    r_u: float = math.nan
    r_ref: float = math.nan
    r_tol: float = math.nan
    corner_hz: float = math.nan
    revolutions: int = 0

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    def text(self) -> str:
        if self.status == "not checked":
            return f"machine fingerprint: not checked ({self.note})"
        return (
            f"machine fingerprint (crosshead acceleration's 1st and 2nd orders, AC coupling's "
            f"corner {self.corner_hz:.2f} Hz): r/l = {self.lam:.3f} +- {self.lam_u:.3f} "
            f"(the diagnoser's machine {self.lam_ref:.3f}, tolerance +-"
            f"{100 * self.lam_tol:.0f} %); r x gain = {1e3 * self.r:.1f} +- {1e3 * self.r_u:.1f}"
            f" mm (the diagnoser's {1e3 * self.r_ref:.1f} mm, tolerance +-"
            f"{100 * self.r_tol:.0f} %): {self.status}"
        )


def harmonics(x, revs, orders=(1, 2)) -> tuple[np.ndarray, int]:
    """The complex amplitudes of the crank ``orders`` of ``x`` (``x ~ Re(c_k e^{i k
    theta})``, ``theta`` the crank angle after the tacho's mark), over the most whole
    revolutions ``revs`` covers from its first angle, and the number of those revolutions.

    ``x`` is resampled by crank angle (cubic spline, as
    `recipdyn.analysis.vibration.angle_resample`) and a straight line through it removed
    first: a drift or the AC coupling's settling over the record would otherwise leak into
    the lowest orders (a line holds ``1/(pi k)`` of its rise in order ``k``)."""
    from scipy.interpolate import CubicSpline

    revs = np.asarray(revs, float)
    ok = np.isfinite(revs)
    r, y = revs[ok], np.asarray(x, float)[ok]
    if r.size < 2 or np.any(np.diff(r) <= 0):
        raise ValueError("crank angle must increase (a tacho or a positive speed)")
    # the last sample ends its interval: a record of exactly N revolutions covers N
    n = int(np.floor((r[-1] - r[0]) + np.median(np.diff(r)) * (1 + 1e-9)))
    if n < 1:
        raise ValueError("less than one whole revolution covered")
    grid = r[0] + np.arange(n * PER_REV) / PER_REV
    ya = CubicSpline(r, y, extrapolate=True)(grid)
    ya = ya - np.polyval(np.polyfit(grid, ya, 1), grid)
    c = np.fft.rfft(ya) * 2.0 / ya.size
    ks = np.asarray(orders)
    return c[ks * n] * np.exp(-2j * np.pi * ks * r[0]), n


def _values(machine=None) -> dict[str, float]:
    from ..model.registry import get_model
    from .classes import MODEL

    v = get_model(MODEL).parameters(dict(machine or {}))
    return {k: float(v[k]) for k in ("r", "l", "ls", "m2", "m3", "J2", "g", "d")}


def kinematic_orders(values: dict[str, float], omega: float, orders=(1, 2)) -> np.ndarray:
    """The complex amplitudes of the crank ``orders`` of the ideal offset slider-crank's
    crosshead acceleration (m/s**2) at ``omega`` rad/s, computed numerically from its exact
    kinematics (`recipdyn.model.kinematics.ideal_mechanism`), the crank angle from 0."""
    from ..model.kinematics import ideal_mechanism

    th = 2.0 * np.pi * np.arange(PER_REV) / PER_REV
    a = ideal_mechanism({**values, "omega": omega}, th)["a"]
    c = np.fft.rfft(a) * 2.0 / a.size
    return np.array([c[k] for k in orders])


def _highpass(n: int, corner_hz: float, f_hz):
    from scipy.signal import butter, freqs

    if corner_hz <= 0.0:
        return np.ones(np.size(f_hz), complex)
    b, a = butter(n, 2.0 * np.pi * corner_hz, "highpass", analog=True)
    return freqs(b, a, 2.0 * np.pi * np.atleast_1d(f_hz))[1]


def _corner(n: int, d: float, f: float) -> float:
    """The corner (Hz) of the order-``n`` Butterworth high-pass whose phase leads at ``f``
    and ``2 f`` combine to ``d = 2 arg H(f) - arg H(2 f)`` (rad); 0 for ``d <= 0``."""
    from scipy.optimize import brentq

    def g(fc):
        h = _highpass(n, fc, [f, 2 * f])
        return 2 * np.angle(h[0]) - np.angle(h[1]) - d

    if d <= 0.0:
        return 0.0
    hi = 10.0 * f
    if g(hi) < 0.0:  # beyond any AC coupling below the crank's speed
        return hi
    return float(brentq(g, 0.0, hi, xtol=1e-6 * f))


def _wrap(a: float) -> float:
    return (a + np.pi) % (2 * np.pi) - np.pi


def estimate(x, fs: float, revs, machine=None) -> dict[str, float]:
    """The raw fingerprint of the acceleration ``x`` (m/s**2, at ``fs`` Hz, the crank angle
    ``revs`` in revolutions after the tacho's mark) against ``machine`` (the diagnoser's
    changes; None: the default machine): ``lam`` (r/l) after the AC coupling's correction,
    ``lam_raw`` without it; ``r`` (m, times the gain) from the 1st order as measured,
    ``r_corrected`` after the coupling's correction (the corner read from the phases makes
    it unstable: ``benchmarks/bench_fingerprint.py``); ``corner_hz``, the two candidate
    orders' disagreement ``lam_spread``/``r_spread`` (half the difference, relative), the
    revolutions used and the machine's ``lam_ref``/``r_ref``."""
    from scipy.optimize import brentq

    revs = np.asarray(revs, float)
    c, n = harmonics(x, revs, (1, 2))
    ok = np.isfinite(revs)
    t = np.flatnonzero(ok)
    f = float((revs[t[-1]] - revs[t[0]]) / ((t[-1] - t[0]) / fs))  # mean speed, Hz
    w = 2.0 * np.pi * f
    v = _values(machine)
    k = kinematic_orders(v, w)
    ratio_ref = abs(k[1]) / abs(k[0])
    d = _wrap(2 * np.angle(c[0]) - np.angle(c[1]) - (2 * np.angle(k[0]) - np.angle(k[1])))
    lams, rs, corners = [], [], []
    for order in (1, 2):
        fc = _corner(order, d, f)
        h = _highpass(order, fc, [f, 2 * f])
        rho = (abs(c[1]) / abs(h[1])) / (abs(c[0]) / abs(h[0]))
        lams.append(rho)
        rs.append(abs(c[0]) / abs(h[0]) / abs(k[0]) * v["r"])
        corners.append(fc)

    def lam_of(rho):  # the r/l whose exact kinematics give this ratio of orders (r fixed)
        def g(lam):
            kk = kinematic_orders({**v, "l": v["r"] / lam}, w)
            return abs(kk[1]) / abs(kk[0]) - rho

        lo, hi = 0.02, 0.6
        if g(lo) > 0 or g(hi) < 0:
            return math.nan
        return float(brentq(g, lo, hi, xtol=1e-7))

    raw = abs(c[1]) / abs(c[0])
    lam_c = [lam_of(x_) for x_ in lams]
    lam = float(np.mean(lam_c))
    r = float(np.mean(rs))
    return {
        "lam": lam,
        "lam_spread": abs(lam_c[1] - lam_c[0]) / 2 / lam if lam > 0 else math.nan,
        "lam_raw": lam_of(raw),
        "r": abs(c[0]) / abs(k[0]) * v["r"],
        "r_corrected": r,
        "r_spread": abs(rs[1] - rs[0]) / 2 / r if r > 0 else math.nan,
        "corner_hz": float(np.mean(corners)),
        "phase_d_deg": math.degrees(d),
        "revolutions": n,
        "speed_hz": f,
        "lam_ref": v["r"] / v["l"],
        "lam_ref_ratio": ratio_ref,
        "r_ref": v["r"],
    }


def check(x, fs: float, revs, machine=None, *, tacho: bool = True) -> Fingerprint:
    """The fingerprint of the record against the diagnoser's machine (``machine``: its
    changes) and its verdict, with the tolerances of
    `recipdyn.diagnosis.tolerances.FINGERPRINT`; ``tacho``: whether ``revs`` comes from a
    tacho (without one the crank angle's zero is unknown and the record is not checked)."""
    from .tolerances import FINGERPRINT

    if not tacho:
        return Fingerprint("not checked", "no tacho: the crank orders need the crank angle")
    revs = np.asarray(revs, float)
    span = np.nanmax(revs) - np.nanmin(revs) if np.isfinite(revs).any() else 0.0
    if span < MIN_REVOLUTIONS:
        return Fingerprint(
            "not checked", f"{span:.1f} revolutions; at least {MIN_REVOLUTIONS} whole needed"
        )
    try:
        e = estimate(x, fs, revs, machine)
    except ValueError as exc:
        return Fingerprint("not checked", str(exc))
    if e["revolutions"] < MIN_REVOLUTIONS or not math.isfinite(e["lam"]):
        return Fingerprint(
            "not checked",
            f"{e['revolutions']} whole revolution(s)"
            if e["revolutions"] < MIN_REVOLUTIONS
            else "the orders' ratio lies beyond any slider-crank's (r/l 0.02-0.6)",
        )
    tl, tr = FINGERPRINT["lam_tol"], FINGERPRINT["r_tol"]
    dl = e["lam"] / e["lam_ref"] - 1.0
    dr = e["r"] / e["r_ref"] - 1.0
    other = abs(dl) > tl or abs(dr) > tr
    return Fingerprint(
        "another machine" if other else "consistent",
        lam=e["lam"],
        lam_u=FINGERPRINT["lam_u"] * e["lam"],
        lam_ref=e["lam_ref"],
        lam_tol=tl,
        r=e["r"],
        r_u=FINGERPRINT["r_u"] * e["r"],
        r_ref=e["r_ref"],
        r_tol=tr,
        corner_hz=e["corner_hz"],
        revolutions=int(e["revolutions"]),
    )


def refusal(fp: Fingerprint, diag) -> str | None:
    """The one-line refusal of a record whose fingerprint ``fp`` is another machine than
    ``diag``'s (None if it is not): what was estimated, the machine's value, the tolerance
    and the commands that build a diagnoser for the record's machine."""
    from .machine import how_to_build

    if fp.status != "another machine":
        return None
    mine = diag.machine
    name = mine.text() if not mine.is_default else "the default machine"
    return (
        f"another machine (its crosshead acceleration's crank orders): r/l from the 2nd/1st "
        f"orders = {fp.lam:.3f} +- {fp.lam_u:.3f} (this diagnoser's machine: "
        f"{fp.lam_ref:.3f}, tolerance +-{100 * fp.lam_tol:.0f} %), r x gain from the 1st "
        f"order = {1e3 * fp.r:.1f} +- {1e3 * fp.r_u:.1f} mm ({1e3 * fp.r_ref:.1f} mm, "
        f"tolerance +-{100 * fp.r_tol:.0f} %): this diagnoser was built for {name} and would "
        f"answer for that one; build a diagnoser for this machine: "
        f"{how_to_build(None, diag.card['spec'])}"
    )
