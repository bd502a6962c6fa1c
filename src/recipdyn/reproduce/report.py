"""The comparison table (every number the paper reports, ours beside it) and the HTML report."""

from __future__ import annotations

import base64
import csv
import html
import io
import platform
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from ..analysis.spectrum import nonharmonic_peak
from ..io import write_text
from ..model.parameters import ASSUMED, ASSUMED_CYCLE, PARAM_UNITS, CompressorParams
from .cases import PAPER_VALUES, PaperValue, case_by_id

__all__ = ["comparison_rows", "write_tables", "write_html", "REASONS", "GLOSSARY", "CAPTIONS"]

#: One-line reason for the differences, per quantity (checked claims, see the report's notes).
REASONS = {
    "peak_a": "natural start: the gas load pins the link, peaks stay at the ideal mechanism's; "
    "larger peaks need a free link oscillation, whose size is set by the (unknown) initial "
    "offset, not by rc; masses assumed",
    "dev_x": "geometric: the link aligned with the rod shifts the crosshead by ~rc at the dead "
    "centres; subsidence adds d-dependent rod-angle terms",
    "dev_v": "follows the link oscillation, i.e. the (unknown) initial condition and masses",
    "min_x": "x at the low dead point = l - r - rc (link toward the crank, physical load sign); "
    "the paper's value implies the link pointing the other way",
    "max_v": "crank kinematics (r omega (1 + r/l) ideally) plus the link oscillation",
    "freq_h": "our crank harmonics are exact multiples of omega/2pi; the paper's frequency axis "
    "is ~2.3 % low at 10, 20, 70 rad/s and 0.7 % high at 150 rad/s (resolution/scaling)",
    "freq_n": "link natural frequency ~sqrt(P/(m_eff rc)): depends on the assumed masses and on "
    "the load phase; absent without a free link oscillation",
    "lyap": "Wolf's estimate (shown) depends on embedding and evolution settings the paper does "
    "not give, its units are not stated, and on our acceleration signals it exceeds the "
    "equation-based (Benettin) lambda1 by 1-2 orders of magnitude: the fast link oscillation "
    "dominates the embedding; the undamped model is conservative (Benettin sum ~ 0)",
}


def _reason(pv: PaperValue) -> str:
    if pv.quantity == "freq":
        return REASONS["freq_h" if pv.harmonic else "freq_n"]
    return REASONS[pv.quantity]


def _peak_near(ds, f0: float, rel: float = 0.15) -> float:
    f = ds.frequency.values
    amp = ds.spectrum_a.values
    sel = (f >= f0 * (1 - rel)) & (f <= f0 * (1 + rel))
    return float(f[sel][np.argmax(amp[sel])]) if sel.any() else float("nan")


def _nonharmonic_fundamental(ds) -> float:
    """Largest spectral peak above 8 crank orders that is not a crank harmonic."""
    return nonharmonic_peak(ds.frequency.values, ds.spectrum_a.values,
                            float(ds.attrs["crank_frequency_hz"]))  # fmt: skip


def our_value(pv: PaperValue, runs: dict, variant: str) -> float:
    ds = runs.get((pv.case, variant))
    if ds is None:
        return float("nan")
    q = pv.quantity
    if q in ("peak_a", "min_x", "max_v"):
        return float(ds.attrs[f"m_{q}"])
    if q in ("dev_x", "dev_v"):
        ref = runs[(pv.ref, variant)]
        var = "x" if q == "dev_x" else "v"
        n = min(ds.sizes["time"], ref.sizes["time"])
        dev = float(np.max(np.abs(ds[var].values[:n] - ref[var].values[:n])))
        return 1e3 * dev if q == "dev_x" else dev
    if q == "freq":
        fc = float(ds.attrs["crank_frequency_hz"])
        if pv.harmonic:
            return _peak_near(ds, pv.harmonic * fc, rel=0.5 / pv.harmonic)
        f0 = _nonharmonic_fundamental(ds)
        k = {"a": 1, "b": 2, "c": 3}[pv.key[-1]]
        return f0 if k == 1 or not np.isfinite(f0) else _peak_near(ds, k * f0, rel=0.1)
    if q == "lyap":
        return float(ds.attrs["m_lyap_wolf"])
    raise KeyError(q)


