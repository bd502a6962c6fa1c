"""Run a diagnoser on the blind set and judge every answer.

Each record's answer is one of:

* **right**: the true class named;
* **refused**: withheld, with its reason (a `recipdyn.errors.ParameterError` from
  ``diagnose``, such as too few tacho pulses, counts as a refusal: the command exits 2 with
  that line);
* **confidently wrong**: another class named with probability >= 0.5 (for a record of no
  compressor, any class);
* **weakly wrong**: another class named with probability < 0.5;
* **error**: ``diagnose`` raised anything else (a defect in itself).

For a right answer of a fault, whether the 90 % severity interval holds the true severity.
Tables per family and per target group (`TARGETS`, the issue's targets), as JSON and
Markdown.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
import warnings
from collections import Counter
from pathlib import Path

import numpy as np

from . import chain as C
from .sources import RecordSpec, physics

__all__ = ["classify", "make_channels", "run_records", "family_table", "group_table",
           "TARGETS", "markdown", "OUTCOMES"]  # fmt: skip

OUTCOMES = ("right", "refused", "confidently wrong", "weakly wrong", "error")

#: The issue's targets, per group of families (docs/diagnosis.md, issue 42).
TARGETS: dict[str, dict] = {
    "control": {"text": "in domain, the data set's kind of chain: as today (0.99 of the healthy "
                "machine and faults at s >= 0.5)", "right_min": 0.95},
    "chain": {"text": "chains within the stated ranges, all channels: >= 90 % right, <= 1 % "
              "confidently wrong, the rest refused", "right_min": 0.90,
              "confidently_wrong_max": 0.01},
    "chain-reduced": {"text": "chains within the ranges, accel + tacho or speed only: a class "
                      "named is right (<= 1 % confidently wrong)",
                      "confidently_wrong_max": 0.01},
    "installation": {"text": "chains outside the ranges (installation mistakes): right or "
                     "refused (<= 1 % confidently wrong)", "confidently_wrong_max": 0.01},
    "machine": {"text": "another machine without its own diagnoser: refused, 100 %",
                "refused_min": 1.0},
    "other-model": {"text": "another model's physics: right or refused (<= 1 % confidently "
                    "wrong)", "confidently_wrong_max": 0.01},
    "negative": {"text": "not a compressor: refused, 100 %", "refused_min": 1.0},
}  # fmt: skip


def classify(
    refused: bool,
    label: str | None,
    p: float | None,
    truth: str | None,
    severity_true: float | None = None,
    interval=None,
) -> tuple[str, bool | None]:
    """The outcome of one answer and whether its severity interval covers the truth (None
    when there is nothing to cover: refused, wrong, healthy, or no true severity)."""
    if refused:
        return "refused", None
    if truth is not None and label == truth:
        if truth == "healthy" or severity_true is None or interval is None:
            return "right", None
        lo, hi = sorted(float(v) for v in interval)
        return "right", bool(lo <= severity_true <= hi)
    return ("confidently wrong" if p is not None and p >= 0.5 else "weakly wrong"), None


def own_chain(phys: dict, rec: RecordSpec) -> tuple[dict, int]:
    """recipdyn's own chain (`recipdyn.sensors`, used as a black box) on the physics sampled
    every k-th sample (an exact simulation at that rate: the samples come from the dense
    output at exact times)."""
    import xarray as xr

    import recipdyn.sensors as S

    k = int(round(phys["fs"] / rec.fs))
    sl = slice(None, None, k)
    units = {"a": "m/s**2", "theta1": "rad", "p_head": "Pa", "p_crank": "Pa"}
    ds = xr.Dataset(
        {n: ("time", np.asarray(phys[n], float)[sl], {"units": u}) for n, u in units.items()},
        coords={"time": ("time", np.asarray(phys["t"], float)[sl], {"units": "s"})},
    )
    o = dict(rec.own)
    acc = S.Accelerometer(snr_db=o.get("snr_db", 40.0), resonance_hz=o.get("resonance_hz", 4e3))
    out = S.record(ds, accelerometer=acc, pressure=S.PressureTransducer(), tacho=S.Tacho(),
                   seed=rec.seed)  # fmt: skip
    th = np.asarray(phys["theta1"], float)
    t = np.asarray(phys["t"], float)
    ch = {
        "fs": phys["fs"] / k,
        "accel": out["accel_guide"].values,
        "tacho": out["tacho"].values,
        "p_head": out["p_head_sensor"].values,
        "p_crank": out["p_crank_sensor"].values,
        "speed_hz": float((th[-1] - th[0]) / (t[-1] - t[0]) / (2 * math.pi)),
    }
    return ch, k


def make_channels(rec: RecordSpec, phys: dict) -> dict:
    """The record's recorded channels: the physics through its chain, then its edits."""
    if rec.chain is not None:
        ch = C.apply_chain(phys, rec.chain, rec.seed)
        k = int(round(phys["fs"] / ch["fs"]))
    else:
        ch, k = own_chain(phys, rec)
    for e in rec.edits:
        ch = e(ch, phys, k)
    return ch


