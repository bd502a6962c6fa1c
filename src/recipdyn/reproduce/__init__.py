"""Reproduce Xiao et al. (2017): every figure and every reported number, side by side.

[`reproduce`][recipdyn.reproduce.reproduce] runs each case of the paper
([`cases`][recipdyn.reproduce.cases]) under three variants
([`runner.VARIANTS`][recipdyn.reproduce.runner.VARIANTS]: exact equations from the natural start,
exact equations with an initial link offset, the paper's printed equations), caches the runs,
regenerates the figures (`figures`), tabulates every number the paper reports beside ours with the
relative difference and a reason (`report`), checks the claims about the model's behaviour
([`investigate`][recipdyn.reproduce.investigate]), and writes a self-contained HTML report plus
Markdown/CSV tables.
"""

from __future__ import annotations

import dataclasses
import json
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ModelValidityWarning
from ..io import jsonable, write_text
from ..model.kinematics import ideal_slider_crank
from ..model.parameters import CompressorParams
from ..progress import phase, quiet
from ..simulate import simulate
from .cases import CASES, PAPER_VALUES
from .runner import VARIANTS, RunSpec, Settings, run_all

__all__ = ["reproduce", "investigate", "Settings", "CASES", "PAPER_VALUES", "VARIANTS"]

OFFSETS = (0.0, 0.01, 0.05, 0.1, 0.2, 0.5, 1.0)


def investigate(quick: bool = False) -> tuple[dict[str, Any], Any]:
    """Check the model-behaviour claims: peak |a| over initial link offsets, clearances and the
    two equation variants. Returns ``(table, figure)``."""
    from ..plotting import _mpl

    revs = 1.0 if quick else 3.0
    offsets = OFFSETS[:4] if quick else OFFSETS
    table: dict[str, Any] = {"offsets_rad": list(offsets)}
    for eq, sign in (("exact", "physical"), ("paper-printed", "paper")):
        for rc in (0.1e-3, 1e-3, 5e-3):
            peaks = []
            for off in offsets:
                p = CompressorParams(rc=rc, d=0.0, theta_c_offset=off, equations=eq,
                                     load_sign=sign)  # fmt: skip
                try:
                    with warnings.catch_warnings():  # large offsets leave the model's validity:
                        # the table is about peak |a| (the report says where contact is lost)
                        warnings.simplefilter("ignore", ModelValidityWarning)
                        ds = simulate(p, revolutions=revs, fs=20_000)
                    peaks.append(float(np.abs(ds.a).max()))
                except Exception:  # the printed equations can blow up: record it
                    peaks.append(float("nan"))
            table[f"{eq}, rc = {1e3 * rc:g} mm"] = peaks
    plt = _mpl()
    fig, ax = plt.subplots(figsize=(8, 5), constrained_layout=True)
    for k, v in table.items():
        if k == "offsets_rad":
            continue
        ls = "-" if k.startswith("exact") else "--"
        ax.plot(offsets, v, ls, marker="o", label=k)
    _, _, a_id = ideal_slider_crank(CompressorParams(rc=0.0, d=0.0), np.linspace(0, 0.32, 4001))
    ax.axhline(np.abs(a_id).max(), color="k", lw=0.8, label="ideal mechanism")
    ax.set_xlabel("initial offset of the clearance angle from equilibrium (rad)")
    ax.set_ylabel("peak |a| of the crosshead (m/s$^2$)")
    ax.set_yscale("log")
    ax.set_title("Peak |a| is set by the initial link offset, not by rc (omega = 20 rad/s)")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, which="both")
    return table, fig


def reproduce(
    out: str | Path = "out",
    *,
    quick: bool = False,
    force: bool = False,
    jobs: int | None = None,
    progress: bool = True,
) -> Path:
    """Run everything and write ``OUT/report.html``, ``comparison.md/.csv``, ``figures/``.

    Parameters
    ----------
    out : path
        Output folder (created). ``OUT/cache`` keeps finished runs (keyed on parameters,
        settings and recipdyn version) so a rerun reuses them unless ``force``.
    quick : bool
        Reduced lengths (for tests and smoke runs); the same cases, figures and table rows.
    jobs : int, optional
        Worker processes (default: all cores).
    """
    from ..io import check_output
    from ..locking import RunLock

    t0 = time.perf_counter()
    out = check_output(out, formats=None, what="output folder")
    with RunLock(out, "reproduce"):
        return _reproduce(out, t0, quick, force, jobs, progress)


