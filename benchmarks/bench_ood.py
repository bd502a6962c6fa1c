"""Out-of-domain scores compared on the blind set (issue 42, item 4a).

Every blind record goes through `recipdyn.diagnosis.diagnose_arrays` as a user's would; at
the out-of-domain step, the feature row the diagnoser reads (after the chain correction and
the range checks) is scored by each detector of `recipdyn.diagnosis.domain` (kNN, local
outlier factor, isolation forest, the class-conditional kNN) under each feature transform,
all calibrated on the same held-out records, and their conformal p-values are kept. The
table gives, per family of the blind set, the share each would refuse at ``--alpha``, among
all the records that reach the step and among those the diagnoser then names wrongly with
p >= 0.5 (what a refusal is for) or rightly (what it costs), and the in-domain refusal rate
and the control families' rate (in-domain records: the stated rate, checked).

    python benchmarks/bench_ood.py --model FILE --calibration DATASET [DATASET...] [--quick]

``--calibration``: the held-out data sets the detectors are calibrated on (the diagnoser's
own calibration records otherwise cannot be rebuilt: its file holds their scores, not their
features). Writes ``OUT/ood.json`` and ``OUT/ood.md``. "Wrong" and "right" are the
classifier's answer at that step, before any refusal.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from blind import harness as H  # noqa: E402
from blind.sources import blind_set  # noqa: E402


def _detectors(diag, held, alpha):
    from recipdyn.diagnosis.domain import DETECTORS, TRANSFORMS, Domain, fit_domain
    from recipdyn.diagnosis.train import AVAILABILITY, _cols

    st = diag.state
    Z = (held["X"] - st["center"]) / st["scale"]
    cols = {k: _cols(diag.names, k) for k in AVAILABILITY}
    out = {}
    for tr in TRANSFORMS:
        for m in DETECTORS:
            dom = fit_domain(st["Z_train"], np.asarray(st["train_labels"]), cols,
                             [(Z, held["labels"], k) for k in AVAILABILITY],
                             fit_rows=np.ones(len(st["train_labels"]), bool), method=m,
                             transform=tr, alpha=alpha)  # fmt: skip
            out[f"{m}/{tr}"] = Domain(dom, st["Z_train"], st["train_labels"])
    return out


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", required=True)
    ap.add_argument("--calibration", nargs="+", required=True)
    ap.add_argument("--alpha", type=float, default=0.02)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--seed", type=int, default=20240)
    ap.add_argument("--cache", default=None)
    ap.add_argument("--out", default="bench-results/ood")
    args = ap.parse_args(argv)
    from recipdyn.diagnosis.train import held_out_rows, load

    t0 = time.perf_counter()
    diag = load(args.model)
    from recipdyn.diagnosis.dataset import read_features

    parts = []
    for f in args.calibration:
        df, _ = read_features(f)
        df = df[df.label.isin(diag.classes)]
        if "chain_refused" in df.columns:
            df = df[df.chain_refused.fillna("") == ""]
        parts.append(held_out_rows(Path(f), df.reset_index(drop=True), diag.names))
    held = {k: np.concatenate([p[k] for p in parts]) for k in ("X", "labels")}
    dets = _detectors(diag, held, args.alpha)
    seen: dict[str, dict] = {}
    base_ood = type(diag).ood

    def ood(self, row, label=None):  # the diagnoser's own verdict, every detector's p kept
        from recipdyn.diagnosis.train import available

        subset = available(row, self.names)
        z = (np.asarray(row, float) - self.state["center"]) / self.state["scale"]
        ps = {k: float(d.p_value(z[None, :], subset, label)[0]) for k, d in dets.items()}
        top = float(np.max(self.predict_proba(np.asarray(row, float)[None, :])[0]))
        seen["last"] = {"p": ps, "subset": subset, "label": label, "p_label": top}
        return base_ood(self, row, label)

    type(diag).ood = ood
    recs = blind_set(args.seed, quick=args.quick)
    rows = []
    cache = Path(args.cache) if args.cache else None
    try:
        phys, _ = H._physics_all([r.physics for r in recs], cache, 1, lambda m: None)
        for rec in recs:
            seen.pop("last", None)
            ch = H.make_channels(rec, phys[rec.physics.key])
            ans = H.diagnose_channels(ch, rec.channels, diag)
            # the classifier's answer at the step (what a refusal there withholds)
            last = seen.get("last", {})
            rows.append({"id": rec.id, "family": rec.family, "group": rec.group,
                         "truth": rec.physics.truth, "reached": bool(last),
                         "p": last.get("p"), "label": last.get("label"),
                         "p_label": last.get("p_label"), "refused": ans["refused"],
                         "reason": ans.get("reason", "")})  # fmt: skip
    finally:
        type(diag).ood = base_ood
    res = {"alpha": args.alpha, "detectors": list(dets), "records": rows,
           "calibration": [str(c) for c in args.calibration],
           "seconds": time.perf_counter() - t0}  # fmt: skip
    md = table(res)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "ood.json").write_text(json.dumps(res, indent=1, default=str))
    (out / "ood.md").write_text(md + "\n")
    print(md)
    return res


def table(res: dict) -> str:
    """Per target group and per family: the share each detector refuses of the records that
    reach the out-of-domain step."""
    a, dets, rows = res["alpha"], res["detectors"], res["records"]
    L = [f"alpha {a:g}; share refused by each detector of the records reaching the step "
         "(n), and of those among them the diagnoser's answer was confidently wrong (w) "
         "or right (r)", "",
         "| group / family | n | " + " | ".join(dets) + " |",
         "|---|---|" + "---|" * len(dets)]  # fmt: skip

    def line(name, rs):
        rs = [r for r in rs if r["reached"]]
        if not rs:
            return f"| {name} | 0 |" + " – |" * len(dets)
        cells = []
        for d in dets:
            ref = [r["p"][d] < a for r in rs]
            wrong = [r["p"][d] < a for r in rs if r["label"] and r["label"] != r["truth"]
                     and (r["p_label"] or 0) >= 0.5]  # fmt: skip
            right = [r["p"][d] < a for r in rs if r["label"] and r["label"] == r["truth"]]
            w = f"{100 * np.mean(wrong):.0f}" if wrong else "–"
            rr = f"{100 * np.mean(right):.0f}" if right else "–"
            cells.append(f"{100 * np.mean(ref):.0f} (w {w}, r {rr})")
        return f"| {name} | {len(rs)} | " + " | ".join(cells) + " |"

    for g in dict.fromkeys(r["group"] for r in rows):
        L.append(line(f"**{g}**", [r for r in rows if r["group"] == g]))
    for f in dict.fromkeys(r["family"] for r in rows):
        L.append(line(f, [r for r in rows if r["family"] == f]))
    return "\n".join(L)


if __name__ == "__main__":
    main()
