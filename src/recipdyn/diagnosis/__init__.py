"""Fault diagnosis from physics-generated records: labelled data sets (`build_dataset`),
diagnosers trained and evaluated on held-out operating conditions (`train`), and the
diagnosis of a record with its evidence and an out-of-distribution refusal (`diagnose`).
See docs/diagnosis.md.
"""

from .classes import CLASSES, CONDITIONS, MODEL, FaultClass
from .dataset import DatasetSpec, build_dataset, dataset_record, read_features, recompute_features
from .diagnose import Diagnosis, default_model_path, diagnose, diagnose_arrays
from .train import Diagnoser, evaluate, load, save, train

#: `train` under the name the package's top level gives it (``recipdyn.train_diagnoser``).
train_diagnoser = train
load_diagnoser = load

__all__ = ["CLASSES", "CONDITIONS", "MODEL", "FaultClass", "DatasetSpec", "build_dataset",
           "read_features", "recompute_features", "dataset_record", "train_diagnoser",
           "load_diagnoser", "Diagnosis", "diagnose", "diagnose_arrays", "default_model_path",
           "Diagnoser", "train", "evaluate", "load", "save"]  # fmt: skip
