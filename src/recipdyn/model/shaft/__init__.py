"""The crankshaft as a torsional system: its lumped inertias and stiffnesses, natural
frequencies and modes, and API 618's separation from the running speed's orders
(`recipdyn.model.shaft.torsion`)."""

from .torsion import TorsionalTrain, throw_inertia, torsion_summary, train_of

__all__ = ["TorsionalTrain", "throw_inertia", "train_of", "torsion_summary"]
