"""What limits a diagnoser's accuracy: a learning curve over the number of training
conditions and a feature-group ablation, both on a data set's held-out conditions
(docs/diagnosis.md).

    python benchmarks/bench_diagnosis_learning.py [DATASET] [--sizes 3,6,9] [--draws 3]
    python benchmarks/bench_diagnosis_learning.py --quick

Learning curve: classifiers (the one of ``recipdyn train``, all features) trained on ``n``
training conditions drawn at random (``--draws`` draws, seeded) from the data set's training
conditions, tested on its test conditions. Ablation: the same classifier on all training
conditions with each feature group left out, and with each group alone. DATASET defaults to
``make diagnoser``'s; ``--quick`` uses the small data set of ``_dataset.py`` with sizes 1,3
(it checks that the benchmark runs, it does not measure a diagnoser).
"""

from __future__ import annotations

import argparse

import numpy as np

from _dataset import dataset_for

#: ``make bench`` runs the quick mode (the full one needs ``make diagnoser``'s data set).
RUN_ALL_ARGV = ["--quick"]


def _fit_score(df_tr, df_te, cols, classes, seed=0):
    from recipdyn.diagnosis.train import _hgb_classifier

    lab = {c: i for i, c in enumerate(classes)}
    clf = _hgb_classifier(seed).fit(df_tr[cols].to_numpy(float), df_tr.label.map(lab).to_numpy())
    pred = clf.predict(df_te[cols].to_numpy(float))
    y = df_te.label.map(lab).to_numpy()
    ok = pred == y
    ms = (df_te.label == "healthy").to_numpy() | (df_te.severity >= 0.5).to_numpy()
    healthy = y == lab["healthy"]
    return ok.mean(), ok[ms].mean(), ok[healthy].mean()


def main(argv: list[str] | None = None) -> dict:
    from threadpoolctl import threadpool_limits

    from recipdyn.diagnosis.dataset import read_features
    from recipdyn.diagnosis.evidence import feature_groups

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset", nargs="?", default=None)
    ap.add_argument("--sizes", default=None, help="default 3,6,9 (--quick: 1,3)")
    ap.add_argument("--draws", type=int, default=3)
    ap.add_argument("--no-ablation", action="store_true")
    ap.add_argument("--quick", action="store_true", help="the small data set of _dataset.py")
    args = ap.parse_args(argv)
    folder, quick = dataset_for(args.dataset, args.quick)
    args.sizes = args.sizes or ("1,3" if quick else "3,6,9")
    if quick:
        print("(quick data set: the accuracies check that the benchmark runs, nothing more)")
    df, card = read_features(folder)
    curve: dict[str, float] = {}
    classes = list(card["spec"]["classes"])
    names = [c[2:] for c in df.columns if c.startswith("f_")]
    cols = [f"f_{n}" for n in names]
    tr, te = df[df.split == "train"], df[df.split == "test"]
    conds = np.array(sorted(tr.condition.unique()))
    print(f"{len(tr)} training records ({len(conds)} conditions), {len(te)} test records")
    print("\n| training conditions | records | accuracy | s >= 0.5 | healthy recall |")
    print("|---|---|---|---|---|")
    with threadpool_limits(1):
        for n in [int(s) for s in args.sizes.split(",")]:
            res = []
            draws = 1 if n >= len(conds) else args.draws
            for d in range(draws):
                pick = np.random.default_rng([d, n]).permutation(conds)[:n]
                sub = tr[tr.condition.isin(pick)]
                res.append(_fit_score(sub, te, cols, classes))
            a = np.array(res)
            curve[str(n)] = float(a[:, 0].mean())
            print(
                f"| {n} | {len(sub)} | {a[:, 0].mean():.3f} ± {a[:, 0].std():.3f} | "
                f"{a[:, 1].mean():.3f} | {a[:, 2].mean():.3f} |",
                flush=True,
            )
        if args.no_ablation:
            return {"dataset": str(folder), "quick": quick, "accuracy_by_conditions": curve}
        groups = feature_groups(names)
        print("\n| features | columns | accuracy | s >= 0.5 | healthy recall |")
        print("|---|---|---|---|---|")
        rows = [("all", cols)]
        for g, members in groups.items():
            if not members:
                continue
            rows.append((f"without {g}", [c for c in cols if c[2:] not in members]))
            rows.append((f"{g} only", [f"f_{m}" for m in members]))
        for label, cs in rows:
            a, ms, h = _fit_score(tr, te, cs, classes)
            print(f"| {label} | {len(cs)} | {a:.3f} | {ms:.3f} | {h:.3f} |", flush=True)
    return {"dataset": str(folder), "quick": quick, "accuracy_by_conditions": curve}


if __name__ == "__main__":
    main()