def diagnose_channels(ch: dict, channels: str, model) -> dict:
    """Run ``recipdyn.diagnosis.diagnose_arrays`` on the channels a user would give."""
    from recipdyn.diagnosis import diagnose_arrays
    from recipdyn.errors import ParameterError

    kw = {"model": model}
    if channels == "accel+speed":
        kw["speed_hz"] = ch["speed_hz"]
    else:
        kw["tacho"] = ch["tacho"]
    if channels == "all":
        kw["p_head"], kw["p_crank"] = ch["p_head"], ch["p_crank"]
    t0 = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = diagnose_arrays(ch["accel"], ch["fs"], **kw)
    except ParameterError as exc:
        return {"refused": True, "reason": f"(exit 2) {exc}", "error": None,
                "seconds": time.perf_counter() - t0}  # fmt: skip
    except Exception as exc:  # noqa: BLE001 -- a crash is an outcome to report, not to hide
        return {"refused": False, "error": f"{type(exc).__name__}: {exc}", "reason": "",
                "seconds": time.perf_counter() - t0}  # fmt: skip
    ans = {"refused": bool(res.refused), "reason": res.reason, "error": None,
           "seconds": time.perf_counter() - t0,
           "fingerprint": res.evidence.get("fingerprint"),
           "windows": res.evidence.get("windows")}  # fmt: skip
    if res.probabilities:  # the classifier's answer, named or refused
        top = max(res.probabilities, key=res.probabilities.get)
        ans.update(top=top, top_p=float(res.probabilities[top]))
    if not res.refused:
        ans.update(
            label=res.label,
            p=float(res.probabilities[res.label]),
            severity=float(res.severity),
            interval=[float(v) for v in res.severity_interval],
            value=float(res.value),
            value_interval=[float(v) for v in res.value_interval],
            unit=res.unit,
            ood=dict(res.ood),
        )
    return ans


def _physics_all(specs, cache, workers, say):
    uniq = {}
    for s in specs:
        uniq.setdefault(s.key, s)
    out = {}
    t0 = time.perf_counter()
    if workers > 1 and len(uniq) > 1:
        from concurrent.futures import ProcessPoolExecutor, as_completed

        with ProcessPoolExecutor(workers) as ex:
            futs = {ex.submit(physics, s, cache): k for k, s in uniq.items()}
            for i, f in enumerate(as_completed(futs)):
                out[futs[f]] = f.result()
                say(f"physics {i + 1}/{len(uniq)} ({time.perf_counter() - t0:.0f} s)")
    else:
        for i, (k, s) in enumerate(uniq.items()):
            out[k] = physics(s, cache)
            say(f"physics {i + 1}/{len(uniq)} ({time.perf_counter() - t0:.0f} s)")
    return out, time.perf_counter() - t0


def model_identity(model) -> dict:
    from recipdyn.diagnosis import default_model_path

    path = Path(default_model_path() if model is None else model)
    digest = hashlib.sha256(path.read_bytes()).hexdigest()[:16]
    return {"path": path.name if model is None else str(path), "sha256_16": digest,
            "shipped": model is None}  # fmt: skip