def comparison_rows(runs: dict, variants: list[str]) -> list[dict[str, Any]]:
    rows = []
    for pv in PAPER_VALUES:
        row: dict[str, Any] = dict(
            key=pv.key, where=pv.where, case=case_by_id(pv.case).label, quantity=pv.quantity,
            unit=pv.unit, paper=pv.value,
        )  # fmt: skip
        for v in variants:
            val = our_value(pv, runs, v)
            row[f"ours_{v}"] = val
            row[f"rel_{v}"] = (val - pv.value) / pv.value if np.isfinite(val) else float("nan")
        for v in variants:  # equation-based exponents beside Wolf's (lyap rows only)
            ds = runs.get((pv.case, v)) if pv.quantity == "lyap" else None
            row[f"benettin_{v}"] = float(ds.attrs["m_lyap_benettin"]) if ds else np.nan
            row[f"benettin_sum_{v}"] = float(ds.attrs["m_lyap_benettin_sum"]) if ds else np.nan
        row["reason"] = _reason(pv)
        rows.append(row)
    return rows


def _fmt(x: Any) -> str:
    if isinstance(x, float):
        if not np.isfinite(x):
            return "n/a"
        return f"{x:.4g}"
    return str(x)


def _table(rows, variants) -> tuple[list[str], list[list[str]]]:
    """Header and formatted cells of the comparison table (shared by Markdown and HTML)."""
    head = ["where", "case", "quantity", "paper"]
    for v in variants:
        head += [f"ours [{v}]", f"diff [{v}]"]
    head.append("reason")
    body = []
    for r in rows:
        cells = [r["where"], r["case"], f"{r['quantity']} ({r['unit']})", _fmt(r["paper"])]
        for v in variants:
            rel = r[f"rel_{v}"]
            cells += [_fmt(r[f"ours_{v}"]), f"{100 * rel:+.1f} %" if np.isfinite(rel) else "n/a"]
        cells.append(r["reason"])
        body.append(cells)
    return head, body


def _md_table(rows, variants) -> str:
    head, body = _table(rows, variants)
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(cells) + " |" for cells in body]
    return "\n".join(lines)


def write_tables(rows, variants, out: Path) -> tuple[Path, Path]:
    csv_path = out / "comparison.csv"
    buf = io.StringIO(newline="")
    w = csv.DictWriter(buf, fieldnames=list(rows[0].keys()))
    w.writeheader()
    w.writerows(rows)
    write_text(csv_path, buf.getvalue())
    md_path = out / "comparison.md"
    write_text(md_path, "# Paper vs recipdyn: every reported number\n\n" + _md_table(rows, variants)
                       + "\n")  # fmt: skip
    return csv_path, md_path


#: Every quantity and term the report uses, defined once (the table links here).
GLOSSARY: dict[str, str] = {
    "peak_a": "largest |a| of the crosshead acceleration over the record (m/s^2)",
    "dev_x": "largest |x - x_ref| between this case's crosshead displacement and the "
    "reference case's (the paper's 'deviation' between curves), sample by sample (mm)",
    "dev_v": "largest |v - v_ref| between this case's crosshead velocity and the reference "
    "case's, sample by sample (m/s)",
    "min_x": "smallest crosshead displacement x3, at the inner dead centre (mm)",
    "max_v": "largest crosshead velocity (m/s)",
    "freq": "frequency of a spectral peak of the crosshead acceleration (Hz): a crank "
    "harmonic (k omega / 2 pi) or the link's own oscillation (not a harmonic)",
    "lyap": "largest Lyapunov exponent; the paper's (Wolf's method on a signal, units not "
    "stated) against ours (Wolf on a, and Benettin from the equations, 1/s)",
    "rc": "radial clearance of the crank-pin joint = length of the massless virtual link (mm)",
    "d": "crosshead subsidence: the crosshead runs at y = -d (mm)",
    "omega": "crank speed (rad/s); the crank frequency is omega / 2 pi (Hz)",
    "theta_c": "clearance angle: direction of the virtual link (rad)",
    "x, v, a": "crosshead displacement x3 (m), velocity (m/s), acceleration (m/s^2)",
    "natural": "variant: exact equations, physical load sign, link at its static equilibrium",
    "offset": "variant: exact equations, link started 0.2 rad off its equilibrium",
    "printed": "variant: the paper's printed Eq. (43)-(47) (errata included) and load sign",
    "diff": "relative difference (ours - paper) / paper",
    "Wolf": "Wolf et al. (1985): largest exponent from a delay embedding of one signal",
    "Benettin": "Benettin et al. (1980): exponents from the variational equations of the model",
    "Poincare section": "the state once per crank revolution (stroboscopic); closed curves "
    "mean quasi-periodic motion, a finite set periodic, a scattered cloud chaotic",
    "assumed": "a value the paper does not give (its Table 1 is illegible); ours, labelled",
    "contact fraction": "contact-impact joint: fraction of the time the journal touches the "
    "bearing (penetration > 0)",
    "impacts/rev": "contact-impact joint: contact onsets per crank revolution",
    "link valid": "massless link: fraction of the time its contact force is positive (the "
    "link can only push; outside, the model does not hold)",
}

