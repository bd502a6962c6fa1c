r"""The slider-crank with a translational clearance joint (Flores, Leine & Glocker 2010) against
the two reference outputs of siconos.

The mechanism and its parameters are
[`FloresTranslational`][recipdyn.model.reference.slider_crank_guide.FloresTranslational]; the
references are siconos's two stored outputs of the same benchmark (Moreau–Jean time stepping,
direct and combined projection, h = 1e-4 s, Newton impacts with e = 0.4 and Coulomb friction
0.01), kept with the package in ``data/siconos_slider_crank/`` with their provenance.

``python -m recipdyn.reproduce.flores_translational OUTDIR`` writes the figure
``flores_translational.png``, the table ``flores_translational.md`` and the numbers
``flores_translational.json``: crank revolutions, slider axial position, lateral position and
tilt, the impacts (instant and corner) over the 0.2 s of the reference, for recipdyn and both
siconos schemes, and their differences (docs/flores_benchmark.md, second section).
"""

from __future__ import annotations

import gzip
import json
import math
from dataclasses import asdict, replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from ..model.reference.slider_crank_guide import FloresTranslational

__all__ = ["SCHEMES", "reference", "run", "onsets", "compare", "table", "figure", "main"]

#: siconos's two stored outputs: label -> file.
SCHEMES = {
    "direct": "SliderCrankMoreauJeanDirectProjectionOSI.ref.gz",
    "combined": "SliderCrankMoreauJeanCombinedProjectionOSI.ref.gz",
}
_DATA = "data/siconos_slider_crank"
#: A corner is in an impact in siconos's output when its velocity-level impulse exceeds this
#: (N s); the impulses of a real impact are 1e-5 .. 1e-2 N s, and between impacts they are 0.
IMPULSE_FLOOR = 1e-9


def reference(scheme: str) -> dict[str, np.ndarray]:
    """One siconos output as named arrays (the columns of its README), read from the copy
    stored with the package."""
    if scheme not in SCHEMES:
        raise ValueError(f"scheme = {scheme!r}; allowed: {', '.join(SCHEMES)}")
    raw = resources.files("recipdyn.reproduce").joinpath(_DATA, SCHEMES[scheme]).read_bytes()
    d = np.loadtxt(gzip.decompress(raw).decode().splitlines()[1:])
    return {
        "t": d[:, 0], "revolutions": d[:, 1], "theta1": 2 * np.pi * d[:, 1], "theta2": d[:, 2],
        "phi": d[:, 3], "rates": d[:, 4:7], "corner_y_c": d[:, 7:11], "x_l1": d[:, 11],
        "y_c": d[:, 12], "gap": d[:, 13:17], "impulse": d[:, 21:25],
    }  # fmt: skip


def _impact_starts(active: np.ndarray, t: np.ndarray, theta1: np.ndarray) -> list[tuple]:
    """(time, crank angle, corner) where a corner's activity starts, in time order."""
    out = []
    for k in range(active.shape[1]):
        a = active[:, k]
        for i in np.nonzero(a[1:] & ~a[:-1])[0] + 1:
            out.append((float(t[i]), float(theta1[i]), k + 1))
    return sorted(out)