def run_records(records: list[RecordSpec], *, model=None, cache=None, workers: int = 1,
                say=print) -> dict:  # fmt: skip
    """Diagnose every record with ``model`` (a diagnoser file, a loaded diagnoser, or None:
    the shipped one); returns ``{"records": [...], "timing": {...}}``."""
    from recipdyn.diagnosis import default_model_path, load

    t_all = time.perf_counter()
    phys, t_phys = _physics_all([r.physics for r in records], cache, workers, say)
    t0 = time.perf_counter()
    if hasattr(model, "predict_proba"):  # a diagnoser already loaded
        diag = model
    else:
        diag = load(default_model_path() if model is None else model)
    t_load = time.perf_counter() - t0
    rows = []
    t_chain = t_diag = 0.0
    for i, rec in enumerate(records):
        t0 = time.perf_counter()
        ch = make_channels(rec, phys[rec.physics.key])
        t_chain += time.perf_counter() - t0
        ans = diagnose_channels(ch, rec.channels, diag)
        t_diag += ans["seconds"]
        ph = rec.physics
        if ans["error"]:
            outcome, covered = "error", None
        else:
            outcome, covered = classify(ans["refused"], ans.get("label"), ans.get("p"),
                                        ph.truth, ph.severity, ans.get("interval"))  # fmt: skip
        rows.append({
            "id": rec.id, "family": rec.family, "group": rec.group, "source": ph.source,
            "truth": ph.truth, "severity_true": ph.severity, "expect": rec.expect,
            "channels": rec.channels, "note": rec.note or ph.note, "outcome": outcome,
            "covered": covered, **{k: v for k, v in ans.items() if k != "seconds"},
            "seconds": ans["seconds"],
        })  # fmt: skip
        if (i + 1) % 25 == 0 or i + 1 == len(records):
            say(f"diagnosed {i + 1}/{len(records)}")
    timing = {"physics_s": t_phys, "load_s": t_load, "chains_s": t_chain, "diagnose_s": t_diag,
              "total_s": time.perf_counter() - t_all, "records": len(records),
              "physics_records": len(phys)}  # fmt: skip
    return {"records": rows, "timing": timing}


# ----------------------------------------------------------------------------- tables


def _reason_kind(reason: str) -> str:
    r = reason.lower()
    if r.startswith("on the held-out conditions,"):  # the channel gate (names the channels)
        # below the class's confidence threshold (channels.selective_threshold), or not at all
        return "confidence threshold" if "below that threshold" in r else "channel gate"
    if r.startswith("another machine (its crosshead acceleration's crank orders)"):
        return "machine fingerprint"
    for key, kind in (("crank speed", "speed range"), ("sampling rate", "sampling rate"),
                      ("noise floor", "noise floor"), ("impacts ring", "sensor band"),
                      ("sensor band", "sensor band"), ("transducer offset", "offset range"),
                      ("features lie", "out of domain"), ("tacho", "tacho")):  # fmt: skip
        if key in r:
            return kind
    return " ".join(reason.split()[:6])


def _counts(rows) -> dict:
    c = Counter(r["outcome"] for r in rows)
    n = len(rows)
    cov = [r["covered"] for r in rows if r["covered"] is not None]
    out = {"n": n, **{o: c.get(o, 0) for o in OUTCOMES}}
    out["severity_covered"] = sum(cov)
    out["severity_judged"] = len(cov)
    for o in ("right", "refused", "confidently wrong"):
        out[f"share {o}"] = c.get(o, 0) / n if n else math.nan
    out["refusals"] = dict(Counter(_reason_kind(r["reason"]) for r in rows if r["refused"]))
    return out


def family_table(rows) -> dict:
    fams: dict[str, list] = {}
    for r in rows:
        fams.setdefault(r["family"], []).append(r)
    return {f: {"group": rs[0]["group"], **_counts(rs)} for f, rs in fams.items()}


def _met(t: dict, c: dict) -> bool | None:
    if not c["n"]:
        return None
    ok = True
    if "right_min" in t:
        ok &= c["share right"] >= t["right_min"]
    if "confidently_wrong_max" in t:
        ok &= c["share confidently wrong"] <= t["confidently_wrong_max"]
    if "refused_min" in t:
        ok &= c["share refused"] >= t["refused_min"]
    return bool(ok)


def group_table(rows) -> dict:
    out = {}
    for g, t in TARGETS.items():
        rs = [r for r in rows if r["group"] == g]
        if rs:
            c = _counts(rs)
            out[g] = {**c, "target": t["text"], "met": _met(t, c)}
    return out


def _pct(x) -> str:
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{100 * x:.0f} %"