#: What each paper figure shows (the report's captions).
CAPTIONS: dict[str, str] = {
    "fig02": "Fig. 2: the cylinder load of Eq. (1)-(2) over a cycle.",
    "fig04": "Figs. 4-7: crosshead x, v, a over time and the spectrum of a, clearance 0 to 5 mm "
    "(d = 0, 20 rad/s); the spectrum extends to the link's own line when there is one.",
    "fig08": "Figs. 8-13: the clearance sweep (8-10) and the subsidence sweep (11-13) "
    "overlaid, with each case's difference from the first case below; a case that rings "
    "(offset start) gets one row per case, drawn as its envelope with a zoom.",
    "fig14": "Figs. 14-16: response at 10, 70 and 150 rad/s (rc = d = 1 mm).",
    "fig17": "Figs. 17-23: phase trajectories x-v and v-a over clearance, subsidence and "
    "speed; a dense orbit is drawn thin and translucent (shade = time spent).",
    "fig24": "Fig. 24: largest Lyapunov exponents per sweep: the paper's, Wolf's on our "
    "signal, and Benettin's from the equations.",
    "fig25": "Figs. 25-28: Poincare sections (v, a) once per revolution; a section that "
    "spans micrometres per second is drawn as the deviation from its median (in the label).",
    "figX": "Investigation: peak |a| against the initial link offset, rc and the equations.",
    "figY": "The compression-cycle case: p-V, pressures and rod loads.",
    "figZ": "Both joint models, light load: the massless link leaves its validity (red), the "
    "contact-impact joint shows free flight and impacts.",
}

#: Width (px) of the copies embedded in the report; the full-size PNGs are linked.
EMBED_WIDTH = 640


def _embedded(path: Path, width: int = EMBED_WIDTH) -> str:
    """The figure as a compact embedded image (a ``data:`` URI): scaled to ``width`` and
    encoded as WebP at quality 70, about 8x smaller than the saved PNG and sharp enough for
    text and lines at that width; the full-size PNG is linked beside it."""
    from PIL import Image

    im = Image.open(path).convert("RGB")
    if im.width > width:
        im = im.resize((width, round(im.height * width / im.width)), Image.Resampling.LANCZOS)
    buf = io.BytesIO()
    im.save(buf, "WEBP", quality=70)
    return "data:image/webp;base64," + base64.b64encode(buf.getvalue()).decode()


_CHECK_SCRIPT = """<script>
window.addEventListener('load', function () {
  var imgs = Array.prototype.slice.call(document.images);
  var ok = imgs.length > 0 && imgs.every(function (i) { return i.complete && i.naturalWidth > 0; });
  document.body.setAttribute('data-images-ok', ok ? 'true' : 'false');
  document.body.setAttribute('data-image-count', String(imgs.length));
  var bad = Array.prototype.slice.call(document.querySelectorAll('a[href^="#"]')).filter(
    function (a) { return !document.getElementById(a.getAttribute('href').slice(1)); });
  document.body.setAttribute('data-broken-anchors', String(bad.length));
});
function openTarget() {  // a link into a collapsed section opens it
  var el = location.hash && document.getElementById(location.hash.slice(1));
  for (; el; el = el.parentElement) { if (el.tagName === 'DETAILS') { el.open = true; } }
}
window.addEventListener('hashchange', openTarget);
window.addEventListener('load', openTarget);
</script>"""

