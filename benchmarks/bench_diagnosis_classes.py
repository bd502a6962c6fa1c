"""What one fault class adds to a diagnoser: trained and evaluated on a data set with all its
classes, then on the same records without that class's (default: the crosshead guide).

    python benchmarks/bench_diagnosis_classes.py [DATASET] [--without crosshead_guide_clearance]
    python benchmarks/bench_diagnosis_classes.py --quick

DATASET defaults to ``make diagnoser``'s; ``--quick`` uses the small data set of
``_dataset.py`` (it checks that the benchmark runs, it does not measure a diagnoser) and
leaves out its last class.

Prints, for each, the held-out accuracy (all features; s >= 0.5), the per-class recall, each
fault's detection limit, the severity's median relative error and its 90 % interval coverage
(docs/diagnosis.md). The two diagnosers see the same records of the other classes: the
difference is the class alone.
"""

from __future__ import annotations

import argparse

from _dataset import dataset_for
from recipdyn.diagnosis.dataset import read_features
from recipdyn.diagnosis.train import train

#: ``make bench`` runs the quick mode (the full one needs ``make diagnoser``'s data set).
RUN_ALL_ARGV = ["--quick"]


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


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset", nargs="?", default=None)
    ap.add_argument(
        "--without",
        default=None,
        help="default: crosshead_guide_clearance (--quick: the last class)",
    )
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--quick", action="store_true", help="the small data set of _dataset.py")
    a = ap.parse_args(argv)
    folder, quick = dataset_for(a.dataset, a.quick)
    _, card = read_features(folder)
    every = list(card["spec"]["classes"])
    without = a.without or (every[-1] if quick else "crosshead_guide_clearance")
    if without not in every[1:]:
        ap.error(f"--without {without}: not a fault class of {folder} ({', '.join(every[1:])})")
    rows = []
    for title, only in (("all classes", None), (f"without {without}", None)):
        if title.startswith("without"):
            only = [c for c in every if c != without]
        _, ev = train(folder, seed=a.seed, classes=only)
        print(f"## {title}" + (" (quick data set: not a measurement)" if quick else "") + "\n")
        print(table(ev, only or every))
        print()
        rows.append(dict(metric=f"held-out accuracy, {title}", value=ev["full"]["accuracy"],
                         unit="", target=None, better="higher"))  # fmt: skip
    return {"dataset": str(folder), "quick": quick, "summary": [] if quick else rows}


if __name__ == "__main__":
    main()
