"""The data set the diagnosis benchmarks read (``bench_diagnosis_*.py``): the one given on
their command line, else the one ``make diagnoser`` builds (``out/diagnoser-data``), else,
with ``--quick``, a small one built here once (and resumed after).

The quick data set checks that a benchmark runs from ``make bench``; it is far too small to
measure a diagnoser (4 operating conditions, one of them held out; 4 classes that share the
data set's compiled model at 2 severities: 32 records, a few minutes on 2 cores once the
model's kernels are compiled), and the benchmarks say so when they use it.
"""

from __future__ import annotations

from pathlib import Path

#: Where ``make diagnoser`` builds the shipped diagnoser's data set.
MAKE_DIAGNOSER = Path("out/diagnoser-data")
#: Where the quick data set is built (beside ``make bench``'s results).
QUICK = Path("bench-results/quick-dataset")
#: Its classes: those of one compiled configuration (the guide's clearance needs another).
QUICK_CLASSES = ("healthy", "crank_pin_clearance", "suction_valve_leak", "ring_leak")


def quick_dataset(root: Path = QUICK) -> Path:
    """Build (or resume, or reuse) the quick data set under ``root``, in a folder named by
    its spec and feature names (a data set of other features is never reused)."""
    import hashlib

    from recipdyn.diagnosis.dataset import DatasetSpec, build_dataset, feature_names

    spec = DatasetSpec(n_conditions=4, levels=(0.5, 1.0), classes=QUICK_CLASSES)
    key = hashlib.sha1((spec.to_json() + ",".join(feature_names())).encode()).hexdigest()
    folder = root / key[:12]
    if (folder / "datacard.json").exists():
        return folder
    print(f"building the quick data set in {folder} (32 records, once)", flush=True)
    return build_dataset(folder, spec, backend="processes", workers=2, resume=folder.exists(),
                         progress=True)  # fmt: skip


def dataset_for(given: str | None, quick: bool) -> tuple[Path, bool]:
    """``(folder, is_quick)``: the data set a diagnosis benchmark reads."""
    if given:
        return Path(given), False
    if not quick and (MAKE_DIAGNOSER / "datacard.json").exists():
        return MAKE_DIAGNOSER, False
    if not quick:
        raise SystemExit(
            f"a data set is needed: give its folder, build {MAKE_DIAGNOSER} with "
            "'make diagnoser', or run with --quick (a small one built here)"
        )
    return quick_dataset(), True