_STYLE = """<style>
body{font-family:system-ui,sans-serif;margin:0;color:#222;line-height:1.4}
nav{position:fixed;top:0;left:0;width:210px;height:100vh;overflow-y:auto;background:#f5f5f5;
 border-right:1px solid #ddd;padding:.8em;box-sizing:border-box;font-size:13px}
nav a{display:block;color:#0072B2;text-decoration:none;padding:2px 0}nav a.sub{padding-left:1em}
main{margin-left:220px;max-width:1250px;padding:0 1.2em 3em}
details{border-top:1px solid #ddd;margin:.4em 0}summary{cursor:pointer;padding:.3em 0}
summary h2,summary h3{display:inline;margin:0}
table{border-collapse:collapse;font-size:12px}td,th{border:1px solid #ccc;padding:3px 5px}
th{background:#eee;position:sticky;top:0}tr.assumed td{background:#fff6e0}
.badge{background:#E69F00;color:#000;border-radius:3px;padding:0 4px;font-size:11px}
.figs{display:grid;grid-template-columns:repeat(auto-fill,minmax(560px,1fr));gap:10px}
figure{margin:0}img{width:100%;height:auto;border:1px solid #eee}figcaption{font-size:12px}
dt{font-weight:bold;margin-top:.3em}dd{margin-left:1.5em}
</style>"""


def _gid(term: str) -> str:
    """The glossary anchor of a term (letters, digits, '-' and '_' only)."""
    import re

    return "gl-" + re.sub(r"[^A-Za-z0-9_-]+", "-", term)


def _figure_groups(figures: dict[str, Path]) -> list[tuple[str, str, list[str]]]:
    """Figures grouped as the paper groups them: ``(anchor, caption, stems)``."""
    groups: dict[str, list[str]] = {}
    starts = sorted(CAPTIONS)
    for stem in sorted(figures):
        num = stem.split("_")[0]
        key = max((k for k in starts if k <= num), default=num)  # "fig13" -> "fig08"
        groups.setdefault(key, []).append(stem)
    return [(f"g-{k}", CAPTIONS.get(k, k), stems) for k, stems in sorted(groups.items())]