def run(par: FloresTranslational | None = None, t_end: float = 0.2, rtol: float = 1e-10,
        atol: float = 1e-13, samples: int = 2001) -> dict[str, Any]:  # fmt: skip
    """The benchmark in recipdyn: the same columns as siconos's outputs at the same instants,
    the energy, and the contact events (onsets and separations, per corner)."""
    from ..integrate import integrate
    from ..model.reference import slider_crank_guide as m

    par = par or FloresTranslational()
    t = np.linspace(0.0, t_end, samples)
    sol = integrate(m.system(par), m.initial_state(par), (0.0, t_end), rtol=rtol, atol=atol,
                    t_eval=t)  # fmt: skip
    y = sol.y
    s = m.corner_series(par, y)
    th1 = y[:, 0]
    ev_t = np.asarray(sol.t_events)
    before, after = np.atleast_2d(sol.y_events), np.atleast_2d(sol.y_events_after)
    events = []
    for i in range(ev_t.size):
        for k in np.nonzero(after[i, 6:10] != before[i, 6:10])[0]:  # the corners reset
            onset = after[i, 6 + k] > 0
            events.append((float(ev_t[i]), float(before[i, 0]), int(k) + 1, bool(onset),
                           float(after[i, 6 + k]) if onset else 0.0))  # fmt: skip
    return {
        "par": par, "t": t, "revolutions": th1 / (2 * np.pi), "theta1": th1,
        "theta2": y[:, 1], "phi": y[:, 2], "rates": y[:, 3:6],
        "x_l1": (par.l1 * np.cos(th1) + par.l2 * np.cos(y[:, 1]) - par.l2) / par.l1,
        "y_c": s["y_rel"] / par.c if par.c > 0 else s["y_rel"],
        "corner_y": s["corner_y"], "gap": s["gap"], "energy": s["energy"],
        "W_loss": y[:, 11], "events": events, "steps": int(sol.nsteps),
        "rejected": int(sol.nreject),
    }  # fmt: skip


def onsets(res: dict[str, Any]) -> list[tuple]:
    """(time, crank angle, corner) of every impact: recipdyn's contact onsets, or, for a
    siconos output, the steps where a corner's impulse becomes nonzero."""
    if "events" in res:
        return [(t, th, k) for t, th, k, on, _ in res["events"] if on]
    return _impact_starts(np.abs(res["impulse"]) > IMPULSE_FLOOR, res["t"], res["theta1"])


def _energy(ref: dict[str, np.ndarray], par: FloresTranslational) -> np.ndarray:
    from ..model.reference import slider_crank_guide as m

    y = np.zeros((ref["t"].size, 12))
    y[:, 0], y[:, 1], y[:, 2] = ref["theta1"], ref["theta2"], ref["phi"]
    y[:, 3:6] = ref["rates"]
    return m.energy(par, y)


def _by_angle(res: dict, ref: dict, key: str) -> np.ndarray:
    """``res[key]`` interpolated to the reference's crank angles (over their common range)."""
    th = ref["theta1"]
    keep = th <= res["theta1"][-1]
    return np.interp(th[keep], res["theta1"], res[key]), keep


def _pair_metrics(a: dict, b: dict, window: float) -> dict[str, float]:
    """Differences between two runs ``a``, ``b`` sampled at the same instants: at equal
    times (over the whole run and up to ``window``), and at equal crank angles."""
    early = a["t"] <= window + 1e-12
    out = {
        "revolutions_final_diff": float(a["revolutions"][-1] - b["revolutions"][-1]),
        "revolutions_max_diff": float(np.abs(a["revolutions"] - b["revolutions"]).max()),
        "revolutions_max_diff_window": float(
            np.abs(a["revolutions"] - b["revolutions"])[early].max()),
        "x_l1_max_diff_window": float(np.abs(a["x_l1"] - b["x_l1"])[early].max()),
        "y_c_rms_diff_window": float(np.sqrt(np.mean((a["y_c"] - b["y_c"])[early] ** 2))),
    }  # fmt: skip
    for key, name in (("x_l1", "x_l1_max_diff_by_angle"), ("y_c", "y_c_rms_diff_by_angle"),
                      ("phi", "phi_rms_diff_by_angle")):  # fmt: skip
        va, keep = _by_angle(a, b, key)
        d = va - b[key][keep]
        out[name] = float(np.abs(d).max() if "max" in name else np.sqrt(np.mean(d**2)))
    return out