def _reproduce(out: Path, t0: float, quick: bool, force: bool, jobs: int | None,
               progress: bool) -> Path:  # fmt: skip
    from .figures import make_all_figures, save_figures
    from .report import comparison_rows, write_html, write_tables

    (out / "figures").mkdir(parents=True, exist_ok=True)
    settings = Settings().quick() if quick else Settings()
    specs = [RunSpec(c, v, settings) for c in CASES for v in VARIANTS]
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(specs), desc="reproduce: runs", unit="run")

    def tick(key, cached, _bar=bar):
        if _bar is not None:
            _bar.set_postfix_str(("cached " if cached else "") + key.split("__")[0])
            _bar.update(1)

    runs = run_all(specs, out / "cache", jobs=jobs, force=force, progress=tick)
    if bar is not None:
        bar.close()
    variants = [v.id for v in VARIANTS]
    step = phase if progress else quiet
    figures = make_all_figures(runs, variants, out / "figures", progress=progress)
    with step(f"reproduce: offset investigation ({2 * 3 * len(OFFSETS)} short runs)"):
        inv_table, inv_fig = investigate(quick=quick)
        figures.update(save_figures({"figX_offset_sweep": inv_fig}, out / "figures"))
    with step("reproduce: compression-cycle case"):
        cycle_findings, cycle_fig = cycle_case(quick=quick)
        figures.update(save_figures({"figY_compression_cycle": cycle_fig}, out / "figures"))
    from .joints import JOINT_CASES, QUICK_CASES, joint_comparison

    n_joint = len(QUICK_CASES if quick else JOINT_CASES)
    with step(f"reproduce: both joint models side by side ({2 * n_joint} runs)"):
        joint_rows, joint_fig = joint_comparison(quick=quick)
        if joint_fig is not None:
            figures.update(save_figures({"figZ_joint_models": joint_fig}, out / "figures"))
        _write_rows(out / "joint_models.csv", joint_rows)
    rows = comparison_rows(runs, variants)
    write_tables(rows, variants, out)
    findings = _findings(runs, inv_table) + cycle_findings + _joint_findings(joint_rows)
    notes = [
        "Masses and the rod's inertia are assumptions (the paper's Table 1 is illegible); "
        "lengths are the paper's. Initial conditions and time step are not given in the paper.",
        "Lyapunov exponents: 'Wolf' is Wolf et al. (1985) on the crosshead acceleration signal "
        "(the paper's method); 'Benettin' is the largest exponent from the variational "
        "equations of the exact model (1/s). The undamped model is conservative, so its "
        "exponents sum to ~0 and it has no attractors: chaos here is Hamiltonian chaos.",
        "The paper's printed Eq. (43)-(47) contain errata (docs/errata.md); the 'printed' "
        "variant uses them exactly as printed, with the paper's load sign.",
        "Spectra: one-sided amplitude spectra with a Hann window over the whole record.",
    ]
    runtime = time.perf_counter() - t0
    sdict = dataclasses.asdict(settings) | {"quick": quick, "variants": variants,
                                            "cases": len(CASES)}  # fmt: skip
    with step("reproduce: writing the report"):
        write_html(out, rows=rows, variants=variants,
                   variant_labels={v.id: v.label for v in VARIANTS}, figures=figures,
                   notes=notes, settings=sdict, runtime_s=runtime, findings=findings,
                   joint_rows=joint_rows)  # fmt: skip
    write_text(out / "investigation.json", json.dumps(jsonable(inv_table), indent=1))
    return out / "report.html"


#: The compression-cycle case of the report: an air compressor, 1 -> 3 bar absolute, at the
#: paper's speed and geometry (the cylinder data are assumptions: docs/gas_load.md).
CYCLE_CASE = dict(load="cycle", suction_pressure=1.0e5, discharge_pressure=3.0e5)


def cycle_case(quick: bool = False) -> tuple[list[tuple[str, Any]], Any]:
    """The paper's mechanism driven by the gas load of the compression cycle instead of the
    fixed Eq. (1)-(2): findings (cycle figures, API 618 pin-load reversal) and the figure."""
    from ..model.cycle import ideal_volumetric_efficiency
    from ..plotting import cycle_figure
    from ..simulate import simulate

    p = CompressorParams(**CYCLE_CASE)
    with warnings.catch_warnings():  # the validity is a finding of its own, below
        warnings.simplefilter("ignore", ModelValidityWarning)
        ds = simulate(p, revolutions=1.2 if quick else 3.0, transient=0, fs=10_000.0)
    a = ds.attrs
    ev = ideal_volumetric_efficiency(3.0, p.clearance_fraction, p.n_compression)
    findings = [
        (
            "compression cycle, air 1 -> 3 bar, paper's geometry and speed (assumed cylinder: "
            f"bore {p.bore} m, {p.acting}-acting, clearance {p.clearance_fraction:g}, n = "
            f"{p.n_compression:g}): indicated power, volumetric efficiency (closed form "
            f"{ev:.4f})",
            f"{a['indicated_power_W'] / 1e3:.1f} kW, {a['volumetric_efficiency_head']:.4f}",
        ),
        (
            "same case: crosshead-pin load reversal (API 618: >= 15 deg and >= 3 %)",
            f"{a.get('pin_reversal_deg', float('nan')):.1f} deg, "
            f"{100 * a.get('pin_reverse_fraction', float('nan')):.1f} %: "
            f"{a.get('api618_pin_reversal', 'n/a')}; gas load alone reverses for "
            f"{a.get('gas_rod_load_reversal_deg', float('nan')):.1f} deg",
        ),
        (
            "same case: does the massless link stay in contact (joint contact force >= 0)?",
            "yes"
            if a["validity"] == "ok"
            else f"no: minimum {a['min_contact_force_N']:.4g} N; the permanent-contact model does "
            "not hold over part of the cycle (use the contact-impact joint there)",
        ),
    ]
    return findings, cycle_figure(
        ds, title="Compression cycle, air 1 -> 3 bar, 20 rad/s (assumed cylinder), last revolution"
    )