def write_html(
    out: Path,
    *,
    rows,
    variants,
    variant_labels,
    figures: dict[str, Path],
    notes: list[str],
    settings: dict,
    runtime_s: float,
    findings: list[tuple[str, Any]],
    joint_rows: list[dict[str, Any]] | None = None,
) -> Path:
    """A single self-contained HTML file: a navigation bar, collapsible sections (findings,
    notes, variants, parameters with the assumed ones marked, settings, the comparison table
    with every quantity linked to the glossary, the figures grouped as the paper groups them,
    each linked to its full-size PNG), and the glossary."""
    from ..model.parameters import SCHEMA

    e = html.escape
    groups = _figure_groups(figures)
    sections = [("findings", "Findings"), ("notes", "Notes"), ("variants", "Variants"),
                ("parameters", "Parameters and assumptions"), ("settings", "Settings"),
                ("table", "Every number the paper reports"),
                ("joints", "Both joint models side by side"), ("figures", "Figures"),
                ("glossary", "Glossary")]  # fmt: skip
    nav = ["<nav><b>recipdyn report</b>"]
    for sid, title in sections:
        nav.append(f"<a href='#{sid}'>{e(title)}</a>")
        if sid == "figures":
            nav += [f"<a class='sub' href='#{gid}'>{e(cap.split(':')[0])}</a>"
                    for gid, cap, _ in groups]  # fmt: skip
    nav.append("</nav>")

    def section(sid, title, body, open_=True):
        return (f"<details id='{sid}'{' open' if open_ else ''}><summary><h2>{e(title)}</h2>"
                f"</summary>{body}</details>")  # fmt: skip

    p0 = CompressorParams()
    values = p0.to_attrs()
    prow = []
    for prm in SCHEMA.params:
        note = ASSUMED.get(prm.name, "") or ASSUMED_CYCLE.get(prm.name, "")
        badge = " <span class='badge'>assumed</span>" if note else ""
        prow.append(f"<tr{' class=assumed' if note else ''}><td>{e(prm.name)}{badge}</td>"
                    f"<td class=n>{e(str(values.get(prm.name, prm.default)))}</td>"
                    f"<td>{e(PARAM_UNITS.get(prm.name, ''))}</td><td>{e(prm.description)}"
                    f"{'<br><i>' + e(note) + '</i>' if note else ''}</td></tr>")  # fmt: skip
    head, body = _table(rows, variants)
    trows = []
    for r, cells in zip(rows, body, strict=True):
        q = r["quantity"]
        cells = [e(c) for c in cells]
        cells[2] = f"<a href='#{_gid(q)}'>{e(q)}</a> ({e(r['unit'])})"
        trows.append("<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
    thead = "".join(f"<th>{e(h)}</th>" for h in head)
    figs = []
    for gid, cap, stems in groups:
        items = "".join(
            f"<figure><a href='figures/{e(figures[s].name)}'><img loading='lazy' alt='{e(s)}' "
            f"src='{_embedded(figures[s])}'></a><figcaption>{e(s)} "
            "(click for full size)</figcaption></figure>"
            for s in stems
        )
        figs.append(f"<details id='{gid}' open><summary><h3>{e(cap)}</h3></summary>"
                    f"<div class='figs'>{items}</div></details>")  # fmt: skip
    gloss = "".join(f"<dt id='{_gid(k)}'>{e(k)}</dt><dd>{e(v)}</dd>" for k, v in GLOSSARY.items())
    parts = [
        "<!doctype html><html lang='en'><head><meta charset='utf-8'>",
        "<meta name='viewport' content='width=device-width, initial-scale=1'>",
        "<title>recipdyn: reproduction of Xiao et al. (2017)</title>",
        _STYLE,
        _CHECK_SCRIPT,
        "</head><body>",
        *nav,
        "<main><h1>Reproduction of Xiao et al. (2017), J. Vibroengineering 19(7)</h1>",
        f"<p>recipdyn {e(__version__)}, Python {e(platform.python_version())}, "
        f"run time {runtime_s:.0f} s. Values marked <span class='badge'>assumed</span> are "
        "not given by the paper. Every quantity is defined in the <a href='#glossary'>"
        "glossary</a>.</p>",
        section("findings", "Findings", "<ul>" + "".join(
            f"<li>{e(str(k))}: <b>{e(str(v))}</b></li>" for k, v in findings) + "</ul>"),
        section("notes", "Notes", "<ul>" + "".join(f"<li>{e(n)}</li>" for n in notes)
                + "</ul>"),
        section("variants", "Variants", "<ul>" + "".join(
            f"<li><b><a href='#{_gid(v)}'>{e(v)}</a></b>: {e(variant_labels[v])}</li>"
            for v in variants) + "</ul>"),
        section("parameters", "Parameters and assumptions",
                "<table><tr><th>parameter</th><th>value</th><th>unit</th><th>meaning</th></tr>"
                + "".join(prow) + "</table>"),
        section("settings", "Settings", "<table>" + "".join(
            f"<tr><td>{e(k)}</td><td>{e(str(v))}</td></tr>" for k, v in settings.items())
            + "</table>", open_=False),
        section("table", "Every number the paper reports",
                "<p>ours [variant] and diff [variant] = (ours - paper) / paper for each "
                "<a href='#variants'>variant</a>; the reason column says why they differ."
                f"</p><table><tr>{thead}</tr>" + "".join(trows) + "</table>"),
        section("joints", "Both joint models side by side", _joint_table(joint_rows or [])),
        section("figures", "Figures", "".join(figs)),
        section("glossary", "Glossary", f"<dl>{gloss}</dl>"),
        "</main></body></html>",
    ]  # fmt: skip
    path = out / "report.html"
    write_text(path, "\n".join(parts))
    return path


def _joint_table(rows: list[dict[str, Any]]) -> str:
    """The joint-model comparison as an HTML table (the CSV has every column)."""
    if not rows:
        return "<p>not run</p>"
    e = html.escape
    head = ["rc (mm)", "omega (rad/s)", "load (kN)", "impacts/rev", "peak |a| contact (m/s^2)",
            "peak force contact (N)", "contact fraction", "peak |a| link (m/s^2)",
            "peak force link (N)", "link valid", "peak |a| contact / link - 1"]  # fmt: skip
    keys = ["rc_mm", "omega", "load_kN", "impacts_per_rev", "contact_peak_a",
            "contact_peak_force_N", "contact_fraction", "link_peak_a", "link_peak_force_N",
            "link_valid_fraction", "peak_a_contact_vs_link"]  # fmt: skip
    link = {"impacts/rev": "impacts/rev", "contact fraction": "contact fraction",
            "link valid": "link valid"}  # fmt: skip
    cells = "".join(
        f"<th><a href='#{_gid(link[h])}'>{e(h)}</a></th>" if h in link else f"<th>{e(h)}</th>"
        for h in head
    )
    body = "".join("<tr>" + "".join(f"<td class=n>{e(_fmt(float(r[k])))}</td>" for k in keys)
                   + "</tr>" for r in rows)  # fmt: skip
    return ("<p>The paper's mechanism with the massless virtual link and with the "
            "contact-impact clearance joint (docs/contact.md), the paper's geometry and the "
            "assumed masses, recorded after a transient. All columns: joint_models.csv.</p>"
            f"<table><tr>{cells}</tr>{body}</table>")  # fmt: skip