def crossings(imp: list[tuple]) -> np.ndarray:
    """Crank angles (deg) of the impacts that end a crossing of the clearance (the first
    impact on the other guide surface), from a list of onsets (time, angle, corner); corners
    1-2 are on the upper surface, 3-4 on the lower."""
    out, side = [], 0
    for _, th, k in imp:
        s = 1 if k <= 2 else -1
        if s != side:
            out.append(math.degrees(th))
            side = s
    return np.array(out)


def _sequence_match(a: dict, b: dict, n: int = 6) -> dict[str, float]:
    """How far two runs' impacts agree: the largest difference in crank angle of their first
    ``n`` crossings of the clearance, and the fraction of the crank angles where both sliders
    are against a surface (|y| > c/2) at which it is the same one."""
    ca, cb = crossings(onsets(a)), crossings(onsets(b))
    m = min(n, ca.size, cb.size)
    va, keep = _by_angle(a, b, "y_c")
    yb = b["y_c"][keep]
    both = (np.abs(va) > 0.5) & (np.abs(yb) > 0.5)
    return {
        "crossings_compared": m,
        "crossings_max_diff_deg": float(np.abs(ca[:m] - cb[:m]).max()) if m else math.nan,
        "same_surface_fraction": float((np.sign(va) == np.sign(yb))[both].mean()),
        "both_on_a_surface_fraction": float(both.mean()),
    }


def compare(res: dict[str, Any] | None = None, window: float = 0.06) -> dict[str, Any]:
    """recipdyn against both siconos schemes, and the schemes against each other (the
    reference's own spread): the differences of `_pair_metrics`, the energies, the impacts."""
    res = res or run()
    par = res["par"]
    refs = {k: reference(k) for k in SCHEMES}
    out: dict[str, Any] = {"window_s": window}
    for k, ref in refs.items():
        ref["energy"] = _energy(ref, par)
        out[f"recipdyn_vs_{k}"] = _pair_metrics(res, ref, window)
        out[f"recipdyn_vs_{k}"].update(_sequence_match(res, ref))
    out["direct_vs_combined"] = _pair_metrics(refs["direct"], refs["combined"], window)
    out["direct_vs_combined"].update(_sequence_match(refs["direct"], refs["combined"]))
    e0 = float(res["energy"][0])
    for name, r in (("recipdyn", res), *refs.items()):
        imp = onsets(r)
        free = r["t"] <= (imp[0][0] if imp else r["t"][-1])
        out[name] = {
            "revolutions_at_end": float(r["revolutions"][-1]),
            "crank_speed_at_end_rad_s": float(r["rates"][-1, 0]),
            "energy_change_rel": float(r["energy"][-1] / e0 - 1.0),
            "energy_change_free_flight_rel": float(r["energy"][free][-1] / e0 - 1.0),
            "first_impact_s": imp[0][0] if imp else math.nan,
            "impacts": len(imp),
            "impacts_by_corner": [sum(1 for x in imp if x[2] == k) for k in range(1, 5)],
            "first_impacts": [(round(t, 5), round(math.degrees(th), 1), k)
                              for t, th, k in imp[:12]],
            "crossings_deg": [round(float(x), 1) for x in crossings(imp)],
        }  # fmt: skip
    out["recipdyn"]["energy_balance_residual"] = float(
        np.abs(res["energy"] + res["W_loss"] - e0).max() / e0
    )
    out["recipdyn"]["steps"] = res["steps"]
    out["parameters"] = {k: v for k, v in asdict(par).items()}
    return out