def markdown(result: dict, before: dict | None = None) -> str:
    """The tables of ``result`` (and the change from ``before``, a previous result)."""
    fam, grp = result["families"], result["groups"]
    L = []
    m = result["meta"]
    L.append(f"Diagnoser `{m['model']['path']}` (sha256 {m['model']['sha256_16']}), recipdyn "
             f"{m['recipdyn']}, seed {m['seed']}{', quick' if m['quick'] else ''}: "
             f"{m['timing']['records']} records from {m['timing']['physics_records']} "
             f"simulations in {m['timing']['total_s'] / 60:.1f} min.")  # fmt: skip
    L.append("")
    bg = (before or {}).get("groups", {})
    head = "| target group | records | right | refused | confidently wrong | weakly wrong | "
    head += "error | severity covered | target | met |" + (" before |" if before else "")
    L.append(head)
    L.append("|---|---|---|---|---|---|---|---|---|---|" + ("---|" if before else ""))
    for g, c in grp.items():
        b = bg.get(g)
        bt = ""
        if before:
            bt = (f" {_pct(b['share right'])} right, {_pct(b['share confidently wrong'])} conf. "
                  f"wrong, {_pct(b['share refused'])} refused |" if b else " – |")  # fmt: skip
        L.append(
            f"| {g} | {c['n']} | {c['right']} ({_pct(c['share right'])}) | {c['refused']} "
            f"({_pct(c['share refused'])}) | {c['confidently wrong']} "
            f"({_pct(c['share confidently wrong'])}) | {c['weakly wrong']} | {c['error']} | "
            f"{c['severity_covered']}/{c['severity_judged']} | {c['target']} | "
            f"{'met' if c['met'] else 'MISSED'} |" + bt
        )
    L.append("")
    L.append("| family | records | right | refused | confidently wrong | weakly wrong | error | "
             "severity covered | refusals |")  # fmt: skip
    L.append("|---|---|---|---|---|---|---|---|---|")
    for f, c in fam.items():
        ref = ", ".join(f"{k} {v}" for k, v in sorted(c["refusals"].items(), key=lambda kv: -kv[1]))
        L.append(f"| {f} | {c['n']} | {c['right']} | {c['refused']} | {c['confidently wrong']} | "
                 f"{c['weakly wrong']} | {c['error']} | {c['severity_covered']}/"
                 f"{c['severity_judged']} | {ref} |")  # fmt: skip
    return "\n".join(L)


def answer_text(r: dict) -> str:
    if r["outcome"] == "error":
        return f"error: {r['error'][:120]}"
    if r["refused"]:
        return f"refused ({_reason_kind(r['reason'])})"
    s = f"{r['label']} p {r['p']:.2f}"
    if r["label"] != "healthy" and r.get("interval"):
        lo, hi = sorted(r["interval"])
        s += f", s {r['severity']:.2f} [{lo:.2f}, {hi:.2f}]"
    return s


def summarise(run: dict, *, seed: int, quick: bool, model) -> dict:
    import recipdyn

    rows = run["records"]
    return {
        "meta": {
            "seed": seed,
            "quick": quick,
            "model": model_identity(model),
            "recipdyn": recipdyn.__version__,
            "timing": run["timing"],
            "ranges": {
                k: {
                    "lo": v.lo,
                    "hi": v.hi,
                    "unit": v.unit,
                    "choices": list(v.choices),
                    "source": v.source,
                }
                for k, v in C.RANGES.items()
            },
        },  # fmt: skip
        "groups": group_table(rows),
        "families": family_table(rows),
        "records": rows,
    }


def write(result: dict, out: Path, name: str, before: dict | None = None) -> tuple[Path, Path]:
    """``out/name.json`` and ``out/name.md`` (written, then renamed)."""
    out.mkdir(parents=True, exist_ok=True)
    js, md = out / f"{name}.json", out / f"{name}.md"
    for path, text in ((js, json.dumps(result, indent=1, default=_json)),
                       (md, markdown(result, before) + "\n")):  # fmt: skip
        tmp = path.with_suffix(path.suffix + ".tmp")
        tmp.write_text(text)
        tmp.replace(path)
    return js, md


def _json(o):
    if isinstance(o, np.generic):
        return o.item()
    return str(o)