def _write_rows(path: Path, rows: list[dict[str, Any]]) -> None:
    import csv
    import io

    buf = io.StringIO(newline="")
    w = csv.DictWriter(buf, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
    write_text(path, buf.getvalue())


def _joint_findings(rows: list[dict[str, Any]]) -> list[tuple[str, Any]]:
    """What the joint-model comparison shows, measured."""
    valid = [r for r in rows if r["link_valid_fraction"] == 1.0 and r["impacts_per_rev"] == 0]
    invalid = [r for r in rows if r["link_valid_fraction"] < 1.0]
    out = []
    if valid:
        worst = max(abs(r["peak_a_contact_vs_link"]) for r in valid)
        out.append(("both joint models, cases where the link force stays positive and the "
                    "journal never leaves the wall: largest difference in peak |a|",
                    f"{100 * worst:.2f} % over {len(valid)} case(s)"))  # fmt: skip
    for r in invalid:
        out.append((f"both joint models, rc = {r['rc_mm']:g} mm, {r['omega']:g} rad/s, load "
                    f"{r['load_kN']:g} kN: the massless link is outside its validity",
                    f"link force > 0 for {100 * r['link_valid_fraction']:.1f} % of the time; "
                    f"the contact joint is in contact {100 * r['contact_fraction']:.1f} % of "
                    f"the time, {r['impacts_per_rev']:.1f} impacts per revolution"))  # fmt: skip
    return out


def _findings(runs, inv) -> list[tuple[str, Any]]:
    """Measured statements for the report's summary."""
    nat = [ds for (c, v), ds in runs.items() if v == "natural"]
    ideal = np.abs(ideal_slider_crank(CompressorParams(rc=0.0, d=0.0),
                                      np.linspace(0, 0.32, 4001))[2]).max()  # fmt: skip
    w20 = [ds for ds in nat if abs(ds.attrs["param_omega"] - 20) < 1e-9]
    ratio = max(ds.attrs["m_peak_a"] for ds in w20) / ideal
    rel_sums = [abs(ds.attrs["m_lyap_benettin_sum"]) / max(abs(ds.attrs["m_lyap_benettin"]), 1e-3)
                for (c, v), ds in runs.items()
                if v != "printed" and ds.attrs["param_rc"] > 0
                and np.isfinite(ds.attrs["m_lyap_benettin_sum"])]  # fmt: skip
    lost = sorted({c for (c, v), ds in runs.items() if v == "natural"
                   and ds.attrs["m_min_contact_force"] < 0})  # fmt: skip
    ben_nat = {c: ds.attrs["m_lyap_benettin"] for (c, v), ds in runs.items() if v == "natural"}
    exact1 = inv.get("exact, rc = 1 mm", [])
    printed1 = inv.get("paper-printed, rc = 1 mm", [])
    out = [
        ("natural start, omega = 20 rad/s: largest peak |a| / ideal mechanism's "
         f"({ideal:.1f} m/s^2)", f"{ratio:.3f}"),
        ("natural-start cases where the joint contact force turns negative (inertia beats the "
         "gas load: the permanent-contact model no longer holds there)",
         ", ".join(lost) or "none"),
        ("largest |sum of Benettin exponents| / lambda1 (0 for a conservative system; the "
         "residual is integration error)", f"{max(rel_sums) if rel_sums else float('nan'):.3g}"),
        ("Benettin lambda1 (1/s) from the natural start, per case",
         ", ".join(f"{c}: {v:.3g}" for c, v in sorted(ben_nat.items()))),
        ("peak |a| vs initial offset (rad), exact, rc = 0.1 / 1 / 5 mm",
         "; ".join(f"{inv['offsets_rad'][i]:g}: " + "/".join(
             f"{inv[f'exact, rc = {r:g} mm'][i]:.4g}" for r in (0.1, 1, 5))
             for i in range(len(inv["offsets_rad"])))),
        ("peak |a| printed / exact equations at rc = 1 mm per offset",
         ", ".join(f"{p / e:.3g}" if e and np.isfinite(p) else "n/a"
                   for p, e in zip(printed1, exact1, strict=True))),
    ]  # fmt: skip
    return out
