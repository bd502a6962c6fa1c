r"""The record's own machine, read from its crosshead acceleration: a kinematic fingerprint.

A diagnoser belongs to one machine (`recipdyn.diagnosis.machine`); a record that comes
without its machine's description must still not be answered for another one. The
crosshead's axial acceleration carries the mechanism's geometry in its lowest crank orders:
the slider-crank's ``a(theta) = -r w^2 (cos theta + lambda cos 2 theta + ...)``,
``lambda = r/l``. Fitted on the crank angle the tacho gives, over whole revolutions
(`recipdyn.analysis.vibration.crank_orders`), the record's 1st and 2nd orders give

* **r/l** from the ratio of the 2nd to the 1st order's amplitude, which the
  accelerometer's gain leaves unchanged;
* **r** (times the gain) from the 1st order's amplitude over ``w^2``.

Both are compared with the same orders of the diagnoser's own machine, computed numerically
from its exact kinematics (`recipdyn.model.kinematics.ideal_mechanism`, the offset ``d``
included), not from the truncated series (`estimate`, `check`).

**The AC coupling.** An accelerometer input is AC-coupled: a Butterworth high-pass of
order 1 or 2 with its corner at 0.1-2 Hz (`recipdyn.chain.DEFAULT_RANGES`), on a crank that
turns at 2.5-4 Hz. At the top of that range it lowers the 1st order by up to 22 % and the
2nd by up to 7 %, and leads both in phase, so the raw ratio overstates r/l by up to ~20 %.
The phase leads tell the corner: the combination ``D = 2 psi_1 - psi_2`` of the two
orders' phases, less that of the kinematic orders, is independent of the crank angle's zero
(a tacho mark off dead centre and a channel's delay cancel in it) and equals ``2 arg H(f) -
arg H(2 f)`` of the high-pass ``H`` alone. For each order of the coupling (1 or 2) the
corner that gives ``D`` is solved (at most the declared range's top) and both orders'
amplitudes are divided by ``|H|``; the two candidates are averaged.

**What else moves these orders** (measured by ``benchmarks/bench_fingerprint.py`` on the
shipped diagnoser's data set, every class and drawn chain): the joints' impacts and the
chain's noise, drift and settling put content into every low order, which the kinematics
leave nearly empty from the 3rd on (below 1 % of the 1st for r/l <= 0.3). Their RMS over
the orders 3-6 is each record's own measure of how far its 1st and 2nd orders may be off:
r/l is refused beyond a measured multiple of it; r, whose errors are the coupling's
(corrected only in part) rather than the record's noise, beyond a fixed share
(`recipdyn.diagnosis.tolerances.FINGERPRINT`, with the measurement).

A record without a tacho, or with less than two whole revolutions, is not fingerprinted;
the check says so in the evidence and the other checks decide.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from ..analysis.vibration import crank_orders as harmonics

__all__ = ["Fingerprint", "harmonics", "kinematic_orders", "estimate", "check", "refusal"]

#: Crank-angle samples per revolution for the orders (the 2nd order has 180 per period).
PER_REV = 360
#: The fewest whole revolutions the fingerprint is read from.
MIN_REVOLUTIONS = 2


@dataclass(frozen=True)
class Fingerprint:
    """The record's estimated geometry against the diagnoser's machine.

    ``lam`` (r/l) and ``r`` (m; the crank radius times the accelerometer's gain) with their
    95 % half-widths ``lam_u``, ``r_u`` (this record's, from the low orders the kinematics
    leave empty, scaled by the estimator's measured spread); the diagnoser's own
    ``lam_ref`` and ``r_ref``; the relative tolerances ``lam_tol``, ``r_tol`` this record
    is refused beyond (`recipdyn.diagnosis.tolerances.FINGERPRINT`); ``corner_hz``: the AC
    coupling's corner read from the phases (averaged over its two candidate orders);
    ``status``: ``"consistent"``, ``"another machine"`` or ``"not checked"`` (``note`` says
    why)."""

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


def _corner_range() -> tuple[float, float]:
    """The AC coupling's corner range (Hz) a record's chain is drawn from
    (`recipdyn.chain.DEFAULT_RANGES`)."""
    from ..chain import DEFAULT_RANGES

    span = DEFAULT_RANGES["accelerometer.highpass_hz"]
    return float(span.lo), float(span.hi)


def _wrap(a: float) -> float:
    return (a + np.pi) % (2 * np.pi) - np.pi


def estimate(x, fs: float, revs, machine=None) -> dict[str, float]:
    """The raw fingerprint of the acceleration ``x`` (m/s**2, at ``fs`` Hz, the crank angle
    ``revs`` in revolutions after the tacho's mark) against ``machine`` (the diagnoser's
    changes; None: the default machine): ``lam`` (r/l) after the AC coupling's correction,
    ``lam_raw`` without it; ``r`` (m, times the gain) from the 1st order after the
    coupling's correction, ``r_raw`` without it; ``corner_hz``, the two candidate
    orders' disagreement ``lam_spread``/``r_spread`` (half the difference, relative), the
    revolutions used and the machine's ``lam_ref``/``r_ref``."""
    from scipy.optimize import brentq

    revs = np.asarray(revs, float)
    c6, n = harmonics(x, revs, (1, 2, 3, 4, 5, 6))
    c = c6[:2]
    ok = np.isfinite(revs)
    t = np.flatnonzero(ok)
    f = float((revs[t[-1]] - revs[t[0]]) / ((t[-1] - t[0]) / fs))  # mean speed, Hz
    w = 2.0 * np.pi * f
    v = _values(machine)
    k6 = kinematic_orders(v, w, (1, 2, 3, 4, 5, 6))
    k = k6[:2]
    ratio_ref = abs(k[1]) / abs(k[0])
    d = _wrap(2 * np.angle(c[0]) - np.angle(c[1]) - (2 * np.angle(k[0]) - np.angle(k[1])))
    lams, rs, corners = [], [], []
    top = _corner_range()[1]
    for order in (1, 2):
        # (a corner beyond the declared range's top is the impacts' or the noise's phase)
        fc = min(_corner(order, d, f), top)
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

    # what the kinematics do not explain in the orders 3-6: the impacts' and the noise's
    # share of the low orders, the scale of the 1st and 2nd orders' own errors
    # (the kinematics' own orders 3-6 are below 1 % of the 1st for r/l <= 0.3: not removed)
    resid = float(np.sqrt(np.mean(np.abs(c6[2:]) ** 2)))
    raw = abs(c[1]) / abs(c[0])
    lam_c = [lam_of(x_) for x_ in lams]
    lam = float(np.mean(lam_c))
    r = float(np.mean(rs))
    return {
        "lam": lam,
        "lam_spread": abs(lam_c[1] - lam_c[0]) / 2 / lam if lam > 0 else math.nan,
        "lam_raw": lam_of(raw),
        "r": r,
        "r_raw": abs(c[0]) / abs(k[0]) * v["r"],
        "r_spread": abs(rs[1] - rs[0]) / 2 / r if r > 0 else math.nan,
        "corner_hz": float(np.mean(corners)),
        "phase_d_deg": math.degrees(d),
        "resid_12": resid / abs(c[0]),
        "resid_2": resid / abs(c[1]),
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
    try:
        e = estimate(x, fs, revs, machine)
    except ValueError as exc:
        return Fingerprint("not checked", str(exc))
    if e["revolutions"] < MIN_REVOLUTIONS or not math.isfinite(e["lam"]):
        return Fingerprint(
            "not checked",
            f"{e['revolutions']} whole revolution(s); at least {MIN_REVOLUTIONS} needed"
            if e["revolutions"] < MIN_REVOLUTIONS
            else "the orders' ratio lies beyond any slider-crank's (r/l 0.02-0.6)",
        )
    f = FINGERPRINT
    # r/l: this record's standard uncertainty, the crank orders 3-6 the kinematics leave
    # empty in units of the orders read and the AC coupling's two candidate orders'
    # disagreement, times the measured limit; r: a fixed tolerance (its
    # errors are the AC coupling's, not the record's noise)
    u_l = math.sqrt(e["resid_12"] ** 2 + e["resid_2"] ** 2 + e["lam_spread"] ** 2)
    dl = e["lam"] / e["lam_ref"] - 1.0
    dr = e["r"] / e["r_ref"] - 1.0
    tol_l = f["lam_z_limit"] * u_l
    other = abs(dl) > tol_l or abs(dr) > f["r_tol"]
    return Fingerprint(
        "another machine" if other else "consistent",
        lam=e["lam"],
        lam_u=f["lam_z95"] * u_l * e["lam"],
        lam_ref=e["lam_ref"],
        lam_tol=tol_l,
        r=e["r"],
        r_u=f["r_u95"] * e["r"],
        r_ref=e["r_ref"],
        r_tol=f["r_tol"],
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
