"""What one fault class adds to a diagnoser: trained and evaluated on a data set with all its
classes, then on the same records without that class's (default: the crosshead guide).

    python benchmarks/bench_diagnosis_classes.py DATASET [--without crosshead_guide_clearance]

Prints, for each, the held-out accuracy (all features; s >= 0.5), the per-class recall, each
fault's detection limit, the severity's median relative error and its 90 % interval coverage
(docs/diagnosis.md). The two diagnosers see the same records of the other classes: the
difference is the class alone.
"""

from __future__ import annotations

import argparse

from recipdyn.diagnosis.dataset import read_features
from recipdyn.diagnosis.train import train


def table(ev, classes) -> str:
    f = ev["full"]
    lines = [
        f"accuracy {f['accuracy']:.3f} (s >= 0.5: {f['accuracy_moderate_severe']:.3f}), "
        f"ECE {f['ece']:.3f}; severity median relative error "
        f"{ev['severity_median_relative_error']:.3f}, 90 % interval coverage "
        f"{ev['severity_coverage']:.3f}; {ev['n_test']} test / {ev['n_train']} train records",
        "| class | recall | recall by severity bin | detection limit | severity error | coverage |",
        "|---|---|---|---|---|---|",
    ]
    for c in classes:
        d = f["detection"].get(c)
        s = ev["severity"].get(c)
        bins = (
            ", ".join(f"{v:.2f}" for _, v in sorted(d["recall_by_severity"].items())) if d else "—"
        )
        lim = "—" if d is None else ("not reached" if d["limit_severity"] is None
                                      else f"{d['limit_severity']:.3g} ({d['limit_value']:.3g} "
                                      f"{d['unit']})")  # fmt: skip
        err = "—" if s is None else f"{s['median_relative_error']:.2f}"
        cov = "—" if s is None else f"{s['coverage']:.2f}"
        lines.append(f"| {c} | {f['recall'][c]:.2f} | {bins} | {lim} | {err} | {cov} |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset")
    ap.add_argument("--without", default="crosshead_guide_clearance")
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    _, card = read_features(a.dataset)
    every = list(card["spec"]["classes"])
    for title, only in (("all classes", None), (f"without {a.without}", None)):
        if title.startswith("without"):
            only = [c for c in every if c != a.without]
        _, ev = train(a.dataset, seed=a.seed, classes=only)
        print(f"## {title}\n")
        print(table(ev, only or every))
        print()


if __name__ == "__main__":
    main()