def table(cmp: dict[str, Any]) -> str:
    """The comparison as a markdown table."""
    rows = [
        ("crank revolutions at 0.2 s", "revolutions_at_end", "{:.4f}"),
        ("crank speed at 0.2 s (rad/s)", "crank_speed_at_end_rad_s", "{:.1f}"),
        ("energy T + V at 0.2 s / at 0, − 1", "energy_change_rel", "{:+.4f}"),
        ("same, up to the first impact", "energy_change_free_flight_rel", "{:+.5f}"),
        ("first impact (s)", "first_impact_s", "{:.4f}"),
        ("impacts in 0.2 s", "impacts", "{}"),
        ("impacts per corner 1-4", "impacts_by_corner", "{}"),
    ]
    out = ["| quantity | recipdyn | siconos direct | siconos combined |", "|---|---|---|---|"]
    for label, key, fmt in rows:
        cells = (fmt.format(cmp[n][key]) for n in ("recipdyn", "direct", "combined"))
        out.append(f"| {label} | " + " | ".join(cells) + " |")
    out += ["", "| difference | recipdyn − direct | recipdyn − combined | direct − combined |",
            "|---|---|---|---|"]  # fmt: skip
    w = cmp["window_s"]
    diffs = [
        ("crank revolutions at 0.2 s", "revolutions_final_diff", "{:+.4f}"),
        (f"max \\|Δ revolutions\\|, t ≤ {w} s", "revolutions_max_diff_window", "{:.2e}"),
        (f"max \\|Δ axial position\\| (col. 11, / l1), t ≤ {w} s", "x_l1_max_diff_window",
         "{:.2e}"),
        (f"RMS Δ lateral position (col. 12, / c), t ≤ {w} s", "y_c_rms_diff_window", "{:.3f}"),
        ("max \\|Δ axial position\\| (/ l1) at equal crank angle, 0.2 s",
         "x_l1_max_diff_by_angle", "{:.2e}"),
        ("RMS Δ lateral position (/ c) at equal crank angle, 0.2 s", "y_c_rms_diff_by_angle",
         "{:.3f}"),
        ("RMS Δ tilt (rad) at equal crank angle, 0.2 s", "phi_rms_diff_by_angle", "{:.2e}"),
        ("first 6 crossings of the clearance: max \\|Δ crank angle\\| (deg)",
         "crossings_max_diff_deg", "{:.1f}"),
        ("against the same surface (fraction of the angles where both are on one)",
         "same_surface_fraction", "{:.3f}"),
    ]  # fmt: skip
    pairs = ("recipdyn_vs_direct", "recipdyn_vs_combined", "direct_vs_combined")
    for label, key, fmt in diffs:
        out.append(f"| {label} | " + " | ".join(fmt.format(cmp[n][key]) for n in pairs) + " |")
    runs = ("recipdyn", "direct", "combined")
    out += ["", "| crossing of the clearance (crank angle, deg; + upper, − lower surface) | "
            "recipdyn | siconos direct | siconos combined |", "|---|---|---|---|"]  # fmt: skip
    n = max(len(cmp[r]["crossings_deg"]) for r in runs)
    for i in range(n):
        cells = []
        for r in runs:
            x = cmp[r]["crossings_deg"]
            cells.append(f"{x[i]:.1f}" if i < len(x) else "")
        out.append(f"| {i + 1} ({'+' if i % 2 == 0 else '−'}) | " + " | ".join(cells) + " |")
    out += ["", "| impact (time s, crank angle deg, corner) | recipdyn | siconos direct | "
            "siconos combined |", "|---|---|---|---|"]  # fmt: skip
    for i in range(12):
        cells = []
        for r in runs:
            x = cmp[r]["first_impacts"]
            cells.append(f"{x[i][0]:.4f}, {x[i][1]:.1f}, {x[i][2]}" if i < len(x) else "")
        out.append(f"| {i + 1} | " + " | ".join(cells) + " |")
    return "\n".join(out) + "\n"


