import os

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


def generalized_mass(p):
    """``A(theta1, theta_c)``: the compressor's generalized mass (Lagrangian coefficient of
    theta_c''), from the symbolic derivation, for parameters ``p`` (a test helper)."""
    import sympy as sp

    from recipdyn.model.derivation import SYMBOLS as S
    from recipdyn.model.derivation import structured_equations

    values = {S["r"]: p.r, S["l"]: p.l, S["ls"]: p.ls, S["m2"]: p.m2, S["m3"]: p.m3,
              S["J2"]: p.J2, S["rc"]: p.rc, S["d"]: p.d}  # fmt: skip
    return sp.lambdify((S["theta1"], S["theta_c"]), structured_equations()["A"].subs(values),
                       "numpy")  # fmt: skip
