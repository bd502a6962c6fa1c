"""How far each fault at each severity level moves each feature group away from the healthy
machine, relative to the healthy records' own spread (docs/diagnosis.md, detection limits).

    python benchmarks/bench_diagnosis_separability.py [DATASET] [--quick]

For every feature: the fault record minus the median of the healthy records of the same
operating condition (same machine, same condition, other noise draws), divided by the
spread of the healthy records over all conditions (interquartile range / 1.349, a robust
standard deviation). A group's score is its largest feature's median over the conditions:
below ~1 the fault hides inside the healthy machine's variation across conditions. On a data
set of continuous severities, by the evaluation's severity bins. DATASET defaults to ``make
diagnoser``'s; ``--quick`` uses the small data set of ``_dataset.py`` (it checks that the
benchmark runs, it does not measure the faults).
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

from _dataset import dataset_for

#: ``make bench`` runs the quick mode (the full one needs ``make diagnoser``'s data set).
RUN_ALL_ARGV = ["--quick"]


def main(argv: list[str] | None = None) -> dict:
    from recipdyn.diagnosis.dataset import read_features
    from recipdyn.diagnosis.evidence import feature_groups
    from recipdyn.diagnosis.train import severity_bins

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset", nargs="?", default=None)
    ap.add_argument("--quick", action="store_true", help="the small data set of _dataset.py")
    args = ap.parse_args(argv)
    folder, quick = dataset_for(args.dataset, args.quick)
    if quick:
        print("(quick data set: the scores check that the benchmark runs, nothing more)")
    df, card = read_features(folder)
    names = [c[2:] for c in df.columns if c.startswith("f_")]
    groups = {g: [f"f_{n}" for n in m] for g, m in feature_groups(names).items() if m}
    cols = [c for m in groups.values() for c in m]
    healthy = df[df.label == "healthy"]
    q1, q3 = np.nanpercentile(healthy[cols].to_numpy(float), [25, 75], axis=0)
    spread = np.where(q3 > q1, (q3 - q1) / 1.349, np.nan)
    base = healthy.groupby("condition")[cols].median()
    print("| class | severity | " + " | ".join(groups) + " |")
    print("|---|---|" + "---|" * len(groups))
    edges = severity_bins(card)  # continuous severities: the evaluation's bins
    if edges is None:
        groups_of = [(f"{s:g}", df.severity == s) for s in card["spec"]["levels"]]
    else:
        groups_of = [
            (f"{a:.3g}–{b:.3g}", (df.severity >= a) & ((df.severity < b) | (b == edges[-1])))
            for a, b in zip(edges[:-1], edges[1:], strict=True)
        ]
    scores: dict[str, dict[str, float]] = {}
    for c in card["spec"]["classes"][1:]:
        for s, in_bin in groups_of:
            sub = df[(df.label == c) & in_bin]
            if sub.empty:
                continue
            d = (sub[cols].to_numpy(float) - base.loc[sub.condition].to_numpy(float)) / spread
            with warnings.catch_warnings():  # a feature NaN on every record (no event)
                warnings.simplefilter("ignore", RuntimeWarning)
                med = np.nanmedian(np.abs(d), axis=0)
            k = {col: i for i, col in enumerate(cols)}
            score = [np.nanmax(med[[k[x] for x in m]]) for m in groups.values()]
            print(f"| {c} | {s} | " + " | ".join(f"{v:.1f}" for v in score) + " |")
            scores[f"{c} {s}"] = dict(zip(groups, map(float, score), strict=True))
    return {"dataset": str(folder), "quick": quick, "scores": scores}


if __name__ == "__main__":
    main()