def figure(res: dict[str, Any], *, title: str | None = None):
    """Crank revolutions and energy over time; slider axial position, lateral position and
    tilt over crank angle; the impacts (crank angle, corner) of the three runs."""
    from ..plotting import _mpl

    plt = _mpl()
    refs = {k: reference(k) for k in SCHEMES}
    for ref in refs.values():
        ref["energy"] = _energy(ref, res["par"])
    fig, ax = plt.subplots(3, 2, figsize=(13, 10), constrained_layout=True)
    styles = {"recipdyn": dict(color="C0", lw=1.0),
              "direct": dict(color="C3", lw=0.8, ls="--"),
              "combined": dict(color="C2", lw=0.8, ls=":")}  # fmt: skip
    runs = {"recipdyn": res, **{k: v for k, v in refs.items()}}
    labels = {"recipdyn": "recipdyn (compliant, Gonthier e = 0.4)"
              if res["par"].law == "gonthier" else f"recipdyn ({res['par'].law})",
              "direct": "siconos, direct projection",
              "combined": "siconos, combined projection"}  # fmt: skip
    for name, r in runs.items():
        deg = np.degrees(r["theta1"])
        ax[0, 0].plot(r["t"], r["revolutions"], label=labels[name], **styles[name])
        ax[0, 1].plot(r["t"], r["energy"], label=labels[name], **styles[name])
        ax[1, 0].plot(deg, r["x_l1"], **styles[name])
        ax[1, 1].plot(deg, r["y_c"], **styles[name])
        ax[2, 0].plot(deg, 1e3 * r["phi"], **styles[name])
        imp = onsets(r)
        off = {"recipdyn": 0.0, "direct": 0.2, "combined": -0.2}[name]
        ax[2, 1].plot([math.degrees(th) for _, th, _ in imp], [k + off for *_, k in imp],
                      "|", ms=7, color=styles[name]["color"])  # fmt: skip
    ax[0, 0].set(xlabel="time (s)", ylabel="crank revolutions")
    ax[0, 1].set(xlabel="time (s)", ylabel="energy T + V (J)")
    ax[1, 0].set(ylabel="slider axial position (col. 11, / l1)")
    ax[1, 1].set(ylabel="slider lateral position (col. 12, / c)")
    ax[2, 0].set(ylabel="slider tilt (mrad)")
    ax[2, 1].set(ylabel="corner of each impact", yticks=[1, 2, 3, 4])
    for a in ax[1:].ravel():
        a.set_xlabel("crank angle (deg)")
    for a in ax.ravel():
        a.grid(alpha=0.3)
    ax[0, 0].legend(fontsize=8)
    ax[1, 1].axhline(1, color="0.5", lw=0.6)
    ax[1, 1].axhline(-1, color="0.5", lw=0.6)
    fig.suptitle(title or "Slider-crank with a translational clearance joint (Flores, Leine & "
                 "Glocker 2010): recipdyn against siconos")  # fmt: skip
    return fig


def sensitivity(factors=(0.1, 10.0), **kw) -> dict[str, dict[str, float]]:
    """The comparison's key numbers with the contact stiffness scaled by ``factors``."""
    out = {}
    base = FloresTranslational()
    for f in (1.0, *factors):
        cmp = compare(run(replace(base, K=base.K * f), **kw))
        out[f"K x {f:g}"] = {
            "revolutions_at_end": cmp["recipdyn"]["revolutions_at_end"],
            "impacts": cmp["recipdyn"]["impacts"],
            "y_c_rms_diff_by_angle_direct": cmp["recipdyn_vs_direct"]["y_c_rms_diff_by_angle"],
            "crossings_max_diff_deg_direct": cmp["recipdyn_vs_direct"]["crossings_max_diff_deg"],
        }  # fmt: skip
    return out


def main(outdir: str | Path = ".") -> dict[str, Any]:
    """Write the figure, the table and the numbers into ``outdir``."""
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    res = run()
    cmp = compare(res)
    figure(res).savefig(out / "flores_translational.png", dpi=100)
    (out / "flores_translational.md").write_text(table(cmp))
    (out / "flores_translational.json").write_text(json.dumps(cmp, indent=1, default=str))
    return cmp


if __name__ == "__main__":  # pragma: no cover - python -m recipdyn.reproduce.flores_translational
    import sys

    c = main(sys.argv[1] if len(sys.argv) > 1 else ".")
    print(table(c))
